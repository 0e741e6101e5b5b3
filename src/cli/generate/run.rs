//! `gaitfit generate run`: RUNNER (Bruderlin & Calvert 1996), a run from a stand at a speed (and
//! optionally step length, step frequency, flight height, level, attributes, a per-step
//! schedule), written as BVH, CSV (+ events CSV) or TRC.
use super::common::{freq_arg, length_arg, speed_arg, Common};
use crate::events::Gait;
use crate::generator::running::attributes::{unit_name, AttrUnit, SPECS};
use crate::generator::running::equations::RunRelations;
use crate::generator::running::params::default_mass;
use crate::generator::running::{
    generate_run, Attr, GenerateOptions, Param, RunAttributes, RunModel, Schedule,
};
use crate::generator::skeleton::Skeleton;
use crate::units::{parse_value, Dimension};
use anyhow::{bail, Context};
use std::path::PathBuf;
use std::process::ExitCode;

/// Arguments of `gaitfit generate run`.
#[derive(Debug, clap::Args)]
#[command(after_long_help = attribute_help())]
pub struct Args {
    /// Speed: `12km/h`, `3.3m/s`, `200m/min` (a bare number is m/s). Without it and without
    /// --step-length/--step-freq: 12 km/h.
    #[arg(long, value_name = "SPEED", value_parser = speed_arg)]
    pub speed: Option<f64>,
    /// Step length: `1.07m`, `107cm` (bare: m). Held fixed together with the other parameters
    /// given; eq. 2 gives way.
    #[arg(long = "step-length", value_name = "LENGTH", value_parser = length_arg)]
    pub step_length: Option<f64>,
    /// Step frequency: `187/min`, `3.1Hz` (bare: steps/min).
    #[arg(long = "step-freq", value_name = "FREQ", value_parser = freq_arg)]
    pub step_freq: Option<f64>,
    /// Flight height H (eq. 3): `0.004m`, `4mm` (bare: m). The flight time then follows from H;
    /// with speed and step length both given this is the paper's case II, and where one H gives
    /// two flight times the one nearest eq. 5's is used and the other is printed in a note.
    #[arg(long = "flight-height", value_name = "LENGTH", value_parser = length_arg)]
    pub flight_height: Option<f64>,
    /// Expertise level, −1 (poor) … 1 (skilled) (scaled to the paper's ±0.001 in eq. 2 and
    /// ±0.0001 in eqs. 4–5).
    #[arg(long, default_value_t = 0.0, allow_hyphen_values = true)]
    pub level: f64,
    /// Body height: `1.8`, `180cm`.
    #[arg(long, value_name = "LENGTH", default_value = "1.8", value_parser = length_arg)]
    pub height: f64,
    /// An attribute, `name=value` in its unit (degrees, metres, factor; `strike=heel|toe`);
    /// repeatable; see the list below.
    #[arg(long = "attr", value_name = "NAME=VALUE")]
    pub attrs: Vec<String>,
    /// Keep these parameters locked during a schedule (comma-separated: speed, step-length,
    /// step-freq, flight-height).
    #[arg(long, value_delimiter = ',')]
    pub lock: Vec<String>,
    /// Folder with refitted relations (`run-sl-v.json`, `run-tflight-sf.json`); the published
    /// coefficients otherwise.
    #[arg(long)]
    pub fits: Option<PathBuf>,
    /// A subject's calibration (`gaitfit calibrate … --out DIR` writes DIR/calibrated.json):
    /// its offsets in the relations and its calibrated attributes; `--subject` picks the subject
    /// when the file holds several. The offsets are the subject's: give `--height` its body
    /// height.
    #[arg(long, value_name = "FILE")]
    pub calibration: Option<PathBuf>,
    /// Do not stop at the end (by default the run ends standing by --seconds, or after --count
    /// steps).
    #[arg(long = "no-stop")]
    pub no_stop: bool,
    /// Also write the generator's plan of each step (kind, start, duration, parameters, flight
    /// case, pelvis at toe off and heel strike, p, recoveries) to this CSV.
    #[arg(long = "plan")]
    pub plan_csv: Option<PathBuf>,
    /// The flags shared by every generator.
    #[command(flatten)]
    pub common: Common,
}

fn attribute_help() -> String {
    let mut s = String::from(
        "Running attributes (--attr name=value; couplings act on top of the setting):\n",
    );
    for a in SPECS.iter() {
        let shown = |v: f64| {
            if a.unit == AttrUnit::Degrees {
                v.to_degrees()
            } else {
                v
            }
        };
        s += &format!(
            "  {:22} default {:>6.3} {:7} range [{}, {}]  {}\n",
            a.name,
            shown(a.default),
            unit_name(a.unit),
            shown(a.min),
            shown(a.max),
            a.doc
        );
    }
    s += "Lengths are for a 1.8 m figure and scale with --height.\n";
    s
}

