//! Sagittal joint angles of one stride, on normalized step time, from a rendered walk W or from
//! measured markers, defined identically for both so they can be compared
//! ([`super::compare`]).
//!
//! - hip: the thigh's angle from the vertical, forward positive (the pelvis is upright in W);
//! - knee: flexion, thigh angle minus shank angle (0 = straight);
//! - ankle: dorsiflexion, the sole's angle from flat minus the shank's angle from the vertical
//!   (0 with the foot flat under a vertical shank);
//! - ankle path: the swing ankle relative to where it lands, on normalized swing time
//!   (toe off → heel strike).
//!
//! A stride of one leg is its stance step (the leg is W's stance leg, t ∈ [0, 1]) followed by
//! its swing step (the leg is W's swing leg, t ∈ [0, 1]), [`SAMPLES`] samples each.
use super::mu::MuFunctions;
use super::pose::{pose, LegPose};
use super::prototype::{flat_foot_line, landmark_at, pelvis_at, SagittalLeg, StrideEvents};
use super::walk_data::WalkData;
use crate::generator::GenerateError;

/// Samples per normalized step.
pub const SAMPLES: usize = 101;

/// One stride's angles (rad) and swing ankle path (m).
#[derive(Debug, Clone, PartialEq)]
pub struct Angles {
    /// Hip (thigh) angle, stance step then swing step (2·[`SAMPLES`]).
    pub hip: Vec<f64>,
    /// Knee flexion.
    pub knee: Vec<f64>,
    /// Ankle dorsiflexion.
    pub ankle: Vec<f64>,
    /// Swing ankle relative to its landing position ([`SAMPLES`] points, m).
    pub ankle_path: Vec<[f64; 2]>,
    /// Of a measured stride whose pelvis is measured: the leg's hip joint centre relative to the
    /// pelvis centre (forward, up; m), stance step then swing step (2·[`SAMPLES`]) — the
    /// pelvis' rotation and list ([`super::prototype::SagittalLeg::hip_offset`]). Empty when not
    /// measured and for drawn candidates.
    pub hip_offset: Vec<[f64; 2]>,
}

/// Thigh, knee and ankle angles (rad, definitions above) of a leg from its hip, knee and ankle
/// joints and its sole angle.
pub(super) fn leg_angles(hip: [f64; 2], knee: [f64; 2], ankle: [f64; 2], foot: f64) -> [f64; 3] {
    let thigh = (knee[0] - hip[0]).atan2(hip[1] - knee[1]);
    let shank = (ankle[0] - knee[0]).atan2(knee[1] - ankle[1]);
    [thigh, thigh - shank, foot - shank]
}

fn push(a: &mut Angles, v: [f64; 3]) {
    a.hip.push(v[0]);
    a.knee.push(v[1]);
    a.ankle.push(v[2]);
}

fn empty() -> Angles {
    Angles {
        hip: Vec::with_capacity(2 * SAMPLES),
        knee: Vec::with_capacity(2 * SAMPLES),
        ankle: Vec::with_capacity(2 * SAMPLES),
        ankle_path: Vec::with_capacity(SAMPLES),
        hip_offset: Vec::new(),
    }
}

fn grid(i: usize) -> f64 {
    i as f64 / (SAMPLES - 1) as f64
}

/// The angles W prescribes (rendered by [`pose`]).
pub fn model_angles(w: &WalkData, mu: &MuFunctions) -> Result<Angles, GenerateError> {
    let poses = (0..SAMPLES)
        .map(|i| pose(w, mu, grid(i)))
        .collect::<Result<Vec<_>, _>>()?;
    Ok(angles_from_poses(w, &poses))
}

/// The angles of a step drawn as `poses` ([`SAMPLES`] poses on the grid of normalized step time),
/// and W's swing ankle path.
pub(super) fn angles_from_poses(w: &WalkData, poses: &[super::pose::StepPose]) -> Angles {
    let mut a = empty();
    let la = |p: &super::pose::StepPose, l: &LegPose| {
        leg_angles(p.hip, l.knee, l.foot.ankle, l.foot_angle)
    };
    for p in poses {
        push(&mut a, la(p, &p.stance));
    }
    for p in poses {
        push(&mut a, la(p, &p.swing));
    }
    let tom = w.moments().tom();
    let land = w.ankle().last();
    for i in 0..SAMPLES {
        let q = w.ankle().interpolate(tom + grid(i) * (1.0 - tom));
        a.ankle_path.push([q[0] - land[0], q[1] - land[1]]);
    }
    a
}

/// The measured angles of the stride `ev` of `leg` (the hip from the same pelvis-centre estimate
/// as the step W built from it, with step length `sl`).
pub fn measured_angles(
    leg: &SagittalLeg,
    ev: &StrideEvents,
    sl: f64,
) -> Result<Angles, GenerateError> {
    let mut a = empty();
    let tau = 0.5 * (ev.next_heel_strike - ev.heel_strike);
    let flat = flat_foot_line(leg, ev);
    let at = |v: &[[f64; 2]], t: f64| landmark_at(leg, v, t);
    let angles_at = |t: f64| {
        let (h, b) = (at(&leg.heel, t), at(&leg.ball, t));
        let foot = (b[1] - h[1]).atan2(b[0] - h[0]) - flat;
        leg_angles(
            pelvis_at(leg, ev, sl, t),
            at(&leg.knee, t),
            at(&leg.ankle, t),
            foot,
        )
    };
    for i in 0..SAMPLES {
        push(&mut a, angles_at(ev.heel_strike + tau * grid(i)));
    }
    for i in 0..SAMPLES {
        push(&mut a, angles_at(ev.heel_strike + tau * (1.0 + grid(i))));
    }
    if let Some(d) = &leg.hip_offset {
        // The same instants as the angles: stance step, then swing step.
        for half in [0.0, 1.0] {
            for i in 0..SAMPLES {
                a.hip_offset
                    .push(at(d, ev.heel_strike + tau * (half + grid(i))));
            }
        }
    }
    let land = at(&leg.ankle, ev.next_heel_strike);
    for i in 0..SAMPLES {
        let t = ev.toe_off + grid(i) * (ev.next_heel_strike - ev.toe_off);
        let q = at(&leg.ankle, t);
        a.ankle_path.push([q[0] - land[0], q[1] - land[1]]);
    }
    if a.hip
        .iter()
        .chain(&a.knee)
        .chain(&a.ankle)
        .any(|v| !v.is_finite())
    {
        return Err(GenerateError::Numerical {
            stage: "measured angles".into(),
            message: "a landmark is missing during the stride".into(),
        });
    }
    Ok(a)
}
