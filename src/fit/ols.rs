//! Weighted and unweighted linear least squares, with the statistics a publication needs.
//!
//! # Method
//! [`ols`] solves `min Σ wᵢ (yᵢ − xᵢᵀβ)²` in an equilibrated basis:
//! 1. rows are multiplied by `√wᵢ` (weighted least squares);
//! 2. when the model has an intercept column (a constant, non-zero column and
//!    `has_intercept = true`), every other column is centred on its weighted mean — this removes
//!    the collinearity between the intercept and columns far from zero (Longley's years, the
//!    sf ≈ 200 steps/min of the running relations);
//! 3. every column is scaled to unit 2-norm;
//! 4. the scaled system `[A | b]` is reduced to its `(p+1)×(p+1)` triangular factor by a
//!    **streaming Householder QR** over blocks of [`QR_BLOCK_ROWS`]
//!    rows (nalgebra's QR on `[R; next block]`), so a million-row fit needs no `n×p` copy and no
//!    explicit `Q`;
//! 5. the SVD of the small factor `R` gives the condition number of the equilibrated design and
//!    the rank; a design with `σ_min/σ_max` below [`SINGULAR_RCOND`] is rejected as
//!    [`FitError::Singular`], naming the collinear columns (from the right singular vector of the
//!    smallest singular value). Full-rank systems are solved by back-substitution in `R`, or,
//!    when the condition number exceeds [`ILL_CONDITIONED`], through the SVD of `R` (the
//!    fallback for ill-conditioned designs);
//! 6. coefficients and their covariance `σ²(XᵀWX)⁻¹` are mapped back to the caller's basis;
//!    fitted values and residuals are evaluated in the centred basis (no cancellation against a
//!    large intercept), and the leverages are `hᵢᵢ = ‖R⁻ᵀ aᵢ‖²`.
//!
//! [`polynomial_fit`] does the same in the basis `t = (x − centre)/half_range ∈ [−1, 1]` and maps
//! coefficients and covariance back to raw powers of `x` (NIST Filip keeps ≥ 7 digits that way).
//! [`huber_irls`] is the robust (Huber M-estimate) variant by iteratively reweighted least
//! squares.
// `!(a > b)` is deliberate throughout: it is also true for NaN, which must be rejected too.
#![allow(clippy::neg_cmp_op_on_partial_ord)]

use nalgebra::{DMatrix, DVector};

use super::prec::{ILL_CONDITIONED, IRLS_TOL, MAD_TO_SIGMA, QR_BLOCK_ROWS, SINGULAR_RCOND};
use super::stats::{self, TTest};
use super::FitError;

/// A linear least-squares problem `y ≈ Xβ` (optionally weighted).
///
/// Build it with [`LinearProblem::new`] and the setters, or as a struct literal
/// (`LinearProblem { weights: Some(&w), ..LinearProblem::new(&x, &y) }`).
#[derive(Debug, Clone, Copy)]
pub struct LinearProblem<'a> {
    /// `n × p` design matrix. The caller includes an intercept column (all ones) if the model
    /// has one.
    pub x: &'a DMatrix<f64>,
    /// Response, length `n`.
    pub y: &'a DVector<f64>,
    /// Weights (inverse variances, > 0), length `n`; `None` = ordinary least squares.
    pub weights: Option<&'a DVector<f64>>,
    /// Whether the model has an intercept. `false` → r² is the **uncentred** one,
    /// `1 − RSS/Σ wᵢyᵢ²` (NIST NoInt1/NoInt2, the walking `sl = k·sf·h` relation).
    pub has_intercept: bool,
    /// Name used in error messages (relation id or data set name).
    pub name: &'a str,
    /// Optional column names, used in error messages (collinear columns); default `x0, x1, …`.
    pub column_names: Option<&'a [String]>,
}

impl<'a> LinearProblem<'a> {
    /// An unweighted problem. `has_intercept` defaults to whether `x` has a constant non-zero
    /// column; name `"linear fit"`.
    pub fn new(x: &'a DMatrix<f64>, y: &'a DVector<f64>) -> Self {
        let has_intercept = constant_column(x).is_some();
        LinearProblem {
            x,
            y,
            weights: None,
            has_intercept,
            name: "linear fit",
            column_names: None,
        }
    }
    /// Sets the weights (inverse variances).
    pub fn with_weights(mut self, w: &'a DVector<f64>) -> Self {
        self.weights = Some(w);
        self
    }
    /// Sets whether the model has an intercept (see [`LinearProblem::has_intercept`]).
    pub fn with_intercept(mut self, has_intercept: bool) -> Self {
        self.has_intercept = has_intercept;
        self
    }
    /// Sets the name used in error messages.
    pub fn named(mut self, name: &'a str) -> Self {
        self.name = name;
        self
    }
    /// Sets the column names used in error messages.
    pub fn with_column_names(mut self, names: &'a [String]) -> Self {
        self.column_names = Some(names);
        self
    }
}

/// The index of the first constant, non-zero column of `x` (the intercept column), if any.
fn constant_column(x: &DMatrix<f64>) -> Option<usize> {
    if x.nrows() == 0 {
        return None;
    }
    (0..x.ncols()).find(|&j| {
        let c = x.column(j);
        let v = c[0];
        v != 0.0 && v.is_finite() && c.iter().all(|&e| e == v)
    })
}

