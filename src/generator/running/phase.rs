//! Phase constraints (§3.3): per-frame evaluation of one planned step — pelvis translation and
//! orientation, the stance leg (heel/toe rotation to flat at mid-support, flat, heel off by
//! circle–sphere intersection), the swing and flight legs (key tracks), with the runtime part of
//! the recovery procedures. Everything here is allocation-free and cheap: the expensive choices
//! are made once per step in [`super::state`].
use glam::{DVec2, DVec3};

use super::attributes::Strike;
use super::dims::{leg_fk, leg_ik, pelvis_matrix, rot2, LegAngles, LegPoints, RunnerDims};
use super::state::{StepKind, StepPlan, G};
use crate::generator::curves::hermite;

/// How the stance foot touches the ground at one instant.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum StanceMode {
    /// Rotating about the heel toward flat (heel strike).
    HeelPivot,
    /// Rotating about the ball toward flat (toe strike), toes flat on the ground.
    BallPivot,
    /// Flat on the ground.
    Flat,
    /// Heel off: rotating about the toe tip (circle–sphere intersection).
    HeelOff,
    /// Heel off, but the interpolated angles would push the ball through the ground: the knee
    /// flexion is raised so that the toes lie flat (recovery procedure 2 of §3.3.1).
    HeelOffKneeRaised,
}

/// Stance leg at one instant.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct StanceEval {
    /// Leg angles.
    pub angles: LegAngles,
    /// Joint and foot positions.
    pub points: LegPoints,
    /// Contact mode.
    pub mode: StanceMode,
    /// The hip was out of reach (recovery procedure 1 failed to prevent it); the leg is
    /// straight and the foot may lift.
    pub out_of_reach: bool,
}

/// Pelvis position and velocity at step time `t` (support spline or flight parabola).
#[inline]
pub fn pelvis_at(plan: &StepPlan, t: f64) -> (DVec3, DVec3) {
    if t <= plan.t_stance || plan.kind == StepKind::Stop {
        let seg = if plan.nseg == 2 && t > plan.support[0].t1 {
            &plan.support[1]
        } else {
            &plan.support[0]
        };
        return seg.eval(t);
    }
    // §3.2: ballistic flight, x = x1 + v t, y = y1 + w t − g t²/2, z linear.
    let tau = t - plan.t_stance;
    let p = plan.flight_p1 + plan.flight_v * tau - DVec3::new(0.0, 0.5 * G * tau * tau, 0.0);
    let v = plan.flight_v - DVec3::new(0.0, G * tau, 0.0);
    (p, v)
}

/// Pelvic rotation (yaw) and list (roll) at `t`: cubic Hermite through the keyframes of Fig. 7
/// (see [`StepPlan::orient_rate`]).
#[inline]
pub fn orient_at(plan: &StepPlan, t: f64) -> (f64, f64) {
    let k = &plan.orient;
    let r = &plan.orient_rate;
    let n = plan.norient;
    if t <= k[0].0 {
        return (k[0].1, k[0].2);
    }
    for i in 0..n - 1 {
        if t <= k[i + 1].0 || i + 2 == n {
            let (a, b) = (k[i], k[i + 1]);
            let (y, _) = hermite(a.0, b.0, a.1, b.1, r[i].0, r[i + 1].0, t);
            let (l, _) = hermite(a.0, b.0, a.2, b.2, r[i].1, r[i + 1].1, t);
            return (y, l);
        }
    }
    (k[n - 1].1, k[n - 1].2)
}

/// Hip joint of the side with sign `sign` (+1 right) for a pelvis pose.
#[inline]
pub fn hip_at(d: &RunnerDims, pelvis: DVec3, yaw: f64, roll: f64, sign: f64) -> DVec3 {
    pelvis + pelvis_matrix(yaw, roll) * d.hip_local(sign)
}

#[inline]
fn smooth01(s: f64) -> f64 {
    let s = s.clamp(0.0, 1.0);
    s * s * (3.0 - 2.0 * s)
}

