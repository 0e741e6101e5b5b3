//! The readers on the real shared data sets (`../shared/data`), checked against facts stated by
//! the data sets' documentation (`../shared/data/README.md`, `hamner2013/README.md`) or read off
//! the files by hand (first rows, headers).
use gaitfit::events::Side;
use gaitfit::ingest::types::{Axis, Setting, Trial};
use gaitfit::ingest::{mot, read_trial, ReadOptions};
use gaitfit::shared_data::require;

fn read(rel: &str) -> Trial {
    let p = require(rel);
    match read_trial(&p, &ReadOptions::default()) {
        Ok(t) => t,
        Err(e) => panic!("{rel}: {e}"),
    }
}

fn y_up_x_forward(t: &Trial) {
    let f = t
        .frame
        .as_ref()
        .unwrap_or_else(|| panic!("{}: no frame: {:?}", t.name, t.notes));
    assert_eq!(
        (f.vertical, f.forward, f.forward_sign),
        (Axis::Y, Axis::X, 1.0),
        "{}",
        f.how
    );
}

#[test]
#[ignore = "needs ../shared/data"]
fn winter_table_a1() {
    let t = read("bmclab/WinterTableA1.txt");
    let m = t.markers.as_ref().unwrap();
    assert_eq!(m.len(), 106);
    assert_eq!(m.rate_hz, 69.9);
    assert_eq!(m.names.len(), 8);
    y_up_x_forward(&t);
    // Frame 1 rib cage (46.98, 104.41) cm (first data row of the table).
    let rib = m.get("RIB CAGE").unwrap();
    assert!((rib[0][0] - 0.4698).abs() < 1e-12 && (rib[0][1] - 1.0441).abs() < 1e-12);
    // Right heel strikes near frames 28 and 97 (README): the heel is lowest there.
    let heel = m.get("RIGHT HEEL").unwrap();
    let lowest = |a: usize, b: usize| {
        (a..=b)
            .min_by(|&i, &j| heel[i - 1][1].total_cmp(&heel[j - 1][1]))
            .unwrap()
    };
    assert_eq!(lowest(20, 40), 28);
    assert_eq!(lowest(85, 106), 97);
    // Stride ≈ 1.41 m, speed ≈ 1.43 m/s (README).
    let stride = heel[96][0] - heel[27][0];
    assert!((stride - 1.41).abs() < 0.02, "stride {stride}");
    let speed = stride / (m.time_s[96] - m.time_s[27]);
    assert!((speed - 1.43).abs() < 0.03, "speed {speed}");
    assert!(t.subject.body_height_m.is_none());
}

#[test]
#[ignore = "needs ../shared/data"]
fn winter_wn35b_is_in_metres_and_matches_table_a1() {
    let raw = read("bmclab/WinterTableA1.txt");
    let t = read("bmclab/wn35b.txt");
    assert!(
        t.notes
            .iter()
            .any(|n| n.contains("header says cm") && n.contains("in m")),
        "{:?}",
        t.notes
    );
    let (a, b) = (raw.markers.unwrap(), t.markers.unwrap());
    assert_eq!(b.len(), 106);
    assert_eq!(a.names, b.names);
    // Filtered vs raw: same landmarks within a few cm in every frame.
    for (ta, tb) in a.positions.iter().zip(&b.positions) {
        for (pa, pb) in ta.iter().zip(tb) {
            assert!((pa[0] - pb[0]).abs() < 0.03 && (pa[1] - pb[1]).abs() < 0.03);
        }
    }
}

