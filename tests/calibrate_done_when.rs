//! Issue 21's done-when on the shared data, through the CLI with the committed `fits/`:
//! - Hamner et al. (2013) subject01 Run_3 calibrated: cadence within 2 %, step length within
//!   3 %, flight within 15 ms of the measured (force plates), knee angle RMS reported;
//! - Schreiber & Moissenet (2019) 2014001 (C4 and C5, one calibration for both speeds): double
//!   support within 1 % of the cycle of the measured (the file's foot-strike/foot-off events);
//!   and its Ko–Badler stage (each speed generalized from the subject's walk at the other):
//!   the rendered walk, measured by the event pipeline, has the commanded (measured) step length
//!   and cadence within 1 %, and its joint-angle RMS are reported.
//!
//! The references are the measured trials, not gaitfit's earlier output. Ignored by default
//! (needs ../shared/data); a few seconds.
#[path = "common/calibrate.rs"]
mod calibrate_cli;
use std::collections::HashMap;
use std::path::Path;

/// (quantity, speed rounded to cm/s) → (measured, generated) of stage `calibrated`.
fn calibrated(dir: &Path) -> HashMap<(String, i64), (f64, f64)> {
    stage(dir, "calibrated")
}

/// (quantity, speed rounded to cm/s) → (measured, generated) of stage `which`.
fn stage(dir: &Path, which: &str) -> HashMap<(String, i64), (f64, f64)> {
    let text = std::fs::read_to_string(dir.join("residuals.csv")).expect("residuals.csv");
    let mut lines = text.lines();
    let head: Vec<&str> = lines.next().expect("header").split(',').collect();
    let col = |name: &str| head.iter().position(|h| *h == name).expect(name);
    let (q, v, m, g, st) = (
        col("quantity"),
        col("speed_m_per_s"),
        col("measured"),
        col("generated"),
        col("stage"),
    );
    let mut out = HashMap::new();
    for l in lines {
        let f: Vec<&str> = l.split(',').collect();
        if f[st] != which {
            continue;
        }
        let num = |i: usize| f[i].parse::<f64>().unwrap_or(f64::NAN);
        out.insert(
            (f[q].to_string(), (num(v) * 100.0).round() as i64),
            (num(m), num(g)),
        );
    }
    out
}

/// The (speed in cm/s, (measured, generated)) pairs of one quantity in a stage's residuals.
fn quantity(r: &HashMap<(String, i64), (f64, f64)>, q: &str) -> Vec<(i64, (f64, f64))> {
    r.iter()
        .filter(|(k, _)| k.0 == q)
        .map(|(k, v)| (k.1, *v))
        .collect()
}

fn calibrate(input: &Path, out: &Path) {
    calibrate_with(input, out, &[]);
}

fn calibrate_with(input: &Path, out: &Path, extra: &[&str]) {
    calibrate_cli::run(input, out, extra);
}

#[test]
#[ignore = "needs ../shared/data"]
fn hamner_run_3_calibrated() {
    let trial = gaitfit::shared_data::require("hamner2013/subject01/Run_3.trc");
    let tmp = tempfile::tempdir().expect("temp dir");
    calibrate(&trial, tmp.path());
    let r = calibrated(tmp.path());
    let get = |q: &str| {
        r.iter()
            .find(|(k, _)| k.0 == q)
            .map(|(_, v)| *v)
            .unwrap_or_else(|| panic!("{q} missing: {r:?}"))
    };
    let (m, g) = get("cadence_steps_per_min");
    println!("cadence {m:.2} → {g:.2} steps/min");
    assert!((g - m).abs() < 0.02 * m, "cadence {g} vs {m}");
    let (m, g) = get("step_length_m");
    println!("step length {m:.4} → {g:.4} m");
    assert!((g - m).abs() < 0.03 * m, "step length {g} vs {m}");
    let (m, g) = get("flight_time_s");
    println!("flight {m:.4} → {g:.4} s");
    assert!((g - m).abs() < 0.015, "flight {g} vs {m}");
    let (_, knee) = get("knee_flexion_rms_deg");
    println!("knee RMS {knee:.1}°");
    assert!(knee.is_finite() && knee > 0.0, "knee RMS {knee}");
    // Pearson's r of the two knee curves: measured 1, generated r.
    let (m, r) = get("knee_flexion_corr");
    println!("knee correlation {r:.3}");
    assert!(
        m == 1.0 && (-1.0..=1.0).contains(&r),
        "knee r {r} (measured {m})"
    );
    converged_before_the_cap(tmp.path());
}

