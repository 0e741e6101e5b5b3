//! State constraints (§3.2): for one running step, from heel strike of one leg (HS) to heel
//! strike of the other, compute the keyframes — heel position at the end of the step, the pelvis
//! at heel strike built bottom-up, the pelvis at toe off from the toe-off leg length (case I,
//! eqs. 7–8; case II, 2-D Newton–Raphson on eqs. 3 and 8), the flight parabola, the support
//! spline through heel strike, mid-support, toe off and (through its tangent) mid-flight, and the
//! pelvic rotation/list keyframes of Fig. 7 — plus the per-step parts of the phase constraints
//! (heel-off timing, the swing and flight leg tracks) and the recovery procedures that need a
//! look at the whole step.
//!
//! Signs: the step's stance leg has side sign `s` (+1 right, −1 left); z and the pelvis angles
//! are mirrored through `s`, so one set of formulas serves both steps ("for the opposite step …
//! all the calculations below are mirrored").
//!
//! This module holds the types a planned step is made of; the work is in its parts:
//! [`keyframes`] (the state keyframes: eq. 8's toe-off leg, cases I and II, the landing),
//! [`step`] (planning a running step: support spline, heel off, swing and flight legs),
//! `clearance` (recovery 3, foot stubbing) and [`stand`] (the stands a run starts from and
//! stops in). Their public items are re-exported here.
use argmin::core::{CostFunction, Executor, Jacobian, Operator, State};
use argmin::solver::gaussnewton::GaussNewton;
use glam::{DVec2, DVec3};
use nalgebra::{Matrix2, Vector2};

use super::attributes::{hidden_impact_pitch, Effective, Strike};
use super::curves::{Key, KneeBump, Track};
use super::dims::{leg_fk, leg_ik, pelvis_matrix, pitch_from_down, rot2, LegAngles, RunnerDims};
use super::phase::{hip_at, orient_at, pelvis_at, stance_leg, stance_leg_in, StanceMode};
use crate::generator::curves::{c2_mid_velocity, Seg3};
use crate::generator::GenerateError;

mod clearance;
pub mod keyframes;
pub mod stand;
pub mod step;

use clearance::*;
pub use keyframes::*;
pub use stand::*;
pub use step::*;

/// Gravitational acceleration used in eq. 3 and the flight parabola, m/s².
pub const G: f64 = crate::units::G;

/// How the flight of a step is specified.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum FlightSpec {
    /// Case I: the flight time (s) is known (from eqs. 4–5); H follows from eq. 3.
    Time(f64),
    /// Case II: the flight height H (m) is known; the flight time follows from eqs. 3, 7, 8.
    /// Eq. 3 with eqs. 7–8 has, in general, two flight times for one H; the one nearest `near`
    /// (s) is used ([`keyframes::CASE_TWO_RULE`]).
    Height {
        /// Flight height H, m.
        height: f64,
        /// The flight time to choose by: the flight-time relation's (eq. 5), s.
        near: f64,
    },
}

/// Which of the two cases of §3.2 produced a step's toe-off pelvis.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum FlightCase {
    /// Flight time given, eqs. 7–8 analytic.
    I,
    /// Flight height given, Newton–Raphson on eqs. 3 and 8.
    II,
}

/// Kind of step.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum StepKind {
    /// First step, from a stand: the stance foot is already flat and the swing leg's first
    /// sub-phase is omitted (§3.3.1).
    Start,
    /// A running step.
    Normal,
    /// The final support after the last landing: the pelvis comes to rest and the other foot
    /// is set down beside the stance foot.
    Stop,
}

/// Where a foot is (or will be) planted: the heel's position when the foot is flat.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Footprint {
    /// Heel of the flat foot on the ground (y = 0).
    pub heel: DVec3,
    /// How the foot strikes.
    pub strike: Strike,
    /// Sole pitch at impact, rad (0 for a foot set down flat).
    pub impact_pitch: f64,
}

impl Default for Footprint {
    fn default() -> Self {
        Footprint {
            heel: DVec3::ZERO,
            strike: Strike::Heel,
            impact_pitch: 0.0,
        }
    }
}

impl Footprint {
    /// Ankle of the foot at impact.
    pub fn impact_ankle(&self, d: &RunnerDims) -> DVec3 {
        let a = match self.strike {
            Strike::Heel => rot2(self.impact_pitch, DVec2::new(d.heel_back, d.ankle_height)),
            Strike::Toe => {
                DVec2::new(d.heel_back + d.ankle_to_ball, d.mtp_height)
                    - rot2(self.impact_pitch, d.mtp_f())
            }
        };
        self.heel + DVec3::new(a.x, a.y, 0.0)
    }
    /// Toe angle at impact: toes flat on the ground for a toe strike.
    pub fn impact_meta(&self) -> f64 {
        match self.strike {
            Strike::Heel => 0.0,
            Strike::Toe => -self.impact_pitch,
        }
    }
    /// Ankle of the flat foot.
    pub fn flat_ankle(&self, d: &RunnerDims) -> DVec3 {
        self.heel + DVec3::new(d.heel_back, d.ankle_height, 0.0)
    }
}

