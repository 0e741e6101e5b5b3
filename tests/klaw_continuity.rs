//! KLAW continuity across steps.
//!
//! `checks::continuity` (k = 5: no frame-to-frame step of a landmark or joint larger than five
//! times the median of its neighbours) is what the RUNNER meets. KLAW meets it at 1 km/h
//! (1.5–2.0 m), 2 km/h (1.5 m, since the heel rocker's landing scan,
//! `virtual_leg::ROCKER_SCAN`), 3 km/h (1.8, 2.0 m) and 4 km/h (1.8, 2.0 m, since the push-off,
//! `stance::push_off_exponent`; 1.5 m since a steady walk's recording begins
//! `generate::LEAD_IN_FRAMES` before its first heel strike, klawlead: frame 0 had been that
//! heel strike, its ankle spike judged against later steps only) and 5 km/h (1.8, 2.0 m, since the landing ankle's contact rate
//! `generate::MAX_CONTACT_ANKLE_RATE` went 3 → 6 rad/s) and 6 km/h (2.0 m, since the trailing
//! knee's hold through the double support, `hold_knees` in `generate.rs`; 1.8 m since the
//! recording runs past the last heel strike, `generate::LEAD_OUT_FRAMES`: its last frame had been
//! the landing thigh's retraction, judged against earlier frames only) and 7 km/h (2.0 m,
//! since the stance leg locks at the projection of the drawn 3-D leg, klawflat), and the
//! standing-start schedule at 1.5 m and 5–6 km/h × 1.5 m and 7 km/h × 1.8 m (since the
//! landing ankle's contact ramp, `SwingFoot::contact_ramp`, klawhs2) — asserted as `passed`
//! below — and not yet elsewhere
//! (2026-11-27, klawpush: 2 km/h 5.2–6.4, 4–7 km/h 6.1–12.4, worst at heel strike, where KLAW's
//! hip closes on the landing heel at 0.98–1.54 m/s (5–7 km/h, 1.8 m), and at frame 0 of a steady
//! walk, the same spike with no history — until the lead-in, klawlead s7). There the worst ratios measured on main are asserted with 25 %
//! headroom (a **regression guard, not the target**) so that they cannot silently get
//! worse. Before this work: 263 at 5 km/h, 1568 on the standing-start schedule.
//!
//! Tighten the bounds when a fix lands; move a walk to the `passed` list when it meets k = 5.
mod common;

use common::{joint_angles, joint_steps};
use gaitfit::events::EventKind;
use gaitfit::generator::checks::{continuity, continuity_over, step_ratios, ContinuityOptions};
use gaitfit::generator::motion::Motion;
use gaitfit::generator::skeleton::Joint;
use gaitfit::generator::walking::generate_walk;

/// The worst continuity ratio (k = 5, the whole walk) of schedule `sched` at height `h`, steady
/// or from standing with a stop, and the report.
fn worst(sched: &[(f64, usize)], h: f64, rest_and_stop: bool) -> (f64, String) {
    common::worst_ratio(&common::walk(sched, h, rest_and_stop, rest_and_stop).0)
}

/// Where KLAW meets k = 5 today (8 steps, steady start): the check itself must pass.
#[test]
fn continuity_is_met_at_1_to_7_kmh() {
    let cases = [
        (1.0, 1.5),
        (1.0, 1.8),
        (1.0, 2.0),
        (2.0, 1.5),
        (2.0, 1.8),
        (2.0, 2.0),
        (3.0, 1.5),
        (3.0, 1.8),
        (3.0, 2.0),
        (4.0, 1.5),
        (4.0, 1.8),
        (4.0, 2.0),
        (5.0, 1.8),
        (5.0, 2.0),
        (6.0, 1.8),
        (6.0, 2.0),
        (7.0, 2.0),
        // Since the landing ankle's contact ramp (`SwingFoot::contact_ramp`; main before:
        // 5.50, 7.79, 6.48, all at the first heel strike, frame 5).
        (5.0, 1.5),
        (6.0, 1.5),
        (7.0, 1.8),
    ];
    let mut failures = Vec::new();
    for (kmh, h) in cases {
        let (w, report) = worst(&[(kmh, 8)], h, false);
        println!("{kmh} km/h {h} m: {report}");
        if w > ContinuityOptions::default().k {
            failures.push(report);
        }
    }
    // The standing-start schedule 2 → 5 → 3 km/h with its stop, at 1.5 m (since the landing
    // ankle's contact ramp, `SwingFoot::contact_ramp`: 5.56 at 373 r_ankle, a 5 km/h heel
    // strike → 4.12 at 72 r_hip).
    let (w, report) = worst(&[(2.0, 4), (5.0, 4), (3.0, 4)], 1.5, true);
    println!("schedule 1.5 m: {report}");
    if w > ContinuityOptions::default().k {
        failures.push(report);
    }
    assert!(failures.is_empty(), "{failures:#?}");
}

/// 7 km/h × 1.5 m, a 1.5 m body at the walk–run transition (Froude 0.73), the one fast walk
/// of a short body that does not meet k = 5: its heel strikes are guarded at 1.25 × their
/// measurement since the landing ankle's contact ramp (`SwingFoot::contact_ramp`; 11.4 at every
/// heel strike before). The whole walk since the arms follow the opposite leg's axis through a
/// second-order lag (`swing_arms`): the walk's last four frames were excluded for a shoulder
/// jolt (8.6 at the walk's end, then 5.95 one frame before its last heel strike).
#[test]
fn fast_short_heel_strikes_do_not_regress() {
    let o = ContinuityOptions::default();
    let (m, _) = common::steady(7.0, 1.5, 8);
    let r = continuity(&m, &o);
    println!("7 km/h 1.5 m: {r}");
    assert!(r.examined > 1000, "{} examined", r.examined);
    assert!(r.worst <= HS_7KMH_1_5M, "{r} (bound {HS_7KMH_1_5M})");
}

/// 7 km/h × 1.5 m: measured 5.29 (frame 48, r_ankle, the second heel strike) × 1.25.
const HS_7KMH_1_5M: f64 = 1.25 * 5.29;

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
        // Meets k = 5 since the speed-up's push-off (`generate::speeds_up`): 4.75 (frame 92,
        // r_heel, the start); 5.07 at 381 (r_knee, the trailing knee of the first 5 km/h step).
        (&[(2.0, 4), (5.0, 4), (3.0, 4)], 2.0, true, 5.0),
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
/// roll; 5 and 7 km/h and the schedule after klawhs' pre-contact ankle rate).
// klawstart (the first stance foot lands pitched for the 3-D leg to reach): frame 0's heel
// 9.35 gone; 1 km/h 9.35 → 6.53, 3 km/h 9.35 → 3.80, 5 km/h 9.35 → 8.53 (frame 0's ankle),
// 7 km/h 13.9 → 16.1 (frame 0's ankle, which the extra ≈ 0.01 rad of landing pitch raises;
// its bound is kept).
const BOUND_1KMH: f64 = 5.0; // measured 4.15 (frame 267, r_knee, since the slow stance lowers the hip twice the projected reach, `generate::SLOW_REST_REACH`: the stance heel no longer hovers; k = 5 kept as the bound); 3.04 (frame 139, r_ankle, since the knee ease carried the rocker's landing rate, `KNEE_ROCKER_EASE`, deleted in stage B); 3.25 (frame 763, l_ankle, since swing1's reach bound `swing::REACH_SHARE`); 3.30 (frame 208, l_ankle, after klawtoe2's arm lag); 4.73 (frame 485, l_knee, late swing; 4.84 at frame 262, l_knee at heel off, before the knee ease; 6.29 at frame 386 before the stance lock's blend)
const BOUND_3KMH: f64 = 4.1; // measured 3.30 (frame 83, r_knee, since klawflat's projected lock; 3.80 at frame 44, r_knee, before): k = 5 met

// klawhs (swing ankle plantarflexing into the contact): 5 km/h 18.4 → 9.35 (the heel strikes'
// 13–18 → ≤ 8.1; the worst is now frame 0), 7 km/h 20.3 → 13.9 (frame 0; heel strikes ≤ 13.9),
// schedule 19.5 → 16.6 (10.3 with the least-bending heel-off roll).
// klawpush (the push-off, `stance::push_off_exponent`): 5 km/h 8.53 → 6.06 (frame 0 gone;
// the heel strikes' ankle ≤ 6.1), 7 km/h 16.1 → 10.6 (frame 0 9.6), schedule 7.23 → 5.73.
// klawhs s6 (contact ankle rate 3 → 6 rad/s): 5 km/h 6.01 → 4.74 (k = 5 met; frame 0), 7 km/h
// 10.8 → 10.2 (frame 0; the heel strikes ≤ 8.5).
// klawhs s6 (the midstance lock, `stance::lock_shortening`): 7 km/h 10.2 → 6.44 (frame 0; the
// heel strikes ≤ 6.4); 5 km/h 4.74 → 4.17 (frame 445, l_hip).
const BOUND_5KMH: f64 = 4.5; // measured 3.66 (frame 61, r_ankle, since the lead-in: the same heel strike 5 frames later); 3.63 (frame 56, r_ankle, since klawflat's projected lock, `generate::PROJECTED_LOCK_FROUDE_MIN`); 4.17 (frame 445, l_hip, since the midstance lock); 4.74 (frame 0, l_ankle; 6.06 at frame 56, r_ankle, heel strike, before the contact rate 6; 8.53 at frame 0 before the push-off)
const BOUND_7KMH: f64 = 5.0; // measured 4.01 (frame 5, l_ankle, since the contact ramp, `SwingFoot::contact_ramp`; k = 5 met); 6.48 (frame 5, l_ankle, the first heel strike, since the lead-in); 6.44 (frame 0, l_ankle; 10.20 before the midstance lock; 10.57–10.8 at frame 283, l_ankle, heel strike, before the contact rate 6; 16.1 at frame 0 before the push-off)

