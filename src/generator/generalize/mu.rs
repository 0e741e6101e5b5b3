//! The μ-functions of Ko & Badler (1993), appendix A (eqs. 21–24): the four joint angles at the
//! heel-strike and toe-off moments as linear functions of the step length.
//!
//! ```text
//! μ₁(S, sl) = −α₁ (x − sl*) + μ₁*   knee flexion at heel strike          (eq. 21)
//! μ₂(S, sl) =  α₂ (x − sl*) + μ₂*   foot angle at heel strike, toes up    (eq. 22)
//! μ₃(S, sl) =  α₃ (x − sl*) + μ₃*   foot angle at toe off, heel up        (eq. 23)
//! μ₄(S, sl) =  α₄ (x − sl*) + μ₄*   meta angle at toe off                 (eq. 24)
//! x = sl · ll(S*) / ll(S)           (corrected; printed as ll(S)/ll(S*) · sl)
//! ```
//!
//! Units: angles in rad, lengths in m, α in rad/m. The paper gives α₁ ∈ [0, 0.3] without a
//! unit (its Table 2 is labelled inches but holds centimetres); we read it as rad/m.
//!
//! **Correction of the argument.** The paper prints the μ argument as ll(S)/ll(S*)·sl. Under
//! the similarity assumption of §5 (S → αS, sl → α·sl keeps every joint angle) that argument
//! becomes α²·ll(S)/ll(S*)·sl, so μ(αS, α·sl) ≠ μ(S, sl): the printed form contradicts the
//! paper's own assumption, makes ψ (which keeps angles, appendix C) disagree with the μ values
//! φ then imposes, and breaks Theorems 4 and 5. The argument sl·ll(S*)/ll(S) — the step length
//! the prototype subject would take at the same leg-length-relative step — is invariant and
//! satisfies all five theorems (see `tests/kb_theorems.rs`).
//!
//! Sign convention: μ₂ is the toes-up angle of the sole at heel strike, μ₃ the heel-up angle of
//! the sole at toe off and μ₄ the angle between floor and toes at toe off, all positive in
//! normal walking, so that α₂…α₄ > 0 means "larger with longer steps" as the paper intends.
//! In [`super::WalkData`] the foot angle is signed (toes up positive), so F₂ ends at −μ₃.
use super::walk_data::Anthropometry;
use crate::generator::GenerateError;

/// Upper bound of α₁ given by the paper (after Inman), rad/m.
pub const ALPHA1_MAX: f64 = 0.3;

/// The four μ values of one walk condition (rad).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct MuValues {
    /// μ₁: knee flexion at heel strike.
    pub knee_hs: f64,
    /// μ₂: foot angle at heel strike (toes up, positive).
    pub foot_hs: f64,
    /// μ₃: foot angle at toe off (heel up, positive).
    pub foot_to: f64,
    /// μ₄: meta angle at toe off (positive).
    pub meta_to: f64,
}

/// The μ-functions: the prototype's values μ*ᵢ at its step length sl* and leg length ll(S*),
/// and the slopes αᵢ.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct MuFunctions {
    alpha: [f64; 4],
    mu_star: [f64; 4],
    sl_star: f64,
    ll_star: f64,
    heel_rise: Option<HeelRise>,
}

/// An optional fifth μ-like relation, not in the paper: the stance foot's heel rise when the
/// other foot strikes (−F₂ at HSM⁺ = t = 1 of the step, rad, positive),
///
/// ```text
/// μ₅(S, sl) = μ₅* + α₅ (sl/ll(S) − sl*/ll(S*))
/// ```
///
/// linear in the step length per leg length (α₅ in rad per unit of sl/ll; sl/ll(S) = x/ll(S*)
/// for the corrected argument x, so μ₅ is a function of x like μ₁…μ₄ and keeps Theorems 1–5).
/// With it φ scales F₂ by μ₅(sl)/μ₅* up to HSM⁺ and blends the scale linearly to eq. 33's
/// μ₃(sl)/μ₃* at toe off ([`super::phi()`]); without it (the paper) eq. 33 scales all of F₂ by
/// μ₃(sl)/μ₃*, so the heel rise at HSM⁺ follows only the toe-off angle's relative change.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct HeelRise {
    /// α₅: rad per unit of step length / leg length.
    pub alpha: f64,
    /// μ₅*: the prototype's heel rise at HSM⁺ (rad, positive).
    pub star: f64,
}

