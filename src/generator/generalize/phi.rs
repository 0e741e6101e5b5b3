//! Step-length generalization φ_ρ (Ko & Badler 1993, appendix B, eqs. 25–40):
//! W(S, sl) → W(S, ρ·sl), for a given length of the step before.
//!
//! As implemented (every deviation from the printed text is marked ★ and tested):
//!
//! ```text
//! ρ' = (sl'_before + ρ·sl) / (sl_before + sl)                                     (eq. 28 ★)
//! H:  x'ᵢ = x₁ − (sl'_before − sl_before)/2 + ρ'(xᵢ − x₁)                          (eq. 26 ★)
//!     y'ᵢ = yᵢ + (1 − tᵢ)(ỹ₁ − y₁) + tᵢ(ỹₙ − yₙ)                                   (eq. 27)
//! F₁: f'₁ᵢ = f₁ᵢ · μ₂(S, sl'_before) / f₁₁                                          (eq. 32)
//! F₂: f'₂ᵢ = f₂ᵢ · (−μ₃(S, ρsl)) / f₂ₙ                                               (eq. 33)
//! F₃: f'₃ᵢ = f₃ᵢ + (1 − t'ᵢ)d₁ + t'ᵢd₂, t'ᵢ = (t₃ᵢ − TOM)/(HSM⁺ − TOM)                (eq. 34 ★)
//!     d₁ = −μ₃(S, sl'_before) − f₃₁ ★,  d₂ = μ₂(S, ρsl) − f₃ₙ
//!     with the optional heel-rise relation μ₅ (not the paper's, [`super::mu::HeelRise`]):
//!     f'₂ᵢ = f₂ᵢ · k(tᵢ), k = μ₅(S, ρsl)/(−f₂(1)) up to F₂'s first sample at or after HSM⁺
//!     (t = 1), then blended linearly in t to eq. 33's (−μ₃(S, ρsl))/f₂ₙ at 1 + TOM
//! M:  m'ᵢ = mᵢ · μ₄(S, ρsl) / mₙ                                                    (eq. 36)
//! A:  x'ᵢ = b₃ₓ + (b₄ₓ − b₃ₓ)/(xₙ − x₁) · (xᵢ − x₁)                                  (eq. 39 ★)
//!     y'ᵢ = yᵢ + (1 − t'ᵢ)d₁ + t'ᵢd₂, d₁ = b₃ᵧ − y₁, d₂ = b₄ᵧ − yₙ                    (eq. 40)
//! ```
//!
//! ỹ₁ is the hip height at which the stance leg, heel on the floor at x = 0 with foot angle
//! μ₂(S, sl'_before), has knee flexion μ₁(S, sl'_before); ỹₙ the same for the new front leg
//! at x = ρ·sl with μ₁, μ₂ at ρ·sl. b₃ is the swing ankle at TOM (toe tip on the floor where the
//! foot stood flat one step earlier, foot angle −μ₃, meta angle μ₄ at sl'_before), b₄ the
//! ankle at HSM⁺ (heel at ρ·sl, foot angle μ₂(S, ρsl)).
//!
//! ★ Corrections and readings, each needed for a theorem or a constraint:
//! - **sl_before is an argument** (the previous step of the animation). ρ' then compares the
//!   new hip travel (sl'_before + ρsl)/2 with the old (sl_before + sl)/2; when the two
//!   sl_before agree this is the printed eq. 28. Using one sl_before in both numerator and
//!   denominator while the data came from another step would make φ₁ a non-identity and leave
//!   the hip drifting against the feet.
//! - **Eq. 26 scales the hip's travel, not its position**: ρ'·xᵢ about the stance heel moves the
//!   hip's start away from where the previous step left it. Scaling xᵢ − x₁ and moving x₁ by
//!   half the change of sl_before keeps the hip exactly continuous across steps of any lengths
//!   (the hip sits behind the stance heel by sl_before/2 + c at HSM⁻ and ahead of it by sl/2 − c
//!   at HSM⁺, c a constant of the prototype; proof: `tests/kb_constraints.rs`).
//! - **Eq. 34's t'** is printed t₃ᵢ/(HSM⁺ − TOM), which is TOM/(1 − TOM) ≠ 0 at TOM, so F₃ would
//!   not start at the toe-off angle; eq. 40's (t − TOM)/(HSM⁺ − TOM) is meant.
//! - **The toe-off state at TOM belongs to the previous step**: the swing foot toes off at TOM
//!   of this step, ending the stance of the step before (whose F₂ and M end at μ₃, μ₄ of
//!   sl_before). The printed d₁ = μ₃(S, ρsl) − f₃₁ and b₃ "of the step length ρsl" would make the
//!   foot angle and ankle jump at TOM whenever successive steps differ; with sl_before they are
//!   continuous, and identical to the printed form in steady walking.
//! - **Eq. 39 maps the data's own end points** (x₁, xₙ) rather than b₁, b₂ recomputed from the
//!   μ-functions: identical on consistent data, and it snaps raw measured data onto the
//!   constraints instead of carrying its offsets along.
use super::geometry::{foot_on_pivot, hip_height_for_knee, Pivot, P2};
use super::mu::{MuFunctions, MuValues};
use super::walk_data::{AngleSequence, Anthropometry, PathSequence, WalkData};
use crate::generator::GenerateError;

