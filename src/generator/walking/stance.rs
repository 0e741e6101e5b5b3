//! The stance phase (§4.2): the telescopic inverted pendulum with upper body, its subphases and
//! force profiles, and the shooting for `F_θ1` and `F_w`.
//!
//! Force profiles:
//! - `F_θ1`: a step torque of magnitude `A`, switched off at `hip_torque_off · t_step` (§4.2:
//!   0.4); `A` is a shooting unknown.
//! - `F_θ2 = −k2 (θ2 − θ2_ref) − c2 θ̇2`: the spring–damper that balances the upper body; `k2`
//!   includes the upper body's gravitational stiffness `m2 g r2` so the natural frequency is the
//!   attribute's.
//! - `F_w = k_w (l1 + pa − w) − v_w ẇ` (eq. 4; the equation itself is missing from the paper's
//!   text, which describes its terms: spring and damping constants `k_w`, `v_w`, unloaded length
//!   `l1`, leg length `w`, velocity `ẇ` and the position actuator `pa`, initially zero).
//!
//! Subphases, switched by events located on the discrete flow (the middle-level state machine):
//! 1. *compression* (telescopic, A.1): the leg shortens after heel strike (knee flexion). The
//!    position actuator monitors the hip: while the hip is below its height at heel strike, `pa`
//!    rises at `monitor_gain · (y_hs − y_hip)` ("if it drops too low, pa is increased").
//! 2. *rigid* (A.1 with correction 3): when the leg is "too long" before it passes the vertical
//!    — at least its unloaded length `l1` and lengthening — it is locked (`ẇ = 0`; the locking
//!    impulse acts along the leg, so the generalized momenta of `θ1` and `θ2` are conserved).
//!    A leg that regains `l1` from below locks at `l1`; one that landed longer than `l1` and
//!    bottoms out above it locks where it turns. The dynamics lock in one instant; the recorded
//!    motion (what the body is drawn from) spreads that rate jump over ±[`LOCK_BLEND`]
//!    ([`blend_rate_jump`]), so the drawn leg decelerates to the lock instead of jolting.
//! 3. *extension* (telescopic): from the event `θ1 > 0` (leg passes the vertical) the lock is
//!    removed with `pa` set so that `F_w` equals the leg's reaction (no jump in force), and `pa`
//!    grows as `pa_u + P·τⁿ` (τ the fraction of the remaining time) to extend the leg — plantar
//!    flexion — to its desired length at the end of the step; `P` is a shooting unknown.
//!
//! **The push-off (a change to the paper's hip path, issue 6).** The paper gives no profile for
//! `pa`; with the quadratic one (`n = 2`) the hip arrives at heel strike descending at 2–4 × a
//! human's rate (the paper's own rule is that it "must never drop below its minimal value at
//! heel strike"), and the new leg, whose straight knee has no leverage, rolls the drawn foot
//! about the heel. Above a Froude speed the profile is `τⁿ` with `n` growing with speed
//! ([`push_off_exponent`]): the same extension, put late — the trailing leg's push-off (its
//! heel rising fast just before the other heel lands). The end conditions, the shooting and its
//! unknowns are unchanged (measured effect and the exponents tried: docs/klaw.md).
//!
//! **The midstance knee (a change to the paper's lock, issue 6).** The paper locks the rigid
//! leg at its unloaded length `l1` — a straight knee through midstance. At speed the leg locks
//! shorter, at `l1 (1 − δ)` ([`StanceSpec::lock_short`], [`lock_shortening`]: δ grows with the
//! push-off exponent up to 1 %, a midstance knee flexion of ≈ 16°, the upper end of a human's at
//! brisk speeds); the extension then lengthens the leg from there to its eq. 3 length, so the
//! hip vaults lower and arrives at heel strike descending more slowly (measured: docs/klaw.md).
//! The virtual leg draws the flexed knee
//! ([`StanceSpec::drawn_span`]). A leg that bottoms out above the shorter length locks where
//! it turns, as above.
//!
//! The paper also locks the leg when it reaches its desired length before the end of the step;
//! here the shooting makes it reach that length exactly at the end, so that lock never engages
//! and is not implemented.
use super::dynamics::{solve2, StanceModel};
use super::integrate::{integrate, spectral_radius, stable_step};
use super::shooting::{solve_2d_with, Solved};
use super::track::{Node, Track};
use crate::generator::curves::smoothstep;

/// Half-width of the kinematic blend that spreads the lock's rate jump, s (the leg is drawn
/// decelerating to the lock over 2 × 20 ms).
pub const LOCK_BLEND: f64 = 0.02;

