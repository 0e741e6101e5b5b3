//! Closing the loop: gaitfit's own event detection (`gaitfit::events` on `Motion::to_trial`)
//! run on generated KLAW walks recovers the commanded step length, step frequency and double
//! support.
//!
//! - Default options (the primary source picked automatically: for a walk from markers alone the
//!   foot-speed detector — Zeni windows refined by the heel and toe speed over the ground,
//!   Bonci et al. 2022 —, 6 Hz marker filter): mean step length and frequency within 1 %, every
//!   steady step's length within 1 %, and the double support within 3 frames (or 10 %) of t_ds
//!   at 1.5, 3, 5 and 7 km/h (measured +32.3, +12.4, +26.3 and +17.8 ms since the slowest
//!   stances lower the hip, `generate::SLOW_REST_REACH`: 1.5 km/h was +12.8 — the lower hip
//!   through the double support sees the heel strike earlier and the toe off later, within the
//!   10 % = 36.6 ms allowed there; +12.8, +12.4, +26.0 and +17.3 ms on main 42fbe9a, with
//!   the landing thigh retracting through terminal swing, `swing::RETRACTION_CYCLE`; −3, +7, +12
//!   and 0 ms when the swing heel still stalled and sped up again in late swing; the Zeni
//!   coordinate method gave +31 % at 7 km/h). 1.5 and 3 km/h used to come out +43 % and +28 % long: the meta-off knee
//!   blend ended at rest, so the swing foot left the floor with almost no speed and no speed
//!   criterion could see it leave; the knee now leaves toe off flexing at up to
//!   `virtual_leg::TOE_OFF_KNEE_RATE` (8 rad/s), the swing2 knee brake takes the faster swing's
//!   knee to rest before the lock, and swing3 lands the thigh at the collision-neutral rate
//!   (`swing::SwingSpec::theta3_rate_hs`), so the heel no longer swings past its landing spot
//!   and back. `toe_leaves_briskly_and_the_knee_decelerates_into_the_lock` pins both ends.
//! - Foot-marker heights (the data are noise free: 1 mm height tolerance, 45 Hz filter): the
//!   double support comes back within 3 frames (30 ms) of t_ds at every speed. With the default
//!   1 cm tolerance the toe, which rises tangentially and is held only 5 mm (the toe-clearance
//!   attribute) above the ground early in slow swings, is never seen leaving.
mod common;

use common::{leg, steady};
use gaitfit::events::{steps_from_trial, EventOptions, Gait, PrimarySource};
use gaitfit::generator::walking::high_level::phase_times;
use gaitfit::ingest::trials::StepRow;

