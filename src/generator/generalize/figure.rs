//! The full figure: a chain of generalized steps rendered on gaitfit's shared skeleton as a
//! [`Motion`] (BVH/CSV/TRC through [`crate::export`]).
//!
//! - Lower body from W (see [`super::pose`]): the pelvis at the hip H, both legs by two-link IK
//!   to the ankles W prescribes (knees forward), feet by their sole angle and the toes by their
//!   bend. The generalization's body B(S) is read off the figure's own skeleton
//!   ([`Anthropometry::from_figure`]), so the skeleton's heel, ball and toe land exactly where
//!   the generalization plants them.
//! - Arm swing "by a kinematic function that depends on the leg movement" (§7): each shoulder
//!   flexes opposite to its own thigh, shoulder = −[`ARM_SWING_GAIN`] · thigh angle, and the
//!   elbow flexes [`ELBOW_REST_RAD`] plus [`ELBOW_GAIN`] of the shoulder's forward flexion. The
//!   paper does not give its function; these gains are ours (shoulder range ≈ 0.6 × hip range
//!   and elbows slightly bent, as in normal walking).
//! - Trunk upright, pelvis level (W has neither).
//! - Timing: W is on normalized step time; each step gets its duration from the schedule.
use super::carried::{carried_pose, Carried};
use super::pose::{pose, LegPose, StepPose};
use super::walk_data::{Anthropometry, WalkData};
use super::Generalizer;
use crate::events::{EventKind, EventSource, Gait, GaitEvent, Side};
use crate::generator::ik::leg_ik;
use crate::generator::motion::{Motion, MotionMetadata};
use crate::generator::skeleton::{Euler, Joint, Pose, Skeleton};
use crate::generator::GenerateError;
use glam::{DQuat, DVec3};

/// Shoulder flexion per radian of the same side's thigh angle (opposite sign).
pub const ARM_SWING_GAIN: f64 = 0.6;
/// Elbow flexion with the arm hanging (rad, 15°).
pub const ELBOW_REST_RAD: f64 = 0.26;
/// Extra elbow flexion per radian of forward shoulder flexion.
pub const ELBOW_GAIN: f64 = 0.5;

/// One planned step.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct StepPlan {
    /// Step length (m).
    pub step_length_m: f64,
    /// Step duration (s).
    pub duration_s: f64,
}

/// What rendering found, beside the motion.
#[derive(Debug, Clone, PartialEq)]
pub struct FigureReport {
    /// The generalized steps, in order.
    pub steps: Vec<WalkData>,
    /// Largest hip lowering needed so both legs reach their feet (m).
    pub max_hip_drop_m: f64,
    /// Frames where a foot was out of reach even so.
    pub unreachable_frames: usize,
    /// Largest distance between a skeleton sole point and where the generalization put it,
    /// over all frames (m): how exactly the figure follows W.
    pub max_foot_mismatch_m: f64,
}

/// Renders the steps of `plan` for `skeleton`, the first step's stance leg on `first_stance`,
/// at `fps` frames per second (the paper's drawing: [`walk_motion_with`] without carried curves).
pub fn walk_motion(
    g: &Generalizer,
    skeleton: Skeleton,
    plan: &[StepPlan],
    first_stance: Side,
    fps: f64,
    metadata: MotionMetadata,
) -> Result<(Motion, FigureReport), GenerateError> {
    walk_motion_with(g, None, skeleton, plan, first_stance, fps, metadata)
}

