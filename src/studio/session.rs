//! One studio request: the page's controls, locks and schedule → resolved parameters → motion.
//!
//! # Locks (the papers' rules)
//! - **RUNNER** (§3.1.1): "If one of the parameters is changed, the other ones are updated using
//!   equations 1, 2, 3, and 4 or 5 … Parameters can be locked." The request's current state is
//!   rebuilt exactly (from the two of v, sl, sf that did not move, and H when it was set), then
//!   [`RunModel::set`] applies the change under the locks — the same rule the CLI and schedules
//!   use (the paper's example: v locked at 12 km/h, sf 187 → 210 gives sl 0.95 m).
//! - **KLAW** (§3): the animator gives one to three of v, sl, sf and eq. 1 completes the rest.
//!   A locked parameter is one the animator has given; the moved one is given too. Nothing
//!   locked: the speed alone is given (the natural walk at that speed).
//! - **Ko–Badler**: the step length is the generalization's parameter and the cadence the
//!   prototype's scaled to the body; v = sl·sf with the same locks.
//!
//! Moving a third parameter while the other two of v, sl, sf are locked over-constrains eq. 1
//! and is refused with the generator's message. A change of body height or expertise level
//! keeps the locked parameters and re-derives the others.
use super::controls::{
    self, generalize_controls, run_attr_to_si, run_controls, walk_controls, Control, ParamValues,
    ATTR_PREFIX, FLIGHT_HEIGHT, HEIGHT, LEVEL, MASS, SPEED, STEP_FREQ, STEP_LENGTH,
};
use super::StudioError;
use crate::events::{Gait, Side};
use crate::generator::generalize::figure::{
    default_step_duration, metadata, walk_motion, StepPlan,
};
use crate::generator::generalize::prototype::Prototype;
use crate::generator::generalize::{default_alpha, Anthropometry as KbBody, Generalizer};
use crate::generator::motion::Motion;
use crate::generator::running::attributes::SPECS;
use crate::generator::running::equations::RunRelations;
use crate::generator::running::{
    generate_run, GenerateOptions, Param, RunAttributes, RunModel, RunParams, Schedule,
};
use crate::generator::skeleton::Skeleton;
use crate::generator::walking::{
    generate_walk, steps_for_duration, ScheduleEntry, WalkAttributes, WalkOptions, WalkParams,
    WalkRelations,
};
use crate::generator::GenerateError;
use crate::ingest::trials::StepRow;
use serde::Deserialize;
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

/// Which generator.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Deserialize, serde::Serialize)]
#[serde(rename_all = "lowercase")]
pub enum GeneratorKind {
    /// RUNNER (1996).
    Run,
    /// KLAW (1989).
    Walk,
    /// Ko & Badler (1993).
    Generalize,
}

impl GeneratorKind {
    /// The name used on the command line (`gaitfit generate <name>`).
    pub fn name(self) -> &'static str {
        match self {
            GeneratorKind::Run => "run",
            GeneratorKind::Walk => "walk",
            GeneratorKind::Generalize => "generalize",
        }
    }
}

/// Which coefficients drive the generator.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Deserialize, serde::Serialize)]
#[serde(rename_all = "lowercase")]
pub enum RelationsChoice {
    /// The papers' coefficients (Ko–Badler: the built-in α, the committed fit).
    #[default]
    Published,
    /// The refitted coefficients in the studio's `--fits` folder.
    Refit,
}

/// One row of the page's schedule: from step `step` on, the given parameters (empty = keep).
#[derive(Debug, Clone, Default, Deserialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct ScheduleRowIn {
    /// Step (0 = the first) from which the row applies.
    pub step: f64,
    /// Speed, km/h.
    #[serde(default)]
    pub speed_km_per_h: Option<f64>,
    /// Step length, m.
    #[serde(default)]
    pub step_length_m: Option<f64>,
    /// Step frequency, steps/min.
    #[serde(default)]
    pub step_freq_steps_per_min: Option<f64>,
    /// Flight height, m (running).
    #[serde(default)]
    pub flight_height_m: Option<f64>,
    /// `run` (default) or `stop`.
    #[serde(default)]
    pub action: Option<String>,
}

/// What the page asks for.
#[derive(Debug, Clone, Deserialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct StudioRequest {
    /// The generator.
    pub generator: GeneratorKind,
    /// Control values in the units the controls show (keys from [`controls`]); missing keys
    /// take their defaults.
    #[serde(default)]
    pub values: BTreeMap<String, f64>,
    /// Locked parameters (keys among [`controls::LOCKABLE`]).
    #[serde(default)]
    pub locks: Vec<String>,
    /// The control the user just moved (its new value is in `values`), if any.
    #[serde(default)]
    pub changed: Option<String>,
    /// RUNNER: the flight time follows from H (H was set), rather than from sf by eqs. 4–5.
    #[serde(default)]
    pub flight_from_height: bool,
    /// Published or refitted relations.
    #[serde(default)]
    pub relations: RelationsChoice,
    /// Duration, s.
    #[serde(default = "default_seconds")]
    pub seconds: f64,
    /// Frames per second (default: the CLI's for the generator).
    #[serde(default)]
    pub fps: Option<f64>,
    /// Start standing (KLAW; RUNNER always starts from a stand; Ko–Badler cannot).
    #[serde(default)]
    pub from_rest: bool,
    /// End standing (RUNNER and KLAW).
    #[serde(default)]
    pub stop: bool,
    /// Per-step changes.
    #[serde(default)]
    pub schedule: Vec<ScheduleRowIn>,
}

