//! Walking events from markers alone (issue 19): `--events kinematic` (foot_speed for a walk,
//! told from the data) against the force-plate events (20 N on the unfiltered force), every
//! plate event inside the marker record scored. Schreiber's plate events are read from
//! `tools/events/schreiber_force_events.csv` (tools/events/force_truth.py: ezc3d's plate
//! extraction and numpy, no gaitfit; gaitfit's own plate events agree within 0.01 ms,
//! tests/events_force_timing.rs); the BMClab walks' from `bmclab_walk_force_events.csv` (the
//! same script reading the Cortex `.forces` table; gaitfit within 0.01 ms). Each Schreiber & Moissenet (2019) record starts about 0.05 s before a
//! plate heel strike, which the Zeni seeds cannot see.
//!
//! Sets: Schreiber subjects 2014001/2014004/2014007 ("train": where the alternative heel-strike
//! fraction 0.3 was chosen and the tangent onset was first tried), subjects
//! 2014014/2014015/2014019 and the BMClab overground walks (another lab, marker set and plate
//! system), held out. 12 of Schreiber's 24 plate heel strikes lie in the first 0.1 s of their
//! record, one BMClab plate event in the first and one in the last 0.1 s.
//!
//! Heel strike by the tangent onset (`--events kinematic`'s default, scale-free: where the
//! tangent at the steepest descent of the heel's speed over the ground reaches zero), aim of
//! Build item 2: recall ≥ 0.99 including record starts and ends, mean within 15 ms. Measured:
//! train −0.9 ± 9.2 ms, held out +1.2 ± 12.0 ms, all 12 +0.2 ± 10.5 ms, BMClab −6.8 ± 8.3 ms,
//! recall 1.000 everywhere (gaitkit's BIKE on the same 12: −20.2 ± 12.1 ms).
//!
//! Heel strike by Bonci's 0.5 × walking speed (`--walk-heel-strike fraction`; the default of
//! `--events foot-speed` and of auto's marker-only walks) — aim of issue 19's
//! done-when: mean |error| ≤ 15 ms, SD ≤ 12 ms, recall ≥ 0.95 including record starts. Its
//! recall is 11 of 12 on the held-out Schreiber subjects (2014015_C4_04's left heel strike,
//! whose crossing precedes the record), and on BMClab its heel strike is 16.6 ms early on
//! average, past the 15 ms aim: the bias of a self-selected walking speed, as on Schreiber's
//! C4 walks (the last test measures it). 0.3 × speed is printed beside them.
use gaitfit::events::compare::{compare, Coverage, KindCounts, DEFAULT_TOLERANCE_S};
use gaitfit::events::kinematic::WalkHeelStrike;
use gaitfit::events::{
    analyse, EventKind, EventOptions, EventSource, GaitEvent, PrimarySource, Side,
};
use gaitfit::ingest::{read_trial, ReadOptions};
use gaitfit::shared_data::require;
use std::collections::BTreeMap;
use std::path::PathBuf;

fn schreiber(subjects: &[&str]) -> Vec<PathBuf> {
    let root = require("schreiber2019");
    let mut files: Vec<PathBuf> = subjects
        .iter()
        .flat_map(|s| std::fs::read_dir(root.join(s).join("dynamic")).unwrap())
        .flatten()
        .map(|e| e.path())
        .filter(|p| p.extension().is_some_and(|e| e == "c3d"))
        .collect();
    files.sort();
    files
}

/// The script's plate events of a trial (file stem): Schreiber's C3Ds and the BMClab walks
/// (tools/events/force_truth.py, no gaitfit).
fn script_plates(path: &std::path::Path) -> Vec<GaitEvent> {
    let trial = path.file_stem().unwrap().to_str().unwrap();
    // (file, columns before `side`: subject and trial, or trial alone)
    let (name, skip) = if path.extension().is_some_and(|e| e == "c3d") {
        ("schreiber_force_events.csv", 1)
    } else {
        ("bmclab_walk_force_events.csv", 0)
    };
    let csv = std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("tools/events")
        .join(name);
    let text = std::fs::read_to_string(csv).unwrap();
    let ev: Vec<GaitEvent> = text
        .lines()
        .skip(1)
        .map(|l| l.split(',').skip(skip).collect::<Vec<_>>())
        .filter(|r| r[0] == trial)
        .map(|r| GaitEvent {
            time_s: r[3].parse().unwrap(),
            side: Side::parse(r[1]).unwrap(),
            kind: match r[2] {
                "heel_strike" => EventKind::HeelStrike,
                "toe_off" => EventKind::ToeOff,
                other => panic!("unknown event {other}"),
            },
            source: EventSource::Force,
        })
        .collect();
    assert!(!ev.is_empty(), "{trial}: not in {name}");
    ev
}

