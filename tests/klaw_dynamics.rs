//! The printed equations of motion (appendix A, corrected) against an independent Lagrangian
//! derivation, and energy conservation of the integrator with forces and damping off.
#![allow(clippy::needless_range_loop)] // matrices are compared entry by entry
use gaitfit::generator::walking::body::Body;
use gaitfit::generator::walking::dynamics::{StanceModel, SwingModel};
use gaitfit::generator::walking::integrate::integrate;
use gaitfit::generator::walking::lagrange::{self, StanceMechanism, SwingMechanism};
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;

fn rel_close(a: f64, b: f64, scale: f64) -> bool {
    (a - b).abs() <= 1e-8 * scale.max(1.0)
}

type NoEvent<const N: usize> = fn(f64, &[f64; N]) -> f64;

#[test]
fn stance_equations_match_the_lagrangian_at_random_states() {
    let mut rng = ChaCha8Rng::seed_from_u64(6);
    for _ in 0..200 {
        let h = rng.random_range(1.5..2.0);
        let m = rng.random_range(50.0..100.0);
        let model = StanceModel::new(&Body::from_height(h, m).unwrap());
        let q = [
            rng.random_range(0.6..1.1),
            rng.random_range(-0.8..0.8),
            rng.random_range(-0.8..0.8),
        ];
        let qd = [
            rng.random_range(-2.0..2.0),
            rng.random_range(-4.0..4.0),
            rng.random_range(-4.0..4.0),
        ];
        let f = [
            rng.random_range(-2000.0..2000.0),
            rng.random_range(-200.0..200.0),
            rng.random_range(-200.0..200.0),
        ];
        let printed_m = model.mass_matrix(&q);
        let t = lagrange::terms(&StanceMechanism(model), &q, &qd);
        for i in 0..3 {
            for j in 0..3 {
                assert!(
                    rel_close(printed_m[i][j], t.mass[i][j], printed_m[i][i]),
                    "A[{i}][{j}]"
                );
            }
        }
        let printed = model.accel(&q, &qd, &f, false);
        let derived = lagrange::free_accel(&StanceMechanism(model), &q, &qd, &f, &[]);
        for i in 0..3 {
            assert!(
                rel_close(printed[i], derived[i], printed[i].abs()),
                "q̈[{i}]: {printed:?} vs {derived:?}"
            );
        }
        // Locked leg (correction 3): the same mechanism with w prescribed (ẇ = ẅ = 0).
        let zd = [0.0, qd[1], qd[2]];
        let printed_locked = model.accel(&q, &zd, &f, true);
        let t = lagrange::terms(&StanceMechanism(model), &q, &zd);
        let a = [[t.mass[1][1], t.mass[1][2]], [t.mass[2][1], t.mass[2][2]]];
        let b = [f[1] + t.bias[1], f[2] + t.bias[2]];
        let det = a[0][0] * a[1][1] - a[0][1] * a[1][0];
        let x1 = (b[0] * a[1][1] - a[0][1] * b[1]) / det;
        let x2 = (a[0][0] * b[1] - a[1][0] * b[0]) / det;
        assert_eq!(printed_locked[0], 0.0);
        assert!(rel_close(printed_locked[1], x1, x1.abs()));
        assert!(rel_close(printed_locked[2], x2, x2.abs()));
    }
}

#[test]
fn swing_equations_match_the_lagrangian_at_random_states() {
    let mut rng = ChaCha8Rng::seed_from_u64(7);
    for _ in 0..200 {
        let h = rng.random_range(1.5..2.0);
        let m = rng.random_range(50.0..100.0);
        let model = SwingModel::new(&Body::from_height(h, m).unwrap());
        let q = [rng.random_range(-1.0..1.0), rng.random_range(0.0..1.5)];
        let qd = [rng.random_range(-6.0..6.0), rng.random_range(-10.0..10.0)];
        let hip_vel = [rng.random_range(-2.0..2.0), rng.random_range(-1.0..1.0)];
        let hip_acc = [rng.random_range(-5.0..5.0), rng.random_range(-5.0..5.0)];
        let f = [
            rng.random_range(-100.0..100.0),
            rng.random_range(-50.0..50.0),
        ];
        let z = [
            q[0],
            q[1],
            rng.random_range(-1.0..1.0),
            rng.random_range(0.7..1.1),
        ];
        let zd = [qd[0], qd[1], hip_vel[0], hip_vel[1]];
        let t = lagrange::terms(&SwingMechanism(model), &z, &zd);
        let printed_m = model.mass_matrix(&q);
        for i in 0..2 {
            for j in 0..2 {
                assert!(
                    rel_close(printed_m[i][j], t.mass[i][j], printed_m[i][i]),
                    "A[{i}][{j}]"
                );
            }
        }
        // The hip velocity must not matter (its terms cancel); the acceleration drives.
        let printed = model.accel(&q, &qd, &f, &hip_acc, false);
        let derived = lagrange::free_accel(&SwingMechanism(model), &z, &zd, &f, &hip_acc);
        for i in 0..2 {
            assert!(
                rel_close(printed[i], derived[i], printed[i].abs()),
                "q̈[{i}]: {printed:?} vs {derived:?}"
            );
        }
    }
}

