//! `gaitfit calibrate INPUT --fits <the committed fits/> --out OUT [EXTRA…]`, shared by the
//! calibrate tests (`calibrate_done_when`, `calibrate_convergence`, `calibrate_steps_table`).
//! Included with `#[path = "common/calibrate.rs"] mod calibrate_cli;`.
#![allow(dead_code)]
use std::path::Path;
use std::process::Output;

/// Runs the calibration of `input` into `out` with the repository's `fits/` and `extra`
/// arguments, asserts that it succeeded and returns its output (stdout, stderr).
pub fn run(input: &Path, out: &Path, extra: &[&str]) -> Output {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    assert_cmd::Command::cargo_bin("gaitfit")
        .expect("the gaitfit binary")
        .arg("calibrate")
        .arg(input)
        .arg("--fits")
        .arg(root.join("fits"))
        .arg("--out")
        .arg(out)
        .args(extra)
        .assert()
        .success()
        .get_output()
        .clone()
}
