//! The swing phase (§4.3): a double pendulum hanging from the moving swing hip, in three
//! subphases whose durations are known beforehand (ends at `swing1_end` and `swing2_end` of the
//! swing, about 50 % and 85 %):
//! - *swing1* (toe-off → t1): hip torque `F_θ3 = A·e^{−(t−t0)/τ}`, `A` found so that `θ3(t1)` is
//!   the heel-strike value; the knee is locked in the dynamics (eq. 5 with correction 4) and its
//!   angle is set, at every evaluation, so that the ankle lies on the 4th-order polynomial `P`
//!   through the five conditions of §4.3;
//! - *swing2* (t1 → t2): hip held by a spring–damper about the heel-strike angle (here, with the
//!   knee brake, the hip torque follows a terminal-swing path of the thigh, with the
//!   spring–damper on its error: the thigh stops flexing and starts to retract
//!   [`RETRACTION_CYCLE`] of the gait cycle before heel strike, as a human thigh does, where the
//!   paper's stays at the heel-strike angle until the knee locks), knee torque
//!   `F_θ4 = B·e^{−(t−t1)/τ}`, `B` found so that the knee is straight (`θ4 = 0`) exactly at t2 —
//!   here plus a terminal knee brake `E·uⁿ` (the hamstrings), `B`
//!   and `E` found together so that the knee is also at rest at t2 ([`KNEE_BRAKE_POWER`]: the
//!   paper's knee slams into the lock at 5–7 rad/s);
//!   if a foot point comes closer to the ground than the toe clearance, a position actuator
//!   (a temporary forward shift of the hip's set point, `pa3·sin(π·τ)`, here over the first
//!   [`RECOVERY_END`] of swing2, at most until the thigh's peak flexion) is increased step by step
//!   and swing2 repeated — the ground-stubbing recovery;
//! - *swing3* (t2 → heel strike): the knee is locked straight (the locking impulse conserves the
//!   thigh's generalized momentum), hip torque `F_θ3 = C·e^{−(t−t2)/τ}`, `C` found so that
//!   `θ3` reaches the heel-strike value exactly at `t_swing`, which with eq. (3) puts the heel on
//!   the ground.
//!
//! The foot is kinematic: the ankle angle θ5 and the toe bend θ6 are interpolated (C¹) between
//! their toe-off and heel-strike values.
use super::ankle_curve::PEAK_AT;
pub use super::ankle_curve::{knee_on_circle, AnkleCurve, KNEE_BRANCH_STEP};
use super::dynamics::{HipMotion, SwingModel};
use super::foot::{FootPoints, FootShape};
use super::integrate::{integrate, spectral_radius, stable_step};
use super::shooting::{solve_1d, solve_1d_with, solve_2d_with, Solved};
pub use super::swing_foot::{SwingFoot, CLEARANCE_RAMP_MIN, CLEARANCE_SOFT};
use super::track::{Node, Track};
use crate::generator::numeric::bisect;
use std::cell::RefCell;
use std::collections::HashMap;
use std::hash::{BuildHasherDefault, Hasher};

/// Everything that defines one swing phase.
#[derive(Clone, Copy)]
pub struct SwingSpec<'a> {
    /// The double pendulum.
    pub model: SwingModel,
    /// The foot.
    pub foot: FootShape,
    /// The swing hip's motion (x from the stance ankle, y above the ground) at stance time t.
    pub hip: &'a dyn Fn(f64) -> HipMotion,
    /// Times where the hip's acceleration jumps (integration restarts there), s.
    pub breakpoints: &'a [f64],
    /// Toe-off, end of swing1, end of swing2, heel strike (stance time), s.
    pub times: [f64; 4],
    /// Thigh angle at heel strike (eq. 3), rad.
    pub theta3_hs: f64,
    /// Ankle angle θ5 at toe-off, at the end of swing1 and at heel strike, rad.
    pub theta5: [f64; 3],
    /// Toe bend θ6 at toe-off, rad (0 at heel strike).
    pub theta6_toe_off: f64,
    /// Height of `a_max` above the higher end of the ankle curve, m.
    pub ankle_lift: f64,
    /// Decay time constants of the three subphases' exponential torques, s.
    pub tau: [f64; 3],
    /// Hip spring (N·m/rad) and damper (N·m·s/rad) of swing2.
    pub hip_spring: [f64; 2],
    /// Minimum clearance of the foot over the ground in swing2, m.
    pub clearance: f64,
    /// Largest ankle angle θ5 of the swing foot (dorsiflexion limit), rad.
    pub theta5_max: f64,
    /// Largest integration step, s.
    pub max_step: f64,
    /// Whether swing2 ends with the knee brought to rest ([`KNEE_BRAKE_POWER`]) while the hip
    /// follows the thigh's terminal-swing path ([`RETRACTION_CYCLE`]; the recovery's shift over
    /// [`RECOVERY_END`], at most until the path's peak) and swing3 lands the thigh at
    /// [`SwingSpec::theta3_rate_hs`]; otherwise the paper's swing2 and swing3 (one torque each,
    /// the knee locks at whatever rate it reaches).
    pub knee_brake: bool,
    /// Thigh rate θ̇3 at heel strike, rad/s, which swing3 meets (with a second torque, a ramp
    /// `D·(t − t2)/(t_swing − t2)`) when `knee_brake` is set: `generate` passes the rate for
    /// which the heel-strike collision leaves the hip's forward velocity unchanged.
    pub theta3_rate_hs: f64,
}

/// State at toe-off: `[θ3, θ4]` and rates.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SwingStart {
    /// `[θ3, θ4]`, rad.
    pub q: [f64; 2],
    /// `[θ̇3, θ̇4]`, rad/s.
    pub qd: [f64; 2],
}

/// Solver state carried from one step's swing to the next (like the force profiles
/// [`SwingRun::params`]): with it a steady walk's two-unknown solves start next to their
/// solution with a usable Jacobian.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct SwingCarry {
    /// Last slope of swing1's residual in its torque `A` (rad per N·m).
    pub swing1_slope: Option<f64>,
    /// Last (Broyden-updated) Jacobian of swing2's solve for the knee torque and brake `(B, E)`.
    pub swing2_jacobian: Option<[[f64; 2]; 2]>,
    /// The recovery actuator (rad) at which swing2's `(B, E)` of [`SwingRun::params`] was found.
    pub swing2_recovery: f64,
    /// Change of swing2's `(B, E)` per recovery grid step (0.02 rad of actuator), from the last two
    /// grid points solved in one step: moves the start of a solve to the grid point it is for.
    pub swing2_per_grid_step: Option<[f64; 2]>,
    /// Last Jacobian of swing3's solve for `(C, D)`.
    pub swing3_jacobian: Option<[[f64; 2]; 2]>,
}

