//! `gaitfit check`: an r² gate over committed fits.
use crate::export::coeffs::{read_fits_dir, FitRecord};
use std::path::PathBuf;
use std::process::ExitCode;

/// Arguments of `gaitfit check`.
#[derive(Debug, clap::Args)]
#[command(
    about = "Check fits against an r² bar (exit 1 and name the fits below it)",
    long_about = "Reads every fits/<id>.json and compares its centred r², 1 − RSS/Σ(y − ȳ)², with \
--min-r2. Prints one line per fit; exits 1, naming them, when any fit is below the bar (or when \
there is no fit at all), 0 otherwise. A fit through the origin (walk-sl-sf) also records the \
uncentred r², 1 − RSS/Σy², which is close to 1 whenever the data are far from zero whatever the \
fit; --uncentred gates on that one instead for such fits.",
    after_help = "Example:\n  gaitfit check --fits fits --min-r2 0.9"
)]
pub struct Args {
    /// Folder with the fit records (one JSON file per relation).
    #[arg(long, value_name = "DIR", default_value = "fits")]
    pub fits: PathBuf,
    /// The bar: fits with r² below it fail.
    #[arg(long = "min-r2", value_name = "R2", default_value_t = 0.9)]
    pub min_r2: f64,
    /// Gate fits through the origin on their uncentred r² (NIST's definition for such fits)
    /// instead of the centred one.
    #[arg(long)]
    pub uncentred: bool,
}

/// The r² a record is gated on and its name: the centred one, or with `uncentred` the record's
/// own r² (uncentred for fits through the origin).
fn gated_r2(r: &FitRecord, uncentred: bool) -> anyhow::Result<(f64, &'static str)> {
    let own_is_uncentred = r.r2_definition.starts_with("uncentred");
    if uncentred && own_is_uncentred {
        return Ok((r.r2, "uncentred"));
    }
    match r.r2_centred {
        Some(v) => Ok((v, "centred")),
        None if !own_is_uncentred => Ok((r.r2, "centred")),
        None => anyhow::bail!(
            "{}: the record has no centred r² (written by an older gaitfit); rerun `gaitfit fit`",
            r.relation
        ),
    }
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
        let (r2, which) = gated_r2(r, args.uncentred)?;
        let ok = r2 >= args.min_r2;
        println!(
            "{} {}: r² = {:.4} ({}), n = {} [{}]",
            if ok { "ok   " } else { "BELOW" },
            r.relation,
            r2,
            which,
            r.n,
            path.display()
        );
        if !ok {
            below.push(format!("{} ({which} r² = {r2:.4})", r.relation));
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
