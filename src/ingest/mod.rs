//! Readers: trial tables (CSV with unit-suffixed headers) and raw measured data (TRC, MOT/STO,
//! Cortex `.forces`, instrumented-treadmill GRF text, C3D, Winter's rotoscope table, a generic
//! per-frame CSV) → the typed in-memory tables of [`types`] and [`trials`], in SI units.
pub mod trials;
pub mod types;

use std::path::PathBuf;
use thiserror::Error;

/// Errors of the ingest layer. Every variant names the file and, where it applies, the row (or
/// frame) and the column (or channel/marker), and says what would fix it.
#[derive(Debug, Error)]
#[non_exhaustive]
pub enum IngestError {
    /// The file could not be opened or read.
    #[error("{path}: {source}")]
    Io {
        /// The file.
        path: PathBuf,
        /// The underlying error.
        source: std::io::Error,
    },
    /// The file's structure is wrong (bad header, truncated, wrong count, …).
    #[error("{path}: {message}")]
    Malformed {
        /// The file.
        path: PathBuf,
        /// What is wrong, including the line/frame where it was seen.
        message: String,
    },
    /// A cell could not be used.
    #[error("{path}: row {row}, column {column}: {message}")]
    Cell {
        /// The file.
        path: PathBuf,
        /// 1-based data row (the header is row 0) or frame number.
        row: usize,
        /// Column header, channel or marker name.
        column: String,
        /// What is wrong and how to fix it.
        message: String,
    },
    /// A required column is missing.
    #[error("{path}: missing column {column}: {message}")]
    MissingColumn {
        /// The file.
        path: PathBuf,
        /// The column (or one of the accepted spellings).
        column: String,
        /// What it is needed for, and the accepted unit suffixes.
        message: String,
    },
    /// A unit suffix gaitfit does not know.
    #[error("{path}: column {column}: unknown unit suffix; {message}")]
    UnknownUnit {
        /// The file.
        path: PathBuf,
        /// The offending header.
        column: String,
        /// The accepted spellings.
        message: String,
    },
}

impl IngestError {
    /// Wraps an I/O error with the file it concerns.
    pub fn io(path: impl Into<PathBuf>, source: std::io::Error) -> Self {
        IngestError::Io {
            path: path.into(),
            source,
        }
    }
    /// A structural error in `path`.
    pub fn malformed(path: impl Into<PathBuf>, message: impl Into<String>) -> Self {
        IngestError::Malformed {
            path: path.into(),
            message: message.into(),
        }
    }
    /// An error in one cell.
    pub fn cell(
        path: impl Into<PathBuf>,
        row: usize,
        column: impl Into<String>,
        message: impl Into<String>,
    ) -> Self {
        IngestError::Cell {
            path: path.into(),
            row,
            column: column.into(),
            message: message.into(),
        }
    }
}
