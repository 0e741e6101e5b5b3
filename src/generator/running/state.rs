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

/// Gravitational acceleration used in eq. 3 and the flight parabola, m/s².
pub const G: f64 = crate::units::G;

/// How the flight of a step is specified.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum FlightSpec {
    /// Case I: the flight time (s) is known (from eqs. 4–5); H follows from eq. 3.
    Time(f64),
    /// Case II: the flight height H (m) is known; the flight time follows from eqs. 3, 7, 8.
    Height(f64),
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
    /// Vertical pelvis velocity at toe off, m/s (negative: no apex, eq. 3 then reports the
    /// height of the mirrored apex).
    pub takeoff_vy: f64,
    /// Toe-off leg length toe → hip in the foot's plane (the paper's `rad`), m.
    pub rad: f64,
    /// Times the mid-support control point was lowered (recovery 1).
    pub mid_support_lowered: u32,
    /// Control points inserted to clear the ground with the swing or flight legs (recovery 3).
    pub clearance_keys: u32,
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

fn numerical(stage: &str, message: String) -> GenerateError {
    GenerateError::Numerical {
        stage: stage.into(),
        message,
    }
}

/// The toe-off leg length `rad` of eq. 8: distance from the toe tip to the hip in the foot's
/// vertical plane for knee flexion `k`, ankle angle `a` and toe angle `m` at toe off, with the
/// hip `dz` to the side of the foot. The chain toe→ankle→hip is a triangle whose angle at the
/// ankle follows from the ankle angle and the knee's offset of the hip–ankle line from the shank.
pub fn toe_off_radius(d: &RunnerDims, k: f64, a: f64, m: f64, dz: f64) -> Option<f64> {
    let dd = d.hip_ankle(k);
    let ds2 = dd * dd - dz * dz;
    if ds2 <= 0.0 {
        return None;
    }
    let ds = ds2.sqrt();
    let tf = d.toe_f(m);
    let r_ta = tf.length();
    let delta = (d.thigh * k.sin() / dd).clamp(-1.0, 1.0).asin();
    let gamma = (std::f64::consts::FRAC_PI_2 - a + delta) - tf.y.atan2(tf.x);
    let rad2 = ds * ds + r_ta * r_ta - 2.0 * ds * r_ta * gamma.cos();
    (rad2 > 0.0).then(|| rad2.sqrt())
}

/// Case II of §3.2: unknowns (x1, y1) of the pelvis at toe off, given H. Residuals: eq. 8
/// (generalised to the hip's offset from the pelvis centre) and eq. 3 with eq. 7's
/// t = (x2 − x1)/v substituted (the paper prints "(x2 − x1)/y1", a typo: eq. 7 gives
/// t_flight = (x2 − x1)/v). Eq. 3 is used unsquared, g·t/2 − (y1 − y2)/t = √(2gH), which picks
/// the branch with the apex after toe off.
struct CaseTwo {
    rad: f64,
    off: DVec3,
    x_toe: f64,
    x2: f64,
    y2: f64,
    v: f64,
    h: f64,
}

impl CaseTwo {
    fn parts(&self, x1: f64) -> (f64, f64) {
        let xh = x1 + self.off.x - self.x_toe;
        (xh, (self.rad * self.rad - xh * xh).max(1e-12).sqrt())
    }
}

impl Operator for CaseTwo {
    type Param = Vector2<f64>;
    type Output = Vector2<f64>;
    fn apply(&self, p: &Self::Param) -> Result<Self::Output, argmin::core::Error> {
        let (x1, y1) = (p[0], p[1]);
        let (_, root) = self.parts(x1);
        let t = (self.x2 - x1) / self.v;
        let r1 = y1 + self.off.y - root;
        let r2 = 0.5 * G * t - (y1 - self.y2) / t - (2.0 * G * self.h).sqrt();
        Ok(Vector2::new(r1, r2))
    }
}

impl Jacobian for CaseTwo {
    type Param = Vector2<f64>;
    type Jacobian = Matrix2<f64>;
    fn jacobian(&self, p: &Self::Param) -> Result<Self::Jacobian, argmin::core::Error> {
        let (x1, y1) = (p[0], p[1]);
        let (xh, root) = self.parts(x1);
        let t = (self.x2 - x1) / self.v;
        let dr2_dt = 0.5 * G + (y1 - self.y2) / (t * t);
        Ok(Matrix2::new(xh / root, 1.0, -dr2_dt / self.v, -1.0 / t))
    }
}

impl CostFunction for CaseTwo {
    type Param = Vector2<f64>;
    type Output = f64;
    fn cost(&self, p: &Self::Param) -> Result<f64, argmin::core::Error> {
        Ok(self.apply(p)?.norm())
    }
}

/// Solves case II with argmin's Gauss–Newton, which on a square system with an invertible
/// Jacobian takes exactly the Newton–Raphson step J⁻¹r of the paper's 2-D method.
fn solve_case_two(problem: CaseTwo, guess: (f64, f64)) -> Result<(f64, f64), GenerateError> {
    let h = problem.h;
    let solver = GaussNewton::new()
        .with_tolerance(1e-15)
        .map_err(|e| numerical("case II Newton-Raphson", e.to_string()))?;
    let check = CaseTwo { ..problem };
    let res = Executor::new(problem, solver)
        .configure(|s| {
            s.param(Vector2::new(guess.0, guess.1))
                .max_iters(60)
                .target_cost(1e-12)
        })
        .run()
        .map_err(|e| numerical("case II Newton-Raphson", format!("H = {h} m: {e}")))?;
    let p = res
        .state()
        .get_best_param()
        .copied()
        .unwrap_or(Vector2::new(guess.0, guess.1));
    let r = check.apply(&p).map(|r| r.norm()).unwrap_or(f64::INFINITY);
    if r.is_nan() || r >= 1e-9 || !p[0].is_finite() || !p[1].is_finite() {
        return Err(numerical(
            "case II Newton-Raphson",
            format!("no toe-off pelvis gives flight height H = {h} m (residual {r:.3e}); lower H or unlock the step frequency"),
        ));
    }
    Ok((p[0], p[1]))
}

/// Time at which the swing leg's toe is vertically under its knee for thigh pitch `pitch` and
/// ankle angle `ankle` (§3.3.1, swing leg at the other leg's toe off): the knee flexion.
pub fn toe_under_knee(d: &RunnerDims, pitch: f64, ankle: f64) -> f64 {
    let w = DVec2::new(0.0, -d.shank) + rot2(ankle, d.toe_f(0.0));
    let shank = -std::f64::consts::FRAC_PI_2 - w.y.atan2(w.x);
    (pitch - shank).max(0.0)
}

/// Minimum height of the swing foot's lowest point at the other leg's toe off, m at 1.8 m.
pub const TOR_CLEARANCE: f64 = 0.03;
/// Fraction of the stance leg's initial joint rates the landing leg arrives with (0: the
/// joints stop at impact; 1: C1 through impact, the heel touching down tangentially).
pub const HS_RATE_MATCH: f64 = 0.6;

