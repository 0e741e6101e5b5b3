//! The equations of motion of appendix A, as printed, with the typesetting errors corrected.
//!
//! **Stance (A.1)**, generalized coordinates `q = [w, θ1, θ2]`: `w` the telescopic leg length
//! (ankle to hip), `θ1` the leg angle from the vertical (positive when the hip is ahead of the
//! ankle), `θ2` the upper body angle from the vertical (positive leaning forward). The ankle is
//! fixed (`ẋ = ẏ = ẍ = ÿ = 0`). `A(q) q̈ = B(q, q̇, F)` with
//!
//! ```text
//! A = | m2                 0                      −m2 r2 sin(θ2−θ1)   |
//!     | 0                  I1 + m1 r1² + m2 w²    m2 r2 w cos(θ2−θ1)  |
//!     | −m2 r2 sin(θ2−θ1)  m2 r2 w cos(θ2−θ1)     I2 + m2 r2²         |
//! B = | F_w  + m2 w θ̇1² + m2 r2 θ̇2² cos(θ2−θ1) − m2 g cos θ1                       |
//!     | F_θ1 − 2 m2 w ẇ θ̇1 + (m1 r1 + m2 w) g sin θ1 + m2 r2 w θ̇2² sin(θ2−θ1)       |
//!     | F_θ2 + m2 g r2 sin θ2 − 2 m2 r2 ẇ θ̇1 cos(θ2−θ1) − m2 r2 w θ̇1² sin(θ2−θ1)     |
//! ```
//!
//! **Swing (A.2)**, `q = [θ3, θ4]`: `θ3` the thigh angle from the vertical (positive when the
//! knee is behind the hip, so a leg swung forward has `θ3 < 0`, figure 2b), `θ4` the knee angle
//! (positive in flexion). The hip moves as the stance model dictates, `(ẍ_h, ÿ_h)`:
//!
//! ```text
//! A = | I3 + m3 r3² + m4 l3² + I4 + m4 r4² + 2 m4 l3 r4 cos θ4   I4 + m4 r4² + m4 l3 r4 cos θ4 |
//!     | I4 + m4 r4² + m4 l3 r4 cos θ4                           I4 + m4 r4²                  |
//! B = | F_θ3 + (m3 r3 + m4 l3)(ẍ_h cos θ3 − ÿ_h sin θ3) + m4 r4 (ẍ_h cos θ34 − ÿ_h sin θ34)
//!     |      + m4 l3 r4 θ̇4 (2θ̇3 + θ̇4) sin θ4 − m3 g r3 sin θ3 − m4 g (l3 sin θ3 + r4 sin θ34) |
//!     | F_θ4 + m4 r4 (ẍ_h cos θ34 − ÿ_h sin θ34) − m4 l3 r4 θ̇3² sin θ4 − m4 g r4 sin θ34       |
//! ```
//! with `θ34 = θ3 + θ4`.
//!
//! # Corrections to the printed equations
//! Each was found by the independent Lagrangian derivation in [`super::lagrange`], which the
//! tests compare with this module at random states to 1e-8.
//! 1. A.2, first row of `B`: the printed `m4 l3 r4 θ̇4 (2θ̇3 + θ4) sin θ4` has a `θ4` where `θ̇4`
//!    belongs (the term is a velocity product, `θ4` would make it dimensionally wrong).
//! 2. A.1 and A.2: the entries left symbolic (`a1,3`, `a2,3` in A.1, `a1,2` in A.2) are the
//!    mirror entries: both mass matrices are symmetric (they are Hessians of the kinetic energy).
//! 3. §4.2, rigid (locked) stance leg: the printed modification `a1,1 = 1, b1 = a1,2 = a3,1 = 0
//!    and w = 0` must zero `a1,3` as well (with `a1,3 ≠ 0` the first row gives
//!    `ẅ = −a1,3 θ̈2 ≠ 0`), and "w = 0" means `ẇ = 0` (the leg keeps its length, not zero length).
//! 4. Eq. (5), locked knee in swing1: "θ4 = 0" likewise means `θ̇4 = 0`.
//! 5. The A.2 hip accelerations are printed correctly; `ẋ_h`, `ẏ_h` do not enter the swing
//!    equations (the Lagrangian derivation confirms their terms cancel).
use super::body::Body;
use crate::units::G;

