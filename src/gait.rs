//! The gait vocabulary shared by every layer: body side, gait, event kinds and sources. A leaf
//! module: it imports nothing from the crate, so readers ([`crate::ingest`]) and detectors
//! ([`crate::events`]) both build on it without importing each other.
use serde::{Deserialize, Serialize};
use std::fmt;

/// Body side.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Side {
    /// Left.
    Left,
    /// Right.
    Right,
}

impl Side {
    /// The other side.
    pub fn opposite(self) -> Side {
        match self {
            Side::Left => Side::Right,
            Side::Right => Side::Left,
        }
    }
    /// `"l"` or `"r"`, as used in landmark and column names (`l_heel_x_m`).
    pub fn prefix(self) -> &'static str {
        match self {
            Side::Left => "l",
            Side::Right => "r",
        }
    }
    /// Parses `left|l|L|right|r|R` (case-insensitive).
    pub fn parse(s: &str) -> Option<Side> {
        match s.trim().to_ascii_lowercase().as_str() {
            "l" | "left" => Some(Side::Left),
            "r" | "right" => Some(Side::Right),
            _ => None,
        }
    }
}

impl fmt::Display for Side {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(match self {
            Side::Left => "left",
            Side::Right => "right",
        })
    }
}

/// Gait: walking (a double-support state each step) or running (a flight state each step).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Gait {
    /// Walking.
    Walk,
    /// Running.
    Run,
}

impl Gait {
    /// Parses `walk|walking|run|running` (case-insensitive).
    pub fn parse(s: &str) -> Option<Gait> {
        match s.trim().to_ascii_lowercase().as_str() {
            "walk" | "walking" => Some(Gait::Walk),
            "run" | "running" => Some(Gait::Run),
            _ => None,
        }
    }
}

impl fmt::Display for Gait {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(match self {
            Gait::Walk => "walk",
            Gait::Run => "run",
        })
    }
}

/// A gait event kind. The names follow the papers: HSM (heel strike moment), FGM (flat ground
/// moment), MOM (meta off moment), TOM (toe off moment) of Ko & Badler (1993) §3; heel off is the
/// start of the heel-off period of Bruderlin & Calvert (1989) §4.2.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum EventKind {
    /// Initial contact (heel strike, or toe strike in forefoot running).
    HeelStrike,
    /// The stance foot becomes flat on the ground (FGM).
    FootFlat,
    /// The heel leaves the ground.
    HeelOff,
    /// The metatarsal heads leave the ground; the foot rotates about the toe tip (MOM).
    MetaOff,
    /// The toe leaves the ground (TOM).
    ToeOff,
}

impl EventKind {
    /// Snake-case name used in CSV files (`heel_strike`, `toe_off`, …).
    pub fn as_str(self) -> &'static str {
        match self {
            EventKind::HeelStrike => "heel_strike",
            EventKind::FootFlat => "foot_flat",
            EventKind::HeelOff => "heel_off",
            EventKind::MetaOff => "meta_off",
            EventKind::ToeOff => "toe_off",
        }
    }
}

impl fmt::Display for EventKind {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.as_str())
    }
}

/// Where an event came from.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum EventSource {
    /// Vertical ground reaction force threshold with hysteresis.
    Force,
    /// Zeni et al. (2008) coordinate method (heel/toe relative to the pelvis).
    ZeniCoordinate,
    /// Zeni et al. (2008) velocity variant.
    ZeniVelocity,
    /// Foot-marker kinematics (heel/metatarsal/toe heights and velocities) for the finer phases.
    FootMarkers,
    /// Heel and toe speed over the ground within the Zeni windows (walking; Bonci et al. 2022).
    FootSpeed,
    /// Running: heel/metatarsal vertical jerk peak at touchdown (after Handsaker et al. 2016)
    /// and the toe's speed over the ground at toe off.
    FootJerk,
    /// Read from the input file (e.g. a C3D EVENT group); kept for comparison, never overwritten.
    Reference,
    /// The file's events with the force plates' in place wherever the plates saw the event
    /// (each event keeps its own source: `Force` or `Reference`).
    ForceThenReference,
    /// Produced by one of gaitfit's generators.
    Generated,
}

impl EventSource {
    /// The name used in tables and on the command line (`force`, `zeni_coordinate`,
    /// `foot_height`, …): the `event_source` of the steps table and the `method` of the events
    /// table.
    pub fn as_str(self) -> &'static str {
        match self {
            EventSource::Force => "force",
            EventSource::ZeniCoordinate => "zeni_coordinate",
            EventSource::ZeniVelocity => "zeni_velocity",
            EventSource::FootMarkers => "foot_height",
            EventSource::FootSpeed => "foot_speed",
            EventSource::FootJerk => "foot_jerk",
            EventSource::Reference => "reference",
            EventSource::ForceThenReference => "force_then_reference",
            EventSource::Generated => "generated",
        }
    }
}

impl fmt::Display for EventSource {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.as_str())
    }
}

/// One gait event of one foot.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct GaitEvent {
    /// Time from the start of the trial, s.
    pub time_s: f64,
    /// Which foot.
    pub side: Side,
    /// What happened.
    pub kind: EventKind,
    /// How it was found.
    pub source: EventSource,
}