#[test]
fn detection_recovers_step_length_frequency_and_double_support() {
    let default = EventOptions {
        gait: Some(Gait::Walk),
        ..EventOptions::default()
    };
    let zeni = EventOptions {
        primary: PrimarySource::ZeniCoordinate,
        ..default.clone()
    };
    let mut heights = EventOptions {
        primary: PrimarySource::FootHeight,
        gait: Some(Gait::Walk),
        ..EventOptions::default()
    };
    heights.phases.height_tol_m = 1e-3;
    heights.kinematic.cutoff_hz = 45.0;
    for (kmh, h) in [(1.5, 1.6), (3.0, 1.7), (5.0, 1.8), (7.0, 1.95)] {
        let opts = common::options(h, false, false);
        let (m, r) = steady(kmh, h, 10);
        let sl = r.steps[0].step_length_m;
        let sf = r.steps[0].step_freq_steps_per_min / 60.0;
        let t_ds = phase_times(r.steps[0].step_freq_steps_per_min, &opts.relations).double_support;
        let trial = m.to_trial("klaw");
        // Steady steps away from the ends (the filter's edges).
        let detect = |eo: &EventOptions| -> Vec<StepRow> {
            let table = match steps_from_trial(&trial, eo) {
                Ok(t) => t,
                Err(e) => panic!("{kmh} km/h: {e}"),
            };
            table
                .rows
                .into_iter()
                .filter(|s| {
                    s.time_s
                        .is_some_and(|t| t > 0.3 && t < m.duration_s() - 1.0 / sf - 0.2)
                })
                .collect()
        };
        let values = |rows: &[StepRow], f: &dyn Fn(&StepRow) -> Option<f64>| -> Vec<f64> {
            let v: Vec<f64> = rows.iter().filter_map(f).collect();
            assert!(v.len() >= 4, "{kmh} km/h: {} values", v.len());
            v
        };
        let mean = |v: &[f64]| v.iter().sum::<f64>() / v.len() as f64;
        let rows = detect(&default);
        let sls = values(&rows, &|r| r.step_length_m);
        let sf_m = mean(&values(&rows, &|r| r.step_freq_hz));
        let ds_default = mean(&values(&rows, &|r| r.double_support_time_s));
        let ds_zeni = mean(&values(&detect(&zeni), &|r| r.double_support_time_s));
        let rows_h = detect(&heights);
        let ds_m = mean(&values(&rows_h, &|r| r.double_support_time_s));
        println!(
            "{kmh} km/h, h {h}: sl {:.4} (cmd {sl:.4}) m, sf {:.2} (cmd {:.2}) steps/min, \
             t_ds {ds_default:.4} by default, {ds_m:.4} by foot heights, {ds_zeni:.4} by Zeni \
             (cmd {t_ds:.4}) s",
            mean(&sls),
            sf_m * 60.0,
            sf * 60.0,
        );
        assert!(
            (mean(&sls) - sl).abs() < 0.01 * sl,
            "{kmh} km/h: sl {sls:?} vs {sl}"
        );
        for s in &sls {
            assert!(
                (s - sl).abs() < 0.01 * sl,
                "{kmh} km/h: a step of {s} vs {sl}"
            );
        }
        assert!(
            (sf_m - sf).abs() < 0.01 * sf,
            "{kmh} km/h: sf {sf_m} vs {sf}"
        );
        assert!(
            (ds_m - t_ds).abs() <= 3.0 / opts.fps,
            "{kmh} km/h: t_ds {ds_m} vs {t_ds}"
        );
        let err = (ds_default - t_ds).abs();
        assert!(
            err <= 3.0 / opts.fps || err <= 0.1 * t_ds,
            "{kmh} km/h: default t_ds {ds_default} vs {t_ds}"
        );
    }
}

/// The mechanism behind the default events' double support: the toe leaves the floor at a
/// human toe-off speed (its speed over the ground passes 0.8 × the walking speed — the
/// detector's threshold — within 50 ms of every generated toe off; it took 50–170 ms at 1.5 and
/// 3 km/h when the knee came to rest at toe off), and the swing knee decelerates into the
/// swing2 → swing3 lock instead of slamming into it at 5–7 rad/s (its last two frame-to-frame
/// steps before it is straight shrink; with the paper's single knee torque they grew).
#[test]
fn toe_leaves_briskly_and_the_knee_decelerates_into_the_lock() {
    use gaitfit::events::EventKind;
    use gaitfit::generator::skeleton::Joint;
    for (kmh, h) in [(1.5, 1.6), (3.0, 1.7), (5.0, 1.8), (7.0, 1.95)] {
        let (m, _) = steady(kmh, h, 8);
        let v = kmh / 3.6;
        let fps = m.fps();
        let toe_offs: Vec<_> = m
            .events
            .iter()
            .filter(|e| e.kind == EventKind::ToeOff)
            .collect();
        assert!(
            toe_offs.len() >= 6,
            "{kmh} km/h: {} toe offs",
            toe_offs.len()
        );
        for e in &toe_offs {
            let (toe, knee) = (leg(e.side).toe, Joint::leg(e.side)[1]);
            // Frames from the one containing toe off to 50 ms after it.
            let i0 = (e.time_s * fps).floor() as usize;
            let i1 = ((e.time_s + 0.05) * fps).floor() as usize;
            if i1 + 1 >= m.len() {
                continue;
            }
            let fastest = (i0..=i1)
                .map(|i| (m.landmark(i + 1, toe) - m.landmark(i, toe)).length() * fps)
                .fold(0.0, f64::max);
            assert!(
                fastest >= 0.8 * v,
                "{kmh} km/h, toe off at {:.3} s: toe at most {fastest:.3} m/s within 50 ms",
                e.time_s
            );
            // The knee from toe off until it is straight (the lock at the end of swing2).
            let flex = |i: usize| m.pose(i).euler(knee).z.abs();
            let Some(straight) = (i0 + 2..m.len()).find(|&i| flex(i) < 1e-3) else {
                continue;
            };
            let steps: Vec<f64> = (straight - 3..straight)
                .map(|i| (flex(i + 1) - flex(i)).abs())
                .collect();
            assert!(
                steps[2] < steps[1] && steps[1] < steps[0],
                "{kmh} km/h, swing after {:.3} s: knee steps into the lock {steps:?} rad",
                e.time_s
            );
        }
    }
}