/// The stable basis a [`LinearFit`] was solved in, kept so that predictions and confidence
/// bands avoid the raw basis' cancellation.
#[derive(Debug, Clone, PartialEq)]
struct ColumnBasis {
    /// Weighted column means subtracted (0 for the intercept column and when not centring).
    means: Vec<f64>,
    /// Coefficients of the centred columns (`β'_j`, with the intercept absorbing the means).
    centred_coef: Vec<f64>,
}

/// Polynomial basis of a [`polynomial_fit`]: `t = (x − centre)/half_range`, coefficients and
/// covariance in powers of `t`.
#[derive(Debug, Clone, PartialEq)]
pub struct PolynomialBasis {
    /// Centre of the x range, `(min + max)/2`.
    pub centre: f64,
    /// Half the x range, `(max − min)/2`.
    pub half_range: f64,
    /// Coefficients of `1, t, t², …`.
    pub coef_t: Vec<f64>,
    /// Covariance of `coef_t`.
    pub cov_t: DMatrix<f64>,
}

impl PolynomialBasis {
    fn powers(&self, x: f64) -> Vec<f64> {
        let t = (x - self.centre) / self.half_range;
        let mut v = Vec::with_capacity(self.coef_t.len());
        let mut tk = 1.0;
        for _ in 0..self.coef_t.len() {
            v.push(tk);
            tk *= t;
        }
        v
    }
}

/// A fitted linear model with its statistics.
#[derive(Debug, Clone, PartialEq)]
pub struct LinearFit {
    /// Coefficients β, in the caller's basis (raw powers for [`polynomial_fit`]).
    pub coef: DVector<f64>,
    /// Covariance of β, `σ²(XᵀWX)⁻¹`.
    pub cov: DMatrix<f64>,
    /// Standard errors, `sqrt(diag cov)`.
    pub std_error: DVector<f64>,
    /// Fitted values `Xβ`.
    pub fitted: DVector<f64>,
    /// Residuals `y − Xβ` (unweighted).
    pub residuals: DVector<f64>,
    /// Leverages, the diagonal of the (weighted) hat matrix.
    pub leverage: DVector<f64>,
    /// Weights used (all ones for an unweighted fit).
    pub weights: DVector<f64>,
    /// Number of rows.
    pub n: usize,
    /// Number of coefficients.
    pub p: usize,
    /// Residual degrees of freedom `n − p`.
    pub df_resid: usize,
    /// Residual sum of squares `Σ wᵢ eᵢ²`.
    pub rss: f64,
    /// Residual standard deviation `sqrt(rss/df_resid)`.
    pub sigma: f64,
    /// r² (centred, or uncentred when `uncentred`).
    pub r2: f64,
    /// Adjusted r²: `1 − (1 − r²)(n − 1)/(n − p)` centred, `1 − (1 − r²)·n/(n − p)` uncentred.
    pub adj_r2: f64,
    /// Whether `r2` is the uncentred one (model through the origin).
    pub uncentred: bool,
    /// Numerical rank of the design (equal to `p`; rank-deficient designs are rejected).
    pub rank: usize,
    /// 2-norm condition number of the equilibrated design (weighted, intercept-centred,
    /// unit-norm columns) in which the problem was solved.
    pub condition_number: f64,
    /// `Σ ln wᵢ` (for the likelihood; 0 unweighted).
    pub sum_log_w: f64,
    /// For [`polynomial_fit`]: the centred/scaled basis the fit was solved in.
    pub polynomial: Option<PolynomialBasis>,
    basis: ColumnBasis,
}

impl LinearFit {
    /// Whether the equilibrated design's condition number exceeds [`ILL_CONDITIONED`].
    pub fn ill_conditioned(&self) -> bool {
        self.condition_number > ILL_CONDITIONED
    }

    /// Two-sided t confidence intervals of the coefficients at `level` (e.g. 0.95), with
    /// `df_resid` degrees of freedom. NaN bounds for a `level` outside (0, 1).
    pub fn ci(&self, level: f64) -> Vec<[f64; 2]> {
        (0..self.p)
            .map(|j| {
                stats::t_interval(self.coef[j], self.std_error[j], self.df_resid as f64, level)
            })
            .collect()
    }

    /// Leave-one-out RMSE from the leverages (PRESS, no refits):
    /// `sqrt(Σ wᵢ (eᵢ/(1 − hᵢᵢ))² / n)`. Infinite when some `hᵢᵢ = 1`.
    pub fn press_rmse(&self) -> f64 {
        let s: f64 = (0..self.n)
            .map(|i| {
                let d = 1.0 - self.leverage[i];
                self.weights[i] * (self.residuals[i] / d).powi(2)
            })
            .sum();
        (s / self.n as f64).sqrt()
    }

    /// Root mean square of the (weighted) residuals, `sqrt(rss/n)`.
    pub fn rmse(&self) -> f64 {
        (self.rss / self.n as f64).sqrt()
    }

    /// Akaike information criterion (Gaussian likelihood, k = p + 1; see [`stats`]).
    pub fn aic(&self) -> f64 {
        stats::aic(self.rss, self.n, self.p, self.sum_log_w)
    }

    /// Bayesian information criterion (Gaussian likelihood, k = p + 1; see [`stats`]).
    pub fn bic(&self) -> f64 {
        stats::bic(self.rss, self.n, self.p, self.sum_log_w)
    }

