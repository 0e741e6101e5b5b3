//! Builders shared by the KLAW tests (`tests/klaw_*.rs`, each with `mod common;`, cargo's idiom
//! for code shared between integration tests: a `tests/common/mod.rs` is not a test binary of
//! its own): the walks they generate — a schedule of (km/h, steps) at one body height, steady
//! or from standing with a stop — and the per-side landmarks, per-frame joint angles and heel
//! strikes they measure on it.
//!
//! Every test binary uses only part of this module, hence the `dead_code` allowance.
#![allow(dead_code)]

use gaitfit::events::{EventKind, GaitEvent, Side};
use gaitfit::generator::checks::{continuity, rotation_angle, ContinuityOptions};
use gaitfit::generator::motion::Motion;
use gaitfit::generator::skeleton::{Joint, Landmark};
use gaitfit::generator::walking::{generate_walk, ScheduleEntry, WalkOptions, WalkReport};

/// `steps` steps at `v` km/h: the natural walk at that speed (step length and frequency
/// completed by the normalizing formula, `ScheduleEntry::at_speed`).
pub fn kmh(v: f64, steps: usize) -> ScheduleEntry {
    ScheduleEntry::at_speed(v / 3.6, steps)
}

/// A schedule of `(km/h, steps)` entries.
pub fn schedule(sched: &[(f64, usize)]) -> Vec<ScheduleEntry> {
    sched.iter().map(|&(v, steps)| kmh(v, steps)).collect()
}

/// The default options at body height `h` (m), starting from standing if `rest`, ending in a
/// stop if `stop`.
pub fn options(h: f64, rest: bool, stop: bool) -> WalkOptions {
    WalkOptions {
        height_m: h,
        start_from_rest: rest,
        stop,
        ..Default::default()
    }
}

/// The walk of schedule `sched` ((km/h, steps) entries) with [`options`]`(h, rest, stop)`.
pub fn walk(sched: &[(f64, usize)], h: f64, rest: bool, stop: bool) -> (Motion, WalkReport) {
    generate_walk(&schedule(sched), &options(h, rest, stop)).unwrap()
}

/// A steady walk (steady start, ends mid-motion) of `steps` steps at `v` km/h, height `h`.
pub fn steady(v: f64, h: f64, steps: usize) -> (Motion, WalkReport) {
    walk(&[(v, steps)], h, false, false)
}

/// A walk of `steps` steps at `v` km/h, height `h`, from standing to a stop.
pub fn from_standing(v: f64, h: f64, steps: usize) -> (Motion, WalkReport) {
    walk(&[(v, steps)], h, true, true)
}

/// `checks::continuity` with its default options (k = 5) over the whole of `m`: the worst
/// ratio and the report's text, after checking that more than 1000 steps were examined.
pub fn worst_ratio(m: &Motion) -> (f64, String) {
    let r = continuity(m, &ContinuityOptions::default());
    assert!(r.examined > 1000, "{} steps examined", r.examined);
    (r.worst, format!("{r}"))
}

/// The heel strikes of `m` as fractional frame numbers (time × fps), in event order.
pub fn heel_strike_frames(m: &Motion) -> Vec<f64> {
    m.events
        .iter()
        .filter(|e| e.kind == EventKind::HeelStrike)
        .map(|e| e.time_s * m.fps())
        .collect()
}

/// Frame-to-frame rotation (rad) of `joint`'s local rotation, as `checks::continuity` measures
/// it (`checks::rotation_angle`).
pub fn joint_steps(m: &Motion, joint: Joint) -> Vec<f64> {
    let ji = joint.index();
    m.poses()
        .windows(2)
        .map(|p| rotation_angle(p[0].rotations[ji], p[1].rotations[ji]))
        .collect()
}

/// The rotation angle (rad) of `joint`'s local rotation per frame (for the knee: its flexion).
pub fn joint_angles(m: &Motion, joint: Joint) -> Vec<f64> {
    let ji = joint.index();
    m.poses()
        .iter()
        .map(|p| {
            let r = p.rotations[ji];
            2.0 * r.xyz().length().atan2(r.w.abs())
        })
        .collect()
}

/// One side's leg landmarks.
#[derive(Debug, Clone, Copy)]
pub struct Leg {
    /// Hip joint centre.
    pub hip: Landmark,
    /// Knee joint centre.
    pub knee: Landmark,
    /// Ankle joint centre.
    pub ankle: Landmark,
    /// Heel.
    pub heel: Landmark,
    /// Ball of the foot.
    pub ball: Landmark,
    /// Toe tip.
    pub toe: Landmark,
}

/// The leg landmarks of `side`.
pub fn leg(side: Side) -> Leg {
    match side {
        Side::Left => Leg {
            hip: Landmark::LHip,
            knee: Landmark::LKnee,
            ankle: Landmark::LAnkle,
            heel: Landmark::LHeel,
            ball: Landmark::LBall,
            toe: Landmark::LToe,
        },
        Side::Right => Leg {
            hip: Landmark::RHip,
            knee: Landmark::RKnee,
            ankle: Landmark::RAnkle,
            heel: Landmark::RHeel,
            ball: Landmark::RBall,
            toe: Landmark::RToe,
        },
    }
}

/// The first event of `kind` on `side` after `after_s` (s, exclusive), in event order.
pub fn next_event(m: &Motion, kind: EventKind, side: Side, after_s: f64) -> Option<&GaitEvent> {
    m.events
        .iter()
        .find(|e| e.kind == kind && e.side == side && e.time_s > after_s)
}

/// `f` over `cases` on every available core (walk grids of hundreds of walks), the results in
/// the order of `cases`.
pub fn par_map<T: Sync, R: Send>(cases: &[T], f: impl Fn(&T) -> R + Sync) -> Vec<R> {
    let next = std::sync::atomic::AtomicUsize::new(0);
    let out = std::sync::Mutex::new(Vec::with_capacity(cases.len()));
    let threads = std::thread::available_parallelism().map_or(2, |n| n.get());
    std::thread::scope(|s| {
        for _ in 0..threads {
            s.spawn(|| loop {
                let i = next.fetch_add(1, std::sync::atomic::Ordering::Relaxed);
                let Some(case) = cases.get(i) else {
                    break;
                };
                let r = f(case);
                out.lock().unwrap().push((i, r));
            });
        }
    });
    let mut out = out.into_inner().unwrap();
    out.sort_by_key(|p| p.0);
    out.into_iter().map(|p| p.1).collect()
}

/// Runs `check` over the walk grid `cases` ([`par_map`]) and fails with every message it
/// returned (`None`: the case passed), and how many of how many cases failed.
pub fn assert_grid<T: Sync>(cases: &[T], check: impl Fn(&T) -> Option<String> + Sync) {
    let failures: Vec<String> = par_map(cases, check).into_iter().flatten().collect();
    assert!(
        failures.is_empty(),
        "{} of {} walks: {failures:#?}",
        failures.len(),
        cases.len()
    );
}