/// Outcome of a simulated swing.
#[derive(Debug, Clone, PartialEq)]
pub struct SwingRun {
    /// The trajectory of `[θ3, θ4]`.
    pub track: Track<2>,
    /// Shooting iterations of swing1, swing2 (all recovery rounds), swing3.
    pub iterations: [usize; 3],
    /// Torque parameters `A`, `B`, `C` found, the swing1 recovery's lift of the ankle curve (m),
    /// the swing2 recovery's position actuator (rad), the swing2 knee brake `E` (see
    /// [`KNEE_BRAKE_POWER`]) and swing3's ramp `D` (see [`SwingSpec::theta3_rate_hs`]); the
    /// next step starts from them.
    pub params: [f64; 7],
    /// What the next step's [`SwingSpec::solve_with`] starts its solves from besides `params`.
    pub carry: SwingCarry,
    /// Final position actuator of the stubbing recovery, rad (0 if not needed).
    pub recovery: f64,
    /// Recovery rounds used.
    pub recovery_rounds: usize,
    /// Lowest foot clearance over the swing after toe-off, m.
    pub min_clearance: f64,
    /// `θ3` error at t1 and at heel strike, `θ4` at t2, rad.
    pub end_errors: [f64; 3],
    /// The ankle curve.
    pub curve: AnkleCurve,
}

const TOL: f64 = 1e-8;

/// Increment of the swing2 recovery's position actuator, rad.
const RECOVERY_STEP: f64 = 0.02;

/// Largest number of recovery increments (0.8 rad of set-point shift).
const RECOVERY_MAX: usize = 40;

/// Largest set-point shift of swing2's ground-stubbing recovery, rad (`RECOVERY_MAX` grid steps of
/// 0.02 rad).
pub const RECOVERY_MAX_RAD: f64 = RECOVERY_MAX as f64 * RECOVERY_STEP;

/// Power `n` of the swing2 knee brake's shape `E·uⁿ` (`u` the fraction of swing2).
pub const KNEE_BRAKE_POWER: i32 = 6;

/// Fraction of swing2 over which the ground-stubbing recovery's set-point shift
/// `pa·sin(π·u/RECOVERY_END)` acts (the paper's shape spans all of swing2).
pub const RECOVERY_END: f64 = 0.85;

/// Time before heel strike at which the swing thigh reaches its peak flexion and starts to retract,
/// as a fraction of the gait cycle (two steps, `2·t_step`).
pub const RETRACTION_CYCLE: f64 = 0.13;

/// Largest share of the time from the end of swing1 to heel strike that the retraction of the
/// thigh's terminal-swing path (`ThighPath`) may take.
pub const RETRACTION_SHARE_MAX: f64 = 0.75;

/// Power `n` of the retraction of the thigh's terminal-swing path (`ThighPath`).
pub const RETRACTION_POWER: f64 = 4.0;

/// The swing thigh's terminal-swing path from the end of swing1 (`t1`, where swing1 left it:
/// at the heel-strike angle, still flexing) to heel strike (`t3`, at the heel-strike angle and
/// the landing rate `θ̇3_hs`), which the knee-braked swing2's hip follows:
/// - from `t1` to the peak at `tp = t3 − T_r` ([`RETRACTION_CYCLE`]) the cubic Hermite that
///   stops the flexion at `θ_peak`;
/// - from `tp` the retraction `θ_peak + Δ·vⁿ` ([`RETRACTION_POWER`]) with `Δ = θ̇3_hs·T_r/n`,
///   so that it lands at `θ̇3_hs` (where that Δ is less than the flexion needs to stop
///   monotonically, `|θ̇3(t1)|·(tp − t1)/3`, Δ is that and the retraction the cubic Hermite).
///
/// Both pieces are monotone, the path C¹ with its only reversal at `tp`.
#[derive(Debug, Clone, Copy)]
struct ThighPath {
    t1: f64,
    tp: f64,
    t3: f64,
    th1: f64,
    om1: f64,
    peak: f64,
    th_hs: f64,
    rate_hs: f64,
}

impl ThighPath {
    /// The path of `spec`'s swing from the thigh's angle `th1` and rate `om1` at the end of
    /// swing1.
    fn new(spec: &SwingSpec, th1: f64, om1: f64) -> ThighPath {
        let [_, t1, _, t3] = spec.times;
        // Stance time: t3 is the step's duration.
        let t_r = (RETRACTION_CYCLE * 2.0 * t3).min(RETRACTION_SHARE_MAX * (t3 - t1));
        let tp = t3 - t_r;
        let rate_hs = spec.theta3_rate_hs.max(0.0);
        let delta = (rate_hs * t_r / RETRACTION_POWER).max((-om1).max(0.0) * (tp - t1) / 3.0);
        ThighPath {
            t1,
            tp,
            t3,
            th1,
            om1,
            peak: spec.theta3_hs - delta,
            th_hs: spec.theta3_hs,
            rate_hs,
        }
    }

    /// Angle, rate and acceleration at `t`.
    fn at(&self, t: f64) -> [f64; 3] {
        if t <= self.tp {
            return hermite(self.t1, self.tp, [self.th1, self.om1], [self.peak, 0.0], t);
        }
        let delta = self.th_hs - self.peak;
        let t_r = self.t3 - self.tp;
        let n = if delta > 0.0 {
            self.rate_hs * t_r / delta
        } else {
            0.0
        };
        if n < 2.0 {
            return hermite(
                self.tp,
                self.t3,
                [self.peak, 0.0],
                [self.th_hs, self.rate_hs],
                t,
            );
        }
        let v = ((t - self.tp) / t_r).clamp(0.0, 1.0);
        let p = v.powf(n - 2.0);
        [
            self.peak + delta * p * v * v,
            delta * n * p * v / t_r,
            delta * n * (n - 1.0) * p / (t_r * t_r),
        ]
    }
}

/// The cubic Hermite from `(value, rate)` `p0` at `a` to `p1` at `b`: value, rate and
/// acceleration at `t` ([`crate::generator::curves::hermite_acc`]).
fn hermite(a: f64, b: f64, p0: [f64; 2], p1: [f64; 2], t: f64) -> [f64; 3] {
    let (v, d, dd) = crate::generator::curves::hermite_acc(a, b, p0[0], p1[0], p0[1], p1[1], t);
    [v, d, dd]
}

