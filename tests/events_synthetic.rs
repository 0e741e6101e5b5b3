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
    for (name, det, tol_ms) in [
        ("force", &an.events.force, 8.0),
        ("zeni coordinate", &an.events.zeni_coordinate, zeni_tol_ms),
        ("zeni velocity", &an.events.zeni_velocity, zeni_tol_ms),
    ] {
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
    // Markers only: the Zeni coordinate events build the steps.
    let an = analyse(&trial, &opts).unwrap();
    assert_eq!(an.events.primary, EventSource::ZeniCoordinate);
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
    assert_eq!(g_an.events.primary, EventSource::ZeniCoordinate);
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
