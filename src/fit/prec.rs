//! Named tolerances of the fitting layer, in one place (statrs style), so no magic epsilon hides
//! in the solvers. Each constant says what it guards and why it has its value.

/// Relative singular-value cut-off for declaring a (column-scaled) design rank-deficient:
/// σ_min / σ_max below this is treated as exact collinearity and reported as
/// [`crate::fit::FitError::Singular`]. The columns are scaled to unit norm first, so this is
/// the reciprocal of the largest condition number we accept (≈ 4.5e12). NIST's Filip, the worst
/// StRD linear set, has a scaled raw-basis condition number of 3.8e9 and must pass.
pub const SINGULAR_RCOND: f64 = 1.0e3 * f64::EPSILON;

/// A scaled condition number above this is flagged as ill-conditioned (the fit is still
/// returned; [`crate::fit::ols::LinearFit::ill_conditioned`] says so): about half of the 16
/// decimal digits of `f64` may be lost in the raw coefficients.
pub const ILL_CONDITIONED: f64 = 1.0e8;

/// Rows per block in the streaming QR of [`crate::fit::ols::ols`]: large enough to amortise the
/// per-block Householder set-up, small enough to stay in L1/L2 cache.
pub const QR_BLOCK_ROWS: usize = 512;

/// Relative step of the central finite-difference gradient of
/// [`crate::fit::nonlinear::Model::gradient`]: ε^(1/3) balances truncation error (∝ h²) against
/// rounding error (∝ ε/h).
pub const FD_REL_STEP: f64 = 6.055_454_452_393_343e-6; // f64::EPSILON.cbrt()

/// Default relative step tolerance of [`crate::fit::nonlinear::nls`]: stop when the scaled step
/// (or the trust radius) is below `xtol·(‖D θ‖ + xtol)`, MINPACK's `xtol` test. Tighter than
/// MINPACK's √ε so that the NIST StRD certified values are reached to ≥ 6 digits.
pub const NLS_XTOL: f64 = 1.0e-12;

/// Default gradient tolerance of [`crate::fit::nonlinear::nls`]: stop when every column of the
/// Jacobian is orthogonal to the residual vector to within this cosine (MINPACK's `gtol`).
pub const NLS_GTOL: f64 = 1.0e-12;

/// Default iteration budget of [`crate::fit::nonlinear::nls`] (trust-region iterations summed
/// over all restarts).
pub const NLS_MAX_ITER: u64 = 2_000;

/// Maximum number of rescaled restarts of the trust-region solver in
/// [`crate::fit::nonlinear::nls`]. Each restart re-reads the Jacobian column norms (Moré's
/// scaling) and resets the trust radius.
pub const NLS_MAX_RESTARTS: usize = 30;

/// A bounded parameter closer than this (relative to the bound interval, or to `max(1,|bound|)`
/// for one-sided bounds) to a bound, with the gradient pushing outwards, is reported as an
/// active bound.
pub const ACTIVE_BOUND_TOL: f64 = 1.0e-7;

/// Absolute tolerance on `x` of [`crate::fit::nonlinear::minimize_1d`] when the caller passes a
/// non-positive tolerance.
pub const MIN1D_DEFAULT_TOL: f64 = 1.0e-10;

/// Number of grid cells scanned by [`crate::fit::nonlinear::minimize_1d`] before Brent's method
/// polishes the best bracket (profiles of breakpoints are often multimodal).
pub const MIN1D_GRID: usize = 64;

/// Allowance for rounding in a breakpoint window's lower bound of the profile RSS (as a
/// fraction of the rows' `yᵀWy`): a relaxed fit's RSS minus this is what
/// [`crate::fit::nonlinear::minimize_1d_bounded`] receives. RSS from normal equations
/// (`yᵀWy − βᵀXᵀWy`, `solve_normal`) carries a rounding error of about `ε·κ·yᵀWy`; with the
/// centred, unit-diagonal bases κ stays far below 1e5 (5 or more distinct keys per piece), so
/// both the bound's and the profile's own error are below 1e-10·yᵀWy and this allowance covers
/// their sum with room to spare.
pub const PROFILE_BOUND_SLACK: f64 = 1.0e-9;

/// Convergence tolerance of [`crate::fit::ols::huber_irls`]: stop when no coefficient moves by
/// more than this times its standard error between iterations.
pub const IRLS_TOL: f64 = 1.0e-10;

/// MAD → σ consistency factor for the normal distribution, 1/Φ⁻¹(3/4).
pub const MAD_TO_SIGMA: f64 = 1.482_602_218_505_602;

/// The largest LRE reported: an exact match is reported as this many digits, since certified
/// values carry 15 significant digits and `f64` about 15.9.
pub const LRE_MAX: f64 = 15.0;