/// Least fraction of the ankle's way from toe-off to heel strike covered by the end of swing1.
const MIN_TRAVEL: f64 = 0.3;

/// Largest ankle lift of swing1's curve per metre of the ankle's travel `D`.
const LIFT_PER_TRAVEL: f64 = 0.25;

/// Speed below which the ankle curve's lift stops growing as 1/speed, m/s (3 km/h; was 0.5 m/s).
const LIFT_SPEED_MIN: f64 = 3.0 / 3.6;

impl SwingSpec<'_> {
    /// The kinematic swing foot of this swing.
    pub fn swing_foot(&self) -> SwingFoot {
        SwingFoot {
            foot: self.foot,
            times: self.times,
            theta5: self.theta5,
            theta6_toe_off: self.theta6_toe_off,
            clearance: self.clearance,
            theta5_max: self.theta5_max,
            theta5_rate_hs: 0.0,
            contact_ramp_weight: 0.0,
        }
    }

    /// Knee and ankle positions (ground frame) for angles `q` at time `t`.
    pub fn joints(&self, t: f64, q: &[f64; 2]) -> ([f64; 2], [f64; 2]) {
        let h = (self.hip)(t).pos;
        let (k, a) = self.model.knee_ankle(q);
        ([h[0] + k[0], h[1] + k[1]], [h[0] + a[0], h[1] + a[1]])
    }

    /// Foot sole points for angles `q` at time `t`.
    pub fn foot_points(&self, t: f64, q: &[f64; 2]) -> FootPoints {
        let (_, ankle) = self.joints(t, q);
        self.swing_foot().points(t, ankle, q[0] + q[1])
    }

    fn segments(&self, a: f64, b: f64) -> Vec<(f64, f64)> {
        let mut cuts: Vec<f64> = self
            .breakpoints
            .iter()
            .copied()
            .filter(|&x| x > a && x < b)
            .collect();
        cuts.sort_by(f64::total_cmp);
        cuts.dedup_by(|x, y| (*x - *y).abs() < 1e-12);
        let mut out = Vec::new();
        let mut s = a;
        for c in cuts {
            out.push((s, c));
            s = c;
        }
        out.push((s, b));
        out
    }

    /// The ankle curve from the toe-off state.
    ///
    /// `reach` holds `(ankle x, shank inclination φ = θ3 + θ4)` along a swing1 already
    /// simulated on this swing's curve (empty at first): the peak `a_max` is then also bounded
    /// so that the curve's flank descends at most at angle `(1 − REACH_SHARE)·φ` where the
    /// ankle passed (see [`REACH_SHARE`]; [`SwingSpec::solve_with`] repeats swing1 with it where
    /// a simulated swing1 came closer to the reach circle's tangent than that).
    pub fn curve(
        &self,
        start: &SwingStart,
        speed: f64,
        extra_lift: f64,
        reach: &[[f64; 2]],
    ) -> Result<AnkleCurve, String> {
        let [t0, t1, _, _] = self.times;
        let (_, a0) = self.joints(t0, &start.q);
        // At t1 the thigh is at its heel-strike angle and the toe is under the knee.
        let mut th4 = 1.0;
        for _ in 0..60 {
            let q = [self.theta3_hs, th4];
            let (k, _) = self.joints(t1, &q);
            let p = self.foot_points(t1, &q);
            let f = p.toe[0] - k[0];
            let q2 = [self.theta3_hs, th4 + 1e-7];
            let (k2, _) = self.joints(t1, &q2);
            let f2 = self.foot_points(t1, &q2).toe[0] - k2[0];
            let d = (f2 - f) / 1e-7;
            if d == 0.0 {
                break;
            }
            let step = (f / d).clamp(-0.3, 0.3);
            th4 -= step;
            if step.abs() < 1e-13 {
                break;
            }
        }
        // If the toe would come closer to the ground than the clearance there, flex the knee
        // further until it clears (the ankle then sits higher and further back).
        if self.foot_points(t1, &[self.theta3_hs, th4]).toe[1] < self.clearance {
            let toe_y =
                |k4: f64| self.foot_points(t1, &[self.theta3_hs, k4]).toe[1] - self.clearance;
            if toe_y(th4 + 1.5) > 0.0 {
                th4 = bisect(th4, th4 + 1.5, 60, 0.0, |k| toe_y(k) <= 0.0).1;
            }
        }
        let (_, mut a1) = self.joints(t1, &[self.theta3_hs, th4]);
        // A short step (the first half step from standing) would leave the ankle behind its
        // toe-off position with the toe under the knee: the knee then flexes less, so that the
        // ankle has covered at least MIN_TRAVEL of its way to heel strike by t1.
        let (_, a_hs) = self.joints(self.times[3], &[self.theta3_hs, 0.0]);
        let d_min = MIN_TRAVEL * (a_hs[0] - a0[0]);
        if a1[0] - a0[0] < d_min && d_min > 0.0 {
            let travel = |k4: f64| self.joints(t1, &[self.theta3_hs, k4]).1[0] - a0[0] - d_min;
            if travel(0.0) > 0.0 {
                th4 = bisect(0.0, th4, 60, 0.0, |k| travel(k) > 0.0).0;
                a1 = self.joints(t1, &[self.theta3_hs, th4]).1;
            }
        }
        let d = a1[0] - a0[0];
        if d.is_nan() || d <= 0.0 {
            return Err(format!(
                "the ankle would not move forward in swing1 (D = {d:.3} m)"
            ));
        }
        let a_min = a1[1] + extra_lift;
        let lift = (self.ankle_lift / speed.max(LIFT_SPEED_MIN)).min(LIFT_PER_TRAVEL * d);
        // §4.3's peak, lowered (and the curve reshaped) where a swing1 on it came too close to
        // the ankle's reach about the knee: see `reach_curve`.
        let a_max = a0[1].max(a_min) + lift;
        if reach.is_empty() {
            AnkleCurve::fit(a0[0], d, a0[1], a_max, a_min)
        } else {
            reach_curve(a0[0], d, a0[1], a_max, a_min, reach)
        }
        .ok_or_else(|| "ankle curve is singular".to_string())
    }

    /// The knee angle that puts the ankle on the curve, continuing the branch of `guess` (the
    /// knee of the last evaluation, at most one integration step earlier): see
    /// [`knee_on_circle`].
    fn knee_on_curve(&self, t: f64, th3: f64, curve: &AnkleCurve, guess: f64) -> f64 {
        let h = (self.hip)(t).pos;
        let l3 = self.model.l3;
        let k = [h[0] - l3 * th3.sin(), h[1] - l3 * th3.cos()];
        knee_on_circle(k, self.model.l4, th3, curve, guess)
    }

    fn swing1(
        &self,
        start: &SwingStart,
        curve: &AnkleCurve,
        a: f64,
        tau: f64,
        h: f64,
        rec: Option<&mut Track<2>>,
    ) -> [f64; 2] {
        let [t0, t1, _, _] = self.times;
        let mut cache = start.q[1];
        let mut y = [start.q[0], start.qd[0]];
        let mut rec = rec;
        for (sa, sb) in self.segments(t0, t1) {
            let mut f = |t: f64, y: &[f64; 2]| {
                let th4 = self.knee_on_curve(t, y[0], curve, cache);
                cache = th4;
                let hip = (self.hip)(t);
                let ft = a * (-(t - t0) / tau).exp();
                let acc = self
                    .model
                    .accel(&[y[0], th4], &[y[1], 0.0], &[ft, 0.0], &hip.acc, true);
                [y[1], acc[0]]
            };
            if let Some(r) = rec.as_deref_mut() {
                let guess = r.nodes.last().map_or(start.q[1], |n| n.q[1]);
                r.push(self.node1(sa, &y, curve, a, tau, guess));
            }
            let recording = rec.is_some();
            let mut nodes: Vec<(f64, [f64; 2])> = Vec::new();
            let mut obs = |_: f64, _: &[f64; 2], t1: f64, y1: &[f64; 2]| {
                if recording {
                    nodes.push((t1, *y1));
                }
            };
            let no: Option<&mut fn(f64, &[f64; 2]) -> f64> = None;
            let end = integrate(&mut f, sa, y, sb, h, no, &mut obs);
            if let Some(r) = rec.as_deref_mut() {
                for (t, yy) in nodes {
                    let guess = r.nodes.last().map_or(start.q[1], |n| n.q[1]);
                    r.push(self.node1(t, &yy, curve, a, tau, guess));
                }
            }
            y = end.y;
        }
        y
    }

    fn node1(
        &self,
        t: f64,
        y: &[f64; 2],
        curve: &AnkleCurve,
        a: f64,
        tau: f64,
        guess: f64,
    ) -> Node<2> {
        let [t0, ..] = self.times;
        let th4 = self.knee_on_curve(t, y[0], curve, guess);
        let eps = 1e-5;
        let hip = (self.hip)(t);
        let ft = a * (-(t - t0) / tau).exp();
        let acc = self
            .model
            .accel(&[y[0], th4], &[y[1], 0.0], &[ft, 0.0], &hip.acc, true);
        let th4p = self.knee_on_curve(t + eps, y[0] + eps * y[1], curve, th4);
        let th4m = self.knee_on_curve(t - eps, y[0] - eps * y[1], curve, th4);
        Node {
            t,
            q: [y[0], th4],
            qd: [y[1], (th4p - th4m) / (2.0 * eps)],
            qdd: [acc[0], (th4p - 2.0 * th4 + th4m) / (eps * eps)],
        }
    }

    fn swing2(
        &self,
        y0: [f64; 4],
        be: [f64; 2],
        pa: f64,
        h: f64,
        rec: Option<&mut Track<2>>,
    ) -> ([f64; 4], f64) {
        let [_, t1, t2, _] = self.times;
        let [k3, c3] = self.hip_spring;
        let tau = self.tau[1];
        let th3_hs = self.theta3_hs;
        // With the knee brake the hip follows the thigh's terminal-swing path (`ThighPath`),
        // and the recovery's shift ends by the path's peak flexion (a forward shift later
        // would delay the retraction); the paper's spring–damper holds the thigh at its
        // heel-strike angle.
        let path = self.knee_brake.then(|| ThighPath::new(self, y0[0], y0[2]));
        let end = match &path {
            Some(p) => RECOVERY_END.min((p.tp - t1) / (t2 - t1)),
            None => 1.0,
        };
        let inertia = self.model.mass_matrix(&[0.0, 0.0])[0][0];
        let f = |t: f64, y: &[f64; 4]| {
            let hip = (self.hip)(t);
            let u = (t - t1) / (t2 - t1);
            let shift = pa * (std::f64::consts::PI * (u / end).min(1.0)).sin();
            // The knee brake (hamstrings) flexes the knee; with the path the hip torque also
            // takes out the momentum it hands to the thigh.
            let brake = be[1] * u.powi(KNEE_BRAKE_POWER);
            let f4 = be[0] * (-(t - t1) / tau).exp() + brake;
            if let Some(p) = &path {
                // The hip torque that gives the thigh the path's acceleration (the knee's
                // torque given), corrected by the spring–damper (per unit of the straight
                // leg's inertia: the same natural frequency and damping) on its error.
                let [th, thd, thdd] = p.at(t);
                let a3 = thdd - k3 / inertia * (y[0] - th + shift) - c3 / inertia * (y[2] - thd);
                let q = [y[0], y[1]];
                let m = self.model.mass_matrix(&q);
                let b = self.model.rhs(&q, &[y[2], y[3]], &[0.0, f4], &hip.acc);
                let a4 = (b[1] - m[1][0] * a3) / m[1][1];
                return [y[2], y[3], a3, a4];
            }
            let set = th3_hs - shift;
            let f3 = -k3 * (y[0] - set) - c3 * y[2];
            let acc = self
                .model
                .accel(&[y[0], y[1]], &[y[2], y[3]], &[f3, f4], &hip.acc, false);
            [y[2], y[3], acc[0], acc[1]]
        };
        let mut y = y0;
        let mut lowest = f64::INFINITY;
        let mut rec = rec;
        for (sa, sb) in self.segments(t1, t2) {
            if let Some(r) = rec.as_deref_mut() {
                let d = f(sa, &y);
                r.push(Node {
                    t: sa,
                    q: [y[0], y[1]],
                    qd: [y[2], y[3]],
                    qdd: [d[2], d[3]],
                });
            }
            let mut ff = f;
            let mut obs = |_: f64, _: &[f64; 4], tt: f64, yy: &[f64; 4]| {
                lowest = lowest.min(self.foot_points(tt, &[yy[0], yy[1]]).lowest());
                if let Some(r) = rec.as_deref_mut() {
                    let d = f(tt, yy);
                    r.push(Node {
                        t: tt,
                        q: [yy[0], yy[1]],
                        qd: [yy[2], yy[3]],
                        qdd: [d[2], d[3]],
                    });
                }
            };
            let no: Option<&mut fn(f64, &[f64; 4]) -> f64> = None;
            y = integrate(&mut ff, sa, y, sb, h, no, &mut obs).y;
        }
        (y, lowest)
    }

    fn swing3(&self, y0: [f64; 2], cd: [f64; 2], h: f64, rec: Option<&mut Track<2>>) -> [f64; 2] {
        let [_, _, t2, t3] = self.times;
        let tau = self.tau[2];
        let f = |t: f64, y: &[f64; 2]| {
            let hip = (self.hip)(t);
            let ft = cd[0] * (-(t - t2) / tau).exp() + cd[1] * (t - t2) / (t3 - t2);
            let acc = self
                .model
                .accel(&[y[0], 0.0], &[y[1], 0.0], &[ft, 0.0], &hip.acc, true);
            [y[1], acc[0]]
        };
        let mut y = y0;
        let mut rec = rec;
        for (sa, sb) in self.segments(t2, t3) {
            if let Some(r) = rec.as_deref_mut() {
                let d = f(sa, &y);
                r.push(Node {
                    t: sa,
                    q: [y[0], 0.0],
                    qd: [y[1], 0.0],
                    qdd: [d[1], 0.0],
                });
            }
            let mut ff = f;
            let mut obs = |_: f64, _: &[f64; 2], tt: f64, yy: &[f64; 2]| {
                if let Some(r) = rec.as_deref_mut() {
                    let d = f(tt, yy);
                    r.push(Node {
                        t: tt,
                        q: [yy[0], 0.0],
                        qd: [yy[1], 0.0],
                        qdd: [d[1], 0.0],
                    });
                }
            };
            let no: Option<&mut fn(f64, &[f64; 2]) -> f64> = None;
            y = integrate(&mut ff, sa, y, sb, h, no, &mut obs).y;
        }
        y
    }

    /// Simulates the swing, finding `A`, `B` and `C` (from `guess`, the previous step's values).
    pub fn solve(
        &self,
        start: &SwingStart,
        guess: [f64; 7],
        speed: f64,
    ) -> Result<SwingRun, String> {
        self.solve_with(start, guess, &SwingCarry::default(), speed)
    }

    /// [`SwingSpec::solve`] also starting swing2's and swing3's two-unknown solves from the
    /// previous step's solver state (its [`SwingRun::carry`]).
    pub fn solve_with(
        &self,
        start: &SwingStart,
        guess: [f64; 7],
        carry: &SwingCarry,
        speed: f64,
    ) -> Result<SwingRun, String> {
        // Every shooting simulation of a subphase integrates over the same fixed step grid, so
        // the hip is read at the same instants again and again (interpolating the stance track
        // and the determinants' offsets was ≈ a quarter of the walk's time): memoized by the
        // exact time. The hip is a pure function of t, so the results are bit-identical.
        let memo = HipMemo::new(self.hip);
        let hip = |t: f64| memo.at(t);
        SwingSpec { hip: &hip, ..*self }.solve_memo(start, guess, carry, speed)
    }

    fn solve_memo(
        &self,
        start: &SwingStart,
        guess: [f64; 7],
        carry: &SwingCarry,
        speed: f64,
    ) -> Result<SwingRun, String> {
        let [t0, t1, t2, _] = self.times;
        // Stability bound from swing2's spring–damper (the stiffest subphase).
        let mut jf = |t: f64, y: &[f64; 4]| {
            let hip = (self.hip)(t);
            let f3 = -self.hip_spring[0] * y[0] - self.hip_spring[1] * y[2];
            let acc = self
                .model
                .accel(&[y[0], y[1]], &[y[2], y[3]], &[f3, 0.0], &hip.acc, false);
            [y[2], y[3], acc[0], acc[1]]
        };
        let h = stable_step(
            spectral_radius(&mut jf, t1, &[start.q[0], start.q[1], 0.0, 0.0]),
            self.max_step,
        );
        let scale = self.model.mass_matrix(&[0.0, 0.0])[0][0];
        // swing1: the torque's magnitude so that the thigh reaches its heel-strike angle at t1.
        // If the foot comes closer to the ground than the clearance, the end of the ankle curve
        // (a_min, and with it a_max) is raised by the deficit and swing1 repeated (the swing2
        // recovery of §4.3, applied to swing1's kinematic ankle path).
        let tau1 = self.tau[0];
        let mut extra = guess[3].max(0.0);
        let mut it1 = 0;
        let mut a_guess = guess[0];
        let mut lift_rounds = 0;
        let mut slope1 = carry.swing1_slope;
        // Where a swing1 came closer to the reach circle's tangent than REACH_SHARE allows, the
        // samples `(ankle x, φ)` of every such round bound the peak of the next (see
        // `reach_peak`; the union only ever lowers it, so the rounds cannot oscillate).
        let mut reach: Vec<[f64; 2]> = Vec::new();
        let mut reach_rounds = 0;
        let (a1, curve, mut track, y1) = loop {
            let curve = self.curve(start, speed, extra, &reach)?;
            let s1 = solve_1d_with(
                |a| self.swing1(start, &curve, a, tau1, h, None)[0] - self.theta3_hs,
                a_guess,
                0.5 * scale,
                TOL,
                60,
                slope1,
            )
            .map_err(|e| format!("swing1: {e}"))?;
            slope1 = s1.jacobian.map(|j| j[0][0]).or(slope1);
            it1 += s1.iterations;
            let mut track = Track::default();
            let y1 = self.swing1(start, &curve, s1.x[0], tau1, h, Some(&mut track));
            // The toe is leaving the ground at toe-off: the clearance applies once it has ramped
            // in (`SwingFoot::clearance_ramp`); before that the foot must merely stay above the ground.
            let t_check = t0 + self.swing_foot().clearance_ramp();
            let mut deficit: f64 = 0.0;
            for n in track.nodes.iter().filter(|n| n.t > t0) {
                let low = self.foot_points(n.t, &n.q).lowest();
                let need = if n.t >= t_check {
                    self.clearance
                } else {
                    -5e-4
                };
                deficit = deficit.max(need - low);
            }
            if deficit > 0.0 && lift_rounds < 10 {
                extra += deficit + 1e-3;
                lift_rounds += 1;
            } else if reach_rounds < REACH_ROUNDS
                && reach_excess(self, &track, &curve) < -REACH_SLACK
            {
                reach.extend(track.nodes.iter().map(|n| {
                    let (_, a) = self.joints(n.t, &n.q);
                    [a[0], n.q[0] + n.q[1]]
                }));
                reach_rounds += 1;
            } else {
                break (s1.x[0], curve, track, y1);
            }
            a_guess = s1.x[0];
        };
        let last = *track.nodes.last().ok_or("swing1 recorded nothing")?;
        let y2_0 = [y1[0], last.q[1], y1[1], last.qd[1]];
        // swing2 with the ground-stubbing recovery: the least position actuator on the grid
        // k·RECOVERY_STEP (k ≤ RECOVERY_MAX) for which the foot clears the ground. The search
        // starts one grid step below the previous step's actuator (carried over like the force
        // profiles): a steady walk then needs two swing2 solves instead of k + 1 (slow walks
        // needed ≈ 35 simulations per step for k = 6). Going up, the clearance is close to
        // linear in k (≈ 1 mm per grid step at 7 km/h, h 1.5 m), so the next k is extrapolated
        // from the last two failing ones (at least one step up); a k reached by a jump is then
        // walked down until the grid step below it fails, so the result is still the least
        // clear k when clearance grows with the actuator.
        let k_prev = (guess[4].max(0.0) / RECOVERY_STEP).round() as usize;
        let mut k = k_prev.saturating_sub(1).min(RECOVERY_MAX);
        let mut it2 = 0;
        // The last solved (B, E) and its grid point (first: the previous step's), and the change
        // of (B, E) per grid step: each solve starts from the last solution moved to its grid
        // point (in a steady walk the two legs' actuators differ, and each step solves two
        // neighbouring grid points).
        let mut b_guess = [guess[1], guess[5]];
        let mut b_k = carry.swing2_recovery / RECOVERY_STEP;
        let mut b_here = false;
        let mut slope = carry.swing2_per_grid_step;
        let mut jac2 = carry.swing2_jacobian;
        // Largest failing k and its clearance; least clear k and its solve.
        let mut fail_hi: Option<(usize, f64)> = None;
        let mut clear_lo = None;
        let mut best_fail = None;
        let (s2, _, rounds) = loop {
            let pa = k as f64 * RECOVERY_STEP;
            let x0 = match slope {
                Some(d) if self.knee_brake => {
                    let dk = k as f64 - b_k;
                    [b_guess[0] + dk * d[0], b_guess[1] + dk * d[1]]
                }
                _ => b_guess,
            };
            // θ4(t2) = 0 and θ̇4(t2) = 0 (the rate scaled by swing2's duration, so both
            // residuals are angles): the knee comes to rest straight where it locks.
            // The foot's lowest point of the last simulation: the solves end on an evaluation
            // of the point they return (checked below), so no extra simulation is needed.
            let mut last: Option<([f64; 2], f64)> = None;
            let s2 = if !self.knee_brake {
                let s = solve_1d(
                    |b| {
                        let (y, low) = self.swing2(y2_0, [b, 0.0], pa, h, None);
                        last = Some(([b, 0.0], low));
                        y[1]
                    },
                    x0[0],
                    0.2 * scale,
                    TOL,
                    60,
                )
                .map_err(|e| format!("swing2: {e}"))?;
                padded(s)
            } else {
                // The Jacobian is carried from grid point to grid point and from step to step
                // (Broyden-updated): a fresh finite-difference one cost two simulations per
                // grid point.
                let s = solve_2d_with(
                    |be| {
                        let (y, low) = self.swing2(y2_0, be, pa, h, None);
                        last = Some((be, low));
                        [y[1], y[3] * (t2 - t1)]
                    },
                    x0,
                    [0.01 * scale, 0.01 * scale],
                    [TOL, TOL],
                    80,
                    jac2,
                )
                .map_err(|e| format!("swing2: {e}"))?;
                jac2 = s.jacobian.or(jac2);
                s
            };
            it2 += s2.iterations;
            let lowest = match last {
                Some((x, low)) if x == s2.x => low,
                _ => self.swing2(y2_0, s2.x, pa, h, None).1,
            };
            if self.knee_brake && b_here && k as f64 != b_k {
                let dk = k as f64 - b_k;
                slope = Some([(s2.x[0] - b_guess[0]) / dk, (s2.x[1] - b_guess[1]) / dk]);
            }
            b_guess = s2.x;
            b_k = k as f64;
            b_here = true;
            if lowest >= self.clearance {
                clear_lo = Some((s2, lowest, k));
                let below_fails = fail_hi.is_some_and(|(kf, _)| kf + 1 == k);
                if k == 0 || below_fails {
                    break (s2, lowest, k);
                }
                k -= 1;
                continue;
            }
            let prev = fail_hi.filter(|&(kf, _)| kf < k);
            fail_hi = Some((k, lowest));
            if best_fail
                .as_ref()
                .is_none_or(|b: &(_, f64, usize)| lowest > b.1)
            {
                best_fail = Some((s2, lowest, k));
            }
            if let Some(c) = clear_lo {
                if c.2 == k + 1 {
                    break c;
                }
            }
            if k >= RECOVERY_MAX {
                // Nothing on the grid clears (the first half step from rest, where the dip
                // comes at swing2's start, before the actuator acts): the clearest one tried.
                // Clearance is then not monotone in k, so the cap itself can be worse.
                break best_fail.unwrap_or((s2, lowest, k));
            }
            let mut next = k + 1;
            if let Some((kp, lp)) = prev {
                let slope = (lowest - lp) / (k - kp) as f64;
                if slope > 0.0 {
                    let need = ((self.clearance - lowest) / slope).ceil();
                    if need.is_finite() && need > 1.0 {
                        next = k + (need as usize).min(RECOVERY_MAX);
                    }
                }
            }
            let cap = clear_lo.map_or(RECOVERY_MAX, |c| c.2 - 1);
            k = next.min(cap).min(RECOVERY_MAX).max(k + 1);
        };
        let pa = rounds as f64 * RECOVERY_STEP;
        let (y2, _) = self.swing2(y2_0, s2.x, pa, h, Some(&mut track));
        // Knee lock at t2: the knee's impulse leaves the thigh's generalized momentum unchanged.
        let m = self.model.mass_matrix(&[y2[0], y2[1]]);
        let th3d =
            (m[0][0] * y2[2] + m[0][1] * y2[3]) / self.model.mass_matrix(&[y2[0], 0.0])[0][0];
        let y3_0 = [y2[0], th3d];
        // swing3: `C` so that the thigh reaches its heel-strike angle at t_swing; with the knee
        // brake also a ramp `D` so that it lands at `theta3_rate_hs` (see that field).
        let t3 = self.times[3];
        let s3 = if self.knee_brake {
            solve_2d_with(
                |cd| {
                    let y = self.swing3(y3_0, cd, h, None);
                    [
                        y[0] - self.theta3_hs,
                        (y[1] - self.theta3_rate_hs) * (t3 - t2),
                    ]
                },
                [guess[2], guess[6]],
                [0.01 * scale, 0.01 * scale],
                [TOL, TOL],
                80,
                carry.swing3_jacobian,
            )
            .map_err(|e| format!("swing3: {e}"))?
        } else {
            let s = solve_1d(
                |c| self.swing3(y3_0, [c, 0.0], h, None)[0] - self.theta3_hs,
                guess[2],
                0.2 * scale,
                TOL,
                60,
            )
            .map_err(|e| format!("swing3: {e}"))?;
            padded(s)
        };
        let y3 = self.swing3(y3_0, s3.x, h, Some(&mut track));
        // Clearance over the swing once it has ramped in (the toe is leaving before that).
        let t_check = t0 + self.swing_foot().clearance_ramp();
        let min_clearance = track
            .nodes
            .iter()
            .filter(|n| n.t >= t_check && n.t <= t2)
            .map(|n| self.foot_points(n.t, &n.q).lowest())
            .fold(f64::INFINITY, f64::min);
        Ok(SwingRun {
            iterations: [it1, it2, s3.iterations],
            params: [a1, s2.x[0], s3.x[0], extra, pa, s2.x[1], s3.x[1]],
            carry: SwingCarry {
                swing1_slope: slope1,
                swing2_jacobian: jac2,
                swing2_recovery: pa,
                swing2_per_grid_step: slope,
                swing3_jacobian: s3.jacobian.or(carry.swing3_jacobian),
            },
            recovery: pa,
            recovery_rounds: rounds + lift_rounds,
            min_clearance,
            end_errors: [y1[0] - self.theta3_hs, y2[1], y3[0] - self.theta3_hs],
            curve,
            track,
        })
    }
}

