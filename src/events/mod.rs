//! Gait event detection (heel strike, foot flat, heel off, meta off, toe off) from force plates
//! and from kinematics, and the per-step spatiotemporal tables built from the events.
//!
//! - [`filter`]: zero-phase Butterworth low-pass (forward–backward, scipy's edge handling);
//! - [`force`]: vertical GRF threshold with hysteresis per foot, baseline offset and drift;
//! - [`kinematic`]: Zeni et al. (2008) coordinate method and its velocity variant, and the
//!   walking foot-speed detector seeded by it (Bonci et al. 2022);
//! - [`phases`]: foot flat (FGM), heel off, meta off (MOM), toe off (TOM) from foot markers;
//! - [`steps`]: one row per step in the trials schema, plus flight height (running paper eq. 3),
//!   double support (walking paper §3) and the Ko–Badler μ inputs;
//! - [`compare`]: detection F1 and timing error of one event source against another;
//! - [`per_event`]: one row per event (trial, time, side, event, method) for external tools;
//! - [`plot`]: a per-trial SVG of the vertical GRF and foot-marker traces with the events;
//! - [`markers`]: which marker plays which role, with presets for common marker sets.
//!
//! The entry points are [`detect`] (all events of a trial) and [`steps_from_trial`] (events,
//! then the per-step table).
pub mod compare;
pub mod filter;
pub mod force;
pub mod input;
pub mod kinematic;
pub mod markers;
pub mod per_event;
pub mod phases;
pub mod plot;
pub mod steps;
pub mod synthetic;

pub use crate::gait::{EventKind, EventSource, Gait, GaitEvent, Side};
pub use markers::MarkerMap;
pub use steps::{steps_from_analysis, Analysis, StepExtra, StepTable};

use crate::ingest::types::{Setting, Trial};
use serde::{Deserialize, Serialize};
use thiserror::Error;