// klawfirst2 (`hold_knees`: the trailing knee no longer straightens again around heel strike):
// 6 km/h × 2.0 m 10.5 (frame 0, r_knee: the trailing knee's straightening at the walk's first
// heel strike, with nothing before it in the window; 6.09 before the brisk toe off) → 6.07, and
// 4.55 with klawhs' contact rate 6 rad/s: asserted in `continuity_is_met_at_1_to_7_kmh`.
// klawflat (the stance leg locks at the projection of the drawn 3-D leg): 7 km/h × 2.0 m
// 5.32 → 4.61 (frame 348, r_ankle): asserted there; 6 km/h × 2.0 m 4.24 → 3.60.
const BOUND_SCHEDULE: f64 = 4.36; // meets k = 5: measured 3.49 (frame 100, r_knee, the start, since the first swing from standing is braked and bell-shaped, klawstart2); 3.70 (frame 100, r_knee, the start, since the default speed-change limit ramps 2 -> 3.5 -> 5 -> 4 -> 3 km/h, `max_speed_change_m_per_s` = 0.5); 4.71 (frame 865, l_ankle, since the stop's swings are braked; 6.08 at 851, l_knee, the unbraked last swing's knee at its lock, before); 6.08 (frame 851, l_knee, the stop's last swing, since the speed-up's push-off, `generate::speeds_up`; 6.20 at 362, r_knee, the trailing knee of the first 5 km/h step, before); 5.73 (frame 520, r_ankle, a 5 km/h heel strike; 7.23 before the push-off; 8.63 at frame 176, l_knee, and 12.6 at frame 144, l_toe, the first swing from standing, before the full first step and the lift's speed floor)

/// The mechanism of the heel-strike fix (klawhs): the landing ankle enters the contact already
/// plantarflexing at the stance foot's early rate (bounded by `MAX_CONTACT_ANKLE_RATE`), instead
/// of arriving at rest and rolling at 8–15 rad/s the next frame. Pinned at 5 and 7 km/h: the
/// last pre-contact frame's ankle step is that of a rate of 1.5 rad/s to 1.35 × the bound
/// (main before: 0.2 rad/s; where in the frame the contact falls moves it within that range;
/// with the bound at 3 rad/s the range was 0.9–4; at 6 rad/s it is measured 1.59–4.38, the
/// first heel strike of the walk included since the lead-in, `generate::LEAD_IN_FRAMES`; with
/// the contact ramp `SwingFoot::contact_ramp` 2.67–5.20),
/// and the ankle's continuity ratio over the contact (± 3 frames) stays below its measurement.
#[test]
fn landing_ankle_is_already_plantarflexing_at_heel_strike() {
    let rate = gaitfit::generator::walking::generate::MAX_CONTACT_ANKLE_RATE;
    for (kmh, bound) in [(5.0, HS_ANKLE_5KMH), (7.0, HS_ANKLE_7KMH)] {
        let (m, _) = common::steady(kmh, 1.8, 8);
        let fps = m.fps();
        let mut seen = (f64::INFINITY, 0.0f64);
        for (f, side) in contact_frames(&m) {
            // The last full frame before the contact: s[f − 2], or s[f − 1] for a contact
            // exactly on frame f (a steady walk's first, `generate::LEAD_IN_FRAMES` in).
            let t = m
                .events
                .iter()
                .find(|e| {
                    e.kind == EventKind::HeelStrike && (e.time_s * fps - 1e-9).ceil() as usize == f
                })
                .map_or(0.0, |e| e.time_s * fps);
            let last = (t + 1e-9).floor() as usize - 1;
            let pre = joint_steps(&m, Joint::leg(side)[2])[last] * fps;
            seen = (seen.0.min(pre), seen.1.max(pre));
            assert!(
                pre > 1.5 && pre < 1.35 * rate,
                "{kmh} km/h, contact at frame {f}: ankle rate before contact {pre:.2} rad/s"
            );
        }
        let (worst, checked) = contact_ratio(&m, |s| Joint::leg(s)[2]);
        assert!(checked >= 6, "{kmh} km/h: {checked} contacts checked");
        println!(
            "{kmh} km/h: ankle rate before contact {:.2}–{:.2} rad/s",
            seen.0, seen.1
        );
        println!("{kmh} km/h: worst ankle ratio over the contacts {worst:.2} (bound {bound})");
        assert!(
            worst <= bound,
            "{kmh} km/h: ankle ratio {worst:.2} > {bound}"
        );
    }
}

/// The arms swing with the opposite leg's axis through a second-order lag (`swing_arms`,
/// `ArmLag` in `generate.rs`): at 7 km/h, where the landing leg stops flexing and retracts
/// within the last three frames before contact, no shoulder or elbow joint jolts around a heel
/// strike. Worst ratio of either arm's shoulder and elbow within ± 3 frames of every contact,
/// 1.5 / 1.8 / 2.0 m: measured 1.18 / 1.13 / 1.16 (the thigh through a one-stage lag before:
/// 5.95 at 1.5 m, one frame before a heel strike), guarded at 1.25 × the worst.
#[test]
fn the_arms_do_not_jolt_at_heel_strike() {
    for h in [1.5, 1.8, 2.0] {
        let (m, _) = common::steady(7.0, h, 8);
        let mut worst: f64 = 0.0;
        for j in [1, 2] {
            for opposite in [false, true] {
                let (w, checked) = contact_ratio(&m, |s| {
                    Joint::arm(if opposite { s.opposite() } else { s })[j]
                });
                assert!(checked >= 6, "{h} m: {checked} contacts checked");
                worst = worst.max(w);
            }
        }
        println!("7 km/h {h} m: worst arm ratio over the contacts {worst:.2}");
        assert!(
            worst <= ARMS_7KMH,
            "{h} m: arm ratio {worst:.2} > {ARMS_7KMH}"
        );
    }
}

/// Worst shoulder or elbow ratio within ± 3 frames of a heel strike at 7 km/h, × 1.25.
const ARMS_7KMH: f64 = 1.25 * 1.18;

/// Worst ankle ratio within ± 3 frames of a heel strike, measured (klawhs) × 1.25.
const HS_ANKLE_5KMH: f64 = 1.25 * 3.26; // since the contact ramp (`SwingFoot::contact_ramp`; 3.66 before); since the lead-in (the first heel strike now counted; 3.94 before, with one pre-roll step); 4.61 before the midstance lock, 6.06 before the contact rate 6 rad/s, 8.1 before the push-off
const HS_ANKLE_7KMH: f64 = 1.25 * 4.01; // since the contact ramp (6.42 bound before); 6.48 since the lead-in, at the first heel strike (now counted: it falls exactly on frame 5; the later ones ≤ 6.4), bound kept; 8.55 before the midstance lock, 10.57 before the contact rate 6 rad/s, 13.9 before the push-off

/// A walk of 6 steps at `kmh` and height `h` that ends in a stop (from standing if `rest`), and
/// its heel strikes as fractional frame numbers.
fn six_steps_to_a_stop(kmh: f64, h: f64, rest: bool) -> (Motion, Vec<f64>) {
    let (m, _) = common::walk(&[(kmh, 6)], h, rest, true);
    let hs = common::heel_strike_frames(&m);
    (m, hs)
}

