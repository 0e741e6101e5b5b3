//! Anthropometry against table B-1 of Bruderlin & Calvert (1989), appendix B, and Winter (2009)
//! Table 4.1. Expected numbers: the paper's worked example for h = 1.8 m, m = 80 kg
//! (m₃ = 8 kg, l₃ = 0.426 m, r₃ = 0.184 m) and the table's fractions multiplied by hand.
use gaitfit::generator::anthropometry::{table, Anthropometry};

fn close(a: f64, b: f64, tol: f64) -> bool {
    (a - b).abs() <= tol
}

#[test]
fn thigh_of_the_worked_example() {
    let a = Anthropometry::from_height(1.8, 80.0).unwrap();
    // Appendix B: m₃ = 8 kg, l₃ = 0.426 m, r₃ = 0.184 m (printed to 3 decimals).
    assert!(close(a.thigh.mass_kg, 8.0, 1e-12));
    assert!(close(a.thigh.length_m, 0.426, 5e-4));
    assert!(close(a.thigh.com_from_proximal_m, 0.184, 5e-4));
    // The radius of gyration the example calls "r₃ = 0.138 m" is γ₃·l₃ = 0.323·0.426.
    assert!(close(a.thigh.radius_of_gyration_m, 0.138, 5e-4));
}

#[test]
fn thigh_moment_of_inertia_follows_the_table_not_the_printed_example() {
    let a = Anthropometry::from_height(1.8, 80.0).unwrap();
    // Table: I₃ = m₃·(γ₃·l₃)² = 8 · (0.323 · 0.42604)² = 0.15150 kg·m².
    let by_hand = 8.0 * (0.323 * 0.23669 * 1.8f64).powi(2);
    assert!(close(by_hand, 0.1515, 5e-5));
    assert!(close(a.thigh.moment_of_inertia_kg_m2(), by_hand, 1e-12));
    // The printed example, m₃·(l₃·r₃)² with r₃ = 0.138 m, gives 0.0276 — units kg·m⁴, not a
    // moment of inertia; gaitfit does not reproduce it.
    let printed = 8.0 * (0.426f64 * 0.138).powi(2);
    assert!(close(printed, 0.0276, 5e-5));
    assert!(a.thigh.moment_of_inertia_kg_m2() > 5.0 * printed);
}

#[test]
fn every_table_b1_value_for_h_1_8_m_80_kg() {
    let h = 1.8;
    let a = Anthropometry::from_height(h, 80.0).unwrap();
    let t = 1e-12;
    assert!(close(a.hip_width_m, 0.10059 * h, t));
    assert!(close(a.upper_body.length_m, 0.47 * h, t));
    assert!(close(a.upper_body.mass_kg, 0.678 * 80.0, t));
    assert!(close(a.upper_body.com_from_proximal_m, 0.5 * 0.47 * h, t));
    assert!(close(
        a.upper_body.radius_of_gyration_m,
        0.496 * 0.47 * h,
        t
    ));
    assert!(close(a.shank.length_m, 0.24556 * h, t));
    assert!(close(a.shank.mass_kg, 0.061 * 80.0, t));
    assert!(close(a.shank.com_from_proximal_m, 0.606 * 0.24556 * h, t));
    assert!(close(a.shank.radius_of_gyration_m, 0.416 * 0.24556 * h, t));
    // Leg (segment 1): l₁ = l₃ + l₄, m₁ = m₃ + m₄, r₁ from the distal end.
    let leg = a.leg();
    assert!(close(leg.length_m, (0.23669 + 0.24556) * h, t));
    assert!(close(leg.mass_kg, (0.1 + 0.061) * 80.0, t));
    assert!(close(leg.com_from_distal_m(), 0.553 * leg.length_m, 1e-12));
    assert!(close(leg.radius_of_gyration_m, 0.326 * leg.length_m, t));
    // Foot: l₅, l₆, l₈, l₉ directly; l₁₁, l₁₂, l₁₃ from the geometry.
    let f = &a.foot;
    assert!(close(f.mid_foot_m, 0.0858 * h, t));
    assert!(close(f.toe_m, 0.04734 * h, t));
    assert!(close(f.hind_foot_m, 0.02959 * h, t));
    assert!(close(f.ankle_height_m, 0.03846 * h, t));
    assert!(close(f.ankle_metatarsal_m(), 0.08901 * h, 1e-12));
    // The table's redundant distances agree with the geometry to 1e-4·h.
    assert!(close(f.heel_ankle_m(), table::HEEL_ANKLE_L11 * h, 1e-4 * h));
    assert!(close(
        f.metatarsal_toe_m(),
        table::METATARSAL_TOE_L13 * h,
        1e-4 * h
    ));
    // Metatarsal joint height l₉ − √(l₁₂² − l₅²) = 0.01477·h.
    assert!(close(f.metatarsal_height_m / h, 0.01477, 1e-5));
}

#[test]
fn upper_body_masses_add_up_to_hat() {
    // Winter Table 4.1: HAT 0.678 = head-neck 0.081 + trunk 0.497 + 2 × (0.028 + 0.016 + 0.006).
    let a = Anthropometry::from_height(1.75, 70.0).unwrap();
    let sum = a.head_neck_mass_kg
        + a.trunk_mass_kg
        + 2.0 * (a.upper_arm.mass_kg + a.forearm.mass_kg + a.hand.mass_kg);
    assert!(close(sum, a.upper_body.mass_kg, 1e-9));
    // Drillis & Contini: elbow at 0.630·h, wrist at 0.485·h, knuckle at 0.377·h (±0.002·h).
    let sh = a.shoulder_height_m();
    assert!(close((sh - a.upper_arm.length_m) / 1.75, 0.630, 2e-3));
    assert!(close(
        (sh - a.upper_arm.length_m - a.forearm.length_m) / 1.75,
        0.485,
        2e-3
    ));
    assert!(close(
        (sh - a.upper_arm.length_m - a.forearm.length_m - a.hand.length_m) / 1.75,
        0.377,
        2e-3
    ));
}

#[test]
fn overrides_are_validated() {
    let mut a = Anthropometry::from_height(1.8, 80.0).unwrap();
    a.thigh.length_m = 0.5; // a long but possible thigh
    assert!(a.validate().is_ok());
    a.shank.length_m = 0.01;
    let e = a.validate().unwrap_err().to_string();
    assert!(e.contains("shank.length_m"), "{e}");
    let mut a = Anthropometry::from_height(1.8, 80.0).unwrap();
    a.hand.com_from_proximal_m = 1.0;
    assert!(a
        .validate()
        .unwrap_err()
        .to_string()
        .contains("hand.com_from_proximal_m"));
    let mut a = Anthropometry::from_height(1.8, 80.0).unwrap();
    a.height_m = 1.5; // segments still those of a 1.8 m figure
    let e = a.validate().unwrap_err().to_string();
    assert!(e.contains("length_m") || e.contains("height_m"), "{e}");
    assert!(Anthropometry::from_height(1.8, -3.0)
        .unwrap_err()
        .to_string()
        .contains("mass_kg"));
}
