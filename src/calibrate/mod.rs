//! `gaitfit calibrate`: measured trials → relations → generated gait → the same measurement →
//! residuals, then a per-subject calibration of the generator attributes the residuals identify.
//!
//! For every subject × condition (trial): the events and steps are detected
//! ([`measure::measure`]), walk or run decided from the data ([`measure::gait_from_data`]);
//! the matching generator (RUNNER for runs, KLAW for walks) is driven at the measured speed and
//! the subject's body size ([`drive::drive`]); the generated motion is measured by the same
//! event pipeline; residuals are generated − measured.
//!
//! Two stages: `relations` (the relations of `--fits`, or refitted on the inputs, with zero
//! offsets and the generators' default attributes) and `calibrated` (the attributes of
//! [`drive::RUN_ATTRS`] / [`drive::WALK_ATTRS`], optionally with speed slopes on the relation
//! offsets, found by a trust-region Gauss–Newton (argmin's `TrustRegion`) on the objective of
//! [`solve`]). With `leave_one_speed_out`, a third stage `held-out` predicts each condition
//! from a calibration on the subject's other conditions.
pub mod drive;
pub mod kb;
pub mod measure;
pub mod output;
pub mod solve;

use crate::events::input::{expand_inputs, read_input};
use crate::events::steps::subject_label;
use crate::events::{EventError, Gait};
pub use crate::generator::generalize::compare::Variant;
use crate::ingest::types::Trial;
use crate::ingest::ReadOptions;
use drive::{DriveOptions, Relations};
use measure::Measurement;
use serde::{Deserialize, Serialize};
use std::path::{Path, PathBuf};

