//! Building walk data W(S, sl) from measured markers (§3: "we will assume that we have the
//! measured data W(S*, sl*) … prototype walk data") — Ko & Badler animated Winter's
//! rotoscoped walk, which is the bundled prototype.
//!
//! Input: one leg's sagittal landmarks (hip = greater trochanter, knee = lateral femoral
//! epicondyle, ankle = lateral malleolus, heel, ball = fifth metatarsal head, toe) over one
//! stride between two heel strikes of that leg, and its toe off. The other leg is taken as the
//! same leg half a stride later and one step back (symmetric walking): the step's swing foot is
//! this leg's own swing, and the hip H is the mean of this hip and the mirrored other hip
//! (the pelvis centre in the sagittal plane).
//!
//! Model decisions (documented, tested):
//! - The foot is the rigid marker triangle heel–ankle–ball, as in Table 2 (its subject column is
//!   Winter's marker triangle); N is the foot of the ankle's perpendicular on the heel–ball
//!   line; the toe segment is ball→toe marker. Lengths are stride means.
//! - The marker lines are not parallel to the floor in the flat foot (Winter's heel marker sits
//!   higher than the MT5 marker, ≈ 3.5°): foot angles are measured from the heel→ball line's
//!   angle in early stance ([`FLAT_WINDOW`]), so the model foot is flat when the measured one is.
//!   Meta angles are measured from the ball→toe line's angle at MOM, when the toes begin to turn
//!   about their tip (the shoe bends at the ball during heel rise, so the mid-stance toe line is
//!   no reference).
//! - The stance heel's floor point x₀ and the floor height y₀ are those that put the model's
//!   stance ankle (rolling over fixed heel, ball and toe pivots with the measured angles) closest
//!   to the measured ankle over the whole stance (least squares). A real heel rolls ≈ 2–3 cm
//!   forward during the heel rocker (Winter's heel marker does); a point pivot cannot, and this
//!   splits the difference between heel strike and foot flat. (Placing the heel at heel strike,
//!   or weighting the error along the leg, made the Schreiber comparison's model floor worse.)
//! - sl* is half the heel marker's displacement between the two heel strikes; the pelvis travel
//!   over the step is corrected linearly to exactly sl* (otherwise repeated steps would drift).
//! - FGM: the foot angle first within [`FLAT_FOOT_TOLERANCE_RAD`] of flat after heel strike;
//!   MOM: the ball marker's last rise [`BALL_LIFT_M`] above its flat height before toe off;
//!   TOM: toe off (as the swing foot's time in the step).
//! - Thigh (from the pelvis centre) and shin keep their marker-mean ratio and are scaled so the
//!   model leg, from H(0) to the model's heel-strike ankle, bends exactly as the measured knee
//!   does at heel strike (μ₁*). A leg near full extension turns a centimetre of skin artifact
//!   into 10–20° of knee flexion, so raw marker means will not do; with them Winter's leg is
//!   ≈ 1 cm too short to reach the hip at heel strike. (A least-squares scale over the whole
//!   stride left heel strike out of reach and, through eq. 27's pinning, lowered the hip over
//!   the whole step: worse.)
//! - μ* are read off the data (μ₂* = F₁(0), μ₃* = −F₂(end), μ₄* = M(end), μ₁* = the measured
//!   knee flexion at heel strike), and the raw W is made consistent by φ₁
//!   (which pins the hip heights, blends F₃ onto the heel-strike angle and maps A onto the
//!   model's toe-off and heel-strike ankles); [`PrototypeReport`] says how far each end moved.
use super::angles::{measured_angles, Angles, SAMPLES};
use super::carried::Carried;
use super::geometry::{foot_on_pivot, hip_ankle_distance, knee_flexion_for_distance, Pivot};
use super::mu::MuFunctions;
use super::phi::phi;
use super::walk_data::{Anthropometry, Moments, TimedSequence, WalkData};
use crate::generator::GenerateError;

/// One leg's sagittal landmarks (x forward, y up, m) at increasing times (s).
#[derive(Debug, Clone, PartialEq)]
pub struct SagittalLeg {
    /// Sample times, s.
    pub time_s: Vec<f64>,
    /// Hip (greater trochanter).
    pub hip: Vec<[f64; 2]>,
    /// Knee (lateral femoral epicondyle).
    pub knee: Vec<[f64; 2]>,
    /// Ankle (lateral malleolus).
    pub ankle: Vec<[f64; 2]>,
    /// Heel.
    pub heel: Vec<[f64; 2]>,
    /// Ball (fifth metatarsal head).
    pub ball: Vec<[f64; 2]>,
    /// Toe.
    pub toe: Vec<[f64; 2]>,
    /// The pelvis centre (the model's hip H) when it is measured directly, e.g. the midpoint of
    /// both hip joint centres; `None` estimates it from `hip` and its mirror half a stride
    /// later (Winter's table has one side only).
    pub pelvis: Option<Vec<[f64; 2]>>,
    /// This leg's hip joint centre minus the pelvis centre (the midpoint of both hip joint
    /// centres), sagittal (forward, up; m), when the pelvis is measured (e.g. from its four
    /// markers, [`super::compare::hip_joint_centre`]): the pelvis' rotation (transverse) and
    /// list seen from the side — how far each hip joint is ahead of / above the other's mean.
    /// The carried variant places each leg's hip with it ([`super::carried`]); `None` when the
    /// pelvis is not measured (Winter's table).
    pub hip_offset: Option<Vec<[f64; 2]>>,
}

