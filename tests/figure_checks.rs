//! The shared generator checks on synthetic motions built to pass and built to fail, with the
//! expected worst values computed by hand.
use gaitfit::events::Side;
use gaitfit::generator::checks::{
    contact_on_ground, continuity, double_support_timing, flight_timing, ground_penetration,
    stance_sliding, step_timings, swing_clearance, symmetry, ContinuityOptions,
};
use gaitfit::generator::ik::{ankle_for_foot_point, leg_ik};
use gaitfit::generator::motion::{Motion, MotionMetadata};
use gaitfit::generator::skeleton::{Euler, FootPoint, Joint, Landmark, Pose, Skeleton};
use glam::{DQuat, DVec3};
use proptest::prelude::*;
use std::f64::consts::PI;

const FPS: f64 = 120.0;

fn skeleton() -> Skeleton {
    Skeleton::from_height(1.8, 75.0).unwrap()
}

/// `frames` frames built by `f(frame, pose, contacts)` starting from the rest pose with both
/// feet in contact.
fn build(frames: usize, mut f: impl FnMut(usize, &Skeleton, &mut Pose, &mut [bool; 2])) -> Motion {
    let sk = skeleton();
    let mut m = Motion::new(sk.clone(), FPS, MotionMetadata::new("test", None)).unwrap();
    for i in 0..frames {
        let mut p = sk.rest_pose();
        let mut c = [true, true];
        f(i, &sk, &mut p, &mut c);
        m.push_frame(p, c);
    }
    m
}

#[test]
fn sliding_passes_when_standing_and_fails_when_gliding() {
    let still = build(50, |_, _, _, _| {});
    let r = stance_sliding(&still, 0.002, 0.002);
    assert!(r.passed && r.worst == 0.0 && r.examined > 0, "{r}");
    // The whole figure glides 0.1 mm per frame with both feet flagged in contact.
    let glide = build(50, |i, _, p, _| p.root.x += 1e-4 * i as f64);
    let r = stance_sliding(&glide, 0.002, 0.002);
    assert!(!r.passed, "{r}");
    assert!((r.worst - 49e-4).abs() < 1e-12, "{r}");
    assert_eq!(r.frame, Some(49));
    // Gliding while the flags say "swing" is not sliding.
    let flying = build(50, |i, _, p, c| {
        p.root.x += 1e-4 * i as f64;
        *c = [false, false];
    });
    assert!(stance_sliding(&flying, 0.002, 0.002).passed);
}

#[test]
fn rolling_about_the_heel_does_not_slide() {
    // Right foot rolls from 20° toes-up to flat about a fixed heel point while the hip moves
    // forward; the toes and ball come down onto the ground without sliding.
    let heel_at = DVec3::new(0.2, 0.0, 0.0905);
    let m = build(30, |i, sk, p, c| {
        c[0] = false; // the left leg swings, lifted clear of the ground
        p.set_euler(Joint::LHip, Euler::sagittal(0.3));
        p.set_euler(Joint::LKnee, Euler::sagittal(-0.8));
        p.set_euler(Joint::LAnkle, Euler::sagittal(0.5));
        let a = 20f64.to_radians() * (1.0 - i as f64 / 29.0);
        p.root.x = 0.05 + 0.004 * i as f64;
        p.root.y -= 0.02;
        let heel_at = DVec3::new(heel_at.x, 0.0, sk.anthropometry().hip_width_m / 2.0);
        let foot = DQuat::from_rotation_z(a);
        let ankle = ankle_for_foot_point(
            sk,
            Side::Right,
            FootPoint::Heel,
            heel_at,
            foot,
            DQuat::IDENTITY,
        );
        leg_ik(sk, p, Side::Right, ankle, DVec3::X);
        p.set_world_rotation(Joint::RAnkle, foot);
    });
    let r = stance_sliding(&m, 0.002, 0.002);
    assert!(r.passed, "{r}");
    assert!(r.worst < 1e-9, "{r}");
    let g = ground_penetration(&m, 0.001);
    assert!(g.passed, "{g}");
}

#[test]
fn penetration_reports_depth_frame_and_point() {
    let m = build(20, |i, _, p, _| {
        if i == 7 {
            p.root.y -= 0.003;
        }
    });
    let r = ground_penetration(&m, 0.001);
    assert!(!r.passed, "{r}");
    assert!((r.worst - 0.003).abs() < 1e-12);
    assert_eq!(r.frame, Some(7));
    assert!(r.subject.as_deref().unwrap().contains("heel"), "{r}");
    let ok = build(20, |_, _, _, _| {});
    let r = ground_penetration(&ok, 0.001);
    assert!(r.passed && r.worst.abs() < 1e-12, "{r}");
}

