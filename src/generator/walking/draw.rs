//! Drawing the simulated steps: the stance feet's rolls smoothed, the knees held, and every frame
//! of the [`Motion`] assembled from the recorded trajectories (pelvis, virtual stance leg, swing
//! leg, kinematic feet, spine and arms).
use super::attributes::WalkAttributes;
use super::body::Body;
use super::determinants::Determinants;
use super::foot::FootShape;
use super::high_level::{Locomotion, PhaseTimes};
use super::pelvis_drop::PelvisLowering;
use super::stance::StanceRun;
use super::stop::Closing;
use super::swing::SwingRun;
use super::track::interp_rho;
use super::virtual_leg::{VirtualLeg, KNEE_SOFT};
use super::WalkOptions;
use crate::events::{EventKind, EventSource, Gait, GaitEvent, Side};
use crate::generator::curves::smoothstep;
use crate::generator::ik::leg_ik;
use crate::generator::motion::{Motion, MotionMetadata};
use crate::generator::skeleton::{Euler, Joint, Skeleton};
use crate::generator::GenerateError;
use glam::{DQuat, DVec3};
use std::f64::consts::PI;

pub(super) struct StepData {
    /// Whether the swing was braked (`SwingSpec::knee_brake`): only then is the drawn swing
    /// ankle moved to the model's knee span (`swing_span_target`).
    pub(super) knee_brake: bool,
    pub(super) side: Side,
    pub(super) start: f64,
    pub(super) loc: Locomotion,
    pub(super) times: PhaseTimes,
    pub(super) ankle_x: f64,
    pub(super) det: Determinants,
    pub(super) stance: StanceRun,
    pub(super) swing: SwingRun,
    pub(super) swing_foot: super::swing::SwingFoot,
    pub(super) swing_times: [f64; 4],
    /// Virtual-leg roll samples of the stance leg over the step (time from step start, ρ).
    pub(super) stance_rho: Vec<(f64, f64)>,
    /// The stance leg's hip (sagittal x, y) and lateral offset from its foot at each
    /// `stance_rho` sample.
    pub(super) stance_hips: Vec<([f64; 2], f64)>,
    pub(super) stance_leg: VirtualLeg,
    /// Trailing leg over the double support.
    pub(super) trail_rho: Vec<(f64, f64)>,
    /// The trailing leg's hip (sagittal x, y) and lateral offset from its foot at each
    /// `trail_rho` sample.
    pub(super) trail_hips: Vec<([f64; 2], f64)>,

    pub(super) trail_leg: VirtualLeg,
    /// Global time of the trailing leg's clock origin, s.
    pub(super) trail_origin: f64,
    /// How far the drawn pelvis is below the simulated hip over the step.
    pub(super) drop: PelvisLowering,
}

pub(super) fn side_z(side: Side, a: &WalkAttributes) -> f64 {
    match side {
        Side::Left => -0.5 * a.stride_width_m,
        Side::Right => 0.5 * a.stride_width_m,
    }
}

/// Time scale of the stance roll's smoothing after foot flat, s (see [`smooth_roll`]), for a
/// leg whose knee straightens softly over [`KNEE_SOFT`].
pub(super) const ROLL_TAU: f64 = 0.02;

