//! `gaitfit generate run`.
use std::process::ExitCode;

/// Arguments of `gaitfit generate run`.
#[derive(Debug, clap::Args)]
pub struct Args {}

/// Runs `gaitfit generate run`.
pub fn run(_args: &Args) -> anyhow::Result<ExitCode> {
    anyhow::bail!("gaitfit generate run: not implemented yet")
}
