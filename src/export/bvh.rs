//! Biovision hierarchy (BVH) files: a writer for [`Motion`] and a small reader (used to prove the
//! round trip and to inspect files).
//!
//! What gaitfit writes, following the conventions Blender's importer and other BVH tools expect:
//! - `HIERARCHY` with the figure's joints ([`Joint::ALL`] is the depth-first order), tab
//!   indentation, `OFFSET`s from the skeleton (rest pose: every joint frame parallel to the world),
//!   `End Site` blocks for the vertex (under `head`), the hand ends (under the wrists) and the toe
//!   tips (under the metatarsal joints);
//! - the root `pelvis` has `OFFSET 0 0 0` and `CHANNELS 6 Xposition Yposition Zposition Zrotation
//!   Xrotation Yrotation` (its position channels are its world position, whichever way a reader
//!   combines them with the offset); every other joint has `CHANNELS 3 Zrotation Xrotation
//!   Yrotation`;
//! - rotation values are the Z–X–Y Euler angles of [`crate::generator::skeleton`] in degrees:
//!   the channel order is the composition order, `R = Rz·Rx·Ry`, as the BVH format defines it;
//!   angles are unwrapped across frames so interpolating tools do not spin;
//! - Y up, x forward, z right (right-handed), lengths in metres by default (Blender's default
//!   import scale 1.0 then gives a figure of the right size) or centimetres
//!   ([`BvhUnit::Centimetres`], common in MotionBuilder pipelines);
//! - `MOTION`, `Frames: N`, `Frame Time: 1/fps`, one line per frame.
use super::ExportError;
use crate::fsio::{write_atomic, FsError};
use crate::generator::motion::Motion;
use crate::generator::skeleton::{Joint, JOINT_COUNT};
use crate::ingest::IngestError;
use glam::{DQuat, DVec3};
use std::fmt::Write as _;
use std::path::{Path, PathBuf};

/// Length unit of a BVH file.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum BvhUnit {
    /// Metres (default).
    #[default]
    Metres,
    /// Centimetres.
    Centimetres,
}

impl BvhUnit {
    /// Metres → this unit.
    pub fn scale(self) -> f64 {
        match self {
            BvhUnit::Metres => 1.0,
            BvhUnit::Centimetres => 100.0,
        }
    }
}

/// Options of the BVH writer.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct BvhOptions {
    /// Length unit of offsets and root positions.
    pub unit: BvhUnit,
}

/// Writes `motion` as BVH to `path` (atomically).
pub fn write(motion: &Motion, path: &Path, options: &BvhOptions) -> Result<(), ExportError> {
    if motion.is_empty() {
        return Err(ExportError::Format {
            path: path.display().to_string(),
            message: "the motion has no frames; a BVH file needs at least one".into(),
        });
    }
    let text = to_string(motion, options);
    write_atomic(path, |w| {
        w.write_all(text.as_bytes())
            .map_err(|e| ExportError::from(FsError::io(path, e)))
    })
}

/// The BVH text of `motion`.
pub fn to_string(motion: &Motion, options: &BvhOptions) -> String {
    let s = options.unit.scale();
    let sk = motion.skeleton();
    let mut out = String::with_capacity(4096 + motion.len() * JOINT_COUNT * 40);
    out.push_str("HIERARCHY\n");
    // Depth-first emission: Joint::ALL is depth-first; close blocks when the next joint is not a
    // descendant of the open ones.
    let mut stack: Vec<Joint> = Vec::new();
    for j in Joint::ALL {
        while let Some(&top) = stack.last() {
            if Some(top) == j.parent() {
                break;
            }
            close_joint(&mut out, sk.end_site(top).map(|e| e * s), stack.len());
            stack.pop();
        }
        let depth = stack.len();
        let tabs = "\t".repeat(depth);
        let o = sk.offset(j) * s;
        if j == Joint::Pelvis {
            let _ = writeln!(out, "ROOT {}\n{{", j.name());
            let _ = writeln!(out, "\tOFFSET 0.000000 0.000000 0.000000");
            let _ = writeln!(
                out,
                "\tCHANNELS 6 Xposition Yposition Zposition Zrotation Xrotation Yrotation"
            );
        } else {
            let _ = writeln!(out, "{tabs}JOINT {}\n{tabs}{{", j.name());
            let _ = writeln!(out, "{tabs}\tOFFSET {} {} {}", num(o.x), num(o.y), num(o.z));
            let _ = writeln!(out, "{tabs}\tCHANNELS 3 Zrotation Xrotation Yrotation");
        }
        stack.push(j);
    }
    while let Some(top) = stack.pop() {
        close_joint(&mut out, sk.end_site(top).map(|e| e * s), stack.len() + 1);
    }
    let _ = writeln!(
        out,
        "MOTION\nFrames: {}\nFrame Time: {:.8}",
        motion.len(),
        1.0 / motion.fps()
    );
    for (i, angles) in motion.joint_angle_series_deg().iter().enumerate() {
        let r = motion.pose(i).root * s;
        let _ = write!(out, "{} {} {}", num(r.x), num(r.y), num(r.z));
        for a in angles {
            let _ = write!(out, " {:.6} {:.6} {:.6}", a[0], a[1], a[2]);
        }
        out.push('\n');
    }
    out
}