/// One stride's events of the leg, s: heel strike, toe off, next heel strike.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct StrideEvents {
    /// Heel strike (HSM⁻ of the prototype step).
    pub heel_strike: f64,
    /// Toe off of the same foot.
    pub toe_off: f64,
    /// The same foot's next heel strike.
    pub next_heel_strike: f64,
}

/// What building the prototype measured and how much φ₁ had to move the raw data onto the
/// model's constraints.
#[derive(Debug, Clone, PartialEq)]
pub struct PrototypeReport {
    /// Step length sl* (m).
    pub step_length_m: f64,
    /// Step duration (s): half the stride.
    pub step_duration_s: f64,
    /// Pelvis travel over the step before the linear correction to sl* (m).
    pub raw_hip_travel_m: f64,
    /// Mid-stance angle of the heel→ball marker line (rad), subtracted from foot angles.
    pub foot_line_offset_rad: f64,
    /// Mid-stance angle of the ball→toe marker line (rad), subtracted from meta angles.
    pub toe_line_offset_rad: f64,
    /// How far φ₁ moved the swing ankle's toe-off end (m).
    pub ankle_to_shift_m: f64,
    /// How far φ₁ moved the swing ankle's heel-strike end (m).
    pub ankle_hs_shift_m: f64,
    /// How far φ₁ moved the hip's end heights (m): HSM⁻, HSM⁺.
    pub hip_pin_m: [f64; 2],
    /// Moments FGM, MOM, TOM (normalized).
    pub moments: [f64; 3],
    /// μ₁*…μ₄* (rad).
    pub mu_star: [f64; 4],
    /// Factor applied to the marker-mean thigh and shin so the model knee at heel strike bends
    /// as the measured one (see the module docs).
    pub leg_scale: f64,
    /// Largest hip lowering the prototype step itself needs for both legs to reach (m).
    pub max_hip_drop_m: f64,
}

/// The flat-foot window, as fractions of stance after heel strike: after the heel rocker, before
/// Winter's heel marker starts creeping up (≈ 45 %).
pub const FLAT_WINDOW: (f64, f64) = (0.20, 0.40);
/// The foot counts as flat (FGM) once its angle is within this of the flat-window angle (rad,
/// 1°): the marker line settles onto its plateau asymptotically.
pub const FLAT_FOOT_TOLERANCE_RAD: f64 = 0.017_453_292_519_943_295;
/// The ball counts as lifted (MOM) once its marker is this far above its flat-window height (m).
pub const BALL_LIFT_M: f64 = 0.005;

fn err(stage: &str, message: String) -> GenerateError {
    GenerateError::Numerical {
        stage: format!("building the prototype: {stage}"),
        message,
    }
}

/// Linear interpolation of a sampled signal at time `t` (clamped to the ends).
fn sample(times: &[f64], v: &[[f64; 2]], t: f64) -> [f64; 2] {
    let n = times.len();
    if t <= times[0] {
        return v[0];
    }
    if t >= times[n - 1] {
        return v[n - 1];
    }
    let i = times.partition_point(|&x| x <= t);
    let w = (t - times[i - 1]) / (times[i] - times[i - 1]);
    [
        v[i - 1][0] + w * (v[i][0] - v[i - 1][0]),
        v[i - 1][1] + w * (v[i][1] - v[i - 1][1]),
    ]
}

fn dist(a: [f64; 2], b: [f64; 2]) -> f64 {
    (a[0] - b[0]).hypot(a[1] - b[1])
}

fn angle(from: [f64; 2], to: [f64; 2]) -> f64 {
    (to[1] - from[1]).atan2(to[0] - from[0])
}

fn median(mut v: Vec<f64>) -> f64 {
    v.sort_by(f64::total_cmp);
    let n = v.len();
    if n % 2 == 1 {
        v[n / 2]
    } else {
        0.5 * (v[n / 2 - 1] + v[n / 2])
    }
}

/// Sample times for a sequence on [t_a, t_b] (seconds): the ends plus every frame strictly
/// inside (frames closer than 1% of a frame to an end are dropped to keep times increasing).
fn grid(times: &[f64], a: f64, b: f64) -> Vec<f64> {
    let dt = (times[times.len() - 1] - times[0]) / (times.len() - 1) as f64;
    let mut g = vec![a];
    g.extend(
        times
            .iter()
            .copied()
            .filter(|&t| t > a + 0.01 * dt && t < b - 0.01 * dt),
    );
    g.push(b);
    g
}

/// The first time in (a, b) where `f` crosses from above `level` to at or below it, by linear
/// interpolation between samples.
fn first_fall(times: &[f64], f: &dyn Fn(f64) -> f64, a: f64, b: f64) -> Option<f64> {
    let g = grid(times, a, b);
    g.windows(2).find_map(|w| {
        let (fa, fb) = (f(w[0]), f(w[1]));
        (fa > 0.0 && fb <= 0.0).then(|| w[0] + (w[1] - w[0]) * fa / (fa - fb))
    })
}

/// The last time in (a, b) where `f` rises from at or below 0 to above it.
fn last_rise(times: &[f64], f: &dyn Fn(f64) -> f64, a: f64, b: f64) -> Option<f64> {
    let g = grid(times, a, b);
    g.windows(2).rev().find_map(|w| {
        let (fa, fb) = (f(w[0]), f(w[1]));
        (fa <= 0.0 && fb > 0.0).then(|| w[0] + (w[1] - w[0]) * (-fa) / (fb - fa))
    })
}

