//! `gaitfit studio`: the papers' interactive editing as a local web page.
//!
//! All three papers describe interactive systems: RUNNER (Bruderlin & Calvert 1996, §3.1,
//! Figs. 4–5, 9) ran in real time with a parameter panel (velocity, step length, step frequency,
//! flight height, expertise level; parameters can be *locked*, §3.1.1) and sliders for its
//! nineteen attributes (§3.1.2); KLAW (1989, §3) lets the animator give one to three of speed,
//! step length and step frequency and completes the rest with its normalising formula (eq. 1);
//! Ko & Badler (1993) generalize a measured step to any step length and body. The studio puts
//! these editing loops on one local page: a slider moves, the server regenerates the whole
//! motion with the library's generators and answers with the figure's landmarks, the steps, the
//! relations' curves and the current point.
//!
//! Layout:
//! - [`controls`]: the controls of each generator (parameters, body, attributes) with units and
//!   ranges taken from the generators' own tables and limits;
//! - [`session`]: one request — resolve the parameters under the locks (the papers' rules), read
//!   the schedule, generate the motion;
//! - [`figure`]: the motion as the page draws it (landmarks, bones, contacts, events);
//! - [`plots`]: the relations' curves (published and refitted) at the figure's height, the
//!   current point, and the data tables' points;
//! - [`export`]: the current motion as a BVH, TRC, CSV or MOT file, or its steps table, through
//!   the library's exporters;
//! - [`server`]: the HTTP server (axum on a single-threaded tokio runtime), bound to 127.0.0.1,
//!   refusing every peer that is not loopback, serving the page from assets embedded in the
//!   binary.
pub mod controls;
pub mod export;
pub mod figure;
pub mod plots;
pub mod server;
pub mod session;

use thiserror::Error;

/// Errors of the studio: a request the page sent that cannot be served, or the server failing
/// to start. Messages are the ones the command line prints for the same input.
#[derive(Debug, Error)]
#[non_exhaustive]
pub enum StudioError {
    /// The request is malformed (not JSON, an unknown control, a value that is not a number).
    #[error("{0}")]
    Request(String),
    /// The generator refused the parameters (out of range, over-constrained locks, …).
    #[error(transparent)]
    Generate(#[from] crate::generator::GenerateError),
    /// An export failed.
    #[error(transparent)]
    Export(#[from] crate::export::ExportError),
    /// Writing a temporary export file failed.
    #[error(transparent)]
    Fs(#[from] crate::fsio::FsError),
    /// Any other library error (writing a steps table, reading data tables).
    #[error(transparent)]
    Library(#[from] crate::Error),
    /// The server could not start or stopped with an error.
    #[error("studio server: {0}")]
    Server(String),
}