/// Solves the 3×3 symmetric positive definite system `a x = b` by Cholesky.
pub(crate) fn solve3(a: &[[f64; 3]; 3], b: &[f64; 3]) -> [f64; 3] {
    let l11 = a[0][0].sqrt();
    let l21 = a[1][0] / l11;
    let l31 = a[2][0] / l11;
    let l22 = (a[1][1] - l21 * l21).sqrt();
    let l32 = (a[2][1] - l31 * l21) / l22;
    let l33 = (a[2][2] - l31 * l31 - l32 * l32).sqrt();
    let y1 = b[0] / l11;
    let y2 = (b[1] - l21 * y1) / l22;
    let y3 = (b[2] - l31 * y1 - l32 * y2) / l33;
    let x3 = y3 / l33;
    let x2 = (y2 - l32 * x3) / l22;
    let x1 = (y1 - l21 * x2 - l31 * x3) / l11;
    [x1, x2, x3]
}

/// Solves the 2×2 system `a x = b` (Cramer).
pub(crate) fn solve2(a: &[[f64; 2]; 2], b: &[f64; 2]) -> [f64; 2] {
    let det = a[0][0] * a[1][1] - a[0][1] * a[1][0];
    [
        (b[0] * a[1][1] - a[0][1] * b[1]) / det,
        (a[0][0] * b[1] - a[1][0] * b[0]) / det,
    ]
}

/// The stance model of figure 2a: telescopic inverted pendulum (leg) carrying the upper body.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct StanceModel {
    /// Leg mass, kg.
    pub m1: f64,
    /// Leg centre of mass from the ankle, m.
    pub r1: f64,
    /// Leg moment of inertia about its centre of mass, kg·m².
    pub i1: f64,
    /// Upper body mass, kg.
    pub m2: f64,
    /// Upper body centre of mass from the hip, m.
    pub r2: f64,
    /// Upper body moment of inertia about its centre of mass, kg·m².
    pub i2: f64,
    /// Gravity, m/s².
    pub g: f64,
}

impl StanceModel {
    /// The model of `body`.
    pub fn new(body: &Body) -> StanceModel {
        StanceModel {
            m1: body.m1,
            r1: body.r1,
            i1: body.i1,
            m2: body.m2,
            r2: body.r2,
            i2: body.i2,
            g: G,
        }
    }

    /// Inertia matrix `A(q)` of A.1 (symmetric, correction 2).
    pub fn mass_matrix(&self, q: &[f64; 3]) -> [[f64; 3]; 3] {
        let [w, t1, t2] = *q;
        let (s21, c21) = (t2 - t1).sin_cos();
        let a13 = -self.m2 * self.r2 * s21;
        let a23 = self.m2 * self.r2 * w * c21;
        [
            [self.m2, 0.0, a13],
            [
                0.0,
                self.i1 + self.m1 * self.r1 * self.r1 + self.m2 * w * w,
                a23,
            ],
            [a13, a23, self.i2 + self.m2 * self.r2 * self.r2],
        ]
    }

    /// Right-hand side `B(q, q̇, F)` of A.1; `f = [F_w, F_θ1, F_θ2]`.
    pub fn rhs(&self, q: &[f64; 3], qd: &[f64; 3], f: &[f64; 3]) -> [f64; 3] {
        let [w, t1, t2] = *q;
        let [wd, t1d, t2d] = *qd;
        let (m1, r1, m2, r2, g) = (self.m1, self.r1, self.m2, self.r2, self.g);
        let (s21, c21) = (t2 - t1).sin_cos();
        let (s1, c1) = t1.sin_cos();
        let s2 = t2.sin();
        [
            f[0] + m2 * w * t1d * t1d + m2 * r2 * t2d * t2d * c21 - m2 * g * c1,
            f[1] - 2.0 * m2 * w * wd * t1d
                + (m1 * r1 + m2 * w) * g * s1
                + m2 * r2 * w * t2d * t2d * s21,
            f[2] + m2 * g * r2 * s2
                - 2.0 * m2 * r2 * wd * t1d * c21
                - m2 * r2 * w * t1d * t1d * s21,
        ]
    }