/// Memo of a pure hip motion `t ↦ HipMotion`, keyed by the exact bits of `t`.
struct HipMemo<'a> {
    hip: &'a dyn Fn(f64) -> HipMotion,
    seen: RefCell<HashMap<u64, HipMotion, BuildHasherDefault<TimeHasher>>>,
}

impl<'a> HipMemo<'a> {
    fn new(hip: &'a dyn Fn(f64) -> HipMotion) -> Self {
        Self {
            hip,
            seen: RefCell::new(HashMap::with_capacity_and_hasher(4096, Default::default())),
        }
    }

    fn at(&self, t: f64) -> HipMotion {
        if let Some(m) = self.seen.borrow().get(&t.to_bits()) {
            return *m;
        }
        let m = (self.hip)(t);
        self.seen.borrow_mut().insert(t.to_bits(), m);
        m
    }
}

/// A multiplicative hash of one `u64` (the memo's keys are times: SipHash's DoS resistance is
/// not needed and costs as much as the lookup saves).
#[derive(Default)]
struct TimeHasher(u64);

impl Hasher for TimeHasher {
    fn finish(&self) -> u64 {
        self.0
    }
    fn write(&mut self, bytes: &[u8]) {
        for &b in bytes {
            self.0 = (self.0.rotate_left(8) ^ u64::from(b)).wrapping_mul(0x9E37_79B9_7F4A_7C15);
        }
    }
    fn write_u64(&mut self, x: u64) {
        let h = (x ^ self.0).wrapping_mul(0x9E37_79B9_7F4A_7C15);
        self.0 = h ^ (h >> 29);
    }
}