#[test]
fn contact_flags_must_touch_the_ground() {
    let m = build(20, |i, _, p, _| {
        if i >= 10 {
            p.root.y += 0.01;
        }
    });
    let r = contact_on_ground(&m, 0.002);
    assert!(
        !r.passed && (r.worst - 0.01).abs() < 1e-12 && r.frame == Some(10),
        "{r}"
    );
    assert!(contact_on_ground(&build(5, |_, _, _, _| {}), 0.002).passed);
}

/// The right foot, flat, lifted by a half-sine of `amplitude` during frames 10..50.
fn lift(amplitude: f64) -> Motion {
    build(60, |i, sk, p, c| {
        if (10..50).contains(&i) {
            c[1] = false;
            let h = amplitude * (PI * (i - 10) as f64 / 40.0).sin();
            let rest = sk.landmarks(&sk.rest_pose())[Landmark::RAnkle.index()];
            leg_ik(sk, p, Side::Right, rest + DVec3::new(0.0, h, 0.0), DVec3::X);
            p.set_world_rotation(Joint::RAnkle, DQuat::IDENTITY);
        }
    })
}

#[test]
fn swing_clearance_measures_the_central_part_of_the_swing() {
    let m = lift(0.05);
    let r = swing_clearance(&m, 0.5, 0.02);
    // Central half: frames 20..30+; the lowest is at frame 20, h = 0.05·sin(π/4).
    assert!(r.passed, "{r}");
    assert!((r.worst - 0.05 * (PI / 4.0).sin()).abs() < 1e-9, "{r}");
    assert_eq!(r.frame, Some(20));
    let low = lift(0.002);
    let r = swing_clearance(&low, 0.5, 0.005);
    assert!(!r.passed, "{r}");
    // A foot flagged in swing with no complete swing examined passes vacuously.
    let r = swing_clearance(&build(5, |_, _, _, _| {}), 0.5, 0.01);
    assert!(r.passed && r.examined == 0);
}

#[test]
fn continuity_flags_a_jump_but_not_smooth_motion() {
    let smooth = build(80, |i, _, p, _| {
        let t = i as f64 / FPS;
        p.root.x = 1.2 * t;
        p.set_euler(
            Joint::RKnee,
            Euler::sagittal(-0.6 * (1.0 - (5.0 * t).cos())),
        );
        p.set_euler(Joint::Pelvis, Euler::new(0.0, 0.0, 3.0 + 2.0 * t)); // wraps past π
    });
    let r = continuity(&smooth, &ContinuityOptions::default());
    assert!(r.passed, "{r}");
    let jumpy = build(80, |i, _, p, _| {
        let t = i as f64 / FPS;
        p.root.x = 1.2 * t + if i >= 30 { 0.1 } else { 0.0 };
    });
    let r = continuity(&jumpy, &ContinuityOptions::default());
    assert!(!r.passed, "{r}");
    assert_eq!(r.frame, Some(29));
    // One knee angle jumping by 10° in one frame.
    let knee = build(80, |i, _, p, _| {
        let t = i as f64 / FPS;
        let jump = if i >= 50 { 0.17 } else { 0.0 };
        p.set_euler(Joint::LKnee, Euler::sagittal(-0.5 * t - jump));
    });
    let r = continuity(&knee, &ContinuityOptions::default());
    assert!(!r.passed && r.frame == Some(49), "{r}");
}