    /// Accelerations `q̈`. With `locked` the leg is rigid (§4.2 with correction 3): `ẅ = 0` and
    /// `F_w` is ignored (the leg's reaction replaces it).
    pub fn accel(&self, q: &[f64; 3], qd: &[f64; 3], f: &[f64; 3], locked: bool) -> [f64; 3] {
        let a = self.mass_matrix(q);
        let b = self.rhs(q, qd, f);
        if locked {
            let x = solve2(&[[a[1][1], a[1][2]], [a[2][1], a[2][2]]], &[b[1], b[2]]);
            [0.0, x[0], x[1]]
        } else {
            solve3(&a, &b)
        }
    }

    /// The leg-axis force that keeps `ẅ = 0` in the locked state (the leg's reaction), N.
    pub fn locked_reaction(&self, q: &[f64; 3], qd: &[f64; 3], f: &[f64; 3]) -> f64 {
        let qdd = self.accel(q, qd, f, true);
        let a = self.mass_matrix(q);
        let b = self.rhs(q, qd, &[0.0, f[1], f[2]]);
        // Row 1 with ẅ = 0: a12 θ̈1 + a13 θ̈2 = F_w + b1(F_w = 0).
        a[0][1] * qdd[1] + a[0][2] * qdd[2] - b[0]
    }

    /// Kinetic energy, J.
    pub fn kinetic_energy(&self, q: &[f64; 3], qd: &[f64; 3]) -> f64 {
        let a = self.mass_matrix(q);
        let mut t = 0.0;
        for i in 0..3 {
            for j in 0..3 {
                t += 0.5 * qd[i] * a[i][j] * qd[j];
            }
        }
        t
    }

    /// Gravitational potential energy relative to the ankle's height, J.
    pub fn potential_energy(&self, q: &[f64; 3]) -> f64 {
        let [w, t1, t2] = *q;
        self.g * (self.m1 * self.r1 * t1.cos() + self.m2 * (w * t1.cos() + self.r2 * t2.cos()))
    }

    /// Hip position, velocity and acceleration relative to the ankle (A.2's `x_h`, `y_h` and
    /// their derivatives).
    pub fn hip(q: &[f64; 3], qd: &[f64; 3], qdd: &[f64; 3]) -> HipMotion {
        let (w, t1) = (q[0], q[1]);
        let (wd, t1d) = (qd[0], qd[1]);
        let (wdd, t1dd) = (qdd[0], qdd[1]);
        let (s1, c1) = t1.sin_cos();
        HipMotion {
            pos: [w * s1, w * c1],
            vel: [wd * s1 + w * t1d * c1, wd * c1 - w * t1d * s1],
            acc: [
                wdd * s1 + 2.0 * wd * t1d * c1 + w * (t1dd * c1 - t1d * t1d * s1),
                wdd * c1 - 2.0 * wd * t1d * s1 - w * (t1dd * s1 + t1d * t1d * c1),
            ],
        }
    }
}

/// Position, velocity and acceleration of the hip (x forward, y up), SI.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct HipMotion {
    /// Position, m.
    pub pos: [f64; 2],
    /// Velocity, m/s.
    pub vel: [f64; 2],
    /// Acceleration, m/s².
    pub acc: [f64; 2],
}

/// The swing model of figure 2b: a double pendulum (thigh, shank) hanging from a moving hip.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SwingModel {
    /// Thigh length, m.
    pub l3: f64,
    /// Thigh mass, kg.
    pub m3: f64,
    /// Thigh centre of mass from the hip, m.
    pub r3: f64,
    /// Thigh moment of inertia, kg·m².
    pub i3: f64,
    /// Shank length, m.
    pub l4: f64,
    /// Shank mass, kg.
    pub m4: f64,
    /// Shank centre of mass from the knee, m.
    pub r4: f64,
    /// Shank moment of inertia, kg·m².
    pub i4: f64,
    /// Gravity, m/s².
    pub g: f64,
}

