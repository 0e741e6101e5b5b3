//! `gaitfit check`.
use std::process::ExitCode;

/// Arguments of `gaitfit check`.
#[derive(Debug, clap::Args)]
pub struct Args {}

/// Runs `gaitfit check`.
pub fn run(_args: &Args) -> anyhow::Result<ExitCode> {
    anyhow::bail!("gaitfit check: not implemented yet")
}
