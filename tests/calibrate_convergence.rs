//! The calibration's stopping rule (issue 21): MINPACK's convergence tests or the iteration
//! cap, and which of them stopped the solver is said — in the summary line, report.html and
//! calibrated.json.
//!
//! Synthetic: a run generated with a step length the relations do not give (1.45 m at
//! 3.2 m/s: ~30 cm, i.e. ~30 finite-difference steps, from the relations' step length), then
//! calibrated with the committed `fits/`. With one iteration the solver cannot converge (its
//! first trust radius is 3 finite-difference steps, `solve::TRUST_RADIUS`) and must say so;
//! with the default cap it converges before the cap and the calibrated run has the synthetic
//! run's cadence and step length (the synthetic motion is the reference, measured by the
//! event pipeline on both sides). A few seconds.
#[path = "common/calibrate.rs"]
mod calibrate_cli;
use std::path::Path;

fn gaitfit() -> assert_cmd::Command {
    assert_cmd::Command::cargo_bin("gaitfit").unwrap()
}

/// The synthetic run's file.
fn synthetic_run(dir: &Path) -> std::path::PathBuf {
    let path = dir.join("syn_run.trc");
    gaitfit()
        .args([
            "generate",
            "run",
            "--speed",
            "3.2",
            "--step-length",
            "1.45",
            "--seconds",
            "6",
            "--no-stop",
            "-o",
        ])
        .arg(&path)
        .assert()
        .success();
    path
}

/// Runs calibrate; returns (stderr, calibrated.json, report.html, residuals.csv).
fn calibrate(
    input: &Path,
    out: &Path,
    extra: &[&str],
) -> (String, serde_json::Value, String, String) {
    let o = calibrate_cli::run(input, out, extra);
    let json: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("calibrated.json")).unwrap())
            .unwrap();
    (
        String::from_utf8_lossy(&o.stderr).into_owned(),
        json,
        std::fs::read_to_string(out.join("report.html")).unwrap(),
        std::fs::read_to_string(out.join("residuals.csv")).unwrap(),
    )
}

#[test]
fn one_iteration_cannot_converge_and_says_so() {
    let dir = tempfile::tempdir().unwrap();
    let trial = synthetic_run(dir.path());
    let (stderr, json, html, _) = calibrate(&trial, &dir.path().join("out"), &["--max-iters", "1"]);
    println!("{stderr}");
    let solver = &json["subjects"][0]["solver"];
    assert_eq!(solver["converged"], false, "{solver}");
    assert_eq!(solver["reason"], "iteration cap (1) reached", "{solver}");
    assert_eq!(solver["iterations"], 1, "{solver}");
    assert!(
        stderr.contains("NOT converged: iteration cap (1) reached"),
        "summary line: {stderr}"
    );
    assert!(
        html.contains("<b>not converged</b>: iteration cap (1) reached after 1 iteration(s)"),
        "report.html does not say it"
    );
}

#[test]
fn the_default_cap_converges_and_fits_the_synthetic_run() {
    let dir = tempfile::tempdir().unwrap();
    let trial = synthetic_run(dir.path());
    let (stderr, json, html, csv) = calibrate(&trial, &dir.path().join("out"), &[]);
    println!("{stderr}");
    let solver = &json["subjects"][0]["solver"];
    assert_eq!(solver["converged"], true, "{solver}");
    let iters = solver["iterations"].as_u64().unwrap();
    assert!(iters < 50, "{solver}");
    assert!(stderr.contains("converged after"), "{stderr}");
    assert!(!stderr.contains("NOT converged"), "{stderr}");
    assert!(html.contains("trust region converged after"), "report.html");
    // The calibrated run has the synthetic run's cadence and step length (within 1 %).
    let head: Vec<&str> = csv.lines().next().unwrap().split(',').collect();
    let col = |n: &str| head.iter().position(|h| *h == n).unwrap();
    let mut seen = 0;
    for l in csv.lines().skip(1) {
        let f: Vec<&str> = l.split(',').collect();
        let q = f[col("quantity")];
        if f[col("stage")] == "calibrated" && (q == "cadence_steps_per_min" || q == "step_length_m")
        {
            let m: f64 = f[col("measured")].parse().unwrap();
            let g: f64 = f[col("generated")].parse().unwrap();
            println!("{q}: measured {m:.4}, calibrated {g:.4}");
            assert!((g - m).abs() < 0.01 * m, "{q}: {g} vs {m}");
            seen += 1;
        }
    }
    assert_eq!(seen, 2, "{csv}");
}
