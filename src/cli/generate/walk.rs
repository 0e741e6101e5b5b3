//! `gaitfit generate walk`: KLAW (Bruderlin & Calvert 1989), a dynamic walk from speed, step
//! length and/or step frequency.
use crate::generator::walking::{
    generate_walk, read_schedule, steps_for_duration, ScheduleEntry, WalkOptions, WalkParams,
    WalkRelations, ATTRIBUTES,
};
use anyhow::{bail, Context};
use std::path::PathBuf;
use std::process::ExitCode;

/// Arguments of `gaitfit generate walk`.
#[derive(Debug, clap::Args)]
#[command(after_long_help = attribute_help())]
pub struct Args {
    /// Forward speed, e.g. `5km/h`, `1.4m/s` or `1.4` (m/s).
    #[arg(long)]
    pub speed: Option<String>,
    /// Step length, m.
    #[arg(long = "step-length")]
    pub step_length: Option<f64>,
    /// Step frequency, steps/min.
    #[arg(long = "step-freq")]
    pub step_freq: Option<f64>,
    /// Body height, m.
    #[arg(long, default_value_t = 1.8)]
    pub height: f64,
    /// Body mass, kg.
    #[arg(long, default_value_t = 75.0)]
    pub mass: f64,
    /// A locomotion attribute, `name=value` (repeatable; see the list below).
    #[arg(long = "attr", value_name = "NAME=VALUE")]
    pub attrs: Vec<String>,
    /// Schedule CSV (columns `steps` and any of `speed_m_per_s`/`speed_km_per_h`,
    /// `step_length_m`, `step_freq_steps_per_min`) instead of --speed/--step-length/--step-freq.
    #[arg(long)]
    pub schedule: Option<PathBuf>,
    /// Folder with refitted relations (`walk-sl-sf.json`, `walk-tds-sf.json`); the published
    /// relations otherwise.
    #[arg(long)]
    pub fits: Option<PathBuf>,
    /// Duration of the walk, s (without --schedule).
    #[arg(long, default_value_t = 10.0)]
    pub seconds: f64,
    /// Frames per second of the output.
    #[arg(long, default_value_t = 100.0)]
    pub fps: f64,
    /// Start standing, feet side by side (the first step starts from rest). Without it the walk
    /// starts steady, recorded from 5 frames before its first heel strike (mid-motion). Without
    /// --stop it ends 5 frames after the trailing toe off that follows its last heel strike.
    #[arg(long = "from-rest")]
    pub from_rest: bool,
    /// End standing: a last half step, then the trailing foot is brought alongside and the body
    /// comes to rest.
    #[arg(long)]
    pub stop: bool,
    /// Output file: `.bvh`, `.csv` (plus `<stem>_events.csv`) or `.trc`.
    #[arg(short = 'o', long)]
    pub output: PathBuf,
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

/// Parses a speed with an optional unit (`km/h`, `m/s`, `m/min`) into m/s.
pub fn parse_speed(s: &str) -> anyhow::Result<f64> {
    let t = s.trim().to_ascii_lowercase().replace(' ', "");
    let (num, factor) = if let Some(n) = t.strip_suffix("km/h").or_else(|| t.strip_suffix("kmh")) {
        (n, 1.0 / 3.6)
    } else if let Some(n) = t.strip_suffix("m/min") {
        (n, 1.0 / 60.0)
    } else if let Some(n) = t.strip_suffix("m/s") {
        (n, 1.0)
    } else {
        (t.as_str(), 1.0)
    };
    let v: f64 = num.parse().with_context(|| {
        format!("--speed {s:?}: not a number with an optional unit km/h, m/s or m/min")
    })?;
    Ok(v * factor)
}

/// Runs `gaitfit generate walk`.
pub fn run(args: &Args) -> anyhow::Result<ExitCode> {
    let mut opts = WalkOptions {
        height_m: args.height,
        mass_kg: args.mass,
        fps: args.fps,
        start_from_rest: args.from_rest,
        stop: args.stop,
        ..Default::default()
    };
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
    let schedule = match &args.schedule {
        Some(path) => {
            if args.speed.is_some() || args.step_length.is_some() || args.step_freq.is_some() {
                bail!("give either --schedule or --speed/--step-length/--step-freq, not both");
            }
            read_schedule(path)?
        }
        None => {
            let params = WalkParams {
                speed_m_per_s: args.speed.as_deref().map(parse_speed).transpose()?,
                step_length_m: args.step_length,
                step_freq_steps_per_min: args.step_freq,
            };
            let steps = steps_for_duration(&params, args.seconds, &opts)?;
            vec![ScheduleEntry { params, steps }]
        }
    };
    let (motion, report) = generate_walk(&schedule, &opts)?;
    crate::export::motion::write(&motion, &args.output)?;
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
        args.output.display(),
        it[0] as f64 / n as f64,
        it[1] as f64 / n as f64,
        it[2] as f64 / n as f64,
        it[3] as f64 / n as f64
    );
    Ok(ExitCode::SUCCESS)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn speeds_with_units() {
        assert!((parse_speed("5km/h").unwrap() - 5.0 / 3.6).abs() < 1e-12);
        assert!((parse_speed("1.4 m/s").unwrap() - 1.4).abs() < 1e-12);
        assert!((parse_speed("84m/min").unwrap() - 1.4).abs() < 1e-12);
        assert!((parse_speed("1.4").unwrap() - 1.4).abs() < 1e-12);
        assert!(parse_speed("fast").is_err());
    }
}