    /// t-test of coefficient `j` against `value` (e.g. its published value):
    /// `t = (β_j − value)/se_j` with `df_resid` degrees of freedom, two-sided p.
    /// Returns NaN statistics when `j` is out of range.
    pub fn t_test(&self, j: usize, value: f64) -> TTest {
        if j >= self.p {
            return TTest::new(f64::NAN, value, f64::NAN, self.df_resid as f64);
        }
        TTest::new(self.coef[j], value, self.std_error[j], self.df_resid as f64)
    }

    /// Prediction `x_rowᵀβ` for one design row (length `p`), evaluated in the centred basis.
    /// NaN when the row has the wrong length.
    pub fn predict(&self, x_row: &[f64]) -> f64 {
        if x_row.len() != self.p {
            return f64::NAN;
        }
        // x_rowᵀβ = Σ (x_j − m_j) β'_j with the intercept coefficient absorbing the means.
        x_row
            .iter()
            .zip(&self.basis.means)
            .zip(&self.basis.centred_coef)
            .map(|((x, m), b)| (x - m) * b)
            .sum()
    }

    fn band(&self, x_row: &[f64], level: f64, new_obs: bool) -> [f64; 2] {
        if x_row.len() != self.p {
            return [f64::NAN; 2];
        }
        let yhat = self.predict(x_row);
        let x = DVector::from_column_slice(x_row);
        let mut var = (x.transpose() * &self.cov * &x)[(0, 0)].max(0.0);
        if new_obs {
            var += self.sigma * self.sigma;
        }
        let q = stats::t_quantile(0.5 + 0.5 * level, self.df_resid as f64);
        [yhat - q * var.sqrt(), yhat + q * var.sqrt()]
    }

    /// Confidence band of the mean response at one design row (length `p`), at `level`:
    /// `x_rowᵀβ ± t·sqrt(x_rowᵀ cov x_row)`. For plots of the refit curve with its band.
    pub fn mean_ci(&self, x_row: &[f64], level: f64) -> [f64; 2] {
        self.band(x_row, level, false)
    }

    /// Prediction interval of a new observation (unit weight) at one design row:
    /// `x_rowᵀβ ± t·sqrt(σ² + x_rowᵀ cov x_row)`.
    pub fn predict_interval(&self, x_row: &[f64], level: f64) -> [f64; 2] {
        self.band(x_row, level, true)
    }

    /// For [`polynomial_fit`] results: the fitted polynomial at `x`, evaluated in the stable
    /// `t` basis. NaN for fits that are not polynomial fits.
    pub fn poly_predict(&self, x: f64) -> f64 {
        match &self.polynomial {
            Some(b) => b.powers(x).iter().zip(&b.coef_t).map(|(t, c)| t * c).sum(),
            None => f64::NAN,
        }
    }

    /// For [`polynomial_fit`] results: confidence band of the mean response at `x` (stable
    /// basis). NaN for fits that are not polynomial fits.
    pub fn poly_mean_ci(&self, x: f64, level: f64) -> [f64; 2] {
        match &self.polynomial {
            Some(b) => {
                let v = DVector::from_vec(b.powers(x));
                let var = (v.transpose() * &b.cov_t * &v)[(0, 0)].max(0.0);
                let yhat = self.poly_predict(x);
                let q = stats::t_quantile(0.5 + 0.5 * level, self.df_resid as f64);
                [yhat - q * var.sqrt(), yhat + q * var.sqrt()]
            }
            None => [f64::NAN; 2],
        }
    }
}

fn col_name(p: &LinearProblem, j: usize) -> String {
    match p.column_names.and_then(|n| n.get(j)) {
        Some(s) => s.clone(),
        None => format!("x{j}"),
    }
}

fn validate(p: &LinearProblem) -> Result<(), FitError> {
    let (n, k) = (p.x.nrows(), p.x.ncols());
    let name = p.name.to_string();
    if k == 0 {
        return Err(FitError::InvalidInput {
            relation: name,
            message: "the design matrix has no columns".into(),
        });
    }
    if p.y.len() != n {
        return Err(FitError::InvalidInput {
            relation: name,
            message: format!("design has {n} rows but y has {} values", p.y.len()),
        });
    }
    if let Some(w) = p.weights {
        if w.len() != n {
            return Err(FitError::InvalidInput {
                relation: name,
                message: format!("design has {n} rows but there are {} weights", w.len()),
            });
        }
        for (i, &wi) in w.iter().enumerate() {
            if !wi.is_finite() {
                return Err(FitError::NonFinite {
                    relation: name,
                    what: "weight".into(),
                    row: i,
                    value: wi,
                });
            }
            if wi <= 0.0 {
                return Err(FitError::InvalidInput {
                    relation: name,
                    message: format!(
                        "weight at row {i} is {wi}; weights must be > 0 (drop the row instead)"
                    ),
                });
            }
        }
    }
    if n <= k {
        return Err(FitError::TooFew {
            relation: name,
            what: "rows".into(),
            have: n,
            need: k + 1,
        });
    }
    if let Some(i) = p.y.as_slice().iter().position(|v| !v.is_finite()) {
        return Err(FitError::NonFinite {
            relation: name,
            what: "y".into(),
            row: i,
            value: p.y[i],
        });
    }
    // Column-major storage: one linear scan finds the first bad cell.
    if let Some(idx) = p.x.as_slice().iter().position(|v| !v.is_finite()) {
        let (i, j) = (idx % n, idx / n);
        return Err(FitError::NonFinite {
            relation: name,
            what: format!("column {}", col_name(p, j)),
            row: i,
            value: p.x[(i, j)],
        });
    }
    Ok(())
}