/// Spreads the rate jump of a recorded track at `t_jump` (a node pair at that time: before and
/// after) over `[t_jump − half, t_jump + half]`: each coordinate gets the compact correction
/// `c = Δ (R(s) − max(s, 0))`, `Δ` its rate jump, `R` the integral of a smoothstep rising from 0
/// to 1 across the window (so `R(±half)` equals the hinge, `c` vanishes outside, and `q + c` is
/// C² there and C¹ at `t_jump`).
pub fn blend_rate_jump<const N: usize>(track: &mut Track<N>, t_jump: f64, half: f64) {
    if half <= 0.0 {
        return;
    }
    let Some(k) = track
        .nodes
        .windows(2)
        .position(|w| w[0].t == t_jump && w[1].t == t_jump)
    else {
        return;
    };
    let (before, after) = (track.nodes[k], track.nodes[k + 1]);
    let mut jump = [0.0; N];
    for (i, d) in jump.iter_mut().enumerate() {
        *d = after.qd[i] - before.qd[i];
    }
    for (j, n) in track.nodes.iter_mut().enumerate() {
        let s = n.t - t_jump;
        if s.abs() >= half {
            continue;
        }
        // The pre-jump node of the pair sits at s = 0 on the left branch of the hinge.
        let right = j > k || (s > 0.0);
        let u = (s + half) / (2.0 * half);
        let r = 2.0 * half * u * u * u * (1.0 - 0.5 * u);
        let r1 = smoothstep(u);
        let r2 = 6.0 * u * (1.0 - u) / (2.0 * half);
        let (hinge, hinge1) = if right { (s, 1.0) } else { (0.0, 0.0) };
        for (i, d) in jump.iter().enumerate() {
            n.q[i] += d * (r - hinge);
            n.qd[i] += d * (r1 - hinge1);
            n.qdd[i] += d * r2;
        }
    }
}

/// Everything that defines one stance phase except its two shooting unknowns.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct StanceSpec {
    /// The model.
    pub model: StanceModel,
    /// Unloaded leg length `l1`, m.
    pub l1: f64,
    /// Leg spring stiffness `k_w`, N/m.
    pub k_w: f64,
    /// Leg damping `v_w`, N·s/m.
    pub v_w: f64,
    /// Upper body spring, N·m/rad.
    pub k2: f64,
    /// Upper body damper, N·m·s/rad.
    pub c2: f64,
    /// Upper body reference angle, rad.
    pub theta2_ref: f64,
    /// Step duration `t_step`, s.
    pub duration: f64,
    /// Time `F_θ1` is switched off, s.
    pub torque_off: f64,
    /// Position-actuator monitor gain, 1/s.
    pub monitor_gain: f64,
    /// Final conditions `[w, θ1]` at `t_step`.
    pub target: [f64; 2],
    /// Largest integration step, s.
    pub max_step: f64,
    /// Exponent `n` of the extension's actuator profile `pa_u + P·τⁿ`, ≥ 2 (2: the extension
    /// spread over the subphase; larger: a late push-off, see [`push_off_exponent`]).
    pub push_off: f64,
    /// How much shorter than `l1` the rigid leg locks, as a fraction of `l1` (0: the paper's
    /// lock at `l1`; see [`lock_shortening`]).
    pub lock_short: f64,
}

/// Froude speed `v/√(g·l1)` up to which the extension keeps the quadratic profile (3 km/h for
/// a 1.8 m body, `l1` ≈ 0.87 m).
pub const PUSH_OFF_FROUDE_0: f64 = 0.286;

/// Froude speed over which the push-off exponent grows by one (≈ 1.25 km/h at 1.8 m).
pub const PUSH_OFF_FROUDE_STEP: f64 = 0.119;

/// Largest push-off exponent (not reached below ≈ 7.5 km/h at 1.5 m).
pub const PUSH_OFF_MAX: f64 = 6.0;

/// Froude speed `v/√(g·l1)` of a walk at `speed` m/s with an unloaded leg `l1` m long: the
/// dimensionless speed at which bodies of different heights walk alike (the push-off and the
/// projected lock are set on it).
pub fn froude_speed(speed: f64, l1: f64) -> f64 {
    speed / (crate::units::G * l1.max(1e-9)).sqrt()
}

/// The extension profile's exponent `n` (see [`StanceSpec::push_off`]) for a walk at `speed`
/// m/s with an unloaded leg `l1` m long: 2 up to the Froude speed [`PUSH_OFF_FROUDE_0`], then
/// growing by one per [`PUSH_OFF_FROUDE_STEP`], capped at [`PUSH_OFF_MAX`] — 2 / 2.8 / 3.6 / 4.4
/// / 5.2 at 3 / 4 / 5 / 6 / 7 km/h for a 1.8 m body. A human's ankle push-off grows steeply
/// with walking speed; the Froude speed makes bodies of different heights push alike at
/// dynamically similar speeds.
pub fn push_off_exponent(speed: f64, l1: f64) -> f64 {
    let froude = froude_speed(speed, l1);
    (2.0 + (froude - PUSH_OFF_FROUDE_0) / PUSH_OFF_FROUDE_STEP).clamp(2.0, PUSH_OFF_MAX)
}

