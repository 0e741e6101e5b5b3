//! Residual tables, plots (plotters; SVG and PNG) and the summary document.
pub mod plots;
pub mod summary;

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

/// Writes the plots of every fit and `summary.md` into `dir`; returns the files written.
pub fn write_report(
    dir: &std::path::Path,
    outcomes: &[crate::fit::pipeline::FitOutcome],
    failures: &[(String, String)],
) -> Result<Vec<std::path::PathBuf>, ReportError> {
    let mut files = Vec::new();
    for o in outcomes {
        files.extend(plots::write_plots(dir, o)?);
    }
    let records: Vec<_> = outcomes.iter().map(|o| o.record.clone()).collect();
    let p = dir.join("summary.md");
    crate::fsio::write_atomic_bytes(&p, summary::render_summary(&records, failures).as_bytes())?;
    files.push(p);
    Ok(files)
}
