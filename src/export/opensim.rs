//! OpenSim motion files (`.mot`, `.sto`): a [`Motion`]'s joint angles as the coordinates of
//! OpenSim's gait models, in degrees (`inDegrees=yes`), in the layout OpenSim's inverse
//! kinematics writes (the shared data's `*_ik.mot`, written by OpenSim, have the same header,
//! column names and number format):
//!
//! ```text
//! Coordinates
//! version=1
//! nRows=<frames>
//! nColumns=<columns, time included>
//! inDegrees=yes
//!
//! Units are S.I. units (second, meters, Newtons, ...)
//! If the header above contains a line with 'inDegrees', this indicates whether rotational values are in degrees (yes) or radians (no).
//!
//! endheader
//! time<TAB>pelvis_tilt<TAB>pelvis_list<TAB>…           (tab-separated)
//!       0.00000000<TAB>     -3.21000000<TAB>…     (16 characters a cell, 8 decimals)
//! ```
//!
//! # Coordinates and conventions
//! OpenSim's frame is gaitfit's (x forward, y up, z right), and the gait models' joints rotate
//! about the same axes in the same order as gaitfit's Z–X–Y Euler angles
//! ([`crate::generator::skeleton`]): flexion/extension about z, then ab/adduction about x, then
//! axial rotation about y. OpenSim mirrors the x and y axes of the left side (so that positive
//! adduction and internal rotation mean the same on both sides); gaitfit uses one right-hand
//! rule for both, so those left-side angles change sign.
//!
//! | OpenSim coordinate | gaitfit | sign |
//! |---|---|---|
//! | `pelvis_tilt`, `pelvis_list`, `pelvis_rotation` | `pelvis` z, x, y (world) | same (tilt: front up positive) |
//! | `pelvis_tx`, `pelvis_ty`, `pelvis_tz` | the model's pelvis origin: `pelvis` + R·(0.0707, 0.0661, 0)·h/1.8 m | metres |
//! | `hip_flexion_r`, `hip_adduction_r`, `hip_rotation_r` | `r_hip` z, x, y | same |
//! | `hip_flexion_l`, `hip_adduction_l`, `hip_rotation_l` | `l_hip` z, −x, −y | left x, y negated |
//! | `knee_angle_r`, `_l` | knee z (flexion negative) | gait2392: same (flexion negative); Rajagopal 2015: negated (flexion positive), and `knee_angle_*_beta` = `knee_angle_*` |
//! | `ankle_angle_r`, `_l` | ankle z (dorsiflexion positive) | same |
//! | `subtalar_angle_r`, `_l` | ankle x | right same, left negated (inversion positive) |
//! | `mtp_angle_r`, `_l` | metatarsal z (toe extension positive) | same |
//! | `lumbar_extension`, `lumbar_bending`, `lumbar_rotation` | z, x, y of `lumbar`·`thoracic_lower`·`thoracic_upper` (the chest relative to the pelvis) | same |
//! | `arm_flex_r`, `arm_add_r`, `arm_rot_r` | z, x, y of `r_clavicle`·`r_shoulder` (the upper arm relative to the chest) | same |
//! | `arm_flex_l`, `arm_add_l`, `arm_rot_l` | the same of the left side, x and y negated | left x, y negated |
//! | `elbow_flex_r`, `_l` | elbow z (flexion positive) | same |
//!
//! What does not correspond: gait2392's ankle, subtalar and mtp axes are oblique (a few degrees
//! to 35° from gaitfit's axes), so those angles are the same rotation about gaitfit's axes, not
//! OpenSim's; gaitfit's ankle axial rotation, neck and head (OpenSim's torso carries the head)
//! and the forearm and wrist (`pro_sup`, `wrist_flex`, `wrist_dev`) are not written. gait2392 has
//! no arms: OpenSim leaves the arm columns unused there (Hamner 2010 and Rajagopal 2015 use
//! them). The pelvis translation places gait2392's pelvis origin (its hip joint centres sit at
//! (−0.0707, −0.0661, ±0.0835) m in the pelvis frame, `gait2392_simbody.osim`), scaled by body
//! height over the model's 1.8 m; Rajagopal 2015's pelvis origin lies within about 2 cm of it.
//!
//! Every angle is unwrapped across frames (successive frames never differ by more than 180°).
use super::ExportError;
use crate::fsio::{write_atomic, FsError};
use crate::generator::motion::Motion;
use crate::generator::skeleton::{Euler, Joint};
use glam::{DQuat, DVec3};
use std::fmt::Write as _;
use std::path::Path;