/// The attribute vector of `gait` for `subject` in a calibrated.json (see
/// [`crate::calibrate::CalibratedFile`]) at speed `speed` (m/s; the offsets may change with
/// speed), with a note when it was calibrated for another body height, and when the offsets
/// have a slope but no speed is given (the reference speed is used).
pub(super) fn load_calibration(
    path: &std::path::Path,
    gait: Gait,
    subject: Option<&str>,
    height: f64,
    speed: Option<f64>,
) -> anyhow::Result<[f64; 3]> {
    use crate::calibrate::CalibratedFile;
    let f = CalibratedFile::read(path)?;
    let s = f
        .pick(gait, subject)
        .map_err(|e| anyhow::anyhow!("--calibration {}: {e}", path.display()))?;
    if (s.body_height_m - height).abs() > 0.005 {
        eprintln!(
            "gaitfit: note: --calibration: {} was calibrated at body height {:.3} m; generating at {height} m",
            s.subject, s.body_height_m
        );
    }
    let v = match (speed, s.reference_speed_m_per_s) {
        (Some(v), _) => v,
        (None, Some(v_ref)) => {
            eprintln!(
                "gaitfit: note: --calibration: {}'s offsets change with speed and no --speed is \
                 given; they are taken at its reference speed {v_ref:.2} m/s",
                s.subject
            );
            v_ref
        }
        (None, None) => 0.0,
    };
    let (lo, hi) = s
        .speeds_m_per_s
        .iter()
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), &x| {
            (a.min(x), b.max(x))
        });
    if s.reference_speed_m_per_s.is_some() && (v < lo - 0.25 || v > hi + 0.25) {
        eprintln!(
            "gaitfit: note: --calibration: {v:.2} m/s is outside {}'s measured speeds \
             {lo:.2}–{hi:.2} m/s; the offsets' speed slopes are extrapolated",
            s.subject
        );
    }
    CalibratedFile::attributes_at(s, v)
        .map_err(|e| anyhow::anyhow!("--calibration {}: {e}", path.display()))
}

fn param_of(name: &str) -> anyhow::Result<Param> {
    Ok(match name.trim() {
        "speed" | "v" => Param::Speed,
        "step-length" | "step_length" | "sl" => Param::StepLength,
        "step-freq" | "step_freq" | "sf" => Param::StepFreq,
        "flight-height" | "flight_height" | "h" | "H" => Param::FlightHeight,
        other => bail!("--lock {other:?}: use speed, step-length, step-freq or flight-height"),
    })
}

fn value(flag: &str, text: &str, dim: Dimension) -> anyhow::Result<f64> {
    parse_value(text, dim).map_err(|e| anyhow::anyhow!("{flag} {e}"))
}

