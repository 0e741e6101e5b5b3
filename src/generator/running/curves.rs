//! RUNNER's leg-angle key tracks: small fixed-capacity tracks of keys (time, angles, rates)
//! evaluated every frame with the shared Hermite segments ([`crate::generator::curves`]). No
//! allocation.
use super::dims::LegAngles;
use crate::generator::curves::hermite;

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