/// Smooths every leg's recorded roll from foot flat to toe-off ([`smooth_roll`], never below
/// the rule): one leg's stance is recorded in two steps (its own, then the next step's double
/// support), so the two pieces are joined, smoothed and split again.
pub(super) fn smooth_rolls(data: &mut [StepData]) {
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
    // support its start was a free end: docs/klaw.md).
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

/// Keeps every leg's knee from straightening again between heel off and toe off.
pub(super) const KNEE_HOLD_TAU: f64 = 0.03;

pub(super) fn hold_knees(data: &mut [StepData]) {
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
pub(super) fn assemble(
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
        pose.root = DVec3::new(x_dyn, y_dyn + off.y - d.drop.at(tau), z_c);
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
            // The swing leg hangs from the drawn pelvis (`PelvisDrop`), as simulated.
            let hip = [x_dyn + off.x, y_dyn + 2.0 * off.y - d.drop.at(tau)];
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
/// (`drawn_heel_off`).
pub(super) const HEEL_OFF_ROLL: f64 = 1e-3;

/// The time (global, s) of the first recorded roll sample (`(t, ρ)` on the clock starting at
/// `start`) at or after `after` whose roll exceeds [`HEEL_OFF_ROLL`]: where the drawn heel
/// leaves the floor.
pub(super) fn drawn_heel_off(rho: &[(f64, f64)], start: f64, after: f64) -> Option<f64> {
    rho.iter()
        .map(|&(t, r)| (start + t, r))
        .find(|&(g, r)| g >= after - 1e-12 && r > HEEL_OFF_ROLL)
        .map(|(g, _)| g)
}

/// One frame of the stop ([`Closing`]): pelvis level and unrotated, trunk returning to its lean,
/// arms following the opposite thighs as in the walk.
pub(super) fn closing_pose(
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
pub(super) fn swing_arms(
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

/// Half-width of the band of shoulder flexion, rad, over which the elbow's extra flexion (half of
/// any forward flexion, [`swing_arms`]) starts.
pub(super) const ELBOW_BAND: f64 = 0.05;

/// `max(x, 0)` with its corner rounded over |x| < `band` by the parabola (x + band)²/(4·band):
/// C¹, equal to `max(x, 0)` outside the band.
pub(super) fn soft_positive(x: f64, band: f64) -> f64 {
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
pub(super) const ARM_LAG_CYCLE: f64 = 0.1;

/// The arms follow the opposite leg through a critically damped second-order lag: two equal
/// first-order stages, each delaying the stride's fundamental by half of [`ARM_LAG_CYCLE`]
/// (continuous time: τ = tan(π·ARM_LAG_CYCLE)·cycle/2π, 45 ms at 7 km/h × 1.5 m, 130 ms at
/// 1 km/h × 1.8 m), with the gain the two stages take from the fundamental, cos²(π·ARM_LAG_CYCLE)
/// = 0.905, given back (`ArmLag::gain`).
pub(super) struct ArmLag {
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
    pub(super) fn new(fps: f64) -> Self {
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
    pub(super) fn set_cycle(&mut self, cycle: f64) -> f64 {
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
    pub(super) fn follow(&mut self, side: Side, leg: f64) -> f64 {
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
    crate::generator::ik::planar_two_link(hip, ankle, l3, l4)
}

/// Smooths the stance foot's roll after it is flat: `rho` (the rule's roll, non-decreasing,
/// sampled at the increasing `times`) is replaced from sample `from` on by the curve that stays
/// closest to it while bending least, `min Σ (ρ − rho)² + (τ/h̄)⁴ Σ (h̄² ρ̈)²` (`h̄` the mean
/// sample spacing, `ρ̈` by divided differences), never below it. The first two samples are kept
/// (`rest`: the second is set equal to the first — the foot lands flat at rest from the heel
/// rocker), and so are the last two (toe-off, where the swing takes over, and its rate).
pub fn smooth_roll(times: &[f64], rho: &mut [f64], from: usize, rest: bool, tau: f64) {
    let n = times.len().min(rho.len());
    if from + 6 >= n || tau <= 0.0 {
        return;
    }
    let m = n - from;
    let t = &times[from..n];
    let target: Vec<f64> = rho[from..n].to_vec();
    let lo = &target;
    let hbar = (t[m - 1] - t[0]) / (m - 1) as f64;
    if hbar.is_nan() || hbar <= 0.0 {
        return;
    }
    let lambda = (tau / hbar).powi(4);
    // Band storage of the symmetric matrix: a[i] = [A_ii, A_i,i+1, A_i,i+2].
    let mut base = vec![[1.0f64, 0.0, 0.0]; m];
    for j in 1..m - 1 {
        let h0 = (t[j] - t[j - 1]).max(0.1 * hbar);
        let h1 = (t[j + 1] - t[j]).max(0.1 * hbar);
        let c0 = 2.0 * hbar * hbar / ((h0 + h1) * h0);
        let c2 = 2.0 * hbar * hbar / ((h0 + h1) * h1);
        let c = [c0, -(c0 + c2), c2];
        for a in 0..3 {
            for b in a..3 {
                base[j - 1 + a][b - a] += lambda * c[a] * c[b];
            }
        }
    }
    let mut fixed: Vec<Option<f64>> = vec![None; m];
    fixed[0] = Some(target[0]);
    fixed[1] = Some(if rest { target[0] } else { target[1] });
    fixed[m - 2] = Some(target[m - 2]);
    fixed[m - 1] = Some(target[m - 1]);
    let mut x = target.clone();
    for _ in 0..60 {
        x = solve_pinned(&base, &target, &fixed);
        // The deepest sample of each run below the rule is pinned to it.
        let mut added = false;
        let mut i = 0;
        while i < m {
            if fixed[i].is_none() && x[i] < lo[i] - 1e-12 {
                let mut worst = i;
                let mut j = i;
                while j < m && fixed[j].is_none() && x[j] < lo[j] - 1e-12 {
                    if x[j] - lo[j] < x[worst] - lo[worst] {
                        worst = j;
                    }
                    j += 1;
                }
                fixed[worst] = Some(lo[worst]);
                added = true;
                i = j;
            } else {
                i += 1;
            }
        }
        if !added {
            break;
        }
    }
    rho[from..n].copy_from_slice(&x);
}

/// Solves `(I + λDᵀD) x = target` (band storage `a`, see [`smooth_roll`]) with the `pinned`
/// samples held at their values: a banded LDLᵀ factorization, O(n).
fn solve_pinned(a: &[[f64; 3]], target: &[f64], pinned: &[Option<f64>]) -> Vec<f64> {
    let m = a.len();
    let mut band = a.to_vec();
    let mut rhs = target.to_vec();
    // Move the pinned samples to the right-hand side and decouple their rows.
    for k in 0..m {
        let Some(v) = pinned[k] else { continue };
        for off in 1..3 {
            if k + off < m {
                rhs[k + off] -= band[k][off] * v;
                band[k][off] = 0.0;
            }
            if k >= off {
                rhs[k - off] -= band[k - off][off] * v;
                band[k - off][off] = 0.0;
            }
        }
        band[k][0] = 1.0;
        rhs[k] = v;
    }
    for k in 0..m {
        if let Some(v) = pinned[k] {
            rhs[k] = v;
        }
    }
    // LDLᵀ with bandwidth 2: l[i] = [L_i,i−1, L_i,i−2].
    let mut d = vec![0.0; m];
    let mut l = vec![[0.0f64; 2]; m];
    for j in 0..m {
        let mut dj = band[j][0];
        if j >= 1 {
            dj -= l[j][0] * l[j][0] * d[j - 1];
        }
        if j >= 2 {
            dj -= l[j][1] * l[j][1] * d[j - 2];
        }
        d[j] = dj;
        if j + 1 < m {
            let mut v = band[j][1];
            if j >= 1 {
                v -= l[j + 1][1] * l[j][0] * d[j - 1];
            }
            l[j + 1][0] = v / dj;
        }
        if j + 2 < m {
            l[j + 2][1] = band[j][2] / dj;
        }
    }
    // Forward, diagonal, backward substitution.
    let mut y = rhs;
    for i in 0..m {
        if i >= 1 {
            y[i] -= l[i][0] * y[i - 1];
        }
        if i >= 2 {
            y[i] -= l[i][1] * y[i - 2];
        }
    }
    for i in 0..m {
        y[i] /= d[i];
    }
    for i in (0..m).rev() {
        if i + 1 < m {
            y[i] -= l[i + 1][0] * y[i + 1];
        }
        if i + 2 < m {
            y[i] -= l[i + 2][1] * y[i + 2];
        }
    }
    y
}

/// The drawn swing ankle's target: the sagittal model's ankle, moved along the line from the
/// skeleton's hip joint by the fraction `w` of the way to the model's hip–ankle span `span`.
pub(super) fn swing_span_target(
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
pub(super) fn place_leg(
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

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn smoothed_roll_is_never_below_the_rule_and_keeps_its_ends() {
        // Flat until 0.1 s, a 0.02 rad rise in 8 ms (the rule's heel-off kick), then a creep.
        let times: Vec<f64> = (0..=200).map(|i| 0.002 * i as f64).collect();
        let rule: Vec<f64> = times
            .iter()
            .map(|&t| {
                if t < 0.1 {
                    0.0
                } else if t < 0.108 {
                    0.02 * (t - 0.1) / 0.008
                } else {
                    0.02 + 0.1 * (t - 0.108)
                }
            })
            .collect();
        let mut s = rule.clone();
        smooth_roll(&times, &mut s, 0, false, 0.02);
        assert_eq!(s[0], rule[0]);
        assert_eq!(s[200], rule[200]);
        assert_eq!(s[199], rule[199]);
        for i in 0..=200 {
            assert!(s[i] >= rule[i] - 1e-12, "below the rule at {i}");
            if i > 0 {
                assert!(s[i] >= s[i - 1] - 1e-9, "decreasing at {i}");
            }
        }
        let max_inc = |v: &[f64]| v.windows(2).map(|w| w[1] - w[0]).fold(0.0, f64::max);
        assert!(
            max_inc(&s) < 0.25 * max_inc(&rule),
            "{} vs {}",
            max_inc(&s),
            max_inc(&rule)
        );
    }

    /// The continuity check's ratio ([`crate::generator::checks::continuity`]: each step
    /// against the median of the 3 on each side, floored) of a series sampled every 10 ms.
    fn worst_step_ratio(v: &[f64], floor: f64) -> f64 {
        let steps: Vec<f64> = v.windows(2).map(|w| (w[1] - w[0]).abs()).collect();
        crate::generator::checks::step_ratios(&steps, 3, floor)
            .into_iter()
            .flatten()
            .fold(0.0, f64::max)
    }

    #[test]
    fn roll_after_a_flat_landing_starts_at_rest_and_spreads_the_heel_off_kick() {
        // What the rule does at 3 km/h: the foot lands flat at rest at 0.11 s (rocker roll
        // < 0 before), the telescopic leg reaches the soft band 20 ms later and locks 15 ms
        // after that: the heel-off roll rises 0.0146 rad in 15 ms, then creeps at 7.5 mrad/s.
        let times: Vec<f64> = (0..=300).map(|i| 0.002 * i as f64).collect();
        let rule: Vec<f64> = times
            .iter()
            .map(|&t| {
                if t < 0.11 {
                    -0.05 * (0.11 - t) * (0.11 - t) / 0.0121
                } else if t < 0.131 {
                    0.0
                } else if t < 0.146 {
                    0.0146 * ((t - 0.131) / 0.015).powi(2)
                } else {
                    0.0146 + 0.0075 * (t - 0.146)
                }
            })
            .collect();
        let from = rule.iter().position(|&r| r >= 0.0).unwrap();
        let mut s = rule.clone();
        smooth_roll(&times, &mut s, from, true, 0.02);
        assert_eq!(
            &s[..=from],
            &rule[..=from],
            "the heel rocker is not touched"
        );
        assert_eq!(s[from + 1], s[from], "lands at rest");
        for i in from..=300 {
            assert!(s[i] >= rule[i] - 1e-12, "below the rule at {i}");
        }
        // Sampled at 100 frames/s, the heel-off roll passes the continuity check (k = 5, floor
        // 1 mrad scaled to the heel: a 0.2 m lever, 0.1 mm floor), which the rule fails.
        let frames = |v: &[f64]| v.iter().step_by(5).copied().collect::<Vec<f64>>();
        let floor = 1e-4 / 0.2;
        let before = worst_step_ratio(&frames(&rule[from..]), floor);
        let after = worst_step_ratio(&frames(&s[from..]), floor);
        assert!(before > 5.0, "the rule's kick: {before}");
        assert!(after < 3.0, "smoothed: {after}");
    }

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
}
