//! Forward kinematics of the figure against hand-computed positions, the rest pose on the
//! ground, mirror symmetry and the IK helpers.
use gaitfit::events::Side;
use gaitfit::generator::ik::{ankle_for_foot_point, leg_ik};
use gaitfit::generator::skeleton::{
    mirror_vec, Euler, FootPoint, Joint, Landmark, Pose, Skeleton, LANDMARK_COUNT,
};
use glam::{DQuat, DVec3};
use std::f64::consts::FRAC_PI_2;

fn near(a: DVec3, b: DVec3, tol: f64) -> bool {
    (a - b).length() <= tol
}

#[test]
fn rest_pose_stands_on_the_ground_and_is_body_height_tall() {
    for h in [1.5, 1.8, 2.0] {
        let sk = Skeleton::from_height(h, 70.0).unwrap();
        let lm = sk.landmarks(&sk.rest_pose());
        for side in [Side::Left, Side::Right] {
            for l in Landmark::foot(side) {
                assert!(
                    lm[l.index()].y.abs() < 1e-12,
                    "{} at {}",
                    l.name(),
                    lm[l.index()].y
                );
            }
        }
        assert!((lm[Landmark::Vertex.index()].y - h).abs() < 1e-12);
        // Nothing is below the ground and the left side is at −z.
        assert!(lm.iter().all(|p| p.y > -1e-12));
        assert!(lm[Landmark::LHip.index()].z < 0.0 && lm[Landmark::RHip.index()].z > 0.0);
        assert!(lm[Landmark::LToe.index()].x > lm[Landmark::LHeel.index()].x);
    }
}

#[test]
fn fk_of_a_sagittal_pose_matches_hand_computation() {
    let sk = Skeleton::from_height(1.8, 80.0).unwrap();
    let a = sk.anthropometry().clone();
    let (l3, l4, l9) = (a.thigh.length_m, a.shank.length_m, a.foot.ankle_height_m);
    let hh = a.hip_height_m();
    let w = a.hip_width_m / 2.0;
    let mut pose = sk.rest_pose();
    pose.root = DVec3::new(1.0, hh, 0.0);
    // Right hip flexed 90° (thigh horizontal, forward), knee flexed 90° (shank vertical).
    pose.set_euler(Joint::RHip, Euler::sagittal(FRAC_PI_2));
    pose.set_euler(Joint::RKnee, Euler::sagittal(-FRAC_PI_2));
    // Left elbow flexed 90°: forearm horizontal, forward.
    pose.set_euler(Joint::LElbow, Euler::sagittal(FRAC_PI_2));
    let lm = sk.landmarks(&pose);
    let r_hip = DVec3::new(1.0, hh, w);
    assert!(near(lm[Landmark::RHip.index()], r_hip, 1e-12));
    assert!(near(
        lm[Landmark::RKnee.index()],
        r_hip + DVec3::new(l3, 0.0, 0.0),
        1e-12
    ));
    let ankle = r_hip + DVec3::new(l3, -l4, 0.0);
    assert!(near(lm[Landmark::RAnkle.index()], ankle, 1e-12));
    let heel = ankle + DVec3::new(-a.foot.hind_foot_m, -l9, 0.0);
    assert!(near(lm[Landmark::RHeel.index()], heel, 1e-12));
    let toe = ankle + DVec3::new(a.foot.mid_foot_m + a.foot.toe_m, -l9, 0.0);
    assert!(near(lm[Landmark::RToe.index()], toe, 1e-12));
    // Left arm: shoulder at shoulder height, z = −shoulder_width/2; elbow below; wrist forward.
    let sh = DVec3::new(1.0, a.shoulder_height_m(), -a.shoulder_width_m / 2.0);
    assert!(near(lm[Landmark::LShoulder.index()], sh, 1e-12));
    let elbow = sh - DVec3::new(0.0, a.upper_arm.length_m, 0.0);
    assert!(near(lm[Landmark::LElbow.index()], elbow, 1e-12));
    assert!(near(
        lm[Landmark::LWrist.index()],
        elbow + DVec3::new(a.forearm.length_m, 0.0, 0.0),
        1e-12
    ));
    // The left leg did not move.
    assert!(lm[Landmark::LHeel.index()].y.abs() < 1e-12);
}

