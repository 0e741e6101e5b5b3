//! Nonlinear least squares through argmin, for any [`Model`], and a bounded 1-D minimiser.
//!
//! # Method
//! [`nls`] minimises `½ Σ wᵢ (yᵢ − f(xᵢ, θ))²` with **argmin's trust-region method**
//! (`argmin::solver::trustregion::TrustRegion` with the `Steihaug` truncated-CG subproblem) on
//! the Gauss–Newton model: gradient `Jᵀr`, Hessian `JᵀJ` (plus a relative `1e-12` ridge that
//! keeps it positive definite when a column vanishes, e.g. a parameter on a bound; it does not
//! move the fixed point, where `g = 0`). A trust region on the Gauss–Newton model is what
//! Levenberg–Marquardt approximates, so this behaves like MINPACK's `lmder`. Why not argmin's
//! `Dogleg`: in argmin 0.11 its τ formulas cover only the Cauchy→Newton leg, so when the Cauchy
//! point lies outside the radius it returns a zero step, the reduction ratio is 0/0 and the
//! radius never shrinks (observed on BoxBOD and Rat43 from NIST start 1). Steihaug's CG is run
//! with `epsilon = 1e-300` (its default 1e-9 is an *absolute* gradient cut-off that returns a
//! zero step on small-scale problems) and at most `2p + 2` CG iterations.
//! - **scaling** (Moré 1978): the solver works in `v = D·u`, where `D` holds the Jacobian column
//!   norms (non-decreasing over restarts, 1 for a zero column), normalised so `‖v₀‖ = 1`; the
//!   initial trust radius is 1 (a step as large as the start itself);
//! - **termination**: argmin's `TrustRegion` has no stopping test of its own, so a thin argmin
//!   `Solver` wrapper adds MINPACK's tests: the scaled step or the trust radius below
//!   `xtol·(‖v‖ + xtol)`, every Jacobian column within cosine `gtol` of orthogonal to the
//!   residuals, or an exactly zero residual;
//! - **restarts**: after each run the scaling is recomputed at the new point and argmin is run
//!   again, until a run converges without moving (≤ 1 accepted step) — this also resets a trust
//!   radius that argmin's update rule could not grow back (it doubles the radius only when
//!   the step lies on the boundary to within 10ε *absolute*);
//! - a rejected step whose reduction ratio is 0/0 (the step is below the resolution of `v`)
//!   leaves argmin's radius unchanged; the wrapper detects the repeat and stops with
//!   "step below machine precision" (converged);
//! - **bounds** by MINUIT's smooth transforms (James & Roos 1975): `θ = lo + (hi − lo)(sin u + 1)/2`
//!   for two-sided bounds, `θ = lo − 1 + √(u² + 1)` (lower) and `θ = hi + 1 − √(u² + 1)` (upper)
//!   for one-sided ones. The optimiser never leaves the box; a parameter that ends within
//!   [`ACTIVE_BOUND_TOL`] of a bound is reported in [`NonlinearFit::active_bounds`], and its
//!   standard error is NaN (the covariance of the other parameters is computed with it fixed).
//!   A start exactly on a bound is moved inside by `1e-3` of the interval (the transform has a
//!   zero derivative there).
//!
//! Statistics are computed in θ at the solution: `cov = σ²(JᵀWJ)⁻¹` with `σ² = RSS/(n − p)`
//! (NIST's convention; Rat43's header prints 9 degrees of freedom, but its certified residual
//! SD uses n − p = 11), by a column-scaled SVD of `√W·J`.
//! Leave-one-out for a nonlinear fit is the refit-free linearisation `eᵢ/(1 − hᵢᵢ)` with the
//! Jacobian leverages `hᵢᵢ` of `√W·J(JᵀWJ)⁻¹JᵀW^{1/2}` ([`NonlinearFit::press_rmse`]).
// `!(a > b)` is deliberate throughout: it is also true for NaN, which must be rejected too.
#![allow(clippy::neg_cmp_op_on_partial_ord)]

use std::cell::RefCell;

use argmin::core::{CostFunction, Executor, Gradient, Hessian, State, TerminationReason};
use argmin::solver::brent::BrentOpt;
use argmin::solver::trustregion::{Steihaug, TrustRegion};
use nalgebra::{DMatrix, DVector};

use super::prec::{
    ACTIVE_BOUND_TOL, FD_REL_STEP, MIN1D_DEFAULT_TOL, MIN1D_GRID, NLS_GTOL, NLS_MAX_ITER,
    NLS_MAX_RESTARTS, NLS_XTOL,
};
use super::stats::{self, TTest};
use super::stopping::Stopping;
use super::FitError;

/// A model `y = f(x, θ)` for nonlinear least squares: one row of inputs `x` (a slice, as wide
/// as the data's rows) and the parameters `θ`.
pub trait Model: Send + Sync {
    /// Number of parameters.
    fn n_params(&self) -> usize;

    /// The model value at one row of inputs.
    fn value(&self, x: &[f64], theta: &[f64]) -> f64;

    /// `∂f/∂θ` at one row into `out` (length [`Model::n_params`]).
    ///
    /// The default is a central finite difference with step `h_j = ε^{1/3}·|θ_j|`
    /// (`ε^{1/3}` when `θ_j = 0`), rounded so that `θ_j ± h_j` is exactly representable;
    /// its truncation error is `O(h²)`, about 1e-10 relative. Implement it analytically when
    /// you can.
    fn gradient(&self, x: &[f64], theta: &[f64], out: &mut [f64]) {
        let mut t = theta.to_vec();
        for j in 0..theta.len().min(out.len()) {
            let tj = theta[j];
            let h0 = if tj == 0.0 {
                FD_REL_STEP
            } else {
                FD_REL_STEP * tj.abs()
            };
            let up = tj + h0;
            let down = tj - h0;
            t[j] = up;
            let fu = self.value(x, &t);
            t[j] = down;
            let fd = self.value(x, &t);
            t[j] = tj;
            out[j] = (fu - fd) / (up - down);
        }
    }
}

