//! Statistics shared by the linear and nonlinear fits: quantiles, accuracy (LRE), r², RMSE,
//! information criteria, and resampling by group (leave-one-group-out, seeded group bootstrap).
//!
//! Conventions (used everywhere in [`crate::fit`]):
//! - **r²** is centred, `1 − RSS/Σ wᵢ(yᵢ − ȳ_w)²`, for models with an intercept, and uncentred,
//!   `1 − RSS/Σ wᵢyᵢ²`, for models through the origin (NIST StRD NoInt1/NoInt2).
//! - **AIC/BIC** use the Gaussian log-likelihood at the maximum-likelihood variance
//!   `σ̂² = RSS/n`, with `k = p + 1` parameters (the `p` coefficients plus σ):
//!   `ln L = −n/2·(ln 2π + ln(RSS/n) + 1) + ½ Σ ln wᵢ`, `AIC = 2k − 2 ln L`,
//!   `BIC = k ln n − 2 ln L`. The `Σ ln wᵢ` term is zero for unweighted fits; it keeps AIC
//!   comparable between fits with the same known weights.
// `!(a > b)` is deliberate throughout: it is also true for NaN, which must be rejected too.
#![allow(clippy::neg_cmp_op_on_partial_ord)]

use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use rayon::prelude::*;
use statrs::distribution::{ContinuousCDF, Normal, StudentsT};

use super::prec::LRE_MAX;

/// The `p`-quantile of Student's t distribution with `df` degrees of freedom.
///
/// Returns NaN when `p` is outside (0, 1) or `df` is not positive (never panics).
///
/// ```
/// // t_{0.975, 10} = 2.228138851986274 (standard tables)
/// let t = gaitfit::fit::stats::t_quantile(0.975, 10.0);
/// assert!((t - 2.228138851986274).abs() < 1e-9);
/// ```
pub fn t_quantile(p: f64, df: f64) -> f64 {
    if !(p > 0.0 && p < 1.0 && df > 0.0) {
        return f64::NAN;
    }
    match StudentsT::new(0.0, 1.0, df) {
        Ok(t) => t.inverse_cdf(p),
        Err(_) => f64::NAN,
    }
}

/// Two-sided p-value of a t statistic with `df` degrees of freedom: `2·P(T > |t|)`.
pub fn t_two_sided_p(t: f64, df: f64) -> f64 {
    if t.is_nan() || !(df > 0.0) {
        return f64::NAN;
    }
    // |t| = ∞ is the limit p = 0 (e.g. a breakpoint F-test on noise-free data, RSS = 0 with the
    // breakpoint): certain evidence, not a degenerate test.
    if t.is_infinite() {
        return 0.0;
    }
    match StudentsT::new(0.0, 1.0, df) {
        Ok(d) => (2.0 * d.sf(t.abs())).min(1.0),
        Err(_) => f64::NAN,
    }
}

/// The `p`-quantile of the standard normal distribution (NaN outside (0, 1)).
///
/// ```
/// let z = gaitfit::fit::stats::normal_quantile(0.975);
/// assert!((z - 1.959963984540054).abs() < 1e-12);
/// ```
pub fn normal_quantile(p: f64) -> f64 {
    if !(p > 0.0 && p < 1.0) {
        return f64::NAN;
    }
    match Normal::new(0.0, 1.0) {
        Ok(n) => n.inverse_cdf(p),
        Err(_) => f64::NAN,
    }
}

/// Log relative error, the number of correct significant digits of `computed` against
/// `certified`: `−log10(|computed − certified| / |certified|)`, or `−log10(|computed|)` (the
/// log absolute error) when `certified` is zero, as NIST reports it. Capped at
/// [`LRE_MAX`] (an exact match); 0 when the error is 100 % or more; NaN when `computed` is not
/// finite.
///
/// ```
/// use gaitfit::fit::stats::lre;
/// assert!((lre(1.000001, 1.0) - 6.0).abs() < 1e-6);
/// assert_eq!(lre(2.0, 2.0), 15.0);
/// assert!((lre(1e-10, 0.0) - 10.0).abs() < 1e-9);
/// ```
pub fn lre(computed: f64, certified: f64) -> f64 {
    if !computed.is_finite() {
        return f64::NAN;
    }
    let err = if certified == 0.0 {
        computed.abs()
    } else {
        (computed - certified).abs() / certified.abs()
    };
    if err == 0.0 {
        LRE_MAX
    } else {
        (-err.log10()).clamp(0.0, LRE_MAX)
    }
}

