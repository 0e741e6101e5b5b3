//! `gaitfit generate generalize`.
use std::process::ExitCode;

/// Arguments of `gaitfit generate generalize`.
#[derive(Debug, clap::Args)]
pub struct Args {}

/// Runs `gaitfit generate generalize`.
pub fn run(_args: &Args) -> anyhow::Result<ExitCode> {
    anyhow::bail!("gaitfit generate generalize: not implemented yet")
}
