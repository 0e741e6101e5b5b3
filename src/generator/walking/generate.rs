//! The walk, step by step (§2.4): for each step the high level is executed first (step
//! constraints), then the stance phase is simulated, the determinants of gait are applied to the
//! pelvis, the trailing leg's stance is completed kinematically through the double support, the
//! swing leg is simulated from toe-off to heel strike, and heel strike (a collision) gives the
//! next stance phase its initial conditions. Finally every frame of the [`Motion`] is assembled
//! from the recorded trajectories: pelvis, virtual stance leg, swing leg, kinematic feet, spine
//! and arms.
use super::attributes::WalkAttributes;
use super::body::Body;
use super::collision::{self, SwingAtImpact};
use super::dynamics::{HipMotion, StanceModel};
use super::foot::FootShape;
use super::high_level::{heel_strike, phase_times, Locomotion, PhaseTimes, WalkRelations};
use super::stance::{StanceRun, StanceSpec, StanceStart};
use super::stop::{Closing, StopStart};
use super::swing::{SwingCarry, SwingRun, SwingSpec, SwingStart};
use super::virtual_leg::{
    smooth_roll, FootPeriod, LegPose, VirtualLeg, KNEE_SOFT, TOE_OFF_KNEE_RATE,
};
use crate::events::{EventKind, EventSource, Gait, GaitEvent, Side};
use crate::generator::curves::smoothstep;
use crate::generator::ik::leg_ik;
use crate::generator::motion::{Motion, MotionMetadata};
use crate::generator::skeleton::{Euler, Joint, Skeleton};
use crate::generator::GenerateError;
use glam::{DQuat, DVec3};
use std::f64::consts::PI;

/// How a walk is to be generated (besides its steps).
#[derive(Debug, Clone, PartialEq)]
pub struct WalkOptions {
    /// Body height, m.
    pub height_m: f64,
    /// Body mass, kg.
    pub mass_kg: f64,
    /// Locomotion attributes.
    pub attributes: WalkAttributes,
    /// The walking relations (published or fitted).
    pub relations: WalkRelations,
    /// Output frame rate, frames/s.
    pub fps: f64,
    /// Start from standing, feet side by side: the first step starts from rest (its swing foot
    /// travels one step length, half a stride), and frame 0 is that first step's start.
    /// Otherwise the walk starts steady, as a motion-capture trial of steady walking does:
    /// [`PRE_ROLL`] unrecorded steps are simulated before it, and the recording begins
    /// mid-motion [`LEAD_IN_FRAMES`] frames before the first heel strike (frame 0 at t = 0,
    /// the first heel strike at `LEAD_IN_FRAMES / fps`, events and [`StepReport::start_s`] on
    /// the same clock), in the last pre-roll step's landing swing.
    pub start_from_rest: bool,
    /// End standing: a last half step, then the trailing foot is brought alongside and the body
    /// comes to rest ([`super::stop`]). Otherwise the walk ends mid-motion: one unrecorded step
    /// is simulated after the last, and the recording ends [`LEAD_OUT_FRAMES`] frames after the
    /// trailing foot's toe off that follows the last heel strike.
    pub stop: bool,
}

impl Default for WalkOptions {
    fn default() -> Self {
        WalkOptions {
            height_m: 1.8,
            mass_kg: 75.0,
            attributes: WalkAttributes::default(),
            relations: WalkRelations::published(),
            fps: 100.0,
            start_from_rest: false,
            stop: false,
        }
    }
}

/// What happened in one step: its constraints, the shooting effort and how well each phase met
/// its final conditions.
#[derive(Debug, Clone, PartialEq)]
pub struct StepReport {
    /// Step number (0-based).
    pub index: usize,
    /// The stance leg.
    pub stance_side: Side,
    /// Start time (heel strike of the stance leg), s from frame 0 (the motion's clock: a
    /// steady walk's first step starts at `LEAD_IN_FRAMES / fps`, see
    /// [`WalkOptions::start_from_rest`]).
    pub start_s: f64,
    /// Commanded step length, m.
    pub step_length_m: f64,
    /// Commanded step frequency, steps/min.
    pub step_freq_steps_per_min: f64,
    /// Phase durations.
    pub times: PhaseTimes,
    /// Shooting simulations: stance, swing1, swing2, swing3.
    pub iterations: [usize; 4],
    /// Force parameters: stance `F_θ1` magnitude (N·m), extension amplitude `P` (m), swing
    /// torque amplitudes `A`, `B`, `C` (N·m).
    pub forces: [f64; 5],
    /// Final-condition errors: stance `w` (m), stance `θ1`, `θ3` at t1, `θ4` at t2, `θ3` at
    /// heel strike (rad).
    pub errors: [f64; 5],
    /// Rounds of the swing2 ground-stubbing recovery.
    pub recovery_rounds: usize,
    /// Final set-point shift of swing2's ground-stubbing recovery (§4.3), rad: 0 when the foot
    /// cleared the ground without it, at most [`super::swing::RECOVERY_MAX_RAD`].
    pub recovery_rad: f64,
    /// Lowest swing-foot clearance, m.
    pub min_clearance_m: f64,
    /// When the stance leg was locked / passed the vertical, s from the step's start.
    pub lock_s: Option<f64>,
    /// End of the swing's swing1 (the knee slaved to the ankle curve), as a fraction of the
    /// swing: the paper's t1, `WalkAttributes::swing1_end`, except for the first swing from
    /// standing (`first_swing_shape`, private: a continuous function of the walk's speed over
    /// body height) and the stop's last swing.
    pub swing1_end: f64,
    /// The swing1 ankle curve's lift (`SwingSpec::ankle_lift`), m: the paper's
    /// `WalkAttributes::ankle_lift_m`, except for the first swing from standing
    /// (`first_swing_shape`) and the stop's last swing.
    pub ankle_lift_m: f64,
}

/// The report of a generated walk.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct WalkReport {
    /// One entry per dynamic step.
    pub steps: Vec<StepReport>,
    /// Notes (start, stop, recoveries).
    pub notes: Vec<String>,
}

impl WalkReport {
    /// Total shooting simulations per phase kind: stance, swing1, swing2, swing3.
    pub fn total_iterations(&self) -> [usize; 4] {
        let mut t = [0; 4];
        for s in &self.steps {
            for (ti, si) in t.iter_mut().zip(s.iterations) {
                *ti += si;
            }
        }
        t
    }
}

/// The pelvic determinants of gait during one step (§4.2), as functions of the time since the
/// step's heel strike: rotation ψ (the swing hip ahead of the stance hip; −ψmax at the start,
/// +ψmax at heel strike), list λ (swing side down; 0 at heel strike, maximal at mid-step),
/// lateral displacement toward the stance foot (0 at heel strike). The paper interpolates them
/// linearly between their boundary values; the swing hip's *acceleration* drives the swing
/// dynamics, which a piecewise-linear path would make impulsive at the knots, so a half-cosine
/// (C¹, same boundary values) is used instead.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Determinants {
    /// Step duration, s.
    pub duration: f64,
    /// Maximal rotation, rad.
    pub rotation: f64,
    /// Maximal list, rad.
    pub list: f64,
    /// Maximal lateral displacement, m.
    pub lateral: f64,
    /// Half the pelvis width, m.
    pub half_width: f64,
    /// The swing side.
    pub swing: Side,
    /// First step from rest (rotation starts at 0).
    pub from_rest: bool,
    /// Last step to rest (rotation ends at 0).
    pub to_rest: bool,
}

impl Determinants {
    fn side_sign(s: Side) -> f64 {
        match s {
            Side::Left => -1.0,
            Side::Right => 1.0,
        }
    }
    /// ψ(t).
    pub fn rotation_at(&self, t: f64) -> f64 {
        let c = (PI * (t / self.duration).clamp(0.0, 1.0)).cos();
        let (a, b) = (
            if self.from_rest { 0.0 } else { -self.rotation },
            if self.to_rest { 0.0 } else { self.rotation },
        );
        a + (b - a) * 0.5 * (1.0 - c)
    }
    /// λ(t).
    pub fn list_at(&self, t: f64) -> f64 {
        self.list * (PI * (t / self.duration).clamp(0.0, 1.0)).sin().powi(2)
    }
    /// Lateral position of the pelvis centre (toward the stance foot), m.
    pub fn lateral_at(&self, t: f64) -> f64 {
        -Determinants::side_sign(self.swing)
            * self.lateral
            * (PI * (t / self.duration).clamp(0.0, 1.0)).sin()
    }
    /// Pelvis orientation (figure convention) at `t`.
    pub fn pelvis(&self, t: f64) -> DQuat {
        let s = Determinants::side_sign(self.swing);
        Euler::new(0.0, s * self.list_at(t), s * self.rotation_at(t)).to_quat()
    }
    /// Offset of the swing hip from the pelvis centre, m.
    pub fn swing_offset(&self, t: f64) -> DVec3 {
        self.pelvis(t)
            * DVec3::new(
                0.0,
                0.0,
                Determinants::side_sign(self.swing) * self.half_width,
            )
    }
    /// Swing hip minus the dynamic hip in the sagittal plane `(dx, dy)` (the stance hip is at
    /// `(−dx_offset, 0)`; see [`Determinants::swing_offset`]): with the pelvis rotation
    /// `Rx(±λ)·Ry(±ψ)`, `(a·sin ψ, −2a·cos ψ·sin λ)`, `a` half the pelvis width.
    pub fn swing_hip_offset(&self, t: f64) -> [f64; 2] {
        let (sp, cp) = self.rotation_at(t).sin_cos();
        let a = self.half_width;
        [a * sp, -2.0 * a * cp * self.list_at(t).sin()]
    }

    /// [`Determinants::swing_hip_offset`] and its first and second time derivatives, analytic
    /// (the swing dynamics read the swing hip's acceleration).
    pub fn swing_hip_offset_rates(&self, t: f64) -> ([f64; 2], [f64; 2], [f64; 2]) {
        let a = self.half_width;
        let s = t / self.duration;
        let inside = (0.0..=1.0).contains(&s);
        let w = PI / self.duration;
        let (s1, c1) = (PI * s.clamp(0.0, 1.0)).sin_cos();
        let (s2, c2) = (2.0 * PI * s.clamp(0.0, 1.0)).sin_cos();
        let (pa, pb) = (
            if self.from_rest { 0.0 } else { -self.rotation },
            if self.to_rest { 0.0 } else { self.rotation },
        );
        let psi = pa + (pb - pa) * 0.5 * (1.0 - c1);
        let lam = self.list * 0.5 * (1.0 - c2);
        let (psi1, psi2, lam1, lam2) = if inside {
            (
                (pb - pa) * 0.5 * w * s1,
                (pb - pa) * 0.5 * w * w * c1,
                self.list * w * s2,
                self.list * 2.0 * w * w * c2,
            )
        } else {
            (0.0, 0.0, 0.0, 0.0)
        };
        let (sp, cp) = psi.sin_cos();
        let (sl, cl) = lam.sin_cos();
        let pos = [a * sp, -2.0 * a * cp * sl];
        let vel = [a * cp * psi1, -2.0 * a * (-sp * psi1 * sl + cp * cl * lam1)];
        let acc = [
            a * (cp * psi2 - sp * psi1 * psi1),
            -2.0 * a
                * (-cp * psi1 * psi1 * sl - sp * psi2 * sl - 2.0 * sp * psi1 * cl * lam1
                    + cp * (-sl * lam1 * lam1 + cl * lam2)),
        ];
        (pos, vel, acc)
    }
}

struct StepData {
    /// Whether the swing was braked (`SwingSpec::knee_brake`): only then is the drawn swing
    /// ankle moved to the model's knee span (`swing_span_target`).
    knee_brake: bool,
    side: Side,
    start: f64,
    loc: Locomotion,
    times: PhaseTimes,
    ankle_x: f64,
    det: Determinants,
    stance: StanceRun,
    swing: SwingRun,
    swing_foot: super::swing::SwingFoot,
    swing_times: [f64; 4],
    /// Virtual-leg roll samples of the stance leg over the step (time from step start, ρ).
    stance_rho: Vec<(f64, f64)>,
    /// The stance leg's hip (sagittal x, y) and lateral offset from its foot at each
    /// `stance_rho` sample.
    stance_hips: Vec<([f64; 2], f64)>,
    stance_leg: VirtualLeg,
    /// Trailing leg over the double support.
    trail_rho: Vec<(f64, f64)>,
    /// The trailing leg's hip (sagittal x, y) and lateral offset from its foot at each
    /// `trail_rho` sample.
    trail_hips: Vec<([f64; 2], f64)>,

    trail_leg: VirtualLeg,
    /// Global time of the trailing leg's clock origin, s.
    trail_origin: f64,
}

/// Linear interpolation of `(t, ρ)` roll samples at `t`, held at the end values outside them
/// (the walk's frames and the stop read the virtual legs' recorded rolls this way).
pub(super) fn interp_rho(samples: &[(f64, f64)], t: f64) -> f64 {
    if samples.is_empty() {
        return 0.0;
    }
    let k = samples.partition_point(|s| s.0 <= t);
    if k == 0 {
        return samples[0].1;
    }
    if k >= samples.len() {
        return samples[samples.len() - 1].1;
    }
    let (a, b) = (samples[k - 1], samples[k]);
    if b.0 == a.0 {
        return b.1;
    }
    a.1 + (b.1 - a.1) * (t - a.0) / (b.0 - a.0)
}

fn num_err(stage: String, message: String) -> GenerateError {
    GenerateError::Numerical { stage, message }
}

/// How many times the projected reach (`StanceSpec::flat_reach`) the leg spring's rest length is
/// shortened by in the slowest walks (Froude speed `v/√(g·l1)` up to [`SLOW_REST_FROUDE`]`[0]`),
/// blending (smoothstep in Froude) to once the reach at [`SLOW_REST_FROUDE`]`[1]` and above.
///
/// Why: below Froude 0.16 (≈ 1.7 km/h at 1.8 m) the leg lands 12–14 mm longer than `l1` and
/// turns within a millimetre of it, so the stance locked at the paper's straight leg and the
/// drawn 3-D leg could not reach its flat foot: the stance heel rose at once after foot flat
/// and hovered through midstance: 83 of 121 walks over 1 mm, 1.5–6.1 mm (1.0–2.0 km/h every
/// 0.1 × 1.5–2.0 m every 5 cm; 1 km/h heel up 1 mm at 5–8 % of the cycle). The projected lock
/// with the rest length shortened by once the reach (as at 2 km/h) left 1.1–2.4 mm; twice the
/// reach, ramped in over the first [`super::stance::REST_RAMP_IN_SLOW`] = 10 % of the stance,
/// keeps it down: ≤ 0.09 mm over 1.0–2.5 km/h × 1.5–2.0 m every 5 cm except 1.4 km/h × 1.6 m
/// (3.98 mm: its rocker landing, chosen by the slow-start rule of
/// `VirtualLeg::plan_heel_rocker` at a threshold, reaches foot flat with the knee still
/// flexing at 4.9 rad/s; down since the knee ease is bounded by the flat foot's knee,
/// `virtual_leg::KNEE_ROCKER_EASE`), the heel rising at 33–36 % of the cycle at 1 km/h (human
/// 30–40 %). Measured cost (continuity, k = 5; 1.0–2.5 km/h every
/// 0.05 × 1.5–2.0 m every 5 cm, 341 steady walks and 176 from standing with a stop): alone,
/// 0 → 2 and 1 → 1 walks over 5 (1.05 km/h × 1.50 m 5.12, 1.10 × 1.55 m 5.08 steady and 5.09
/// from standing, l_knee: the trailing knee, see `hold_knees`; the stop's 1.8 km/h × 2.0 m 5.14
/// gone with `edge_lock`), 40 steady walks over 4.5 (1 before); with `hold_knees`' relaxed
/// floor none over 5 (worst 4.27 and 4.69). The midstance knee is more flexed: 1 km/h ×
/// 1.5/1.8/2.0 m 7.5/2.8/1.2° → 10.6/9.1/8.1° (as at 2–3 km/h, 9–12°). The default events'
/// double support at 1.5 km/h × 1.6 m comes out +32.3 ms long (+12.8 before; the limit there
/// is 10 % = 36.6 ms: the lower hip through the double support). Earlier
/// attempts (session 9, before the heel rocker's `DIP_TRADE` = 3 and the last stance's lock)
/// broke the last stance before a stop (10.06) and a first trailing leg (24.7).
pub const SLOW_REST_REACH: f64 = 2.0;

