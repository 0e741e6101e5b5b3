//! OpenSim motion files (`-o x.mot` / `.sto`): the layout OpenSim's inverse kinematics writes
//! (compared with files OpenSim wrote, in the shared data), the gait models' coordinate names,
//! degrees, and the sign conventions of gait2392 and Rajagopal 2015 on poses whose angles are
//! known. OpenSim itself reads the files and reproduces gaitfit's joint positions from them in
//! `tools/export/check_mot_opensim.py` (optional; run by hand, see the note of issue 22).
use assert_cmd::Command;
use gaitfit::export::opensim::{self, coordinate_names, MotOptions, OpenSimModel};
use gaitfit::generator::motion::{Motion, MotionMetadata};
use gaitfit::generator::skeleton::{Euler, Joint, Skeleton};
use gaitfit::ingest::mot::read_table;
use glam::DVec3;

const H: f64 = 1.62;

/// Frames whose joint angles are set, one frame per pose.
fn motion(poses: &[&[(Joint, Euler)]]) -> Motion {
    let sk = Skeleton::from_height(H, 60.0).unwrap();
    let mut m = Motion::new(sk.clone(), 100.0, MotionMetadata::new("test", None)).unwrap();
    for (i, set) in poses.iter().enumerate() {
        let mut p = sk.rest_pose();
        p.root = DVec3::new(0.5 + 0.01 * i as f64, sk.hip_height(), -0.02);
        for &(j, e) in set.iter() {
            p.set_euler(j, e);
        }
        m.push_frame(p, [true, true]);
    }
    m
}

/// The header lines before `endheader`, the column labels, and the rows.
fn parse(text: &str) -> (Vec<&str>, Vec<&str>, Vec<Vec<f64>>) {
    let mut lines = text.lines();
    let header: Vec<&str> = lines.by_ref().take_while(|l| *l != "endheader").collect();
    let labels: Vec<&str> = lines.next().unwrap().split('\t').collect();
    let rows = lines
        .map(|l| {
            l.split('\t')
                .map(|c| {
                    assert_eq!(c.len(), 16, "{c:?}: cells are 16 wide, as OpenSim writes");
                    c.trim().parse::<f64>().unwrap()
                })
                .collect()
        })
        .collect();
    (header, labels, rows)
}

/// The header of OpenSim's inverse-kinematics output (the shared data's `*_ik.mot`, written by
/// OpenSim 4), with the two counts.
fn opensim_ik_header(rows: usize, columns: usize) -> Vec<String> {
    vec![
        "Coordinates".into(),
        "version=1".into(),
        format!("nRows={rows}"),
        format!("nColumns={columns}"),
        "inDegrees=yes".into(),
        String::new(),
        "Units are S.I. units (second, meters, Newtons, ...)".into(),
        "If the header above contains a line with 'inDegrees', this indicates whether rotational \
         values are in degrees (yes) or radians (no)."
            .into(),
        String::new(),
    ]
}