/// The smallest [`lre`] over pairs of computed and certified values (NaN if any computed value
/// is not finite): the figure NIST StRD results are judged by.
///
/// ```
/// use gaitfit::fit::stats::min_lre;
/// assert!((min_lre(&[1.000001, 2.0], &[1.0, 2.0]) - 6.0).abs() < 1e-6);
/// assert!(min_lre(&[f64::NAN, 2.0], &[1.0, 2.0]).is_nan());
/// ```
pub fn min_lre(computed: &[f64], certified: &[f64]) -> f64 {
    computed
        .iter()
        .zip(certified)
        .map(|(&c, &x)| lre(c, x))
        .fold(f64::INFINITY, |a, b| {
            if b.is_nan() || a.is_nan() {
                f64::NAN
            } else {
                a.min(b)
            }
        })
}

/// Centred r² = `1 − rss / Σ wᵢ (yᵢ − ȳ_w)²` (unit weights when `weights` is `None`).
pub fn r2_centred(y: &[f64], rss: f64, weights: Option<&[f64]>) -> f64 {
    let (sw, swy) = y
        .iter()
        .enumerate()
        .fold((0.0, 0.0), |(sw, swy), (i, &yi)| {
            let w = weights.map_or(1.0, |w| w[i]);
            (sw + w, swy + w * yi)
        });
    let mean = swy / sw;
    let tss: f64 = y
        .iter()
        .enumerate()
        .map(|(i, &yi)| weights.map_or(1.0, |w| w[i]) * (yi - mean).powi(2))
        .sum();
    1.0 - rss / tss
}

/// Uncentred r² = `1 − rss / Σ wᵢ yᵢ²`, the one NIST certifies for fits through the origin.
pub fn r2_uncentred(y: &[f64], rss: f64, weights: Option<&[f64]>) -> f64 {
    let tss: f64 = y
        .iter()
        .enumerate()
        .map(|(i, &yi)| weights.map_or(1.0, |w| w[i]) * yi * yi)
        .sum();
    1.0 - rss / tss
}

/// Root mean square of residuals, `sqrt(Σ eᵢ² / n)` (no degrees-of-freedom correction; that
/// is the residual SD σ of the fits).
pub fn rmse(residuals: &[f64]) -> f64 {
    if residuals.is_empty() {
        return f64::NAN;
    }
    (residuals.iter().map(|e| e * e).sum::<f64>() / residuals.len() as f64).sqrt()
}

/// Gaussian log-likelihood at the maximum-likelihood variance (see the module docs).
/// `sum_log_w` is `Σ ln wᵢ` (0 for unweighted fits).
pub fn gaussian_log_likelihood(rss: f64, n: usize, sum_log_w: f64) -> f64 {
    let nf = n as f64;
    -0.5 * nf * ((2.0 * std::f64::consts::PI).ln() + (rss / nf).ln() + 1.0) + 0.5 * sum_log_w
}

/// Akaike information criterion with `p` coefficients (k = p + 1, σ counted; module docs).
pub fn aic(rss: f64, n: usize, p: usize, sum_log_w: f64) -> f64 {
    2.0 * (p as f64 + 1.0) - 2.0 * gaussian_log_likelihood(rss, n, sum_log_w)
}

/// Bayesian information criterion with `p` coefficients (k = p + 1, σ counted; module docs).
pub fn bic(rss: f64, n: usize, p: usize, sum_log_w: f64) -> f64 {
    (p as f64 + 1.0) * (n as f64).ln() - 2.0 * gaussian_log_likelihood(rss, n, sum_log_w)
}

/// Result of a t-test of one coefficient against a reference value.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct TTest {
    /// The estimate.
    pub estimate: f64,
    /// The reference value tested against (e.g. the published coefficient).
    pub value: f64,
    /// Standard error of the estimate.
    pub std_error: f64,
    /// `t = (estimate − value) / std_error`.
    pub t: f64,
    /// Degrees of freedom (residual degrees of freedom of the fit).
    pub df: f64,
    /// Two-sided p-value, `2·P(T_df > |t|)`.
    pub p_value: f64,
}

impl TTest {
    /// Builds the test; `t` and `p` are NaN when the standard error is zero or not finite.
    pub fn new(estimate: f64, value: f64, std_error: f64, df: f64) -> Self {
        let t = if std_error > 0.0 && std_error.is_finite() {
            (estimate - value) / std_error
        } else {
            f64::NAN
        };
        TTest {
            estimate,
            value,
            std_error,
            t,
            df,
            p_value: t_two_sided_p(t, df),
        }
    }
}