#[test]
fn fk_of_a_turned_and_tilted_pose_matches_hand_computation() {
    let sk = Skeleton::from_height(1.7, 65.0).unwrap();
    let a = sk.anthropometry().clone();
    let hh = a.hip_height_m();
    let w = a.hip_width_m / 2.0;
    let mut pose = sk.rest_pose();
    // Pelvis turned +90° about y: the front (+x) turns to −z, the right side (+z) to +x.
    pose.set_euler(Joint::Pelvis, Euler::new(0.0, 0.0, FRAC_PI_2));
    let lm = sk.landmarks(&pose);
    assert!(near(
        lm[Landmark::RHip.index()],
        DVec3::new(w, hh, 0.0),
        1e-12
    ));
    let foot_len = a.foot.mid_foot_m + a.foot.toe_m;
    assert!(near(
        lm[Landmark::RToe.index()],
        DVec3::new(w, 0.0, -foot_len),
        1e-12
    ));
    // Right hip abducted: x rotation −30° swings the right thigh's bottom toward +z.
    let mut pose = sk.rest_pose();
    pose.set_euler(Joint::RHip, Euler::new(0.0, -30f64.to_radians(), 0.0));
    let lm = sk.landmarks(&pose);
    let l34 = a.thigh.length_m;
    let knee = DVec3::new(0.0, hh - l34 * 30f64.to_radians().cos(), w + l34 * 0.5);
    assert!(near(lm[Landmark::RKnee.index()], knee, 1e-12));
    // Trunk flexed forward 30° at the lumbar joint (negative z): the vertex moves forward.
    let mut pose = sk.rest_pose();
    pose.set_euler(Joint::Lumbar, Euler::sagittal(-30f64.to_radians()));
    let lm = sk.landmarks(&pose);
    let lumbar = DVec3::new(0.0, hh + a.pelvis_to_lumbar_m, 0.0);
    let up = a.standing_height_m() - lumbar.y;
    let vertex = lumbar + up * DVec3::new(0.5, 3f64.sqrt() / 2.0, 0.0);
    assert!(near(lm[Landmark::Vertex.index()], vertex, 1e-12));
}

#[test]
fn mirrored_pose_gives_mirrored_landmarks() {
    let sk = Skeleton::from_height(1.8, 80.0).unwrap();
    let mut pose = sk.rest_pose();
    pose.root = DVec3::new(0.3, 0.9, 0.05);
    let mut k = 0.1;
    for j in Joint::ALL {
        pose.set_euler(j, Euler::new(k, -0.7 * k, 0.4 * k));
        k += 0.03;
    }
    let lm = sk.landmarks(&pose);
    let mlm = sk.landmarks(&pose.mirrored());
    for l in Landmark::ALL {
        assert!(near(
            mlm[l.mirrored().index()],
            mirror_vec(lm[l.index()]),
            1e-12
        ));
    }
    assert_eq!(lm.len(), LANDMARK_COUNT);
}

#[test]
fn set_world_rotation_and_foot_placement() {
    let sk = Skeleton::from_height(1.8, 80.0).unwrap();
    let mut pose = sk.rest_pose();
    pose.set_euler(Joint::Pelvis, Euler::new(0.1, 0.05, -0.1));
    pose.root = DVec3::new(0.4, 0.88, 0.0);
    // Right foot rolled 20° onto its heel (toes up), heel at a fixed ground point.
    let heel_at = DVec3::new(0.6, 0.0, 0.09);
    let foot = DQuat::from_rotation_z(20f64.to_radians());
    let ankle = ankle_for_foot_point(
        &sk,
        Side::Right,
        FootPoint::Heel,
        heel_at,
        foot,
        DQuat::IDENTITY,
    );
    let forward = pose.rotations[0] * DVec3::X;
    let r = leg_ik(&sk, &mut pose, Side::Right, ankle, forward);
    assert!(r.reached);
    pose.set_world_rotation(Joint::RAnkle, foot);
    let lm = sk.landmarks(&pose);
    assert!(near(lm[Landmark::RHeel.index()], heel_at, 1e-9));
    assert!(lm[Landmark::RToe.index()].y > 0.05);
    let g = sk.forward(&pose);
    assert!(g.rotation(Joint::RAnkle).dot(foot).abs() > 1.0 - 1e-12);
    // Rolling about the metatarsal joint with the toes flat keeps ball and toe on the ground.
    let mut p2 = pose;
    let ball_at = DVec3::new(0.8, 0.0, 0.09);
    let heel_up = DQuat::from_rotation_z(-25f64.to_radians());
    let toe_flat = heel_up.inverse(); // toe segment stays parallel to the ground
    let ankle = ankle_for_foot_point(
        &sk,
        Side::Right,
        FootPoint::Ball,
        ball_at,
        heel_up,
        toe_flat,
    );
    leg_ik(&sk, &mut p2, Side::Right, ankle, DVec3::X);
    p2.set_world_rotation(Joint::RAnkle, heel_up);
    p2[Joint::RMetatarsal] = toe_flat;
    let lm = sk.landmarks(&p2);
    assert!(near(lm[Landmark::RBall.index()], ball_at, 1e-9));
    assert!(lm[Landmark::RToe.index()].y.abs() < 1e-9);
    assert!(lm[Landmark::RHeel.index()].y > 0.05);
}

