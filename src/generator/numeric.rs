//! The generators' one bracketed root finder: the Illinois variant of regula falsi (Dowell &
//! Jarratt 1971), a secant iteration kept inside a sign-change bracket, whose retained end's value
//! is halved when the same end is kept twice (superlinear, order ≈ 1.44), with a bisection
//! whenever the bracket stalls. A leaf module: no imports.
//!
//! KLAW uses it for its shooting (§4.1: the paper's bisection refined by the secant method,
//! `walking::shooting`), for locating events on the integrator's discrete flow
//! (`walking::integrate`) and for the virtual leg's foot-roll rules (`walking::virtual_leg`).
//!
//! [`bisect`] is the plain bisection on a predicate (a side, not a sign: where the quantity is
//! not continuous or only its side is known), for KLAW's one-dimensional searches in the swing,
//! the first step, the ankle curve's knee and the drawn pelvis's rise.

/// When [`illinois`] stops.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Stop {
    /// A point with `|f| ≤ f_tol` is a root.
    pub f_tol: f64,
    /// The bracket is narrow enough when its width is below `x_tol · (1 + |b|)`.
    pub x_tol: f64,
    /// At most this many evaluations of `f`.
    pub max_evals: usize,
}

/// Why [`illinois`] stopped.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Status {
    /// The last point evaluated met `|f| ≤ f_tol`.
    Root,
    /// The bracket narrowed below `x_tol` (a root, or a jump of `f` when `|f|` stays large).
    Narrow,
    /// The evaluations ran out first.
    Exhausted,
}

/// The end of an [`illinois`] search.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Bracketed {
    /// The end on the starting `a`'s side, `(x, f(x))`: `f` strictly of `f(a)`'s sign.
    pub a: (f64, f64),
    /// The other end, `(x, f(x))`: `f` zero or of the other sign.
    pub b: (f64, f64),
    /// The last point evaluated (`a` or `b`), `(x, f(x))`; `(NaN, NaN)` if none was.
    pub last: (f64, f64),
    /// Evaluations of `f` made.
    pub evals: usize,
    /// Why the search stopped.
    pub status: Status,
}

impl Bracketed {
    /// The end or the last point with the smallest `|f|`.
    pub fn best(&self) -> (f64, f64) {
        [self.a, self.b, self.last]
            .into_iter()
            .filter(|p| p.1.is_finite())
            .min_by(|p, q| p.1.abs().total_cmp(&q.1.abs()))
            .unwrap_or(self.b)
    }
}

/// Finds a root of `f` in the bracket between `a = (x_a, f(x_a))` and `b = (x_b, f(x_b))`, whose
/// values are known and differ in sign (`f(x_a) ≠ 0`; a zero counts on `b`'s side, so a caller
/// choosing which end is `b` chooses which side a point with `f = 0` joins).
///
/// Each iteration evaluates the regula-falsi point of the bracket (its midpoint if that is not
/// strictly inside, or when every third iteration finds the bracket not narrowed to 0.7 × its
/// previous width) and keeps the sign change. No evaluation is made if `b` is already a root or
/// the bracket already narrow.
pub fn illinois(
    mut f: impl FnMut(f64) -> f64,
    a: (f64, f64),
    b: (f64, f64),
    stop: Stop,
) -> Bracketed {
    let (mut a, mut b) = (a, b);
    let a_positive = a.1 > 0.0;
    let narrow = |a: (f64, f64), b: (f64, f64)| (b.0 - a.0).abs() < stop.x_tol * (1.0 + b.0.abs());
    let mut out = Bracketed {
        a,
        b,
        last: (f64::NAN, f64::NAN),
        evals: 0,
        status: Status::Exhausted,
    };
    if b.1.abs() <= stop.f_tol {
        out.status = Status::Root;
        return out;
    }
    if narrow(a, b) {
        out.status = Status::Narrow;
        return out;
    }
    // Which end was kept last: 1 = a, -1 = b, 0 = none yet.
    let mut kept = 0i8;
    let mut last_width = (b.0 - a.0).abs();
    while out.evals < stop.max_evals {
        let width = (b.0 - a.0).abs();
        let mut c = (a.0 * b.1 - b.0 * a.1) / (b.1 - a.1);
        let stalled = kept != 0 && out.evals % 3 == 2 && width > 0.7 * last_width;
        if stalled || !(c.is_finite() && (c - a.0) * (c - b.0) < 0.0) {
            c = 0.5 * (a.0 + b.0);
        }
        if out.evals % 3 == 2 {
            last_width = width;
        }
        let fc = f(c);
        out.evals += 1;
        out.last = (c, fc);
        let b_side = fc == 0.0 || (fc > 0.0) != a_positive || fc.is_nan();
        if b_side {
            b = (c, fc);
            if kept == 1 {
                a.1 *= 0.5;
            }
            kept = 1;
        } else {
            a = (c, fc);
            if kept == -1 {
                b.1 *= 0.5;
            }
            kept = -1;
        }
        if fc.abs() <= stop.f_tol {
            out.status = Status::Root;
            break;
        }
        if narrow(a, b) {
            out.status = Status::Narrow;
            break;
        }
    }
    out.a = a;
    out.b = b;
    out
}

