//! The wild cluster bootstrap-t with Webb's six-point weights, from per-cluster sums.
//!
//! # Method (unrestricted: WCU, bootstrap-t)
//! Model `y = Xβ + u`, clusters `g` (subjects), OLS estimate `β̂`, residuals `û`. A bootstrap
//! sample is `y* = Xβ̂ + w_g û_g` with one weight `w_g` per cluster drawn from Webb's six-point
//! distribution (±√(1/2), ±1, ±√(3/2), each 1/6: mean 0, variance 1), which MacKinnon & Webb
//! (2017, "Wild bootstrap inference for wildly different cluster sizes", J. Appl. Econometrics
//! 32) recommend over Rademacher weights with few clusters: 6^G distinct samples instead of 2^G.
//! Each sample is refitted and studentised with its own CR1 covariance:
//! `t*_k = ℓ_kᵀ(β* − β̂) / SE*_CR1,k`; the interval is
//! `[θ̂_k − q*_{0.975}·SE_CR1,k, θ̂_k − q*_{0.025}·SE_CR1,k]` (the percentile-t interval).
//!
//! Unrestricted, not restricted (WCR, the null imposed on β̂ and û): an interval is wanted
//! directly, and the restricted bootstrap gives one only by inverting its test at every
//! candidate value (a bootstrap per candidate). MacKinnon & Webb (2017) find the restricted
//! test closer to its level with few or unbalanced clusters, the unrestricted one tending to
//! over-reject there (intervals too narrow): a caveat to read with its intervals.
//!
//! Everything follows from per-cluster sums, no pass over rows: with `A = ΣX_gᵀX_g`,
//! `a_g = X_gᵀû_g`, `b_g = A⁻¹a_g`, a sample's `β* − β̂ = d = Σ w_g b_g`, its residual scores are
//! `X_gᵀû*_g = w_g a_g − X_gᵀX_g d`, so `ℓᵀA⁻¹X_gᵀû*_g = w_g ℓᵀb_g − (X_gᵀX_g A⁻¹ℓ)ᵀd`:
//! O(G·p²) per sample.
//!
//! With at most [`ENUMERATE_MAX_CLUSTERS`] clusters every one of the 6^G weight patterns is
//! evaluated (each has probability 6^−G): the quantiles are exact, with no Monte Carlo error;
//! beyond, `n` seeded draws. Quantiles are order statistics, `q_α = t*_(⌈αN⌉)` (numpy's
//! `inverted_cdf`); the exact ones are selected in two passes (a histogram of the values'
//! order-preserving bit keys, then the values in the bucket holding the rank), so 6^10 values
//! are never stored.
use nalgebra::{DMatrix, DVector};
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use rayon::prelude::*;

/// Up to this many clusters every weight pattern is enumerated (6^10 ≈ 6·10⁷ samples).
pub const ENUMERATE_MAX_CLUSTERS: usize = 10;

/// The two tail probabilities of a 95 % interval.
const TAILS: [f64; 2] = [0.025, 0.975];

/// Bits of the order-preserving key used as histogram buckets in the exact selection.
const BUCKET_BITS: u32 = 16;

/// Webb's six-point weights: ±√(1/2), ±1, ±√(3/2), each with probability 1/6.
pub fn webb_weights() -> [f64; 6] {
    let (a, c) = (0.5f64.sqrt(), 1.5f64.sqrt());
    [-c, -1.0, -a, a, 1.0, c]
}

/// One cluster's sums at the OLS estimate.
#[derive(Debug, Clone, PartialEq)]
pub struct ClusterSums {
    /// `X_gᵀX_g`, `p × p` row-major.
    pub xtx: Vec<f64>,
    /// `X_gᵀû_g` (the cluster's score at β̂).
    pub score: Vec<f64>,
}