#[test]
fn the_layout_is_opensims_and_gaitfits_mot_reader_reads_it_back() {
    let m = motion(&[
        &[(Joint::RKnee, Euler::sagittal(-0.3))],
        &[(Joint::RKnee, Euler::sagittal(-0.6))],
        &[(Joint::RKnee, Euler::sagittal(-0.9))],
    ]);
    let dir = tempfile::tempdir().unwrap();
    for (ext, model) in [
        ("mot", OpenSimModel::Gait2392),
        ("sto", OpenSimModel::Rajagopal2015),
    ] {
        let path = dir.path().join(format!("m.{ext}"));
        opensim::write(&m, &path, &MotOptions { model }).unwrap();
        let text = std::fs::read_to_string(&path).unwrap();
        let (header, labels, rows) = parse(&text);
        let names = coordinate_names(model);
        assert_eq!(header, opensim_ik_header(3, names.len() + 1));
        assert_eq!(labels[0], "time");
        assert_eq!(&labels[1..], names.as_slice());
        assert_eq!(rows.len(), 3);
        for (i, r) in rows.iter().enumerate() {
            assert_eq!(r.len(), names.len() + 1);
            assert!((r[0] - i as f64 / 100.0).abs() < 1e-9);
        }
        // gaitfit's reader of OpenSim's MOT/STO files: degrees converted back, translations
        // not.
        let t = read_table(&path).unwrap();
        assert_eq!(t.in_degrees, Some(true));
        assert_eq!(t.names, names);
        let knee = t.column("knee_angle_r").unwrap();
        let sign = if model == OpenSimModel::Gait2392 {
            1.0
        } else {
            -1.0
        };
        for (k, want) in knee.iter().zip([-0.3, -0.6, -0.9]) {
            assert!(
                (k - sign * want).abs() < 1e-8,
                "{ext}: {k} vs {}",
                sign * want
            );
        }
        let ty = t.column("pelvis_ty").unwrap();
        let sk = m.skeleton();
        assert!(
            (ty[0] - (sk.hip_height() + 0.0661 * H / 1.8)).abs() < 1e-8,
            "{}",
            ty[0]
        );
    }
}

/// The sign conventions on known angles: OpenSim's axes are gaitfit's, its left-side x and y
/// axes are mirrored, gait2392's knee flexes negative and Rajagopal's positive, the lumbar
/// coordinates are the chest relative to the pelvis, the arm's the upper arm relative to it.
#[test]
fn coordinates_follow_the_gait_models_conventions() {
    let (a, b, c) = (0.5, 0.1, -0.2);
    let m = motion(&[&[
        (Joint::Pelvis, Euler::new(-0.1, 0.05, 0.2)),
        (Joint::RHip, Euler::new(a, b, c)),
        (Joint::LHip, Euler::new(a, b, c)),
        (Joint::RKnee, Euler::sagittal(-1.0)),
        (Joint::LKnee, Euler::sagittal(-0.2)),
        (Joint::RAnkle, Euler::new(0.15, 0.07, 0.0)),
        (Joint::LAnkle, Euler::new(-0.25, 0.07, 0.0)),
        (Joint::RMetatarsal, Euler::sagittal(0.4)),
        (Joint::Lumbar, Euler::sagittal(0.1)),
        (Joint::ThoracicLower, Euler::sagittal(0.2)),
        (Joint::ThoracicUpper, Euler::sagittal(0.05)),
        (Joint::RShoulder, Euler::new(0.6, 0.0, 0.0)),
        (Joint::LShoulder, Euler::new(-0.3, 0.2, 0.0)),
        (Joint::RElbow, Euler::sagittal(1.1)),
    ]]);
    let deg = f64::to_degrees;
    for model in [OpenSimModel::Gait2392, OpenSimModel::Rajagopal2015] {
        let names = coordinate_names(model);
        let row = opensim::frame_coordinates(&m, 0, model);
        let get = |n: &str| row[names.iter().position(|x| *x == n).unwrap()];
        let knee = if model == OpenSimModel::Gait2392 {
            1.0
        } else {
            -1.0
        };
        for (n, want) in [
            ("pelvis_tilt", deg(-0.1)),
            ("pelvis_list", deg(0.05)),
            ("pelvis_rotation", deg(0.2)),
            ("hip_flexion_r", deg(a)),
            ("hip_adduction_r", deg(b)),
            ("hip_rotation_r", deg(c)),
            ("hip_flexion_l", deg(a)),
            ("hip_adduction_l", -deg(b)),
            ("hip_rotation_l", -deg(c)),
            ("knee_angle_r", knee * deg(-1.0)),
            ("knee_angle_l", knee * deg(-0.2)),
            ("ankle_angle_r", deg(0.15)),
            ("ankle_angle_l", deg(-0.25)),
            ("subtalar_angle_r", deg(0.07)),
            ("subtalar_angle_l", -deg(0.07)),
            ("mtp_angle_r", deg(0.4)),
            ("mtp_angle_l", 0.0),
            ("lumbar_extension", deg(0.35)),
            ("lumbar_bending", 0.0),
            ("arm_flex_r", deg(0.6)),
            ("arm_flex_l", deg(-0.3)),
            ("arm_add_l", -deg(0.2)),
            ("elbow_flex_r", deg(1.1)),
        ] {
            assert!(
                (get(n) - want).abs() < 1e-9,
                "{model:?} {n}: {} vs {want}",
                get(n)
            );
        }
        if model == OpenSimModel::Rajagopal2015 {
            assert_eq!(get("knee_angle_r_beta"), get("knee_angle_r"));
        } else {
            assert!(!names.iter().any(|n| n.ends_with("_beta")));
        }
        // The pelvis origin of gait2392, scaled: R·(0.0707, 0.0661, 0)·h/1.8 from the root.
        let pose = m.pose(0);
        let want = pose.root
            + pose.rotations[Joint::Pelvis.index()] * DVec3::new(0.0707, 0.0661, 0.0) * (H / 1.8);
        let got = DVec3::new(get("pelvis_tx"), get("pelvis_ty"), get("pelvis_tz"));
        assert!((got - want).length() < 1e-12, "{got} vs {want}");
    }
}

