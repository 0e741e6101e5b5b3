//! Walks that change speed at one-step granularity (§2.4), start from standing and stop, and the
//! paper's Fig. 8 sequences (one leg over 2 km/h for 4 cycles and 5 km/h for 3 cycles).
use gaitfit::events::{EventKind, Side};
use gaitfit::generator::checks::{ground_penetration, stance_sliding};
use gaitfit::generator::motion::Motion;
use gaitfit::generator::skeleton::Landmark;
use gaitfit::generator::walking::{
    generate_walk, read_schedule, ScheduleEntry, WalkOptions, WalkParams, WalkReport,
};

fn kmh(v: f64, steps: usize) -> ScheduleEntry {
    ScheduleEntry {
        params: WalkParams {
            speed_m_per_s: Some(v / 3.6),
            ..Default::default()
        },
        steps,
    }
}

/// Heel x of the landing foot just after each heel strike inside the motion, with its time.
fn heel_strikes(m: &Motion) -> Vec<(f64, Side, f64)> {
    m.events
        .iter()
        .filter(|e| e.kind == EventKind::HeelStrike)
        .filter_map(|e| {
            let f = (e.time_s * m.fps()).ceil() as usize;
            (f < m.len()).then(|| {
                let lm = match e.side {
                    Side::Left => Landmark::LHeel,
                    Side::Right => Landmark::RHeel,
                };
                (e.time_s, e.side, m.landmark(f, lm).x)
            })
        })
        .collect()
}

/// Every step ends on its own commanded step length (heel to heel, 1 %) and lasts its own
/// commanded step time (1 %); every phase meets its end conditions (0.1°).
fn each_step_meets_its_own_command(m: &Motion, r: &WalkReport) {
    let hs = heel_strikes(m);
    for s in &r.steps {
        for e in &s.errors[1..] {
            assert!(e.abs() < 0.1f64.to_radians(), "step {}: {e}", s.index);
        }
        assert!(
            s.errors[0].abs() < 1e-4,
            "step {}: {}",
            s.index,
            s.errors[0]
        );
        let t_end = s.start_s + s.times.step;
        let (Some(a), Some(b)) = (
            hs.iter().find(|h| (h.0 - s.start_s).abs() < 1e-9),
            hs.iter().find(|h| (h.0 - t_end).abs() < 1e-9),
        ) else {
            continue; // the first step from rest has no heel strike at its start
        };
        let d = b.2 - a.2;
        assert!(
            (d - s.step_length_m).abs() < 0.01 * s.step_length_m,
            "step {}: length {d} vs {}",
            s.index,
            s.step_length_m
        );
        let f = 60.0 / (b.0 - a.0);
        let sf = s.step_freq_steps_per_min;
        assert!((f - sf).abs() < 0.01 * sf, "step {}: {f} vs {sf}", s.index);
    }
    let sliding = stance_sliding(m, 0.002, 0.002);
    assert!(sliding.passed, "{sliding}");
    let pen = ground_penetration(m, 0.001);
    assert!(pen.passed, "{pen}");
}

#[test]
fn figure_8_sequences_two_and_five_km_per_h() {
    // Fig. 8: one leg, 2 km/h for 4 cycles (8 steps) and 5 km/h for 3 cycles (6 steps), h = 1.8 m.
    for (v, cycles) in [(2.0, 4), (5.0, 3)] {
        let (m, r) = generate_walk(&[kmh(v, 2 * cycles)], &WalkOptions::default()).unwrap();
        assert_eq!(r.steps.len(), 2 * cycles);
        each_step_meets_its_own_command(&m, &r);
        // One leg's cycles: its heel strikes are a stride (two step lengths) and a cycle time
        // (two step times) apart.
        let s = &r.steps[0];
        let left: Vec<_> = heel_strikes(&m)
            .into_iter()
            .filter(|h| h.1 == Side::Left)
            .collect();
        assert_eq!(left.len(), cycles, "{v} km/h");
        for w in left.windows(2) {
            let stride = w[1].2 - w[0].2;
            assert!((stride - 2.0 * s.step_length_m).abs() < 0.02 * s.step_length_m);
            let cycle = w[1].0 - w[0].0;
            assert!((cycle - 2.0 * s.times.step).abs() < 1e-9);
        }
        // The walk's speed is the commanded one.
        let first = left[0];
        let last = left[left.len() - 1];
        let speed = (last.2 - first.2) / (last.0 - first.0) * 3.6;
        assert!((speed - v).abs() < 0.01 * v, "{speed} km/h vs {v}");
    }
}

#[test]
fn accelerating_and_decelerating_from_standing_to_stop() {
    // From standing at 2 km/h, up to 5 km/h, down to 3 km/h, and stop: the steps change at
    // one-step granularity and each meets its own constraints.
    let opts = WalkOptions {
        start_from_rest: true,
        stop: true,
        ..Default::default()
    };
    let (m, r) = generate_walk(&[kmh(2.0, 3), kmh(5.0, 4), kmh(3.0, 3)], &opts).unwrap();
    assert_eq!(r.steps.len(), 10);
    // The first and last steps are half steps (from and to standing).
    let sl = |k: usize| r.steps[k].step_length_m;
    assert!((sl(0) - 0.5 * sl(1)).abs() < 1e-12);
    assert!((sl(9) - 0.5 * sl(8)).abs() < 1e-12);
    // The speed changes between consecutive steps.
    assert!(r.steps[3].step_length_m > r.steps[2].step_length_m);
    assert!(r.steps[7].step_length_m < r.steps[6].step_length_m);
    each_step_meets_its_own_command(&m, &r);
    // Standing at the start: the pelvis is at rest in the first frames.
    let p0 = m.landmark(0, Landmark::Pelvis);
    let p1 = m.landmark(1, Landmark::Pelvis);
    assert!((p1 - p0).length() * m.fps() < 0.3, "start speed");
}

#[test]
fn schedule_file_reads_and_drives_a_walk() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("fig8.csv");
    std::fs::write(
        &path,
        "steps,speed_km_per_h,step_length_m\n4,2,\n3,5,\n2,,0.6\n",
    )
    .unwrap();
    let s = read_schedule(&path).unwrap();
    assert_eq!(s.len(), 3);
    assert!((s[1].params.speed_m_per_s.unwrap() - 5.0 / 3.6).abs() < 1e-12);
    assert_eq!(s[2].params.step_length_m, Some(0.6));
    let (m, r) = generate_walk(&s, &WalkOptions::default()).unwrap();
    assert_eq!(r.steps.len(), 9);
    each_step_meets_its_own_command(&m, &r);
    // A bad cell names the file, row and column.
    std::fs::write(&path, "steps,speed_km_per_h\n4,fast\n").unwrap();
    let e = read_schedule(&path).unwrap_err().to_string();
    assert!(
        e.contains("fig8.csv") && e.contains("row 2") && e.contains("speed_km_per_h"),
        "{e}"
    );
}
