//! Force events against 20 N on the unfiltered force, computed without gaitfit by
//! `tools/events/force_truth.py` (numpy; thresholds the raw force, runs under 50 ms are blips,
//! interpolates the crossings): every reference event is found within 2 ms, and WBDS subject
//! 04's mean double support per trial is within 6 ms of the reference and of issue 19's
//! figures (0.070/0.060/0.050/0.047 s). Schreiber's two C3D plates: the script reads them with
//! ezc3d's force-platform extraction (not gaitfit's C3D reader) and assigns the feet by the
//! markers; every plate event within 2 ms (measured: 0.005 ms).
//!
//! Double support is one period per step: the other foot's toe off after this foot's heel
//! strike, minus that heel strike (`src/events/steps.rs`). The WBDS export zeroes isolated
//! samples, some in unloading tails; by default (the guide's truth) a zero ends the contact.
//! `bridge_dropouts = true` (`--bridge-dropouts`) times the toe off after the tail's later
//! nonzero samples; it is compared with the script's bridged reference
//! (`wbds04_force_events_bridged.csv`, `bridged_double_support_mean_s`).
use gaitfit::events::{analyse, steps_from_analysis, EventKind, EventOptions, GaitEvent, Side};
use gaitfit::ingest::{read_trial, ReadOptions};
use gaitfit::shared_data::require;
use std::path::Path;

/// Largest |gaitfit − reference| of an event, s.
const EVENT_TOL_S: f64 = 0.002;
/// Largest |gaitfit − reference| of a trial's mean double support, s.
const DOUBLE_SUPPORT_TOL_S: f64 = 0.006;

fn tool_csv(name: &str) -> Vec<Vec<String>> {
    let p = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("tools/events")
        .join(name);
    let text = std::fs::read_to_string(&p).unwrap();
    text.lines()
        .skip(1)
        .map(|l| l.split(',').map(str::to_string).collect())
        .collect()
}

fn kind(s: &str) -> EventKind {
    match s {
        "heel_strike" => EventKind::HeelStrike,
        "toe_off" => EventKind::ToeOff,
        other => panic!("unknown event {other}"),
    }
}

/// The `(subject, trial)` pairs of a reference table whose first two columns name them, in
/// file order; the table must hold `n` trials.
fn subject_trials(events: &[Vec<String>], n: usize) -> Vec<(String, String)> {
    let mut trials: Vec<(String, String)> = events
        .iter()
        .map(|r| (r[0].clone(), r[1].clone()))
        .collect();
    trials.dedup();
    assert_eq!(trials.len(), n);
    trials
}

/// The reference events `(side, kind, time)` of the rows `keep` selects; `at` is the column of
/// the side (kind and time follow it).
fn reference_rows(
    events: &[Vec<String>],
    at: usize,
    keep: impl Fn(&[String]) -> bool,
) -> Vec<(Side, EventKind, f64)> {
    events
        .iter()
        .filter(|r| keep(r))
        .map(|r| {
            (
                Side::parse(&r[at]).unwrap(),
                kind(&r[at + 1]),
                r[at + 2].parse().unwrap(),
            )
        })
        .collect()
}

/// Every reference `(side, kind, time)` has a gaitfit event of that foot and kind within
/// [`EVENT_TOL_S`]; returns the largest error, s.
fn check_events(label: &str, found: &[GaitEvent], reference: &[(Side, EventKind, f64)]) -> f64 {
    let mut worst = 0.0f64;
    for &(side, k, t) in reference {
        let err = found
            .iter()
            .filter(|e| e.side == side && e.kind == k)
            .map(|e| e.time_s - t)
            .min_by(|a, b| a.abs().total_cmp(&b.abs()))
            .unwrap_or(f64::INFINITY);
        assert!(
            err.abs() <= EVENT_TOL_S,
            "{label}: {side} {k} at {t:.5} s: gaitfit is {:.2} ms off",
            err * 1e3
        );
        worst = worst.max(err.abs());
    }
    // And nothing more: every gaitfit event has its reference partner.
    assert_eq!(
        found.len(),
        reference.len(),
        "{label}: {} gaitfit force events, {} reference events",
        found.len(),
        reference.len()
    );
    worst
}