/// Builds the prototype W(S*, sl*) and its μ-functions (slopes `alpha`, rad/m) from one leg's
/// markers over one stride. Errors name the stage and what the data lacked.
pub fn build_prototype(
    leg: &SagittalLeg,
    ev: &StrideEvents,
    alpha: [f64; 4],
) -> Result<(WalkData, MuFunctions, PrototypeReport), GenerateError> {
    let n = leg.time_s.len();
    for (name, v) in [
        ("hip", &leg.hip),
        ("knee", &leg.knee),
        ("ankle", &leg.ankle),
        ("heel", &leg.heel),
        ("ball", &leg.ball),
        ("toe", &leg.toe),
        ("pelvis", leg.pelvis.as_ref().unwrap_or(&leg.hip)),
        ("hip offset", leg.hip_offset.as_ref().unwrap_or(&leg.hip)),
    ] {
        if v.len() != n {
            return Err(err(
                "input",
                format!("{name} has {} samples but there are {n} times", v.len()),
            ));
        }
        if let Some(i) = v
            .iter()
            .position(|p| !(p[0].is_finite() && p[1].is_finite()))
        {
            return Err(err("input", format!("{name} is missing at sample {i}")));
        }
    }
    if n < 10 || leg.time_s.windows(2).any(|w| w[1] <= w[0]) {
        return Err(err(
            "input",
            "need at least 10 samples at strictly increasing times".into(),
        ));
    }
    let (hs0, to, hs1) = (ev.heel_strike, ev.toe_off, ev.next_heel_strike);
    if !(leg.time_s[0] <= hs0 && hs0 < to && to < hs1 && hs1 <= leg.time_s[n - 1]) {
        return Err(err(
            "events",
            format!(
                "need time₀ ≤ heel strike < toe off < next heel strike ≤ last time, got \
                 {hs0} < {to} < {hs1} within [{}, {}] s",
                leg.time_s[0],
                leg.time_s[n - 1]
            ),
        ));
    }
    let tau = 0.5 * (hs1 - hs0);
    if to <= hs0 + tau {
        return Err(err(
            "events",
            format!(
                "toe off at {to} s falls before the other foot's heel strike at {} s: that is \
                 running, not walking",
                hs0 + tau
            ),
        ));
    }
    let ts = &leg.time_s;
    let at = |v: &[[f64; 2]], t: f64| sample(ts, v, t);
    let stride: Vec<f64> = ts
        .iter()
        .copied()
        .filter(|&t| t >= hs0 && t <= hs1)
        .collect();

    let sl = 0.5 * (at(&leg.heel, hs1)[0] - at(&leg.heel, hs0)[0]);
    if sl <= 0.0 {
        return Err(err(
            "step length",
            format!(
                "the heel moved {:.4} m backwards over the stride",
                -2.0 * sl
            ),
        ));
    }
    // The hip joint: the mean of this hip and the other (this one half a stride away in time,
    // one step away in space) — the pelvis centre in the sagittal plane. Each trochanter marker
    // alone sits ±3.5 cm off it at heel strike as the thigh swings.
    let pelvis = |t: f64| {
        if let Some(p) = &leg.pelvis {
            return at(p, t);
        }
        let a = at(&leg.hip, t);
        let b = if t + tau <= hs1 {
            let q = at(&leg.hip, t + tau);
            [q[0] - sl, q[1]]
        } else {
            let q = at(&leg.hip, t - tau);
            [q[0] + sl, q[1]]
        };
        [0.5 * (a[0] + b[0]), 0.5 * (a[1] + b[1])]
    };

    // Segment lengths and the foot triangle (stride means); the thigh runs from the pelvis
    // centre, which is the model's hip.
    let mean =
        |f: &dyn Fn(f64) -> f64| stride.iter().map(|&t| f(t)).sum::<f64>() / stride.len() as f64;
    let thigh = mean(&|t| dist(pelvis(t), at(&leg.knee, t)));
    let shin = mean(&|t| dist(at(&leg.knee, t), at(&leg.ankle, t)));
    let hb = mean(&|t| dist(at(&leg.heel, t), at(&leg.ball, t)));
    let bt = mean(&|t| dist(at(&leg.ball, t), at(&leg.toe, t)));
    let local = |t: f64| {
        let (h, b, a) = (at(&leg.heel, t), at(&leg.ball, t), at(&leg.ankle, t));
        let l = dist(h, b);
        let (ux, uy) = ((b[0] - h[0]) / l, (b[1] - h[1]) / l);
        let (dx, dy) = (a[0] - h[0], a[1] - h[1]);
        (dx * ux + dy * uy, -dx * uy + dy * ux)
    };
    let hn = mean(&|t| local(t).0);
    let an = mean(&|t| local(t).1);
    if !(hn > 0.0 && hn < hb && an > 0.0) {
        return Err(err(
            "foot",
            format!(
                "the ankle does not project between heel and ball (heel to N {hn:.4} m, heel \
                 to ball {hb:.4} m, ankle to N {an:.4} m): check the marker names"
            ),
        ));
    }
    let body = Anthropometry::new(thigh, shin, hn, hb - hn, an, bt)?;

    // Flat-foot offsets (early-stance window, before the heel marker starts to creep up).
    let stance = to - hs0;
    let flat: Vec<f64> = ts
        .iter()
        .copied()
        .filter(|&t| t >= hs0 + FLAT_WINDOW.0 * stance && t <= hs0 + FLAT_WINDOW.1 * stance)
        .collect();
    if flat.len() < 2 {
        return Err(err(
            "foot flat",
            format!(
                "fewer than two samples in the flat-foot window ({:.0}–{:.0} % of stance)",
                100.0 * FLAT_WINDOW.0,
                100.0 * FLAT_WINDOW.1
            ),
        ));
    }
    let f_off = median(
        flat.iter()
            .map(|&t| angle(at(&leg.heel, t), at(&leg.ball, t)))
            .collect(),
    );
    let ball_flat = median(flat.iter().map(|&t| at(&leg.ball, t)[1]).collect());
    let foot = |t: f64| angle(at(&leg.heel, t), at(&leg.ball, t)) - f_off;
    let raw_meta = |t: f64| {
        let (b, o) = (at(&leg.ball, t), at(&leg.toe, t));
        (b[1] - o[1]).atan2(o[0] - b[0])
    };
    // Moments, in step time s = (t − hs0)/τ.
    let st = |t: f64| (t - hs0) / tau;
    let fgm_t =
        first_fall(ts, &|t| foot(t) - FLAT_FOOT_TOLERANCE_RAD, hs0, to).ok_or_else(|| {
            err(
                "FGM",
                "the foot angle never comes down to flat after heel strike".into(),
            )
        })?;
    let mom_t = last_rise(
        ts,
        &|t| at(&leg.ball, t)[1] - ball_flat - BALL_LIFT_M,
        fgm_t,
        to,
    )
    .ok_or_else(|| err("MOM", "the ball marker never lifts before toe off".into()))?;
    // The toes start rotating about their tip at MOM: meta angles are measured from there.
    let m_off = raw_meta(mom_t);
    let meta = |t: f64| raw_meta(t) - m_off;
    // The stance foot's floor position: the (x₀, y₀) that best puts the model's stance ankle
    // (rolling over its fixed pivots with the measured angles) on the measured ankle over the
    // whole stance, in the least-squares sense (closed form: the mean residual).
    let model_ankle = |t: f64| {
        let f = foot(t);
        let pivot = if t <= fgm_t {
            Pivot::Heel(0.0)
        } else if t < mom_t {
            Pivot::Ball(body.heel_to_ball())
        } else {
            Pivot::Toe(body.heel_to_ball() + body.ball_to_toe())
        };
        let f = if t <= fgm_t { f.max(0.0) } else { f.min(0.0) };
        foot_on_pivot(&body, pivot, f, meta(t).max(0.0)).ankle
    };
    // Least squares over the whole stance (closed form: the mean residual).
    let stance_grid = grid(ts, hs0, to);
    let k = stance_grid.len() as f64;
    let (mut x0, mut y0) = (0.0, 0.0);
    for &t in &stance_grid {
        let (a, m) = (at(&leg.ankle, t), model_ankle(t));
        x0 += (a[0] - m[0]) / k;
        y0 += (a[1] - m[1]) / k;
    }
    let (fgm, mom, tom) = (st(fgm_t), st(mom_t), st(to) - 1.0);
    let moments = Moments::new(fgm, mom, tom)?;

    // H: the pelvis centre over the step.
    let th: Vec<f64> = grid(ts, hs0, hs0 + tau);
    let raw_travel = pelvis(hs0 + tau)[0] - pelvis(hs0)[0];
    let hip = TimedSequence::new(
        "H",
        th.iter().map(|&t| st(t)).collect(),
        th.iter()
            .map(|&t| {
                let p = pelvis(t);
                [p[0] - x0 + st(t) * (sl - raw_travel), p[1] - y0]
            })
            .collect(),
    )?;

    // F1 on [0, FGM] (≥ 0, ends at 0), F2 on [FGM, 1 + TOM] (≤ 0), M on [MOM, 1 + TOM] (≥ 0).
    let seq = |what: &str, a: f64, b: f64, f: &dyn Fn(f64) -> f64| {
        let g = grid(ts, a, b);
        TimedSequence::new(
            what,
            g.iter().map(|&t| st(t)).collect(),
            g.iter().map(|&t| [f(t)]).collect(),
        )
    };
    let foot1 = seq("F1", hs0, fgm_t, &|t| {
        if t >= fgm_t {
            0.0
        } else {
            foot(t).max(0.0)
        }
    })?;
    let foot2 = seq("F2", fgm_t, to, &|t| {
        if t <= fgm_t {
            0.0
        } else {
            foot(t).min(0.0)
        }
    })?;
    let meta_seq = seq("M", mom_t, to, &|t| {
        if t <= mom_t {
            0.0
        } else {
            meta(t).max(0.0)
        }
    })?;

    // F3 and A: this leg's swing, [toe off, next heel strike] → [TOM, 1], one step back.
    let g3 = grid(ts, to, hs1);
    let sw = |t: f64| st(t) - 1.0;
    let foot3 = TimedSequence::new(
        "F3",
        g3.iter().map(|&t| sw(t)).collect(),
        g3.iter().map(|&t| [foot(t)]).collect(),
    )?;
    let ankle = TimedSequence::new(
        "A",
        g3.iter().map(|&t| sw(t)).collect(),
        g3.iter()
            .map(|&t| {
                let a = at(&leg.ankle, t);
                [a[0] - x0 - sl, a[1] - y0]
            })
            .collect(),
    )?;

    // Leg lengths: thigh and shin keep their marker-mean ratio, scaled so the model leg bends
    // at heel strike exactly as the measured knee (thigh from the pelvis centre) does.
    let mu2 = foot1.first()[0];
    let (hh, kk, aa) = (pelvis(hs0), at(&leg.knee, hs0), at(&leg.ankle, hs0));
    let mu1_measured = (kk[0] - hh[0]).atan2(hh[1] - kk[1]) - (aa[0] - kk[0]).atan2(kk[1] - aa[1]);
    let a0 = foot_on_pivot(&body, Pivot::Heel(0.0), mu2, 0.0).ankle;
    let leg_scale = dist(hip.first(), a0) / hip_ankle_distance(&body, mu1_measured);
    let body = Anthropometry::new(
        leg_scale * body.thigh(),
        leg_scale * body.shin(),
        body.heel_to_n(),
        body.ball_to_n(),
        body.ankle_to_n(),
        body.ball_to_toe(),
    )?;
    // μ* from the data: μ₂* = F₁(0), μ₃* = −F₂(end), μ₄* = M(end); μ₁* = the model leg's knee
    // flexion at heel strike — the measured one, by the scaling above.
    let mu3 = -foot2.last()[0];
    let mu4 = meta_seq.last()[0];
    let a0 = foot_on_pivot(&body, Pivot::Heel(0.0), mu2, 0.0).ankle;
    let mu1 = knee_flexion_for_distance(&body, dist(hip.first(), a0)).unwrap_or(0.0);
    let mu_star = [mu1, mu2, mu3, mu4];
    let raw = WalkData::new(
        body, sl, sl, moments, hip, foot1, foot2, foot3, meta_seq, ankle,
    )?;
    let mu = MuFunctions::new(alpha, mu_star, sl, body.leg_length())?;
    let w = phi(&raw, 1.0, sl, &mu)?;

    let report = PrototypeReport {
        step_length_m: sl,
        step_duration_s: tau,
        raw_hip_travel_m: raw_travel,
        foot_line_offset_rad: f_off,
        toe_line_offset_rad: m_off,
        ankle_to_shift_m: dist(raw.ankle().first(), w.ankle().first()),
        ankle_hs_shift_m: dist(raw.ankle().last(), w.ankle().last()),
        hip_pin_m: [
            w.hip().first()[1] - raw.hip().first()[1],
            w.hip().last()[1] - raw.hip().last()[1],
        ],
        moments: [fgm, mom, tom],
        mu_star,
        leg_scale,
        max_hip_drop_m: (0..=200)
            .map(|i| {
                super::pose::pose(&w, &mu, i as f64 / 200.0)
                    .map(|p| p.hip_drop)
                    .unwrap_or(f64::NAN)
            })
            .fold(0.0, f64::max),
    };
    Ok((w, mu, report))
}

