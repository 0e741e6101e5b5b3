//! C² curves through keys: each knot carries a value, a rate and an acceleration, and the curve
//! between two knots is the quintic Hermite segment ([`Quintic`]) meeting both, so value, rate
//! and acceleration are continuous at every knot by construction. [`spline_keys`] makes the keys
//! of a cubic spline through samples (whose keys reproduce the spline exactly), with each end
//! natural, at rest or given.
use crate::generator::curves::Quintic;
use crate::generator::GenerateError;

/// One knot of a [`C2Track`]: time (s), value, rate (per s) and acceleration (per s²).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Key {
    /// Time, s.
    pub t: f64,
    /// Value.
    pub p: f64,
    /// Rate, per s.
    pub v: f64,
    /// Acceleration, per s².
    pub a: f64,
}

impl Key {
    /// A key at rest: value `p`, rate and acceleration 0 (a planted coordinate's knot).
    pub fn rest(t: f64, p: f64) -> Key {
        Key {
            t,
            p,
            v: 0.0,
            a: 0.0,
        }
    }
}

/// A C² curve of time through [`Key`]s, one quintic Hermite segment per knot interval. Before
/// the first and after the last key it continues as the end key's quadratic (value, rate and
/// acceleration still continuous). Between two keys at rest with equal values it is exactly
/// that value (every coefficient of the segment but its constant is zero).
#[derive(Debug, Clone, PartialEq)]
pub struct C2Track {
    keys: Vec<Key>,
    segs: Vec<Quintic>,
}

impl C2Track {
    /// The curve through `keys` (at least one; strictly increasing finite times; finite
    /// values, rates and accelerations).
    pub fn new(keys: Vec<Key>) -> Result<C2Track, GenerateError> {
        let bad = |message: String| GenerateError::Numerical {
            stage: "drawing curve".into(),
            message,
        };
        if keys.is_empty() {
            return Err(bad("a curve needs at least one key".into()));
        }
        for (i, k) in keys.iter().enumerate() {
            if !(k.t.is_finite() && k.p.is_finite() && k.v.is_finite() && k.a.is_finite()) {
                return Err(bad(format!("key {i} is not finite: {k:?}")));
            }
            if i > 0 && k.t <= keys[i - 1].t {
                return Err(bad(format!(
                    "key {i} at {} s is not after key {} at {} s",
                    k.t,
                    i - 1,
                    keys[i - 1].t
                )));
            }
        }
        let segs = keys
            .windows(2)
            .map(|w| {
                Quintic::new(
                    [w[0].p, w[0].v, w[0].a],
                    [w[1].p, w[1].v, w[1].a],
                    w[1].t - w[0].t,
                )
            })
            .collect();
        Ok(C2Track { keys, segs })
    }

    /// The keys.
    pub fn keys(&self) -> &[Key] {
        &self.keys
    }

    /// Time of the first and of the last key, s.
    pub fn span(&self) -> (f64, f64) {
        (self.keys[0].t, self.keys[self.keys.len() - 1].t)
    }

    /// Value, rate and acceleration at `t` s.
    pub fn at(&self, t: f64) -> [f64; 3] {
        let (first, last) = (self.keys[0], self.keys[self.keys.len() - 1]);
        let taylor = |k: Key| {
            let h = t - k.t;
            [k.p + h * (k.v + 0.5 * h * k.a), k.v + h * k.a, k.a]
        };
        if t <= first.t {
            return taylor(first);
        }
        if t >= last.t {
            return taylor(last);
        }
        let i = self.keys.partition_point(|k| k.t <= t) - 1;
        let k = self.keys[i];
        let seg = &self.segs[i];
        let d = self.keys[i + 1].t - k.t;
        seg.at_fraction((t - k.t) / d)
    }

    /// Value at `t` s.
    pub fn value(&self, t: f64) -> f64 {
        self.at(t)[0]
    }
}

/// An end condition of [`spline_keys`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum End {
    /// Zero acceleration, free rate (the natural spline's end).
    Natural,
    /// The given rate and acceleration (e.g. `Given(0, 0)`, at rest: a planted end).
    Given(f64, f64),
}