impl MuFunctions {
    /// Validated constructor: α₁ ∈ [0, 0.3] (rad/m), α₂…α₄ ≥ 0, μ₂*…μ₄* > 0 (they scale F₁, F₂
    /// and M multiplicatively), sl* and ll(S*) positive (m).
    pub fn new(
        alpha: [f64; 4],
        mu_star: [f64; 4],
        sl_star: f64,
        ll_star: f64,
    ) -> Result<Self, GenerateError> {
        let p = |name: &str, v: f64, m: &str| GenerateError::Parameter {
            name: name.into(),
            value: v,
            message: m.into(),
        };
        if !(alpha[0].is_finite() && (0.0..=ALPHA1_MAX).contains(&alpha[0])) {
            return Err(p(
                "alpha1",
                alpha[0],
                "must lie in [0, 0.3] rad/m (appendix A)",
            ));
        }
        for (i, a) in alpha.iter().enumerate().skip(1) {
            if !(a.is_finite() && *a >= 0.0) {
                return Err(p(
                    &format!("alpha{}", i + 1),
                    *a,
                    "must be a non-negative rad/m (appendix A)",
                ));
            }
        }
        if !mu_star[0].is_finite() {
            return Err(p("mu1_star", mu_star[0], "must be finite (rad)"));
        }
        for (i, m) in mu_star.iter().enumerate().skip(1) {
            if !(m.is_finite() && *m > 0.0) {
                return Err(p(
                    &format!("mu{}_star", i + 1),
                    *m,
                    "must be a positive angle (rad): it scales F1, F2 or M",
                ));
            }
        }
        for (name, v) in [("sl_star", sl_star), ("ll_star", ll_star)] {
            if !(v.is_finite() && v > 0.0) {
                return Err(p(name, v, "must be a positive length (m)"));
            }
        }
        Ok(MuFunctions {
            alpha,
            mu_star,
            sl_star,
            ll_star,
            heel_rise: None,
        })
    }

    /// The same μ-functions with the heel-rise relation μ₅ ([`HeelRise`]); errors unless α₅ is
    /// finite and μ₅* positive (it scales F₂ multiplicatively).
    pub fn with_heel_rise(&self, heel: HeelRise) -> Result<Self, GenerateError> {
        if !heel.alpha.is_finite() {
            return Err(GenerateError::Parameter {
                name: "alpha5".into(),
                value: heel.alpha,
                message: "must be finite (rad per unit of sl/ll)".into(),
            });
        }
        if !(heel.star.is_finite() && heel.star > 0.0) {
            return Err(GenerateError::Parameter {
                name: "mu5_star".into(),
                value: heel.star,
                message: "must be a positive angle (rad): the heel must be up at HSM+ to scale F2"
                    .into(),
            });
        }
        Ok(MuFunctions {
            heel_rise: Some(heel),
            ..*self
        })
    }

    /// The heel-rise relation, if any (`None`: the paper's eq. 33).
    pub fn heel_rise(&self) -> Option<HeelRise> {
        self.heel_rise
    }

    /// μ₅(S, sl) ([`HeelRise`]), or `None` without the relation; errors when it is not positive.
    pub fn heel_rise_at(
        &self,
        body: &Anthropometry,
        step_length: f64,
    ) -> Result<Option<f64>, GenerateError> {
        let Some(h) = self.heel_rise else {
            return Ok(None);
        };
        let x = self.argument(body.leg_length(), step_length);
        let v = h.star + h.alpha * (x - self.sl_star) / self.ll_star;
        if v.is_nan() || v <= 0.0 {
            return Err(GenerateError::Parameter {
                name: "step_length".into(),
                value: step_length,
                message: format!(
                    "mu5 (heel rise at HSM+) = {v:.4} rad is not positive at this step length: \
                     choose a step closer to the prototype's"
                ),
            });
        }
        Ok(Some(v))
    }

