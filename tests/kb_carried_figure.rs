//! The carried Ko–Badler variant drawn on gaitfit's figure (issue 21 item 5): the motion's joint
//! angles — measured here from the skeleton's joint centres and foot points — are the angles the
//! comparison scores for the carried variant ([`carried_angles`]), and the feet are the paper's,
//! so the stance foot does not slide or sink (the shared generator checks). Property-tested over
//! random heights, step lengths and perturbed carried curves on the bundled (Winter) prototype, and on the
//! prototype's own measured curves.
use gaitfit::events::Side;
use gaitfit::generator::checks::{ground_penetration, stance_sliding};
use gaitfit::generator::generalize::angles::SAMPLES;
use gaitfit::generator::generalize::carried::{carried_angles, carried_pose, Carried};
use gaitfit::generator::generalize::figure::{metadata, walk_motion, walk_motion_with, StepPlan};
use gaitfit::generator::generalize::prototype::Prototype;
use gaitfit::generator::generalize::{default_alpha, Anthropometry, Generalizer};
use gaitfit::generator::motion::Motion;
use gaitfit::generator::skeleton::{Landmark, Pose, Skeleton};
use glam::DVec3;
use rand::{Rng, SeedableRng};

/// Thigh, knee, ankle (rad) of one leg in frame `i`, from the skeleton's landmarks only: thigh
/// from the vertical (pelvis centre — the midpoint of both hip joints — → knee, as the measured
/// and carried angles define it), knee flexion = thigh − shank, ankle = sole angle − shank, the
/// sole angle being the heel→ankle line's angle less its angle in the neutral pose.
fn frame_angles(m: &Motion, i: usize, side: Side, neutral_sole: f64) -> [f64; 3] {
    let (_, k, a, heel) = match side {
        Side::Left => (
            Landmark::LHip,
            Landmark::LKnee,
            Landmark::LAnkle,
            Landmark::LHeel,
        ),
        Side::Right => (
            Landmark::RHip,
            Landmark::RKnee,
            Landmark::RAnkle,
            Landmark::RHeel,
        ),
    };
    let (h, k, a, e) = (
        0.5 * (m.landmark(i, Landmark::LHip) + m.landmark(i, Landmark::RHip)),
        m.landmark(i, k),
        m.landmark(i, a),
        m.landmark(i, heel),
    );
    let thigh = (k.x - h.x).atan2(h.y - k.y);
    let shank = (a.x - k.x).atan2(k.y - a.y);
    let sole = (a.y - e.y).atan2(a.x - e.x) - neutral_sole;
    [thigh, thigh - shank, sole - shank]
}

fn neutral_sole(sk: &Skeleton, side: Side) -> f64 {
    let lm = sk.landmarks(&Pose::identity_at(DVec3::ZERO));
    let (a, e) = match side {
        Side::Left => (Landmark::LAnkle, Landmark::LHeel),
        Side::Right => (Landmark::RAnkle, Landmark::RHeel),
    };
    let (a, e) = (lm[a.index()], lm[e.index()]);
    (a.y - e.y).atan2(a.x - e.x)
}

/// Draws `lengths` (1 s per step at 100 frames/s, so step k's frames are the comparison's grid)
/// in both variants and checks the carried one.
fn check(p: &Prototype, c: &Carried, height: f64, lengths: &[f64]) -> f64 {
    let alpha = default_alpha();
    let g = Generalizer::new(p.walk.clone(), p.mu(alpha).unwrap()).unwrap();
    let sk = Skeleton::from_height(height, 70.0).unwrap();
    let body = Anthropometry::from_figure(sk.anthropometry()).unwrap();
    let plan: Vec<StepPlan> = lengths
        .iter()
        .map(|&l| StepPlan {
            step_length_m: l,
            duration_s: 1.0,
        })
        .collect();
    let meta = || metadata(&g, height, "test");
    let (paper, _) = walk_motion(&g, sk.clone(), &plan, Side::Right, 100.0, meta()).unwrap();
    let (m, r) =
        walk_motion_with(&g, Some(c), sk.clone(), &plan, Side::Right, 100.0, meta()).unwrap();
    assert!(
        r.max_foot_mismatch_m < 1e-7,
        "feet off by {}",
        r.max_foot_mismatch_m
    );
    assert_eq!(r.unreachable_frames, 0);
    // The feet are the paper's, frame by frame.
    for i in 0..m.len() {
        for l in [
            Landmark::LHeel,
            Landmark::RHeel,
            Landmark::LBall,
            Landmark::RBall,
            Landmark::LToe,
            Landmark::RToe,
        ] {
            // Sagittal: a turned / listed pelvis brings the hip joints (and the legs hanging in
            // their sagittal planes) in by half the hip width times 1 − cos(turn)·cos(list):
            // ≈ 1.3 mm for this test's offsets up to 1.5 cm on a ≈ 9 cm half width.
            let (a, b) = (m.landmark(i, l), paper.landmark(i, l));
            let d = (a.x - b.x).hypot(a.y - b.y);
            assert!(d < 1e-7, "frame {i} {l:?}: {d} m from the paper's foot");
            assert!(
                (a.z - b.z).abs() < 3e-3,
                "frame {i} {l:?}: {} m aside",
                a.z - b.z
            );
        }
    }
    let s = stance_sliding(&m, 0.002, 0.002);
    assert!(s.passed && s.examined > 0, "{s}");
    let pen = ground_penetration(&m, 0.001);
    assert!(pen.passed, "{pen}");
    // The motion's angles are the comparison's carried angles on the grid.
    let steps = g.chain(&body, lengths).unwrap();
    let mut worst: f64 = 0.0;
    let mut hip_moved: f64 = 0.0;
    for (k, w) in steps.iter().enumerate() {
        let want = carried_angles(w, g.mu(), c).unwrap();
        let stance = if k % 2 == 0 { Side::Right } else { Side::Left };
        for j in 0..SAMPLES {
            let i = 100 * k + j;
            // The frame at a step's end is the next step's first.
            if i >= m.len() || (j == SAMPLES - 1 && k + 1 < steps.len()) {
                break;
            }
            for (leg, side) in [(0, stance), (1, stance.opposite())] {
                let got = frame_angles(&m, i, side, neutral_sole(&sk, side));
                let n = leg * SAMPLES + j;
                let exp = [want.hip[n], want.knee[n], want.ankle[n]];
                for q in 0..3 {
                    worst = worst.max((got[q] - exp[q]).abs());
                }
            }
            // Each leg hangs from its own hip joint: the stance hip `hip_offset` ahead of / above
            // the pelvis centre, the swing hip as far behind / below.
            let off = c.hip_offset_at(w, j as f64 / (SAMPLES - 1) as f64);
            let (hs, ho) = match stance {
                Side::Right => (Landmark::RHip, Landmark::LHip),
                Side::Left => (Landmark::LHip, Landmark::RHip),
            };
            let d = 0.5 * (m.landmark(i, hs) - m.landmark(i, ho));
            assert!(
                (d.x - off[0]).abs() < 1e-9 && (d.y - off[1]).abs() < 1e-9,
                "frame {i}: hips {d:?} apart, carried offset {off:?}"
            );
            hip_moved = hip_moved.max(
                m.landmark(i, Landmark::Pelvis)
                    .distance(paper.landmark(i, Landmark::Pelvis)),
            );
        }
    }
    // The hip joins across steps (the paper's feet and the preferred angles both do).
    for k in 1..steps.len() {
        let a = carried_pose(&steps[k - 1], g.mu(), 1.0, c).unwrap().hip;
        let b = carried_pose(&steps[k], g.mu(), 0.0, c).unwrap().hip;
        let x0 = lengths[k - 1];
        let d = (a[0] - x0 - b[0]).hypot(a[1] - b[1]);
        assert!(d < 1e-5, "hip jumps {d} m between steps {k} and {}", k + 1);
    }
    // 2e-4 rad (0.01°): the skeleton's two-link IK places the feet to 1e-7 m, and within
    // ~1e-5 m of a straight knee the knee angle moves ~200 rad per metre of hip–ankle distance.
    assert!(
        worst < 2e-4,
        "motion angles {worst} rad from the carried angles"
    );
    hip_moved
}