/// Froude speed over which the first stance from standing's push-off exponent rises from 2 to
/// [`PUSH_OFF_MAX`], from [`PUSH_OFF_FROUDE_0`] (see [`first_push_off_exponent`]).
pub const FIRST_PUSH_OFF_FROUDE_RAMP: f64 = 0.05;

/// The extension profile's exponent `n` ([`StanceSpec::push_off`]) of the first stance from
/// standing for a walk at `speed` m/s with an unloaded leg `l1` m long: 2 (the paper's
/// quadratic extension) up to [`PUSH_OFF_FROUDE_0`], where the walk's own push-off starts, then
/// rising (smoothstep in Froude speed) to [`PUSH_OFF_MAX`] over
/// [`FIRST_PUSH_OFF_FROUDE_RAMP`] — ≈ 3.0 → 3.5 km/h for a 1.8 m body, 2.75 → 3.2 km/h for
/// 1.5 m. A change to the paper (klawstart4), which gives no profile for `pa`.
pub fn first_push_off_exponent(speed: f64, l1: f64) -> f64 {
    let froude = froude_speed(speed, l1);
    let u = ((froude - PUSH_OFF_FROUDE_0) / FIRST_PUSH_OFF_FROUDE_RAMP).clamp(0.0, 1.0);
    2.0 + (PUSH_OFF_MAX - 2.0) * smoothstep(u)
}

/// Midstance shortening of the locked leg per unit of push-off exponent above 2, fraction of
/// `l1` (see [`lock_shortening`]).
pub const LOCK_SHORT_PER_PUSH: f64 = 0.006;

/// Largest midstance shortening of the locked leg, fraction of `l1` (a knee flexion of ≈ 16°).
pub const LOCK_SHORT_MAX: f64 = 0.01;

/// How much shorter than `l1` the stance leg locks ([`StanceSpec::lock_short`]) for a stance
/// with push-off exponent `push_off` ([`push_off_exponent`]): 0 up to the push-off's Froude
/// speed (the paper's lock), then [`LOCK_SHORT_PER_PUSH`] per unit of exponent, at most
/// [`LOCK_SHORT_MAX`] — 0.5 / 1.0 / 1.0 % at 4 / 5 / 7 km/h for a 1.8 m body.
pub fn lock_shortening(push_off: f64) -> f64 {
    (LOCK_SHORT_PER_PUSH * (push_off - 2.0)).clamp(0.0, LOCK_SHORT_MAX)
}

/// Initial state of a stance phase.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct StanceStart {
    /// `[w, θ1, θ2]`.
    pub q: [f64; 3],
    /// `[ẇ, θ̇1, θ̇2]`.
    pub qd: [f64; 3],
}

#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Sub {
    Compress,
    Rigid,
    Extend,
}

/// Outcome of one simulated stance phase.
#[derive(Debug, Clone, PartialEq)]
pub struct StanceRun {
    /// Final `[w, θ1, θ2, ẇ, θ̇1, θ̇2]`.
    pub end: [f64; 6],
    /// Time the leg was locked, s.
    pub lock_time: Option<f64>,
    /// Time the leg passed the vertical (unlock / start of extension), s.
    pub extend_time: Option<f64>,
    /// The trajectory (only when recorded).
    pub track: Track<3>,
}

impl StanceSpec {
    /// The length the rigid leg locks at, m: `l1 (1 − lock_short)` — the paper's lock at the
    /// unloaded leg length `l1` (§4.2), shorter by the midstance knee at speed
    /// ([`lock_shortening`]). Nothing of the drawn 3-D leg enters: its lateral reach is the
    /// drawing's (`draw::PelvisDrop`).
    pub fn lock_length(&self) -> f64 {
        self.l1 * (1.0 - self.lock_short.max(0.0))
    }

    /// The longest hip–ankle span the virtual leg's flat and heel-off rules may draw for this
    /// stance (`VirtualLeg::span_max`), for a straight leg spanning `leg_span`: shortened by the
    /// lock's shortening when `run` locked at [`StanceSpec::lock_length`] (regained it from
    /// below), so the drawn knee keeps the midstance flexion and the extension beyond that
    /// length is drawn as the heel rising (the paper's heel-off rule, one knee angle earlier);
    /// longer by as much as the leg locked above that length where it turned, up to `leg_span`
    /// (the paper's straight knee: the first step at a new, faster speed, whose hip comes in
    /// high); `leg_span` when it never locked or `lock_short` is 0.
    pub fn drawn_span(&self, run: &StanceRun, leg_span: f64) -> f64 {
        let short = self.l1 * self.lock_short.max(0.0);
        match run.lock_time {
            Some(t) if short > 0.0 => {
                let above = (run.track.at(t).0[0] - self.lock_length()).max(0.0);
                (leg_span - short + above).min(leg_span)
            }
            _ => leg_span,
        }
    }

