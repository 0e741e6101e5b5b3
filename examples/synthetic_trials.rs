//! A seeded synthetic trials table for measuring `gaitfit fit` at scale (issue 24): rows drawn
//! from the published relations plus Gaussian noise ([`gaitfit::fit::synthetic`]), half
//! running, half walking, written in the trials schema that `gaitfit fit --data` reads.
//!
//! ```sh
//! cargo run --release --example synthetic_trials -- /tmp/trials_1e6.csv 1000000 10 42
//! /usr/bin/time -v gaitfit fit --data /tmp/trials_1e6.csv --fits /tmp/f --reports /tmp/r
//! ```
//! Arguments: output file, rows (default 1,000,000), subjects (default 10), seed (default 42).
use gaitfit::fit::synthetic::{synthetic_rows, SyntheticSpec};
use gaitfit::ingest::trials::write_trials;
use std::process::ExitCode;

fn main() -> ExitCode {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let Some(out) = args.first() else {
        eprintln!("usage: synthetic_trials OUT.csv [ROWS] [SUBJECTS] [SEED]");
        return ExitCode::from(2);
    };
    let num = |k: usize, default: u64| -> Result<u64, String> {
        args.get(k).map_or(Ok(default), |s| {
            s.parse().map_err(|e| format!("{s:?}: {e}"))
        })
    };
    let spec = match (num(1, 1_000_000), num(2, 10), num(3, 42)) {
        (Ok(rows), Ok(subjects), Ok(seed)) => SyntheticSpec {
            rows: rows as usize,
            subjects: subjects as usize,
            seed,
            ..SyntheticSpec::default()
        },
        (a, b, c) => {
            for e in [a.err(), b.err(), c.err()].into_iter().flatten() {
                eprintln!("synthetic_trials: {e}");
            }
            return ExitCode::from(2);
        }
    };
    let rows = synthetic_rows(&spec);
    if let Err(e) = write_trials(std::path::Path::new(out), &rows) {
        eprintln!("synthetic_trials: {e}");
        return ExitCode::FAILURE;
    }
    eprintln!(
        "{} rows, {} subjects, seed {} → {out}",
        spec.rows, spec.subjects, spec.seed
    );
    ExitCode::SUCCESS
}
