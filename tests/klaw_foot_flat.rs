//! KLAW's stance heel stays on the floor from foot flat until the heel rises for push-off
//! (issue 6). The sagittal stance model's rigid leg is the projection of the drawn 3-D leg
//! (`StanceSpec::lock_length`); before that, the 3-D hip–ankle distance at the lock exceeded the
//! leg's reach and the flat foot rolled onto its ball right after foot flat, the heel hovering
//! 4–5 mm up through midstance.
//!
//! Independent of the generator's bookkeeping: heights are the drawn heel landmark's, and
//! midstance is where the drawn hip joint passes over the drawn ankle.
use gaitfit::events::{EventKind, Side};
use gaitfit::generator::skeleton::Landmark;
use gaitfit::generator::walking::{generate_walk, ScheduleEntry, WalkOptions};

/// For every steady stance (foot flat followed by heel off on the same side) of an 8-step
/// steady walk at `kmh`, `h` m: the highest the stance heel gets from foot flat to the later of
/// heel off and midstance (m), the lowest heel-off frame minus its midstance frame, and the
/// number of stances checked.
fn heel_hover(kmh: f64, h: f64) -> (f64, i64, usize) {
    let schedule = [ScheduleEntry::at_speed(kmh / 3.6, 8)];
    let opts = WalkOptions {
        height_m: h,
        ..Default::default()
    };
    let (m, _) = generate_walk(&schedule, &opts).unwrap();
    let fps = m.fps();
    let frame = |t: f64| (t * fps).round() as usize;
    let (mut worst, mut lead, mut n) = (0.0f64, i64::MAX, 0);
    for e in m.events.iter().filter(|e| e.kind == EventKind::FootFlat) {
        let Some(off) = m
            .events
            .iter()
            .find(|o| o.kind == EventKind::HeelOff && o.side == e.side && o.time_s > e.time_s)
        else {
            continue;
        };
        let (hip, ankle, heel) = match e.side {
            Side::Left => (Landmark::LHip, Landmark::LAnkle, Landmark::LHeel),
            Side::Right => (Landmark::RHip, Landmark::RAnkle, Landmark::RHeel),
        };
        let (ff, ho) = (frame(e.time_s), frame(off.time_s).min(m.len() - 1));
        // Midstance: the first frame with the hip joint ahead of the ankle.
        let Some(mid) = (ff..m.len()).find(|&i| m.landmark(i, hip).x >= m.landmark(i, ankle).x)
        else {
            continue;
        };
        for i in ff..=ho.max(mid) {
            worst = worst.max(m.landmark(i, heel).y);
        }
        lead = lead.min(ho as i64 - mid as i64);
        n += 1;
    }
    (worst, lead, n)
}

/// Measured (8 steps, steady start, frame rate 100/s), the heel's highest from foot flat to the
/// later of heel off and midstance, 1.5/1.8/2.0 m, with the paper's sagittal lock at the straight
/// leg's length: 3 km/h 3.98/4.90/5.54 mm, 5 km/h 4.01/4.94/5.58, 7 km/h 4.24/5.14/5.75 (heel
/// off 9–28 frames before midstance). With the projected lock (Froude 0.24–0.65,
/// `generate::PROJECTED_LOCK_FROUDE_MIN`/`MAX`): ≤ 0.01 mm at 3–6 km/h and 7 km/h × 2.0 m. The
/// walks outside that range keep the hover (1–2 km/h 2.3–5.5 mm, 7 km/h × 1.5/1.8 m 4.2/5.1):
/// asserted above 1 mm so that a fix there is noticed.
#[test]
fn the_stance_heel_stays_down_from_foot_flat_to_heel_off() {
    let mut failed = Vec::new();
    let mut still = Vec::new();
    for kmh in [1.0, 2.0, 3.0, 4.0, 5.0, 6.0, 7.0] {
        for h in [1.5, 1.8, 2.0] {
            let (worst, lead, n) = heel_hover(kmh, h);
            println!(
                "{kmh} km/h × {h} m: heel ≤ {:.2} mm from foot flat to heel off / midstance, \
                 heel off ≥ {lead} frames after midstance ({n} stances)",
                1e3 * worst
            );
            let fixed = kmh >= 3.0 && (kmh < 7.0 || h >= 2.0);
            if n < 6 || (fixed && worst > 1e-3) {
                failed.push(format!(
                    "{kmh} km/h × {h} m: {:.2} mm, {n} stances",
                    1e3 * worst
                ));
            }
            if !fixed && worst <= 1e-3 {
                still.push(format!("{kmh} km/h × {h} m"));
            }
        }
    }
    assert!(
        failed.is_empty(),
        "stance heel up before heel off: {failed:?}"
    );
    assert!(
        still.is_empty(),
        "heel now down (move into the asserted set): {still:?}"
    );
}