/// Errors of the event layer. Every message names the file and, where relevant, the frame and
/// channel, and says what would fix it.
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
    /// A marker needed for detection has a gap that the reader could not fill.
    #[error(
        "{path}: frame {frame} (t = {time_s:.3} s), marker {marker} ({role}): missing for \
         {frames} frame(s); fill the gap, trim the trial, or map the role to another marker \
         with --marker {role}=NAME"
    )]
    MarkerGap {
        /// The trial's source file.
        path: String,
        /// The marker (or the alternative `A+B` in use).
        marker: String,
        /// The role it plays (`r_heel`, `pelvis`, …).
        role: String,
        /// First missing frame (1-based, as in the file).
        frame: usize,
        /// Time of that frame, s.
        time_s: f64,
        /// Length of the gap, frames.
        frames: usize,
    },
    /// A force plate's unloaded level drifts more than the tolerance.
    #[error(
        "{path}: force plate {channel}: the unloaded baseline drifts by {drift_n:.1} N over the \
         trial (from {start_n:.1} N near frame {first_frame} to {end_n:.1} N near frame \
         {last_frame}; tolerance {tolerance_n:.1} N); re-zero the plate, or pass \
         --correct-drift to subtract a linear baseline fitted to the unloaded periods"
    )]
    PlateDrift {
        /// The trial's source file.
        path: String,
        /// The plate (channel) name.
        channel: String,
        /// Drift over the trial, N.
        drift_n: f64,
        /// Baseline at the start, N.
        start_n: f64,
        /// Baseline at the end, N.
        end_n: f64,
        /// First unloaded frame used (1-based).
        first_frame: usize,
        /// Last unloaded frame used (1-based).
        last_frame: usize,
        /// The tolerance, N.
        tolerance_n: f64,
    },
    /// A force plate's signal is unusable (wrong sign, never unloaded, …).
    #[error("{path}: force plate {channel}: {message}")]
    Plate {
        /// The trial's source file.
        path: String,
        /// The plate (channel) name.
        channel: String,
        /// What is wrong and what to do.
        message: String,
    },
    /// Invalid options (cutoff above Nyquist, unknown preset, …).
    #[error("invalid event options: {0}")]
    Options(String),
    /// Reading the input failed.
    #[error(transparent)]
    Ingest(#[from] crate::ingest::IngestError),
    /// Writing an output file failed.
    #[error(transparent)]
    Io(#[from] crate::fsio::FsError),
    /// Writing a CSV or plot failed.
    #[error("{path}: {message}")]
    Write {
        /// The file being written.
        path: String,
        /// What failed.
        message: String,
    },
}

/// Which events the per-step table is built from.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize, Default)]
#[serde(rename_all = "snake_case")]
pub enum PrimarySource {
    /// Force-plate events when every contact of both feet falls on a plate (per-foot plates:
    /// dual-belt treadmill, OpenSim `R_`/`L_` forces); otherwise the file's measured reference
    /// events (C3D EVENT group; not a generator's own events), with the plates' events in
    /// their place where the plates saw them (`force-then-reference`); otherwise the force events if
    /// the plates saw at least two steps
    /// (successive heel strikes of opposite feet, no contact beside the plates in between:
    /// an overground walkway); otherwise, in walking, the foot-speed detector (Zeni windows
    /// refined by the heel and toe speed over the ground, Bonci et al. 2022); otherwise the
    /// Zeni coordinate method; otherwise the file's events whatever their origin.
    #[default]
    Auto,
    /// Force-plate events only.
    Force,
    /// Zeni coordinate method.
    ZeniCoordinate,
    /// Zeni velocity variant.
    ZeniVelocity,
    /// Foot-marker heights seeded by the Zeni stances.
    FootHeight,
    /// Heel and toe speed over the ground in the Zeni windows (walking; Bonci et al. 2022).
    FootSpeed,
    /// Running: heel/metatarsal jerk peak at touchdown and the toe's speed over the ground at
    /// toe off (see [`kinematic::Kinematics::run_foot`]).
    FootJerk,
    /// The markers' method for the trial's gait, told from the data (the Zeni events: at most
    /// heel strikes, is the other foot on the ground or in the air?): `foot-speed` for a walk
    /// (its heel strike by the tangent onset unless [`kinematic::KinematicOptions`]'s
    /// `walk_heel_strike` says otherwise, see [`kinematic::WalkHeelStrike`]), `foot-jerk` for a
    /// run.
    Kinematic,
    /// The events stored in the file (C3D EVENT group).
    Reference,
    /// The force plates' events where the plates saw the event (20 N on the unfiltered force),
    /// the file's events elsewhere (see [`force_then_reference`]); the automatic choice for
    /// files with both.
    ForceThenReference,
}

impl PrimarySource {
    /// Parses `auto|force|kinematic|zeni|zeni-coordinate|zeni-velocity|foot-height|foot-speed|
    /// foot-jerk|reference`.
    pub fn parse(s: &str) -> Option<Self> {
        match s.trim().to_ascii_lowercase().replace('_', "-").as_str() {
            "auto" => Some(Self::Auto),
            "force" => Some(Self::Force),
            "kinematic" | "markers" => Some(Self::Kinematic),
            "zeni" | "zeni-coordinate" | "coordinate" => Some(Self::ZeniCoordinate),
            "zeni-velocity" | "velocity" => Some(Self::ZeniVelocity),
            "foot" | "foot-height" => Some(Self::FootHeight),
            "foot-speed" | "speed" | "bonci" => Some(Self::FootSpeed),
            "foot-jerk" | "jerk" | "run-foot" => Some(Self::FootJerk),
            "reference" | "c3d" => Some(Self::Reference),
            "force-then-reference" | "force+reference" | "plates-then-reference" => {
                Some(Self::ForceThenReference)
            }
            _ => None,
        }
    }
}

/// Every setting of event detection, with stated defaults.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct EventOptions {
    /// Force-plate thresholds and filtering.
    pub force: force::ForceOptions,
    /// Kinematic detection settings.
    pub kinematic: kinematic::KinematicOptions,
    /// Foot-phase settings.
    pub phases: phases::PhaseOptions,
    /// Marker roles; `None` picks the preset that matches the trial best.
    pub markers: Option<MarkerMap>,
    /// Which events build the steps.
    pub primary: PrimarySource,
    /// Walk or run, overriding the trial and the detected gait.
    pub gait: Option<Gait>,
    /// Treadmill or overground, overriding the trial.
    pub setting: Option<Setting>,
}

