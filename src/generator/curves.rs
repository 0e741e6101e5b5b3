//! Interpolation primitives shared by the generators, evaluated every frame: cubic Hermite
//! segments (scalar and 3-D), the quintic Hermite segment, the C² middle-knot velocity and the
//! smoothstep blends. No allocation.
use glam::DVec3;

/// Value and derivative of the cubic Hermite segment through `(t0, p0, m0)` and `(t1, p1, m1)`
/// at `t` (clamped to the segment).
#[inline]
pub fn hermite(t0: f64, t1: f64, p0: f64, p1: f64, m0: f64, m1: f64, t: f64) -> (f64, f64) {
    let h = t1 - t0;
    if h <= 0.0 {
        return (p1, m1);
    }
    let s = ((t - t0) / h).clamp(0.0, 1.0);
    let s2 = s * s;
    let s3 = s2 * s;
    let h00 = 2.0 * s3 - 3.0 * s2 + 1.0;
    let h10 = s3 - 2.0 * s2 + s;
    let h01 = -2.0 * s3 + 3.0 * s2;
    let h11 = s3 - s2;
    let v = h00 * p0 + h10 * h * m0 + h01 * p1 + h11 * h * m1;
    let d00 = 6.0 * s2 - 6.0 * s;
    let d10 = 3.0 * s2 - 4.0 * s + 1.0;
    let d01 = -6.0 * s2 + 6.0 * s;
    let d11 = 3.0 * s2 - 2.0 * s;
    let d = (d00 * p0 + d01 * p1) / h + d10 * m0 + d11 * m1;
    (v, d)
}

/// [`hermite`] with the second derivative: value, first and second derivative at `t` (the
/// walking generator's swing thigh path needs the acceleration, `walking::swing`).
pub fn hermite_acc(
    t0: f64,
    t1: f64,
    p0: f64,
    p1: f64,
    m0: f64,
    m1: f64,
    t: f64,
) -> (f64, f64, f64) {
    let (v, d) = hermite(t0, t1, p0, p1, m0, m1, t);
    let h = t1 - t0;
    if h <= 0.0 {
        return (v, d, 0.0);
    }
    let s = ((t - t0) / h).clamp(0.0, 1.0);
    let dd = ((12.0 * s - 6.0) * (p0 - p1)) / (h * h)
        + ((6.0 * s - 4.0) * m0 + (6.0 * s - 2.0) * m1) / h;
    (v, d, dd)
}

/// 3-D cubic Hermite segment.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct Seg3 {
    /// Start time.
    pub t0: f64,
    /// End time.
    pub t1: f64,
    /// Start point.
    pub p0: DVec3,
    /// End point.
    pub p1: DVec3,
    /// Start velocity.
    pub v0: DVec3,
    /// End velocity.
    pub v1: DVec3,
}

impl Seg3 {
    /// Position and velocity at `t`.
    #[inline]
    pub fn eval(&self, t: f64) -> (DVec3, DVec3) {
        let (x, dx) = hermite(
            self.t0, self.t1, self.p0.x, self.p1.x, self.v0.x, self.v1.x, t,
        );
        let (y, dy) = hermite(
            self.t0, self.t1, self.p0.y, self.p1.y, self.v0.y, self.v1.y, t,
        );
        let (z, dz) = hermite(
            self.t0, self.t1, self.p0.z, self.p1.z, self.v0.z, self.v1.z, t,
        );
        (DVec3::new(x, y, z), DVec3::new(dx, dy, dz))
    }
}

/// Velocity at the middle knot of a clamped cubic spline through three equally spaced points
/// (C2 there): m1 = (3(p2 − p0)/h − m0 − m2)/4.
#[inline]
pub fn c2_mid_velocity(p0: DVec3, p2: DVec3, v0: DVec3, v2: DVec3, h: f64) -> DVec3 {
    (3.0 * (p2 - p0) / h - v0 - v2) / 4.0
}

/// `3s² − 2s³` on [0, 1] (clamped): a C¹ blend used for the kinematic interpolations.
#[inline]
pub fn smoothstep(s: f64) -> f64 {
    let s = s.clamp(0.0, 1.0);
    s * s * (3.0 - 2.0 * s)
}

/// `6s⁵ − 15s⁴ + 10s³` on [0, 1] (clamped): a C² blend (zero rate and acceleration at both
/// ends).
#[inline]
pub fn smootherstep(s: f64) -> f64 {
    let s = s.clamp(0.0, 1.0);
    s * s * s * (s * (6.0 * s - 15.0) + 10.0)
}

/// The quintic Hermite segment on `[0, d]` from `(p0, v0, a0)` to `(p1, v1, a1)` (value, rate,
/// acceleration at each end): the C² interpolant of KLAW's recorded tracks and the stop's
/// curves. Constant beyond `d` when read by time ([`Quintic::at`]).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Quintic {
    c: [f64; 6],
    d: f64,
}

impl Quintic {
    /// The quintic with the given end values, rates and accelerations over `d > 0` s.
    pub fn new(start: [f64; 3], end: [f64; 3], d: f64) -> Quintic {
        let [p0, v0, a0] = start;
        let [p1, v1, a1] = end;
        // In s = t/d: q(s) = Σ c_i s^i with q'(s) = v·d and q''(s) = a·d².
        let c1 = d * v0;
        let c2 = 0.5 * d * d * a0;
        let p = p1 - p0 - c1 - c2;
        let v = d * v1 - c1 - 2.0 * c2;
        let acc = d * d * a1 - 2.0 * c2;
        let c3 = 10.0 * p - 4.0 * v + 0.5 * acc;
        let c4 = -15.0 * p + 7.0 * v - acc;
        let c5 = 6.0 * p - 3.0 * v + 0.5 * acc;
        Quintic {
            c: [p0, c1, c2, c3, c4, c5],
            d,
        }
    }

