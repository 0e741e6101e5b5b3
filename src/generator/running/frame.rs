//! One frame: evaluates a planned step at a time into the shared skeleton [`Pose`] (root
//! translation + local joint rotations), with the contact flags and the foot points the
//! generator computed (which equal the skeleton's forward kinematics).
use glam::{DQuat, DVec3};

use super::dims::{
    leg_fk, leg_ik, leg_orientations, pelvis_orientation, LegAngles, LegPoints, RunnerDims,
};
use super::phase::{hip_at, orient_at, pelvis_at, stance_leg, StanceMode};
use super::state::{StepKind, StepPlan};
use super::upper_body::{arm_drivers, fill_upper};
use crate::generator::curves::hermite;
use crate::generator::skeleton::{Joint, Pose};

/// Per-frame facts besides the pose.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct FrameInfo {
    /// Whether each foot (`[left, right]`) is on the ground.
    pub contact: [bool; 2],
    /// Foot and leg points (`[left, right]`), world, m.
    pub legs: [LegPoints; 2],
    /// Leg angles (`[left, right]`).
    pub angles: [LegAngles; 2],
    /// Mode of the stance foot (`None` in flight).
    pub stance_mode: Option<StanceMode>,
    /// The stance hip was out of reach in this frame.
    pub out_of_reach: bool,
}

#[inline]
fn idx(sign: f64) -> usize {
    if sign > 0.0 {
        1
    } else {
        0
    }
}

#[inline]
fn smooth01(s: f64) -> f64 {
    let s = s.clamp(0.0, 1.0);
    s * s * (3.0 - 2.0 * s)
}

/// The swing foot of a stop: Cartesian ankle path, sole pitch to flat, leg by IK.
#[inline]
fn stop_swing(plan: &StepPlan, d: &RunnerDims, t: f64, hip: DVec3) -> (LegAngles, LegPoints, bool) {
    let sp = &plan.stop;
    if t >= sp.t_land {
        let (a, _) = leg_ik(d, hip, sp.print.flat_ankle(d), 0.0, 0.0);
        return (a, leg_fk(d, hip, &a), true);
    }
    let seg = if t < sp.ankle[0].t1 {
        &sp.ankle[0]
    } else {
        &sp.ankle[1]
    };
    let (ankle, _) = seg.eval(t);
    let s = smooth01(t / (0.8 * sp.t_land));
    let pitch = sp.pitch0 * (1.0 - s);
    let (meta, _) = hermite(0.0, 0.8 * sp.t_land, sp.meta0, 0.0, 0.0, 0.0, t);
    let (a, _) = leg_ik(d, hip, ankle, pitch, meta.max(0.0));
    (a, leg_fk(d, hip, &a), false)
}

/// Evaluates `plan` at step time `t` (0 ≤ t ≤ t_step) into `pose`.
pub fn eval_frame(plan: &StepPlan, d: &RunnerDims, t: f64, pose: &mut Pose) -> FrameInfo {
    let s = plan.s;
    let (pelvis, _) = pelvis_at(plan, t);
    let (yaw, roll) = orient_at(plan, t);
    let q_pelvis = pelvis_orientation(yaw, roll);
    let hip_st = hip_at(d, pelvis, yaw, roll, s);
    let hip_sw = hip_at(d, pelvis, yaw, roll, -s);
    let in_support = plan.kind == StepKind::Stop || t <= plan.t_stance;

    // Stance leg: phase constraints while on the ground, hind-leg track in flight.
    let (st_ang, st_pts, mode, out) = if in_support {
        let e = stance_leg(plan, d, t, hip_st);
        (e.angles, e.points, Some(e.mode), e.out_of_reach)
    } else {
        let (a, _) = plan.hind.eval(t);
        (a, leg_fk(d, hip_st, &a), None, false)
    };
    // Swing leg.
    let (sw_ang, sw_pts, sw_contact) = if plan.kind == StepKind::Stop {
        stop_swing(plan, d, t, hip_sw)
    } else if plan.kind == StepKind::Start && t < plan.stop.t_land {
        let (ankle, _) = plan.stop.ankle[0].eval(t);
        let (a, _) = leg_ik(d, hip_sw, ankle, 0.0, 0.0);
        (a, leg_fk(d, hip_sw, &a), t <= 0.0)
    } else {
        let (a, _) = plan.swing.eval(t);
        (
            a,
            leg_fk(d, hip_sw, &a),
            plan.kind == StepKind::Start && t <= 0.0,
        )
    };

    pose.root = pelvis;
    pose.rotations[Joint::Pelvis.index()] = q_pelvis;
    let inv_pelvis = q_pelvis.inverse();
    for (sign, ang) in [(s, &st_ang), (-s, &sw_ang)] {
        let [thigh, shank, foot, _] = leg_orientations(ang);
        let [hip, knee, ankle, mtp] = if sign > 0.0 {
            [Joint::RHip, Joint::RKnee, Joint::RAnkle, Joint::RMetatarsal]
        } else {
            [Joint::LHip, Joint::LKnee, Joint::LAnkle, Joint::LMetatarsal]
        };
        pose.rotations[hip.index()] = inv_pelvis * thigh;
        pose.rotations[knee.index()] = DQuat::from_rotation_z(-ang.knee);
        pose.rotations[ankle.index()] = shank.inverse() * foot;
        pose.rotations[mtp.index()] = DQuat::from_rotation_z(ang.meta);
    }

    fill_upper(plan, t, yaw, roll, arm_drivers(plan, t), pose);

    let mut info = FrameInfo {
        contact: [false; 2],
        legs: [LegPoints::default(); 2],
        angles: [LegAngles::default(); 2],
        stance_mode: if in_support { mode } else { None },
        out_of_reach: out,
    };
    info.contact[idx(s)] = in_support;
    info.contact[idx(-s)] = sw_contact;
    info.legs[idx(s)] = st_pts;
    info.legs[idx(-s)] = sw_pts;
    info.angles[idx(s)] = st_ang;
    info.angles[idx(-s)] = sw_ang;
    info
}
