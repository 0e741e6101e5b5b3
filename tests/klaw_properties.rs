//! Property tests of the KLAW generator over speeds and body heights: commanded step length and
//! frequency, phase end conditions, double support, stance-foot sliding and ground penetration.
//!
//! Range: 1–7 km/h and 1.5–2.0 m (the issue's), sampled by proptest plus the range's corners.
mod common;

use gaitfit::events::{EventKind, Side};
use gaitfit::generator::checks::{double_support_timing, ground_penetration, stance_sliding};
use gaitfit::generator::skeleton::Landmark;
use gaitfit::generator::walking::high_level::phase_times;
use gaitfit::generator::walking::swing::RECOVERY_MAX_RAD;
use proptest::prelude::*;

/// Checks every property of a walk at `kmh` and height `h`; returns the first violation.
/// What [`check`] measured on one walk, against its bounds: step length and frequency errors
/// (fraction of the commanded), the stance `w` error (m) and angle error (rad) at the phase ends,
/// and the worst double-support timing (s off t_ds), stance sliding (m) and ground penetration (m).
#[derive(Debug, Clone, Copy, Default)]
struct Measured {
    sl: f64,
    sf: f64,
    w: f64,
    angle: f64,
    ds: f64,
    sliding: f64,
    penetration: f64,
}

impl Measured {
    fn max(self, o: Measured) -> Measured {
        Measured {
            sl: self.sl.max(o.sl),
            sf: self.sf.max(o.sf),
            w: self.w.max(o.w),
            angle: self.angle.max(o.angle),
            ds: self.ds.max(o.ds),
            sliding: self.sliding.max(o.sliding),
            penetration: self.penetration.max(o.penetration),
        }
    }
}

fn check(kmh: f64, h: f64) -> Result<Measured, String> {
    let mut got = Measured::default();
    let opts = common::options(h, false, false);
    let (m, r) = common::steady(kmh, h, 6);
    let ctx = format!("{kmh:.2} km/h, h = {h:.3} m");
    let l = &r.steps[0];
    let sl = l.step_length_m;
    let sf = l.step_freq_steps_per_min;
    // Each phase ends on its constraints: angles within 0.1°, lengths within 0.1 mm; the
    // durations are exact by construction (fixed steps landing on the phase end).
    for s in &r.steps {
        // The ground-stubbing recovery never runs out of actuator in a steady walk (its 0.8 rad
        // bound was only inspected in traces before; measured on 1–7 km/h × 1.5–2.0 m at
        // 0.25 km/h × 5 cm, 8 steps: at most 0.42 rad, 4.5 km/h × 1.85 m).
        if s.recovery_rad >= RECOVERY_MAX_RAD - 1e-9 {
            return Err(format!(
                "{ctx}: swing2 recovery saturated at {} rad in step {}",
                s.recovery_rad, s.index
            ));
        }
        if s.errors[0].abs() >= 1e-4 {
            return Err(format!("{ctx}: stance w error {}", s.errors[0]));
        }
        got.w = got.w.max(s.errors[0].abs());
        for e in &s.errors[1..] {
            got.angle = got.angle.max(e.abs());
            if e.abs() >= 0.1f64.to_radians() {
                return Err(format!("{ctx}: angle error {e} in step {}", s.index));
            }
        }
    }
    // Commanded step length: heel positions at successive heel strikes (the heel is the
    // pivot just after heel strike, so the first frame after the event shows it exactly).
    let hs: Vec<_> = m
        .events
        .iter()
        .filter(|e| {
            // The walk's final heel strike falls after its last frame.
            e.kind == EventKind::HeelStrike && ((e.time_s * m.fps()).ceil() as usize) < m.len()
        })
        .collect();
    if hs.len() < 6 {
        return Err(format!("{ctx}: {} heel strikes", hs.len()));
    }
    let heel_x = |e: &gaitfit::events::GaitEvent| {
        let f = (e.time_s * m.fps()).ceil() as usize;
        let lm = if e.side == Side::Left {
            Landmark::LHeel
        } else {
            Landmark::RHeel
        };
        m.landmark(f, lm).x
    };
    for w in hs.windows(2) {
        let d = heel_x(w[1]) - heel_x(w[0]);
        got.sl = got.sl.max((d - sl).abs() / sl);
        if (d - sl).abs() >= 0.01 * sl {
            return Err(format!("{ctx}: step length {d} vs {sl}"));
        }
        let f = 60.0 / (w[1].time_s - w[0].time_s);
        got.sf = got.sf.max((f - sf).abs() / sf);
        if (f - sf).abs() >= 0.01 * sf {
            return Err(format!("{ctx}: step frequency {f} vs {sf}"));
        }
    }
    // Double support lasts t_ds (to one frame).
    let t = phase_times(sf, &opts.relations);
    let ds = double_support_timing(&m, t.double_support, 1.0 / opts.fps + 1e-9);
    if !ds.passed {
        return Err(format!("{ctx}: {ds}"));
    }
    // No stance-foot sliding, no ground penetration.
    let sliding = stance_sliding(&m, 0.002, 0.002);
    if !(sliding.passed && sliding.examined > 0) {
        return Err(format!("{ctx}: {sliding}"));
    }
    let pen = ground_penetration(&m, 0.001);
    if !pen.passed {
        return Err(format!("{ctx}: {pen}"));
    }
    got.ds = ds.worst;
    got.sliding = sliding.worst;
    got.penetration = pen.worst;
    Ok(got)
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 8, ..ProptestConfig::default() })]

    #[test]
    fn walks_meet_their_constraints(kmh in 1.0f64..7.0, h in 1.5f64..2.0) {
        if let Err(e) = check(kmh, h) {
            prop_assert!(false, "{}", e);
        }
    }
}

