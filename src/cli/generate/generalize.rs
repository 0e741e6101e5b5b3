//! `gaitfit generate generalize`: a measured walk step (Ko & Badler 1993) generalized to a figure
//! of any height and to any step lengths, written as BVH, CSV or TRC (by the extension of `-o`).
//!
//! ```text
//! gaitfit generate generalize --height 1.9 --step-length 0.9 -o walk.bvh
//! gaitfit generate generalize --height 1.6 --schedule steps.csv -o walk.trc
//! gaitfit generate generalize --build-prototype ../shared/data/bmclab/wn35b.txt \
//!     --write-prototype data/prototype_winter.json
//! ```
//!
//! A schedule is a CSV with a `step_length_m` column and optionally `duration_s` (one row per
//! step). Without `--prototype` the bundled Winter prototype is used; without `--alpha` the
//! μ-function slopes come from `fits/kb-mu.json` (written by `gaitfit fit`, relation `kb-mu`) when
//! it exists, else from the built-in values (the committed fit).
use crate::events::Side;
use crate::generator::generalize::figure::{
    default_step_duration, metadata, walk_motion, StepPlan,
};
use crate::generator::generalize::prototype::{winter_prototype, Prototype};
use crate::generator::generalize::{Anthropometry, Generalizer, DEFAULT_ALPHA};
use crate::generator::skeleton::Skeleton;
use anyhow::{anyhow, bail, Context};
use std::path::{Path, PathBuf};
use std::process::ExitCode;

/// Arguments of `gaitfit generate generalize` (boxed: they are many).
#[derive(Debug, clap::Args)]
pub struct Args {
    /// The options.
    #[command(flatten)]
    pub options: Box<Options>,
}

/// The options of `gaitfit generate generalize`.
#[derive(Debug, clap::Args)]
pub struct Options {
    /// Prototype walk file (JSON written by `--write-prototype`); default: the bundled Winter
    /// prototype.
    #[arg(long, value_name = "FILE")]
    pub prototype: Option<PathBuf>,
    /// Build a prototype from Winter's table (`WinterTableA1.txt` or `wn35b.txt`) instead.
    #[arg(long, value_name = "FILE", conflicts_with = "prototype")]
    pub build_prototype: Option<PathBuf>,
    /// Write the prototype in use to this JSON file (how `data/prototype_winter.json` is made).
    #[arg(long, value_name = "FILE")]
    pub write_prototype: Option<PathBuf>,
    /// μ-function slopes α1,α2,α3,α4 in rad/m (default: fits/kb-mu.json, else built in).
    #[arg(long, value_delimiter = ',', num_args = 4, value_name = "A1,A2,A3,A4")]
    pub alpha: Option<Vec<f64>>,
    /// The kb-mu fit to take α from (made by `gaitfit fit --relation kb-mu`).
    #[arg(long, value_name = "FILE", default_value = "fits/kb-mu.json")]
    pub mu_fit: PathBuf,
    /// Body height of the figure, m.
    #[arg(long, default_value_t = 1.75)]
    pub height: f64,
    /// Body mass of the figure, kg (only the skeleton's metadata uses it).
    #[arg(long, default_value_t = 70.0)]
    pub mass: f64,
    /// Step length, m (every step; see --schedule for varying steps).
    #[arg(long)]
    pub step_length: Option<f64>,
    /// Number of steps with --step-length.
    #[arg(long, default_value_t = 6)]
    pub steps: usize,
    /// CSV schedule: `step_length_m`[, `duration_s`] per step.
    #[arg(long, value_name = "FILE", conflicts_with = "step_length")]
    pub schedule: Option<PathBuf>,
    /// Cadence, steps/min (default: the prototype's, scaled by √(leg length ratio)).
    #[arg(long)]
    pub cadence: Option<f64>,
    /// Frames per second.
    #[arg(long, default_value_t = 120.0)]
    pub fps: f64,
    /// Output motion (.bvh, .csv or .trc).
    #[arg(short, long, value_name = "FILE")]
    pub output: Option<PathBuf>,
}