/// The factorised problem: everything [`ols`] and [`ols_coef_rss`] share.
struct Core {
    wv: Vec<f64>,
    means: Vec<f64>,
    scales: Vec<f64>,
    rinv: DMatrix<f64>,
    t: DMatrix<f64>,
    coef: DVector<f64>,
    centred: Vec<f64>,
    cond: f64,
    rss_qr: f64,
}

fn solve_core(p: &LinearProblem) -> Result<Core, FitError> {
    validate(p)?;
    let (n, k) = (p.x.nrows(), p.x.ncols());
    let x = p.x;
    // Column j of the column-major design as a contiguous slice.
    let col = |j: usize| &x.as_slice()[j * n..(j + 1) * n];
    let y = p.y.as_slice();
    let wv: Vec<f64> = match p.weights {
        Some(w) => w.as_slice().to_vec(),
        None => vec![1.0; n],
    };
    let sw: Option<Vec<f64>> = p.weights.map(|_| wv.iter().map(|w| w.sqrt()).collect());
    let sum_w: f64 = wv.iter().sum();

    // Centre non-intercept columns when the model has an intercept column.
    let ic = if p.has_intercept {
        constant_column(x)
    } else {
        None
    };
    let mut means = vec![0.0; k];
    if let Some(ic) = ic {
        for (j, m) in means.iter_mut().enumerate() {
            if j == ic {
                continue;
            }
            let c = col(j);
            let m1 = c.iter().zip(&wv).map(|(v, w)| w * v).sum::<f64>() / sum_w;
            // Second pass corrects the rounding of the first (two-pass mean).
            let corr = c.iter().zip(&wv).map(|(v, w)| w * (v - m1)).sum::<f64>() / sum_w;
            *m = m1 + corr;
        }
    }
    // Column scales (weighted 2-norms of the centred columns).
    let mut scales = vec![0.0; k];
    for (j, s) in scales.iter_mut().enumerate() {
        let m = means[j];
        *s = col(j)
            .iter()
            .zip(&wv)
            .map(|(v, w)| w * (v - m) * (v - m))
            .sum::<f64>()
            .sqrt();
        if *s == 0.0 || !s.is_finite() {
            let why = if ic.is_some() && Some(j) != ic {
                "is constant, so it duplicates the intercept column"
            } else {
                "is all zeros"
            };
            return Err(FitError::Singular {
                relation: p.name.to_string(),
                message: format!("column {} {why}; remove it from the model", col_name(p, j)),
            });
        }
    }

    // Streaming Householder QR of the scaled [A | b], block by block: QR([R; block]).
    let kk = k + 1;
    let mut r_aug = DMatrix::<f64>::zeros(kk, kk);
    let mut start = 0;
    while start < n {
        let end = (start + QR_BLOCK_ROWS).min(n);
        let rows = end - start;
        let h = kk + rows;
        let mut m = DMatrix::<f64>::zeros(h, kk);
        m.view_mut((0, 0), (kk, kk)).copy_from(&r_aug);
        let ms = m.as_mut_slice();
        for j in 0..k {
            let (mj, inv_s) = (means[j], 1.0 / scales[j]);
            let dst = &mut ms[j * h + kk..(j + 1) * h];
            for (d, v) in dst.iter_mut().zip(&col(j)[start..end]) {
                *d = (v - mj) * inv_s;
            }
            if let Some(sw) = &sw {
                dst.iter_mut()
                    .zip(&sw[start..end])
                    .for_each(|(d, s)| *d *= s);
            }
        }
        let dst = &mut ms[k * h + kk..(k + 1) * h];
        dst.copy_from_slice(&y[start..end]);
        if let Some(sw) = &sw {
            dst.iter_mut()
                .zip(&sw[start..end])
                .for_each(|(d, s)| *d *= s);
        }
        let r = m.qr().r();
        r_aug.copy_from(&r.view((0, 0), (kk, kk)));
        start = end;
    }
    let r = r_aug.view((0, 0), (k, k)).into_owned();
    let z = r_aug.view((0, k), (k, 1)).column(0).into_owned();
    let rss_qr = r_aug[(k, k)] * r_aug[(k, k)];

    // Rank and condition number from the SVD of R (same singular values as A).
    let svd =
        nalgebra::SVD::try_new(r.clone(), true, true, f64::EPSILON, 10_000).ok_or_else(|| {
            FitError::Singular {
                relation: p.name.to_string(),
                message: "the SVD of the design did not converge".into(),
            }
        })?;
    let sv = &svd.singular_values;
    let smax = sv.max();
    let smin = sv.min();
    let cond = smax / smin;
    if !(smin > SINGULAR_RCOND * smax) {
        // Columns with a large share of the null-space direction are the collinear ones.
        let jmin = sv.imin();
        let names: Vec<String> = match svd.v_t.as_ref() {
            Some(vt) => {
                let row = vt.row(jmin);
                let big = row.amax();
                (0..k)
                    .filter(|&j| row[j].abs() >= 0.1 * big)
                    .map(|j| col_name(p, j))
                    .collect()
            }
            None => Vec::new(),
        };
        return Err(FitError::Singular {
            relation: p.name.to_string(),
            message: format!(
                "columns {} are (nearly) collinear (condition number {:.3e} after scaling); \
                 drop one of them or add data that separates them",
                names.join(", "),
                cond
            ),
        });
    }
    // Coefficients in the scaled basis.
    let c = if cond > ILL_CONDITIONED {
        svd.solve(&z, 0.0).map_err(|e| FitError::Singular {
            relation: p.name.to_string(),
            message: e.to_string(),
        })?
    } else {
        r.solve_upper_triangular(&z)
            .ok_or_else(|| FitError::Singular {
                relation: p.name.to_string(),
                message: "zero pivot in the triangular factor".into(),
            })?
    };
    let eye = DMatrix::<f64>::identity(k, k);
    let rinv = r
        .solve_upper_triangular(&eye)
        .ok_or_else(|| FitError::Singular {
            relation: p.name.to_string(),
            message: "zero pivot in the triangular factor".into(),
        })?;

    // Centred-basis coefficients β'_j = c_j/s_j; the raw intercept absorbs Σ m_j β'_j.
    let centred: Vec<f64> = (0..k).map(|j| c[j] / scales[j]).collect();
    let mut t = DMatrix::<f64>::zeros(k, k);
    for j in 0..k {
        t[(j, j)] = 1.0 / scales[j];
    }
    let mut coef = DVector::from_column_slice(&centred);
    if let Some(ic) = ic {
        let kappa = x[(0, ic)];
        let shift: f64 = (0..k)
            .filter(|&j| j != ic)
            .map(|j| means[j] * centred[j])
            .sum();
        coef[ic] = centred[ic] - shift / kappa;
        for j in 0..k {
            if j != ic {
                t[(ic, j)] = -means[j] / (scales[j] * kappa);
            }
        }
    }

    Ok(Core {
        wv,
        means,
        scales,
        rinv,
        t,
        coef,
        centred,
        cond,
        rss_qr,
    })
}