/// Runs `gaitfit generate run`.
pub fn run(args: &Args) -> anyhow::Result<ExitCode> {
    let c = &args.common;
    let output = c.output()?;
    let height = args.height;
    let skeleton = Skeleton::from_height(height, default_mass(height))
        .with_context(|| format!("--height {height}"))?;
    let relations = match &args.fits {
        Some(dir) => RunRelations::from_fits(dir)?,
        None => RunRelations::published(),
    };
    let model = RunModel::new(skeleton, relations)?;
    let mut attrs = RunAttributes::defaults(height);
    let calibration = match &args.calibration {
        Some(path) => {
            let v = args.speed.unwrap_or(12.0 / 3.6);
            let theta = load_calibration(path, Gait::Run, c.subject.as_deref(), height, Some(v))?;
            attrs.set(Attr::Bounciness, theta[2].to_radians())?;
            Some(theta)
        }
        None => None,
    };
    for a in &args.attrs {
        let (name, val) = a
            .split_once('=')
            .with_context(|| format!("--attr {a:?}: expected name=value"))?;
        let attr = Attr::from_name(name).with_context(|| {
            format!("--attr {name:?}: unknown attribute; `gaitfit generate run --help` lists them")
        })?;
        let v = match attr.spec().unit {
            AttrUnit::Degrees => value("--attr", val, Dimension::Angle)?,
            AttrUnit::Metres => value("--attr", val, Dimension::Length)?,
            AttrUnit::Switch => match val.trim() {
                "heel" | "0" => 0.0,
                "toe" | "1" => 1.0,
                other => bail!("--attr strike={other:?}: use heel or toe"),
            },
            AttrUnit::Factor => val
                .trim()
                .parse::<f64>()
                .with_context(|| format!("--attr {a:?}: not a number"))?,
        };
        attrs.set(attr, v)?;
    }
    // Parameters: start natural at the given speed (or 12 km/h), then fix each parameter given,
    // holding the earlier ones (as one schedule row does).
    let given: Vec<(Param, f64)> = [
        (Param::Speed, args.speed),
        (Param::StepLength, args.step_length),
        (Param::StepFreq, args.step_freq),
        (Param::FlightHeight, args.flight_height),
    ]
    .into_iter()
    .filter_map(|(p, v)| v.map(|v| (p, v)))
    .collect();
    let start_v = given
        .iter()
        .find(|(p, _)| *p == Param::Speed)
        .map(|g| g.1)
        .unwrap_or(12.0 / 3.6);
    let mut params = match &calibration {
        // The subject's step length and flight time at this speed (calibrate::drive).
        Some(theta) => crate::calibrate::drive::run_params(&model, &attrs, start_v, theta)?,
        None => model.natural(start_v, args.level, &attrs)?,
    };
    for &(p, v) in &given {
        // With a calibration the speed is already that of `run_params` (re-setting it would
        // return to the relation's step length).
        if !(calibration.is_some() && p == Param::Speed) {
            params = model.set(&params, p, v, &attrs)?;
        }
        params.locks.set(p, true);
    }
    params.locks = Default::default();
    for l in &args.lock {
        params.locks.set(param_of(l)?, true);
    }
    let mut schedule = match &c.schedule {
        Some(p) => Some(Schedule::from_csv(p)?),
        None => None,
    };
    if let Some(n) = c.count {
        let s = schedule.get_or_insert_with(Schedule::default);
        if s.end_step.is_some() {
            eprintln!(
                "gaitfit: note: {} holds its own number of steps; --count is not used",
                s.source
            );
        } else {
            s.end_step = Some(n);
        }
    }
    let opts = GenerateOptions {
        seconds: c.seconds(),
        fps: c.fps,
        stop_at_end: !args.no_stop,
    };
    let (motion, report) = generate_run(&model, params, attrs, schedule, &opts)?;
    c.write_motion(&motion)?;
    if c.steps_out.is_some() {
        let subject = c
            .subject
            .clone()
            .unwrap_or_else(|| format!("runner-{height:.2}m"));
        let leg = model.skeleton.anthropometry().hip_height_m();
        c.write_steps(&report.step_rows(&subject, &c.trial(), Some(leg)))?;
    }
    if let Some(path) = &args.plan_csv {
        write_plan(path, &report)?;
    }
    println!(
        "gaitfit generate run: {} frames at {} fps ({:.2} s), {} steps, relations {}",
        motion.len(),
        motion.fps(),
        motion.duration_s(),
        report.steps.len(),
        report.relations
    );
    let first = report.steps.first();
    println!(
        "  first step: v {:.3} m/s ({:.1} km/h), sl {:.3} m, sf {:.1} steps/min, t_flight {:.3} s, H {:.4} m",
        first.map_or(0.0, |s| s.speed),
        first.map_or(0.0, |s| s.speed * 3.6),
        first.map_or(0.0, |s| s.step_length),
        first.map_or(0.0, |s| s.step_freq * 60.0),
        first.map_or(0.0, |s| s.report.t_flight),
        first.map_or(0.0, |s| s.report.flight_height),
    );
    println!(
        "  requested: v {:.3} m/s ({:.1} km/h), sl {:.3} m, sf {:.1} steps/min, t_flight {:.3} s, H {:.4} m, level {}",
        params.speed,
        params.speed * 3.6,
        params.step_length,
        params.step_freq * 60.0,
        params.flight_time,
        params.flight_height,
        params.level
    );
    for n in &report.notes {
        println!("  note: {n}");
    }
    println!("  wrote {}", output.display());
    Ok(ExitCode::SUCCESS)
}

fn write_plan(
    path: &std::path::Path,
    report: &crate::generator::running::RunReport,
) -> anyhow::Result<()> {
    let mut out = String::from(
        "step,side,kind,start_s,duration_s,speed_m_per_s,step_length_m,step_freq_steps_per_min,\
         stance_time_s,flight_time_s,flight_height_m,case,x1_m,y1_m,x2_m,y2_m,p,mid_support_lowered,clearance_raises\n",
    );
    for s in &report.steps {
        let r = &s.report;
        out += &format!(
            "{},{},{:?},{:.6},{:.6},{:.6},{:.6},{:.4},{:.6},{:.6},{:.6},{},{:.6},{:.6},{:.6},{:.6},{:.4},{},{}\n",
            s.index,
            s.side,
            s.kind,
            s.start_s,
            s.duration_s,
            s.speed,
            s.step_length,
            s.step_freq * 60.0,
            r.t_stance,
            r.t_flight,
            r.flight_height,
            match r.case {
                Some(crate::generator::running::state::FlightCase::I) => "I",
                Some(crate::generator::running::state::FlightCase::II) => "II",
                None => "",
            },
            r.p1.x,
            r.p1.y,
            r.p2.x,
            r.p2.y,
            r.p,
            r.mid_support_lowered,
            r.clearance_keys
        );
    }
    crate::fsio::write_atomic_bytes(path, out.as_bytes())
        .with_context(|| format!("writing {}", path.display()))?;
    Ok(())
}