    /// Generalized forces; `f1` is the step torque's value on the current segment (`A` before
    /// `torque_off`, 0 after), fixed per integration segment rather than read from `t`: the last
    /// RK4 stage of the segment ending at `torque_off` is evaluated at `t + h`, which rounds to
    /// either side of the switch, and a torque read from `t` there made `θ̇1` jump by `h·A/(6I)`
    /// (a discontinuous shooting residual that stalled the solver, issue 6 / klawfix).
    fn forces(&self, t: f64, y: &[f64; 7], f1: f64, sub: Sub, ext: (f64, f64, f64)) -> [f64; 3] {
        let f2 = -self.k2 * (y[2] - self.theta2_ref) - self.c2 * y[5];
        let pa = match sub {
            Sub::Extend => {
                let (t_u, pa_u, p) = ext;
                let tau = ((t - t_u) / (self.duration - t_u).max(1e-9)).clamp(0.0, 1.0);
                pa_u + p * tau.powf(self.push_off.max(2.0))
            }
            _ => y[6],
        };
        let fw = self.k_w * (self.l1 + pa - y[0]) - self.v_w * y[3];
        [fw, f1, f2]
    }

    fn deriv(
        &self,
        t: f64,
        y: &[f64; 7],
        f1: f64,
        sub: Sub,
        ext: (f64, f64, f64),
        floor: f64,
    ) -> [f64; 7] {
        // Far outside any walking posture (a trial force that makes the pendulum fall): freeze
        // the state, so the shooting residual stays finite and keeps its sign.
        if y[1].abs() > 1.3 || y[0] < 0.3 * self.l1 || y[0] > 1.6 * self.l1 || y[2].abs() > 1.3 {
            return [0.0; 7];
        }
        let q = [y[0], y[1], y[2]];
        let qd = [y[3], y[4], y[5]];
        let f = self.forces(t, y, f1, sub, ext);
        let acc = self.model.accel(&q, &qd, &f, sub == Sub::Rigid);
        let pa_rate = match sub {
            Sub::Compress => self.monitor_gain * (floor - y[0] * y[1].cos()).max(0.0),
            _ => 0.0,
        };
        [y[3], y[4], y[5], acc[0], acc[1], acc[2], pa_rate]
    }

    /// The integration step: the attribute's maximum, reduced if the stiffness requires it
    /// (see [`super::integrate`]).
    pub fn step(&self, start: &StanceStart) -> f64 {
        let y = [
            start.q[0],
            start.q[1],
            start.q[2],
            start.qd[0],
            start.qd[1],
            start.qd[2],
        ];
        let mut f = |t: f64, y6: &[f64; 6]| {
            let y7 = [y6[0], y6[1], y6[2], y6[3], y6[4], y6[5], 0.0];
            let d = self.deriv(t, &y7, 0.0, Sub::Extend, (0.0, 0.0, 0.0), 0.0);
            [d[0], d[1], d[2], d[3], d[4], d[5]]
        };
        stable_step(spectral_radius(&mut f, 0.0, &y), self.max_step)
    }