#[test]
fn perturbed_curves_are_drawn_as_compared_and_the_feet_stay_the_papers() {
    let p = Prototype::bundled();
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(21);
    let mut prng = rand_chacha::ChaCha8Rng::seed_from_u64(7);
    let mut moved: f64 = 0.0;
    for case in 0..6 {
        // Smooth perturbations up to ~8°: a few harmonics over the stride.
        let mut curve = |amp: f64| -> Vec<f64> {
            let (a1, a2, ph1, ph2) = (
                rng.random_range(-amp..amp),
                rng.random_range(-amp..amp),
                rng.random_range(0.0..6.3),
                rng.random_range(0.0..6.3),
            );
            (0..2 * SAMPLES)
                .map(|i| {
                    let s = i as f64 / (2 * SAMPLES - 1) as f64 * std::f64::consts::TAU;
                    a1 * (s + ph1).sin() + a2 * (2.0 * s + ph2).sin()
                })
                .collect()
        };
        // Winter's measured curves, perturbed.
        let own = p.angles.as_ref().unwrap();
        let add = |a: &[f64], d: Vec<f64>| a.iter().zip(d).map(|(x, y)| x + y).collect::<Vec<_>>();
        let c = Carried::from_curves(
            add(&own.hip, curve(0.07)),
            add(&own.knee, curve(0.14)),
            add(&own.ankle, curve(0.1)),
        )
        .unwrap();
        // Every other case carries a pelvis (rotation and list, up to ~1.5 cm at the hips; drawn
        // from its own generator so the cases' curves, heights and lengths stay as they were).
        let c = if case % 2 == 1 {
            let (ax, ay, ph) = (
                prng.random_range(0.005..0.015),
                prng.random_range(0.003..0.01),
                prng.random_range(0.0..6.3),
            );
            let stride: Vec<[f64; 2]> = (0..2 * SAMPLES)
                .map(|i| {
                    let s = i as f64 / (2 * SAMPLES - 1) as f64 * std::f64::consts::TAU;
                    [ax * (s + ph).cos(), ay * (s + 2.0 * ph).sin()]
                })
                .collect();
            c.with_hip_offset(&stride, p.walk.step_length(), p.walk.body().leg_length())
                .unwrap()
        } else {
            c
        };
        let height = rng.random_range(1.55..1.95);
        let base = p.walk.step_length() * height / 1.75;
        let lengths: Vec<f64> = (0..4)
            .map(|_| base * rng.random_range(0.85..1.15))
            .collect();
        moved = moved.max(check(&p, &c, height, &lengths));
        eprintln!("case {case}: height {height:.3} m, hip moved up to {moved:.4} m");
    }
    // The variant does something: the hip leaves the paper's.
    assert!(moved > 0.005, "hip moved at most {moved} m");
}

#[test]
fn the_bundled_prototypes_own_curves_are_drawn_as_compared() {
    let p = Prototype::bundled();
    let c = p
        .carried()
        .unwrap()
        .expect("the bundled prototype carries its angles");
    check(&p, &c, 1.8, &[0.75, 0.8, 0.7, 0.78]);
}