#[test]
fn corners_of_the_range_meet_their_constraints() {
    // The slowest walks of the tallest and shortest bodies are the hardest (sf ≈ 45 steps/min:
    // the inverted pendulum hovers near the vertical for over a second), the fastest the
    // stiffest; each corner is checked every time, not left to sampling.
    for (kmh, h) in [(1.0, 1.5), (1.0, 2.0), (7.0, 1.5), (7.0, 2.0), (3.0, 1.7)] {
        check(kmh, h).unwrap();
    }
}

#[test]
fn fast_walks_of_short_bodies_keep_the_swing_heel_above_the_ground() {
    // 6.9–7.0 km/h at 1.50–1.56 m: the swing2 heel dipped 2–4 mm into the ground because the
    // ground-stubbing recovery stopped at a 0.4 rad actuator while about 0.5 rad was needed
    // (clearance grows ≈ 1 mm per 0.02 rad there). 6.9864 km/h at 1.5 m is the case proptest
    // found (2.2 mm at frame 164); the grid is the family around it.
    check(6.986_4, 1.5).unwrap();
    for i in 0..=5 {
        for j in 0..=3 {
            check(6.9 + 0.02 * f64::from(i), 1.5 + 0.02 * f64::from(j)).unwrap();
        }
    }
}

#[test]
fn the_last_half_step_of_a_slow_stop_moves_the_swing_foot_continuously() {
    // 1 km/h, h 1.8 m, with the stop: the last (short) half step's swing1 ankle curve fell
    // 7 cm over 9 cm of travel, nearly along the circle the ankle can reach about the knee, so
    // the slaved knee angle slid the ankle 10 cm along the curve in 11 ms (heel 15 cm in one
    // frame, frame 462). The lift is now capped at a quarter of the travel.
    let (m, _) = common::walk(&[(1.0, 4)], 1.8, false, true);
    let feet = [
        Landmark::LAnkle,
        Landmark::LHeel,
        Landmark::LBall,
        Landmark::LToe,
        Landmark::RAnkle,
        Landmark::RHeel,
        Landmark::RBall,
        Landmark::RToe,
    ];
    // A jump is a frame's step both large (> 2 cm; the swing toe moves up to ≈ 6 cm per frame
    // smoothly) and 5 times the median of its six neighbours' steps (the old one: ≈ 11).
    let mut worst = (0.0f64, 0, Landmark::LAnkle);
    for &lm in &feet {
        let steps: Vec<f64> = (1..m.len())
            .map(|f| (m.landmark(f, lm) - m.landmark(f - 1, lm)).length())
            .collect();
        for i in 0..steps.len() {
            let mut near: Vec<f64> = steps[i.saturating_sub(3)..i]
                .iter()
                .chain(steps[i + 1..(i + 4).min(steps.len())].iter())
                .copied()
                .collect();
            near.sort_by(f64::total_cmp);
            let med = near[near.len() / 2].max(1e-4);
            let ratio = steps[i] / med;
            if steps[i] > 0.02 && ratio > worst.0 {
                worst = (ratio, i + 1, lm);
            }
        }
    }
    assert!(
        worst.0 < 5.0,
        "foot point step {:.1} times its neighbours' at frame {} ({:?})",
        worst.0,
        worst.1,
        worst.2
    );
}