/// Shortest time over which a swinging foot's required clearance grows from zero (after toe
/// off) or shrinks to zero (before heel strike), s.
pub const CLEARANCE_RAMP: f64 = 0.1;

/// The flight's share of the time from toe off to the next mid-support at the paper's
/// reference stride (12 km/h, 1.8 m: 0.188 s of 0.254 s), for which p ∈ [0.6, 0.9] was tuned.
pub const P_REFERENCE_SHARE: f64 = 0.74;

/// Fraction of the first support during which the swing foot is lifted off from the stand.
pub const START_LIFT_FRACTION: f64 = 0.4;
/// How high the swing foot is lifted from the stand by then, m at 1.8 m.
pub const START_LIFT: f64 = 0.04;

/// How far ahead of the stance ankle the pelvis comes to rest at a stop, m at 1.8 m.
pub const STOP_STAGGER: f64 = 0.1;
/// Knee flexion of the final stand, rad.
pub const STOP_KNEE: f64 = 15.0 * std::f64::consts::PI / 180.0;
/// Longest stop phase, s at 1.8 m.
pub const STOP_TIME: f64 = 0.6;

/// Least support time as a fraction of the step. Eqs. 4–5 never ask for less (published: ≥ 26 %
/// up to 25 km/h and +10 % step frequency), but a refitted eq. 5 extrapolated beyond its data
/// can (0.231 s of flight in a 0.243 s step), and the legs then whirl through the support;
/// sprinters' support is about 40 % of the step.
pub const MIN_STANCE_FRACTION: f64 = 0.25;

/// Longest overstride the landing may be moved ahead to for long supports, m at 1.8 m (the
/// attribute's range).
pub const OVERSTRIDE_MAX: f64 = 0.4;

/// Toe-off leg lean (hip ahead of the toe tip, from the vertical) beyond which a long support
/// moves the landing ahead, rad. Real runners leave the ground at about 30–40°; the published
/// relations' runs stay at or under 26°, so they are unaffected.
pub const TOE_OFF_LEAN_MAX: f64 = 30.0 * std::f64::consts::PI / 180.0;

/// Least downward speed of the landing foot's lowest point at heel strike, m/s at 1.8 m.
pub const LANDING_SPEED: f64 = 0.15;

/// Standing: knee flexion used for the initial and final stands, rad.
pub const STAND_KNEE: f64 = 6.0 * std::f64::consts::PI / 180.0;

/// The standing pose both the start and the stop use: feet flat side by side (heels at
/// `heel_x`, stride width apart), pelvis centred above the ankles.
pub fn standing_carry(
    d: &RunnerDims,
    eff: &Effective,
    heel_x: f64,
    first_stance_sign: f64,
    max_pelvis_y: f64,
) -> Carry {
    let s = first_stance_sign;
    let print = |sign: f64| Footprint {
        heel: DVec3::new(heel_x, 0.0, sign * eff.stride_width / 2.0),
        strike: eff.strike,
        impact_pitch: 0.0,
    };
    let stance = print(s);
    let other = print(-s);
    let x = heel_x + d.heel_back;
    let dz = d.hip_offset.z - eff.stride_width / 2.0;
    let dd = d.hip_ankle(STAND_KNEE);
    let y =
        (d.ankle_height + (dd * dd - dz * dz).max(0.0).sqrt() - d.hip_offset.y).min(max_pelvis_y);
    let pelvis = DVec3::new(x, y, 0.0);
    let hip = pelvis + d.hip_local(-s);
    let (swing, _) = leg_ik(d, hip, other.flat_ankle(d), 0.0, 0.0);
    Carry {
        stance_sign: s,
        pelvis,
        pelvis_vel: DVec3::ZERO,
        yaw: 0.0,
        roll: 0.0,
        yaw_rate: 0.0,
        roll_rate: 0.0,
        stance_print: stance,
        other_print: other,
        swing,
        swing_rate: LegAngles::default(),
        standing: true,
        sway_phase: 1.5 * std::f64::consts::PI, // cos = 0: upright, rising to the forward maximum
        upper: [
            0.0,
            0.0,
            0.0,
            eff.elbow_min,
            eff.elbow_min,
            0.0,
            eff.arm_abduction,
        ],
        arm_back: 0.0,
        arm_front: 0.0,
        // At rest; the first step's stance leg swings its arm from the front (π) to the back
        // at its toe off (2π), from a standstill of the phase.
        arm_phase: std::f64::consts::PI,
        arm_phase_rate: 0.0,
    }
}

fn hs_pose(d: &RunnerDims, print: &Footprint, hip: DVec3) -> LegAngles {
    leg_ik(
        d,
        hip,
        print.impact_ankle(d),
        print.impact_pitch,
        print.impact_meta(),
    )
    .0
}

/// Required clearance of a swinging foot at time `t` of a window [t_a, t_b] that starts
/// (`ramp_in`) and/or ends (`ramp_out`) at a ground contact: `margin`, ramped smoothly from zero
/// over the first/last quarter of the window (a foot leaves and reaches the ground with the
/// joint rates of the neighbouring phase, so its height grows from zero smoothly).
fn required_clearance(
    t: f64,
    t_a: f64,
    t_b: f64,
    ramp_in: bool,
    ramp_out: bool,
    margin: f64,
) -> f64 {
    // A quarter of the window, but at least CLEARANCE_RAMP: short flights (slow runs) need not
    // lift the foot a full margin within a few milliseconds.
    let q = (0.25 * (t_b - t_a)).max(CLEARANCE_RAMP);
    let ramp = |tau: f64| {
        let s = (tau / q).clamp(0.0, 1.0);
        s * s * (3.0 - 2.0 * s)
    };
    let mut r = margin;
    if ramp_in {
        r = r.min(margin * ramp(t - t_a));
    }
    if ramp_out {
        r = r.min(margin * ramp(t_b - t));
    }
    r
}

/// The state keyframes of one step (§3.2): the pelvis at toe off (p1) and at the next heel
/// strike (p2), the flight time and height, and what the rest of the plan needs from them.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct StateKeys {
    /// Where the other foot lands.
    pub next_print: Footprint,
    /// Pelvis at toe off (x1, y1, z1).
    pub p1: DVec3,
    /// Pelvis at the next heel strike (x2, y2, z2).
    pub p2: DVec3,
    /// Flight time, s.
    pub t_flight: f64,
    /// Support time, s.
    pub t_stance: f64,
    /// Flight height by eq. 3, m.
    pub flight_height: f64,
    /// Vertical take-off velocity, m/s.
    pub w: f64,
    /// Toe-off leg length (eq. 8's rad), m.
    pub rad: f64,
    /// Case I or II.
    pub case: FlightCase,
    /// Landing hip relative to the pelvis at heel strike (world frame).
    pub o2: DVec3,
    /// Pelvic rotation at toe off, rad.
    pub yaw1: f64,
    /// Pelvic rotation at heel strike, rad.
    pub yaw2: f64,
    /// Pelvic list at heel strike, rad.
    pub roll2: f64,
    /// Heel of the next footprint ahead of the pelvis at its heel strike, m: the overstride
    /// attribute, or more for a long support (see [`TOE_OFF_LEAN_MAX`]).
    pub overstride: f64,
}

