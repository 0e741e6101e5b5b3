//! `gaitfit fit`.
use std::process::ExitCode;

/// Arguments of `gaitfit fit`.
#[derive(Debug, clap::Args)]
pub struct Args {}

/// Runs `gaitfit fit`.
pub fn run(_args: &Args) -> anyhow::Result<ExitCode> {
    anyhow::bail!("gaitfit fit: not implemented yet")
}
