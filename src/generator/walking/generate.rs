//! The walk, step by step (§2.4): for each step the high level is executed first (step
//! constraints), then the stance phase is simulated, the determinants of gait are applied to the
//! pelvis, the trailing leg's stance is completed kinematically through the double support, the
//! swing leg is simulated from toe-off to heel strike, and heel strike (a collision) gives the
//! next stance phase its initial conditions. Finally every frame of the [`Motion`] is assembled
//! from the recorded trajectories: pelvis, virtual stance leg, swing leg, kinematic feet, spine
//! and arms.
use super::body::Body;
use super::collision::{self, SwingAtImpact};
use super::dynamics::{HipMotion, StanceModel};
use super::foot::FootShape;
use super::high_level::{heel_strike, phase_times, Locomotion, PhaseTimes};
use super::stance::{StanceSpec, StanceStart};
use super::stop::{Closing, StopStart};
use super::swing::{SwingCarry, SwingSpec, SwingStart};
use super::virtual_leg::{FootPeriod, LegPose, VirtualLeg, KNEE_SOFT, TOE_OFF_KNEE_RATE};
use crate::events::Side;
use crate::generator::motion::Motion;
use crate::generator::skeleton::Skeleton;
use crate::generator::GenerateError;
use std::f64::consts::PI;

pub use super::determinants::Determinants;
pub use super::draw::sagittal_angles;
use super::draw::*;
pub use super::first_step::FIRST_TOE_OFF_THIGH;
use super::first_step::*;
use super::pelvis_drop::{flat_drop, pelvis_smooth_tau, PelvisDrop, PelvisLowering};
pub use super::WalkOptions;
use crate::generator::numeric::bisect;

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

fn num_err(stage: String, message: String) -> GenerateError {
    GenerateError::Numerical { stage, message }
}

/// Shortest meta-off knee flexion, as a fraction of the double support (see
/// [`VirtualLeg::min_knee_blend`]).
const MIN_KNEE_BLEND: f64 = 0.3;

/// Window over which the stance ankle's rate just after heel strike is measured, s.
const CONTACT_RATE_WINDOW: f64 = 0.01;

/// Largest ankle rate |θ̇5| the swing foot is given at heel strike, rad/s.
pub const MAX_CONTACT_ANKLE_RATE: f64 = 6.0;

/// Weight of the swing ankle's contact ramp ([`super::swing::SwingFoot::contact_ramp`]) for a
/// landing whose stance ankle turns at `rate` rad/s just after heel strike: 0 up to
/// [`MAX_CONTACT_ANKLE_RATE`] (the swing3 cubic matches such a rate in full, and the paper's
/// ending is kept), rising linearly to 1 at twice it.
pub fn contact_ramp_weight(rate: f64) -> f64 {
    ((rate.abs() - MAX_CONTACT_ANKLE_RATE) / MAX_CONTACT_ANKLE_RATE).clamp(0.0, 1.0)
}

/// How much later (fraction of the swing) swing1 ends in the last step before a stop, a half step
/// whose swing foot travels 1.5 step lengths to a heel strike only half a step ahead.
const STOP_SWING1_DELAY: f64 = 0.05;

/// Fraction of the ankle curve's lift (`ankle_lift_m`, §4.3's `a_max` over the curve's higher end)
/// kept in the last step before a stop.
const STOP_LIFT: f64 = 0.5;

/// How much shorter than the soft knee's straight limit the standing legs are, m (floating-point
/// margin, so that the standing feet are flat, not rolled by 1e-12).
const STAND_MARGIN: f64 = 1e-4;

/// Unrecorded steps simulated before a steady (not from rest) start.
pub const PRE_ROLL: usize = 2;

/// Frames a steady (not from rest) walk's recording begins before its first heel strike.
pub const LEAD_IN_FRAMES: usize = 5;