/// The start and the stop, region by region (`checks::continuity_over`: the same ratios, local
/// medians over the whole motion, reported only for the steps that begin in the region), for
/// 6-step walks with a stop at 1/2/3/5/7 km/h × 1.5/1.8/2.0 m, steady start and from standing:
/// - *start*: frames before the second heel strike of the motion (steady: the lead-in of
///   `generate::LEAD_IN_FRAMES` and the first step; from standing: the first step, from rest,
///   and the next, whose trailing foot stood through the first);
/// - *stop*: from the last step's heel strike to the end (the kinematic closing, `stop.rs`).
///
/// Regression guard like the one above (1.25 × the measurement of 2026-11-27 00:40 UTC on
/// bbb3597 + the stop's planned heel rocker, its contact ankle rate and the first stance
/// foot's landing pitch; the 1–2 km/h starts re-measured after the stance lock's blend,
/// `stance::blend_rate_jump`), not the target k = 5. The stop is within 5 at
/// 1–3 km/h and 7 km/h, 4.8–5.7 at 5 km/h (it was 5.3–7.0 at 1 and 3 km/h, 6–10 at 5–7 km/h:
/// the straight-leg heel rocker slapped the foot flat and snapped the knee, and the last swing
/// ankle arrived at rest into the rocker); what remains is the heel's landing at 5 km/h. What remains at the start, located:
/// steady start — the first heel strike's ankle spike, which frame 0 used to be (its rate
/// decaying within the 3 frames the one-sided window saw) and which the lead-in (klawlead)
/// now gives its pre-contact frames, as every later heel strike has; within the region, the
/// heel-strike ankle and toe-off knee spikes of every step. From standing (klawfirst, 2026-11-27 02:25 UTC): the
/// first step keeps its full length and the first two trailing legs roll onto their toes before
/// their toe off (the first only as far as its thigh allows), so the first swings no longer stay
/// on the ground through swing1 and get thrown forward in swing2 (1–5 km/h from standing at
/// 1.5/1.8/2.0 m: 4.0–6.8, was 4.4–11.4); what is left there is mostly the heel strikes of the
/// first two steps, which now land with a real step's hip approach (5 km/h × 2.0 m 4.9 → 5.6,
/// 7 km/h × 1.8/2.0 m 9.5/7.6 → 11.6/9.5, at the second heel strike); those bounds are kept. The
/// stop's last half step ends swing1 later (`STOP_SWING1_DELAY`): stops at 1–5 km/h lower,
/// 7 km/h × 1.8 m 4.7 → 5.5 (the heel's landing; bound kept). Since the stop's swings are
/// braked (klawsched, `generate::FIRST_PAPER_SWINGS`' doc) the stop is within k = 5 everywhere
/// (1.7–4.8); its bounds at 1 km/h × 1.5/2.0 m, 3 km/h × 1.5/1.8 m, 5 km/h × 1.5/1.8 m and
/// 7 km/h × 1.5/2.0 m were raised to the new measurement (the landing knee leaves its lock at
/// 0.5 rad/s at 1 km/h × 1.5 m: 2.3 → 4.8), for the half step's 6.6 → 2.9 and the recovery.
#[test]
fn the_start_and_the_stop_do_not_regress() {
    // (km/h, height, from standing, measured worst ratio over the start, over the stop)
    #[rustfmt::skip]
    let cases: &[(f64, f64, bool, f64, f64)] = &[
        (1.0, 1.5, false, 3.76, 2.48), // stop now 2.66 at 688 l_ankle since the stop's contact ankle rate runs from the heel strike to 10 ms past the leg's reach (`Closing::contact_ankle_rate`), within the bound, kept; stop 2.48 at 688 l_ankle since the rocker's landing scan leaves a dipping knee (`VirtualLeg::plan_heel_rocker`; 4.78 at 689 l_knee before); start 11 l_hip (4.2 at 113 r_heel before the lead-in, generate::LEAD_IN_FRAMES; 5.6 at 12 l_knee, heel off, before the knee ease), stop 688 l_ankle; stop 2.6 before STOP_SWING2_ADVANCE; stop 4.78 at 689 l_knee since the stop's swings are braked (was 2.3)
        (1.0, 1.8, false, 2.99, 3.5), // stop now 3.65 at 756 l_knee since the stop's contact ankle rate runs from the heel strike to 10 ms past the leg's reach (`Closing::contact_ankle_rate`), within the bound, kept; start 14 l_ankle (4.2 at 111 r_knee before the lead-in), stop 756 l_knee
        (1.0, 2.0, false, 3.91, 1.94), // stop 1.94 at 797 l_heel since the stop's contact ankle rate runs from the heel strike to 10 ms past the leg's reach (`Closing::contact_ankle_rate`; was 2.0); stop 2.00 at 873 l_elbow since the rocker's landing scan leaves a dipping knee (2.44 at 798 l_knee before); start 87 l_knee (4.2 at 117 r_knee before the lead-in; 8.5 at 11 l_knee, heel off, before the knee ease), stop 873 l_elbow (2.02 since the lead-in's second pre-roll step); stop 2.1 before STOP_SWING2_ADVANCE; stop 2.44 at 798 l_knee since the stop's swings are braked (was 1.94)
        (2.0, 1.5, false, 3.35, 1.96), // stop 1.96 at 490 l_ankle since the stop's contact ankle rate runs from the heel strike to 10 ms past the leg's reach (`Closing::contact_ankle_rate`; was 2.47); start 20 l_knee (4.6 at 80 r_knee before the lead-in), stop 487 l_heel; 6.3 before the rocker's landing scan; stop 4.0 before STOP_SWING2_ADVANCE; stop 2.47 at 489 l_ankle since the stop's swings are braked (was 2.92)
        (2.0, 1.8, false, 4.03, 2.38), // stop 2.38 at 536 l_ankle measured since the slowest stances lower the hip (`generate::SLOW_REST_REACH`, `generate::edge_lock`; the heel stays down), was 1.7; stop now 2.01 at 536 l_ankle since the stop's contact ankle rate runs from the heel strike to 10 ms past the leg's reach (`Closing::contact_ankle_rate`), within the bound, kept; start 36 r_ankle (5.0 at 79 l_elbow before the lead-in), stop 534 l_ankle (1.96 since the lead-in's second pre-roll step; 560 r_metatarsal before); stop 2.12 at 580 l_elbow since the rocker's landing scan
        (2.0, 2.0, false, 4.48, 2.41), // stop 2.41 at 563 l_ankle measured since the slowest stances lower the hip (`generate::SLOW_REST_REACH`, `generate::edge_lock`; the heel stays down), was 1.87; stop 1.87 at 563 l_ankle since the stop's contact ankle rate runs from the heel strike to 10 ms past the leg's reach (`Closing::contact_ankle_rate`; was 2.05); start 39 r_ankle (5.1 at 92 r_heel before the lead-in), stop 563 l_ankle; stop 2.4 before STOP_SWING2_ADVANCE; stop 2.05 at 563 l_ankle since the stop's swings are braked (was 2.22)
        (3.0, 1.5, false, 3.17, 2.32), // stop 2.32 at 400 l_ankle since the stop's contact ankle rate runs from the heel strike to 10 ms past the leg's reach (`Closing::contact_ankle_rate`; was 2.68); start 5 l_ankle, the first heel strike (4.9 at 0 before the lead-in; 5.0 before the push-off), stop 400 l_ankle; stop 2.7 before STOP_SWING2_ADVANCE; stop 2.68 at 400 l_ankle since the stop's swings are braked (was 2.21)
        (3.0, 1.8, false, 3.30, 2.88), // stop 2.88 at 438 l_ankle since the stop's contact ankle rate runs from the heel strike to 10 ms past the leg's reach (`Closing::contact_ankle_rate`; was 3.58); start 16 l_knee (3.9 at 44 r_knee before the lead-in), stop 438 l_ankle; stop 3.58 at 438 l_ankle since the stop's swings are braked (was 2.9)
        (3.0, 2.0, false, 3.7, 3.15), // stop 3.141 (written 3.15: clippy reads 3.14 as π) at 462 l_ankle since the stop's contact ankle rate runs from the heel strike to 10 ms past the leg's reach (`Closing::contact_ankle_rate`; RAISED from 2.14: the landing pitch's hold before the leg reaches now sits between the swing's and the roll's rates); start 29 r_ankle (3.74 since the lead-in; 47 r_knee before), stop 464 l_ankle; stop 2.14 at 464 l_ankle since the stop's swings are braked (was 2.3)
        (5.0, 1.5, false, 3.64, 3.09), // stop 3.09 at 310 l_ankle since the stop's contact ankle rate runs from the heel strike to 10 ms past the leg's reach (`Closing::contact_ankle_rate`; was 3.09); since the contact ramp (`SwingFoot::contact_ramp`) measured 3.64 at 5 l_ankle; before: start 5 l_ankle, the first heel strike, now with its pre-contact frames (frame 0's 5.80 before the lead-in; 9.29 before the midstance lock; 9.5 before the contact rate 6 rad/s), stop 310 r_elbow; 12.1 before the rocker's landing scan; stop 4.4 before STOP_SWING2_ADVANCE; stop 3.09 at 310 l_ankle since the stop's swings are braked (was 2.08)
        (5.0, 1.8, false, 2.86, 3.13), // stop 3.13 at 340 l_ankle since the stop's contact ankle rate runs from the heel strike to 10 ms past the leg's reach (`Closing::contact_ankle_rate`; was 3.55); since the contact ramp (`SwingFoot::contact_ramp`) measured 2.86 at 5 l_ankle; before: start 5 l_ankle, the first heel strike (3.66 at frame 0 before the lead-in; 4.74 before the midstance lock; 4.8 before the contact rate 6 rad/s, 8.6 before the push-off), stop 340 l_ankle; stop 4.9 before STOP_SWING2_ADVANCE; stop 3.55 at 340 l_ankle since the stop's swings are braked (was 2.82)
        (5.0, 2.0, false, 2.44, 2.53), // stop 2.53 at 359 l_ankle since the stop's contact ankle rate runs from the heel strike to 10 ms past the leg's reach (`Closing::contact_ankle_rate`; was 3.11); since the contact ramp (`SwingFoot::contact_ramp`) measured 2.44 at 63 r_heel; before: start 5 l_ankle, the first heel strike (3.16 at frame 0 before the lead-in; 3.77 before the midstance lock; 6.0 before the contact rate 6 rad/s; 6.86 at 0 r_knee since the push-off: the trailing knee straightens to rest at the first heel strike), stop 359 l_ankle; stop 4.9 before STOP_SWING2_ADVANCE
        (7.0, 1.5, false, 5.29, 3.36), // stop 3.36 at 263 l_ankle since the stop's contact ankle rate runs from the heel strike to 10 ms past the leg's reach (`Closing::contact_ankle_rate`; was 3.37); since the contact ramp (`SwingFoot::contact_ramp`) measured 5.29 at 48 r_ankle; before: start 48 r_ankle, the second heel strike (11.1 since the lead-in, 43 before; 12.3 before the contact rate 6 rad/s; 11.2 with the midstance lock, bound kept), stop 263 l_ankle; stop 3.5 before STOP_SWING2_ADVANCE; stop 3.37 at 263 l_ankle since the stop's swings are braked (was 2.65)
        (7.0, 1.8, false, 4.01, 3.67), // stop now 3.78 at 287 l_ankle since the stop's contact ankle rate runs from the heel strike to 10 ms past the leg's reach (`Closing::contact_ankle_rate`), within the bound, kept; since the contact ramp (`SwingFoot::contact_ramp`) measured 4.01 at 5 l_ankle; before: start 5 l_ankle, the first heel strike, now with its pre-contact frames (6.48 since the lead-in; frame 0's 6.44 before; 16.1 before the push-off; 10.2 on c4af9fa, before the midstance lock), stop 4.47 before the midstance lock, 5.24 since the push-off, stop 287 l_heel; stop 4.7 before STOP_SWING2_ADVANCE; stop 3.67 at 287 l_ankle since the stop's swings are braked (was 3.99)
        (7.0, 2.0, false, 3.10, 2.38), // stop 2.38 at 303 l_ankle since the stop's contact ankle rate runs from the heel strike to 10 ms past the leg's reach (`Closing::contact_ankle_rate`; was 2.41); since the arms follow the leg's axis through a second-order lag (`swing_arms`) measured 3.10 at 5 l_ankle; since the contact ramp (`SwingFoot::contact_ramp`) 3.51 at 4 r_elbow; before: start 5 l_ankle, the first heel strike (4.52 at frame 0 before the lead-in; 5.83 before the midstance lock; 10.1 before the push-off), stop 2.41 since the push-off, stop 304 l_ankle; stop 2.3 before STOP_SWING2_ADVANCE; stop 2.41 at 303 l_ankle since the stop's swings are braked (was 1.95)
        (1.0, 1.5, true, 3.24, 2.48), // stop now 2.66 at 683 l_ankle since the stop's contact ankle rate runs from the heel strike to 10 ms past the leg's reach (`Closing::contact_ankle_rate`), within the bound, kept; start 125 r_knee since the first swing from standing is braked and bell-shaped (klawstart2, `generate::first_swing_shape`); before: start 5.53 at 113 r_heel, stop 2.48 at 683 l_ankle (4.78 at 684 l_knee before); start 113 r_heel, stop 684 l_knee; stop 2.6 before STOP_SWING2_ADVANCE; stop 4.78 at 684 l_knee since the stop's swings are braked (was 2.28)
        (1.0, 1.8, true, 3.27, 3.4), // stop now 3.65 at 751 l_knee since the stop's contact ankle rate runs from the heel strike to 10 ms past the leg's reach (`Closing::contact_ankle_rate`), within the bound, kept; start 125 r_knee since the first swing from standing is braked and bell-shaped (klawstart2, `generate::first_swing_shape`); before: start 111 r_knee, stop 751 l_knee
        (1.0, 2.0, true, 3.71, 1.94), // stop 1.94 at 792 l_heel since the stop's contact ankle rate runs from the heel strike to 10 ms past the leg's reach (`Closing::contact_ankle_rate`; was 2.0); start 141 r_ankle since the first swing from standing is braked and bell-shaped (klawstart2, `generate::first_swing_shape`); before: stop 2.00 at 868 l_elbow since the rocker's landing scan leaves a dipping knee (2.44 before); start 117 r_knee, stop 793 l_knee; stop 2.1 before STOP_SWING2_ADVANCE; stop 2.44 at 793 l_knee since the stop's swings are braked (was 1.94)
        (2.0, 1.5, true, 3.61, 1.96), // start 3.61 at 92 r_knee measured since the slowest stances lower the hip (`generate::SLOW_REST_REACH`, `generate::edge_lock`; the heel stays down), was 2.84; stop 1.96 at 485 l_ankle since the stop's contact ankle rate runs from the heel strike to 10 ms past the leg's reach (`Closing::contact_ankle_rate`; was 2.47); start 160 l_heel since the first swing from standing is braked and bell-shaped (klawstart2, `generate::first_swing_shape`) and its toe's clearance ramps in over at least 15 % of the swing (`swing::CLEARANCE_RAMP_MIN`); before: start 72 r_hip (4.42 at 160 l_heel before FIRST_PAPER_SWINGS = 1), was 80 r_knee, stop 482 l_heel; 6.1 before the rocker's landing scan; stop 4.1 before STOP_SWING2_ADVANCE; stop 2.47 at 484 l_ankle since the stop's swings are braked (was 2.92)
        (2.0, 1.8, true, 3.49, 2.38), // stop 2.38 at 531 l_ankle measured since the slowest stances lower the hip (`generate::SLOW_REST_REACH`, `generate::edge_lock`; the heel stays down), was 1.7; stop now 2.01 at 531 l_ankle since the stop's contact ankle rate runs from the heel strike to 10 ms past the leg's reach (`Closing::contact_ankle_rate`), within the bound, kept; start 100 r_knee since the first swing from standing is braked and bell-shaped (klawstart2, `generate::first_swing_shape`) and its toe's clearance ramps in over at least 15 % of the swing (`swing::CLEARANCE_RAMP_MIN`) (3.70 at 100 r_knee before); before: start 176 l_knee, stop 560 r_metatarsal
        (2.0, 2.0, true, 3.80, 2.41), // stop 2.41 at 558 l_ankle measured since the slowest stances lower the hip (`generate::SLOW_REST_REACH`, `generate::edge_lock`; the heel stays down), was 1.87; stop 1.87 at 558 l_ankle since the stop's contact ankle rate runs from the heel strike to 10 ms past the leg's reach (`Closing::contact_ankle_rate`; was 2.05); start 105 r_knee since the first swing from standing is braked and bell-shaped (klawstart2, `generate::first_swing_shape`) (4.75 at 92 r_heel before); before: start 185 l_heel (5.15 since the full first step), stop 557 l_heel; stop 2.4 before STOP_SWING2_ADVANCE; stop 2.05 at 558 l_ankle since the stop's swings are braked (was 2.22)
        (3.0, 1.5, true, 3.44, 2.32), // stop 2.32 at 395 l_ankle since the stop's contact ankle rate runs from the heel strike to 10 ms past the leg's reach (`Closing::contact_ankle_rate`; was 2.68); start 76 r_knee since the first swing from standing is braked and bell-shaped (klawstart2, `generate::first_swing_shape`); before: start 131 l_ankle (3.56 before FIRST_PAPER_SWINGS = 1; 58 l_shoulder earlier), stop 395 l_ankle; stop 2.7 before STOP_SWING2_ADVANCE; stop 2.68 at 395 l_ankle since the stop's swings are braked (was 2.21)
        (3.0, 1.8, true, 3.03, 2.88), // stop 2.88 at 433 l_ankle since the stop's contact ankle rate runs from the heel strike to 10 ms past the leg's reach (`Closing::contact_ankle_rate`; was 3.58); start 83 r_knee since the first swing from standing is braked and bell-shaped (klawstart2, `generate::first_swing_shape`) and its toe's clearance ramps in over at least 15 % of the swing (`swing::CLEARANCE_RAMP_MIN`) (4.22 at 71 r_heel before); before: start 64 l_elbow, stop 433 l_ankle; stop 3.58 at 433 l_ankle since the stop's swings are braked (was 2.9)
        (3.0, 2.0, true, 3.08, 3.15), // stop 3.141 (written 3.15: clippy reads 3.14 as π) at 457 l_ankle since the stop's contact ankle rate runs from the heel strike to 10 ms past the leg's reach (`Closing::contact_ankle_rate`; RAISED from 2.14: the landing pitch's hold before the leg reaches now sits between the swing's and the roll's rates); start 84 r_ankle since the first swing from standing is braked and bell-shaped (klawstart2, `generate::first_swing_shape`) and its toe's clearance ramps in over at least 15 % of the swing (`swing::CLEARANCE_RAMP_MIN`) (4.07 at 66 r_knee before); before: start 66 r_knee, stop 499 l_elbow; stop 2.14 at 459 l_ankle since the stop's swings are braked (was 2.3)
        (5.0, 1.5, true, 3.98, 3.09), // stop 3.09 at 305 l_ankle since the stop's contact ankle rate runs from the heel strike to 10 ms past the leg's reach (`Closing::contact_ankle_rate`; was 3.09); start 61 r_knee since the first swing from standing is braked and bell-shaped (klawstart2, `generate::first_swing_shape`) (5.74 at 28 r_ankle before: swing1's slaved ankle racing across its curve near t1); before: start 51 r_ankle (28 r_ankle 5.74 since the contact ramp, the first swing from standing, bound kept; 6.8 at 101 l_ankle before the contact rate 6 rad/s), stop 305 l_heel; stop 4.5 before STOP_SWING2_ADVANCE; stop 3.09 at 305 l_ankle since the stop's swings are braked (was 2.08)
        (5.0, 1.8, true, 3.38, 3.13), // stop 3.13 at 335 l_ankle since the stop's contact ankle rate runs from the heel strike to 10 ms past the leg's reach (`Closing::contact_ankle_rate`; was 3.55); start 56 r_ankle since the first swing from standing is braked and bell-shaped (klawstart2, `generate::first_swing_shape`); before: start 31 r_knee (5.57 at 111 before the midstance lock; 5.6 at 31 before the contact rate 6 rad/s), stop 334 l_heel; stop 5.0 before STOP_SWING2_ADVANCE; stop 3.55 at 335 l_ankle since the stop's swings are braked (was 2.82)
        (5.0, 2.0, true, 3.35, 2.53), // stop 2.53 at 354 l_ankle since the stop's contact ankle rate runs from the heel strike to 10 ms past the leg's reach (`Closing::contact_ankle_rate`; was 3.11); start 59 r_hip since the first swing from standing is braked and bell-shaped (klawstart2, `generate::first_swing_shape`) (3.80 at 33 r_knee before); before: start 33 r_knee (4.9 at 59 r_ankle before; 5.57 since the full first step; 5.14 at 117 r_knee with the contact rate 6 rad/s), stop 352 l_heel; stop 4.9 before STOP_SWING2_ADVANCE
        (7.0, 1.5, true, 5.61, 3.36), // stop 3.36 at 258 l_ankle since the stop's contact ankle rate runs from the heel strike to 10 ms past the leg's reach (`Closing::contact_ankle_rate`; was 3.37); since the contact ramp (`SwingFoot::contact_ramp`) measured 5.61 at 86 l_ankle; before: start 43 r_ankle (12.0 before the contact rate 6 rad/s; 9.54 at 86 l_ankle with the midstance lock, bound kept), stop 258 l_ankle; stop 3.5 before STOP_SWING2_ADVANCE; stop 3.37 at 258 l_ankle since the stop's swings are braked (was 2.65)
        (7.0, 1.8, true, 3.75, 3.67), // stop now 3.78 at 282 l_ankle since the stop's contact ankle rate runs from the heel strike to 10 ms past the leg's reach (`Closing::contact_ankle_rate`), within the bound, kept; since the contact ramp (`SwingFoot::contact_ramp`) measured 3.75 at 94 l_ankle; before: start 94 l_ankle (8.11 before the midstance lock, stop 4.47; 9.1 at 47 r_ankle before the contact rate 6 rad/s; 11.7 at 94 since the full first step, the second heel strike; 9.09 since the push-off), stop 5.24 since the push-off, stop 282 l_heel (5.5 with STOP_SWING1_DELAY); stop 5.1 before STOP_SWING2_ADVANCE; stop 3.67 at 282 l_ankle since the stop's swings are braked (was 3.99)
        (7.0, 2.0, true, 3.35, 2.38), // stop 2.38 at 298 l_ankle since the stop's contact ankle rate runs from the heel strike to 10 ms past the leg's reach (`Closing::contact_ankle_rate`; was 2.41); start 50 r_ankle since the first swing from standing is braked and bell-shaped (klawstart2, `generate::first_swing_shape`) (4.22 at 43 r_hip before); since the contact ramp (`SwingFoot::contact_ramp`) measured 4.22 at 43 r_hip; before: start 50 r_ankle (5.15 at 99 l_ankle before the midstance lock; 7.6 before the contact rate 6 rad/s; 9.48 since the full first step: the second heel strike; 7.52 since the push-off), stop 2.40 since the push-off, stop 299 l_ankle; stop 2.3 before STOP_SWING2_ADVANCE; stop 2.41 at 298 l_ankle since the stop's swings are braked (was 1.95)
    ];
    let mut failures = Vec::new();
    for &(kmh, h, rest, start_ratio, stop_ratio) in cases {
        let (m, hs) = six_steps_to_a_stop(kmh, h, rest);
        assert!(hs.len() >= 4, "{kmh} km/h {h} m: {} heel strikes", hs.len());
        let o = ContinuityOptions::default();
        let start = continuity_over(&m, &o, 0..hs[1].ceil() as usize);
        let stop = continuity_over(&m, &o, hs[hs.len() - 2].floor() as usize..m.len());
        println!("{kmh} km/h {h} m from standing {rest}: start {start}; stop {stop}");
        for (what, r, measured) in [("start", &start, start_ratio), ("stop", &stop, stop_ratio)] {
            assert!(r.examined > 100, "{what}: {} examined", r.examined);
            if r.worst > 1.25 * measured {
                failures.push(format!(
                    "{kmh} km/h {h} m from standing {rest}, {what}: {:.1} > 1.25 × {measured}",
                    r.worst
                ));
            }
        }
    }
    assert!(failures.is_empty(), "{failures:#?}");
}

