//! The dynamic model's segment parameters from body height and mass (table B-1 of Bruderlin &
//! Calvert 1989, appendix B).
//!
//! Lengths in table B-1 are fractions of body height, masses fractions of body mass; `r_i`
//! (centre of mass) is measured from the proximal end except for `r_1`, measured from the distal
//! end (the ankle); `γ_i` (radius of gyration) is about the centre of mass. The moment of inertia
//! about the centre of mass is therefore `I_i = m_i · (γ_i · l_i)²`.
//!
//! **Appendix B's worked example is inconsistent with its own table.** For h = 1.8 m, m = 80 kg
//! it prints `I_3 = m_3·(l_3·r_3)² = 0.0276 kg·m²`, i.e. 8 · (0.426 · 0.138)², which multiplies
//! the absolute radius of gyration (0.138 m = 0.323 · 0.426 m) by the length a second time and is
//! dimensionally kg·m⁴. The table's definition gives `I_3 = 8 · 0.138² = 0.1515 kg·m²`, which is
//! also what Winter's tables (the source of γ = 0.323 for the thigh) give. We use the table.
//!
//! The foot segments (`l_8`, `l_9`, `l_11`, `l_12`, `l_13`) carry no mass: the model's feet are
//! kinematic (§4).

/// Relative segment values of table B-1 (lengths / body height, masses / body mass).
pub mod table_b1 {
    /// Pelvis width `l_0` (hip joint to hip joint).
    pub const L0: f64 = 0.10059;
    /// Leg: centre of mass from the distal end (ankle), fraction of `l_1`.
    pub const R1: f64 = 0.553;
    /// Leg: radius of gyration, fraction of `l_1`.
    pub const GAMMA1: f64 = 0.326;
    /// Upper body length.
    pub const L2: f64 = 0.47;
    /// Upper body mass.
    pub const M2: f64 = 0.678;
    /// Upper body centre of mass from the hip, fraction of `l_2`.
    pub const R2: f64 = 0.5;
    /// Upper body radius of gyration, fraction of `l_2`.
    pub const GAMMA2: f64 = 0.496;
    /// Thigh length.
    pub const L3: f64 = 0.23669;
    /// Thigh mass.
    pub const M3: f64 = 0.1;
    /// Thigh centre of mass from the hip, fraction of `l_3`.
    pub const R3: f64 = 0.433;
    /// Thigh radius of gyration, fraction of `l_3`.
    pub const GAMMA3: f64 = 0.323;
    /// Shank length.
    pub const L4: f64 = 0.24556;
    /// Shank mass.
    pub const M4: f64 = 0.061;
    /// Shank centre of mass from the knee, fraction of `l_4`.
    pub const R4: f64 = 0.606;
    /// Shank radius of gyration, fraction of `l_4`.
    pub const GAMMA4: f64 = 0.416;
    /// Mid foot length `l_5`.
    pub const L5: f64 = 0.0858;
    /// Toe length `l_6`.
    pub const L6: f64 = 0.04734;
    /// Hind foot `l_8` (horizontal heel–ankle distance).
    pub const L8: f64 = 0.02959;
    /// Ankle to foot base `l_9` (ankle height over a flat foot).
    pub const L9: f64 = 0.03846;
    /// Heel to ankle `l_11`.
    pub const L11: f64 = 0.04853;
    /// Ankle to first metatarsal head `l_12`.
    pub const L12: f64 = 0.08901;
    /// First metatarsal head to toe tip `l_13`.
    pub const L13: f64 = 0.0496;
}

/// Absolute segment values (SI) of the KLAW dynamic model for one body.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Body {
    /// Body height, m.
    pub height_m: f64,
    /// Body mass, kg.
    pub mass_kg: f64,
    /// Pelvis width `l_0` (hip joint to hip joint), m.
    pub l0: f64,
    /// Unloaded leg length `l_1 = l_3 + l_4` (hip to ankle), m.
    pub l1: f64,
    /// Leg mass `m_1 = m_3 + m_4`, kg.
    pub m1: f64,
    /// Leg centre of mass from the ankle, m.
    pub r1: f64,
    /// Leg moment of inertia about its centre of mass, kg·m².
    pub i1: f64,
    /// Upper body length, m.
    pub l2: f64,
    /// Upper body mass, kg.
    pub m2: f64,
    /// Upper body centre of mass from the hip, m.
    pub r2: f64,
    /// Upper body moment of inertia about its centre of mass, kg·m².
    pub i2: f64,
    /// Thigh length, m.
    pub l3: f64,
    /// Thigh mass, kg.
    pub m3: f64,
    /// Thigh centre of mass from the hip, m.
    pub r3: f64,
    /// Thigh moment of inertia about its centre of mass, kg·m².
    pub i3: f64,
    /// Shank length (knee to ankle), m.
    pub l4: f64,
    /// Shank mass, kg.
    pub m4: f64,
    /// Shank centre of mass from the knee, m.
    pub r4: f64,
    /// Shank moment of inertia about its centre of mass, kg·m².
    pub i4: f64,
    /// Hind foot `l_8` (horizontal heel–ankle distance), m.
    pub l8: f64,
    /// Ankle height over a flat foot `l_9`, m.
    pub l9: f64,
    /// Heel to ankle `l_11`, m.
    pub l11: f64,
    /// Ankle to first metatarsal head `l_12`, m.
    pub l12: f64,
    /// First metatarsal head to toe tip `l_13`, m.
    pub l13: f64,
}

