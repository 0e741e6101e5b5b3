//! Anthropometry generalization ψ_S^{S'} (Ko & Badler 1993, appendix C, eqs. 41–48):
//! W(S, sl) → W(S', α·sl) with α = ll(S')/ll(S) (eq. 3, eq. 9).
//!
//! As implemented (★ marks a correction, each tested):
//!
//! ```text
//! H:  x'ᵢ = α·xᵢ                                                   (eq. 43 ★ printed "xᵢ = αxᵢ")
//!     y'ᵢ = α·yᵢ + ΔaN, then pinned onto ỹ₁, ỹₙ as in eq. 27       (eq. 44 ★)
//! F₁, F₂, F₃, M unchanged                                           (appendix C)
//! A:  x'ᵢ = b₃ₓ + (b₄ₓ − b₃ₓ)/(xₙ − x₁) · (xᵢ − x₁)                  (eq. 47)
//!     y'ᵢ = α·yᵢ + (1 − t'ᵢ)d₁ + t'ᵢd₂, d₁ = b₃ᵧ − α·y₁, d₂ = b₄ᵧ − α·yₙ (eq. 48)
//! sl' = α·sl, sl'_before = α·sl_before
//! ```
//!
//! ΔaN = ankle_to_n(S') − α·ankle_to_n(S) (positive when S' has the higher ankle).
//!
//! ★ **Eq. 44 pins the hip.** For a body that is not a uniform scaling of S (another thigh/shin
//! ratio or foot), α·y + ΔaN does not put the hip at the height where the new leg has knee
//! flexion μ₁(S', α·sl) = μ₁(S, sl) at the heel strikes, which φ then imposes; the two orders of
//! Theorem 4 would then disagree at HSM±. Pinning the hip's end heights as eq. 27 does makes
//! the constant ΔaN drop out of H (the blend absorbs any constant) and satisfies Theorems 3–5.
//! For S' = αS both forms coincide (ΔaN = 0 and the pinned heights are α·y₁, α·yₙ).
//!
//! ★ **Eq. 43** is printed "xᵢ = αxᵢ"; x'ᵢ = αxᵢ is meant.
//!
//! x is measured from the stance heel's contact point, so α·x scales the hip's offset behind
//! the heel and its travel together, as the similarity assumption requires; b₃ and b₄ (eq. 47)
//! follow from S', α·sl_before and α·sl through the μ-functions, which are invariant under the
//! corrected argument (see [`super::mu`]).
use super::mu::MuFunctions;
use super::phi::{pin_hip_heights, retarget_ankle, StepEnds};
use super::walk_data::{Anthropometry, WalkData};
use crate::generator::GenerateError;

/// ψ_S^{S'}: the walk of `target` at α·sl after α·sl_before, α = ll(S')/ll(S) (appendix C,
/// with the corrections listed in the module docs). Errors when the new body cannot reach the
/// hip heights of eq. 27 or a μ leaves its range.
pub fn psi(
    w: &WalkData,
    target: &Anthropometry,
    mu: &MuFunctions,
) -> Result<WalkData, GenerateError> {
    let alpha = target.ratio_to(&w.body);
    let sl = alpha * w.step_length;
    let sl_before = alpha * w.step_length_before;
    let tom = w.moments.tom();

    // Eqs. 43–44.
    let delta_an = target.ankle_to_n() - alpha * w.body.ankle_to_n();
    let hip_scaled = w.hip.map(|_, [x, y]| [alpha * x, alpha * y + delta_an]);
    let ends = StepEnds::new(
        target,
        sl_before,
        sl,
        [hip_scaled.first()[0], hip_scaled.last()[0]],
        mu,
    )?;
    let hip = pin_hip_heights(&hip_scaled, ends.hip_y);

    // Eqs. 47–48.
    let ankle = retarget_ankle(&w.ankle, tom, alpha, &ends);

    Ok(WalkData {
        body: *target,
        step_length: sl,
        step_length_before: sl_before,
        moments: w.moments,
        hip,
        foot1: w.foot1.clone(),
        foot2: w.foot2.clone(),
        foot3: w.foot3.clone(),
        meta: w.meta.clone(),
        ankle,
    })
}

/// The printed eq. 44 without the pinning, for the tests that show why it was changed: the hip
/// heights α·yᵢ + ΔaN.
pub fn psi_hip_as_printed(w: &WalkData, target: &Anthropometry) -> Vec<[f64; 2]> {
    let alpha = target.ratio_to(&w.body);
    let delta_an = target.ankle_to_n() - alpha * w.body.ankle_to_n();
    w.hip
        .values()
        .iter()
        .map(|[x, y]| [alpha * x, alpha * y + delta_an])
        .collect()
}
