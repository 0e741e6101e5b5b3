//! Round trips of the motion exports: BVH (re-read and re-run through an independent BVH forward
//! kinematics), TRC (re-read with a small parser), CSV and events CSV; and the dispatcher.
use gaitfit::events::{EventKind, EventSource, GaitEvent, Side};
use gaitfit::export::bvh::{self, BvhOptions, BvhUnit};
use gaitfit::export::motion::{write, MotionFormat};
use gaitfit::export::motion_csv;
use gaitfit::export::trc::{self, TrcOptions, TrcUnit};
use gaitfit::generator::motion::{Motion, MotionMetadata};
use gaitfit::generator::skeleton::{Euler, Joint, Landmark, Skeleton};
use glam::DVec3;

/// A synthetic 3-D motion exercising every joint on three axes; with `spin` the pelvis turns
/// through ±180° so the Euler angles wrap.
fn synthetic(frames: usize, spin: bool) -> Motion {
    let sk = Skeleton::from_height(1.78, 72.0).unwrap();
    let mut m = Motion::new(sk.clone(), 120.0, MotionMetadata::new("synthetic", None)).unwrap();
    for i in 0..frames {
        let t = i as f64 / 120.0;
        let ph = 2.0 * std::f64::consts::PI * t;
        let mut p = sk.rest_pose();
        p.root = DVec3::new(
            1.3 * t,
            sk.hip_height() - 0.02 + 0.02 * ph.cos(),
            0.01 * ph.sin(),
        );
        let yaw = if spin { 2.0 * ph } else { 0.1 * ph.sin() };
        p.set_euler(
            Joint::Pelvis,
            Euler::new(0.05 * ph.cos(), 0.04 * ph.sin(), yaw),
        );
        for (k, j) in Joint::ALL.iter().enumerate().skip(1) {
            let a = 0.3 * (ph + k as f64).sin();
            p.set_euler(*j, Euler::new(a, 0.3 * a, -0.5 * a));
        }
        m.push_frame(p, [ph.sin() > 0.0, ph.sin() <= 0.1]);
    }
    m.events.push(GaitEvent {
        time_s: 0.25,
        side: Side::Right,
        kind: EventKind::ToeOff,
        source: EventSource::Generated,
    });
    m.events.push(GaitEvent {
        time_s: 0.05,
        side: Side::Left,
        kind: EventKind::HeelStrike,
        source: EventSource::Generated,
    });
    m
}

/// Joint/end-site name in the BVH for each landmark that is a joint centre or an end site.
fn bvh_name(l: Landmark) -> Option<String> {
    Some(match l {
        Landmark::LHeel | Landmark::RHeel | Landmark::LBall | Landmark::RBall => return None,
        Landmark::Vertex => "head_end".into(),
        Landmark::LHand => "l_wrist_end".into(),
        Landmark::RHand => "r_wrist_end".into(),
        Landmark::LToe => "l_metatarsal_end".into(),
        Landmark::RToe => "r_metatarsal_end".into(),
        other => other.name().into(),
    })
}

#[test]
fn bvh_round_trip_reproduces_every_joint_and_landmark() {
    let dir = tempfile::tempdir().unwrap();
    for spin in [false, true] {
        let m = synthetic(150, spin);
        for unit in [BvhUnit::Metres, BvhUnit::Centimetres] {
            let path = dir.path().join(format!("m_{spin}_{unit:?}.bvh"));
            bvh::write(&m, &path, &BvhOptions { unit }).unwrap();
            let b = bvh::read(&path).unwrap();
            assert_eq!(b.frames.len(), m.len());
            assert!((b.frame_time_s - 1.0 / 120.0).abs() < 1e-8);
            // 22 joints + 5 end sites.
            assert_eq!(b.joints.len(), 27);
            let s = unit.scale();
            let mut worst = 0.0f64;
            for i in 0..m.len() {
                let pos = b.positions(i);
                let g = m.skeleton().forward(m.pose(i));
                for j in Joint::ALL {
                    let k = b.index(j.name()).unwrap();
                    worst = worst.max((pos[k] / s - g.position(j)).length());
                }
                for l in Landmark::ALL {
                    if let Some(name) = bvh_name(l) {
                        let k = b.index(&name).unwrap();
                        worst = worst.max((pos[k] / s - m.landmark(i, l)).length());
                    }
                }
            }
            assert!(worst < 1e-6, "worst BVH round-trip error {worst} m");
        }
    }
}

