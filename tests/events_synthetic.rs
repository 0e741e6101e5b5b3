//! Event detection and per-step tables on a synthetic treadmill gait with known events.
use gaitfit::events::compare::{compare, Coverage};
use gaitfit::events::synthetic::SyntheticGait;
use gaitfit::events::{analyse, steps_from_analysis, EventKind, EventOptions, EventSource, Gait};

fn check(g: &SyntheticGait, gait: Gait, zeni_tol_ms: f64) {
    let trial = g.trial();
    let truth = g.events();
    let opts = EventOptions::default();
    let an = analyse(&trial, &opts).unwrap();
    assert_eq!(an.events.primary, EventSource::Force);
    let span = (0.0, g.duration_s);
    let mut sources = vec![
        ("force", &an.events.force, 8.0),
        ("zeni coordinate", &an.events.zeni_coordinate, zeni_tol_ms),
        ("zeni velocity", &an.events.zeni_velocity, zeni_tol_ms),
    ];
    match gait {
        // On the belt the synthetic foot's speed over the ground jumps from the walking speed
        // to zero at heel strike and back at toe off (the belt velocity must be removed for
        // that); the 6 Hz filter spreads each jump over about ±40 ms, so the 0.5 / 0.8
        // crossings land within three frames (20 ms at 150 Hz) of the jump.
        Gait::Walk => sources.push(("foot speed", &an.events.foot_speed, 20.0)),
        Gait::Run => assert!(an.events.foot_speed.is_empty(), "walking detector on a run"),
    }
    for (name, det, tol_ms) in sources {
        let c = compare(det, &truth, Coverage::Complete, span, 0.06);
        for kind in [EventKind::HeelStrike, EventKind::ToeOff] {
            let k = &c[&kind];
            assert!(
                k.f1().unwrap() > 0.95,
                "{name} {kind}: F1 {:?} {k:?}",
                k.f1()
            );
            let m = k.mean_ms().unwrap();
            eprintln!("{name} {kind}: mean error {m:.1} ms, F1 {:?}", k.f1());
            assert!(m.abs() < tol_ms, "{name} {kind}: mean error {m} ms");
        }
    }
    let t = steps_from_analysis(&trial, &an, &opts).unwrap();
    assert!(t.rows.len() > 10);
    for r in &t.rows {
        assert_eq!(r.gait, Some(gait));
        let sl = r.step_length_m.unwrap();
        assert!((sl - g.step_length_m()).abs() < 0.02, "step length {sl}");
        let sf = r.step_freq_hz.unwrap();
        assert!((1.0 / sf - 0.5 * g.stride_time_s).abs() < 0.005);
        let st = r.stance_time_s.unwrap();
        // A half-sine force crosses 20 N about 6 ms after contact and before lift-off.
        assert!((st - g.stance_s()).abs() < 0.015, "stance {st}");
        let v = r.speed_m_per_s.unwrap();
        assert!((v - sl * sf).abs() < 1e-9);
        match gait {
            Gait::Walk => {
                let ds = r.double_support_time_s.unwrap();
                assert!((ds + g.flight_s()).abs() < 0.015, "double support {ds}");
                let pct = r.double_support_pct_cycle.unwrap();
                assert!((pct - ds / g.stride_time_s * 100.0).abs() < 1.0);
                assert!(r.flight_time_s.is_none());
            }
            Gait::Run => {
                let tf = r.flight_time_s.unwrap();
                assert!((tf - g.flight_s()).abs() < 0.015, "flight {tf}");
                let h = r.flight_height_m.unwrap();
                let truth_h = gaitfit::units::G * g.flight_s().powi(2) / 8.0;
                assert!((h - truth_h).abs() < 0.003, "H {h} vs {truth_h}");
                assert!(r.double_support_time_s.is_none());
            }
        }
        // μ inputs are there with gaitfit landmarks.
        assert!(r.foot_angle_hs_rad.is_some() && r.knee_angle_hs_rad.is_some());
    }
}

#[test]
fn synthetic_walk() {
    check(&SyntheticGait::walk(), Gait::Walk, 25.0);
}

#[test]
fn synthetic_run() {
    // The synthetic swing ends with the heel at rest relative to the pelvis; the 6 Hz filter
    // rounds that corner and moves the maximum earlier, more so for the short running step.
    check(&SyntheticGait::run(), Gait::Run, 40.0);
}

