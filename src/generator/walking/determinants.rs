//! The determinants of gait (§4.2): pelvic rotation, pelvic list and the lateral displacement of
//! the body, interpolated linearly between their boundary values over a step.
use crate::events::Side;
use crate::generator::skeleton::Euler;
use glam::{DQuat, DVec3};
use std::f64::consts::PI;

/// The pelvic determinants of gait during one step (§4.2), as functions of the time since the
/// step's heel strike: rotation ψ (the swing hip ahead of the stance hip; −ψmax at the start,
/// +ψmax at heel strike), list λ (swing side down; 0 at heel strike, maximal at mid-step),
/// lateral displacement toward the stance foot (0 at heel strike). The paper interpolates them
/// linearly between their boundary values; the swing hip's *acceleration* drives the swing
/// dynamics, which a piecewise-linear path would make impulsive at the knots, so a half-cosine
/// (C¹, same boundary values) is used instead.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Determinants {
    /// Step duration, s.
    pub duration: f64,
    /// Maximal rotation, rad.
    pub rotation: f64,
    /// Maximal list, rad.
    pub list: f64,
    /// Maximal lateral displacement, m.
    pub lateral: f64,
    /// Half the pelvis width, m.
    pub half_width: f64,
    /// The swing side.
    pub swing: Side,
    /// First step from rest (rotation starts at 0).
    pub from_rest: bool,
    /// Last step to rest (rotation ends at 0).
    pub to_rest: bool,
}

impl Determinants {
    pub(super) fn side_sign(s: Side) -> f64 {
        match s {
            Side::Left => -1.0,
            Side::Right => 1.0,
        }
    }
    /// ψ(t).
    pub fn rotation_at(&self, t: f64) -> f64 {
        let c = (PI * (t / self.duration).clamp(0.0, 1.0)).cos();
        let (a, b) = (
            if self.from_rest { 0.0 } else { -self.rotation },
            if self.to_rest { 0.0 } else { self.rotation },
        );
        a + (b - a) * 0.5 * (1.0 - c)
    }
    /// λ(t).
    pub fn list_at(&self, t: f64) -> f64 {
        self.list * (PI * (t / self.duration).clamp(0.0, 1.0)).sin().powi(2)
    }
    /// Lateral position of the pelvis centre (toward the stance foot), m.
    pub fn lateral_at(&self, t: f64) -> f64 {
        -Determinants::side_sign(self.swing)
            * self.lateral
            * (PI * (t / self.duration).clamp(0.0, 1.0)).sin()
    }
    /// Pelvis orientation (figure convention) at `t`.
    pub fn pelvis(&self, t: f64) -> DQuat {
        let s = Determinants::side_sign(self.swing);
        Euler::new(0.0, s * self.list_at(t), s * self.rotation_at(t)).to_quat()
    }
    /// Offset of the swing hip from the pelvis centre, m.
    pub fn swing_offset(&self, t: f64) -> DVec3 {
        self.pelvis(t)
            * DVec3::new(
                0.0,
                0.0,
                Determinants::side_sign(self.swing) * self.half_width,
            )
    }
    /// Swing hip minus the dynamic hip in the sagittal plane `(dx, dy)` (the stance hip is at
    /// `(−dx_offset, 0)`; see [`Determinants::swing_offset`]): with the pelvis rotation
    /// `Rx(±λ)·Ry(±ψ)`, `(a·sin ψ, −2a·cos ψ·sin λ)`, `a` half the pelvis width.
    pub fn swing_hip_offset(&self, t: f64) -> [f64; 2] {
        let (sp, cp) = self.rotation_at(t).sin_cos();
        let a = self.half_width;
        [a * sp, -2.0 * a * cp * self.list_at(t).sin()]
    }

    /// [`Determinants::swing_hip_offset`] and its first and second time derivatives, analytic
    /// (the swing dynamics read the swing hip's acceleration).
    pub fn swing_hip_offset_rates(&self, t: f64) -> ([f64; 2], [f64; 2], [f64; 2]) {
        let a = self.half_width;
        let s = t / self.duration;
        let inside = (0.0..=1.0).contains(&s);
        let w = PI / self.duration;
        let (s1, c1) = (PI * s.clamp(0.0, 1.0)).sin_cos();
        let (s2, c2) = (2.0 * PI * s.clamp(0.0, 1.0)).sin_cos();
        let (pa, pb) = (
            if self.from_rest { 0.0 } else { -self.rotation },
            if self.to_rest { 0.0 } else { self.rotation },
        );
        let psi = pa + (pb - pa) * 0.5 * (1.0 - c1);
        let lam = self.list * 0.5 * (1.0 - c2);
        let (psi1, psi2, lam1, lam2) = if inside {
            (
                (pb - pa) * 0.5 * w * s1,
                (pb - pa) * 0.5 * w * w * c1,
                self.list * w * s2,
                self.list * 2.0 * w * w * c2,
            )
        } else {
            (0.0, 0.0, 0.0, 0.0)
        };
        let (sp, cp) = psi.sin_cos();
        let (sl, cl) = lam.sin_cos();
        let pos = [a * sp, -2.0 * a * cp * sl];
        let vel = [a * cp * psi1, -2.0 * a * (-sp * psi1 * sl + cp * cl * lam1)];
        let acc = [
            a * (cp * psi2 - sp * psi1 * psi1),
            -2.0 * a
                * (-cp * psi1 * psi1 * sl - sp * psi2 * sl - 2.0 * sp * psi1 * cl * lam1
                    + cp * (-sl * lam1 * lam1 + cl * lam2)),
        ];
        (pos, vel, acc)
    }
}
