//! Ko & Badler (1993), *Straight line walking animation based on kinematic generalization that
//! preserves the original characteristics*: from one measured step W(S*, sl*) of one subject,
//! the step of any subject S and step length sl, with the stance foot neither sliding nor
//! penetrating the floor and with successive steps chaining continuously.
//!
//! - [`walk_data`]: W(S, sl) = {H, F₁, F₂, F₃, M, A} on normalized step time (eqs. 1–4), the
//!   moments FGM, MOM, TOM and the anthropometry B(S) of Table 2;
//! - [`mu`]: the μ-functions (appendix A, eqs. 21–24);
//! - [`mod@phi`]: step-length generalization φ_ρ (appendix B, eqs. 25–40);
//! - [`mod@psi`]: anthropometry generalization ψ (appendix C, eqs. 41–48);
//! - [`carried`]: the carried variant — the prototype's measured angle curves kept in W, the hip
//!   placed so the drawn angles come nearest them with the paper's feet (issue 21 item 5);
//! - [`geometry`]: foot pivots, leg inverse kinematics, the hip heights of eq. 27;
//! - [`Generalizer`]: prototype + μ-functions → the combined generalization τ (eqs. 11–12)
//!   and chains of steps.
//!
//! # Corrections to the printed formulas
//! Each is explained where it is implemented and tested in `tests/kb_theorems.rs` and
//! `tests/kb_constraints.rs`:
//! 1. μ argument ll(S)/ll(S*)·sl → sl·ll(S*)/ll(S) (appendix A): the printed form is not
//!    invariant under the similarity assumption of §5 and breaks Theorems 4 and 5.
//! 2. sl_before is a parameter of φ and carried in W (eqs. 28, 32); eq. 26 scales the hip's
//!    travel and moves its start by half the change of sl_before (hip continuity across steps).
//! 3. eq. 34's t' = t/(HSM⁺ − TOM) → (t − TOM)/(HSM⁺ − TOM) (F₃ must start at the toe-off angle).
//! 4. the swing foot's toe-off state (eq. 34's d₁, eq. 39's b₃) uses sl_before, not ρ·sl (no
//!    jump at TOM between steps of different lengths; identical in steady walking).
//! 5. eq. 43 "xᵢ = αxᵢ" means x'ᵢ = αxᵢ; eq. 44 also pins the hip's end heights as eq. 27
//!    does (Theorem 4 for non-uniformly scaled bodies).
//! 6. Table 2 is labelled "inches" but holds centimetres (its subject is Winter's: step
//!    length 70.69 and leg length 73.90 match Winter's data in cm).
//!
//! With these, Theorems 1–5 hold to rounding (property tests to 1e-9).
pub mod angles;
pub mod carried;
pub mod compare;
pub mod figure;
pub mod geometry;
pub mod mu;
pub mod phi;
pub mod pose;
pub mod prototype;
pub mod psi;
pub mod synthetic;
pub mod walk_data;

pub use mu::{HeelRise, MuFunctions, MuValues};
pub use phi::{phi, phi_rho};
pub use psi::psi;
pub use walk_data::{AngleSequence, Anthropometry, Moments, PathSequence, TimedSequence, WalkData};

use crate::generator::GenerateError;

/// The committed fit `fits/kb-mu.json` (relation `kb-mu`, written by `gaitfit fit` on the
/// bundled trials tables), compiled in: [`default_alpha`] reads its α from here, so the built-in
/// slopes are whatever the committed fit says, never a copy of it.
const COMMITTED_KB_MU_FIT: &str = include_str!("../../../fits/kb-mu.json");

/// The μ-function slopes α₁…α₄ (rad/m) used when no fit is given: those of the committed
/// `fits/kb-mu.json`, parsed once (on these data α₁ sits on its lower bound 0 — measured knees
/// flex *more* at heel strike in longer steps). `tests/kb_mu_fit.rs` checks them against the
/// bounded least-squares optimum computed independently from the bundled tables.
pub fn default_alpha() -> [f64; 4] {
    static ALPHA: std::sync::OnceLock<[f64; 4]> = std::sync::OnceLock::new();
    *ALPHA.get_or_init(|| {
        crate::relations::kb_mu::KbMu::from_fit_json(
            std::path::Path::new("fits/kb-mu.json"),
            COMMITTED_KB_MU_FIT,
        )
        .map(|r| r.alpha())
        // Compiled in from the repository, not user input; the unit test below parses it.
        .expect("the committed fits/kb-mu.json is a kb-mu fit")
    })
}

/// A prototype walk W(S*, sl*) with its μ-functions: the generator of every other step.
#[derive(Debug, Clone)]
pub struct Generalizer {
    prototype: WalkData,
    mu: MuFunctions,
}

impl Generalizer {
    /// Pairs a prototype with μ-functions. The μ-functions' sl* and ll(S*) must be the
    /// prototype's.
    pub fn new(prototype: WalkData, mu: MuFunctions) -> Result<Self, GenerateError> {
        let ll = prototype.body().leg_length();
        if (mu.ll_star() - ll).abs() > 1e-9 * ll
            || (mu.sl_star() - prototype.step_length()).abs() > 1e-9 * ll
        {
            return Err(GenerateError::Parameter {
                name: "mu".into(),
                value: mu.sl_star(),
                message: format!(
                    "the μ-functions are for sl* = {} m, ll(S*) = {} m but the prototype has \
                     sl = {} m, ll = {} m",
                    mu.sl_star(),
                    mu.ll_star(),
                    prototype.step_length(),
                    ll
                ),
            });
        }
        Ok(Generalizer { prototype, mu })
    }
    /// The prototype W(S*, sl*).
    pub fn prototype(&self) -> &WalkData {
        &self.prototype
    }
    /// The μ-functions.
    pub fn mu(&self) -> &MuFunctions {
        &self.mu
    }

    /// τ: the step of `body` of length `sl` after a step of `sl_before` — ψ to the body first
    /// (eq. 11), then φ (eq. 12); Theorem 4 says the order does not matter.
    pub fn step(
        &self,
        body: &Anthropometry,
        sl_before: f64,
        sl: f64,
    ) -> Result<WalkData, GenerateError> {
        let w = psi(&self.prototype, body, &self.mu)?;
        let rho = sl / w.step_length();
        phi(&w, rho, sl_before, &self.mu)
    }

    /// A chain of steps: step k has length `lengths[k]` and follows step k − 1 (the first
    /// follows a step of its own length).
    pub fn chain(
        &self,
        body: &Anthropometry,
        lengths: &[f64],
    ) -> Result<Vec<WalkData>, GenerateError> {
        let mut out = Vec::with_capacity(lengths.len());
        let mut before = lengths.first().copied().unwrap_or(0.0);
        for (k, &sl) in lengths.iter().enumerate() {
            let w = self.step(body, before, sl).map_err(|e| match e {
                GenerateError::Parameter {
                    name,
                    value,
                    message,
                } => GenerateError::Parameter {
                    name: format!("step {} {name}", k + 1),
                    value,
                    message,
                },
                GenerateError::Numerical { stage, message } => GenerateError::Numerical {
                    stage: format!("step {} {stage}", k + 1),
                    message,
                },
                #[allow(unreachable_patterns)]
                other => other,
            })?;
            out.push(w);
            before = sl;
        }
        Ok(out)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_committed_fit_parses_into_bounded_slopes() {
        let a = default_alpha();
        assert!(a.iter().all(|x| x.is_finite() && *x >= 0.0), "{a:?}");
    }
}