/// The trust region stopped on a convergence test, before the default iteration cap (50).
fn converged_before_the_cap(dir: &Path) {
    let text = std::fs::read_to_string(dir.join("calibrated.json")).expect("calibrated.json");
    let json: serde_json::Value = serde_json::from_str(&text).expect("json");
    for s in json["subjects"].as_array().expect("subjects") {
        let solver = &s["solver"];
        println!("{}: {solver}", s["subject"]);
        assert_eq!(solver["converged"], true, "{solver}");
        assert!(
            solver["iterations"].as_u64().expect("iterations") < 50,
            "{solver}"
        );
    }
}

#[test]
#[ignore = "needs ../shared/data"]
fn schreiber_2014001_double_support() {
    let dir = gaitfit::shared_data::require("schreiber2019/2014001/dynamic");
    let tmp = tempfile::tempdir().expect("temp dir");
    calibrate(&dir, tmp.path());
    let r = calibrated(tmp.path());
    let ds = quantity(&r, "double_support_pct_cycle");
    assert_eq!(ds.len(), 2, "C4 and C5: {r:?}");
    for (v, (m, g)) in ds {
        println!(
            "{:.2} m/s: double support {m:.2} → {g:.2} % cycle",
            v as f64 / 100.0
        );
        assert!((g - m).abs() < 1.0, "{v} cm/s: {g} vs {m} % cycle");
    }
    converged_before_the_cap(tmp.path());
    let kb = stage(tmp.path(), "ko-badler");
    for q in ["step_length_m", "cadence_steps_per_min"] {
        let rows: Vec<_> = kb.iter().filter(|(k, _)| k.0 == q).collect();
        assert_eq!(rows.len(), 2, "Ko–Badler {q} at C4 and C5: {kb:?}");
        for ((_, v), (m, g)) in rows {
            println!("Ko–Badler {v} cm/s: {q} {m:.4} → {g:.4}");
            assert!((g - m).abs() < 0.01 * m, "Ko–Badler {q} {g} vs {m}");
        }
    }
    for q in [
        "hip_flexion_rms_deg",
        "knee_flexion_rms_deg",
        "ankle_dorsiflexion_rms_deg",
    ] {
        for ((name, v), (_, g)) in kb.iter().filter(|(k, _)| k.0 == q) {
            println!("Ko–Badler {v} cm/s: {name} {g:.1}");
            assert!(g.is_finite(), "{name} {g}");
        }
    }
}

#[test]
#[ignore = "needs ../shared/data"]
fn schreiber_2014001_carried_ko_badler_keeps_the_subjects_knee() {
    // `--kb-variant carried` draws each speed from the subject's own walk at the other speed
    // with that walk's measured angle curves carried in W: the feet are still the paper's (the
    // same step length and cadence), and the knee, which the paper's rigid drawing misses most,
    // comes nearer the subject's own (measured against the markers of the generated trial).
    let dir = gaitfit::shared_data::require("schreiber2019/2014001/dynamic");
    let paper = tempfile::tempdir().expect("temp dir");
    let carried = tempfile::tempdir().expect("temp dir");
    calibrate_with(&dir, paper.path(), &["--kb-variant", "paper"]);
    calibrate_with(&dir, carried.path(), &["--kb-variant", "carried"]);
    let (p, c) = (
        stage(paper.path(), "ko-badler"),
        stage(carried.path(), "ko-badler"),
    );
    for q in ["step_length_m", "cadence_steps_per_min"] {
        for ((name, v), (m, g)) in c.iter().filter(|(k, _)| k.0 == q) {
            println!("carried {v} cm/s: {name} {m:.4} → {g:.4}");
            assert!((g - m).abs() < 0.01 * m, "carried {name} {g} vs {m}");
        }
    }
    let knees: Vec<_> = c
        .iter()
        .filter(|(k, _)| k.0 == "knee_flexion_rms_deg")
        .collect();
    assert_eq!(knees.len(), 2, "C4 and C5: {c:?}");
    for (k, (_, g)) in knees {
        let (_, gp) = p[k];
        println!("{} cm/s: knee RMS paper {gp:.1}°, carried {g:.1}°", k.1);
        assert!(
            *g < gp,
            "{k:?}: carried {g} not nearer than the paper's {gp}"
        );
    }
}

