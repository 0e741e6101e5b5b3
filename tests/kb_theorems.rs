//! Ko & Badler (1993) Theorems 1–5 and Corollaries 1–2 as property tests: random walks
//! (synthetic, consistent with their μ-functions), random ρ, random bodies and random walk
//! conditions; every generalization is compared number by number (times, values, lengths) to
//! 1e-9. Also the tests that show why the printed μ argument and eq. 44 were corrected.
use gaitfit::generator::generalize::synthetic::synthetic_walk;
use gaitfit::generator::generalize::{phi, phi_rho, psi, Anthropometry, WalkData};
use proptest::prelude::*;

const TOL: f64 = 1e-9;

fn close(a: &WalkData, b: &WalkData) -> Result<(), TestCaseError> {
    let d = a
        .max_abs_diff(b)
        .ok_or_else(|| TestCaseError::fail("walk data of different shapes"))?;
    prop_assert!(d <= TOL, "max difference {d:e} > {TOL:e}");
    Ok(())
}

/// A body that is not a uniform scaling of `b`: every segment scaled by its own factor.
fn other_body(b: &Anthropometry, k: &[f64; 7]) -> Anthropometry {
    Anthropometry::new(
        b.thigh() * k[0] * k[6],
        b.shin() * k[1] * k[6],
        b.heel_to_n() * k[2] * k[6],
        b.ball_to_n() * k[3] * k[6],
        b.ankle_to_n() * k[4] * k[6],
        b.ball_to_toe() * k[5] * k[6],
    )
    .unwrap()
    .with_ball_height(b.ball_height() * k[6])
    .unwrap()
}

fn factors() -> impl Strategy<Value = [f64; 7]> {
    (
        [
            0.85..1.18f64,
            0.85..1.18,
            0.8..1.25,
            0.8..1.25,
            0.8..1.25,
            0.8..1.25,
        ],
        0.85..1.2f64,
    )
        .prop_map(|(a, s)| [a[0], a[1], a[2], a[3], a[4], a[5], s])
}

fn cfg() -> ProptestConfig {
    ProptestConfig {
        cases: 48,
        ..ProptestConfig::default()
    }
}

