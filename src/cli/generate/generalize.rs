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
//! A schedule uses the columns every generator shares ([`crate::generator::schedule`]): here
//! `step`/`steps`, `step_length_*` (kept until changed; the first row needs one unless
//! `--step-length` is given), `step_freq_*` or `speed_*` (the cadence then follows from the
//! step length), one row per step without `step`/`steps`. Without `--prototype` the bundled
//! Winter prototype is used; without `--alpha` the μ-function slopes come from
//! `fits/kb-mu.json` (written by `gaitfit fit`, relation `kb-mu`) when it exists, else from the
//! built-in values (the committed fit). `--kb-variant carried` draws the carried variant
//! ([`crate::generator::generalize::carried`]).
use super::common::{freq_arg, length_arg, Common};
use crate::events::{Gait, Side};
use crate::generator::generalize::compare::Variant;
use crate::generator::generalize::figure::{
    default_step_duration, metadata, walk_motion_with, StepPlan,
};
use crate::generator::generalize::prototype::{winter_prototype, Prototype};
use crate::generator::generalize::{default_alpha, Anthropometry, Generalizer};
use crate::generator::schedule::Schedule;
use crate::generator::skeleton::Skeleton;
use crate::ingest::trials::StepRow;
use crate::units::Quantity;
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
    /// μ-function slopes α1,α2,α3,α4 in rad/m, comma-separated (default: fits/kb-mu.json,
    /// else built in).
    #[arg(long, value_name = "A1,A2,A3,A4", allow_hyphen_values = true)]
    pub alpha: Option<String>,
    /// The kb-mu fit to take α from (made by `gaitfit fit --relation kb-mu`).
    #[arg(long, value_name = "FILE", default_value = "fits/kb-mu.json")]
    pub mu_fit: PathBuf,
    /// Body height of the figure: `1.75`, `175cm`.
    #[arg(long, value_name = "LENGTH", default_value = "1.75", value_parser = length_arg)]
    pub height: f64,
    /// Body mass of the figure, kg (only the skeleton's metadata uses it).
    #[arg(long, default_value_t = 70.0)]
    pub mass: f64,
    /// Step length: `0.7m`, `70cm` (bare: m); every step, or until a schedule row changes it.
    #[arg(long = "step-length", value_name = "LENGTH", value_parser = length_arg)]
    pub step_length: Option<f64>,
    /// Cadence: `110/min`, `1.8Hz` (bare: steps/min); default: the prototype's, scaled by
    /// √(leg length ratio).
    #[arg(long = "step-freq", visible_alias = "cadence", value_name = "FREQ", value_parser = freq_arg)]
    pub step_freq: Option<f64>,
    /// Ko–Badler variant: `paper` (W's rigid drawing, eqs. 11–12, 25–48) or `carried` (the
    /// prototype's measured angle curves kept in W: the paper's feet, the hip placed where the
    /// drawn angles come nearest them; the prototype must carry measured angles — the bundled
    /// one does). Default `paper`: the generator draws the published model; `gaitfit
    /// calibrate`, which compares with measured subjects, defaults to `carried`.
    #[arg(
        long = "kb-variant",
        value_name = "paper|carried",
        default_value = "paper"
    )]
    pub kb_variant: Variant,
    /// The flags shared by every generator.
    #[command(flatten)]
    pub common: Common,
}

fn parse_alpha(text: &str) -> anyhow::Result<[f64; 4]> {
    let v: Vec<f64> = text
        .split(',')
        .map(|x| x.trim().parse::<f64>())
        .collect::<Result<_, _>>()
        .map_err(|_| anyhow!("--alpha {text:?}: four numbers (rad/m), comma-separated"))?;
    match v.as_slice() {
        &[a, b, c, d] => Ok([a, b, c, d]),
        _ => bail!(
            "--alpha {text:?}: {} value(s); give four, α1,α2,α3,α4 (rad/m)",
            v.len()
        ),
    }
}

/// One step's plan from a schedule row: its step length (`sl`, the row's or the one before) and
/// duration (the row's cadence, or its speed over the step length, or `default_duration`).
fn plan_of(
    row: Option<&crate::generator::schedule::ScheduleRow>,
    sl: &mut Option<f64>,
    default_duration: f64,
    source: &str,
) -> anyhow::Result<StepPlan> {
    if let Some(v) = row.and_then(|r| r.get(Quantity::StepLength)) {
        *sl = Some(v);
    }
    let Some(step_length_m) = *sl else {
        bail!(
            "{source}: row {}: no step length yet; give step_length_m in the first row or \
             --step-length",
            row.map_or(1, |r| r.row)
        );
    };
    let duration_s = match (
        row.and_then(|r| r.get(Quantity::StepFreq)),
        row.and_then(|r| r.get(Quantity::Speed)),
    ) {
        (Some(f), _) => 1.0 / f,
        (None, Some(v)) => step_length_m / v,
        (None, None) => default_duration,
    };
    Ok(StepPlan {
        step_length_m,
        duration_s,
    })
}