/// Froude speeds between which [`SLOW_REST_REACH`] blends to once the reach (see there).
pub const SLOW_REST_FROUDE: [f64; 2] = [0.14, 0.20];

/// Froude speed below which a stance that locks at the projected length
/// ([`PROJECTED_LOCK_FROUDE_MAX`]) also shortens its leg spring's rest length by the reach
/// ([`SLOW_REST_REACH`] × it in the slowest walks)
/// (`StanceSpec::rest_reach`, ramped in over the first 20 % of the stance and out from its
/// middle: `stance::REST_RAMP_IN`/`REST_RAMP_OUT`).
///
/// Why: at 2 km/h (Froude 0.19–0.21) the projected lock alone left the stance heel 0.4–0.8 mm
/// up, with the rest length ≤ 0.29 mm (2.3–5.5 mm before either; `tests/klaw_foot_flat.rs`).
/// Why not above: there the lock alone keeps the heel down, and the shorter rest length
/// (kept to the end of the stance) raised 3 km/h × 1.5/2.0 m's worst continuity ratio
/// 3.32/3.13 → 4.09/3.72 (landing knees).
pub const REST_SHORTENING_FROUDE_MAX: f64 = 0.24;

/// Froude speed up to which the stance leg locks at the projected length (≈ 7 km/h at 2.0 m);
/// above it the drawn knee takes the same reach instead (`StanceSpec::flat_reach`, through
/// `StanceSpec::drawn_span`: the midstance knee drawn with the 3-D leg's flexion), so the
/// stance heel stays down at every speed.
///
/// Why not the lower lock above: its lower hip makes the arms jolt harder at heel strike
/// (the shoulder's step at 7 km/h × 1.8 m, frame 287 before the lead-out: 0.0072 → 0.0107
/// rad). Measured (8 steps, with the lead-in and lead-out frames): 7 km/h ×
/// 1.5/1.8 m 5.95/4.01 → 6.17/4.45, the worst frame at a shoulder in all four; before the
/// lead-out, 7 km/h × 1.8 m's last frame went 6.48 → 9.48.
pub const PROJECTED_LOCK_FROUDE_MAX: f64 = 0.65;

/// Whether a stance at `speed` m/s of a body with unloaded leg `l1` locks at the sagittal
/// projection of the drawn leg (below [`PROJECTED_LOCK_FROUDE_MAX`]): not on the first step from
/// standing (`from_rest`), nor on the last before a stop (`to_rest`) at or above
/// [`REST_SHORTENING_FROUDE_MAX`], whose own rules keep their measured landings (see
/// [`edge_lock`]).
fn projected_lock(speed: f64, l1: f64, from_rest: bool, to_rest: bool) -> bool {
    let froude = super::stance::froude_speed(speed, l1);
    !from_rest && (!to_rest || edge_lock(froude)) && froude < PROJECTED_LOCK_FROUDE_MAX
}

/// The weight of the slowest walks' settings ([`SLOW_REST_REACH`],
/// [`super::stance::REST_RAMP_IN_SLOW`]) at Froude speed `froude`: 1 up to
/// [`SLOW_REST_FROUDE`]`[0]`, 0 from [`SLOW_REST_FROUDE`]`[1]`, a smoothstep between.
fn slowness(froude: f64) -> f64 {
    let [lo, hi] = SLOW_REST_FROUDE;
    smoothstep(((hi - froude) / (hi - lo)).clamp(0.0, 1.0))
}

/// Whether the last stance before a stop locks at the projected length (and shortens its rest
/// length) like the walk's: in slow walks (Froude below [`REST_SHORTENING_FROUDE_MAX`]).
///
/// Why: a slow walk's stances all lower the hip ([`SLOW_REST_REACH`]); a last stance that kept
/// the paper's lock landed its knee from the lower hip into a straight leg (1 km/h × 2.0 m from
/// standing with a stop 5.67, r_knee; the stop's landing ankle at 1.8 km/h × 2.0 m 5.14 → 4.35,
/// 3.27 since `hold_knees` relaxes its floor).
/// Faster, the last stance keeps the paper's lock: locking it raised 7 km/h × 1.5 m's stop
/// 3.36 → 4.2.
fn edge_lock(froude: f64) -> bool {
    froude < REST_SHORTENING_FROUDE_MAX
}

fn side_z(side: Side, a: &WalkAttributes) -> f64 {
    match side {
        Side::Left => -0.5 * a.stride_width_m,
        Side::Right => 0.5 * a.stride_width_m,
    }
}

/// Shortest meta-off knee flexion, as a fraction of the double support (see
/// [`VirtualLeg::min_knee_blend`]).
const MIN_KNEE_BLEND: f64 = 0.3;

/// Window over which the stance ankle's rate just after heel strike is measured, s.
const CONTACT_RATE_WINDOW: f64 = 0.01;

/// Largest ankle rate |θ̇5| the swing foot is given at heel strike, rad/s.
///
/// The stance ankle's rate just after heel strike is large (5–15 rad/s at 5–7 km/h: the
/// dynamics' hip closes on the heel at ≈ 1–1.4 m/s along the leg and the straight knee cannot
/// take it up, so the foot must roll about the heel), while the swing foot used to arrive with
/// its ankle at rest — a one-frame spike of the ankle's rotation (continuity ratios 10–20).
/// Matching the rate in full would need the swing ankle to dorsiflex 5–8° and snap back at
/// 9–15 rad/s in the last 60 ms before contact, which no walker does.
///
/// 6 rad/s (was 3; klawhs, issue 6): the top of a human ankle's plantarflexion rate in loading
/// response at brisk walking speeds, reached only at the contact (swing3's cubic, see
/// `SwingFoot::theta56`); the ankle first dorsiflexes ≈ 1.5° more than the paper's
/// interpolation in swing3 (5 km/h, 1.8 m: 0.027 rad, against ≈ 0.01 at 3 rad/s). The three
/// frames before the contact then carry part of the stance foot's roll, so the landing ankle's
/// steps rise into the contact instead of jumping (worst ratio, 8 steps, 1.5/1.8/2.0 m: 4 km/h
/// 6.98/4.73/4.33 → 6.58/4.22/3.31, 5 km/h 9.92/6.01/5.26 → 9.29/4.74/4.31 — 1.8 and 2.0 m now
/// meet k = 5 —, 6 km/h 11.3/7.96/10.5 → 10.7/6.46/10.5, 7 km/h 12.4/10.8/7.82 →
/// 11.0/10.2/6.15; frame 0 of a steady start, which has no pre-contact frames, is now the worst
/// at 4–6 km/h and is unchanged). 10 rad/s took 7 km/h × 1.8 m's heel strikes further (≤ 7.2)
/// but is beyond what a human ankle does just before contact; not taken. The swing ankle's
/// rate rises to it over the last 4–6 frames before the contact
/// ([`super::swing::SwingFoot::contact_ramp`], klawhs2), not within the last one or two.
pub const MAX_CONTACT_ANKLE_RATE: f64 = 6.0;

/// Weight of the swing ankle's contact ramp ([`super::swing::SwingFoot::contact_ramp`]) for a
/// landing whose stance ankle turns at `rate` rad/s just after heel strike: 0 up to
/// [`MAX_CONTACT_ANKLE_RATE`] (the swing3 cubic matches such a rate in full, and the paper's
/// ending is kept), rising linearly to 1 at twice it.
///
/// Why: the ramp is needed where the stance roll outruns the swing ankle's cap — the fast walks
/// of short bodies (measured |rate| 12–17.5 rad/s at 5–7 km/h × 1.5 m, 13.3 at 7 km/h × 1.8 m,
/// 10–12 at the 5 km/h steps of the 2 → 5 → 3 km/h schedule at 1.5 m); in slower walks
/// (3 km/h × 1.7 m: 6.75, 4–5 km/h × 1.8–2.0 m: 6.6–8.0) the full ramp plantarflexed the ankle
/// earlier than needed and the heel slowed earlier before contact: the default (foot-speed)
/// events saw the double support at 3 km/h × 1.7 m 31 ms too long (`klaw_events`, within
/// 30 ms before).
pub fn contact_ramp_weight(rate: f64) -> f64 {
    ((rate.abs() - MAX_CONTACT_ANKLE_RATE) / MAX_CONTACT_ANKLE_RATE).clamp(0.0, 1.0)
}

/// How much later (fraction of the swing) swing1 ends in the last step before a stop, a half
/// step whose swing foot travels 1.5 step lengths to a heel strike only half a step ahead.
///
/// Near the end of swing1 its ankle curve falls about as steeply as the circle the ankle can
/// reach about the knee, and the slaved knee slid the ankle down the curve's far flank at up to
/// 5.6 m/s (the standing-start schedule 2 → 5 → 3 km/h at 1.8 m: knee ratio 10.9 three frames
/// before t1, once the first step no longer carried its curve lift into every later swing).
/// Measured, not derived: ends at 50/55/58/60 % of the swing gave that swing's ankle peak/mean
/// speed at 2 km/h 5.95/6.17/4.97/4.74 and the schedule's worst ratio 10.9/7.2/7.2/7.2, but the
/// 7 km/h × 1.8 m stop's heel landing 4.7/5.5/5.8/7.0; 40 % was worse everywhere.
const STOP_SWING1_DELAY: f64 = 0.05;

/// Fraction of the ankle curve's lift (`ankle_lift_m`, §4.3's `a_max` over the curve's higher
/// end) kept in the last step before a stop.
///
/// That half step's swing ankle leaves from a high heel (toe off, ≈ 15 cm at 2 km/h × 1.5 m) and
/// ends swing1 lower (≈ 10 cm), so the full lift put the curve's far flank about along the
/// circle the ankle can reach about the knee (slope ≈ −1 against the shank's −1.1 there): the
/// slaved knee still swept the ankle 11 cm forward in two frames at 4.7 m/s just before t1
/// (2 km/h × 1.5 m: knee ratio 15.0), which `STOP_SWING1_DELAY` alone did not remove. Half
/// the lift flattens the flank; the swing1 clearance rounds still raise the curve wherever the
/// toe needs it. Measured, not derived (worst ratio over that half step, steady start + stop,
/// 1.5/1.8/2.0 m): full lift 1 km/h 5.8/6.3/6.4, 2 km/h 15.0/8.7/6.5, 3 km/h 6.0/4.8/6.3;
/// half 4.5/5.5/3.3, 4.6/6.6/6.5, 4.6/4.8/5.6 (a quarter or none: the same within 0.05;
/// 5–7 km/h unchanged).
const STOP_LIFT: f64 = 0.5;

/// How much shorter than the soft knee's straight limit the standing legs are, m (floating-point
/// margin, so that the standing feet are flat, not rolled by 1e-12).
const STAND_MARGIN: f64 = 1e-4;

/// Unrecorded steps simulated before a steady (not from rest) start.
///
/// 2 (was 1; klawlead, issue 6): the recording now begins [`LEAD_IN_FRAMES`] before the first
/// heel strike, so it draws the last pre-roll step's swing. With one pre-roll step that swing
/// left a trailing foot that had no history (the first simulated step's, placed, not walked),
/// and the first recorded heel strike's ankle spike was 0.4–0.8 above the walk's later heel
/// strikes at the same sub-frame phase (8 steps, 5 km/h × 1.5 m, 6 km/h × 1.5 m, 7 km/h ×
/// 1.8 m, phases 0–0.8 of a frame); with two it is within ±0.1 of them. Costs one simulated
/// step per steady walk.
pub const PRE_ROLL: usize = 2;

/// Frames a steady (not from rest) walk's recording begins before its first heel strike: frame
/// 0 is at t = 0, the first heel strike at t = `LEAD_IN_FRAMES / fps` (a whole number of frames,
/// so every later frame samples the walk at the same phase as with no lead-in), drawn from the
/// last pre-roll step ([`PRE_ROLL`]) — its swing leg's swing3 (knee locked, landing), its
/// stance leg's heel-off roll. A clip of steady walking thus starts mid-motion, as a
/// motion-capture trial does, and its first heel strike is judged like every other.
///
/// Why 5 (50 ms at 100 frames/s), measured with `checks::continuity` (8 steps, 1–7 km/h ×
/// 1.5/1.8/2.0 m, 100 frames/s): a frame 0 has no earlier frames, so the check's window there
/// is one-sided, and whatever comes to rest or turns within the first 3 frames fails it; only
/// a stretch of the gait where nothing does can start a clip. The first heel strike needs 4
/// frames before it (the landing heel comes to rest at the contact; with 3, frame 2's heel
/// measured 4.2–32.8 against a window of rest); with 4, 6 km/h × 2.0 m's trailing knee
/// measured 3.70 at frame 1 (3.50 elsewhere); 5 and 6 gave the same table; 10 put frame 0 in
/// late swing2, where the swing knee brakes into its lock (2–5 km/h: knee 6.4–52 at frames
/// 0–2); half the swing (whole frames) left 3 km/h × 1.8 m's shoulder turning at frame 0
/// (4.33, 3.30 elsewhere). The shortest clean lead-in is taken: at 100 frames/s it lies within
/// swing3 (56–111 ms on the natural walks at 1–7 km/h, knee locked) and adds 50 ms to the
/// recording. It is a number of frames, not a time: 5 frames were as clean at 120 and
/// 250 frames/s; at 60 frames/s they reach back into swing2's knee brake (frame 0's knee
/// 6.6–107 at 3–7 km/h; the same walks' later heel strikes already measure 5–11 there, so the
/// check is not met at 60 frames/s with or without a lead-in).
pub const LEAD_IN_FRAMES: usize = 5;

