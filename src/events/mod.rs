//! Gait event detection (heel strike, foot flat, heel off, meta off, toe off) from force plates
//! and from kinematics, and the per-step spatiotemporal tables built from the events.
pub mod types;

pub use types::{EventKind, EventSource, Gait, GaitEvent, Side};

use thiserror::Error;

/// Errors of the event layer. Every message names the file and, where relevant, the frame and
/// channel.
#[derive(Debug, Error)]
#[non_exhaustive]
pub enum EventError {
    /// No usable events were found (e.g. a standing trial).
    #[error("{path}: no usable gait events: {reason}")]
    NoEvents {
        /// The trial's source file.
        path: String,
        /// Why (what was looked at and what was missing).
        reason: String,
    },
    /// The trial is too short to contain one stride.
    #[error("{path}: trial too short for one stride: {reason}")]
    TooShort {
        /// The trial's source file.
        path: String,
        /// What was found.
        reason: String,
    },
    /// A required signal is missing (a marker, a force channel).
    #[error("{path}: missing {what}")]
    Missing {
        /// The trial's source file.
        path: String,
        /// What is missing.
        what: String,
    },
}