/// Winter's published events for Table A.1 (and its filtered version `wn35b.txt`), 1-based
/// frames at 69.9 Hz: right heel strike 28, right toe off 70, right heel strike 97 (Winter 1990,
/// Appendix A; BMClab's copy of the table).
pub const WINTER_EVENT_FRAMES: [usize; 3] = [28, 70, 97];

/// The right leg of a trial read by [`crate::ingest::winter`], projected onto its sagittal
/// plane (forward, up), with Winter's published stride events.
pub fn winter_leg(
    trial: &crate::ingest::types::Trial,
) -> Result<(SagittalLeg, StrideEvents), GenerateError> {
    let name = trial.source.display().to_string();
    let m = trial
        .markers
        .as_ref()
        .ok_or_else(|| err("Winter's table", format!("{name}: no marker trajectories")))?;
    let frame = trial.frame.as_ref().ok_or_else(|| {
        err(
            "Winter's table",
            format!("{name}: the laboratory frame (vertical and forward axes) is unknown"),
        )
    })?;
    let (v, f, s) = (
        frame.vertical.index(),
        frame.forward.index(),
        frame.forward_sign,
    );
    let get = |label: &str| -> Result<Vec<[f64; 2]>, GenerateError> {
        let p = m.get(label).ok_or_else(|| {
            err(
                "Winter's table",
                format!("{name}: no landmark {label:?} (has {})", m.names.join(", ")),
            )
        })?;
        Ok(p.iter().map(|q| [s * q[f], q[v]]).collect())
    };
    let leg = SagittalLeg {
        time_s: m.time_s.clone(),
        hip: get("RIGHT HIP")?,
        knee: get("RIGHT KNEE")?,
        ankle: get("RIGHT ANKLE")?,
        heel: get("RIGHT HEEL")?,
        ball: get("RIGHT MT5")?,
        toe: get("RIGHT TOE")?,
        pelvis: None,
        hip_offset: None,
    };
    let t = |frame: usize| -> Result<f64, GenerateError> {
        m.time_s.get(frame - 1).copied().ok_or_else(|| {
            err(
                "Winter's events",
                format!(
                    "{name}: has {} frames, the published events need frame {frame}",
                    m.len()
                ),
            )
        })
    };
    let [a, b, c] = WINTER_EVENT_FRAMES;
    Ok((
        leg,
        StrideEvents {
            heel_strike: t(a)?,
            toe_off: t(b)?,
            next_heel_strike: t(c)?,
        },
    ))
}