/// Bisection of `[lo, hi]` on a predicate: up to `halvings` times, and while `|hi − lo| > tol`,
/// the midpoint `m` replaces `lo` where `lo_side(m)` holds and `hi` where it does not. Returns
/// the final `(lo, hi)` (`lo` may be the larger end).
pub fn bisect(
    lo: f64,
    hi: f64,
    halvings: usize,
    tol: f64,
    mut lo_side: impl FnMut(f64) -> bool,
) -> (f64, f64) {
    let (mut lo, mut hi) = (lo, hi);
    for _ in 0..halvings {
        if (hi - lo).abs() <= tol {
            break;
        }
        let m = 0.5 * (lo + hi);
        if lo_side(m) {
            lo = m;
        } else {
            hi = m;
        }
    }
    (lo, hi)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn bisect_keeps_each_end_on_its_side() {
        // x² < 2 on the lo side: the ends close on √2 from either order of the bracket.
        let (lo, hi) = bisect(0.0, 2.0, 60, 0.0, |x| x * x < 2.0);
        assert!(lo * lo < 2.0 && hi * hi >= 2.0 && (hi - lo).abs() < 1e-15);
        let (lo, hi) = bisect(3.0, 1.0, 60, 0.0, |x| x * x >= 2.0);
        assert!((lo - 2f64.sqrt()).abs() < 1e-15 && hi < lo);
        // The tolerance stops it early: 2/2^k ≤ 0.01 after 8 halvings.
        let (lo, hi) = bisect(0.0, 2.0, usize::MAX, 0.01, |x| x * x < 2.0);
        assert!((hi - lo - 2.0 / 256.0).abs() < 1e-15);
    }

    #[test]
    fn finds_a_cube_root_to_tolerance_in_few_evaluations() {
        let f = |x: f64| x * x * x - 2.0;
        let stop = Stop {
            f_tol: 1e-13,
            x_tol: 0.0,
            max_evals: 50,
        };
        let r = illinois(f, (0.0, f(0.0)), (2.0, f(2.0)), stop);
        assert_eq!(r.status, Status::Root);
        assert!((r.last.0 - 2f64.cbrt()).abs() < 1e-12, "{r:?}");
        assert!(r.evals < 20, "{r:?}");
    }

    #[test]
    fn a_zero_joins_the_b_side_and_a_jump_ends_narrow() {
        // A step function: no root, the bracket closes on the jump at 0.3, b on the ≤ 0 side.
        let f = |x: f64| if x < 0.3 { 1.0 } else { -1.0 };
        let stop = Stop {
            f_tol: 0.0,
            x_tol: 1e-10,
            max_evals: 200,
        };
        let r = illinois(f, (0.0, 1.0), (1.0, -1.0), stop);
        assert_eq!(r.status, Status::Narrow);
        assert!(r.b.0 >= 0.3 && r.b.0 - 0.3 < 1e-9, "{r:?}");
        assert!(r.a.0 < 0.3);
        // Zero on b's side: g(x) = max(x − 0.5, 0) − … is zero on [0, 0.5]; from a = 1 (g > 0)
        // the search ends at a zero of g, on the b side.
        let g = |x: f64| (x - 0.5).max(0.0);
        let r = illinois(g, (1.0, 0.5), (0.0, 0.0), stop);
        assert_eq!(r.status, Status::Root);
        assert_eq!(r.evals, 0);
        let r = illinois(g, (1.0, 0.5), (-1.0, g(-1.0)), stop);
        assert_eq!(r.b.1, 0.0);
        assert!(r.b.0 <= 0.5);
    }

    #[test]
    fn runs_out_of_evaluations_without_lying() {
        let f = |x: f64| x - 0.123_456_789;
        let stop = Stop {
            f_tol: 0.0,
            x_tol: 0.0,
            max_evals: 1,
        };
        let r = illinois(f, (-1.0, f(-1.0)), (1.0, f(1.0)), stop);
        assert_eq!(r.evals, 1);
        assert!(matches!(r.status, Status::Exhausted | Status::Root));
        assert!(r.best().1.abs() <= 1.0);
    }
}
