//! The real binary in a fresh temp folder: fit → fits/ and reports/, check, export.
use assert_cmd::Command;
use gaitfit::fit::synthetic::{synthetic_rows, SyntheticSpec};
use gaitfit::ingest::trials::write_trials;
use std::path::Path;

fn gaitfit(dir: &Path) -> Command {
    let mut c = Command::cargo_bin("gaitfit").unwrap();
    c.current_dir(dir);
    c
}

fn setup() -> tempfile::TempDir {
    let dir = tempfile::tempdir().unwrap();
    let rows = synthetic_rows(&SyntheticSpec {
        rows: 800,
        subjects: 6,
        seed: 5,
        ..Default::default()
    });
    write_trials(&dir.path().join("data/trials.csv"), &rows).unwrap();
    dir
}

const REQUIRED: &[&str] = &[
    "relation",
    "equation",
    "units",
    "n",
    "coefficients",
    "r2",
    "adj_r2",
    "rmse",
    "residual_mean_square",
    "aic",
    "bic",
    "loo_rmse",
    "loso_rmse",
    "published_fit",
    "valid_range",
    "data",
    "gaitfit_version",
];

#[test]
fn help_explains_every_subcommand() {
    let dir = tempfile::tempdir().unwrap();
    for (args, must) in [
        (vec!["--help"], "fit"),
        (vec!["fit", "--help"], "--bootstrap"),
        (vec!["check", "--help"], "--min-r2"),
        (vec!["export", "--help"], "--format"),
    ] {
        let out = gaitfit(dir.path()).args(&args).output().unwrap();
        assert!(out.status.success(), "{args:?}");
        let s = String::from_utf8_lossy(&out.stdout);
        assert!(s.contains(must), "{args:?}: {s}");
    }
}

#[test]
fn fit_check_export_round_trip() {
    let dir = setup();
    let d = dir.path();
    let out = gaitfit(d)
        .args(["fit", "--robust", "--bootstrap", "20", "--seed", "4"])
        .output()
        .unwrap();
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert!(
        out.status.success(),
        "{stdout}\n{}",
        String::from_utf8_lossy(&out.stderr)
    );
    // Piped: no progress bar.
    assert!(!String::from_utf8_lossy(&out.stderr).contains("fitting"));
    for id in [
        "run-sl-v",
        "run-tflight-sf",
        "run-tflight-sf-continuous",
        "walk-sl-sf",
        "walk-tds-sf",
    ] {
        assert!(stdout.contains(&format!("{id}: n = ")), "{stdout}");
        let v: serde_json::Value = serde_json::from_str(
            &std::fs::read_to_string(d.join(format!("fits/{id}.json"))).unwrap(),
        )
        .unwrap();
        for k in REQUIRED {
            assert!(v.get(k).is_some(), "{id}: key {k} missing");
        }
        for c in v["coefficients"].as_array().unwrap() {
            for k in ["name", "value", "std_error", "ci95", "published"] {
                assert!(c.get(k).is_some(), "{id}: coefficient key {k}");
            }
        }
        assert_eq!(v["data"]["path"], "data/trials.csv");
        assert_eq!(v["data"]["sha256"].as_str().unwrap().len(), 64);
        let t: toml::Value =
            toml::from_str(&std::fs::read_to_string(d.join(format!("fits/{id}.toml"))).unwrap())
                .unwrap();
        assert_eq!(
            t["n"].as_integer().unwrap() as u64,
            v["n"].as_u64().unwrap()
        );
        for suffix in ["", "-residuals", "-residuals-inputs", "-qq"] {
            for ext in ["svg", "png"] {
                let p = d.join(format!("reports/{id}{suffix}.{ext}"));
                assert!(
                    std::fs::metadata(&p)
                        .map(|m| m.len() > 1000)
                        .unwrap_or(false),
                    "{}",
                    p.display()
                );
            }
        }
    }
    let summary = std::fs::read_to_string(d.join("reports/summary.md")).unwrap();
    assert!(summary.contains("uncentred") && summary.contains("jump_at_k1"));

    // The r² gate.
    let ok = gaitfit(d)
        .args(["check", "--fits", "fits", "--min-r2", "0.5"])
        .output()
        .unwrap();
    assert!(ok.status.success());
    let bad = gaitfit(d)
        .args(["check", "--fits", "fits", "--min-r2", "0.95"])
        .output()
        .unwrap();
    assert_eq!(bad.status.code(), Some(1));
    let err = String::from_utf8_lossy(&bad.stderr);
    // The gate is the centred r²: the fit through the origin (walk-sl-sf, uncentred r² ≈ 1)
    // is below the bar on it (issue 18).
    assert!(
        err.contains("run-tflight-sf")
            && err.contains("walk-tds-sf")
            && err.contains("walk-sl-sf (centred"),
        "{err}"
    );
    let unc = gaitfit(d)
        .args(["check", "--fits", "fits", "--min-r2", "0.95", "--uncentred"])
        .output()
        .unwrap();
    let err = String::from_utf8_lossy(&unc.stderr);
    assert!(
        err.contains("walk-tds-sf") && !err.contains("walk-sl-sf"),
        "{err}"
    );

    // Exports.
    let csv = gaitfit(d)
        .args(["export", "--format", "csv"])
        .output()
        .unwrap();
    assert!(csv.status.success());
    let csv = String::from_utf8_lossy(&csv.stdout).to_string();
    assert!(csv
        .lines()
        .next()
        .unwrap()
        .starts_with("relation,coefficient,unit,value"));
    assert!(csv.contains("walk-sl-sf,k,"));
    let json = gaitfit(d)
        .args(["export", "--format", "json"])
        .output()
        .unwrap();
    let arr: serde_json::Value = serde_json::from_slice(&json.stdout).unwrap();
    assert_eq!(arr.as_array().unwrap().len(), 5);
    let tml = gaitfit(d)
        .args(["export", "--format", "toml", "-o", "out/all.toml"])
        .output()
        .unwrap();
    assert!(tml.status.success());
    let t: toml::Value =
        toml::from_str(&std::fs::read_to_string(d.join("out/all.toml")).unwrap()).unwrap();
    assert!(t.get("walk-sl-sf").is_some());

    // Rust: a module that compiles on its own (under a crate root that documents the crate;
    // tests/export_coeffs.rs also checks include! and the values).
    let rs = gaitfit(d)
        .args(["export", "--format", "rust", "-o", "coeffs.rs"])
        .output()
        .unwrap();
    assert!(rs.status.success());
    let src = std::fs::read_to_string(d.join("coeffs.rs")).unwrap();
    assert!(src.contains("pub mod walk_sl_sf {") && src.contains("    pub const K: f64 ="));
    assert!(src.contains("/// `k` of `walk-sl-sf`"));
    std::fs::write(
        d.join("wrapper.rs"),
        "//! Wrapper.\n/// The export.\npub mod coeffs;\n",
    )
    .unwrap();
    let rustc = std::env::var("RUSTC").unwrap_or_else(|_| "rustc".into());
    let out = std::process::Command::new(rustc)
        .current_dir(d)
        .args([
            "--crate-type",
            "lib",
            "--edition",
            "2021",
            "-D",
            "warnings",
            "-D",
            "missing_docs",
            "--emit",
            "metadata",
            "-o",
            "coeffs.rmeta",
            "wrapper.rs",
        ])
        .output()
        .unwrap();
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
}