/// Coefficients and residual sum of squares only — one streaming QR pass, no residuals,
/// leverages or covariance — for profiling a breakpoint or knot (many fits of the same size).
/// The RSS comes from the QR's last diagonal element (`‖Qᵀb‖` tail), accurate to about
/// `ε·Σwᵢyᵢ²`. Same validation and errors as [`ols`].
pub fn ols_coef_rss(p: &LinearProblem) -> Result<(DVector<f64>, f64), FitError> {
    let core = solve_core(p)?;
    Ok((core.coef, core.rss_qr))
}

/// Fits `y ≈ Xβ` by (weighted) least squares; see the [module docs](self) for the method.
///
/// Errors: [`FitError::TooFew`] when `n ≤ p`, [`FitError::NonFinite`] for NaN/∞ inputs,
/// [`FitError::InvalidInput`] for mismatched lengths or non-positive weights,
/// [`FitError::Singular`] for a rank-deficient design (naming the collinear columns).
///
/// ```
/// use nalgebra::{DMatrix, DVector};
/// use gaitfit::fit::ols::{ols, LinearProblem};
/// let x = DMatrix::from_row_slice(4, 2, &[1.0, 0.0, 1.0, 1.0, 1.0, 2.0, 1.0, 3.0]);
/// let y = DVector::from_vec(vec![1.0, 3.1, 4.9, 7.0]);
/// let fit = ols(&LinearProblem::new(&x, &y)).unwrap();
/// assert!((fit.coef[1] - 1.98).abs() < 1e-12); // Sxy/Sxx = 9.9/5
/// assert_eq!(fit.df_resid, 2);
/// ```
pub fn ols(p: &LinearProblem) -> Result<LinearFit, FitError> {
    let Core {
        wv,
        means,
        scales,
        rinv,
        t,
        coef,
        centred,
        cond,
        rss_qr: _,
    } = solve_core(p)?;
    let (n, k) = (p.x.nrows(), p.x.ncols());
    let x = p.x;
    let col = |j: usize| &x.as_slice()[j * n..(j + 1) * n];
    let y = p.y.as_slice();
    // Fitted values (centred basis) and leverages h_ii = ‖R⁻ᵀ a_i‖² in one pass over blocks of
    // rows: each block's centred columns are formed once, and every inner loop runs along the
    // rows (contiguous, vectorised). Sums are taken in the same order as row by row.
    let g: Vec<f64> = (0..k * k)
        .map(|idx| {
            let (l, jj) = (idx % k, idx / k);
            rinv[(l, jj)] / scales[l]
        })
        .collect();
    let mut fitted = vec![0.0; n];
    let mut leverage = vec![0.0; n];
    const B: usize = 256;
    let mut d = vec![0.0; k * B];
    let (mut u, mut acc) = ([0.0f64; B], [0.0f64; B]);
    let mut start = 0;
    while start < n {
        let m = B.min(n - start);
        for l in 0..k {
            let ml = means[l];
            let dl = &mut d[l * B..l * B + m];
            for (dv, v) in dl.iter_mut().zip(&col(l)[start..start + m]) {
                *dv = v - ml;
            }
        }
        let f = &mut fitted[start..start + m];
        for j in 0..k {
            let bj = centred[j];
            for (f, dv) in f.iter_mut().zip(&d[j * B..j * B + m]) {
                *f += dv * bj;
            }
        }
        acc[..m].fill(0.0);
        for jj in 0..k {
            // −0.0: the start of `Iterator::sum`, which the row-by-row form used.
            u[..m].fill(-0.0);
            for l in 0..=jj {
                let gl = g[jj * k + l];
                for (uv, dv) in u[..m].iter_mut().zip(&d[l * B..l * B + m]) {
                    *uv += gl * dv;
                }
            }
            for (a, uv) in acc[..m].iter_mut().zip(&u[..m]) {
                *a += uv * uv;
            }
        }
        for ((h, a), w) in leverage[start..start + m]
            .iter_mut()
            .zip(&acc[..m])
            .zip(&wv[start..start + m])
        {
            *h = a * w;
        }
        start += m;
    }
    let residuals: Vec<f64> = y.iter().zip(&fitted).map(|(y, f)| y - f).collect();
    let rss: f64 = residuals.iter().zip(&wv).map(|(e, w)| w * e * e).sum();

    let df = n - k;
    let sigma2 = rss / df as f64;
    let cov_scaled = &rinv * rinv.transpose();
    let cov = (&t * cov_scaled * t.transpose()) * sigma2;
    let std_error = cov.diagonal().map(|v| v.max(0.0).sqrt());
    let wopt = p.weights.map(|_| wv.as_slice());
    let (r2, adj_r2) = if p.has_intercept {
        let r2 = stats::r2_centred(y, rss, wopt);
        (r2, 1.0 - (1.0 - r2) * (n as f64 - 1.0) / df as f64)
    } else {
        let r2 = stats::r2_uncentred(y, rss, wopt);
        (r2, 1.0 - (1.0 - r2) * n as f64 / df as f64)
    };
    let sum_log_w = if p.weights.is_some() {
        wv.iter().map(|w| w.ln()).sum()
    } else {
        0.0
    };
    Ok(LinearFit {
        coef,
        cov,
        std_error,
        fitted: DVector::from_vec(fitted),
        residuals: DVector::from_vec(residuals),
        leverage: DVector::from_vec(leverage),
        weights: DVector::from_vec(wv),
        n,
        p: k,
        df_resid: df,
        rss,
        sigma: sigma2.sqrt(),
        r2,
        adj_r2,
        uncentred: !p.has_intercept,
        rank: k,
        condition_number: cond,
        sum_log_w,
        polynomial: None,
        basis: ColumnBasis {
            means,
            centred_coef: centred,
        },
    })
}

