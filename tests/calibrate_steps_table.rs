//! `gaitfit calibrate` on steps tables (issue 21 item 1: "INPUT is raw measured files or
//! folders … or steps tables"): the committed derived tables of `data/` (one row per step, made
//! by the event pipeline from the shared data), one subject each, calibrated with the committed
//! `fits/`. The gait comes from the table's `gait` column, one condition per trial; the
//! references are the table's measured step quantities. The done-when figures hold on the
//! tables as on the raw files: Hamner subject01 Run_3 cadence within 2 %, step length within
//! 3 %, flight within 15 ms; Schreiber 2014001 double support within 1 % of the cycle at both
//! speeds. Not ignored (data/ is in the repository); a few seconds.
#[path = "common/calibrate.rs"]
mod calibrate_cli;
use std::collections::HashMap;
use std::path::Path;

/// The header and `subject`'s rows of a committed table, written to `dir/name`.
fn one_subject(table: &str, subject: &str, dir: &Path, name: &str) -> std::path::PathBuf {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let text = std::fs::read_to_string(root.join("data").join(table)).unwrap();
    let mut lines = text.lines().filter(|l| !l.starts_with('#'));
    let mut out = vec![lines.next().unwrap().to_string()];
    out.extend(
        lines
            .filter(|l| l.split(',').next() == Some(subject))
            .map(String::from),
    );
    assert!(out.len() > 4, "{subject} not in {table}");
    let p = dir.join(name);
    std::fs::write(&p, out.join("\n") + "\n").unwrap();
    p
}

/// (trial speed in cm/s, quantity) → (measured, generated) of stage `calibrated`.
type Residuals = HashMap<(i64, String), (f64, f64)>;

/// Calibrates `input`; returns stderr and its calibrated residuals.
fn calibrate(input: &Path, out: &Path) -> (String, Residuals) {
    let o = calibrate_cli::run(input, out, &[]);
    let csv = std::fs::read_to_string(out.join("residuals.csv")).unwrap();
    let head: Vec<&str> = csv.lines().next().unwrap().split(',').collect();
    let col = |n: &str| head.iter().position(|h| *h == n).unwrap();
    let mut r = HashMap::new();
    for l in csv.lines().skip(1) {
        let f: Vec<&str> = l.split(',').collect();
        if f[col("stage")] != "calibrated" {
            continue;
        }
        let v: f64 = f[col("speed_m_per_s")].parse().unwrap();
        let num = |i: usize| f[i].parse::<f64>().unwrap_or(f64::NAN);
        r.insert(
            ((v * 100.0).round() as i64, f[col("quantity")].to_string()),
            (num(col("measured")), num(col("generated"))),
        );
    }
    (String::from_utf8_lossy(&o.stderr).into_owned(), r)
}

#[test]
fn hamner_subject01_from_its_steps_table() {
    let dir = tempfile::tempdir().unwrap();
    let t = one_subject("run_hamner2013.csv", "subject01", dir.path(), "steps.csv");
    let (stderr, r) = calibrate(&t, &dir.path().join("out"));
    println!("{stderr}");
    assert!(
        stderr.contains("subject01 (run, 4 condition(s)"),
        "gait from the table's column, one condition per trial: {stderr}"
    );
    // Run_3, 3 m/s.
    let get = |q: &str| {
        *r.get(&(300, q.to_string()))
            .unwrap_or_else(|| panic!("{q}: {r:?}"))
    };
    let (m, g) = get("cadence_steps_per_min");
    assert!((g - m).abs() < 0.02 * m, "cadence {g} vs {m}");
    let (m, g) = get("step_length_m");
    assert!((g - m).abs() < 0.03 * m, "step length {g} vs {m}");
    let (m, g) = get("flight_time_s");
    assert!((g - m).abs() < 0.015, "flight {g} vs {m}");
    // No per-frame data: no pelvis excursion, no angle curves.
    assert!(!r
        .keys()
        .any(|k| k.1 == "pelvis_excursion_m" || k.1.ends_with("_rms_deg")));
}

#[test]
fn schreiber_2014001_from_its_steps_table() {
    let dir = tempfile::tempdir().unwrap();
    let t = one_subject("walk_schreiber2019.csv", "2014001", dir.path(), "steps.csv");
    let (stderr, r) = calibrate(&t, &dir.path().join("out"));
    println!("{stderr}");
    assert!(stderr.contains("2014001 (walk, 2 condition(s)"), "{stderr}");
    let ds: Vec<_> = r
        .iter()
        .filter(|(k, _)| k.1 == "double_support_pct_cycle")
        .collect();
    assert_eq!(ds.len(), 2, "{r:?}");
    for (k, (m, g)) in ds {
        assert!((g - m).abs() < 1.0, "{k:?}: {g} vs {m} % cycle");
    }
}
