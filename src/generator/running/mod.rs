//! RUNNER: the knowledge-driven running generator of Bruderlin & Calvert (1996),
//! *Knowledge-driven, interactive animation of human running* (Graphics Interface '96).
//!
//! A run is set by four parameters — speed v, step length sl, step frequency sf, flight height
//! H — plus expertise level and body height, coupled by the paper's eqs. 1–5 ([`params`]), and by
//! nineteen attributes that individualise it ([`attributes`]). Each step is planned from state
//! constraints ([`state`], §3.2: heel position, pelvis at heel strike bottom-up, pelvis at toe
//! off by case I or II, ballistic flight, support spline, pelvic rotation and list) and phase
//! constraints ([`phase`], §3.3: stance foot heel/toe rotation, flat, heel off by circle–sphere
//! intersection; swing and flight legs; recovery procedures), with the upper body of §3.3.3
//! ([`upper_body`]). The [`Runner`] state machine plans step after step — parameter changes act
//! at the next step, the first step starts from a stand and a stop ends in one — and
//! [`generate_run`] samples it into the shared [`Motion`].
//!
//! ```
//! use gaitfit::generator::running::{generate_run, GenerateOptions, RunAttributes, RunModel};
//! let model = RunModel::published(1.8).unwrap();
//! let attrs = RunAttributes::defaults(1.8);
//! let params = model.natural(12.0 / 3.6, 0.0, &attrs).unwrap();
//! // The paper's numbers (§3.1.1): 12 km/h → sl 1.07 m, sf 187 steps/min, H 0.004 m.
//! assert!((params.step_length - 1.07).abs() < 0.005);
//! assert!((params.step_freq * 60.0 - 187.0).abs() < 0.5);
//! assert!((params.flight_height - 0.004).abs() < 0.0005);
//! let opts = GenerateOptions { seconds: 2.0, fps: 120.0, stop_at_end: false };
//! let (motion, report) = generate_run(&model, params, attrs, None, &opts).unwrap();
//! assert_eq!(motion.len(), 241);
//! assert!(report.steps.len() >= 6);
//! ```
pub mod attributes;
pub mod curves;
pub mod dims;
pub mod equations;
pub mod frame;
pub mod params;
pub mod phase;
pub mod runner;
pub mod schedule;
pub mod state;
pub mod upper_body;

pub use attributes::{Attr, RunAttributes, Strike};
pub use params::{Locks, Param, RunModel, RunParams};
pub use runner::{RunState, Runner, StepRecord};
pub use schedule::Schedule;

use crate::events::Gait;
use crate::generator::motion::{Motion, MotionMetadata};
use crate::generator::GenerateError;

/// How long and how finely to generate.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct GenerateOptions {
    /// Duration, s (frames at 0, 1/fps, …, up to and including `seconds`).
    pub seconds: f64,
    /// Frames per second.
    pub fps: f64,
    /// End in a stand: request a stop early enough for the runner to decelerate and stand still
    /// by `seconds` (the motion is extended if the stop takes longer). A schedule's own `stop`
    /// also ends the run in a stand.
    pub stop_at_end: bool,
}

/// What was generated: the steps with their state-constraint numbers and recoveries.
#[derive(Debug, Clone, PartialEq)]
pub struct RunReport {
    /// Every planned step.
    pub steps: Vec<StepRecord>,
    /// Where the relations' coefficients came from.
    pub relations: String,
    /// The parameters the run started with.
    pub initial: RunParams,
    /// Notes on recoveries and anything the user should know.
    pub notes: Vec<String>,
}