/// Frames a walk without a stop is recorded past the trailing foot's toe off that follows its
/// last heel strike (so `t_ds + LEAD_OUT_FRAMES / fps` past that heel strike), drawn from one
/// unrecorded step simulated after the last (the landing leg's heel rocker, the trailing leg's
/// double support and first swing frames): the clip ends mid-motion, as it begins
/// ([`LEAD_IN_FRAMES`]), and the last heel strike is judged like every other.
///
/// Why (klawlead, issue 6): the recording used to end at that heel strike, so its last frames
/// were the landing swing, whose thigh retracts into the contact at the collision-neutral rate
/// (`SwingSpec::theta3_rate_hs`) — at 6 km/h × 1.8 m the hip's steps 0.004 → 0.010 → 0.021 rad
/// in the last three frames — against a window of earlier, slower frames only: ratio 5.33 on
/// the last frame (l_hip, the walk's one offender); the same retraction mid-walk, with the
/// frames after the contact in the window, measures ≤ 4.5, and a ninth step moved the failure
/// to the ninth's last frame (r_hip 5.25). The end's window is one-sided the other way, so
/// whatever *starts* moving within the last 3 frames fails it: ending 5 frames after the heel
/// strike caught the trailing foot's ball leaving the floor at meta off (r_ball 5.8–12.4 at
/// 5–7 km/h); after the toe off nothing starts from rest until the stance heel off, and the
/// swing toe's rise is 5 frames under way (6 km/h × 1.8 m 5.33 → 4.52).
pub const LEAD_OUT_FRAMES: usize = 5;

/// Generates a walk of the given steps (complete locomotion parameters, one per step).
pub fn generate_steps(
    steps: &[Locomotion],
    opt: &WalkOptions,
) -> Result<(Motion, WalkReport), GenerateError> {
    let a = &opt.attributes;
    a.validate()?;
    let skeleton = Skeleton::from_height(opt.height_m, opt.mass_kg)?;
    let body = Body::new(skeleton.anthropometry());
    if steps.is_empty() {
        return Err(GenerateError::Parameter {
            name: "steps".into(),
            value: 0.0,
            message: "a walk needs at least one step; give a longer duration".into(),
        });
    }
    let model = StanceModel::new(&body);
    let foot = FootShape::new(&body);
    let g = model.g;
    let k_w = a.leg_stiffness * body.mass_kg * g / body.l1;
    let ieff = body.i2 + body.m2 * body.r2 * body.r2;
    let om2 = 2.0 * PI * a.trunk_freq_hz;
    let swing_model = super::dynamics::SwingModel::new(&body);
    let m33 = swing_model.mass_matrix(&[0.0, 0.0])[0][0];
    let om3 = 2.0 * PI * a.swing_hip_freq_hz;
    let half_width = 0.5 * body.l0;
    let ahead = half_width * a.pelvic_rotation_deg.to_radians().sin();
    let theta5_hs = a.ankle_heel_strike_deg.to_radians();

    let mut report = WalkReport::default();
    let mut data: Vec<StepData> = Vec::with_capacity(steps.len());
    let mut ankle_x = [0.0f64; 2]; // [left, right] flat-ankle x
    let idx = |s: Side| match s {
        Side::Left => 0,
        Side::Right => 1,
    };
    // A steady start is preceded by PRE_ROLL unrecorded copies of the first step: the steady
    // state is only approximated for the first of them (eq. 3 and the speed), and its trailing
    // foot has no history, so it may toe off late and abruptly. The simulated steps bring the
    // hip's velocities, the forces and the trailing foot's roll onto the periodic walk (the
    // shooting then carries them on), so the recorded walk, lead-in included, starts steady.
    let pre = if opt.start_from_rest { 0 } else { PRE_ROLL };
    let mut stance_side = if pre % 2 == 0 {
        Side::Left
    } else {
        Side::Right
    };
    // Standing (from rest): both feet flat under hips half a pelvis width apart, the feet a
    // stride width apart. A sagittal leg of length l1 put the 3-D hip–ankle distance
    // √(l1² + dz²) ≈ 1 mm beyond the leg's reach, and the virtual leg's soft knee (straight only
    // up to l1 − 2·KNEE_SOFT) rolled both feet onto their toes: heels 1–3 mm up while standing.
    // The standing hip is as high as the soft knee lets the flat feet stay down.
    let dz_stand = half_width - 0.5 * a.stride_width_m;
    let w_stand = ((body.l1 - 2.0 * KNEE_SOFT - STAND_MARGIN).powi(2) - dz_stand * dz_stand)
        .max(0.0)
        .sqrt();
    let mut stance_start = StanceStart {
        q: [w_stand, 0.0, a.trunk_lean_deg.to_radians()],
        qd: [0.0; 3],
    };
    let mut from_rest = opt.start_from_rest;
    if !from_rest {
        // A steady start: the state a previous identical step would leave (approximated from
        // eq. 3 and the speed; the first step's shooting absorbs the difference).
        let l = &steps[0];
        let hs = heel_strike(&body, l.step_length_m, theta5_hs, ahead)?;
        let th = -hs.theta1;
        let v = l.speed_m_per_s;
        stance_start = StanceStart {
            q: [hs.w, th, a.trunk_lean_deg.to_radians()],
            qd: [v * th.sin(), v * th.cos() / hs.w, 0.0],
        };
        // The recorded walk's first stance foot lands at x = 0.
        let back = pre as f64 * l.step_length_m;
        ankle_x = match stance_side {
            Side::Left => [-back, -back - l.step_length_m],
            Side::Right => [-back - l.step_length_m, -back],
        };
    }
    // The trailing leg's virtual-leg state.
    let mk_leg = |flat_x: f64, period: FootPeriod, rho: f64| {
        VirtualLeg::new(foot, &body, a, flat_x, period, rho)
    };
    let mut trailing = mk_leg(ankle_x[idx(stance_side.opposite())], FootPeriod::Flat, 0.0);
    let mut trailing_clock = 0.0;
    if !from_rest {
        // Put the trailing foot where the steady step would have it at heel strike: rolled so the
        // leg reaches the hip.
        trailing.period = FootPeriod::HeelOff;
    }
    let mut stance_guess = [0.0, 0.0];
    let mut stance_jac = None;
    let mut swing_guess = [0.0; 7];
    let mut swing_carry = SwingCarry::default();
    let mut recovery_by_leg = [0.0f64; 2];
    // Without a stop, one unrecorded step after the last: the lead-out draws its start.
    let post = if opt.stop { 0 } else { 1 };
    let all: Vec<Locomotion> = std::iter::repeat_n(steps[0], pre)
        .chain(steps.iter().copied())
        .chain(std::iter::repeat_n(steps[steps.len() - 1], post))
        .collect();
    // The last recorded heel strike (the end of the last recorded step).
    let mut t_end = 0.0;
    // Time origin: frame 0 at t = 0, the first recorded heel strike at t = LEAD_IN_FRAMES / fps
    // (at 0 from rest), the pre-roll steps before it.
    let lead = if pre > 0 {
        LEAD_IN_FRAMES as f64 / opt.fps
    } else {
        0.0
    };
    let mut t_global =
        lead - pre as f64 * phase_times(steps[0].step_freq_steps_per_min, &opt.relations).step;
    let mut prev_hs_pitch = if from_rest {
        0.0
    } else {
        heel_strike(&body, steps[0].step_length_m, theta5_hs, ahead)?.foot_pitch
    };
    let n = all.len();
    // Every swing is braked (`SwingSpec::knee_brake`) and leaves with the brisk toe off, but the
    // first from standing, which keeps the paper's toe off (see `FIRST_PAPER_SWINGS`).
    let toe_off_rate = |kk: usize| {
        if opt.start_from_rest && kk < FIRST_PAPER_SWINGS {
            0.0
        } else {
            TOE_OFF_KNEE_RATE
        }
    };
    for (kk, l) in all.iter().enumerate() {
        let recorded = kk >= pre && kk < pre + steps.len();
        let k = kk.saturating_sub(pre);
        let stage = |what: &str| {
            if recorded {
                format!("step {k} ({} stance), {what}", stance_side)
            } else if kk < pre {
                format!(
                    "steady-state pre-roll step ({} stance), {what}",
                    stance_side
                )
            } else {
                format!(
                    "lead-out step after the last ({} stance), {what}",
                    stance_side
                )
            }
        };
        let swing_side = stance_side.opposite();
        let to_rest = opt.stop && kk + 1 == n;
        let times = phase_times(l.step_freq_steps_per_min, &opt.relations);
        let t_step = times.step;
        let det = Determinants {
            duration: t_step,
            rotation: a.pelvic_rotation_deg.to_radians(),
            list: a.pelvic_list_deg.to_radians(),
            lateral: a.lateral_displacement_m,
            half_width,
            swing: swing_side,
            from_rest,
            to_rest,
        };
        let hs = heel_strike(
            &body,
            l.step_length_m,
            theta5_hs,
            if to_rest { 0.0 } else { ahead },
        )?;
        // 1. Stance.
        let spec = StanceSpec {
            model,
            l1: body.l1,
            k_w,
            v_w: 2.0 * a.leg_damping * (k_w * body.m2).sqrt(),
            k2: ieff * om2 * om2 + body.m2 * g * body.r2,
            c2: 2.0 * a.trunk_damping * ieff * om2,
            theta2_ref: a.trunk_lean_deg.to_radians(),
            duration: t_step,
            torque_off: a.hip_torque_off * t_step,
            monitor_gain: 20.0,
            target: [hs.w, hs.theta1],
            max_step: a.max_step_s,
            // No push-off on the last step before the stop (the body is brought to rest): with
            // it there, 7 km/h × 1.5 m measured stop 3.6 → 4.9. The first step from standing
            // pushes off late (`stance::first_push_off_exponent`, klawstart4), so the hip does
            // not fall onto the next heel.
            push_off: if to_rest {
                2.0
            } else if from_rest {
                super::stance::first_push_off_exponent(l.speed_m_per_s, body.l1)
            } else {
                super::stance::push_off_exponent(l.speed_m_per_s, body.l1)
            },
            lock_short: 0.0,
            lock_reach: 0.0,
            flat_reach: 0.0,
            rest_reach: 0.0,
            rest_ramp_in: super::stance::REST_RAMP_IN,
        };
        // At speed the leg locks short of l1: the midstance knee (`stance::lock_shortening`).
        let lock_short = super::stance::lock_shortening(spec.push_off);
        // The rigid leg is the sagittal projection of the drawn 3-D leg, whose hip is `dz` beside
        // the stance foot, with the virtual leg's soft knee (flat only up to 2·KNEE_SOFT short of
        // straight): the stance heel stays down through midstance (`StanceSpec::lock_length`).
        // The largest `dz` of the stance (sampled; its peak is at midstance, in the lock).
        let zf_lock = side_z(stance_side, a);
        let dz_max = (0..=32)
            .map(|i| {
                let t = t_step * i as f64 / 32.0;
                (det.lateral_at(t) - det.swing_offset(t).z - zf_lock).abs()
            })
            .fold(0.0, f64::max);
        let lock_full = body.l1 * (1.0 - lock_short);
        let lock_flat = lock_full - 2.0 * KNEE_SOFT - STAND_MARGIN;
        let flat_reach = lock_full - (lock_flat * lock_flat - dz_max * dz_max).max(0.0).sqrt();
        // Where the lock is not shortened by it, the drawn knee takes it (`drawn_span`); in
        // slow walks the spring's rest length is shortened by it as well
        // (`REST_SHORTENING_FROUDE_MAX`).
        let projected = projected_lock(l.speed_m_per_s, body.l1, from_rest, to_rest);
        let froude = super::stance::froude_speed(l.speed_m_per_s, body.l1);
        let slow = froude < REST_SHORTENING_FROUDE_MAX;
        let spec = StanceSpec {
            lock_short,
            lock_reach: if projected { flat_reach } else { 0.0 },
            flat_reach,
            rest_reach: if projected && slow {
                flat_reach * (1.0 + (SLOW_REST_REACH - 1.0) * slowness(froude))
            } else {
                0.0
            },
            rest_ramp_in: super::stance::REST_RAMP_IN
                + (super::stance::REST_RAMP_IN_SLOW - super::stance::REST_RAMP_IN)
                    * slowness(froude),
            ..spec
        };
        let (st_solved, st_run) = spec
            .solve_with(&stance_start, stance_guess, stance_jac)
            .map_err(|e| num_err(stage("stance shooting"), e))?;
        stance_guess = st_solved.x;
        stance_jac = st_solved.jacobian.or(stance_jac);
        let ax = ankle_x[idx(stance_side)];
        let track = st_run.track.clone();
        let dyn_hip = move |t: f64| -> HipMotion {
            let (q, qd, qdd) = track.at(t);
            let mut h = StanceModel::hip(&q, &qd, &qdd);
            h.pos[0] += ax;
            h.pos[1] += body.l9;
            h
        };
        let swing_hip = |t: f64| -> HipMotion {
            let mut h = dyn_hip(t);
            let (o, od, odd) = det.swing_hip_offset_rates(t);
            for i in 0..2 {
                h.pos[i] += o[i];
                h.vel[i] += od[i];
                h.acc[i] += odd[i];
            }
            h
        };
        let stance_hip = |t: f64| -> ([f64; 2], f64) {
            let h = dyn_hip(t);
            let o = det.swing_offset(t);
            let z_c = det.lateral_at(t);
            ([h.pos[0] - o.x, h.pos[1]], z_c - o.z)
        };
        let swing_hip3 = |t: f64| -> ([f64; 2], f64) {
            let h = swing_hip(t);
            let o = det.swing_offset(t);
            (h.pos, det.lateral_at(t) + o.z)
        };
        // 2. The trailing leg completes its stance through the double support.
        let dt_v = 2e-3;
        let t_ds = times.double_support;
        trailing.toe_off_time = trailing_clock + t_ds;
        trailing.toe_off_knee_rate = toe_off_rate(kk);
        trailing.min_knee_blend = MIN_KNEE_BLEND * t_ds;
        let mut trail_rho = Vec::new();
        let mut trail_hips = Vec::new();
        let n_v = ((t_ds / dt_v).ceil() as usize).max(3);
        let zf_w = side_z(swing_side, a);
        // From standing, the first two trailing legs leave from their toes, as at every steady
        // toe off: the meta-off rule from the start of the double support (the foot rolls onto
        // its toes while the knee flexes to its toe-off value; the heel rises).
        // The second step's trailing leg (the first stance leg) stood flat or barely heeled off
        // through the first step — the hip, starting at rest, never gets far enough ahead for
        // the heel-off rule to roll it — so it left the ground nearly flat with the knee almost
        // straight and its shank vertical: swing1's slaved knee lifted the ankle 12 cm almost
        // straight up (2 km/h) and then switched to the ankle curve's other branch (7.5 cm in one
        // frame). The first step's trailing leg stands under the hip, where a flexed knee pitches
        // the thigh forward: its knee flexes only as far as keeps the thigh at toe off behind
        // `FIRST_TOE_OFF_THIGH` of its heel-strike angle (see there).
        // So does a trailing leg whose stance was slower than the step it toes off in (a speed
        // change in the schedule, `speeds_up`): see there.
        if ((opt.start_from_rest && kk < 2)
            || (speeds_up(&all, kk) && trailing.period == FootPeriod::HeelOff))
            && trailing.period != FootPeriod::MetaOff
        {
            let (hp, hz) = swing_hip3(0.0);
            let knee = trailing.pose_at(hp, hz - zf_w, trailing.rho).knee;
            trailing.period = FootPeriod::MetaOff;
            trailing.meta_start = Some((trailing_clock, knee));
            trailing.transitions[1].get_or_insert(trailing_clock);
            trailing.transitions[2] = Some(trailing_clock);
            if kk == 0 {
                let hips: Vec<(f64, [f64; 2], f64)> = (0..=n_v)
                    .map(|i| {
                        let t = t_ds * i as f64 / n_v as f64;
                        let (hp, hz) = swing_hip3(t);
                        (trailing_clock + t, hp, hz - zf_w)
                    })
                    .collect();
                trailing.knee_toe_off =
                    first_toe_off_knee(&trailing, &hips, knee, FIRST_TOE_OFF_THIGH * hs.theta3);
            }
        }
        let mut trail_poses: Vec<(f64, LegPose, [f64; 2])> = Vec::with_capacity(n_v + 1);
        for i in 0..=n_v {
            let t = t_ds * i as f64 / n_v as f64;
            let (hp, hz) = swing_hip3(t);
            let p = trailing.advance(trailing_clock + t, hp, hz - zf_w);
            trail_rho.push((t, p.rho));
            trail_hips.push((hp, hz - zf_w));
            trail_poses.push((t, p, hp));
        }
        let trail_leg = trailing.clone();
        // Toe-off state: the sagittal thigh and knee angles of the hip–ankle chain (so the swing
        // starts with its ankle exactly where the stance foot left it), rates by second-order
        // backward differences.
        let m = trail_poses.len();
        let sag =
            |i: usize| sagittal_angles(trail_poses[i].2, trail_poses[i].1.ankle, body.l3, body.l4);
        let (q0, q1, q2) = (sag(m - 1), sag(m - 2), sag(m - 3));
        let p0 = trail_poses[m - 1].1;
        let hstep = t_ds / n_v as f64;
        let d = |f0: f64, f1: f64, f2: f64| (3.0 * f0 - 4.0 * f1 + f2) / (2.0 * hstep);
        let swing_start = SwingStart {
            q: q0,
            qd: [d(q0[0], q1[0], q2[0]), d(q0[1], q1[1], q2[1])],
        };
        // 3. The stance leg's virtual leg over the step.
        let mut stance_leg = if from_rest && kk == 0 {
            mk_leg(ax, FootPeriod::Flat, 0.0)
        } else {
            mk_leg(ax, FootPeriod::HeelRocker, -prev_hs_pitch)
        };
        let next_times = all
            .get(kk + 1)
            .map(|nl| phase_times(nl.step_freq_steps_per_min, &opt.relations));
        stance_leg.toe_off_knee_rate = toe_off_rate(kk + 1);
        // The knee keeps the locked leg's midstance flexion (see `StanceSpec::drawn_span`).
        stance_leg.span_max = spec.drawn_span(&st_run, stance_leg.l3 + stance_leg.l4);
        stance_leg.toe_off_time = t_step
            + next_times
                .map(|t| t.double_support)
                .unwrap_or(times.double_support);
        let zf_s = side_z(stance_side, a);
        let n_s = ((t_step / dt_v).ceil() as usize).max(2);
        let hips: Vec<(f64, [f64; 2], f64)> = (0..=n_s)
            .map(|i| {
                let t = t_step * i as f64 / n_s as f64;
                let (hp, hz) = stance_hip(t);
                (t, hp, hz - zf_s)
            })
            .collect();
        stance_leg.plan_heel_rocker(&hips, a.heel_rocker_fraction * t_step);
        let mut stance_rho = Vec::with_capacity(n_s + 1);
        let mut theta5_early = Vec::new();
        for &(t, hp, dz) in &hips {
            let p = stance_leg.advance(t, hp, dz);
            stance_rho.push((t, p.rho));
            if t <= CONTACT_RATE_WINDOW + 1e-9 {
                theta5_early.push((t, p.theta5));
            }
        }
        // The previous step's swing foot lands into this heel rocker: its ankle ends swing3 with
        // the rocker's early ankle rate (C¹ θ5 across heel strike, see `SwingFoot::theta56`);
        // the last pre-roll step's too, which the lead-in draws.
        if let (Some(prev), Some(&a), Some(&b)) =
            (data.last_mut(), theta5_early.first(), theta5_early.last())
        {
            if b.0 > a.0 {
                let rate = (b.1 - a.1) / (b.0 - a.0);
                prev.swing_foot.theta5_rate_hs =
                    rate.clamp(-MAX_CONTACT_ANKLE_RATE, MAX_CONTACT_ANKLE_RATE);
                prev.swing_foot.contact_ramp_weight = contact_ramp_weight(rate);
            }
        }
        // 4. Swing.
        let t0 = t_ds;
        let tsw = times.swing;
        let breakpoints = st_run.track.breakpoints();
        let hip_fn = &swing_hip;
        let theta3_rate_hs = neutral_landing_rate(
            &body,
            &model,
            &st_run.end,
            [ax, body.l9],
            swing_hip(t_step),
            hs.theta3,
            [ax + l.step_length_m, body.l9],
        );
        let first_swing = opt.start_from_rest && kk == 0;
        // The swing's spec for a swing1 end (fraction of the swing) and an ankle lift.
        let swing_spec = |swing1_end: f64, ankle_lift: f64| {
            let swing_times = [t0, t0 + swing1_end * tsw, t0 + a.swing2_end * tsw, t_step];
            SwingSpec {
                model: swing_model,
                foot,
                hip: hip_fn,
                breakpoints: &breakpoints,
                times: swing_times,
                theta3_hs: hs.theta3,
                theta5: [p0.theta5, a.ankle_mid_swing_deg.to_radians(), theta5_hs],
                theta6_toe_off: p0.toe_bend,
                ankle_lift,
                tau: [
                    a.swing1_tau * (swing_times[1] - t0),
                    a.swing2_tau * (swing_times[2] - swing_times[1]),
                    a.swing3_tau * (t_step - swing_times[2]),
                ],
                hip_spring: [m33 * om3 * om3, 2.0 * a.swing_hip_damping * m33 * om3],
                clearance: a.toe_clearance_m,
                theta5_max: a.ankle_swing_dorsiflexion_max_deg.to_radians(),
                max_step: a.max_step_s,
                // Every swing, the first from standing too since klawstart2 (see
                // `first_swing_shape`; it keeps the paper's toe off, `FIRST_PAPER_SWINGS`).
                knee_brake: true,
                theta3_rate_hs,
            }
        };
        let (swing1_end, ankle_lift) = if first_swing {
            first_swing_shape(l.speed_m_per_s, opt.height_m, a.swing1_end, a.ankle_lift_m)
        } else if to_rest {
            (
                (a.swing1_end + STOP_SWING1_DELAY).min(0.5 * (a.swing1_end + a.swing2_end)),
                STOP_LIFT * a.ankle_lift_m,
            )
        } else {
            (a.swing1_end, a.ankle_lift_m)
        };
        // The swing2 recovery's actuator is carried over from the same leg's last swing: fast
        // walks alternate between legs (period-two pattern of the recovery).
        swing_guess[4] = recovery_by_leg[idx(swing_side)];
        let sspec = swing_spec(swing1_end, ankle_lift);
        let sw = sspec
            .solve_with(&swing_start, swing_guess, &swing_carry, l.speed_m_per_s)
            .map_err(|e| num_err(stage("swing shooting"), e))?;
        let swing_times = sspec.times;
        swing_guess = sw.params;
        if first_swing {
            // The first swing's clearance lift of its ankle curve is its own (its curve was
            // built for a hip starting from rest): the next swing starts its search from none.
            // Carried on (it never decreases), 2.7 cm at 1 km/h × 1.5 m raised every later
            // swing's curve, and their ankles (continuity 4.2 → 5.7 at their mid-swings).
            swing_guess[3] = 0.0;
        }
        swing_carry = sw.carry;
        recovery_by_leg[idx(swing_side)] = sw.params[4];
        // 5. Heel strike.
        let last = *sw
            .track
            .nodes
            .last()
            .ok_or_else(|| num_err(stage("swing"), "empty swing".into()))?;
        let sh = swing_hip(t_step);
        let new_ankle_x = ax + l.step_length_m;
        let next_start = collision::heel_strike(
            &body,
            &model,
            &st_run.end,
            [ax, body.l9],
            &SwingAtImpact {
                hip: sh.pos,
                hip_vel: sh.vel,
                theta3: [last.q[0], last.qd[0]],
            },
            [new_ankle_x, body.l9],
        );
        if recorded {
            report.steps.push(StepReport {
                index: k,
                stance_side,
                start_s: t_global,
                step_length_m: l.step_length_m,
                step_freq_steps_per_min: l.step_freq_steps_per_min,
                times,
                iterations: [
                    st_solved.iterations,
                    sw.iterations[0],
                    sw.iterations[1],
                    sw.iterations[2],
                ],
                forces: [
                    st_solved.x[0],
                    st_solved.x[1],
                    sw.params[0],
                    sw.params[1],
                    sw.params[2],
                ],
                errors: [
                    st_solved.residual[1],
                    st_solved.residual[0],
                    sw.end_errors[0],
                    sw.end_errors[1],
                    sw.end_errors[2],
                ],
                recovery_rounds: sw.recovery_rounds,
                recovery_rad: sw.recovery,
                min_clearance_m: sw.min_clearance,
                lock_s: st_run.lock_time,
                swing1_end,
                ankle_lift_m: ankle_lift,
            });
        }
        // The pre-roll step too: the lead-in draws its last frames, and its stance leg is the
        // recorded walk's first trailing leg (rolls smoothed across both, `smooth_rolls`).
        data.push(StepData {
            side: stance_side,
            start: t_global,
            loc: *l,
            times,
            ankle_x: ax,
            det,
            stance: st_run,
            swing: sw,
            swing_foot: sspec.swing_foot(),
            knee_brake: sspec.knee_brake,
            swing_times,
            stance_rho,
            stance_hips: hips.iter().map(|&(_, hp, dz)| (hp, dz)).collect(),
            stance_leg: stance_leg.clone(),
            trail_rho,
            trail_hips,
            trail_leg,
            trail_origin: t_global - trailing_clock,
        });
        if recorded {
            t_end = t_global + t_step;
        }
        // Next step.
        ankle_x[idx(swing_side)] = new_ankle_x;
        trailing = stance_leg;
        trailing_clock = t_step;
        prev_hs_pitch = hs.foot_pitch;
        stance_start = next_start;
        stance_side = swing_side;
        t_global += t_step;
        from_rest = false;
    }
    smooth_rolls(&mut data);
    hold_knees(&mut data);
    // The stop: the trailing foot is brought alongside and the body comes to rest.
    let closing = match (opt.stop, data.last()) {
        (true, Some(d)) => {
            let w = stance_side;
            let (q, qd, qdd) = d.stance.track.at(d.times.step);
            let h = StanceModel::hip(&q, &qd, &qdd);
            let sgn = Determinants::side_sign(w);
            let om = PI / d.times.step;
            let geo = StopStart {
                hip: [
                    [d.ankle_x + h.pos[0], h.vel[0], h.acc[0]],
                    [body.l9 + h.pos[1], h.vel[1], h.acc[1]],
                ],
                // d/dt of the last step's lateral_at at its end (sin(π) = 0, cos(π) = −1).
                lateral: [
                    d.det.lateral_at(d.times.step),
                    sgn * d.det.lateral * om,
                    0.0,
                ],
                lean: [q[2], qd[2], qdd[2]],
                lean_ref: a.trunk_lean_deg.to_radians(),
                stance_ankle_x: ankle_x[idx(w)],
                ankle_height: body.l9,
                hip_z: [sgn * half_width, -sgn * half_width],
                ankle_z: [side_z(w, a), side_z(w.opposite(), a)],
                l1: body.l1,
                t_ds: d.times.double_support,
                t_swing: d.times.swing,
                clearance: a.toe_clearance_m,
                trail_clock: trailing_clock,
                min_knee_blend: MIN_KNEE_BLEND * d.times.double_support,
                heel_rocker_min: a.heel_rocker_fraction * d.times.step,
            };
            let mut lead = mk_leg(ankle_x[idx(w)], FootPeriod::HeelRocker, -prev_hs_pitch);
            lead.slow_knee_start = false;
            Some(Closing::new(
                t_global,
                w,
                geo,
                lead,
                trailing.clone(),
                &foot,
            ))
        }
        _ => None,
    };
    // The last step's swing foot lands into the stop's heel rocker as every other lands into
    // the next step's: its ankle ends swing3 at the rocker's early ankle rate.
    if let (Some(c), Some(d)) = (closing.as_ref(), data.last_mut()) {
        let rate = c.contact_ankle_rate(CONTACT_RATE_WINDOW);
        d.swing_foot.theta5_rate_hs = rate.clamp(-MAX_CONTACT_ANKLE_RATE, MAX_CONTACT_ANKLE_RATE);
        d.swing_foot.contact_ramp_weight = contact_ramp_weight(rate);
    }
    let total = if post > 0 {
        t_end
            + phase_times(
                steps[steps.len() - 1].step_freq_steps_per_min,
                &opt.relations,
            )
            .double_support
            + LEAD_OUT_FRAMES as f64 / opt.fps
    } else {
        t_global + closing.as_ref().map_or(0.0, |c| c.duration)
    };
    let motion = assemble(&skeleton, &body, &foot, &data, opt, total, closing.as_ref())?;
    Ok((motion, report))
}