/// Scores every file of a set with the heel strike by the tangent onset (`rule` `None`) or
/// the fraction `rule` of the walking speed; returns the counts per event kind and the number
/// of plate events in the first 0.1 s of a marker record (those in its last 0.1 s printed).
fn score(files: &[PathBuf], rule: Option<f64>) -> (BTreeMap<EventKind, KindCounts>, usize) {
    let mut opts = EventOptions {
        primary: PrimarySource::Kinematic,
        ..EventOptions::default()
    };
    match rule {
        Some(f) => {
            opts.kinematic.walk_heel_strike = Some(WalkHeelStrike::Fraction);
            opts.kinematic.hs_speed_fraction = f;
        }
        // `--events kinematic`'s default.
        None => assert_eq!(opts.kinematic.walk_heel_strike, None),
    }
    let mut all: BTreeMap<EventKind, KindCounts> = BTreeMap::new();
    let (mut at_start, mut at_end) = (0, 0);
    for f in files {
        let t = read_trial(f, &ReadOptions::default()).unwrap();
        let an = analyse(&t, &opts).unwrap();
        assert_eq!(an.events.primary, EventSource::FootSpeed, "{}", f.display());
        let k = an.kinematics.as_ref().unwrap();
        let span = (k.time_s[0], k.time_s[k.time_s.len() - 1]);
        let plates = script_plates(f);
        at_start += plates.iter().filter(|e| e.time_s < span.0 + 0.1).count();
        at_end += plates.iter().filter(|e| e.time_s > span.1 - 0.1).count();
        let res = compare(
            an.events.primary_events(),
            &plates,
            Coverage::MatchedOnly,
            span,
            DEFAULT_TOLERANCE_S,
        );
        for (kind, c) in &res {
            all.entry(*kind).or_default().merge(c);
        }
    }
    println!("{at_start} plate event(s) in a record's first 0.1 s, {at_end} in its last");
    (all, at_start)
}

/// Scores a set with the tangent heel strike (aim, Build item 2: recall ≥ 0.99 including
/// record starts and ends, mean within 15 ms; SD printed) and with the fraction rule at Bonci's
/// 0.5 (aim of issue 19's done-when: mean ≤ 15 ms, SD ≤ 12 ms, recall ≥ `min_recall`; `None`:
/// printed, not asserted); 0.3 printed for comparison. Toe off is the same rule in all three.
fn check(
    name: &str,
    files: &[PathBuf],
    n_files: usize,
    min_at_start: usize,
    min_recall: Option<f64>,
) {
    assert_eq!(files.len(), n_files, "{name}");
    let default = gaitfit::events::kinematic::KinematicOptions::default().hs_speed_fraction;
    for (rule, aim) in [
        (None, Some((0.99, 15.0, f64::INFINITY))),
        (Some(default), min_recall.map(|r| (r, 15.0, 12.0))),
        (Some(0.3), None),
    ] {
        let (all, at_start) = score(files, rule);
        assert!(
            at_start >= min_at_start,
            "{name}: {at_start} plate events in the first 0.1 s"
        );
        let label = rule.map_or("tangent onset".to_string(), |f| format!("{f} × speed"));
        for kind in [EventKind::HeelStrike, EventKind::ToeOff] {
            let c = &all[&kind];
            let (m, sd, r) = (
                c.mean_ms().unwrap(),
                c.sd_ms().unwrap(),
                c.recall().unwrap(),
            );
            println!(
                "{name}, heel strike by {label}, {kind}: {m:+.1} ± {sd:.1} ms, recall {r:.3} \
                 ({} of {}), {} unmatched detections",
                c.tp,
                c.tp + c.fn_,
                c.fp
            );
            if let Some((recall, max_mean, max_sd)) = aim {
                assert!(
                    m.abs() <= max_mean && r >= recall && sd <= max_sd,
                    "{name} {label} {kind}"
                );
            }
        }
    }
}

#[test]
#[ignore = "needs ../shared/data"]
fn schreiber_training_subjects_meet_the_aim_including_record_starts() {
    let files = schreiber(&["2014001", "2014004", "2014007"]);
    check("schreiber train", &files, 6, 5, Some(0.99));
}