    /// The same prototype values with other slopes (validated).
    pub fn with_alpha(&self, alpha: [f64; 4]) -> Result<Self, GenerateError> {
        Ok(MuFunctions {
            heel_rise: self.heel_rise,
            ..MuFunctions::new(alpha, self.mu_star, self.sl_star, self.ll_star)?
        })
    }

    /// α₁…α₄ (rad/m).
    pub fn alpha(&self) -> [f64; 4] {
        self.alpha
    }
    /// μ₁*…μ₄* (rad).
    pub fn mu_star(&self) -> [f64; 4] {
        self.mu_star
    }
    /// sl*: the prototype's step length (m).
    pub fn sl_star(&self) -> f64 {
        self.sl_star
    }
    /// ll(S*): the prototype's leg length (m).
    pub fn ll_star(&self) -> f64 {
        self.ll_star
    }

    /// The μ argument x = sl·ll(S*)/ll(S) (m): the corrected form, invariant under
    /// S → αS, sl → α·sl.
    pub fn argument(&self, leg_length: f64, step_length: f64) -> f64 {
        step_length * self.ll_star / leg_length
    }

    /// The argument as printed in eqs. 21–24, ll(S)/ll(S*)·sl; kept only so the tests can show
    /// why it was replaced.
    pub fn argument_as_printed(&self, leg_length: f64, step_length: f64) -> f64 {
        leg_length / self.ll_star * step_length
    }

    /// μᵢ at argument x (i = 0…3 for μ₁…μ₄), as the linear law of eqs. 21–24.
    pub fn linear_at_argument(&self, i: usize, x: f64) -> f64 {
        let sign = if i == 0 { -1.0 } else { 1.0 };
        sign * self.alpha[i] * (x - self.sl_star) + self.mu_star[i]
    }

    /// μᵢ at argument x (i = 0…3 for μ₁…μ₄) as the generator uses it: eqs. 21–24, except
    /// that μ₁ is held at 0 for steps long enough to make the linear law negative.
    // The knee cannot hyperextend, and a negative μ₁ would give the same hip height as +μ₁
    // (eq. 27 depends on cos μ₁), lowering the hip again for longer steps. Any function of the
    // invariant argument keeps Theorems 1–5, so the clamp costs none of them.
    pub fn at_argument(&self, i: usize, x: f64) -> f64 {
        let v = self.linear_at_argument(i, x);
        if i == 0 {
            v.max(0.0)
        } else {
            v
        }
    }

    /// All four μ values of walk condition (S, sl), unchecked.
    pub fn values_unchecked(&self, body: &Anthropometry, step_length: f64) -> MuValues {
        let x = self.argument(body.leg_length(), step_length);
        MuValues {
            knee_hs: self.at_argument(0, x),
            foot_hs: self.at_argument(1, x),
            foot_to: self.at_argument(2, x),
            meta_to: self.at_argument(3, x),
        }
    }

