//! `gaitfit generate run|walk|generalize`.
use clap::Subcommand;
use std::process::ExitCode;

pub mod common;
pub mod generalize;
pub mod run;
pub mod walk;

/// Arguments of `gaitfit generate`.
#[derive(Debug, clap::Args)]
pub struct Args {
    /// Which generator.
    #[command(subcommand)]
    pub generator: Generator,
}

/// The generators.
#[derive(Debug, Subcommand)]
pub enum Generator {
    /// RUNNER (Bruderlin & Calvert 1996): a run from velocity, step length, step frequency,
    /// flight height and expertise level.
    Run(run::Args),
    /// KLAW (Bruderlin & Calvert 1989): a dynamic walk from speed, step length and/or step
    /// frequency.
    Walk(walk::Args),
    /// Ko & Badler (1993): a measured walk step generalized to any step length and body.
    Generalize(generalize::Args),
}

/// Runs `gaitfit generate`.
pub fn run(args: &Args) -> anyhow::Result<ExitCode> {
    match &args.generator {
        Generator::Run(a) => run::run(a),
        Generator::Walk(a) => walk::run(a),
        Generator::Generalize(a) => generalize::run(a),
    }
}
