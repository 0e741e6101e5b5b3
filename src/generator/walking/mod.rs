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
//! **Continuity caveat.** Steady walks of 1–7 km/h × 1.5–2.0 m meet the smoothness check
//! [`crate::generator::checks::continuity`] at k = 5 (every frame-to-frame step within 5 × the
//! median of its neighbours) except near the walk–run transition (7 km/h × 1.5 m, the ankle at
//! a heel strike), a speed above it: its Froude number `v²/(g·l1)` is 0.53 >
//! [`high_level::WALK_RUN_FROUDE`] and its report carries a note saying so
//! ([`high_level::walk_run_note`]). The figures and their history are in docs/klaw.md.
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
pub mod ankle_curve;
pub mod attributes;
pub mod body;
pub mod collision;
pub mod determinants;
pub mod draw;
pub mod dynamics;
pub mod first_step;
pub mod foot;
pub mod generate;
pub mod high_level;
pub mod integrate;
pub mod lagrange;
pub mod pelvis_drop;
pub mod schedule;
pub mod shooting;
pub mod stance;
pub mod stop;
pub mod swing;
pub mod swing_foot;
pub mod track;
pub mod virtual_leg;

pub use attributes::{WalkAttributes, ATTRIBUTES};
pub use generate::{StepReport, WalkReport};
pub use high_level::{Locomotion, WalkParams, WalkRelations};
pub use schedule::{walk_params, WalkSchedule};

use crate::generator::motion::Motion;
use crate::generator::GenerateError;
use std::path::Path;

/// How a walk is to be generated (besides its steps).
#[derive(Debug, Clone, PartialEq)]
pub struct WalkOptions {
    /// Body height, m.
    pub height_m: f64,
    /// Body mass, kg.
    pub mass_kg: f64,
    /// Locomotion attributes.
    pub attributes: WalkAttributes,
    /// The walking relations (published or fitted).
    pub relations: WalkRelations,
    /// Output frame rate, frames/s.
    pub fps: f64,
    /// Start from standing, feet side by side: the first step starts from rest (its swing foot
    /// travels one step length, half a stride), and frame 0 is that first step's start.
    /// Otherwise the walk starts steady, as a motion-capture trial of steady walking does:
    /// [`generate::PRE_ROLL`] unrecorded steps are simulated before it, and the recording begins
    /// mid-motion [`generate::LEAD_IN_FRAMES`] frames before the first heel strike (frame 0 at t = 0,
    /// the first heel strike at `LEAD_IN_FRAMES / fps`, events and [`StepReport::start_s`] on
    /// the same clock), in the last pre-roll step's landing swing.
    pub start_from_rest: bool,
    /// End standing: a last half step, then the trailing foot is brought alongside and the body
    /// comes to rest ([`stop`]). Otherwise the walk ends mid-motion: one unrecorded step
    /// is simulated after the last, and the recording ends [`generate::LEAD_OUT_FRAMES`] frames after the
    /// trailing foot's toe off that follows the last heel strike.
    pub stop: bool,
}

impl Default for WalkOptions {
    fn default() -> Self {
        WalkOptions {
            height_m: 1.8,
            mass_kg: 75.0,
            attributes: WalkAttributes::default(),
            relations: WalkRelations::published(),
            fps: 100.0,
            start_from_rest: false,
            stop: false,
        }
    }
}

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
///
/// A change of speed between stretches larger than the attribute `max_speed_change_m_per_s`
/// (per step) is ramped ([`ramp_schedule`]); the walk's `metadata.notes` and the report's notes
/// say where. They also name every stretch commanded beyond the walk–run transition (Froude
/// number above [`high_level::WALK_RUN_FROUDE`]), which is walked all the same.
pub fn generate_walk(
    schedule: &[ScheduleEntry],
    opts: &WalkOptions,
) -> Result<(Motion, WalkReport), GenerateError> {
    opts.attributes.validate()?;
    let (mut steps, ramps) = ramp_schedule(schedule, opts)?;
    if steps.is_empty() {
        return Err(GenerateError::Parameter {
            name: "steps".into(),
            value: 0.0,
            message: "the walk has no steps; give a duration or a schedule with steps".into(),
        });
    }
    // From standing the first step keeps its full length: with the feet side by side its swing
    // foot travels one step length (half a stride, as a person's first step does) and eq. 3's
    // symmetric heel strike puts the hip half a step ahead (why not a half step: docs/klaw.md).
    if opts.stop && steps.len() > 1 {
        let f = steps.last_mut().into_iter().next();
        if let Some(f) = f {
            f.step_length_m *= 0.5;
            f.speed_m_per_s *= 0.5;
        }
    }
    let (mut motion, mut report) = generate::generate_steps(&steps, opts)?;
    motion.metadata.notes.extend(ramps.iter().cloned());
    report.notes.extend(ramps);
    Ok((motion, report))
}