/// A [`Model`] from a closure `f(x, θ)`, with finite-difference gradients.
pub struct FnModel<F> {
    /// Number of parameters.
    pub n_params: usize,
    /// The model function.
    pub f: F,
}

impl<F> Model for FnModel<F>
where
    F: Fn(&[f64], &[f64]) -> f64 + Send + Sync,
{
    fn n_params(&self) -> usize {
        self.n_params
    }
    fn value(&self, x: &[f64], theta: &[f64]) -> f64 {
        (self.f)(x, theta)
    }
}

/// Input rows of a nonlinear fit: a row-major `n × width` table borrowed from a flat slice.
#[derive(Debug, Clone, Copy)]
pub struct Rows<'a> {
    values: &'a [f64],
    width: usize,
}

impl<'a> Rows<'a> {
    /// Wraps a row-major slice of `n·width` values. Errors when `width` is 0 or does not divide
    /// the length.
    pub fn new(values: &'a [f64], width: usize) -> Result<Self, FitError> {
        if width == 0 || values.len() % width != 0 {
            return Err(FitError::InvalidInput {
                relation: "nls".into(),
                message: format!(
                    "{} input values cannot be split into rows of width {width}",
                    values.len()
                ),
            });
        }
        Ok(Rows { values, width })
    }
    /// One input per row (`width = 1`).
    pub fn single(values: &'a [f64]) -> Self {
        Rows { values, width: 1 }
    }
    /// Number of rows.
    pub fn len(&self) -> usize {
        self.values.len() / self.width
    }
    /// Whether there are no rows.
    pub fn is_empty(&self) -> bool {
        self.values.is_empty()
    }
    /// Number of inputs per row.
    pub fn width(&self) -> usize {
        self.width
    }
    /// Row `i`.
    pub fn row(&self, i: usize) -> &'a [f64] {
        &self.values[i * self.width..(i + 1) * self.width]
    }
}

/// Options of [`nls`].
#[derive(Debug, Clone, PartialEq)]
pub struct NlsOptions {
    /// Name used in error messages (relation id).
    pub name: String,
    /// Per-parameter bounds `(lo, hi)`; use `f64::NEG_INFINITY` / `f64::INFINITY` for an open
    /// side. `None` = unbounded.
    pub bounds: Option<Vec<(f64, f64)>>,
    /// Weights (inverse variances, > 0), one per row; `None` = unweighted.
    pub weights: Option<Vec<f64>>,
    /// Trust-region iteration budget over all restarts.
    pub max_iter: u64,
    /// Step tolerance (MINPACK `xtol`), see [`NLS_XTOL`].
    pub xtol: f64,
    /// Gradient tolerance (MINPACK `gtol`), see [`NLS_GTOL`].
    pub gtol: f64,
    /// Maximum number of rescaled restarts, see [`NLS_MAX_RESTARTS`].
    pub max_restarts: usize,
}

impl Default for NlsOptions {
    fn default() -> Self {
        NlsOptions {
            name: "nls".into(),
            bounds: None,
            weights: None,
            max_iter: NLS_MAX_ITER,
            xtol: NLS_XTOL,
            gtol: NLS_GTOL,
            max_restarts: NLS_MAX_RESTARTS,
        }
    }
}

/// A fitted nonlinear model with its statistics (all in θ, at the solution).
#[derive(Debug, Clone, PartialEq)]
pub struct NonlinearFit {
    /// Estimated parameters θ.
    pub theta: Vec<f64>,
    /// Covariance `σ²(JᵀWJ)⁻¹` (rows/columns of parameters at an active bound are NaN).
    pub cov: DMatrix<f64>,
    /// Standard errors (NaN for parameters at an active bound).
    pub std_error: Vec<f64>,
    /// Residual sum of squares `Σ wᵢ eᵢ²`.
    pub rss: f64,
    /// Residual SD `sqrt(rss/(n − p))`.
    pub sigma: f64,
    /// Centred r², `1 − RSS/Σ wᵢ(yᵢ − ȳ_w)²` (for a nonlinear model only a descriptive
    /// number; use [`stats::r2_uncentred`] on `rss` for models through the origin).
    pub r2: f64,
    /// Number of rows.
    pub n: usize,
    /// Number of parameters.
    pub p: usize,
    /// Residual degrees of freedom `n − p`.
    pub df_resid: usize,
    /// Trust-region iterations, summed over restarts.
    pub iterations: u64,
    /// Number of argmin runs (1 + restarts).
    pub runs: usize,
    /// Whether a convergence test (xtol, gtol, zero residual) was met.
    pub converged: bool,
    /// Why the solver stopped (human-readable).
    pub termination: String,
    /// Residuals `y − f(x, θ)` (unweighted).
    pub residuals: Vec<f64>,
    /// Fitted values `f(x, θ)`.
    pub fitted: Vec<f64>,
    /// Jacobian `∂f/∂θ` at the solution (n × p, unweighted).
    pub jacobian: DMatrix<f64>,
    /// Jacobian leverages (diagonal of the linearised hat matrix).
    pub leverage: Vec<f64>,
    /// Weights used (all ones when unweighted).
    pub weights: Vec<f64>,
    /// Per parameter: whether it ended on a bound.
    pub active_bounds: Vec<bool>,
    /// 2-norm condition number of the column-scaled weighted Jacobian of the free parameters.
    pub condition_number: f64,
    /// `Σ ln wᵢ` (0 unweighted).
    pub sum_log_w: f64,
}