/// Issue 19's WBDS04 double support (T05…T08), s: a plain 20 N threshold on the exported force.
const ISSUE_DS_S: [(&str, f64); 4] = [
    ("WBDS04walkT05", 0.070),
    ("WBDS04walkT06", 0.060),
    ("WBDS04walkT07", 0.050),
    ("WBDS04walkT08", 0.047),
];

/// Checks one WBDS04 reading (`bridge`) against the script's events file `events_csv` and its
/// double-support column `ds_col`; returns the mean double support per trial.
fn wbds04_reading(bridge: bool, events_csv: &str, ds_col: usize) -> Vec<(String, f64)> {
    let root = require("wbds");
    let events = tool_csv(events_csv);
    let ds = tool_csv("wbds04_double_support.csv");
    let mut out = Vec::new();
    for row in &ds {
        let trial = &row[0];
        let path = root.join(format!("{trial}grf.txt"));
        let t = read_trial(&path, &ReadOptions::default()).unwrap();
        let mut opts = EventOptions::default();
        opts.force.bridge_dropouts = bridge;
        let an = analyse(&t, &opts).unwrap();
        let reference = reference_rows(&events, 1, |r| &r[0] == trial);
        let worst = check_events(trial, &an.events.force, &reference);
        let steps = steps_from_analysis(&t, &an, &opts).unwrap();
        let d: Vec<f64> = steps
            .rows
            .iter()
            .filter_map(|r| r.double_support_time_s)
            .collect();
        let mean = d.iter().sum::<f64>() / d.len() as f64;
        let want: f64 = row[ds_col].parse().unwrap();
        println!(
            "{trial} (bridge {bridge}): worst event error {:.3} ms; double support {mean:.4} s \
             ({} steps), reference {want:.4} s",
            worst * 1e3,
            d.len(),
        );
        assert!(
            (mean - want).abs() <= DOUBLE_SUPPORT_TOL_S,
            "{trial}: double support {mean:.4} s, reference {want:.4} s"
        );
        out.push((trial.clone(), mean));
    }
    out
}

#[test]
#[ignore = "needs ../shared/data"]
fn wbds04_events_and_double_support_match_20_n_on_the_unfiltered_force() {
    let plain = wbds04_reading(false, "wbds04_force_events.csv", 2);
    for (trial, issue) in ISSUE_DS_S {
        let (_, mean) = plain.iter().find(|(t, _)| t == trial).unwrap();
        println!("{trial}: default {mean:.4} s, issue {issue:.3} s");
        assert!(
            (mean - issue).abs() <= DOUBLE_SUPPORT_TOL_S,
            "{trial}: default {mean:.4} s, issue {issue:.3} s"
        );
    }
}

#[test]
#[ignore = "needs ../shared/data"]
fn wbds04_bridged_dropouts_match_the_bridged_reference() {
    let plain = wbds04_reading(false, "wbds04_force_events.csv", 2);
    let bridged = wbds04_reading(true, "wbds04_force_events_bridged.csv", 5);
    for ((trial, p), (_, b)) in plain.iter().zip(&bridged) {
        assert!(
            b - p > 0.005,
            "{trial}: bridging should lengthen it ({p:.4} → {b:.4} s)"
        );
    }
}