#[test]
#[ignore = "needs ../shared/data"]
fn bmclab_walk_trc_with_forces() {
    let t = read("bmclab/walk1.trc");
    let m = t.markers.as_ref().unwrap();
    assert_eq!((m.rate_hz, m.names.len(), m.len()), (150.0, 28, 364));
    y_up_x_forward(&t);
    assert_eq!(t.setting, Setting::Overground);
    // First data row, R.ASIS = (-148.01762, 1039.82568, -479.70297) mm.
    let asis = m.get("R.ASIS").unwrap()[0];
    assert!((asis[0] + 0.14801762).abs() < 1e-12 && (asis[1] - 1.03982568).abs() < 1e-12);
    // walk1.forces: 7 plates at 450 Hz, 1092 samples, same duration as the markers.
    assert_eq!(t.plates.len(), 7);
    for p in &t.plates {
        assert_eq!((p.rate_hz, p.time_s.len()), (450.0, 1092));
    }
    let loaded: Vec<&str> = t
        .plates
        .iter()
        .filter(|p| p.force_n.iter().any(|f| f[1] > 100.0))
        .map(|p| p.name.as_str())
        .collect();
    assert_eq!(loaded, ["FP3", "FP4", "FP5", "FP6"]);
    // Peak vertical force of a walking step: 1–1.4 body weights of a ~60–90 kg adult.
    let peak = t
        .plates
        .iter()
        .flat_map(|p| p.force_n.iter().map(|f| f[1]))
        .fold(0.0, f64::max);
    assert!((600.0..1300.0).contains(&peak), "peak {peak}");
    for (rel, frames) in [("bmclab/walk.trc", 184), ("bmclab/walk2.trc", 251)] {
        let t = read(rel);
        let m = t.markers.as_ref().unwrap();
        assert_eq!((m.names.len(), m.len()), (28, frames), "{rel}");
        y_up_x_forward(&t);
    }
}

#[test]
#[ignore = "needs ../shared/data"]
fn bmclab_running_trial() {
    let t = read("bmclab/motion_capture_run.trc");
    let m = t.markers.as_ref().unwrap();
    assert_eq!((m.rate_hz, m.names.len(), m.len()), (150.0, 78, 123));
    y_up_x_forward(&t);
    let g = read("bmclab/grf_run.mot");
    assert_eq!(g.plates.len(), 2);
    assert_eq!(g.plates[0].side, Some(Side::Right));
    assert_eq!(g.plates[1].side, Some(Side::Left));
    assert_eq!(g.plates[0].rate_hz, 300.0);
    assert_eq!(g.plates[0].time_s.len(), 246);
    y_up_x_forward(&g);
    // Real flight phases: samples where neither foot is loaded, between stances.
    let n = g.plates[0].force_n.len();
    let flight = (0..n)
        .filter(|&i| g.plates.iter().all(|p| p.force_n[i][1] < 20.0))
        .count();
    assert!(flight > 20, "{flight} flight samples");
    let ik = mot::read_table(&require("bmclab/ik_output_run.mot")).unwrap();
    assert_eq!(ik.time_s.len(), 122);
    assert_eq!(ik.names.len(), 39);
    assert_eq!(ik.in_degrees, Some(true));
    // First row: knee_angle_r = 18.53939731° (converted to radians).
    let k = ik.column("knee_angle_r").unwrap()[0];
    assert!((k - 18.53939731f64.to_radians()).abs() < 1e-12);
}

#[test]
#[ignore = "needs ../shared/data"]
fn hamner_running_grf_and_subjects() {
    let masses = [
        ("subject01", 72.84, 1000.0),
        ("subject02", 76.48, 960.0),
        ("subject03", 64.00, 2000.0),
        ("subject04", 80.47, 2000.0),
        ("subject08", 82.37, 1000.0),
    ];
    for (s, mass, rate) in masses {
        for v in 2..=5 {
            let rel = format!("hamner2013/{s}/Run_{v}_grf.mot");
            let t = read(&rel);
            assert_eq!(
                t.setting,
                Setting::Treadmill {
                    belt_speed_m_per_s: v as f64
                },
                "{rel}"
            );
            assert_eq!(t.gait, Some(gaitfit::events::Gait::Run));
            assert_eq!(t.subject.mass_kg, Some(mass), "{rel}");
            assert_eq!(t.plates.len(), 2);
            assert_eq!(t.plates[0].side, Some(Side::Right));
            assert_eq!(t.plates[1].side, Some(Side::Left));
            assert_eq!(t.plates[0].rate_hz, rate, "{rel}");
            y_up_x_forward(&t);
            let leg = t.subject.leg_length_m.unwrap();
            assert!((0.85..1.10).contains(&leg), "{rel}: leg {leg}");
            let h = t.subject.body_height_m.unwrap();
            assert!((1.6..2.0).contains(&h), "{rel}: height {h}");
        }
    }
    // subject01's running markers and static trial.
    let t = read("hamner2013/subject01/Run_3.trc");
    let m = t.markers.as_ref().unwrap();
    assert_eq!((m.rate_hz, m.names.len(), m.len()), (100.0, 42, 475));
    assert_eq!(m.time_s[0], 0.05);
    assert_eq!(t.plates.len(), 2, "Run_3_grf.mot read as companion");
    y_up_x_forward(&t);
    let s = read("hamner2013/subject01/static.trc");
    assert_eq!(s.markers.as_ref().unwrap().names.len(), 64);
    assert_eq!(s.markers.as_ref().unwrap().len(), 397);
}

