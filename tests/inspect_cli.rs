//! `gaitfit inspect FILE [-o frames.csv]` (issue 22): it prints what the reader loaded, and the
//! per-frame CSV it writes reads back — through the same readers `gaitfit events` and `gaitfit
//! fit` use — as the same markers, plates, axes and reference events, and gives the same steps.
use assert_cmd::Command;
use gaitfit::events::synthetic::{grf_mot_text, trc_text, SyntheticGait};
use gaitfit::ingest::types::Trial;
use gaitfit::ingest::{read_trial, ReadOptions};
use std::path::{Path, PathBuf};

fn gaitfit(dir: &Path, args: &[&str]) -> String {
    let out = Command::cargo_bin("gaitfit")
        .unwrap()
        .current_dir(dir)
        .args(args)
        .output()
        .unwrap();
    assert!(
        out.status.success(),
        "{args:?}: {}",
        String::from_utf8_lossy(&out.stderr)
    );
    String::from_utf8_lossy(&out.stdout).into_owned()
}

fn read(p: &Path) -> Trial {
    read_trial(p, &ReadOptions::default()).unwrap_or_else(|e| panic!("{}: {e}", p.display()))
}

/// The per-step table of `gaitfit events`, without the columns that name the file.
fn steps(dir: &Path, input: &Path) -> Vec<Vec<String>> {
    let text = gaitfit(dir, &["events", &input.display().to_string()]);
    let mut lines = text.lines();
    let header: Vec<&str> = lines.next().unwrap().split(',').collect();
    let keep: Vec<usize> = (0..header.len())
        .filter(|&i| !matches!(header[i], "subject" | "source" | "trial"))
        .collect();
    lines
        .map(|l| {
            let c: Vec<&str> = l.split(',').collect();
            keep.iter().map(|&i| c[i].to_string()).collect()
        })
        .collect()
}