#[test]
fn bvh_text_follows_the_common_conventions() {
    let m = synthetic(3, false);
    let text = bvh::to_string(&m, &BvhOptions::default());
    assert!(text.starts_with("HIERARCHY\nROOT pelvis\n{\n\tOFFSET 0.000000 0.000000 0.000000\n"));
    assert!(
        text.contains("\tCHANNELS 6 Xposition Yposition Zposition Zrotation Xrotation Yrotation\n")
    );
    assert!(text.contains("\t\tJOINT thoracic_lower\n\t\t{\n"));
    assert!(text.contains("End Site\n"));
    assert!(text.contains("MOTION\nFrames: 3\nFrame Time: 0.00833333\n"));
    let opens = text.matches('{').count();
    let closes = text.matches('}').count();
    assert_eq!(opens, closes);
    assert_eq!(opens, 27);
    // Each frame line has 6 + 21·3 values.
    let last = text.lines().last().unwrap();
    assert_eq!(last.split_whitespace().count(), 6 + 21 * 3);
}

#[test]
fn bvh_reader_rejects_broken_files() {
    let p = std::path::Path::new("broken.bvh");
    let e = bvh::parse("HIERARCHY\nROOT a\n{\nOFFSET 0 0\n}\n", p).unwrap_err();
    assert!(e.to_string().contains("line 4"), "{e}");
    let e = bvh::parse(
        "HIERARCHY\nROOT a\n{\nOFFSET 0 0 0\nCHANNELS 1 Xposition\n}\nMOTION\nFrames: 2\nFrame Time: 0.1\n1\n",
        p,
    )
    .unwrap_err();
    assert!(e.to_string().contains("Frames: 2"), "{e}");
}

/// A minimal TRC reader: (units, rate, marker names, frames of [x, y, z] per marker).
fn read_trc(path: &std::path::Path) -> (String, f64, Vec<String>, Vec<Vec<[f64; 3]>>) {
    let text = std::fs::read_to_string(path).unwrap();
    let lines: Vec<&str> = text.lines().collect();
    assert!(lines[0].starts_with("PathFileType\t4\t(X/Y/Z)\t"));
    let keys: Vec<&str> = lines[1].split('\t').collect();
    let vals: Vec<&str> = lines[2].split('\t').collect();
    assert_eq!(keys.len(), 8);
    assert_eq!(vals.len(), 8);
    let get = |k: &str| vals[keys.iter().position(|x| *x == k).unwrap()];
    let n_frames: usize = get("NumFrames").parse().unwrap();
    let n_markers: usize = get("NumMarkers").parse().unwrap();
    let names: Vec<String> = lines[3]
        .split('\t')
        .skip(2)
        .filter(|s| !s.is_empty())
        .map(String::from)
        .collect();
    assert_eq!(names.len(), n_markers);
    let xyz: Vec<&str> = lines[4].split('\t').skip(2).collect();
    assert_eq!(xyz.len(), 3 * n_markers);
    assert_eq!(xyz[0], "X1");
    assert!(lines[5].is_empty());
    let mut frames = Vec::new();
    for (k, line) in lines[6..].iter().enumerate() {
        let v: Vec<f64> = line.split('\t').map(|s| s.parse().unwrap()).collect();
        assert_eq!(v[0] as usize, k + 1);
        frames.push(
            (0..n_markers)
                .map(|m| [v[2 + 3 * m], v[3 + 3 * m], v[4 + 3 * m]])
                .collect(),
        );
    }
    assert_eq!(frames.len(), n_frames);
    (
        get("Units").to_string(),
        get("DataRate").parse().unwrap(),
        names,
        frames,
    )
}