/// Least share of the shank's inclination kept between swing1's ankle curve `P` and the circle the
/// ankle can reach about the knee.
pub const REACH_SHARE: f64 = 0.6;

/// Largest number of swing1 repeats with the peak bounded by `reach_curve`.
const REACH_ROUNDS: usize = 4;

/// How far below `sin(REACH_SHARE·φ)` a swing1 may stay after a round of `reach_curve` (its bound
/// is met at the samples of the round before; lowering the peak also lowers the shank's
/// inclination a little).
const REACH_SLACK: f64 = 0.02;

/// The least excess of the transversality `sin(φ − ψ)` over its required value (see
/// [`REACH_SHARE`]) over the nodes of a simulated swing1.
fn reach_excess(spec: &SwingSpec<'_>, track: &Track<2>, curve: &AnkleCurve) -> f64 {
    track
        .nodes
        .iter()
        .map(|n| {
            let (_, a) = spec.joints(n.t, &n.q);
            let dy = curve.eval(a[0]).1;
            let phi = n.q[0] + n.q[1];
            (phi.sin() + dy * phi.cos()) / (1.0 + dy * dy).sqrt() - (REACH_SHARE * phi).sin()
        })
        .fold(f64::INFINITY, f64::min)
}

/// The ankle curve from `(x0, a0)` to `(x0 + d, a_min)` with peak at most `a_max` whose flank
/// keeps [`REACH_SHARE`] to the reach circle at the samples `(ankle x, φ)` of `reach`, i.e.
/// descends at most at `tan((1 − REACH_SHARE)·φ)` where the ankle passed.
///
/// First the paper's quartic with a lower peak: it is linear in its heights,
/// `y = a_min + H·f(u) + A0·g(u)` (`u = (x − x0)/d`, `H = a_max − a_min`, `A0 = a0 − a_min`,
/// `f` and `g` the curves of unit `H` and unit `A0`), so each sample bounds `H` where
/// `f'(u) < 0`. The peak is not lowered below the one for which the curve leaves `a0` level
/// (`y'(0) = 0`, `H = 1.115·A0`): lower, it dips after toe-off. Where that is still too steep
/// (a toe-off ankle far above the landing height on a short travel: the drop `A0` alone makes
/// the flank too steep after a peak at `0.3·D`) the peak moves towards toe-off instead, along
/// the quartics that leave `a0` level with a peak at `γ·D` ([`AnkleCurve::fit_level`],
/// `γ` from 0.3 to 0, where the peak is gone and the descent is spread over all of `D`): the
/// largest `γ` that keeps the margin, by bisection, `γ = 0` if none does (the knee's guard,
/// [`knee_on_circle`], then keeps the knee continuous).
fn reach_curve(
    x0: f64,
    d: f64,
    a0: f64,
    a_max: f64,
    a_min: f64,
    reach: &[[f64; 2]],
) -> Option<AnkleCurve> {
    // The samples on the curve, with the steepest descent they allow.
    let samples: Vec<(f64, f64)> = reach
        .iter()
        .filter(|&&[x, phi]| (x0..=x0 + d).contains(&x) && phi.is_finite())
        .map(|&[x, phi]| {
            (
                (x - x0) / d,
                ((1.0 - REACH_SHARE) * phi).clamp(0.0, 1.4).tan(),
            )
        })
        .collect();
    let (f, g) = (
        AnkleCurve::fit(0.0, 1.0, 0.0, 1.0, 0.0)?,
        AnkleCurve::fit(0.0, 1.0, 1.0, 0.0, 0.0)?,
    );
    let a0_rel = a0 - a_min;
    let mut h = a_max - a_min;
    for &(u, allowed) in &samples {
        let (fd, gd) = (f.eval(u).1, g.eval(u).1);
        if fd < 0.0 {
            h = h.min((allowed * d + a0_rel * gd) / -fd);
        }
    }
    // y'(0) = (H·f'(0) + A0·g'(0))/d ≥ 0.
    let level = -a0_rel * g.eval(0.0).1 / f.eval(0.0).1;
    if h >= a_max - a_min {
        return AnkleCurve::fit(x0, d, a0, a_max, a_min);
    }
    if h >= level {
        return AnkleCurve::fit(x0, d, a0, a_min + h, a_min);
    }
    let keeps = |c: &AnkleCurve| {
        samples
            .iter()
            .all(|&(u, allowed)| -c.eval(x0 + u * d).1 <= allowed)
    };
    let (mut lo, mut hi) = (0.0, PEAK_AT);
    let mut best = AnkleCurve::fit_level(x0, d, 0.0, a0, a_min)?;
    if !keeps(&best) {
        return Some(best);
    }
    for _ in 0..30 {
        let mid = 0.5 * (lo + hi);
        let c = AnkleCurve::fit_level(x0, d, mid, a0, a_min)?;
        if keeps(&c) {
            lo = mid;
            best = c;
        } else {
            hi = mid;
        }
    }
    Some(best)
}