/// How the weight patterns are chosen.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Draws {
    /// Every pattern when there are at most [`ENUMERATE_MAX_CLUSTERS`] clusters, else `n`
    /// patterns drawn with `seed`.
    EnumerateOr {
        /// Draws beyond the enumeration limit.
        n: usize,
        /// Seed of those draws (ChaCha8, one stream per draw).
        seed: u64,
    },
}

/// The bootstrap distribution's quantiles for each contrast.
#[derive(Debug, Clone, PartialEq)]
pub struct WildT {
    /// Samples evaluated (6^G when enumerated).
    pub samples: u64,
    /// True when every weight pattern was evaluated (exact quantiles).
    pub enumerated: bool,
    /// Per contrast: `[q*_{0.025}, q*_{0.975}]` of `t*`.
    pub quantiles: Vec<[f64; 2]>,
    /// Per contrast: the CR1 standard error of the original fit (what `t*` is scaled back by).
    pub se_cr1: Vec<f64>,
}

impl WildT {
    /// The percentile-t interval of contrast `k` whose estimate is `estimate`.
    pub fn interval(&self, k: usize, estimate: f64) -> [f64; 2] {
        let [lo, hi] = self.quantiles[k];
        [
            estimate - hi * self.se_cr1[k],
            estimate - lo * self.se_cr1[k],
        ]
    }
}

/// Per-contrast constants of the studentised statistic as a function of the weights:
/// `t*_k(w) = βₖᵀw / √(c1·Σ_g (w_g βₖ[g] − νₖ[g]ᵀd)²)` with `d = Σ w_g b_g`, `βₖ[g] = ℓₖᵀb_g`,
/// `νₖ[g] = X_gᵀX_g A⁻¹ℓₖ`; for the enumeration, the same sum as the quadratic form `wᵀQₖw`,
/// `Qₖ = KₖᵀKₖ`, `Kₖ[g][h] = δ_gh·βₖ[g] − νₖ[g]ᵀb_h` (the sample's scaled scores are `Kₖw`).
struct Prepared {
    /// `b_g = A⁻¹a_g`, per cluster.
    b: Vec<DVector<f64>>,
    /// `βₖ`, `[k][g]`.
    beta: Vec<Vec<f64>>,
    /// `νₖ[g]`, `[k][g]`.
    nu: Vec<Vec<DVector<f64>>>,
    /// `Qₖ`, `[k][h][h']` (only when enumerating: G × G per contrast).
    q: Vec<Vec<Vec<f64>>>,
    /// CR1's small-sample factor `G/(G−1)·(n−1)/(n−p)`.
    c1: f64,
}

impl Prepared {
    /// `t*` from the numerator `βᵀw` and the quadratic form `wᵀQw`.
    #[inline]
    fn t(&self, num: f64, quad: f64) -> f64 {
        let den = self.c1 * quad;
        if den > 0.0 {
            num / den.sqrt()
        } else if num == 0.0 {
            0.0
        } else {
            num.signum() * f64::INFINITY
        }
    }

    /// `t*_k` for every contrast at weights `w` (one per cluster), into `out`: O(G·p²).
    fn t_at(&self, w: &[f64], out: &mut [f64]) {
        let mut d = DVector::<f64>::zeros(self.b.first().map_or(0, |b| b.len()));
        for (wg, bg) in w.iter().zip(&self.b) {
            d.axpy(*wg, bg, 1.0);
        }
        for (k, o) in out.iter_mut().enumerate() {
            let (mut num, mut quad) = (0.0, 0.0);
            for ((wg, bk), nu) in w.iter().zip(&self.beta[k]).zip(&self.nu[k]) {
                num += wg * bk;
                let e = wg * bk - nu.dot(&d);
                quad += e * e;
            }
            *o = self.t(num, quad);
        }
    }
}

