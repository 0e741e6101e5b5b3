//! Least-squares fitting: linear (QR/SVD in a scaled basis, via nalgebra) and nonlinear (argmin),
//! with the statistics a publication needs.
use thiserror::Error;

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
}