fn default_seconds() -> f64 {
    10.0
}

/// Longest motion the studio generates, s (a design limit: the page holds every frame).
pub const MAX_SECONDS: f64 = 120.0;

/// Frame rates the studio generates at, frames/s (a design limit: every frame goes to the page).
pub const FPS_RANGE: (f64, f64) = (10.0, 480.0);

/// Where the studio finds refitted relations.
#[derive(Debug, Clone)]
pub struct Sources {
    /// The `--fits` folder.
    pub fits: PathBuf,
}

/// A generated motion with everything the page shows about it.
#[derive(Debug, Clone)]
pub struct Generated {
    /// The generator.
    pub generator: GeneratorKind,
    /// The motion.
    pub motion: Motion,
    /// Its steps in the trials schema (`gaitfit fit` reads them).
    pub steps: Vec<StepRow>,
    /// The controls with their resolved values and current ranges.
    pub controls: Vec<Control>,
    /// The resolved parameters (first step's).
    pub params: ParamValues,
    /// Locked parameters (as sent, validated).
    pub locks: Vec<String>,
    /// RUNNER: whether H drives the flight time.
    pub flight_from_height: bool,
    /// Notes of the generator (walk–run transition, ramps, recoveries, …).
    pub notes: Vec<String>,
    /// Which coefficients drive the generator.
    pub relations: RelationsChoice,
    /// Where the relations came from.
    pub relations_source: String,
    /// The relations that drive the run (for the plots), when the generator is RUNNER.
    pub run_relations: Option<RunRelations>,
    /// The relations that drive the walk (for the plots), when the generator is KLAW.
    pub walk_relations: Option<WalkRelations>,
}

/// Parses a request body (JSON), with a message that says what is wrong.
pub fn parse_request(body: &[u8]) -> Result<StudioRequest, StudioError> {
    serde_json::from_slice(body)
        .map_err(|e| StudioError::Request(format!("request: not a studio request: {e}")))
}

/// Serves one request: resolve, generate.
pub fn generate(req: &StudioRequest, src: &Sources) -> Result<Generated, StudioError> {
    for (k, v) in &req.values {
        if !v.is_finite() {
            return Err(StudioError::Request(format!(
                "{k}: {v} is not a finite number"
            )));
        }
    }
    for l in &req.locks {
        if !controls::LOCKABLE.contains(&l.as_str()) {
            return Err(StudioError::Request(format!(
                "lock {l:?}: only {} can be locked",
                controls::LOCKABLE.join(", ")
            )));
        }
    }
    if !(req.seconds.is_finite() && req.seconds > 0.0 && req.seconds <= MAX_SECONDS) {
        return Err(StudioError::Request(format!(
            "duration {} s: must be within (0, {MAX_SECONDS}] s",
            req.seconds
        )));
    }
    if let Some(fps) = req.fps {
        if !(fps.is_finite() && (FPS_RANGE.0..=FPS_RANGE.1).contains(&fps)) {
            return Err(StudioError::Request(format!(
                "frame rate {fps}: must be within [{}, {}] frames/s",
                FPS_RANGE.0, FPS_RANGE.1
            )));
        }
    }
    match req.generator {
        GeneratorKind::Run => run(req, src),
        GeneratorKind::Walk => walk(req, src),
        GeneratorKind::Generalize => generalize(req, src),
    }
}

fn locked(req: &StudioRequest, key: &str) -> bool {
    req.locks.iter().any(|l| l == key)
}

fn changed(req: &StudioRequest, key: &str) -> bool {
    req.changed.as_deref() == Some(key)
}

fn param_of(key: &str) -> Option<Param> {
    Some(match key {
        SPEED => Param::Speed,
        STEP_LENGTH => Param::StepLength,
        STEP_FREQ => Param::StepFreq,
        FLIGHT_HEIGHT => Param::FlightHeight,
        _ => return None,
    })
}

/// The value of `key` converted to SI (km/h → m/s, steps/min → steps/s), if sent.
fn si(req: &StudioRequest, key: &str) -> Option<f64> {
    let v = *req.values.get(key)?;
    Some(match key {
        SPEED => v / 3.6,
        STEP_FREQ => v / 60.0,
        _ => v,
    })
}

