//! `gaitfit inspect FILE [-o frames.csv]`: what a reader loaded from a file — rates, markers,
//! force plates, reference events, subject metadata, gaps, axes — for every format gaitfit reads
//! (TRC, C3D, MOT/STO, `.forces`, WBDS GRF text, the Hamner data set's files, Winter's table,
//! gaitfit's per-frame CSV and the motion CSV its generators write, and trials/steps tables).
//!
//! With `-o` the per-frame data are written in gaitfit's per-frame CSV
//! ([`crate::ingest::frame_csv`]), which `gaitfit events` and `gaitfit fit --data` read back:
//! metres and newtons in SI with the shortest decimals that read back to the same `f64`, the
//! detected axes, gait, treadmill speed and subject as `# key = value` settings, and the file's
//! heel-strike/toe-off reference events as `l_contact`/`r_contact` flags (they read back as
//! reference events of source `generated`). Streams sampled at different rates (markers at
//! 150 Hz, plates at 450 Hz) share one time column: the fastest stream's; the slower ones are
//! linearly interpolated at its times, and the file and standard error say so.
use crate::events::input::{expand_inputs, is_raw_input, read_input};
use crate::gait::{EventKind, GaitEvent, Side};
use crate::ingest::types::{ForcePlate, Setting, Trial};
use crate::ingest::{detect_format, gaps, mot, Format, ReadOptions};
use crate::units::Quantity;
use std::fmt::Write as _;
use std::path::{Path, PathBuf};
use std::process::ExitCode;

/// Arguments of `gaitfit inspect`.
#[derive(Debug, clap::Args)]
#[command(
    about = "Print what a reader loaded from a file (rates, markers, plates, events, subject, \
             gaps, axes); -o writes its per-frame data as gaitfit's per-frame CSV",
    after_help = "Inputs: .trc (with X.forces or X_grf.mot beside it), .c3d, .mot/.sto, .forces, \
WBDS *grf.txt, Winter's table, gaitfit's per-frame CSV (and the motion CSV of `gaitfit \
generate`), trials/steps tables (CSV with a subject or gait column); MARKERS+FORCES pairs a \
marker file with a force file of another name.\n\nExamples:\n  \
gaitfit inspect ../shared/data/bmclab/walk1.trc\n  \
gaitfit inspect ../shared/data/bmclab/Gait.c3d -o gait_frames.csv\n  \
gaitfit events gait_frames.csv            # reads the per-frame CSV back"
)]
pub struct Args {
    /// The file to inspect (or MARKERS+FORCES).
    #[arg(value_name = "FILE")]
    pub input: PathBuf,
    /// Write the per-frame data (markers, plates, contact flags) to this CSV.
    #[arg(short = 'o', long = "output", value_name = "FILE")]
    pub output: Option<PathBuf>,
    /// Do not read companion files (X.forces or X_grf.mot beside X.trc, WBDSinfo.csv, the
    /// Hamner data set's static.trc and README).
    #[arg(long)]
    pub no_companions: bool,
    /// List every marker name (default: at most 40).
    #[arg(long)]
    pub all_markers: bool,
}