#[test]
#[ignore = "needs ../shared/data"]
fn schreiber_held_out_subjects_meet_the_aim_including_record_starts() {
    let files = schreiber(&["2014014", "2014015", "2014019"]);
    check("schreiber held out", &files, 6, 5, Some(0.9));
}

#[test]
#[ignore = "needs ../shared/data"]
fn bmclab_overground_walks_held_out_meet_the_aim() {
    // The fraction rule's heel strike is −16.6 ± 9.7 ms here (recall 1.000): 1.6 ms past the
    // mean aim, printed and not asserted; the tangent onset is asserted.
    let b = require("bmclab");
    let files = vec![b.join("walk1.trc"), b.join("walk2.trc")];
    check("bmclab held out", &files, 2, 1, None);
}

#[test]
#[ignore = "needs ../shared/data"]
fn all_twelve_schreiber_trials_meet_the_issue_done_when() {
    let files = schreiber(&[
        "2014001", "2014004", "2014007", "2014014", "2014015", "2014019",
    ]);
    check("schreiber all 12", &files, 12, 10, Some(0.95));
}

/// Mean walking speed of a set's trials, m/s (the detector's own: median pelvis speed over
/// the ground, from the Zeni seeds' stances).
fn mean_speed(files: &[PathBuf]) -> f64 {
    let opts = EventOptions {
        primary: PrimarySource::Kinematic,
        ..EventOptions::default()
    };
    let v: Vec<f64> = files
        .iter()
        .map(|f| {
            let t = read_trial(f, &ReadOptions::default()).unwrap();
            let an = analyse(&t, &opts).unwrap();
            let k = an.kinematics.as_ref().unwrap();
            k.ground_and_walking_speed(&an.events.zeni_coordinate)
                .unwrap()
                .1
        })
        .collect();
    v.iter().sum::<f64>() / v.len() as f64
}

#[test]
#[ignore = "needs ../shared/data"]
fn the_fraction_heel_strike_follows_walking_speed_and_the_tangent_stays_within_the_aim() {
    // The fraction rule's BMClab heel strike is −16.6 ms (past the 15 ms aim), Schreiber's
    // −12.7 ms. The BMClab walks are at a self-selected speed (≈1.2 m/s); Schreiber mixes
    // self-selected (C4) and fast (C5) walks. The heel's speed over the ground when the plate
    // reaches 20 N is a smaller fraction of the walking speed at the slower speed, so Bonci's
    // fixed 0.5 × speed is crossed earlier before the contact: the bias is the speed's, and
    // BMClab's is that of Schreiber's self-selected walks (another lab, marker set, plate
    // system and frame rate). Measured: C4 −18.0 ± 11.0 ms at 1.11 m/s, C5 −7.9 ± 7.4 ms at
    // 1.57 m/s, BMClab −16.6 ± 9.7 ms at 1.17 m/s (the heel at 0.30/0.40/0.31 × speed at the
    // plates' heel strike, reports/events.md). The tangent onset uses no fraction of the speed:
    // C4 −4.0 ± 12.4 ms (n 12, 2014015's start now found), C5 +4.3 ± 6.2 ms, BMClab
    // −6.8 ± 8.3 ms. It does not remove the speed's effect (C5 − C4 +8.3 ms against +10.1,
    // about 2 standard errors) but centres both speeds on the plates. Asserted: fraction C5
    // later than C4 by more than 5 ms and BMClab within two standard errors of C4; tangent
    // within 15 ms of the plates at each speed and in each lab, BMClab within two standard
    // errors of C4.
    let all = schreiber(&[
        "2014001", "2014004", "2014007", "2014014", "2014015", "2014019",
    ]);
    let is = |tag: &str| -> Vec<PathBuf> {
        all.iter()
            .filter(|p| p.to_string_lossy().contains(tag))
            .cloned()
            .collect()
    };
    let b = require("bmclab");
    let sets = [
        ("schreiber C4 (self-selected)", is("_C4_")),
        ("schreiber C5 (fast)", is("_C5_")),
        (
            "bmclab walks",
            vec![b.join("walk1.trc"), b.join("walk2.trc")],
        ),
    ];
    let default = gaitfit::events::kinematic::KinematicOptions::default().hs_speed_fraction;
    let mut hs = Vec::new();
    for rule in [Some(default), None] {
        for (name, files) in &sets {
            let (counts, _) = score(files, rule);
            let c = &counts[&EventKind::HeelStrike];
            let (m, sd, n) = (c.mean_ms().unwrap(), c.sd_ms().unwrap(), c.tp as f64);
            let v = mean_speed(files);
            println!(
                "{name}, {}: {} trial(s), walking speed {v:.2} m/s, heel strike {m:+.1} ± \
                 {sd:.1} ms (n {n})",
                rule.map_or("tangent".into(), |f| format!("{f} × speed")),
                files.len()
            );
            hs.push((m, sd, n));
        }
    }
    let se = |a: (f64, f64, f64), b: (f64, f64, f64)| (a.1 * a.1 / a.2 + b.1 * b.1 / b.2).sqrt();
    let (c4, c5, bm) = (hs[0], hs[1], hs[2]);
    assert!(c5.0 - c4.0 > 5.0, "fraction: C4 {c4:?}, C5 {c5:?}");
    assert!(
        (bm.0 - c4.0).abs() <= 2.0 * se(c4, bm),
        "fraction: C4 {c4:?}, BMClab {bm:?}"
    );
    let (c4, c5, bm) = (hs[3], hs[4], hs[5]);
    for (name, h) in [("C4", c4), ("C5", c5), ("BMClab", bm)] {
        assert!(h.0.abs() <= 15.0 && h.2 >= 8.0, "tangent {name} {h:?}");
    }
    assert!(
        (bm.0 - c4.0).abs() <= 2.0 * se(c4, bm),
        "tangent: C4 {c4:?}, BMClab {bm:?}"
    );
}