fn check_attr_keys(req: &StudioRequest, known: &[&str]) -> Result<(), StudioError> {
    let fixed = [
        SPEED,
        STEP_LENGTH,
        STEP_FREQ,
        FLIGHT_HEIGHT,
        LEVEL,
        HEIGHT,
        MASS,
    ];
    for k in req.values.keys() {
        let ok = match k.strip_prefix(ATTR_PREFIX) {
            Some(name) => known.contains(&name),
            None => fixed.contains(&k.as_str()),
        };
        if !ok {
            return Err(StudioError::Request(format!(
                "{k}: not a control of `gaitfit generate {}`",
                req.generator.name()
            )));
        }
    }
    Ok(())
}

// ---------------------------------------------------------------------------------------------
// RUNNER

fn run(req: &StudioRequest, src: &Sources) -> Result<Generated, StudioError> {
    let names: Vec<&str> = SPECS.iter().map(|s| s.name).collect();
    check_attr_keys(req, &names)?;
    let h = req.values.get(HEIGHT).copied().unwrap_or(1.8);
    let relations = match req.relations {
        RelationsChoice::Published => RunRelations::published(),
        RelationsChoice::Refit => RunRelations::from_fits(&src.fits)?,
    };
    let skeleton = Skeleton::from_height(h, controls::run_mass(h))?;
    let model = RunModel::new(skeleton, relations.clone())?;
    let mut attrs = RunAttributes::defaults(h);
    for spec in SPECS.iter() {
        if let Some(v) = req.values.get(&format!("{ATTR_PREFIX}{}", spec.name)) {
            attrs.set(spec.attr, run_attr_to_si(spec.unit, *v))?;
        }
    }
    let level = req.values.get(LEVEL).copied().unwrap_or(0.0);
    let params = run_resolve(req, &model, &attrs, level)?;

    let schedule = run_schedule(&req.schedule)?;
    let opts = GenerateOptions {
        seconds: req.seconds,
        fps: req.fps.unwrap_or(120.0),
        stop_at_end: req.stop,
    };
    let (motion, report) = generate_run(&model, params, attrs.clone(), schedule, &opts)?;
    let mut notes = report.notes.clone();
    if let Some(last) = req.schedule.iter().map(|r| r.step).reduce(f64::max) {
        if last as usize >= report.steps.len() {
            notes.push(format!(
                "schedule: a row at step {last} is past the run's {} steps; raise the duration",
                report.steps.len()
            ));
        }
    }
    let leg = model.skeleton.anthropometry().hip_height_m();
    let steps = report.step_rows(&format!("runner-{h:.2}m"), "studio", Some(leg));
    let pv = ParamValues {
        speed_m_per_s: params.speed,
        step_length_m: params.step_length,
        step_freq_steps_per_min: params.step_freq * 60.0,
        flight_height_m: Some(params.flight_height),
        flight_time_s: Some(params.flight_time),
        level: Some(params.level),
        height_m: h,
        mass_kg: None,
    };
    let h_max = controls::run_flight_height_span(&model, &attrs, level, 12);
    Ok(Generated {
        generator: GeneratorKind::Run,
        motion,
        steps,
        controls: run_controls(&pv, &attrs, &relations, h_max),
        params: pv,
        locks: req.locks.clone(),
        flight_from_height: params.flight_from_height,
        notes,
        relations: req.relations,
        relations_source: match req.relations {
            RelationsChoice::Published => "published (running paper, eqs. 2, 4–5)".into(),
            RelationsChoice::Refit => format!("refit: {}", relations.source),
        },
        run_relations: Some(relations),
        walk_relations: None,
    })
}