/// Schreiber 2014004 and 2014007 (two speeds each, one calibration per subject): double
/// support within 1 % of the cycle at both speeds. Before the trust-region solver, Gauss–Newton's
/// first step from a noisy finite-difference Jacobian left the attributes' bounds and the start
/// was kept (2014007: −1.8 / −4.0 % cycle at 0.92 / 1.34 m/s).
#[test]
#[ignore = "needs ../shared/data"]
fn schreiber_2014004_2014007_double_support() {
    for subject in ["2014004", "2014007"] {
        let dir = gaitfit::shared_data::require(format!("schreiber2019/{subject}/dynamic"));
        let tmp = tempfile::tempdir().expect("temp dir");
        calibrate(&dir, tmp.path());
        let r = calibrated(tmp.path());
        let ds = quantity(&r, "double_support_pct_cycle");
        assert_eq!(ds.len(), 2, "{subject}: two speeds: {r:?}");
        for (v, (m, g)) in ds {
            println!("{subject} {v} cm/s: double support {m:.2} → {g:.2} % cycle");
            assert!(
                (g - m).abs() < 1.0,
                "{subject} {v} cm/s: {g} vs {m} % cycle"
            );
        }
    }
}

/// `--leave-one-speed-out` predicts every one of Hamner subject01's four speeds from a
/// calibration on the other three (stage `held-out`), with and without `--speed-slopes`. A
/// prediction cannot fit its condition better than the calibration that saw it, so the
/// held-out objective terms exceed the calibrated ones in total (printed: the figures of the
/// report, constant offsets against speed slopes).
#[test]
#[ignore = "needs ../shared/data"]
fn hamner_leave_one_speed_out() {
    let dir = gaitfit::shared_data::require("hamner2013/subject01");
    for extra in [&[][..], &["--speed-slopes"][..]] {
        let tmp = tempfile::tempdir().expect("temp dir");
        let mut args = vec!["--leave-one-speed-out"];
        args.extend(extra);
        calibrate_with(&dir, tmp.path(), &args);
        let (cal, held) = (calibrated(tmp.path()), stage(tmp.path(), "held-out"));
        let mut sums = [0.0f64; 2];
        for (q, unit) in [
            ("cadence_steps_per_min", 1.0),
            ("step_length_m", 100.0),
            ("flight_time_s", 1000.0),
        ] {
            let mut rows: Vec<_> = held.iter().filter(|(k, _)| k.0 == q).collect();
            rows.sort_by_key(|(k, _)| k.1);
            assert_eq!(rows.len(), 4, "{q}: held out at four speeds: {held:?}");
            let mut line = format!("{extra:?} {q}:");
            for (k, (m, g)) in rows {
                let (_, gc) = cal[k];
                assert!(g.is_finite(), "{k:?} held out {g}");
                line += &format!(
                    " {:.2} m/s {:+.1}/{:+.1}",
                    k.1 as f64 / 100.0,
                    unit * (gc - m),
                    unit * (g - m)
                );
                sums[0] += ((gc - m) * unit).abs();
                sums[1] += ((g - m) * unit).abs();
            }
            println!("{line} (calibrated/held out)");
        }
        assert!(
            sums[1] > sums[0],
            "{extra:?}: held out {} vs calibrated {}",
            sums[1],
            sums[0]
        );
    }
}

/// A force-only MOT (Hamner's GRF without its TRC) is timed by the forces but has no distance:
/// calibrate says that step lengths are missing and why, naming the file once, instead of
/// calling the trial "too short for one stride".
#[test]
#[ignore = "needs ../shared/data"]
fn a_force_only_mot_says_what_is_missing() {
    let grf = gaitfit::shared_data::require("hamner2013/subject01/Run_2_grf.mot");
    let tmp = tempfile::tempdir().expect("temp dir");
    let mot = tmp.path().join("Run_2_grf.mot");
    std::fs::copy(&grf, &mot).expect("copy the MOT alone");
    let out = assert_cmd::Command::cargo_bin("gaitfit")
        .expect("the gaitfit binary")
        .arg("calibrate")
        .arg(&mot)
        .arg("--fits")
        .arg(Path::new(env!("CARGO_MANIFEST_DIR")).join("fits"))
        .arg("--out")
        .arg(tmp.path().join("cal"))
        .assert()
        .failure()
        .get_output()
        .clone();
    let err = String::from_utf8_lossy(&out.stderr);
    println!("{err}");
    assert!(err.contains("missing step lengths"), "{err}");
    assert!(
        err.contains("force data alone measures no distance"),
        "{err}"
    );
    assert_eq!(err.matches("Run_2_grf.mot").count(), 1, "{err}");
    assert!(!tmp.path().join("cal").join("report.html").exists());
}
