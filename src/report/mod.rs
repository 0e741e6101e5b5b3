//! Residual tables, plots (plotters; SVG and PNG) and the summary document.
//!
//! The plots' cost and size do not grow with the rows: above a few thousand rows they draw
//! densities, not points (see [`layers`]), and every curve is evaluated at a fixed number of
//! abscissae. The fit's numbers always come from all rows.
pub mod layers;
pub mod plots;
pub mod qq;
pub mod raster;
pub mod summary;
pub mod ticks;

use std::collections::BTreeMap;
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

/// One written figure (`<stem>.svg` and `<stem>.png`) and its caption.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Figure {
    /// File name without extension.
    pub stem: String,
    /// What the figure shows.
    pub shows: String,
    /// What of the data is drawn: all rows as points, or their density (with how many rows).
    pub drawn: String,
}

/// Writes the plots of every fit and `summary.md` into `dir`; returns the files written.
pub fn write_report(
    dir: &std::path::Path,
    outcomes: &[crate::fit::pipeline::FitOutcome],
    failures: &[(String, String)],
) -> Result<Vec<std::path::PathBuf>, ReportError> {
    use rayon::prelude::*;
    let plotted = outcomes
        .par_iter()
        .map(|o| plots::write_plots(dir, o).map(|p| (o.record.relation.clone(), p)))
        .collect::<Result<Vec<_>, _>>()?;
    let mut files = Vec::new();
    let mut figures = BTreeMap::new();
    for (id, (f, figs)) in plotted {
        files.extend(f);
        figures.insert(id, figs);
    }
    let records: Vec<_> = outcomes.iter().map(|o| o.record.clone()).collect();
    let p = dir.join("summary.md");
    crate::fsio::write_atomic_bytes(
        &p,
        summary::render_summary(&records, failures, &figures).as_bytes(),
    )?;
    files.push(p);
    Ok(files)
}