/// Errors of `gaitfit calibrate`.
#[derive(Debug, thiserror::Error)]
pub enum CalibrateError {
    /// Event detection or reading failed.
    #[error(transparent)]
    Events(#[from] EventError),
    /// A generator refused its parameters.
    #[error("{subject}: {message}")]
    Generate {
        /// The subject.
        subject: String,
        /// What failed.
        message: String,
    },
    /// Nothing could be measured.
    #[error("no input could be measured: {0}")]
    NoInput(String),
    /// Writing an output failed.
    #[error("{path}: {message}")]
    Write {
        /// The file.
        path: String,
        /// What failed.
        message: String,
    },
}

/// Settings of a calibration.
#[derive(Debug, Clone, PartialEq)]
pub struct CalibrateOptions {
    /// Folder of fitted relations; `None` refits them on the inputs (into `refit_dir`).
    pub fits: Option<PathBuf>,
    /// Where the refitted relations are written when `fits` is `None`.
    pub refit_dir: Option<PathBuf>,
    /// Walk or run for every input, overriding the data.
    pub gait: Option<Gait>,
    /// Generated motions.
    pub drive: DriveOptions,
    /// Trust-region iterations at most (the cap; the solver stops earlier when a convergence
    /// test of [`solve`] is met).
    pub max_iters: u64,
    /// The Ko–Badler variant of the `ko-badler` stage (the paper's drawing, or the subject's
    /// measured angle curves carried in W).
    pub kb_variant: Variant,
    /// Give the relation offsets a speed slope for subjects measured at two or more speeds
    /// ([`drive::AttrModel`]); `false`: one constant offset set per subject.
    pub speed_slopes: bool,
    /// Also calibrate each subject once per condition without it and predict the condition
    /// left out (stage `held-out`).
    pub leave_one_speed_out: bool,
}

impl Default for CalibrateOptions {
    fn default() -> Self {
        CalibrateOptions {
            fits: None,
            refit_dir: None,
            gait: None,
            drive: DriveOptions::default(),
            max_iters: 50,
            kb_variant: Variant::Carried,
            speed_slopes: false,
            leave_one_speed_out: false,
        }
    }
}

/// One measured condition (trial) of a subject.
#[derive(Debug, Clone)]
pub struct Condition {
    /// Trial name.
    pub trial: String,
    /// Source file.
    pub path: String,
    /// The measurement.
    pub measured: Measurement,
    /// The measured step rows (for the refit).
    pub rows: Vec<crate::ingest::trials::StepRow>,
}

impl Condition {
    /// The measured speed (m/s).
    pub fn speed(&self) -> f64 {
        self.measured.quantities.speed_m_per_s
    }
}

/// One subject × gait and its conditions.
#[derive(Debug, Clone)]
pub struct Subject {
    /// Subject id.
    pub name: String,
    /// Walk or run.
    pub gait: Gait,
    /// Body height, m (from the data, or estimated; see `notes`).
    pub body_height_m: f64,
    /// Body mass, kg (0 when unknown).
    pub mass_kg: f64,
    /// The conditions, by speed.
    pub conditions: Vec<Condition>,
    /// What was assumed.
    pub notes: Vec<String>,
}

/// Reads every input, detects events and steps, decides the gait from the data and groups
/// the trials by subject and gait. Inputs that cannot be measured are reported in the second
/// list (file: reason) and skipped.
pub fn load_subjects(
    inputs: &[PathBuf],
    gait: Option<Gait>,
) -> Result<(Vec<Subject>, Vec<String>), CalibrateError> {
    let mut subjects: Vec<Subject> = Vec::new();
    let mut failed = Vec::new();
    let (tables, raw): (Vec<&PathBuf>, Vec<&PathBuf>) = inputs
        .iter()
        .partition(|p| p.is_file() && !crate::events::input::is_raw_input(p));
    for path in tables {
        match crate::ingest::trials::read_trials(path) {
            Ok(t) => add_steps_table(&mut subjects, &mut failed, path, t.to_step_rows(), gait),
            Err(e) => failed.push(format!("{}: {e}", path.display())),
        }
    }
    let raw: Vec<PathBuf> = raw.into_iter().cloned().collect();
    for input in if raw.is_empty() {
        Vec::new()
    } else {
        expand_inputs(&raw)?
    } {
        let label = input.label();
        if input
            .path
            .file_stem()
            .is_some_and(|s| s.to_string_lossy().eq_ignore_ascii_case("static"))
        {
            continue;
        }
        let mut trial = match read_input(&input, &ReadOptions::default()) {
            Ok(t) => t,
            Err(e) => {
                failed.push(labelled(&label, e));
                continue;
            }
        };
        let mut notes = Vec::new();
        add_static_joint_centres(&mut trial, &input.path, &mut notes);
        match measure_trial(&trial, gait) {
            Ok((m, rows)) => {
                let name = subject_label(&trial);
                let (h, hn) = body_height(&trial);
                notes.extend(hn);
                let cond = Condition {
                    trial: trial.name.clone(),
                    path: trial.source.display().to_string(),
                    measured: m,
                    rows,
                };
                let mass = trial.subject.mass_kg.unwrap_or(0.0);
                add_condition(&mut subjects, name, (h, mass), cond, notes);
            }
            Err(e) => failed.push(labelled(&label, e)),
        }
    }
    for s in &mut subjects {
        s.conditions.sort_by(|a, b| a.speed().total_cmp(&b.speed()));
        s.notes.sort();
        s.notes.dedup();
    }
    if subjects.is_empty() {
        return Err(CalibrateError::NoInput(failed.join("; ")));
    }
    Ok((subjects, failed))
}

/// Adds the trials of a steps table (one row per step: `gaitfit events` output or a table of
/// `data/`) as conditions: one per subject × trial, measured by [`measure::measure_rows`]; the
/// gait from `--gait`, else the table's `gait` column (decided from the data when the table
/// was made); the body height from its `body_height_m` (else the leg length, else 1.75 m).
fn add_steps_table(
    subjects: &mut Vec<Subject>,
    failed: &mut Vec<String>,
    path: &Path,
    rows: Vec<crate::ingest::trials::StepRow>,
    gait: Option<Gait>,
) {
    let mut keys: Vec<(String, String)> = Vec::new();
    for r in &rows {
        let k = (r.subject.clone(), r.trial.clone());
        if !keys.contains(&k) {
            keys.push(k);
        }
    }
    for (name, trial) in keys {
        let label = format!("{} ({name}, {trial})", path.display());
        let tr: Vec<_> = rows
            .iter()
            .filter(|r| r.subject == name && r.trial == trial)
            .cloned()
            .collect();
        let (g, evidence) = match gait {
            Some(g) => (g, format!("{g}: given with --gait")),
            None => {
                let runs = tr.iter().filter(|r| r.gait == Some(Gait::Run)).count();
                let walks = tr.iter().filter(|r| r.gait == Some(Gait::Walk)).count();
                if runs + walks == 0 {
                    failed.push(format!("{label}: no gait in the table; give --gait"));
                    continue;
                }
                let g = if runs > walks { Gait::Run } else { Gait::Walk };
                (
                    g,
                    format!("{g}: the steps table's gait column ({runs} run, {walks} walk rows)"),
                )
            }
        };
        let Some(m) = measure::measure_rows(&tr, g, evidence) else {
            failed.push(format!("{label}: no step with a step length and frequency"));
            continue;
        };
        let median = |v: Vec<f64>| -> Option<f64> {
            let mut v: Vec<f64> = v.into_iter().filter(|x| x.is_finite()).collect();
            v.sort_by(f64::total_cmp);
            (!v.is_empty()).then(|| v[v.len() / 2])
        };
        let mut notes = vec![format!(
            "measured from the steps table {} (no per-frame data: no pelvis excursion, no angle curves)",
            path.display()
        )];
        let (h, hn) = body_height_from(
            median(tr.iter().filter_map(|r| r.body_height_m).collect()),
            median(tr.iter().filter_map(|r| r.leg_length_m).collect()),
            "the table",
        );
        notes.extend(hn);
        let cond = Condition {
            trial,
            path: path.display().to_string(),
            measured: m,
            rows: tr,
        };
        add_condition(subjects, name, (h, 0.0), cond, notes);
    }
}

/// Files `cond` (and its notes) under the subject of that name and gait, or starts the subject
/// with `body` = (height m, mass kg; 0 unknown) when it is the first of its conditions.
fn add_condition(
    subjects: &mut Vec<Subject>,
    name: String,
    (body_height_m, mass_kg): (f64, f64),
    cond: Condition,
    notes: Vec<String>,
) {
    let gait = cond.measured.gait;
    match subjects
        .iter_mut()
        .find(|s| s.name == name && s.gait == gait)
    {
        Some(s) => {
            s.conditions.push(cond);
            s.notes.extend(notes);
        }
        None => subjects.push(Subject {
            name,
            gait,
            body_height_m,
            mass_kg,
            conditions: vec![cond],
            notes,
        }),
    }
}

/// `error` prefixed with the input's `label`, unless its message already starts with it (the
/// readers' and the event pipeline's errors name their file).
fn labelled(label: &str, error: impl std::fmt::Display) -> String {
    let msg = error.to_string();
    if msg.starts_with(label) {
        msg
    } else {
        format!("{label}: {msg}")
    }
}

/// Adds joint centres carried from a `static.trc` beside a trial whose markers have only
/// clusters (the Hamner runs), so that the hip/knee/ankle angles can be measured.
fn add_static_joint_centres(trial: &mut Trial, path: &Path, notes: &mut Vec<String>) {
    let st = path.with_file_name("static.trc");
    let Some(markers) = trial.markers.as_mut() else {
        return;
    };
    if markers.index("RKJC").is_some() || !st.is_file() {
        return;
    }
    let opts = ReadOptions {
        companions: false,
        ..Default::default()
    };
    if let Ok(s) = crate::ingest::read_trial(&st, &opts) {
        if let Some(sm) = &s.markers {
            let added = measure::add_joint_centres(markers, sm);
            if !added.is_empty() {
                notes.push(format!(
                    "joint centres {} carried from {} by their segment clusters (Kabsch)",
                    added.join(", "),
                    st.display()
                ));
            }
        }
    }
}

/// Body height from the trial, else from the leg length (Bruderlin & Calvert 1989 Table B-1,
/// thigh + shank = 0.48225 h, with the hip height ≈ leg + 0.039 h ankle height), else 1.75 m.
fn body_height(trial: &Trial) -> (f64, Vec<String>) {
    body_height_from(
        trial.subject.body_height_m,
        trial.subject.leg_length_m,
        "the data",
    )
}

/// The body height from a measured `height` (> 0.5 m), else from the leg length (> 0.3 m,
/// [`crate::events::steps::LEG_LENGTH_PER_BODY_HEIGHT`]), else 1.75 m; with a note naming
/// `source` when it was not measured.
fn body_height_from(height: Option<f64>, leg: Option<f64>, source: &str) -> (f64, Vec<String>) {
    use crate::events::steps::LEG_LENGTH_PER_BODY_HEIGHT as LEG;
    if let Some(h) = height.filter(|h| *h > 0.5) {
        return (h, Vec::new());
    }
    if let Some(l) = leg.filter(|l| *l > 0.3) {
        let h = l / LEG;
        return (
            h,
            vec![format!(
                "body height not in {source}: {h:.3} m from the leg length {l:.3} m (leg ≈ {LEG} h)"
            )],
        );
    }
    (
        1.75,
        vec![format!("body height not in {source}: 1.75 m assumed")],
    )
}

/// Decides the gait (unless given) and measures a measured trial over all its steps.
pub fn measure_trial(
    trial: &Trial,
    gait: Option<Gait>,
) -> Result<(Measurement, Vec<crate::ingest::trials::StepRow>), EventError> {
    let (g, evidence) = match gait {
        Some(g) => (g, format!("{g}: given with --gait")),
        None => measure::gait_from_data(trial)?,
    };
    let opts = measure::event_options(trial, g, None);
    let m = measure::measure(
        trial,
        g,
        evidence,
        &opts,
        (f64::NEG_INFINITY, f64::INFINITY),
    )?;
    let rows = crate::events::steps_from_trial(trial, &opts)
        .map(|t| t.rows)
        .unwrap_or_default();
    Ok((m, rows))
}

/// Measures a generated motion with the same pipeline (gait known, noise-free data: a
/// 0.2·fps marker filter and a 1 mm foot-height tolerance).
pub fn measure_generated(d: &drive::Driven, gait: Gait) -> Result<Measurement, EventError> {
    let trial = d.motion.to_trial("generated");
    let fps = d.motion.fps();
    let opts = measure::event_options(&trial, gait, Some((0.2 * fps, 1e-3)));
    measure::measure(&trial, gait, format!("{gait}: generated"), &opts, d.window)
}

/// The relations to drive the generators with: `--fits DIR`, or refitted on the measured
/// steps (written to `refit_dir`), each relation that cannot be fitted falling back to the
/// published one (with a note).
pub fn relations(
    opts: &CalibrateOptions,
    subjects: &[Subject],
) -> Result<(Relations, Vec<String>), CalibrateError> {
    use crate::generator::running::equations::RunRelations;
    use crate::generator::walking::WalkRelations;
    let gen = |e: crate::generator::GenerateError| CalibrateError::Generate {
        subject: "relations".into(),
        message: e.to_string(),
    };
    if let Some(dir) = &opts.fits {
        let has_run = subjects.iter().any(|s| s.gait == Gait::Run);
        let has_walk = subjects.iter().any(|s| s.gait == Gait::Walk);
        let run = if has_run {
            RunRelations::from_fits(dir).map_err(gen)?
        } else {
            RunRelations::published()
        };
        let walk = if has_walk {
            WalkRelations::from_fits_dir(dir).map_err(gen)?
        } else {
            WalkRelations::published()
        };
        return Ok((
            Relations {
                run,
                walk,
                source: dir.display().to_string(),
            },
            Vec::new(),
        ));
    }
    let mut notes = Vec::new();
    let rows: Vec<_> = subjects
        .iter()
        .flat_map(|s| s.conditions.iter().flat_map(|c| c.rows.iter().cloned()))
        .collect();
    let table = crate::ingest::trials::TrialsTable::from_step_rows("calibrate inputs", &rows);
    let dir = opts
        .refit_dir
        .clone()
        .unwrap_or_else(|| std::env::temp_dir().join("gaitfit-calibrate-fits"));
    std::fs::create_dir_all(&dir).map_err(|e| CalibrateError::Write {
        path: dir.display().to_string(),
        message: e.to_string(),
    })?;
    let rels: Vec<_> = crate::relations::registry()
        .into_iter()
        .filter(|r| r.card().id != "kb-mu")
        .collect();
    let run = crate::fit::pipeline::fit_all(
        &rels,
        std::slice::from_ref(&table),
        &crate::fit::pipeline::FitOptions::default(),
        true,
        |_| {},
    );
    for o in &run.outcomes {
        crate::export::coeffs::write_fit_files(&dir, &o.record).map_err(|e| {
            CalibrateError::Write {
                path: dir.display().to_string(),
                message: e.to_string(),
            }
        })?;
        notes.push(format!("refitted {} on the inputs", o.record.relation));
    }
    for (id, why) in run.failures.iter().chain(&run.skipped) {
        notes.push(format!("{id} not refitted ({why}): published coefficients"));
    }
    let run_rel = RunRelations::from_fits(&dir).unwrap_or_else(|_| RunRelations::published());
    let walk_rel =
        WalkRelations::from_fits_dir(&dir).unwrap_or_else(|_| WalkRelations::published());
    Ok((
        Relations {
            run: run_rel,
            walk: walk_rel,
            source: format!("refitted on the inputs ({})", dir.display()),
        },
        notes,
    ))
}

/// A subject's two stages and its calibration.
#[derive(Debug, Clone)]
pub struct SubjectResult {
    /// The subject.
    pub subject: Subject,
    /// How the parameters give the attributes at a speed.
    pub model: drive::AttrModel,
    /// Stage `relations`: the attributes before calibration and the generated measurements.
    pub before: solve::Stage,
    /// Stage `calibrated`.
    pub after: solve::Stage,
    /// Standard errors of the calibrated parameters (Gauss–Newton covariance), in the order
    /// of [`drive::AttrModel::params`].
    pub se: Vec<Option<f64>>,
    /// How the trust region stopped: the convergence test met, or the iteration cap, or a
    /// failure; its iterations and objective evaluations ([`solve::Termination`]).
    pub termination: solve::Termination,
    /// Stage `ko-badler` (walks with another condition of the subject): each condition
    /// generalized from the subject's walk at the nearest other speed ([`kb`]).
    pub kb: Option<solve::Stage>,
    /// Stage `held-out` (with `--leave-one-speed-out`, subjects with two or more speeds): each
    /// condition generated with the attributes calibrated on the subject's other conditions
    /// ([`solve::leave_one_speed_out`]); `params` empty, since they differ per condition.
    pub held_out: Option<solve::Stage>,
}

/// Everything one `calibrate` run found.
#[derive(Debug, Clone)]
pub struct Calibration {
    /// Per subject.
    pub subjects: Vec<SubjectResult>,
    /// Where the relations came from.
    pub relations_source: String,
    /// Notes of the relations (refit).
    pub relation_notes: Vec<String>,
    /// Inputs that could not be measured.
    pub failed: Vec<String>,
    /// The generated motions' settings.
    pub drive: DriveOptions,
    /// Ko–Badler leave-one-out across the walking subjects (paper, carried, naive scaling).
    pub kb_leave_one_out: Option<kb::KbLeaveOneOut>,
    /// The Ko–Badler variant the `ko-badler` stage generated with.
    pub kb_variant: Variant,
}

/// Calibrates every subject (`progress` is called with each subject's one-line summary).
pub fn calibrate(
    inputs: &[PathBuf],
    opts: &CalibrateOptions,
    mut progress: impl FnMut(usize, usize, &SubjectResult),
) -> Result<Calibration, CalibrateError> {
    let (subjects, failed) = load_subjects(inputs, opts.gait)?;
    let (rel, relation_notes) = relations(opts, &subjects)?;
    let n = subjects.len();
    let mut out = Vec::new();
    for (i, s) in subjects.into_iter().enumerate() {
        let mut r = solve::calibrate_subject(s, &rel, opts)?;
        if opts.leave_one_speed_out {
            r.held_out = solve::leave_one_speed_out(&r.subject, &rel, opts)?;
        }
        r.kb = kb::kb_stage(
            &r.subject,
            opts.drive.fps,
            opts.drive.steps,
            opts.kb_variant,
        );
        progress(i + 1, n, &r);
        out.push(r);
    }
    let kb_leave_one_out = kb::leave_one_out(&out.iter().map(|r| &r.subject).collect::<Vec<_>>());
    Ok(Calibration {
        subjects: out,
        relations_source: rel.source.clone(),
        relation_notes,
        failed,
        drive: opts.drive,
        kb_leave_one_out,
        kb_variant: opts.kb_variant,
    })
}

/// One subject's calibration as stored in `calibrated.json`.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct CalibratedSubject {
    /// Subject id.
    pub subject: String,
    /// walk or run.
    pub gait: Gait,
    /// Body height, m.
    pub body_height_m: f64,
    /// Body mass, kg (0 when unknown).
    pub mass_kg: f64,
    /// Measured speeds, m/s.
    pub speeds_m_per_s: Vec<f64>,
    /// The speed (m/s) at which the attributes' `value`s hold when some have a slope (format
    /// 2; absent in format 1, whose attributes are constant).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub reference_speed_m_per_s: Option<f64>,
    /// The attributes.
    pub attributes: Vec<CalibratedAttr>,
    /// How the calibration's solver stopped (added to format 2 without a new tag: optional,
    /// informational, ignored by readers; absent in files written before it).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub solver: Option<solve::Termination>,
}