    /// Value, rate and acceleration at `t` s (clamped to `[0, d]`; rates 0 from `d` on).
    pub fn at(&self, t: f64) -> [f64; 3] {
        let r = self.at_fraction((t / self.d).clamp(0.0, 1.0));
        if t >= self.d {
            return [r[0], 0.0, 0.0];
        }
        r
    }

    /// Value, rate and acceleration (per second) at the fraction `s = t/d` of the segment.
    pub fn at_fraction(&self, s: f64) -> [f64; 3] {
        let c = &self.c;
        let p = c[0] + s * (c[1] + s * (c[2] + s * (c[3] + s * (c[4] + s * c[5]))));
        let v = c[1] + s * (2.0 * c[2] + s * (3.0 * c[3] + s * (4.0 * c[4] + s * 5.0 * c[5])));
        let a = 2.0 * c[2] + s * (6.0 * c[3] + s * (12.0 * c[4] + s * 20.0 * c[5]));
        [p, v / self.d, a / (self.d * self.d)]
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn quintic_meets_its_end_conditions() {
        let q = Quintic::new([0.3, 1.2, -0.7], [1.0, 0.0, 0.0], 0.8);
        let a = q.at(0.0);
        assert!((a[0] - 0.3).abs() < 1e-12 && (a[1] - 1.2).abs() < 1e-12);
        assert!((a[2] + 0.7).abs() < 1e-9);
        let b = q.at(0.8 - 1e-12);
        assert!((b[0] - 1.0).abs() < 1e-9 && b[1].abs() < 1e-9 && b[2].abs() < 1e-6);
        // Rates are the derivatives of the positions.
        for k in 1..20 {
            let t = 0.04 * k as f64;
            let e = 1e-6;
            let (p, m) = (q.at(t + e), q.at(t - e));
            let c = q.at(t);
            assert!((c[1] - (p[0] - m[0]) / (2.0 * e)).abs() < 1e-6);
            assert!((c[2] - (p[1] - m[1]) / (2.0 * e)).abs() < 1e-5);
        }
    }

    #[test]
    fn hermite_acc_is_the_derivative_of_the_rate() {
        let (t0, t1, p0, p1, m0, m1) = (0.2, 0.7, 0.3, -0.4, 1.5, 2.5);
        for k in 0..=10 {
            let t = t0 + (t1 - t0) * f64::from(k) / 10.0;
            let (v, d, dd) = hermite_acc(t0, t1, p0, p1, m0, m1, t);
            assert_eq!((v, d), hermite(t0, t1, p0, p1, m0, m1, t));
            let e = 1e-6;
            let (ta, tb) = ((t - e).max(t0), (t + e).min(t1));
            let num = (hermite(t0, t1, p0, p1, m0, m1, tb).1
                - hermite(t0, t1, p0, p1, m0, m1, ta).1)
                / (tb - ta);
            assert!(
                (dd - num).abs() < 1e-5 * (1.0 + num.abs()),
                "{t}: {dd} vs {num}"
            );
        }
    }

    #[test]
    fn hermite_hits_ends_and_slopes() {
        let (v0, d0) = hermite(1.0, 3.0, 2.0, 5.0, -1.0, 4.0, 1.0);
        let (v1, d1) = hermite(1.0, 3.0, 2.0, 5.0, -1.0, 4.0, 3.0);
        assert!((v0 - 2.0).abs() < 1e-12 && (d0 + 1.0).abs() < 1e-12);
        assert!((v1 - 5.0).abs() < 1e-12 && (d1 - 4.0).abs() < 1e-12);
        // Derivative agrees with a finite difference.
        let e = 1e-6;
        let (a, d) = hermite(1.0, 3.0, 2.0, 5.0, -1.0, 4.0, 2.2);
        let (b, _) = hermite(1.0, 3.0, 2.0, 5.0, -1.0, 4.0, 2.2 + e);
        assert!(((b - a) / e - d).abs() < 1e-4);
    }

    #[test]
    fn c2_spline_has_continuous_second_derivative() {
        let (p0, p1, p2) = (
            DVec3::ZERO,
            DVec3::new(1.0, -0.2, 0.1),
            DVec3::new(2.5, 0.3, 0.0),
        );
        let (v0, v2) = (DVec3::new(1.0, -1.0, 0.0), DVec3::new(2.0, 1.0, -0.5));
        let h = 0.5;
        let m = c2_mid_velocity(p0, p2, v0, v2, h);
        let a = Seg3 {
            t0: 0.0,
            t1: h,
            p0,
            p1,
            v0,
            v1: m,
        };
        let b = Seg3 {
            t0: h,
            t1: 2.0 * h,
            p0: p1,
            p1: p2,
            v0: m,
            v1: v2,
        };
        let e = 1e-6;
        let acc_a = (a.eval(h).1 - a.eval(h - e).1) / e;
        let acc_b = (b.eval(h + e).1 - b.eval(h).1) / e;
        assert!((acc_a - acc_b).length() < 1e-3, "{acc_a:?} {acc_b:?}");
    }
}
