//! Planning one running step from its state keyframes: the pelvis orientation keys, the support
//! spline with recovery 1 (mid-support lowered while the stance hip is out of reach), heel off,
//! the swing leg's keys (§3.3.1) and the legs in flight (§3.3.2), and the state handed to the
//! next step.
use super::*;

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

/// The flight's share of the time from toe off to the next mid-support at the paper's
/// reference stride (12 km/h, 1.8 m: 0.188 s of 0.254 s), for which p ∈ [0.6, 0.9] was tuned.
pub const P_REFERENCE_SHARE: f64 = 0.74;

/// Fraction of the first support during which the swing foot is lifted off from the stand.
pub const START_LIFT_FRACTION: f64 = 0.4;
/// How high the swing foot is lifted from the stand by then, m at 1.8 m.
pub const START_LIFT: f64 = 0.04;

/// Least downward speed of the landing foot's lowest point at heel strike, m/s at 1.8 m.
pub const LANDING_SPEED: f64 = 0.15;

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
        other_flight_time,
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
            other_flight_time,
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

    // From a stand the pelvis rises straight to toe off: no mid-support sink.
    if kind != StepKind::Start {
        plan.report.pelvis_sink = p0.y - y_ms;
    }
    plan.report.bounciness = e.bounciness;

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
    let tor_deficit = need - leg_fk(d, hip_tor, &tor_pose).lowest();
    if tor_deficit > 0.0 {
        plan.report.clearance_deficit = tor_deficit;
    }
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
    for (sign, hind, t_a, ramp_in, ramp_out) in [
        (sw, false, t_sw0, start, true),
        (s, true, t_stance, true, false),
    ] {
        let (keys, deficit) = clear_track(
            &mut plan, d, sign, hind, t_a, t_step, ramp_in, ramp_out, margin,
        );
        plan.report.clearance_keys += keys;
        if deficit > plan.report.clearance_deficit {
            plan.report.clearance_deficit = deficit;
            plan.report.clearance_hind = hind;
        }
    }
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

pub(super) fn hip_of(plan: &StepPlan, d: &RunnerDims, t: f64, sign: f64) -> DVec3 {
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
pub(super) fn stance_reachable(plan: &StepPlan, d: &RunnerDims) -> bool {
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

/// The mode of the stance foot at `t` of a planned step (for events and reports).
pub fn stance_mode(plan: &StepPlan, d: &RunnerDims, t: f64) -> StanceMode {
    let hip = hip_of(plan, d, t, plan.s);
    stance_leg(plan, d, t, hip).mode
}
