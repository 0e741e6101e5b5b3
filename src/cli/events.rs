//! `gaitfit events`: detect gait events in measured files and write per-step tables.
use crate::events::compare::CompareTable;
use crate::events::input::{expand_inputs, read_input, TrialInput};
use crate::events::{
    analyse, steps_from_analysis, EventOptions, EventSource, Gait, MarkerMap, PrimarySource,
    StepTable,
};
use crate::ingest::ReadOptions;
use anyhow::Context;
use std::process::ExitCode;

/// Arguments of `gaitfit events`.
#[derive(Debug, clap::Args)]
#[command(
    after_help = "Inputs: .trc (with X.forces or X_grf.mot beside it), .mot/.sto GRF, \
    .forces, .c3d, WBDS *grf.txt, Winter's table; folders are searched recursively (static \
    trials and companion files skipped); MARKERS+FORCES pairs a marker file with a force file \
    of another name (e.g. motion_capture_run.trc+grf_run.mot).\n\nDefaults: contacts found \
    on the force low-passed at 20 Hz (on at 50 N, off at 20 N), events timed where the \
    unfiltered force crosses 20 N; markers 6 Hz low-pass; Zeni extrema hysteresis 30 % of the signal range; matching tolerance 60 ms."
)]
pub struct Args {
    /// Trial files or folders.
    #[arg(required = true, value_name = "INPUT")]
    pub inputs: Vec<std::path::PathBuf>,
    /// Write the per-step table here (CSV); without it the table goes to standard output
    /// unless --compare or --summary is given.
    #[arg(short, long, value_name = "FILE")]
    pub output: Option<std::path::PathBuf>,
    /// Write one row per event here (CSV: subject, trial, time_s, side, event, method,
    /// source): the heel strikes and toe offs the steps are built from, and the foot phases.
    #[arg(long, value_name = "FILE")]
    pub events_out: Option<std::path::PathBuf>,
    /// Compare the kinematic methods with the force-plate events (`force`) or with the
    /// file's reference events (`reference`): detection F1 and timing error per event type.
    #[arg(long, value_name = "force|reference")]
    pub compare: Option<String>,
    /// Write one check plot per trial into this folder, as SVG and PNG (vertical GRF and
    /// heel/toe traces with the events marked).
    #[arg(long, value_name = "DIR")]
    pub plots: Option<std::path::PathBuf>,
    /// Print a per-trial summary (steps, cadence, step length, stance, double support/flight).
    #[arg(long)]
    pub summary: bool,
    /// Print what the readers and the detection assumed or found, per trial (to stderr).
    #[arg(short, long)]
    pub verbose: bool,
    /// Which events build the steps: auto (force with per-foot plates, else the file's own
    /// events with the plates' in their place where the plates saw them, else the plates if they saw two steps, else the markers' method for the gait),
    /// force, kinematic (markers alone, the method for the trial's gait told from the data:
    /// foot-speed for walks with the tangent heel strike, see --walk-heel-strike, foot-jerk
    /// for runs), foot-speed (walks: Zeni windows refined by
    /// the heel and toe speed over the ground, Bonci et al. 2022), foot-jerk (runs: heel or
    /// metatarsal impact jerk at touchdown, toe speed over the ground at toe off), zeni,
    /// zeni-velocity, foot-height, reference (the file's own events, e.g. a C3D's),
    /// force-then-reference (the plates' events where the plates saw the event — 20 N on the
    /// unfiltered force, the truth there — and the file's events elsewhere; auto's choice for
    /// files with both, see reports/events.md). Where a file has its own events and plates,
    /// their disagreement (file − plates, per kind) is printed on stderr.
    #[arg(long, default_value = "auto", value_name = "SOURCE")]
    pub events: String,
    /// Marker-name preset: auto, gaitfit, opensim, cortex, schreiber, pig, winter.
    #[arg(long, default_value = "auto", value_name = "PRESET")]
    pub markers: String,
    /// Override one marker role, e.g. --marker r_heel=RHEE or --marker pelvis=RASI+LASI
    /// (repeatable; roles: pelvis, {l,r}_{heel,toe,meta,ankle,knee,hip}).
    #[arg(long = "marker", value_name = "ROLE=NAME")]
    pub marker: Vec<String>,
    /// Walk or run (default: from the file, else from the events).
    #[arg(long, value_name = "walk|run")]
    pub gait: Option<String>,
    /// Treadmill belt speed, m/s (default: from the file or its metadata).
    #[arg(long, value_name = "M_PER_S")]
    pub belt_speed: Option<f64>,
    /// Force low-pass cutoff for finding the contacts, Hz.
    #[arg(long, default_value_t = 20.0)]
    pub force_cutoff: f64,
    /// Low-pass cutoff of the force the events are timed on, Hz (default: the unfiltered
    /// force; at least --force-cutoff).
    #[arg(long, value_name = "HZ")]
    pub force_timing_cutoff: Option<f64>,
    /// Contact-on threshold, N: a contact must reach it (equal to --off for a single
    /// threshold).
    #[arg(long, default_value_t = 50.0)]
    pub on: f64,
    /// Contact-off threshold, N: contacts begin and end where the force crosses it, and the
    /// events are timed there on the unfiltered force.
    #[arg(long, default_value_t = 20.0)]
    pub off: f64,
    /// Subtract a linear baseline from drifting force plates instead of failing.
    #[arg(long)]
    pub correct_drift: bool,
    /// Bridge export dropouts: time a toe off after the last unfiltered sample above --off
    /// near the contact's end, so isolated samples an export zeroed in the unloading tail
    /// (WBDS) do not end the contact (longer stance and double support). Default: each contact
    /// is timed on the first run of the unfiltered force above --off lasting 50 ms, 20 N on
    /// the unfiltered force, the guide's truth; a batch whose contacts end at such dropouts
    /// says so on stderr, with what this option would change (reports/events.md).
    #[arg(long)]
    pub bridge_dropouts: bool,
    /// Marker low-pass cutoff, Hz.
    #[arg(long, default_value_t = 6.0)]
    pub marker_cutoff: f64,
    /// Walking heel strike from markers (foot-speed detector): tangent (the tangent at the
    /// steepest descent of the heel's speed over the ground reaches zero: scale-free, recall
    /// 1.000 on the shared walks, reports/events.md; the default of --events kinematic) or
    /// fraction (the heel's speed falls through 0.5 × the walking speed, Bonci et al. 2022;
    /// the default of --events foot-speed and auto).
    #[arg(long, value_name = "RULE")]
    pub walk_heel_strike: Option<String>,
    /// Matching tolerance for --compare, ms.
    #[arg(long, default_value_t = 60.0)]
    pub tolerance_ms: f64,
}

