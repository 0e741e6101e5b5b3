//! Least-squares fitting: linear (QR/SVD in a scaled basis, via nalgebra) and nonlinear (argmin),
//! with the statistics a publication needs.
//!
//! - [`ols`]: weighted/unweighted linear least squares ([`ols::ols`]), polynomial fits in a
//!   centred/scaled basis reported in the raw basis ([`ols::polynomial_fit`]), Huber IRLS
//!   ([`ols::huber_irls`]);
//! - [`nonlinear`]: nonlinear least squares through argmin's trust-region solver
//!   ([`nonlinear::nls`]) for any [`nonlinear::Model`], and a bounded 1-D minimiser
//!   ([`nonlinear::minimize_1d`]) for profiling breakpoints;
//! - [`bounded`]: box-constrained linear least squares, exact (active set, KKT-checked);
//! - [`design`]: the linear part at fixed breakpoints from per-subject sufficient statistics
//!   (per-subject effects absorbed), the normal-equation solve, covariances;
//! - [`inference`]: iid, cluster-robust CR1 and CR2 (Bell–McCaffrey) standard errors;
//! - [`mixed`]: the random-intercept model by REML (`--random-subject`);
//! - [`wild`]: the wild cluster bootstrap-t with Webb six-point weights (exact by enumeration
//!   with few clusters);
//! - [`stats`]: quantiles, LRE, r², AIC/BIC, leave-one-group-out and the seeded group bootstrap;
//! - [`prec`]: every named tolerance of the fitting layer in one place;
//! - [`strd`]: a reader for NIST StRD `.dat` files (the golden tests of this layer).
use thiserror::Error;

pub mod bounded;
pub mod constrained;
pub mod design;
pub mod forms;
pub mod inference;
pub mod mixed;
pub mod nonlinear;
pub mod ols;
pub mod pipeline;
pub mod prec;
pub mod record;
pub mod stats;
pub(crate) mod stopping;
pub mod strd;
pub mod synthetic;
pub mod wild;

/// Errors of the fitting layer.
#[derive(Debug, Error)]
#[non_exhaustive]
pub enum FitError {
    /// Too few rows (or subjects) for the requested fit.
    #[error("{relation}: too few {what}: {have} (need at least {need})")]
    TooFew {
        /// Relation id or data set name.
        relation: String,
        /// "rows", "subjects", …
        what: String,
        /// How many there are.
        have: usize,
        /// How many are needed.
        need: usize,
    },
    /// The design matrix is singular or numerically rank-deficient.
    #[error("{relation}: singular design: {message}")]
    Singular {
        /// Relation id or data set name.
        relation: String,
        /// Details (which columns are collinear, the condition number).
        message: String,
    },
    /// The optimizer failed.
    #[error("{relation}: optimizer failed: {message}")]
    Optimizer {
        /// Relation id or data set name.
        relation: String,
        /// Details.
        message: String,
    },
    /// An input value is NaN or infinite.
    #[error("{relation}: {what} at row {row} is not finite ({value}); remove or repair that row")]
    NonFinite {
        /// Relation id or data set name.
        relation: String,
        /// Which input ("y", "x column 2", "weight", …).
        what: String,
        /// 0-based row index.
        row: usize,
        /// The offending value.
        value: f64,
    },
    /// Inputs are inconsistent (mismatched lengths, bad weights, bad options).
    #[error("{relation}: invalid input: {message}")]
    InvalidInput {
        /// Relation id or data set name.
        relation: String,
        /// What is wrong and how to fix it.
        message: String,
    },
    /// A NIST StRD reference file could not be read or parsed.
    #[error("{file}: line {line}: {message}")]
    Strd {
        /// The file.
        file: String,
        /// 1-based line number (0 when the problem is not tied to one line).
        line: usize,
        /// What is wrong.
        message: String,
    },
}