impl NonlinearFit {
    /// Two-sided t intervals `θ_j ± t_{df}·se_j` at `level` (Wald intervals from the
    /// linearisation). NaN for parameters at an active bound.
    pub fn ci(&self, level: f64) -> Vec<[f64; 2]> {
        (0..self.p)
            .map(|j| {
                stats::t_interval(
                    self.theta[j],
                    self.std_error[j],
                    self.df_resid as f64,
                    level,
                )
            })
            .collect()
    }
    /// `sqrt(rss/n)`.
    pub fn rmse(&self) -> f64 {
        (self.rss / self.n as f64).sqrt()
    }
    /// Refit-free leave-one-out RMSE from the Jacobian leverages (module docs).
    pub fn press_rmse(&self) -> f64 {
        let s: f64 = (0..self.n)
            .map(|i| self.weights[i] * (self.residuals[i] / (1.0 - self.leverage[i])).powi(2))
            .sum();
        (s / self.n as f64).sqrt()
    }
    /// Akaike information criterion (Gaussian likelihood, k = p + 1; see [`stats`]).
    pub fn aic(&self) -> f64 {
        stats::aic(self.rss, self.n, self.p, self.sum_log_w)
    }
    /// Bayesian information criterion (Gaussian likelihood, k = p + 1; see [`stats`]).
    pub fn bic(&self) -> f64 {
        stats::bic(self.rss, self.n, self.p, self.sum_log_w)
    }
    /// t-test of parameter `j` against `value` (NaN statistics when `j` is out of range).
    pub fn t_test(&self, j: usize, value: f64) -> TTest {
        match self.theta.get(j) {
            Some(&t) => TTest::new(t, value, self.std_error[j], self.df_resid as f64),
            None => TTest::new(f64::NAN, value, f64::NAN, self.df_resid as f64),
        }
    }
    /// Confidence band of the mean response at inputs `x` (delta method):
    /// `f(x, θ) ± t·sqrt(gᵀ cov g)`, `g = ∂f/∂θ(x)`. Parameters at an active bound contribute
    /// no variance.
    pub fn mean_ci<M: Model>(&self, model: &M, x: &[f64], level: f64) -> [f64; 2] {
        let f = model.value(x, &self.theta);
        let mut g = vec![0.0; self.p];
        model.gradient(x, &self.theta, &mut g);
        let mut var = 0.0;
        for a in 0..self.p {
            for b in 0..self.p {
                let c = self.cov[(a, b)];
                if c.is_finite() {
                    var += g[a] * c * g[b];
                }
            }
        }
        let q = stats::t_quantile(0.5 + 0.5 * level, self.df_resid as f64);
        let half = q * var.max(0.0).sqrt();
        [f - half, f + half]
    }
}

/// How one parameter maps from the unconstrained `u` to θ.
#[derive(Debug, Clone, Copy)]
enum Transform {
    Free,
    Lower(f64),
    Upper(f64),
    Both(f64, f64),
}

impl Transform {
    fn theta(self, u: f64) -> f64 {
        match self {
            Transform::Free => u,
            Transform::Lower(lo) => lo - 1.0 + (u * u + 1.0).sqrt(),
            Transform::Upper(hi) => hi + 1.0 - (u * u + 1.0).sqrt(),
            Transform::Both(lo, hi) => lo + 0.5 * (hi - lo) * (u.sin() + 1.0),
        }
    }
    fn dtheta(self, u: f64) -> f64 {
        match self {
            Transform::Free => 1.0,
            Transform::Lower(_) => u / (u * u + 1.0).sqrt(),
            Transform::Upper(_) => -u / (u * u + 1.0).sqrt(),
            Transform::Both(lo, hi) => 0.5 * (hi - lo) * u.cos(),
        }
    }
    /// Inverse, for a θ strictly inside the bounds.
    fn u(self, theta: f64) -> f64 {
        match self {
            Transform::Free => theta,
            Transform::Lower(lo) => ((theta - lo + 1.0).powi(2) - 1.0).max(0.0).sqrt(),
            Transform::Upper(hi) => ((hi - theta + 1.0).powi(2) - 1.0).max(0.0).sqrt(),
            Transform::Both(lo, hi) => (2.0 * (theta - lo) / (hi - lo) - 1.0)
                .clamp(-1.0, 1.0)
                .asin(),
        }
    }
    /// Whether θ is on (within tolerance of) a bound.
    fn at_bound(self, theta: f64) -> bool {
        match self {
            Transform::Free => false,
            Transform::Lower(lo) => theta - lo <= ACTIVE_BOUND_TOL * lo.abs().max(1.0),
            Transform::Upper(hi) => hi - theta <= ACTIVE_BOUND_TOL * hi.abs().max(1.0),
            Transform::Both(lo, hi) => {
                let tol = ACTIVE_BOUND_TOL * (hi - lo);
                theta - lo <= tol || hi - theta <= tol
            }
        }
    }
}

/// Parameter `v`, `JᵀJ` and `Jᵀr` in `v`.
type JacobianCache = (DVector<f64>, DMatrix<f64>, DVector<f64>);

/// The argmin problem: any [`Model`] plus data, in scaled unconstrained coordinates `v`.
struct Adapter<'a, M: Model> {
    model: &'a M,
    x: Rows<'a>,
    y: &'a [f64],
    sw: &'a [f64],
    transforms: &'a [Transform],
    /// `v_j = d_j · u_j`.
    d: Vec<f64>,
    /// Last Jacobian (in v) and its parameter, shared by `gradient` and `hessian`.
    cache: RefCell<Option<JacobianCache>>,
}