fn options(args: &Args) -> anyhow::Result<(ReadOptions, EventOptions)> {
    let mut read = ReadOptions::default();
    let mut opts = EventOptions::default();
    if let Some(g) = &args.gait {
        let g = Gait::parse(g).with_context(|| format!("--gait {g}: use walk or run"))?;
        opts.gait = Some(g);
        read.gait = Some(g);
    }
    read.belt_speed_m_per_s = args.belt_speed;
    opts.primary = PrimarySource::parse(&args.events).with_context(|| {
        format!(
            "--events {}: use auto, force, kinematic, foot-speed, foot-jerk, zeni, \
             zeni-velocity, foot-height, reference or force-then-reference",
            args.events
        )
    })?;
    if args.markers != "auto" || !args.marker.is_empty() {
        let mut m = if args.markers == "auto" {
            MarkerMap::default()
        } else {
            MarkerMap::preset(&args.markers).with_context(|| {
                format!(
                    "--markers {}: use auto or one of {}",
                    args.markers,
                    crate::events::markers::PRESETS.join(", ")
                )
            })?
        };
        for a in &args.marker {
            m.set(a)?;
        }
        opts.markers = Some(m);
    }
    opts.force.cutoff_hz = args.force_cutoff;
    opts.force.timing_cutoff_hz = args.force_timing_cutoff;
    opts.force.on_n = args.on;
    opts.force.off_n = args.off;
    opts.force.correct_drift = args.correct_drift;
    opts.force.bridge_dropouts = args.bridge_dropouts;
    opts.kinematic.cutoff_hz = args.marker_cutoff;
    if let Some(r) = &args.walk_heel_strike {
        let rule = crate::events::kinematic::WalkHeelStrike::parse(r)
            .with_context(|| format!("--walk-heel-strike {r}: use tangent or fraction"))?;
        opts.kinematic.walk_heel_strike = Some(rule);
    }
    Ok((read, opts))
}