impl Body {
    /// Absolute values from body height (m) and mass (kg) by table B-1; `I = m·(γ·l)²`.
    ///
    /// The caller validates height and mass (see [`super::high_level`]).
    pub fn from_table_b1(height_m: f64, mass_kg: f64) -> Body {
        use table_b1 as t;
        let h = height_m;
        let m = mass_kg;
        let l3 = t::L3 * h;
        let l4 = t::L4 * h;
        let l1 = l3 + l4;
        let m3 = t::M3 * m;
        let m4 = t::M4 * m;
        let m1 = m3 + m4;
        let l2 = t::L2 * h;
        let m2 = t::M2 * m;
        Body {
            height_m,
            mass_kg,
            l0: t::L0 * h,
            l1,
            m1,
            r1: t::R1 * l1,
            i1: m1 * (t::GAMMA1 * l1).powi(2),
            l2,
            m2,
            r2: t::R2 * l2,
            i2: m2 * (t::GAMMA2 * l2).powi(2),
            l3,
            m3,
            r3: t::R3 * l3,
            i3: m3 * (t::GAMMA3 * l3).powi(2),
            l4,
            m4,
            r4: t::R4 * l4,
            i4: m4 * (t::GAMMA4 * l4).powi(2),
            l8: t::L8 * h,
            l9: t::L9 * h,
            l11: t::L11 * h,
            l12: t::L12 * h,
            l13: t::L13 * h,
        }
    }

    /// Angle `ω_8` between the sole and the heel–ankle line, `cos ω_8 = l_8 / l_11` (§3).
    pub fn omega8(&self) -> f64 {
        (self.l8 / self.l11).clamp(-1.0, 1.0).acos()
    }

    /// Horizontal distance from the ankle to the first metatarsal head over a flat foot, m.
    pub fn ankle_to_meta_x(&self) -> f64 {
        (self.l12 * self.l12 - self.l9 * self.l9).max(0.0).sqrt()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn thigh_example_of_appendix_b() {
        // Appendix B, h = 1.8 m, m = 80 kg: m3 = 8 kg, l3 = 0.426 m, r3 = 0.184 m, γ3 = 0.138 m.
        let b = Body::from_table_b1(1.8, 80.0);
        assert!((b.m3 - 8.0).abs() < 1e-12);
        assert!((b.l3 - 0.426).abs() < 5e-4);
        assert!((b.r3 - 0.184).abs() < 5e-4);
        assert!((table_b1::GAMMA3 * b.l3 - 0.138).abs() < 5e-4);
        // The table's I = m·(γ·l)² ...
        assert!((b.i3 - 0.1515).abs() < 5e-4, "I3 = {}", b.i3);
        // ... while the printed 0.0276 is m·(l·γ_abs)², a length too many.
        // (With the printed, rounded 0.426 m and 0.138 m: 8·(0.426·0.138)² = 0.02766.)
        let misprint = 8.0 * (0.426f64 * 0.138).powi(2);
        assert!((misprint - 0.0276).abs() < 1e-4, "misprint reproduces as {misprint}");
        let dimensionally_consistent = 8.0 * 0.138f64.powi(2);
        assert!((dimensionally_consistent - b.i3).abs() < 1e-3);
    }

    #[test]
    fn masses_add_up_and_heel_geometry_is_consistent() {
        let b = Body::from_table_b1(1.8, 80.0);
        // Upper body + two legs = whole body (the feet are massless).
        assert!((b.m2 + 2.0 * b.m1 - 80.0).abs() < 1e-9);
        // l11 is the hypotenuse of l8 and l9 (to the table's 4 digits).
        assert!(((b.l8.powi(2) + b.l9.powi(2)).sqrt() - b.l11).abs() < 1e-4 * 1.8);
    }
}