/// Runs `gaitfit inspect`.
pub fn run(args: &Args) -> anyhow::Result<ExitCode> {
    let p = &args.input;
    let is_csv = p.extension().is_some_and(|e| e.eq_ignore_ascii_case("csv"));
    if is_csv && p.is_file() && !is_raw_input(p) {
        if args.output.is_some() {
            anyhow::bail!(
                "{}: a trials table (one row per step, with a subject or gait column) has no \
                 per-frame data; -o applies to measured files",
                p.display()
            );
        }
        let t = crate::ingest::trials::read_trials(p)?;
        print!("{}", describe_trials(&t));
        return Ok(ExitCode::SUCCESS);
    }
    let inputs = expand_inputs(std::slice::from_ref(p))?;
    let [input] = inputs.as_slice() else {
        anyhow::bail!(
            "{}: inspect reads one file (this names {} trials); give one of them",
            p.display(),
            inputs.len()
        );
    };
    let opts = ReadOptions {
        companions: !args.no_companions,
        ..ReadOptions::default()
    };
    let trial = read_input(input, &opts)?;
    let format = detect_format(&input.path)?;
    let mot_table = if format == Format::Mot {
        Some(mot::read_table(&input.path)?)
    } else {
        None
    };
    print!(
        "{}",
        describe_trial(&trial, format, mot_table.as_ref(), args.all_markers)
    );
    if let Some(out) = &args.output {
        let w = write_frames(&trial, out)?;
        for n in &w.notes {
            eprintln!("gaitfit inspect: {n}");
        }
        println!(
            "wrote {} frames × {} columns at {} Hz to {}",
            w.frames,
            w.columns,
            fmt_g(w.rate_hz),
            out.display()
        );
    }
    Ok(ExitCode::SUCCESS)
}

/// `v` with up to 6 significant digits, no trailing zeros.
fn fmt_g(v: f64) -> String {
    if !v.is_finite() {
        return format!("{v}");
    }
    if v == 0.0 {
        return "0".into();
    }
    let mag = v.abs().log10().floor() as i32;
    let d = (5 - mag).clamp(0, 12) as usize;
    let s = format!("{v:.d$}");
    if s.contains('.') {
        s.trim_end_matches('0').trim_end_matches('.').to_string()
    } else {
        s
    }
}

fn format_name(f: Format) -> &'static str {
    match f {
        Format::Trc => "TRC (markers)",
        Format::Mot => "OpenSim MOT/STO",
        Format::Forces => "Cortex .forces (force plates)",
        Format::TreadmillGrf => "instrumented-treadmill GRF text (WBDS)",
        Format::C3d => "C3D",
        Format::Winter => "Winter's rotoscope table",
        Format::FrameCsv => "gaitfit per-frame CSV",
    }
}

fn span(t: &[f64]) -> String {
    match (t.first(), t.last()) {
        (Some(a), Some(b)) => format!("t = {} … {} s", fmt_g(*a), fmt_g(*b)),
        _ => "no samples".into(),
    }
}

fn axis_name(a: crate::ingest::types::Axis) -> &'static str {
    match a {
        crate::ingest::types::Axis::X => "x",
        crate::ingest::types::Axis::Y => "y",
        crate::ingest::types::Axis::Z => "z",
    }
}

