//! The lower-body pose W(S, sl) prescribes at a normalized time: "W(S, sl) provides enough
//! information to generate the lower body movement during one step" (§3).
//!
//! - Hip: H(t).
//! - Stance foot: heel rocker on [0, FGM] with F₁, then F₂ on the ball rocker, then on the toe
//!   rocker with M from MOM (pivots at x = 0, heel-to-ball, heel-to-toe: the foot cannot slide
//!   or penetrate).
//! - Swing foot: on [0, TOM] it is still finishing the previous step's stance — F₂ and M on
//!   [1, 1 + TOM], rescaled from μ(ρsl) to μ(sl_before) (with the heel-rise relation μ₅, by the
//!   ratio of the two steps' blended F₂ scales) (the previous step's own F₂ and M, since
//!   every step derives from the same prototype by the same multiplicative scalings) on its
//!   ball/toe pivot one step back; on [TOM, 1] its ankle follows A and its angle F₃.
//! - Knees: two-link inverse kinematics, knee forward. Where the data asks the hip to be higher
//!   than a leg can reach, the hip is lowered to the reachable height so that the feet stay
//!   exactly where the constraints put them; the drop is reported.
use super::geometry::{foot_from_ankle, foot_on_pivot, knee_position, FootPoints, Pivot, P2};
use super::mu::MuFunctions;
use super::walk_data::WalkData;
use crate::generator::GenerateError;

/// One leg's joint positions (step frame, m).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct LegPose {
    /// Knee joint.
    pub knee: P2,
    /// Foot points (ankle, heel, ball, toe tip).
    pub foot: FootPoints,
    /// Foot (sole) angle, toes up positive (rad).
    pub foot_angle: f64,
    /// Toe segment angle relative to the sole, extension positive (rad).
    pub toe_angle: f64,
    /// Whether the foot is on the floor (stance, or the swing foot before TOM).
    pub on_floor: bool,
}

/// The lower body at one normalized time of one step.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct StepPose {
    /// Normalized step time.
    pub t: f64,
    /// Hip joint (both hips in the sagittal plane), after any lowering; with a carried pelvis
    /// ([`super::carried`]) the pelvis centre, the legs' hip joints at ± `hip_offset`.
    pub hip: P2,
    /// The stance leg's hip joint relative to `hip` (forward, up; m), the swing leg's being its
    /// negative: the pelvis' rotation and list the carried variant keeps; zero in the paper's
    /// drawing (one hip point).
    pub hip_offset: P2,
    /// The stance leg (heel strike at HSM⁻ of this step).
    pub stance: LegPose,
    /// The swing leg.
    pub swing: LegPose,
    /// How far the hip was lowered below H(t) so both legs reach their feet (m, ≥ 0).
    pub hip_drop: f64,
    /// True if a foot could not be reached even by lowering the hip (the leg is drawn straight
    /// toward it); never happens on consistent data within the μ range.
    pub unreachable: bool,
}

/// Samples W at time `t` ∈ [0, 1]. `mu` gives the swing foot's toe-off state (μ₃, μ₄ at
/// sl_before).
pub fn pose(w: &WalkData, mu: &MuFunctions, t: f64) -> Result<StepPose, GenerateError> {
    let body = w.body();
    let m = w.moments();
    let (hb, bt) = (body.heel_to_ball(), body.ball_to_toe());

    // Stance foot.
    let (stance_foot, s_angle, s_toe) = if t <= m.fgm() {
        let f = w.foot1().at(t);
        (foot_on_pivot(body, Pivot::Heel(0.0), f, 0.0), f, 0.0)
    } else {
        let f = w.foot2().at(t);
        if t < m.mom() {
            (foot_on_pivot(body, Pivot::Ball(hb), f, 0.0), f, -f)
        } else {
            let me = w.meta().at(t);
            (foot_on_pivot(body, Pivot::Toe(hb + bt), f, me), f, -me - f)
        }
    };

    // Swing foot.
    let sb = w.step_length_before();
    let mb = mu.values(body, sb)?;
    let tom = m.tom();
    let (swing_foot, w_angle, w_toe, w_floor) = if t < tom {
        // The previous step's F₂ and M tails: this step's, rescaled to μ(sl_before).
        let kf = match (
            mu.heel_rise_at(body, sb)?,
            mu.heel_rise_at(body, w.step_length())?,
        ) {
            // With μ₅ the scale of F₂'s tail is a blend (phi): the previous step's tail is this
            // one's times the ratio of the two blends, exactly −μ₅(sl_before) at t = 0 (where the
            // previous step's stance foot left it) and −μ₃(sl_before) at TOM (where F₃ starts).
            (Some(hb), Some(hs)) => {
                let m3 = mu.mu_star()[2];
                let h5 = mu.heel_rise().map_or(1.0, |h| h.star);
                let ms = mu.values(body, w.step_length())?;
                let s = super::phi::heel_blend(w.foot2(), t + 1.0);
                ((1.0 - s) * hb / h5 + s * mb.foot_to / m3)
                    / ((1.0 - s) * hs / h5 + s * ms.foot_to / m3)
            }
            _ => w.foot3().first()[0] / w.foot2().last()[0],
        };
        let km = mb.meta_to / w.meta().last()[0];
        let f = w.foot2().at(t + 1.0) * kf;
        if t + 1.0 < m.mom() {
            let p = foot_on_pivot(body, Pivot::Ball(-sb + hb), f, 0.0);
            (p, f, -f, true)
        } else {
            let me = w.meta().at(t + 1.0) * km;
            let p = foot_on_pivot(body, Pivot::Toe(-sb + hb + bt), f, me);
            (p, f, -me - f, true)
        }
    } else {
        let tp = (t - tom) / (1.0 - tom);
        let f = w.foot3().at(t);
        let rel0 = mb.foot_to - mb.meta_to;
        let toe_rel = (1.0 - tp) * rel0;
        let a = w.ankle().interpolate(t);
        (foot_from_ankle(body, a, f, toe_rel), f, toe_rel, false)
    };

    // Hip, lowered if a leg cannot reach.
    let h = w.hip().interpolate(t);
    let reach = body.leg_length();
    let mut hip = h;
    let mut unreachable = false;
    for a in [stance_foot.ankle, swing_foot.ankle] {
        let dx = hip[0] - a[0];
        if dx.abs() > reach {
            unreachable = true;
            continue;
        }
        let ymax = a[1] + (reach * reach - dx * dx).sqrt();
        if hip[1] > ymax {
            hip[1] = ymax;
        }
    }
    let (k_st, c1) = knee_position(body, hip, stance_foot.ankle);
    let (k_sw, c2) = knee_position(body, hip, swing_foot.ankle);
    // A leg exactly at full reach after lowering is not "unreachable" (rounding).
    let _ = (c1, c2);
    Ok(StepPose {
        t,
        hip,
        hip_offset: [0.0, 0.0],
        stance: LegPose {
            knee: k_st,
            foot: stance_foot,
            foot_angle: s_angle,
            toe_angle: s_toe,
            on_floor: true,
        },
        swing: LegPose {
            knee: k_sw,
            foot: swing_foot,
            foot_angle: w_angle,
            toe_angle: w_toe,
            on_floor: w_floor,
        },
        hip_drop: h[1] - hip[1],
        unreachable,
    })
}