/// RUNNER's parameters for the request: the current state rebuilt, then the change applied
/// under the locks (module docs).
fn run_resolve(
    req: &StudioRequest,
    model: &RunModel,
    attrs: &RunAttributes,
    level: f64,
) -> Result<RunParams, StudioError> {
    let moved = req.changed.as_deref().and_then(param_of);
    let (v, sl, sf) = (si(req, SPEED), si(req, STEP_LENGTH), si(req, STEP_FREQ));
    // The state before the change: v and sl from the two of v, sl, sf that did not move.
    let (v0, sl0) = match moved {
        Some(Param::Speed) => (sl.zip(sf).map(|(a, b)| a * b), sl),
        Some(Param::StepLength) => (v, v.zip(sf).map(|(a, b)| a / b)),
        _ => (v, sl),
    };
    let rederive = changed(req, HEIGHT) || changed(req, LEVEL);
    let start_v = v0.unwrap_or(12.0 / 3.6);
    let mut p = model.natural(start_v, level, attrs)?;
    let lock_set = |p: &mut RunParams, on: &[Param]| {
        p.locks = Default::default();
        for q in on {
            p.locks.set(*q, true);
        }
    };
    if rederive || sl0.is_none() {
        // Keep the locked parameters, each held while the next is set (as a schedule row).
        let mut held = vec![Param::Speed];
        for key in [SPEED, STEP_LENGTH, STEP_FREQ, FLIGHT_HEIGHT] {
            if let (true, Some(q), Some(val)) = (locked(req, key), param_of(key), si(req, key)) {
                lock_set(&mut p, &held);
                p = model.set(&p, q, val, attrs)?;
                held.push(q);
            }
        }
    } else if let Some(sl0) = sl0 {
        if (sl0 - p.step_length).abs() > 1e-9 * sl0.abs().max(1.0) {
            lock_set(&mut p, &[Param::Speed]);
            p = model.set(&p, Param::StepLength, sl0, attrs)?;
        }
        if req.flight_from_height && !matches!(moved, Some(Param::FlightHeight)) {
            if let Some(h0) = si(req, FLIGHT_HEIGHT) {
                lock_set(&mut p, &[Param::Speed, Param::StepLength]);
                p = model.set(&p, Param::FlightHeight, h0, attrs)?;
            }
        }
    }
    let mut locks = crate::generator::running::Locks::default();
    for key in controls::LOCKABLE {
        if let (true, Some(q)) = (locked(req, key), param_of(key)) {
            locks.set(q, true);
        }
    }
    p.locks = locks;
    if let Some(q) = moved {
        let key = req.changed.as_deref().unwrap_or_default();
        let val = si(req, key).ok_or_else(|| {
            StudioError::Request(format!("changed {key:?} but sent no value for it"))
        })?;
        p = model.set(&p, q, val, attrs)?;
    }
    p.locks = locks;
    Ok(p)
}

/// The page's schedule as RUNNER's schedule CSV, read by [`Schedule::parse`] so that its checks
/// and messages are the command line's.
fn run_schedule(rows: &[ScheduleRowIn]) -> Result<Option<Schedule>, StudioError> {
    if rows.is_empty() {
        return Ok(None);
    }
    let cell = |x: Option<f64>| x.map(|v| v.to_string()).unwrap_or_default();
    let mut csv = String::from(
        "step,speed_km_per_h,step_length_m,step_freq_steps_per_min,flight_height_m,action\n",
    );
    for (i, r) in rows.iter().enumerate() {
        let step = schedule_step(i, r.step)?;
        let action = action_of(i, r)?;
        csv += &format!(
            "{step},{},{},{},{},{}\n",
            cell(r.speed_km_per_h),
            cell(r.step_length_m),
            cell(r.step_freq_steps_per_min),
            cell(r.flight_height_m),
            if action { "stop" } else { "run" }
        );
    }
    Ok(Some(Schedule::parse(&csv, "schedule")?))
}

fn schedule_step(i: usize, step: f64) -> Result<usize, StudioError> {
    if !(step.is_finite() && step >= 0.0 && step.fract() == 0.0 && step < 1e6) {
        return Err(StudioError::Request(format!(
            "schedule row {}: step {step} is not a whole step number ≥ 0",
            i + 1
        )));
    }
    Ok(step as usize)
}

/// Whether a schedule row stops.
fn action_of(i: usize, r: &ScheduleRowIn) -> Result<bool, StudioError> {
    match r.action.as_deref().map(str::trim) {
        None | Some("") | Some("run") | Some("walk") => Ok(false),
        Some("stop") => Ok(true),
        Some(other) => Err(StudioError::Request(format!(
            "schedule row {}: action {other:?}: use run or stop",
            i + 1
        ))),
    }
}

// ---------------------------------------------------------------------------------------------
// KLAW

/// The given parameters (KLAW's specification): the locked ones and the moved one; nothing
/// locked or moved → the speed.
fn given(req: &StudioRequest) -> Result<WalkParams, StudioError> {
    let keys = [SPEED, STEP_LENGTH, STEP_FREQ];
    let mut g = WalkParams::default();
    let mut n = 0;
    for key in keys {
        if locked(req, key) || changed(req, key) {
            let v = req.values.get(key).copied().ok_or_else(|| {
                StudioError::Request(format!("{key} is locked or changed but has no value"))
            })?;
            n += 1;
            match key {
                SPEED => g.speed_m_per_s = Some(v / 3.6),
                STEP_LENGTH => g.step_length_m = Some(v),
                _ => g.step_freq_steps_per_min = Some(v),
            }
        }
    }
    if n == 3 && keys.iter().any(|k| changed(req, k)) {
        let key = req.changed.as_deref().unwrap_or_default();
        return Err(GenerateError::Parameter {
            name: key.to_string(),
            value: req.values.get(key).copied().unwrap_or(f64::NAN),
            message: "speed, step length and step frequency cannot all be fixed (eq. 1: v = sl·sf); unlock one of the other two".into(),
        }
        .into());
    }
    if n == 0 {
        g.speed_m_per_s = Some(req.values.get(SPEED).copied().unwrap_or(5.0) / 3.6);
    }
    Ok(g)
}

