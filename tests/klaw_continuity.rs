//! KLAW continuity across steps: a **regression guard, not the target**.
//!
//! `checks::continuity` (k = 5: no frame-to-frame step of a landmark or joint larger than five
//! times the median of its neighbours) is what the RUNNER meets; KLAW does not meet it yet. The
//! worst ratios measured on main (2026-11-26, after the planned heel rocker and the roll
//! smoothing; before them 263 at 5 km/h, 1568 on the standing-start schedule) are asserted
//! here with 25 % headroom so that they cannot silently get worse. Remaining offenders: the
//! ankle at heel strike (the swing lands with a straight knee, so the foot must start
//! plantarflexing fast), the first frames of a steady start, and the knee at toe off (the
//! meta-off knee blend ends at rest).
//!
//! Tighten the bounds when a fix lands; replace them by `passed` when KLAW meets k = 5.
use gaitfit::generator::checks::{continuity, ContinuityOptions};
use gaitfit::generator::walking::{generate_walk, ScheduleEntry, WalkOptions, WalkParams};

fn worst(sched: &[(f64, usize)], h: f64, rest_and_stop: bool) -> (f64, String) {
    let schedule: Vec<ScheduleEntry> = sched
        .iter()
        .map(|&(kmh, steps)| ScheduleEntry {
            params: WalkParams {
                speed_m_per_s: Some(kmh / 3.6),
                ..Default::default()
            },
            steps,
        })
        .collect();
    let opts = WalkOptions {
        height_m: h,
        start_from_rest: rest_and_stop,
        stop: rest_and_stop,
        ..Default::default()
    };
    let (m, _) = generate_walk(&schedule, &opts).unwrap();
    let r = continuity(&m, &ContinuityOptions::default());
    assert!(
        r.examined > 1000,
        "{sched:?}: {} steps examined",
        r.examined
    );
    (r.worst, format!("{r}"))
}

/// (schedule as (km/h, steps), height m, from rest with stop, bound on the worst ratio).
type Case = (&'static [(f64, usize)], f64, bool, f64);

#[test]
fn continuity_ratios_do_not_regress() {
    // (schedule, height, from rest with stop, bound = measured × 1.25)
    let cases: &[Case] = &[
        (&[(1.0, 8)], 1.8, false, BOUND_1KMH),
        (&[(3.0, 8)], 1.8, false, BOUND_3KMH),
        (&[(5.0, 8)], 1.8, false, BOUND_5KMH),
        (&[(7.0, 8)], 1.8, false, BOUND_7KMH),
        (&[(2.0, 4), (5.0, 4), (3.0, 4)], 1.8, true, BOUND_SCHEDULE),
    ];
    let mut failures = Vec::new();
    for &(sched, h, rest, bound) in cases {
        let (w, report) = worst(sched, h, rest);
        println!("{sched:?} h {h} rest/stop {rest}: {report}");
        if w > bound {
            failures.push(format!("{sched:?}: ratio {w:.1} > {bound}"));
        }
    }
    assert!(failures.is_empty(), "{failures:?}");
}

/// Bounds: the worst ratio measured on main, × 1.25 (1 and 3 km/h after the least-bending heel-off
/// roll, 2026-11-27 00:30 UTC; the others 2026-11-26 23:00 UTC).
const BOUND_1KMH: f64 = 11.7; // measured 9.35 (frame 0, l_heel; was 15.1 at heel off, l_knee)
const BOUND_3KMH: f64 = 11.7; // measured 9.35 (frame 0, l_heel; was 15.1 at heel off, r_heel)
const BOUND_5KMH: f64 = 23.0; // measured 18.4 (frame 223, l_ankle)
const BOUND_7KMH: f64 = 25.0; // measured 20.3 (frame 47, r_ankle at heel strike)
const BOUND_SCHEDULE: f64 = 24.0; // measured 19.5 (frame 520, r_ankle)