#[test]
#[ignore = "needs ../shared/data"]
fn wbds_treadmill_subject04() {
    // WBDSinfo.csv: subject 04, 184 cm, 61.05 kg, leg ≈ 0.94 m; speeds 1.30–1.88 m/s.
    for (trial, speed) in [("T05", 1.30), ("T06", 1.49), ("T07", 1.69), ("T08", 1.88)] {
        let rel = format!("wbds/WBDS04walk{trial}grf.txt");
        let t = read(&rel);
        assert_eq!(
            t.setting,
            Setting::Treadmill {
                belt_speed_m_per_s: speed
            },
            "{rel}"
        );
        assert_eq!(t.gait, Some(gaitfit::events::Gait::Walk));
        assert_eq!(t.subject.id.as_deref(), Some("WBDS04"));
        assert_eq!(t.subject.body_height_m, Some(1.84));
        assert_eq!(t.subject.mass_kg, Some(61.05));
        let leg = t.subject.leg_length_m.unwrap();
        assert!((leg - 0.94).abs() < 0.01, "{rel}: leg {leg}");
        assert_eq!(t.plates.len(), 2);
        for p in &t.plates {
            assert_eq!(p.rate_hz, 300.0);
            assert_eq!(p.time_s.len(), 9000, "30 s at 300 Hz");
            assert!((p.time_s[8999] - 29.99667).abs() < 1e-4);
        }
        y_up_x_forward(&t);
        // Belt 2 lies on the subject's right (+Z when walking toward +X with Y up).
        assert_eq!(t.plates[0].side, Some(Side::Left), "{:?}", t.notes);
        assert_eq!(t.plates[1].side, Some(Side::Right));
        // Body weight check: mean total vertical force ≈ 61.05 kg × g. Measured: 563 N at T05,
        // i.e. 57.4 kg (−6 %); the export zeroes forces below its own threshold (the unloaded
        // belt reads exactly 0), which loses part of the loading ramps.
        let n = t.plates[0].force_n.len();
        let mean: f64 = (0..n)
            .map(|i| t.plates[0].force_n[i][1] + t.plates[1].force_n[i][1])
            .sum::<f64>()
            / n as f64;
        assert!(
            (mean / (61.05 * 9.81) - 1.0).abs() < 0.08,
            "{rel}: mean Fy {mean}"
        );
    }
}

/// Loaded interval (vertical force above 20 N) of a plate: (first, last) sample times.
fn loaded_interval(p: &gaitfit::ingest::types::ForcePlate, up: usize) -> Option<(f64, f64)> {
    let first = p.force_n.iter().position(|f| f[up] > 20.0)?;
    let last = p.force_n.iter().rposition(|f| f[up] > 20.0)?;
    Some((p.time_s[first], p.time_s[last]))
}