/// The constrained end points of a step of `body` stepping `sl` after `sl_before`, with the hip
/// at x = `hip_x` (start, end).
#[derive(Debug, Clone, Copy)]
pub(crate) struct StepEnds {
    pub mu_before: MuValues,
    pub mu: MuValues,
    /// ỹ₁, ỹₙ of eq. 27.
    pub hip_y: [f64; 2],
    /// b₃: swing ankle at TOM.
    pub ankle_to: P2,
    /// b₄: swing (front) ankle at HSM⁺.
    pub ankle_hs: P2,
}

impl StepEnds {
    pub(crate) fn new(
        body: &Anthropometry,
        sl_before: f64,
        sl: f64,
        hip_x: [f64; 2],
        mu: &MuFunctions,
    ) -> Result<Self, GenerateError> {
        let mb = mu.values(body, sl_before)?;
        let m = mu.values(body, sl)?;
        let stance_ankle = foot_on_pivot(body, Pivot::Heel(0.0), mb.foot_hs, 0.0).ankle;
        let ankle_hs = foot_on_pivot(body, Pivot::Heel(sl), m.foot_hs, 0.0).ankle;
        let toe_x = -sl_before + body.heel_to_ball() + body.ball_to_toe();
        let ankle_to = foot_on_pivot(body, Pivot::Toe(toe_x), -mb.foot_to, mb.meta_to).ankle;
        let y1 = hip_height_for_knee(body, stance_ankle, hip_x[0], mb.knee_hs, "hip at HSM-")?;
        let yn = hip_height_for_knee(body, ankle_hs, hip_x[1], m.knee_hs, "hip at HSM+")?;
        Ok(StepEnds {
            mu_before: mb,
            mu: m,
            hip_y: [y1, yn],
            ankle_to,
            ankle_hs,
        })
    }
}

/// Where F₂'s scale stands between the heel-rise scale (0) and eq. 33's (1) at time `t` with
/// the heel-rise relation μ₅: 0 up to F₂'s first sample at or after HSM⁺ (so F₂ interpolated
/// at t = 1 is exactly −μ₅), then linear in t to 1 at F₂'s end (1 + TOM).
pub(crate) fn heel_blend(foot2: &AngleSequence, t: f64) -> f64 {
    let tb = foot2
        .times()
        .iter()
        .copied()
        .find(|&x| x >= 1.0)
        .unwrap_or(1.0);
    let te = foot2.t_last();
    if t <= tb || te <= tb {
        0.0
    } else {
        ((t - tb) / (te - tb)).min(1.0)
    }
}

/// The linear blend (1 − t)d₁ + t·d₂ of eqs. 27, 34, 40.
#[inline]
pub(crate) fn ramp(t: f64, d1: f64, d2: f64) -> f64 {
    (1.0 - t) * d1 + t * d2
}

/// Eqs. 39/47 and 40/48: maps the swing ankle path affinely in x onto [b₃ₓ, b₄ₓ] and blends y
/// onto b₃ᵧ, b₄ᵧ, after scaling y by `y_scale` (1 for φ, α for ψ).
pub(crate) fn retarget_ankle(
    a: &PathSequence,
    tom: f64,
    y_scale: f64,
    ends: &StepEnds,
) -> PathSequence {
    let [x1, y1] = a.first();
    let [xn, yn] = a.last();
    let (b3, b4) = (ends.ankle_to, ends.ankle_hs);
    let kx = (b4[0] - b3[0]) / (xn - x1);
    let d1 = b3[1] - y_scale * y1;
    let d2 = b4[1] - y_scale * yn;
    a.map(|t, [x, y]| {
        let tp = (t - tom) / (1.0 - tom);
        [b3[0] + kx * (x - x1), y_scale * y + ramp(tp, d1, d2)]
    })
}