/// Whether step `kk` of `all` is faster than the step before it: its trailing leg, whose heel-off
/// rule ran at the slower step's hip, enters meta-off at the start of the double support (if
/// it is not there yet), as the first trailing legs from standing do.
///
/// Why: a slow stance leaves the trailing leg in heel off, knee straight, at the slower walk's
/// roll; the faster step's double support is short and its hip fast, so the heel-off rule
/// reached no meta-off before toe off. The leg left the ground with its knee straight (2 km/h
/// stance, 5 km/h toe off × 1.8 m: 0.118 rad, heel 7 cm up), and the least-bending roll
/// ([`smooth_roll`]), which rounded the rule's accelerating roll, drew a knee that flexed by
/// 0.016 rad and straightened again at 0.7 rad/frame in the last frames before toe off, which
/// [`hold_knees`] cannot hold there (the toe-off samples are the swing's start): continuity 6.2
/// on that knee (2 → 5 → 3 km/h, 1.8 m; 5.07 at 2.0 m, 12.2 on 2 → 4 km/h × 2.0 m). A person
/// speeding up pushes off with that leg: its knee now flexes from rest (the meta-off blend) to
/// its toe-off value. Measured (from standing with a stop, 1.5/1.8/2.0 m; the worst ratio of the
/// whole walk, before → after): 2 → 5 → 3 km/h 5.56/6.20/5.07 → 5.56/6.08/4.75 (the trailing
/// knee gone; 1.8 m's worst is now the stop); 2 → 4 km/h 4.97/6.22/12.2 → 4.97/5.24/5.87;
/// 1 → 7 km/h × 2.0 m 8.74 → 5.36; 1 → 2, 1 → 3, 2 → 3 and the speed-ups from 3 km/h
/// unchanged; **1 → 5 km/h worse, 5.53/5.69/4.58 → 6.24/6.63/4.75**: the 1 km/h leg stands
/// nearly straight (knee 0.02–0.06 rad) and closer under the hip, and flexing it fully in the
/// 0.10–0.15 s double support rolls the foot fast enough that the ankle's rate at toe off
/// (the swing foot's θ5 starts at rest) spikes. Starting the blend later (only as early as a
/// u² ramp at `TOE_OFF_KNEE_RATE` needs) was the same or worse (1 → 2 km/h × 2.0 m
/// 4.58 → 4.73). Slower steps are left alone: 5 → 3 km/h's trailing leg enters meta-off within
/// 5 ms of the same time either way. Only a trailing foot already in heel off is moved on to
/// meta off: a foot still flat (1 km/h stance legs of a 2.0 m body, flat until late) snapped
/// onto its toe tip, 22 mm in one frame (1 → 3 and 1 → 5 km/h × 2.0 m from standing: 46.4 and
/// 22.8 → 4.58), and goes through heel off as the rule has it.
fn speeds_up(all: &[Locomotion], kk: usize) -> bool {
    kk > 0 && all[kk].speed_m_per_s > all[kk - 1].speed_m_per_s + 1e-9
}

