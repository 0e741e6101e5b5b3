//! Upper body (§3.3.3): torso tilt rising with speed and sway (forward maximum at mid-support,
//! backward at toe off), spine compensation of pelvic rotation and list so the head points
//! straight ahead (list over the lumbar spine; rotation "towards the pelvis" below T7 and
//! counter to it above, by the shoulder-rotation attribute), arm swing driven by the opposite
//! leg (back to its hip–ankle angle at its toe off, forward to its swing hip flexion at the
//! other leg's toe off; see [`arm_driver`] for where this departs from the paper) and elbow
//! flexion between its minimum (back of the swing) and maximum (front).
//!
//! The skeleton has spine joints at L5/S1 (`lumbar`), T12/L1 (`thoracic_lower`), T7
//! (`thoracic_upper`), C7/T1 (`neck`) and C1 (`head`). World targets per segment (yaw, roll,
//! pitch; pelvis ψ, ρ; tilt τ; counter-rotation c): lumbar segment (ψ/2, ρ/2, −τ/2); thoracic
//! lower (0, 0, −τ); thoracic upper, above T7 (−cψ, 0, −τ); neck (−cψ/2, 0, −τ/2); head upright
//! and facing forward. Local rotations are parent⁻¹ · child, so the head is exactly level.
use glam::DQuat;

use super::state::{StepKind, StepPlan, UpperAttrs};
use crate::generator::curves::hermite;
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

/// The arm-drive phase of the step's stance leg at step time `t` (rad, increasing; ≡ 0 mod 2π
/// at its toe off, π at the other leg's toe off): the plan's [`StepPlan::arm_phase`] keys
/// joined by cubic Hermite segments, continued at the end rates outside them. The swing leg's
/// phase is π more.
#[inline]
pub fn arm_phase(plan: &StepPlan, t: f64) -> f64 {
    let k = &plan.arm_phase;
    if t <= k[0].0 {
        return k[0].1 + k[0].2 * (t - k[0].0);
    }
    if t >= k[2].0 {
        return k[2].1 + k[2].2 * (t - k[2].0);
    }
    let (a, b) = if t <= k[1].0 {
        (k[0], k[1])
    } else {
        (k[1], k[2])
    };
    hermite(a.0, b.0, a.1, b.1, a.2, b.2, t).0
}

/// The arm-swing driver of one leg (rad, positive forward) at its arm-drive `phase` (see
/// [`arm_phase`]): at the back of the swing (`back`, the leg's hip–ankle pitch at its toe off)
/// at phase 0, at the front (`front`, the swing hip's flexion at the other leg's toe off) at
/// phase π, and a cosine of the phase in between.
///
/// §3.3.3 copies the swing leg's hip angle into the forward swing and its hip–ankle angle into
/// the backward swing frame by frame. The extremes and their timing are kept here; the path
/// between them is not, because the swing thigh sweeps most of its range within the support
/// (in a sprint ~45° within a 65 ms stance), and the arm copied that whip: at 270.8 steps/min
/// (24.99 km/h, 1.50 m, +9.8 % step frequency) the elbow's frame-to-frame step reached 9.2 × its
/// neighbours' (continuity, k = 5), beyond k = 5 from 260 steps/min up. The cosine of a phase
/// that advances π from toe off to toe off is smooth at any cadence.
#[inline]
pub fn arm_driver(back: f64, front: f64, phase: f64) -> f64 {
    back + (front - back) * 0.5 * (1.0 - phase.cos())
}

/// The back and front ends of the arm swing at step time `t` (rad; blended from the previous
/// step's over the step).
#[inline]
pub fn arm_ends(plan: &StepPlan, t: f64) -> (f64, f64) {
    let s = smooth01(t / plan.t_step.max(1e-6));
    (
        plan.arm_back.0 + s * (plan.arm_back.1 - plan.arm_back.0),
        plan.arm_front.0 + s * (plan.arm_front.1 - plan.arm_front.0),
    )
}

/// The arm-swing drivers (`[left leg, right leg]`, see [`arm_driver`]) at step time `t`: the
/// stance leg at [`arm_phase`], the swing leg π ahead of it.
#[inline]
pub fn arm_drivers(plan: &StepPlan, t: f64) -> [f64; 2] {
    let (back, front) = arm_ends(plan, t);
    let phase = arm_phase(plan, t);
    let stance = arm_driver(back, front, phase);
    let swing = arm_driver(back, front, phase + std::f64::consts::PI);
    if plan.s > 0.0 {
        [swing, stance]
    } else {
        [stance, swing]
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
    let (arm_back, arm_front) = arm_ends(plan, t);
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