impl RunReport {
    /// The generated running steps (the start and every running step; the final stop is not a
    /// step of the relations) as rows of the trials schema that `gaitfit fit` reads
    /// ([`crate::ingest::trials::write_trials`]): the commanded speed, step length, step
    /// frequency, stance and flight time and eq. 3's H of each step, with `subject` and `trial`
    /// naming them and the figure's body height (and `leg_length_m`, if given).
    pub fn step_rows(
        &self,
        subject: &str,
        trial: &str,
        leg_length_m: Option<f64>,
    ) -> Vec<crate::ingest::trials::StepRow> {
        self.steps
            .iter()
            .filter(|s| s.kind != state::StepKind::Stop)
            .map(|s| crate::ingest::trials::StepRow {
                subject: subject.to_string(),
                gait: Some(Gait::Run),
                side: Some(s.side),
                source: format!("gaitfit generate run (relations: {})", self.relations),
                trial: trial.to_string(),
                time_s: Some(s.start_s),
                speed_m_per_s: Some(s.speed),
                step_length_m: Some(s.step_length),
                step_freq_hz: Some(s.step_freq),
                stance_time_s: Some(s.report.t_stance),
                flight_time_s: Some(s.report.t_flight),
                flight_height_m: Some(s.report.flight_height),
                body_height_m: Some(self.initial.body_height),
                leg_length_m,
                ..Default::default()
            })
            .collect()
    }
}

/// The note for a step where recovery 3 (§3.3.1) inserted knee flexion: which foot, by how much
/// it would have missed its ground clearance, and the cause. In a running step the pelvis sinks
/// from touchdown to mid-support by what the commanded bounciness (stance knee flexion at
/// mid-support) requires, and the swing leg's joint-angle track passes under it. In the start
/// from a stand (no sink) the swing track leaves the standing pose with the foot on the ground.
fn clearance_note(index: usize, r: &state::StepReport) -> String {
    let foot = if r.clearance_hind {
        "hind foot (after toe off)"
    } else {
        "swing foot"
    };
    if r.pelvis_sink <= 0.0 {
        return format!(
            "step {index} (start from a stand): the {foot}'s joint-angle track from the standing \
             pose would have passed {:.0} mm lower than its ground clearance; RUNNER's recovery 3 \
             (§3.3.1) flexed the knee more at {} control point(s)",
            1000.0 * r.clearance_deficit,
            r.clearance_keys
        );
    }
    format!(
        "step {index}: the {foot} would have passed {:.0} mm lower than its ground clearance \
         because the pelvis sinks {:.1} cm from touchdown to mid-support for the commanded \
         bounciness (stance knee {:.0}° at mid-support); RUNNER's recovery 3 (§3.3.1) flexed \
         the knee more at {} control point(s)",
        1000.0 * r.clearance_deficit,
        100.0 * r.pelvis_sink,
        r.bounciness.to_degrees(),
        r.clearance_keys
    )
}

/// Estimated time from a stop request to standing still, s.
fn stop_duration_estimate(params: &RunParams) -> f64 {
    let fr = (params.body_height / 1.8).sqrt();
    let v_stop = runner::STOP_SPEED * fr;
    let n = ((params.speed - v_stop).max(0.0) / (runner::STOP_DECELERATION * fr)).ceil();
    (n + 1.0) / params.step_freq + (0.45 + 0.12 * v_stop) * fr + 0.1
}

