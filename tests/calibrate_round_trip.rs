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
/// subject's offsets: a step-length offset of +5 cm shows in the generated plan; in format 2 an
/// offset with a speed slope is taken at the generated speed (+5 cm at 3.0 m/s, +0.1 m per m/s:
/// +10 cm at 3.5 m/s); a format-1 file (no slopes) still reads; an unknown format is refused
/// with the formats it knows.
#[test]
fn generate_reuses_a_calibration_file() {
    use gaitfit::calibrate::{CalibratedAttr, CalibratedFile, CalibratedSubject};
    let dir = tempfile::tempdir().unwrap();
    let attr = |name: &str, unit: &str, v: f64, slope: Option<f64>| CalibratedAttr {
        name: name.into(),
        unit: unit.into(),
        before: 0.0,
        value: v,
        se: None,
        slope_per_m_per_s: slope,
        slope_se: None,
    };
    let file = |slope: Option<f64>| CalibratedFile {
        format: CalibratedFile::FORMAT.into(),
        relations: "published".into(),
        subjects: vec![CalibratedSubject {
            subject: "s1".into(),
            gait: Gait::Run,
            body_height_m: 1.8,
            mass_kg: 70.0,
            speeds_m_per_s: vec![2.5, 3.5],
            reference_speed_m_per_s: slope.map(|_| 3.0),
            attributes: vec![
                attr("step_length_offset_m", "m", 0.05, slope),
                attr("flight_time_offset_s", "s", 0.0, slope.map(|_| 0.0)),
                attr("bounciness_deg", "deg", 40.0, None),
            ],
            solver: None,
        }],
    };
    let write = |name: &str, text: String| {
        let p = dir.path().join(name);
        std::fs::write(&p, text).unwrap();
        p.to_str().unwrap().to_string()
    };
    let constant = write("c.json", serde_json::to_string(&file(None)).unwrap());
    let sloped = write("s.json", serde_json::to_string(&file(Some(0.1))).unwrap());
    let v1 = write(
        "v1.json",
        serde_json::to_string(&file(None))
            .unwrap()
            .replace(CalibratedFile::FORMAT, "gaitfit-calibration-1"),
    );
    let v9 = write(
        "v9.json",
        serde_json::to_string(&file(None))
            .unwrap()
            .replace(CalibratedFile::FORMAT, "gaitfit-calibration-9"),
    );
    let args = |extra: &[&str], o: &str, p: &str| -> Vec<String> {
        let mut a: Vec<String> = [
            "generate",
            "run",
            "--speed",
            "3.5",
            "--seconds",
            "3",
            "--no-stop",
            "-o",
            o,
            "--plan",
            p,
        ]
        .iter()
        .map(|s| s.to_string())
        .collect();
        a.extend(extra.iter().map(|s| s.to_string()));
        a
    };
    let plan = |extra: &[&str]| -> f64 {
        let out = dir.path().join("r.csv");
        let plan = dir.path().join("plan.csv");
        let (o, p) = (out.to_str().unwrap(), plan.to_str().unwrap());
        assert_cmd::Command::cargo_bin("gaitfit")
            .unwrap()
            .args(args(extra, o, p))
            .assert()
            .success();
        let text = std::fs::read_to_string(&plan).unwrap();
        let last = text.lines().nth(4).unwrap().to_string();
        last.split(',').nth(6).unwrap().parse().unwrap()
    };
    let base = plan(&[]);
    for (f, want) in [(&constant, 0.05), (&v1, 0.05), (&sloped, 0.10)] {
        let calibrated = plan(&["--calibration", f]);
        assert!(
            (calibrated - base - want).abs() < 1e-3,
            "{f}: step length {base} → {calibrated}, want +{want}"
        );
    }
    let out = dir.path().join("r.csv");
    let err = assert_cmd::Command::cargo_bin("gaitfit")
        .unwrap()
        .args(args(
            &["--calibration", &v9],
            out.to_str().unwrap(),
            dir.path().join("p.csv").to_str().unwrap(),
        ))
        .assert()
        .failure()
        .get_output()
        .stderr
        .clone();
    let err = String::from_utf8_lossy(&err);
    assert!(
        err.contains("gaitfit-calibration-9") && err.contains("gaitfit-calibration-1"),
        "{err}"
    );
}
