//! What the three generators share on the command line: the length of the motion (`--seconds`
//! or `--count`), `--fps` (one default), `--schedule` (one column vocabulary,
//! [`crate::generator::schedule`]), `--steps-out` (the generated steps in the trials schema
//! that `gaitfit fit` reads), `--bvh-units` and `-o`; and the value parsers for numbers with
//! units (all through [`crate::units::parse_value`]).
use crate::export::bvh::BvhUnit;
use crate::export::motion::MotionOptions;
use crate::export::opensim::OpenSimModel;
use crate::generator::motion::Motion;
use crate::ingest::trials::StepRow;
use crate::units::{parse_value, Dimension};
use anyhow::Context;
use std::path::{Path, PathBuf};

/// Frames per second of every generator's output unless `--fps` says otherwise: 120 Hz, a
/// common motion-capture rate (the shared data's Vicon and Qualisys trials are 100–200 Hz), and
/// a whole number of frames for BVH players at 24/30/60 Hz multiples.
pub const DEFAULT_FPS: f64 = 120.0;

/// Duration of the motion unless `--seconds`, `--count` or a schedule with its own length says
/// otherwise, s.
pub const DEFAULT_SECONDS: f64 = 10.0;

/// The flags every `gaitfit generate` subcommand shares.
#[derive(Debug, Clone, clap::Args)]
#[command(next_help_heading = "Shared by run, walk and generalize")]
pub struct Common {
    /// Per-step schedule CSV: `step` (where a row starts) or `steps` (how many steps it holds),
    /// and `speed_*`, `step_length_*`, `step_freq_*` (run also `flight_height_*`, `level`;
    /// run and walk `action` = go|stop). The same columns for every generator; see the README.
    #[arg(long, value_name = "FILE")]
    pub schedule: Option<PathBuf>,
    /// Duration, s (`10`, `10s`, `9500ms`); default 10 s. A schedule with a `steps` column has
    /// its own length. Walk rounds it to whole steps (and says so).
    #[arg(long, value_name = "S", value_parser = seconds_arg, conflicts_with = "count")]
    pub seconds: Option<f64>,
    /// Number of steps instead of a duration. run: N steps, then (unless --no-stop) the stop,
    /// decelerating over a few more; walk: N steps, with --stop the last is the stop's half
    /// step; generalize: N steps.
    #[arg(long, value_name = "N", value_parser = count_arg)]
    pub count: Option<usize>,
    /// Frames per second of the output.
    #[arg(long, value_name = "HZ", default_value_t = DEFAULT_FPS, value_parser = fps_arg)]
    pub fps: f64,
    /// Also write the generated steps to this CSV in the trials schema `gaitfit fit` reads
    /// (time, side, speed, step length and frequency, phase times, body and leg length; what
    /// each generator knows).
    #[arg(long = "steps-out", value_name = "FILE")]
    pub steps_out: Option<PathBuf>,
    /// Subject name in the --steps-out table (default: the generator and the body height).
    #[arg(long, value_name = "NAME")]
    pub subject: Option<String>,
    /// Length unit of a BVH output: m (Blender's default import scale) or cm (MotionBuilder).
    #[arg(long = "bvh-units", value_name = "UNIT", default_value = "m", value_parser = bvh_units_arg)]
    pub bvh_units: BvhUnit,
    /// Coordinate conventions of a `.mot`/`.sto` output: gait2392 (also gait2354 and Hamner
    /// 2010; knee flexion negative) or rajagopal (Rajagopal 2015; knee flexion positive).
    #[arg(long = "opensim-model", value_name = "MODEL", default_value = "gait2392", value_parser = opensim_model_arg)]
    pub opensim_model: OpenSimModel,
    /// Output file: `.bvh`, `.csv` (plus `<stem>_events.csv`), `.trc` (OpenSim markers) or
    /// `.mot`/`.sto` (OpenSim joint angles).
    #[arg(short = 'o', long, value_name = "FILE")]
    pub output: Option<PathBuf>,
}

impl Common {
    /// The output path, or an error saying to give one.
    pub fn output(&self) -> anyhow::Result<&Path> {
        self.output.as_deref().with_context(|| {
            "give -o FILE (.bvh, .csv, .trc, .mot or .sto): where to write the motion"
        })
    }

    /// The duration asked for (default [`DEFAULT_SECONDS`]).
    pub fn seconds(&self) -> f64 {
        self.seconds.unwrap_or(DEFAULT_SECONDS)
    }