/// Time scale of the stance roll's smoothing after foot flat, s (see [`smooth_roll`]), for a
/// leg whose knee straightens softly over [`KNEE_SOFT`].
const ROLL_TAU: f64 = 0.02;

/// Smooths every leg's recorded roll from foot flat to toe-off ([`smooth_roll`], never below
/// the rule): one leg's stance is recorded in two steps (its own, then the next step's double
/// support), so the two pieces are joined, smoothed and split again.
///
/// The time scale shrinks with the square root of the leg's soft knee margin
/// ([`VirtualLeg::knee_soft`], narrowed in slow walks whose hip never comes below the straight
/// leg): a smoother roll leaves the hip's motion along the leg (the telescopic leg extending,
/// then locking at `l1`) to the knee, and a nearly straight knee turns it into large rates
/// (dθ4/dd ∝ 1/θ4). Measured (8 steps, 1.8 m): a fixed 20 ms took the worst knee ratio at
/// 1 km/h from 11.7 (rule) to 9.9, 10 ms to 7.9 but left 3 km/h's heel off at 5.1; the scaled
/// time scale gives 6.5 (not at heel off) and 3 km/h below 4.
///
fn smooth_rolls(data: &mut [StepData]) {
    let smooth = |times: &[f64], rho: &mut Vec<f64>, knee_soft: f64| {
        let from = rho.iter().position(|&r| r >= 0.0).unwrap_or(rho.len());
        // Landing flat from the heel rocker: at rest.
        let rest = from > 0;
        let tau = ROLL_TAU * (knee_soft / KNEE_SOFT).clamp(0.0, 1.0).sqrt();
        smooth_roll(times, rho, from, rest, tau);
    };
    // The first step's trailing leg: from rest its stance begins with the walk; after a steady
    // start the first step is the unrecorded pre-roll (whose trailing leg has no history and is
    // never drawn), and the recorded walk's first trailing leg is the pre-roll's stance leg,
    // joined with it below as every later step's (smoothed alone over the recorded double
    // support, its start was a free end: with the forward-mean smoother that was the
    // 7 km/h × 1.5 m toe-bend jump at frame 2, ratio 25.5).
    if let Some(d) = data.first_mut() {
        let times: Vec<f64> = d.trail_rho.iter().map(|s| d.start + s.0).collect();
        let mut rho: Vec<f64> = d.trail_rho.iter().map(|s| s.1).collect();
        smooth(&times, &mut rho, d.trail_leg.knee_soft);
        for (s, r) in d.trail_rho.iter_mut().zip(rho) {
            s.1 = r;
        }
    }
    for k in 0..data.len() {
        let start = data[k].start;
        let mut times: Vec<f64> = data[k].stance_rho.iter().map(|s| start + s.0).collect();
        let mut rho: Vec<f64> = data[k].stance_rho.iter().map(|s| s.1).collect();
        let n1 = times.len();
        let mut skipped = 0;
        if let Some(next) = data.get(k + 1) {
            for &(t, r) in &next.trail_rho {
                let g = next.start + t;
                if times.last().is_some_and(|&l| g <= l + 1e-12) {
                    skipped += 1;
                    continue;
                }
                times.push(g);
                rho.push(r);
            }
        }
        smooth(&times, &mut rho, data[k].stance_leg.knee_soft);
        for (s, &r) in data[k].stance_rho.iter_mut().zip(&rho[..n1]) {
            s.1 = r;
        }
        if let Some(next) = data.get_mut(k + 1) {
            let last = rho[n1.saturating_sub(1)];
            for (i, s) in next.trail_rho.iter_mut().enumerate() {
                s.1 = if i < skipped {
                    last
                } else {
                    rho[n1 + i - skipped]
                };
            }
        }
    }
}

/// Keeps every leg's knee from straightening again between heel off and toe off: wherever the
/// smoothed roll would draw it less flexed than it already was since heel off, the foot rolls
/// on (about the ball or the toe tip, so nothing slides or sinks) until the knee is as flexed
/// as it was. A leg's late stance is recorded in two steps (its own stance, then the next
/// step's double support), so the two are joined. The toe-off samples (the last two, where the
/// swing takes over with their state) keep their roll. Where the hold would need them — the
/// knee ends its late stance straighter than its peak: slow walks, whose trailing knee stays
/// near the heel-off rule's soft floor to toe off, with bumps of ≈ 0.01 rad where the hip comes
/// closer — the floor descends linearly from the peak to the toe-off knee instead (≈ 0.03 rad/s
/// at 1.1 km/h); only if that fails too is the leg left as it was.
///
/// Why the descent: giving the hold up left the bump, straightened in 3 frames after the other
/// foot's foot flat (1.1 km/h × 1.7 m 4.87, 1.05 km/h × 1.5 m 5.12, r/l_knee, once the slowest
/// stances lowered the hip, [`SLOW_REST_REACH`]). With it, 1.0–2.5 km/h every 0.05 × 1.5–2.0 m
/// every 5 cm (341 steady walks): worst 5.12 → 4.27, geometric mean 3.31 → 3.05, walks over
/// 4.5: 40 → 0; from standing with a stop (176): 5.09 → 4.69; 2.5–7 km/h unchanged.
///
/// Why: the heel-off rule's roll accelerates through late stance with the push-off and
/// flattens at heel strike, where the push-off ends; the least-bending roll above the rule
/// ([`smooth_roll`]) rounds that corner by rolling a little ahead of the rule before heel
/// strike and rejoining it within 1–2 frames after — drawn as a knee that flexes ≈ 0.012 rad
/// and straightens back at ≈ 1.2 rad/s around heel strike, before its meta-off flexion
/// (6 km/h × 2.0 m: the recorded walk's first frame is that heel strike, with nothing before
/// it in the continuity window: ratio 10.5 on the trailing knee; 5.3–6.5 at later heel
/// strikes). A person's trailing knee flexes steadily from heel off to toe off.
/// Time scale of the held knee's smoothing ([`hold_knees`]), s.
const KNEE_HOLD_TAU: f64 = 0.03;

fn hold_knees(data: &mut [StepData]) {
    /// One leg's late stance: its samples (step, in the trail part, index) in time order, the
    /// trail samples at the same time as the stance's last (drawn with its roll), and whether
    /// the hold starts at the first sample (the recorded walk's first trailing leg: its
    /// history before the walk is not here).
    struct Chain {
        samples: Vec<(usize, bool, usize)>,
        same_time: Vec<(usize, usize)>,
        from_first: bool,
    }
    let mut chains: Vec<Chain> = Vec::new();
    if let Some(d) = data.first() {
        let heel_off = d.trail_leg.transitions[1].map_or(f64::INFINITY, |t| d.trail_origin + t);
        chains.push(Chain {
            samples: (0..d.trail_rho.len().min(d.trail_hips.len()))
                .filter(|&i| d.start + d.trail_rho[i].0 >= heel_off - 1e-9)
                .map(|i| (0, true, i))
                .collect(),
            same_time: Vec::new(),
            from_first: true,
        });
    }
    for k in 0..data.len().saturating_sub(1) {
        let (d, n) = (&data[k], &data[k + 1]);
        let heel_off = d.stance_leg.transitions[1]
            .map(|t| d.start + t)
            .or_else(|| n.trail_leg.transitions[1].map(|t| n.trail_origin + t))
            .unwrap_or(f64::INFINITY);
        let mut samples: Vec<(usize, bool, usize)> =
            (0..d.stance_rho.len().min(d.stance_hips.len()))
                .filter(|&i| d.start + d.stance_rho[i].0 >= heel_off - 1e-9)
                .map(|i| (k, false, i))
                .collect();
        let mut same_time = Vec::new();
        let mut last = samples
            .last()
            .map_or(f64::NEG_INFINITY, |&(_, _, i)| d.start + d.stance_rho[i].0);
        for i in 0..n.trail_rho.len().min(n.trail_hips.len()) {
            let g = n.start + n.trail_rho[i].0;
            if g < heel_off - 1e-9 {
                continue;
            }
            if g <= last + 1e-12 {
                same_time.push((k + 1, i));
                continue;
            }
            last = g;
            samples.push((k + 1, true, i));
        }
        chains.push(Chain {
            samples,
            same_time,
            from_first: false,
        });
    }
    fn sample<'a>(
        data: &'a [StepData],
        &(k, trail, i): &(usize, bool, usize),
    ) -> (&'a VirtualLeg, [f64; 2], f64, f64) {
        let d = &data[k];
        let (leg, (hip, dz), r) = if trail {
            (&d.trail_leg, d.trail_hips[i], d.trail_rho[i].1)
        } else {
            (&d.stance_leg, d.stance_hips[i], d.stance_rho[i].1)
        };
        (leg, hip, dz, r)
    }
    for c in chains {
        let knees: Vec<f64> = c
            .samples
            .iter()
            .map(|s| {
                let (leg, hip, dz, r) = sample(data, s);
                leg.pose_at(hip, dz, r).knee
            })
            .collect();
        // From the knee's last straightest sample before heel strike (within 0.1 mrad): the
        // heel-off rule may begin while the knee still straightens from loading response, and
        // may straighten it with a kink of its own (3 km/h), which the hold would only sharpen.
        let n_stance = c.samples.iter().take_while(|s| !s.1).count();
        let k_min = knees[..n_stance]
            .iter()
            .copied()
            .fold(f64::INFINITY, f64::min);
        let i0 = if c.from_first {
            Some(0)
        } else {
            knees[..n_stance].iter().rposition(|&k| k <= k_min + 1e-4)
        };
        let Some(i0) = i0 else {
            continue;
        };
        let chain = &c.samples[i0..];
        if chain.len() < 4 {
            continue;
        }
        // The knee to draw: the running maximum of the drawn knee, then the least-bending
        // curve above it (`smooth_roll` on the knee, the toe-off samples kept): a knee that
        // flexes steadily instead of in a short burst followed by a hold.
        let times: Vec<f64> = chain
            .iter()
            .map(|&(k, trail, i)| {
                let d = &data[k];
                d.start
                    + if trail {
                        d.trail_rho[i].0
                    } else {
                        d.stance_rho[i].0
                    }
            })
            .collect();
        let prefix_max: Vec<f64> = knees[i0..]
            .iter()
            .scan(f64::NEG_INFINITY, |m, &k| {
                *m = k.max(*m);
                Some(*m)
            })
            .collect();
        let hold = |mut floor: Vec<f64>| -> Option<Vec<f64>> {
            smooth_roll(&times, &mut floor, 0, false, KNEE_HOLD_TAU);
            let mut held = vec![sample(data, &chain[0]).3];
            for (j, s) in chain.iter().enumerate().skip(1) {
                let (leg, hip, dz, r) = sample(data, s);
                let r0 = r;
                let r = r.max(held[j - 1]);
                if leg.pose_at(hip, dz, r).knee < floor[j] - 1e-9 {
                    if j + 2 >= chain.len() {
                        return None;
                    }
                    held.push(leg.roll_for_knee(hip, dz, r, floor[j]));
                } else if j + 2 >= chain.len() && r > r0 + 1e-9 {
                    // The toe-off samples keep their roll (the swing starts from it).
                    return None;
                } else {
                    held.push(r);
                }
            }
            Some(held)
        };
        // Where the knee ends its late stance straighter than it has been (slow walks, whose
        // trailing knee stays near the heel-off rule's soft floor to toe off), a floor that
        // never decreases would need the toe-off samples: the floor then descends linearly
        // from the peak to the toe-off knee.
        let Some(held) = hold(prefix_max.clone()).or_else(|| {
            let n = prefix_max.len();
            let (t_end, k_end) = (times[n - 2], knees[i0 + n - 2]);
            let peak = (0..n).find(|&j| prefix_max[j] >= prefix_max[n - 1])?;
            let (t_peak, k_peak) = (times[peak], prefix_max[n - 1]);
            if t_end <= t_peak + 1e-9 {
                return None;
            }
            let floor: Vec<f64> = (0..n)
                .map(|j| {
                    let line = k_peak
                        + (k_end - k_peak)
                            * ((times[j] - t_peak) / (t_end - t_peak)).clamp(0.0, 1.0);
                    prefix_max[j].min(line.max(k_end))
                })
                .collect();
            hold(floor)
        }) else {
            continue;
        };
        let mut stance_last = None;
        for (&(k, trail, i), &r) in chain.iter().zip(&held) {
            if trail {
                data[k].trail_rho[i].1 = r;
            } else {
                data[k].stance_rho[i].1 = r;
                stance_last = Some(r);
            }
        }
        if let Some(r) = stance_last {
            for &(k, i) in &c.same_time {
                data[k].trail_rho[i].1 = r;
            }
        }
    }
}