/// Upper-body attribute values carried across steps so that changes blend in (tilt, sway, arm
/// swing, elbow min, elbow max, shoulder rotation, arm abduction).
pub type UpperAttrs = [f64; 7];

/// Upper-body attributes of an effective set, in [`UpperAttrs`] order.
pub fn upper_attrs(e: &Effective) -> UpperAttrs {
    [
        e.torso_tilt,
        e.torso_sway,
        e.arm_swing,
        e.elbow_min,
        e.elbow_max,
        e.shoulder_rotation,
        e.arm_abduction,
    ]
}

/// The state at a heel strike, handed from one step to the next.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Carry {
    /// Side sign of the foot that has just landed (the coming step's stance leg).
    pub stance_sign: f64,
    /// Pelvis position.
    pub pelvis: DVec3,
    /// Pelvis velocity.
    pub pelvis_vel: DVec3,
    /// Pelvic rotation, rad.
    pub yaw: f64,
    /// Pelvic list, rad.
    pub roll: f64,
    /// Pelvic rotation rate, rad/s.
    pub yaw_rate: f64,
    /// Pelvic list rate, rad/s.
    pub roll_rate: f64,
    /// The landed foot.
    pub stance_print: Footprint,
    /// The other foot's last footprint.
    pub other_print: Footprint,
    /// The other leg's angles.
    pub swing: LegAngles,
    /// The other leg's angle rates.
    pub swing_rate: LegAngles,
    /// Starting from a stand.
    pub standing: bool,
    /// Torso sway phase (rad; 0 = forward maximum at mid-support, π = back at toe off).
    pub sway_phase: f64,
    /// Upper-body attributes in force at this instant.
    pub upper: UpperAttrs,
    /// Hip–ankle pitch of a leg at toe off (the back end of the arm swing), rad.
    pub arm_back: f64,
    /// Maximum swing hip flexion (the front end of the arm swing), rad.
    pub arm_front: f64,
    /// Arm-drive phase of the landed leg (rad in [0, 2π): 0 at its toe off, π at the other
    /// leg's; see [`StepPlan::arm_phase`]).
    pub arm_phase: f64,
    /// Rate of the arm-drive phase, rad/s.
    pub arm_phase_rate: f64,
}

/// Inputs of one step: the parameters and effective attributes in force.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct StepInput {
    /// Speed, m/s.
    pub speed: f64,
    /// Step length, m.
    pub step_length: f64,
    /// Step frequency, steps/s.
    pub step_freq: f64,
    /// Flight specification (case I or II).
    pub flight: FlightSpec,
    /// Effective attributes of this step.
    pub eff: Effective,
    /// Effective attributes expected for the next step (for the hind leg's flight target).
    pub next_eff: Effective,
    /// Fraction p of the way to the next mid-support pose the hind leg reaches at heel strike
    /// (§3.3.2, 0.6–0.9).
    pub p: f64,
}

/// Heel-off interpolation: knee flexion and toe angle from heel off to toe off (§3.3.1).
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct HeelOff {
    /// Knee flexion at heel off, rad.
    pub k0: f64,
    /// Knee flexion at toe off, rad.
    pub k1: f64,
    /// Knee rate at heel off, rad/s.
    pub kr0: f64,
    /// Knee rate at toe off, rad/s.
    pub kr1: f64,
    /// Toe angle at toe off, rad.
    pub m1: f64,
    /// Toe rate at toe off, rad/s.
    pub mr1: f64,
}

