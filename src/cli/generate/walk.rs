//! `gaitfit generate walk`.
use std::process::ExitCode;

/// Arguments of `gaitfit generate walk`.
#[derive(Debug, clap::Args)]
pub struct Args {}

/// Runs `gaitfit generate walk`.
pub fn run(_args: &Args) -> anyhow::Result<ExitCode> {
    anyhow::bail!("gaitfit generate walk: not implemented yet")
}
