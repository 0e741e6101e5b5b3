//! # gaitfit
//!
//! Fit and calibrate the classic knowledge-driven human locomotion models against measured gait
//! data, drive the models with the fitted coefficients, and report how far the generated gait is
//! from the measured one.
//!
//! The three models come from:
//! - Bruderlin & Calvert (1989), *Goal-directed, dynamic animation of human walking* (KLAW);
//! - Bruderlin & Calvert (1996), *Knowledge-driven, interactive animation of human running*
//!   (RUNNER);
//! - Ko & Badler (1993), *Straight line walking animation based on kinematic generalization that
//!   preserves the original characteristics*.
//!
//! Layout (one module per concept):
//! - [`units`]: unit-suffixed column names (`speed_m_per_s`, …) → SI, and back to the papers'
//!   units (m/min, steps/min);
//! - [`gait`]: the shared vocabulary (side, gait, event kinds and sources), a leaf module;
//! - [`ingest`]: readers (trial tables, TRC, MOT/STO, Cortex `.forces`, treadmill GRF, C3D,
//!   Winter's rotoscope table) → typed in-memory tables;
//! - [`events`]: gait event detection and per-step spatiotemporal tables;
//! - [`relations`]: one type per published relation (sl–v, t_flight–sf, walk sl–sf, t_ds–sf, μ);
//! - [`fit`]: linear (QR/SVD) and nonlinear (argmin) least squares with full statistics;
//! - [`generator`]: the shared skeleton and [`generator::motion::Motion`] type, and the three
//!   generators (running, walking, generalize);
//! - [`export`]: coefficient tables (JSON/TOML/Rust/CSV) and motion files (BVH/CSV/TRC);
//! - [`report`]: residual tables, plots and the summary document;
//! - [`studio`]: the local web page for editing runs and walks live (`gaitfit studio`);
//! - [`cli`]: the thin command-line layer used by the `gaitfit` binary.
#![forbid(unsafe_code)]
#![warn(missing_docs)]

pub mod calibrate;
pub mod cli;
pub mod error;
pub mod events;
pub mod export;
pub mod fit;
pub mod fsio;
pub mod gait;
pub mod generator;
pub mod ingest;
pub mod relations;
pub mod report;
pub mod shared_data;
pub mod studio;
pub mod units;

pub use error::{Error, Result};

/// The crate version, written into every coefficient table gaitfit produces.
pub const GAITFIT_VERSION: &str = env!("CARGO_PKG_VERSION");
