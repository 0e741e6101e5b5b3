//! KLAW: goal-directed, dynamic animation of human walking (Bruderlin & Calvert 1989).
//!
//! A walk is specified by its locomotion parameters (speed, and optionally step length and/or
//! step frequency, [`WalkParams`]) and individualized by locomotion attributes
//! ([`WalkAttributes`]). For every step:
//! 1. the high level ([`high_level`]) completes the parameters with the normalizing formula
//!    (eq. 1), checks anatomical limits, and decomposes them into *step constraints*: the phase
//!    durations (eq. 2 and the double-support relation) and the final conditions at heel strike
//!    (eq. 3, step symmetry with the kinematic foot);
//! 2. the stance phase ([`stance`]) — a telescopic inverted pendulum carrying the upper body,
//!    appendix A.1 ([`dynamics`]) — is simulated with forces found by shooting ([`shooting`]) so
//!    that it ends exactly on its constraints;
//! 3. the determinants of gait move the pelvis ([`generate::Determinants`]), and the trailing
//!    leg's stance is completed kinematically through the double support ([`virtual_leg`]);
//! 4. the swing leg ([`swing`]) — a double pendulum driven by the swing hip's acceleration,
//!    appendix A.2 — is simulated in three subphases, each shot onto its constraints;
//! 5. heel strike is a collision ([`collision`]) giving the next stance its initial velocities.
//!
//! The virtual leg, kinematic feet, spine and arms then dress the dynamics, and the result is the
//! shared [`Motion`] (exported as BVH, CSV or TRC by [`crate::export::motion::write`]).
//!
//! The equations of motion are checked against an independent Lagrangian derivation
//! ([`lagrange`]); the corrections to the printed equations are listed in [`dynamics`]. The
//! integrator and its stability argument are in [`integrate`].
//!
//! ```
//! use gaitfit::generator::walking::{generate_walk, ScheduleEntry, WalkOptions, WalkParams};
//! let walk = [ScheduleEntry {
//!     params: WalkParams { speed_m_per_s: Some(5.0 / 3.6), ..Default::default() },
//!     steps: 4,
//! }];
//! let (motion, report) = generate_walk(&walk, &WalkOptions::default()).unwrap();
//! assert_eq!(report.steps.len(), 4);
//! assert!(motion.len() > 200); // 4 steps of 0.56 s at 100 frames/s
//! ```
pub mod attributes;
pub mod body;
pub mod collision;
pub mod dynamics;
pub mod foot;
pub mod generate;
pub mod high_level;
pub mod integrate;
pub mod lagrange;
pub mod shooting;
pub mod stance;
pub mod stop;
pub mod swing;
pub mod track;
pub mod virtual_leg;

pub use attributes::{WalkAttributes, ATTRIBUTES};
pub use generate::{StepReport, WalkOptions, WalkReport};
pub use high_level::{Locomotion, WalkParams, WalkRelations};

use crate::generator::motion::Motion;
use crate::generator::GenerateError;
use std::path::Path;

/// A stretch of a walk: the locomotion parameters held for a number of steps.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ScheduleEntry {
    /// The locomotion parameters (at least one of the three).
    pub params: WalkParams,
    /// Number of steps.
    pub steps: usize,
}

impl ScheduleEntry {
    /// `steps` steps at `speed_m_per_s` (m/s), the step length and frequency completed by the
    /// normalizing formula (eq. 1) — the natural walk at that speed.
    pub fn at_speed(speed_m_per_s: f64, steps: usize) -> ScheduleEntry {
        ScheduleEntry {
            params: WalkParams {
                speed_m_per_s: Some(speed_m_per_s),
                ..Default::default()
            },
            steps,
        }
    }
}

/// Number of steps of a walk of `seconds` with parameters `params` (at least one).
pub fn steps_for_duration(
    params: &WalkParams,
    seconds: f64,
    opts: &WalkOptions,
) -> Result<usize, GenerateError> {
    if !(seconds.is_finite() && seconds > 0.0 && seconds <= 3600.0) {
        return Err(GenerateError::Parameter {
            name: "seconds".into(),
            value: seconds,
            message: "the duration must lie in (0, 3600] s".into(),
        });
    }
    let l = high_level::complete(params, opts.height_m, &opts.relations, &opts.attributes)?;
    Ok(((seconds * l.step_freq_steps_per_min / 60.0).round() as usize).max(1))
}