fn walk(req: &StudioRequest, src: &Sources) -> Result<Generated, StudioError> {
    let names: Vec<&str> = crate::generator::walking::ATTRIBUTES
        .iter()
        .map(|s| s.name)
        .collect();
    check_attr_keys(req, &names)?;
    if req.values.contains_key(FLIGHT_HEIGHT) || req.values.contains_key(LEVEL) {
        return Err(StudioError::Request(
            "flight height and level are RUNNER's parameters, not KLAW's".into(),
        ));
    }
    let mut attributes = WalkAttributes::default();
    for name in &names {
        if let Some(v) = req.values.get(&format!("{ATTR_PREFIX}{name}")) {
            attributes.set(name, *v)?;
        }
    }
    let relations = match req.relations {
        RelationsChoice::Published => WalkRelations::published(),
        RelationsChoice::Refit => WalkRelations::from_fits_dir(&src.fits)?,
    };
    // KLAW's own defaults (body, frame rate) where the page sends nothing.
    let klaw = WalkOptions::default();
    let opts = WalkOptions {
        height_m: req.values.get(HEIGHT).copied().unwrap_or(klaw.height_m),
        mass_kg: req.values.get(MASS).copied().unwrap_or(klaw.mass_kg),
        attributes,
        relations: relations.clone(),
        fps: req.fps.unwrap_or(klaw.fps),
        start_from_rest: req.from_rest,
        stop: req.stop
            || req
                .schedule
                .iter()
                .any(|r| r.action.as_deref() == Some("stop")),
    };
    let base = given(req)?;
    let total = steps_for_duration(&base, req.seconds, &opts)?;
    let schedule = walk_schedule(base, total, &req.schedule)?;
    let (motion, report) = generate_walk(&schedule, &opts)?;
    let first = crate::generator::walking::high_level::complete(
        &base,
        opts.height_m,
        &opts.relations,
        &opts.attributes,
    )?;
    let leg = motion.skeleton().anthropometry().hip_height_m();
    let subject = format!("klaw-{:.2}m", opts.height_m);
    let steps = report
        .steps
        .iter()
        .map(|s| StepRow {
            subject: subject.clone(),
            gait: Some(Gait::Walk),
            side: Some(s.stance_side),
            source: format!("gaitfit studio walk (relations: {})", relations_name(req)),
            trial: "studio".into(),
            time_s: Some(s.start_s),
            speed_m_per_s: Some(s.step_length_m * s.step_freq_steps_per_min / 60.0),
            step_length_m: Some(s.step_length_m),
            step_freq_hz: Some(s.step_freq_steps_per_min / 60.0),
            stance_time_s: Some(s.times.stance),
            swing_time_s: Some(s.times.swing),
            double_support_time_s: Some(s.times.double_support),
            double_support_pct_cycle: Some(100.0 * s.times.double_support / s.times.cycle),
            body_height_m: Some(opts.height_m),
            leg_length_m: Some(leg),
            ..Default::default()
        })
        .collect();
    let pv = ParamValues {
        speed_m_per_s: first.speed_m_per_s,
        step_length_m: first.step_length_m,
        step_freq_steps_per_min: first.step_freq_steps_per_min,
        flight_height_m: None,
        flight_time_s: None,
        level: None,
        height_m: opts.height_m,
        mass_kg: Some(opts.mass_kg),
    };
    Ok(Generated {
        generator: GeneratorKind::Walk,
        motion,
        steps,
        controls: walk_controls(&pv, &opts.attributes),
        params: pv,
        locks: req.locks.clone(),
        flight_from_height: false,
        notes: report.notes,
        relations: req.relations,
        relations_source: match req.relations {
            RelationsChoice::Published => {
                "published (walking paper: k = 0.004, d0 = 29.08, d1 = −0.16)".into()
            }
            RelationsChoice::Refit => format!("refit: {}", src.fits.display()),
        },
        run_relations: None,
        walk_relations: Some(relations),
    })
}

fn relations_name(req: &StudioRequest) -> &'static str {
    match req.relations {
        RelationsChoice::Published => "published",
        RelationsChoice::Refit => "refit",
    }
}