/// Frames a walk without a stop is recorded past the trailing foot's toe off that follows its last
/// heel strike (so `t_ds + LEAD_OUT_FRAMES / fps` past that heel strike), drawn from one unrecorded
/// step simulated after the last (the landing leg's heel rocker, the trailing leg's double support
/// and first swing frames).
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
        };
        // At speed the leg locks short of l1: the midstance knee (`stance::lock_shortening`).
        let lock_short = super::stance::lock_shortening(spec.push_off);
        let spec = StanceSpec { lock_short, ..spec };
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
        // The simulated hips of the stance and the trailing leg (sagittal x, y; lateral z).
        let stance_hip_sim = |t: f64| -> ([f64; 2], f64) {
            let h = dyn_hip(t);
            let o = det.swing_offset(t);
            let z_c = det.lateral_at(t);
            ([h.pos[0] - o.x, h.pos[1]], z_c - o.z)
        };
        // The drawn pelvis is lowered where the flat stance foot is out of the drawn leg's soft
        // reach (`draw::PelvisDrop`): this stance's drop is the largest its flat foot needs
        // while the simulated leg is not extending (the extension beyond the lock is the heel
        // rising, §4.2), blended in from the previous stance's over the double support.
        let span_max = spec.drawn_span(&st_run, body.l3 + body.l4);
        let zf_s = side_z(stance_side, a);
        let flat_reach = span_max.min(body.l3 + body.l4) - 2.0 * KNEE_SOFT - STAND_MARGIN;
        let need = |t: f64| {
            let (hp, hz) = stance_hip_sim(t);
            flat_drop(hp, hz - zf_s, [ax, body.l9], flat_reach)
        };
        // From the hip's closest approach to the flat ankle (the need's least: the foot cannot
        // be flat before) to the extension.
        let t_flat_end = st_run.extend_time.unwrap_or(0.5 * t_step).min(t_step);
        let needs: Vec<f64> = (0..=64)
            .map(|i| need(t_flat_end * i as f64 / 64.0))
            .collect();
        let closest = (0..needs.len()).fold(0, |m, i| if needs[i] < needs[m] { i } else { m });
        let drop_to = needs[closest..].iter().copied().fold(0.0, f64::max);
        // The drop rises as slowly as still covers the need, with the soft knee's width to
        // spare, from the closest approach on (where the foot can first be flat).
        let covers = |rise: f64| {
            let p = PelvisDrop {
                height: drop_to,
                rise,
                fall: t_flat_end,
                end: t_step,
            };
            (closest..needs.len()).all(|i| {
                let need = (needs[i] + KNEE_SOFT).min(drop_to);
                p.at(t_flat_end * i as f64 / 64.0) >= need - 1e-6
            })
        };
        // The largest rise that covers (bisection: the drop's rise is continuous in the need).
        let (mut lo, hi) = (t_flat_end * closest.max(8) as f64 / 64.0, t_flat_end);
        if covers(hi) {
            lo = hi;
        }
        let rise = bisect(lo, hi, usize::MAX, 1e-6, &covers).0;
        let drop = PelvisDrop {
            height: drop_to,
            rise,
            fall: t_flat_end,
            end: t_step,
        };
        // The drawn pelvis height: the least-bending curve below the simulated hip lowered by
        // the flat foot's drop (low-passed at twice the step frequency, `pelvis_smooth_tau`),
        // equal to it at both heel strikes.
        let lowering = {
            let n = ((t_step / 2e-3).ceil() as usize).max(8);
            let h = t_step / n as f64;
            let times: Vec<f64> = (0..=n).map(|i| h * i as f64).collect();
            let sim: Vec<f64> = times.iter().map(|&t| stance_hip_sim(t).0[1]).collect();
            let mut below: Vec<f64> = times
                .iter()
                .zip(&sim)
                .map(|(&t, &y)| drop.at(t) - y)
                .collect();
            smooth_roll(&times, &mut below, 0, false, pelvis_smooth_tau(t_step));
            let d = (0..=n)
                .map(|i| (sim[i] + below[i]).max(drop.at(times[i])))
                .collect();
            PelvisLowering::from_samples(h, d)
        };
        let stance_hip = |t: f64| -> ([f64; 2], f64) {
            let (hp, hz) = stance_hip_sim(t);
            ([hp[0], hp[1] - lowering.at(t)], hz)
        };
        // The swing leg hangs from the drawn pelvis, as from the kinematic pelvic rotation and
        // list (§2: the determinants are injected into the one-hip model): the simulated hip with
        // the determinants' offsets and the drop.
        let swing_hip = |t: f64| -> HipMotion {
            let mut h = dyn_hip(t);
            let (o, od, odd) = det.swing_hip_offset_rates(t);
            for i in 0..2 {
                h.pos[i] += o[i];
                h.vel[i] += od[i];
                h.acc[i] += odd[i];
            }
            let [d, dd, ddd] = lowering.rates(t);
            h.pos[1] -= d;
            h.vel[1] -= dd;
            h.acc[1] -= ddd;
            h
        };
        let swing_hip3 = |t: f64| -> ([f64; 2], f64) {
            let h = swing_hip(t);
            let o = det.swing_offset(t);
            (h.pos, det.lateral_at(t) + o.z)
        };
        // The trailing leg's rules see the simulated hip: its foot is off flat, and the drop
        // rising under it through the double support would bend its knee and then roll the foot
        // (the drawn leg reaches the rule's ankle from the lowered pelvis all the same).
        let trail_hip3 = |t: f64| -> ([f64; 2], f64) {
            let (hp, hz) = swing_hip3(t);
            ([hp[0], hp[1] + lowering.at(t)], hz)
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
            let (hp, hz) = trail_hip3(0.0);
            let knee = trailing.pose_at(hp, hz - zf_w, trailing.rho).knee;
            trailing.period = FootPeriod::MetaOff;
            trailing.meta_start = Some((trailing_clock, knee));
            trailing.transitions[1].get_or_insert(trailing_clock);
            trailing.transitions[2] = Some(trailing_clock);
            if kk == 0 {
                let hips: Vec<(f64, [f64; 2], f64)> = (0..=n_v)
                    .map(|i| {
                        let t = t_ds * i as f64 / n_v as f64;
                        let (hp, hz) = trail_hip3(t);
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
            let (hp, hz) = trail_hip3(t);
            let p = trailing.advance(trailing_clock + t, hp, hz - zf_w);
            trail_rho.push((t, p.rho));
            trail_hips.push((hp, hz - zf_w));
            // The swing starts from the drawn (lowered) hip it hangs from.
            trail_poses.push((t, p, swing_hip3(t).0));
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
        stance_leg.span_max = span_max;
        stance_leg.toe_off_time = t_step
            + next_times
                .map(|t| t.double_support)
                .unwrap_or(times.double_support);
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
            drop: lowering,
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
fn speeds_up(all: &[Locomotion], kk: usize) -> bool {
    kk > 0 && all[kk].speed_m_per_s > all[kk - 1].speed_m_per_s + 1e-9
}

#[cfg(test)]
mod tests {
    use super::*;

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