impl Default for EventOptions {
    fn default() -> Self {
        EventOptions {
            force: force::ForceOptions::default(),
            kinematic: kinematic::KinematicOptions::default(),
            phases: phases::PhaseOptions::default(),
            markers: None,
            primary: PrimarySource::Auto,
            gait: None,
            setting: None,
        }
    }
}

/// All events found in one trial, by source, and what the per-step table uses.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct TrialEvents {
    /// The trial's source file.
    pub path: String,
    /// The trial's name.
    pub trial: String,
    /// Force-plate contacts (one per foot contact and plate; merged across plates per foot).
    pub contacts: Vec<force::Contact>,
    /// Force-plate events (heel strike and toe off).
    pub force: Vec<GaitEvent>,
    /// Whether the force events cover every contact of both feet (per-foot plates).
    pub force_complete: bool,
    /// Zeni coordinate-method events.
    pub zeni_coordinate: Vec<GaitEvent>,
    /// Zeni velocity-variant events.
    pub zeni_velocity: Vec<GaitEvent>,
    /// Initial contact and toe off from the foot-marker heights, seeded by the Zeni stances
    /// (see [`phases::foot_contact_events`]).
    pub foot_contact: Vec<GaitEvent>,
    /// Heel strike and toe off from the heel and toe speed over the ground within the Zeni
    /// windows (walking trials only; see [`kinematic::Kinematics::foot_speed`]).
    pub foot_speed: Vec<GaitEvent>,
    /// Running heel strike and toe off from the foot markers' jerk and speed (running trials
    /// only; see [`kinematic::Kinematics::run_foot`]).
    #[serde(default)]
    pub foot_jerk: Vec<GaitEvent>,
    /// Whether the trial is a walk (from the options, the file, else the Zeni events).
    #[serde(default)]
    pub walking: bool,
    /// Foot-marker phases of the primary stances (foot flat, heel off, meta off, and toe off
    /// from a distinct toe marker).
    pub phases: Vec<GaitEvent>,
    /// Events read from the file (kept, never overwritten).
    pub reference: Vec<GaitEvent>,
    /// The file's measured events with the plates' in place where the plates saw the event
    /// (see [`force_then_reference`]); empty without both.
    #[serde(default)]
    pub force_then_reference: Vec<GaitEvent>,
    /// File event − plate event, s, for every file event the plates also saw (matched within
    /// [`compare::DEFAULT_TOLERANCE_S`], same foot and kind).
    #[serde(default)]
    pub reference_minus_force_s: Vec<(EventKind, f64)>,
    /// The source the steps are built from.
    pub primary: EventSource,
    /// What was assumed or found (axes, marker roles, baseline offsets, dropped events).
    pub notes: Vec<String>,
}

impl TrialEvents {
    /// The events of `source` (empty for a source that was not run).
    pub fn of(&self, source: EventSource) -> &[GaitEvent] {
        match source {
            EventSource::Force => &self.force,
            EventSource::ZeniCoordinate => &self.zeni_coordinate,
            EventSource::ZeniVelocity => &self.zeni_velocity,
            EventSource::FootMarkers => &self.foot_contact,
            EventSource::FootSpeed => &self.foot_speed,
            EventSource::FootJerk => &self.foot_jerk,
            EventSource::Reference => &self.reference,
            EventSource::ForceThenReference => &self.force_then_reference,
            EventSource::Generated => &[],
        }
    }
    /// The heel-strike and toe-off events of the primary source.
    pub fn primary_events(&self) -> &[GaitEvent] {
        self.of(self.primary)
    }
}

/// The trial's source path as text, for error messages.
pub(crate) fn path_of(trial: &Trial) -> String {
    trial.source.display().to_string()
}