/// A one-unknown solve in the two-unknown form of the braked swing (the second unknown, the
/// brake or landing-rate ramp, fixed at 0).
fn padded(s: Solved<1>) -> Solved<2> {
    Solved {
        x: [s.x[0], 0.0],
        residual: [s.residual[0], 0.0],
        iterations: s.iterations,
        jacobian: None,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_reach_bound_lowers_the_peak_then_moves_it_towards_toe_off() {
        let tan = |phi: f64| ((1.0 - REACH_SHARE) * phi).tan();
        let check = |c: &AnkleCurve, a0: f64, a_min: f64, d: f64, phi: f64| {
            // At the samples (those of `samples` below).
            for i in 0..=50 {
                let x = d * i as f64 / 50.0;
                assert!(-c.eval(x).1 <= tan(phi) + 1e-9, "too steep at {x}");
            }
            assert!((c.eval(0.0).0 - a0).abs() < 1e-12 && c.eval(0.0).1 >= -1e-12);
            assert!((c.eval(d).0 - a_min).abs() < 1e-12 && c.eval(d).1.abs() < 1e-12);
        };
        let samples = |d: f64, phi: f64| -> Vec<[f64; 2]> {
            (0..=50).map(|i| [d * i as f64 / 50.0, phi]).collect()
        };
        // A steady walk's curve that keeps the margin: unchanged.
        let (d, a0, a_min, a_max) = (0.6, 0.12, 0.15, 0.19);
        let plain = AnkleCurve::fit(0.0, d, a0, a_max, a_min).unwrap();
        let kept = reach_curve(0.0, d, a0, a_max, a_min, &samples(d, 0.6)).unwrap();
        assert_eq!(kept.heights, plain.heights);
        for (a, b) in kept.c.iter().zip(&plain.c) {
            assert!((a - b).abs() < 1e-12, "{kept:?}");
        }
        // A slow step after fast ones (a0 8 cm above a_min on a short travel, §4.3's peak 2 cm
        // higher): §4.3's flank is far too steep, and a lower peak at 0.3·D still is (the drop
        // alone), so the peak moves towards toe-off, leaving a0 level.
        let (d, a0, a_min, phi) = (0.4, 0.215, 0.137, 0.9);
        let steepest = |c: &AnkleCurve| {
            (0..=50)
                .map(|i| -c.eval(d * i as f64 / 50.0).1)
                .fold(0.0, f64::max)
        };
        let paper = AnkleCurve::fit(0.0, d, a0, a0 + 0.021, a_min).unwrap();
        let level = AnkleCurve::fit_level(0.0, d, PEAK_AT, a0, a_min).unwrap();
        assert!(steepest(&paper) > tan(phi) && steepest(&level) > tan(phi));
        let c = reach_curve(0.0, d, a0, a0 + 0.021, a_min, &samples(d, phi)).unwrap();
        check(&c, a0, a_min, d, phi);
        assert!(
            c.heights[1] < level.heights[1] && c.heights[1] >= a0,
            "{:?}",
            c.heights
        );
        assert!(c.eval(0.0).1.abs() < 1e-12);
        // Where no curve of the family keeps the margin: the flattest, without a peak.
        let (d, phi) = (0.289, 0.62);
        let c = reach_curve(0.0, d, a0, a0 + 0.021, a_min, &samples(d, phi)).unwrap();
        assert_eq!(c, AnkleCurve::fit_level(0.0, d, 0.0, a0, a_min).unwrap());
        // A milder drop only lowers §4.3's peak (still at 0.3·D, with zero slope there).
        let (a0, a_min) = (0.16, 0.14);
        let c = reach_curve(0.0, d, a0, a0 + 0.04, a_min, &samples(d, 0.62)).unwrap();
        check(&c, a0, a_min, d, 0.62);
        assert!(c.eval(0.3 * d).1.abs() < 1e-12 && c.heights[1] < a0 + 0.04);
    }
}
