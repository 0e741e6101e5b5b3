//! `gaitfit events` run as a binary in a fresh temporary folder, on synthetic trials written as
//! TRC + OpenSim GRF MOT files; and the bad inputs of issue 4 (standing trial, too short, plate
//! drift, marker gaps, missing markers) with clear errors and no partial output.
use assert_cmd::Command;
use gaitfit::events::synthetic::{grf_mot_text, trc_text, SyntheticGait};
use gaitfit::events::{steps_from_trial, EventError, EventOptions};
use gaitfit::ingest::types::{ForcePlate, MarkerSet, Trial};
use std::path::Path;

fn write_trc(path: &Path, m: &MarkerSet) {
    std::fs::write(path, trc_text(&path.display().to_string(), m)).unwrap();
}

fn write_grf_mot(path: &Path, plates: &[ForcePlate]) {
    let text = grf_mot_text(&path.display().to_string(), &plates[1], &plates[0]);
    std::fs::write(path, text).unwrap();
}

fn write_trial(dir: &Path, stem: &str, t: &Trial) {
    write_trc(
        &dir.join(format!("{stem}.trc")),
        t.markers.as_ref().unwrap(),
    );
    write_grf_mot(&dir.join(format!("{stem}_grf.mot")), &t.plates);
}

#[test]
fn writes_steps_comparison_and_plots_from_a_folder() {
    let dir = tempfile::tempdir().unwrap();
    let data = dir.path().join("trials");
    std::fs::create_dir(&data).unwrap();
    let g = SyntheticGait {
        duration_s: 6.0,
        ..SyntheticGait::walk()
    };
    write_trial(&data, "walk", &g.trial());
    let out = dir.path().join("steps.csv");
    let assert = Command::cargo_bin("gaitfit")
        .unwrap()
        .current_dir(dir.path())
        .args(["events", "trials", "-o", "steps.csv", "--compare", "force"])
        .args(["--plots", "plots", "--belt-speed", "1.3"])
        .assert()
        .success();
    let stdout = String::from_utf8_lossy(&assert.get_output().stdout).to_string();
    assert!(
        stdout.contains("zeni_coordinate") && stdout.contains("heel_strike"),
        "{stdout}"
    );
    let csv = std::fs::read_to_string(&out).unwrap();
    let lines: Vec<&str> = csv.lines().collect();
    assert!(lines[0].starts_with("subject,gait,side,source,trial,time_s,speed_m_per_s"));
    assert!(lines.len() > 8, "{csv}");
    // Step length = belt speed × step time (the pelvis holds its place on the belt).
    let t = gaitfit::ingest::trials::read_trials(&out).unwrap();
    for r in t.to_step_rows() {
        let sl = r.step_length_m.unwrap();
        assert!((sl - g.step_length_m()).abs() < 0.03, "{sl}");
    }
    let plot = std::fs::read_to_string(dir.path().join("plots/trials_walk.svg")).unwrap();
    assert!(plot.starts_with("<svg") && plot.contains("polyline"));
    let png = std::fs::read(dir.path().join("plots/trials_walk.png")).unwrap();
    assert!(png.starts_with(b"\x89PNG\r\n\x1a\n"), "not a PNG");
    // A drawn figure, not a blank canvas: many distinct bytes after compression.
    assert!(png.len() > 10_000, "{} bytes", png.len());
}