/// A prototype walk with what the generator needs besides W: the μ values it was measured with,
/// its step duration, and where it came from.
#[derive(Debug, Clone, PartialEq)]
pub struct Prototype {
    /// W(S*, sl*), consistent (φ₁ is the identity on it).
    pub walk: WalkData,
    /// μ₁*…μ₄* (rad).
    pub mu_star: [f64; 4],
    /// The measured step's duration (s).
    pub step_duration_s: f64,
    /// Where the markers came from.
    pub source: String,
    /// Whom to cite.
    pub citation: String,
    /// The measured sagittal angles of the stride W was built from (hip, knee, ankle over the
    /// stance and swing steps, [`super::angles::measured_angles`]; the ankle path is not kept):
    /// the curves the carried variant keeps ([`Prototype::carried`]). `None` for a prototype
    /// file written without them.
    pub angles: Option<Angles>,
}

impl Prototype {
    /// The μ-functions of this prototype with slopes `alpha` (rad/m).
    pub fn mu(&self, alpha: [f64; 4]) -> Result<MuFunctions, GenerateError> {
        MuFunctions::new(
            alpha,
            self.mu_star,
            self.walk.step_length(),
            self.walk.body().leg_length(),
        )
    }

    /// The curves the carried variant keeps ([`Carried::from_measured`]); `None` without
    /// measured angles.
    pub fn carried(&self) -> Result<Option<Carried>, GenerateError> {
        self.angles
            .as_ref()
            .map(|a| Carried::from_measured(a, &self.walk))
            .transpose()
    }