/// Two-sided t confidence interval `estimate ± t_{(1+level)/2, df} · se`.
/// NaN bounds when `level` is outside (0, 1), `df ≤ 0` or `se` is not finite.
pub fn t_interval(estimate: f64, se: f64, df: f64, level: f64) -> [f64; 2] {
    let q = t_quantile(0.5 + 0.5 * level, df);
    [estimate - q * se, estimate + q * se]
}

/// The distinct group ids of `groups`, ascending. This is the order in which
/// [`leave_one_group_out`] returns its results.
pub fn unique_groups(groups: &[usize]) -> Vec<usize> {
    let mut u = groups.to_vec();
    u.sort_unstable();
    u.dedup();
    u
}

/// Rows of each group, in the order of [`unique_groups`].
fn rows_by_group(groups: &[usize]) -> (Vec<usize>, Vec<Vec<usize>>) {
    let ids = unique_groups(groups);
    let mut rows = vec![Vec::new(); ids.len()];
    for (i, g) in groups.iter().enumerate() {
        // `ids` is sorted and contains every g, so the search always succeeds.
        if let Ok(k) = ids.binary_search(g) {
            rows[k].push(i);
        }
    }
    (ids, rows)
}

/// Leave-one-group-out (e.g. leave-one-subject-out) resampling.
///
/// For each distinct group id (ascending, see [`unique_groups`]) calls
/// `fit(train_rows, test_rows)`, where `test_rows` are that group's rows and `train_rows` all
/// the others (both ascending row indices), and collects the `Some` results in group order.
/// Runs the groups in parallel (rayon); the result does not depend on the number of threads.
///
/// ```
/// use gaitfit::fit::stats::leave_one_group_out;
/// let groups = [0, 0, 1, 1, 2];
/// let sizes = leave_one_group_out(&groups, |train, test| Some((train.len(), test.len())));
/// assert_eq!(sizes, vec![(3, 2), (3, 2), (4, 1)]);
/// ```
pub fn leave_one_group_out<T, F>(groups: &[usize], fit: F) -> Vec<T>
where
    T: Send,
    F: Fn(&[usize], &[usize]) -> Option<T> + Sync,
{
    let (_, rows) = rows_by_group(groups);
    (0..rows.len())
        .into_par_iter()
        .map(|k| {
            let test = &rows[k];
            let train: Vec<usize> = (0..groups.len())
                .filter(|&i| groups[i] != groups[test[0]])
                .collect();
            fit(&train, test)
        })
        .collect::<Vec<Option<T>>>()
        .into_iter()
        .flatten()
        .collect()
}

/// Summary of a bootstrap: per-parameter percentile intervals and moments of the replicates.
#[derive(Debug, Clone, PartialEq)]
pub struct BootstrapSummary {
    /// Replicates whose fit succeeded (and returned the same number of parameters as the
    /// first successful one).
    pub n_ok: usize,
    /// Replicates whose fit returned `None`, a different number of parameters, or a non-finite
    /// value.
    pub n_failed: usize,
    /// Mean of each parameter over the successful replicates.
    pub mean: Vec<f64>,
    /// Standard deviation (n − 1) of each parameter over the successful replicates: the
    /// bootstrap standard error.
    pub std_dev: Vec<f64>,
    /// Percentile 95 % interval of each parameter: the 2.5 % and 97.5 % quantiles of the
    /// replicates (Hyndman–Fan type 7, linear interpolation).
    pub ci95: Vec<[f64; 2]>,
    /// The successful replicates, in replicate order (each one parameter vector).
    pub replicates: Vec<Vec<f64>>,
}

impl BootstrapSummary {
    /// Percentile interval at another `level` (e.g. 0.9), type-7 quantiles.
    pub fn percentile_ci(&self, level: f64) -> Vec<[f64; 2]> {
        let lo = 0.5 - 0.5 * level;
        let hi = 0.5 + 0.5 * level;
        (0..self.mean.len())
            .map(|j| {
                let mut v: Vec<f64> = self.replicates.iter().map(|r| r[j]).collect();
                v.sort_by(f64::total_cmp);
                [quantile_sorted(&v, lo), quantile_sorted(&v, hi)]
            })
            .collect()
    }
}