/// Computes the state keyframes for a step whose stance foot (side sign `s`) is planted at
/// `fp`: heel position at the end of the step, the pelvis at heel strike bottom-up, and the
/// pelvis at toe off by case I (eqs. 7–8) or case II (Newton–Raphson on eqs. 3 and 8).
pub fn state_keyframes(
    d: &RunnerDims,
    inp: &StepInput,
    s: f64,
    fp: &Footprint,
) -> Result<StateKeys, GenerateError> {
    let e = inp.eff;
    let (v, sl, sf) = (inp.speed, inp.step_length, inp.step_freq);
    let t_step = 1.0 / sf;
    let (rot_max, list_max, lat_max) = (e.pelvic_rotation, e.pelvic_list, e.lateral_displacement);
    // Fig. 7: at heel strike 20 % rotation (landing hip forward), 80 % list (swing side down),
    // 80 % lateral displacement toward the landing foot.
    let (yaw2, roll2, z2) = (-s * 0.2 * rot_max, s * 0.8 * list_max, -s * 0.8 * lat_max);
    let o2 = pelvis_matrix(yaw2, roll2) * d.hip_local(-s);
    let scale = d.body_height / 1.8;
    // --- Heel strike at the end of the step (HSL), bottom-up, for a landing `os` ahead. ---
    let landing = |os: f64| -> Result<(Footprint, f64, f64), GenerateError> {
        let next_print = Footprint {
            heel: DVec3::new(fp.heel.x + sl, 0.0, -s * e.stride_width / 2.0),
            strike: e.strike,
            impact_pitch: if os > e.overstride {
                hidden_impact_pitch(os / scale, e.strike)
            } else {
                e.impact_pitch
            },
        };
        let x2 = next_print.heel.x - os;
        let a2 = next_print.impact_ankle(d);
        let dd2 = d.hip_ankle(e.knee_heel_strike);
        let (dx2, dz2) = (x2 + o2.x - a2.x, z2 + o2.z - a2.z);
        let r2 = dd2 * dd2 - dx2 * dx2 - dz2 * dz2;
        if r2 <= 0.0 {
            return Err(GenerateError::Parameter {
                name: "overstride".into(),
                value: os,
                message: format!(
                    "the landing leg cannot reach its heel {:.3} m ahead and {:.3} m aside of the hip; lower overstride or stride width",
                    -dx2, dz2.abs()
                ),
            });
        }
        Ok((next_print, x2, a2.y + r2.sqrt() - o2.y))
    };

    // --- Toe off of the stance leg (TOR), backwards from HSL. ---
    let x_toe = fp.heel.x + d.foot_length();
    let (yaw1, z1) = (-s * rot_max, s * 0.8 * lat_max); // rotation maximal, list zero
    let o1 = pelvis_matrix(yaw1, 0.0) * d.hip_local(s);
    let dz1 = z1 + o1.z - fp.heel.z;
    let rad = toe_off_radius(d, e.knee_toe_off, e.ankle_toe_off, e.meta_toe_off, dz1).ok_or_else(|| {
        numerical("toe-off leg", format!("the hip is {dz1:.3} m aside of the foot, beyond the leg; lower stride width or lateral displacement"))
    })?;
    let case_one = |x2: f64, t_f: f64| -> Result<(f64, f64), GenerateError> {
        // Eq. 7: x1 = x2 − v·t_flight; eq. 8: y1 = √(rad² − (x1 − x_toe)²), for the hip.
        let x1 = x2 - v * t_f;
        let xh = x1 + o1.x - x_toe;
        if xh.abs() >= rad {
            return Err(numerical(
                "toe-off pelvis (eq. 8)",
                format!(
                    "the toe-off leg ({rad:.3} m) cannot reach from the toe to a hip {xh:.3} m ahead of it \
                     (v = {v:.3} m/s, sl = {sl:.3} m, t_flight = {t_f:.3} s); the step is too long or too short for its flight time"
                ),
            ));
        }
        Ok((x1, (rad * rad - xh * xh).sqrt() - o1.y))
    };
    // Long supports (a refitted eq. 5's short flights at high speed: 1.1 m of ground in 0.22 s
    // at 18 km/h) cannot all be covered behind the toe: the toe-off hip would sink (0.69 m vs
    // 1.02 m with the published flights). Real runners then land further ahead. The paper keeps
    // overstride an attribute; here, with the flight time given (case I), the landing moves
    // ahead (the attribute stays the least overstride) until the pelvis takes off no lower than
    // it lands (the take-off of an unforced flight), or the toe-off leg leans no more than
    // TOE_OFF_LEAN_MAX; the published relations never lean it further (≤ 26° over 2–25 km/h).
    let mut os = e.overstride;
    if let FlightSpec::Time(t_f) = inp.flight {
        let gap = |os: f64| match landing(os) {
            Err(_) => f64::INFINITY,
            Ok((_, x2, y2)) => match case_one(x2, t_f) {
                Ok((x1, y1)) => (y1 - y2).max(rad * TOE_OFF_LEAN_MAX.sin() - (x1 + o1.x - x_toe)),
                Err(_) if x2 - v * t_f + o1.x > x_toe => f64::NEG_INFINITY,
                Err(_) => f64::INFINITY,
            },
        };
        if gap(os) < 0.0 {
            let (mut lo, mut hi) = (os, OVERSTRIDE_MAX * scale);
            if gap(hi) >= 0.0 {
                for _ in 0..50 {
                    let mid = 0.5 * (lo + hi);
                    if gap(mid) < 0.0 {
                        lo = mid;
                    } else {
                        hi = mid;
                    }
                }
                // The reachable side of the bracket, so that the landing leg reaches its heel.
                os = if gap(hi).is_finite() { hi } else { lo };
            }
        }
    }
    let (next_print, x2, y2) = landing(os)?;
    let (x1, y1, t_flight, case) = match inp.flight {
        FlightSpec::Time(t_f) => {
            let (x1, y1) = case_one(x2, t_f)?;
            (x1, y1, t_f, FlightCase::I)
        }
        FlightSpec::Height(h) => {
            let guess_t = 0.5 * t_step;
            let (gx, gy) = case_one(x2, guess_t).unwrap_or((x2 - v * guess_t, rad * 0.99));
            let (x1, y1) = solve_case_two(
                CaseTwo {
                    rad,
                    off: o1,
                    x_toe,
                    x2,
                    y2,
                    v,
                    h,
                },
                (gx, gy),
            )?;
            (x1, y1, (x2 - x1) / v, FlightCase::II)
        }
    };
    if !(t_flight > 0.0 && t_flight < t_step) {
        return Err(numerical(
            "flight time",
            format!("t_flight = {t_flight:.4} s must lie within (0, 1/sf = {t_step:.4} s); lower the flight height or the step frequency"),
        ));
    }
    let t_stance = t_step - t_flight;
    if t_stance < MIN_STANCE_FRACTION * t_step {
        return Err(numerical(
            "flight time",
            format!(
                "t_flight = {t_flight:.4} s leaves a support of {t_stance:.4} s, under {:.0} % of the step (1/sf = {t_step:.4} s), which no leg can push off in; lower the flight height or the step frequency (or, with --fits, keep to the step frequencies the refitted eq. 5 was fitted on)",
                MIN_STANCE_FRACTION * 100.0
            ),
        ));
    }
    let w = (y2 - y1) / t_flight + 0.5 * G * t_flight; // vertical take-off velocity
    let flight_height = w * w / (2.0 * G); // eq. 3
    Ok(StateKeys {
        next_print,
        p1: DVec3::new(x1, y1, z1),
        p2: DVec3::new(x2, y2, z2),
        t_flight,
        t_stance,
        flight_height,
        w,
        rad,
        case,
        o2,
        yaw1,
        yaw2,
        roll2,
        overstride: os,
    })
}