/// Generates a walk: the schedule's stretches one after the other, with accelerations and
/// decelerations at one-step granularity (§2.4). With `opts.start_from_rest` the first step
/// starts from standing, feet side by side, and keeps its commanded step length (its swing foot
/// travels one step length, half a stride; the hip, starting at rest, half a step); with
/// `opts.stop` the last step is a half step, after which the trailing foot is brought alongside
/// and the body comes to rest ([`stop`]).
pub fn generate_walk(
    schedule: &[ScheduleEntry],
    opts: &WalkOptions,
) -> Result<(Motion, WalkReport), GenerateError> {
    let mut steps = Vec::new();
    for (i, e) in schedule.iter().enumerate() {
        let l = high_level::complete(&e.params, opts.height_m, &opts.relations, &opts.attributes)
            .map_err(|err| match err {
            GenerateError::Parameter {
                name,
                value,
                message,
            } => GenerateError::Parameter {
                name,
                value,
                message: format!("schedule entry {}: {message}", i + 1),
            },
            other => other,
        })?;
        steps.extend(std::iter::repeat_n(l, e.steps));
    }
    if steps.is_empty() {
        return Err(GenerateError::Parameter {
            name: "steps".into(),
            value: 0.0,
            message: "the walk has no steps; give a duration or a schedule with steps".into(),
        });
    }
    // From standing the first step keeps its full length: with the feet side by side its swing
    // foot travels one step length (half a stride, as a person's first step does) and eq. 3's
    // symmetric heel strike puts the hip half a step ahead. It used to be a half step (the swing
    // foot travelling a quarter stride): its heel-strike thigh angle (≈ 7° at 2 km/h) was less
    // than the standing swing leg's own, so swing1 could not move the ankle forward (1 mm at
    // 2 km/h), swing2 threw the foot 19 cm past its landing and swing3 pulled it back (swing
    // ankle peak/mean speed 4.4–14.6), at 1 km/h the toe-clearance pitch sank the heel 1.5–3.2 mm
    // into the ground, and the curve lift its clearance rounds needed (4.4 cm at 2 km/h) was
    // carried into every later swing.
    if opts.stop && steps.len() > 1 {
        let f = steps.last_mut().into_iter().next();
        if let Some(f) = f {
            f.step_length_m *= 0.5;
            f.speed_m_per_s *= 0.5;
        }
    }
    generate::generate_steps(&steps, opts)
}

/// Reads a schedule CSV: one row per stretch with columns `steps` and any of `speed_m_per_s`
/// (or `speed_km_per_h`), `step_length_m`, `step_freq_steps_per_min`; empty cells mean "not
/// given" (completed by eq. 1).
pub fn read_schedule(path: &Path) -> Result<Vec<ScheduleEntry>, GenerateError> {
    let bad = |row: usize, col: &str, msg: String| GenerateError::Parameter {
        name: "schedule".into(),
        value: f64::NAN,
        message: format!("{}: row {row}, column {col}: {msg}", path.display()),
    };
    let mut rdr = csv::ReaderBuilder::new()
        .trim(csv::Trim::All)
        .from_path(path)
        .map_err(|e| bad(0, "-", format!("cannot read: {e}")))?;
    let headers = rdr
        .headers()
        .map_err(|e| bad(1, "-", e.to_string()))?
        .clone();
    let col = |name: &str| headers.iter().position(|h| h == name);
    let steps_col = col("steps").ok_or_else(|| bad(1, "steps", "missing column `steps`".into()))?;
    let known = [
        "steps",
        "speed_m_per_s",
        "speed_km_per_h",
        "step_length_m",
        "step_freq_steps_per_min",
    ];
    if let Some(h) = headers.iter().find(|h| !known.contains(h)) {
        return Err(bad(
            1,
            h,
            format!("unknown column; expected {}", known.join(", ")),
        ));
    }
    let mut out = Vec::new();
    for (i, rec) in rdr.records().enumerate() {
        let row = i + 2;
        let rec = rec.map_err(|e| bad(row, "-", e.to_string()))?;
        let num = |name: &str| -> Result<Option<f64>, GenerateError> {
            match col(name).and_then(|c| rec.get(c)) {
                None | Some("") => Ok(None),
                Some(s) => s
                    .parse::<f64>()
                    .map(Some)
                    .map_err(|_| bad(row, name, format!("{s:?} is not a number"))),
            }
        };
        let steps_s = rec.get(steps_col).unwrap_or("");
        let steps: usize = steps_s.parse().map_err(|_| {
            bad(
                row,
                "steps",
                format!("{steps_s:?} is not a whole number of steps"),
            )
        })?;
        let speed = match (num("speed_m_per_s")?, num("speed_km_per_h")?) {
            (Some(_), Some(_)) => {
                return Err(bad(
                    row,
                    "speed_km_per_h",
                    "give the speed in one unit only".into(),
                ))
            }
            (a, b) => a.or(b.map(crate::units::km_per_h_to_m_per_s)),
        };
        out.push(ScheduleEntry {
            params: WalkParams {
                speed_m_per_s: speed,
                step_length_m: num("step_length_m")?,
                step_freq_steps_per_min: num("step_freq_steps_per_min")?,
            },
            steps,
        });
    }
    Ok(out)
}