    /// Simulates the phase with step-torque magnitude `a` (N·m) and extension amplitude `p` (m).
    pub fn run(&self, start: &StanceStart, a: f64, p: f64, h: f64, record: bool) -> StanceRun {
        let floor = start.q[0] * start.q[1].cos();
        let m2g = self.model.m2 * self.model.g;
        // pa starts at the static preload of the upper body's weight (rest length l1 under load).
        let pa0 = m2g * start.q[1].cos() / self.k_w;
        let mut y = [
            start.q[0],
            start.q[1],
            start.q[2],
            start.qd[0],
            start.qd[1],
            start.qd[2],
            pa0,
        ];
        let mut t = 0.0;
        let mut sub = if y[1] >= 0.0 {
            Sub::Extend
        } else {
            Sub::Compress
        };
        let mut ext = (0.0, pa0, p);
        let mut lock_time = None;
        let mut extend_time = if sub == Sub::Extend { Some(0.0) } else { None };
        let mut track = Track::default();
        // The step torque's value on the current segment (see `forces`).
        let torque_at = |t: f64| if t < self.torque_off { a } else { 0.0 };
        let mut f1 = torque_at(0.0);
        let node = |spec: &StanceSpec, t: f64, y: &[f64; 7], sub: Sub, ext, f1: f64| {
            let d = spec.deriv(t, y, f1, sub, ext, floor);
            Node {
                t,
                q: [y[0], y[1], y[2]],
                qd: [y[3], y[4], y[5]],
                qdd: [d[3], d[4], d[5]],
            }
        };
        // The lock's length: `l1`, shorter at speed (see `lock_short`).
        let l1 = self.lock_length();
        // The middle level's event functions: a subphase ends when its function reaches 0.
        // Compression ends with the lock ("leg too long": the leg is at least its lock length
        // and lengthening, `min(w − l1, ẇ) ≥ 0`) or at the vertical (`θ1 ≥ 0`). A leg that lands
        // longer than `l1` (eq. 3 asks for it at slow speeds) and bottoms out above `l1` is
        // locked where it turns (ẇ = 0) instead of lengthening telescopically: that is what the
        // paper's lock prevents ("w > l1 … too early in the stance phase"), and it keeps the
        // end state continuous in the forces. The earlier rule (lock only on regaining `l1`
        // from below) switched between "never locked" and "locked at l1" when the compression
        // grazed `l1` — a jump of ≈ 0.07 rad in θ1(t_step) that no torque could shoot across
        // (1.41 km/h, h 1.739 m; issue 6, klawshoot).
        let event_value = |sub: Sub, yy: &[f64; 7]| match sub {
            Sub::Compress => (yy[0] - l1).min(yy[3]).max(yy[1]),
            Sub::Rigid => yy[1],
            Sub::Extend => -1.0,
        };
        let mut fired = false;
        loop {
            // Switch subphase on an event, or when a segment starts past its event (a boundary
            // at the torque switch-off can fall between the crossing and its detection).
            // Which condition fired is decided by the state with a tolerance: the located
            // event is exact to 1e-12 s, so θ1 may sit a rounding error below 0 when the leg
            // passes the vertical.
            if fired || (sub != Sub::Extend && event_value(sub, &y) > 1e-12) {
                fired = false;
                if y[1] >= -1e-9 {
                    let pa_u = if sub == Sub::Rigid {
                        let q = [y[0], y[1], y[2]];
                        let qd = [y[3], y[4], y[5]];
                        let f = self.forces(t, &y, f1, sub, ext);
                        self.model.locked_reaction(&q, &qd, &f) / self.k_w + y[0] - self.l1
                    } else {
                        y[6]
                    };
                    ext = (t, pa_u, p);
                    extend_time = Some(t);
                    sub = Sub::Extend;
                } else if sub == Sub::Compress {
                    // Lock: the impulse acts along the leg only.
                    let q = [y[0], y[1], y[2]];
                    let m = self.model.mass_matrix(&q);
                    let p1 = m[1][0] * y[3] + m[1][1] * y[4] + m[1][2] * y[5];
                    let p2 = m[2][0] * y[3] + m[2][1] * y[4] + m[2][2] * y[5];
                    let v = solve2(&[[m[1][1], m[1][2]], [m[2][1], m[2][2]]], &[p1, p2]);
                    y[3] = 0.0;
                    y[4] = v[0];
                    y[5] = v[1];
                    lock_time = Some(t);
                    sub = Sub::Rigid;
                }
                continue;
            }
            if t >= self.duration {
                break;
            }
            let t_end = if t < self.torque_off {
                self.torque_off.min(self.duration)
            } else {
                self.duration
            };
            f1 = torque_at(t);
            if record {
                track.push(node(self, t, &y, sub, ext, f1));
            }
            let spec = *self;
            let mut f = |tt: f64, yy: &[f64; 7]| spec.deriv(tt, yy, f1, sub, ext, floor);
            let mut ev = |_tt: f64, yy: &[f64; 7]| event_value(sub, yy);
            let mut tr: Vec<Node<3>> = Vec::new();
            let mut obs = |_t0: f64, _y0: &[f64; 7], t1: f64, y1: &[f64; 7]| {
                if record {
                    tr.push(node(&spec, t1, y1, sub, ext, f1));
                }
            };
            let seg = integrate(&mut f, t, y, t_end, h, Some(&mut ev), &mut obs);
            track.nodes.extend(tr);
            t = seg.t;
            y = seg.y;
            fired = seg.event;
        }
        if record {
            track.push(node(self, t, &y, sub, ext, f1));
            if let Some(t_lock) = lock_time {
                let half = LOCK_BLEND.min(t_lock).min(self.duration - t_lock);
                blend_rate_jump(&mut track, t_lock, half);
            }
        }
        StanceRun {
            end: [y[0], y[1], y[2], y[3], y[4], y[5]],
            lock_time,
            extend_time,
            track,
        }
    }

    /// Finds `A` and `P` so that `w(t_step)` and `θ1(t_step)` meet the targets, starting from the
    /// previous step's values `guess`, and returns them with the recorded run.
    pub fn solve(
        &self,
        start: &StanceStart,
        guess: [f64; 2],
    ) -> Result<(Solved<2>, StanceRun), String> {
        self.solve_with(start, guess, None)
    }