/// A symmetric gait: every right-side curve is the mirrored left-side curve one step later.
/// `knee_bias` breaks the symmetry.
fn gait(step_s: f64, knee_bias: f64) -> Motion {
    let w = PI / step_s;
    build(300, |i, sk, p, _| {
        let t = i as f64 / FPS;
        p.root = DVec3::new(
            1.3 * t,
            sk.hip_height() - 0.03 + 0.01 * (2.0 * w * t).cos(),
            0.02 * (w * t).sin(),
        );
        p.set_euler(
            Joint::Pelvis,
            Euler::new(
                0.02 * (2.0 * w * t).cos(),
                0.05 * (w * t).sin(),
                0.1 * (w * t).sin(),
            ),
        );
        p.set_euler(
            Joint::Lumbar,
            Euler::new(-0.05, 0.02 * (w * t).sin(), -0.05 * (w * t).sin()),
        );
        for (side, phase, sign) in [(Side::Right, 0.0, 1.0), (Side::Left, PI, -1.0)] {
            let ph = w * t + phase;
            let [hip, knee, ankle, _] = Joint::leg(side);
            let [_, shoulder, elbow, _] = Joint::arm(side);
            p.set_euler(
                hip,
                Euler::new(
                    0.4 * ph.sin(),
                    sign * 0.05 * ph.sin(),
                    sign * 0.1 * ph.cos(),
                ),
            );
            let bias = if side == Side::Right { knee_bias } else { 0.0 };
            p.set_euler(
                knee,
                Euler::sagittal(-0.3 * (1.0 + (ph + 1.0).sin()) - bias),
            );
            p.set_euler(
                ankle,
                Euler::new(0.2 * (ph + 2.0).sin(), sign * 0.03 * ph.cos(), 0.0),
            );
            p.set_euler(shoulder, Euler::new(-0.3 * ph.sin(), sign * 0.1, 0.0));
            p.set_euler(elbow, Euler::sagittal(0.5 + 0.2 * ph.sin()));
        }
    })
}

#[test]
fn symmetry_passes_for_a_mirrored_gait_and_fails_when_one_knee_is_off() {
    // Step of exactly 60 frames.
    let m = gait(0.5, 0.0);
    let r = symmetry(&m, 0..200, 0.5, 1e-9, 1e-9);
    assert!(
        r.landmarks.passed && r.joints.passed,
        "{} / {}",
        r.landmarks,
        r.joints
    );
    assert!(r.landmarks.examined > 0 && r.joints.examined > 0);
    // A step that is not a whole number of frames: interpolation error only.
    let m = gait(0.4567, 0.0);
    let r = symmetry(&m, 0..200, 0.4567, 1e-3, 1e-3);
    assert!(
        r.landmarks.passed && r.joints.passed,
        "{} / {}",
        r.landmarks,
        r.joints
    );
    let bad = gait(0.5, 0.1);
    let r = symmetry(&bad, 0..200, 0.5, 1e-3, 1e-3);
    assert!(!r.joints.passed && !r.landmarks.passed);
    assert!((r.joints.worst - 0.1).abs() < 1e-9, "{}", r.joints);
    assert!(r.joints.subject.as_deref().unwrap().contains("knee"));
}

#[test]
fn flight_and_double_support_from_contact_flags() {
    // Running: 40-frame steps, 25 frames of single support then 15 of flight.
    let run = build(200, |i, _, _, c| {
        let k = i % 80;
        *c = [(40..65).contains(&k), k < 25];
    });
    let steps = step_timings(&run);
    assert!(steps.len() >= 3);
    for s in &steps {
        assert!((s.duration_s - 40.0 / FPS).abs() < 1e-12);
        assert!((s.flight_s - 15.0 / FPS).abs() < 1e-12);
        assert_eq!(s.double_support_s, 0.0);
    }
    assert!(flight_timing(&run, 15.0 / FPS, 0.5 / FPS).passed);
    let r = flight_timing(&run, 0.2, 1.0 / FPS);
    assert!(!r.passed && (r.worst - (0.2 - 0.125)).abs() < 1e-12, "{r}");
    // Walking: 60-frame steps with 12 frames of double support.
    let walk = build(240, |i, _, _, c| {
        let k = i % 120;
        *c = [!(12..60).contains(&k), k < 72];
    });
    assert!(double_support_timing(&walk, 12.0 / FPS, 0.5 / FPS).passed);
    assert!(flight_timing(&walk, 0.0, 0.0).passed);
    assert!(!double_support_timing(&walk, 0.2, 1.0 / FPS).passed);
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(24))]
    /// The sliding check reports exactly the drift imposed on a flat stance foot.
    #[test]
    fn sliding_reports_the_imposed_drift(dx in -0.01f64..0.01, dz in -0.01f64..0.01, n in 5usize..40) {
        let m = build(n, |i, _, p, _| {
            let u = i as f64 / (n - 1) as f64;
            p.root += DVec3::new(dx * u, 0.0, dz * u);
        });
        let r = stance_sliding(&m, 0.002, 0.002);
        let expected = dx.hypot(dz);
        prop_assert!((r.worst - expected).abs() < 1e-12);
        prop_assert_eq!(r.passed, expected <= 0.002);
    }
}