impl<M: Model> Adapter<'_, M> {
    fn theta_of_u(&self, u: &[f64]) -> Vec<f64> {
        u.iter()
            .zip(self.transforms)
            .map(|(&u, t)| t.theta(u))
            .collect()
    }
    fn u_of_v(&self, v: &DVector<f64>) -> Vec<f64> {
        v.iter().zip(&self.d).map(|(v, d)| v / d).collect()
    }
    /// Weighted residuals `√wᵢ (yᵢ − f)`; `None` if any is not finite.
    fn residuals(&self, theta: &[f64]) -> Option<DVector<f64>> {
        let n = self.y.len();
        let mut r = DVector::zeros(n);
        for i in 0..n {
            let f = self.model.value(self.x.row(i), theta);
            let v = self.sw[i] * (self.y[i] - f);
            if !v.is_finite() {
                return None;
            }
            r[i] = v;
        }
        Some(r)
    }
    /// Gauss–Newton pieces in v, `(JᵀJ, Jᵀr)`, accumulated row by row (no n×p Jacobian is
    /// stored) and cached for the `gradient`/`hessian` pair at the same point.
    fn normal_v(
        &self,
        v: &DVector<f64>,
    ) -> Result<(DMatrix<f64>, DVector<f64>), argmin::core::Error> {
        if let Some((pv, h, g)) = self.cache.borrow().as_ref() {
            if pv == v {
                return Ok((h.clone(), g.clone()));
            }
        }
        let u = self.u_of_v(v);
        let theta = self.theta_of_u(&u);
        let p = theta.len();
        // dr/dv_k = −√w ∂f/∂θ_k · dθ_k/du_k / d_k
        let chain: Vec<f64> = (0..p)
            .map(|k| self.transforms[k].dtheta(u[k]) / self.d[k])
            .collect();
        let mut h = DMatrix::<f64>::zeros(p, p);
        let mut g = DVector::<f64>::zeros(p);
        let mut df = vec![0.0; p];
        let mut jr = vec![0.0; p];
        for i in 0..self.y.len() {
            let xi = self.x.row(i);
            let f = self.model.value(xi, &theta);
            self.model.gradient(xi, &theta, &mut df);
            let r = self.sw[i] * (self.y[i] - f);
            for k in 0..p {
                jr[k] = -self.sw[i] * df[k] * chain[k];
            }
            if !r.is_finite() || jr.iter().any(|v| !v.is_finite()) {
                return Err(argmin::core::Error::msg(format!(
                    "non-finite residual or gradient at row {i}, θ = {theta:?}"
                )));
            }
            for a in 0..p {
                g[a] += jr[a] * r;
                for b in 0..=a {
                    h[(a, b)] += jr[a] * jr[b];
                }
            }
        }
        for a in 0..p {
            for b in 0..a {
                h[(b, a)] = h[(a, b)];
            }
        }
        *self.cache.borrow_mut() = Some((v.clone(), h.clone(), g.clone()));
        Ok((h, g))
    }
}

impl<M: Model> CostFunction for Adapter<'_, M> {
    type Param = DVector<f64>;
    type Output = f64;
    fn cost(&self, v: &DVector<f64>) -> Result<f64, argmin::core::Error> {
        let theta = self.theta_of_u(&self.u_of_v(v));
        let mut ss = 0.0;
        for i in 0..self.y.len() {
            let r = self.sw[i] * (self.y[i] - self.model.value(self.x.row(i), &theta));
            ss += r * r;
        }
        // A non-finite trial point is simply a very bad one: the trust region shrinks.
        Ok(if ss.is_finite() {
            0.5 * ss
        } else {
            f64::INFINITY
        })
    }
}

impl<M: Model> Gradient for Adapter<'_, M> {
    type Param = DVector<f64>;
    type Gradient = DVector<f64>;
    fn gradient(&self, v: &DVector<f64>) -> Result<DVector<f64>, argmin::core::Error> {
        Ok(self.normal_v(v)?.1)
    }
}

impl<M: Model> Hessian for Adapter<'_, M> {
    type Param = DVector<f64>;
    type Hessian = DMatrix<f64>;
    fn hessian(&self, v: &DVector<f64>) -> Result<DMatrix<f64>, argmin::core::Error> {
        let mut h = self.normal_v(v)?.0;
        // Tiny ridge: keeps H positive definite when a column vanishes (parameter on a bound),
        // so Steihaug's CG never meets zero curvature (its negative-curvature branch sorts NaN
        // model values with `partial_cmp().unwrap()`). It does not move the fixed point g = 0.
        let ridge = 1e-12 * h.diagonal().max().max(f64::MIN_POSITIVE);
        for k in 0..h.nrows() {
            h[(k, k)] += ridge;
        }
        Ok(h)
    }
}

