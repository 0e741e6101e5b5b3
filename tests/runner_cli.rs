//! `gaitfit generate run` end to end in a fresh temp folder: the issue's schedule (accelerate
//! from 8 to 20 km/h, then stop) from standing to standing, and the three export formats (BVH,
//! CSV + events CSV, TRC) with the CSV columns the issue lists; bad input fails with a message
//! naming the problem and writes nothing.
use assert_cmd::Command;
use std::path::Path;

fn gaitfit(dir: &Path) -> Command {
    let mut c = Command::cargo_bin("gaitfit").unwrap();
    c.current_dir(dir);
    c
}

fn read_csv(path: &Path) -> (Vec<String>, Vec<Vec<f64>>) {
    let text = std::fs::read_to_string(path).unwrap();
    let mut lines = text.lines();
    let head = lines
        .next()
        .unwrap()
        .split(',')
        .map(str::to_string)
        .collect();
    let rows = lines
        .map(|l| {
            l.split(',')
                .map(|c| c.parse::<f64>().unwrap_or(f64::NAN))
                .collect()
        })
        .collect();
    (head, rows)
}

#[test]
fn schedule_accelerates_8_to_20_then_stops_standing() {
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(
        dir.path().join("steps.csv"),
        "step,speed_km_per_h,action\n0,8,run\n4,11,run\n8,14,run\n12,17,run\n16,20,run\n24,,stop\n",
    )
    .unwrap();
    gaitfit(dir.path())
        .args([
            "generate",
            "run",
            "--schedule",
            "steps.csv",
            "--seconds",
            "12",
        ])
        .args(["--steps-out", "table.csv", "-o", "run.csv"])
        .assert()
        .success();
    // The steps follow the schedule: 8 km/h from the start, 20 km/h from step 16, then a
    // deceleration, and never faster than 20 km/h.
    let (head, rows) = read_csv(&dir.path().join("table.csv"));
    let v = head.iter().position(|h| h == "speed_m_per_s").unwrap();
    let kmh: Vec<f64> = rows.iter().map(|r| r[v] * 3.6).collect();
    assert!((kmh[0] - 8.0).abs() < 1e-9, "first step at {} km/h", kmh[0]);
    assert!((kmh[16] - 20.0).abs() < 1e-9, "step 16 at {} km/h", kmh[16]);
    assert!(kmh.iter().all(|k| *k <= 20.0 + 1e-9));
    assert!(
        *kmh.last().unwrap() < 8.0,
        "decelerated to {} km/h",
        kmh.last().unwrap()
    );
    // From standing to standing: both feet down in the first and last frames, and the figure
    // still at the end.
    let (head, rows) = read_csv(&dir.path().join("run.csv"));
    let col = |n: &str| head.iter().position(|h| h == n).unwrap();
    let (lc, rc, px) = (col("l_contact"), col("r_contact"), col("pelvis_x_m"));
    let (first, last) = (&rows[0], rows.last().unwrap());
    assert_eq!((first[lc], first[rc]), (1.0, 1.0), "starts standing");
    assert_eq!((last[lc], last[rc]), (1.0, 1.0), "ends standing");
    let before = &rows[rows.len() - 13];
    assert!(
        (last[px] - before[px]).abs() < 1e-6,
        "still moving at the end"
    );
    assert!(last[px] > 20.0, "ran only {} m", last[px]);
}