/// Which OpenSim model's conventions the coordinates follow (they differ only in the knee's
/// sign).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum OpenSimModel {
    /// gait2392 / gait2354 / Hamner 2010: `knee_angle` negative in flexion (range −120°…10°).
    #[default]
    Gait2392,
    /// Rajagopal et al. 2015: `knee_angle` positive in flexion (range 0…120°), plus
    /// `knee_angle_*_beta` (the patella's coupled coordinate, equal to `knee_angle_*`).
    Rajagopal2015,
}

impl OpenSimModel {
    /// The name used on the command line (`gait2392`, `rajagopal`).
    pub fn as_str(self) -> &'static str {
        match self {
            OpenSimModel::Gait2392 => "gait2392",
            OpenSimModel::Rajagopal2015 => "rajagopal",
        }
    }
}

/// Options of the OpenSim motion writer.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct MotOptions {
    /// Coordinate conventions.
    pub model: OpenSimModel,
}

/// Hip joint centre (right) in gait2392's pelvis frame, m: the pelvis origin lies at minus its
/// x and y from the hip-centre midpoint (`gait2392_simbody.osim`, joint `hip_r`).
const GAIT2392_HIP_IN_PELVIS: DVec3 = DVec3::new(-0.0707, -0.0661, 0.0835);
/// Body height of the unscaled gait2392 model, m (its 1.8 m, 75 kg subject).
const GAIT2392_HEIGHT_M: f64 = 1.8;

/// The coordinate names written, in column order after `time`.
pub fn coordinate_names(model: OpenSimModel) -> Vec<&'static str> {
    let mut v = vec![
        "pelvis_tilt",
        "pelvis_list",
        "pelvis_rotation",
        "pelvis_tx",
        "pelvis_ty",
        "pelvis_tz",
    ];
    for s in ["r", "l"] {
        let side: [&'static str; 8] = if s == "r" {
            [
                "hip_flexion_r",
                "hip_adduction_r",
                "hip_rotation_r",
                "knee_angle_r",
                "knee_angle_r_beta",
                "ankle_angle_r",
                "subtalar_angle_r",
                "mtp_angle_r",
            ]
        } else {
            [
                "hip_flexion_l",
                "hip_adduction_l",
                "hip_rotation_l",
                "knee_angle_l",
                "knee_angle_l_beta",
                "ankle_angle_l",
                "subtalar_angle_l",
                "mtp_angle_l",
            ]
        };
        v.extend(
            side.into_iter()
                .filter(|n| model == OpenSimModel::Rajagopal2015 || !n.ends_with("_beta")),
        );
    }
    v.extend(["lumbar_extension", "lumbar_bending", "lumbar_rotation"]);
    v.extend([
        "arm_flex_r",
        "arm_add_r",
        "arm_rot_r",
        "elbow_flex_r",
        "arm_flex_l",
        "arm_add_l",
        "arm_rot_l",
        "elbow_flex_l",
    ]);
    v
}

/// Whether a coordinate is a translation (metres) rather than an angle (degrees).
pub fn is_translation(name: &str) -> bool {
    matches!(name, "pelvis_tx" | "pelvis_ty" | "pelvis_tz")
}

fn zxy_deg(q: DQuat) -> [f64; 3] {
    Euler::from_quat(q).to_degrees()
}

