//! Upper body (§3.3.3): torso tilt rising with speed and sway (forward maximum at mid-support,
//! backward at toe off), spine compensation of pelvic rotation and list so the head points
//! straight ahead (list over the lumbar spine; rotation "towards the pelvis" below T7 and
//! counter to it above, by the shoulder-rotation attribute), arm swing driven by the opposite
//! leg (its hip angle on the forward swing, its hip–ankle vector on the backward swing) and
//! elbow flexion between its minimum (back of the swing) and maximum (front).
//!
//! The skeleton has spine joints at L5/S1 (`lumbar`), T12/L1 (`thoracic_lower`), T7
//! (`thoracic_upper`), C7/T1 (`neck`) and C1 (`head`). World targets per segment (yaw, roll,
//! pitch; pelvis ψ, ρ; tilt τ; counter-rotation c): lumbar segment (ψ/2, ρ/2, −τ/2); thoracic
//! lower (0, 0, −τ); thoracic upper, above T7 (−cψ, 0, −τ); neck (−cψ/2, 0, −τ/2); head upright
//! and facing forward. Local rotations are parent⁻¹ · child, so the head is exactly level.
use glam::{DQuat, DVec2};

use super::curves::hermite;
use super::dims::{pitch_from_down, LegAngles, LegPoints};
use super::state::{StepKind, StepPlan, UpperAttrs};
use crate::generator::skeleton::{Joint, Pose};

#[inline]
fn smooth01(s: f64) -> f64 {
    let s = s.clamp(0.0, 1.0);
    s * s * (3.0 - 2.0 * s)
}

#[inline]
fn world(yaw: f64, roll: f64, pitch: f64) -> DQuat {
    DQuat::from_rotation_y(yaw) * DQuat::from_rotation_x(roll) * DQuat::from_rotation_z(pitch)
}

/// The arm-swing driver of one leg (rad, positive forward): §3.3.3 drives the forward swing of
/// the arm by the opposite leg's hip (thigh) angle and the backward swing by its hip–ankle
/// vector. The switch is made smooth: pure hip–ankle angle from heel strike to mid-support,
/// blending into the thigh angle from mid-support through toe off to the next mid-support
/// (when the leg swings), pure thigh angle until the swing leg's mid-support, and blending back
/// into the hip–ankle angle until heel strike. `beta` is the weight of the hip–ankle angle.
#[inline]
pub fn arm_driver(angles: &LegAngles, points: &LegPoints, beta: f64) -> f64 {
    let ha = points.ankle - points.hip;
    let hip_ankle = pitch_from_down(DVec2::new(ha.x, ha.y));
    angles.pitch + beta * (hip_ankle - angles.pitch)
}

/// The hip–ankle weight of the arm driver for the stance leg (`stance = true`) or the swing
/// leg of a step at time `t` (see [`arm_driver`]).
#[inline]
pub fn arm_beta(plan: &StepPlan, t: f64, stance: bool) -> f64 {
    let span = (plan.t_step - plan.t_ms).max(1e-6);
    let s = smooth01((t - plan.t_ms) / span);
    if stance {
        1.0 - s
    } else {
        s
    }
}

/// Upper-body attributes in force at step time `t` (blended from the previous step's over the
/// step; toward rest over a stop).
#[inline]
pub fn upper_at(plan: &StepPlan, t: f64) -> UpperAttrs {
    let target = match plan.kind {
        StepKind::Stop => {
            let e = &plan.eff;
            [
                0.0,
                0.0,
                0.0,
                e.elbow_min,
                e.elbow_min,
                0.0,
                e.arm_abduction,
            ]
        }
        _ => super::state::upper_attrs(&plan.eff),
    };
    // Over the whole step: at high step frequencies the support lasts only a few frames, and
    // a blend over it alone would snap the arms to a new parameter set.
    let s = smooth01(t / plan.t_step.max(1e-6));
    let mut u = plan.upper0;
    for (a, b) in u.iter_mut().zip(target.iter()) {
        *a += s * (b - *a);
    }
    u
}

/// Sway phase at `t` (piecewise linear through the plan's keys).
#[inline]
fn sway_phase(plan: &StepPlan, t: f64) -> f64 {
    let k = &plan.sway;
    if t <= k[0].0 {
        return k[0].1;
    }
    for i in 0..3 {
        if t <= k[i + 1].0 || i == 2 {
            let (a, b) = (k[i], k[i + 1]);
            let s = if b.0 > a.0 {
                ((t - a.0) / (b.0 - a.0)).clamp(0.0, 1.0)
            } else {
                1.0
            };
            return a.1 + s * (b.1 - a.1);
        }
    }
    k[3].1
}

/// Sets the spine, neck, head and arm joints of `pose`.
///
/// `drivers[i]` is the arm-swing driver of leg `i` (`[left, right]`); the left arm follows the
/// right leg and vice versa.
#[inline]
pub fn fill_upper(
    plan: &StepPlan,
    t: f64,
    yaw: f64,
    roll: f64,
    drivers: [f64; 2],
    pose: &mut Pose,
) {
    let u = upper_at(plan, t);
    let [tilt, sway, swing, el_min, el_max, counter, abd] = u;
    let lean = tilt + sway * sway_phase(plan, t).cos();
    let pelvis = pose.rotations[Joint::Pelvis.index()];
    let w_lumbar = world(0.5 * yaw, 0.5 * roll, -0.5 * lean);
    let w_tl = world(0.0, 0.0, -lean);
    let w_tu = world(-counter * yaw, 0.0, -lean);
    let w_neck = world(-0.5 * counter * yaw, 0.0, -0.5 * lean);
    let r = &mut pose.rotations;
    r[Joint::Lumbar.index()] = pelvis.inverse() * w_lumbar;
    r[Joint::ThoracicLower.index()] = w_lumbar.inverse() * w_tl;
    r[Joint::ThoracicUpper.index()] = w_tl.inverse() * w_tu;
    r[Joint::Neck.index()] = w_tu.inverse() * w_neck;
    r[Joint::Head.index()] = w_neck.inverse();
    // Arms, relative to the thorax (the clavicles stay at rest).
    let (arm_back, arm_front) = {
        let s = smooth01(t / plan.t_step.max(1e-6));
        (
            plan.arm_back.0 + s * (plan.arm_back.1 - plan.arm_back.0),
            plan.arm_front.0 + s * (plan.arm_front.1 - plan.arm_front.0),
        )
    };
    let front = swing * arm_front;
    let back = swing * arm_back;
    let stop_fade = if plan.kind == StepKind::Stop {
        1.0 - smooth01(t / plan.t_step)
    } else {
        1.0
    };
    for (side, sign) in [(0usize, -1.0f64), (1usize, 1.0f64)] {
        let flex = swing * drivers[1 - side] * stop_fade;
        let span = front - back;
        let frac = if span > 1e-6 {
            ((flex - back) / span).clamp(0.0, 1.0)
        } else {
            0.5
        };
        let (elbow, _) = hermite(0.0, 1.0, el_min, el_max, 0.0, 0.0, frac);
        let (shoulder, elbow_j) = if side == 0 {
            (Joint::LShoulder, Joint::LElbow)
        } else {
            (Joint::RShoulder, Joint::RElbow)
        };
        r[shoulder.index()] = DQuat::from_rotation_z(flex) * DQuat::from_rotation_x(-sign * abd);
        r[elbow_j.index()] = DQuat::from_rotation_z(elbow);
    }
}