/// Eq. 27: blends the hip heights onto ỹ₁, ỹₙ (H's times are already normalized, t ∈ [0, 1]).
pub(crate) fn pin_hip_heights(h: &PathSequence, hip_y: [f64; 2]) -> PathSequence {
    let [_, y1] = h.first();
    let [_, yn] = h.last();
    let (d1, d2) = (hip_y[0] - y1, hip_y[1] - yn);
    h.map(|t, [x, y]| [x, y + ramp(t, d1, d2)])
}

/// φ_ρ: the walk of the same subject stepping ρ·sl after a step of `sl_before` (appendix B, with
/// the corrections listed in the module docs). Errors when ρ or `sl_before` is not positive or
/// the new step is so far from the prototype's that a μ leaves its range or the leg cannot
/// reach the hip height of eq. 27.
pub fn phi(
    w: &WalkData,
    rho: f64,
    sl_before: f64,
    mu: &MuFunctions,
) -> Result<WalkData, GenerateError> {
    for (name, v) in [("rho", rho), ("sl_before", sl_before)] {
        if !(v.is_finite() && v > 0.0) {
            return Err(GenerateError::Parameter {
                name: name.into(),
                value: v,
                message: "must be positive and finite".into(),
            });
        }
    }
    let body = w.body;
    let sl = rho * w.step_length;
    let tom = w.moments.tom();

    // Eqs. 26 and 28 (hip travel scaled, start moved by half the change of sl_before).
    let rho_p = (sl_before + sl) / (w.step_length_before + w.step_length);
    let x1 = w.hip.first()[0];
    let x1_new = x1 - 0.5 * (sl_before - w.step_length_before);
    let hip_x = w.hip.map(|_, [x, y]| [x1_new + rho_p * (x - x1), y]);
    let ends = StepEnds::new(
        &body,
        sl_before,
        sl,
        [hip_x.first()[0], hip_x.last()[0]],
        mu,
    )?;
    // Eq. 27.
    let hip = pin_hip_heights(&hip_x, ends.hip_y);

    // Eqs. 32, 33, 36 (multiplicative), 34 (additive blend).
    let k1 = ends.mu_before.foot_hs / w.foot1.first()[0];
    let foot1 = w.foot1.map(|_, [f]| [f * k1]);
    let k2 = -ends.mu.foot_to / w.foot2.last()[0];
    let foot2 = match mu.heel_rise_at(&body, sl)? {
        None => w.foot2.map(|_, [f]| [f * k2]),
        // μ₅ ([`super::mu::HeelRise`]): F₂ scaled to the heel rise μ₅(ρsl) on [FGM, HSM⁺], the
        // scale blended linearly to eq. 33's on [HSM⁺, 1 + TOM] (both ends exact, F₂ continuous).
        Some(h) => {
            let h_w = -w.foot2.at(1.0);
            if !(h_w.is_finite() && h_w > 0.0) {
                return Err(GenerateError::Parameter {
                    name: "F2(HSM+)".into(),
                    value: h_w,
                    message: "the heel must be up at HSM+ for the heel-rise relation mu5".into(),
                });
            }
            let kh = h / h_w;
            w.foot2
                .map(|t, [f]| [f * ramp(heel_blend(&w.foot2, t), kh, k2)])
        }
    };
    let d1 = -ends.mu_before.foot_to - w.foot3.first()[0];
    let d2 = ends.mu.foot_hs - w.foot3.last()[0];
    let foot3 = w
        .foot3
        .map(|t, [f]| [f + ramp((t - tom) / (1.0 - tom), d1, d2)]);
    let km = ends.mu.meta_to / w.meta.last()[0];
    let meta = w.meta.map(|_, [m]| [m * km]);

    // Eqs. 39–40.
    let ankle = retarget_ankle(&w.ankle, tom, 1.0, &ends);

    Ok(WalkData {
        body,
        step_length: sl,
        step_length_before: sl_before,
        moments: w.moments,
        hip,
        foot1,
        foot2,
        foot3,
        meta,
        ankle,
    })
}

/// φ_ρ exactly as the paper writes it, with the step before unchanged: `phi(w, rho,
/// w.step_length_before(), mu)`.
pub fn phi_rho(w: &WalkData, rho: f64, mu: &MuFunctions) -> Result<WalkData, GenerateError> {
    phi(w, rho, w.step_length_before, mu)
}
