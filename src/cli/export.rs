//! `gaitfit export`.
use std::process::ExitCode;

/// Arguments of `gaitfit export`.
#[derive(Debug, clap::Args)]
pub struct Args {}

/// Runs `gaitfit export`.
pub fn run(_args: &Args) -> anyhow::Result<ExitCode> {
    anyhow::bail!("gaitfit export: not implemented yet")
}