/// The steps to walk: from a schedule (its own length, `--count`, or filling `--seconds`) or
/// `--step-length` repeated. Says on stderr when a duration is rounded to whole steps.
fn plan_steps(
    c: &Common,
    step_length: Option<f64>,
    default_duration: f64,
) -> anyhow::Result<Vec<StepPlan>> {
    let sched = match &c.schedule {
        Some(p) => {
            let s = Schedule::from_csv(p)?;
            s.accept_only(
                "generate generalize",
                &[Quantity::Speed, Quantity::StepLength, Quantity::StepFreq],
                false,
                false,
            )?;
            Some(s)
        }
        None => None,
    };
    let source = c
        .schedule
        .as_ref()
        .map_or("--step-length".to_string(), |p| p.display().to_string());
    let mut sl = step_length;
    let mut plan = Vec::new();
    // Rows (or none) holding a number of steps each; `None` for the command line's step.
    let mut stretches: Vec<(Option<&crate::generator::schedule::ScheduleRow>, usize)> = Vec::new();
    let first = sched
        .as_ref()
        .and_then(|s| s.rows.first())
        .map_or(0, |r| r.step);
    let total = match &sched {
        Some(s) if s.length().is_some() => s.length(),
        _ => c.count,
    };
    if let Some(s) = &sched {
        if first > 0 {
            stretches.push((None, total.map_or(first, |t| first.min(t))));
        }
        let open = s.length().is_none() && total.is_none();
        // Filling a duration: the last row holds until the time is up (below).
        let cut = if open {
            s.rows.last().map(|r| r.step)
        } else {
            total
        };
        for (r, n) in s.stretches(cut)? {
            stretches.push((Some(r), n));
        }
        if open {
            stretches.push((s.rows.last(), 0));
        }
    } else {
        stretches.push((None, total.unwrap_or(0)));
    }
    for &(row, n) in &stretches {
        let p = plan_of(row, &mut sl, default_duration, &source)?;
        plan.extend(std::iter::repeat_n(p, n));
    }
    if total.is_none() {
        // --seconds: whole steps of the last stretch's kind fill the time left.
        let seconds = c.seconds();
        let used: f64 = plan.iter().map(|p| p.duration_s).sum();
        let row = stretches.last().and_then(|s| s.0);
        let p = plan_of(row, &mut sl, default_duration, &source)?;
        let exact = (seconds - used).max(0.0) / p.duration_s;
        let n = exact.round() as usize;
        plan.extend(std::iter::repeat_n(p, n));
        let whole = plan.len() as f64;
        let all = plan.len() as f64 - n as f64 + exact;
        if (all - whole).abs() > 1e-6 {
            eprintln!(
                "gaitfit: note: --seconds {seconds} holds {all:.2} steps; walking {} whole \
                 step(s) (--count N asks for a number of steps)",
                plan.len()
            );
        }
    }
    if plan.is_empty() {
        bail!("{source}: no steps to walk (a longer --seconds or --count N)");
    }
    Ok(plan)
}

/// Runs `gaitfit generate generalize`.
pub fn run(args: &Args) -> anyhow::Result<ExitCode> {
    let args = &*args.options;
    let c = &args.common;
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
    if c.output.is_none() && args.write_prototype.is_some() {
        return Ok(ExitCode::SUCCESS);
    }
    let output = c.output()?;

    let alpha = match &args.alpha {
        Some(a) => parse_alpha(a)?,
        None => alpha_from_fit(&args.mu_fit)?.unwrap_or(default_alpha()),
    };
    let mu = proto.mu(alpha)?;
    let g = Generalizer::new(proto.walk.clone(), mu)?;
    let skeleton = Skeleton::from_height(args.height, args.mass)?;
    let body = Anthropometry::from_figure(skeleton.anthropometry())?;
    let default_duration = match args.step_freq {
        Some(f) => 1.0 / f,
        None => default_step_duration(proto.step_duration_s, &body, &proto.walk),
    };
    let plan = plan_steps(c, args.step_length, default_duration)?;
    let carried = match args.kb_variant {
        Variant::Paper => None,
        Variant::Carried => Some(proto.carried()?.ok_or_else(|| {
            anyhow!(
                "--kb-variant carried: the prototype ({source}) carries no measured angle curves \
                 (a prototype built by --build-prototype, or the bundled one, has them)"
            )
        })?),
    };
    let mut meta = metadata(&g, args.height, &source);
    meta.push("kb_variant", args.kb_variant.name());
    let (motion, report) = walk_motion_with(
        &g,
        carried.as_ref(),
        skeleton,
        &plan,
        Side::Right,
        c.fps,
        meta,
    )?;
    c.write_motion(&motion)?;
    if c.steps_out.is_some() {
        let subject = c
            .subject
            .clone()
            .unwrap_or_else(|| format!("ko-badler-{:.2}m", args.height));
        c.write_steps(&step_rows(
            &g,
            &body,
            &plan,
            &subject,
            &c.trial(),
            args.height,
        ))?;
    }
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

/// The generalized steps as trials-table rows: step length, cadence and speed as planned, and
/// the μ values (eqs. 21–24) the generalization gave each step — the inputs `gaitfit fit
/// --relation kb-mu` refits α from. Times are each step's start (the first at 0).
fn step_rows(
    g: &Generalizer,
    body: &Anthropometry,
    plan: &[StepPlan],
    subject: &str,
    trial: &str,
    height: f64,
) -> Vec<StepRow> {
    let mut t = 0.0;
    let mut side = Side::Right;
    plan.iter()
        .map(|p| {
            let mu = g.mu().values_unchecked(body, p.step_length_m);
            let row = StepRow {
                subject: subject.to_string(),
                gait: Some(Gait::Walk),
                side: Some(side),
                source: "gaitfit generate generalize (Ko & Badler 1993)".into(),
                trial: trial.to_string(),
                time_s: Some(t),
                speed_m_per_s: Some(p.step_length_m / p.duration_s),
                step_length_m: Some(p.step_length_m),
                step_freq_hz: Some(1.0 / p.duration_s),
                body_height_m: Some(height),
                leg_length_m: Some(body.leg_length()),
                knee_angle_hs_rad: Some(mu.knee_hs),
                foot_angle_hs_rad: Some(mu.foot_hs),
                foot_angle_to_rad: Some(mu.foot_to),
                meta_angle_to_rad: Some(mu.meta_to),
                ..Default::default()
            };
            t += p.duration_s;
            side = side.opposite();
            row
        })
        .collect()
}
