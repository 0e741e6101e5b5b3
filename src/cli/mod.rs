//! The command-line layer: argument parsing (clap) and one file per subcommand. The binary is
//! thin; every subcommand calls into the library.
use clap::{Parser, Subcommand};
use std::process::ExitCode;

pub mod calibrate;
pub mod check;
pub mod events;
pub mod export;
pub mod fit;
pub mod generate;
pub mod inspect;
pub mod studio;

/// gaitfit: fit the published gait relations of KLAW (1989), RUNNER (1996) and Ko–Badler
/// (1993) to measured data, generate walking and running with the fitted coefficients, and
/// report residuals.
#[derive(Debug, Parser)]
#[command(name = "gaitfit", version, about, long_about = None, propagate_version = true)]
pub struct Cli {
    /// What to do.
    #[command(subcommand)]
    pub command: Command,
}

/// The subcommands.
#[derive(Debug, Subcommand)]
pub enum Command {
    /// Refit the published relations on trial tables (or raw measured files) and write fits/ and
    /// reports/.
    Fit(fit::Args),
    /// Check committed fits against an r² bar (exit 1 and say which fit is below it).
    Check(check::Args),
    /// Export fitted coefficient tables for other programs (Rust, JSON, TOML, CSV).
    Export(export::Args),
    /// Detect gait events in measured files and write per-step tables.
    Events(Box<events::Args>),
    /// Generate motion (running, walking, or a generalized measured walk).
    Generate(generate::Args),
    /// Print what a reader loaded from a file; -o writes its per-frame data as gaitfit's
    /// per-frame CSV.
    Inspect(inspect::Args),
    /// Edit runs and walks live in a local web page (127.0.0.1 only).
    Studio(studio::Args),
    /// Measured trials → relations → generated gait → the same measurement → residuals and a
    /// per-subject calibration (report.html, residuals.csv, calibrated.json).
    Calibrate(calibrate::Args),
}

/// Runs the command line; returns the process exit code (0 success, 1 check failed or error,
/// 2 usage error).
pub fn main() -> ExitCode {
    quiet_on_closed_pipe();
    let cli = Cli::parse();
    let result = match &cli.command {
        Command::Fit(a) => fit::run(a),
        Command::Check(a) => check::run(a),
        Command::Export(a) => export::run(a),
        Command::Events(a) => events::run(a),
        Command::Generate(a) => generate::run(a),
        Command::Inspect(a) => inspect::run(a),
        Command::Studio(a) => studio::run(a),
        Command::Calibrate(a) => calibrate::run(a),
    };
    match result {
        Ok(code) => code,
        Err(e) => {
            eprintln!("gaitfit: error: {e:#}");
            ExitCode::FAILURE
        }
    }
}

/// Makes `gaitfit ... | head` end quietly: when the reader of standard output goes away,
/// `println!` panics with "failed printing to stdout: Broken pipe"; like `cat`, gaitfit then
/// stops without a panic message (exit status 0, the reader got all it asked for). Files being
/// written are unaffected: they go through `fsio::write_atomic`, which never leaves half a file.
fn quiet_on_closed_pipe() {
    let default = std::panic::take_hook();
    std::panic::set_hook(Box::new(move |info| {
        let payload = info.payload();
        let msg = payload
            .downcast_ref::<String>()
            .map(String::as_str)
            .or_else(|| payload.downcast_ref::<&str>().copied())
            .unwrap_or("");
        if msg.contains("failed printing to stdout") && msg.contains("Broken pipe") {
            std::process::exit(0);
        }
        default(info)
    }));
}
