//! Writers: coefficient tables (JSON, TOML, Rust, CSV) and motion files (BVH, CSV, TRC, OpenSim
//! MOT/STO).
pub mod bvh;
pub mod coeffs;
pub mod motion;
pub mod motion_csv;
pub mod opensim;
pub mod trc;

use thiserror::Error;

/// Errors of the export layer.
#[derive(Debug, Error)]
#[non_exhaustive]
pub enum ExportError {
    /// Writing a file failed.
    #[error(transparent)]
    Fs(#[from] crate::fsio::FsError),
    /// The content cannot be written in the requested format.
    #[error("{path}: {message}")]
    Format {
        /// The destination.
        path: String,
        /// Why.
        message: String,
    },
}