/// Keys of the cubic spline through the samples `(ts[i], ys[i])` (at least two, strictly
/// increasing times): interior knots carry the spline's value, rate and acceleration, so the
/// [`C2Track`] of these keys is that spline except in the end segments, where an end
/// [`End::Given`] also sets the acceleration (the spline is clamped to the given rate; the
/// quintic end segment then meets the given acceleration too).
pub fn spline_keys(ts: &[f64], ys: &[f64], start: End, end: End) -> Vec<Key> {
    let n = ts.len().min(ys.len());
    if n == 0 {
        return Vec::new();
    }
    if n == 1 {
        let (v, a) = match start {
            End::Given(v, a) => (v, a),
            End::Natural => (0.0, 0.0),
        };
        return vec![Key {
            t: ts[0],
            p: ys[0],
            v,
            a,
        }];
    }
    let h: Vec<f64> = (0..n - 1).map(|i| ts[i + 1] - ts[i]).collect();
    let slope: Vec<f64> = (0..n - 1).map(|i| (ys[i + 1] - ys[i]) / h[i]).collect();
    // Tridiagonal system for the knots' second derivatives m: sub, diag, sup, rhs.
    let (mut sub, mut diag, mut sup, mut rhs) =
        (vec![0.0; n], vec![0.0; n], vec![0.0; n], vec![0.0; n]);
    for i in 1..n - 1 {
        sub[i] = h[i - 1];
        diag[i] = 2.0 * (h[i - 1] + h[i]);
        sup[i] = h[i];
        rhs[i] = 6.0 * (slope[i] - slope[i - 1]);
    }
    match start {
        End::Natural => diag[0] = 1.0,
        End::Given(v, _) => {
            diag[0] = 2.0 * h[0];
            sup[0] = h[0];
            rhs[0] = 6.0 * (slope[0] - v);
        }
    }
    match end {
        End::Natural => diag[n - 1] = 1.0,
        End::Given(v, _) => {
            sub[n - 1] = h[n - 2];
            diag[n - 1] = 2.0 * h[n - 2];
            rhs[n - 1] = 6.0 * (v - slope[n - 2]);
        }
    }
    // Thomas algorithm (diagonally dominant: stable without pivoting).
    for i in 1..n {
        let w = sub[i] / diag[i - 1];
        diag[i] -= w * sup[i - 1];
        rhs[i] -= w * rhs[i - 1];
    }
    let mut m = vec![0.0; n];
    m[n - 1] = rhs[n - 1] / diag[n - 1];
    for i in (0..n - 1).rev() {
        m[i] = (rhs[i] - sup[i] * m[i + 1]) / diag[i];
    }
    let mut keys: Vec<Key> = (0..n)
        .map(|i| {
            let v = if i + 1 < n {
                slope[i] - h[i] * (2.0 * m[i] + m[i + 1]) / 6.0
            } else {
                slope[i - 1] + h[i - 1] * (m[i - 1] + 2.0 * m[i]) / 6.0
            };
            Key {
                t: ts[i],
                p: ys[i],
                v,
                a: m[i],
            }
        })
        .collect();
    if let End::Given(v, a) = start {
        keys[0].v = v;
        keys[0].a = a;
    }
    if let End::Given(v, a) = end {
        keys[n - 1].v = v;
        keys[n - 1].a = a;
    }
    keys
}

