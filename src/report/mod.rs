//! Residual tables, plots (plotters; SVG and PNG) and the summary document.
use thiserror::Error;

/// Errors of the report layer.
#[derive(Debug, Error)]
#[non_exhaustive]
pub enum ReportError {
    /// Writing a file failed.
    #[error(transparent)]
    Fs(#[from] crate::fsio::FsError),
    /// Drawing a plot failed.
    #[error("{path}: plot failed: {message}")]
    Plot {
        /// The destination.
        path: String,
        /// Why.
        message: String,
    },
}
