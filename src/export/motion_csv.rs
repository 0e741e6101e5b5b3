//! Motion as CSV: one row per frame, and the gait events as a second CSV.
//!
//! Columns: `time_s`; for every landmark (in [`Landmark::ALL`] order: `pelvis`, `l_hip`, `r_hip`,
//! `l_knee`, `r_knee`, `l_ankle`, `r_ankle`, `l_heel`, `r_heel`, `l_ball`, `r_ball`, `l_toe`,
//! `r_toe`, `head`, `neck`, `l_shoulder`, …, `l_hand`, `r_hand`) `<landmark>_x_m`,
//! `<landmark>_y_m`, `<landmark>_z_m` (x forward, y up, z right, metres, 1 µm resolution);
//! `l_contact`, `r_contact` (0/1); then for every joint (in [`Joint::ALL`] order)
//! `<joint>_z_deg`, `<joint>_x_deg`, `<joint>_y_deg`: the Z–X–Y Euler angles of
//! [`crate::generator::skeleton`], degrees, unwrapped across frames (the pelvis's are its world
//! orientation).
//!
//! Events: `time_s,side,event` with side `left`/`right` and event `heel_strike`, `foot_flat`,
//! `heel_off`, `meta_off` or `toe_off`.
use super::ExportError;
use crate::fsio::{write_atomic, FsError};
use crate::generator::motion::Motion;
use crate::generator::skeleton::{Joint, Landmark};
use std::path::Path;

/// The header row of the motion CSV.
pub fn header() -> Vec<String> {
    let mut h = vec!["time_s".to_string()];
    for l in Landmark::ALL {
        for ax in ["x", "y", "z"] {
            h.push(format!("{}_{ax}_m", l.name()));
        }
    }
    h.push("l_contact".into());
    h.push("r_contact".into());
    for j in Joint::ALL {
        for ax in ["z", "x", "y"] {
            h.push(format!("{}_{ax}_deg", j.name()));
        }
    }
    h
}

/// Writes the motion CSV to `path` (atomically).
pub fn write(motion: &Motion, path: &Path) -> Result<(), ExportError> {
    let angles = motion.joint_angle_series_deg();
    write_atomic(path, |w| {
        let io = |e| ExportError::from(FsError::io(path, e));
        writeln!(w, "{}", header().join(",")).map_err(io)?;
        let mut line = String::with_capacity(4096);
        for (i, ang) in angles.iter().enumerate() {
            use std::fmt::Write as _;
            line.clear();
            let _ = write!(line, "{:.6}", motion.frame_time(i));
            for p in motion.landmarks(i) {
                let _ = write!(line, ",{:.6},{:.6},{:.6}", p.x, p.y, p.z);
            }
            let c = motion.contacts()[i];
            let _ = write!(line, ",{},{}", u8::from(c[0]), u8::from(c[1]));
            for row in ang {
                let _ = write!(line, ",{:.4},{:.4},{:.4}", row[0], row[1], row[2]);
            }
            writeln!(w, "{line}").map_err(io)?;
        }
        Ok(())
    })
}

/// Writes the events CSV (`time_s,side,event`) to `path` (atomically), events in time order.
pub fn write_events(motion: &Motion, path: &Path) -> Result<(), ExportError> {
    let mut events = motion.events.clone();
    events.sort_by(|a, b| a.time_s.total_cmp(&b.time_s));
    write_atomic(path, |w| {
        let io = |e| ExportError::from(FsError::io(path, e));
        writeln!(w, "time_s,side,event").map_err(io)?;
        for e in &events {
            writeln!(w, "{:.6},{},{}", e.time_s, e.side, e.kind.as_str()).map_err(io)?;
        }
        Ok(())
    })
}

/// Path of the events CSV written next to a motion CSV: `<stem>_events.csv`.
pub fn events_path(csv_path: &Path) -> std::path::PathBuf {
    let stem = csv_path
        .file_stem()
        .map(|s| s.to_string_lossy().into_owned())
        .unwrap_or_else(|| "motion".into());
    csv_path.with_file_name(format!("{stem}_events.csv"))
}
