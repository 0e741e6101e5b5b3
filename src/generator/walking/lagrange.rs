//! An independent derivation of the equations of motion from the Lagrangian of the same model,
//! used to check (and correct) the printed equations of appendix A ([`super::dynamics`]).
//!
//! Only the model's geometry is written down: the centre-of-mass position and the orientation of
//! every body as functions of the generalized coordinates. The kinetic energy
//! `T = Σ ½ m |v|² + ½ I ω²` gets its velocities by forward-mode differentiation of those
//! positions along `q̇`; the potential energy is `V = Σ m g y`. Lagrange's equations
//! `d/dt ∂L/∂q̇ − ∂L/∂q = F` then read
//!
//! ```text
//! M(q) q̈ = F − (∂²T/∂q̇∂q) q̇ + ∂T/∂q − ∂V/∂q,      M = ∂²T/∂q̇²,
//! ```
//!
//! and every partial derivative is taken exactly with nested dual numbers ([`Dual`]), so the
//! comparison with the printed equations is limited by rounding only. Coordinates whose motion is
//! prescribed (the swing hip's `x_h`, `y_h`) are ordinary coordinates of the mechanism whose
//! accelerations are given instead of solved for.
//!
//! No dependency is added: the forward-mode dual number below is 60 lines, nests to any order,
//! and is only used by this cross-check.
use std::ops::{Add, Mul, Neg, Sub};

/// The arithmetic the mechanism geometry needs.
pub trait Scalar:
    Copy + Add<Output = Self> + Sub<Output = Self> + Mul<Output = Self> + Neg<Output = Self>
{
    /// A constant.
    fn cst(x: f64) -> Self;
    /// Sine.
    fn sin(self) -> Self;
    /// Cosine.
    fn cos(self) -> Self;
}

impl Scalar for f64 {
    fn cst(x: f64) -> Self {
        x
    }
    fn sin(self) -> Self {
        f64::sin(self)
    }
    fn cos(self) -> Self {
        f64::cos(self)
    }
}

/// A forward-mode dual number `re + du·ε`, `ε² = 0`, over any [`Scalar`] (so it nests).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Dual<S> {
    /// Value.
    pub re: S,
    /// Derivative part.
    pub du: S,
}

impl<S: Scalar> Add for Dual<S> {
    type Output = Self;
    fn add(self, o: Self) -> Self {
        Dual {
            re: self.re + o.re,
            du: self.du + o.du,
        }
    }
}
impl<S: Scalar> Sub for Dual<S> {
    type Output = Self;
    fn sub(self, o: Self) -> Self {
        Dual {
            re: self.re - o.re,
            du: self.du - o.du,
        }
    }
}
impl<S: Scalar> Mul for Dual<S> {
    type Output = Self;
    fn mul(self, o: Self) -> Self {
        Dual {
            re: self.re * o.re,
            du: self.re * o.du + self.du * o.re,
        }
    }
}
impl<S: Scalar> Neg for Dual<S> {
    type Output = Self;
    fn neg(self) -> Self {
        Dual {
            re: -self.re,
            du: -self.du,
        }
    }
}
impl<S: Scalar> Scalar for Dual<S> {
    fn cst(x: f64) -> Self {
        Dual {
            re: S::cst(x),
            du: S::cst(0.0),
        }
    }
    fn sin(self) -> Self {
        Dual {
            re: self.re.sin(),
            du: self.re.cos() * self.du,
        }
    }
    fn cos(self) -> Self {
        Dual {
            re: self.re.cos(),
            du: -(self.re.sin() * self.du),
        }
    }
}

/// One rigid body of a planar mechanism: mass, central moment of inertia, centre-of-mass
/// position `(x, y)` (y up) and orientation angle.
#[derive(Debug, Clone, Copy)]
pub struct RigidBody<S> {
    /// Mass, kg.
    pub mass: f64,
    /// Moment of inertia about the centre of mass, kg·m².
    pub inertia: f64,
    /// Centre of mass, m.
    pub com: [S; 2],
    /// Orientation, rad.
    pub angle: S,
}

/// A planar mechanism described by its geometry only.
pub trait Mechanism {
    /// Number of coordinates (free and prescribed).
    fn dof(&self) -> usize;
    /// The bodies at coordinates `z`.
    fn bodies<S: Scalar>(&self, z: &[S]) -> Vec<RigidBody<S>>;
    /// Gravity, m/s².
    fn gravity(&self) -> f64;
}

fn kinetic<S: Scalar, M: Mechanism>(m: &M, z: &[S], zd: &[S]) -> S {
    let zz: Vec<Dual<S>> = z.iter().zip(zd).map(|(&re, &du)| Dual { re, du }).collect();
    let mut t = S::cst(0.0);
    for b in m.bodies(&zz) {
        let (vx, vy, w) = (b.com[0].du, b.com[1].du, b.angle.du);
        t = t + S::cst(0.5 * b.mass) * (vx * vx + vy * vy) + S::cst(0.5 * b.inertia) * w * w;
    }
    t
}

fn potential<S: Scalar, M: Mechanism>(m: &M, z: &[S]) -> S {
    let mut v = S::cst(0.0);
    for b in m.bodies(z) {
        v = v + S::cst(b.mass * m.gravity()) * b.com[1];
    }
    v
}

type D2 = Dual<Dual<f64>>;

fn d2(x: f64, outer: f64, inner: f64) -> D2 {
    Dual {
        re: Dual { re: x, du: inner },
        du: Dual { re: outer, du: 0.0 },
    }
}