/// Plans one running step (kind Start or Normal).
pub fn plan_step(
    d: &RunnerDims,
    inp: &StepInput,
    carry: &Carry,
    kind: StepKind,
) -> Result<StepPlan, GenerateError> {
    let s = carry.stance_sign;
    let e = inp.eff;
    let (v, sl, sf) = (inp.speed, inp.step_length, inp.step_freq);
    if !(v > 0.0 && sl > 0.0 && sf > 0.0) {
        return Err(GenerateError::Parameter {
            name: "speed/step_length/step_freq".into(),
            value: v,
            message: format!("all must be positive (v = {v} m/s, sl = {sl} m, sf = {sf} steps/s)"),
        });
    }
    let t_step = 1.0 / sf;
    let fp = carry.stance_print;
    let k = state_keyframes(d, inp, s, &fp)?;
    let StateKeys {
        next_print,
        p1,
        p2,
        t_flight,
        t_stance,
        flight_height,
        w,
        rad,
        case,
        o2,
        yaw1,
        yaw2,
        roll2,
        overstride,
    } = k;
    let (x1, y1, z1) = (p1.x, p1.y, p1.z);
    let (list_max, lat_max) = (e.pelvic_list, e.lateral_displacement);
    let flight_v = DVec3::new(v, w, (p2.z - z1) / t_flight);

    // --- Pelvis orientation keyframes (Fig. 7). ---
    let t_ms = 0.5 * t_stance;
    let orient = [
        (0.0, carry.yaw, carry.roll),
        (t_ms, 0.0, -s * list_max),
        (t_stance, yaw1, 0.0),
        (t_step, yaw2, roll2),
    ];
    // Fig. 7's keyframes are joined smoothly (the paper interpolates linearly; its kinks at toe
    // off would jerk the hips, and with them the feet, in short flights). The rate at the end
    // heads for the next step's mid-support keyframe (no rotation, list to the other side).
    let cr = |a: (f64, f64, f64), b: (f64, f64, f64)| {
        ((b.1 - a.1) / (b.0 - a.0), (b.2 - a.2) / (b.0 - a.0))
    };
    let next_ms = (t_step + t_ms, 0.0, s * list_max);
    let orient_rate = [
        (carry.yaw_rate, carry.roll_rate),
        cr(orient[0], orient[2]),
        cr(orient[1], orient[3]),
        cr(orient[2], next_ms),
    ];

    let empty_track = Track::new();
    let mut plan = StepPlan {
        kind,
        s,
        t_step,
        t_stance,
        t_flight,
        t_ms,
        t_flat: if kind == StepKind::Start { 0.0 } else { t_ms },
        t_heel_off: t_stance,
        support: [Seg3::default(); 2],
        nseg: 1,
        flight_p1: p1,
        flight_v,
        orient,
        orient_rate,
        norient: 4,
        stance_print: fp,
        next_print,
        other_print: carry.other_print,
        heel_off: HeelOff::default(),
        hind: empty_track,
        swing: empty_track,
        eff: e,
        upper0: carry.upper,
        sway: [
            (0.0, carry.sway_phase),
            (t_ms, std::f64::consts::TAU),
            (t_stance, 3.0 * std::f64::consts::PI),
            (t_step, 0.0),
        ],
        arm_back: (carry.arm_back, carry.arm_back),
        arm_front: (carry.arm_front, e.swing_hip),
        arm_phase: {
            // From the carried heel-strike phase to the toe off (2π) C1, then on at π per toe
            // off to toe off (this step's flight + support, the next step's assumed alike).
            let rate = std::f64::consts::PI / (t_flight + t_stance);
            [
                (0.0, carry.arm_phase, carry.arm_phase_rate),
                (t_stance, std::f64::consts::TAU, rate),
                (t_step, std::f64::consts::TAU + rate * t_flight, rate),
            ]
        },
        speed: v,
        step_length: sl,
        step_freq: sf,
        stop: StopPath::default(),
        report: StepReport {
            case: Some(case),
            p1,
            p2,
            t_flight,
            t_stance,
            flight_height,
            takeoff_vy: w,
            rad,
            p: inp.p,
            overstride,
            ..StepReport::default()
        },
    };
    // Sway phase continues from the previous step: forward maximum (2π ≡ 0) at mid-support, back
    // maximum (3π ≡ π) at toe off, and on toward the next mid-support.
    let end_phase =
        3.0 * std::f64::consts::PI + std::f64::consts::PI * t_flight / (t_flight + t_ms);
    // The previous step ended between toe off (π) and mid-support (2π), mod 2π.
    plan.sway[0].1 = carry.sway_phase.rem_euclid(std::f64::consts::TAU);
    plan.sway[3].1 = end_phase;

    // --- Support spline with the mid-support control point, lowered if the hip is too high. ---
    let flat_ankle = fp.flat_ankle(d);
    let p0 = carry.pelvis;
    let x_ms = p0.x + 0.8 * 0.5 * (x1 - p0.x); // 0.8 × the average forward position (§3.2)
    let z_ms = s * lat_max;
    let o_ms = pelvis_matrix(0.0, -s * list_max) * d.hip_local(s);
    let dd_ms = d.hip_ankle(e.bounciness);
    let (dxm, dzm) = (x_ms + o_ms.x - flat_ankle.x, z_ms + o_ms.z - flat_ankle.z);
    let rm = dd_ms * dd_ms - dxm * dxm - dzm * dzm;
    let y_low = p0.y.min(y1);
    let mut y_ms = if rm > 0.0 {
        flat_ankle.y + rm.sqrt() - o_ms.y
    } else {
        y_low - 0.02
    };
    // The mid-support point is the low point of support (§3.2: energies lowest there).
    y_ms = y_ms.min(y_low - 0.002 * d.body_height / 1.8);
    let lower_by = 0.01 * d.body_height / 1.8;
    // The hind leg's flight target (§3.3.2): p is the fraction of the way to the next
    // mid-support pose reached at heel strike. The paper's 0.6–0.9 suit its long flights (at
    // 12 km/h the flight is 74 % of the time from toe off to the next mid-support); for shorter
    // flights p is scaled by the flight's share of that time, or a slow run's 50 ms flight would
    // whip the leg through most of its swing.
    let share = t_flight / (t_flight + t_ms);
    let p_eff = inp.p * (share / P_REFERENCE_SHARE).min(1.0);
    plan.report.p = p_eff;
    // The push-off ends with the knee already folding toward that target (real knees flex
    // before toe off), so the hind leg leaves the ground C1 and its toe lifts.
    let knee_target = e.knee_toe_off + p_eff * (inp.next_eff.swing_knee - e.knee_toe_off);
    let kr_to = 0.5 * (knee_target - e.knee_toe_off) / t_flight;
    loop {
        build_support(
            &mut plan,
            kind,
            p0,
            carry.pelvis_vel,
            DVec3::new(x_ms, y_ms, z_ms),
            p1,
            flight_v,
        );
        find_heel_off(&mut plan, d, kr_to);
        let ok = stance_reachable(&plan, d);
        if ok || kind == StepKind::Start || plan.report.mid_support_lowered >= 12 {
            plan.report.out_of_reach = !ok;
            break;
        }
        // Recovery 1 (§3.3.1): the hip is too high, lower the mid-support control point.
        y_ms -= lower_by;
        plan.report.mid_support_lowered += 1;
    }

    // --- Toe-off pose of the stance leg and its rates (start of the hind leg's flight). ---
    let (to_pose, to_rate, to_hip_ankle) = stance_state(&plan, d, t_stance);
    plan.arm_back.1 = to_hip_ankle;

    // --- Swing leg (§3.3.1) and front leg in flight (§3.3.2). ---
    let sw = -s;
    let mut swing = Track::new();
    if kind == StepKind::Start {
        // From a stand the swing foot is lifted off the ground first along a Cartesian ankle
        // path (flat foot straight up and forward with the pelvis), with the leg from inverse
        // kinematics; the swing track takes over from the pose and rates where the path ends.
        let t_lift = START_LIFT_FRACTION * t_stance;
        let scale = d.body_height / 1.8;
        let a0 = plan.other_print.flat_ankle(d);
        let (pl0, _) = pelvis_at(&plan, 0.0);
        let (pl1, vl1) = pelvis_at(&plan, t_lift);
        let a1 = a0 + DVec3::new(pl1.x - pl0.x, START_LIFT * scale, 0.0);
        let v1 = DVec3::new(vl1.x, 0.5 * START_LIFT * scale / t_lift, 0.0);
        plan.stop = StopPath {
            ankle: [Seg3 {
                t0: 0.0,
                t1: t_lift,
                p0: a0,
                p1: a1,
                v0: DVec3::ZERO,
                v1,
            }; 2],
            t_land: t_lift,
            pitch0: 0.0,
            meta0: 0.0,
            print: plan.other_print,
        };
        let eps = 1e-4;
        let pose_at = |t: f64| {
            let hip = hip_of(&plan, d, t, sw);
            let (ankle, _) = plan.stop.ankle[0].eval(t);
            leg_ik(d, hip, ankle, 0.0, 0.0).0
        };
        let (q1, q0) = (pose_at(t_lift), pose_at(t_lift - eps));
        let mut rate = LegAngles::default();
        for c in 0..5 {
            rate.set(c, (q1.get(c) - q0.get(c)) / eps);
        }
        swing.push(Key {
            t: t_lift,
            val: q1,
            rate,
        });
    } else {
        swing.push(Key {
            t: 0.0,
            val: carry.swing,
            rate: carry.swing_rate,
        });
    }
    let roll_sw = carry.swing.roll;
    let ms_pose = LegAngles {
        pitch: 0.0,
        roll: roll_sw,
        knee: e.swing_knee,
        ankle: e.swing_ankle,
        meta: 0.0,
    };
    let mut tor_pose = LegAngles {
        pitch: e.swing_hip,
        roll: roll_sw,
        knee: toe_under_knee(d, e.swing_hip, e.swing_ankle),
        ankle: e.swing_ankle,
        meta: 0.0,
    };
    let hip2 = p2 + o2;
    let hs = hs_pose(d, &next_print, hip2);
    // The swing leg's toe-under-knee pose can leave the toe on the ground when the pelvis is low
    // at toe off (slow runs, short bent-knee push-offs): then the swing hip is flexed further
    // (keeping the toe under the knee) until the foot clears — the foot-stubbing recovery
    // applied to the keyframe itself, so the flight starts from a clear foot.
    let hip_tor = hip_of(&plan, d, t_stance, -s);
    let need = TOR_CLEARANCE * d.body_height / 1.8;
    while leg_fk(d, hip_tor, &tor_pose).lowest() < need && tor_pose.pitch < 100f64.to_radians() {
        tor_pose.pitch += 2f64.to_radians();
        tor_pose.knee = toe_under_knee(d, tor_pose.pitch, tor_pose.ankle);
        plan.report.clearance_keys += 1;
    }
    // Landing: the front leg arrives with HS_RATE_MATCH of the joint rates the stance leg
    // starts with (hip moving with the landing velocity over the planted foot), so the joints
    // do not jerk at impact while the heel still comes down onto the ground.
    let v_land = flight_v - DVec3::new(0.0, G * t_flight, 0.0);
    let eps = 1e-4;
    let hs_next = hs_pose(d, &next_print, hip2 + v_land * eps);
    let mut hs_rate = LegAngles::default();
    for c in 0..5 {
        hs_rate.set(c, HS_RATE_MATCH * (hs_next.get(c) - hs.get(c)) / eps);
    }
    // The foot must come down onto the ground, not graze it: if the lowest sole point would
    // arrive slower than LANDING_SPEED (slow runs land with almost no vertical pelvis speed),
    // the knee extends and the thigh retracts a little faster at impact, in the proportion that
    // moves the lowest sole point straight down. Not the knee alone: extending it faster also
    // flung the foot forward (2.2 m/s at 6 km/h with the refitted relations' 45 ms flights,
    // after the foot had stalled in the air), and the toe's last step before contact reached
    // 5.8 × its neighbours' (continuity, 6.0 km/h, 1.98 m; tests/runner_properties.rs).
    let lowest_before = |rate: &LegAngles| {
        let mut a = hs;
        for c in 0..5 {
            a.set(c, hs.get(c) - eps * rate.get(c));
        }
        leg_fk(d, hip2 - v_land * eps, &a).lowest()
    };
    let vy = -lowest_before(&hs_rate) / eps;
    let need = -LANDING_SPEED * (d.body_height / 1.8).sqrt();
    if vy > need {
        // The lowest sole point (heel, ball or toe) of the heel-strike pose, and its sagittal
        // velocity per unit knee and hip rate.
        let pts = |a: &LegAngles| {
            let p = leg_fk(d, hip2, a);
            [p.heel, p.ball, p.toe]
        };
        let base = pts(&hs);
        let k = (0..3)
            .min_by(|&i, &j| base[i].y.total_cmp(&base[j].y))
            .unwrap_or(0);
        let partial = |c: usize| {
            let mut a = hs;
            a.set(c, hs.get(c) + eps);
            let v = (pts(&a)[k] - base[k]) / eps;
            DVec2::new(v.x, v.y)
        };
        let (jk, jp) = (partial(2), partial(0));
        let det = jk.x * jp.y - jp.x * jk.y;
        let r = need - vy;
        if det.abs() > 1e-4 {
            // jk·a + jp·b = (0, r): no added forward speed, r more downward.
            hs_rate.knee += -jp.x * r / det;
            hs_rate.pitch += jk.x * r / det;
        } else if jk.y.abs() > 1e-3 {
            hs_rate.knee += r / jk.y;
        }
    }
    if kind != StepKind::Start {
        let rate = LegAngles {
            pitch: (tor_pose.pitch - carry.swing.pitch) / t_stance,
            ankle: (tor_pose.ankle - carry.swing.ankle) / t_stance,
            ..LegAngles::default()
        };
        swing.push(Key {
            t: t_ms,
            val: ms_pose,
            rate,
        });
    }
    let mut rate = LegAngles::default();
    let (t_prev, prev) = if kind == StepKind::Start {
        (swing.start(), swing.keys()[0].val)
    } else {
        (t_ms, ms_pose)
    };
    rate.knee = (hs.knee - prev.knee) / (t_step - t_prev);
    rate.ankle = (hs.ankle - prev.ankle) / (t_step - t_prev);
    swing.push(Key {
        t: t_stance,
        val: tor_pose,
        rate,
    });
    swing.push(Key {
        t: t_step,
        val: hs,
        rate: hs_rate,
    });

    // --- Hind leg in flight: toward p of the next mid-support pose (§3.3.2). ---
    let ne = inp.next_eff;
    let next_ms = LegAngles {
        pitch: 0.0,
        roll: to_pose.roll,
        knee: ne.swing_knee,
        ankle: ne.swing_ankle,
        meta: 0.0,
    };
    let mut target = LegAngles::default();
    let mut end_rate = LegAngles::default();
    for c in 0..5 {
        let (a, b) = (to_pose.get(c), next_ms.get(c));
        let tv = a + p_eff * (b - a);
        target.set(c, tv);
        end_rate.set(c, (b - tv) / t_ms.max(1e-3));
    }
    let mut hind = Track::new();
    // The hind leg leaves the ground with the push-off's joint rates (C1 through toe off).
    hind.push(Key {
        t: t_stance,
        val: to_pose,
        rate: to_rate,
    });
    hind.push(Key {
        t: t_step,
        val: target,
        rate: end_rate,
    });
    plan.swing = swing;
    plan.hind = hind;

    // Recovery 3 (§3.3.1): toe stubbing — insert control points with more knee flexion.
    let margin = 0.01 * d.body_height / 1.8;
    let start = kind == StepKind::Start;
    let t_sw0 = plan.swing.start();
    plan.report.clearance_keys +=
        clear_track(&mut plan, d, sw, false, t_sw0, t_step, start, true, margin);
    plan.report.clearance_keys +=
        clear_track(&mut plan, d, s, true, t_stance, t_step, true, false, margin);
    Ok(plan)
}