/// Type-7 (linear interpolation) quantile of sorted data; NaN for empty data.
pub fn quantile_sorted(sorted: &[f64], q: f64) -> f64 {
    if sorted.is_empty() || !(0.0..=1.0).contains(&q) {
        return f64::NAN;
    }
    let h = (sorted.len() - 1) as f64 * q;
    let lo = h.floor() as usize;
    let hi = h.ceil() as usize;
    sorted[lo] + (h - lo as f64) * (sorted[hi] - sorted[lo])
}

/// Median of unsorted data (NaN when empty).
pub fn median(values: &[f64]) -> f64 {
    let mut v = values.to_vec();
    v.sort_by(f64::total_cmp);
    quantile_sorted(&v, 0.5)
}

/// Seeded bootstrap by group (cluster bootstrap): each replicate draws as many groups as there
/// are, with replacement, and passes all rows of the drawn groups (in draw order, a group drawn
/// twice contributes its rows twice) to `fit`, which returns the parameter vector or `None`.
///
/// Reproducible: replicate `b` uses its own ChaCha8 stream (`seed`, stream `b`), so the result
/// is identical for any number of rayon threads. Replicates run in parallel.
///
/// ```
/// use gaitfit::fit::stats::bootstrap_by_group;
/// let groups = [0, 0, 1, 1, 2, 2];
/// let y = [1.0, 1.2, 2.0, 2.2, 3.0, 3.2];
/// let mean = |rows: &[usize]| Some(vec![rows.iter().map(|&i| y[i]).sum::<f64>() / rows.len() as f64]);
/// let a = bootstrap_by_group(&groups, 200, 7, mean);
/// let b = bootstrap_by_group(&groups, 200, 7, mean);
/// assert_eq!(a, b);
/// assert!(a.ci95[0][0] >= 1.1 && a.ci95[0][1] <= 3.1);
/// ```
pub fn bootstrap_by_group<F>(groups: &[usize], n_boot: usize, seed: u64, fit: F) -> BootstrapSummary
where
    F: Fn(&[usize]) -> Option<Vec<f64>> + Sync,
{
    let (_, rows) = rows_by_group(groups);
    let g = rows.len();
    let results: Vec<Option<Vec<f64>>> = (0..n_boot)
        .into_par_iter()
        .map(|b| {
            if g == 0 {
                return None;
            }
            let mut rng = ChaCha8Rng::seed_from_u64(seed);
            rng.set_stream(b as u64);
            let mut sample = Vec::with_capacity(groups.len());
            for _ in 0..g {
                let k = rng.random_range(0..g);
                sample.extend_from_slice(&rows[k]);
            }
            fit(&sample)
        })
        .collect();
    summarize(results)
}

fn summarize(results: Vec<Option<Vec<f64>>>) -> BootstrapSummary {
    let total = results.len();
    let width = results.iter().flatten().map(Vec::len).next().unwrap_or(0);
    let replicates: Vec<Vec<f64>> = results
        .into_iter()
        .flatten()
        .filter(|r| r.len() == width && r.iter().all(|v| v.is_finite()))
        .collect();
    let n_ok = replicates.len();
    let mut mean = vec![f64::NAN; width];
    let mut std_dev = vec![f64::NAN; width];
    let mut ci95 = vec![[f64::NAN; 2]; width];
    for j in 0..width {
        let mut v: Vec<f64> = replicates.iter().map(|r| r[j]).collect();
        if v.is_empty() {
            continue;
        }
        let m = v.iter().sum::<f64>() / v.len() as f64;
        mean[j] = m;
        if v.len() > 1 {
            std_dev[j] =
                (v.iter().map(|x| (x - m).powi(2)).sum::<f64>() / (v.len() - 1) as f64).sqrt();
        }
        v.sort_by(f64::total_cmp);
        ci95[j] = [quantile_sorted(&v, 0.025), quantile_sorted(&v, 0.975)];
    }
    BootstrapSummary {
        n_ok,
        n_failed: total - n_ok,
        mean,
        std_dev,
        ci95,
        replicates,
    }
}

