//! KLAW's stance heel stays on the floor from foot flat until the heel rises for push-off
//! (issue 6). The sagittal stance model's rigid leg is the projection of the drawn 3-D leg
//! (`StanceSpec::lock_length`); before that, the 3-D hip–ankle distance at the lock exceeded the
//! leg's reach and the flat foot rolled onto its ball right after foot flat, the heel hovering
//! 4–5 mm up through midstance.
//!
//! Independent of the generator's bookkeeping: heights are the drawn heel landmark's, and
//! midstance is where the drawn hip joint passes over the drawn ankle.
mod common;

use gaitfit::events::EventKind;

/// For every steady stance (foot flat followed by heel off on the same side) of an 8-step
/// steady walk at `kmh`, `h` m: the highest the stance heel gets from foot flat to the later of
/// heel off and midstance (m), the lowest heel-off frame minus its midstance frame, the
/// number of stances checked, and the earliest and latest heel rise (the first frame after
/// foot flat with the heel more than 1 mm up) as fractions of the gait cycle (heel strike to
/// the same foot's next heel strike), over the stances with a next heel strike.
fn heel_hover(kmh: f64, h: f64) -> (f64, i64, usize, [f64; 2]) {
    let (m, _) = common::steady(kmh, h, 8);
    let fps = m.fps();
    let frame = |t: f64| (t * fps).round() as usize;
    let (mut worst, mut lead, mut n) = (0.0f64, i64::MAX, 0);
    let mut rise = [f64::INFINITY, f64::NEG_INFINITY];
    for e in m.events.iter().filter(|e| e.kind == EventKind::FootFlat) {
        let Some(off) = common::next_event(&m, EventKind::HeelOff, e.side, e.time_s) else {
            continue;
        };
        let common::Leg {
            hip, ankle, heel, ..
        } = common::leg(e.side);
        // The last frame before the heel-off event (the drawn heel's leaving the floor,
        // `generate::drawn_heel_off`).
        let before_off = ((off.time_s * fps).ceil() as usize).saturating_sub(1);
        let (ff, ho) = (frame(e.time_s), before_off.min(m.len() - 1));
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
        let strikes = || {
            m.events
                .iter()
                .filter(|o| o.kind == EventKind::HeelStrike && o.side == e.side)
        };
        let hs = strikes().rfind(|o| o.time_s <= e.time_s);
        let next = strikes().find(|o| o.time_s > e.time_s);
        let up = (ff..m.len()).find(|&i| m.landmark(i, heel).y > 1e-3);
        if let (Some(hs), Some(next), Some(up)) = (hs, next, up) {
            let f = (up as f64 / fps - hs.time_s) / (next.time_s - hs.time_s);
            rise = [rise[0].min(f), rise[1].max(f)];
        }
    }
    (worst, lead, n, rise)
}

/// Measured (8 steps, steady start, frame rate 100/s), the heel's highest from foot flat to the
/// later of heel off and midstance, 1.5/1.8/2.0 m, with the paper's sagittal lock at the straight
/// leg's length: 3 km/h 3.98/4.90/5.54 mm, 5 km/h 4.01/4.94/5.58, 7 km/h 4.24/5.14/5.75 (heel
/// off 9–28 frames before midstance). With the projected lock (Froude 0.24–0.65,
/// `generate::PROJECTED_LOCK_FROUDE_MAX`): ≤ 0.01 mm at 3–6 km/h and 7 km/h × 2.0 m.
/// Above Froude 0.65 (7 km/h × 1.5/1.8 m) the drawn midstance knee takes the 3-D reach
/// instead (`StanceSpec::flat_reach`): 4.24/5.14 → 0.00 mm. 2 km/h (Froude 0.19–0.21) locks at
/// the projected length with the leg spring's rest length shortened
/// (`generate::REST_SHORTENING_FROUDE_MAX`, `StanceSpec::rest_length`): 3.97/4.89/5.53 → 0.00/0.04/0.29 mm
/// (0.39/0.41/0.77 with the lock alone). The walks below Froude 0.16 (1 km/h) hovered
/// 4.07/3.17/3.52 mm (1.0–1.8 km/h: 3.0–5.8 mm) until those stances also locked at the projected
/// length with twice its reach off the rest length (`generate::SLOW_REST_REACH`): 0.00/0.02/0.09
/// mm, the heel rising at 33–36 % of the cycle. Every speed is asserted now.
///
/// Since the stance simulation locks at the paper's `l1` (no reach of the drawn leg in it) and
/// the drawing lowers the pelvis where the flat foot is out of the drawn leg's soft reach
/// (`draw::PelvisDrop`, issue 20 stage A): the highest heel 0.10–0.26 mm at every walk here, the
/// heel rising (1 mm) at 38–43 % of the cycle.
///
/// Since the heel-off event is where the drawn heel leaves the floor (≈ 0.2 mm of roll,
/// `generate::drawn_heel_off`; before, the rule's switch, 1–46 frames earlier), the highest heel
/// up to the frame before it is 0.07–0.25 mm at every one of these walks (the figures above
/// were measured up to the rule's switch).
///
/// Where the heel stays down it rises (1 mm) at 34–43 % of the gait cycle (2 km/h 34–37 %,
/// 3 km/h 37–39 %, 5 km/h 39–42 %, 7 km/h 41–43 %): a human's heel off is at 30–40 %, so up to
/// 3 % late at 5–7 km/h; asserted within 30–45 %. The hovering walks' heels are 1 mm up at 5–8 %.
#[test]
fn the_stance_heel_stays_down_from_foot_flat_to_heel_off() {
    let mut failed = Vec::new();
    for kmh in [1.0, 2.0, 3.0, 4.0, 5.0, 6.0, 7.0] {
        for h in [1.5, 1.8, 2.0] {
            let (worst, lead, n, rise) = heel_hover(kmh, h);
            println!(
                "{kmh} km/h × {h} m: heel ≤ {:.2} mm from foot flat to heel off / midstance, \
                 heel off ≥ {lead} frames after midstance ({n} stances), heel up 1 mm at \
                 {:.0}–{:.0} % of the cycle",
                1e3 * worst,
                100.0 * rise[0],
                100.0 * rise[1]
            );
            // The heel stays down and rises where a human's does (30–40 % of the cycle), a
            // little late at speed.
            let timed = rise[0] >= 0.30 && rise[1] <= 0.45;
            if n < 6 || worst > 1e-3 || !timed {
                failed.push(format!(
                    "{kmh} km/h × {h} m: {:.2} mm, {n} stances, heel up at {:.2}–{:.2}",
                    1e3 * worst,
                    rise[0],
                    rise[1]
                ));
            }
        }
    }
    assert!(
        failed.is_empty(),
        "stance heel up before heel off: {failed:?}"
    );
}