/// Sole pitch of the stance foot during the first stance sub-phase (impact → flat at `t_flat`).
#[inline]
fn pivot_pitch(plan: &StepPlan, t: f64) -> f64 {
    if plan.t_flat <= 0.0 {
        return 0.0;
    }
    plan.stance_print.impact_pitch * (1.0 - smooth01(t / plan.t_flat))
}

/// Knee flexion and toe angle of the heel-off interpolation at `t` (§3.3.1: both interpolated
/// "from the current time and values until TOR").
#[inline]
pub fn heel_off_angles(plan: &StepPlan, t: f64) -> (f64, f64) {
    let h = &plan.heel_off;
    let (k, _) = hermite(plan.t_heel_off, plan.t_stance, h.k0, h.k1, h.kr0, h.kr1, t);
    let (m, _) = hermite(plan.t_heel_off, plan.t_stance, 0.0, h.m1, 0.0, h.mr1, t);
    (k, m.max(0.0))
}

/// Intersection of the circle about the toe tip (radius toe–ankle) with the sphere about the
/// hip (radius hip–ankle), in the foot's vertical plane: the ankle position (x, y), choosing the
/// solution behind the toe–hip line. `None` when the hip is out of reach.
#[inline]
pub fn circle_sphere(toe: DVec2, r_toe: f64, hip: DVec2, r_hip: f64) -> Option<DVec2> {
    let u = hip - toe;
    let dist = u.length();
    if dist > r_toe + r_hip || dist < (r_toe - r_hip).abs() || dist <= 0.0 {
        return None;
    }
    let e = u / dist;
    let a = (r_toe * r_toe - r_hip * r_hip + dist * dist) / (2.0 * dist);
    let h = (r_toe * r_toe - a * a).max(0.0).sqrt();
    Some(toe + a * e + h * DVec2::new(-e.y, e.x))
}

/// Width of the smooth maximum between the heel-off knee and the knee the toes-flat recovery
/// needs (§3.3.1), rad: the knee is raised by at most half of it where the two cross.
pub const KNEE_RAISE_BLEND: f64 = 0.03;

/// The stance leg at step time `t` (0 ≤ t ≤ t_stance, or the whole stop phase), given the hip.
pub fn stance_leg(plan: &StepPlan, d: &RunnerDims, t: f64, hip: DVec3) -> StanceEval {
    stance_leg_in(plan, d, t, hip, None)
}