#[test]
#[ignore = "needs ../shared/data"]
fn c3d_gait_sample() {
    let t = read("bmclab/Gait.c3d");
    let m = t.markers.as_ref().unwrap();
    assert_eq!((m.rate_hz, m.names.len(), m.len()), (100.0, 33, 487));
    assert!(
        t.notes
            .iter()
            .any(|n| n.contains("Dec processor, integer data")),
        "{:?}",
        t.notes
    );
    // Frame 200 RASI, as read independently by the Python `c3d` package (0.5):
    // (1198.927, 90.479, 906.506) mm.
    let rasi = m.get("RASI").unwrap()[199];
    for (a, b) in rasi.iter().zip([1.198927, 0.090479, 0.906506]) {
        assert!((a - b).abs() < 2e-6, "{rasi:?}");
    }
    let f = t.frame.as_ref().unwrap();
    assert_eq!(
        (f.vertical, f.forward, f.forward_sign),
        (Axis::Z, Axis::X, -1.0),
        "{}",
        f.how
    );
    assert_eq!(t.plates.len(), 2);
    for p in &t.plates {
        assert_eq!((p.rate_hz, p.time_s.len()), (1000.0, 4870));
        let peak = p.force_n.iter().map(|f| f[2]).fold(0.0, f64::max);
        assert!((700.0..1000.0).contains(&peak), "{}: peak {peak}", p.name);
        let (a, b) = loaded_interval(p, 2).unwrap();
        assert!((0.45..0.75).contains(&(b - a)), "walking stance {}", b - a);
    }
    assert!(t.reference_events.is_empty());
}

#[test]
#[ignore = "needs ../shared/data"]
fn c3d_schreiber_dynamic_trials() {
    // SUBJECT:VALUES per participant (age, gender, weight kg, height m, R/L leg length m), as
    // read independently by the Python `c3d` package.
    let subjects = [
        ("2014001", 67.0, 1.655, 0.731, 0.735),
        ("2014004", 72.5, 1.77, 0.829, 0.848),
        ("2014007", 65.0, 1.69, 0.837, 0.838),
        ("2014014", 92.0, 1.80, 0.842, 0.847),
        ("2014015", 67.0, 1.58, 0.716, 0.708),
        ("2014019", 73.8, 1.755, 0.819, 0.828),
    ];
    let root = require("schreiber2019");
    let mut files = 0;
    for (id, mass, height, rleg, lleg) in subjects {
        let dir = root.join(id).join("dynamic");
        let mut names: Vec<_> = std::fs::read_dir(&dir)
            .unwrap()
            .map(|e| e.unwrap().path())
            .filter(|p| p.extension().is_some_and(|e| e == "c3d"))
            .collect();
        names.sort();
        assert_eq!(names.len(), 2, "{id}: C4 and C5");
        for p in names {
            files += 1;
            let t = read_trial(&p, &ReadOptions::default()).unwrap();
            let m = t.markers.as_ref().unwrap();
            assert_eq!((m.rate_hz, m.names.len()), (100.0, 52));
            assert_eq!(t.subject.mass_kg, Some(mass));
            assert!((t.subject.body_height_m.unwrap() - height).abs() < 1e-3);
            assert!((t.subject.leg_length_m.unwrap() - (rleg + lleg) / 2.0).abs() < 1e-3);
            assert_eq!(t.gait, Some(gaitfit::events::Gait::Walk));
            assert_eq!(t.setting, Setting::Overground);
            let f = t.frame.as_ref().unwrap();
            assert_eq!(f.vertical, Axis::Z, "{}", f.how);
            assert_eq!(t.reference_events.len(), 7, "{}", p.display());
            assert!(t
                .reference_events
                .iter()
                .all(|e| e.source == gaitfit::events::EventSource::Reference));
            assert_eq!(t.plates.len(), 2);
            // Every plate loaded by one whole stance starts and ends within 40 ms (4 marker
            // frames) of a reference foot strike / foot off (measured: ≤ 27 ms; the reference
            // events are at marker-frame resolution and were not set from the 20 N threshold).
            for pl in &t.plates {
                assert_eq!(pl.rate_hz, 1500.0);
                let Some((a, b)) = loaded_interval(pl, 2) else {
                    continue;
                };
                if a < 0.01 || b > pl.time_s[pl.time_s.len() - 1] - 0.01 {
                    continue;
                }
                let near = |k: gaitfit::events::EventKind, at: f64| t_min(&t_events(&t, k), at);
                let hs = near(gaitfit::events::EventKind::HeelStrike, a);
                let to = near(gaitfit::events::EventKind::ToeOff, b);
                println!(
                    "{} {}: onset-strike {hs:.3} s, end-off {to:.3} s",
                    p.display(),
                    pl.name
                );
                assert!(
                    hs < 0.04,
                    "{} {}: onset {a} is {hs} s from a strike",
                    p.display(),
                    pl.name
                );
                assert!(
                    to < 0.04,
                    "{} {}: end {b} is {to} s from a foot off",
                    p.display(),
                    pl.name
                );
            }
        }
    }
    assert_eq!(files, 12);
    // 2014001_C4_05 frame 51, first marker (L_IAS) = (491.302, 125.429, 851.317) mm (Python
    // `c3d`).
    let t = read("schreiber2019/2014001/dynamic/2014001_C4_05.c3d");
    let p = t.markers.as_ref().unwrap().positions[0][50];
    for (a, b) in p.iter().zip([0.491302, 0.125429, 0.851317]) {
        assert!((a - b).abs() < 2e-6, "{p:?}");
    }
    // The static trials and the inverse-kinematics tables read too.
    for id in [
        "2014001", "2014004", "2014007", "2014014", "2014015", "2014019",
    ] {
        let t = read(&format!("schreiber2019/{id}/static/{id}_ST.c3d"));
        let m = t.markers.as_ref().unwrap();
        assert_eq!(
            (m.names.len(), m.len()),
            (52, 1),
            "static trials hold one averaged frame"
        );
        for e in std::fs::read_dir(root.join(id).join("ik")).unwrap() {
            for f in std::fs::read_dir(e.unwrap().path()).unwrap() {
                let f = f.unwrap().path();
                let table = mot::read_table(&f).unwrap_or_else(|e| panic!("{e}"));
                assert!(
                    table.time_s.len() > 20 && table.in_degrees == Some(true),
                    "{}",
                    f.display()
                );
            }
        }
    }
}