/// Between the grid points of the slow walks (1.0–2.0 km/h every 0.1 × 1.5–2.0 m every 5 cm,
/// 121 steady walks of 8 steps) the stance heel stays within 1 mm of the floor from foot flat to
/// heel off / midstance. Measured on main 9c72f4f (before `generate::SLOW_REST_REACH`): 83 of the
/// 121 walks hovered 1.5–6.1 mm (1.0–1.8 km/h; 1.5 km/h × 1.5 m 5.78 mm); then one (1.4 km/h ×
/// 1.6 m, 3.98 mm: heel off at foot flat, the knee ease flexing past the flat foot's knee) until
/// the eased knee was bounded by the flat foot's (`KNEE_ROCKER_EASE`, deleted in stage B): its heel
/// then stayed down until 4 frames before the rule's heel-off switch (1.26 mm there). Since the
/// heel-off event marks where the drawn heel leaves the floor (`generate::drawn_heel_off`) every
/// one of the 121 walks keeps its heel within 0.25 mm until then. `KNOWN` lists walks allowed
/// over 1 mm with their bound (none).
#[test]
#[ignore = "slow (121 walks, ≈ 5 s in release on 2 cores); CI runs it with --ignored"]
fn the_slow_stance_heel_stays_down_between_the_grid_points() {
    // (km/h, height): measured highest heel, m.
    const KNOWN: &[(f64, f64, f64)] = &[];
    let cases: Vec<(f64, f64)> = (0..=10)
        .flat_map(|i| (0..=10).map(move |j| (1.0 + 0.1 * f64::from(i), 1.5 + 0.05 * f64::from(j))))
        .collect();
    common::assert_grid(&cases, |&(kmh, h)| {
        let (worst, _, n, _) = heel_hover(kmh, h);
        let bound = KNOWN
            .iter()
            .find(|k| (k.0 - kmh).abs() < 1e-6 && (k.1 - h).abs() < 1e-6)
            .map_or(1e-3, |k| 1.05 * k.2);
        (n < 6 || worst > bound).then(|| {
            format!(
                "{kmh:.1} km/h × {h:.2} m: heel {:.2} mm, {n} stances",
                1e3 * worst
            )
        })
    });
}

/// The heel-off event is where the drawn heel leaves the floor (`generate::drawn_heel_off`):
/// within 2 frames of the first frame after foot flat with the heel more than 0.2 mm up, 8-step
/// steady walks at 1–7 km/h × 1.5/1.8/2.0 m (measured −1 to +1). It was the heel-off rule's
/// switch, 5–14 frames early at 3–7 km/h and up to 46 frames early at 1–2 km/h × 1.8–2.0 m,
/// where the drawn roll stays flat well past it.
#[test]
fn the_heel_off_event_is_where_the_drawn_heel_leaves_the_floor() {
    let mut cases = Vec::new();
    for kmh in [1.0, 2.0, 3.0, 4.0, 5.0, 6.0, 7.0] {
        for h in [1.5, 1.8, 2.0] {
            cases.push((kmh, h));
        }
    }
    common::assert_grid(&cases, |&(kmh, h)| {
        let (m, _) = common::steady(kmh, h, 8);
        let fps = m.fps();
        let mut worst = 0i64;
        for e in m.events.iter().filter(|e| e.kind == EventKind::FootFlat) {
            let Some(off) = common::next_event(&m, EventKind::HeelOff, e.side, e.time_s) else {
                continue;
            };
            let heel = common::leg(e.side).heel;
            let ff = (e.time_s * fps).ceil() as usize;
            let Some(up) = (ff..m.len()).find(|&i| m.landmark(i, heel).y > 2e-4) else {
                continue;
            };
            let d = (off.time_s * fps).round() as i64 - up as i64;
            if d.abs() > worst.abs() {
                worst = d;
            }
        }
        (worst.abs() > 2).then(|| {
            format!("{kmh} km/h × {h} m: heel-off event {worst} frames from the drawn heel's rise")
        })
    });
}