/// The raw polynomial design `[1, x, x², …, x^degree]` (n × (degree+1)).
pub fn polynomial_design(x: &[f64], degree: usize) -> DMatrix<f64> {
    DMatrix::from_fn(x.len(), degree + 1, |i, j| x[i].powi(j as i32))
}

/// Binomial coefficient C(k, j) as f64 (exact for the degrees used here).
fn binom(k: usize, j: usize) -> f64 {
    let mut c = 1.0;
    for i in 0..j {
        c = c * (k - i) as f64 / (i + 1) as f64;
    }
    c
}

/// Fits a polynomial `y = β₀ + β₁x + … + β_d x^d` (optionally weighted) in the well-conditioned
/// basis `t = (x − centre)/half_range ∈ [−1, 1]`, then maps coefficients and covariance back to
/// raw powers of `x` (the returned [`LinearFit`] is in the raw basis; its
/// [`LinearFit::polynomial`] keeps the `t`-basis solution for stable evaluation with
/// [`LinearFit::poly_predict`] / [`LinearFit::poly_mean_ci`]).
///
/// ```
/// use gaitfit::fit::ols::polynomial_fit;
/// // t_flight(sf) cubic of the running paper (eq. 5) sampled exactly at sf = 180…230.
/// let sf: Vec<f64> = (0..11).map(|i| 180.0 + 5.0 * i as f64).collect();
/// let c = [-8.925, 0.131, -0.623e-3, 0.979e-6];
/// let y: Vec<f64> = sf.iter().map(|s| c[0] + c[1] * s + c[2] * s * s + c[3] * s * s * s).collect();
/// let fit = polynomial_fit(&sf, &y, 3, None).unwrap();
/// for j in 0..4 {
///     assert!(((fit.coef[j] - c[j]) / c[j]).abs() < 1e-8);
/// }
/// ```
pub fn polynomial_fit(
    x: &[f64],
    y: &[f64],
    degree: usize,
    weights: Option<&[f64]>,
) -> Result<LinearFit, FitError> {
    let name = "polynomial fit";
    if x.len() != y.len() {
        return Err(FitError::InvalidInput {
            relation: name.into(),
            message: format!("x has {} values but y has {}", x.len(), y.len()),
        });
    }
    for (i, &xi) in x.iter().enumerate() {
        if !xi.is_finite() {
            return Err(FitError::NonFinite {
                relation: name.into(),
                what: "x".into(),
                row: i,
                value: xi,
            });
        }
    }
    let k = degree + 1;
    if x.len() <= k {
        return Err(FitError::TooFew {
            relation: name.into(),
            what: "rows".into(),
            have: x.len(),
            need: k + 1,
        });
    }
    let (lo, hi) = x
        .iter()
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), &v| {
            (a.min(v), b.max(v))
        });
    let centre = 0.5 * (lo + hi);
    let half = 0.5 * (hi - lo);
    if !(half > 0.0) {
        return Err(FitError::Singular {
            relation: name.into(),
            message: format!("all x values are equal ({lo}); a polynomial needs distinct x"),
        });
    }
    // Columns 1, t, t², … filled by recurrence, column-major.
    let n = x.len();
    let mut buf = vec![1.0; n * k];
    for j in 1..k {
        let (prev, cur) = buf.split_at_mut(j * n);
        let prev = &prev[(j - 1) * n..];
        for ((c, p), xi) in cur[..n].iter_mut().zip(prev).zip(x) {
            *c = p * ((xi - centre) / half);
        }
    }
    let tx = DMatrix::from_vec(n, k, buf);
    let yv = DVector::from_column_slice(y);
    let wv = weights.map(DVector::from_column_slice);
    let names: Vec<String> = (0..k).map(|j| format!("x^{j}")).collect();
    let mut prob = LinearProblem::new(&tx, &yv)
        .with_intercept(true)
        .named(name)
        .with_column_names(&names);
    if let Some(w) = wv.as_ref() {
        prob = prob.with_weights(w);
    }
    let mut fit = ols(&prob)?;

    // Raw coefficients: β_j = Σ_{k≥j} γ_k C(k,j) (−centre)^{k−j} / half^k.
    let mut m = DMatrix::<f64>::zeros(k, k);
    for kk in 0..k {
        let hk = half.powi(kk as i32);
        for j in 0..=kk {
            m[(j, kk)] = binom(kk, j) * (-centre).powi((kk - j) as i32) / hk;
        }
    }
    let gamma = fit.coef.clone();
    let cov_t = fit.cov.clone();
    // Compensated (Neumaier) summation of the mapping: its terms alternate in sign.
    let mut coef = DVector::<f64>::zeros(k);
    for j in 0..k {
        let mut s = 0.0;
        let mut comp = 0.0;
        for kk in j..k {
            let (term, err) = two_prod(m[(j, kk)], gamma[kk]);
            let tsum = s + term;
            comp += if s.abs() >= term.abs() {
                (s - tsum) + term
            } else {
                (term - tsum) + s
            };
            comp += err;
            s = tsum;
        }
        coef[j] = s + comp;
    }
    fit.cov = &m * &cov_t * m.transpose();
    fit.std_error = fit.cov.diagonal().map(|v| v.max(0.0).sqrt());
    fit.coef = coef;
    fit.basis = ColumnBasis {
        means: vec![0.0; k],
        centred_coef: fit.coef.iter().copied().collect(),
    };
    fit.polynomial = Some(PolynomialBasis {
        centre,
        half_range: half,
        coef_t: gamma.iter().copied().collect(),
        cov_t,
    });
    Ok(fit)
}

