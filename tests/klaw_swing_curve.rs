//! KLAW swing1 (§4.3): the ankle is forced along the 4th-order polynomial `P` and the knee is
//! slaved to it while the thigh follows the dynamics. Property: over speed changes and
//! heights, the swing leg's knee and ankle never jump in swing1 (issue 6: slowing 7 → 1 km/h
//! the curve's far flank ran along the circle the ankle can reach about the knee and the knee
//! lost its root — one frame of a 0.4 m ankle jump, continuity 73.5).
//!
//! The measure is `checks::continuity`'s own (each frame-to-frame step against the median of
//! the 3 steps on either side, floors 1e-4 m and 1e-3 rad), restricted to the swing leg's ankle
//! centre and knee rotation over swing1 (toe off to `swing1_end` = 50 % of the swing).
mod common;

use gaitfit::events::{EventKind, Side};
use gaitfit::generator::checks::{step_ratios, ContinuityOptions};
use gaitfit::generator::motion::Motion;
use gaitfit::generator::skeleton::{Joint, Landmark};
use proptest::prelude::*;

/// The worst ratio of the swing leg's ankle and knee steps over every swing1 of `m`, with a
/// description of where.
fn swing1_worst(m: &Motion) -> (f64, String) {
    let o = ContinuityOptions::default();
    let fps = m.fps();
    let lms = m.all_landmarks();
    let mut worst = (0.0, String::from("no swing1"));
    for side in [Side::Left, Side::Right] {
        let (ankle, knee) = (common::leg(side).ankle, Joint::leg(side)[1]);
        let ai = Landmark::ALL.iter().position(|&l| l == ankle).unwrap();
        let ankle_steps: Vec<f64> = lms
            .windows(2)
            .map(|p| (p[1][ai] - p[0][ai]).length())
            .collect();
        let knee_steps = common::joint_steps(m, knee);
        // `checks::continuity`'s own ratios (a step without neighbours counts as 0).
        let ratios = |steps: &[f64], floor| -> Vec<f64> {
            step_ratios(steps, o.window, floor)
                .into_iter()
                .map(|r| r.unwrap_or(0.0))
                .collect()
        };
        let ra = ratios(&ankle_steps, o.floor_m);
        let rk = ratios(&knee_steps, o.floor_rad);
        let mine: Vec<_> = m.events.iter().filter(|e| e.side == side).collect();
        for (i, e) in mine.iter().enumerate() {
            if e.kind != EventKind::ToeOff {
                continue;
            }
            let Some(hs) = mine[i + 1..]
                .iter()
                .find(|h| h.kind == EventKind::HeelStrike)
            else {
                continue;
            };
            let t1 = e.time_s + 0.5 * (hs.time_s - e.time_s);
            let (a, b) = ((e.time_s * fps).ceil() as usize, (t1 * fps) as usize);
            for f in a..b.min(ra.len()) {
                for (r, what) in [(ra[f], ankle.name()), (rk[f], knee.name())] {
                    if r > worst.0 {
                        worst = (r, format!("{r:.2} at frame {f} ({what})"));
                    }
                }
            }
        }
    }
    worst
}

/// The walk of `sched` ((km/h, steps) entries) at height `h`, from standing with a stop.
fn walk(sched: &[(f64, usize)], h: f64) -> Motion {
    common::walk(sched, h, true, true).0
}

/// The case that failed (`LIFT_OVER_TOE_OFF`'s paper value, the peak lifted from the toe-off
/// ankle: 73.5 at frame 498, l_knee, 2.0 m; 13.0 / 11.0 at 1.5 / 1.8 m).
#[test]
fn slowing_from_7_to_1_kmh_keeps_the_swing1_knee_continuous() {
    for h in [1.5, 1.8, 2.0] {
        let (w, r) = swing1_worst(&walk(&[(7.0, 4), (1.0, 4)], h));
        assert!(w <= 5.0, "7 -> 1 km/h x {h} m: swing1 {r}");
    }
}