/// The schedule's steps, each completed by eq. 1 ([`high_level::complete`]), with every change
/// of speed between stretches larger than `max_speed_change_m_per_s` spread over
/// n = ⌈|Δv| / limit⌉ steps at equal increments of speed (the paper changes speed in one step,
/// §2.4, whatever the size: no one changes walking speed by 1.7 m/s in one step, and the
/// generator breaks the continuity check from about 1.1 m/s per step). Returns the steps and
/// the notes: one per ramped change, and one per entry (with steps) whose Froude number exceeds
/// [`high_level::WALK_RUN_FROUDE`] ([`high_level::walk_run_note`]: it is walked all the same).
pub fn ramp_schedule(
    schedule: &[ScheduleEntry],
    opts: &WalkOptions,
) -> Result<(Vec<Locomotion>, Vec<String>), GenerateError> {
    let entry_err = |i: usize, what: &str, err: GenerateError| match err {
        GenerateError::Parameter {
            name,
            value,
            message,
        } => GenerateError::Parameter {
            name,
            value,
            message: format!("schedule entry {}{what}: {message}", i + 1),
        },
        other => other,
    };
    let complete =
        |p: &WalkParams| high_level::complete(p, opts.height_m, &opts.relations, &opts.attributes);
    let limit = opts.attributes.max_speed_change_m_per_s;
    // The stance model's leg (generate::generate_steps builds the same body).
    let l1 = body::Body::from_height(opts.height_m, opts.mass_kg)?.l1;
    let mut steps: Vec<Locomotion> = Vec::new();
    let mut notes = Vec::new();
    // Whether the last step walked naturally at its speed (given by its speed alone).
    let mut last_natural = true;
    for (i, e) in schedule.iter().enumerate() {
        let target = complete(&e.params).map_err(|err| entry_err(i, "", err))?;
        if e.steps > 0 {
            notes.extend(high_level::walk_run_note(i + 1, &target, opts.height_m, l1));
        }
        let natural =
            e.params.step_length_m.is_none() && e.params.step_freq_steps_per_min.is_none();
        let mut left = e.steps;
        if let (Some(&from), true) = (steps.last(), e.steps > 0) {
            let dv = target.speed_m_per_s - from.speed_m_per_s;
            // 1e-9: a change of exactly the limit is one step.
            let n = ((dv.abs() / limit) - 1e-9).ceil().max(1.0) as usize;
            if n > 1 {
                let ramp = (n - 1).min(e.steps);
                for k in 1..=ramp {
                    let f = k as f64 / n as f64;
                    let v = from.speed_m_per_s + f * dv;
                    let p = WalkParams {
                        speed_m_per_s: Some(v),
                        step_length_m: (!(natural && last_natural)).then_some(
                            from.step_length_m + f * (target.step_length_m - from.step_length_m),
                        ),
                        step_freq_steps_per_min: None,
                    };
                    steps.push(complete(&p).map_err(|err| entry_err(i, " (ramp step)", err))?);
                }
                left -= ramp;
                let reached = steps
                    .last()
                    .map_or(target.speed_m_per_s, |s| s.speed_m_per_s);
                notes.push(format!(
                    "schedule entry {}: speed change {:.2} -> {:.2} m/s exceeds \
                     max_speed_change_m_per_s = {limit} per step; ramped over {} step(s) taken \
                     from the entry{}",
                    i + 1,
                    from.speed_m_per_s,
                    target.speed_m_per_s,
                    ramp + usize::from(left > 0),
                    if left == 0 {
                        format!(
                            ", which is too short: it ends at {reached:.2} m/s, short of its speed"
                        )
                    } else {
                        String::new()
                    }
                ));
            }
        }
        steps.extend(std::iter::repeat_n(target, left));
        if e.steps > 0 {
            last_natural = natural;
        }
    }
    Ok((steps, notes))
}

