//! The points of a normal Q–Q plot: every residual when there are few, else exact order
//! statistics at a fixed number of ranks.
//!
//! Ranks are spread evenly in the normal-quantile axis (not in probability), so the tails, where
//! a Q–Q plot is read, get as many points as the middle. The order statistics are exact without
//! sorting all rows: a histogram of the residuals locates the bin of each wanted rank, one more
//! pass collects the values of only those bins, and each is sorted — three linear passes.
use crate::fit::stats::normal_quantile;

/// Ranks drawn when the residuals are more than [`super::layers::MAX_SCATTER_POINTS`]: 1000 —
/// about two per pixel of the plot's width, so the drawn curve is the curve of all rows.
pub const QQ_RANKS: usize = 1000;

/// Histogram bins of the rank search (memory 0.5 MB; a bin then holds ~n/65 536 values).
const SEARCH_BINS: usize = 1 << 16;

/// The points of a Q–Q plot and the moments of the residuals drawn.
#[derive(Debug, Clone, PartialEq)]
pub struct QqPoints {
    /// `(normal quantile, residual)`, ascending.
    pub pts: Vec<(f64, f64)>,
    /// Finite residuals.
    pub n: usize,
    /// Their mean.
    pub mean: f64,
    /// Their sample standard deviation.
    pub sd: f64,
}

/// Q–Q points of `r`: all of them (sorted) when there are at most `max_all` finite residuals,
/// else [`QQ_RANKS`] exact order statistics. Non-finite residuals are skipped.
pub fn qq_points(r: &[f64], max_all: usize) -> QqPoints {
    let (mut n, mut lo, mut hi, mut s1) = (0usize, f64::INFINITY, f64::NEG_INFINITY, 0.0);
    for &v in r.iter().filter(|v| v.is_finite()) {
        n += 1;
        lo = lo.min(v);
        hi = hi.max(v);
        s1 += v;
    }
    if n == 0 {
        return QqPoints {
            pts: Vec::new(),
            n,
            mean: f64::NAN,
            sd: f64::NAN,
        };
    }
    let mean = s1 / n as f64;
    // Two-pass variance (about the mean): no cancellation for residuals far from zero.
    let ss: f64 = r
        .iter()
        .filter(|v| v.is_finite())
        .map(|v| (v - mean) * (v - mean))
        .sum();
    let sd = (ss / (n.max(2) - 1) as f64).sqrt();
    let z = |k: usize| normal_quantile((k as f64 + 0.5) / n as f64);
    let pts = if n <= max_all {
        let mut s: Vec<f64> = r.iter().copied().filter(|v| v.is_finite()).collect();
        s.sort_by(f64::total_cmp);
        s.iter().enumerate().map(|(k, &v)| (z(k), v)).collect()
    } else {
        let ranks = ranks(n, QQ_RANKS);
        let vals = order_statistics(r, n, (lo, hi), &ranks);
        ranks.iter().zip(vals).map(|(&k, v)| (z(k), v)).collect()
    };
    QqPoints { pts, n, mean, sd }
}

/// `m` distinct ranks of `0..n`, evenly spaced in the normal quantile of (k + ½)/n, always
/// including the smallest and the largest.
fn ranks(n: usize, m: usize) -> Vec<usize> {
    let z0 = normal_quantile(0.5 / n as f64);
    let z1 = -z0;
    let mut out: Vec<usize> = (0..m)
        .map(|i| {
            let z = z0 + (z1 - z0) * i as f64 / (m - 1) as f64;
            let p = 0.5 * statrs::function::erf::erfc(-z / std::f64::consts::SQRT_2);
            ((p * n as f64 - 0.5).round().max(0.0) as usize).min(n - 1)
        })
        .collect();
    out.dedup();
    out
}

/// The order statistics of the finite values of `r` (`n` of them, in `lo..=hi`) at sorted
/// `ranks`.
fn order_statistics(r: &[f64], n: usize, (lo, hi): (f64, f64), ranks: &[usize]) -> Vec<f64> {
    if hi <= lo {
        return vec![lo; ranks.len()];
    }
    let scale = SEARCH_BINS as f64 / (hi - lo);
    let bin = |v: f64| (((v - lo) * scale) as usize).min(SEARCH_BINS - 1);
    let mut counts = vec![0u32; SEARCH_BINS];
    for &v in r.iter().filter(|v| v.is_finite()) {
        counts[bin(v)] += 1;
    }
    // Rows before each bin; the bin (and the rank within it) of every wanted rank.
    let mut start = vec![0usize; SEARCH_BINS + 1];
    for b in 0..SEARCH_BINS {
        start[b + 1] = start[b] + counts[b] as usize;
    }
    debug_assert_eq!(start[SEARCH_BINS], n);
    const NONE: u32 = u32::MAX;
    let mut slot = vec![NONE; SEARCH_BINS];
    let mut wanted: Vec<usize> = Vec::new();
    let mut where_: Vec<(usize, usize)> = Vec::with_capacity(ranks.len());
    for &k in ranks {
        let b = start.partition_point(|&s| s <= k) - 1;
        if slot[b] == NONE {
            slot[b] = wanted.len() as u32;
            wanted.push(b);
        }
        where_.push((slot[b] as usize, k - start[b]));
    }
    let mut buckets: Vec<Vec<f64>> = wanted
        .iter()
        .map(|&b| Vec::with_capacity(counts[b] as usize))
        .collect();
    for &v in r.iter().filter(|v| v.is_finite()) {
        let s = slot[bin(v)];
        if s != NONE {
            buckets[s as usize].push(v);
        }
    }
    for b in &mut buckets {
        b.sort_by(f64::total_cmp);
    }
    where_.iter().map(|&(s, j)| buckets[s][j]).collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::{Rng, SeedableRng};

    #[test]
    fn order_statistics_equal_a_full_sort() {
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(3);
        // Heavy-tailed, with ties, so bins are uneven and some hold many equal values.
        let r: Vec<f64> = (0..200_000)
            .map(|i| {
                let u: f64 = rng.random::<f64>() - 0.5;
                if i % 7 == 0 {
                    0.25
                } else {
                    u / (1.0 - 2.0 * u.abs()).max(1e-3)
                }
            })
            .collect();
        let mut s = r.clone();
        s.sort_by(f64::total_cmp);
        let q = qq_points(&r, 5000);
        let pts = q.pts;
        assert_eq!(q.n, r.len());
        assert!(pts.len() > 800 && pts.len() <= QQ_RANKS, "{}", pts.len());
        let ks = ranks(r.len(), QQ_RANKS);
        assert_eq!(ks[0], 0);
        assert_eq!(*ks.last().unwrap(), r.len() - 1);
        for (&k, p) in ks.iter().zip(&pts) {
            assert_eq!(p.1, s[k], "rank {k}");
            assert!((p.0 - normal_quantile((k as f64 + 0.5) / r.len() as f64)).abs() < 1e-12);
        }
    }

    #[test]
    fn few_residuals_are_all_drawn() {
        let r = [0.3, -0.1, 0.2, f64::NAN];
        let p = qq_points(&r, 10).pts;
        assert_eq!(
            p.iter().map(|p| p.1).collect::<Vec<_>>(),
            vec![-0.1, 0.2, 0.3]
        );
    }
}