struct TrialResult {
    table: StepTable,
    events: Vec<crate::events::per_event::EventRow>,
    compare: CompareTable,
    notes: Vec<String>,
    label: String,
    /// File event − plate event, s, per event the plates also saw.
    reference_minus_force_s: Vec<(crate::events::EventKind, f64)>,
    /// Contacts ending at an export dropout (see `events::force`): the toe-off shift bridging
    /// would make, s, each.
    dropout_shifts_s: Vec<f64>,
    /// Double support of every step, s, as written and (when the trial has dropouts and they
    /// were not bridged) with `--bridge-dropouts`.
    double_support_s: (Vec<f64>, Vec<f64>),
}

fn process(
    input: &TrialInput,
    read: &ReadOptions,
    opts: &EventOptions,
    args: &Args,
    compare_with: Option<EventSource>,
) -> anyhow::Result<TrialResult> {
    let trial = read_input(input, read)?;
    let an = analyse(&trial, opts)?;
    let table = steps_from_analysis(&trial, &an, opts)?;
    let events = crate::events::per_event::event_rows(&trial, &an);
    let compare = match compare_with {
        Some(src) => an.compare(src, args.tolerance_ms / 1000.0),
        None => CompareTable::default(),
    };
    if let Some(dir) = &args.plots {
        let stem = input
            .path
            .file_stem()
            .map(|s| s.to_string_lossy().into_owned())
            .unwrap_or_else(|| "trial".into());
        let parent = input
            .path
            .parent()
            .and_then(|p| p.file_name())
            .map(|s| s.to_string_lossy().into_owned())
            .unwrap_or_default();
        let name = if parent.is_empty() {
            stem
        } else {
            format!("{parent}_{stem}")
        };
        crate::events::plot::write_svg(&dir.join(format!("{name}.svg")), &an)?;
        crate::events::plot::write_png(&dir.join(format!("{name}.png")), &an)?;
    }
    let double_support = |t: &StepTable| -> Vec<f64> {
        t.rows
            .iter()
            .filter_map(|r| r.double_support_time_s)
            .collect()
    };
    let dropout_shifts_s = an.force.dropout_shifts_s.clone();
    let bridged = if !dropout_shifts_s.is_empty() && !opts.force.bridge_dropouts {
        let mut o = opts.clone();
        o.force.bridge_dropouts = true;
        let b = analyse(&trial, &o)?;
        double_support(&steps_from_analysis(&trial, &b, &o)?)
    } else {
        Vec::new()
    };
    let mut notes = trial.notes.clone();
    notes.extend(an.events.notes.iter().cloned());
    notes.extend(table.notes.iter().cloned());
    let double_support_s = (double_support(&table), bridged);
    Ok(TrialResult {
        table,
        events,
        compare,
        notes,
        label: input.label(),
        reference_minus_force_s: an.events.reference_minus_force_s.clone(),
        double_support_s,
        dropout_shifts_s,
    })
}

fn mean_sd(v: &[f64]) -> String {
    mean_sd_prec(v, 3)
}

/// Mean and sample SD of `v` (SD 0 for one value; `None` when empty).
fn mean_and_sd(v: &[f64]) -> Option<(f64, f64)> {
    if v.is_empty() {
        return None;
    }
    let n = v.len() as f64;
    let m = v.iter().sum::<f64>() / n;
    let sd = if v.len() > 1 {
        (v.iter().map(|x| (x - m).powi(2)).sum::<f64>() / (n - 1.0)).sqrt()
    } else {
        0.0
    };
    Some((m, sd))
}

fn mean_sd_prec(v: &[f64], digits: usize) -> String {
    mean_and_sd(v).map_or_else(
        || "–".into(),
        |(m, sd)| format!("{m:.digits$}±{sd:.digits$}"),
    )
}