/// Markers at 100 Hz and GRF at 1000 Hz (a TRC with its `_grf.mot` companion): the CSV has
/// the plates' times, the plates read back bit for bit, the markers are the TRC's at its own
/// sample times, and `gaitfit events` finds the same steps in both; `gaitfit fit` reads it.
#[test]
fn trc_with_grf_round_trips_through_the_per_frame_csv() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let g = SyntheticGait {
        duration_s: 6.0,
        ..SyntheticGait::walk()
    };
    let t = g.trial();
    let m = t.markers.as_ref().unwrap();
    std::fs::write(d.join("walk.trc"), trc_text("walk.trc", m)).unwrap();
    std::fs::write(
        d.join("walk_grf.mot"),
        grf_mot_text("walk_grf.mot", &t.plates[1], &t.plates[0]),
    )
    .unwrap();
    let printed = gaitfit(d, &["inspect", "walk.trc", "-o", "frames.csv"]);
    let orig = read(&d.join("walk.trc"));
    let back = read(&d.join("frames.csv"));
    let (om, bm) = (
        orig.markers.as_ref().unwrap(),
        back.markers.as_ref().unwrap(),
    );
    let plate_rate = orig.plates[0].rate_hz;
    assert!(plate_rate > om.rate_hz, "{plate_rate} vs {}", om.rate_hz);
    // What was printed is what the reader loaded.
    assert!(printed.contains(&format!(
        "markers: {} at {} Hz, {} frames",
        om.names.len(),
        om.rate_hz,
        om.len()
    )));
    for p in &orig.plates {
        assert!(printed.contains(&format!(
            "  {}: {} Hz, {} samples",
            p.name,
            p.rate_hz,
            p.time_s.len()
        )));
    }
    assert!(printed.contains(&format!("wrote {} frames", orig.plates[0].time_s.len())));
    let f = orig.frame.as_ref().unwrap();
    let fb = back.frame.as_ref().unwrap();
    assert_eq!(
        (f.vertical, f.forward, f.forward_sign),
        (fb.vertical, fb.forward, fb.forward_sign)
    );
    assert_eq!(orig.gait, back.gait);
    // Plates: same names' feet, same samples, bit for bit.
    assert_eq!(orig.plates.len(), back.plates.len());
    for (a, b) in orig.plates.iter().zip(&back.plates) {
        assert_eq!(a.side, b.side, "{}", a.name);
        assert_eq!(a.time_s, b.time_s);
        assert_eq!(a.force_n, b.force_n);
    }
    // Markers: the TRC's samples wherever a CSV frame falls on one (to rounding of the time);
    // between samples, a value between the two neighbouring samples.
    assert_eq!(om.names, bm.names);
    let mut matched = 0;
    for (i, &tb) in bm.time_s.iter().enumerate() {
        let j = om.time_s.partition_point(|&t| t < tb - 1e-9);
        let on_sample = j < om.len() && (om.time_s[j] - tb).abs() < 1e-9;
        matched += usize::from(on_sample);
        for (a, b) in om.positions.iter().zip(&bm.positions) {
            for k in 0..3 {
                let v = b[i][k];
                if on_sample {
                    assert!((a[j][k] - v).abs() < 1e-9, "{} vs {v}", a[j][k]);
                } else if j == 0 || j == om.len() {
                    assert!(v.is_nan(), "outside the markers' record: {v}");
                } else {
                    let (lo, hi) = (a[j - 1][k].min(a[j][k]), a[j - 1][k].max(a[j][k]));
                    assert!(
                        v >= lo - 1e-12 && v <= hi + 1e-12,
                        "{v} not in [{lo}, {hi}]"
                    );
                }
            }
        }
    }
    let common = om
        .time_s
        .iter()
        .filter(|&&t| bm.time_s.iter().any(|&x| (x - t).abs() < 1e-9))
        .count();
    assert!(common > 10);
    assert_eq!(matched, common);
    // Events and fit read it back: the same steps.
    let s1 = steps(d, &d.join("walk.trc"));
    let s2 = steps(d, &d.join("frames.csv"));
    assert!(s1.len() > 5, "{s1:?}");
    assert_eq!(s1.len(), s2.len());
    let header = gaitfit(d, &["events", "walk.trc"]);
    let cols: Vec<&str> = header
        .lines()
        .next()
        .unwrap()
        .split(',')
        .filter(|c| !matches!(*c, "subject" | "source" | "trial"))
        .collect();
    for (a, b) in s1.iter().zip(&s2) {
        for (k, c) in cols.iter().enumerate() {
            // Force-timed events and what follows from them are identical; kinematic values
            // (from markers low-passed at the CSV's rate) agree to their printed precision.
            let (x, y) = (&a[k], &b[k]);
            match (x.parse::<f64>(), y.parse::<f64>()) {
                (Ok(x), Ok(y)) => {
                    assert!((x - y).abs() <= 0.02 * x.abs().max(1.0), "{c}: {x} vs {y}")
                }
                _ => assert_eq!(x, y, "{c}"),
            }
        }
        let t = cols.iter().position(|c| *c == "time_s").unwrap();
        assert_eq!(a[t], b[t], "heel-strike times");
    }
    // `gaitfit fit` reads it (with a second, faster trial: one cadence alone is singular).
    let g2 = SyntheticGait {
        stride_time_s: 0.85 * g.stride_time_s,
        ..g
    };
    let t2 = g2.trial();
    std::fs::write(
        d.join("fast.trc"),
        trc_text("fast.trc", t2.markers.as_ref().unwrap()),
    )
    .unwrap();
    std::fs::write(
        d.join("fast_grf.mot"),
        grf_mot_text("fast_grf.mot", &t2.plates[1], &t2.plates[0]),
    )
    .unwrap();
    gaitfit(d, &["inspect", "fast.trc", "-o", "fast.csv"]);
    let n = s2.len() + steps(d, &d.join("fast.csv")).len();
    let fits = d.join("fits");
    let out = gaitfit(
        d,
        &[
            "fit",
            "--data",
            "frames.csv",
            "fast.csv",
            "--relation",
            "walk-tds-sf",
            "--no-report",
            "--fits",
            &fits.display().to_string(),
        ],
    );
    assert!(out.contains(&format!("walk-tds-sf: n = {n},")), "{out}");
}