/// Runs `gaitfit generate generalize`.
pub fn run(args: &Args) -> anyhow::Result<ExitCode> {
    let args = &*args.options;
    let (proto, source) = if let Some(p) = &args.build_prototype {
        let (proto, report) = winter_prototype(p)?;
        eprintln!(
            "prototype from {}: sl* = {:.4} m, step {:.4} s, μ* = {:?} rad; φ₁ moved the swing \
             ankle by {:.4} m (toe off) and {:.4} m (heel strike), the hip ends by {:?} m",
            p.display(),
            report.step_length_m,
            report.step_duration_s,
            report.mu_star,
            report.ankle_to_shift_m,
            report.ankle_hs_shift_m,
            report.hip_pin_m
        );
        if let Some(out) = &args.write_prototype {
            let file = p
                .file_name()
                .map(|f| f.to_string_lossy().into_owned())
                .unwrap_or_default();
            let cmd = format!(
                "gaitfit generate generalize --build-prototype ../shared/data/bmclab/{file} \
                 --write-prototype {}",
                out.display()
            );
            crate::fsio::write_atomic_bytes(out, proto.to_json(&cmd, Some(&report)).as_bytes())?;
            eprintln!("wrote {}", out.display());
        }
        (proto, p.display().to_string())
    } else if let Some(p) = &args.prototype {
        let text = std::fs::read_to_string(p).with_context(|| format!("{}", p.display()))?;
        let proto =
            Prototype::from_json(&text, &p.display().to_string()).map_err(|e| anyhow!(e))?;
        (proto, p.display().to_string())
    } else {
        (
            Prototype::bundled(),
            "bundled data/prototype_winter.json".to_string(),
        )
    };
    if args.build_prototype.is_none() {
        if let Some(out) = &args.write_prototype {
            crate::fsio::write_atomic_bytes(out, proto.to_json("(copied)", None).as_bytes())?;
        }
    }
    let Some(output) = &args.output else {
        if args.write_prototype.is_some() {
            return Ok(ExitCode::SUCCESS);
        }
        bail!("give -o/--output FILE (.bvh, .csv or .trc), or --write-prototype");
    };

    let alpha = match &args.alpha {
        Some(a) => [a[0], a[1], a[2], a[3]],
        None => alpha_from_fit(&args.mu_fit)?.unwrap_or(DEFAULT_ALPHA),
    };
    let mu = proto.mu(alpha)?;
    let g = Generalizer::new(proto.walk.clone(), mu)?;
    let skeleton = Skeleton::from_height(args.height, args.mass)?;
    let body = Anthropometry::from_figure(skeleton.anthropometry())?;
    let default_duration = match args.cadence {
        Some(c) if c.is_finite() && c > 0.0 => 60.0 / c,
        Some(c) => bail!("--cadence {c}: must be positive steps/min"),
        None => default_step_duration(proto.step_duration_s, &body, &proto.walk),
    };
    let plan: Vec<StepPlan> = match (&args.schedule, args.step_length) {
        (Some(path), _) => read_schedule(path, default_duration)?,
        (None, Some(sl)) => {
            if args.steps == 0 {
                bail!("--steps must be at least 1");
            }
            vec![
                StepPlan {
                    step_length_m: sl,
                    duration_s: default_duration,
                };
                args.steps
            ]
        }
        (None, None) => bail!("give --step-length M or --schedule FILE"),
    };
    let meta = metadata(&g, args.height, &source);
    let (motion, report) = walk_motion(&g, skeleton, &plan, Side::Right, args.fps, meta)?;
    crate::export::motion::write(&motion, output)?;
    eprintln!(
        "wrote {} ({} frames, {} steps); hip lowered at most {:.4} m to reach the feet; skeleton \
         feet within {:.2e} m of the generalization",
        output.display(),
        motion.len(),
        plan.len(),
        report.max_hip_drop_m,
        report.max_foot_mismatch_m
    );
    Ok(ExitCode::SUCCESS)
}

/// α from a kb-mu fit file (`coefficients` with `alpha1`…`alpha4`), if the file exists.
// Read generically (not through `kb_mu::KbMuFit`) so a file written by `gaitfit fit` in the
// common fits format works too.
fn alpha_from_fit(path: &Path) -> anyhow::Result<Option<[f64; 4]>> {
    if !path.exists() {
        return Ok(None);
    }
    let text = std::fs::read_to_string(path).with_context(|| format!("{}", path.display()))?;
    let v: serde_json::Value =
        serde_json::from_str(&text).with_context(|| format!("{}: not JSON", path.display()))?;
    let mut a = [0.0; 4];
    for (i, slot) in a.iter_mut().enumerate() {
        let name = format!("alpha{}", i + 1);
        *slot = find_coefficient(&v, &name)
            .ok_or_else(|| anyhow!("{}: no coefficient {name}", path.display()))?;
    }
    Ok(Some(a))
}

/// Finds a coefficient's value by name anywhere in a fit file (`{"name": …, "value": …}` entries
/// or a `{name: value}` map).
fn find_coefficient(v: &serde_json::Value, name: &str) -> Option<f64> {
    match v {
        serde_json::Value::Object(m) => {
            if m.get("name").and_then(|n| n.as_str()) == Some(name) {
                if let Some(x) = m.get("value").and_then(|x| x.as_f64()) {
                    return Some(x);
                }
            }
            if let Some(x) = m.get(name).and_then(|x| x.as_f64()) {
                return Some(x);
            }
            m.values().find_map(|c| find_coefficient(c, name))
        }
        serde_json::Value::Array(a) => a.iter().find_map(|c| find_coefficient(c, name)),
        _ => None,
    }
}

/// Reads a schedule CSV: `step_length_m` and optional `duration_s` columns.
fn read_schedule(path: &Path, default_duration: f64) -> anyhow::Result<Vec<StepPlan>> {
    let mut r = csv::ReaderBuilder::new()
        .trim(csv::Trim::All)
        .comment(Some(b'#'))
        .from_path(path)
        .with_context(|| format!("{}", path.display()))?;
    let headers = r.headers()?.clone();
    let col = |n: &str| headers.iter().position(|h| h == n);
    let sl_col = col("step_length_m").ok_or_else(|| {
        anyhow!(
            "{}: missing column step_length_m (one row per step, metres; optional duration_s)",
            path.display()
        )
    })?;
    let d_col = col("duration_s");
    let mut plan = Vec::new();
    for (i, rec) in r.records().enumerate() {
        let rec = rec.with_context(|| format!("{}: row {}", path.display(), i + 1))?;
        let num = |c: usize, name: &str| -> anyhow::Result<f64> {
            let s = rec.get(c).unwrap_or("");
            let v: f64 = s.parse().map_err(|_| {
                anyhow!(
                    "{}: row {}, column {name}: {s:?} is not a number",
                    path.display(),
                    i + 1
                )
            })?;
            if !(v.is_finite() && v > 0.0) {
                bail!(
                    "{}: row {}, column {name}: {v} must be positive",
                    path.display(),
                    i + 1
                );
            }
            Ok(v)
        };
        plan.push(StepPlan {
            step_length_m: num(sl_col, "step_length_m")?,
            duration_s: match d_col {
                Some(c) if !rec.get(c).unwrap_or("").is_empty() => num(c, "duration_s")?,
                _ => default_duration,
            },
        });
    }
    if plan.is_empty() {
        bail!("{}: no steps", path.display());
    }
    Ok(plan)
}