#[test]
fn pose_index_and_euler_accessors_agree() {
    let mut p = Pose::identity_at(DVec3::ZERO);
    p.set_euler(Joint::LKnee, Euler::sagittal(-0.5));
    assert!((p.euler(Joint::LKnee).z + 0.5).abs() < 1e-12);
    assert_eq!(p[Joint::LKnee], DQuat::from_rotation_z(-0.5));
}

#[test]
fn pelvis_list_sign_lowers_the_right_hip() {
    let sk = Skeleton::from_height(1.8, 80.0).unwrap();
    let mut pose = sk.rest_pose();
    pose.set_euler(Joint::Pelvis, Euler::new(0.0, 0.1, 0.0));
    let lm = sk.landmarks(&pose);
    assert!(lm[Landmark::RHip.index()].y < lm[Landmark::LHip.index()].y);
    // Ankle +x on the right foot: inversion (lateral, +z, edge down).
    let mut pose = sk.rest_pose();
    pose.set_euler(Joint::RAnkle, Euler::new(0.0, 0.2, 0.0));
    let g = sk.forward(&pose);
    assert!((g.rotation(Joint::RAnkle) * DVec3::Z).y < 0.0);
}

mod properties {
    use super::*;
    use proptest::prelude::*;

    fn angles() -> impl Strategy<Value = Vec<(f64, f64, f64)>> {
        proptest::collection::vec((-3.0f64..3.0, -1.5f64..1.5, -3.0f64..3.0), 22)
    }

    proptest! {
        #![proptest_config(ProptestConfig::with_cases(64))]

        /// Any pose keeps every segment length and every landmark's distance to its joint; the
        /// Euler decomposition reproduces every rotation.
        #[test]
        fn fk_is_rigid_and_euler_round_trips(a in angles(), root in (-5.0f64..5.0, 0.0f64..2.0, -5.0f64..5.0)) {
            let sk = Skeleton::from_height(1.75, 70.0).unwrap();
            let mut pose = sk.rest_pose();
            pose.root = DVec3::new(root.0, root.1, root.2);
            for (j, (z, x, y)) in Joint::ALL.iter().zip(a.iter()) {
                pose.set_euler(*j, Euler::new(*z, *x, *y));
                let back = pose.euler(*j).to_quat();
                prop_assert!(back.dot(pose[*j]).abs() > 1.0 - 1e-12);
            }
            let g = sk.forward(&pose);
            for j in Joint::ALL.iter().skip(1) {
                let p = j.parent().unwrap();
                let d = (g.position(*j) - g.position(p)).length();
                prop_assert!((d - sk.offset(*j).length()).abs() < 1e-12);
            }
            let lm = sk.landmarks(&pose);
            for l in Landmark::ALL {
                let (j, off) = sk.landmark_attachment(l);
                prop_assert!(((lm[l.index()] - g.position(j)).length() - off.length()).abs() < 1e-12);
            }
            let rest = sk.landmarks(&sk.rest_pose());
            // Heel–toe distance is rigid only with the toe joint at rest; check heel–ankle.
            let ha = (lm[Landmark::LHeel.index()] - lm[Landmark::LAnkle.index()]).length();
            let ha0 = (rest[Landmark::LHeel.index()] - rest[Landmark::LAnkle.index()]).length();
            prop_assert!((ha - ha0).abs() < 1e-12);
        }
    }
}
