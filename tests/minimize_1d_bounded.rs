//! `fit::nonlinear::minimize_1d_bounded` against the plain scan `minimize_1d`.
use gaitfit::fit::nonlinear::{minimize_1d, minimize_1d_bounded};

/// The bounded scan returns the plain scan's result bit for bit on a multimodal function with
/// exact ties (the first of equal grid minima wins), from any warm start; with bounds that
/// are exact minima over each window it evaluates far fewer points.
#[test]
fn the_bounded_scan_is_the_plain_scan() {
    use std::cell::Cell;
    // Steps of width 1 with equal minima at [2, 3) and [7, 8): ties on the grid.
    let f = |x: f64| match x.floor() as i64 {
        2 | 7 => 1.0,
        5 => 1.5,
        k => 3.0 + (k as f64 - 4.5).abs(),
    };
    // The exact minimum of f over [a, b] (its steps' values).
    let lower = |a: f64, b: f64| {
        (a.floor() as i64..=b.floor() as i64)
            .map(|k| f(k as f64))
            .fold(f64::INFINITY, f64::min)
    };
    let (lo, hi) = (0.0, 10.0);
    let n = Cell::new(0usize);
    let plain = minimize_1d(
        |x| {
            n.set(n.get() + 1);
            f(x)
        },
        lo,
        hi,
        1e-9,
    )
    .expect("plain");
    let n_plain = n.get();
    for warm in [0.0, 2.5, 5.2, 7.5, 10.0, f64::NAN] {
        n.set(0);
        let b = minimize_1d_bounded(
            |x| {
                n.set(n.get() + 1);
                f(x)
            },
            lower,
            warm,
            lo,
            hi,
            1e-9,
        )
        .expect("bounded");
        assert_eq!(
            (b.0.to_bits(), b.1.to_bits()),
            (plain.0.to_bits(), plain.1.to_bits())
        );
        assert!(plain.0 < 3.0, "the first minimum: {}", plain.0);
        assert!(n.get() < n_plain, "warm {warm}: {} vs {n_plain}", n.get());
    }
}