/// The wild cluster bootstrap-t of the contrasts `contrasts` (each of length p) of an OLS fit
/// with the clusters' sums `clusters` on `n_obs` rows. `None` when `ΣX_gᵀX_g` is singular or
/// there are fewer than two clusters.
pub fn wild_cluster_t(
    clusters: &[ClusterSums],
    contrasts: &[Vec<f64>],
    n_obs: usize,
    draws: Draws,
) -> Option<WildT> {
    wild_cluster_t_up_to(clusters, contrasts, n_obs, draws, ENUMERATE_MAX_CLUSTERS)
}

/// [`wild_cluster_t`], enumerating up to `enumerate_max` clusters.
fn wild_cluster_t_up_to(
    clusters: &[ClusterSums],
    contrasts: &[Vec<f64>],
    n_obs: usize,
    draws: Draws,
    enumerate_max: usize,
) -> Option<WildT> {
    let g = clusters.len();
    let p = clusters.first()?.score.len();
    if g < 2 || p == 0 || n_obs <= p {
        return None;
    }
    let mut a = DMatrix::<f64>::zeros(p, p);
    for c in clusters {
        a += DMatrix::from_row_slice(p, p, &c.xtx);
    }
    let ainv = a.try_inverse()?;
    let b: Vec<DVector<f64>> = clusters
        .iter()
        .map(|c| &ainv * DVector::from_column_slice(&c.score))
        .collect();
    let mut beta = Vec::with_capacity(contrasts.len());
    let mut nu = Vec::with_capacity(contrasts.len());
    let mut q = Vec::new();
    for l in contrasts {
        let l = DVector::from_column_slice(l);
        let al = &ainv * &l;
        let bk: Vec<f64> = b.iter().map(|bg| l.dot(bg)).collect();
        let nk: Vec<DVector<f64>> = clusters
            .iter()
            .map(|c| DMatrix::from_row_slice(p, p, &c.xtx) * &al)
            .collect();
        if g <= enumerate_max {
            let kmat = DMatrix::from_fn(g, g, |r, h| {
                f64::from(u8::from(r == h)) * bk[r] - nk[r].dot(&b[h])
            });
            let qk = kmat.transpose() * kmat;
            q.push(
                (0..g)
                    .map(|h| qk.row(h).iter().copied().collect())
                    .collect(),
            );
        }
        beta.push(bk);
        nu.push(nk);
    }
    let c1 = g as f64 / (g - 1) as f64 * (n_obs - 1) as f64 / (n_obs - p) as f64;
    let se_cr1 = beta
        .iter()
        .map(|bk: &Vec<f64>| (c1 * bk.iter().map(|x| x * x).sum::<f64>()).sqrt())
        .collect();
    let prep = Prepared { b, beta, nu, q, c1 };
    let nk = contrasts.len();
    let Draws::EnumerateOr { n, seed } = draws;
    if g <= enumerate_max {
        let total = 6u64.pow(g as u32);
        Some(WildT {
            samples: total,
            enumerated: true,
            quantiles: exact_quantiles(&prep, g, nk, total),
            se_cr1,
        })
    } else {
        if n == 0 {
            return None;
        }
        let weights = webb_weights();
        let values: Vec<Vec<f64>> = (0..n)
            .into_par_iter()
            .map(|r| {
                let mut rng = ChaCha8Rng::seed_from_u64(seed);
                rng.set_stream(r as u64);
                let w: Vec<f64> = (0..g).map(|_| weights[rng.random_range(0..6)]).collect();
                let mut t = vec![0.0; nk];
                prep.t_at(&w, &mut t);
                t
            })
            .collect();
        let quantiles = (0..nk)
            .map(|k| {
                let mut v: Vec<f64> = values.iter().map(|t| t[k]).collect();
                v.sort_by(f64::total_cmp);
                TAILS.map(|a| v[rank(a, n as u64) as usize - 1])
            })
            .collect();
        Some(WildT {
            samples: n as u64,
            enumerated: false,
            quantiles,
            se_cr1,
        })
    }
}