/// One calibrated attribute.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct CalibratedAttr {
    /// Name (see [`drive::RUN_ATTRS`], [`drive::WALK_ATTRS`]).
    pub name: String,
    /// Unit.
    pub unit: String,
    /// Before calibration.
    pub before: f64,
    /// After calibration.
    pub value: f64,
    /// Standard error (Gauss–Newton), when identifiable.
    pub se: Option<f64>,
    /// Change of the value per m/s of speed away from the reference speed (format 2; only the
    /// relation offsets of subjects measured at two or more speeds have one):
    /// value(v) = value + slope·(v − v_ref).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub slope_per_m_per_s: Option<f64>,
    /// Standard error of the slope (Gauss–Newton).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub slope_se: Option<f64>,
}

/// `calibrated.json`: what `gaitfit generate run|walk --calibration FILE` reuses.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct CalibratedFile {
    /// Format tag.
    pub format: String,
    /// Where the relations came from (`--fits DIR` or the refit folder).
    pub relations: String,
    /// Per subject.
    pub subjects: Vec<CalibratedSubject>,
}

impl CalibratedFile {
    /// The format tag written: format 2 adds the offsets' speed slopes
    /// (`reference_speed_m_per_s`, `slope_per_m_per_s`, `slope_se`).
    pub const FORMAT: &'static str = "gaitfit-calibration-2";

