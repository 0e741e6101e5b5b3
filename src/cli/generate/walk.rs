//! `gaitfit generate walk`: KLAW (Bruderlin & Calvert 1989), a dynamic walk from speed, step
//! length and/or step frequency.
use super::common::{freq_arg, length_arg, speed_arg, Common};
use crate::events::Gait;
use crate::generator::schedule::Schedule;
use crate::generator::skeleton::Skeleton;
use crate::generator::walking::walk_params;
use crate::generator::walking::{
    generate_walk, high_level, steps_for_duration, ScheduleEntry, WalkOptions, WalkParams,
    WalkRelations, WalkReport, ATTRIBUTES,
};
use crate::ingest::trials::StepRow;
use anyhow::{bail, Context};
use std::process::ExitCode;

/// Arguments of `gaitfit generate walk`.
#[derive(Debug, clap::Args)]
#[command(after_long_help = attribute_help())]
pub struct Args {
    /// Forward speed: `5km/h`, `1.4m/s`, `84m/min` (bare: m/s).
    #[arg(long, value_name = "SPEED", value_parser = speed_arg)]
    pub speed: Option<f64>,
    /// Step length: `0.7m`, `70cm` (bare: m).
    #[arg(long = "step-length", value_name = "LENGTH", value_parser = length_arg)]
    pub step_length: Option<f64>,
    /// Step frequency: `110/min`, `1.8Hz` (bare: steps/min).
    #[arg(long = "step-freq", value_name = "FREQ", value_parser = freq_arg)]
    pub step_freq: Option<f64>,
    /// Body height: `1.8`, `180cm`.
    #[arg(long, value_name = "LENGTH", default_value = "1.8", value_parser = length_arg)]
    pub height: f64,
    /// Body mass, kg.
    #[arg(long, default_value_t = 75.0)]
    pub mass: f64,
    /// A locomotion attribute, `name=value` (repeatable; see the list below).
    #[arg(long = "attr", value_name = "NAME=VALUE")]
    pub attrs: Vec<String>,
    /// Folder with refitted relations (`walk-sl-sf.json`, `walk-tds-sf.json`); the published
    /// relations otherwise.
    #[arg(long)]
    pub fits: Option<std::path::PathBuf>,
    /// A subject's calibration (`gaitfit calibrate … --out DIR` writes DIR/calibrated.json):
    /// its offsets in the relations and its calibrated attributes; `--subject` picks the subject
    /// when the file holds several. The offsets are the subject's: give `--height` its body
    /// height.
    #[arg(long, value_name = "FILE")]
    pub calibration: Option<std::path::PathBuf>,
    /// Start standing, feet side by side (the first step starts from rest). Without it the walk
    /// starts steady, recorded from 5 frames before its first heel strike (mid-motion). Without
    /// --stop it ends 5 frames after the trailing toe off that follows its last heel strike.
    #[arg(long = "from-rest")]
    pub from_rest: bool,
    /// End standing: a last half step, then the trailing foot is brought alongside and the body
    /// comes to rest (also `action = stop` on a schedule's last row).
    #[arg(long)]
    pub stop: bool,
    /// The flags shared by every generator.
    #[command(flatten)]
    pub common: Common,
}

fn attribute_help() -> String {
    let mut s = String::from("Locomotion attributes (--attr name=value):\n");
    for a in ATTRIBUTES {
        s += &format!(
            "  {:28} default {:>8} {:10} {}\n",
            a.name,
            a.default,
            a.unit,
            a.doc.trim()
        );
    }
    s
}

/// Steps that fill `seconds` along `entries` (each completed by eq. 1), the last stretch
/// extended or cut; and the exact (fractional) number of steps that `seconds` holds.
fn fill_seconds(
    entries: &[ScheduleEntry],
    last: &WalkParams,
    seconds: f64,
    opts: &WalkOptions,
) -> anyhow::Result<(Vec<ScheduleEntry>, f64)> {
    let mut out = Vec::new();
    let mut t = 0.0;
    let mut exact = 0.0;
    for e in entries {
        let l = high_level::complete(&e.params, opts.height_m, &opts.relations, &opts.attributes)?;
        let step = 60.0 / l.step_freq_steps_per_min;
        let left = seconds - t;
        if e.steps as f64 * step >= left {
            exact += left / step;
            let n = (left / step).round() as usize;
            if n > 0 {
                out.push(ScheduleEntry { steps: n, ..*e });
            }
            return Ok((out, exact));
        }
        t += e.steps as f64 * step;
        exact += e.steps as f64;
        out.push(*e);
    }
    let left = seconds - t;
    let n = steps_for_duration(last, left, opts)?;
    let l = high_level::complete(last, opts.height_m, &opts.relations, &opts.attributes)?;
    exact += left * l.step_freq_steps_per_min / 60.0;
    out.push(ScheduleEntry {
        params: *last,
        steps: n,
    });
    Ok((out, exact))
}

/// The walk's steps as trials-table rows: the commanded step length and frequency (eq. 1),
/// their speed, and KLAW's phase times (eq. 2 and the double-support relation).
fn step_rows(
    report: &WalkReport,
    subject: &str,
    trial: &str,
    height: f64,
    leg: f64,
) -> Vec<StepRow> {
    report
        .steps
        .iter()
        .map(|s| {
            let sf = s.step_freq_steps_per_min / 60.0;
            StepRow {
                subject: subject.to_string(),
                gait: Some(Gait::Walk),
                side: Some(s.stance_side),
                source: "gaitfit generate walk (KLAW 1989)".into(),
                trial: trial.to_string(),
                time_s: Some(s.start_s),
                speed_m_per_s: Some(s.step_length_m * sf),
                step_length_m: Some(s.step_length_m),
                step_freq_hz: Some(sf),
                stance_time_s: Some(s.times.stance),
                swing_time_s: Some(s.times.swing),
                double_support_time_s: Some(s.times.double_support),
                double_support_pct_cycle: Some(100.0 * s.times.double_support / s.times.cycle),
                body_height_m: Some(height),
                leg_length_m: Some(leg),
                ..Default::default()
            }
        })
        .collect()
}