/// As [`stance_leg`], with the heel-off sub-mode forced to `heel_off_mode` (HeelOff or
/// HeelOffKneeRaised) when given: rates are taken within one mode, not across a switch.
pub fn stance_leg_in(
    plan: &StepPlan,
    d: &RunnerDims,
    t: f64,
    hip: DVec3,
    heel_off_mode: Option<StanceMode>,
) -> StanceEval {
    let fp = &plan.stance_print;
    let z = fp.heel.z;
    let flat_ankle = fp.heel + DVec3::new(d.heel_back, d.ankle_height, 0.0);
    let finish = |ankle: DVec3, pitch: f64, meta: f64, mode: StanceMode| {
        let (angles, out) = leg_ik(d, hip, ankle, pitch, meta);
        let points = leg_fk(d, hip, &angles);
        StanceEval {
            angles,
            points,
            mode,
            out_of_reach: out,
        }
    };
    if t < plan.t_flat {
        let pitch = pivot_pitch(plan, t);
        return match fp.strike {
            Strike::Heel => {
                let a = rot2(pitch, DVec2::new(d.heel_back, d.ankle_height));
                finish(
                    fp.heel + DVec3::new(a.x, a.y, 0.0),
                    pitch,
                    0.0,
                    StanceMode::HeelPivot,
                )
            }
            Strike::Toe => {
                // Toes flat: the foot rolls about the metatarsal joint, the ball stays put.
                let mtp = fp.heel + DVec3::new(d.heel_back + d.ankle_to_ball, d.mtp_height, 0.0);
                let a = rot2(pitch, d.mtp_f());
                finish(
                    mtp - DVec3::new(a.x, a.y, 0.0),
                    pitch,
                    -pitch,
                    StanceMode::BallPivot,
                )
            }
        };
    }
    if t < plan.t_heel_off || plan.kind == StepKind::Stop {
        return finish(flat_ankle, 0.0, 0.0, StanceMode::Flat);
    }
    // Heel off (§3.3.1): circle about the toe (radius toe–ankle at the current toe angle)
    // intersected with the sphere about the hip (radius thigh–shank at the current knee angle).
    let (k, m) = heel_off_angles(plan, t);
    let toe = DVec2::new(fp.heel.x + d.foot_length(), 0.0);
    let tf = d.toe_f(m);
    let r_toe = tf.length();
    let dz = hip.z - z;
    // The recovery below raises the knee to the flexion k_req that puts the toes flat; taking
    // max(k, k_req) switched the knee's rate within a frame where k crossed k_req (the stance
    // knee of a start from a stand stopped extending at 0.8 rad/s: continuity 5.3 at 6.41 km/h,
    // 1.51 m, refitted relations). A smooth maximum, never below either, blends the two over
    // about KNEE_RAISE_BLEND of flexion.
    let mtp = DVec2::new(toe.x - d.toe, d.mtp_height);
    let a_req = mtp - rot2(-m, d.mtp_f());
    let k_req = d.knee_for_distance((hip - DVec3::new(a_req.x, a_req.y, z)).length());
    // The blend grows from nothing at heel off (where the flat foot has k = k_req exactly), or
    // the heel would jump off the ground.
    let u = ((t - plan.t_heel_off) / (0.3 * (plan.t_stance - plan.t_heel_off)).max(1e-6)).min(1.0);
    let w = KNEE_RAISE_BLEND * u * u;
    let k = 0.5 * (k + k_req + ((k - k_req).powi(2) + w * w).sqrt());
    let dd = d.hip_ankle(k);
    let r_hip = (dd * dd - dz * dz).max(0.0).sqrt();
    let hip2 = DVec2::new(hip.x, hip.y);
    let allow_circle = heel_off_mode != Some(StanceMode::HeelOffKneeRaised);
    let force_circle = heel_off_mode == Some(StanceMode::HeelOff);
    if let Some(a) = circle_sphere(toe, r_toe, hip2, r_hip).filter(|_| allow_circle) {
        let to_toe = toe - a;
        let pitch = to_toe.y.atan2(to_toe.x) - tf.y.atan2(tf.x);
        let ball_y = a.y + rot2(pitch, d.ball_f(m)).y;
        let heel_y = a.y + rot2(pitch, d.heel_f()).y;
        if force_circle || (ball_y >= -1e-9 && heel_y >= -1e-9) {
            return finish(DVec3::new(a.x, a.y, z), pitch, m, StanceMode::HeelOff);
        }
    }
    // Recovery (§3.3.1): "the intersection might push the foot through the ground. In this case,
    // the knee angle is automatically temporarily increased" — the knee takes whatever flexion
    // puts the toes flat on the ground at the current toe angle; the foot pivots about the ball.
    let pitch = -m;
    let mtp = DVec2::new(toe.x - d.toe, d.mtp_height);
    let a = mtp - rot2(pitch, d.mtp_f());
    finish(
        DVec3::new(a.x, a.y, z),
        pitch,
        m,
        StanceMode::HeelOffKneeRaised,
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn circle_sphere_points_are_on_both_circles() {
        let toe = DVec2::new(0.3, 0.0);
        let hip = DVec2::new(0.2, 0.95);
        let a = circle_sphere(toe, 0.22, hip, 0.86).unwrap();
        assert!(((a - toe).length() - 0.22).abs() < 1e-12);
        assert!(((a - hip).length() - 0.86).abs() < 1e-12);
        assert!(a.x < toe.x, "ankle behind the toe");
        assert!(circle_sphere(toe, 0.1, hip, 0.5).is_none());
    }
}