/// Builds the frames.
fn assemble(
    skeleton: &Skeleton,
    body: &Body,
    foot: &FootShape,
    data: &[StepData],
    opt: &WalkOptions,
    total: f64,
    closing: Option<&Closing>,
) -> Result<Motion, GenerateError> {
    let a = &opt.attributes;
    let mut meta = MotionMetadata::new("klaw", Some(Gait::Walk));
    meta.push("height_m", opt.height_m);
    meta.push("mass_kg", opt.mass_kg);
    if let Some(d) = data.first() {
        meta.push("speed_m_per_s", d.loc.speed_m_per_s);
        meta.push("step_length_m", d.loc.step_length_m);
        meta.push("step_freq_steps_per_min", d.loc.step_freq_steps_per_min);
    }
    let mut motion = Motion::new(skeleton.clone(), opt.fps, meta)?;
    let frames = (total * opt.fps).floor() as usize + 1;
    motion.reserve(frames);
    let swing_model = super::dynamics::SwingModel::new(body);
    let mut arms = ArmLag::new(opt.fps);
    // A steady walk's lead-in starts mid-motion: the arms' lag is run over the pre-roll's last
    // frames before frame 0 (7 time constants, the two-stage lag's start forgotten to < 1 %), so
    // frame 0's arms already trail their legs as they do mid-walk instead of starting on them.
    let warm = data.first().map_or(0, |d| {
        let tau = arms.set_cycle(2.0 * d.times.step);
        ((-d.start).max(0.0) * opt.fps)
            .floor()
            .min((7.0 * tau * opt.fps).ceil()) as i64
    });
    for i in -warm..frames as i64 {
        let t = (i as f64 / opt.fps).min(total);
        if let Some(c) = closing.filter(|c| t > c.start) {
            let (pose, contact) = closing_pose(skeleton, foot, c, t, a, &mut arms);
            if i >= 0 {
                motion.push_frame(pose, contact);
            }
            continue;
        }
        let k = data.partition_point(|d| d.start <= t).saturating_sub(1);
        let d = &data[k];
        arms.set_cycle(2.0 * d.times.step);
        let tau = (t - d.start).clamp(0.0, d.times.step);
        let (q, _, _) = d.stance.track.at(tau);
        let x_dyn = d.ankle_x + q[0] * q[1].sin();
        let y_dyn = body.l9 + q[0] * q[1].cos();
        let off = d.det.swing_offset(tau);
        let z_c = d.det.lateral_at(tau);
        let mut pose = skeleton.rest_pose();
        pose.root = DVec3::new(x_dyn, y_dyn + off.y, z_c);
        let pelvis = d.det.pelvis(tau);
        pose.rotations[Joint::Pelvis.index()] = pelvis;
        let stance = d.side;
        let swing = stance.opposite();
        // Stance leg (virtual leg).
        let rho = interp_rho(&d.stance_rho, tau);
        let (ankle, pitch, bend) =
            foot.rolled(d.stance_leg.flat_ankle, rho, d.stance_leg.theta6_max);
        let stance_axis = place_leg(
            skeleton,
            &mut pose,
            stance,
            [ankle[0], ankle[1], side_z(stance, a)],
            pitch,
            bend,
        );
        // Swing / trailing leg.
        let (swing_axis, contact_w) = if tau < d.swing_times[0] {
            let rho = interp_rho(&d.trail_rho, tau);
            let (ankle, pitch, bend) =
                foot.rolled(d.trail_leg.flat_ankle, rho, d.trail_leg.theta6_max);
            (
                place_leg(
                    skeleton,
                    &mut pose,
                    swing,
                    [ankle[0], ankle[1], side_z(swing, a)],
                    pitch,
                    bend,
                ),
                true,
            )
        } else {
            let (sq, _, _) = d.swing.track.at(tau);
            let hip = [x_dyn + off.x, y_dyn + 2.0 * off.y];
            let (_, an) = swing_model.knee_ankle(&sq);
            let ankle = [hip[0] + an[0], hip[1] + an[1]];
            let (pitch, th6) = d.swing_foot.pose(tau, ankle, sq[0] + sq[1]);
            let [_, t1, t2, _] = d.swing_times;
            let target = swing_span_target(
                skeleton,
                &pose,
                swing,
                [ankle[0], ankle[1], side_z(swing, a)],
                an[0].hypot(an[1]),
                if d.knee_brake {
                    smoothstep((tau - t1) / (t2 - t1))
                } else {
                    0.0
                },
            );
            (
                place_leg(skeleton, &mut pose, swing, target, pitch, th6),
                false,
            )
        };
        // Spine: the upper body's lean θ2, counter-rotating the pelvic rotation.
        let yaw = Euler::from_quat(pelvis).y;
        let lean = q[2];
        pose.set_world_rotation(
            Joint::Lumbar,
            DQuat::from_rotation_y(yaw) * DQuat::from_rotation_z(-lean),
        );
        pose.set_euler(
            Joint::ThoracicUpper,
            Euler::new(0.0, 0.0, -yaw * a.spine_compensation),
        );
        pose.set_world_rotation(
            Joint::Head,
            DQuat::from_rotation_y(yaw * (1.0 - a.spine_compensation)),
        );
        swing_arms(
            &mut pose,
            a,
            &mut arms,
            [(stance, swing_axis), (swing, stance_axis)],
        );
        let mut contact = [false; 2];
        contact[match stance {
            Side::Left => 0,
            Side::Right => 1,
        }] = true;
        contact[match swing {
            Side::Left => 0,
            Side::Right => 1,
        }] = contact_w;
        if i >= 0 {
            motion.push_frame(pose, contact);
        }
    }
    // Events.
    let mut events = Vec::new();
    let ev = |t: f64, side: Side, kind: EventKind| GaitEvent {
        time_s: t,
        side,
        kind,
        source: EventSource::Generated,
    };
    for (k, d) in data.iter().enumerate() {
        if k > 0 || !opt.start_from_rest {
            events.push(ev(d.start, d.side, EventKind::HeelStrike));
        }
        events.push(ev(
            d.start + d.times.double_support,
            d.side.opposite(),
            EventKind::ToeOff,
        ));
        let tr = d.stance_leg.transitions;
        for (j, kind) in [(0, EventKind::FootFlat), (2, EventKind::MetaOff)] {
            if let Some(tt) = tr[j] {
                events.push(ev(d.start + tt, d.side, kind));
            }
        }
        // This stance leg's heel off, once, wherever the rule switches (in the stance, in the
        // next step's double support, or in the stop's): where the drawn heel leaves the floor
        // in the stance or that double support (`drawn_heel_off`), else the rule's switch.
        let next = data.get(k + 1);
        let rule = tr[1].map(|tt| d.start + tt).or_else(|| match next {
            Some(n) => n.trail_leg.transitions[1]
                .map(|tt| n.trail_origin + tt)
                .filter(|&g| g <= n.start + n.times.double_support + 1e-12),
            None => closing.and_then(|c| c.trail_transitions[0].map(|tt| c.start + tt)),
        });
        if let Some(rule) = rule {
            let flat = d.start + tr[0].unwrap_or(0.0);
            let drawn = drawn_heel_off(&d.stance_rho, d.start, flat).or_else(|| match next {
                Some(n) => drawn_heel_off(&n.trail_rho, n.start, flat),
                None => closing.and_then(|c| drawn_heel_off(c.trail_rho(), c.start, flat)),
            });
            events.push(ev(drawn.unwrap_or(rule), d.side, EventKind::HeelOff));
        }
        let tr = d.trail_leg.transitions;
        let prev_start = d.trail_origin;
        for (j, kind) in [EventKind::FootFlat, EventKind::HeelOff, EventKind::MetaOff]
            .iter()
            .enumerate()
        {
            if let Some(tt) = tr[j] {
                let g = prev_start + tt;
                // A trailing leg's heel off is its own stance's event (above), but for the
                // walk's first trailing leg, whose stance is not recorded.
                if *kind == EventKind::HeelOff && k > 0 {
                    continue;
                }
                let g = if *kind == EventKind::HeelOff {
                    match d.trail_rho.first() {
                        Some(&(_, r0)) if r0 > HEEL_OFF_ROLL => continue,
                        _ => drawn_heel_off(&d.trail_rho, d.start, f64::NEG_INFINITY).unwrap_or(g),
                    }
                } else {
                    g
                };
                if g >= d.start - 1e-12 && g <= d.start + d.times.double_support + 1e-12 {
                    events.push(ev(g, d.side.opposite(), *kind));
                }
            }
        }
    }
    if let Some(d) = data.last() {
        events.push(ev(
            d.start + d.times.step,
            d.side.opposite(),
            EventKind::HeelStrike,
        ));
    }
    if let Some(c) = closing {
        let (w, tr) = (c.stance, c.stance.opposite());
        if let Some(tf) = c.stance_flat {
            events.push(ev(c.start + tf, w, EventKind::FootFlat));
        }
        // The trailing leg's heel off is its last stance's event (above).
        if let Some(tt) = c.trail_transitions[1] {
            events.push(ev(c.start + tt, tr, EventKind::MetaOff));
        }
        events.push(ev(c.start + c.toe_off, tr, EventKind::ToeOff));
        // The trailing foot lands flat beside the stance foot: heel strike and foot flat at once.
        events.push(ev(c.start + c.landing, tr, EventKind::HeelStrike));
        events.push(ev(c.start + c.landing, tr, EventKind::FootFlat));
    }
    // A steady walk's pre-roll step is drawn only over the lead-in, the step after the last
    // over the lead-out: their events outside the recording (the pre-roll's heel strike, its
    // trailing leg's toe off; the lead-out step's toe off and end) are not in it.
    events.retain(|e| e.time_s >= -1e-9 && e.time_s <= total + 1e-9);
    events.sort_by(|x, y| x.time_s.total_cmp(&y.time_s));
    events.dedup_by(|x, y| {
        x.kind == y.kind && x.side == y.side && (x.time_s - y.time_s).abs() < 1e-9
    });
    motion.events = events;
    Ok(motion)
}

/// The foot's roll (rad) above which the drawn heel is off the floor for the heel-off event
/// (`drawn_heel_off`): ≈ 0.2 mm of heel for a 0.18 m heel–ball length, below which the heel
/// is drawn on the floor within the checks' tolerances.
const HEEL_OFF_ROLL: f64 = 1e-3;

/// The time (global, s) of the first recorded roll sample (`(t, ρ)` on the clock starting at
/// `start`) at or after `after` whose roll exceeds [`HEEL_OFF_ROLL`]: where the drawn heel
/// leaves the floor.
///
/// Why not the heel-off rule's switch (`VirtualLeg::transitions`): the rule's period begins
/// when the ankle reaches its dorsiflexion limit or the foot must roll, but the drawn roll is
/// the least-bending curve above the rule's (`smooth_roll`, `hold_knees`), which can stay flat
/// well past the switch: the event came 5–14 frames (3–7 km/h) and up to 46 frames (1–2 km/h ×
/// 1.8–2.0 m) before the drawn heel was 0.2 mm up, and a few frames after it in 1.4 km/h ×
/// 1.6 m. `EventKind::HeelOff` is documented as the heel leaving the ground.
fn drawn_heel_off(rho: &[(f64, f64)], start: f64, after: f64) -> Option<f64> {
    rho.iter()
        .map(|&(t, r)| (start + t, r))
        .find(|&(g, r)| g >= after - 1e-12 && r > HEEL_OFF_ROLL)
        .map(|(g, _)| g)
}

/// One frame of the stop ([`Closing`]): pelvis level and unrotated, trunk returning to its lean,
/// arms following the opposite thighs as in the walk.
fn closing_pose(
    skeleton: &Skeleton,
    foot: &FootShape,
    c: &Closing,
    t: f64,
    a: &WalkAttributes,
    arms: &mut ArmLag,
) -> (crate::generator::skeleton::Pose, [bool; 2]) {
    let f = c.frame(t - c.start, foot);
    arms.settle = smoothstep(((t - c.start) / c.duration).clamp(0.0, 1.0));
    let mut pose = skeleton.rest_pose();
    pose.root = DVec3::new(f.hip[0], f.hip[1], f.lateral);
    let (w, tr) = (c.stance, c.stance.opposite());
    let place =
        |pose: &mut crate::generator::skeleton::Pose, side: Side, ft: ([f64; 2], f64, f64)| {
            let (ankle, pitch, bend) = ft;
            place_leg(
                skeleton,
                pose,
                side,
                [ankle[0], ankle[1], side_z(side, a)],
                pitch,
                bend,
            )
        };
    let stance_axis = place(&mut pose, w, f.stance_foot);
    let trail_axis = place(&mut pose, tr, f.trail_foot);
    pose.set_world_rotation(Joint::Lumbar, DQuat::from_rotation_z(-f.lean));
    pose.set_euler(Joint::ThoracicUpper, Euler::new(0.0, 0.0, 0.0));
    pose.set_world_rotation(Joint::Head, DQuat::IDENTITY);
    swing_arms(&mut pose, a, arms, [(w, trail_axis), (tr, stance_axis)]);
    let mut contact = [true; 2];
    contact[match tr {
        Side::Left => 0,
        Side::Right => 1,
    }] = f.trail_contact;
    (pose, contact)
}

/// The arms swing with the opposite leg (§4.3): shoulder flexion = −(arm gain) × the opposite
/// leg's angle (hip to ankle, lagged by [`ArmLag`]), the elbow flexed by its attribute plus half
/// of any forward shoulder flexion (its start rounded, [`soft_positive`]). One rule for the walk and the stop, so the hands cannot jump
/// where one hands over to the other. `sides`: (arm's side, opposite leg's sagittal angle, rad,
/// positive behind the hip).
///
/// The paper says only that "the arms swing forward with the opposite legs" (§4.3); we take the
/// leg as the hip–ankle line (the model's leg, θ1 in stance), not the thigh: the thigh also turns
/// with the knee, and at heel strike its knee-driven turns are fast and brief (the landing
/// stance knee flexing ≈ 0.13 rad in a frame at 7 km/h × 1.5 m turns the stance thigh forward
/// 0.09 rad in 4 frames while the leg's axis keeps rotating back smoothly). Worst shoulder or
/// elbow ratio over 1–7 km/h × 1.5–2.0 m with the earlier one-stage lag of 30 ms: thigh 5.95
/// (7 km/h × 1.5 m, one frame before heel strike), leg axis 3.9. Over a stride the leg's axis swings 10–20 % more than the thigh and ≈ 5°
/// further back: at the unchanged gain (with `ArmLag::gain`) the arm's swing each way,
/// measured 10.7 / 17.7 / 23.9° at 1 km/h × 1.8 m, 4 km/h × 1.8 m, 7 km/h × 1.5 m, is within
/// 12 % of the thigh-driven one (12.1 / 16.4 / 22.5°), and its middle moves 4–5° towards
/// extension, as a human's shoulder swings further behind the trunk than in front of it.
fn swing_arms(
    pose: &mut crate::generator::skeleton::Pose,
    a: &WalkAttributes,
    arms: &mut ArmLag,
    sides: [(Side, f64); 2],
) {
    let arm_gain = a.arm_swing_deg / 25.0 * ArmLag::gain();
    for (side, leg) in sides {
        let opposite_leg = arms.follow(side, leg);
        let [_, shoulder, elbow, _] = Joint::arm(side);
        let flex = -arm_gain * opposite_leg;
        pose.set_world_rotation(shoulder, DQuat::from_rotation_z(flex));
        let elbow_flex = a.elbow_flexion_deg.to_radians() + 0.5 * soft_positive(flex, ELBOW_BAND);
        pose.set_euler(elbow, Euler::sagittal(elbow_flex));
    }
}

/// Half-width of the band of shoulder flexion, rad, over which the elbow's extra flexion
/// (half of any forward flexion, [`swing_arms`]) starts: `max(flex, 0)` started it at the full
/// rate where the arm passes the vertical, a kink in the elbow (2 km/h × 1.8 m, the stop's arms
/// settling: 0 → 0.0042 rad/frame, 2.3 × its neighbours). ≈ 3°: the arm crosses it in 3–10
/// frames at 1–7 km/h.
const ELBOW_BAND: f64 = 0.05;

