//! The `gaitfit` command-line tool: a thin layer over the library (see `gaitfit --help`).
use std::process::ExitCode;

fn main() -> ExitCode {
    gaitfit::cli::main()
}