impl SwingModel {
    /// The model of `body`.
    pub fn new(body: &Body) -> SwingModel {
        SwingModel {
            l3: body.l3,
            m3: body.m3,
            r3: body.r3,
            i3: body.i3,
            l4: body.l4,
            m4: body.m4,
            r4: body.r4,
            i4: body.i4,
            g: G,
        }
    }

    /// Inertia matrix of A.2 (symmetric, correction 2).
    pub fn mass_matrix(&self, q: &[f64; 2]) -> [[f64; 2]; 2] {
        let c4 = q[1].cos();
        let k = self.m4 * self.l3 * self.r4;
        let a22 = self.i4 + self.m4 * self.r4 * self.r4;
        let a12 = a22 + k * c4;
        let a11 = self.i3
            + self.m3 * self.r3 * self.r3
            + self.m4 * self.l3 * self.l3
            + a22
            + 2.0 * k * c4;
        [[a11, a12], [a12, a22]]
    }

    /// Right-hand side of A.2 with correction 1; `f = [F_θ3, F_θ4]`, `hip_acc = [ẍ_h, ÿ_h]`.
    pub fn rhs(&self, q: &[f64; 2], qd: &[f64; 2], f: &[f64; 2], hip_acc: &[f64; 2]) -> [f64; 2] {
        let [t3, t4] = *q;
        let [t3d, t4d] = *qd;
        let [xa, ya] = *hip_acc;
        let (s3, c3) = t3.sin_cos();
        let (s34, c34) = (t3 + t4).sin_cos();
        let s4 = t4.sin();
        let (m3, r3, l3, m4, r4, g) = (self.m3, self.r3, self.l3, self.m4, self.r4, self.g);
        let drive34 = m4 * r4 * (xa * c34 - ya * s34);
        [
            f[0] + (m3 * r3 + m4 * l3) * (xa * c3 - ya * s3)
                + drive34
                + m4 * l3 * r4 * t4d * (2.0 * t3d + t4d) * s4
                - m3 * g * r3 * s3
                - m4 * g * (l3 * s3 + r4 * s34),
            f[1] + drive34 - m4 * l3 * r4 * t3d * t3d * s4 - m4 * g * r4 * s34,
        ]
    }

    /// Accelerations `[θ̈3, θ̈4]`; with `knee_locked` eq. (5) with correction 4 (`θ̈4 = 0`).
    pub fn accel(
        &self,
        q: &[f64; 2],
        qd: &[f64; 2],
        f: &[f64; 2],
        hip_acc: &[f64; 2],
        knee_locked: bool,
    ) -> [f64; 2] {
        let a = self.mass_matrix(q);
        let b = self.rhs(q, qd, f, hip_acc);
        if knee_locked {
            [b[0] / a[0][0], 0.0]
        } else {
            solve2(&a, &b)
        }
    }

    /// Kinetic energy with the hip at rest, J.
    pub fn kinetic_energy(&self, q: &[f64; 2], qd: &[f64; 2]) -> f64 {
        let a = self.mass_matrix(q);
        0.5 * (a[0][0] * qd[0] * qd[0] + 2.0 * a[0][1] * qd[0] * qd[1] + a[1][1] * qd[1] * qd[1])
    }

    /// Gravitational potential energy relative to the hip, J.
    pub fn potential_energy(&self, q: &[f64; 2]) -> f64 {
        let [t3, t4] = *q;
        -self.g
            * (self.m3 * self.r3 * t3.cos()
                + self.m4 * (self.l3 * t3.cos() + self.r4 * (t3 + t4).cos()))
    }

    /// Knee and ankle positions relative to the hip, m.
    pub fn knee_ankle(&self, q: &[f64; 2]) -> ([f64; 2], [f64; 2]) {
        let (s3, c3) = q[0].sin_cos();
        let (s34, c34) = (q[0] + q[1]).sin_cos();
        let knee = [-self.l3 * s3, -self.l3 * c3];
        (knee, [knee[0] - self.l4 * s34, knee[1] - self.l4 * c34])
    }
}
