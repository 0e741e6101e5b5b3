//! Reference tests of the running generator's parameter coupling against the numbers printed in
//! Bruderlin & Calvert (1996). Sources:
//! - §2.2, eq. 2: at 12 km/h (200 m/min), level 0, h = 1.8 m, sl = 0.1394 + 0.00465·200 =
//!   1.0694 m, so sf = v/sl = 187.0 steps/min (§3.1.1: "the default 187 steps/sec", a typo for
//!   steps/min; "the normally chosen step length of 1.07 m").
//! - §2.2, eq. 4: t_flight(187 steps/min) = 0.188 s.
//! - §3.1.1, Fig. 4: "the velocity was locked at 12 km/h and then step frequency was increased
//!   from the default 187 … to 210, which decreased the normally chosen step length of 1.07 m to
//!   0.95 and the flight height from 0.004 m to 0.001." The flight heights depend on the pelvis
//!   heights at toe off and heel strike (eq. 3), i.e. on the figure and the attribute defaults,
//!   which the paper does not print; gaitfit's defaults are tuned to give 0.0040 m and 0.0013 m
//!   (both round to the paper's figures).
use gaitfit::generator::running::state::G;
use gaitfit::generator::running::{generate_run, GenerateOptions, Param, RunAttributes, RunModel};

fn model() -> (RunModel, RunAttributes) {
    (
        RunModel::published(1.8).unwrap(),
        RunAttributes::defaults(1.8),
    )
}

#[test]
fn natural_stride_at_12_km_h() {
    let (m, a) = model();
    let p = m.natural(12.0 / 3.6, 0.0, &a).unwrap();
    assert!(
        (p.step_length - 1.0694).abs() < 1e-9,
        "sl {}",
        p.step_length
    );
    assert!(
        (p.step_freq * 60.0 - 187.02).abs() < 0.01,
        "sf {}",
        p.step_freq * 60.0
    );
    assert!(
        (p.flight_time - 0.188).abs() < 5e-4,
        "t_flight {}",
        p.flight_time
    );
    // Paper: H = 0.004 m (printed to one significant digit).
    assert!(
        (p.flight_height - 0.004).abs() < 0.0002,
        "H {}",
        p.flight_height
    );
}

#[test]
fn locked_speed_and_raised_step_frequency() {
    let (m, a) = model();
    let mut p = m.natural(12.0 / 3.6, 0.0, &a).unwrap();
    p.locks.speed = true;
    let q = m.set(&p, Param::StepFreq, 210.0 / 60.0, &a).unwrap();
    assert!((q.speed - 12.0 / 3.6).abs() < 1e-12, "v stays locked");
    assert!(
        (q.step_length - 0.9524).abs() < 1e-4,
        "sl {} (paper 0.95)",
        q.step_length
    );
    // Paper: H 0.004 → 0.001 m.
    assert!(
        (q.flight_height - 0.001).abs() < 0.0005,
        "H {} (paper 0.001)",
        q.flight_height
    );
    assert!(q.flight_height < p.flight_height);
    println!(
        "paper example: sl {:.4} → {:.4} m (paper 1.07 → 0.95), H {:.5} → {:.5} m (paper 0.004 → 0.001)",
        p.step_length, q.step_length, p.flight_height, q.flight_height
    );
}

#[test]
fn changing_one_parameter_updates_the_others() {
    let (m, a) = model();
    let p = m.natural(12.0 / 3.6, 0.0, &a).unwrap();
    // Step length → speed by the inverse of eq. 2, sf by eq. 1.
    let q = m.set(&p, Param::StepLength, 1.379, &a).unwrap();
    assert!((q.speed * 60.0 - 0.0 - (1.379 - 0.1394) / 0.00465).abs() < 1e-6);
    assert!((q.speed - q.step_length * q.step_freq).abs() < 1e-12);
    // Step frequency → sl = a/(1 − b·sf) (eqs. 1–2 together).
    let r = m.set(&p, Param::StepFreq, 190.0 / 60.0, &a).unwrap();
    assert!((r.step_length - 0.1394 / (1.0 - 0.00465 * 190.0)).abs() < 1e-9);
    // Flight height with nothing locked: sf moves along eqs. 1–2 until eq. 3 gives H.
    let h = m.set(&p, Param::FlightHeight, 0.008, &a).unwrap();
    assert!(
        (h.flight_height - 0.008).abs() < 1e-6,
        "H {}",
        h.flight_height
    );
    assert!(
        (h.step_length - m.relations.step_length(h.speed, 0.0, 1.8)).abs() < 1e-9,
        "eq. 2 still holds"
    );
    assert!(!h.flight_from_height);
    // Flight height with v and sf locked: eqs. 4–5 give way, the flight time comes from H
    // (case II, Newton–Raphson) and the generated steps fly exactly that high.
    let mut locked = p;
    locked.locks.speed = true;
    locked.locks.step_freq = true;
    let c2 = m.set(&locked, Param::FlightHeight, 0.010, &a).unwrap();
    assert!(c2.flight_from_height && (c2.flight_height - 0.010).abs() < 1e-12);
    assert!((c2.step_freq - p.step_freq).abs() < 1e-12 && (c2.speed - p.speed).abs() < 1e-12);
    assert!(
        c2.flight_time > p.flight_time,
        "higher flight, longer flight time"
    );
    let opts = GenerateOptions {
        seconds: 2.0,
        fps: 120.0,
        stop_at_end: false,
    };
    let (_, rep) = generate_run(&m, c2, a, None, &opts).unwrap();
    for s in rep.steps.iter().skip(2) {
        assert!(
            (s.report.flight_height - 0.010).abs() < 1e-9,
            "step {} H {}",
            s.index,
            s.report.flight_height
        );
    }
}

