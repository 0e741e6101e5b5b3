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
//! The foot carries no mass: the model's feet are kinematic (§4); its geometry is the shared
//! figure's ([`FootGeometry`](crate::generator::anthropometry::FootGeometry)).
//!
//! The values come from the shared figure ([`Anthropometry`]), so the dynamics and the exported
//! skeleton have the same proportions.
use crate::generator::anthropometry::Anthropometry;
use crate::generator::GenerateError;

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
    /// Heel sole point relative to the ankle, foot flat, m (x forward, y up).
    pub heel: [f64; 2],
    /// Metatarsal (ball) joint centre relative to the ankle, foot flat, m.
    pub mtp: [f64; 2],
    /// Ball sole point (under the metatarsal joint) relative to the ankle, foot flat, m.
    pub ball: [f64; 2],
    /// Toe tip relative to the ankle, foot flat, m.
    pub toe: [f64; 2],
}

impl Body {
    /// The dynamic model of the shared figure's anthropometry (table B-1; `I = m·(γ·l)²`).
    pub fn new(a: &Anthropometry) -> Body {
        let leg = a.leg();
        let f = &a.foot;
        let mtp = [f.mid_foot_m, f.metatarsal_height_m - f.ankle_height_m];
        Body {
            height_m: a.height_m,
            mass_kg: a.mass_kg,
            l0: a.hip_width_m,
            l1: leg.length_m,
            m1: leg.mass_kg,
            r1: leg.com_from_distal_m(),
            i1: leg.moment_of_inertia_kg_m2(),
            l2: a.upper_body.length_m,
            m2: a.upper_body.mass_kg,
            r2: a.upper_body.com_from_proximal_m,
            i2: a.upper_body.moment_of_inertia_kg_m2(),
            l3: a.thigh.length_m,
            m3: a.thigh.mass_kg,
            r3: a.thigh.com_from_proximal_m,
            i3: a.thigh.moment_of_inertia_kg_m2(),
            l4: a.shank.length_m,
            m4: a.shank.mass_kg,
            r4: a.shank.com_from_proximal_m,
            i4: a.shank.moment_of_inertia_kg_m2(),
            l8: f.hind_foot_m,
            l9: f.ankle_height_m,
            l11: f.heel_ankle_m(),
            heel: [-f.hind_foot_m, -f.ankle_height_m],
            mtp,
            ball: [f.mid_foot_m, -f.ankle_height_m],
            toe: [f.mid_foot_m + f.toe_m, -f.ankle_height_m],
        }
    }

    /// The dynamic model of a figure of height `height_m` and mass `mass_kg` with the table's
    /// proportions.
    pub fn from_height(height_m: f64, mass_kg: f64) -> Result<Body, GenerateError> {
        Ok(Body::new(&Anthropometry::from_height(height_m, mass_kg)?))
    }

    /// Angle `ω_8` between the sole and the heel–ankle line, `cos ω_8 = l_8 / l_11` (§3).
    pub fn omega8(&self) -> f64 {
        (self.l8 / self.l11).clamp(-1.0, 1.0).acos()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn thigh_example_of_appendix_b() {
        // Appendix B, h = 1.8 m, m = 80 kg: m3 = 8 kg, l3 = 0.426 m, r3 = 0.184 m, γ3 = 0.138 m.
        let b = Body::from_height(1.8, 80.0).unwrap();
        assert!((b.m3 - 8.0).abs() < 1e-12);
        assert!((b.l3 - 0.426).abs() < 5e-4);
        assert!((b.r3 - 0.184).abs() < 5e-4);
        // The table's I = m·(γ·l)² ...
        assert!((b.i3 - 0.1515).abs() < 5e-4, "I3 = {}", b.i3);
        // ... while the printed 0.0276 is m·(l·γ_abs)² with the printed, rounded 0.426 m and
        // 0.138 m (a length too many).
        let misprint = 8.0 * (0.426f64 * 0.138).powi(2);
        assert!(
            (misprint - 0.0276).abs() < 1e-4,
            "misprint reproduces as {misprint}"
        );
        assert!((8.0 * 0.138f64.powi(2) - b.i3).abs() < 1e-3);
    }

    #[test]
    fn masses_add_up_and_leg_is_the_table_leg() {
        let b = Body::from_height(1.8, 80.0).unwrap();
        // Upper body + two legs = whole body (the feet are massless).
        assert!((b.m2 + 2.0 * b.m1 - 80.0).abs() < 1e-9);
        assert!((b.l1 - b.l3 - b.l4).abs() < 1e-12);
        assert!((b.r1 - 0.553 * b.l1).abs() < 1e-12);
        assert!((b.i1 - b.m1 * (0.326 * b.l1).powi(2)).abs() < 1e-12);
    }
}
