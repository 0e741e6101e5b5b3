//! The trials table: one row per trial or per step, the input of every fit.
//!
//! Values are held in SI units (m, m/s, s, steps/s, radians) once read; the CSV headers carry
//! their unit (`speed_m_per_s`, `step_freq_steps_per_min`, …) and are converted at the boundary
//! by [`crate::units`]. The schema is documented in `data/README.md`.
use crate::events::{Gait, Side};
use serde::{Deserialize, Serialize};

/// One row of a trials table (a trial or a single step), SI units.
///
/// Every quantity is optional: each relation states which it needs, and rows lacking them are
/// reported as rejected for that relation, not silently dropped.
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
pub struct StepRow {
    /// Subject identifier.
    pub subject: String,
    /// Walk or run.
    pub gait: Option<Gait>,
    /// The foot whose contact starts the step (the leading foot at its heel strike).
    pub side: Option<Side>,
    /// Data source (data set and file), for provenance.
    pub source: String,
    /// Trial name within the source.
    pub trial: String,
    /// Time of the step's initial heel strike, s from the start of the trial.
    pub time_s: Option<f64>,
    /// Speed of progression, m/s.
    pub speed_m_per_s: Option<f64>,
    /// Step length, m.
    pub step_length_m: Option<f64>,
    /// Step frequency, steps/s (CSV: `step_freq_steps_per_min` or `step_freq_hz`).
    pub step_freq_hz: Option<f64>,
    /// Stance time of the leading foot, s.
    pub stance_time_s: Option<f64>,
    /// Swing time, s.
    pub swing_time_s: Option<f64>,
    /// Double-support time of the step, s (walking).
    pub double_support_time_s: Option<f64>,
    /// Double support as a percentage of the gait cycle (walking), %.
    pub double_support_pct_cycle: Option<f64>,
    /// Flight time of the step, s (running).
    pub flight_time_s: Option<f64>,
    /// Flight height H of the running paper's eq. 3, m.
    pub flight_height_m: Option<f64>,
    /// Body height, m.
    pub body_height_m: Option<f64>,
    /// Leg length, m.
    pub leg_length_m: Option<f64>,
    /// Ko–Badler μ1 input: knee flexion angle at heel strike, rad.
    pub knee_angle_hs_rad: Option<f64>,
    /// Ko–Badler μ2 input: foot-sole angle to the floor at heel strike, rad.
    pub foot_angle_hs_rad: Option<f64>,
    /// Ko–Badler μ3 input: foot-sole angle to the floor at toe off, rad.
    pub foot_angle_to_rad: Option<f64>,
    /// Ko–Badler μ4 input: metatarsal (toe) angle to the floor at toe off, rad.
    pub meta_angle_to_rad: Option<f64>,
}

/// The canonical column headers gaitfit writes, in order, with their units.
///
/// Readers accept these and the alternative unit suffixes documented in `data/README.md`
/// (`_cm`, `_mm`, `_km_per_h`, `_m_per_min`, `_hz`, `_ms`, `_deg`, …).
pub const CANONICAL_COLUMNS: &[&str] = &[
    "subject",
    "gait",
    "side",
    "source",
    "trial",
    "time_s",
    "speed_m_per_s",
    "step_length_m",
    "step_freq_steps_per_min",
    "stance_time_s",
    "swing_time_s",
    "double_support_time_s",
    "double_support_pct_cycle",
    "flight_time_s",
    "flight_height_m",
    "body_height_m",
    "leg_length_m",
    "knee_angle_hs_deg",
    "foot_angle_hs_deg",
    "foot_angle_to_deg",
    "meta_angle_to_deg",
];