/// A motion CSV of `gaitfit generate`: its contact flags (reference events) and landmarks come
/// back unchanged from the inspected copy.
#[test]
fn generated_motion_keeps_its_landmarks_and_contact_events() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    gaitfit(
        d,
        &[
            "generate", "walk", "--speed", "5km/h", "--count", "6", "-o", "walk.csv",
        ],
    );
    let printed = gaitfit(d, &["inspect", "walk.csv", "-o", "frames.csv"]);
    let orig = read(&d.join("walk.csv"));
    let back = read(&d.join("frames.csv"));
    assert!(
        printed.contains("format: gaitfit per-frame CSV"),
        "{printed}"
    );
    assert!(orig.reference_events.len() >= 10);
    assert!(printed.contains(&format!(
        "reference events: {}",
        orig.reference_events.len()
    )));
    assert_eq!(orig.reference_events, back.reference_events);
    let (a, b) = (orig.markers.unwrap(), back.markers.unwrap());
    assert_eq!(a, b);
}

fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

/// A trials table: its rows, subjects and columns are listed, and -o is refused (it has no
/// frames).
#[test]
fn trials_table_is_described_and_has_no_frames_to_write() {
    let p = root().join("data/walk_wbds.csv");
    let t = gaitfit::ingest::trials::read_trials(&p).unwrap();
    let dir = tempfile::tempdir().unwrap();
    let printed = gaitfit(dir.path(), &["inspect", &p.display().to_string()]);
    assert!(printed.contains(&format!("rows: {}", t.len())), "{printed}");
    assert!(printed.contains(&format!("subjects: {}", t.subjects.len())));
    for s in &t.subjects {
        assert!(printed.contains(&format!("  {s}: ")), "{s}");
    }
    assert!(printed.contains("speed_m_per_s: "));
    let out = Command::cargo_bin("gaitfit")
        .unwrap()
        .current_dir(dir.path())
        .args(["inspect", &p.display().to_string(), "-o", "x.csv"])
        .output()
        .unwrap();
    assert!(!out.status.success());
    assert!(String::from_utf8_lossy(&out.stderr).contains("no per-frame data"));
    assert!(!dir.path().join("x.csv").exists());
}

/// Real files of every raw format in ../shared/data: the CSV gives the same steps (the same
/// heel-strike times where the events come from force plates, within one marker frame where
/// they come from markers).
#[test]
#[ignore = "needs ../shared/data"]
fn shared_data_files_round_trip_through_the_per_frame_csv() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    for (rel, frame_s) in [
        ("bmclab/walk1.trc", 0.0),
        ("bmclab/Gait.c3d", 0.01),
        ("wbds/WBDS04walkT05grf.txt", 0.0),
        ("hamner2013/subject03/Run_3_grf.mot", 0.0),
    ] {
        let src = gaitfit::shared_data::require(rel);
        gaitfit(
            d,
            &["inspect", &src.display().to_string(), "-o", "frames.csv"],
        );
        let s1 = steps(d, &src);
        let s2 = steps(d, &d.join("frames.csv"));
        assert!(s1.len() >= 3, "{rel}");
        assert_eq!(s1.len(), s2.len(), "{rel}");
        // time_s is the first kept column after gait and side.
        for (a, b) in s1.iter().zip(&s2) {
            let (x, y): (f64, f64) = (a[2].parse().unwrap(), b[2].parse().unwrap());
            assert!((x - y).abs() <= frame_s + 1e-9, "{rel}: {x} vs {y}");
        }
    }
}