fn validate_nls<M: Model>(
    model: &M,
    x: &Rows,
    y: &[f64],
    start: &[f64],
    opts: &NlsOptions,
) -> Result<Vec<Transform>, FitError> {
    let name = opts.name.clone();
    let p = model.n_params();
    let invalid = |message: String| FitError::InvalidInput {
        relation: name.clone(),
        message,
    };
    if start.len() != p {
        return Err(invalid(format!(
            "the model has {p} parameters but {} start values were given",
            start.len()
        )));
    }
    if x.len() != y.len() {
        return Err(invalid(format!(
            "{} input rows but {} responses",
            x.len(),
            y.len()
        )));
    }
    if y.len() <= p {
        return Err(FitError::TooFew {
            relation: name,
            what: "rows".into(),
            have: y.len(),
            need: p + 1,
        });
    }
    for (i, &v) in y.iter().enumerate() {
        if !v.is_finite() {
            return Err(FitError::NonFinite {
                relation: name,
                what: "y".into(),
                row: i,
                value: v,
            });
        }
    }
    for i in 0..x.len() {
        if let Some(&v) = x.row(i).iter().find(|v| !v.is_finite()) {
            return Err(FitError::NonFinite {
                relation: name,
                what: "x".into(),
                row: i,
                value: v,
            });
        }
    }
    if let Some(w) = &opts.weights {
        if w.len() != y.len() {
            return Err(invalid(format!("{} weights for {} rows", w.len(), y.len())));
        }
        if let Some((i, &v)) = w
            .iter()
            .enumerate()
            .find(|(_, v)| !(v.is_finite() && **v > 0.0))
        {
            return Err(invalid(format!(
                "weight at row {i} is {v}; weights must be finite and > 0"
            )));
        }
    }
    if let Some((j, &s)) = start.iter().enumerate().find(|(_, s)| !s.is_finite()) {
        return Err(invalid(format!("start value {j} is {s}")));
    }
    if !(opts.xtol > 0.0 && opts.gtol >= 0.0) {
        return Err(invalid("xtol must be > 0 and gtol ≥ 0".into()));
    }
    let mut tr = vec![Transform::Free; p];
    if let Some(b) = &opts.bounds {
        if b.len() != p {
            return Err(invalid(format!("{} bounds for {p} parameters", b.len())));
        }
        for (j, &(lo, hi)) in b.iter().enumerate() {
            if lo.is_nan() || hi.is_nan() || lo >= hi {
                return Err(invalid(format!(
                    "bounds of parameter {j} are ({lo}, {hi}); need lo < hi"
                )));
            }
            if start[j] < lo || start[j] > hi {
                return Err(invalid(format!(
                    "start value {} of parameter {j} is outside its bounds ({lo}, {hi})",
                    start[j]
                )));
            }
            tr[j] = match (lo.is_finite(), hi.is_finite()) {
                (false, false) => Transform::Free,
                (true, false) => Transform::Lower(lo),
                (false, true) => Transform::Upper(hi),
                (true, true) => Transform::Both(lo, hi),
            };
        }
    }
    Ok(tr)
}

/// Fits `model` to `(x, y)` by nonlinear least squares from `start`, through argmin's
/// trust-region solver (see the [module docs](self) for the method, scaling, stopping tests
/// and bounds).
///
/// A run that stops without meeting a convergence test is returned with `converged = false`
/// and the reason in `termination` (not as an error); errors are reserved for invalid input
/// ([`FitError::InvalidInput`], [`FitError::NonFinite`], [`FitError::TooFew`]), a start where
/// the model is not finite, and optimiser failures ([`FitError::Optimizer`]).
///
/// ```
/// use gaitfit::fit::nonlinear::{nls, FnModel, NlsOptions, Rows};
/// // y = a·exp(b·x), exact data.
/// let x: Vec<f64> = (0..10).map(|i| i as f64 / 3.0).collect();
/// let y: Vec<f64> = x.iter().map(|x| 2.0 * (0.5 * x).exp()).collect();
/// let model = FnModel { n_params: 2, f: |x: &[f64], t: &[f64]| t[0] * (t[1] * x[0]).exp() };
/// let fit = nls(&model, Rows::single(&x), &y, &[1.0, 0.1], &NlsOptions::default()).unwrap();
/// assert!(fit.converged);
/// assert!((fit.theta[0] - 2.0).abs() < 1e-8 && (fit.theta[1] - 0.5).abs() < 1e-8);
/// ```
pub fn nls<M: Model>(
    model: &M,
    x: Rows,
    y: &[f64],
    start: &[f64],
    opts: &NlsOptions,
) -> Result<NonlinearFit, FitError> {
    let transforms = validate_nls(model, &x, y, start, opts)?;
    let name = opts.name.clone();
    let (n, p) = (y.len(), start.len());
    let weights: Vec<f64> = opts.weights.clone().unwrap_or_else(|| vec![1.0; n]);
    let sw: Vec<f64> = weights.iter().map(|w| w.sqrt()).collect();

    // Start strictly inside the bounds (the transforms have zero slope on a bound).
    let mut u: Vec<f64> = start
        .iter()
        .zip(&transforms)
        .map(|(&s, t)| {
            let s = match *t {
                Transform::Both(lo, hi) => s.clamp(lo + 1e-3 * (hi - lo), hi - 1e-3 * (hi - lo)),
                Transform::Lower(lo) => s.max(lo + 1e-3 * lo.abs().max(1.0)),
                Transform::Upper(hi) => s.min(hi - 1e-3 * hi.abs().max(1.0)),
                Transform::Free => s,
            };
            t.u(s)
        })
        .collect();

    let mut probe = Adapter {
        model,
        x,
        y,
        sw: &sw,
        transforms: &transforms,
        d: vec![1.0; p],
        cache: RefCell::new(None),
    };
    let theta0 = probe.theta_of_u(&u);
    if probe.residuals(&theta0).is_none() {
        return Err(FitError::InvalidInput {
            relation: name,
            message: format!(
                "the model is not finite at the start θ = {theta0:?}; choose another start"
            ),
        });
    }

    let mut d_max = vec![0.0f64; p];
    let mut iterations = 0u64;
    let mut runs = 0usize;
    let mut converged = false;
    let mut termination = String::from("not started");
    while runs <= opts.max_restarts && iterations < opts.max_iter {
        runs += 1;
        // Moré scaling: non-decreasing column norms of the Jacobian in u.
        // Column norms of J in u are the square roots of diag(JᵀJ) with unit scaling.
        probe.d = vec![1.0; p];
        *probe.cache.borrow_mut() = None;
        let (jtj, _) = probe
            .normal_v(&DVector::from_column_slice(&u))
            .map_err(|e| FitError::Optimizer {
                relation: name.clone(),
                message: e.to_string(),
            })?;
        for (k, dk) in d_max.iter_mut().enumerate() {
            *dk = dk.max(jtj[(k, k)].sqrt());
        }
        let mut d: Vec<f64> = d_max
            .iter()
            .map(|&c| if c > 0.0 { c } else { 1.0 })
            .collect();
        let du: f64 = u
            .iter()
            .zip(&d)
            .map(|(u, d)| (u * d).powi(2))
            .sum::<f64>()
            .sqrt();
        if du > 0.0 {
            for dk in &mut d {
                *dk /= du;
            }
        }
        probe.d = d.clone();
        *probe.cache.borrow_mut() = None;
        let v0 = DVector::from_iterator(p, u.iter().zip(&d).map(|(u, d)| u * d));

        let sub = Steihaug::new()
            .with_epsilon(1e-300)
            .map_err(|e| FitError::Optimizer {
                relation: name.clone(),
                message: e.to_string(),
            })?
            .with_max_iters(2 * p as u64 + 2);
        let tr = TrustRegion::new(sub)
            .with_radius(1.0)
            .and_then(|t| t.with_max_radius(1e10))
            .map_err(|e| FitError::Optimizer {
                relation: name.clone(),
                message: e.to_string(),
            })?;
        let solver = Stopping::new(tr, opts.xtol, opts.gtol);
        let budget = opts.max_iter - iterations;
        let mut res = Executor::new(probe, solver)
            .configure(|s| s.param(v0).max_iters(budget))
            .timer(false)
            .run()
            .map_err(|e| FitError::Optimizer {
                relation: name.clone(),
                message: e.to_string(),
            })?;
        let state = res.state();
        iterations += state.get_iter();
        let reason = state
            .get_termination_reason()
            .map(|r| match r {
                TerminationReason::SolverExit(s) => s.clone(),
                other => other.text().to_string(),
            })
            .unwrap_or_else(|| "unknown".into());
        let accepted = res.solver().accepted();
        let v = state
            .get_best_param()
            .or_else(|| state.get_param())
            .cloned()
            .ok_or_else(|| FitError::Optimizer {
                relation: name.clone(),
                message: "argmin returned no parameter vector".into(),
            })?;
        let ok = matches!(
            state.get_termination_reason(),
            Some(TerminationReason::SolverExit(_))
        );
        u = v.iter().zip(&d).map(|(v, d)| v / d).collect();
        termination = reason;
        // Recover the adapter for the next run.
        probe = res
            .problem
            .take_problem()
            .ok_or_else(|| FitError::Optimizer {
                relation: name.clone(),
                message: "argmin did not hand the problem back".into(),
            })?;
        converged = ok;
        if ok && accepted <= 1 {
            break;
        }
        if !ok {
            // Budget exhausted (max_iters) or another argmin stop: report as not converged.
            break;
        }
    }
    if converged && runs > opts.max_restarts && iterations < opts.max_iter {
        termination = format!("{termination} (restart limit reached)");
    }

    let theta = probe.theta_of_u(&u);
    finish(
        model,
        x,
        y,
        &weights,
        &transforms,
        theta,
        iterations,
        runs,
        converged,
        termination,
        &name,
    )
}