/// For every swing of an 8-step steady walk at `kmh`, `h` m with a heel strike on the same
/// side before it (so a whole gait cycle): the drawn thigh's (hip–knee line, sagittal) peak
/// flexion before its heel strike as a fraction of that cycle, and the largest forward step of
/// the thigh (rad per frame) from the peak to the last frame before contact. The earliest peak
/// and the worst step over the walk's swings, with the number of swings.
fn thigh_reversal(kmh: f64, h: f64) -> (f64, f64, usize) {
    let (m, _) = common::steady(kmh, h, 8);
    let fps = m.fps();
    let (mut lead, mut forward, mut n) = (f64::INFINITY, f64::NEG_INFINITY, 0);
    for to in m.events.iter().filter(|e| e.kind == EventKind::ToeOff) {
        let Some(hs) = common::next_event(&m, EventKind::HeelStrike, to.side, to.time_s) else {
            continue;
        };
        let Some(before) = m.events.iter().rfind(|e| {
            e.kind == EventKind::HeelStrike && e.side == to.side && e.time_s < to.time_s
        }) else {
            continue;
        };
        let (hip, knee) = (common::leg(to.side).hip, common::leg(to.side).knee);
        // Forward flexion of the thigh from the vertical (the walk goes along +x).
        let thigh = |i: usize| {
            let (p, k) = (m.landmark(i, hip), m.landmark(i, knee));
            (k.x - p.x).atan2(p.y - k.y)
        };
        let first = (to.time_s * fps).ceil() as usize;
        let last = (hs.time_s * fps + 1e-9).floor() as usize;
        let peak = (first..=last)
            .max_by(|&a, &b| thigh(a).total_cmp(&thigh(b)))
            .unwrap();
        lead = lead.min((hs.time_s - peak as f64 / fps) / (hs.time_s - before.time_s));
        for i in peak..last {
            forward = forward.max(thigh(i + 1) - thigh(i));
        }
        n += 1;
    }
    (lead, forward, n)
}

/// Terminal swing (issue 6): the landing thigh reaches its peak flexion and starts to retract
/// at least 10 % of the gait cycle before heel strike (a human's at ≈ 15 %), and from there
/// retracts without flexing again into the contact. Before swing2's hip followed the thigh's
/// terminal-swing path (`swing::RETRACTION_CYCLE`) the thigh flexed until 3.0–7.8 % of the
/// cycle before contact (5 km/h × 1.8 m 7.0 %, 6 km/h × 1.5 m 3.0 %); now 10.6–13.3 % from
/// 3 km/h up, 9.5–12.4 % at 2 km/h and 8.9–9.6 % at 1 km/h (whose swing is 30 % of the cycle).
#[test]
fn the_landing_thigh_retracts_through_terminal_swing() {
    for kmh in [2.0, 3.0, 4.0, 5.0, 6.0, 7.0] {
        for h in [1.5, 1.8, 2.0] {
            let (lead, forward, n) = thigh_reversal(kmh, h);
            assert!(n >= 6, "{kmh} km/h x {h} m: {n} swings");
            let least = if kmh >= 3.0 { 0.10 } else { 0.09 };
            assert!(
                lead >= least,
                "{kmh} km/h x {h} m: the thigh peaks {:.1} % of the cycle before contact",
                lead * 100.0
            );
            assert!(
                forward <= 1e-4,
                "{kmh} km/h x {h} m: the thigh flexes again by {forward:.5} rad in a frame"
            );
        }
    }
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 16, ..ProptestConfig::default() })]

    /// Two steps at each of two speeds, from standing, with a stop.
    #[test]
    fn swing1_knee_and_ankle_never_jump(
        v0 in 1.0f64..7.0,
        v1 in 1.0f64..7.0,
        h in 1.5f64..2.0,
    ) {
        let (w, r) = swing1_worst(&walk(&[(v0, 2), (v1, 2)], h));
        prop_assert!(w <= 5.0, "{v0:.2} -> {v1:.2} km/h x {h:.2} m: swing1 {r}");
    }
}