fn build_support(
    plan: &mut StepPlan,
    kind: StepKind,
    p0: DVec3,
    v0: DVec3,
    pms: DVec3,
    p1: DVec3,
    v1: DVec3,
) {
    let t_st = plan.t_stance;
    if kind == StepKind::Start {
        // From a stand the pelvis rises straight to toe off (no dip: the runner pushes off).
        plan.support[0] = Seg3 {
            t0: 0.0,
            t1: t_st,
            p0,
            p1,
            v0,
            v1,
        };
        plan.nseg = 1;
        return;
    }
    let h = 0.5 * t_st;
    let vm = c2_mid_velocity(p0, p1, v0, v1, h);
    plan.support[0] = Seg3 {
        t0: 0.0,
        t1: h,
        p0,
        p1: pms,
        v0,
        v1: vm,
    };
    plan.support[1] = Seg3 {
        t0: h,
        t1: t_st,
        p0: pms,
        p1,
        v0: vm,
        v1,
    };
    plan.nseg = 2;
}

fn hip_of(plan: &StepPlan, d: &RunnerDims, t: f64, sign: f64) -> DVec3 {
    let (p, _) = pelvis_at(plan, t);
    let (yaw, roll) = orient_at(plan, t);
    hip_at(d, p, yaw, roll, sign)
}

