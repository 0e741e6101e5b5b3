//! The heel-rise relation μ₅ (not the paper's; `generator::generalize::mu::HeelRise`): with it
//! φ puts the stance foot's heel rise at HSM⁺ on μ₅(sl) and still ends F₂ at −μ₃(sl) (eq. 33's
//! toe-off angle), and chains of steps of different lengths stay continuous and planted — the
//! swing foot's tail before TOM (the previous step's F₂) meets the previous step's stance foot
//! at the boundary. Without μ₅ φ is the paper's, bit for bit.
use gaitfit::generator::generalize::pose::{pose, LegPose};
use gaitfit::generator::generalize::synthetic::synthetic_walk;
use gaitfit::generator::generalize::{phi, Generalizer, HeelRise};
use proptest::prelude::*;

fn points(l: &LegPose, dx: f64) -> Vec<[f64; 2]> {
    [l.foot.ankle, l.foot.heel, l.foot.ball, l.foot.toe]
        .iter()
        .map(|p| [p[0] + dx, p[1]])
        .collect()
}

fn max_gap(a: &[[f64; 2]], b: &[[f64; 2]]) -> f64 {
    a.iter()
        .zip(b)
        .map(|(p, q)| (p[0] - q[0]).hypot(p[1] - q[1]))
        .fold(0.0, f64::max)
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 32, ..ProptestConfig::default() })]

    #[test]
    fn heel_rise_ends_and_chain_continuity(seed in 0u64..10_000,
                                           alpha5 in -2.0..1.0f64,
                                           lengths in proptest::collection::vec(0.85..1.15f64, 2..5)) {
        let (proto, mu0) = synthetic_walk(seed).unwrap();
        let star = -proto.foot2().at(1.0);
        prop_assume!(star > 0.05);
        let mu = mu0.with_heel_rise(HeelRise { alpha: alpha5, star }).unwrap();
        let sl0 = proto.step_length();
        // φ₁ with μ₅ is still the identity on the prototype.
        let w1 = phi(&proto, 1.0, sl0, &mu).unwrap();
        for (a, b) in w1.foot2().values().iter().zip(proto.foot2().values()) {
            prop_assert!((a[0] - b[0]).abs() < 1e-12);
        }
        let g = Generalizer::new(proto.clone(), mu).unwrap();
        let body = *g.prototype().body();
        let sls: Vec<f64> = lengths.iter().map(|l| l * sl0).collect();
        let Ok(steps) = g.chain(&body, &sls) else {
            // μ₅ or μ₂…μ₄ left their range for this slope: an error, never a wrong drawing.
            return Ok(());
        };
        let mut x = 0.0;
        for (k, w) in steps.iter().enumerate() {
            let h = mu.heel_rise_at(&body, sls[k]).unwrap().unwrap();
            let m = mu.values(&body, sls[k]).unwrap();
            prop_assert!((w.foot2().at(1.0) + h).abs() < 1e-12, "heel rise at HSM+");
            prop_assert!((w.foot2().last()[0] + m.foot_to).abs() < 1e-12, "toe off angle");
            // Without μ₅ the same step is the paper's eq. 33 (one scale for all of F₂).
            let p = phi(&proto, sls[k] / sl0, if k == 0 { sls[0] } else { sls[k - 1] }, &mu0).unwrap();
            let k2 = p.foot2().last()[0] / proto.foot2().last()[0];
            for (a, b) in p.foot2().values().iter().zip(proto.foot2().values()) {
                prop_assert!((a[0] - k2 * b[0]).abs() < 1e-12);
            }
            let end = pose(w, &mu, 1.0).unwrap();
            if let Some(next) = steps.get(k + 1) {
                let start = pose(next, &mu, 0.0).unwrap();
                // Legs swap roles: this step's stance foot is the next step's trailing foot.
                let gs = max_gap(&points(&end.stance, x), &points(&start.swing, x + sls[k]));
                let gw = max_gap(&points(&end.swing, x), &points(&start.stance, x + sls[k]));
                prop_assert!(gs < 1e-9 && gw < 1e-9, "discontinuity {gs:e} / {gw:e} m after step {}", k + 1);
                prop_assert!((end.stance.foot_angle - start.swing.foot_angle).abs() < 1e-12);
                // Inside the next step the trailing foot reaches F₃'s start at TOM continuously.
                let tom = next.moments().tom();
                let (a, b) = (pose(next, &mu, tom - 1e-10).unwrap(), pose(next, &mu, tom + 1e-10).unwrap());
                prop_assert!((a.swing.foot_angle - b.swing.foot_angle).abs() < 1e-7);
            }
            x += sls[k];
        }
    }
}