    /// All four μ values of walk condition (S, sl) (eqs. 21–24, μ₁ held at ≥ 0), or an error
    /// when the step is so far from the prototype's that μ₂…μ₄ would reach 0 (the
    /// multiplicative scaling of F₁, F₂ and M in eqs. 32, 33 and 36 cannot come back from 0).
    pub fn values(
        &self,
        body: &Anthropometry,
        step_length: f64,
    ) -> Result<MuValues, GenerateError> {
        let v = self.values_unchecked(body, step_length);
        let x = self.argument(body.leg_length(), step_length);
        let bad = |name: &str, val: f64, what: &str| GenerateError::Parameter {
            name: "step_length".into(),
            value: step_length,
            message: format!(
                "{name} = {val:.4} rad {what} at this step length (leg-length-normalized \
                 {x:.3} m vs the prototype's {:.3} m): choose a step closer to the prototype's",
                self.sl_star
            ),
        };
        if v.foot_hs.is_nan() || v.foot_hs <= 0.0 {
            return Err(bad(
                "mu2 (foot at heel strike)",
                v.foot_hs,
                "is not positive",
            ));
        }
        if v.foot_to.is_nan() || v.foot_to <= 0.0 {
            return Err(bad("mu3 (foot at toe off)", v.foot_to, "is not positive"));
        }
        if v.meta_to.is_nan() || v.meta_to <= 0.0 {
            return Err(bad("mu4 (meta at toe off)", v.meta_to, "is not positive"));
        }
        Ok(v)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn body(scale: f64) -> Anthropometry {
        Anthropometry::new(0.36, 0.38, 0.05, 0.11, 0.057, 0.07)
            .unwrap()
            .scaled(scale)
            .unwrap()
    }

    #[test]
    fn prototype_condition_gives_mu_star() {
        let mu = MuFunctions::new([0.1, 0.2, 0.3, 0.4], [0.1, 0.4, 1.2, 1.0], 0.7, 0.74).unwrap();
        let v = mu.values(&body(1.0), 0.7).unwrap();
        assert!((v.knee_hs - 0.1).abs() < 1e-15);
        assert!((v.meta_to - 1.0).abs() < 1e-15);
    }

    #[test]
    fn corrected_argument_is_similarity_invariant_printed_is_not() {
        let mu = MuFunctions::new([0.1, 0.2, 0.3, 0.4], [0.1, 0.4, 1.2, 1.0], 0.7, 0.74).unwrap();
        let (b, b2) = (body(1.0), body(1.3));
        let a = mu.argument(b.leg_length(), 0.6);
        let a2 = mu.argument(b2.leg_length(), 1.3 * 0.6);
        assert!((a - a2).abs() < 1e-12);
        let p = mu.argument_as_printed(b.leg_length(), 0.6);
        let p2 = mu.argument_as_printed(b2.leg_length(), 1.3 * 0.6);
        assert!((p2 / p - 1.69).abs() < 1e-9, "printed form scales with α²");
    }

    #[test]
    fn heel_rise_is_linear_in_step_per_leg_length() {
        let mu = MuFunctions::new([0.1, 0.2, 0.3, 0.4], [0.1, 0.4, 1.2, 1.0], 0.7, 0.74).unwrap();
        assert_eq!(
            mu.heel_rise_at(&body(1.0), 0.7).unwrap(),
            None,
            "paper: no μ5"
        );
        let h = mu
            .with_heel_rise(HeelRise {
                alpha: 1.5,
                star: 0.3,
            })
            .unwrap();
        let b = body(1.0);
        let ll = b.leg_length();
        // At the prototype's condition μ5 = μ5*; 0.074 m longer → +1.5 · 0.074 / ll(S*).
        let at = |sl: f64| h.heel_rise_at(&b, sl).unwrap().unwrap();
        assert!((at(0.7) - 0.3).abs() < 1e-15);
        assert!(
            (at(0.774) - (0.3 + 1.5 * 0.074 / ll)).abs() < 1e-12,
            "ll = {ll}"
        );
        // Similarity invariant like μ1…μ4: the same sl/ll on a body 1.3 times larger.
        let big = body(1.3);
        let v = h.heel_rise_at(&big, 1.3 * 0.774).unwrap().unwrap();
        assert!((v - at(0.774)).abs() < 1e-12);
        assert!(h.heel_rise_at(&b, 0.3).is_err(), "μ5 through zero");
        assert!(mu
            .with_heel_rise(HeelRise {
                alpha: 1.0,
                star: 0.0
            })
            .is_err());
        assert!(mu
            .with_heel_rise(HeelRise {
                alpha: f64::NAN,
                star: 0.2
            })
            .is_err());
        assert_eq!(
            h.with_alpha([0.1, 0.2, 0.3, 0.5]).unwrap().heel_rise(),
            h.heel_rise()
        );
    }

    #[test]
    fn bounds_are_enforced() {
        assert!(MuFunctions::new([0.31, 0.2, 0.3, 0.4], [0.1, 0.4, 1.2, 1.0], 0.7, 0.74).is_err());
        assert!(MuFunctions::new([0.1, -0.2, 0.3, 0.4], [0.1, 0.4, 1.2, 1.0], 0.7, 0.74).is_err());
        assert!(MuFunctions::new([0.1, 0.2, 0.3, 0.4], [0.1, 0.0, 1.2, 1.0], 0.7, 0.74).is_err());
        let mu = MuFunctions::new([0.3, 2.0, 0.3, 0.4], [0.1, 0.4, 1.2, 1.0], 0.7, 0.74).unwrap();
        assert!(mu.values(&body(1.0), 0.2).is_err(), "μ2 goes through zero");
    }
}
