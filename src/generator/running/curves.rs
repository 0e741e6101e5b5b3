//! Interpolation primitives evaluated every frame: cubic Hermite segments (scalar and 3-D) and
//! small fixed-capacity key tracks for the leg angles. No allocation.
use glam::DVec3;

use super::dims::LegAngles;

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

/// One key of a leg-angle track: time, angles and their rates.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct Key {
    /// Time (relative to the step start), s.
    pub t: f64,
    /// Angles.
    pub val: LegAngles,
    /// Angle rates, rad/s.
    pub rate: LegAngles,
}

/// Maximum keys in one track (the recovery procedures insert a few).
pub const MAX_KEYS: usize = 10;

/// A temporary extra knee flexion on a track (the foot-stubbing recovery's control point):
/// rises smoothly from 0 at `t0` to `amount` at `peak` and falls back to 0 at `t1`, with zero
/// slope at all three, so the track stays C1 and its end keys are untouched.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct KneeBump {
    /// Start, s.
    pub t0: f64,
    /// Time of the maximum, s.
    pub peak: f64,
    /// End, s.
    pub t1: f64,
    /// Extra knee flexion at the peak, rad.
    pub amount: f64,
    /// Hold the peak to the end instead of returning to zero (the hind leg in flight, whose
    /// track hands its end state to the next step's swing).
    pub hold: bool,
}

impl KneeBump {
    /// Extra flexion and its rate at `t`.
    #[inline]
    pub fn eval(&self, t: f64) -> (f64, f64) {
        if self.amount == 0.0 || t <= self.t0 {
            return (0.0, 0.0);
        }
        if self.hold && t >= self.peak {
            return (self.amount, 0.0);
        }
        if t >= self.t1 {
            return (0.0, 0.0);
        }
        let (a, b, up) = if t <= self.peak {
            (self.t0, self.peak, true)
        } else {
            (self.peak, self.t1, false)
        };
        let (p0, p1) = if up {
            (0.0, self.amount)
        } else {
            (self.amount, 0.0)
        };
        hermite(a, b, p0, p1, 0.0, 0.0, t)
    }
}

/// A piecewise cubic Hermite track of leg angles (C1 through its keys), plus an optional knee
/// bump.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct Track {
    keys: [Key; MAX_KEYS],
    len: usize,
    /// Foot-stubbing recovery on this track.
    pub bump: KneeBump,
}

impl Track {
    /// An empty track.
    pub fn new() -> Self {
        Track::default()
    }

    /// Appends a key (times must increase). Returns false when the track is full.
    pub fn push(&mut self, k: Key) -> bool {
        if self.len == MAX_KEYS {
            return false;
        }
        self.keys[self.len] = k;
        self.len += 1;
        true
    }

    /// Inserts a key in time order. Returns false when the track is full.
    pub fn insert(&mut self, k: Key) -> bool {
        if self.len == MAX_KEYS {
            return false;
        }
        let mut i = self.len;
        while i > 0 && self.keys[i - 1].t > k.t {
            self.keys[i] = self.keys[i - 1];
            i -= 1;
        }
        self.keys[i] = k;
        self.len += 1;
        true
    }

    /// The keys.
    pub fn keys(&self) -> &[Key] {
        &self.keys[..self.len]
    }

    /// Time of the first key.
    pub fn start(&self) -> f64 {
        self.keys[0].t
    }

    /// Time of the last key.
    pub fn end(&self) -> f64 {
        self.keys[self.len.saturating_sub(1)].t
    }

    /// Angles and rates at `t` (clamped to the track).
    #[inline]
    pub fn eval(&self, t: f64) -> (LegAngles, LegAngles) {
        let n = self.len;
        if n == 0 {
            return (LegAngles::default(), LegAngles::default());
        }
        if n == 1 || t <= self.keys[0].t {
            return (
                self.keys[0].val,
                if n == 1 {
                    LegAngles::default()
                } else {
                    self.keys[0].rate
                },
            );
        }
        let mut i = 0;
        while i + 2 < n && t > self.keys[i + 1].t {
            i += 1;
        }
        let (a, b) = (&self.keys[i], &self.keys[i + 1]);
        let mut v = LegAngles::default();
        let mut r = LegAngles::default();
        for c in 0..5 {
            let (x, dx) = hermite(
                a.t,
                b.t,
                a.val.get(c),
                b.val.get(c),
                a.rate.get(c),
                b.rate.get(c),
                t,
            );
            v.set(c, x);
            r.set(c, dx);
        }
        let (bk, br) = self.bump.eval(t);
        v.knee += bk;
        r.knee += br;
        (v, r)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

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