/// The walk as KLAW schedule entries: the base parameters up to the first row, then each row's
/// parameters (completed by eq. 1) up to the next; a `stop` row ends the walk there.
fn walk_schedule(
    base: WalkParams,
    total: usize,
    rows: &[ScheduleRowIn],
) -> Result<Vec<ScheduleEntry>, StudioError> {
    let mut out = Vec::new();
    let mut at = 0usize;
    let mut cur = base;
    let mut end = total;
    for (i, r) in rows.iter().enumerate() {
        let step = schedule_step(i, r.step)?;
        if step < at {
            return Err(StudioError::Request(format!(
                "schedule row {}: step {step} comes before the previous row's step {at}; \
                 rows must be in step order",
                i + 1
            )));
        }
        if step >= total {
            return Err(StudioError::Request(format!(
                "schedule row {}: step {step} is past the walk's last step ({} steps in the \
                 duration); raise the duration",
                i + 1,
                total
            )));
        }
        if r.flight_height_m.is_some() {
            return Err(StudioError::Request(format!(
                "schedule row {}: flight height is RUNNER's parameter; a walk has no flight",
                i + 1
            )));
        }
        out.push(ScheduleEntry {
            params: cur,
            steps: step - at,
        });
        at = step;
        if action_of(i, r)? {
            end = step.max(1);
            break;
        }
        let p = WalkParams {
            speed_m_per_s: r.speed_km_per_h.map(|v| v / 3.6),
            step_length_m: r.step_length_m,
            step_freq_steps_per_min: r.step_freq_steps_per_min,
        };
        if p == WalkParams::default() {
            return Err(StudioError::Request(format!(
                "schedule row {}: give a speed, a step length or a step frequency (or stop)",
                i + 1
            )));
        }
        cur = p;
    }
    if end > at {
        out.push(ScheduleEntry {
            params: cur,
            steps: end - at,
        });
    }
    out.retain(|e| e.steps > 0);
    Ok(out)
}

// ---------------------------------------------------------------------------------------------
// Ko–Badler

fn generalize(req: &StudioRequest, src: &Sources) -> Result<Generated, StudioError> {
    check_attr_keys(req, &[])?;
    if req.values.contains_key(FLIGHT_HEIGHT) || req.values.contains_key(LEVEL) {
        return Err(StudioError::Request(
            "flight height and level are RUNNER's parameters, not Ko–Badler's".into(),
        ));
    }
    if req.from_rest || req.stop {
        return Err(StudioError::Request(
            "Ko–Badler generalizes a steady step: it has no start from standing and no stop \
             (use the walk generator)"
                .into(),
        ));
    }
    let h = req.values.get(HEIGHT).copied().unwrap_or(1.75);
    let mass = req.values.get(MASS).copied().unwrap_or(70.0);
    let proto = Prototype::bundled();
    let (alpha, source) = match req.relations {
        RelationsChoice::Published => (default_alpha(), "built-in α (the committed kb-mu fit)"),
        RelationsChoice::Refit => (kb_alpha(&src.fits.join("kb-mu.json"))?, "refit kb-mu.json"),
    };
    let mu = proto.mu(alpha)?;
    let g = Generalizer::new(proto.walk.clone(), mu)?;
    let skeleton = Skeleton::from_height(h, mass)?;
    let body = KbBody::from_figure(skeleton.anthropometry())?;
    let sf_nat = 60.0 / default_step_duration(proto.step_duration_s, &body, &proto.walk);
    let sl_nat = g.prototype().step_length() * body.leg_length() / proto.walk.body().leg_length();

    let get = |k: &str| req.values.get(k).copied();
    let held = |k: &str| locked(req, k) || changed(req, k);
    let n = [SPEED, STEP_LENGTH, STEP_FREQ]
        .iter()
        .filter(|k| held(k))
        .count();
    if n == 3 && req.changed.is_some() {
        let key = req.changed.as_deref().unwrap_or_default();
        return Err(GenerateError::Parameter {
            name: key.to_string(),
            value: get(key).unwrap_or(f64::NAN),
            message: "speed, step length and step frequency cannot all be fixed (v = sl·sf); unlock one of the other two".into(),
        }
        .into());
    }
    let v = if held(SPEED) {
        get(SPEED).map(|v| v / 3.6)
    } else {
        None
    };
    let sl = if held(STEP_LENGTH) {
        get(STEP_LENGTH)
    } else {
        None
    };
    let sf = if held(STEP_FREQ) {
        get(STEP_FREQ)
    } else {
        None
    };
    let (sl, sf) = match (v, sl, sf) {
        (Some(v), Some(sl), _) => (sl, v / sl * 60.0),
        (Some(v), None, Some(sf)) => (v / sf * 60.0, sf),
        (Some(v), None, None) => (v / sf_nat * 60.0, sf_nat),
        (None, Some(sl), Some(sf)) => (sl, sf),
        (None, Some(sl), None) => (sl, sf_nat),
        // The cadence moved alone: the step length stays (no relation ties them here).
        (None, None, Some(sf)) => (get(STEP_LENGTH).unwrap_or(sl_nat), sf),
        (None, None, None) => (get(STEP_LENGTH).unwrap_or(sl_nat), sf_nat),
    };
    check_locomotion(sl, sf, h)?;
    let n_steps = ((req.seconds * sf / 60.0).round() as usize).max(1);
    let plan = generalize_plan(sl, sf, n_steps, &req.schedule, h)?;
    let meta = metadata(&g, h, "bundled data/prototype_winter.json");
    let (motion, report) = walk_motion(
        &g,
        skeleton,
        &plan,
        Side::Right,
        req.fps.unwrap_or(120.0),
        meta,
    )?;
    let leg = motion.skeleton().anthropometry().hip_height_m();
    let mut t = 0.0;
    let steps = plan
        .iter()
        .enumerate()
        .map(|(i, s)| {
            let row = StepRow {
                subject: format!("ko-badler-{h:.2}m"),
                gait: Some(Gait::Walk),
                side: Some(if i % 2 == 0 { Side::Right } else { Side::Left }),
                source: format!("gaitfit studio generalize ({source})"),
                trial: "studio".into(),
                time_s: Some(t),
                speed_m_per_s: Some(s.step_length_m / s.duration_s),
                step_length_m: Some(s.step_length_m),
                step_freq_hz: Some(1.0 / s.duration_s),
                body_height_m: Some(h),
                leg_length_m: Some(leg),
                ..Default::default()
            };
            t += s.duration_s;
            row
        })
        .collect();
    let mut notes = Vec::new();
    if report.unreachable_frames > 0 {
        notes.push(format!(
            "{} frame(s) with a foot out of the leg's reach even with the hip lowered {:.3} m",
            report.unreachable_frames, report.max_hip_drop_m
        ));
    }
    let pv = ParamValues {
        speed_m_per_s: sl * sf / 60.0,
        step_length_m: sl,
        step_freq_steps_per_min: sf,
        flight_height_m: None,
        flight_time_s: None,
        level: None,
        height_m: h,
        mass_kg: Some(mass),
    };
    Ok(Generated {
        generator: GeneratorKind::Generalize,
        motion,
        steps,
        controls: generalize_controls(&pv, sf_nat, sl_nat),
        params: pv,
        locks: req.locks.clone(),
        flight_from_height: false,
        notes,
        relations: req.relations,
        relations_source: source.into(),
        run_relations: None,
        walk_relations: Some(WalkRelations::published()),
    })
}