/// Fixed-point with 8 decimals (1e-8 m, or 1e-10 m in centimetres), no negative zero.
fn num(v: f64) -> String {
    let t = format!("{v:.8}");
    if t.trim_start_matches('-')
        .bytes()
        .all(|b| b == b'0' || b == b'.')
    {
        "0.00000000".into()
    } else {
        t
    }
}

/// Closes the joint block opened at depth `depth − 1`, writing its end site first.
fn close_joint(out: &mut String, end: Option<DVec3>, depth: usize) {
    let tabs = "\t".repeat(depth - 1);
    if let Some(e) = end {
        let _ = writeln!(
            out,
            "{tabs}\tEnd Site\n{tabs}\t{{\n{tabs}\t\tOFFSET {} {} {}\n{tabs}\t}}",
            num(e.x),
            num(e.y),
            num(e.z)
        );
    }
    let _ = writeln!(out, "{tabs}}}");
}

/// One channel of a BVH joint.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum BvhChannel {
    /// Translation along x.
    Xposition,
    /// Translation along y.
    Yposition,
    /// Translation along z.
    Zposition,
    /// Rotation about x, degrees.
    Xrotation,
    /// Rotation about y, degrees.
    Yrotation,
    /// Rotation about z, degrees.
    Zrotation,
}

/// A joint (or end site) read from a BVH hierarchy.
#[derive(Debug, Clone, PartialEq)]
pub struct BvhJoint {
    /// Name; end sites are named `<parent>_end`.
    pub name: String,
    /// Index of the parent in [`Bvh::joints`].
    pub parent: Option<usize>,
    /// Offset from the parent, file units.
    pub offset: DVec3,
    /// Channels in file order (empty for end sites).
    pub channels: Vec<BvhChannel>,
    /// True for `End Site` entries.
    pub end_site: bool,
    /// Index of this joint's first channel in a frame's values.
    pub first_channel: usize,
}

/// A parsed BVH file.
#[derive(Debug, Clone, PartialEq)]
pub struct Bvh {
    /// Joints and end sites in file order (parents before children).
    pub joints: Vec<BvhJoint>,
    /// Frame time, s.
    pub frame_time_s: f64,
    /// Channel values per frame, in hierarchy order.
    pub frames: Vec<Vec<f64>>,
}

impl Bvh {
    /// World positions of every joint and end site in frame `i` (file units), by the standard
    /// BVH forward kinematics: `local = translate(offset + position channels) · rotations in
    /// channel order`.
    pub fn positions(&self, i: usize) -> Vec<DVec3> {
        let values = &self.frames[i];
        let mut rot = vec![DQuat::IDENTITY; self.joints.len()];
        let mut pos = vec![DVec3::ZERO; self.joints.len()];
        for (k, j) in self.joints.iter().enumerate() {
            let mut t = j.offset;
            let mut r = DQuat::IDENTITY;
            for (c, ch) in j.channels.iter().enumerate() {
                let v = values[j.first_channel + c];
                match ch {
                    BvhChannel::Xposition => t.x += v,
                    BvhChannel::Yposition => t.y += v,
                    BvhChannel::Zposition => t.z += v,
                    BvhChannel::Xrotation => r *= DQuat::from_rotation_x(v.to_radians()),
                    BvhChannel::Yrotation => r *= DQuat::from_rotation_y(v.to_radians()),
                    BvhChannel::Zrotation => r *= DQuat::from_rotation_z(v.to_radians()),
                }
            }
            match j.parent {
                Some(p) => {
                    pos[k] = pos[p] + rot[p] * t;
                    rot[k] = rot[p] * r;
                }
                None => {
                    pos[k] = t;
                    rot[k] = r;
                }
            }
        }
        pos
    }

    /// Index of the joint (or end site) named `name`.
    pub fn index(&self, name: &str) -> Option<usize> {
        self.joints.iter().position(|j| j.name == name)
    }
}

/// Reads a BVH file.
pub fn read(path: &Path) -> Result<Bvh, IngestError> {
    let text = std::fs::read_to_string(path).map_err(|e| IngestError::io(path, e))?;
    parse(&text, path)
}