#[test]
fn a_failing_trial_is_named_and_the_others_are_written() {
    let dir = tempfile::tempdir().unwrap();
    let data = dir.path().join("trials");
    std::fs::create_dir(&data).unwrap();
    write_trial(&data, "walk", &SyntheticGait::walk().trial());
    // A standing trial: markers still, both feet loaded throughout.
    let mut stand = SyntheticGait::walk().trial();
    for t in &mut stand.markers.as_mut().unwrap().positions {
        let p0 = t[0];
        t.iter_mut().for_each(|p| *p = p0);
    }
    for p in &mut stand.plates {
        p.force_n.iter_mut().for_each(|f| f[1] = 350.0);
    }
    write_trial(&data, "standing", &stand);
    let assert = Command::cargo_bin("gaitfit")
        .unwrap()
        .current_dir(dir.path())
        .args([
            "events",
            "trials",
            "-o",
            "steps.csv",
            "--events-out",
            "events.csv",
            "--belt-speed",
            "1.3",
        ])
        .assert()
        .code(1);
    let err = String::from_utf8_lossy(&assert.get_output().stderr).to_string();
    assert!(
        err.contains("standing_grf.mot") || err.contains("standing.trc"),
        "{err}"
    );
    assert!(err.contains("1 of 2 trial(s) failed"), "{err}");
    // The good trial's outputs are there, and only its rows.
    let steps = std::fs::read_to_string(dir.path().join("steps.csv")).unwrap();
    assert!(steps.lines().count() > 2, "{steps}");
    assert!(steps.lines().skip(1).all(|l| l.contains("walk")), "{steps}");
    assert!(!steps.contains("standing"), "{steps}");
    let events = std::fs::read_to_string(dir.path().join("events.csv")).unwrap();
    assert!(events.starts_with("subject,trial,time_s,side,event,method,source\n"));
    assert!(events.contains(",heel_strike,force,") && events.contains(",toe_off,force,"));
    // All of them failing: nothing to write, and the message says so.
    std::fs::remove_file(data.join("walk.trc")).unwrap();
    std::fs::remove_file(data.join("walk_grf.mot")).unwrap();
    let assert = Command::cargo_bin("gaitfit")
        .unwrap()
        .current_dir(dir.path())
        .args(["events", "trials", "-o", "again.csv", "--belt-speed", "1.3"])
        .assert()
        .code(1);
    let err = String::from_utf8_lossy(&assert.get_output().stderr).to_string();
    assert!(err.contains("nothing was written"), "{err}");
    assert!(!dir.path().join("again.csv").exists());
}

#[test]
fn standing_on_markers_only_has_no_events() {
    let mut t = SyntheticGait::walk().trial();
    t.plates.clear();
    for m in &mut t.markers.as_mut().unwrap().positions {
        let p0 = m[0];
        m.iter_mut().for_each(|p| *p = p0);
    }
    let e = steps_from_trial(&t, &EventOptions::default()).unwrap_err();
    assert!(matches!(e, EventError::NoEvents { .. }), "{e}");
    assert!(e.to_string().contains("synthetic.trc"));
}

#[test]
fn too_short_for_a_stride() {
    let g = SyntheticGait {
        duration_s: 0.7,
        ..SyntheticGait::walk()
    };
    let e = steps_from_trial(&g.trial(), &EventOptions::default()).unwrap_err();
    assert!(
        matches!(e, EventError::TooShort { .. } | EventError::NoEvents { .. }),
        "{e}"
    );
    assert!(e.to_string().contains("synthetic.trc"));
}

#[test]
fn plate_offset_is_removed_and_drift_is_named() {
    let mut t = SyntheticGait::walk().trial();
    for f in &mut t.plates[1].force_n {
        f[1] += 30.0;
    }
    let table = steps_from_trial(&t, &EventOptions::default()).unwrap();
    assert!(table.rows.len() > 10);
    let mut t = SyntheticGait::walk().trial();
    let times = t.plates[0].time_s.clone();
    for (f, s) in t.plates[0].force_n.iter_mut().zip(times) {
        f[1] += 4.0 * s; // 40 N over 10 s
    }
    let e = steps_from_trial(&t, &EventOptions::default()).unwrap_err();
    let msg = e.to_string();
    assert!(matches!(e, EventError::PlateDrift { .. }), "{msg}");
    assert!(msg.contains("left belt") && msg.contains("frame"), "{msg}");
    let mut opts = EventOptions::default();
    opts.force.correct_drift = true;
    assert!(steps_from_trial(&t, &opts).is_ok());
}

#[test]
fn marker_gap_names_marker_and_frame() {
    let mut t = SyntheticGait::walk().trial();
    let m = t.markers.as_mut().unwrap();
    let i = m.index("r_heel").unwrap();
    for p in &mut m.positions[i][300..340] {
        *p = [f64::NAN; 3];
    }
    let e = steps_from_trial(&t, &EventOptions::default()).unwrap_err();
    let msg = e.to_string();
    assert!(matches!(e, EventError::MarkerGap { .. }), "{msg}");
    assert!(
        msg.contains("r_heel") && msg.contains("frame 301") && msg.contains("40 frame"),
        "{msg}"
    );
}

#[test]
fn missing_foot_markers_are_named() {
    let mut t = SyntheticGait::walk().trial();
    t.plates.clear();
    let m = t.markers.as_mut().unwrap();
    for n in m.names.iter_mut() {
        if n.ends_with("_heel") {
            *n = format!("{n}_renamed");
        }
    }
    let e = steps_from_trial(&t, &EventOptions::default()).unwrap_err();
    let msg = e.to_string();
    assert!(matches!(e, EventError::Missing { .. }), "{msg}");
    assert!(msg.contains("heel") && msg.contains("--marker"), "{msg}");
}