/// Per-step numbers for the report.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct StepReport {
    /// Case I or II (`None` for start/stop-only quantities).
    pub case: Option<FlightCase>,
    /// Pelvis at toe off (x1, y1, z1), m.
    pub p1: DVec3,
    /// Pelvis at the next heel strike (x2, y2, z2), m.
    pub p2: DVec3,
    /// Flight time, s.
    pub t_flight: f64,
    /// Stance time, s.
    pub t_stance: f64,
    /// Flight height by eq. 3, m.
    pub flight_height: f64,
    /// Case II: the other flight time that gives the same flight height, s (see
    /// [`keyframes::CASE_TWO_RULE`]); `None` for case I or a single root.
    pub other_flight_time: Option<f64>,
    /// Vertical pelvis velocity at toe off, m/s (negative: no apex, eq. 3 then reports the
    /// height of the mirrored apex).
    pub takeoff_vy: f64,
    /// Toe-off leg length toe → hip in the foot's plane (the paper's `rad`), m.
    pub rad: f64,
    /// Times the mid-support control point was lowered (recovery 1).
    pub mid_support_lowered: u32,
    /// Control points inserted to clear the ground with the swing or flight legs (recovery 3).
    pub clearance_keys: u32,
    /// How far below its required clearance a foot would have passed without recovery 3, m
    /// (the worst of the toe-off keyframe, the swing leg and the hind leg; 0 if none).
    pub clearance_deficit: f64,
    /// Which leg needed the most recovery 3: `true` the hind leg (after toe off), `false` the
    /// swing leg.
    pub clearance_hind: bool,
    /// Pelvis drop from touchdown to the mid-support control point, m (what the commanded
    /// bounciness, the stance knee flexion at mid-support, makes the pelvis sink); 0 for the
    /// start from a stand, whose pelvis rises straight to toe off.
    pub pelvis_sink: f64,
    /// The stance knee flexion at mid-support this step was planned with (the bounciness), rad.
    pub bounciness: f64,
    /// The stance hip stayed out of reach somewhere despite recovery 1.
    pub out_of_reach: bool,
    /// Overstride of the landing that ends the step, m (the attribute, or more for a long
    /// support).
    pub overstride: f64,
    /// Hind-leg fraction p.
    pub p: f64,
}

/// Stop-phase extras: the swing foot's Cartesian path to its final footprint.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct StopPath {
    /// Ankle path (lift, set down).
    pub ankle: [Seg3; 2],
    /// Time the foot is down, s.
    pub t_land: f64,
    /// Sole pitch at the start, rad.
    pub pitch0: f64,
    /// Toe angle at the start, rad.
    pub meta0: f64,
    /// Final footprint of the swing foot.
    pub print: Footprint,
}

/// One planned step: everything the per-frame evaluation needs.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct StepPlan {
    /// Kind of step.
    pub kind: StepKind,
    /// Side sign of the stance leg (+1 right).
    pub s: f64,
    /// Step duration 1/sf (stop: the stop duration), s.
    pub t_step: f64,
    /// Support duration, s (stop: = t_step).
    pub t_stance: f64,
    /// Flight duration, s.
    pub t_flight: f64,
    /// Mid-support time, s.
    pub t_ms: f64,
    /// Stance foot flat from, s.
    pub t_flat: f64,
    /// Heel off at, s.
    pub t_heel_off: f64,
    /// Support spline (1 or 2 segments).
    pub support: [Seg3; 2],
    /// Segments used.
    pub nseg: usize,
    /// Pelvis at toe off.
    pub flight_p1: DVec3,
    /// Pelvis velocity at toe off (v, w, ż).
    pub flight_v: DVec3,
    /// Orientation keyframes (t, yaw, roll).
    pub orient: [(f64, f64, f64); 4],
    /// Rotation and list rates at the keyframes (rad/s): the keyframes are joined by cubic
    /// Hermite segments with Catmull–Rom rates, C1 across steps.
    pub orient_rate: [(f64, f64); 4],
    /// Keyframes used.
    pub norient: usize,
    /// Stance foot.
    pub stance_print: Footprint,
    /// Where the other foot lands at the end of the step.
    pub next_print: Footprint,
    /// The other foot's previous footprint (where it stands on a start step).
    pub other_print: Footprint,
    /// Heel-off interpolation.
    pub heel_off: HeelOff,
    /// The stance leg after toe off (flight, hind leg).
    pub hind: Track,
    /// The swing leg (support: swing sub-phases; flight: front leg).
    pub swing: Track,
    /// Effective attributes of the step.
    pub eff: Effective,
    /// Upper-body attributes at the start of the step (blended into `eff`'s over the step).
    pub upper0: UpperAttrs,
    /// Sway phase keys (t, phase).
    pub sway: [(f64, f64); 4],
    /// Arm-swing back end at the start of the step and for this step, rad.
    pub arm_back: (f64, f64),
    /// Arm-swing front end at the start of the step and for this step, rad.
    pub arm_front: (f64, f64),
    /// Arm-drive phase keys (t, phase, rate) of the stance leg, joined by cubic Hermite
    /// segments: the phase is 0 (mod 2π) at the leg's toe off, where the arm it drives is at
    /// the back of its swing, and π at the other leg's toe off (the front); the swing leg's
    /// phase is π ahead. A running step keys its heel strike (carried), its toe off (2π) and
    /// its end (heading for the next toe off at the step's own rate, π per toe off to toe off).
    pub arm_phase: [(f64, f64, f64); 3],
    /// Speed, m/s.
    pub speed: f64,
    /// Step length, m.
    pub step_length: f64,
    /// Step frequency, steps/s.
    pub step_freq: f64,
    /// Stop phase path (kind Stop only).
    pub stop: StopPath,
    /// Report numbers.
    pub report: StepReport,
}