#[test]
fn trc_round_trip() {
    let dir = tempfile::tempdir().unwrap();
    let m = synthetic(60, false);
    for unit in [TrcUnit::Millimetres, TrcUnit::Metres] {
        let path = dir.path().join(format!("m_{unit:?}.trc"));
        trc::write(&m, &path, &TrcOptions { unit }).unwrap();
        let (units, rate, names, frames) = read_trc(&path);
        assert_eq!(units, unit.as_str());
        assert!((rate - 120.0).abs() < 1e-9);
        let s = unit.scale();
        for (k, name) in names.iter().enumerate() {
            let l = Landmark::from_name(name).unwrap();
            for (i, f) in frames.iter().enumerate() {
                let p = DVec3::from_array(f[k]) / s;
                assert!((p - m.landmark(i, l)).length() < 1e-6);
            }
        }
        // gaitfit's own TRC reader gets the same markers, in metres.
        let (ms, header, _) = gaitfit::ingest::trc::read_markers(&path).unwrap();
        assert_eq!(header.num_frames, m.len());
        assert_eq!(ms.names.len(), Landmark::ALL.len());
        assert!((ms.rate_hz - 120.0).abs() < 1e-9);
        for l in Landmark::ALL {
            let traj = ms.get(l.name()).unwrap();
            for (i, p) in traj.iter().enumerate() {
                assert!((DVec3::from_array(*p) - m.landmark(i, l)).length() < 1e-6);
            }
        }
    }
}

#[test]
fn csv_and_events_round_trip_through_the_dispatcher() {
    let dir = tempfile::tempdir().unwrap();
    let m = synthetic(50, true);
    let path = dir.path().join("walk.csv");
    write(&m, &path).unwrap();
    let mut r = csv::Reader::from_path(&path).unwrap();
    let header: Vec<String> = r.headers().unwrap().iter().map(String::from).collect();
    assert_eq!(header, motion_csv::header());
    for required in [
        "time_s",
        "pelvis_x_m",
        "l_hip_y_m",
        "r_knee_z_m",
        "l_ankle_x_m",
        "r_heel_y_m",
        "l_ball_x_m",
        "r_toe_z_m",
        "vertex_y_m",
        "l_wrist_x_m",
        "l_contact",
        "r_contact",
        "r_knee_z_deg",
        "pelvis_y_deg",
    ] {
        assert!(header.iter().any(|h| h == required), "missing {required}");
    }
    let col = |name: &str| header.iter().position(|h| h == name).unwrap();
    let angles = m.joint_angle_series_deg();
    let mut n = 0;
    for (i, rec) in r.records().enumerate() {
        let rec = rec.unwrap();
        let v = |c: &str| rec[col(c)].parse::<f64>().unwrap();
        assert!((v("time_s") - m.frame_time(i)).abs() < 1e-6);
        for l in Landmark::ALL {
            let p = DVec3::new(
                v(&format!("{}_x_m", l.name())),
                v(&format!("{}_y_m", l.name())),
                v(&format!("{}_z_m", l.name())),
            );
            assert!((p - m.landmark(i, l)).length() < 1e-6);
        }
        assert_eq!(v("l_contact") == 1.0, m.contacts()[i][0]);
        assert_eq!(v("r_contact") == 1.0, m.contacts()[i][1]);
        for j in Joint::ALL {
            for (a, ax) in ["z", "x", "y"].iter().enumerate() {
                let got = v(&format!("{}_{ax}_deg", j.name()));
                assert!((got - angles[i][j.index()][a]).abs() < 1e-4);
            }
        }
        n += 1;
    }
    assert_eq!(n, m.len());
    let ev = std::fs::read_to_string(dir.path().join("walk_events.csv")).unwrap();
    assert_eq!(
        ev,
        "time_s,side,event\n0.050000,left,heel_strike\n0.250000,right,toe_off\n"
    );
}

#[test]
fn dispatcher_writes_each_format_and_rejects_unknown_extensions() {
    let dir = tempfile::tempdir().unwrap();
    let m = synthetic(5, false);
    for ext in ["bvh", "BVH", "trc", "csv"] {
        let p = dir.path().join(format!("x.{ext}"));
        write(&m, &p).unwrap();
        assert!(p.exists());
    }
    let p = dir.path().join("x.fbx");
    let e = write(&m, &p).unwrap_err().to_string();
    assert!(e.contains("x.fbx") && e.contains(".bvh"), "{e}");
    assert!(!p.exists());
    assert!(MotionFormat::from_path(std::path::Path::new("noext")).is_err());
}