/// The report printed for a measured file.
fn describe_trial(
    trial: &Trial,
    format: Format,
    table: Option<&mot::MotTable>,
    all_markers: bool,
) -> String {
    let mut s = String::new();
    let _ = writeln!(s, "file: {}", trial.source.display());
    let _ = writeln!(s, "format: {}", format_name(format));
    let _ = writeln!(s, "trial: {}", trial.name);
    let sub = &trial.subject;
    let opt =
        |v: Option<f64>, u: &str| v.map_or("—".to_string(), |v| format!("{} {u}", fmt_g(v)));
    let _ = writeln!(
        s,
        "subject: {}; body height {}; leg length {}; mass {}",
        sub.id.as_deref().unwrap_or("—"),
        opt(sub.body_height_m, "m"),
        opt(sub.leg_length_m, "m"),
        opt(sub.mass_kg, "kg")
    );
    for n in &sub.notes {
        let _ = writeln!(s, "  {n}");
    }
    let _ = writeln!(
        s,
        "gait: {}",
        trial
            .gait
            .map_or("not known".to_string(), |g| g.to_string())
    );
    let _ = writeln!(
        s,
        "setting: {}",
        match trial.setting {
            Setting::Treadmill { belt_speed_m_per_s } =>
                format!("treadmill, belt at {} m/s", fmt_g(belt_speed_m_per_s)),
            Setting::Overground => "overground".into(),
            Setting::Unknown => "not known".into(),
        }
    );
    match &trial.frame {
        Some(f) => {
            let _ = writeln!(
                s,
                "axes: vertical +{}, forward {}{} ({})",
                axis_name(f.vertical),
                if f.forward_sign < 0.0 { "-" } else { "+" },
                axis_name(f.forward),
                f.how
            );
        }
        None => {
            let _ = writeln!(s, "axes: not established (see the notes)");
        }
    }
    match &trial.markers {
        Some(m) => {
            let _ = writeln!(
                s,
                "markers: {} at {} Hz, {} frames, {}",
                m.names.len(),
                fmt_g(m.rate_hz),
                m.len(),
                span(&m.time_s)
            );
            let shown = if all_markers {
                m.names.len()
            } else {
                m.names.len().min(40)
            };
            let _ = writeln!(s, "  names: {}", m.names[..shown].join(", "));
            if shown < m.names.len() {
                let _ = writeln!(
                    s,
                    "  … and {} more (--all-markers lists them)",
                    m.names.len() - shown
                );
            }
            let mut missing: Vec<(String, usize, usize, usize)> = Vec::new();
            for (name, traj) in m.names.iter().zip(&m.positions) {
                let g = gaps::find_gaps(traj);
                if !g.is_empty() {
                    let n = g.iter().map(|g| g.len).sum();
                    let longest = g.iter().map(|g| g.len).max().unwrap_or(0);
                    missing.push((name.clone(), n, g.len(), longest));
                }
            }
            if missing.is_empty() {
                let _ = writeln!(
                    s,
                    "  gaps: none left (every marker has every frame; filled gaps are in the notes)"
                );
            } else {
                let _ = writeln!(
                    s,
                    "  gaps left after filling (too long to fill): {} marker(s)",
                    missing.len()
                );
                for (name, n, k, longest) in &missing {
                    let _ = writeln!(
                        s,
                        "    {name}: {n} frame(s) missing in {k} gap(s), longest {longest}"
                    );
                }
            }
        }
        None => {
            let _ = writeln!(s, "markers: none");
        }
    }
    let vertical = trial.frame.as_ref().map(|f| f.vertical.index());
    if trial.plates.is_empty() {
        let _ = writeln!(s, "force plates: none");
    } else {
        let _ = writeln!(s, "force plates: {}", trial.plates.len());
        for p in &trial.plates {
            let loaded = p.cop_m.iter().filter(|c| c[0].is_finite()).count();
            let peak = vertical.map(|k| {
                p.force_n
                    .iter()
                    .map(|f| f[k])
                    .filter(|v| v.is_finite())
                    .fold(f64::NEG_INFINITY, f64::max)
            });
            let _ = writeln!(
                s,
                "  {}: {} Hz, {} samples, {}; foot: {}; peak vertical force {}; centre of \
                 pressure in {} samples; free moment {}",
                p.name,
                fmt_g(p.rate_hz),
                p.force_n.len(),
                span(&p.time_s),
                p.side.map_or("either".to_string(), |x| x.to_string()),
                peak.filter(|v| v.is_finite())
                    .map_or("— (no vertical axis)".into(), |v| format!(
                        "{} N",
                        fmt_g(v)
                    )),
                loaded,
                if p.free_moment_nm.is_empty() {
                    "not given"
                } else {
                    "given"
                }
            );
        }
    }
    if let Some(t) = table {
        let _ = writeln!(
            s,
            "table: {} columns at {} Hz, {} rows, {}; angles {}",
            t.names.len(),
            fmt_g(t.rate_hz),
            t.time_s.len(),
            span(&t.time_s),
            match t.in_degrees {
                Some(true) => "in degrees in the file (radians once read)",
                Some(false) => "in radians",
                None => "in an unstated unit",
            }
        );
        let _ = writeln!(s, "  columns: {}", t.names.join(", "));
    }
    if trial.reference_events.is_empty() {
        let _ = writeln!(s, "reference events: none");
    } else {
        let _ = writeln!(
            s,
            "reference events: {} (kept for comparison, never used in place of detection)",
            trial.reference_events.len()
        );
        for side in [Side::Left, Side::Right] {
            for kind in [
                EventKind::HeelStrike,
                EventKind::FootFlat,
                EventKind::HeelOff,
                EventKind::MetaOff,
                EventKind::ToeOff,
            ] {
                let ev: Vec<&GaitEvent> = trial
                    .reference_events
                    .iter()
                    .filter(|e| e.side == side && e.kind == kind)
                    .collect();
                if ev.is_empty() {
                    continue;
                }
                let times: Vec<String> = ev.iter().take(12).map(|e| fmt_g(e.time_s)).collect();
                let _ = writeln!(
                    s,
                    "  {side} {kind} ×{} (source {}): {}{} s",
                    ev.len(),
                    ev[0].source,
                    times.join(", "),
                    if ev.len() > 12 { ", …" } else { "" }
                );
            }
        }
    }
    if !trial.notes.is_empty() {
        let _ = writeln!(s, "notes:");
        for n in &trial.notes {
            let _ = writeln!(s, "  - {n}");
        }
    }
    s
}