/// Parses BVH text; `path` is used in error messages.
pub fn parse(text: &str, path: &Path) -> Result<Bvh, IngestError> {
    let path: PathBuf = path.to_path_buf();
    let bad = |line: usize, m: String| IngestError::malformed(&path, format!("line {line}: {m}"));
    let mut lines = text.lines().enumerate().map(|(i, l)| (i + 1, l.trim()));
    let mut joints: Vec<BvhJoint> = Vec::new();
    let mut stack: Vec<usize> = Vec::new();
    let mut n_channels = 0usize;
    let mut pending: Option<(String, bool)> = None;
    let mut saw_hierarchy = false;
    let mut motion_line = None;
    for (ln, line) in lines.by_ref() {
        if line.is_empty() {
            continue;
        }
        let mut tok = line.split_whitespace();
        let head = tok.next().unwrap_or("");
        match head {
            "HIERARCHY" => saw_hierarchy = true,
            "ROOT" | "JOINT" => {
                let name = tok
                    .next()
                    .ok_or_else(|| bad(ln, format!("{head} without a name")))?;
                pending = Some((name.to_string(), false));
            }
            "End" => pending = Some((String::new(), true)),
            "{" => {
                let (name, end) = pending
                    .take()
                    .ok_or_else(|| bad(ln, "'{' without ROOT, JOINT or End Site".into()))?;
                let parent = stack.last().copied();
                let name = if end {
                    let p = parent.ok_or_else(|| bad(ln, "End Site outside a joint".into()))?;
                    format!("{}_end", joints[p].name)
                } else {
                    name
                };
                joints.push(BvhJoint {
                    name,
                    parent,
                    offset: DVec3::ZERO,
                    channels: Vec::new(),
                    end_site: end,
                    first_channel: n_channels,
                });
                stack.push(joints.len() - 1);
            }
            "}" => {
                stack
                    .pop()
                    .ok_or_else(|| bad(ln, "unbalanced '}'".into()))?;
            }
            "OFFSET" => {
                let &k = stack
                    .last()
                    .ok_or_else(|| bad(ln, "OFFSET outside a joint".into()))?;
                let v: Vec<f64> = tok
                    .map(|t| t.parse::<f64>())
                    .collect::<Result<_, _>>()
                    .map_err(|e| bad(ln, format!("OFFSET: {e}")))?;
                if v.len() != 3 {
                    return Err(bad(
                        ln,
                        format!("OFFSET needs 3 numbers, found {}", v.len()),
                    ));
                }
                joints[k].offset = DVec3::new(v[0], v[1], v[2]);
            }
            "CHANNELS" => {
                let &k = stack
                    .last()
                    .ok_or_else(|| bad(ln, "CHANNELS outside a joint".into()))?;
                let n: usize = tok
                    .next()
                    .and_then(|t| t.parse().ok())
                    .ok_or_else(|| bad(ln, "CHANNELS needs a count".into()))?;
                let mut chans = Vec::with_capacity(n);
                for t in tok {
                    chans.push(match t {
                        "Xposition" => BvhChannel::Xposition,
                        "Yposition" => BvhChannel::Yposition,
                        "Zposition" => BvhChannel::Zposition,
                        "Xrotation" => BvhChannel::Xrotation,
                        "Yrotation" => BvhChannel::Yrotation,
                        "Zrotation" => BvhChannel::Zrotation,
                        other => return Err(bad(ln, format!("unknown channel {other:?}"))),
                    });
                }
                if chans.len() != n {
                    return Err(bad(
                        ln,
                        format!("CHANNELS {n} lists {} channels", chans.len()),
                    ));
                }
                joints[k].first_channel = n_channels;
                n_channels += n;
                joints[k].channels = chans;
            }
            "MOTION" => {
                motion_line = Some(ln);
                break;
            }
            other => return Err(bad(ln, format!("unexpected {other:?} in HIERARCHY"))),
        }
    }
    if !saw_hierarchy || joints.is_empty() {
        return Err(IngestError::malformed(
            &path,
            "no HIERARCHY with a ROOT joint",
        ));
    }
    if !stack.is_empty() {
        return Err(IngestError::malformed(
            &path,
            "HIERARCHY ends with unclosed '{'",
        ));
    }
    let ml = motion_line.ok_or_else(|| IngestError::malformed(&path, "no MOTION section"))?;
    let mut frames_n = None;
    let mut frame_time = None;
    let mut frames = Vec::new();
    for (ln, line) in lines {
        if line.is_empty() {
            continue;
        }
        if let Some(rest) = line.strip_prefix("Frames:") {
            frames_n = Some(
                rest.trim()
                    .parse::<usize>()
                    .map_err(|e| bad(ln, format!("Frames: {e}")))?,
            );
        } else if let Some(rest) = line.strip_prefix("Frame Time:") {
            frame_time = Some(
                rest.trim()
                    .parse::<f64>()
                    .map_err(|e| bad(ln, format!("Frame Time: {e}")))?,
            );
        } else {
            let v: Vec<f64> = line
                .split_whitespace()
                .map(|t| t.parse::<f64>())
                .collect::<Result<_, _>>()
                .map_err(|e| bad(ln, format!("frame {}: {e}", frames.len() + 1)))?;
            if v.len() != n_channels {
                return Err(bad(
                    ln,
                    format!(
                        "frame {} has {} values, the hierarchy declares {n_channels} channels",
                        frames.len() + 1,
                        v.len()
                    ),
                ));
            }
            frames.push(v);
        }
    }
    let frames_n = frames_n.ok_or_else(|| bad(ml, "MOTION without 'Frames:'".into()))?;
    let frame_time_s = frame_time.ok_or_else(|| bad(ml, "MOTION without 'Frame Time:'".into()))?;
    if frames.len() != frames_n {
        return Err(IngestError::malformed(
            &path,
            format!("'Frames: {frames_n}' but {} frame lines", frames.len()),
        ));
    }
    Ok(Bvh {
        joints,
        frame_time_s,
        frames,
    })
}
