//! `gaitfit events`.
use std::process::ExitCode;

/// Arguments of `gaitfit events`.
#[derive(Debug, clap::Args)]
pub struct Args {}

/// Runs `gaitfit events`.
pub fn run(_args: &Args) -> anyhow::Result<ExitCode> {
    anyhow::bail!("gaitfit events: not implemented yet")
}
