//! Round trip through gaitfit's own motion files: a generated run or walk written as CSV and
//! as TRC, under a file name that says the opposite gait, is read back, its gait decided from
//! the data (flight phases or double support), and its steps measured by the event pipeline:
//! cadence and step length within 1 % of the generator's plan, over a grid of speeds.
use gaitfit::calibrate::drive::{self, DriveOptions, Relations};
use gaitfit::calibrate::{measure, measure_trial};
use gaitfit::events::Gait;
use gaitfit::export::motion::{write_with, MotionOptions};
use gaitfit::generator::running::equations::RunRelations;
use gaitfit::generator::walking::WalkRelations;
use gaitfit::ingest::{read_trial, ReadOptions};

fn relations() -> Relations {
    Relations {
        run: RunRelations::published(),
        walk: WalkRelations::published(),
        source: "published".into(),
    }
}

fn check(gait: Gait, v: f64, h: f64) {
    let rel = relations();
    let o = DriveOptions {
        fps: 120.0,
        steps: 10,
    };
    let d = drive::drive(&rel, gait, v, h, 0.0, &drive::initial(gait, h), &o).unwrap();
    // The plan: the generator's commanded step length and frequency at this speed.
    let (sl, cad) = match gait {
        Gait::Run => {
            let sl = rel.run.step_length(v, 0.0, h);
            (sl, 60.0 * v / sl)
        }
        Gait::Walk => {
            let sl = rel.walk.sl_sf.step_length_for_speed(v * 60.0, h);
            (sl, 60.0 * v / sl)
        }
    };
    let dir = tempfile::tempdir().unwrap();
    let liar = match gait {
        Gait::Run => "walk",
        Gait::Walk => "run",
    };
    for ext in ["csv", "trc"] {
        let path = dir.path().join(format!("{liar}_{v}.{ext}"));
        write_with(&d.motion, &path, &MotionOptions::default()).unwrap();
        let trial = read_trial(&path, &ReadOptions::default()).unwrap();
        let (g, evidence) = measure::gait_from_data(&trial).unwrap();
        assert_eq!(g, gait, "{ext} {v} m/s: {evidence}");
        let (m, _) = measure_trial(&trial, None).unwrap();
        let opts = measure::event_options(&trial, g, None);
        let mw = measure::measure(&trial, g, evidence.clone(), &opts, d.window).unwrap();
        let q = &mw.quantities;
        println!(
            "{gait} {v} m/s {ext}: {evidence}; cadence {:.2} (plan {cad:.2}), sl {:.4} (plan {sl:.4}), all steps {:.2}",
            q.cadence_steps_per_min, q.step_length_m, m.quantities.cadence_steps_per_min
        );
        assert!(q.steps >= 6, "{ext} {v}: {} steps", q.steps);
        assert!(
            (q.cadence_steps_per_min / cad - 1.0).abs() < 0.01,
            "{gait} {v} m/s {ext}: cadence {} vs {cad}",
            q.cadence_steps_per_min
        );
        assert!(
            (q.step_length_m / sl - 1.0).abs() < 0.01,
            "{gait} {v} m/s {ext}: step length {} vs {sl}",
            q.step_length_m
        );
    }
}

#[test]
fn runs_read_back_as_runs_with_their_cadence_and_step_length() {
    for (v, h) in [(2.5, 1.7), (3.5, 1.8), (5.0, 1.9)] {
        check(Gait::Run, v, h);
    }
}

#[test]
fn walks_read_back_as_walks_with_their_cadence_and_step_length() {
    for (v, h) in [(1.0, 1.65), (1.4, 1.8), (1.7, 1.9)] {
        check(Gait::Walk, v, h);
    }
}

/// `gaitfit generate run|walk --calibration FILE` reads a calibrated.json and applies the
/// subject's offsets: a step-length offset of +5 cm shows in the generated plan.
#[test]
fn generate_reuses_a_calibration_file() {
    use gaitfit::calibrate::{CalibratedAttr, CalibratedFile, CalibratedSubject};
    let dir = tempfile::tempdir().unwrap();
    let attr = |name: &str, unit: &str, v: f64| CalibratedAttr {
        name: name.into(),
        unit: unit.into(),
        before: 0.0,
        value: v,
        se: None,
    };
    let f = CalibratedFile {
        format: CalibratedFile::FORMAT.into(),
        relations: "published".into(),
        subjects: vec![CalibratedSubject {
            subject: "s1".into(),
            gait: Gait::Run,
            body_height_m: 1.8,
            mass_kg: 70.0,
            speeds_m_per_s: vec![3.5],
            attributes: vec![
                attr("step_length_offset_m", "m", 0.05),
                attr("flight_time_offset_s", "s", 0.0),
                attr("bounciness_deg", "deg", 40.0),
            ],
        }],
    };
    let cal = dir.path().join("calibrated.json");
    std::fs::write(&cal, serde_json::to_string(&f).unwrap()).unwrap();
    let plan = |extra: &[&str]| -> f64 {
        let out = dir.path().join("r.csv");
        let plan = dir.path().join("plan.csv");
        let mut args = vec![
            "generate",
            "run",
            "--speed",
            "3.5",
            "--seconds",
            "3",
            "--no-stop",
            "-o",
        ];
        let (o, p) = (out.to_str().unwrap(), plan.to_str().unwrap());
        args.extend([o, "--plan", p]);
        args.extend(extra);
        assert_cmd::Command::cargo_bin("gaitfit")
            .unwrap()
            .args(&args)
            .assert()
            .success();
        let text = std::fs::read_to_string(&plan).unwrap();
        let last = text.lines().nth(4).unwrap().to_string();
        last.split(',').nth(6).unwrap().parse().unwrap()
    };
    let base = plan(&[]);
    let calibrated = plan(&["--calibration", cal.to_str().unwrap()]);
    assert!(
        (calibrated - base - 0.05).abs() < 1e-3,
        "step length {base} → {calibrated}"
    );
}
