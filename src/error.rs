//! The crate-level error: one variant per layer, each wrapping that layer's own `thiserror` enum.
//!
//! Library functions return their layer's error; code that crosses layers (the pipelines behind
//! the CLI) returns [`Error`](enum@Error). Every message names its subject (file, row, column, frame or
//! channel) and, where there is one, the remedy.
use thiserror::Error;

/// Any error gaitfit's library can return.
#[derive(Debug, Error)]
#[non_exhaustive]
pub enum Error {
    /// Reading or validating input files.
    #[error(transparent)]
    Ingest(#[from] crate::ingest::IngestError),
    /// Detecting gait events or building per-step tables.
    #[error(transparent)]
    Events(#[from] crate::events::EventError),
    /// Fitting a relation.
    #[error(transparent)]
    Fit(#[from] crate::fit::FitError),
    /// Generating motion.
    #[error(transparent)]
    Generate(#[from] crate::generator::GenerateError),
    /// Writing coefficient tables or motion files.
    #[error(transparent)]
    Export(#[from] crate::export::ExportError),
    /// Writing reports and plots.
    #[error(transparent)]
    Report(#[from] crate::report::ReportError),
    /// Locating or writing files.
    #[error(transparent)]
    Io(#[from] crate::fsio::FsError),
    /// Building a relation from coefficients or a fits file.
    #[error(transparent)]
    Relation(#[from] crate::relations::RelationError),
}

/// `Result` with gaitfit's [`Error`](enum@Error).
pub type Result<T, E = Error> = std::result::Result<T, E>;