/// Draws `n` indices in `0..n` with replacement from a seeded ChaCha8 stream (row bootstrap
/// helper for data without groups; equivalent to [`bootstrap_by_group`] with one group per row).
pub fn resample_indices(n: usize, seed: u64, stream: u64) -> Vec<usize> {
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    rng.set_stream(stream);
    (0..n).map(|_| rng.random_range(0..n)).collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn p_value_limits() {
        // |t| = ∞ (noise-free data) is p = 0, not NaN; NaN and df ≤ 0 stay NaN.
        assert_eq!(t_two_sided_p(f64::INFINITY, 10.0), 0.0);
        assert_eq!(t_two_sided_p(f64::NEG_INFINITY, 10.0), 0.0);
        assert!(t_two_sided_p(f64::NAN, 10.0).is_nan());
        assert!(t_two_sided_p(1.0, 0.0).is_nan());
        assert!((t_two_sided_p(0.0, 10.0) - 1.0).abs() < 1e-12);
    }

    #[test]
    fn quantiles_match_tables() {
        // Student t table values (Abramowitz & Stegun 26.10 / any statistics text).
        assert!((t_quantile(0.975, 1.0) - 12.706204736174698).abs() < 1e-8);
        assert!((t_quantile(0.975, 30.0) - 2.042272456301238).abs() < 1e-9);
        assert!((t_quantile(0.025, 5.0) + 2.570581835636314).abs() < 1e-9);
        assert!(t_quantile(1.5, 5.0).is_nan());
        assert!(t_quantile(0.5, 0.0).is_nan());
        assert!((t_two_sided_p(2.228138851986274, 10.0) - 0.05).abs() < 1e-9);
    }

    #[test]
    fn lre_conventions() {
        assert!(lre(f64::NAN, 1.0).is_nan());
        assert_eq!(lre(0.0, 0.0), LRE_MAX);
        assert_eq!(lre(3.0, 1.0), 0.0);
        assert!((lre(-1.0e-3, 0.0) - 3.0).abs() < 1e-12);
    }

    #[test]
    fn r2_and_information_criteria() {
        let y = [1.0, 2.0, 3.0];
        assert!((r2_centred(&y, 0.5, None) - 0.75).abs() < 1e-15);
        assert!((r2_uncentred(&y, 1.4, None) - 0.9).abs() < 1e-15);
        // AIC − BIC difference is k(2 − ln n).
        let (a, b) = (aic(2.0, 10, 2, 0.0), bic(2.0, 10, 2, 0.0));
        assert!((a - b - 3.0 * (2.0 - 10f64.ln())).abs() < 1e-12);
        // ln L by hand: n = 4, RSS = 4 → σ̂² = 1.
        let ll = gaussian_log_likelihood(4.0, 4, 0.0);
        assert!((ll + 2.0 * ((2.0 * std::f64::consts::PI).ln() + 1.0)).abs() < 1e-12);
    }

    #[test]
    fn logo_covers_every_row_once() {
        let groups = [3, 1, 3, 2, 1, 1];
        let out = leave_one_group_out(&groups, |train, test| Some((train.to_vec(), test.to_vec())));
        assert_eq!(out.len(), 3);
        assert_eq!(out[0].1, vec![1, 4, 5]);
        assert_eq!(out[1].1, vec![3]);
        assert_eq!(out[2].1, vec![0, 2]);
        for (train, test) in &out {
            assert_eq!(train.len() + test.len(), groups.len());
        }
    }

    #[test]
    fn bootstrap_is_reproducible_and_thread_independent() {
        let groups: Vec<usize> = (0..40).map(|i| i / 4).collect();
        let y: Vec<f64> = (0..40).map(|i| (i as f64).sin()).collect();
        let f = |rows: &[usize]| {
            Some(vec![
                rows.iter().map(|&i| y[i]).sum::<f64>() / rows.len() as f64,
                rows.len() as f64,
            ])
        };
        let a = bootstrap_by_group(&groups, 300, 42, f);
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(1)
            .build()
            .unwrap();
        let b = pool.install(|| bootstrap_by_group(&groups, 300, 42, f));
        assert_eq!(a, b);
        assert_eq!(a.n_ok, 300);
        // Every group has 4 rows and 10 groups are drawn.
        assert!(a.replicates.iter().all(|r| r[1] == 40.0));
        let c = bootstrap_by_group(&groups, 300, 43, f);
        assert_ne!(a.replicates, c.replicates);
        // Failures are counted, not kept.
        let d = bootstrap_by_group(&groups, 50, 1, |rows: &[usize]| {
            (rows[0] % 8 != 0).then(|| vec![1.0])
        });
        assert_eq!(d.n_ok + d.n_failed, 50);
        assert!(d.n_failed > 0);
    }

    #[test]
    fn quantile_type7() {
        let v = [1.0, 2.0, 3.0, 4.0];
        assert_eq!(quantile_sorted(&v, 0.5), 2.5);
        assert!((quantile_sorted(&v, 0.025) - 1.075).abs() < 1e-15);
        assert_eq!(median(&[3.0, 1.0, 2.0]), 2.0);
    }
}