/// Runs `gaitfit generate walk`.
pub fn run(args: &Args) -> anyhow::Result<ExitCode> {
    let c = &args.common;
    let output = c.output()?;
    let mut opts = WalkOptions {
        height_m: args.height,
        mass_kg: args.mass,
        fps: c.fps,
        start_from_rest: args.from_rest,
        stop: args.stop,
        ..Default::default()
    };
    let calibration = match &args.calibration {
        Some(path) => Some(super::run::load_calibration(
            path,
            Gait::Walk,
            c.subject.as_deref(),
            args.height,
            args.speed,
        )?),
        None => None,
    };
    if let Some(theta) = &calibration {
        opts.attributes.set("leg_stiffness", theta[2])?;
    }
    for a in &args.attrs {
        let Some((name, value)) = a.split_once('=') else {
            bail!("--attr {a:?}: expected name=value (see `gaitfit generate walk --help`)");
        };
        let v: f64 = value
            .trim()
            .parse()
            .with_context(|| format!("--attr {a:?}: {value:?} is not a number"))?;
        opts.attributes.set(name.trim(), v)?;
    }
    if let Some(dir) = &args.fits {
        opts.relations = WalkRelations::from_fits_dir(dir)?;
    }
    let mut params = WalkParams {
        speed_m_per_s: args.speed,
        step_length_m: args.step_length,
        step_freq_steps_per_min: args.step_freq.map(crate::units::hz_to_steps_per_min),
    };
    if let Some(theta) = &calibration {
        let r = &opts.relations.tds_sf;
        opts.relations.tds_sf = crate::relations::WalkTdsSf::new(r.d0() + theta[1], r.d1());
        match (args.speed, args.step_length, args.step_freq) {
            (Some(v), None, None) => {
                params.step_length_m = Some(
                    opts.relations
                        .sl_sf
                        .step_length_for_speed(v * 60.0, args.height)
                        + theta[0],
                );
            }
            _ => eprintln!(
                "gaitfit: note: --calibration: the step-length offset applies to --speed alone; \
                 the step length and frequency given are kept"
            ),
        }
    }
    let sched = match &c.schedule {
        Some(path) => Some(Schedule::from_csv(path)?),
        None => None,
    };
    if let Some(s) = &sched {
        opts.stop |= s.stops();
    }
    let schedule: Vec<ScheduleEntry> = match (&sched, c.count) {
        (Some(s), _) if s.length().is_some() => {
            if c.count.is_some() || c.seconds.is_some() {
                eprintln!(
                    "gaitfit: note: {} holds {} steps of its own; --count/--seconds are not used",
                    s.source,
                    s.length().unwrap_or(0)
                );
            }
            s.walk(None, params)?.entries
        }
        (Some(s), Some(n)) => s.walk(Some(n), params)?.entries,
        (None, Some(n)) => vec![ScheduleEntry { params, steps: n }],
        (sched, None) => {
            // A duration: the rows before the last as scheduled, then whole steps of the last
            // row's (or the command line's) parameters that fill it — said when rounded.
            let (before, last) = match sched {
                Some(s) => {
                    let k = s.rows.last().map_or(0, |r| r.step);
                    let last = s.rows.last().map_or(params, walk_params);
                    (s.walk(Some(k), params)?.entries, last)
                }
                None => (Vec::new(), params),
            };
            let seconds = c.seconds();
            let (filled, exact) = fill_seconds(&before, &last, seconds, &opts)?;
            let n: usize = filled.iter().map(|e| e.steps).sum();
            if (exact - n as f64).abs() > 1e-6 {
                eprintln!(
                    "gaitfit: note: --seconds {seconds} holds {exact:.2} steps; walking {n} \
                     whole step(s) (--count N asks for a number of steps)"
                );
            }
            filled
        }
    };
    let (motion, report) = generate_walk(&schedule, &opts)?;
    c.write_motion(&motion)?;
    if c.steps_out.is_some() {
        let leg = Skeleton::from_height(args.height, args.mass)?
            .anthropometry()
            .hip_height_m();
        let subject = c
            .subject
            .clone()
            .unwrap_or_else(|| format!("klaw-{:.2}m", args.height));
        c.write_steps(&step_rows(&report, &subject, &c.trial(), args.height, leg))?;
    }
    // What the generator changed or chose on its own (a ramped speed change, the start, the
    // stop, recoveries) is said, not only stored in the motion's metadata.
    for note in &report.notes {
        eprintln!("gaitfit: note: {note}");
    }
    let it = report.total_iterations();
    let n = report.steps.len().max(1);
    eprintln!(
        "gaitfit: {} steps, {:.2} s, {} frames → {}; shooting simulations per step (mean): \
         stance {:.1}, swing1 {:.1}, swing2 {:.1}, swing3 {:.1}",
        report.steps.len(),
        motion.duration_s(),
        motion.len(),
        output.display(),
        it[0] as f64 / n as f64,
        it[1] as f64 / n as f64,
        it[2] as f64 / n as f64,
        it[3] as f64 / n as f64
    );
    Ok(ExitCode::SUCCESS)
}
