//! `gaitfit fit --data RAW…`: raw measured files go through the events layer, then the fit. The
//! independent path is `gaitfit events -o steps.csv` followed by `gaitfit fit --data steps.csv`;
//! both must give the same rows and the same coefficients.
use assert_cmd::Command;
use gaitfit::events::synthetic::SyntheticGait;
use std::path::Path;

fn gaitfit(dir: &Path) -> Command {
    let mut c = Command::cargo_bin("gaitfit").unwrap();
    c.current_dir(dir);
    c
}

fn record(dir: &Path, fits: &str, id: &str) -> serde_json::Value {
    let p = dir.join(fits).join(format!("{id}.json"));
    let text = std::fs::read_to_string(&p).unwrap_or_else(|e| panic!("{}: {e}", p.display()));
    serde_json::from_str(&text).unwrap()
}

fn coefficient(v: &serde_json::Value, i: usize) -> f64 {
    v["coefficients"][i]["value"].as_f64().unwrap()
}

/// Fits `inputs` directly and through `gaitfit events` + CSV, and checks that the two agree.
fn raw_fit_matches_events_then_fit(dir: &Path, inputs: &[String], relations: &[&str]) {
    gaitfit(dir)
        .args(["fit", "--no-report", "--fits", "fits_raw", "--data"])
        .args(inputs)
        .arg("--relation")
        .args(relations)
        .assert()
        .success();
    gaitfit(dir)
        .arg("events")
        .args(inputs)
        .args(["-o", "steps.csv"])
        .assert()
        .success();
    gaitfit(dir)
        .args([
            "fit",
            "--no-report",
            "--fits",
            "fits_csv",
            "--data",
            "steps.csv",
        ])
        .arg("--relation")
        .args(relations)
        .assert()
        .success();
    for id in relations {
        let (raw, csv) = (record(dir, "fits_raw", id), record(dir, "fits_csv", id));
        assert!(raw["n"].as_u64().unwrap() > 0, "{id}: {raw}");
        assert_eq!(raw["n"], csv["n"], "{id}: same rows");
        let n = raw["coefficients"].as_array().unwrap().len();
        for i in 0..n {
            let (a, b) = (coefficient(&raw, i), coefficient(&csv, i));
            // The CSV rounds to its printed digits (double support to 0.01 % of the cycle),
            // hence not bit-identical.
            let tol = if *id == "walk-tds-sf" { 1e-3 } else { 2e-5 };
            assert!(
                (a - b).abs() <= tol * b.abs().max(1e-9),
                "{id}: coefficient {i}: raw {a} vs csv {b}"
            );
        }
    }
}

#[test]
fn fit_accepts_raw_per_frame_csv_files() {
    let dir = tempfile::tempdir().unwrap();
    let mut inputs = Vec::new();
    let mut k_per_trial = Vec::new();
    for (i, (v, stride)) in [(1.1, 1.16), (1.4, 1.06)].into_iter().enumerate() {
        let g = SyntheticGait {
            belt_speed_m_per_s: v,
            stride_time_s: stride,
            duration_s: 8.0,
            ..SyntheticGait::walk()
        };
        let name = format!("walk{i}.csv");
        std::fs::write(dir.path().join(&name), g.frame_csv()).unwrap();
        inputs.push(name);
        // sl = k·sf·h, sf in steps/min, h = 1.8 m (the frame CSV's body height).
        k_per_trial.push(g.step_length_m() / (120.0 / stride * 1.8));
    }
    // (Not walk-tds-sf: two nearly equal synthetic cadences leave its slope ill-determined.)
    raw_fit_matches_events_then_fit(dir.path(), &inputs, &["walk-sl-sf"]);
    // The synthetic walks' own step lengths and cadences come back through the fit.
    let k = coefficient(&record(dir.path(), "fits_raw", "walk-sl-sf"), 0);
    let (lo, hi) = (
        k_per_trial[0].min(k_per_trial[1]),
        k_per_trial[0].max(k_per_trial[1]),
    );
    assert!(
        k > lo * 0.98 && k < hi * 1.02,
        "k = {k}, per-trial values {k_per_trial:?}"
    );
}

#[test]
fn fit_rejects_an_unreadable_raw_file_naming_it() {
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(dir.path().join("broken.c3d"), b"not a c3d file").unwrap();
    let out = gaitfit(dir.path())
        .args(["fit", "--no-report", "--data", "broken.c3d"])
        .assert()
        .failure();
    let err = String::from_utf8_lossy(&out.get_output().stderr).to_string();
    assert!(err.contains("broken.c3d"), "{err}");
    assert!(!dir.path().join("fits").exists(), "no partial output");
}

#[test]
fn a_trials_table_is_not_taken_for_a_raw_file() {
    let dir = tempfile::tempdir().unwrap();
    let p = dir.path().join("t.csv");
    std::fs::write(&p, "subject,gait,speed_m_per_s\ns1,walk,1.2\n").unwrap();
    assert!(!gaitfit::events::input::is_raw_input(&p));
    std::fs::write(&p, "# gait = walk\ntime_s,heel_x_m\n0,0\n").unwrap();
    assert!(gaitfit::events::input::is_raw_input(&p));
    assert!(gaitfit::events::input::is_raw_input(Path::new("x.c3d")));
}

#[test]
#[ignore = "needs ../shared/data"]
fn fit_on_the_raw_wbds_folder_equals_events_then_fit() {
    let wbds = gaitfit::shared_data::require("wbds");
    let dir = tempfile::tempdir().unwrap();
    raw_fit_matches_events_then_fit(
        dir.path(),
        &[wbds.display().to_string()],
        &["walk-sl-sf", "walk-tds-sf"],
    );
}