/// Statistics at the solution.
#[allow(clippy::too_many_arguments)]
fn finish<M: Model>(
    model: &M,
    x: Rows,
    y: &[f64],
    weights: &[f64],
    transforms: &[Transform],
    theta: Vec<f64>,
    iterations: u64,
    runs: usize,
    converged: bool,
    termination: String,
    name: &str,
) -> Result<NonlinearFit, FitError> {
    let (n, p) = (y.len(), theta.len());
    let mut jac = DMatrix::zeros(n, p);
    let mut fitted = vec![0.0; n];
    let mut residuals = vec![0.0; n];
    let mut g = vec![0.0; p];
    let mut rss = 0.0;
    for i in 0..n {
        let xi = x.row(i);
        let f = model.value(xi, &theta);
        model.gradient(xi, &theta, &mut g);
        for k in 0..p {
            jac[(i, k)] = g[k];
        }
        fitted[i] = f;
        residuals[i] = y[i] - f;
        rss += weights[i] * residuals[i].powi(2);
    }
    if !rss.is_finite() || jac.iter().any(|v| !v.is_finite()) {
        return Err(FitError::Optimizer {
            relation: name.to_string(),
            message: format!(
                "the model or its gradient is not finite at the solution θ = {theta:?}"
            ),
        });
    }
    let active: Vec<bool> = theta
        .iter()
        .zip(transforms)
        .map(|(&t, tr)| tr.at_bound(t))
        .collect();
    let free: Vec<usize> = (0..p).filter(|&k| !active[k]).collect();
    let df = n - p;
    let sigma2 = rss / df as f64;

    // Covariance of the free parameters from the column-scaled SVD of √W·J.
    let mut cov = DMatrix::from_element(p, p, f64::NAN);
    let mut leverage = vec![0.0; n];
    let mut condition_number = f64::NAN;
    if !free.is_empty() {
        let q = free.len();
        let mut a = DMatrix::zeros(n, q);
        for (c, &k) in free.iter().enumerate() {
            for i in 0..n {
                a[(i, c)] = weights[i].sqrt() * jac[(i, k)];
            }
        }
        let scales: Vec<f64> = (0..q).map(|c| a.column(c).norm()).collect();
        if scales.iter().any(|&s| !(s > 0.0)) {
            return Err(FitError::Singular {
                relation: name.to_string(),
                message: format!(
                    "a parameter has no effect on the model at the solution θ = {theta:?} \
                     (zero Jacobian column); it cannot be estimated from these data"
                ),
            });
        }
        for (c, sc) in scales.iter().enumerate() {
            a.column_mut(c).scale_mut(1.0 / sc);
        }
        let svd = nalgebra::SVD::try_new(a, true, true, f64::EPSILON, 10_000).ok_or_else(|| {
            FitError::Optimizer {
                relation: name.to_string(),
                message: "SVD of the Jacobian did not converge".into(),
            }
        })?;
        let s = &svd.singular_values;
        condition_number = s.max() / s.min();
        if let (Some(uu), Some(vt)) = (svd.u.as_ref(), svd.v_t.as_ref()) {
            // (AᵀA)⁻¹ = V Σ⁻² Vᵀ; leverages = row norms of U.
            for a_ in 0..q {
                for b_ in 0..q {
                    let mut sum = 0.0;
                    for k in 0..q {
                        sum += vt[(k, a_)] * vt[(k, b_)] / (s[k] * s[k]);
                    }
                    cov[(free[a_], free[b_])] = sigma2 * sum / (scales[a_] * scales[b_]);
                }
            }
            for (i, h) in leverage.iter_mut().enumerate() {
                *h = (0..q).map(|k| uu[(i, k)].powi(2)).sum();
            }
        }
    }
    let std_error: Vec<f64> = (0..p).map(|k| cov[(k, k)].max(0.0).sqrt()).collect();
    let std_error = std_error
        .into_iter()
        .enumerate()
        .map(|(k, s)| if active[k] { f64::NAN } else { s })
        .collect();
    let r2 = stats::r2_centred(y, rss, Some(weights));
    let sum_log_w = if weights.iter().all(|&w| w == 1.0) {
        0.0
    } else {
        weights.iter().map(|w| w.ln()).sum()
    };
    Ok(NonlinearFit {
        theta,
        cov,
        std_error,
        rss,
        sigma: sigma2.sqrt(),
        r2,
        n,
        p,
        df_resid: df,
        iterations,
        runs,
        converged,
        termination,
        residuals,
        fitted,
        jacobian: jac,
        leverage,
        weights: weights.to_vec(),
        active_bounds: active,
        condition_number,
        sum_log_w,
    })
}