/// The report printed for a trials table.
fn describe_trials(t: &crate::ingest::trials::TrialsTable) -> String {
    let mut s = String::new();
    let _ = writeln!(s, "file: {}", t.path.display());
    let _ = writeln!(s, "format: trials table (one row per step or trial)");
    let _ = writeln!(
        s,
        "sha256: {}",
        t.sha256.get(..16).unwrap_or(t.sha256.as_str())
    );
    let _ = writeln!(s, "rows: {}", t.len());
    let mut per_subject = vec![0usize; t.subjects.len()];
    for &k in &t.subject {
        per_subject[k as usize] += 1;
    }
    let _ = writeln!(s, "subjects: {}", t.subjects.len());
    for (name, n) in t.subjects.iter().zip(&per_subject).take(40) {
        let _ = writeln!(s, "  {name}: {n} rows");
    }
    if t.subjects.len() > 40 {
        let _ = writeln!(s, "  … and {} more", t.subjects.len() - 40);
    }
    let count = |f: &dyn Fn(usize) -> bool| (0..t.len()).filter(|&i| f(i)).count();
    let _ = writeln!(
        s,
        "gait: {} walk, {} run, {} not given",
        count(&|i| t.gait[i] == Some(crate::gait::Gait::Walk)),
        count(&|i| t.gait[i] == Some(crate::gait::Gait::Run)),
        count(&|i| t.gait[i].is_none())
    );
    let _ = writeln!(
        s,
        "side: {} left, {} right, {} not given",
        count(&|i| t.side[i] == Some(Side::Left)),
        count(&|i| t.side[i] == Some(Side::Right)),
        count(&|i| t.side[i].is_none())
    );
    let _ = writeln!(
        s,
        "sources: {}; trials: {}",
        t.sources.len(),
        t.trials.len()
    );
    let _ = writeln!(
        s,
        "columns (given or derived; gaitfit's canonical units): rows with a value, min … max"
    );
    for q in Quantity::ALL {
        let Some(c) = &t.columns[q as usize] else {
            continue;
        };
        let v: Vec<f64> = c.iter().copied().filter(|v| !v.is_nan()).collect();
        let (lo, hi) = v
            .iter()
            .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), &x| {
                (a.min(x), b.max(x))
            });
        let unit = q.dimension().canonical_unit();
        let si = unit.to_si_factor();
        let _ = writeln!(
            s,
            "  {}: {} rows{}",
            q.canonical_header(),
            v.len(),
            if v.is_empty() {
                String::new()
            } else {
                format!(", {} … {}", fmt_g(lo / si), fmt_g(hi / si))
            }
        );
    }
    if !t.ignored_columns.is_empty() {
        let _ = writeln!(
            s,
            "columns not used by gaitfit: {}",
            t.ignored_columns.join(", ")
        );
    }
    let _ = writeln!(s, "flagged rows (used by no fit): {}", t.flagged.len());
    for (row, why) in t.flagged.iter().take(10) {
        let _ = writeln!(s, "  row {row}: {why}");
    }
    if t.flagged.len() > 10 {
        let _ = writeln!(s, "  … and {} more", t.flagged.len() - 10);
    }
    s
}