    /// Writes the motion to `-o` in the format its extension names.
    pub fn write_motion(&self, motion: &Motion) -> anyhow::Result<&Path> {
        let out = self.output()?;
        let opts = MotionOptions {
            bvh_unit: self.bvh_units,
            opensim_model: self.opensim_model,
        };
        crate::export::motion::write_with(motion, out, &opts)?;
        Ok(out)
    }

    /// Writes `rows` to `--steps-out`, if given.
    pub fn write_steps(&self, rows: &[StepRow]) -> anyhow::Result<()> {
        if let Some(path) = &self.steps_out {
            crate::ingest::trials::write_trials(path, rows)
                .with_context(|| format!("writing {}", path.display()))?;
        }
        Ok(())
    }

    /// The trial name of the --steps-out rows: the output's file stem.
    pub fn trial(&self) -> String {
        self.output
            .as_deref()
            .and_then(Path::file_stem)
            .map(|s| s.to_string_lossy().into_owned())
            .unwrap_or_default()
    }
}

fn value_arg(text: &str, dim: Dimension) -> Result<f64, String> {
    parse_value(text, dim).map_err(|e| e.to_string())
}

/// A speed (`12km/h`, `3.3m/s`, `200m/min`; bare: m/s), m/s.
pub fn speed_arg(text: &str) -> Result<f64, String> {
    positive(value_arg(text, Dimension::Speed)?, text)
}

/// A length (`1.07m`, `107cm`, `4mm`; bare: m), m.
pub fn length_arg(text: &str) -> Result<f64, String> {
    positive(value_arg(text, Dimension::Length)?, text)
}

/// A step frequency (`187/min`, `3.1Hz`; bare: steps/min), steps/s.
pub fn freq_arg(text: &str) -> Result<f64, String> {
    positive(value_arg(text, Dimension::Frequency)?, text)
}

fn seconds_arg(text: &str) -> Result<f64, String> {
    let v = value_arg(text, Dimension::Time)?;
    if v > 0.0 && v <= 3600.0 {
        Ok(v)
    } else {
        Err(format!("{text:?}: the duration must lie in (0, 3600] s"))
    }
}

fn count_arg(text: &str) -> Result<usize, String> {
    match text.trim().parse::<usize>() {
        Ok(n) if n >= 1 => Ok(n),
        _ => Err(format!("{text:?}: a number of steps, 1 or more")),
    }
}

fn fps_arg(text: &str) -> Result<f64, String> {
    match text.trim().parse::<f64>() {
        Ok(v) if v.is_finite() && (1.0..=10_000.0).contains(&v) => Ok(v),
        _ => Err(format!("{text:?}: frames per second, 1 to 10000")),
    }
}

fn bvh_units_arg(text: &str) -> Result<BvhUnit, String> {
    match text.trim().to_ascii_lowercase().as_str() {
        "m" | "metres" | "meters" => Ok(BvhUnit::Metres),
        "cm" | "centimetres" | "centimeters" => Ok(BvhUnit::Centimetres),
        _ => Err(format!("{text:?}: use m or cm")),
    }
}

fn opensim_model_arg(text: &str) -> Result<OpenSimModel, String> {
    match text.trim().to_ascii_lowercase().as_str() {
        "gait2392" | "gait2354" | "hamner" | "hamner2010" => Ok(OpenSimModel::Gait2392),
        "rajagopal" | "rajagopal2015" => Ok(OpenSimModel::Rajagopal2015),
        _ => Err(format!("{text:?}: use gait2392 or rajagopal")),
    }
}

fn positive(v: f64, text: &str) -> Result<f64, String> {
    if v > 0.0 {
        Ok(v)
    } else {
        Err(format!("{text:?}: must be positive"))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn argument_parsers() {
        assert!((speed_arg("5km/h").unwrap() - 5.0 / 3.6).abs() < 1e-12);
        assert!((speed_arg("1.4").unwrap() - 1.4).abs() < 1e-12);
        assert!((length_arg("180cm").unwrap() - 1.8).abs() < 1e-12);
        assert!((freq_arg("120").unwrap() - 2.0).abs() < 1e-12);
        assert!(speed_arg("-1").is_err() && speed_arg("fast").is_err());
        assert_eq!(seconds_arg("1500ms"), Ok(1.5));
        assert!(seconds_arg("0").is_err() && seconds_arg("2h").is_err());
        assert_eq!(count_arg("4"), Ok(4));
        assert!(count_arg("0").is_err() && count_arg("2.5").is_err());
        assert_eq!(bvh_units_arg("cm"), Ok(BvhUnit::Centimetres));
        assert!(bvh_units_arg("in").is_err());
        assert!(fps_arg("0").is_err() && fps_arg("nan").is_err());
    }
}