/// Error-free product: `a·b = p + e` exactly (FMA).
fn two_prod(a: f64, b: f64) -> (f64, f64) {
    let p = a * b;
    (p, a.mul_add(b, -p))
}

/// A Huber M-estimate fitted by iteratively reweighted least squares.
#[derive(Debug, Clone, PartialEq)]
pub struct HuberFit {
    /// The final weighted least-squares fit (weights = user weights × robust weights): its
    /// coefficients are the M-estimate; its `cov`/`std_error` are the weighted fit's at the
    /// final weights, *not* the M-estimate's (use [`HuberFit::cov`]).
    pub fit: LinearFit,
    /// Covariance of the M-estimate: Huber's (1981, eq. 7.6.4) sandwich with his small-sample
    /// correction, `H1` exactly as statsmodels `RLM(...).fit(cov='H1')` (its default):
    /// `κ² · [Σψ(rᵢ)²/(n − p)] · s² / [Σψ'(rᵢ)/n]² · (XᵀWX)⁻¹` with `rᵢ = √wᵢ eᵢ/s`,
    /// `κ = 1 + (p/n)·var(ψ')/mean(ψ')²` (population variance) and `s` the MAD scale of the
    /// final residuals. With user weights the rows are scaled by `√wᵢ` first.
    pub cov: DMatrix<f64>,
    /// `sqrt(diag cov)`.
    pub std_error: DVector<f64>,
    /// Robust weights `min(1, k·s/|rᵢ|)` of the last iteration (1 = not down-weighted).
    pub robust_weights: DVector<f64>,
    /// Robust residual scale `s = 1.4826·median|√wᵢ eᵢ|` of the final residuals (as statsmodels
    /// RLM reports it).
    pub scale: f64,
    /// The tuning constant `k` (1.345 gives 95 % efficiency under normal errors).
    pub k: f64,
    /// Iterations used.
    pub iterations: usize,
    /// Whether the coefficients stopped moving (see [`IRLS_TOL`]) within `max_iter`.
    pub converged: bool,
}

