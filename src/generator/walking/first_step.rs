//! The first step from standing: its swing's shape and its trailing leg's toe off (§2.4: "even
//! the extreme cases of starting and stopping are possible").
use super::body::Body;
use super::collision::{self, SwingAtImpact};
use super::draw::sagittal_angles;
use super::dynamics::{HipMotion, StanceModel};
use super::virtual_leg::VirtualLeg;
use crate::generator::curves::smoothstep;
use crate::generator::numeric::bisect;

/// Swings from standing that keep the paper's toe off (no brisk knee flexion at toe off,
/// `TOE_OFF_KNEE_RATE`).
pub(super) const FIRST_PAPER_SWINGS: usize = 1;

/// The first swing from standing's two shapes (see [`first_swing_shape`]), each at its end of the
/// walk's speed over body height `u` (1/s).
pub(super) const FIRST_SWING_SLOW: [f64; 2] = [0.15, 0.22];

/// Where the first swing from standing goes from its slow shape to its fast one (see
/// [`FIRST_SWING_SLOW`]), in walking speed over body height, 1/s.
pub(super) const FIRST_SWING_FAST: [f64; 2] = [0.46, 0.62];

/// The early ends of swing1 (fractions of the swing) of the first swing from standing's slow shape.
pub(super) const FIRST_SWING1_ENDS: [f64; 2] = [0.25, 0.3];

/// The first swing from standing's `(swing1 end, ankle lift)`: a continuous (C¹, smoothstep)
/// function of the walk's speed over body height `u = speed / height`, from the slow shape
/// (an early swing1 end, [`FIRST_SWING1_ENDS`], with the paper's `ankle_lift`) to the fast one
/// (the paper's `swing1_end`, no lift) over [`FIRST_SWING_FAST`]. It is braked
/// (`SwingSpec::knee_brake`) like every swing.
pub(super) fn first_swing_shape(
    speed: f64,
    height: f64,
    swing1_end: f64,
    ankle_lift: f64,
) -> (f64, f64) {
    let u = speed / height;
    let blend = |[a, b]: [f64; 2]| smoothstep((u - a) / (b - a));
    let [slowest, slow] = FIRST_SWING1_ENDS;
    let early = slowest + (slow - slowest) * blend(FIRST_SWING_SLOW);
    let fast = blend(FIRST_SWING_FAST);
    (
        early + (swing1_end - early) * fast,
        ankle_lift * (1.0 - fast),
    )
}

/// The swing thigh's rate θ̇3 at heel strike for which the collision
/// ([`collision::heel_strike`]) leaves the stance hip's forward velocity unchanged, rad/s: the
/// new stance's generalized momenta are linear in θ̇3 (the swing leg's angular momentum about
/// the new pivot), so two evaluations give it exactly. `old` is the stance state at heel strike,
/// `hip` the swing hip's motion then, `theta3` the heel-strike thigh angle (eq. 3).
pub(super) fn neutral_landing_rate(
    body: &Body,
    model: &StanceModel,
    old: &[f64; 6],
    old_ankle: [f64; 2],
    hip: HipMotion,
    theta3: f64,
    new_ankle: [f64; 2],
) -> f64 {
    let [w, t1, _, wd, t1d, _] = *old;
    let before = wd * t1.sin() + w * t1d * t1.cos();
    let jump = |rate: f64| {
        let s = collision::heel_strike(
            body,
            model,
            old,
            old_ankle,
            &SwingAtImpact {
                hip: hip.pos,
                hip_vel: hip.vel,
                theta3: [theta3, rate],
            },
            new_ankle,
        );
        let (q, qd) = (s.q, s.qd);
        qd[0] * q[1].sin() + q[0] * qd[1] * q[1].cos() - before
    };
    let (j0, j1) = (jump(0.0), jump(1.0));
    if (j1 - j0).abs() > 1e-12 {
        -j0 / (j1 - j0)
    } else {
        0.0
    }
}

/// How far forward the first swing leg's thigh may be at toe off from standing, as a fraction of
/// its heel-strike angle θ3 (eq. 3), so that swing1 still swings it forward to that angle.
pub const FIRST_TOE_OFF_THIGH: f64 = 0.6;

/// The knee flexion the first trailing leg from standing flexes to through its double support
/// (the meta-off rule, from `knee_now` at its start): the leg's own toe-off value, or less where
/// that would leave the thigh at toe off further forward than `thigh_min` (θ3 < 0 forward). The
/// thigh's angle at toe off is that of the sagittal hip–ankle chain after running the rule over
/// `hips` (`(leg clock, hip, dz)`); it decreases as the knee flexes more (bisection, 20 halvings).
pub(super) fn first_toe_off_knee(
    leg: &VirtualLeg,
    hips: &[(f64, [f64; 2], f64)],
    knee_now: f64,
    thigh_min: f64,
) -> f64 {
    let thigh_for = |k: f64| {
        let mut l = leg.clone();
        l.knee_toe_off = k;
        let mut last = None;
        for &(t, hip, dz) in hips {
            last = Some((l.advance(t, hip, dz).ankle, hip));
        }
        last.map_or(0.0, |(ankle, hip)| {
            sagittal_angles(hip, ankle, leg.l3, leg.l4)[0]
        })
    };
    let (lo, hi) = (knee_now.min(leg.knee_toe_off), leg.knee_toe_off);
    if thigh_for(hi) >= thigh_min {
        return hi;
    }
    bisect(lo, hi, 20, 0.0, |k| thigh_for(k) >= thigh_min).0
}