/// Walks of 6 steps from standing to a stop meet k = 5 (`checks::continuity`, the whole walk)
/// since the first swing from standing is braked and bell-shaped (klawstart2,
/// `generate::first_swing_shape`; before: main 8d2edf8): 5 km/h × 1.5 m 5.74 → 4.24 (the first swing's
/// swing1 ankle raced across its curve near t1, 4.4 m/s at frame 28; now 102 l_knee, the
/// second heel strike), 4 km/h × 1.8/2.0 m 7.62/10.54 → 3.56/3.55, 1 km/h × 1.5/1.8/2.0 m
/// 5.53/4.98/4.58 → 4.25/3.65/4.30 (since 4fee3bf's rocker trade; 4.78 at 684 l_knee, the
/// stop, before). 4 km/h × 1.5 m since the first stance from standing pushes off late
/// (klawstart4, `stance::first_push_off_exponent`): 8.62 → 5.17 → 4.40 (57 r_knee, the first
/// heel strike after the start: the hip fell onto it at −0.43 m/s, now −0.30, and the landing
/// knee left its lock at 3 × its mean rate, now 2.5 ×), 1.55 m 5.37 → 4.59 (58 r_knee). Not
/// yet: 7 km/h × 1.5 m (5.56, 86 l_ankle, a heel strike of the walk–run transition, see
/// `fast_short_heel_strikes_do_not_regress`).
#[test]
fn walks_from_standing_meet_k5() {
    #[rustfmt::skip]
    let cases = [
        (1.0, 1.5), (1.0, 1.8), (1.0, 2.0),
        (2.0, 1.5), (2.0, 1.8), (2.0, 2.0),
        (3.0, 1.5), (3.0, 1.8), (3.0, 2.0),
        (4.0, 1.5), (4.0, 1.55), (4.0, 1.8), (4.0, 2.0),
        (5.0, 1.5), (5.0, 1.8), (5.0, 2.0),
        (6.0, 1.5), (6.0, 1.8), (6.0, 2.0),
        (7.0, 1.8), (7.0, 2.0),
    ];
    let mut failures = Vec::new();
    for (kmh, h) in cases {
        let (w, report) = worst(&[(kmh, 6)], h, true);
        println!("{kmh} km/h {h} m from standing: {report}");
        if w > ContinuityOptions::default().k {
            failures.push(format!("{kmh} km/h {h} m: {report}"));
        }
    }
    assert!(failures.is_empty(), "{failures:#?}");
}