/// What [`write_frames`] wrote.
#[derive(Debug)]
struct Written {
    frames: usize,
    columns: usize,
    rate_hz: f64,
    notes: Vec<String>,
}

/// A header-safe name: no commas, quotes or white space, never empty.
fn safe_name(name: &str, fallback: String) -> String {
    let s: String = name
        .trim()
        .chars()
        .map(|c| {
            if c == ',' || c == '"' || c == '=' || c.is_whitespace() {
                '_'
            } else {
                c
            }
        })
        .collect();
    if s.is_empty() {
        fallback
    } else {
        s
    }
}

/// The foot the per-frame CSV reader gives a plate of this name (its naming rule).
fn side_of_plate_name(name: &str) -> Option<Side> {
    let l = name.to_ascii_lowercase();
    if l == "r" || l.starts_with("r_") || l.starts_with("right") {
        Some(Side::Right)
    } else if l == "l" || l.starts_with("l_") || l.starts_with("left") {
        Some(Side::Left)
    } else {
        None
    }
}

/// The plate's name in the CSV: header-safe, and carrying its foot by the reader's rule
/// (`r_…`/`l_…`), or not carrying one when it has none.
fn plate_name(p: &ForcePlate, k: usize) -> String {
    let base = safe_name(&p.name, format!("plate{}", k + 1));
    match (p.side, side_of_plate_name(&base)) {
        (a, b) if a == b => base,
        (Some(Side::Right), _) => format!("r_{base}"),
        (Some(Side::Left), _) => format!("l_{base}"),
        (None, _) => format!("plate_{base}"),
    }
}

/// Linear interpolation of samples `(t, v)` at increasing times `at`: `None` outside `t`'s
/// range; an exact sample time gives that sample unchanged.
struct Resampler<'a> {
    t: &'a [f64],
    j: usize,
}

impl<'a> Resampler<'a> {
    fn new(t: &'a [f64]) -> Self {
        Resampler { t, j: 0 }
    }
    /// (index, weight of the next sample) for time `x`, which must not decrease between calls.
    fn locate(&mut self, x: f64) -> Option<(usize, f64)> {
        let t = self.t;
        if t.is_empty() || x < t[0] || x > t[t.len() - 1] {
            return None;
        }
        while self.j + 1 < t.len() && t[self.j + 1] <= x {
            self.j += 1;
        }
        let j = self.j;
        if t[j] == x || j + 1 == t.len() {
            return Some((j, 0.0));
        }
        Some((j, (x - t[j]) / (t[j + 1] - t[j])))
    }
}

fn lerp(a: f64, b: f64, w: f64) -> f64 {
    if w == 0.0 {
        a
    } else {
        a + w * (b - a)
    }
}