/// A steady walk starts and ends mid-motion (klawlead, `generate::LEAD_IN_FRAMES`,
/// `generate::LEAD_OUT_FRAMES`). The start: frame 0 is at t = 0,
/// `LEAD_IN_FRAMES` frames before the first heel strike, in the landing swing of the last
/// pre-roll step (`generate::PRE_ROLL`) — the landing foot in the air, the other on the ground —
/// and no event falls before frame 0. The first step is as steady as the later ones: the times
/// from its heel strike to its foot flat and heel off and to the trailing foot's meta off and
/// toe off match the third step's within 3 ms. Before the lead-in frame 0 was the first heel
/// strike, drawn with one pre-roll step and an extra landing pitch: at 5 km/h × 1.8 m the first
/// step's foot flat came 10 ms early and the trailing meta off 9 ms late. The end: the last
/// heel strike and the trailing toe off after it are recorded, and the recording runs
/// `LEAD_OUT_FRAMES` past that toe off (to the frame); it used to end at the last heel strike.
#[test]
fn a_steady_walk_starts_and_ends_mid_motion() {
    use gaitfit::events::{EventKind, Side};
    use gaitfit::generator::skeleton::Landmark;
    use gaitfit::generator::walking::generate::{LEAD_IN_FRAMES, LEAD_OUT_FRAMES};
    for (kmh, h) in [(1.0, 2.0), (3.0, 1.8), (5.0, 1.8), (7.0, 1.5)] {
        let (m, r) = steady(kmh, h, 8);
        let fps = m.fps();
        let lead = LEAD_IN_FRAMES as f64 / fps;
        assert!(m.events.iter().all(|e| e.time_s >= 0.0), "{kmh} km/h");
        let hs: Vec<_> = m
            .events
            .iter()
            .filter(|e| e.kind == EventKind::HeelStrike)
            .collect();
        assert!(
            (hs[0].time_s - lead).abs() < 1e-9,
            "{kmh} km/h: {}",
            hs[0].time_s
        );
        assert!((r.steps[0].start_s - lead).abs() < 1e-9);
        // The end.
        let last = &r.steps[r.steps.len() - 1];
        let t_hs = last.start_s + last.times.step;
        let t_last = (m.len() - 1) as f64 / fps;
        assert!((hs[hs.len() - 1].time_s - t_hs).abs() < 1e-9, "{kmh} km/h");
        let to = m
            .events
            .iter()
            .find(|e| e.kind == EventKind::ToeOff && e.time_s > t_hs)
            .map_or(f64::NAN, |e| e.time_s);
        assert!(
            (to - t_hs - last.times.double_support).abs() < 1e-9,
            "{kmh} km/h: {to}"
        );
        let out = LEAD_OUT_FRAMES as f64 / fps;
        assert!(
            t_last > to + out - 1.0 / fps - 1e-9 && t_last <= to + out + 1e-9,
            "{kmh} km/h: last frame at {t_last} s, toe off at {to} s"
        );
        assert!(m.events.iter().all(|e| e.time_s <= t_last + 1.0 / fps));
        // Frame 0: the landing foot in the air above the ground, the other foot on it.
        let (landing, heel) = match hs[0].side {
            Side::Left => (0, Landmark::LHeel),
            Side::Right => (1, Landmark::RHeel),
        };
        let c = m.contacts()[0];
        assert!(
            !c[landing] && c[1 - landing],
            "{kmh} km/h: frame 0 contacts {c:?}"
        );
        assert!(
            m.landmark(0, heel).y > 0.002,
            "{kmh} km/h: {}",
            m.landmark(0, heel).y
        );
        // Event times after each step's heel strike: the first step against the third.
        let after = |k: usize, kind: EventKind, same_side: bool| -> f64 {
            let side = if same_side {
                hs[k].side
            } else {
                hs[k].side.opposite()
            };
            m.events
                .iter()
                .find(|e| e.kind == kind && e.side == side && e.time_s > hs[k].time_s)
                .map_or(f64::NAN, |e| e.time_s - hs[k].time_s)
        };
        for (kind, same) in [
            (EventKind::FootFlat, true),
            (EventKind::HeelOff, true),
            (EventKind::MetaOff, false),
            (EventKind::ToeOff, false),
        ] {
            let (first, third) = (after(0, kind, same), after(2, kind, same));
            if first.is_nan() && third.is_nan() && kind == EventKind::MetaOff {
                continue; // slow walks: the trailing foot leaves without a meta-off period
            }
            println!("{kmh} km/h {h} m: {kind:?} {first:.4} s after the first heel strike, {third:.4} s after the third");
            assert!(
                (first - third).abs() < 0.003,
                "{kmh} km/h: {kind:?} {first:.4} s after the first heel strike, {third:.4} s after the third"
            );
        }
    }
}

