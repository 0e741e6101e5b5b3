//! The stands at either end of a run: the standing pose a start begins from, and the stop after
//! the last landing, which brings the pelvis to rest and sets the other foot down.
use super::*;

/// How far ahead of the stance ankle the pelvis comes to rest at a stop, m at 1.8 m.
pub const STOP_STAGGER: f64 = 0.1;
/// Knee flexion of the final stand, rad.
pub const STOP_KNEE: f64 = 15.0 * std::f64::consts::PI / 180.0;
/// Longest stop phase, s at 1.8 m.
pub const STOP_TIME: f64 = 0.6;

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