/// The trailing knee flexes steadily through the double support (klawfirst2, `hold_knees`): from
/// each heel strike to the other foot's toe off it never straightens by more than 1 mrad in a
/// frame (the continuity floor; measured ≤ 0.46 mrad). It used to straighten by 0.01 rad in the frame after heel strike (≈ 1 rad/s, undoing
/// the flexion the smoothed heel-off roll put there before heel strike) and then rest until its
/// meta-off flexion — at the recorded walk's first frame a ratio of 10.5 (6 km/h × 2.0 m). Steady
/// walks of 8 steps, 3–7 km/h × 1.5/1.8/2.0 m.
#[test]
fn the_trailing_knee_does_not_straighten_in_double_support() {
    let mut failures = Vec::new();
    for kmh in [3.0, 5.0, 6.0, 7.0] {
        for h in [1.5, 1.8, 2.0] {
            let (m, _) = common::steady(kmh, h, 8);
            let fps = m.fps();
            let mut worst = (0.0f64, 0usize);
            for hs in m.events.iter().filter(|e| e.kind == EventKind::HeelStrike) {
                let trailing = hs.side.opposite();
                let Some(to) = common::next_event(&m, EventKind::ToeOff, trailing, hs.time_s)
                else {
                    continue;
                };
                let knee = joint_angles(&m, Joint::leg(trailing)[1]);
                let (a, b) = (
                    (hs.time_s * fps).floor() as usize,
                    ((to.time_s * fps).floor() as usize).min(knee.len() - 1),
                );
                for f in a..b {
                    let straighten = knee[f] - knee[f + 1];
                    if straighten > worst.0 {
                        worst = (straighten, f);
                    }
                }
            }
            println!(
                "{kmh} km/h {h} m: trailing knee straightens at most {:.5} rad/frame (frame {})",
                worst.0, worst.1
            );
            if worst.0 > 1e-3 {
                failures.push(format!(
                    "{kmh} km/h {h} m: {:.5} at frame {}",
                    worst.0, worst.1
                ));
            }
        }
    }
    assert!(failures.is_empty(), "{failures:#?}");
}

