//! The prototype W(S*, sl*) built from Winter's walk (Winter 1990, Table A.1 and its filtered
//! version, via BMClab, CC BY 4.0): its measures against Ko & Badler's Table 2 (whose subject
//! column is Winter's subject, in cm), its consistency, the raw table against Winter's filtered
//! one, and the committed `data/prototype_winter.json` against a fresh build.
use gaitfit::generator::generalize::prototype::{winter_prototype, Prototype};
use gaitfit::generator::generalize::{default_alpha, phi_rho, psi};
use gaitfit::shared_data;

fn rel(got: f64, want: f64) -> f64 {
    (got / want - 1.0).abs()
}

/// Table 2, "Subject (Measured)" column (cm → m): Ko & Badler measured Winter's subject.
#[test]
fn bundled_prototype_matches_table2_subject() {
    let p = Prototype::bundled();
    let b = p.walk.body();
    let cases = [
        // (name, ours, Table 2, relative tolerance and why)
        ("step length", p.walk.step_length(), 0.7069, 0.002),
        // Our thigh runs from the pelvis centre, Table 2's knee sits between Winter's knee and
        // fibula markers (35.85/38.05 vs our 32.2/42.4), but the leg length agrees.
        ("leg length", b.leg_length(), 0.7390, 0.015),
        ("ankle to heel", b.ankle_to_heel(), 0.07629, 0.04),
        ("ankle to ball", b.ankle_to_ball(), 0.1220, 0.04),
        ("heel to ball", b.heel_to_ball(), 0.1589, 0.04),
        ("ball to toe", b.ball_to_toe(), 0.07095, 0.04),
        ("ball angle", b.ball_angle(), 0.4842, 0.03),
        ("heel angle", b.heel_angle(), 0.8400, 0.03),
        ("ankle angle", b.ankle_angle(), 1.818, 0.03),
    ];
    for (name, got, want, tol) in cases {
        assert!(
            rel(got, want) <= tol,
            "{name}: ours {got:.5}, Table 2 {want} (tolerance {tol})"
        );
    }
}

/// The committed prototype is consistent: φ₁ and ψ onto its own body leave it unchanged.
#[test]
fn bundled_prototype_is_a_fixed_point() {
    let p = Prototype::bundled();
    let mu = p.mu(default_alpha()).unwrap();
    let d = p
        .walk
        .max_abs_diff(&phi_rho(&p.walk, 1.0, &mu).unwrap())
        .unwrap();
    assert!(d < 1e-12, "φ₁ moves the prototype by {d}");
    let d = p
        .walk
        .max_abs_diff(&psi(&p.walk, p.walk.body(), &mu).unwrap())
        .unwrap();
    assert!(d < 1e-12, "ψ onto itself moves the prototype by {d}");
}

/// Regenerating the prototype from the shared data reproduces the committed file.
#[test]
#[ignore = "needs ../shared/data"]
fn committed_prototype_is_reproducible() {
    let (fresh, report) = winter_prototype(&shared_data::require("bmclab/wn35b.txt")).unwrap();
    let bundled = Prototype::bundled();
    let d = fresh.walk.max_abs_diff(&bundled.walk).unwrap();
    assert!(
        d < 1e-12,
        "fresh build differs from data/prototype_winter.json by {d}"
    );
    for i in 0..4 {
        assert!((fresh.mu_star[i] - bundled.mu_star[i]).abs() < 1e-12);
    }
    // How far φ₁ had to move the raw data onto the model (see prototype.rs docs).
    assert!(
        report.ankle_to_shift_m < 0.05 && report.ankle_hs_shift_m < 0.04,
        "{report:?}"
    );
    assert!(report.max_hip_drop_m < 0.01, "{report:?}");
}

/// Winter's raw table gives nearly the same prototype as his filtered one.
#[test]
#[ignore = "needs ../shared/data"]
fn raw_and_filtered_tables_agree() {
    let (raw, _) = winter_prototype(&shared_data::require("bmclab/WinterTableA1.txt")).unwrap();
    let (flt, _) = winter_prototype(&shared_data::require("bmclab/wn35b.txt")).unwrap();
    assert!((raw.walk.step_length() - flt.walk.step_length()).abs() < 0.001);
    assert!((raw.walk.body().leg_length() - flt.walk.body().leg_length()).abs() < 0.005);
    for i in 0..4 {
        let d = (raw.mu_star[i] - flt.mu_star[i]).abs();
        // Filtering rounds the toe-off peaks (≈ 4°); the knee and heel-strike angles agree to 2°.
        assert!(
            d < 0.08,
            "μ{} raw {} vs filtered {}",
            i + 1,
            raw.mu_star[i],
            flt.mu_star[i]
        );
    }
}