/// The Lagrangian equations of motion at one state.
#[derive(Debug, Clone)]
pub struct LagrangeTerms {
    /// Mass matrix `∂²T/∂ż²` (all coordinates).
    pub mass: Vec<Vec<f64>>,
    /// `−(∂²T/∂ż∂z) ż + ∂T/∂z − ∂V/∂z`: the right-hand side without the generalized forces.
    pub bias: Vec<f64>,
    /// Total energy `T + V`, J.
    pub energy: f64,
}

/// Mass matrix and bias terms of `m` at `(z, ż)`.
pub fn terms<M: Mechanism>(m: &M, z: &[f64], zd: &[f64]) -> LagrangeTerms {
    let n = m.dof();
    let mut mass = vec![vec![0.0; n]; n];
    for (i, row) in mass.iter_mut().enumerate() {
        for (j, mij) in row.iter_mut().enumerate() {
            let zz: Vec<D2> = z.iter().map(|&x| d2(x, 0.0, 0.0)).collect();
            let vv: Vec<D2> = (0..n)
                .map(|k| {
                    let o = if k == i { 1.0 } else { 0.0 };
                    let inn = if k == j { 1.0 } else { 0.0 };
                    d2(zd[k], o, inn)
                })
                .collect();
            *mij = kinetic(m, &zz, &vv).du.du;
        }
    }
    let mut bias = vec![0.0; n];
    for (i, b) in bias.iter_mut().enumerate() {
        // (∂²T/∂ż_i∂z)·ż: outer ε on ż_i, inner ε along z + ε ż.
        let zz: Vec<D2> = (0..n).map(|k| d2(z[k], 0.0, zd[k])).collect();
        let vv: Vec<D2> = (0..n)
            .map(|k| d2(zd[k], if k == i { 1.0 } else { 0.0 }, 0.0))
            .collect();
        let mixed = kinetic(m, &zz, &vv).du.du;
        let zq: Vec<Dual<f64>> = (0..n)
            .map(|k| Dual {
                re: z[k],
                du: if k == i { 1.0 } else { 0.0 },
            })
            .collect();
        let vq: Vec<Dual<f64>> = zd.iter().map(|&x| Dual { re: x, du: 0.0 }).collect();
        let dt_dz = kinetic(m, &zq, &vq).du;
        let dv_dz = potential(m, &zq).du;
        *b = -mixed + dt_dz - dv_dz;
    }
    let energy = kinetic(m, z, zd) + potential(m, z);
    LagrangeTerms { mass, bias, energy }
}

/// Accelerations of the first `free` coordinates given generalized forces on them and the
/// prescribed accelerations of the remaining coordinates.
pub fn free_accel<M: Mechanism>(
    m: &M,
    z: &[f64],
    zd: &[f64],
    forces: &[f64],
    prescribed_acc: &[f64],
) -> Vec<f64> {
    let t = terms(m, z, zd);
    let nf = forces.len();
    let a = nalgebra::DMatrix::from_fn(nf, nf, |i, j| t.mass[i][j]);
    let b = nalgebra::DVector::from_fn(nf, |i, _| {
        let mut r = forces[i] + t.bias[i];
        for (k, acc) in prescribed_acc.iter().enumerate() {
            r -= t.mass[i][nf + k] * acc;
        }
        r
    });
    match a.lu().solve(&b) {
        Some(x) => x.iter().copied().collect(),
        None => vec![f64::NAN; nf],
    }
}

/// The stance mechanism of figure 2a (coordinates `w, θ1, θ2`), from geometry only.
#[derive(Debug, Clone, Copy)]
pub struct StanceMechanism(pub super::dynamics::StanceModel);

impl Mechanism for StanceMechanism {
    fn dof(&self) -> usize {
        3
    }
    fn gravity(&self) -> f64 {
        self.0.g
    }
    fn bodies<S: Scalar>(&self, z: &[S]) -> Vec<RigidBody<S>> {
        let p = &self.0;
        let (w, t1, t2) = (z[0], z[1], z[2]);
        let (s1, c1, s2, c2) = (t1.sin(), t1.cos(), t2.sin(), t2.cos());
        let hip = [w * s1, w * c1];
        vec![
            // The leg pivots at the ankle; its centre of mass stays r1 from it (table B-1).
            RigidBody {
                mass: p.m1,
                inertia: p.i1,
                com: [S::cst(p.r1) * s1, S::cst(p.r1) * c1],
                angle: t1,
            },
            RigidBody {
                mass: p.m2,
                inertia: p.i2,
                com: [hip[0] + S::cst(p.r2) * s2, hip[1] + S::cst(p.r2) * c2],
                angle: t2,
            },
        ]
    }
}

/// The swing mechanism of figure 2b (coordinates `θ3, θ4, x_h, y_h`), from geometry only.
#[derive(Debug, Clone, Copy)]
pub struct SwingMechanism(pub super::dynamics::SwingModel);

impl Mechanism for SwingMechanism {
    fn dof(&self) -> usize {
        4
    }
    fn gravity(&self) -> f64 {
        self.0.g
    }
    fn bodies<S: Scalar>(&self, z: &[S]) -> Vec<RigidBody<S>> {
        let p = &self.0;
        let (t3, t4, xh, yh) = (z[0], z[1], z[2], z[3]);
        let t34 = t3 + t4;
        let (s3, c3, s34, c34) = (t3.sin(), t3.cos(), t34.sin(), t34.cos());
        let knee = [xh - S::cst(p.l3) * s3, yh - S::cst(p.l3) * c3];
        vec![
            RigidBody {
                mass: p.m3,
                inertia: p.i3,
                com: [xh - S::cst(p.r3) * s3, yh - S::cst(p.r3) * c3],
                angle: t3,
            },
            RigidBody {
                mass: p.m4,
                inertia: p.i4,
                com: [knee[0] - S::cst(p.r4) * s34, knee[1] - S::cst(p.r4) * c34],
                angle: t34,
            },
        ]
    }
}