/// Detects every event the trial's data allow: force-plate contacts, the two Zeni methods, the
/// foot phases, and keeps the file's reference events; picks the primary source.
pub fn analyse(trial: &Trial, opts: &EventOptions) -> Result<Analysis, EventError> {
    let path = path_of(trial);
    let mut notes = Vec::new();
    let kin = match &trial.markers {
        Some(m) if !m.is_empty() => Some(kinematic::Kinematics::from_trial(
            trial,
            opts.markers.as_ref(),
            &opts.kinematic,
            opts.setting,
        )?),
        _ => None,
    };
    if let Some(k) = &kin {
        notes.extend(k.notes.iter().cloned());
    }
    let fr = force::detect(trial, kin.as_ref(), &opts.force)?;
    notes.extend(fr.notes.iter().cloned());
    let (zc, zv, fc) = match &kin {
        Some(k) => {
            let zc = k.zeni_coordinate(&opts.kinematic);
            let fc = phases::foot_contact_events(k, &zc, &opts.phases);
            (zc, k.zeni_velocity(&opts.kinematic), fc)
        }
        None => (Vec::new(), Vec::new(), Vec::new()),
    };
    // Walk or run: the user's --gait, a reader's data-based decision (a C3D's measured events,
    // a treadmill data set's metadata), else the data here: the plates' events where they saw
    // both kinds, the markers' (Zeni) otherwise. Never the file name (issue 21).
    let walking = match opts.gait.or(trial.gait) {
        Some(g) => g == Gait::Walk,
        None if has_both_kinds(&fr.events) => looks_like_walking(&fr.events),
        None => looks_like_walking(&zc),
    };
    let fs = match &kin {
        Some(k) if walking => {
            let mut ko = opts.kinematic.clone();
            if ko.walk_heel_strike.is_none() && opts.primary == PrimarySource::Kinematic {
                ko.walk_heel_strike = Some(kinematic::WalkHeelStrike::Tangent);
            }
            k.foot_speed(&zc, &ko)
        }
        _ => Vec::new(),
    };
    let fj = match &kin {
        Some(k) if !walking => k.run_foot(&zc, &opts.kinematic),
        _ => Vec::new(),
    };
    let mut ev = TrialEvents {
        path: path.clone(),
        trial: trial.name.clone(),
        contacts: fr.contacts.clone(),
        force: fr.events.clone(),
        force_complete: fr.complete,
        zeni_coordinate: zc,
        zeni_velocity: zv,
        foot_contact: fc,
        foot_speed: fs,
        foot_jerk: fj,
        walking,
        phases: Vec::new(),
        reference: trial.reference_events.clone(),
        force_then_reference: Vec::new(),
        reference_minus_force_s: Vec::new(),
        primary: EventSource::Force,
        notes,
    };
    if trial.markers.is_none() && trial.plates.is_empty() && trial.reference_events.is_empty() {
        return Err(EventError::Missing {
            path,
            what: "markers, force plates and reference events: nothing to detect events from"
                .into(),
        });
    }
    if measured(&ev.reference) && !ev.reference.is_empty() && !ev.force.is_empty() {
        let (merged, diffs) =
            force_then_reference(&ev.force, &ev.reference, compare::DEFAULT_TOLERANCE_S);
        ev.force_then_reference = merged;
        ev.reference_minus_force_s = diffs;
    }
    ev.primary = choose_primary(&ev, opts.primary, &path)?;
    if let Some(k) = &kin {
        ev.phases = phases::detect(k, ev.primary_events(), &opts.phases);
    }
    Ok(Analysis {
        events: ev,
        kinematics: kin,
        force: fr,
    })
}

/// The events of every source found in `trial` (see [`analyse`]).
pub fn detect(trial: &Trial, opts: &EventOptions) -> Result<TrialEvents, EventError> {
    analyse(trial, opts).map(|a| a.events)
}

/// Steps the force events describe: successive heel strikes of opposite feet. `None` when a
/// pair of them encloses a heel strike the markers saw (`kinematic`: a contact beside the
/// plates), since the per-step table would then take a stride and a half for a step.
fn force_steps(ev: &[GaitEvent], kinematic: &[GaitEvent]) -> Option<usize> {
    let heel_strikes = |v: &[GaitEvent]| -> Vec<(f64, Side)> {
        let mut h: Vec<(f64, Side)> = v
            .iter()
            .filter(|e| e.kind == EventKind::HeelStrike)
            .map(|e| (e.time_s, e.side))
            .collect();
        h.sort_by(|a, b| a.0.total_cmp(&b.0));
        h
    };
    let (hs, kin) = (heel_strikes(ev), heel_strikes(kinematic));
    let mut n = 0;
    for w in hs.windows(2).filter(|w| w[0].1 != w[1].1) {
        // 0.1 s: well beyond the kinematic methods' timing error, well below a step.
        if kin.iter().any(|k| k.0 > w[0].0 + 0.1 && k.0 < w[1].0 - 0.1) {
            return None;
        }
        n += 1;
    }
    Some(n)
}