fn summary(results: &[TrialResult]) -> String {
    let mut s = format!(
        "{:<44} {:>4} {:>5} {:>13} {:>13} {:>13} {:>13} {:>13} {:>13} {:>13}\n",
        "trial",
        "gait",
        "steps",
        "speed m/s",
        "cadence /min",
        "step len m",
        "stance s",
        "dbl supp s",
        "dbl supp %",
        "flight s"
    );
    for r in results {
        let rows = &r.table.rows;
        let col = |f: &dyn Fn(&crate::ingest::trials::StepRow) -> Option<f64>| -> Vec<f64> {
            rows.iter().filter_map(f).collect()
        };
        let label: String = r
            .label
            .chars()
            .rev()
            .take(44)
            .collect::<Vec<_>>()
            .into_iter()
            .rev()
            .collect();
        s.push_str(&format!(
            "{:<44} {:>4} {:>5} {:>13} {:>13} {:>13} {:>13} {:>13} {:>13} {:>13}\n",
            label,
            rows.first()
                .and_then(|x| x.gait)
                .map(|g| g.to_string())
                .unwrap_or_default(),
            rows.len(),
            mean_sd(&col(&|x| x.speed_m_per_s)),
            mean_sd(&col(&|x| x.step_freq_hz.map(|f| f * 60.0))),
            mean_sd(&col(&|x| x.step_length_m)),
            mean_sd(&col(&|x| x.stance_time_s)),
            mean_sd(&col(&|x| x.double_support_time_s)),
            mean_sd_prec(&col(&|x| x.double_support_pct_cycle), 1),
            mean_sd(&col(&|x| x.flight_time_s)),
        ));
    }
    s
}

/// Prints, on stderr, how the files' own events disagree with the plates where both saw an
/// event (file − plate, mean ± SD per kind over the batch), when any trial had both.
fn print_reference_disagreement(results: &[TrialResult]) {
    use crate::events::EventKind;
    let trials = results
        .iter()
        .filter(|r| !r.reference_minus_force_s.is_empty())
        .count();
    if trials == 0 {
        return;
    }
    let part = |kind: EventKind| -> String {
        let v: Vec<f64> = results
            .iter()
            .flat_map(|r| &r.reference_minus_force_s)
            .filter(|(k, _)| *k == kind)
            .map(|(_, d)| d * 1e3)
            .collect();
        format!("{kind} {} ms (n {})", mean_sd_signed(&v), v.len())
    };
    eprintln!(
        "gaitfit events: the files' own events − the plates' (20 N on the unfiltered force), {} \
         trial(s): {}, {}",
        trials,
        part(EventKind::HeelStrike),
        part(EventKind::ToeOff)
    );
}

/// Prints, on stderr, one warning for the batch when force contacts end at export dropouts
/// and they were not bridged: how many, and what `--bridge-dropouts` would change.
fn print_dropouts(results: &[TrialResult]) {
    let shifts: Vec<f64> = results
        .iter()
        .flat_map(|r| r.dropout_shifts_s.iter().map(|d| d * 1e3))
        .collect();
    let with: Vec<&TrialResult> = results
        .iter()
        .filter(|r| !r.double_support_s.1.is_empty())
        .collect();
    if shifts.is_empty() || with.is_empty() {
        return;
    }
    let mean = |v: &[f64]| v.iter().sum::<f64>() / v.len().max(1) as f64;
    let plain: Vec<f64> = with
        .iter()
        .flat_map(|r| r.double_support_s.0.iter().copied())
        .collect();
    let bridged: Vec<f64> = with
        .iter()
        .flat_map(|r| r.double_support_s.1.iter().copied())
        .collect();
    eprintln!(
        "warning: {} force contact(s) in {} trial(s) end at a sample the export zeroed, the \
         force back above --off within a --force-cutoff period after it (dropouts); they end \
         there (20 N on the unfiltered force). --bridge-dropouts would time their toe offs \
         after the tail: {} ms later each, mean double support {:.3} → {:.3} s ({:+.0} ms) \
         (reports/events.md)",
        shifts.len(),
        with.len(),
        mean_sd_signed(&shifts),
        mean(&plain),
        mean(&bridged),
        (mean(&bridged) - mean(&plain)) * 1e3
    );
}