#[test]
fn the_command_line_writes_mot_and_sto() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    for (out, model, sign) in [("w.mot", "gait2392", -1.0), ("w.sto", "rajagopal", 1.0)] {
        Command::cargo_bin("gaitfit")
            .unwrap()
            .current_dir(d)
            .args([
                "generate",
                "generalize",
                "--step-length",
                "0.7",
                "--count",
                "2",
            ])
            .args(["--opensim-model", model, "-o", out])
            .assert()
            .success();
        let t = read_table(&d.join(out)).unwrap();
        // A walk flexes its knees (up to 60° in swing): the sign says which model.
        let knee = t.column("knee_angle_r").unwrap();
        let most = knee
            .iter()
            .copied()
            .max_by(|a, b| a.abs().total_cmp(&b.abs()))
            .unwrap();
        assert!(sign * most > 0.5, "{model}: {most} rad");
    }
    let out = Command::cargo_bin("gaitfit")
        .unwrap()
        .current_dir(d)
        .args([
            "generate",
            "walk",
            "--opensim-model",
            "gait2354x",
            "-o",
            "x.mot",
        ])
        .output()
        .unwrap();
    assert!(!out.status.success());
}

/// Files OpenSim wrote (Schreiber 2019's and BMC lab's inverse kinematics, Rajagopal's model):
/// the same header, every coordinate gaitfit writes among their columns, in their order, and
/// the same 16-wide cells.
#[test]
#[ignore = "needs ../shared/data"]
fn the_layout_and_names_match_files_opensim_wrote() {
    let ours = coordinate_names(OpenSimModel::Rajagopal2015);
    for rel in [
        "schreiber2019/2014019/ik/C5_03/C5_03_ik.mot",
        "bmclab/ik_output_run.mot",
    ] {
        let path = gaitfit::shared_data::path(rel).unwrap();
        let text = std::fs::read_to_string(&path).unwrap();
        let (header, labels, rows) = parse(&text);
        let want = opensim_ik_header(rows.len(), labels.len());
        // Lines 1–5 and the blank line before endheader as ours; the free text may differ
        // ("Angles are in degrees." in BMC lab's).
        assert_eq!(header[..6], want[..6], "{rel}");
        assert_eq!(
            header.last().copied(),
            want.last().map(String::as_str),
            "{rel}"
        );
        assert_eq!(labels[0], "time");
        let mut at = 0;
        for n in &ours {
            let k = labels
                .iter()
                .position(|l| l == n)
                .unwrap_or_else(|| panic!("{rel}: OpenSim wrote no column {n}"));
            assert!(k > at, "{rel}: {n} out of OpenSim's order");
            at = k;
        }
    }
}