/// Whether the Zeni events describe walking: at most heel strikes the other foot is still on
/// the ground (its last event before is a heel strike: double support) rather than in the air
/// (its last event is a toe off: flight). Used only when neither the options nor the trial
/// say which gait it is.
fn looks_like_walking(zeni: &[GaitEvent]) -> bool {
    let (mut walk, mut run) = (0usize, 0usize);
    for e in zeni.iter().filter(|e| e.kind == EventKind::HeelStrike) {
        let other = zeni
            .iter()
            .filter(|o| o.side != e.side && o.time_s < e.time_s)
            .max_by(|a, b| a.time_s.total_cmp(&b.time_s));
        match other.map(|o| o.kind) {
            Some(EventKind::HeelStrike) => walk += 1,
            Some(EventKind::ToeOff) => run += 1,
            _ => {}
        }
    }
    walk > run
}

/// Whether the file's events were measured (a laboratory's C3D events) rather than written by
/// a generator: a generated motion's own events are its ground truth, and detecting events on
/// it is the point of reading it back (closing the loop), so they do not replace detection.
fn measured(ev: &[GaitEvent]) -> bool {
    ev.iter().all(|e| e.source != EventSource::Generated)
}

/// The file's events with the plates' in their place wherever the plates saw the event: each
/// plate heel strike or toe off replaces the file's event of the same foot and kind nearest to
/// it within `tol_s` (each file event replaced at most once); a plate event with no file
/// partner is added (the plates saw it, the file lacks it). The plates are the truth where
/// they see the event (20 N on the unfiltered vertical force; on Schreiber & Moissenet 2019
/// the files' toe offs are 14 ms late on average, up to 85 ms — reports/events.md); the file's
/// events fill in the contacts beside the plates. Returns the merged events in time order and
/// file − plate, s, per matched pair.
pub fn force_then_reference(
    force: &[GaitEvent],
    reference: &[GaitEvent],
    tol_s: f64,
) -> (Vec<GaitEvent>, Vec<(EventKind, f64)>) {
    let mut out: Vec<GaitEvent> = reference.to_vec();
    let mut taken = vec![false; out.len()];
    let mut diffs = Vec::new();
    for f in force
        .iter()
        .filter(|e| matches!(e.kind, EventKind::HeelStrike | EventKind::ToeOff))
    {
        let best = out
            .iter()
            .enumerate()
            .filter(|(i, r)| {
                !taken[*i]
                    && r.side == f.side
                    && r.kind == f.kind
                    && (r.time_s - f.time_s).abs() <= tol_s
            })
            .min_by(|a, b| {
                (a.1.time_s - f.time_s)
                    .abs()
                    .total_cmp(&(b.1.time_s - f.time_s).abs())
            })
            .map(|(i, _)| i);
        match best {
            Some(i) => {
                diffs.push((f.kind, out[i].time_s - f.time_s));
                out[i] = *f;
                taken[i] = true;
            }
            None => {
                out.push(*f);
                taken.push(true);
            }
        }
    }
    out.sort_by(|a, b| a.time_s.total_cmp(&b.time_s));
    (out, diffs)
}

fn has_both_kinds(ev: &[GaitEvent]) -> bool {
    ev.iter().any(|e| e.kind == EventKind::HeelStrike)
        && ev.iter().any(|e| e.kind == EventKind::ToeOff)
}