/// Huber robust regression by IRLS: start from the (weighted) least-squares fit, then repeat
/// `s = 1.4826·median|√wᵢ eᵢ|`, `uᵢ = min(1, k·s/|√wᵢ eᵢ|)`, refit with weights `wᵢuᵢ`, until no
/// coefficient moves by more than [`IRLS_TOL`] times its standard error (or `max_iter`).
/// The scale is re-estimated every iteration (MAD of the residuals, not centred), as in
/// Huber's "proposal 2"-style IRLS of MASS::rlm with `scale.est = "MAD"`.
pub fn huber_irls(p: &LinearProblem, k: f64, max_iter: usize) -> Result<HuberFit, FitError> {
    if !(k > 0.0 && k.is_finite()) {
        return Err(FitError::InvalidInput {
            relation: p.name.to_string(),
            message: format!("Huber tuning constant k = {k}; it must be > 0 (1.345 is usual)"),
        });
    }
    let n = p.x.nrows();
    let base_w: DVector<f64> = match p.weights {
        Some(w) => w.clone(),
        None => DVector::from_element(n, 1.0),
    };
    let mut fit = ols(p)?;
    // (XᵀWX)⁻¹ from the plain fit (σ²(XᵀWX)⁻¹ / σ²), solved in its equilibrated basis.
    let plain_cov = if fit.sigma > 0.0 {
        &fit.cov / (fit.sigma * fit.sigma)
    } else {
        DMatrix::from_element(fit.p, fit.p, f64::NAN)
    };
    let mut u = DVector::from_element(n, 1.0);
    let mut scale = f64::NAN;
    let mut converged = false;
    let mut iterations = 0;
    while iterations < max_iter {
        iterations += 1;
        let r: Vec<f64> = (0..n)
            .map(|i| base_w[i].sqrt() * fit.residuals[i])
            .collect();
        let abs_r: Vec<f64> = r.iter().map(|v| v.abs()).collect();
        scale = MAD_TO_SIGMA * stats::median(&abs_r);
        if !(scale > 0.0) {
            // More than half the points fit exactly: nothing left to down-weight.
            converged = true;
            break;
        }
        for i in 0..n {
            let a = abs_r[i] / scale;
            u[i] = if a <= k { 1.0 } else { k / a };
        }
        let w = base_w.component_mul(&u);
        let next = ols(&LinearProblem {
            weights: Some(&w),
            ..*p
        })?;
        let moved = (0..fit.p).all(|j| {
            let tol = IRLS_TOL * next.std_error[j].max(f64::MIN_POSITIVE);
            (next.coef[j] - fit.coef[j]).abs() <= tol
        });
        fit = next;
        if moved {
            converged = true;
            break;
        }
    }
    // The scale of the final residuals, and the H1 sandwich at them (statsmodels RLM).
    let r: Vec<f64> = (0..n)
        .map(|i| base_w[i].sqrt() * fit.residuals[i])
        .collect();
    let abs_r: Vec<f64> = r.iter().map(|v| v.abs()).collect();
    let s_final = MAD_TO_SIGMA * stats::median(&abs_r);
    if s_final > 0.0 {
        scale = s_final;
    }
    let cov = huber_h1(&plain_cov, &r, scale, k, n, fit.p);
    let std_error = cov.diagonal().map(|v| v.max(0.0).sqrt());
    Ok(HuberFit {
        fit,
        cov,
        std_error,
        robust_weights: u,
        scale,
        k,
        iterations,
        converged,
    })
}

/// Huber's H1 covariance (see [`HuberFit::cov`]) from `(XᵀWX)⁻¹` (`unscaled`), the √w-scaled
/// residuals `r`, the scale `s` and tuning constant `k`. NaN when no residual lies inside ±k·s
/// (ψ' is then 0 everywhere: the M-estimate has no asymptotic variance).
fn huber_h1(
    unscaled: &DMatrix<f64>,
    r: &[f64],
    s: f64,
    k: f64,
    n: usize,
    p: usize,
) -> DMatrix<f64> {
    let nf = n as f64;
    let (mut ss_psi, mut n_in) = (0.0, 0.0);
    for &ri in r {
        let z = if s > 0.0 { ri / s } else { 0.0 };
        ss_psi += z.clamp(-k, k).powi(2);
        if z.abs() <= k {
            n_in += 1.0;
        }
    }
    // ψ' is 1 inside ±k and 0 outside: mean m = n_in/n, population variance m(1 − m).
    let m = n_in / nf;
    let var_d = m * (1.0 - m);
    let kappa = 1.0 + p as f64 / nf * var_d / (m * m);
    let factor = kappa * kappa * (ss_psi / (nf - p as f64)) * s * s / (m * m);
    unscaled * factor
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn exact_line_and_statistics() {
        let x = DMatrix::from_row_slice(5, 2, &[1., 1., 1., 2., 1., 3., 1., 4., 1., 5.]);
        let y = DVector::from_vec(vec![2.9, 5.1, 7.0, 8.8, 11.2]);
        let fit = ols(&LinearProblem::new(&x, &y)).unwrap();
        // Hand computation: x̄ = 3, ȳ = 7, Sxx = 10, Sxy = 20.3 → b = 2.03, a = 7 − 6.09 = 0.91.
        assert!((fit.coef[1] - 2.03).abs() < 1e-13);
        assert!((fit.coef[0] - 0.91).abs() < 1e-13);
        let lev_sum: f64 = fit.leverage.iter().sum();
        assert!((lev_sum - 2.0).abs() < 1e-12);
        assert!(!fit.uncentred);
        assert!(fit.r2 > 0.99 && fit.r2 < 1.0);
    }

    #[test]
    fn errors_are_typed() {
        let x = DMatrix::from_row_slice(2, 2, &[1., 1., 1., 2.]);
        let y = DVector::from_vec(vec![1.0, 2.0]);
        assert!(matches!(
            ols(&LinearProblem::new(&x, &y)),
            Err(FitError::TooFew { need: 3, .. })
        ));
        let x = DMatrix::from_row_slice(3, 2, &[1., 1., 1., f64::NAN, 1., 3.]);
        let y = DVector::from_vec(vec![1.0, 2.0, 3.0]);
        assert!(matches!(
            ols(&LinearProblem::new(&x, &y)),
            Err(FitError::NonFinite { row: 1, .. })
        ));
    }
}
