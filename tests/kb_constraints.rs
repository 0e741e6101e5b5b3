//! Ko & Badler (1993) constraints inside the generalization, as property tests over random
//! walks, bodies and schedules of step lengths: the stance foot never slides or penetrates the
//! floor, the swing ankle meets the next heel strike, and successive steps of different lengths
//! chain without discontinuity (the sl_before term) — hip, knees and every foot point.
use gaitfit::generator::generalize::pose::{pose, LegPose, StepPose};
use gaitfit::generator::generalize::synthetic::synthetic_walk;
use gaitfit::generator::generalize::{Anthropometry, Generalizer, MuFunctions, WalkData};
use proptest::prelude::*;

fn cfg() -> ProptestConfig {
    ProptestConfig {
        cases: 32,
        ..ProptestConfig::default()
    }
}

fn shift(p: [f64; 2], dx: f64) -> [f64; 2] {
    [p[0] + dx, p[1]]
}

fn leg_points(l: &LegPose, dx: f64) -> Vec<[f64; 2]> {
    vec![
        shift(l.foot.ankle, dx),
        shift(l.foot.heel, dx),
        shift(l.foot.ball, dx),
        shift(l.foot.toe, dx),
    ]
}

fn max_gap(a: &[[f64; 2]], b: &[[f64; 2]]) -> f64 {
    a.iter()
        .zip(b)
        .map(|(p, q)| (p[0] - q[0]).hypot(p[1] - q[1]))
        .fold(0.0, f64::max)
}

/// Every joint of pose `p` (step at world offset `x`) against pose `q` (offset `y`), with the
/// legs swapped when `swap`.
fn gap(p: &StepPose, x: f64, q: &StepPose, y: f64, swap: bool) -> f64 {
    let (qa, qb) = if swap {
        (&q.swing, &q.stance)
    } else {
        (&q.stance, &q.swing)
    };
    let h = max_gap(&[shift(p.hip, x)], &[shift(q.hip, y)]);
    h.max(max_gap(&leg_points(&p.stance, x), &leg_points(qa, y)))
        .max(max_gap(&leg_points(&p.swing, x), &leg_points(qb, y)))
}

/// The knees' gap. Near a straight knee the two-link IK amplifies rounding like √ε (the
/// knee's offset from the hip–ankle line is √(t² − a²)), so knees get their own tolerance.
fn knee_gap(p: &StepPose, x: f64, q: &StepPose, y: f64, swap: bool) -> f64 {
    let (qa, qb) = if swap {
        (&q.swing, &q.stance)
    } else {
        (&q.stance, &q.swing)
    };
    max_gap(
        &[shift(p.stance.knee, x), shift(p.swing.knee, x)],
        &[shift(qa.knee, y), shift(qb.knee, y)],
    )
}

fn body_like(b: &Anthropometry, k: &[f64; 3]) -> Anthropometry {
    Anthropometry::new(
        b.thigh() * k[0] * k[2],
        b.shin() * k[1] * k[2],
        b.heel_to_n() * k[2],
        b.ball_to_n() * k[2],
        b.ankle_to_n() * k[2],
        b.ball_to_toe() * k[2],
    )
    .unwrap()
    .with_ball_height(b.ball_height() * k[2])
    .unwrap()
}

fn stance_foot_is_planted(w: &WalkData, mu: &MuFunctions) -> Result<(), TestCaseError> {
    let b = w.body();
    let (hb, bt) = (b.heel_to_ball(), b.ball_to_toe());
    for i in 0..=240 {
        let t = i as f64 / 240.0;
        let p = pose(w, mu, t).unwrap();
        let f = &p.stance.foot;
        for q in [f.heel, f.ball, f.toe] {
            prop_assert!(q[1] >= -1e-12, "stance foot penetrates at t = {t}: {q:?}");
        }
        // Whatever touches the floor is at its fixed pivot: heel at 0, ball at hb, toe at hb+bt.
        let mut touching = 0;
        for (q, x) in [(f.heel, 0.0), (f.ball, hb), (f.toe, hb + bt)] {
            if q[1].abs() < 1e-12 {
                touching += 1;
                prop_assert!((q[0] - x).abs() < 1e-12, "stance foot slid at t = {t}");
            }
        }
        prop_assert!(touching >= 1, "stance foot off the floor at t = {t}");
        // The trailing foot, before TOM, is planted on its pivot one step back.
        if t < w.moments().tom() {
            let s = &p.swing.foot;
            let back = -w.step_length_before();
            let on = [(s.ball, back + hb), (s.toe, back + hb + bt)]
                .iter()
                .any(|(q, x)| q[1].abs() < 1e-12 && (q[0] - x).abs() < 1e-12);
            prop_assert!(on, "trailing foot not on its pivot at t = {t}");
            for q in [s.heel, s.ball, s.toe] {
                prop_assert!(q[1] >= -1e-12);
            }
        }
    }
    Ok(())
}