proptest! {
    #![proptest_config(cfg())]

    /// Theorem 1 (eq. 6): φ_{ρ1ρ2} = φ_{ρ2} ∘ φ_{ρ1}, with the step before kept (the printed
    /// setting) and with a new step before at each application.
    #[test]
    fn theorem1_composition(seed in 0u64..10_000, r1 in 0.8..1.25f64, r2 in 0.8..1.25f64,
                            b1 in 0.8..1.25f64, b2 in 0.8..1.25f64) {
        let (w, mu) = synthetic_walk(seed).unwrap();
        let direct = phi_rho(&w, r1 * r2, &mu).unwrap();
        let two = phi_rho(&phi_rho(&w, r1, &mu).unwrap(), r2, &mu).unwrap();
        close(&direct, &two)?;
        let sl = w.step_length();
        let direct = phi(&w, r1 * r2, b2 * sl, &mu).unwrap();
        let two = phi(&phi(&w, r1, b1 * sl, &mu).unwrap(), r2, b2 * sl, &mu).unwrap();
        close(&direct, &two)?;
    }

    /// φ₁ with the same step before is the identity on consistent data.
    #[test]
    fn phi_one_is_identity(seed in 0u64..10_000) {
        let (w, mu) = synthetic_walk(seed).unwrap();
        close(&w, &phi_rho(&w, 1.0, &mu).unwrap())?;
    }

    /// Corollary 1 (eq. 7): φ_{ρ2} ∘ φ_{ρ1} = φ_{ρ1} ∘ φ_{ρ2}.
    #[test]
    fn corollary1_commutative(seed in 0u64..10_000, r1 in 0.8..1.25f64, r2 in 0.8..1.25f64) {
        let (w, mu) = synthetic_walk(seed).unwrap();
        let a = phi_rho(&phi_rho(&w, r1, &mu).unwrap(), r2, &mu).unwrap();
        let b = phi_rho(&phi_rho(&w, r2, &mu).unwrap(), r1, &mu).unwrap();
        close(&a, &b)?;
    }

    /// Corollary 2 (eq. 8): φ_{ρ1} ∘ (φ_{ρ2} ∘ φ_{ρ3}) = (φ_{ρ1} ∘ φ_{ρ2}) ∘ φ_{ρ3}.
    #[test]
    fn corollary2_associative(seed in 0u64..10_000, r1 in 0.85..1.18f64, r2 in 0.85..1.18f64,
                              r3 in 0.85..1.18f64) {
        let (w, mu) = synthetic_walk(seed).unwrap();
        let p = |w: &WalkData, r: f64| phi_rho(w, r, &mu).unwrap();
        // Right-hand side: apply φ3, then the composite (φ1 ∘ φ2) as one map φ_{ρ1ρ2}.
        let lhs = p(&p(&p(&w, r3), r2), r1);
        let rhs = p(&p(&w, r3), r1 * r2);
        close(&lhs, &rhs)?;
        let lhs2 = p(&w, r1 * r2 * r3);
        close(&lhs, &lhs2)?;
    }

    /// Theorem 2: φ is characteristic preserving, φ_{sl3/sl2} ∘ φ_{sl2/sl1} = φ_{sl3/sl1}, for
    /// arbitrary step lengths (and steps before).
    #[test]
    fn theorem2_transitive(seed in 0u64..10_000, l2 in 0.8..1.25f64, l3 in 0.8..1.25f64,
                           b in 0.8..1.25f64) {
        let (w, mu) = synthetic_walk(seed).unwrap();
        let (sl1, sl2, sl3) = (w.step_length(), l2 * w.step_length(), l3 * w.step_length());
        let before = b * sl1;
        let via = phi(&phi(&w, sl2 / sl1, before, &mu).unwrap(), sl3 / sl2, before, &mu).unwrap();
        let direct = phi(&w, sl3 / sl1, before, &mu).unwrap();
        close(&via, &direct)?;
    }

    /// Theorem 3 (eq. 10): ψ_{S1}^{S2} ∘ ψ_S^{S1} = ψ_S^{S2} for bodies that are not scalings
    /// of each other.
    #[test]
    fn theorem3_psi_transitive(seed in 0u64..10_000, k1 in factors(), k2 in factors()) {
        let (w, mu) = synthetic_walk(seed).unwrap();
        let s1 = other_body(w.body(), &k1);
        let s2 = other_body(w.body(), &k2);
        let via = psi(&psi(&w, &s1, &mu).unwrap(), &s2, &mu).unwrap();
        let direct = psi(&w, &s2, &mu).unwrap();
        close(&via, &direct)?;
    }

    /// ψ onto the same body is the identity on consistent data, and ψ onto αS scales every
    /// length by α and keeps every angle (the similarity assumption of §5).
    #[test]
    fn psi_similarity(seed in 0u64..10_000, alpha in 0.8..1.25f64) {
        let (w, mu) = synthetic_walk(seed).unwrap();
        close(&w, &psi(&w, w.body(), &mu).unwrap())?;
        let big = w.body().scaled(alpha).unwrap();
        let g = psi(&w, &big, &mu).unwrap();
        prop_assert!((g.step_length() - alpha * w.step_length()).abs() < TOL);
        for (a, b) in g.hip().values().iter().zip(w.hip().values()) {
            prop_assert!((a[0] - alpha * b[0]).abs() < TOL && (a[1] - alpha * b[1]).abs() < TOL);
        }
        for (a, b) in g.ankle().values().iter().zip(w.ankle().values()) {
            prop_assert!((a[0] - alpha * b[0]).abs() < TOL && (a[1] - alpha * b[1]).abs() < TOL);
        }
        prop_assert_eq!(g.foot2(), w.foot2());
        prop_assert_eq!(g.meta(), w.meta());
    }

    /// Theorem 4 (eqs. 15–16): φ_r ∘ ψ_{S1}^{S2} = ψ_{S1}^{S2} ∘ φ_r, r = (S1/S2)(sl2/sl1).
    #[test]
    fn theorem4_order_free(seed in 0u64..10_000, k in factors(), l2 in 0.8..1.25f64,
                           b2 in 0.8..1.25f64) {
        let (w1, mu) = synthetic_walk(seed).unwrap();
        let s2 = other_body(w1.body(), &k);
        let alpha = s2.ratio_to(w1.body());
        let (sl1, sl2) = (w1.step_length(), l2 * w1.step_length() * alpha);
        let before2 = b2 * sl1 * alpha;
        let r = sl2 / (alpha * sl1);
        let a = phi(&psi(&w1, &s2, &mu).unwrap(), r, before2, &mu).unwrap();
        let b = psi(&phi(&w1, r, before2 / alpha, &mu).unwrap(), &s2, &mu).unwrap();
        close(&a, &b)?;
        prop_assert!((a.step_length() - sl2).abs() < TOL);
    }

    /// Theorem 5 (eq. 20): τ23 ∘ τ12 = τ13 with τij = ψ_{Si}^{Sj} φ_{(Si/Sj)(slj/sli)}.
    #[test]
    fn theorem5_combined_transitive(seed in 0u64..10_000, k2 in factors(), k3 in factors(),
                                    l2 in 0.85..1.18f64, l3 in 0.85..1.18f64,
                                    b2 in 0.85..1.18f64, b3 in 0.85..1.18f64) {
        let (w1, mu) = synthetic_walk(seed).unwrap();
        let s1 = *w1.body();
        let s2 = other_body(&s1, &k2);
        let s3 = other_body(&s1, &k3);
        let sl1 = w1.step_length();
        let (sl2, sl3) = (l2 * sl1 * s2.ratio_to(&s1), l3 * sl1 * s3.ratio_to(&s1));
        let (bf2, bf3) = (b2 * sl2, b3 * sl3);
        // τ_ij: φ in Si's frame to the step (Si/Sj)·slj after (Si/Sj)·before, then ψ to Sj.
        let tau = |w: &WalkData, sj: &Anthropometry, slj: f64, beforej: f64| {
            let a = sj.ratio_to(w.body());
            let r = slj / (a * w.step_length());
            psi(&phi(w, r, beforej / a, &mu).unwrap(), sj, &mu).unwrap()
        };
        let w2 = tau(&w1, &s2, sl2, bf2);
        let w3_via = tau(&w2, &s3, sl3, bf3);
        let w3_direct = tau(&w1, &s3, sl3, bf3);
        close(&w3_via, &w3_direct)?;
    }
}