/// Reads a schedule CSV (the columns shared by every generator,
/// [`crate::generator::schedule`]) as KLAW's stretches. It needs a length of its own (a `steps`
/// column, or one step per row) and no `stop` (set [`WalkOptions::stop`]; the command line
/// reads `action = stop` itself).
pub fn read_schedule(path: &Path) -> Result<Vec<ScheduleEntry>, GenerateError> {
    let s =
        crate::generator::schedule::Schedule::from_csv(path)?.walk(None, WalkParams::default())?;
    if s.stop {
        return Err(GenerateError::Input {
            path: path.display().to_string(),
            message: "action stop: set WalkOptions::stop instead".into(),
        });
    }
    Ok(s.entries)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn kmh(v: f64, steps: usize) -> ScheduleEntry {
        ScheduleEntry::at_speed(v / 3.6, steps)
    }

    fn speeds_kmh(schedule: &[ScheduleEntry], opts: &WalkOptions) -> (Vec<f64>, Vec<String>) {
        let (steps, notes) = ramp_schedule(schedule, opts).unwrap();
        let v = steps.iter().map(|s| s.speed_m_per_s * 3.6).collect();
        (v, notes)
    }

    fn close(a: &[f64], b: &[f64]) -> bool {
        a.len() == b.len() && a.iter().zip(b).all(|(x, y)| (x - y).abs() < 1e-9)
    }

    #[test]
    fn a_large_speed_change_is_ramped_out_of_the_new_stretch() {
        let opts = WalkOptions::default();
        assert_eq!(opts.attributes.max_speed_change_m_per_s, 0.5);
        // 1 -> 7 km/h is 1.67 m/s: n = ceil(1.67 / 0.5) = 4 steps of 1.5 km/h, the first three
        // taken out of the 7 km/h stretch (the schedule keeps its 10 steps).
        let (v, notes) = speeds_kmh(&[kmh(1.0, 4), kmh(7.0, 6)], &opts);
        assert!(
            close(&v, &[1.0, 1.0, 1.0, 1.0, 2.5, 4.0, 5.5, 7.0, 7.0, 7.0]),
            "{v:?}"
        );
        assert_eq!(notes.len(), 1);
        assert!(
            notes[0].contains("schedule entry 2") && notes[0].contains("4 step(s)"),
            "{notes:?}"
        );
        // Down as well: 5 -> 3 km/h (0.56 m/s) takes 2 steps.
        let (v, _) = speeds_kmh(&[kmh(5.0, 2), kmh(3.0, 3)], &opts);
        assert!(close(&v, &[5.0, 5.0, 4.0, 3.0, 3.0]), "{v:?}");
        // The intermediate steps of natural stretches walk naturally (eq. 1) at their speed.
        let (steps, _) = ramp_schedule(&[kmh(1.0, 1), kmh(7.0, 4)], &opts).unwrap();
        let natural = high_level::complete(
            &WalkParams {
                speed_m_per_s: Some(4.0 / 3.6),
                ..Default::default()
            },
            opts.height_m,
            &opts.relations,
            &opts.attributes,
        )
        .unwrap();
        assert_eq!(steps[2], natural);
    }

    #[test]
    fn a_change_within_the_limit_is_untouched() {
        let opts = WalkOptions::default();
        // 2 -> 3.8 km/h is exactly 0.5 m/s; 3.8 -> 3 km/h is 0.22 m/s.
        let (v, notes) = speeds_kmh(&[kmh(2.0, 2), kmh(3.8, 2), kmh(3.0, 2)], &opts);
        assert!(close(&v, &[2.0, 2.0, 3.8, 3.8, 3.0, 3.0]), "{v:?}");
        assert!(notes.is_empty(), "{notes:?}");
        // The limit turned off (10 m/s per step): the paper's one-step change (§2.4).
        let mut off = WalkOptions::default();
        off.attributes.max_speed_change_m_per_s = 10.0;
        let (v, notes) = speeds_kmh(&[kmh(1.0, 2), kmh(7.0, 2)], &off);
        assert!(close(&v, &[1.0, 1.0, 7.0, 7.0]), "{v:?}");
        assert!(notes.is_empty());
    }

    #[test]
    fn a_stretch_shorter_than_its_ramp_ends_short_of_its_speed() {
        let opts = WalkOptions::default();
        // 1 -> 7 km/h needs 4 steps; a 2-step stretch reaches 4 km/h, and the next change
        // (to 1 km/h, 0.83 m/s: 2 steps) starts from there.
        let (v, notes) = speeds_kmh(&[kmh(1.0, 2), kmh(7.0, 2), kmh(1.0, 3)], &opts);
        assert!(close(&v, &[1.0, 1.0, 2.5, 4.0, 2.5, 1.0, 1.0]), "{v:?}");
        assert_eq!(notes.len(), 2, "{notes:?}");
        assert!(notes[0].contains("too short") && notes[0].contains("1.11 m/s"));
        assert!(!notes[1].contains("too short"), "{notes:?}");
    }

    #[test]
    fn given_step_lengths_are_interpolated_linearly() {
        let opts = WalkOptions::default();
        let entry = |v: f64, sl: f64| ScheduleEntry {
            params: WalkParams {
                speed_m_per_s: Some(v),
                step_length_m: Some(sl),
                step_freq_steps_per_min: None,
            },
            steps: 2,
        };
        let (steps, _) = ramp_schedule(&[entry(0.5, 0.5), entry(1.5, 0.8)], &opts).unwrap();
        let sl: Vec<f64> = steps.iter().map(|s| s.step_length_m).collect();
        assert!(close(&sl, &[0.5, 0.5, 0.65, 0.8]), "{sl:?}");
        assert!((steps[2].speed_m_per_s - 1.0).abs() < 1e-12);
        assert!((steps[2].step_freq_steps_per_min - 60.0 / 0.65).abs() < 1e-9);
    }

    #[test]
    fn the_limit_is_validated_before_ramping() {
        let mut opts = WalkOptions::default();
        opts.attributes.max_speed_change_m_per_s = 0.0;
        let e = generate_walk(&[kmh(1.0, 2), kmh(7.0, 2)], &opts)
            .unwrap_err()
            .to_string();
        assert!(e.contains("max_speed_change_m_per_s"), "{e}");
    }
}