proptest! {
    #![proptest_config(cfg())]

    /// Chains of steps of different lengths, for other bodies: every joint is continuous at
    /// every step boundary (legs swap roles), the swing heel lands exactly at the next step's
    /// stance heel, and both feet are planted without sliding or penetration.
    #[test]
    fn chain_is_continuous_and_planted(seed in 0u64..10_000,
                                       k in [0.9..1.1f64, 0.9..1.1, 0.85..1.2],
                                       lengths in proptest::collection::vec(0.8..1.2f64, 2..6)) {
        let (proto, mu) = synthetic_walk(seed).unwrap();
        let g = Generalizer::new(proto, mu).unwrap();
        let body = body_like(g.prototype().body(), &k);
        let a = body.ratio_to(g.prototype().body());
        let sls: Vec<f64> = lengths.iter().map(|l| l * a * g.prototype().step_length()).collect();
        let steps = g.chain(&body, &sls).unwrap();
        let mut x = 0.0;
        for (k, w) in steps.iter().enumerate() {
            prop_assert!((w.step_length() - sls[k]).abs() < 1e-12);
            stance_foot_is_planted(w, &mu)?;
            let end = pose(w, &mu, 1.0).unwrap();
            // The swing heel meets the floor exactly one step ahead.
            prop_assert!((end.swing.foot.heel[0] - sls[k]).abs() < 1e-12);
            prop_assert!(end.swing.foot.heel[1].abs() < 1e-12);
            prop_assert!(end.hip_drop.abs() < 1e-12 && !end.unreachable);
            if let Some(next) = steps.get(k + 1) {
                let start = pose(next, &mu, 0.0).unwrap();
                let g = gap(&end, x, &start, x + sls[k], true);
                prop_assert!(g < 1e-9, "discontinuity {g:e} m between steps {} and {}", k + 1, k + 2);
                let gk = knee_gap(&end, x, &start, x + sls[k], true);
                prop_assert!(gk < 1e-6, "knee jump {gk:e} m between steps {} and {}", k + 1, k + 2);
            }
            x += sls[k];
        }
    }

    /// Inside a step the pose is continuous at FGM, MOM (when inside the step) and TOM, where
    /// the pivots and the sequences change.
    #[test]
    fn continuous_at_the_moments(seed in 0u64..10_000, r in 0.8..1.25f64, b in 0.8..1.25f64) {
        let (proto, mu) = synthetic_walk(seed).unwrap();
        let sl = proto.step_length();
        let w = gaitfit::generator::generalize::phi(&proto, r, b * sl, &mu).unwrap();
        let m = *w.moments();
        for t in [m.fgm(), m.tom(), m.mom(), m.mom() - 1.0] {
            if !(0.0..1.0).contains(&t) {
                continue;
            }
            let e = 1e-10;
            let p = pose(&w, &mu, t - e).unwrap();
            let q = pose(&w, &mu, t + e).unwrap();
            let g = gap(&p, 0.0, &q, 0.0, false);
            prop_assert!(g < 1e-7, "jump {g:e} m at t = {t}");
            let gk = knee_gap(&p, 0.0, &q, 0.0, false);
            prop_assert!(gk < 1e-4, "knee jump {gk:e} m at t = {t}");
        }
        // F₃ starts at the toe-off angle of the step before (eq. 34 with t' = (t − TOM)/(1 − TOM)).
        let mb = mu.values(w.body(), b * sl).unwrap();
        prop_assert!((w.foot3().first()[0] + mb.foot_to).abs() < 1e-12);
    }
}

/// Over a long chain of random step lengths the hip neither drifts ahead of nor behind the
/// feet: at every heel strike it sits sl_before/2 + c behind the stance heel, c fixed by the
/// prototype (the reason eq. 26 moves the hip's start by half the change of sl_before).
#[test]
fn hip_does_not_drift_over_fifty_steps() {
    use rand::{Rng, SeedableRng};
    let (proto, mu) = synthetic_walk(3).unwrap();
    let c = -proto.hip().first()[0] - proto.step_length_before() / 2.0;
    let g = Generalizer::new(proto.clone(), mu).unwrap();
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(9);
    let sls: Vec<f64> = (0..50)
        .map(|_| proto.step_length() * rng.random_range(0.8..1.2))
        .collect();
    let steps = g.chain(proto.body(), &sls).unwrap();
    for w in &steps {
        let offset = -w.hip().first()[0] - w.step_length_before() / 2.0;
        assert!((offset - c).abs() < 1e-12, "hip offset {offset} vs {c}");
        let end = w.hip().last()[0] - w.step_length();
        assert!((-end - w.step_length() / 2.0 - c).abs() < 1e-12);
    }
}