#[test]
#[ignore = "needs ../shared/data"]
fn the_tangent_finds_a_heel_strike_the_record_end_cuts() {
    // Record ends: the BMClab walks cut 0.05 s after each plate heel strike past 0.5 s (the
    // plates dropped, markers alone). The walking speed comes from the pelvis over the
    // ground; the ground's velocity from a whole Zeni stance in the record, or, with none
    // (3 of the 6 cuts), 0 overground. Only a cut that leaves no landing to see gives no
    // events (walk2 cut at 0.63 s), not scored. Measured: the tangent −6.8 ± 9.7 ms, 5 of 5
    // (before the overground ground: −3.0 ± 9.1 ms on the 3 cuts that kept a stance, the two
    // others gave no events). Asserted: every scored cut heel strike found within the
    // tolerance, mean within 15 ms, at least 5.
    let b = require("bmclab");
    let plates: Vec<(String, GaitEvent)> = ["walk1", "walk2"]
        .iter()
        .flat_map(|w| {
            script_plates(&b.join(format!("{w}.trc")))
                .into_iter()
                .map(|e| (w.to_string(), e))
        })
        .filter(|(_, e)| e.kind == EventKind::HeelStrike && e.time_s > 0.5)
        .collect();
    let opts = EventOptions {
        primary: PrimarySource::Kinematic,
        ..EventOptions::default()
    };
    let mut err_ms = Vec::new();
    for (w, plate) in &plates {
        let mut t = read_trial(&b.join(format!("{w}.trc")), &ReadOptions::default()).unwrap();
        t.plates.clear();
        t.reference_events.clear();
        let ms = t.markers.as_mut().unwrap();
        let k = ms.time_s.partition_point(|&x| x <= plate.time_s + 0.05);
        ms.time_s.truncate(k);
        ms.positions.iter_mut().for_each(|m| m.truncate(k));
        let Ok(an) = analyse(&t, &opts) else {
            println!(
                "{w} cut at {:.3} s: no events (record too short)",
                plate.time_s + 0.05
            );
            continue;
        };
        let d = an
            .events
            .primary_events()
            .iter()
            .filter(|e| e.kind == EventKind::HeelStrike && e.side == plate.side)
            .map(|e| e.time_s - plate.time_s)
            .min_by(|x, y| x.abs().total_cmp(&y.abs()));
        println!(
            "{w} {} heel strike {:.3} s, cut 0.05 s after: {d:?}",
            plate.side, plate.time_s
        );
        let d = d.expect("a heel strike");
        assert!(d.abs() <= DEFAULT_TOLERANCE_S, "{w} {d}");
        err_ms.push(d * 1e3);
    }
    let mean = err_ms.iter().sum::<f64>() / err_ms.len() as f64;
    println!("cut record ends: {mean:+.1} ms mean, n {}", err_ms.len());
    assert!(err_ms.len() >= 5 && mean.abs() <= 15.0, "{err_ms:?}");
}