/// `count ≥ 2` knot times evenly spaced over `[t0, t1]`, about `spacing` s apart (at least two
/// knots): where a simulated track is sampled for [`spline_keys`].
pub fn knots(t0: f64, t1: f64, spacing: f64) -> Vec<f64> {
    let n = (((t1 - t0) / spacing.max(1e-9)).round() as usize).max(1);
    // The ends exactly: a knot is where a rest key may start a planted stretch.
    (0..=n)
        .map(|i| match i {
            0 => t0,
            i if i == n => t1,
            i => t0 + (t1 - t0) * i as f64 / n as f64,
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Largest jump of value, rate and acceleration across the interior knots, relative to
    /// the larger one-sided magnitude (at least 1): the left segment read at its end against the
    /// right one read at its start.
    fn knot_jumps(c: &C2Track) -> [f64; 3] {
        let mut j = [0.0f64; 3];
        for i in 1..c.segs.len() {
            let (l, r) = (c.segs[i - 1].at_fraction(1.0), c.segs[i].at_fraction(0.0));
            for q in 0..3 {
                let scale = l[q].abs().max(r[q].abs()).max(1.0);
                j[q] = j[q].max((r[q] - l[q]).abs() / scale);
            }
        }
        j
    }

    #[test]
    fn a_track_is_c2_at_its_knots_and_meets_its_keys() {
        let keys = vec![
            Key {
                t: 0.0,
                p: 0.1,
                v: -2.0,
                a: 30.0,
            },
            Key {
                t: 0.07,
                p: -0.3,
                v: 4.0,
                a: -50.0,
            },
            Key {
                t: 0.1,
                p: 0.2,
                v: 0.0,
                a: 0.0,
            },
            Key {
                t: 0.4,
                p: 0.25,
                v: 1.0,
                a: 9.0,
            },
        ];
        let c = C2Track::new(keys.clone()).unwrap();
        for k in &keys {
            let r = c.at(k.t);
            assert!((r[0] - k.p).abs() < 1e-12 && (r[1] - k.v).abs() < 1e-9);
            assert!((r[2] - k.a).abs() < 1e-6, "{r:?} vs {k:?}");
        }
        // Value, rate and acceleration meet across every knot (to rounding).
        let j = knot_jumps(&c);
        assert!(j.iter().all(|&x| x < 1e-9), "{j:?}");
        // The rates are the derivatives of the values (central differences inside segments).
        // (Away from the knots, where the jerk may jump: the curve is C², not C³.)
        for i in 1..80 {
            let t = 0.005 * i as f64 + 0.001;
            let e = 1e-6;
            let (p, m, c0) = (c.at(t + e), c.at(t - e), c.at(t));
            assert!((c0[1] - (p[0] - m[0]) / (2.0 * e)).abs() < 1e-4);
            assert!(
                (c0[2] - (p[1] - m[1]) / (2.0 * e)).abs() < 1e-2,
                "{t}: {c0:?} {p:?} {m:?}"
            );
        }
        // Beyond the ends: the end key's quadratic.
        let r = c.at(0.5);
        assert!(
            (r[0] - (0.25 + 0.1 + 0.5 * 0.01 * 9.0)).abs() < 1e-12 && (r[2] - 9.0).abs() < 1e-12
        );
    }

    #[test]
    fn a_planted_stretch_is_exactly_constant() {
        let p = 0.123_456_789_012_345_6;
        let c = C2Track::new(vec![
            Key {
                t: 0.0,
                p: 0.5,
                v: -1.0,
                a: 3.0,
            },
            Key::rest(0.1, p),
            Key::rest(0.35, p),
            Key {
                t: 0.5,
                p: 0.2,
                v: 1.0,
                a: 0.0,
            },
        ])
        .unwrap();
        for i in 0..=1000 {
            let t = 0.1 + 0.25 * i as f64 / 1000.0;
            let r = c.at(t);
            assert!(r[0] == p && r[1] == 0.0 && r[2] == 0.0, "{t}: {r:?}");
        }
    }

    #[test]
    fn bad_keys_are_errors_naming_the_key() {
        let e = C2Track::new(vec![Key::rest(0.0, 0.0), Key::rest(0.0, 1.0)]).unwrap_err();
        assert!(e.to_string().contains("key 1"), "{e}");
        assert!(C2Track::new(vec![]).is_err());
        assert!(C2Track::new(vec![Key::rest(f64::NAN, 0.0)]).is_err());
    }

    #[test]
    fn spline_keys_reproduce_a_cubic_and_interpolate_the_samples() {
        // A cubic is its own clamped spline: the track must equal it everywhere.
        let f = |t: f64| 0.3 - 1.2 * t + 2.0 * t * t - 1.5 * t * t * t;
        let df = |t: f64| -1.2 + 4.0 * t - 4.5 * t * t;
        let ddf = |t: f64| 4.0 - 9.0 * t;
        let ts = [0.0, 0.13, 0.3, 0.32, 0.7, 1.0];
        let ys: Vec<f64> = ts.iter().map(|&t| f(t)).collect();
        let keys = spline_keys(
            &ts,
            &ys,
            End::Given(df(0.0), ddf(0.0)),
            End::Given(df(1.0), ddf(1.0)),
        );
        let c = C2Track::new(keys).unwrap();
        for i in 0..=200 {
            let t = i as f64 / 200.0;
            let r = c.at(t);
            assert!(
                (r[0] - f(t)).abs() < 1e-12 && (r[1] - df(t)).abs() < 1e-10,
                "{t}"
            );
            assert!((r[2] - ddf(t)).abs() < 1e-8, "{t}");
        }
        // Natural ends: interpolates the samples of any data, C² at the knots.
        let ys = [0.0, 1.0, -1.0, 0.5, 0.5, 2.0];
        let c = C2Track::new(spline_keys(&ts, &ys, End::Natural, End::Given(0.0, 0.0))).unwrap();
        for (t, y) in ts.iter().zip(ys) {
            assert!((c.value(*t) - y).abs() < 1e-12);
        }
        assert_eq!(c.at(0.0)[2], 0.0);
        assert_eq!(&c.at(1.0)[1..], &[0.0, 0.0]);
        let j = knot_jumps(&c);
        assert!(j.iter().all(|&x| x < 1e-9), "{j:?}");
    }

    #[test]
    fn knots_cover_the_interval_evenly() {
        let k = knots(0.2, 0.5, 0.04);
        assert_eq!(k.len(), 9);
        assert_eq!((k[0], k[8]), (0.2, 0.5));
        assert_eq!(knots(0.0, 0.01, 0.04).len(), 2);
    }
}