#[test]
fn a_failed_fit_leaves_existing_fits_untouched_and_exits_1() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    std::fs::create_dir_all(d.join("fits")).unwrap();
    std::fs::write(d.join("fits/walk-tds-sf.json"), "OLD").unwrap();
    std::fs::create_dir_all(d.join("data")).unwrap();
    let mut csv = String::from("subject,gait,step_freq_hz,step_length_m,body_height_m\n");
    for i in 0..10 {
        csv.push_str(&format!(
            "S{},walk,{},0.7,1.8\n",
            i % 3,
            1.7 + 0.02 * i as f64
        ));
    }
    std::fs::write(d.join("data/t.csv"), csv).unwrap();
    let out = gaitfit(d)
        .args(["fit", "--relation", "walk-tds-sf"])
        .output()
        .unwrap();
    assert_eq!(out.status.code(), Some(1));
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(
        err.contains("walk-tds-sf") && err.contains("missing double_support_pct_cycle"),
        "{err}"
    );
    assert_eq!(
        std::fs::read_to_string(d.join("fits/walk-tds-sf.json")).unwrap(),
        "OLD"
    );
    let leftovers = std::fs::read_dir(d.join("fits")).unwrap().count();
    assert_eq!(leftovers, 1);
}

#[test]
fn bad_data_and_bad_relation_are_clear_errors() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    std::fs::write(d.join("t.csv"), "subject,gait,step_length_m\nA,walk,80\n").unwrap();
    let out = gaitfit(d)
        .args(["fit", "--data", "t.csv"])
        .output()
        .unwrap();
    assert_eq!(out.status.code(), Some(1));
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(
        err.contains("t.csv: row 1, column step_length_m") && err.contains("step_length_cm"),
        "{err}"
    );
    let out = gaitfit(d)
        .args(["fit", "--data", "t.csv", "--relation", "run-sl-x"])
        .output()
        .unwrap();
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(
        err.contains("unknown relation `run-sl-x`") && err.contains("run-sl-v"),
        "{err}"
    );
    let out = gaitfit(d)
        .args(["check", "--fits", "nowhere"])
        .output()
        .unwrap();
    assert_eq!(out.status.code(), Some(1));
}