fn t_events(t: &Trial, k: gaitfit::events::EventKind) -> Vec<f64> {
    t.reference_events
        .iter()
        .filter(|e| e.kind == k)
        .map(|e| e.time_s)
        .collect()
}

fn t_min(v: &[f64], t: f64) -> f64 {
    v.iter()
        .map(|x| (x - t).abs())
        .fold(f64::INFINITY, f64::min)
}

#[test]
#[ignore = "needs ../shared/data"]
fn every_shared_motion_file_reads() {
    // Every file of the gait data sets that read_trial knows, read with default options.
    let root = require("bmclab").parent().unwrap().to_path_buf();
    let mut stack = vec![root.clone()];
    let mut count = 0;
    while let Some(dir) = stack.pop() {
        for e in std::fs::read_dir(&dir).unwrap() {
            let p = e.unwrap().path();
            if p.is_dir() {
                if !p.ends_with("nist-strd") {
                    stack.push(p);
                }
                continue;
            }
            let name = p.file_name().unwrap().to_string_lossy().to_string();
            let known = ["trc", "mot", "forces", "c3d"]
                .iter()
                .any(|x| name.ends_with(&format!(".{x}")))
                || name.ends_with("grf.txt")
                || name == "WinterTableA1.txt"
                || name == "wn35b.txt";
            if !known {
                continue;
            }
            let t = read_trial(&p, &ReadOptions::default())
                .unwrap_or_else(|e| panic!("{}: {e}", p.display()));
            assert!(
                t.markers.is_some()
                    || !t.plates.is_empty()
                    || name.ends_with("_ik.mot")
                    || name == "ik_output_run.mot",
                "{}: nothing read",
                p.display()
            );
            count += 1;
        }
    }
    // bmclab 11, hamner 20 GRF + 4 Run trc + 5 static, wbds 4, schreiber 12 + 6 + 12 ik.
    assert_eq!(count, 74, "files read");
}