/// A speed-up whose trailing foot is still flat when the faster step's double support begins
/// (1 km/h stance legs of a 2.0 m body: the foot is flat only in passing, heel off starts late)
/// rolls it through heel off as the rule does; only a foot already in heel off enters meta-off
/// early (`generate::speeds_up`). Snapping the flat foot into meta-off moved its toe 22 mm in one
/// frame: 1 → 3 and 1 → 5 km/h × 2.0 m (ramped by the default limit, from standing, with a stop)
/// scored 46.4 (l_toe) and 22.8 (l_metatarsal); now 4.58 and 4.58 (frame 484, l_ankle): k = 5 met.
/// Since the stance simulation locks at the paper's `l1` and the drawing lowers the pelvis
/// instead (`draw::PelvisDrop`, issue 20 stage A): 1 → 3 km/h within k = 5, 1 → 5 km/h 5.75
/// (frame 526, l_ankle: a 5 km/h heel strike), bounded at 1.05 × that; since the drawn pelvis
/// height is the least-bending curve below the simulated hip (`pelvis_drop::PelvisLowering`,
/// stage B) 4.41 (frame 395, r_knee): k = 5 again.
#[test]
fn a_speed_up_from_a_flat_trailing_foot_stays_continuous() {
    let mut failures = Vec::new();
    for to_kmh in [3.0, 5.0] {
        let bound = ContinuityOptions::default().k;
        let (w, r) = worst(&[(1.0, 4), (to_kmh, 4)], 2.0, true);
        if w > bound {
            failures.push(format!("1 -> {to_kmh} km/h x 2.0 m: {r}"));
        }
    }
    assert!(failures.is_empty(), "{failures:#?}");
}

/// A slow step whose heel rocker finds no landing (1 → 1.5 km/h × 2.0 m from standing, with a
/// stop: the first 1.5 km/h stance, whose hip never comes within the straight leg's reach of the
/// flat ankle) is landed by the straight leg with the knee straight; the flat and heel-off rules
/// asked for the soft leg length in that same frame (foot flat and heel off at once: the knee
/// 0.112 rad in one frame, ratio 111.9). The knee then eased up from straight
/// (`KNEE_LAND_EASE`): measured 4.58 (frame 484, l_ankle), k = 5 met. Since the drawn pelvis
/// height is the least-bending curve below the simulated hip (`pelvis_drop::PelvisLowering`)
/// the knee eases are deleted (issue 20 stage B) and k = 5 is still met.
#[test]
fn a_straight_leg_landing_eases_the_knee() {
    let (w, r) = worst(&[(1.0, 4), (1.5, 4)], 2.0, true);
    assert!(w <= 5.0, "1 -> 1.5 km/h x 2.0 m: {r}");
}

/// 1 km/h walks of 1.6–1.7 m bodies (from standing, with a stop): the planned heel rocker lands
/// the foot where the flat foot's knee still straightens at ≈ 3 rad/s, 0.4 mm short of the
/// straight leg, and the flat period has no length. The knee's ease after foot flat started at
/// rest and threw that rate away, so the heel left the floor at 0.7 mm/frame from rest (1 km/h
/// × 1.7 m: 6.73 at frame 618, `5x4,1x6` 6.86 at 735, `6x4,1x6` 6.30 at 706, all r_heel), or,
/// where the landing narrowed the knee's soft margin less, the knee stopped dead at heel off
/// (1 km/h × 1.6 m: 6.81 at frame 600, r_knee). The ease now carries the rocker's knee rate on
/// (`KNEE_ROCKER_EASE`): measured 3.67 (frame 860, r_knee), 3.45 (217, l_ankle),
/// 3.56 (198, l_knee) and 3.32 (715, l_ankle): k = 5 met. The eases are deleted since the drawn
/// pelvis height is smoothed (`pelvis_drop::PelvisLowering`, issue 20 stage B): k = 5 still met.
#[test]
fn a_slow_walk_lands_flat_without_a_heel_pop() {
    let mut failures = Vec::new();
    let cases: [(&[(f64, usize)], f64); 4] = [
        (&[(1.0, 8)], 1.7),
        (&[(5.0, 4), (1.0, 6)], 1.7),
        (&[(6.0, 4), (1.0, 6)], 1.7),
        (&[(1.0, 8)], 1.6),
    ];
    for (sched, h) in cases {
        let (w, r) = worst(sched, h, true);
        println!("{sched:?} x {h} m: {r}");
        if w > ContinuityOptions::default().k {
            failures.push(format!("{sched:?} x {h} m: {r}"));
        }
    }
    assert!(failures.is_empty(), "{failures:#?}");
}

/// Slow walks between the grid points (steady start, 8 steps): at the switch from heel off to
/// meta-off the foot's roll dropped back from the heel-off rule's roll to `meta_off_rho`, moving
/// the ankle away from the hip within one 2 ms sample; the nearly straight knee straightened by
/// up to 0.014 rad there, drawn directly (1.2 km/h × 1.7 m 6.14, frame 602, l_knee, every step)
/// or, where the switch fell on the toe-off sample, as the swing's starting rates (1.25 km/h ×
/// 1.8 m 11.14, frame 59, r_knee, swing1's thigh torque −114 against −30 at the later steps;
/// 1.4 km/h × 2.0 m 5.66, frame 49, r_ankle). Meta-off now starts from the rule's roll
/// (diagnosis: klawdiag, session 9). Measured 4.14 (frame 337, r_knee), 3.74 (15, l_ankle),
/// 3.99 (571, r_ankle): k = 5 met.
#[test]
fn meta_off_starts_from_the_heel_off_roll() {
    let mut failures = Vec::new();
    for (v, h) in [(1.2, 1.7), (1.25, 1.8), (1.4, 2.0)] {
        let (w, r) = worst(&[(v, 8)], h, false);
        println!("{v} km/h x {h} m: {r}");
        if w > ContinuityOptions::default().k {
            failures.push(format!("{v} km/h x {h} m: {r}"));
        }
    }
    assert!(failures.is_empty(), "{failures:#?}");
}

/// Slowing 7 → 1 km/h (4 steps each, from standing, with a stop; ramped 7 → 5.5 → 4 → 2.5 →
/// 1 km/h) at 2.0 m: the slow steps' ankle leaves the ground high and the swing1 ankle curve's
/// far flank was as steep as the ankle's reach about the knee (73.5 at frame 498, l_knee, before
/// `LIFT_OVER_TOE_OFF` in `swing.rs`; 4.62 with it; 4.21 since `swing::REACH_SHARE` replaced it,
/// see `tests/klaw_swing_curve.rs`).
#[test]
fn slowing_from_7_to_1_kmh_keeps_the_swing_ankle_on_its_curve() {
    let (w, r) = worst(&[(7.0, 4), (1.0, 4)], 2.0, true);
    assert!(w <= 5.0, "7 -> 1 km/h x 2.0 m: {r}");
}