/// A 1-D function for argmin's Brent minimiser; NaN is treated as +∞.
struct OneD<F>(F);

impl<F: Fn(f64) -> f64> CostFunction for OneD<F> {
    type Param = f64;
    type Output = f64;
    fn cost(&self, x: &f64) -> Result<f64, argmin::core::Error> {
        let v = (self.0)(*x);
        Ok(if v.is_nan() { f64::INFINITY } else { v })
    }
}

/// The points [`minimize_1d`] evaluates first on `[lo, hi]` (its scan of [`MIN1D_GRID`] cells),
/// in order.
pub fn minimize_1d_grid(lo: f64, hi: f64) -> Vec<f64> {
    let h = (hi - lo) / MIN1D_GRID as f64;
    (0..=MIN1D_GRID)
        .map(|k| {
            if k == MIN1D_GRID {
                hi
            } else {
                lo + h * k as f64
            }
        })
        .collect()
}

/// Minimises `f` on `[lo, hi]`: a scan of [`MIN1D_GRID`] cells finds the best bracket (profiles
/// of breakpoints are often multimodal), then argmin's Brent minimiser (`BrentOpt`) polishes it
/// to `tol` in x ([`MIN1D_DEFAULT_TOL`] when `tol ≤ 0`). Returns `(x*, f(x*))`.
///
/// ```
/// use gaitfit::fit::nonlinear::minimize_1d;
/// let (x, fx) = minimize_1d(|x| (x - 2.5).powi(2) + 1.0, 0.0, 10.0, 1e-9).unwrap();
/// assert!((x - 2.5).abs() < 1e-6 && (fx - 1.0).abs() < 1e-12);
/// ```
pub fn minimize_1d<F: Fn(f64) -> f64>(
    f: F,
    lo: f64,
    hi: f64,
    tol: f64,
) -> Result<(f64, f64), FitError> {
    minimize_1d_impl(f, None::<fn(f64, f64) -> f64>, f64::NAN, lo, hi, tol)
}

/// [`minimize_1d`] with a lower bound of `f` on intervals, `lower(a, b) ≤ f(t)` for every `t`
/// in `[a, b]` *as `f` computes it* (so allowing for `f`'s rounding; `−∞` or NaN when there is
/// none): the same result, bit for bit, from fewer evaluations of `f`.
///
/// # Why the result is the same
/// [`minimize_1d`]'s result is a function of the index of the *first* minimum of `f` over its
/// grid ([`minimize_1d_grid`]), of that minimum's value, and of `f` inside the bracket around
/// it (Brent's method evaluates there only). Here that index is found by branch and bound over
/// ranges of grid indices: the grid point nearest `warm` is evaluated first (the incumbent), a
/// range `a..=b` is discarded when `lower(grid[a], grid[b])` exceeds the best value found
/// (then every point in it is strictly worse than the incumbent, so none of them is the first
/// minimum), and the others are bisected, their middle points evaluated. Every grid point is thus evaluated or
/// proven strictly worse than an evaluated one, and ties among evaluated points go to the lower
/// index, as `min_by` does. `warm` only changes how much is discarded.
pub fn minimize_1d_bounded<F: Fn(f64) -> f64, L: Fn(f64, f64) -> f64>(
    f: F,
    lower: L,
    warm: f64,
    lo: f64,
    hi: f64,
    tol: f64,
) -> Result<(f64, f64), FitError> {
    minimize_1d_impl(f, Some(lower), warm, lo, hi, tol)
}

