//! `gaitfit check`: an r² gate over committed fits.
use crate::export::coeffs::read_fits_dir;
use std::path::PathBuf;
use std::process::ExitCode;

/// Arguments of `gaitfit check`.
#[derive(Debug, clap::Args)]
#[command(
    about = "Check fits against an r² bar (exit 1 and name the fits below it)",
    long_about = "Reads every fits/<id>.json and compares its r² with --min-r2. Prints one line per \
fit; exits 1, naming them, when any fit is below the bar (or when there is no fit at all), 0 \
otherwise. Note that walk-sl-sf's r² is the uncentred one (fit through the origin), which is \
much higher than a centred r² would be.",
    after_help = "Example:\n  gaitfit check --fits fits --min-r2 0.9"
)]
pub struct Args {
    /// Folder with the fit records (one JSON file per relation).
    #[arg(long, value_name = "DIR", default_value = "fits")]
    pub fits: PathBuf,
    /// The bar: fits with r² below it fail.
    #[arg(long = "min-r2", value_name = "R2", default_value_t = 0.9)]
    pub min_r2: f64,
}

/// Runs `gaitfit check`.
pub fn run(args: &Args) -> anyhow::Result<ExitCode> {
    let fits = read_fits_dir(&args.fits)?;
    if fits.is_empty() {
        anyhow::bail!(
            "{}: no fits (*.json) to check; run `gaitfit fit` first",
            args.fits.display()
        );
    }
    let mut below = Vec::new();
    for (path, r) in &fits {
        let ok = r.r2 >= args.min_r2;
        println!(
            "{} {}: r² = {:.4} ({}), n = {} [{}]",
            if ok { "ok   " } else { "BELOW" },
            r.relation,
            r.r2,
            if r.r2_definition.starts_with("uncentred") {
                "uncentred"
            } else {
                "centred"
            },
            r.n,
            path.display()
        );
        if !ok {
            below.push(format!("{} (r² = {:.4})", r.relation, r.r2));
        }
    }
    if below.is_empty() {
        Ok(ExitCode::SUCCESS)
    } else {
        eprintln!(
            "gaitfit check: {} fit(s) below r² = {}: {}",
            below.len(),
            args.min_r2,
            below.join(", ")
        );
        Ok(ExitCode::FAILURE)
    }
}