/// Generates a run from a stand: `seconds` of motion at `fps` (or, if the schedule has an
/// [`Schedule::end_step`], that many steps), starting with `params` and `attrs` and following
/// `schedule` if given.
pub fn generate_run(
    model: &RunModel,
    params: RunParams,
    attrs: RunAttributes,
    schedule: Option<Schedule>,
    opts: &GenerateOptions,
) -> Result<(Motion, RunReport), GenerateError> {
    if !(opts.seconds.is_finite() && opts.seconds > 0.0 && opts.seconds <= 3600.0) {
        return Err(GenerateError::Parameter {
            name: "seconds".into(),
            value: opts.seconds,
            message: "must be within (0, 3600] s".into(),
        });
    }
    let mut meta = MotionMetadata::new("runner", Some(Gait::Run));
    meta.push("speed_m_per_s", params.speed);
    meta.push("step_length_m", params.step_length);
    meta.push("step_freq_steps_per_min", params.step_freq * 60.0);
    meta.push("flight_height_m", params.flight_height);
    meta.push("flight_time_s", params.flight_time);
    meta.push("level", params.level);
    meta.push("body_height_m", params.body_height);
    meta.push("relations", &model.relations.source);
    for spec in attributes::SPECS.iter() {
        let v = attrs.get(spec.attr);
        let (key, val) = match spec.unit {
            attributes::AttrUnit::Degrees => (format!("{}_deg", spec.name), v.to_degrees()),
            attributes::AttrUnit::Metres => (format!("{}_m", spec.name), v),
            _ => (spec.name.to_string(), v),
        };
        meta.push(key, val);
    }
    let mut motion = Motion::new(model.skeleton.clone(), opts.fps, meta)?;
    // A schedule with a length (`steps` column, `--count`) ends the run after that many steps
    // instead of `seconds`; ending in a stand, the stop decelerates from the step after them.
    let end_step = schedule.as_ref().and_then(|s| s.end_step);
    let mut schedule = schedule;
    if let (Some(k), Some(s)) = (end_step, schedule.as_mut()) {
        if opts.stop_at_end && !s.stops() {
            s.rows.push(schedule::ScheduleRow {
                step: k,
                set: Vec::new(),
                level: None,
                stop: true,
                row: 0,
            });
        }
    }
    let scheduled_stop = schedule.as_ref().is_some_and(|s| s.stops());
    let mut runner = Runner::new(model.clone(), params, attrs, schedule)?;
    let n = (opts.seconds * opts.fps).round() as usize + 1;
    motion.reserve(n);
    let stop_at = if opts.stop_at_end && !scheduled_stop && end_step.is_none() {
        Some(opts.seconds - stop_duration_estimate(&params))
    } else {
        None
    };
    // A stop that never comes to a stand ends 60 s late; a run of so many steps, at 1 h.
    let limit = match end_step {
        Some(_) => (3600.0 * opts.fps) as usize,
        None => n + (60.0 * opts.fps) as usize,
    };
    let mut pose = model.skeleton.rest_pose();
    let mut i = 0usize;
    let mut stopped_at: Option<usize> = None;
    loop {
        let t = i as f64 / opts.fps;
        let past_end = end_step.map_or(i >= n, |k| runner.step_index() >= k);
        let standing = runner.state() == RunState::Stopped;
        if standing && stopped_at.is_none() {
            stopped_at = Some(i);
        }
        // Extend past `seconds` only to finish a stop that ran late, plus a short hold.
        if past_end
            && (stopped_at.is_some_and(|s| i >= s + (0.2 * opts.fps) as usize)
                || !(opts.stop_at_end || scheduled_stop)
                || i > limit)
        {
            break;
        }
        if let Some(ts) = stop_at {
            if t >= ts {
                runner.request_stop();
            }
        }
        let info = runner.pose_at(t, &mut pose)?;
        motion.push_frame(pose, info.contact);
        i += 1;
    }
    let end = motion.duration_s();
    motion.events = runner
        .events()
        .iter()
        .copied()
        .filter(|e| e.time_s <= end + 1e-9)
        .collect();
    let steps: Vec<StepRecord> = runner
        .steps()
        .iter()
        .copied()
        // Without a stop, a run of `end_step` steps ends on the first frame of the next one.
        .filter(|s| s.start_s <= end && (scheduled_stop || end_step.is_none_or(|k| s.index < k)))
        .collect();
    let mut notes = Vec::new();
    let mut ambiguous_noted = false;
    for s in &steps {
        let r = &s.report;
        if r.mid_support_lowered > 0 {
            notes.push(format!(
                "step {}: hip too high, mid-support control point lowered {} time(s)",
                s.index, r.mid_support_lowered
            ));
        }
        if let Some(t_other) = r.other_flight_time {
            if !ambiguous_noted {
                ambiguous_noted = true;
                notes.push(format!(
                    "step {}: flight height H = {:.4} m is reached with a flight of {:.3} s and of \
                     {t_other:.3} s (eq. 3 with eqs. 7–8); {} is used, here and in every later \
                     step with two flight times",
                    s.index,
                    r.flight_height,
                    r.t_flight,
                    state::keyframes::CASE_TWO_RULE
                ));
            }
        }
        if r.clearance_keys > 0 {
            notes.push(clearance_note(s.index, r));
        }
        if r.out_of_reach {
            notes.push(format!(
                "step {}: the stance hip is out of reach somewhere; the foot may lift",
                s.index
            ));
        }
    }
    motion.metadata.notes.extend(notes.iter().cloned());
    Ok((
        motion,
        RunReport {
            steps,
            relations: model.relations.source.clone(),
            initial: params,
            notes,
        },
    ))
}