/// As [`walk_motion`]; with `carried`, every frame is drawn by [`carried_pose`] (the carried
/// variant: the paper's feet, the hip where the drawn angles come nearest the generalized
/// step's rendering plus the prototype's residual), else by [`pose`] (the paper's).
pub fn walk_motion_with(
    g: &Generalizer,
    carried: Option<&Carried>,
    skeleton: Skeleton,
    plan: &[StepPlan],
    first_stance: Side,
    fps: f64,
    metadata: MotionMetadata,
) -> Result<(Motion, FigureReport), GenerateError> {
    if plan.is_empty() {
        return Err(GenerateError::Parameter {
            name: "steps".into(),
            value: 0.0,
            message: "need at least one step".into(),
        });
    }
    for (k, s) in plan.iter().enumerate() {
        if !(s.duration_s.is_finite() && s.duration_s > 0.0) {
            return Err(GenerateError::Parameter {
                name: format!("step {} duration_s", k + 1),
                value: s.duration_s,
                message: "must be positive".into(),
            });
        }
    }
    let body = Anthropometry::from_figure(skeleton.anthropometry())?;
    let lengths: Vec<f64> = plan.iter().map(|s| s.step_length_m).collect();
    let steps = g.chain(&body, &lengths)?;
    let mu = g.mu();

    let mut starts = Vec::with_capacity(plan.len() + 1);
    let (mut t0, mut x0) = (0.0, 0.0);
    for s in plan {
        starts.push((t0, x0));
        t0 += s.duration_s;
        x0 += s.step_length_m;
    }
    let total = t0;
    let n = (total * fps).floor() as usize + 1;
    let mut motion = Motion::new(skeleton, fps, metadata)?;
    motion.reserve(n);
    let half_width = 0.5 * motion.skeleton().anthropometry().hip_width_m;

    let mut report = FigureReport {
        steps: Vec::new(),
        max_hip_drop_m: 0.0,
        unreachable_frames: 0,
        max_foot_mismatch_m: 0.0,
    };
    let mut k = 0;
    for i in 0..n {
        let time = (i as f64 / fps).min(total);
        while k + 1 < plan.len() && time >= starts[k + 1].0 {
            k += 1;
        }
        let t = ((time - starts[k].0) / plan[k].duration_s).clamp(0.0, 1.0);
        let p = match carried {
            Some(c) => carried_pose(&steps[k], mu, t, c)?,
            None => pose(&steps[k], mu, t)?,
        };
        let stance = if k % 2 == 0 {
            first_stance
        } else {
            first_stance.opposite()
        };
        let (frame, mismatch) = figure_pose(motion.skeleton(), &p, starts[k].1, stance, half_width);
        report.max_hip_drop_m = report.max_hip_drop_m.max(p.hip_drop);
        report.unreachable_frames += usize::from(p.unreachable);
        report.max_foot_mismatch_m = report.max_foot_mismatch_m.max(mismatch);
        let mut contact = [false; 2];
        contact[side_slot(stance)] = true;
        contact[side_slot(stance.opposite())] = p.swing.on_floor;
        motion.push_frame(frame, contact);
    }
    motion.events = step_events(&steps, plan, &starts, first_stance);
    report.steps = steps;
    Ok((motion, report))
}

fn side_slot(s: Side) -> usize {
    crate::generator::skeleton::side_index(s)
}

/// The skeleton pose for one sampled step pose at world offset `x0`, and the largest distance
/// between the skeleton's sole points and the generalization's.
fn figure_pose(
    skeleton: &Skeleton,
    p: &StepPose,
    x0: f64,
    stance: Side,
    half_width: f64,
) -> (Pose, f64) {
    let mut pose = Pose::identity_at(DVec3::new(p.hip[0] + x0, p.hip[1], 0.0));
    let [ex, ey] = p.hip_offset;
    if (ex != 0.0 || ey != 0.0) && half_width > 0.0 {
        // The carried pelvis: turned about the vertical and listed about the forward axis so
        // the stance hip joint sits `hip_offset` ahead of / above the centre (and the swing hip
        // as far behind / below), the trunk kept upright.
        let z = match stance {
            Side::Left => -half_width,
            Side::Right => half_width,
        };
        let list = (-ey / z).clamp(-1.0, 1.0).asin();
        let turn = (ex / (z * list.cos())).clamp(-1.0, 1.0).asin();
        pose.set_world_rotation(
            Joint::Pelvis,
            DQuat::from_rotation_y(turn) * DQuat::from_rotation_x(list),
        );
        pose.set_world_rotation(Joint::Lumbar, DQuat::IDENTITY);
    }
    let mut mismatch: f64 = 0.0;
    for (side, leg) in [(stance, &p.stance), (stance.opposite(), &p.swing)] {
        let z = match side {
            Side::Left => -half_width,
            Side::Right => half_width,
        };
        let [hip_j, _, ankle_j, mtp_j] = Joint::leg(side);
        // The leg in the sagittal plane through its hip joint (a turned / listed pelvis brings
        // the hip joints in by half the hip width times 1 − cos(turn)·cos(list): ≈ 0.15 mm for
        // the Schreiber subjects' 5 mm offsets), so the drawn sagittal geometry is exactly the
        // generalization's.
        let z = if p.hip_offset == [0.0, 0.0] {
            z
        } else {
            skeleton.joint_world(&pose, hip_j).1.z
        };
        let target = DVec3::new(leg.foot.ankle[0] + x0, leg.foot.ankle[1], z);
        leg_ik(skeleton, &mut pose, side, target, DVec3::X);
        pose.set_world_rotation(ankle_j, DQuat::from_rotation_z(leg.foot_angle));
        pose.set_euler(mtp_j, Euler::new(leg.toe_angle, 0.0, 0.0));
        let thigh = thigh_angle(p.hip, leg);
        let [_, shoulder, elbow, _] = Joint::arm(side);
        let s = -ARM_SWING_GAIN * thigh;
        pose.set_euler(shoulder, Euler::new(s, 0.0, 0.0));
        pose.set_euler(
            elbow,
            Euler::new(ELBOW_REST_RAD + ELBOW_GAIN * s.max(0.0), 0.0, 0.0),
        );
        let lm = skeleton.landmarks(&pose);
        for (point, want) in [
            (crate::generator::skeleton::FootPoint::Heel, leg.foot.heel),
            (crate::generator::skeleton::FootPoint::Ball, leg.foot.ball),
            (crate::generator::skeleton::FootPoint::Toe, leg.foot.toe),
        ] {
            let got = lm[crate::generator::skeleton::Landmark::foot_point(side, point).index()];
            mismatch = mismatch.max((got.x - want[0] - x0).hypot(got.y - want[1]));
        }
    }
    (pose, mismatch)
}