/// The anatomical limits of a walk (KLAW's default attributes; Ko–Badler has none of its own),
/// with KLAW's messages.
fn check_locomotion(sl: f64, sf: f64, h: f64) -> Result<(), StudioError> {
    let l = crate::generator::walking::Locomotion {
        speed_m_per_s: sl * sf / 60.0,
        step_length_m: sl,
        step_freq_steps_per_min: sf,
    };
    if !(sl.is_finite() && sf.is_finite() && sl > 0.0 && sf > 0.0) {
        return Err(GenerateError::Parameter {
            name: "step_length_m".into(),
            value: sl,
            message: format!("step length {sl} m and frequency {sf} steps/min must be positive"),
        }
        .into());
    }
    crate::generator::walking::high_level::check_limits(
        &l,
        h,
        &WalkRelations::published(),
        &WalkAttributes::default(),
    )?;
    Ok(())
}

fn generalize_plan(
    sl: f64,
    sf: f64,
    n: usize,
    rows: &[ScheduleRowIn],
    h: f64,
) -> Result<Vec<StepPlan>, StudioError> {
    let mut cur = (sl, sf);
    let mut plan = Vec::with_capacity(n);
    let mut next = 0;
    for k in 0..n {
        while let Some(r) = rows.get(next) {
            let step = schedule_step(next, r.step)?;
            if step > k {
                break;
            }
            if action_of(next, r)? {
                return if plan.is_empty() {
                    Err(StudioError::Request(format!(
                        "schedule row {}: a stop at step 0 leaves no step",
                        next + 1
                    )))
                } else {
                    Ok(plan)
                };
            }
            if r.flight_height_m.is_some() {
                return Err(StudioError::Request(format!(
                    "schedule row {}: flight height is RUNNER's parameter; a walk has no flight",
                    next + 1
                )));
            }
            let v = r.speed_km_per_h.map(|v| v / 3.6);
            cur = match (v, r.step_length_m, r.step_freq_steps_per_min) {
                (Some(v), Some(sl), _) => (sl, v / sl * 60.0),
                (Some(v), None, Some(sf)) => (v / sf * 60.0, sf),
                (Some(v), None, None) => (v / cur.1 * 60.0, cur.1),
                (None, Some(sl), Some(sf)) => (sl, sf),
                (None, Some(sl), None) => (sl, cur.1),
                (None, None, Some(sf)) => (cur.0, sf),
                (None, None, None) => {
                    return Err(StudioError::Request(format!(
                    "schedule row {}: give a speed, a step length or a step frequency (or stop)",
                    next + 1
                )))
                }
            };
            check_locomotion(cur.0, cur.1, h)
                .map_err(|e| StudioError::Request(format!("schedule row {}: {e}", next + 1)))?;
            next += 1;
        }
        plan.push(StepPlan {
            step_length_m: cur.0,
            duration_s: 60.0 / cur.1,
        });
    }
    if let Some(r) = rows.get(next) {
        return Err(StudioError::Request(format!(
            "schedule row {}: step {} is past the walk's last step ({n} steps in the duration); \
             raise the duration",
            next + 1,
            r.step
        )));
    }
    Ok(plan)
}