    /// The prototype bundled with gaitfit: Winter's walk (`data/prototype_winter.json`).
    pub fn bundled() -> Prototype {
        // The file is committed and checked by tests/kb_prototype.rs; parsing it cannot fail
        // unless the repository itself is broken.
        match Prototype::from_json(BUNDLED_JSON, "data/prototype_winter.json") {
            Ok(p) => p,
            Err(e) => panic!("the bundled prototype data/prototype_winter.json is broken: {e}"),
        }
    }

    /// Parses a prototype file's text (`what` names it in errors).
    pub fn from_json(text: &str, what: &str) -> Result<Prototype, String> {
        let f: PrototypeFile = serde_json::from_str(text)
            .map_err(|e| format!("{what}: not a gaitfit prototype: {e}"))?;
        if f.format != PROTOTYPE_FORMAT {
            return Err(format!(
                "{what}: format {:?}, expected {PROTOTYPE_FORMAT:?}",
                f.format
            ));
        }
        let wrap = |e: GenerateError| format!("{what}: {e}");
        let b = &f.body;
        let body = Anthropometry::new(
            b.thigh_m,
            b.shin_m,
            b.heel_to_n_m,
            b.ball_to_n_m,
            b.ankle_to_n_m,
            b.ball_to_toe_m,
        )
        .and_then(|a| a.with_ball_height(b.ball_height_m))
        .map_err(wrap)?;
        let moments = Moments::new(f.moments.fgm_step, f.moments.mom_step, f.moments.tom_step)
            .map_err(wrap)?;
        let path = |name: &str, p: &PathFile| {
            if p.x_m.len() != p.t_step.len() || p.y_m.len() != p.t_step.len() {
                return Err(format!(
                    "{what}: {name}: t_step, x_m and y_m differ in length"
                ));
            }
            TimedSequence::new(
                name,
                p.t_step.clone(),
                p.x_m.iter().zip(&p.y_m).map(|(&x, &y)| [x, y]).collect(),
            )
            .map_err(wrap)
        };
        let angle = |name: &str, a: &AngleFile| {
            if a.angle_rad.len() != a.t_step.len() {
                return Err(format!(
                    "{what}: {name}: t_step and angle_rad differ in length"
                ));
            }
            TimedSequence::new(
                name,
                a.t_step.clone(),
                a.angle_rad.iter().map(|&v| [v]).collect(),
            )
            .map_err(wrap)
        };
        let walk = WalkData::new(
            body,
            f.step_length_m,
            f.step_length_before_m,
            moments,
            path("hip", &f.hip)?,
            angle("foot1", &f.foot1)?,
            angle("foot2", &f.foot2)?,
            angle("foot3", &f.foot3)?,
            angle("meta", &f.meta)?,
            path("ankle", &f.ankle)?,
        )
        .map_err(wrap)?;
        if !(f.step_duration_s.is_finite() && f.step_duration_s > 0.0) {
            return Err(format!("{what}: step_duration_s must be positive"));
        }
        let angles = match f.measured_angles {
            Some(m) => {
                let n = 2 * SAMPLES;
                if m.samples_per_step != SAMPLES
                    || m.hip_rad.len() != n
                    || m.knee_rad.len() != n
                    || m.ankle_rad.len() != n
                    || !(m.hip_offset_m.is_empty() || m.hip_offset_m.len() == n)
                {
                    return Err(format!(
                        "{what}: measured_angles: samples_per_step must be {SAMPLES} and hip_rad, \
                         knee_rad, ankle_rad (and hip_offset_m if given) hold {n} values each \
                         (stance step, then swing step)"
                    ));
                }
                if m.hip_rad
                    .iter()
                    .chain(&m.knee_rad)
                    .chain(&m.ankle_rad)
                    .chain(m.hip_offset_m.iter().flatten())
                    .any(|v| !v.is_finite())
                {
                    return Err(format!("{what}: measured_angles: a value is not finite"));
                }
                Some(Angles {
                    hip: m.hip_rad,
                    knee: m.knee_rad,
                    ankle: m.ankle_rad,
                    ankle_path: Vec::new(),
                    hip_offset: m.hip_offset_m,
                })
            }
            None => None,
        };
        let p = Prototype {
            walk,
            mu_star: f.mu_star_rad,
            step_duration_s: f.step_duration_s,
            source: f.source,
            citation: f.citation,
            angles,
        };
        p.mu([0.0; 4]).map_err(wrap)?;
        Ok(p)
    }

