//! `gaitfit export`: coefficient tables for other programs.
use crate::export::coeffs::{export, read_fits_dir, ExportFormat};
use std::path::PathBuf;
use std::process::ExitCode;

/// Arguments of `gaitfit export`.
#[derive(Debug, clap::Args)]
#[command(
    about = "Export fitted coefficients (Rust, JSON, TOML, CSV)",
    long_about = "Reads every fits/<id>.json and writes the coefficients in one document:\n  \
rust — a self-contained module of documented `pub const`s (value, 95 % CI, published value, n, \
r², data SHA-256 in each doc comment; compiles on its own);\n  json — an array of the full fit \
records;\n  toml — one table per relation;\n  csv — one row per coefficient.\n\
Writes to standard output, or atomically to -o FILE.",
    after_help = "Example:\n  gaitfit export --fits fits --format rust -o src/gait_coeffs.rs"
)]
pub struct Args {
    /// Folder with the fit records (one JSON file per relation).
    #[arg(long, value_name = "DIR", default_value = "fits")]
    pub fits: PathBuf,
    /// Output format.
    #[arg(long, value_enum)]
    pub format: ExportFormat,
    /// Output file (default: standard output).
    #[arg(short = 'o', long = "output", value_name = "FILE")]
    pub output: Option<PathBuf>,
}

/// Runs `gaitfit export`.
pub fn run(args: &Args) -> anyhow::Result<ExitCode> {
    let fits = read_fits_dir(&args.fits)?;
    if fits.is_empty() {
        anyhow::bail!(
            "{}: no fits (*.json) to export; run `gaitfit fit` first",
            args.fits.display()
        );
    }
    let records: Vec<_> = fits.into_iter().map(|(_, r)| r).collect();
    let text = export(&records, args.format)?;
    match &args.output {
        Some(p) => crate::fsio::write_atomic_bytes(p, text.as_bytes())?,
        None => print!("{text}"),
    }
    Ok(ExitCode::SUCCESS)
}