/// `max(x, 0)` with its corner rounded over |x| < `band` by the parabola (x + band)²/(4·band):
/// C¹, equal to `max(x, 0)` outside the band.
fn soft_positive(x: f64, band: f64) -> f64 {
    if x <= -band {
        0.0
    } else if x >= band {
        x
    } else {
        (x + band).powi(2) / (4.0 * band)
    }
}

/// Fraction of the stride cycle by which the arms trail the opposite leg ([`ArmLag`]): a human
/// arm's ≈ 10 %.
const ARM_LAG_CYCLE: f64 = 0.1;

/// The arms follow the opposite leg through a critically damped second-order lag: two equal
/// first-order stages, each delaying the stride's fundamental by half of [`ARM_LAG_CYCLE`]
/// (continuous time: τ = tan(π·ARM_LAG_CYCLE)·cycle/2π, 45 ms at 7 km/h × 1.5 m, 130 ms at
/// 1 km/h × 1.8 m), with the gain the two stages take from the fundamental, cos²(π·ARM_LAG_CYCLE)
/// = 0.905, given back (`ArmLag::gain`).
///
/// Why: the arm is a pendulum driven at the shoulder, not welded to the leg, and the leg's rate
/// changes within a frame or two at heel strike (the swing leg stops flexing and lands
/// retracting at the collision-neutral rate: at 7 km/h × 1.5 m −1.4 → +2.2 rad/s over the last
/// three frames). A one-to-one copy put that kink into the shoulder (4 km/h, 1.8/2.0 m: 6.1/6.4 ×
/// its neighbours' step); one stage of 30 ms kept the arm's angle C¹ but passed the kink as a
/// one-frame dip of its rate, which, where the arm turns at the opposite heel strike and its
/// steps are smallest, made the shoulder joint's step 5.95 × its neighbours' at 7 km/h × 1.5 m.
/// Two stages make the angle C² (the dip is spread over the lag). Measured, worst shoulder or
/// elbow ratio over 1–7 km/h × 1.5–2.0 m and the 2 → 5 → 3 km/h schedule, leg axis as input:
/// one stage of 30 ms 3.9; two of 30 / 40 ms 3.5 / 2.5 (8 % of the cycle at 7 km/h, 3 % at
/// 1 km/h); this cycle-scaled 10 %, 3.5 (7 km/h × 1.5 m; the thigh as input, 5.2 at 5 km/h ×
/// 1.5 m). Each step sets the lag for its own cycle (two of its steps); a change of speed changes
/// the filter's weight, not its state, so the arm stays C¹. In the stop's closing the lag fades
/// out (smoothstep over the closing), so the arms come to rest exactly when the legs do.
struct ArmLag {
    /// Frame rate, frames/s.
    fps: f64,
    /// Filter weight per frame and stage, 1 − exp(−Δt/τ).
    alpha: f64,
    /// How far the lag has faded out, 0 (full lag) to 1 (the arm copies the leg).
    settle: f64,
    /// The lagged leg angle per arm (left, right) after the first and the second stage, rad;
    /// `None` before the first frame.
    state: [Option<[f64; 2]>; 2],
}

impl ArmLag {
    /// A lag for frames at `fps`, tuned to a 1 s cycle until [`ArmLag::set_cycle`].
    fn new(fps: f64) -> Self {
        let mut lag = Self {
            fps,
            alpha: 1.0,
            settle: 0.0,
            state: [None; 2],
        };
        lag.set_cycle(1.0);
        lag
    }

    /// Tunes each stage to delay a stride of `cycle` s by half of [`ARM_LAG_CYCLE`]; returns its
    /// time constant, s. The weight is the discrete stage's exact one: `y ← b·y + (1 − b)·u`
    /// delays a sinusoid of θ rad per frame by φ where b = sin φ / sin(θ + φ).
    fn set_cycle(&mut self, cycle: f64) -> f64 {
        let phi = PI * ARM_LAG_CYCLE;
        let theta = 2.0 * PI / (self.fps * cycle.max(1e-3));
        let b = phi.sin() / (theta + phi).sin();
        self.alpha = 1.0 - b;
        -1.0 / (self.fps * b.ln())
    }

    /// The arm's gain on its lagged leg angle: what the two stages take from the stride's
    /// fundamental, given back. Constant (through the stop's closing too): a gain that changed
    /// with the lag's fade would move the arm while the legs stand still.
    fn gain() -> f64 {
        1.0 / (PI * ARM_LAG_CYCLE).cos().powi(2)
    }

    /// Advances `side`'s arm by one frame towards the opposite leg's angle `leg`.
    fn follow(&mut self, side: Side, leg: f64) -> f64 {
        let slot = &mut self.state[match side {
            Side::Left => 0,
            Side::Right => 1,
        }];
        let w = self.alpha + (1.0 - self.alpha) * self.settle;
        let y = match *slot {
            Some([y1, y2]) => {
                let y1 = y1 + w * (leg - y1);
                [y1, y2 + w * (y1 - y2)]
            }
            None => [leg, leg],
        };
        *slot = Some(y);
        y[1]
    }
}

/// Thigh angle θ3 and knee flexion θ4 of the sagittal two-link chain from `hip` to `ankle`.
pub fn sagittal_angles(hip: [f64; 2], ankle: [f64; 2], l3: f64, l4: f64) -> [f64; 2] {
    let dx = hip[0] - ankle[0];
    let dy = hip[1] - ankle[1];
    let d = dx.hypot(dy).clamp((l3 - l4).abs() + 1e-12, l3 + l4);
    let cos_k = ((l3 * l3 + l4 * l4 - d * d) / (2.0 * l3 * l4)).clamp(-1.0, 1.0);
    let knee = PI - cos_k.acos();
    // Angle at the hip between the hip–ankle line and the thigh; the knee bends forward.
    let cos_h = ((l3 * l3 + d * d - l4 * l4) / (2.0 * l3 * d)).clamp(-1.0, 1.0);
    let line = dx.atan2(dy); // the hip–ankle line's angle, same sign convention as θ3
    [line - cos_h.acos(), knee]
}

/// Swings from standing that keep the paper's toe off (no brisk knee flexion at toe off,
/// `TOE_OFF_KNEE_RATE`): the first only, whose trailing leg stood under the hip with its knee
/// bounded by [`FIRST_TOE_OFF_THIGH`]. Until klawstart2 they also kept the paper's unbraked swing
/// (`SwingSpec::knee_brake`); the first swing is now braked with its swing1 chosen by
/// `first_swing_shape` (the measurements below are of that earlier state).
///
/// Measured (`kstart`: 6 steps from standing + stop, 1.5/1.8/2.0 m): 3 (the earlier hand-off)
/// → 1 takes the second swing's ankle peak/mean speed at 1/2/3/5/7 km/h from 2.96/2.70/2.87,
/// 2.84/2.90/2.81, 2.33/2.38/2.38, 1.65/1.72/1.79, 1.67/1.60/1.59 to 2.50/2.69/2.80,
/// 2.21/2.21/2.15, 1.81/1.84/1.84, 1.31/1.43/1.52, 1.38/1.32/1.33 (the third's at 2 km/h from
/// 3.0–3.2 to 2.0–2.3), the start region no worse anywhere (2 km/h × 1.5/2.0 m 4.42/4.97 →
/// 4.12/4.75); 0 (the first swing braked too) left its peak/mean about the same at 1–2 km/h,
/// worse at 3–7 km/h (3.0–3.2 → 3.2–3.4, 1.9–2.0 → 2.5–2.7) and 5 km/h × 1.5 m's start at 13.6.
///
/// The swings before a stop are braked like every steady swing (`SwingSpec::knee_brake`, the
/// brisk toe off): the stop's half step and the swing before it used to keep the paper's swing
/// (`LAST_PAPER_SWINGS` = 2), and the half step's swing2 ended at 77 % of the swing instead of
/// 85 % (`STOP_SWING2_ADVANCE` = 0.08) so that its unbraked knee, extending at 10–15 rad/s,
/// locked earlier. Ending swing2 earlier extended the knee while the foot was still low: that
/// swing needed the whole stubbing recovery ([`super::swing::RECOVERY_MAX_RAD`], 0.8 rad) at
/// 3–4 km/h × 1.5–1.55 m and cleared the 5 mm toe clearance by one grid step. Braked, the knee
/// comes to rest at the lock by itself, so swing2 keeps its 85 %.
///
/// Measured (`krec`, 8 steps from standing or steady with a stop, 1–7 km/h every 0.5 ×
/// 1.5–2.0 m every 5 cm): the half step's recovery at most 0.80 → 0.64 rad (3.5 km/h × 1.5 m),
/// no ground penetration, no sliding. Continuity (6 steps + stop, steady start, 1.5/1.8/2.0 m):
/// the last half step 1–3 km/h 4.0–6.6 → 2.7–4.6 (3 km/h × 2.0 m 6.62 → 2.92); the whole walk
/// no worse anywhere, better at 1–6 km/h (2 km/h × 1.8 m 5.56 → 4.57, 3 km/h × 2.0 m
/// 6.62 → 3.81, 4 km/h × 2.0 m 5.98 → 3.23); the schedule 2 → 5 → 3 km/h × 1.8 m 6.08 → 4.71.
/// The closing region alone got worse at 1 km/h × 1.5/2.0 m (2.3/1.94 → 4.78/2.44: the landing
/// knee leaves its lock at 0.5 rad/s, then slows, against a knee at rest before it), 5 km/h ×
/// 1.5/1.8 m (2.1/2.8 → 3.1/3.5) and 7 km/h × 1.5 m (2.6 → 3.4), all within k = 5. Braking
/// only the swing before the half step (the half step on the paper's swing, 77 %) left the
/// recovery at 0.80 rad; the half step braked with swing2 at 81 % needed 0.80 (and cleared
/// only 3.5 mm), at 83 % 0.74.
const FIRST_PAPER_SWINGS: usize = 1;

/// The first swing from standing's two shapes (see [`first_swing_shape`]), each at its end of
/// the walk's speed over body height `u` (1/s):
/// - slow (`u` up to [`FIRST_SWING_FAST`]`[0]`): an early end of swing1 with the paper's lift,
///   swing1 lifting the foot and the braked swing2 carrying it over most of the swing. Its
///   swing1 ends at [`FIRST_SWING1_ENDS`]`[0]` (25 % of the swing) up to
///   `FIRST_SWING_SLOW[0]` and at `FIRST_SWING1_ENDS[1]` (30 %) from `FIRST_SWING_SLOW[1]`,
///   blended in between;
/// - fast (`u` from `FIRST_SWING_FAST[1]`): the paper's end of swing1 with no lift.
///
/// `FIRST_SWING_SLOW`, 1/s: where the early end goes from 25 % to 30 % of the swing. 30 % is
/// not bell-shaped at the slowest walks (drawn ankle peak/mean 2.5–2.55 at 1 km/h × 1.8 m,
/// against 2.31–2.35 with 25 %), and 25 % lifted the toe off too fast at 2–3 km/h (continuity
/// 7.8 at 2 km/h × 1.5 m and 6.7 at 3 km/h × 1.8 m, against 2.9 and 3.2 with 30 %). The old
/// selection by the model's peak/mean switched between them at 1.2–1.5 km/h, `u` = 0.21–0.22
/// at 1.5/1.8/2.0 m.
const FIRST_SWING_SLOW: [f64; 2] = [0.15, 0.22];

/// Where the first swing from standing goes from its slow shape to its fast one (see
/// [`FIRST_SWING_SLOW`]), in walking speed over body height, 1/s: 0.46–0.62 is 2.5–3.3 km/h
/// at 1.5 m, 3.0–4.0 km/h at 1.8 m, 3.3–4.5 km/h at 2.0 m. The old selection (the first of the
/// two whose model ankle peak/mean was at most 2.4) switched at `u` = 0.53–0.54 at all three
/// heights (2.9/3.4/3.9 km/h), which is why `u` and not the Froude number (0.044/0.050/0.060
/// there) parameterizes the blend. Measured (`kfs`, 2 steps from standing + stop, 1.0–7.0 km/h
/// every 0.1, drawn ankle): 0.46–0.62 kept the first swing's peak/mean ≤ 2.42 everywhere and
/// halved the largest jump of its peak speed between neighbouring speeds at 1.8 m; a blend that
/// drops the lift before the swing1 end rises (over 0.42–0.6) saturated the stubbing recovery
/// at 2.8–3.5 km/h (peak/mean 3.3–3.7), and one that keeps the lift while the swing1 end rises
/// threw the slaved ankle across its curve near t1 (peak/mean to 4.4).
const FIRST_SWING_FAST: [f64; 2] = [0.46, 0.62];

/// The early ends of swing1 (fractions of the swing) of the first swing from standing's slow
/// shape: 25 % at the slowest walks, 30 % from `FIRST_SWING_SLOW[1]` (see [`FIRST_SWING_SLOW`]).
///
/// Measured (`kstart`, 6 steps from standing + stop, braked first swing with the paper's lift,
/// 1.5/1.8/2.0 m, on 4b3f141): 0.25 / 0.3 left its ankle's peak/mean speed at 1 km/h
/// 2.30–2.43 / 2.50–2.64 and at 2 km/h 2.00–2.09 / 2.22–2.32, but 0.25 put the toe off at 2 km/h
/// × 1.5 m and 3 km/h × 1.8 m at 7.8 and 6.7 (the toe leaving the floor, against 2.9 and 3.2
/// with 0.3). Before 4b3f141 (swing2's hip lead): 0.3 / 0.35 / 0.4 / 0.45 / 0.5
/// left 1 km/h at 2.3–2.4 / 2.5–2.7 / 2.9–3.0 / 3.2–3.4 / 3.7–3.9 and 2 km/h at 2.1–2.2 /
/// 2.3–2.4 / 2.6–2.7 / 2.9–3.0 / 3.4–3.5.
const FIRST_SWING1_ENDS: [f64; 2] = [0.25, 0.3];