/// Slowing down into 1 km/h (4 steps each, from standing, with a stop; 3 → 1 km/h is ramped
/// 3 → 2 → 1): the first slower stance lands from the faster step's steeper heel-strike pitch,
/// and its shortest (eased) heel-rocker landing had to meet the flat foot's knee at 5 × its mean
/// rate — the knee flexed ≈ 0.012 rad in the first frame after contact, straightened, and surged
/// 0.2 rad at foot flat. The rocker's landing scan now leaves a landing whose knee dips
/// (`VirtualLeg::plan_heel_rocker`). Before: 3 → 1 km/h × 1.8 m 10.63 (frame 376, r_knee),
/// 2 → 1 km/h × 1.8 m 7.92 (frame 353, l_knee), 1.5 → 1 km/h × 2.0 m 6.16 (frame 429, l_knee),
/// all at that heel strike; after 4.22 (frame 71, r_heel, the first swing from standing), 3.99,
/// 4.77: k = 5 met.
#[test]
fn a_slow_down_lands_the_knee_without_a_dip() {
    let mut failures = Vec::new();
    for (from, to, h) in [(3.0, 1.0, 1.8), (2.0, 1.0, 1.8), (1.5, 1.0, 2.0)] {
        let (w, r) = worst(&[(from, 4), (to, 4)], h, true);
        println!("{from} -> {to} km/h x {h} m: {r}");
        if w > 5.0 {
            failures.push(format!("{from} -> {to} km/h x {h} m: {r}"));
        }
    }
    assert!(failures.is_empty(), "{failures:#?}");
}

/// A 1 → 7 km/h schedule (4 steps each, from standing, with a stop) is ramped by the default
/// `max_speed_change_m_per_s` = 0.5 m/s per step (1 → 2.5 → 4 → 5.5 → 7 km/h) and meets k = 5
/// at 1.5, 1.8 and 2.0 m. In one step (the limit off) the same walk scored 128.9 /
/// 153.9 / 5.36 at 1.5 / 1.8 / 2.0 m: the trailing leg of the first 7 km/h step.
#[test]
fn a_large_speed_change_is_ramped_and_stays_continuous() {
    // (height, bound): all three meet k = 5 since the braked first swing from standing
    // (`generate::first_swing_shape`) and swing1's reach bound (`swing::REACH_SHARE`).
    let cases = [
        // measured 3.90 (frame 633, r_knee); was 5.53 (frame 113, r_heel, the first swing from
        // standing) and 5.80 (frame 633, r_ankle, a 7 km/h heel strike, before the landing
        // ankle's contact ramp).
        (1.5, 5.0),
        // measured 3.62 (frame 740, l_ankle); was 4.98 (frame 111, r_knee, the start).
        (1.8, 5.0),
        // measured 3.88 (frame 345, l_knee); was 4.02 (frame 117) and 4.58 (frame 484, l_ankle)
        // before swing1's reach bound, 26.85 (frame 609, r_knee: the 4 km/h step's heel-rocker
        // knee leaving heel strike at 3 × its mean rate, before `VirtualLeg::plan_heel_rocker`
        // could trade a fast-starting eased landing for a gentler one), 32.0 (l_toe) before
        // `generate::speeds_up` stopped snapping a still-flat trailing foot into meta-off (see
        // `a_speed_up_from_a_flat_trailing_foot_stays_continuous`).
        (2.0, 5.0),
    ];
    let mut failures = Vec::new();
    for (h, bound) in cases {
        let (m, report) = common::walk(&[(1.0, 4), (7.0, 4)], h, true, true);
        // The ramp: 3 of the 7 km/h stretch's 4 steps, the last a half step (the stop).
        let kmh: Vec<f64> = report
            .steps
            .iter()
            .map(|s| s.step_length_m * s.step_freq_steps_per_min / 60.0 * 3.6)
            .collect();
        let expect = [1.0, 1.0, 1.0, 1.0, 2.5, 4.0, 5.5, 3.5];
        assert!(
            kmh.len() == expect.len() && kmh.iter().zip(expect).all(|(a, b)| (a - b).abs() < 1e-6),
            "{kmh:?}"
        );
        assert!(
            m.metadata
                .notes
                .iter()
                .any(|n| n.contains("max_speed_change_m_per_s")),
            "{:?}",
            m.metadata.notes
        );
        let r = continuity(&m, &ContinuityOptions::default());
        println!("1 -> 7 km/h {h} m: {r}");
        if r.worst > bound {
            failures.push(format!("{h} m: ratio {:.2} > {bound}", r.worst));
        }
    }
    assert!(failures.is_empty(), "{failures:?}");
}

/// A speed-up's trailing leg pushes off (`generate::speeds_up`): in the double support of the
/// first faster step of 2 → 4 and 2 → 5 km/h (4 steps each, from standing, with a stop,
/// 1.5/1.8/2.0 m) the trailing knee never straightens by more than 1 mrad in a frame (the
/// continuity floor) and leaves the ground flexed ≥ 0.4 rad. Before, that leg left the ground
/// nearly straight (0.12 rad at 2 → 5 km/h × 1.8 m, heel 7 cm up) after a flexion of 0.016 rad
/// that straightened again at up to 6.9 mrad/frame just before toe off (continuity 6.2 there;
/// 12.2 at 2 → 4 km/h × 2.0 m).
#[test]
fn a_speed_up_pushes_off_with_the_trailing_knee() {
    let mut failures = Vec::new();
    for fast in [4.0, 5.0] {
        for h in [1.5, 1.8, 2.0] {
            let mut opts = common::options(h, true, true);
            // The paper's one-step change (0.56 and 0.83 m/s), not the default ramp: this
            // tests the push-off of a large one-step speed-up.
            opts.attributes.max_speed_change_m_per_s = 10.0;
            let schedule = common::schedule(&[(2.0, 4), (fast, 4)]);
            let (m, report) = generate_walk(&schedule, &opts).unwrap();
            let step = &report.steps[4];
            let knee = joint_angles(&m, Joint::leg(step.stance_side.opposite())[1]);
            let fps = m.fps();
            let a = (step.start_s * fps).floor() as usize;
            let b = ((step.start_s + step.times.double_support) * fps).floor() as usize;
            let straighten = (a..b)
                .map(|f| knee[f] - knee[f + 1])
                .fold(f64::NEG_INFINITY, f64::max);
            println!(
                "2 -> {fast} km/h {h} m: trailing knee straightens at most {straighten:.5} \
                 rad/frame in frames {a}..{b}, {:.3} rad at toe off",
                knee[b]
            );
            if straighten > 1e-3 || knee[b] < 0.4 {
                failures.push(format!(
                    "2 -> {fast} km/h {h} m: straightens {straighten:.5}, toe-off knee {:.3}",
                    knee[b]
                ));
            }
        }
    }
    assert!(failures.is_empty(), "{failures:#?}");
}

/// Heel strikes with 4 frames of swing before and 4 of stance after (a steady walk's first
/// heel strike too, which comes `generate::LEAD_IN_FRAMES` = 5 frames into the recording): the
/// first frame at or after each contact, and its side.
fn contact_frames(m: &Motion) -> Vec<(usize, gaitfit::events::Side)> {
    let fps = m.fps();
    m.events
        .iter()
        .filter(|e| e.kind == EventKind::HeelStrike)
        .map(|e| ((e.time_s * fps - 1e-9).ceil() as usize, e.side))
        .filter(|&(f, _)| f >= 4 && f + 5 < m.len())
        .collect()
}

/// Worst continuity ratio of `joint_of(side)` within ± 3 frames of the walk's heel strikes
/// ([`contact_frames`]), and the number of contacts examined.
fn contact_ratio(m: &Motion, joint_of: impl Fn(gaitfit::events::Side) -> Joint) -> (f64, usize) {
    let mut worst: f64 = 0.0;
    let contacts = contact_frames(m);
    for &(f, side) in &contacts {
        // The ratio as `checks::continuity` takes it (window 3, floor 1e-3 rad).
        let r = step_ratios(&joint_steps(m, joint_of(side)), 3, 1e-3);
        for ratio in r[f - 3..=f + 2].iter().flatten() {
            worst = worst.max(*ratio);
        }
    }
    (worst, contacts.len())
}

/// Slow walks: the stance knee leaves heel strike from rest (C¹ with the swing's locked knee;
/// the planned heel rocker's start rate may now be 0), where it used to start at its mean rate
/// and then slow down (1 km/h, 1.5 m: knee ratio 6.3–6.5 at every contact).
#[test]
fn slow_walk_knee_leaves_heel_strike_from_rest() {
    for h in [1.5, 1.8, 2.0] {
        let (m, _) = common::steady(1.0, h, 6);
        let (worst, checked) = contact_ratio(&m, |s| Joint::leg(s)[1]);
        println!("1 km/h, {h} m: worst knee ratio over {checked} contacts {worst:.2}");
        assert!(checked >= 4);
        assert!(
            worst <= SLOW_KNEE_BOUND,
            "1 km/h, {h} m: knee ratio {worst:.2}"
        );
    }
}

/// Worst knee ratio within ± 3 frames of a contact at 1 km/h, 1.5–2.0 m (3.84 at 1.5 m) × 1.25.
const SLOW_KNEE_BOUND: f64 = 4.8;