fn choose_primary(
    ev: &TrialEvents,
    want: PrimarySource,
    path: &str,
) -> Result<EventSource, EventError> {
    let need = |src: EventSource, what: &str| -> Result<EventSource, EventError> {
        if has_both_kinds(ev.of(src)) {
            Ok(src)
        } else {
            Err(EventError::NoEvents {
                path: path.to_string(),
                reason: format!("{what} found no heel strike and toe off"),
            })
        }
    };
    match want {
        PrimarySource::Force => need(EventSource::Force, "the force plates"),
        PrimarySource::ZeniCoordinate => {
            need(EventSource::ZeniCoordinate, "the Zeni coordinate method")
        }
        PrimarySource::ZeniVelocity => need(EventSource::ZeniVelocity, "the Zeni velocity method"),
        PrimarySource::FootHeight => need(EventSource::FootMarkers, "the foot-marker heights"),
        PrimarySource::FootSpeed => need(
            EventSource::FootSpeed,
            "the foot-speed detector (walking only: pass --gait walk if the trial is a walk)",
        ),
        PrimarySource::FootJerk => need(
            EventSource::FootJerk,
            "the running foot detector (running only: pass --gait run if the trial is a run)",
        ),
        PrimarySource::Kinematic => {
            if ev.walking {
                need(
                    EventSource::FootSpeed,
                    "the walking foot-speed detector (the trial walks, told from the data)",
                )
            } else {
                need(
                    EventSource::FootJerk,
                    "the running foot detector (the trial runs, told from the data)",
                )
            }
        }
        PrimarySource::Reference => need(EventSource::Reference, "the file's reference events"),
        PrimarySource::ForceThenReference => need(
            EventSource::ForceThenReference,
            "the force plates together with the file's measured events",
        ),
        PrimarySource::Auto => {
            // The file's own events come before the Zeni estimate: on the shared overground
            // data the Zeni heel strike precedes the force-plate contact by 30–40 ms (the heel
            // still travels forward in the ground frame after its largest lead on the pelvis),
            // which lengthens stance and double support by as much; the laboratories' events
            // (Schreiber & Moissenet 2019) agree with the plates to a frame (reports/events.md).
            if ev.force_complete && has_both_kinds(&ev.force) {
                Ok(EventSource::Force)
            } else if has_both_kinds(&ev.reference)
                && measured(&ev.reference)
                && has_both_kinds(&ev.force_then_reference)
            {
                // Plates and the file's events both: the plates where they saw the event (the
                // Schreiber files' toe offs are +18 ± 9 ms late against them), the file's
                // events beside the plates (reports/events.md).
                Ok(EventSource::ForceThenReference)
            } else if has_both_kinds(&ev.reference) && measured(&ev.reference) {
                Ok(EventSource::Reference)
            } else if has_both_kinds(&ev.force)
                && force_steps(&ev.force, &ev.zeni_coordinate).is_some_and(|n| n >= 2)
            {
                // Overground plates that saw at least two successive steps (BMClab's walkway):
                // fewer steps than the markers give, but timed by the plates.
                Ok(EventSource::Force)
            } else if has_both_kinds(&ev.foot_speed) {
                // Walking from markers alone: the Zeni windows refined by the foot's own speed
                // over the ground, which removes the Zeni heel-strike bias (reports/events.md).
                Ok(EventSource::FootSpeed)
            } else if has_both_kinds(&ev.foot_jerk) {
                // Running from markers alone: touchdown at the foot's impact jerk, toe off at
                // the toe's speed over the ground (reports/events.md).
                Ok(EventSource::FootJerk)
            } else if has_both_kinds(&ev.zeni_coordinate) {
                Ok(EventSource::ZeniCoordinate)
            } else if has_both_kinds(&ev.reference) {
                Ok(EventSource::Reference)
            } else if has_both_kinds(&ev.force) {
                Ok(EventSource::Force)
            } else {
                Err(EventError::NoEvents {
                    path: path.to_string(),
                    reason: "neither the force plates nor the foot markers show a heel strike \
                             followed by a toe off (a standing trial?)"
                        .into(),
                })
            }
        }
    }
}

/// Detects the events of `trial` and builds its per-step table (see [`steps`]).
pub fn steps_from_trial(trial: &Trial, opts: &EventOptions) -> Result<StepTable, EventError> {
    let an = analyse(trial, opts)?;
    steps_from_analysis(trial, &an, opts)
}

