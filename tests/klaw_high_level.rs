//! Reference tests of KLAW's high level (§3) against the paper's own numbers.
use gaitfit::generator::walking::attributes::WalkAttributes;
use gaitfit::generator::walking::body::Body;
use gaitfit::generator::walking::high_level::{
    complete, heel_strike, phase_times, WalkParams, WalkRelations,
};

const KMH: f64 = 1.0 / 3.6;

fn fig10(sl: Option<f64>) -> (f64, f64) {
    let p = WalkParams {
        speed_m_per_s: Some(5.0 * KMH),
        step_length_m: sl,
        ..Default::default()
    };
    let l = complete(
        &p,
        1.8,
        &WalkRelations::published(),
        &WalkAttributes::default(),
    )
    .unwrap();
    (l.step_length_m, l.step_freq_steps_per_min)
}

#[test]
fn figure_10_natural_short_and_long_steps() {
    // Fig. 10 caption, v = 5 km/h, h = 1.8 m (printed to the digits shown).
    let (sl, sf) = fig10(None);
    assert!(
        (sl - 0.77).abs() < 0.005 && (sf - 107.5).abs() < 0.1,
        "natural: {sl} m, {sf}"
    );
    let (_, sf) = fig10(Some(0.50));
    assert!((sf - 166.7).abs() < 0.05, "short steps: {sf}");
    let (_, sf) = fig10(Some(1.05));
    assert!((sf - 79.4).abs() < 0.05, "long steps: {sf}");
}

#[test]
fn anatomical_limits_give_clear_errors() {
    let a = WalkAttributes::default();
    // 5 km/h with 0.45 m steps needs 185 steps/min > sf_max = 182.
    let p = WalkParams {
        speed_m_per_s: Some(5.0 * KMH),
        step_length_m: Some(0.45),
        ..Default::default()
    };
    let e = complete(&p, 1.8, &WalkRelations::published(), &a)
        .unwrap_err()
        .to_string();
    assert!(e.contains("sf_max") && e.contains("182"), "{e}");
    let p = WalkParams {
        step_length_m: Some(1.5),
        step_freq_steps_per_min: Some(60.0),
        ..Default::default()
    };
    let e = complete(&p, 1.8, &WalkRelations::published(), &a)
        .unwrap_err()
        .to_string();
    assert!(e.contains("step_length_m"), "{e}");
    let p = WalkParams {
        speed_m_per_s: Some(-1.0),
        ..Default::default()
    };
    assert!(complete(&p, 1.8, &WalkRelations::published(), &a).is_err());
    assert!(complete(&WalkParams::default(), 1.8, &WalkRelations::published(), &a).is_err());
    // Inconsistent triple.
    let p = WalkParams {
        speed_m_per_s: Some(1.0),
        step_length_m: Some(0.7),
        step_freq_steps_per_min: Some(100.0),
    };
    assert!(complete(&p, 1.8, &WalkRelations::published(), &a).is_err());
}

#[test]
fn completion_is_consistent_for_every_combination() {
    let rel = WalkRelations::published();
    let a = WalkAttributes::default();
    for p in [
        WalkParams {
            step_length_m: Some(0.7),
            ..Default::default()
        },
        WalkParams {
            step_freq_steps_per_min: Some(100.0),
            ..Default::default()
        },
        WalkParams {
            step_length_m: Some(0.7),
            step_freq_steps_per_min: Some(100.0),
            ..Default::default()
        },
        WalkParams {
            speed_m_per_s: Some(1.2),
            step_freq_steps_per_min: Some(100.0),
            ..Default::default()
        },
    ] {
        let l = complete(&p, 1.75, &rel, &a).unwrap();
        assert!(
            (l.step_length_m * l.step_freq_steps_per_min / 60.0 - l.speed_m_per_s).abs() < 1e-12
        );
    }
    // Only sl or only sf: eq. (1) holds exactly.
    let l = complete(
        &WalkParams {
            step_length_m: Some(0.7),
            ..Default::default()
        },
        1.75,
        &rel,
        &a,
    )
    .unwrap();
    assert!((l.step_length_m / (l.step_freq_steps_per_min * 1.75) - 0.004).abs() < 1e-15);
}

#[test]
fn double_support_relation_and_eq_2() {
    // sf = 107.5: t_ds = (29.08 − 0.16·107.5)% of the cycle = 11.88 % of 1.1163 s.
    let t = phase_times(107.5, &WalkRelations::published());
    assert!((t.double_support - 0.1188 * 120.0 / 107.5).abs() < 1e-12);
    assert!((t.stance - (t.step + t.double_support)).abs() < 1e-15);
    assert!((t.swing - (t.step - t.double_support)).abs() < 1e-15);
}

#[test]
fn eq_3_puts_the_swing_heel_on_the_ground_and_mirrors_the_stance_leg() {
    let b = Body::from_height(1.8, 80.0).unwrap();
    for (sl, theta5_deg, ahead) in [(0.77, 90.0, 0.0), (0.5, 95.0, 0.006), (1.05, 85.0, 0.01)] {
        let hs = heel_strike(&b, sl, f64::to_radians(theta5_deg), ahead).unwrap();
        // Stance model: ankle₁ at (0, l9), hip at w·(sin θ1, cos θ1) from it.
        let hip = [hs.w * hs.theta1.sin(), b.l9 + hs.w * hs.theta1.cos()];
        assert!((hip[0] - sl / 2.0).abs() < 1e-12);
        assert!((hip[1] - hs.hip_height).abs() < 1e-12);
        // Swing leg, extended, from the swing hip (ahead by the pelvic offset): ankle, then the heel
        // of a foot pitched so that the ankle angle is θ5.
        let sh = [hip[0] + ahead, hip[1]];
        let ankle = [
            sh[0] - b.l1 * hs.theta3.sin(),
            sh[1] - b.l1 * hs.theta3.cos(),
        ];
        let (s, c) = hs.foot_pitch.sin_cos();
        let heel = [
            ankle[0] + c * b.heel[0] - s * b.heel[1],
            ankle[1] + s * b.heel[0] + c * b.heel[1],
        ];
        assert!((heel[0] - (sl - b.l8)).abs() < 1e-9, "heel x {heel:?}");
        assert!(heel[1].abs() < 1e-9, "heel y {heel:?}");
        // The foot raises the hip at impact: w > l1 (§3); and |θ3| < θ1 with a dorsiflexed foot.
        assert!(hs.w > b.l1);
    }
}
