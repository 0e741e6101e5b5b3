//! Reference tests for `walk-sl-sf` against the walking paper (Bruderlin & Calvert 1989, §3
//! eq. 1, Figure 10).
use gaitfit::relations::{Inputs, Relation, WalkSlSf};

const V_5_KM_PER_H: f64 = 5000.0 / 60.0; // m/min

/// 5 km/h at h = 1.8 m: sf² = v/(0.004·h) → sf = 107.58 steps/min, sl = v/sf = 0.7746 m.
#[test]
fn five_km_per_h_at_1_8_m() {
    let w = WalkSlSf::published();
    let sf = w.step_freq_for_speed(V_5_KM_PER_H, 1.8);
    let sl = w.step_length_for_speed(V_5_KM_PER_H, 1.8);
    assert!((sf - 107.6).abs() < 0.05, "{sf}");
    assert!((sl - 0.775).abs() < 0.001, "{sl}");
    // eq. 1 itself: sl/(sf·h) = 0.004.
    assert!((sl / (sf * 1.8) - 0.004).abs() < 1e-15);
    assert!((w.step_length(sf, 1.8) - sl).abs() < 1e-12);
    assert!(
        (w.predict_with(&w.card().published_values(), 0.0, &Inputs::new(&[sf, 1.8])) - sl).abs()
            < 1e-12
    );
}

/// Figure 10: three walks at v = 5 km/h with step lengths 0.50 m and 1.05 m besides the natural
/// one; v = sl·sf gives 166.7 and 79.4 steps/min.
#[test]
fn figure_10_step_frequencies() {
    assert!((V_5_KM_PER_H / 0.50 - 166.7).abs() < 0.05);
    assert!((V_5_KM_PER_H / 1.05 - 79.4).abs() < 0.05);
    // Both deviate from the natural step length, which lies between them.
    let natural = WalkSlSf::published().step_length_for_speed(V_5_KM_PER_H, 1.8);
    assert!(0.50 < natural && natural < 1.05);
}

#[test]
fn through_the_origin_and_inverse() {
    let w = WalkSlSf::published();
    assert!(!w.card().has_intercept);
    assert_eq!(
        w.predict_with(&w.card().published_values(), 0.0, &Inputs::new(&[0.0, 1.8])),
        0.0
    );
    assert!((w.step_freq(w.step_length(120.0, 1.7), 1.7) - 120.0).abs() < 1e-12);
}