    /// [`StanceSpec::solve`] starting the Broyden iteration from a carried Jacobian (the previous
    /// step's [`Solved::jacobian`]) instead of a finite-difference one.
    pub fn solve_with(
        &self,
        start: &StanceStart,
        guess: [f64; 2],
        jacobian: Option<[[f64; 2]; 2]>,
    ) -> Result<(Solved<2>, StanceRun), String> {
        let h = self.step(start);
        // The residual at the guess is needed twice (to judge it, then as the solve's first
        // evaluation): the last evaluation is kept rather than simulated again.
        let last = std::cell::Cell::new(None::<([f64; 2], [f64; 2])>);
        let f = |x: [f64; 2]| {
            if let Some((xl, rl)) = last.get() {
                if xl == x {
                    return rl;
                }
            }
            let r = self.run(start, x[0], x[1], h, false);
            let r = [r.end[1] - self.target[1], r.end[0] - self.target[0]];
            last.set(Some((x, r)));
            r
        };
        // Without a previous step's profile (the walk's first step), or when that profile is far
        // off for this step's start (the pendulum falls: the residual saturates and the Jacobian
        // is meaningless, so the Broyden iteration diverges), a coarse scan of the step torque
        // picks the start: the Broyden iteration needs a start near the solution.
        let norm = |r: [f64; 2]| (r[0] / 0.01).hypot(r[1] / 0.01);
        let far = guess == [0.0, 0.0] || {
            let r = f(guess);
            !(r[0].abs() < 0.2 && r[1].abs() < 0.05)
        };
        // A coarse scan's start is far from where the carried Jacobian was taken.
        let jacobian = if far { None } else { jacobian };
        let guess = if far {
            let scale = (self.model.m1 + self.model.m2) * self.model.g * self.l1;
            let mut best = (f64::INFINITY, guess);
            for i in 0..=16 {
                let x = [scale * (0.5 * i as f64 / 16.0 - 0.05), guess[1]];
                let n = norm(f(x));
                if n < best.0 {
                    best = (n, x);
                }
            }
            best.1
        } else {
            guess
        };
        let solved = solve_2d_with(f, guess, [2.0, 1e-3], [1e-7, 1e-7], 160, jacobian)?;
        let run = self.run(start, solved.x[0], solved.x[1], h, true);
        Ok((solved, run))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The pre-roll stance of a 1.41 km/h walk of a 1.739 m, 75 kg body (issue 6, klawshoot):
    /// the leg lands 1.4 cm longer than `l1` and its compression bottoms out right at `l1` for
    /// step torques near 76 N·m.
    fn grazing_spec() -> (StanceSpec, StanceStart) {
        let spec = StanceSpec {
            model: StanceModel {
                m1: 12.075,
                r1: 0.4637049549994735,
                i1: 0.9023095423237595,
                m2: 50.85,
                r2: 0.4086130486703893,
                i2: 8.354852059153348,
                g: 9.80665,
            },
            l1: 0.8385261392395542,
            k_w: 17542.655275290806,
            v_w: 755.5846565932001,
            k2: 1700.0439705506935,
            c2: 317.5208291826306,
            theta2_ref: 0.03490658503988659,
            duration: 1.0319516195325107,
            torque_off: 0.4127806478130043,
            monitor_gain: 20.0,
            target: [0.8526964553305313, 0.23940226803375858],
            max_step: 0.004,
            push_off: 2.0,
            lock_short: 0.0,
        };
        let start = StanceStart {
            q: [
                0.8526964553305313,
                -0.23940226803375858,
                0.03490658503988659,
            ],
            qd: [-0.09291990504440535, 0.44645356106147843, 0.0],
        };
        (spec, start)
    }

    /// The first stance's push-off (`first_push_off_exponent`): the paper's quadratic up to the
    /// walk's push-off speed, the latest profile a Froude ramp above it, continuous and rising.
    #[test]
    fn the_first_push_off_ramps_from_the_papers_profile_to_the_latest() {
        let l1 = 0.87;
        let speed = |froude: f64| froude * (crate::units::G * l1).sqrt();
        for froude in [0.0, 0.1, PUSH_OFF_FROUDE_0] {
            assert_eq!(first_push_off_exponent(speed(froude), l1), 2.0);
        }
        for froude in [PUSH_OFF_FROUDE_0 + FIRST_PUSH_OFF_FROUDE_RAMP, 0.5, 1.0] {
            assert_eq!(first_push_off_exponent(speed(froude), l1), PUSH_OFF_MAX);
        }
        let mut last = 2.0;
        for i in 0..=100 {
            let froude = PUSH_OFF_FROUDE_0 + FIRST_PUSH_OFF_FROUDE_RAMP * i as f64 / 100.0;
            let n = first_push_off_exponent(speed(froude), l1);
            assert!(n >= last && n - last < 0.07, "{froude}: {last} -> {n}");
            last = n;
        }
    }

    #[test]
    fn end_state_is_continuous_where_the_compression_grazes_l1() {
        let (spec, start) = grazing_spec();
        let h = spec.step(&start);
        let da = 0.02;
        let mut prev: Option<[f64; 6]> = None;
        // Leg locked above l1 (where it turned) / at l1 (regained from below).
        let (mut above, mut at) = (0, 0);
        let mut worst = [0.0f64; 2];
        for i in 0..=250 {
            let a = 74.0 + da * i as f64;
            let r = spec.run(&start, a, 0.0, h, true);
            let lock = r
                .lock_time
                .expect("the compression ends above the vertical");
            let w = r.track.at(lock).0[0];
            if w > spec.l1 + 1e-9 {
                above += 1;
            } else {
                at += 1;
            }
            if let Some(p) = prev {
                worst[0] = worst[0].max((r.end[1] - p[1]).abs());
                worst[1] = worst[1].max((r.end[0] - p[0]).abs());
            }
            prev = Some(r.end);
        }
        // θ1(t_step) grows ≈ 0.03 rad per N·m here, so 0.02 N·m moves it ≈ 6e-4 rad; the old
        // lock rule jumped by 0.04–0.07 rad (and 1 cm in w) where the graze flipped.
        assert!(worst[0] < 2e-3 && worst[1] < 5e-4, "jumps {worst:?}");
        // The scan crosses the graze.
        assert!(above > 0 && at > 0, "locked above l1 {above}, at l1 {at}");
    }

    #[test]
    fn the_lock_is_drawn_decelerating_over_the_blend() {
        // A leg lengthening at v that locks at t = 0.5 s (nodes every 2 ms, a pair at the lock).
        let (v, t_lock, half) = (0.2, 0.5, LOCK_BLEND);
        let mut tr = Track::<1>::default();
        for k in 0..=500 {
            let t = 0.002 * k as f64;
            let before = t <= t_lock;
            let n = |locked: bool| Node {
                t,
                q: [v * t.min(t_lock)],
                qd: [if locked { 0.0 } else { v }],
                qdd: [0.0],
            };
            tr.push(n(!before));
            if k == 250 {
                tr.push(n(true));
            }
        }
        let raw = tr.clone();
        blend_rate_jump(&mut tr, t_lock, half);
        // Independent: the drawn rate is v (1 − smoothstep) across the window; the position
        // its integral, never beyond the lock and at most 3·half·v/16 short of it.
        let mut worst = [0.0f64; 2];
        for k in 0..=4000 {
            let t = 0.40 + 0.00005 * k as f64;
            let (q, qd, _) = tr.at(t);
            let (q_raw, _, _) = raw.at(t);
            let u = ((t - t_lock + half) / (2.0 * half)).clamp(0.0, 1.0);
            let rate = v * (1.0 - u * u * (3.0 - 2.0 * u));
            worst[0] = worst[0].max((qd[0] - rate).abs());
            assert!(q[0] <= q_raw[0] + 1e-12, "longer than simulated at {t}");
            worst[1] = worst[1].max(q_raw[0] - q[0]);
            if (t - t_lock).abs() >= half {
                assert!(
                    (q[0] - q_raw[0]).abs() < 1e-12,
                    "changed outside the blend at {t}"
                );
            }
        }
        assert!(worst[0] < 1e-6, "rate off by {}", worst[0]);
        assert!(
            (worst[1] - 3.0 * half * v / 16.0).abs() < 1e-6,
            "{}",
            worst[1]
        );
        let k = tr.nodes.iter().position(|n| n.t == t_lock).unwrap();
        let (a, b) = (tr.nodes[k], tr.nodes[k + 1]);
        assert!(a.q[0] == b.q[0] && (a.qd[0] - b.qd[0]).abs() < 1e-12 && a.qd[0] > 0.0);
    }

    #[test]
    fn a_recorded_stance_is_c1_at_the_lock_and_ends_where_the_simulated_one_does() {
        let (spec, start) = grazing_spec();
        let h = spec.step(&start);
        // Step torques where the compression regains l1 from below (a real rate jump).
        let mut seen = 0;
        for i in 0..=50 {
            let a = 74.0 + 0.1 * i as f64;
            let drawn = spec.run(&start, a, 0.0, h, true);
            let sim = spec.run(&start, a, 0.0, h, false);
            assert_eq!(drawn.end, sim.end);
            let lock = drawn.lock_time.expect("locked");
            let k = drawn.track.nodes.iter().position(|n| n.t == lock).unwrap();
            let (b, c) = (drawn.track.nodes[k], drawn.track.nodes[k + 1]);
            for j in 0..3 {
                assert!(
                    (b.qd[j] - c.qd[j]).abs() < 1e-12,
                    "rate jump in {j} at {lock}"
                );
            }
            // Regained l1 from below: the simulated leg stops at the lock, the drawn one is
            // halfway down from its lengthening rate there, and at rest by the blend's end.
            if b.qd[0] > 1e-4 {
                seen += 1;
                let ext = drawn.extend_time.unwrap_or(spec.duration);
                if ext > lock + LOCK_BLEND {
                    let after = drawn.track.at(lock + LOCK_BLEND).1[0];
                    assert!(
                        after.abs() < 1e-6,
                        "still moving {after} at the blend's end"
                    );
                }
            }
        }
        assert!(seen > 0, "no lock from below");
    }

    #[test]
    fn a_late_push_off_meets_the_same_targets_with_the_hip_descending_less() {
        let (spec, start) = grazing_spec();
        let end = |n: f64| {
            let spec = StanceSpec {
                push_off: n,
                ..spec
            };
            let (s, run) = spec.solve(&start, [0.0, 0.0]).unwrap();
            assert!(s.residual[0].abs() <= 1e-7 && s.residual[1].abs() <= 1e-7);
            assert!(run.extend_time.is_some());
            let [w, t1, _, wd, t1d, _] = run.end;
            // The hip's vertical velocity at t_step (StanceModel::hip).
            (wd, wd * t1.cos() - w * t1d * t1.sin())
        };
        let (wd2, vy2) = end(2.0);
        let (wd4, vy4) = end(4.0);
        // τ⁴ against τ²: the same extension, its end rate larger — the hip descends less.
        assert!(wd4 > wd2 + 0.05, "ẇ(t_step) {wd2} → {wd4}");
        assert!(vy4 > vy2 + 0.02, "hip vertical velocity {vy2} → {vy4}");
        assert_eq!(push_off_exponent(0.5, 0.87), 2.0);
    }

    #[test]
    fn a_leg_locked_short_keeps_its_length_and_the_drawn_knee_its_flexion() {
        assert_eq!(lock_shortening(2.0), 0.0);
        assert!((lock_shortening(3.0) - LOCK_SHORT_PER_PUSH).abs() < 1e-15);
        assert_eq!(lock_shortening(6.0), LOCK_SHORT_MAX);
        let (spec, start) = grazing_spec();
        let leg_span = spec.l1;
        // A softer leg compresses well below l1 and regains the shorter lock length from below:
        // it locks there, and the drawn span is shortened by as much.
        let soft = StanceSpec {
            k_w: 0.3 * spec.k_w,
            lock_short: 0.005,
            push_off: 4.0,
            ..spec
        };
        // Landing with the hip closing on the ankle at 0.4 m/s.
        let start = StanceStart {
            qd: [-0.4, start.qd[1], 0.0],
            ..start
        };
        let h = soft.step(&start);
        let mut from_below = 0;
        for i in 0..=10 {
            let run = soft.run(&start, 60.0 + 4.0 * i as f64, 0.0, h, true);
            let Some(t) = run.lock_time else { continue };
            let w_min = run
                .track
                .nodes
                .iter()
                .filter(|n| n.t <= t)
                .map(|n| n.q[0])
                .fold(f64::INFINITY, f64::min);
            if w_min < soft.lock_length() - 1e-3 {
                from_below += 1;
                // The drawn track is blended over the lock (≤ 0.8 mm shorter, see LOCK_BLEND).
                let w = run.track.at(t).0[0];
                assert!((w - soft.lock_length()).abs() < 1e-3, "locked at {w}");
                let span = soft.drawn_span(&run, leg_span);
                let above = (w - soft.lock_length()).max(0.0);
                assert!((span - (leg_span - 0.005 * spec.l1 + above)).abs() < 1e-12);
                assert!(span <= leg_span - 0.005 * spec.l1 + 1e-3);
            }
        }
        assert!(from_below > 0, "no lock regained from below");
        // The grazing leg bottoms out near l1, above the shorter length: it locks where it
        // turns and keeps the knee it turned with (the span longer by as much, ≤ leg_span).
        let short = StanceSpec {
            lock_short: 0.02,
            ..spec
        };
        let run = short.run(&start, 76.0, 0.0, short.step(&start), true);
        let t = run.lock_time.expect("locked");
        let w = run.track.at(t).0[0];
        assert!(w > short.lock_length() + 5e-4);
        let span = short.drawn_span(&run, leg_span);
        let expected = (leg_span - 0.02 * spec.l1 + (w - short.lock_length())).min(leg_span);
        assert!((span - expected).abs() < 1e-12, "{span} vs {expected}");
        assert!(span > leg_span - 0.02 * spec.l1 + 5e-4);
        // Without the shortening, never shortened.
        assert_eq!(spec.drawn_span(&run, leg_span), leg_span);
    }

    #[test]
    fn the_grazing_stance_shoots_onto_its_targets() {
        let (spec, start) = grazing_spec();
        let (s, run) = spec.solve(&start, [0.0, 0.0]).unwrap();
        assert!(s.residual[0].abs() <= 1e-7 && s.residual[1].abs() <= 1e-7);
        assert!((run.end[0] - spec.target[0]).abs() <= 1e-7);
        assert!((run.end[1] - spec.target[1]).abs() <= 1e-7);
    }
}