#[test]
#[ignore = "slow (671 walks, ≈ 15 s in release); CI runs it with --ignored"]
fn grid_of_walks_meets_their_constraints() {
    // The whole issue range on a deterministic grid: 1–7 km/h every 0.1 km/h × 1.5–2.0 m every
    // 5 cm. Sampling (above) finds rare failures only in one run of several hundred cases; the
    // grid makes the range's coverage reproducible. Every walk is checked; all failures listed.
    // The worst measured values are printed (`-- --ignored --nocapture`) for the notes.
    let mut failures = Vec::new();
    let mut worst = Measured::default();
    for i in 0..=60 {
        for j in 0..=10 {
            let (kmh, h) = (1.0 + 0.1 * f64::from(i), 1.5 + 0.05 * f64::from(j));
            match check(kmh, h) {
                Ok(got) => worst = worst.max(got),
                Err(e) => failures.push(e),
            }
        }
    }
    println!(
        "671 walks, worst: step length {:.3} %, step frequency {:.3} %, stance w {:.2e} m, \
         phase-end angle {:.4}°, double support {:.1} ms off t_ds, sliding {:.2} mm, \
         penetration {:.2} mm",
        100.0 * worst.sl,
        100.0 * worst.sf,
        worst.w,
        worst.angle.to_degrees(),
        1e3 * worst.ds,
        1e3 * worst.sliding,
        1e3 * worst.penetration
    );
    assert!(
        failures.is_empty(),
        "{} of 671 walks: {failures:#?}",
        failures.len()
    );
}

#[test]
#[ignore = "slow (286 walks with a stop, ≈ 5 s in release); CI runs it with --ignored"]
fn walks_with_a_stop_never_saturate_the_recovery() {
    // The stop's swings (8 steps, from standing and steady, 1–7 km/h every 0.5 km/h ×
    // 1.5–2.0 m every 5 cm) never run out of swing2's stubbing recovery and never sink into the
    // ground. Before the swings before a stop were braked (`generate::FIRST_PAPER_SWINGS`' doc),
    // the half step saturated it at 3–4 km/h × 1.5–1.55 m (0.8 rad, clearing the toe clearance
    // by one grid step); measured now at most 0.64 rad (3.5 km/h × 1.5 m).
    let mut failures = Vec::new();
    let mut most = (0.0f64, String::new());
    for i in 0..=12 {
        for j in 0..=10 {
            let (kmh, h) = (1.0 + 0.5 * f64::from(i), 1.5 + 0.05 * f64::from(j));
            for rest in [true, false] {
                let (m, r) = common::walk(&[(kmh, 8)], h, rest, true);
                let ctx = format!("{kmh:.1} km/h, h = {h:.2} m, from standing {rest}");
                for s in &r.steps {
                    if s.recovery_rad > most.0 {
                        most = (s.recovery_rad, format!("{ctx}, step {}", s.index));
                    }
                    if s.recovery_rad >= RECOVERY_MAX_RAD - 1e-9 {
                        failures.push(format!(
                            "{ctx}: swing2 recovery saturated at {} rad in step {}",
                            s.recovery_rad, s.index
                        ));
                    }
                }
                let pen = ground_penetration(&m, 0.001);
                if !pen.passed {
                    failures.push(format!("{ctx}: {pen}"));
                }
            }
        }
    }
    println!("largest recovery {:.2} rad ({})", most.0, most.1);
    assert!(
        failures.is_empty(),
        "{} of 286 walks: {failures:#?}",
        failures.len()
    );
}