/// Heel off (§3.3.1): after the foot is flat, "triggered by either the body passing through the
/// vertical or the ankle-hip distance becoming bigger than the length of the extended leg". The
/// vertical is read as the hip passing over the ankle. If neither happens, heel off is forced
/// so that the last quarter of the flat-to-toe-off time is left for the push-off.
fn find_heel_off(plan: &mut StepPlan, d: &RunnerDims, kr_to: f64) {
    let s = plan.s;
    let ankle = plan.stance_print.flat_ankle(d);
    let reach = d.leg_reach();
    let trig = |t: f64| {
        let hip = hip_of(plan, d, t, s);
        hip.x >= ankle.x || (hip - ankle).length() >= reach * (1.0 - 1e-9)
    };
    let t_lo = plan.t_flat;
    let t_max = plan.t_stance - 0.25 * (plan.t_stance - t_lo);
    let n = 24;
    let mut found = t_max;
    let mut prev = t_lo;
    for i in 0..=n {
        let t = t_lo + (t_max - t_lo) * i as f64 / n as f64;
        if trig(t) {
            if i == 0 {
                found = t;
            } else {
                let (mut a, mut b) = (prev, t);
                for _ in 0..40 {
                    let m = 0.5 * (a + b);
                    if trig(m) {
                        b = m
                    } else {
                        a = m
                    }
                }
                found = b;
            }
            break;
        }
        prev = t;
    }
    plan.t_heel_off = found;
    let h0 = hip_of(plan, d, found, s);
    let (a0, _) = leg_ik(d, h0, ankle, 0.0, 0.0);
    let e = 1e-4;
    let tb = (found - e).max(0.0);
    let hb = hip_of(plan, d, tb, s);
    let (ab, _) = leg_ik(d, hb, ankle, 0.0, 0.0);
    let kr0 = if found > tb {
        (a0.knee - ab.knee) / (found - tb)
    } else {
        0.0
    };
    let dur = (plan.t_stance - found).max(1e-6);
    plan.heel_off = HeelOff {
        k0: a0.knee,
        k1: plan.eff.knee_toe_off,
        kr0,
        kr1: ((plan.eff.knee_toe_off - a0.knee) / dur).max(kr_to),
        m1: plan.eff.meta_toe_off,
        mr1: plan.eff.meta_toe_off / dur,
    };
}

/// Whether the stance hip stays within reach over the whole support (samples).
fn stance_reachable(plan: &StepPlan, d: &RunnerDims) -> bool {
    let n = 32;
    (0..=n).all(|i| {
        let t = plan.t_stance * i as f64 / n as f64;
        let hip = hip_of(plan, d, t, plan.s);
        !stance_leg(plan, d, t, hip).out_of_reach
    })
}