#[test]
fn exports_bvh_csv_events_and_trc() {
    let dir = tempfile::tempdir().unwrap();
    for out in ["run.bvh", "run.csv", "run.trc"] {
        gaitfit(dir.path())
            .args([
                "generate",
                "run",
                "--speed",
                "12km/h",
                "--height",
                "1.75",
                "--seconds",
                "3",
            ])
            .args(["--attr", "strike=toe", "--attr", "arm_swing=1.4", "-o", out])
            .assert()
            .success();
    }
    // CSV: time, the landmarks the issue lists (x forward, y up, z right, metres), contacts,
    // then joint angles in degrees.
    let (head, rows) = read_csv(&dir.path().join("run.csv"));
    assert_eq!(head[0], "time_s");
    let mut want = vec!["pelvis".to_string(), "vertex".to_string()];
    for s in ["l", "r"] {
        for l in ["hip", "knee", "ankle", "heel", "ball", "toe", "wrist"] {
            want.push(format!("{s}_{l}"));
        }
    }
    for l in &want {
        for a in ["x", "y", "z"] {
            let c = format!("{l}_{a}_m");
            assert!(head.contains(&c), "no column {c}");
        }
    }
    let pos = |n: &str| head.iter().position(|h| h == n).unwrap();
    let (lc, rc) = (pos("l_contact"), pos("r_contact"));
    let last_landmark = head.iter().rposition(|h| h.ends_with("_m")).unwrap();
    let first_angle = head.iter().position(|h| h.ends_with("_deg")).unwrap();
    assert!(
        last_landmark < lc && lc < rc && rc < first_angle,
        "column order"
    );
    assert!(head[first_angle..].iter().all(|h| h.ends_with("_deg")));
    for j in ["l_hip", "r_knee", "l_ankle", "r_elbow", "pelvis", "lumbar"] {
        assert!(
            head.iter()
                .any(|h| h.starts_with(&format!("{j}_")) && h.ends_with("_deg")),
            "no {j} angles"
        );
    }
    // z to the right: the right hip lies at +z of the left; y up; x forward over the run.
    let r0 = &rows[0];
    assert!(r0[pos("r_hip_z_m")] > r0[pos("l_hip_z_m")]);
    assert!(r0[pos("vertex_y_m")] > 1.5);
    assert!(rows.last().unwrap()[pos("pelvis_x_m")] > r0[pos("pelvis_x_m")] + 3.0);
    // Contacts are 0/1; there are flight frames (both 0).
    assert!(rows
        .iter()
        .all(|r| [0.0, 1.0].contains(&r[lc]) && [0.0, 1.0].contains(&r[rc])));
    assert!(rows.iter().any(|r| r[lc] == 0.0 && r[rc] == 0.0));
    // Events CSV beside it.
    let ev = std::fs::read_to_string(dir.path().join("run_events.csv")).unwrap();
    let mut lines = ev.lines();
    assert_eq!(lines.next().unwrap(), "time_s,side,event");
    let events: Vec<Vec<&str>> = lines.map(|l| l.split(',').collect()).collect();
    for kind in ["heel_strike", "toe_off"] {
        for side in ["left", "right"] {
            assert!(
                events.iter().any(|e| e[1] == side && e[2] == kind),
                "no {side} {kind}"
            );
        }
    }
    // BVH: hierarchy rooted at the pelvis, one motion line per CSV frame.
    let bvh = std::fs::read_to_string(dir.path().join("run.bvh")).unwrap();
    assert!(bvh.starts_with("HIERARCHY\nROOT pelvis"));
    let frames: usize = bvh
        .lines()
        .find_map(|l| l.strip_prefix("Frames: "))
        .unwrap()
        .trim()
        .parse()
        .unwrap();
    assert_eq!(frames, rows.len());
    let motion = bvh.split("MOTION\n").nth(1).unwrap();
    assert_eq!(motion.lines().count(), frames + 2);
    // TRC: OpenSim header with the frame and marker counts, millimetres.
    let trc = std::fs::read_to_string(dir.path().join("run.trc")).unwrap();
    let l: Vec<&str> = trc.lines().collect();
    assert!(l[0].starts_with("PathFileType\t4"));
    let vals: Vec<&str> = l[2].split('\t').collect();
    assert_eq!(vals[2].parse::<usize>().unwrap(), rows.len());
    assert_eq!(vals[4], "mm");
    assert!(l[3].contains("\tl_heel\t") && l[3].contains("\tr_toe\t"));
}

#[test]
fn bad_input_names_the_problem_and_writes_nothing() {
    let dir = tempfile::tempdir().unwrap();
    let cases: [(&[&str], &str); 4] = [
        (&["--attr", "wobble=3"], "wobble"),
        (&["--attr", "overstride=2m"], "overstride"),
        (&["--speed", "fast"], "--speed"),
        (&["--schedule", "missing.csv"], "missing.csv"),
    ];
    for (args, needle) in cases {
        let out = gaitfit(dir.path())
            .args(["generate", "run"])
            .args(args)
            .args(["-o", "run.csv"])
            .assert()
            .failure();
        let err = String::from_utf8_lossy(&out.get_output().stderr).to_string();
        assert!(err.contains(needle), "{args:?}: {err}");
        assert!(
            !dir.path().join("run.csv").exists(),
            "{args:?} wrote output"
        );
    }
    std::fs::write(
        dir.path().join("s.csv"),
        "step,speed_km_per_h\n0,12\n1,abc\n",
    )
    .unwrap();
    let out = gaitfit(dir.path())
        .args(["generate", "run", "--schedule", "s.csv", "-o", "run.csv"])
        .assert()
        .failure();
    let err = String::from_utf8_lossy(&out.get_output().stderr).to_string();
    assert!(err.contains("s.csv") && err.contains("row 2"), "{err}");
}