/// The coordinates of frame `i` in [`coordinate_names`] order (degrees, metres), not unwrapped.
pub fn frame_coordinates(motion: &Motion, i: usize, model: OpenSimModel) -> Vec<f64> {
    let pose = motion.pose(i);
    let q = |j: Joint| pose.rotations[j.index()];
    let knee_sign = match model {
        OpenSimModel::Gait2392 => 1.0,
        OpenSimModel::Rajagopal2015 => -1.0,
    };
    let scale = motion.skeleton().anthropometry().height_m / GAIT2392_HEIGHT_M;
    let pelvis = zxy_deg(q(Joint::Pelvis));
    let origin = pose.root
        + q(Joint::Pelvis)
            * DVec3::new(-GAIT2392_HIP_IN_PELVIS.x, -GAIT2392_HIP_IN_PELVIS.y, 0.0)
            * scale;
    let mut v = vec![
        pelvis[0], pelvis[1], pelvis[2], origin.x, origin.y, origin.z,
    ];
    for (hip, knee, ankle, mtp, mirror) in [
        (
            Joint::RHip,
            Joint::RKnee,
            Joint::RAnkle,
            Joint::RMetatarsal,
            1.0,
        ),
        (
            Joint::LHip,
            Joint::LKnee,
            Joint::LAnkle,
            Joint::LMetatarsal,
            -1.0,
        ),
    ] {
        let h = zxy_deg(q(hip));
        let k = knee_sign * zxy_deg(q(knee))[0];
        let a = zxy_deg(q(ankle));
        v.extend([h[0], mirror * h[1], mirror * h[2], k]);
        if model == OpenSimModel::Rajagopal2015 {
            v.push(k);
        }
        v.extend([a[0], mirror * a[1], zxy_deg(q(mtp))[0]]);
    }
    let chest = q(Joint::Lumbar) * q(Joint::ThoracicLower) * q(Joint::ThoracicUpper);
    v.extend(zxy_deg(chest));
    for (clavicle, shoulder, elbow, mirror) in [
        (Joint::RClavicle, Joint::RShoulder, Joint::RElbow, 1.0),
        (Joint::LClavicle, Joint::LShoulder, Joint::LElbow, -1.0),
    ] {
        let arm = zxy_deg(q(clavicle) * q(shoulder));
        v.extend([
            arm[0],
            mirror * arm[1],
            mirror * arm[2],
            zxy_deg(q(elbow))[0],
        ]);
    }
    v
}

/// Every frame's coordinates, angles unwrapped across frames.
pub fn coordinates(motion: &Motion, model: OpenSimModel) -> Vec<Vec<f64>> {
    let names = coordinate_names(model);
    let mut out: Vec<Vec<f64>> = Vec::with_capacity(motion.len());
    for i in 0..motion.len() {
        let mut row = frame_coordinates(motion, i, model);
        if let Some(prev) = out.last() {
            for ((v, p), n) in row.iter_mut().zip(prev).zip(&names) {
                if !is_translation(n) {
                    *v += 360.0 * ((p - *v) / 360.0).round();
                }
            }
        }
        out.push(row);
    }
    out
}

/// The file's text (see the module docs).
pub fn to_string(motion: &Motion, options: &MotOptions) -> String {
    let names = coordinate_names(options.model);
    let rows = coordinates(motion, options.model);
    let mut s = String::with_capacity(64 + rows.len() * (names.len() + 1) * 17);
    let _ = write!(
        s,
        "Coordinates\nversion=1\nnRows={}\nnColumns={}\ninDegrees=yes\n\n\
         Units are S.I. units (second, meters, Newtons, ...)\n\
         If the header above contains a line with 'inDegrees', this indicates whether rotational \
         values are in degrees (yes) or radians (no).\n\nendheader\ntime",
        rows.len(),
        names.len() + 1
    );
    for n in &names {
        s.push('\t');
        s.push_str(n);
    }
    s.push('\n');
    for (i, row) in rows.iter().enumerate() {
        let _ = write!(s, "{:16.8}", motion.frame_time(i));
        for v in row {
            // + 0.0: no "-0.00000000".
            let _ = write!(s, "\t{:16.8}", v + 0.0);
        }
        s.push('\n');
    }
    s
}

/// Writes the motion's coordinates to `path` (`.mot` or `.sto`, the same content), atomically.
pub fn write(motion: &Motion, path: &Path, options: &MotOptions) -> Result<(), ExportError> {
    if motion.is_empty() {
        return Err(ExportError::Format {
            path: path.display().to_string(),
            message: "the motion has no frames; an OpenSim motion file needs at least one".into(),
        });
    }
    let text = to_string(motion, options);
    write_atomic(path, |w| {
        w.write_all(text.as_bytes())
            .map_err(|e| ExportError::from(FsError::io(path, e)))
    })
}