/// Writes the trial's per-frame data as gaitfit's per-frame CSV (see the module docs).
fn write_frames(trial: &Trial, path: &Path) -> anyhow::Result<Written> {
    let mut notes = Vec::new();
    // The time base: the fastest stream's times (markers win a tie).
    let mut base: Option<(&[f64], f64, String)> = trial
        .markers
        .as_ref()
        .filter(|m| !m.is_empty())
        .map(|m| (m.time_s.as_slice(), m.rate_hz, "the markers".to_string()));
    for p in &trial.plates {
        if p.time_s.is_empty() {
            continue;
        }
        if base.as_ref().is_none_or(|b| p.rate_hz > b.1 * (1.0 + 1e-9)) {
            base = Some((p.time_s.as_slice(), p.rate_hz, format!("plate {}", p.name)));
        }
    }
    let Some((time, rate, from)) = base else {
        anyhow::bail!(
            "{}: no markers or force plates were loaded: nothing per frame to write",
            trial.source.display()
        );
    };
    let mut comments = vec![format!(
        "# gaitfit inspect: per-frame data of {} (times of {})",
        safe_name(&trial.source.display().to_string(), "input".into()),
        from
    )];
    if let Some(m) = trial.markers.as_ref().filter(|m| m.time_s != time) {
        let n = format!(
            "markers resampled from {} Hz to {} Hz (the times of {from}) by linear interpolation",
            fmt_g(m.rate_hz),
            fmt_g(rate)
        );
        comments.push(format!("# {n}"));
        notes.push(n);
    }
    for p in trial.plates.iter().filter(|p| p.time_s != time) {
        let n = format!(
            "plate {} resampled from {} Hz to {} Hz by linear interpolation (zero force outside \
             its record)",
            p.name,
            fmt_g(p.rate_hz),
            fmt_g(rate)
        );
        comments.push(format!("# {n}"));
        notes.push(n);
    }
    // Settings the reader takes back.
    if let Some(g) = trial.gait {
        comments.push(format!("# gait = {g}"));
    }
    if let Some(f) = &trial.frame {
        comments.push(format!("# vertical = {}", axis_name(f.vertical)));
        comments.push(format!(
            "# forward = {}{}",
            if f.forward_sign < 0.0 { "-" } else { "+" },
            axis_name(f.forward)
        ));
    }
    if let Setting::Treadmill { belt_speed_m_per_s } = trial.setting {
        comments.push(format!("# belt_speed_m_per_s = {belt_speed_m_per_s}"));
    }
    let sub = &trial.subject;
    if let Some(id) = &sub.id {
        comments.push(format!("# subject = {}", safe_name(id, "subject".into())));
    }
    for (k, v) in [
        ("body_height_m", sub.body_height_m),
        ("leg_length_m", sub.leg_length_m),
        ("mass_kg", sub.mass_kg),
    ] {
        if let Some(v) = v.filter(|v| v.is_finite()) {
            comments.push(format!("# {k} = {v}"));
        }
    }
    // Columns.
    let mut header = vec!["time_s".to_string()];
    let mut taken: Vec<String> = Vec::new();
    let mut unique = |name: String| -> String {
        let mut n = name.clone();
        let mut k = 2;
        while taken.iter().any(|t| t.eq_ignore_ascii_case(&n)) {
            n = format!("{name}_{k}");
            k += 1;
        }
        taken.push(n.clone());
        n
    };
    let mut marker_cols: Vec<Vec<Option<[f64; 3]>>> = Vec::new();
    if let Some(m) = &trial.markers {
        for (i, (name, traj)) in m.names.iter().zip(&m.positions).enumerate() {
            let mut n = safe_name(name, format!("marker{}", i + 1));
            // `<name>_cop_x_m` would read as a plate's centre of pressure.
            if n.to_ascii_lowercase().ends_with("_cop") {
                n.push_str("_marker");
            }
            let n = unique(n);
            for ax in ["x", "y", "z"] {
                header.push(format!("{n}_{ax}_m"));
            }
            let mut r = Resampler::new(&m.time_s);
            marker_cols.push(
                time.iter()
                    .map(|&t| {
                        let (j, w) = r.locate(t)?;
                        let a = traj[j];
                        let b = traj.get(j + 1).copied().unwrap_or(a);
                        let v = [
                            lerp(a[0], b[0], w),
                            lerp(a[1], b[1], w),
                            lerp(a[2], b[2], w),
                        ];
                        Some(v)
                    })
                    .collect(),
            );
        }
    }
    struct PlateCols {
        force: Vec<[f64; 3]>,
        cop: Option<Vec<[f64; 3]>>,
        moment: Option<Vec<f64>>,
    }
    let mut plate_cols: Vec<PlateCols> = Vec::new();
    let mut nonfinite = 0usize;
    for (k, p) in trial.plates.iter().enumerate() {
        let n = unique(plate_name(p, k));
        for c in ["fx", "fy", "fz"] {
            header.push(format!("{n}_{c}_n"));
        }
        let has_cop = p.cop_m.iter().any(|c| c.iter().all(|v| v.is_finite()));
        if has_cop {
            for ax in ["x", "y", "z"] {
                header.push(format!("{n}_cop_{ax}_m"));
            }
        }
        let has_moment = p.free_moment_nm.iter().any(|v| v.is_finite());
        if has_moment {
            header.push(format!("{n}_tz_n_m"));
        }
        let mut r = Resampler::new(&p.time_s);
        let mut force = Vec::with_capacity(time.len());
        let mut cop = Vec::with_capacity(time.len());
        let mut moment = Vec::with_capacity(time.len());
        for &t in time {
            match r.locate(t) {
                Some((j, w)) => {
                    let j1 = (j + 1).min(p.time_s.len() - 1);
                    let (a, b) = (p.force_n[j], p.force_n[j1]);
                    let mut f = [
                        lerp(a[0], b[0], w),
                        lerp(a[1], b[1], w),
                        lerp(a[2], b[2], w),
                    ];
                    for v in &mut f {
                        if !v.is_finite() {
                            nonfinite += 1;
                            *v = 0.0;
                        }
                    }
                    force.push(f);
                    let (a, b) = (
                        p.cop_m.get(j).copied().unwrap_or([f64::NAN; 3]),
                        p.cop_m.get(j1).copied().unwrap_or([f64::NAN; 3]),
                    );
                    cop.push([
                        lerp(a[0], b[0], w),
                        lerp(a[1], b[1], w),
                        lerp(a[2], b[2], w),
                    ]);
                    let (a, b) = (
                        p.free_moment_nm.get(j).copied().unwrap_or(0.0),
                        p.free_moment_nm.get(j1).copied().unwrap_or(0.0),
                    );
                    let mut mz = lerp(a, b, w);
                    if !mz.is_finite() && has_moment {
                        nonfinite += 1;
                        mz = 0.0;
                    }
                    moment.push(mz);
                }
                None => {
                    force.push([0.0; 3]);
                    cop.push([f64::NAN; 3]);
                    moment.push(0.0);
                }
            }
        }
        plate_cols.push(PlateCols {
            force,
            cop: has_cop.then_some(cop),
            moment: has_moment.then_some(moment),
        });
    }
    if nonfinite > 0 {
        notes.push(format!(
            "{nonfinite} force or free-moment sample(s) were not numbers: written as 0 (the \
             per-frame CSV needs finite forces)"
        ));
    }
    // Reference heel strikes and toe offs as contact flags.
    let mut contact: Vec<(Side, Vec<bool>)> = Vec::new();
    let kept = |e: &&GaitEvent| matches!(e.kind, EventKind::HeelStrike | EventKind::ToeOff);
    let dropped = trial.reference_events.iter().filter(|e| !kept(e)).count();
    for side in [Side::Left, Side::Right] {
        let mut ev: Vec<&GaitEvent> = trial
            .reference_events
            .iter()
            .filter(kept)
            .filter(|e| e.side == side)
            .collect();
        if ev.is_empty() {
            continue;
        }
        ev.sort_by(|a, b| a.time_s.total_cmp(&b.time_s));
        let mut on = ev[0].kind == EventKind::ToeOff;
        let mut k = 0;
        let mut flags = Vec::with_capacity(time.len());
        let mut changes = 0;
        for &t in time {
            let before = on;
            while k < ev.len() && ev[k].time_s <= t {
                on = ev[k].kind == EventKind::HeelStrike;
                k += 1;
            }
            if on != before && !flags.is_empty() {
                changes += 1;
            }
            flags.push(on);
        }
        if changes < ev.len() {
            notes.push(format!(
                "{side}: {} of {} reference heel strikes/toe offs become contact changes (two \
                 events of one kind in a row, or events outside the frames, have none)",
                changes,
                ev.len()
            ));
        }
        header.push(format!(
            "{}_contact",
            if side == Side::Left { "l" } else { "r" }
        ));
        contact.push((side, flags));
    }
    if !contact.is_empty() {
        notes.push(
            "reference heel strikes and toe offs written as l_contact/r_contact flags: they \
             read back as reference events of source 'generated', at the first frame of each \
             new contact state"
                .into(),
        );
    }
    if dropped > 0 {
        notes.push(format!(
            "{dropped} reference event(s) other than heel strike and toe off are not carried \
             by the per-frame CSV"
        ));
    }
    let columns = header.len();
    let frames = time.len();
    crate::fsio::write_atomic(path, |w| -> anyhow::Result<()> {
        let io = |e: std::io::Error| crate::fsio::FsError::io(path, e);
        let mut line = String::with_capacity(columns * 12);
        for c in &comments {
            writeln!(w, "{c}").map_err(io)?;
        }
        writeln!(w, "{}", header.join(",")).map_err(io)?;
        let num = |s: &mut String, v: f64| {
            s.push(',');
            if v.is_finite() {
                let _ = write!(s, "{v}");
            }
        };
        for (i, &t) in time.iter().enumerate() {
            line.clear();
            let _ = write!(line, "{t}");
            for m in &marker_cols {
                let v = m[i].unwrap_or([f64::NAN; 3]);
                for x in v {
                    num(&mut line, x);
                }
            }
            for p in &plate_cols {
                for x in p.force[i] {
                    num(&mut line, x);
                }
                if let Some(c) = &p.cop {
                    for x in c[i] {
                        num(&mut line, x);
                    }
                }
                if let Some(m) = &p.moment {
                    num(&mut line, m[i]);
                }
            }
            for (_, f) in &contact {
                line.push_str(if f[i] { ",1" } else { ",0" });
            }
            writeln!(w, "{line}").map_err(io)?;
        }
        Ok(())
    })?;
    Ok(Written {
        frames,
        columns,
        rate_hz: rate,
        notes,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn resampler_is_exact_on_samples_and_linear_between() {
        let t = [0.0, 0.1, 0.2];
        let mut r = Resampler::new(&t);
        assert_eq!(r.locate(-0.01), None);
        assert_eq!(r.locate(0.0), Some((0, 0.0)));
        let (j, w) = r.locate(0.15).unwrap();
        assert_eq!(j, 1);
        assert!((w - 0.5).abs() < 1e-12);
        assert_eq!(r.locate(0.2), Some((2, 0.0)));
        assert_eq!(r.locate(0.21), None);
        assert_eq!(lerp(1.0, f64::NAN, 0.0), 1.0);
        assert!(lerp(1.0, f64::NAN, 0.5).is_nan());
    }

    #[test]
    fn plate_names_carry_their_foot_by_the_readers_rule() {
        let p = |name: &str, side| ForcePlate {
            name: name.into(),
            side,
            ..ForcePlate::default()
        };
        assert_eq!(plate_name(&p("belt 1", Some(Side::Right)), 0), "r_belt_1");
        assert_eq!(
            plate_name(&p("L_ground_force", Some(Side::Left)), 0),
            "L_ground_force"
        );
        assert_eq!(plate_name(&p("FP1", None), 0), "FP1");
        assert_eq!(
            plate_name(&p("right walkway", None), 0),
            "plate_right_walkway"
        );
        assert_eq!(plate_name(&p("", None), 2), "plate3");
    }
}