#[test]
#[ignore = "needs ../shared/data"]
fn hamner_events_match_20_n_on_the_unfiltered_force() {
    let root = require("hamner2013");
    let events = tool_csv("hamner_force_events.csv");
    let trials = subject_trials(&events, 20);
    let (mut worst, mut n, mut skipped) = (0.0f64, 0usize, 0usize);
    for (subject, trial) in &trials {
        let path = root.join(subject).join(format!("{trial}_grf.mot"));
        let t = read_trial(&path, &ReadOptions::default()).unwrap();
        let an = analyse(&t, &EventOptions::default()).unwrap();
        // A foot landing across both belts is one contact to gaitfit (merged, its side
        // reassigned) and one per belt to the reference: such contacts are left out of both.
        let across: Vec<(f64, f64)> = an
            .force
            .contacts
            .iter()
            .filter(|c| c.assigned_by.contains("both belts"))
            .map(|c| (c.span_s.0 - 0.01, c.span_s.1 + 0.01))
            .collect();
        // A contact the record cuts within 50 ms of its end may or may not be confirmed (reach
        // 50 N) before the end, on the filtered force or on the raw: not judged either way.
        let plate = &t.plates[0];
        let (t0, t1) = (plate.time_s[0], plate.time_s[plate.time_s.len() - 1]);
        let kept = |t: f64| {
            !across.iter().any(|&(a, b)| t >= a && t <= b) && t > t0 + 0.05 && t < t1 - 0.05
        };
        let reference: Vec<(Side, EventKind, f64)> =
            reference_rows(&events, 2, |r| &r[0] == subject && &r[1] == trial)
                .into_iter()
                .filter(|r| kept(r.2))
                .collect();
        let found: Vec<GaitEvent> = an
            .events
            .force
            .iter()
            .filter(|e| kept(e.time_s))
            .copied()
            .collect();
        skipped += across.len();
        let label = format!("{subject}/{trial}");
        worst = worst.max(check_events(&label, &found, &reference));
        n += reference.len();
    }
    println!(
        "Hamner, 20 trials: {n} events, worst error {:.3} ms ({skipped} contacts across both \
         belts left out)",
        worst * 1e3
    );
}

#[test]
#[ignore = "needs ../shared/data"]
fn schreiber_plate_events_match_20_n_on_ezc3d_plates() {
    // The reference reads the two plates with ezc3d's own force-platform extraction (not
    // gaitfit's C3D reader) and assigns each plate's contact to the foot whose heel–toe
    // midpoint is nearest the centre of pressure; every event of both plates must match.
    let root = require("schreiber2019");
    let events = tool_csv("schreiber_force_events.csv");
    let trials = subject_trials(&events, 12);
    let (mut worst, mut n) = (0.0f64, 0usize);
    for (subject, trial) in &trials {
        let path = root
            .join(subject)
            .join("dynamic")
            .join(format!("{trial}.c3d"));
        let t = read_trial(&path, &ReadOptions::default()).unwrap();
        let an = analyse(&t, &EventOptions::default()).unwrap();
        let reference = reference_rows(&events, 2, |r| &r[0] == subject && &r[1] == trial);
        worst = worst.max(check_events(trial, &an.events.force, &reference));
        n += reference.len();
    }
    println!(
        "Schreiber, 12 trials: {n} plate events, worst |gaitfit − ezc3d/numpy| {:.3} ms",
        worst * 1e3
    );
}

#[test]
#[ignore = "needs ../shared/data"]
fn bmclab_walk_plate_events_match_20_n_on_the_forces_export() {
    // The reference reads the Cortex `.forces` table itself (7 plates, FYk vertical) and
    // assigns the feet by the TRC's heel–MT2 midpoint nearest the centre of pressure.
    let root = require("bmclab");
    let events = tool_csv("bmclab_walk_force_events.csv");
    let (mut worst, mut n) = (0.0f64, 0usize);
    for trial in ["walk1", "walk2"] {
        let t = read_trial(&root.join(format!("{trial}.trc")), &ReadOptions::default()).unwrap();
        let an = analyse(&t, &EventOptions::default()).unwrap();
        let reference = reference_rows(&events, 1, |r| r[0] == trial);
        worst = worst.max(check_events(trial, &an.events.force, &reference));
        n += reference.len();
    }
    assert_eq!(n, 13);
    println!(
        "BMClab walks: {n} plate events, worst |gaitfit − numpy| {:.3} ms",
        worst * 1e3
    );
}