/// The first swing from standing's `(swing1 end, ankle lift)`: a continuous (C¹, smoothstep)
/// function of the walk's speed over body height `u = speed / height`, from the slow shape
/// (an early swing1 end, [`FIRST_SWING1_ENDS`], with the paper's `ankle_lift`) to the fast one
/// (the paper's `swing1_end`, no lift) over [`FIRST_SWING_FAST`]. It is braked
/// (`SwingSpec::knee_brake`) like every swing.
///
/// Why two shapes: the first swing's ankle travels one step length from beside the stance
/// foot while the hip starts from rest, so at the paper's end of swing1 (thigh at its
/// heel-strike angle, ≈ 20 % of the step on) the knee is barely ahead of the toe-off ankle and
/// the travel there is `MIN_TRAVEL`-bound (`SwingSpec::curve`). With the paper's lift that
/// curve passes inside the circle the ankle can reach about the knee at t1 (by 5–16 mm at
/// 1–3 km/h): the slaved ankle stays on the curve's near branch, rises in place (3 cm forward
/// of 14 at 2 km/h × 1.8 m), and swing2 carried the rest (peak/mean 3.0–3.9 at 1–3 km/h, the
/// knee locking at 7.7 rad/s unbraked); at 4–5 km/h the curve is barely reachable and the
/// slaved ankle raced along it near t1 (4.4 m/s at 5 km/h × 1.5 m, peak/mean 2.4–5.9). The
/// paper's swing1 end with no lift ends the curve on the ankle's branch, but at 1–3 km/h it is
/// too low (the toe needs the whole stubbing recovery, peak/mean 3.3–4.2); the early end with
/// the lift lifts the foot in swing1, but at 4–5 km/h the thigh's fast swing to its
/// heel-strike angle drags the slaved ankle across the curve's branches (peak/mean 4–38).
///
/// Until klawtidy (session 9) the first of the three shapes (paper's, 30 %, 25 %) whose model
/// ankle peak/mean was at most 2.4 was kept: the swing1 end jumped 0.5 → 0.3 and the first
/// swing's drawn ankle peak speed by 0.39/0.53/0.90 m/s between neighbouring speeds 0.1 km/h
/// apart (1.5/1.8/2.0 m), at 2.9/3.4/3.9 km/h; and it took up to three swing solves.
fn first_swing_shape(speed: f64, height: f64, swing1_end: f64, ankle_lift: f64) -> (f64, f64) {
    let u = speed / height;
    let blend = |[a, b]: [f64; 2]| smoothstep((u - a) / (b - a));
    let [slowest, slow] = FIRST_SWING1_ENDS;
    let early = slowest + (slow - slowest) * blend(FIRST_SWING_SLOW);
    let fast = blend(FIRST_SWING_FAST);
    (
        early + (swing1_end - early) * fast,
        ankle_lift * (1.0 - fast),
    )
}

/// The swing thigh's rate θ̇3 at heel strike for which the collision
/// ([`collision::heel_strike`]) leaves the stance hip's forward velocity unchanged, rad/s: the
/// new stance's generalized momenta are linear in θ̇3 (the swing leg's angular momentum about
/// the new pivot), so two evaluations give it exactly. `old` is the stance state at heel strike,
/// `hip` the swing hip's motion then, `theta3` the heel-strike thigh angle (eq. 3).
fn neutral_landing_rate(
    body: &Body,
    model: &StanceModel,
    old: &[f64; 6],
    old_ankle: [f64; 2],
    hip: HipMotion,
    theta3: f64,
    new_ankle: [f64; 2],
) -> f64 {
    let [w, t1, _, wd, t1d, _] = *old;
    let before = wd * t1.sin() + w * t1d * t1.cos();
    let jump = |rate: f64| {
        let s = collision::heel_strike(
            body,
            model,
            old,
            old_ankle,
            &SwingAtImpact {
                hip: hip.pos,
                hip_vel: hip.vel,
                theta3: [theta3, rate],
            },
            new_ankle,
        );
        let (q, qd) = (s.q, s.qd);
        qd[0] * q[1].sin() + q[0] * qd[1] * q[1].cos() - before
    };
    let (j0, j1) = (jump(0.0), jump(1.0));
    if (j1 - j0).abs() > 1e-12 {
        -j0 / (j1 - j0)
    } else {
        0.0
    }
}

/// The drawn swing ankle's target: the sagittal model's ankle, moved along the line from the
/// skeleton's hip joint by the fraction `w` of the way to the model's hip–ankle span `span`.
///
/// Why: the swing model is sagittal, but the drawn hip joint sits ≈ 4 cm beside the foot's line,
/// so the 3-D hip–ankle distance is ≈ dz²/2d ≈ 1 mm longer than the model's and the drawn knee
/// is ≈ 5° straighter. Near the end of swing2, where the model's knee comes to rest straight
/// ([`SwingSpec`]'s knee brake), the drawn knee would hit straight (the ankle out of reach) some
/// 20 ms early and stop there in one frame, snapping the thigh (and the arms, which follow the
/// thigh). With `w` = 1 the drawn knee has the model's angle exactly; `w` ramps in over swing2
/// (so the toe-off ankle, drawn where the stance foot left it, does not jump), and the ankle
/// moves by that millimetre gradually. At heel strike the straight leg is drawn along the line
/// to its out-of-reach ankle as before.
fn swing_span_target(
    skeleton: &Skeleton,
    pose: &crate::generator::skeleton::Pose,
    side: Side,
    ankle: [f64; 3],
    span: f64,
    w: f64,
) -> [f64; 3] {
    let h = skeleton.forward(pose).position(Joint::leg(side)[0]);
    let v = DVec3::new(ankle[0], ankle[1], ankle[2]) - h;
    let len = v.length();
    if w <= 0.0 || len <= 1e-9 {
        return ankle;
    }
    let p = h + v * (1.0 - w + w * span / len);
    [p.x, p.y, p.z]
}

/// Places one leg: ankle at `ankle` (world), foot pitched by `pitch` with toe bend `bend`.
/// Returns the leg's sagittal angle, hip to ankle (positive: ankle behind the hip), which the
/// opposite arm follows ([`swing_arms`]).
fn place_leg(
    skeleton: &Skeleton,
    pose: &mut crate::generator::skeleton::Pose,
    side: Side,
    ankle: [f64; 3],
    pitch: f64,
    bend: f64,
) -> f64 {
    let target = DVec3::new(ankle[0], ankle[1], ankle[2]);
    leg_ik(skeleton, pose, side, target, DVec3::X);
    let [hip, _, ank, mtp] = Joint::leg(side);
    pose.set_world_rotation(ank, DQuat::from_rotation_z(pitch));
    pose.set_euler(mtp, Euler::sagittal(bend));
    let g = skeleton.forward(pose);
    let h = g.position(hip);
    let an = g.position(ank);
    (h.x - an.x).atan2(h.y - an.y)
}

/// How far forward the first swing leg's thigh may be at toe off from standing, as a fraction of
/// its heel-strike angle θ3 (eq. 3), so that swing1 still swings it forward to that angle.
///
/// The first trailing leg stands under the hip, so flexing its knee to the toe-off value (35°)
/// pitches the thigh forward by about half of that — at 1–2 km/h beyond the heel-strike angle
/// (≈ 10–15°) — and swing1, which brings the thigh to its heel-strike angle, then swung it back
/// while the slaved knee dragged the ankle behind its start (at 1 km/h onto the curve's other
/// branch: ratios 200–600). Measured (first swing's ankle peak/mean speed, 1.5/1.8/2.0 m): with
/// 0.6 the knee flexes fully at 7 km/h, to 0.51–0.57 rad at 5 km/h and 0.41–0.46 at 3 km/h, and
/// 5 / 7 km/h go from 3.2–3.8 / 2.5–2.9 (no roll) to 2.4–2.7 / 1.8–2.0, 1–3 km/h unchanged; at
/// 1–2 km/h the bound leaves the knee no more flexion than the lowering hip gives it anyway, so
/// that foot still leaves nearly flat (heel ≤ 7 mm up). 1.0 left 1 km/h's second swing at
/// 5.4–6.4.
pub const FIRST_TOE_OFF_THIGH: f64 = 0.6;

/// The knee flexion the first trailing leg from standing flexes to through its double support
/// (the meta-off rule, from `knee_now` at its start): the leg's own toe-off value, or less where
/// that would leave the thigh at toe off further forward than `thigh_min` (θ3 < 0 forward). The
/// thigh's angle at toe off is that of the sagittal hip–ankle chain after running the rule over
/// `hips` (`(leg clock, hip, dz)`); it decreases as the knee flexes more (bisection, 20 halvings).
fn first_toe_off_knee(
    leg: &VirtualLeg,
    hips: &[(f64, [f64; 2], f64)],
    knee_now: f64,
    thigh_min: f64,
) -> f64 {
    let thigh_for = |k: f64| {
        let mut l = leg.clone();
        l.knee_toe_off = k;
        let mut last = None;
        for &(t, hip, dz) in hips {
            last = Some((l.advance(t, hip, dz).ankle, hip));
        }
        last.map_or(0.0, |(ankle, hip)| {
            sagittal_angles(hip, ankle, leg.l3, leg.l4)[0]
        })
    };
    let (mut lo, mut hi) = (knee_now.min(leg.knee_toe_off), leg.knee_toe_off);
    if thigh_for(hi) >= thigh_min {
        return hi;
    }
    for _ in 0..20 {
        let mid = 0.5 * (lo + hi);
        if thigh_for(mid) < thigh_min {
            hi = mid;
        } else {
            lo = mid;
        }
    }
    lo
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn soft_positive_is_max_with_a_c1_corner() {
        let b = ELBOW_BAND;
        for x in [-1.0, -b, b, 0.3] {
            assert!((soft_positive(x, b) - x.max(0.0)).abs() < 1e-15, "{x}");
        }
        // Value and slope continuous at the band's edges, monotone inside.
        let h = 1e-7;
        for e in [-b, b] {
            let left = (soft_positive(e, b) - soft_positive(e - h, b)) / h;
            let right = (soft_positive(e + h, b) - soft_positive(e, b)) / h;
            assert!(
                (left - right).abs() < 1e-5,
                "slope at {e}: {left} vs {right}"
            );
        }
        assert!((soft_positive(0.0, b) - b / 4.0).abs() < 1e-15);
    }

    /// The arm lag is two equal first-order stages, per arm; faded out (`settle` = 1) the arm
    /// copies the leg.
    #[test]
    fn arm_lag_is_a_second_order_lag_that_fades_out() {
        for fps in [100.0, 120.0, 250.0] {
            let mut lag = ArmLag::new(fps);
            let tau = lag.set_cycle(1.1);
            // The discrete stage's time constant is the continuous one's, tan(π/10)·cycle/2π,
            // plus ≈ half a frame (the stage takes the current frame's input: half a frame of
            // lead that its weight gives back).
            let lead = (tau - (0.1 * PI).tan() * 1.1 / (2.0 * PI)) * fps;
            assert!(lead > 0.5 && lead < 0.6, "{fps} fps: {lead} frames");
            assert_eq!(lag.follow(Side::Left, 0.0), 0.0);
            assert_eq!(lag.follow(Side::Right, -0.5), -0.5);
            // A unit step of the left leg: after n frames two stages of weight a have come
            // 1 − (1 − a)ⁿ (1 + n a) of the way.
            let n = (2.0 * tau * fps).round() as usize;
            let a = 1.0 - (-1.0 / (fps * tau)).exp();
            let mut y = 0.0;
            let mut steps = vec![];
            for _ in 0..n {
                let y1 = lag.follow(Side::Left, 1.0);
                steps.push(y1 - y);
                y = y1;
            }
            let expected = 1.0 - (1.0 - a).powi(n as i32) * (1.0 + n as f64 * a);
            assert!((y - expected).abs() < 1e-12, "{fps} fps: {y} vs {expected}");
            // C¹: the step's rate starts from nothing (a² in the first frame, a one-stage lag's
            // was a) and rises before it falls.
            assert!((steps[0] - a * a).abs() < 1e-12);
            assert!(steps[1] > steps[0]);
            // The other arm kept its own state.
            assert_eq!(lag.follow(Side::Right, -0.5), -0.5);
            lag.settle = 1.0;
            assert!((lag.follow(Side::Left, 0.3) - 0.3).abs() < 1e-15);
        }
    }

    /// At any stride cycle (0.85 s, 7 km/h × 1.5 m, to 2.5 s, 1 km/h × 1.8 m) and frame rate the
    /// arm trails a sinusoidal leg by `ARM_LAG_CYCLE` of the cycle, and with its gain keeps the
    /// leg's amplitude within 5 % (the discrete stages lose a little more than the continuous
    /// cos² the gain gives back: 2.4 % at 100 fps and 4 % at 60 fps for a 0.85 s cycle).
    #[test]
    fn arm_lag_trails_the_leg_by_a_tenth_of_the_cycle() {
        for fps in [60.0, 100.0, 250.0] {
            for cycle in [0.85, 1.25, 2.5] {
                let mut lag = ArmLag::new(fps);
                lag.set_cycle(cycle);
                let om = 2.0 * PI / cycle;
                let m = cycle * fps;
                let n = (8.0 * m) as usize;
                let out: Vec<f64> = (0..n)
                    .map(|i| ArmLag::gain() * lag.follow(Side::Left, (om * i as f64 / fps).sin()))
                    .collect();
                // The last whole cycles: the output's fit a·sin + b·cos.
                let k = (3.0 * m).floor() as usize;
                let (mut s, mut c, mut ss, mut cc, mut sc) = (0.0, 0.0, 0.0, 0.0, 0.0);
                for (i, y) in out.iter().enumerate().skip(n - k) {
                    let (sn, cs) = (om * i as f64 / fps).sin_cos();
                    s += y * sn;
                    c += y * cs;
                    ss += sn * sn;
                    cc += cs * cs;
                    sc += sn * cs;
                }
                let det = ss * cc - sc * sc;
                let (fa, fb) = ((s * cc - c * sc) / det, (c * ss - s * sc) / det);
                let amp = fa.hypot(fb);
                let delay = (-fb).atan2(fa) / (2.0 * PI);
                assert!(
                    (amp - 1.0).abs() < 0.05,
                    "{fps} fps, {cycle} s: amplitude {amp}"
                );
                assert!(
                    (delay - ARM_LAG_CYCLE).abs() < 1e-9,
                    "{fps} fps, {cycle} s: delay {delay} of the cycle"
                );
            }
        }
    }

    #[test]
    fn swing_hip_offset_matches_the_pelvis_rotation() {
        for swing in [Side::Left, Side::Right] {
            let d = Determinants {
                duration: 0.56,
                rotation: 0.07,
                list: 0.08,
                lateral: 0.02,
                half_width: 0.09,
                swing,
                from_rest: false,
                to_rest: false,
            };
            for k in 0..=20 {
                let t = 0.56 * k as f64 / 20.0;
                let o = d.swing_offset(t);
                let a = d.swing_hip_offset(t);
                assert!((a[0] - o.x).abs() < 1e-12 && (a[1] - 2.0 * o.y).abs() < 1e-12);
            }
            // The analytic rates against central differences.
            for k in 1..20 {
                let t = 0.56 * k as f64 / 20.0;
                let e = 1e-4;
                let (p, v, a) = d.swing_hip_offset_rates(t);
                let (pp, pm) = (d.swing_hip_offset(t + e), d.swing_hip_offset(t - e));
                let o = d.swing_hip_offset(t);
                for i in 0..2 {
                    assert!((p[i] - o[i]).abs() < 1e-15);
                    assert!((v[i] - (pp[i] - pm[i]) / (2.0 * e)).abs() < 1e-7);
                    assert!((a[i] - (pp[i] - 2.0 * o[i] + pm[i]) / (e * e)).abs() < 1e-4);
                }
            }
            // Rotation: swing hip behind at the start, ahead at heel strike; list 0 at both.
            assert!(d.swing_hip_offset(0.0)[0] < 0.0 && d.swing_hip_offset(0.56)[0] > 0.0);
            assert!(d.swing_hip_offset(0.28)[1] < 0.0 && d.swing_hip_offset(0.0)[1].abs() < 1e-12);
        }
    }
}
