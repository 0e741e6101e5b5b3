//! `gaitfit export`: coefficient tables for other programs.
use crate::export::coeffs::{export, read_fits_dir, write_crate, ExportFormat};
use std::path::PathBuf;
use std::process::ExitCode;

/// Arguments of `gaitfit export`.
#[derive(Debug, clap::Args)]
#[command(
    about = "Export fitted coefficients (Rust, a Rust crate, JSON, TOML, CSV)",
    long_about = "Reads every fits/<id>.json and writes the coefficients in one document:\n  \
rust  — Rust source: one module per relation, one documented `pub const` per coefficient \
(equation, unit, valid range, 95 % CI, n, r², data SHA-256 in each doc); use it as a module \
(`mod gait_coeffs;`) or with `include!(\"gait_coeffs.rs\")`;\n  \
crate — the same as a crate folder (-o DIR: Cargo.toml, src/lib.rs) that another crate depends \
on by path;\n  \
json  — an array of the full fit records;\n  \
toml  — one table per relation, the same records as the JSON (an open interval end is an \
absent key);\n  \
csv   — one row per coefficient.\n\
Values are the shortest decimals that read back to the fitted f64, bit-identical in every format. \
Writes to standard output, or atomically to -o FILE.",
    after_help = "Examples:\n  gaitfit export --format rust -o src/gait_coeffs.rs\n  \
gaitfit export --format crate -o ../gait_coeffs     # then: gait_coeffs = { path = \"../gait_coeffs\" }\n  \
gaitfit export --format toml -o gait.toml           # Python: tomllib.load(open('gait.toml', 'rb'))"
)]
pub struct Args {
    /// Folder with the fit records (one JSON file per relation).
    #[arg(long, value_name = "DIR", default_value = "fits")]
    pub fits: PathBuf,
    /// Output format.
    #[arg(long, value_enum)]
    pub format: ExportFormat,
    /// Output file (default: standard output); for `--format crate` the crate's folder.
    #[arg(short = 'o', long = "output", value_name = "FILE|DIR")]
    pub output: Option<PathBuf>,
    /// Package name of `--format crate`.
    #[arg(
        long = "crate-name",
        value_name = "NAME",
        default_value = "gait_coeffs"
    )]
    pub crate_name: String,
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
    if args.format == ExportFormat::Crate {
        let Some(dir) = &args.output else {
            anyhow::bail!("--format crate writes a folder: give -o DIR");
        };
        write_crate(&records, dir, &args.crate_name)?;
        eprintln!(
            "wrote the crate `{}` to {} (Cargo.toml, src/lib.rs)",
            args.crate_name,
            dir.display()
        );
        return Ok(ExitCode::SUCCESS);
    }
    let text = export(&records, args.format)?;
    match &args.output {
        Some(p) => crate::fsio::write_atomic_bytes(p, text.as_bytes())?,
        None => print!("{text}"),
    }
    Ok(ExitCode::SUCCESS)
}