/// The thigh's angle from the vertical, forward positive (rad).
fn thigh_angle(hip: [f64; 2], leg: &LegPose) -> f64 {
    (leg.knee[0] - hip[0]).atan2(hip[1] - leg.knee[1])
}

fn step_events(
    steps: &[WalkData],
    plan: &[StepPlan],
    starts: &[(f64, f64)],
    first_stance: Side,
) -> Vec<GaitEvent> {
    let mut ev = Vec::new();
    let e = |time_s: f64, side: Side, kind: EventKind| GaitEvent {
        time_s,
        side,
        kind,
        source: EventSource::Generated,
    };
    for (k, w) in steps.iter().enumerate() {
        let stance = if k % 2 == 0 {
            first_stance
        } else {
            first_stance.opposite()
        };
        let (t0, d) = (starts[k].0, plan[k].duration_s);
        let m = w.moments();
        ev.push(e(t0, stance, EventKind::HeelStrike));
        ev.push(e(t0 + m.tom() * d, stance.opposite(), EventKind::ToeOff));
        ev.push(e(t0 + m.fgm() * d, stance, EventKind::FootFlat));
        if m.mom() < 1.0 {
            ev.push(e(t0 + m.mom() * d, stance, EventKind::MetaOff));
        } else if k + 1 < steps.len() {
            ev.push(e(
                t0 + d + (m.mom() - 1.0) * plan[k + 1].duration_s,
                stance,
                EventKind::MetaOff,
            ));
        }
    }
    let end: f64 = plan.iter().map(|s| s.duration_s).sum();
    ev.push(e(
        end,
        if steps.len() % 2 == 0 {
            first_stance
        } else {
            first_stance.opposite()
        },
        EventKind::HeelStrike,
    ));
    ev.sort_by(|a, b| a.time_s.total_cmp(&b.time_s));
    ev
}

/// The default duration of a step: the prototype's, scaled by √(ll(S)/ll(S*)) (dynamic
/// similarity, equal Froude number of the leg-length-scaled walk), whatever the step length.
pub fn default_step_duration(proto_duration_s: f64, body: &Anthropometry, proto: &WalkData) -> f64 {
    proto_duration_s * (body.leg_length() / proto.body().leg_length()).sqrt()
}

/// Metadata for a generalized walk.
pub fn metadata(g: &Generalizer, height_m: f64, source: &str) -> MotionMetadata {
    let mut m = MotionMetadata::new("ko-badler-generalize", Some(Gait::Walk));
    m.push("height_m", height_m);
    m.push("prototype", source);
    m.push("prototype_step_length_m", g.prototype().step_length());
    let a = g.mu().alpha();
    for (i, v) in a.iter().enumerate() {
        m.push(format!("alpha{}_rad_per_m", i + 1), v);
    }
    m
}