/// The 1-based rank of the `alpha` quantile among `n` values: `⌈α·n⌉` (at least 1).
fn rank(alpha: f64, n: u64) -> u64 {
    ((alpha * n as f64).ceil() as u64).clamp(1, n)
}

/// An order-preserving integer key of a float (total order, −0 before +0).
fn key(x: f64) -> u64 {
    let b = x.to_bits();
    if b >> 63 == 1 {
        !b
    } else {
        b | (1 << 63)
    }
}

/// Calls `f(t)` (t: one value per contrast) for every weight pattern whose first two
/// clusters' weights are `weights[lead.0]`, `weights[lead.1]`, depth first: a level adds its
/// cluster's terms to the numerator and the quadratic form (`O(G)` per inner node, `O(1)` per
/// pattern at the last level).
fn each_pattern(
    prep: &Prepared,
    g: usize,
    nk: usize,
    lead: (usize, usize),
    f: &mut impl FnMut(&[f64]),
) {
    struct Level {
        /// Per contrast: `Σ_{i<j} βₖ[i]·w_i`.
        num: Vec<f64>,
        /// Per contrast: `Σ_{i,i'<j} w_i Qₖ[i][i'] w_i'`.
        quad: Vec<f64>,
        /// Per contrast, per cluster h: `Σ_{i<j} Qₖ[h][i]·w_i`.
        v: Vec<Vec<f64>>,
    }
    let weights = webb_weights();
    let mut levels: Vec<Level> = (0..=g)
        .map(|_| Level {
            num: vec![0.0; nk],
            quad: vec![0.0; nk],
            v: vec![vec![0.0; g]; nk],
        })
        .collect();
    let mut t = vec![0.0; nk];
    // Level j → j + 1 with weight w for cluster j.
    let step = |levels: &mut [Level], j: usize, w: f64| {
        let (lo, hi) = levels.split_at_mut(j + 1);
        let (cur, next) = (&lo[j], &mut hi[0]);
        for k in 0..nk {
            let qk = &prep.q[k];
            next.num[k] = cur.num[k] + w * prep.beta[k][j];
            next.quad[k] = cur.quad[k] + 2.0 * w * cur.v[k][j] + w * w * qk[j][j];
            for ((nv, cv), qh) in next.v[k][j + 1..g]
                .iter_mut()
                .zip(&cur.v[k][j + 1..g])
                .zip(&qk[j + 1..g])
            {
                *nv = cv + w * qh[j];
            }
        }
    };
    step(&mut levels, 0, weights[lead.0]);
    step(&mut levels, 1, weights[lead.1]);
    if g == 2 {
        for (k, tk) in t.iter_mut().enumerate() {
            *tk = prep.t(levels[2].num[k], levels[2].quad[k]);
        }
        f(&t);
        return;
    }
    // Digits of clusters 2..g−1 (an odometer over the inner levels), the last one innermost.
    let mut digits = vec![0usize; g];
    let mut j = 2;
    loop {
        // Descend to the last level with the current digits.
        while j < g - 1 {
            step(&mut levels, j, weights[digits[j]]);
            j += 1;
        }
        let cur = &levels[g - 1];
        for &w in &weights {
            for (k, tk) in t.iter_mut().enumerate() {
                let num = cur.num[k] + w * prep.beta[k][g - 1];
                let quad =
                    cur.quad[k] + 2.0 * w * cur.v[k][g - 1] + w * w * prep.q[k][g - 1][g - 1];
                *tk = prep.t(num, quad);
            }
            f(&t);
        }
        // Next digits: advance the deepest inner cluster that has weights left.
        loop {
            if j == 2 {
                return;
            }
            j -= 1;
            digits[j] += 1;
            if digits[j] < 6 {
                break;
            }
            digits[j] = 0;
        }
    }
}