#[test]
fn the_printed_theta4_typo_would_fail_the_cross_check() {
    // A.2 as printed has m4 l3 r4 θ̇4 (2θ̇3 + θ4) sin θ4: the Lagrangian disagrees with it, so the
    // cross-check does detect the typo.
    let model = SwingModel::new(&Body::from_height(1.8, 80.0).unwrap());
    let (q, qd) = ([-0.3, 0.8], [2.0, -5.0]);
    let z = [q[0], q[1], 0.0, 0.9];
    let zd = [qd[0], qd[1], 0.0, 0.0];
    let t = lagrange::terms(&SwingMechanism(model), &z, &zd);
    let corrected = model.rhs(&q, &qd, &[0.0, 0.0], &[0.0, 0.0]);
    let k = model.m4 * model.l3 * model.r4;
    let printed_row1 = corrected[0] - k * qd[1] * (2.0 * qd[0] + qd[1]) * q[1].sin()
        + k * qd[1] * (2.0 * qd[0] + q[1]) * q[1].sin();
    assert!((corrected[0] - t.bias[0]).abs() < 1e-9);
    assert!((printed_row1 - t.bias[0]).abs() > 1e-2);
}

/// Total energy over one step of a free (unforced, undamped) motion.
#[test]
fn energy_is_conserved_with_forces_and_damping_off() {
    let body = Body::from_height(1.8, 80.0).unwrap();
    let h = 1e-3;
    let duration = 0.56; // one step at 5 km/h (sf = 107.5 steps/min)

    // Stance, all generalized forces zero.
    let st = StanceModel::new(&body);
    let energy = |y: &[f64; 6]| {
        st.kinetic_energy(&[y[0], y[1], y[2]], &[y[3], y[4], y[5]])
            + st.potential_energy(&[y[0], y[1], y[2]])
    };
    let mut f = |_t: f64, y: &[f64; 6]| {
        let a = st.accel(&[y[0], y[1], y[2]], &[y[3], y[4], y[5]], &[0.0; 3], false);
        [y[3], y[4], y[5], a[0], a[1], a[2]]
    };
    let y0 = [0.9, -0.4, 0.05, -0.3, 1.6, 0.2];
    let e0 = energy(&y0);
    let mut worst: f64 = 0.0;
    let end =
        integrate::<6, _, NoEvent<6>, _>(&mut f, 0.0, y0, duration, h, None, &mut |_, _, _, y| {
            worst = worst.max((energy(y) - e0).abs());
        });
    assert!(end.t == duration);
    println!(
        "stance: relative energy drift over the step {:.2e}",
        worst / e0.abs()
    );
    assert!(
        worst / e0.abs() < 1e-6,
        "stance: relative drift {}",
        worst / e0.abs()
    );

    // Stance with the conservative leg spring (damping off): spring energy joins the total.
    let (kw, l1) = (20_000.0, body.l1);
    let energy_s = |y: &[f64; 6]| energy(y) + 0.5 * kw * (l1 - y[0]).powi(2);
    let mut fs = |_t: f64, y: &[f64; 6]| {
        let f = [kw * (l1 - y[0]), 0.0, 0.0];
        let a = st.accel(&[y[0], y[1], y[2]], &[y[3], y[4], y[5]], &f, false);
        [y[3], y[4], y[5], a[0], a[1], a[2]]
    };
    let e0 = energy_s(&y0);
    let mut worst: f64 = 0.0;
    integrate::<6, _, NoEvent<6>, _>(&mut fs, 0.0, y0, duration, h, None, &mut |_, _, _, y| {
        worst = worst.max((energy_s(y) - e0).abs());
    });
    println!(
        "stance with spring: relative energy drift over the step {:.2e}",
        worst / e0.abs()
    );
    assert!(
        worst / e0.abs() < 1e-6,
        "stance with spring: relative drift {}",
        worst / e0.abs()
    );

    // Swing with the hip at rest: an unforced double pendulum.
    let sw = SwingModel::new(&body);
    let energy_w = |y: &[f64; 4]| {
        sw.kinetic_energy(&[y[0], y[1]], &[y[2], y[3]]) + sw.potential_energy(&[y[0], y[1]])
    };
    let mut fw = |_t: f64, y: &[f64; 4]| {
        let a = sw.accel(&[y[0], y[1]], &[y[2], y[3]], &[0.0; 2], &[0.0; 2], false);
        [y[2], y[3], a[0], a[1]]
    };
    let y0 = [0.4, 0.3, -3.0, 4.0];
    let e0 = energy_w(&y0);
    let mut worst: f64 = 0.0;
    integrate::<4, _, NoEvent<4>, _>(&mut fw, 0.0, y0, duration, h, None, &mut |_, _, _, y| {
        worst = worst.max((energy_w(y) - e0).abs());
    });
    println!(
        "swing: relative energy drift over the step {:.2e}",
        worst / e0.abs()
    );
    assert!(
        worst / e0.abs() < 1e-6,
        "swing: relative drift {}",
        worst / e0.abs()
    );
}