/// `+m.m ± s.s` of `v` (`–` when empty).
fn mean_sd_signed(v: &[f64]) -> String {
    mean_and_sd(v).map_or_else(|| "–".into(), |(m, sd)| format!("{m:+.1} ± {sd:.1}"))
}

/// Runs `gaitfit events`.
pub fn run(args: &Args) -> anyhow::Result<ExitCode> {
    use indicatif::{ProgressBar, ProgressDrawTarget, ProgressStyle};
    use rayon::prelude::*;
    use std::io::IsTerminal;
    let (read, opts) = options(args)?;
    let compare_with = match args.compare.as_deref() {
        None => None,
        Some("force") => Some(EventSource::Force),
        Some("reference") => Some(EventSource::Reference),
        Some(other) => anyhow::bail!("--compare {other}: use force or reference"),
    };
    let inputs = expand_inputs(&args.inputs)?;
    let bar = ProgressBar::new(inputs.len() as u64);
    if std::io::stderr().is_terminal() {
        bar.set_style(
            ProgressStyle::with_template("{bar:40} {pos}/{len} trials {msg}")
                .unwrap_or_else(|_| ProgressStyle::default_bar()),
        );
    } else {
        bar.set_draw_target(ProgressDrawTarget::hidden());
    }
    let results: Vec<anyhow::Result<TrialResult>> = inputs
        .par_iter()
        .map(|i| {
            let r = process(i, &read, &opts, args, compare_with)
                .with_context(|| format!("while processing {}", i.label()));
            bar.inc(1);
            r
        })
        .collect();
    bar.finish_and_clear();
    // A bad file does not cost the others: the good trials' outputs are written, every failure
    // is named, and the exit status says that something failed.
    let mut ok = Vec::new();
    let mut errors = Vec::new();
    for r in results {
        match r {
            Ok(t) => ok.push(t),
            Err(e) => errors.push(format!("{e:#}")),
        }
    }
    if ok.is_empty() {
        anyhow::bail!(
            "all {} trial(s) failed; nothing was written:\n  {}",
            errors.len(),
            errors.join("\n  ")
        );
    }
    let tables: Vec<StepTable> = ok.iter().map(|r| r.table.clone()).collect();
    let n_rows: usize = tables.iter().map(|t| t.rows.len()).sum();
    match &args.output {
        Some(path) => {
            crate::events::steps::write_csv(path, &tables)?;
            eprintln!(
                "gaitfit events: {n_rows} steps from {} trial(s) → {}",
                ok.len(),
                path.display()
            );
        }
        None if compare_with.is_none() && !args.summary => {
            let stdout = std::io::stdout();
            let mut lock = stdout.lock();
            crate::events::steps::write_csv_to(&mut lock, &tables)?;
        }
        None => {}
    }
    if let Some(path) = &args.events_out {
        let rows: Vec<crate::events::per_event::EventRow> =
            ok.iter().flat_map(|r| r.events.iter().cloned()).collect();
        crate::events::per_event::write_csv(path, &rows)?;
        eprintln!(
            "gaitfit events: {} events from {} trial(s) → {}",
            rows.len(),
            ok.len(),
            path.display()
        );
    }
    if args.summary {
        print!("{}", summary(&ok));
    }
    // Warnings (an estimated body height, a header that over-counts its frames, …) always go
    // to stderr; the other notes with -v.
    for r in &ok {
        for n in &r.notes {
            if args.verbose || n.starts_with("warning:") {
                eprintln!("{}: {n}", r.label);
            }
        }
    }
    print_reference_disagreement(&ok);
    print_dropouts(&ok);
    if compare_with.is_some() {
        let mut all = CompareTable::default();
        for r in &ok {
            all.merge(&r.compare);
        }
        if all.rows.is_empty() {
            println!("no trial had both kinematic events and the requested reference events");
        } else {
            print!("{}", all.render());
        }
    }
    if !errors.is_empty() {
        eprintln!(
            "gaitfit events: {} of {} trial(s) failed (the outputs above hold the other {}):\n  {}",
            errors.len(),
            inputs.len(),
            ok.len(),
            errors.join("\n  ")
        );
        return Ok(ExitCode::FAILURE);
    }
    Ok(ExitCode::SUCCESS)
}