impl Analysis {
    /// Compares the kinematic methods (Zeni coordinate and velocity, foot heights, foot speed) with the
    /// force-plate events (`reference = Force`; then also the file's own events, as
    /// `file_events`) or with the file's reference events (`Reference`), over the time both
    /// cover. Returns an empty table when either side has no events.
    pub fn compare(&self, reference: EventSource, tol_s: f64) -> compare::CompareTable {
        let mut table = compare::CompareTable::default();
        let refs = self.events.of(reference);
        let Some(k) = &self.kinematics else {
            return table;
        };
        if refs.is_empty() || k.time_s.is_empty() {
            return table;
        }
        let (coverage, mut span) = match reference {
            EventSource::Force => (
                if self.events.force_complete {
                    compare::Coverage::Complete
                } else {
                    compare::Coverage::MatchedOnly
                },
                self.force
                    .vertical
                    .iter()
                    .filter(|v| !v.time_s.is_empty())
                    .fold((f64::NEG_INFINITY, f64::INFINITY), |(a, b), v| {
                        (a.max(v.time_s[0]), b.min(v.time_s[v.time_s.len() - 1]))
                    }),
            ),
            _ => (
                compare::Coverage::Window,
                (f64::NEG_INFINITY, f64::INFINITY),
            ),
        };
        // Every reference event inside the marker record is judged, including those at its
        // ends (issue 19: leaving them out overstated recall); the table says how many lie
        // within the tolerance of an end.
        let (k0, k1) = (k.time_s[0], k.time_s[k.time_s.len() - 1]);
        span.0 = span.0.max(k0);
        span.1 = span.1.min(k1);
        let judged: Vec<&GaitEvent> = refs
            .iter()
            .filter(|e| {
                matches!(e.kind, EventKind::HeelStrike | EventKind::ToeOff)
                    && e.time_s >= span.0
                    && e.time_s <= span.1
            })
            .collect();
        table.scored = judged.len();
        table.near_ends = judged
            .iter()
            .filter(|e| e.time_s < k0 + tol_s || e.time_s > k1 - tol_s)
            .count();
        let rname = match reference {
            EventSource::Force => "force",
            _ => "reference",
        };
        for (name, det) in [
            ("zeni_coordinate", &self.events.zeni_coordinate),
            ("zeni_velocity", &self.events.zeni_velocity),
            ("foot_height", &self.events.foot_contact),
            ("foot_speed", &self.events.foot_speed),
            ("foot_jerk", &self.events.foot_jerk),
        ] {
            // The foot-speed detector runs on walks only, the foot-jerk one on runs: no row
            // for the other gait.
            if (name == "foot_speed" || name == "foot_jerk") && det.is_empty() {
                continue;
            }
            let res = compare::compare(det, refs, coverage, span, tol_s);
            table.add(name, rname, &res);
            if reference == EventSource::Force {
                let ds = compare::double_support_errors(det, refs, span, tol_s);
                table.add_double_support(name, rname, &ds);
            }
        }
        // The file's own events against the plates: what justifies building steps from them.
        if reference == EventSource::Force && !self.events.reference.is_empty() {
            let res = compare::compare(&self.events.reference, refs, coverage, span, tol_s);
            table.add("file_events", rname, &res);
            let ds = compare::double_support_errors(&self.events.reference, refs, span, tol_s);
            table.add_double_support("file_events", rname, &ds);
        }
        table
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn hs(t: f64, side: Side, source: EventSource) -> GaitEvent {
        GaitEvent {
            time_s: t,
            side,
            kind: EventKind::HeelStrike,
            source,
        }
    }

    #[test]
    fn force_steps_counts_alternating_strikes_and_refuses_a_missed_contact() {
        use EventSource::{Force, ZeniCoordinate as Z};
        use Side::{Left as L, Right as R};
        let kin = vec![
            hs(0.17, L, Z),
            hs(0.70, R, Z),
            hs(1.26, L, Z),
            hs(1.82, R, Z),
        ];
        let force = vec![hs(0.21, L, Force), hs(0.75, R, Force), hs(1.31, L, Force)];
        assert_eq!(force_steps(&force, &kin), Some(2));
        // The right contact at 0.70 s missed the plates: L 0.21 → L 1.31 is skipped as a
        // same-foot pair, but L 1.31 → R 1.85 is fine, and L 0.21 → R 1.85 would not be.
        let force = vec![hs(0.21, L, Force), hs(1.31, L, Force), hs(1.85, R, Force)];
        assert_eq!(force_steps(&force, &kin), Some(1));
        let force = vec![hs(0.21, L, Force), hs(1.85, R, Force)];
        assert_eq!(force_steps(&force, &kin), None);
    }
}