proptest! {
    #![proptest_config(cfg())]

    /// Theorems 1, 3, 4 and 5 on the bundled Winter prototype, with random slopes within the
    /// paper's bounds, random bodies and walk conditions.
    #[test]
    fn theorems_on_winter(a in [0.0..0.3f64, 0.0..1.5, 0.0..1.5, 0.0..1.5],
                          k2 in factors(), k3 in factors(),
                          l2 in 0.85..1.18f64, l3 in 0.85..1.18f64, b in 0.85..1.18f64) {
        use gaitfit::generator::generalize::prototype::Prototype;
        let p = Prototype::bundled();
        let mu = p.mu(a).unwrap();
        let w = &p.walk;
        let sl = w.step_length();
        // Theorem 1 / 2.
        close(&phi(&phi(w, l2, b * sl, &mu).unwrap(), l3, b * sl, &mu).unwrap(),
              &phi(w, l2 * l3, b * sl, &mu).unwrap())?;
        // Theorem 3.
        let s2 = other_body(w.body(), &k2);
        let s3 = other_body(w.body(), &k3);
        close(&psi(&psi(w, &s2, &mu).unwrap(), &s3, &mu).unwrap(), &psi(w, &s3, &mu).unwrap())?;
        // Theorem 4.
        let al = s2.ratio_to(w.body());
        let r = l2;
        close(&phi(&psi(w, &s2, &mu).unwrap(), r, b * sl * al, &mu).unwrap(),
              &psi(&phi(w, r, b * sl, &mu).unwrap(), &s2, &mu).unwrap())?;
        // Theorem 5.
        let tau = |w: &WalkData, sj: &Anthropometry, slj: f64, bj: f64| {
            let a = sj.ratio_to(w.body());
            psi(&phi(w, slj / (a * w.step_length()), bj / a, &mu).unwrap(), sj, &mu).unwrap()
        };
        let (sl2, sl3) = (l2 * sl * al, l3 * sl * s3.ratio_to(w.body()));
        let w2 = tau(w, &s2, sl2, b * sl2);
        close(&tau(&w2, &s3, sl3, b * sl3), &tau(w, &s3, sl3, b * sl3))?;
    }
}