    /// The prototype file's text (JSON, every number at full precision), with the command that
    /// regenerates it and the build report.
    pub fn to_json(&self, regenerate: &str, report: Option<&PrototypeReport>) -> String {
        let w = &self.walk;
        let b = w.body();
        let path = |s: &super::walk_data::PathSequence| PathFile {
            t_step: s.times().to_vec(),
            x_m: s.values().iter().map(|v| v[0]).collect(),
            y_m: s.values().iter().map(|v| v[1]).collect(),
        };
        let angle = |s: &super::walk_data::AngleSequence| AngleFile {
            t_step: s.times().to_vec(),
            angle_rad: s.values().iter().map(|v| v[0]).collect(),
        };
        let f = PrototypeFile {
            format: PROTOTYPE_FORMAT.into(),
            source: self.source.clone(),
            citation: self.citation.clone(),
            regenerate: regenerate.into(),
            body: BodyFile {
                thigh_m: b.thigh(),
                shin_m: b.shin(),
                heel_to_n_m: b.heel_to_n(),
                ball_to_n_m: b.ball_to_n(),
                ankle_to_n_m: b.ankle_to_n(),
                ball_to_toe_m: b.ball_to_toe(),
                ball_height_m: b.ball_height(),
            },
            step_length_m: w.step_length(),
            step_length_before_m: w.step_length_before(),
            step_duration_s: self.step_duration_s,
            moments: MomentsFile {
                fgm_step: w.moments().fgm(),
                mom_step: w.moments().mom(),
                tom_step: w.moments().tom(),
            },
            mu_star_rad: self.mu_star,
            build: report.map(|r| BuildFile {
                raw_hip_travel_m: r.raw_hip_travel_m,
                foot_line_offset_rad: r.foot_line_offset_rad,
                toe_line_offset_rad: r.toe_line_offset_rad,
                ankle_to_shift_m: r.ankle_to_shift_m,
                ankle_hs_shift_m: r.ankle_hs_shift_m,
                hip_pin_m: r.hip_pin_m,
            }),
            hip: path(w.hip()),
            foot1: angle(w.foot1()),
            foot2: angle(w.foot2()),
            foot3: angle(w.foot3()),
            meta: angle(w.meta()),
            ankle: path(w.ankle()),
            measured_angles: self.angles.as_ref().map(|a| MeasuredAnglesFile {
                samples_per_step: SAMPLES,
                hip_rad: a.hip.clone(),
                knee_rad: a.knee.clone(),
                ankle_rad: a.ankle.clone(),
                hip_offset_m: a.hip_offset.clone(),
            }),
        };
        // Serializing plain numbers and strings cannot fail.
        serde_json::to_string_pretty(&f).unwrap_or_default() + "\n"
    }
}

/// The bundled prototype file's text.
pub const BUNDLED_JSON: &str = include_str!("../../../data/prototype_winter.json");

/// Format tag of prototype files.
pub const PROTOTYPE_FORMAT: &str = "gaitfit-ko-badler-prototype-1";

/// Citation of the bundled prototype's data.
pub const WINTER_CITATION: &str = "Winter, D. A. (1990). Biomechanics and Motor Control of Human \
Movement, 2nd ed., Wiley: Appendix A, Table A.1 (raw) and its filtered version, as \
redistributed by BMClab (Federal University of ABC, repository BMClab/BMC, CC BY 4.0): \
bmclab/wn35b.txt";

#[derive(Debug, serde::Serialize, serde::Deserialize)]
#[serde(deny_unknown_fields)]
struct PrototypeFile {
    format: String,
    source: String,
    citation: String,
    regenerate: String,
    body: BodyFile,
    step_length_m: f64,
    step_length_before_m: f64,
    step_duration_s: f64,
    moments: MomentsFile,
    mu_star_rad: [f64; 4],
    #[serde(default, skip_serializing_if = "Option::is_none")]
    build: Option<BuildFile>,
    hip: PathFile,
    foot1: AngleFile,
    foot2: AngleFile,
    foot3: AngleFile,
    meta: AngleFile,
    ankle: PathFile,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    measured_angles: Option<MeasuredAnglesFile>,
}

/// The measured stride angles (rad) on normalized step time: `samples_per_step` points over the
/// stance step, then as many over the swing step.
#[derive(Debug, serde::Serialize, serde::Deserialize)]
#[serde(deny_unknown_fields)]
struct MeasuredAnglesFile {
    samples_per_step: usize,
    hip_rad: Vec<f64>,
    knee_rad: Vec<f64>,
    ankle_rad: Vec<f64>,
    /// The leg's hip joint centre relative to the pelvis centre (forward, up; m) at the same
    /// samples, when the pelvis was measured.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    hip_offset_m: Vec<[f64; 2]>,
}