    /// The formats read: 1 (constant attributes) and 2.
    pub const READ_FORMATS: [&'static str; 2] = ["gaitfit-calibration-1", Self::FORMAT];

    /// Reads a calibrated.json.
    pub fn read(path: &Path) -> Result<CalibratedFile, CalibrateError> {
        let text = std::fs::read_to_string(path).map_err(|e| CalibrateError::Write {
            path: path.display().to_string(),
            message: format!("cannot read: {e}"),
        })?;
        let f: CalibratedFile = serde_json::from_str(&text).map_err(|e| CalibrateError::Write {
            path: path.display().to_string(),
            message: format!("not a calibrated.json: {e}"),
        })?;
        if !Self::READ_FORMATS.contains(&f.format.as_str()) {
            return Err(CalibrateError::Write {
                path: path.display().to_string(),
                message: format!(
                    "format {:?}, expected one of {:?} (written by a newer gaitfit?)",
                    f.format,
                    Self::READ_FORMATS
                ),
            });
        }
        Ok(f)
    }

    /// The entry of `gait` for `subject` (or the only entry of that gait).
    pub fn pick(&self, gait: Gait, subject: Option<&str>) -> Result<&CalibratedSubject, String> {
        let of_gait: Vec<_> = self.subjects.iter().filter(|s| s.gait == gait).collect();
        match subject {
            Some(name) => of_gait
                .iter()
                .find(|s| s.subject == name)
                .copied()
                .ok_or_else(|| format!("no {gait} calibration for subject {name:?}")),
            None if of_gait.len() == 1 => Ok(of_gait[0]),
            None if of_gait.is_empty() => Err(format!("no {gait} calibration in the file")),
            None => Err(format!(
                "{} {gait} calibrations ({}): choose one with --subject",
                of_gait.len(),
                of_gait
                    .iter()
                    .map(|s| s.subject.as_str())
                    .collect::<Vec<_>>()
                    .join(", ")
            )),
        }
    }

    /// The attribute vector of an entry at speed `v` (m/s), in the order of
    /// [`drive::attr_defs`]: each value plus its slope times `v` less the reference speed.
    pub fn attributes_at(s: &CalibratedSubject, v: f64) -> Result<[f64; 3], String> {
        let defs = drive::attr_defs(s.gait);
        let mut out = [0.0; 3];
        for (o, d) in out.iter_mut().zip(defs.iter()) {
            let a = s
                .attributes
                .iter()
                .find(|a| a.name == d.name)
                .ok_or_else(|| format!("attribute {} missing", d.name))?;
            *o = a.value;
            if let Some(b) = a.slope_per_m_per_s {
                let v_ref = s.reference_speed_m_per_s.ok_or_else(|| {
                    format!(
                        "attribute {} has a slope but the subject has no reference_speed_m_per_s",
                        d.name
                    )
                })?;
                *o += b * (v - v_ref);
            }
        }
        Ok(out)
    }
}

/// The one-line summary of a subject: gait, conditions, and the mean |residual| of cadence,
/// step length and flight/double support before → after calibration.
pub fn summary_line(r: &SubjectResult) -> String {
    let s = &r.subject;
    let mean_abs = |st: &solve::Stage, q: usize| {
        let v: Vec<f64> = s
            .conditions
            .iter()
            .zip(&st.generated)
            .filter_map(|(c, g)| {
                let g = g.as_ref().ok()?;
                Some((solve::value(g, q)? - solve::value(&c.measured, q)?).abs())
            })
            .collect();
        if v.is_empty() {
            f64::NAN
        } else {
            v.iter().sum::<f64>() / v.len() as f64
        }
    };
    let (pname, pscale, punit) = match s.gait {
        Gait::Run => ("flight", 1000.0, "ms"),
        Gait::Walk => ("double support", 1.0, "% cycle"),
    };
    let held = r.held_out.as_ref().map_or(String::new(), |h| {
        format!(
            "; held out (calibrated on the other speeds): {:.1} steps/min, {:.1} cm, {:.1} {punit}",
            mean_abs(h, 0),
            100.0 * mean_abs(h, 1),
            pscale * mean_abs(h, 3)
        )
    });
    format!(
        "{} ({}, {} condition(s), {:.2}–{:.2} m/s): |Δcadence| {:.1} → {:.1} steps/min, \
         |Δstep length| {:.1} → {:.1} cm, |Δ{pname}| {:.1} → {:.1} {punit}{held}; {}",
        s.name,
        s.gait,
        s.conditions.len(),
        s.conditions.first().map_or(0.0, |c| c.speed()),
        s.conditions.last().map_or(0.0, |c| c.speed()),
        mean_abs(&r.before, 0),
        mean_abs(&r.after, 0),
        100.0 * mean_abs(&r.before, 1),
        100.0 * mean_abs(&r.after, 1),
        pscale * mean_abs(&r.before, 3),
        pscale * mean_abs(&r.after, 3),
        r.termination.describe(),
    )
}