/// Theorem 4 needs μ(S2, sl2) = μ(S1, sl2·ll(S1)/ll(S2)): ψ keeps angles, φ sets them from the
/// μ-functions. The corrected argument satisfies it; the printed ll(S)/ll(S*)·sl does not.
#[test]
fn printed_mu_argument_breaks_theorem4() {
    let (w, mu) = synthetic_walk(7).unwrap();
    let s1 = *w.body();
    let s2 = other_body(&s1, &[1.1, 1.05, 1.0, 1.0, 1.0, 1.0, 1.1]);
    let sl2 = 0.8;
    let via_s2 = mu.argument(s2.leg_length(), sl2);
    let via_s1 = mu.argument(s1.leg_length(), sl2 * s1.leg_length() / s2.leg_length());
    assert!((via_s2 - via_s1).abs() < 1e-12);
    let p2 = mu.argument_as_printed(s2.leg_length(), sl2);
    let p1 = mu.argument_as_printed(s1.leg_length(), sl2 * s1.leg_length() / s2.leg_length());
    assert!(
        (p2 - p1).abs() > 0.05,
        "printed arguments {p1} and {p2} should differ"
    );
    // With a non-zero slope, the μ values (hence F₁, F₂, F₃, M) of the two orders differ.
    let d = mu.at_argument(2, p2) - mu.at_argument(2, p1);
    assert!(d.abs() > 1e-3, "μ3 differs by {d}");
}

/// Eq. 44 as printed (y' = αy + ΔaN, no pinning) disagrees at the heel strikes with the order
/// φ-then-ψ for a body with another thigh/shin ratio; pinned, it agrees (Theorem 4 above).
#[test]
fn printed_eq44_breaks_theorem4_for_nonuniform_bodies() {
    let (w, mu) = synthetic_walk(11).unwrap();
    let s1 = *w.body();
    let s2 = other_body(&s1, &[1.15, 0.9, 1.0, 1.0, 1.2, 1.0, 1.0]);
    let alpha = s2.ratio_to(&s1);
    // ψ (printed) first, then φ pins the hip onto ỹ of S2 at HSM±: the result's start height.
    let phi_after = phi_rho(&psi(&w, &s2, &mu).unwrap(), 1.0, &mu).unwrap();
    let printed = gaitfit::generator::generalize::psi::psi_hip_as_printed(&w, &s2);
    let dy = (phi_after.hip().first()[1] - printed[0][1]).abs();
    assert!(
        dy > 1e-4,
        "printed eq. 44 puts the hip {dy} m off the μ₁ knee angle"
    );
    // For S2 = αS1 the printed form is exact.
    let s_uniform = s1.scaled(alpha).unwrap();
    let printed_u = gaitfit::generator::generalize::psi::psi_hip_as_printed(&w, &s_uniform);
    let pinned_u = psi(&w, &s_uniform, &mu).unwrap();
    for (a, b) in printed_u.iter().zip(pinned_u.hip().values()) {
        assert!((a[1] - b[1]).abs() < 1e-12);
    }
}