#[derive(Debug, serde::Serialize, serde::Deserialize)]
#[serde(deny_unknown_fields)]
struct BodyFile {
    thigh_m: f64,
    shin_m: f64,
    heel_to_n_m: f64,
    ball_to_n_m: f64,
    ankle_to_n_m: f64,
    ball_to_toe_m: f64,
    #[serde(default)]
    ball_height_m: f64,
}

#[derive(Debug, serde::Serialize, serde::Deserialize)]
#[serde(deny_unknown_fields)]
struct MomentsFile {
    fgm_step: f64,
    mom_step: f64,
    tom_step: f64,
}

#[derive(Debug, serde::Serialize, serde::Deserialize)]
#[serde(deny_unknown_fields)]
struct BuildFile {
    raw_hip_travel_m: f64,
    foot_line_offset_rad: f64,
    toe_line_offset_rad: f64,
    ankle_to_shift_m: f64,
    ankle_hs_shift_m: f64,
    hip_pin_m: [f64; 2],
}

#[derive(Debug, serde::Serialize, serde::Deserialize)]
#[serde(deny_unknown_fields)]
struct PathFile {
    t_step: Vec<f64>,
    x_m: Vec<f64>,
    y_m: Vec<f64>,
}

#[derive(Debug, serde::Serialize, serde::Deserialize)]
#[serde(deny_unknown_fields)]
struct AngleFile {
    t_step: Vec<f64>,
    angle_rad: Vec<f64>,
}

/// Builds the prototype from one of Winter's tables (`WinterTableA1.txt` or `wn35b.txt`).
pub fn winter_prototype(
    path: &std::path::Path,
) -> Result<(Prototype, PrototypeReport), crate::Error> {
    let trial = crate::ingest::winter::read(path, &crate::ingest::ReadOptions::default())?;
    let (leg, ev) = winter_leg(&trial)?;
    let (walk, mu, report) = build_prototype(&leg, &ev, [0.0; 4])?;
    let angles = measured_angles(&leg, &ev, walk.step_length())?;
    let file = path
        .file_name()
        .map(|f| f.to_string_lossy().into_owned())
        .unwrap_or_default();
    Ok((
        Prototype {
            walk,
            mu_star: mu.mu_star(),
            step_duration_s: report.step_duration_s,
            source: format!("bmclab/{file} (right leg, frames 28–97; events 28, 70, 97)"),
            citation: WINTER_CITATION.into(),
            angles: Some(angles),
        },
        report,
    ))
}

/// The pelvis-centre estimate the builder uses for H, at time `t` (see [`build_prototype`]):
/// the mean of this hip and the mirrored other hip (this one half a stride away, one step
/// `sl` away).
pub(crate) fn pelvis_at(leg: &SagittalLeg, ev: &StrideEvents, sl: f64, t: f64) -> [f64; 2] {
    if let Some(p) = &leg.pelvis {
        return sample(&leg.time_s, p, t);
    }
    let tau = 0.5 * (ev.next_heel_strike - ev.heel_strike);
    let a = sample(&leg.time_s, &leg.hip, t);
    let b = if t + tau <= ev.next_heel_strike {
        let q = sample(&leg.time_s, &leg.hip, t + tau);
        [q[0] - sl, q[1]]
    } else {
        let q = sample(&leg.time_s, &leg.hip, t - tau);
        [q[0] + sl, q[1]]
    };
    [0.5 * (a[0] + b[0]), 0.5 * (a[1] + b[1])]
}

/// The heel→ball marker line's angle in the flat-foot window (what foot angles are measured
/// from), rad.
pub(crate) fn flat_foot_line(leg: &SagittalLeg, ev: &StrideEvents) -> f64 {
    let stance = ev.toe_off - ev.heel_strike;
    let v: Vec<f64> = leg
        .time_s
        .iter()
        .copied()
        .filter(|&t| {
            t >= ev.heel_strike + FLAT_WINDOW.0 * stance
                && t <= ev.heel_strike + FLAT_WINDOW.1 * stance
        })
        .map(|t| {
            angle(
                sample(&leg.time_s, &leg.heel, t),
                sample(&leg.time_s, &leg.ball, t),
            )
        })
        .collect();
    if v.is_empty() {
        0.0
    } else {
        median(v)
    }
}

/// Linear interpolation of a landmark at time `t` (clamped).
pub(crate) fn landmark_at(leg: &SagittalLeg, v: &[[f64; 2]], t: f64) -> [f64; 2] {
    sample(&leg.time_s, v, t)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A measured pelvis (hip joint offsets) survives the prototype file, and a wrong count is
    /// refused by name.
    #[test]
    fn the_hip_offset_round_trips_through_the_prototype_file() {
        let mut p = Prototype::bundled();
        let a = p.angles.as_mut().unwrap();
        assert!(a.hip_offset.is_empty());
        a.hip_offset = (0..2 * SAMPLES)
            .map(|i| [0.001 * i as f64, -0.0005 * i as f64])
            .collect();
        let text = p.to_json("test", None);
        let q = Prototype::from_json(&text, "t.json").unwrap();
        assert_eq!(q.angles, p.angles);
        assert!(q.carried().unwrap().unwrap().has_hip_offset());
        let short = text.replacen("\"hip_offset_m\": [", "\"hip_offset_m\": [\n[0.0, 0.0],", 1);
        let e = Prototype::from_json(&short, "t.json").unwrap_err();
        assert!(e.contains("hip_offset_m"), "{e}");
    }
}
