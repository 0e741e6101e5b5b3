//! `gaitfit ... | head`: a reader that closes standard output early must not make gaitfit
//! print a panic.
use std::io::Read;
use std::process::{Command, Stdio};

#[test]
fn closed_stdout_does_not_panic() {
    // `export --format csv` without -o prints every coefficient of every committed fit.
    let mut child = Command::new(env!("CARGO_BIN_EXE_gaitfit"))
        .args(["export", "--fits", "fits", "--format", "csv"])
        .current_dir(env!("CARGO_MANIFEST_DIR"))
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .expect("spawn gaitfit");
    // Close the read end at once, like `| head -0`.
    drop(child.stdout.take());
    let mut err = String::new();
    child
        .stderr
        .take()
        .expect("stderr")
        .read_to_string(&mut err)
        .expect("read stderr");
    let status = child.wait().expect("wait");
    assert!(!err.contains("panicked"), "gaitfit panicked: {err}");
    assert!(status.success(), "exit status {status}, stderr: {err}");
}