/// The first minimum `(index, value)` of `eval` over `xs`: every point evaluated without a
/// bound, by branch and bound with one (see [`minimize_1d_bounded`]).
fn grid_argmin<E: Fn(f64) -> f64, L: Fn(f64, f64) -> f64>(
    xs: &[f64],
    eval: &E,
    lower: Option<L>,
    warm: f64,
) -> (usize, f64) {
    let Some(lower) = lower else {
        return xs
            .iter()
            .map(|&x| eval(x))
            .enumerate()
            .min_by(|a, b| a.1.total_cmp(&b.1))
            .unwrap_or((0, f64::INFINITY));
    };
    let n = xs.len();
    let mut seen = vec![false; n];
    let mut best = (f64::INFINITY, usize::MAX);
    let mut visit = |k: usize, best: &mut (f64, usize)| {
        if !seen[k] {
            seen[k] = true;
            let v = eval(xs[k]);
            // `min_by(total_cmp)`'s order; equal values go to the lower index.
            if v.total_cmp(&best.0).then(k.cmp(&best.1)).is_lt() {
                *best = (v, k);
            }
        }
    };
    let w = if warm.is_finite() {
        (0..n)
            .min_by(|&a, &b| (xs[a] - warm).abs().total_cmp(&(xs[b] - warm).abs()))
            .unwrap_or(0)
    } else {
        0
    };
    visit(w, &mut best);
    // Open ranges of indices `(bound, a, b, own)`, the lowest bound first: a range enters with
    // its parent's bound (valid for it too) and gets its own only when it comes first, so the
    // bounds of ranges that never come first are not computed; a single point is evaluated.
    let mut open: Vec<(f64, usize, usize, bool)> = vec![(f64::NEG_INFINITY, 0, n - 1, true)];
    while let Some(i) = (0..open.len()).min_by(|&i, &j| open[i].0.total_cmp(&open[j].0)) {
        let (lb, a, b, own) = open.swap_remove(i);
        if lb > best.0 {
            break;
        }
        if a == b {
            visit(a, &mut best);
        } else if !own {
            let v = lower(xs[a], xs[b]);
            // NaN: no bound.
            open.push((if v.is_nan() { lb } else { v.max(lb) }, a, b, true));
        } else {
            let m = a + (b - a) / 2;
            open.push((lb, m, m, false));
            if m > a {
                open.push((lb, a, m - 1, false));
            }
            open.push((lb, m + 1, b, false));
        }
    }
    (best.1.min(n - 1), best.0)
}

fn minimize_1d_impl<F: Fn(f64) -> f64, L: Fn(f64, f64) -> f64>(
    f: F,
    lower: Option<L>,
    warm: f64,
    lo: f64,
    hi: f64,
    tol: f64,
) -> Result<(f64, f64), FitError> {
    if !(lo.is_finite() && hi.is_finite() && lo < hi) {
        return Err(FitError::InvalidInput {
            relation: "minimize_1d".into(),
            message: format!("the interval [{lo}, {hi}] must be finite with lo < hi"),
        });
    }
    let tol = if tol > 0.0 { tol } else { MIN1D_DEFAULT_TOL };
    let eval = |x: f64| {
        let v = f(x);
        if v.is_nan() {
            f64::INFINITY
        } else {
            v
        }
    };
    let xs = minimize_1d_grid(lo, hi);
    let (kbest, fb) = grid_argmin(&xs, &eval, lower, warm);
    let xb = xs[kbest];
    if !fb.is_finite() {
        return Err(FitError::Optimizer {
            relation: "minimize_1d".into(),
            message: format!("the function is not finite anywhere on [{lo}, {hi}]"),
        });
    }
    let a = xs[kbest.saturating_sub(1)];
    let b = xs[(kbest + 1).min(MIN1D_GRID)];
    let solver = BrentOpt::new(a, b).set_tolerance(f64::EPSILON.sqrt(), tol);
    let res = Executor::new(OneD(&eval), solver)
        .configure(|s| s.max_iters(500))
        .timer(false)
        .run()
        .map_err(|e| FitError::Optimizer {
            relation: "minimize_1d".into(),
            message: e.to_string(),
        })?;
    let st = res.state();
    let xr = st.get_best_param().copied().unwrap_or(xb);
    let fr = eval(xr);
    Ok(if fr <= fb { (xr, fr) } else { (xb, fb) })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn transforms_round_trip() {
        for t in [
            Transform::Free,
            Transform::Lower(0.0),
            Transform::Upper(3.0),
            Transform::Both(0.0, 0.3),
        ] {
            let th = 0.1;
            let u = t.u(th);
            assert!((t.theta(u) - th).abs() < 1e-12, "{t:?}");
            let h = 1e-6;
            let fd = (t.theta(u + h) - t.theta(u - h)) / (2.0 * h);
            assert!((fd - t.dtheta(u)).abs() < 1e-7, "{t:?}");
        }
    }

    #[test]
    fn bounded_fit_reports_active_bound() {
        // y = a + b·x with b forced into [0, 1] while the data want b = 2.
        let x: Vec<f64> = (0..20).map(|i| i as f64).collect();
        let y: Vec<f64> = x.iter().map(|x| 1.0 + 2.0 * x).collect();
        let m = FnModel {
            n_params: 2,
            f: |x: &[f64], t: &[f64]| t[0] + t[1] * x[0],
        };
        let opts = NlsOptions {
            bounds: Some(vec![(f64::NEG_INFINITY, f64::INFINITY), (0.0, 1.0)]),
            ..NlsOptions::default()
        };
        let fit = nls(&m, Rows::single(&x), &y, &[0.0, 0.5], &opts).unwrap();
        assert!(fit.converged, "{}", fit.termination);
        assert_eq!(fit.active_bounds, vec![false, true]);
        assert!((fit.theta[1] - 1.0).abs() < 1e-6);
        // With b = 1 fixed the best a is mean(y − x) = 1 + mean(x) = 10.5.
        assert!((fit.theta[0] - 10.5).abs() < 1e-4, "{:?}", fit.theta);
        assert!(fit.std_error[1].is_nan() && fit.std_error[0].is_finite());
    }

    #[test]
    fn minimize_1d_finds_global_min_of_bimodal() {
        let f = |x: f64| (x * x - 1.0).powi(2) + 0.1 * x;
        let (x, _) = minimize_1d(f, -2.0, 2.0, 1e-10).unwrap();
        assert!((x + 1.0).abs() < 0.05, "{x}");
        assert!(minimize_1d(f, 1.0, 1.0, 0.0).is_err());
    }
}