/// The stop's last half step (from the second-to-last heel strike, exclusive, to the last),
/// steady start + stop, 6 steps, 1–3 km/h × 1.5/1.8/2.0 m: the swing that ends it used to race
/// its slaved ankle down the ankle curve's far flank at the end of swing1 (2 km/h × 1.5 m: knee
/// ratio 15.0, 1 km/h 5.8/6.3/6.4, 3 km/h 6.0/4.8/6.3), now with half the curve's lift
/// (`generate::STOP_LIFT`, private), and with the knee brake of every steady swing (the stop's
/// swings kept the paper's swing and ended swing2 early, `STOP_SWING2_ADVANCE`, until klawsched
/// braked them: see `generate::FIRST_PAPER_SWINGS`' doc, private). Bound: k = 5 where the
/// measurement meets it (now everywhere), else 1.25 × the measurement.
#[test]
fn the_stops_last_half_step_does_not_regress() {
    // (km/h, height, measured worst ratio over the last half step)
    #[rustfmt::skip]
    let cases: &[(f64, f64, f64)] = &[
        (1.0, 1.5, 4.25), // 575 r_hip (4.49 at 575 l_elbow before the stop's swings were braked)
        (1.0, 1.8, 3.03), // 632 r_ankle (3.57 at 730 l_knee before; 5.54 at 737 r_hand before STOP_SWING2_ADVANCE)
        (1.0, 2.0, 3.42), // 670 r_heel (4.57 at 770 l_knee before; 3.25 at 670 r_heel before STOP_SWING2_ADVANCE)
        (2.0, 1.5, 4.10), // 429 l_ankle (4.26 at 456 l_knee before; 14.95 at 456 l_knee with the full lift)
        (2.0, 1.8, 4.57), // 472 l_ankle (4.52 at 500 l_knee before; 6.62 at 520 r_elbow, the knee's lock, before STOP_SWING2_ADVANCE)
        (2.0, 2.0, 4.09), // 498 l_ankle (5.01 at 543 l_knee before)
        (3.0, 1.5, 2.92), // 329 r_ankle (4.61 at 329 r_ankle before; 6.01 at 370 l_knee with the full lift)
        (3.0, 1.8, 2.71), // 381 l_ankle (3.56 at 406 l_knee before)
        (3.0, 2.0, 2.92), // 403 l_ankle (6.62 at 442 l_knee before, the unbraked knee at its lock)
    ];
    let mut failures = Vec::new();
    for &(kmh, h, measured) in cases {
        let (m, hs) = six_steps_to_a_stop(kmh, h, false);
        let n = hs.len();
        assert!(n >= 4, "{kmh} km/h {h} m: {n} heel strikes");
        let region = hs[n - 3].ceil() as usize..hs[n - 2].ceil() as usize;
        let r = continuity_over(&m, &ContinuityOptions::default(), region);
        println!("{kmh} km/h {h} m, last half step: {r}");
        assert!(r.examined > 100, "{} examined", r.examined);
        let bound = if measured <= 5.0 {
            5.0
        } else {
            1.25 * measured
        };
        if r.worst > bound {
            failures.push(format!(
                "{kmh} km/h {h} m, last half step: {:.2} > {bound:.2} (measured {measured})",
                r.worst
            ));
        }
    }
    assert!(failures.is_empty(), "{failures:#?}");
}

/// The stop's landing ankle (`stop.rs`): the last step's swing foot lands into the stop's heel
/// rocker with that rocker's early ankle rate (`Closing::contact_ankle_rate`), as every step's
/// lands into the next step's. The rocker holds its landing pitch until the straight leg reaches
/// the pitched foot's ankle (the 3-D leg may fall up to a millimetre short at contact: 8 ms at
/// 4 km/h × 2.0 m), and only then rolls; the rate was the mean over the first 10 ms from the
/// contact, which the hold's dorsiflexion (+0.95 rad/s, the shank turning over a held foot) could
/// fill almost entirely: +0.47 rad/s against a roll of −1.32, so the swing ankle arrived at rest
/// while the stance ankle then turned 0.012 rad in the first frame against a median of 0.0023.
/// The mean now runs from the contact to 10 ms past the reach (hold and roll). Before: 4 km/h ×
/// 2.0 m, 8 steps, steady start, 5.23 (frame 532, l_ankle, the stop's heel strike + 1.2 frames);
/// 1.5 → 4 km/h × 2.0 m (4 steps each, from standing) 5.34 (frame 707, l_ankle, the same site).
/// After: 3.23 and 3.61: k = 5 met.
#[test]
fn the_stops_landing_ankle_meets_k5() {
    let mut failures = Vec::new();
    for (sched, rest) in [(&[(4.0, 8)][..], false), (&[(1.5, 4), (4.0, 4)][..], true)] {
        let (m, _) = common::walk(sched, 2.0, rest, true);
        let (w, r) = common::worst_ratio(&m);
        println!("{sched:?} x 2.0 m, from standing {rest}, with a stop: {r}");
        if w > ContinuityOptions::default().k {
            failures.push(format!("{sched:?} x 2.0 m: {r}"));
        }
    }
    assert!(failures.is_empty(), "{failures:#?}");
}

/// Slow walks between the grid points meet k = 5: 1.0–2.5 km/h every 0.05 km/h × 1.5–2.0 m every
/// 5 cm, 8 steps, steady start (341 walks), and the same every 0.1 km/h from standing to a stop
/// in 6 steps (176 walks). The heel rocker's landing choice (`VirtualLeg::plan_heel_rocker`)
/// used to keep a landing whose knee dips (flexes, straightens and flexes again) unless another
/// was `DIP_TRADE` = 10 × gentler; between the grid points the gentler landings are only 4–9 ×
/// gentler, and the dip became a knee or heel jolt at heel strike or foot flat. Measured on main
/// f83c97b: 17 of the 341 steady walks failed (worst 11.35, 1.05 km/h × 1.55 m, r_knee; 1.45 ×
/// 1.75 m 10.92, 1.2 × 1.55 m 10.48, 1.25 × 1.95 m 9.50) and 15 of the 176 from standing (worst
/// 12.43, 1.7 km/h × 2.0 m, l_knee; 1.2 × 1.7 m 11.75). With `DIP_TRADE` = 3: none of the steady
/// walks (worst 4.78) and one from standing (1.8 km/h × 2.0 m 5.14, the stop's landing ankle).
/// Since the slowest stances lower the hip so that the stance heel stays down
/// (`generate::SLOW_REST_REACH`, `generate::edge_lock`): that one 4.35, and three others just
/// over 5 (1.05 km/h × 1.50 m 5.12, 1.10 × 1.55 m 5.08 and 5.09 from standing: the trailing knee
/// straightening 0.01 rad in 3 frames after the other foot's foot flat), until the trailing
/// knee's hold relaxed toward toe off instead of giving up (`hold_knees`): none, the worst
/// 4.27 steady (geometric mean 3.31 → 3.05; 40 → 0 walks over 4.5) and 4.69 from standing.
/// Since the stance simulation locks at the paper's `l1` and the drawing lowers the pelvis
/// instead (`draw::PelvisDrop`, issue 20 stage A, re-measured): 4 of the 517 over 5, all from
/// standing, the first stance's knee as the drop rises (r_knee, frames 113–118) or the stop's
/// landing ankle: 1.5 km/h × 1.90 m 5.65, 1.6 × 1.95 m 5.99, 1.7 × 1.95 m 6.22, 1.8 × 2.0 m
/// 5.14 (l_ankle). Since the drawn pelvis height is the least-bending curve below the simulated
/// hip (`pelvis_drop::PelvisLowering`, stage B: the stance spring's loading-response dip no
/// longer reaches the flat-foot knee) the first three meet k = 5 (4.28, 4.44, 3.76); `KNOWN`
/// lists the walk still allowed over 5 with its bound (× 1.05): the stop's landing ankle.
#[test]
#[ignore = "slow (517 walks, ≈ 20 s in release on 2 cores); CI runs it with --ignored"]
fn slow_walks_between_the_grid_points_meet_k5() {
    // (km/h, height, from standing): measured worst ratio, for walks known to exceed k = 5.
    const KNOWN: &[(f64, f64, bool, f64)] = &[(1.8, 2.0, true, 5.14)];
    let mut cases = Vec::new();
    for i in 0..=30 {
        for j in 0..=10 {
            let (kmh, h) = (1.0 + 0.05 * f64::from(i), 1.5 + 0.05 * f64::from(j));
            cases.push((kmh, h, false));
            if i % 2 == 0 {
                cases.push((kmh, h, true));
            }
        }
    }
    common::assert_grid(&cases, |&(kmh, h, rest)| {
        let steps = if rest { 6 } else { 8 };
        let (w, report) = worst(&[(kmh, steps)], h, rest);
        let bound = KNOWN
            .iter()
            .find(|k| (k.0 - kmh).abs() < 1e-6 && (k.1 - h).abs() < 1e-6 && k.2 == rest)
            .map_or(ContinuityOptions::default().k, |k| 1.05 * k.3);
        (w > bound).then(|| format!("{kmh:.2} km/h x {h:.2} m, from standing {rest}: {report}"))
    });
}