/// The swing heel's approach to heel strike (issue 6, `swing::RETRACTION_CYCLE`, which replaced
/// session 8's `SWING3_LEAD`): from its
/// late-swing peak (second half of the swing) the heel's forward speed over the ground falls
/// all the way to contact — it never speeds up again by more than 0.05 m/s — and from the knee
/// lock (the knee straight, the end of swing2) to contact the heel only descends (0.1 mm).
/// Before the lead the thigh reached the lock with too little way left to retract into the
/// contact: the heel stalled at 0.19–0.26 m/s about 1 cm above the floor 9 frames before heel
/// strike and sped up again by 0.31–0.41 m/s at 1.5 km/h, 1.1 m/s at 7 km/h × 1.8 m, where it
/// also rose 3 mm after the lock.
#[test]
fn the_swing_heel_slows_and_descends_into_the_contact() {
    use gaitfit::events::EventKind;
    use gaitfit::generator::skeleton::Joint;
    for (kmh, h) in [(1.5, 1.6), (3.0, 1.7), (5.0, 1.8), (7.0, 1.8), (7.0, 1.95)] {
        let (m, _) = steady(kmh, h, 8);
        let fps = m.fps();
        let mut swings = 0;
        for to in m.events.iter().filter(|e| e.kind == EventKind::ToeOff) {
            let Some(hs) = common::next_event(&m, EventKind::HeelStrike, to.side, to.time_s) else {
                continue;
            };
            let (heel, knee) = (leg(to.side).heel, Joint::leg(to.side)[1]);
            // Frames of the second half of the swing, up to the last one at or before contact.
            let mid = ((to.time_s + 0.5 * (hs.time_s - to.time_s)) * fps).ceil() as usize;
            let last = (hs.time_s * fps + 1e-9).floor() as usize;
            let vx = |i: usize| (m.landmark(i + 1, heel).x - m.landmark(i, heel).x) * fps;
            let peak = (mid..last)
                .max_by(|&a, &b| vx(a).total_cmp(&vx(b)))
                .unwrap();
            let (mut low, mut again) = (f64::INFINITY, 0.0_f64);
            for i in peak..last {
                low = low.min(vx(i));
                again = again.max(vx(i) - low);
            }
            assert!(
                again <= 0.05,
                "{kmh} km/h × {h} m, swing into {:.3} s: the heel speeds up again by {again:.3} m/s",
                hs.time_s
            );
            let flex = |i: usize| m.pose(i).euler(knee).z.abs();
            let lock = (mid..=last).find(|&i| flex(i) < 1e-3).unwrap_or(last);
            for i in lock..last {
                let rise = m.landmark(i + 1, heel).y - m.landmark(i, heel).y;
                assert!(
                    rise <= 1e-4,
                    "{kmh} km/h × {h} m, frame {i}: the heel rises {:.2} mm after the knee lock",
                    rise * 1e3
                );
            }
            swings += 1;
        }
        assert!(swings >= 6, "{kmh} km/h: {swings} swings");
    }
}