/// Exact `TAILS` quantiles of every contrast's `t*` over all 6^g patterns, in two passes.
///
/// The weights are symmetric and `t*(−w) = −t*(w)` exactly (negation commutes with every
/// rounding), so only the patterns whose first weight is positive are evaluated, each value
/// counted with its negation.
fn exact_quantiles(prep: &Prepared, g: usize, nk: usize, total: u64) -> Vec<[f64; 2]> {
    let buckets = 1usize << BUCKET_BITS;
    let shift = 64 - BUCKET_BITS;
    // The positive weights are webb_weights()[3..6]; the second cluster's weight splits the work.
    let leads: Vec<(usize, usize)> = (3..6).flat_map(|a| (0..6).map(move |b| (a, b))).collect();
    // Pass 1: per contrast, how many values fall in each bucket.
    let hist = leads
        .par_iter()
        .map(|&lead| {
            let mut h = vec![vec![0u64; buckets]; nk];
            each_pattern(prep, g, nk, lead, &mut |t: &[f64]| {
                for (hk, &x) in h.iter_mut().zip(t) {
                    hk[(key(x) >> shift) as usize] += 1;
                    hk[(key(-x) >> shift) as usize] += 1;
                }
            });
            h
        })
        .reduce(
            || vec![vec![0u64; buckets]; nk],
            |mut a, b| {
                for (ak, bk) in a.iter_mut().zip(&b) {
                    for (x, y) in ak.iter_mut().zip(bk) {
                        *x += y;
                    }
                }
                a
            },
        );
    // Each wanted rank's bucket and how many values lie below it.
    let targets: Vec<[(usize, u64, u64); 2]> = hist
        .iter()
        .map(|h| {
            TAILS.map(|a| {
                let r = rank(a, total);
                let mut below = 0u64;
                for (bkt, &c) in h.iter().enumerate() {
                    if below + c >= r {
                        return (bkt, below, r);
                    }
                    below += c;
                }
                (buckets - 1, below, r)
            })
        })
        .collect();
    // Pass 2: the values in those buckets, sorted; the rank's value.
    let found = leads
        .par_iter()
        .map(|&lead| {
            let mut v: Vec<[Vec<f64>; 2]> = vec![[Vec::new(), Vec::new()]; nk];
            each_pattern(prep, g, nk, lead, &mut |t: &[f64]| {
                for ((vk, tk), &x) in v.iter_mut().zip(&targets).zip(t) {
                    for y in [x, -x] {
                        let bkt = (key(y) >> shift) as usize;
                        for (side, target) in vk.iter_mut().zip(tk) {
                            if bkt == target.0 {
                                side.push(y);
                            }
                        }
                    }
                }
            });
            v
        })
        .reduce(
            || vec![[Vec::new(), Vec::new()]; nk],
            |mut a, b| {
                for (ak, bk) in a.iter_mut().zip(b) {
                    for (x, y) in ak.iter_mut().zip(bk) {
                        x.extend(y);
                    }
                }
                a
            },
        );
    found
        .into_iter()
        .zip(&targets)
        .map(|(mut vk, tk)| {
            let mut q = [0.0; 2];
            for ((side, &(_, below, r)), qs) in vk.iter_mut().zip(tk).zip(q.iter_mut()) {
                side.sort_by(f64::total_cmp);
                *qs = side[(r - below - 1) as usize];
            }
            q
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Clusters' sums of a dense design `x` (rows × p), response `y`, cluster ids `c`.
    fn sums(x: &[Vec<f64>], y: &[f64], c: &[usize], g: usize) -> (Vec<ClusterSums>, Vec<f64>) {
        let p = x[0].len();
        let mut a = DMatrix::<f64>::zeros(p, p);
        let mut r = DVector::<f64>::zeros(p);
        for (xi, &yi) in x.iter().zip(y) {
            let v = DVector::from_column_slice(xi);
            a += &v * v.transpose();
            r += &v * yi;
        }
        let beta = a.try_inverse().unwrap() * r;
        let mut out = vec![
            ClusterSums {
                xtx: vec![0.0; p * p],
                score: vec![0.0; p],
            };
            g
        ];
        for ((xi, &yi), &ci) in x.iter().zip(y).zip(c) {
            let e = yi - xi.iter().zip(beta.iter()).map(|(a, b)| a * b).sum::<f64>();
            for i in 0..p {
                out[ci].score[i] += xi[i] * e;
                for j in 0..p {
                    out[ci].xtx[i * p + j] += xi[i] * xi[j];
                }
            }
        }
        (out, beta.as_slice().to_vec())
    }

    /// Brute force: every pattern refitted on the rows (dense OLS and CR1 of the sample).
    fn brute(x: &[Vec<f64>], y: &[f64], c: &[usize], g: usize, k: usize) -> Vec<f64> {
        let (s, beta) = sums(x, y, c, g);
        let _ = s;
        let fitted: Vec<f64> = x
            .iter()
            .map(|xi| xi.iter().zip(&beta).map(|(a, b)| a * b).sum())
            .collect();
        let weights = webb_weights();
        let total = 6usize.pow(g as u32);
        let mut out = Vec::with_capacity(total);
        for pat in 0..total {
            let mut w = vec![0.0; g];
            let mut q = pat;
            for wg in w.iter_mut().rev() {
                *wg = weights[q % 6];
                q /= 6;
            }
            let ys: Vec<f64> = (0..y.len())
                .map(|i| fitted[i] + w[c[i]] * (y[i] - fitted[i]))
                .collect();
            let (s2, b2) = sums(x, &ys, c, g);
            let p = x[0].len();
            let mut a = DMatrix::<f64>::zeros(p, p);
            for cs in &s2 {
                a += DMatrix::from_row_slice(p, p, &cs.xtx);
            }
            let ainv = a.try_inverse().unwrap();
            let mut meat = DMatrix::<f64>::zeros(p, p);
            for cs in &s2 {
                let u = DVector::from_column_slice(&cs.score);
                meat += &u * u.transpose();
            }
            let n = y.len();
            let c1 = g as f64 / (g - 1) as f64 * (n - 1) as f64 / (n - p) as f64;
            let v = &ainv * meat * &ainv * c1;
            out.push((b2[k] - beta[k]) / v[(k, k)].sqrt());
        }
        out.sort_by(f64::total_cmp);
        out
    }

    #[test]
    fn enumeration_matches_refitting_every_pattern() {
        // 4 unbalanced clusters, intercept + slope: 6^4 = 1296 patterns refitted on the rows.
        let xs = [
            0.3, 1.1, 2.0, 2.2, 3.5, 0.7, 4.1, 5.0, 1.9, 2.8, 3.3, 6.0, 0.1,
        ];
        let ys = [
            1.0, 1.9, 3.2, 2.6, 4.8, 1.1, 5.2, 6.9, 2.0, 3.9, 3.1, 8.2, 0.4,
        ];
        let cl = [0, 0, 0, 0, 0, 0, 0, 1, 1, 2, 2, 3, 3];
        let x: Vec<Vec<f64>> = xs.iter().map(|&v| vec![1.0, v]).collect();
        // Also with the clusters merged to 3 and 2 (the enumeration's shortest paths).
        for g in [4, 3, 2] {
            let cl: Vec<usize> = cl.iter().map(|&c| c.min(g - 1)).collect();
            let (s, _) = sums(&x, &ys, &cl, g);
            let draws = Draws::EnumerateOr { n: 0, seed: 0 };
            let l = [vec![1.0, 0.0], vec![0.0, 1.0]];
            let w = wild_cluster_t(&s, &l, xs.len(), draws).unwrap();
            assert!(w.enumerated);
            let total = 6u64.pow(g as u32);
            assert_eq!(w.samples, total);
            for k in 0..2 {
                let v = brute(&x, &ys, &cl, g, k);
                for (j, a) in TAILS.iter().enumerate() {
                    let want = v[rank(*a, total) as usize - 1];
                    let got = w.quantiles[k][j];
                    assert!(
                        (got - want).abs() <= 1e-9 * want.abs().max(1.0),
                        "G = {g}, {k} {a}: {got} vs {want}"
                    );
                }
            }
        }
    }

    #[test]
    fn random_draws_agree_with_the_enumeration_within_monte_carlo_error() {
        let xs = [
            0.3, 1.1, 2.0, 2.2, 3.5, 0.7, 4.1, 5.0, 1.9, 2.8, 3.3, 6.0, 0.1, 2.4, 3.0,
        ];
        let ys = [
            1.0, 1.9, 3.2, 2.6, 4.8, 1.1, 5.2, 6.9, 2.0, 3.9, 3.1, 8.2, 0.4, 2.2, 3.7,
        ];
        let cl = [0, 0, 0, 1, 1, 1, 2, 2, 3, 3, 4, 4, 5, 5, 5];
        let x: Vec<Vec<f64>> = xs.iter().map(|&v| vec![1.0, v]).collect();
        let (s, _) = sums(&x, &ys, &cl, 6);
        let l = [vec![0.0, 1.0]];
        let exact = wild_cluster_t(&s, &l, xs.len(), Draws::EnumerateOr { n: 0, seed: 0 }).unwrap();
        let n = 20_000;
        let draws = Draws::EnumerateOr { n, seed: 3 };
        let mc = wild_cluster_t_up_to(&s, &l, xs.len(), draws, 0).unwrap();
        assert!(!mc.enumerated);
        assert_eq!(mc.samples, n as u64);
        // A draw's quantile sits within a few standard errors of the exact one: compare ranks,
        // the share of the exact distribution below the drawn quantile vs 2.5 % / 97.5 %.
        // Binomial SE of a share at 2.5 % with 20,000 draws: 0.11 %; allowed 5 SE.
        let v = brute(&x, &ys, &cl, 6, 1);
        for (j, a) in TAILS.iter().enumerate() {
            let q = mc.quantiles[0][j];
            let share = v.partition_point(|&t| t <= q) as f64 / v.len() as f64;
            let se = (a * (1.0 - a) / n as f64).sqrt();
            assert!((share - a).abs() <= 5.0 * se, "{a}: share {share}");
            assert!(exact.quantiles[0][j].is_finite());
        }
    }

    #[test]
    fn exact_selection_is_the_sorted_order_statistic() {
        // The two-pass selection against sorting all values, on a wide spread of t* values.
        let xs = [0.5, 1.0, 1.5, 2.5, 3.0, 3.5, 4.0, 9.0, 0.2, 7.0, 8.0];
        let ys = [0.1, 2.0, 1.0, 4.0, 2.5, 3.9, 3.0, 12.0, 0.0, 5.0, 9.5];
        let cl = [0, 0, 1, 1, 2, 2, 3, 3, 4, 4, 4];
        let x: Vec<Vec<f64>> = xs.iter().map(|&v| vec![v]).collect();
        let (s, _) = sums(&x, &ys, &cl, 5);
        let w = wild_cluster_t(
            &s,
            &[vec![1.0]],
            xs.len(),
            Draws::EnumerateOr { n: 0, seed: 0 },
        )
        .unwrap();
        let v = brute(&x, &ys, &cl, 5, 0);
        for (j, a) in TAILS.iter().enumerate() {
            let want = v[rank(*a, 7776) as usize - 1];
            assert!((w.quantiles[0][j] - want).abs() <= 1e-9 * want.abs().max(1.0));
        }
    }

    #[test]
    fn keys_order_floats() {
        let v = [
            -f64::INFINITY,
            -3.0,
            -1e-300,
            -0.0,
            0.0,
            1e-300,
            2.0,
            f64::INFINITY,
        ];
        for w in v.windows(2) {
            assert!(key(w[0]) < key(w[1]), "{} {}", w[0], w[1]);
        }
    }
}
