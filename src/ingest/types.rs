//! In-memory measured data, in SI units (m, N, N·m, s), in the laboratory frame of the file with
//! its axes identified. Every reader produces a [`Trial`].
use crate::gait::{Gait, GaitEvent, Side};
use serde::{Deserialize, Serialize};
use std::path::PathBuf;

/// A laboratory axis.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize, Deserialize)]
pub enum Axis {
    /// First coordinate.
    X,
    /// Second coordinate.
    Y,
    /// Third coordinate.
    Z,
}

impl Axis {
    /// 0, 1 or 2.
    pub fn index(self) -> usize {
        match self {
            Axis::X => 0,
            Axis::Y => 1,
            Axis::Z => 2,
        }
    }
}

/// How the laboratory frame of a trial maps to gait directions. Detected by the reader (or set by
/// the user) and reported.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct LabFrame {
    /// The vertical axis (positive up).
    pub vertical: Axis,
    /// The axis of progression (walking direction, or the belt's direction on a treadmill).
    pub forward: Axis,
    /// +1.0 if the subject progresses toward +forward, −1.0 if toward −forward.
    pub forward_sign: f64,
    /// How the frame was established (e.g. "vertical = Y from file header; forward = +X from
    /// pelvis displacement").
    pub how: String,
}

/// Marker trajectories.
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
pub struct MarkerSet {
    /// Sampling rate, Hz.
    pub rate_hz: f64,
    /// Sample times, s, strictly increasing.
    pub time_s: Vec<f64>,
    /// Marker names as in the file.
    pub names: Vec<String>,
    /// `positions[marker][frame]`, metres, laboratory frame; `NaN` where the marker is missing
    /// (after gap filling, only gaps too long to fill remain `NaN`).
    pub positions: Vec<Vec<[f64; 3]>>,
}

impl MarkerSet {
    /// Number of frames.
    pub fn len(&self) -> usize {
        self.time_s.len()
    }
    /// True when there are no frames.
    pub fn is_empty(&self) -> bool {
        self.time_s.is_empty()
    }
    /// Index of the marker named `name` (exact match first, then case-insensitive).
    pub fn index(&self, name: &str) -> Option<usize> {
        self.names
            .iter()
            .position(|n| n == name)
            .or_else(|| self.names.iter().position(|n| n.eq_ignore_ascii_case(name)))
    }
    /// The trajectory of marker `name`.
    pub fn get(&self, name: &str) -> Option<&[[f64; 3]]> {
        self.index(name).map(|i| self.positions[i].as_slice())
    }
}

/// One force plate (or one belt of an instrumented treadmill, or one foot's force in an OpenSim
/// GRF file).
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
pub struct ForcePlate {
    /// Name (e.g. "FP1", "belt 1", "R_ground_force").
    pub name: String,
    /// Sampling rate, Hz.
    pub rate_hz: f64,
    /// Sample times, s.
    pub time_s: Vec<f64>,
    /// Ground reaction force on the body, N, laboratory frame.
    pub force_n: Vec<[f64; 3]>,
    /// Centre of pressure, m, laboratory frame; `NaN` when the plate is unloaded or the file
    /// does not give it.
    pub cop_m: Vec<[f64; 3]>,
    /// Free moment about the vertical axis, N·m; empty when the file does not give it.
    pub free_moment_nm: Vec<f64>,
    /// The foot this plate carries, when it is known to carry only one (dual-belt treadmill
    /// belts, OpenSim `R_`/`L_` columns); `None` for overground plates that either foot may hit.
    pub side: Option<Side>,
}

/// Subject parameters, with where each came from.
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
pub struct SubjectInfo {
    /// Subject identifier.
    pub id: Option<String>,
    /// Body height, m.
    pub body_height_m: Option<f64>,
    /// Leg length, m.
    pub leg_length_m: Option<f64>,
    /// Body mass, kg.
    pub mass_kg: Option<f64>,
    /// Provenance notes ("height from C3D SUBJECT:HEIGHT", "leg length estimated from hip and
    /// ankle joint centres of static.trc", …).
    pub notes: Vec<String>,
}

/// Where the trial was recorded.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub enum Setting {
    /// On a treadmill at a constant belt speed, m/s.
    Treadmill {
        /// Belt speed, m/s.
        belt_speed_m_per_s: f64,
    },
    /// Overground (walkway with force plates).
    Overground,
    /// Not known.
    Unknown,
}

/// One measured trial: whatever of markers, force plates, reference events and subject data the
/// source provides.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Trial {
    /// The file(s) it was read from.
    pub source: PathBuf,
    /// A short trial name (file stem, e.g. "Run_3" or "WBDS04walkT06").
    pub name: String,
    /// The subject.
    pub subject: SubjectInfo,
    /// Walking or running, when known.
    pub gait: Option<Gait>,
    /// Treadmill or overground.
    pub setting: Setting,
    /// The laboratory frame, when established.
    pub frame: Option<LabFrame>,
    /// Marker trajectories, if any.
    pub markers: Option<MarkerSet>,
    /// Force plates, if any.
    pub plates: Vec<ForcePlate>,
    /// Events stored in the file (C3D EVENT group): kept as reference, never overwritten.
    pub reference_events: Vec<GaitEvent>,
    /// Things the reader reports to the user: gaps found and filled (marker, frames, method),
    /// axis detection, assumptions.
    pub notes: Vec<String>,
}

impl Trial {
    /// An empty trial read from `source`.
    pub fn new(source: impl Into<PathBuf>, name: impl Into<String>) -> Self {
        Trial {
            source: source.into(),
            name: name.into(),
            subject: SubjectInfo::default(),
            gait: None,
            setting: Setting::Unknown,
            frame: None,
            markers: None,
            plates: Vec::new(),
            reference_events: Vec::new(),
            notes: Vec::new(),
        }
    }
}