#[test]
fn three_locked_parameters_are_refused() {
    let (m, a) = model();
    let mut p = m.natural(12.0 / 3.6, 0.0, &a).unwrap();
    p.locks.speed = true;
    p.locks.step_length = true;
    let e = m.set(&p, Param::StepFreq, 3.3, &a).unwrap_err().to_string();
    assert!(e.contains("unlock"), "{e}");
    assert!(m.set(&p, Param::Speed, -1.0, &a).is_err());
    assert!(m.natural(40.0, 0.0, &a).is_err(), "144 km/h is not a run");
}

/// Eq. 3 holds for every generated step: H = g/8 · (t − 2(y1 − y2)/(g t))², with y1, y2 the pelvis
/// heights at toe off and heel strike and t the flight time; eq. 7: x1 = x2 − v·t.
#[test]
fn every_step_satisfies_eqs_3_and_7() {
    let (m, a) = model();
    for kmh in [6.0, 12.0, 18.0] {
        let p = m.natural(kmh / 3.6, 0.0, &a).unwrap();
        let opts = GenerateOptions {
            seconds: 2.0,
            fps: 120.0,
            stop_at_end: false,
        };
        let (_, rep) = generate_run(&m, p, a.clone(), None, &opts).unwrap();
        let last = rep.steps.last().unwrap();
        assert!((last.speed - p.speed).abs() < 1e-12, "{kmh} km/h reached");
        for s in &rep.steps {
            let r = &s.report;
            let t = r.t_flight;
            let h = G / 8.0 * (t - 2.0 * (r.p1.y - r.p2.y) / (G * t)).powi(2);
            assert!((h - r.flight_height).abs() < 1e-12);
            assert!((r.p1.x - (r.p2.x - s.speed * t)).abs() < 1e-12);
            // The start builds up speed step by step, each step at its natural parameters.
            let own = m.natural(s.speed, 0.0, &a).unwrap();
            assert!(
                (t - own.flight_time).abs() < 1e-12,
                "case I: t_flight from eq. 4/5"
            );
        }
    }
}

/// The paper's Fig. 4 example carried through the generated motion: v locked at 12 km/h and
/// sf raised from 187 to 210 steps/min; once steady, the run measured by gaitfit's own event
/// detection (foot-marker heights, default options, 120 fps) has sl 0.95 m and sf 210/min
/// (1 %), and every steady step was planned with the paper's H (0.001 m; here 0.0013).
#[test]
fn locked_speed_example_in_the_generated_run() {
    use gaitfit::events::{steps_from_trial, EventOptions, Gait, PrimarySource};
    let (m, a) = model();
    let mut p = m.natural(12.0 / 3.6, 0.0, &a).unwrap();
    p.locks.speed = true;
    let q = m.set(&p, Param::StepFreq, 210.0 / 60.0, &a).unwrap();
    let opts = GenerateOptions {
        seconds: 6.0,
        fps: 120.0,
        stop_at_end: false,
    };
    let (mo, rep) = generate_run(&m, q, a, None, &opts).unwrap();
    let steady = rep
        .steps
        .iter()
        .find(|s| (s.step_freq - q.step_freq).abs() < 1e-12)
        .unwrap()
        .start_s;
    for s in rep.steps.iter().filter(|s| s.start_s >= steady) {
        assert!((s.report.flight_height - 0.001).abs() < 0.0005);
        assert!((s.step_length - 0.9524).abs() < 1e-4);
    }
    let eo = EventOptions {
        primary: PrimarySource::FootHeight,
        gait: Some(Gait::Run),
        ..EventOptions::default()
    };
    let table = steps_from_trial(&mo.to_trial("fig4"), &eo).unwrap();
    let rows: Vec<_> = table
        .rows
        .iter()
        .filter(|r| r.time_s.unwrap() > steady + 0.05 && r.time_s.unwrap() < mo.duration_s() - 0.5)
        .collect();
    assert!(rows.len() >= 10, "{} steady steps", rows.len());
    let mean = |f: &dyn Fn(&gaitfit::ingest::trials::StepRow) -> f64| {
        rows.iter().map(|r| f(r)).sum::<f64>() / rows.len() as f64
    };
    let sl = mean(&|r| r.step_length_m.unwrap());
    let sf = mean(&|r| r.step_freq_hz.unwrap()) * 60.0;
    println!(
        "Fig. 4 run, detected: sl {sl:.4} m, sf {sf:.2} steps/min over {} steps",
        rows.len()
    );
    assert!((sl / 0.95 - 1.0).abs() < 0.01, "sl {sl}");
    assert!((sf / 210.0 - 1.0).abs() < 0.01, "sf {sf}");
}
