//! Reference tests for `walk-tds-sf` against the walking paper (Bruderlin & Calvert 1989, §3:
//! t_ds = (−0.16·sf + 29.08)·t_cycle/100, t_cycle = 2/sf).
use gaitfit::relations::{Inputs, Relation, WalkTdsSf};

#[test]
fn published_formula() {
    let w = WalkTdsSf::published();
    // At the natural 5 km/h frequency of a 1.8 m walker (107.6 steps/min): 11.864 % of the
    // cycle; t_cycle = 2/(107.6/60) = 1.1152 s → t_ds = 0.1323 s.
    assert!((w.double_support_pct(107.6) - (29.08 - 0.16 * 107.6)).abs() < 1e-12);
    let t = w.double_support_time(107.6);
    assert!((t - 0.11864 * 120.0 / 107.6).abs() < 1e-12, "{t}");
    assert!((t - 0.1323).abs() < 0.0001);
    // "As t_ds vanishes, walking becomes running": at 29.08/0.16 = 181.75 steps/min, just under
    // KLAW's sf_max = 182.
    assert!(w.double_support_pct(181.75).abs() < 1e-12);
    assert!(
        (w.predict_with(&w.card().published_values(), 0.0, &Inputs::new(&[100.0])) - 13.08).abs()
            < 1e-12
    );
}

#[test]
fn stance_and_swing_from_eq_2() {
    // eq. 2: t_step = t_stance − t_ds = t_swing + t_ds.
    let w = WalkTdsSf::published();
    let sf = 110.0;
    let t_step = 60.0 / sf;
    let t_ds = w.double_support_time(sf);
    let (stance, swing) = (t_step + t_ds, t_step - t_ds);
    assert!((stance + swing - 2.0 * t_step).abs() < 1e-12);
    assert!(stance / (2.0 * t_step) > 0.5 && stance / (2.0 * t_step) < 0.7);
}