#[test]
fn without_per_foot_plates_the_files_own_events_come_before_zeni() {
    let g = SyntheticGait::walk();
    let mut trial = g.trial();
    trial.plates.clear();
    let opts = EventOptions::default();
    // Markers only, walking: the foot-speed events (Zeni windows refined) build the steps.
    let an = analyse(&trial, &opts).unwrap();
    assert_eq!(an.events.primary, EventSource::FootSpeed);
    // With the file's own events (a C3D EVENT group), those are used and kept as they are.
    trial.reference_events = g
        .events()
        .into_iter()
        .map(|mut e| {
            e.source = EventSource::Reference;
            e
        })
        .collect();
    let an = analyse(&trial, &opts).unwrap();
    assert_eq!(an.events.primary, EventSource::Reference);
    assert_eq!(an.events.reference, trial.reference_events);
    // A generator's own events (a generated motion read back) do not replace detection.
    let mut generated = trial.clone();
    for e in &mut generated.reference_events {
        e.source = EventSource::Generated;
    }
    let g_an = analyse(&generated, &opts).unwrap();
    assert_eq!(g_an.events.primary, EventSource::FootSpeed);
    let t = steps_from_analysis(&trial, &an, &opts).unwrap();
    let ds: Vec<f64> = t
        .rows
        .iter()
        .filter_map(|r| r.double_support_time_s)
        .collect();
    assert!(ds.len() > 10, "{} steps with double support", ds.len());
    let expect = (g.duty_factor - 0.5) * g.stride_time_s;
    for d in ds {
        assert!((d - expect).abs() < 1e-6, "double support {d} vs {expect}");
    }
}

/// The same walk on a treadmill and overground (every forward coordinate plus belt speed × t):
/// the foot-speed detector removes the belt's velocity, so it finds the same events, and the
/// ground moves at minus the belt speed on the treadmill and stands still overground.
#[test]
fn foot_speed_events_are_the_same_on_a_treadmill_and_overground() {
    use gaitfit::events::kinematic::Kinematics;
    let g = SyntheticGait::walk();
    let mut belt = g.trial();
    belt.plates.clear();
    let mut ground = belt.clone();
    let ms = ground.markers.as_mut().unwrap();
    let times = ms.time_s.clone();
    for m in &mut ms.positions {
        for (p, t) in m.iter_mut().zip(&times) {
            p[0] += g.belt_speed_m_per_s * t;
        }
    }
    let opts = EventOptions::default();
    let a = analyse(&belt, &opts).unwrap();
    let b = analyse(&ground, &opts).unwrap();
    assert_eq!(a.events.primary, EventSource::FootSpeed);
    assert_eq!(b.events.primary, EventSource::FootSpeed);
    assert!(a.events.foot_speed.len() > 20);
    assert_eq!(a.events.foot_speed.len(), b.events.foot_speed.len());
    for (x, y) in a.events.foot_speed.iter().zip(&b.events.foot_speed) {
        assert_eq!((x.side, x.kind), (y.side, y.kind));
        // 1e-5 s: the two medians (ground, walking speed) differ in the last digits.
        // The filter is linear and passes a ramp unchanged, except within its edge padding
        // (about half a second) at either end of the record.
        let interior = x.time_s > 0.5 && x.time_s < g.duration_s - 0.5;
        let tol = if interior { 1e-9 } else { 1e-4 };
        assert!((x.time_s - y.time_s).abs() < tol, "{x:?} vs {y:?}");
    }
    let speeds = |an: &gaitfit::events::Analysis| {
        let k: &Kinematics = an.kinematics.as_ref().unwrap();
        k.ground_and_walking_speed(&an.events.zeni_coordinate)
            .unwrap()
    };
    let (gb, vb) = speeds(&a);
    let (gg, vg) = speeds(&b);
    let v = g.belt_speed_m_per_s;
    assert!(
        (gb + v).abs() < 0.01 && gg.abs() < 0.01,
        "ground {gb} / {gg}"
    );
    assert!(
        (vb - v).abs() < 0.01 && (vg - v).abs() < 0.01,
        "speed {vb} / {vg}"
    );
}