/// α₁…α₄ from a kb-mu fit file (relation `kb-mu`, written by `gaitfit fit`).
fn kb_alpha(path: &Path) -> Result<[f64; 4], StudioError> {
    let rel = crate::relations::load_fit(path).map_err(crate::Error::from)?;
    let mut a = [0.0; 4];
    for (i, slot) in a.iter_mut().enumerate() {
        let name = format!("alpha{}", i + 1);
        let idx = rel
            .card()
            .parameters
            .iter()
            .position(|p| p.name == name)
            .ok_or_else(|| {
                StudioError::Request(format!("{}: no coefficient {name}", path.display()))
            })?;
        *slot = rel.values()[idx];
    }
    Ok(a)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn req(generator: GeneratorKind) -> StudioRequest {
        StudioRequest {
            generator,
            values: BTreeMap::new(),
            locks: vec![],
            changed: None,
            flight_from_height: false,
            relations: RelationsChoice::Published,
            seconds: 3.0,
            fps: Some(60.0),
            from_rest: false,
            stop: false,
            schedule: vec![],
        }
    }

    fn src() -> Sources {
        Sources {
            fits: PathBuf::from("fits"),
        }
    }

    fn value(g: &Generated, key: &str) -> f64 {
        g.controls.iter().find(|c| c.key == key).unwrap().value
    }

    #[test]
    fn runner_locked_speed_reproduces_the_papers_example() {
        // §3.1.1: v locked at 12 km/h, sf raised 187 → 210 steps/min: sl 1.07 → 0.95 m.
        let mut r = req(GeneratorKind::Run);
        let first = generate(&r, &src()).unwrap();
        assert!((value(&first, STEP_LENGTH) - 1.07).abs() < 0.005);
        for c in &first.controls {
            if c.group == "parameter" {
                r.values.insert(c.key.clone(), c.value);
            }
        }
        r.locks = vec![SPEED.into()];
        r.changed = Some(STEP_FREQ.into());
        r.values.insert(STEP_FREQ.into(), 210.0);
        let g = generate(&r, &src()).unwrap();
        assert!((value(&g, SPEED) - 12.0).abs() < 1e-9);
        assert!((value(&g, STEP_LENGTH) - 0.952).abs() < 0.005);
        // Unlocked, the same change follows eq. 2: the speed moves.
        r.locks.clear();
        let g = generate(&r, &src()).unwrap();
        assert!(value(&g, SPEED) > 12.5);
    }

    #[test]
    fn klaw_completes_what_is_not_given_and_refuses_three_locks() {
        let mut r = req(GeneratorKind::Walk);
        r.values.insert(SPEED.into(), 5.0);
        r.values.insert(STEP_LENGTH.into(), 0.5);
        r.values.insert(STEP_FREQ.into(), 166.7);
        r.locks = vec![STEP_LENGTH.into()];
        r.changed = Some(SPEED.into());
        // Fig. 10, middle: v = 5 km/h and sl = 0.50 m given → sf = 166.7 steps/min.
        let g = generate(&r, &src()).unwrap();
        assert!((value(&g, STEP_FREQ) - 166.7).abs() < 0.1);
        r.locks = vec![STEP_LENGTH.into(), STEP_FREQ.into()];
        let e = generate(&r, &src()).unwrap_err().to_string();
        assert!(e.contains("cannot all be fixed"), "{e}");
    }

    #[test]
    fn bad_input_is_said_in_words() {
        let mut r = req(GeneratorKind::Run);
        r.values.insert(SPEED.into(), 90.0);
        r.changed = Some(SPEED.into());
        let e = generate(&r, &src()).unwrap_err().to_string();
        assert!(e.contains("speed") && e.contains("must be within"), "{e}");
        let mut r = req(GeneratorKind::Walk);
        r.values.insert("attr.nonsense".into(), 1.0);
        let e = generate(&r, &src()).unwrap_err().to_string();
        assert!(e.contains("not a control"), "{e}");
        assert!(parse_request(b"{\"generator\": \"fly\"}").is_err());
    }

    #[test]
    fn walk_schedule_splits_the_steps() {
        let base = WalkParams {
            speed_m_per_s: Some(1.0),
            ..Default::default()
        };
        let rows = vec![
            ScheduleRowIn {
                step: 3.0,
                speed_km_per_h: Some(6.0),
                ..Default::default()
            },
            ScheduleRowIn {
                step: 6.0,
                action: Some("stop".into()),
                ..Default::default()
            },
        ];
        let s = walk_schedule(base, 10, &rows).unwrap();
        assert_eq!(s.iter().map(|e| e.steps).collect::<Vec<_>>(), vec![3, 3]);
        assert_eq!(s[1].params.speed_m_per_s, Some(6.0 / 3.6));
        assert!(walk_schedule(base, 4, &rows).is_err());
    }
}