/// Stance-leg angles, rates and hip–ankle pitch at `t` (rates by a backward difference).
fn stance_state(plan: &StepPlan, d: &RunnerDims, t: f64) -> (LegAngles, LegAngles, f64) {
    let e = 1e-5;
    let hip = hip_of(plan, d, t, plan.s);
    let now = stance_leg(plan, d, t, hip);
    let hip_b = hip_of(plan, d, t - e, plan.s);
    let mode = match now.mode {
        StanceMode::HeelOff | StanceMode::HeelOffKneeRaised => Some(now.mode),
        _ => None,
    };
    let before = stance_leg_in(plan, d, t - e, hip_b, mode);
    let mut rate = LegAngles::default();
    for c in 0..5 {
        rate.set(c, (now.angles.get(c) - before.angles.get(c)) / e);
    }
    let ha = now.points.ankle - now.points.hip;
    (now.angles, rate, pitch_from_down(DVec2::new(ha.x, ha.y)))
}

/// Checks a swinging foot's clearance on a track over [t_a, t_b] and, where it stubs the
/// ground, adds a temporary knee flexion peaking at the worst instant (§3.3.1's recovery:
/// "inserts a new control point with temporarily increased knee flexion"), raised until the
/// foot clears. Returns the number of raises.
#[allow(clippy::too_many_arguments)]
fn clear_track(
    plan: &mut StepPlan,
    d: &RunnerDims,
    sign: f64,
    hind: bool,
    t_a: f64,
    t_b: f64,
    ramp_in: bool,
    ramp_out: bool,
    margin: f64,
) -> u32 {
    let n = 40;
    let worst = |plan: &StepPlan| {
        let track = if hind { &plan.hind } else { &plan.swing };
        let mut worst = (0.0, 0.0); // (deficit, t)
        for i in 1..n {
            let t = t_a + (t_b - t_a) * i as f64 / n as f64;
            let (ang, _) = track.eval(t);
            let pts = leg_fk(d, hip_of(plan, d, t, sign), &ang);
            // A twentieth of a millimetre of slack (numerical noise), so the foot is strictly off
            // the ground wherever the requirement is positive.
            let deficit =
                required_clearance(t, t_a, t_b, ramp_in, ramp_out, margin) - pts.lowest() - 0.00005;
            if deficit > worst.0 {
                worst = (deficit, t);
            }
        }
        worst
    };
    let (deficit, t_worst) = worst(plan);
    if deficit <= 0.0 {
        return 0;
    }
    // The bump's peak is kept off the window's ends so the extra flexion builds up smoothly.
    // A held bump (hind leg) may peak after the window: the next step inherits its value and
    // rate.
    let t_peak = if hind {
        t_worst.max(t_a + 0.5 * (t_b - t_a))
    } else {
        t_worst.clamp(t_a + 0.3 * (t_b - t_a), t_b - 0.3 * (t_b - t_a))
    };
    let mut raises = 0;
    let mut deficit = deficit;
    let lever = 0.5 * d.shank;
    while deficit > 0.0 && raises < 16 {
        let track = if hind {
            &mut plan.hind
        } else {
            &mut plan.swing
        };
        track.bump = KneeBump {
            t0: t_a,
            peak: t_peak,
            t1: t_b,
            amount: track.bump.amount + (deficit / lever).max(3f64.to_radians()),
            hold: hind,
        };
        raises += 1;
        deficit = worst(plan).0;
    }
    raises
}

/// The state at the end of a planned running step (the next heel strike).
pub fn carry_out(plan: &StepPlan, d: &RunnerDims) -> Carry {
    let s = plan.s;
    let t = plan.t_step;
    let (pelvis, pelvis_vel) = pelvis_at(plan, t);
    let (yaw, roll) = orient_at(plan, t);
    let (swing, swing_rate) = plan.hind.eval(t);
    let _ = d;
    Carry {
        stance_sign: -s,
        pelvis,
        pelvis_vel,
        yaw,
        roll,
        yaw_rate: plan.orient_rate[3].0,
        roll_rate: plan.orient_rate[3].1,
        stance_print: plan.next_print,
        other_print: plan.stance_print,
        swing,
        swing_rate,
        standing: false,
        sway_phase: plan.sway[3].1,
        upper: upper_attrs(&plan.eff),
        arm_back: plan.arm_back.1,
        arm_front: plan.arm_front.1,
        // The landing leg is π behind the leg that took off.
        arm_phase: (plan.arm_phase[2].1 - std::f64::consts::PI).rem_euclid(std::f64::consts::TAU),
        arm_phase_rate: plan.arm_phase[2].2,
    }
}

