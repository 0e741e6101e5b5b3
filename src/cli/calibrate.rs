//! `gaitfit calibrate`: the closing loop as a command (library: [`crate::calibrate`]).
use crate::calibrate::{calibrate, output, CalibrateOptions, Variant};
use crate::events::Gait;
use std::io::IsTerminal;
use std::path::PathBuf;
use std::process::ExitCode;

/// Arguments of `gaitfit calibrate`.
#[derive(Debug, clap::Args)]
pub struct Args {
    /// Measured trials: files or folders (TRC + GRF, C3D, MOT, WBDS, gaitfit CSV), or steps
    /// tables (one row per step with `subject` and `gait` columns, as `gaitfit events` writes
    /// them: one condition per subject × trial, no pelvis excursion or angle curves).
    #[arg(required = true)]
    pub inputs: Vec<PathBuf>,
    /// Folder of fitted relations (`gaitfit fit`); without it the relations are refitted on the
    /// inputs (into DIR/fits).
    #[arg(long)]
    pub fits: Option<PathBuf>,
    /// Walk or run for every input (default: decided from the data: flight phases or double
    /// support).
    #[arg(long, value_parser = parse_gait)]
    pub gait: Option<Gait>,
    /// Output folder: report.html, residuals.csv, calibrated.json.
    #[arg(long, short = 'o')]
    pub out: PathBuf,
    /// Frames per second of the generated motions.
    #[arg(long, default_value_t = 200.0)]
    pub fps: f64,
    /// Steady steps generated per condition.
    #[arg(long, default_value_t = 12)]
    pub steps: usize,
    /// Trust-region (Gauss–Newton) iterations at most. The solver stops earlier when MINPACK's
    /// convergence tests are met (relative reduction, step or gradient; see
    /// `calibrate::solve`); whether it converged or hit this cap is printed per subject and
    /// written in report.html and calibrated.json. On the shared data the subjects converged
    /// in 4–14 iterations (Schreiber 2014007 with `--speed-slopes` in 37).
    #[arg(long, default_value_t = 50)]
    pub max_iters: u64,
    /// Ko–Badler variant of the `ko-badler` stage (walking subjects with two or more speeds):
    /// `paper` (W's rigid drawing, eqs. 11–12, 25–48) or `carried` (the subject's measured
    /// hip/knee/ankle curves kept in W: the paper's feet, the hip placed where the drawn angles
    /// come nearest them). Default `carried`: in the leave-one-out across the Schreiber subjects
    /// it is nearer the held-out subjects' hip/knee/ankle angles than `paper` (4.7/7.6/6.5°
    /// against 9.0/16.1/8.1°, tests/kb_carried.rs).
    #[arg(
        long = "kb-variant",
        value_name = "paper|carried",
        default_value = "carried"
    )]
    pub kb_variant: Variant,
    /// Give the relation offsets (step length; flight time or double support) a slope per m/s
    /// for subjects measured at two or more speeds (default: one constant offset set per
    /// subject). Off by default: leave one speed out, Hamner subject01's held-out residuals
    /// were larger with the slopes (see `--leave-one-speed-out`).
    #[arg(long)]
    pub speed_slopes: bool,
    /// Also predict each condition from a calibration on the subject's other conditions
    /// (stage `held-out` in residuals.csv and the report; one more calibration per condition).
    #[arg(long)]
    pub leave_one_speed_out: bool,
}

fn parse_gait(s: &str) -> Result<Gait, String> {
    Gait::parse(s).ok_or_else(|| format!("{s:?}: use walk or run"))
}

/// Runs `gaitfit calibrate`.
pub fn run(args: &Args) -> anyhow::Result<ExitCode> {
    if !(args.fps.is_finite() && (50.0..=2000.0).contains(&args.fps)) {
        anyhow::bail!("--fps {}: use 50 to 2000 frames/s", args.fps);
    }
    if args.steps < 4 {
        anyhow::bail!("--steps {}: at least 4 steady steps", args.steps);
    }
    let opts = CalibrateOptions {
        fits: args.fits.clone(),
        refit_dir: Some(args.out.join("fits")),
        gait: args.gait,
        drive: crate::calibrate::drive::DriveOptions {
            fps: args.fps,
            steps: args.steps,
        },
        max_iters: args.max_iters,
        kb_variant: args.kb_variant,
        speed_slopes: args.speed_slopes,
        leave_one_speed_out: args.leave_one_speed_out,
    };
    let bar = std::io::stderr().is_terminal().then(|| {
        let b = indicatif::ProgressBar::new_spinner();
        if let Ok(style) =
            indicatif::ProgressStyle::with_template("{spinner} {pos}/{len} subjects {msg}")
        {
            b.set_style(style);
        }
        b.set_message("measuring the inputs");
        b.enable_steady_tick(std::time::Duration::from_millis(200));
        b
    });
    let cal = calibrate(&args.inputs, &opts, |i, n, r| {
        let line = crate::calibrate::summary_line(r);
        match &bar {
            Some(b) => {
                b.set_length(n as u64);
                b.set_position(i as u64);
                b.println(line);
            }
            None => eprintln!("{line}"),
        }
    })?;
    if let Some(b) = &bar {
        b.finish_and_clear();
    }
    for f in &cal.failed {
        eprintln!("gaitfit: warning: not measured: {f}");
    }
    for r in &cal.subjects {
        for n in r
            .subject
            .notes
            .iter()
            .filter(|n| n.starts_with("calibration:"))
        {
            eprintln!("gaitfit: warning: {}: {n}", r.subject.name);
        }
    }
    if let Some(l) = &cal.kb_leave_one_out {
        let (p, c, n) = (
            l.mean.generalized_same,
            l.mean.carried_same,
            l.mean.naive_same,
        );
        println!(
            "Ko–Badler leave-one-out ({} strides, {} subjects), hip/knee/ankle RMS deg, ankle path cm: \
             paper {:.1}/{:.1}/{:.1}, {:.1}; carried {:.1}/{:.1}/{:.1}, {:.1}; naive scaling {:.1}/{:.1}/{:.1}, {:.1}",
            l.strides, l.subjects, p.hip_deg, p.knee_deg, p.ankle_deg, p.ankle_path_cm,
            c.hip_deg, c.knee_deg, c.ankle_deg, c.ankle_path_cm,
            n.hip_deg, n.knee_deg, n.ankle_deg, n.ankle_path_cm
        );
    }
    output::write_all(&args.out, &cal)?;
    println!(
        "gaitfit calibrate: {} subject(s) → {}/report.html, residuals.csv, calibrated.json",
        cal.subjects.len(),
        args.out.display()
    );
    Ok(ExitCode::SUCCESS)
}