/// Plans the stop after the last landing: the pelvis decelerates to rest over the landed foot
/// while the other foot is carried forward and set down flat (a Cartesian ankle path with the
/// leg from inverse kinematics), ending in a stand. The paper's own stop ("the previous stance
/// phases for this leg are extended until HSL") is replaced by this; see the module docs.
pub fn plan_stop(d: &RunnerDims, carry: &Carry, eff: &Effective) -> StepPlan {
    let s = carry.stance_sign;
    let scale = d.body_height / 1.8;
    let v0 = carry.pelvis_vel.x.max(0.0);
    let fp = carry.stance_print;
    let stance_ankle = fp.flat_ankle(d);
    // The pelvis comes to rest STOP_STAGGER ahead of the stance ankle (the other foot lands as
    // far ahead of the pelvis, a short staggered stand). The stop lasts as long as a cubic with
    // the landing speed and zero final speed can take without moving backwards (Δx ≥ v·T/3),
    // capped at STOP_TIME.
    let x_end = stance_ankle.x + STOP_STAGGER * scale;
    let dx_total = (x_end - carry.pelvis.x).max(0.02 * scale);
    let t_stop = if v0 > 1e-6 {
        (2.9 * dx_total / v0).min(STOP_TIME * scale.sqrt())
    } else {
        STOP_TIME * scale.sqrt()
    }
    .max(0.25);
    let dz = d.hip_offset.z - eff.stride_width / 2.0;
    // Come to rest with the knees a little bent, so both legs reach the ground throughout.
    let dd = d.hip_ankle(STOP_KNEE);
    let dx = STOP_STAGGER * scale;
    let y_hip = d.ankle_height + (dd * dd - dz * dz - dx * dx).max(0.0).sqrt();
    let y_end = y_hip - d.hip_offset.y;
    let p_end = DVec3::new(x_end, y_end, 0.0);
    let final_print = Footprint {
        heel: DVec3::new(
            2.0 * x_end - stance_ankle.x - d.heel_back,
            0.0,
            -s * eff.stride_width / 2.0,
        ),
        strike: eff.strike,
        impact_pitch: 0.0,
    };
    // Two spline segments like a support phase: through a mid-support point over the stance
    // foot (lateral displacement toward it, as in Fig. 7) to rest centred between the feet.
    let lat = eff.lateral_displacement;
    let mut p_mid = DVec3::new(
        0.5 * (carry.pelvis.x + x_end),
        carry.pelvis.y.min(y_end),
        s * lat,
    );
    let h = 0.5 * t_stop;
    // The mid-support velocity depends only on the ends, so recovery 1 below only moves p_mid.
    let v_mid = c2_mid_velocity(carry.pelvis, p_end, carry.pelvis_vel, DVec3::ZERO, h);
    let support_through = |p_mid: DVec3| {
        [
            Seg3 {
                t0: 0.0,
                t1: h,
                p0: carry.pelvis,
                p1: p_mid,
                v0: carry.pelvis_vel,
                v1: v_mid,
            },
            Seg3 {
                t0: h,
                t1: t_stop,
                p0: p_mid,
                p1: p_end,
                v0: v_mid,
                v1: DVec3::ZERO,
            },
        ]
    };
    let support = support_through(p_mid);
    let t_flat = (0.12 * scale.sqrt()).min(0.4 * t_stop);
    let mut plan = StepPlan {
        kind: StepKind::Stop,
        s,
        t_step: t_stop,
        t_stance: t_stop,
        t_flight: 0.0,
        t_ms: 0.5 * t_stop,
        t_flat,
        t_heel_off: t_stop,
        support,
        nseg: 2,
        flight_p1: p_end,
        flight_v: DVec3::ZERO,
        orient: [
            (0.0, carry.yaw, carry.roll),
            (0.5 * t_stop, 0.0, 0.0),
            (t_stop, 0.0, 0.0),
            (t_stop, 0.0, 0.0),
        ],
        orient_rate: [
            (carry.yaw_rate, carry.roll_rate),
            (0.0, 0.0),
            (0.0, 0.0),
            (0.0, 0.0),
        ],
        norient: 3,
        stance_print: fp,
        next_print: final_print,
        other_print: carry.other_print,
        heel_off: HeelOff::default(),
        hind: Track::new(),
        swing: Track::new(),
        eff: *eff,
        upper0: carry.upper,
        sway: [
            (0.0, carry.sway_phase),
            (t_stop, carry.sway_phase),
            (t_stop, carry.sway_phase),
            (t_stop, carry.sway_phase),
        ],
        arm_back: (carry.arm_back, carry.arm_back),
        arm_front: (carry.arm_front, carry.arm_front),
        // The arms keep their rhythm while they fade out (`upper_body::fill_upper`).
        arm_phase: {
            let end = carry.arm_phase + carry.arm_phase_rate * t_stop;
            [
                (0.0, carry.arm_phase, carry.arm_phase_rate),
                (t_stop, end, carry.arm_phase_rate),
                (t_stop, end, carry.arm_phase_rate),
            ]
        },
        speed: 0.0,
        step_length: 0.0,
        step_freq: 0.0,
        stop: StopPath::default(),
        report: StepReport {
            t_stance: t_stop,
            ..StepReport::default()
        },
    };
    // Recovery 1 as in a running step: lower the mid-support point while the stance hip is
    // out of reach.
    while !stance_reachable(&plan, d) && plan.report.mid_support_lowered < 12 {
        p_mid.y -= 0.01 * scale;
        plan.support = support_through(p_mid);
        plan.report.mid_support_lowered += 1;
    }
    // The swing foot: ankle from where it is now, up and forward, down onto its footprint.
    let hip0 = hip_at(d, carry.pelvis, carry.yaw, carry.roll, -s);
    let pts0 = leg_fk(d, hip0, &carry.swing);
    let e = 1e-4;
    let mut ahead = carry.swing;
    for c in 0..5 {
        ahead.set(c, carry.swing.get(c) + e * carry.swing_rate.get(c));
    }
    let hip_e = hip_at(
        d,
        carry.pelvis + e * carry.pelvis_vel,
        carry.yaw,
        carry.roll,
        -s,
    );
    let va0 = (leg_fk(d, hip_e, &ahead).ankle - pts0.ankle) / e;
    let land = final_print.flat_ankle(d);
    let t_land = 0.8 * t_stop;
    let mid = DVec3::new(
        0.5 * (pts0.ankle.x + land.x),
        pts0.ankle.y.max(land.y) + 0.06 * d.body_height / 1.8,
        0.5 * (pts0.ankle.z + land.z),
    );
    let vmid = DVec3::new(
        (land.x - pts0.ankle.x) / t_land,
        0.0,
        (land.z - pts0.ankle.z) / t_land,
    );
    plan.stop = StopPath {
        ankle: [
            Seg3 {
                t0: 0.0,
                t1: 0.5 * t_land,
                p0: pts0.ankle,
                p1: mid,
                v0: va0,
                v1: vmid,
            },
            Seg3 {
                t0: 0.5 * t_land,
                t1: t_land,
                p0: mid,
                p1: land,
                v0: vmid,
                v1: DVec3::new(0.0, -0.3, 0.0),
            },
        ],
        t_land,
        pitch0: carry.swing.foot_pitch(),
        meta0: carry.swing.meta,
        print: final_print,
    };
    plan
}

/// The mode of the stance foot at `t` of a planned step (for events and reports).
pub fn stance_mode(plan: &StepPlan, d: &RunnerDims, t: f64) -> StanceMode {
    let hip = hip_of(plan, d, t, plan.s);
    stance_leg(plan, d, t, hip).mode
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::generator::running::attributes::{Drivers, RunAttributes};

    #[test]
    fn toe_off_radius_matches_forward_kinematics() {
        let d = RunnerDims::from_height(1.8).unwrap();
        let (k, a, m) = (0.35, -0.6, 0.5);
        let rad = toe_off_radius(&d, k, a, m, 0.0).unwrap();
        for pitch in [-0.5, -0.2, 0.1] {
            let ang = LegAngles {
                pitch,
                roll: 0.0,
                knee: k,
                ankle: a,
                meta: m,
            };
            let p = leg_fk(&d, DVec3::ZERO, &ang);
            assert!(((p.toe - p.hip).length() - rad).abs() < 1e-12);
        }
    }

    #[test]
    fn case_two_inverts_case_one() {
        let d = RunnerDims::from_height(1.8).unwrap();
        let attrs = RunAttributes::defaults(1.8);
        let v = 12.0 / 3.6;
        let sl = 1.0694;
        let sf = v / sl;
        let eff = attrs.effective(&Drivers {
            speed: v,
            step_length: sl,
            step_freq: sf,
            flight_height: 0.004,
        });
        let mut carry = standing_carry(&d, &eff, 0.0, 1.0, f64::INFINITY);
        carry.standing = false;
        carry.pelvis_vel = DVec3::new(v, -1.0, 0.0);
        let inp = StepInput {
            speed: v,
            step_length: sl,
            step_freq: sf,
            flight: FlightSpec::Time(0.188),
            eff,
            next_eff: eff,
            p: 0.75,
        };
        let one = plan_step(&d, &inp, &carry, StepKind::Normal).unwrap();
        let h = one.report.flight_height;
        let inp2 = StepInput {
            flight: FlightSpec::Height(h),
            ..inp
        };
        let two = plan_step(&d, &inp2, &carry, StepKind::Normal).unwrap();
        assert_eq!(two.report.case, Some(FlightCase::II));
        assert!((two.t_flight - 0.188).abs() < 1e-9, "{}", two.t_flight);
        assert!((two.report.p1 - one.report.p1).length() < 1e-9);
    }
}
