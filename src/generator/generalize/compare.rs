//! Measured against reality: does a generalized step look like the real walk of that person at
//! that step length? (Schreiber & Moissenet 2019: six subjects, self-selected `C4` and fast `C5`
//! overground walks, C3D markers and reference foot-strike/foot-off events.)
//!
//! For every measured stride (subject B, condition c, leg) the *target* is B's measured
//! sagittal angles over one stride of that leg — hip (thigh from the vertical, from the pelvis
//! centre), knee flexion, ankle dorsiflexion (sole angle from its flat value minus the shank's
//! forward lean) — on normalized step time (stance step, then swing step), and its swing ankle
//! path relative to the landing ankle on normalized swing time. Candidates:
//! - **generalized**: subject A's measured step W_A (built like the Winter prototype), ψ onto
//!   B's body and φ onto B's step length (after a step of the same length), rendered;
//! - **generalized, carried** ([`Variant::Carried`], [`super::carried`]): the same step, with
//!   A's own character carried in W — A's measured angle curves are kept with W, and the step is
//!   drawn with the paper's feet and the hip placed where the drawn angles come nearest A's
//!   measured curves (on the same normalized step time: φ and ψ keep the moments). These are
//!   the angles
//!   `gaitfit generate generalize --kb-variant carried` draws; the ankle path is the paper's;
//!   here the trailing foot's heel rise at HSM⁺ follows μ₅ ([`super::HeelRise`]) with α₅ fitted
//!   on the fold's other subjects ([`fit_heel_rise_slope`]), which the CLI does not (yet) do;
//! - **naive**: A's measured stride unchanged in angles and time-normalized, its ankle path
//!   scaled by ll(B)/ll(A) (A's step scaled uniformly in size and time);
//! - **naive rendered**: A's step W rendered through the same model, unchanged (uniform scaling
//!   keeps angles): the like-for-like baseline, carrying the same rendering error as
//!   *generalized*;
//! - **best case**: B's own step at the other condition, generalized to this step length, and
//!   beside it B's own other-condition stride unchanged (what φ has to improve on);
//! - **model floor**: B's own step at this condition rendered through the model (what the
//!   point-pivot foot, rigid legs and single hip point cost even without generalizing).
//!
//! Each is scored by RMS differences over 101 samples per step; no offsets are removed (the
//! generalization claims absolute angles). Sources and targets are the same leg; all
//! candidates use the target's normalized step time (heel strike → half stride → heel strike).
//!
//! Findings (see the tests' output): the swing ankle path is clearly better than naive scaling,
//! but the joint angles are not — the model floor (≈ 7 / 13 / 6° hip / knee / ankle, mostly a
//! stance crouch: the rigid model thigh cannot follow the apparent thigh from the trochanter
//! pelvis estimate, which shortens by ≈ 2 cm from heel strike to mid-stance) exceeds the
//! differences between subjects (≈ 5 / 8 / 6°), and within a subject the angles change little
//! with step length (≈ 3.5 / 4.5 / 4° between the two speeds), less than φ changes them.
//!
//! The carried variant (issue 21 item 5, `tests/kb_carried.rs`, lateral markers, 2026-12-07):
//! without the heel-rise relation μ₅: hip / knee / ankle RMS 4.7 / 7.6 / 6.5° against the
//! paper's 9.0 / 16.1 / 8.1° and naive scaling's 5.3 / 7.7 / 5.7°; ankle path 6.4 cm (the
//! paper's) against naive's 9.0 cm: hip better than naive, knee equal, ankle 0.85° worse (with
//! μ₅, below: 4.74 / 7.58 / 5.60°). With one hip point for both legs it was
//! 4.8 / 7.7 / 6.7°; each leg now hangs from its own hip joint, the pelvis' rotation and list
//! carried from the Harrington joint centres ([`super::carried`]) — but they sit only ≈ 5 mm
//! ahead of / behind the pelvis centre at heel strike (≈ 1.5 % of the step). The ankle's excess
//! is the drawn shank in loading response and late swing: at heel strike, per unit of step
//! length / leg length, the subjects' leading leg reaches 0.40 and the trailing leg 0.49 (leg
//! lengths; the pelvis further forward in longer steps), the drawing 0.58 and 0.39 — its pelvis
//! centre stays back and the leading shank inclines ≈ 39° per unit against the subjects' ≈ 16°.
//! What holds the trailing leg back is its foot: at heel strike the subjects' trailing heel
//! rise grows ≈ 91° per unit of step length / leg length (across subjects), the drawing's
//! ≈ 19° — eq. 33 scales the whole F₂ by μ₃(sl)/μ₃*, so the heel rise at the other foot's heel
//! strike moves only in proportion to the toe-off angle's relative change. The comparison's
//! carried candidates therefore draw with the heel-rise relation μ₅ ([`super::HeelRise`]: the
//! heel rise at HSM⁺ linear in sl/leg, μ₅* the source's own), its slope α₅ fitted in each
//! leave-one-out fold by [`fit_heel_rise_slope`] on the other subjects' strides only (1.60 to
//! 1.70 rad ≈ 92–98° per unit of sl/leg over the six folds): hip / knee / ankle 4.74 / 7.58 /
//! 5.60° against naive's 5.28 / 7.67 / 5.66°, ankle path 6.35 vs 9.03 cm — the ankle from 6.51
//! to 5.60°, the angles now no worse than naive scaling (the ankle by 0.06°, within the spread
//! of one subject; the hip 0.05° worse than without μ₅). Calibrate's Ko–Badler stage has no
//! training subjects and draws without μ₅. Earlier carried designs, all worse: the
//! generalized step's rendering plus the prototype's measured-minus-rendered residual as the
//! preferred posture (6.2 / 10.2 / 6.8°) or simply added to the rendered angles (not drawable —
//! the feet would move; 6.1 / 10.6 / 6.5°) — both carry what φ changes in the rendered angles:
//! within one subject between its two speeds φ changes the stance knee by 7.6° RMS while the
//! subject's knee changes by 4.5° (eq. 27's linear pinning of the hip heights lowers the
//! mid-stance hip for longer steps); the stance knee's rendered curve as the IK's preferred posture (the hip height that
//! gives it, pinned at the ends as eq. 27; 6.5 / 10.6 / 6.3°), and the swing ankle path kept
//! relative to the hip (6.1 / 10.8 / 6.5°).
use super::angles::{model_angles, Angles};
use super::carried::{carried_angles, Carried};
use super::prototype::{build_prototype, Prototype, SagittalLeg, StrideEvents};
use super::{phi, psi, Generalizer};
use crate::events::filter::Butterworth;
use crate::events::{EventKind, Side};
use crate::generator::GenerateError;
use crate::ingest::types::Trial;

/// Which Ko–Badler generalization a candidate uses.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Variant {
    /// The paper's: the angles are those of W's rigid two-link drawing (eqs. 11–12, 25–48).
    #[default]
    Paper,
    /// The paper's feet, the pelvis placed so the drawn angles come nearest the prototype's
    /// measured curves, each leg from its own hip joint when the prototype's pelvis was measured
    /// ([`super::carried`]).
    Carried,
}

impl Variant {
    /// The variant's name as `--kb-variant` spells it.
    pub fn name(self) -> &'static str {
        match self {
            Variant::Paper => "paper",
            Variant::Carried => "carried",
        }
    }
}

impl std::str::FromStr for Variant {
    type Err = String;
    fn from_str(s: &str) -> Result<Self, String> {
        match s {
            "paper" => Ok(Variant::Paper),
            "carried" => Ok(Variant::Carried),
            other => Err(format!(
                "Ko–Badler variant {other:?}: expected paper or carried"
            )),
        }
    }
}

/// Low-pass cutoff for the markers (Hz), zero-lag 2nd-order Butterworth (Winter's 6 Hz).
pub const CUTOFF_HZ: f64 = 6.0;

/// One measured stride of one leg, with its step W and the measured angles.
#[derive(Debug, Clone)]
pub struct MeasuredStride {
    /// Subject id.
    pub subject: String,
    /// Condition (file stem part, e.g. `C4`).
    pub condition: String,
    /// Which leg.
    pub side: Side,
    /// The step built from this stride (consistent W, its μ*, duration).
    pub prototype: Prototype,
    /// Measured angles over the stride on normalized step time.
    pub angles: Angles,
}

/// RMS differences of one candidate against the target (degrees and centimetres).
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct Scores {
    /// Hip (thigh) angle RMS, deg.
    pub hip_deg: f64,
    /// Knee flexion RMS, deg.
    pub knee_deg: f64,
    /// Ankle dorsiflexion RMS, deg.
    pub ankle_deg: f64,
    /// Swing ankle path RMS, cm.
    pub ankle_path_cm: f64,
}

impl Scores {
    /// Compares candidate angles with the target's.
    pub fn of(candidate: &Angles, target: &Angles) -> Scores {
        let rms = |a: &[f64], b: &[f64]| {
            (a.iter().zip(b).map(|(x, y)| (x - y) * (x - y)).sum::<f64>() / a.len() as f64).sqrt()
        };
        let path = {
            let s: f64 = candidate
                .ankle_path
                .iter()
                .zip(&target.ankle_path)
                .map(|(p, q)| (p[0] - q[0]).powi(2) + (p[1] - q[1]).powi(2))
                .sum();
            (s / candidate.ankle_path.len() as f64).sqrt()
        };
        Scores {
            hip_deg: rms(&candidate.hip, &target.hip).to_degrees(),
            knee_deg: rms(&candidate.knee, &target.knee).to_degrees(),
            ankle_deg: rms(&candidate.ankle, &target.ankle).to_degrees(),
            ankle_path_cm: 100.0 * path,
        }
    }
    fn add(&mut self, o: &Scores) {
        self.hip_deg += o.hip_deg;
        self.knee_deg += o.knee_deg;
        self.ankle_deg += o.ankle_deg;
        self.ankle_path_cm += o.ankle_path_cm;
    }
    fn scale(&mut self, k: f64) {
        self.hip_deg *= k;
        self.knee_deg *= k;
        self.ankle_deg *= k;
        self.ankle_path_cm *= k;
    }
    /// Mean of the three angle RMS values, deg.
    pub fn angles_mean_deg(&self) -> f64 {
        (self.hip_deg + self.knee_deg + self.ankle_deg) / 3.0
    }
}

/// Which hip, knee and ankle points the Schreiber legs use.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Landmarks {
    /// Joint centres: hip from the pelvis markers (Harrington et al. 2007 regression, see
    /// [`hip_joint_centre`]), knee and ankle as the epicondyle and malleolus midpoints.
    JointCentres,
    /// Lateral skin markers as Winter's table has them: greater trochanter (FTC), lateral
    /// epicondyle (FLE), lateral malleolus (FAL).
    LateralMarkers,
}

/// The hip joint centre of `side` (lab frame, m) from the four pelvis markers at one frame,
/// by Harrington et al. (2007, J Biomech 40:595, their eq. for the full regression) in the
/// pelvis frame (origin mid-ASIS, x anterior, y superior, z right), with PW the inter-ASIS
/// width and PD the mid-ASIS to mid-PSIS depth: x = −0.24·PD − 9.9 mm, y = −0.30·PW − 10.9 mm,
/// z = ±(0.33·PW + 7.3 mm). `None` if a marker is missing or degenerate.
pub fn hip_joint_centre(
    l_asis: [f64; 3],
    r_asis: [f64; 3],
    l_psis: [f64; 3],
    r_psis: [f64; 3],
    side: Side,
) -> Option<[f64; 3]> {
    let sub = |a: [f64; 3], b: [f64; 3]| [a[0] - b[0], a[1] - b[1], a[2] - b[2]];
    let mid = |a: [f64; 3], b: [f64; 3]| {
        [
            0.5 * (a[0] + b[0]),
            0.5 * (a[1] + b[1]),
            0.5 * (a[2] + b[2]),
        ]
    };
    let dot = |a: [f64; 3], b: [f64; 3]| a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
    let cross = |a: [f64; 3], b: [f64; 3]| {
        [
            a[1] * b[2] - a[2] * b[1],
            a[2] * b[0] - a[0] * b[2],
            a[0] * b[1] - a[1] * b[0],
        ]
    };
    let norm = |a: [f64; 3]| dot(a, a).sqrt();
    let o = mid(l_asis, r_asis);
    let zr = sub(r_asis, l_asis);
    let pw = norm(zr);
    let back = sub(o, mid(l_psis, r_psis));
    let pd = norm(back);
    if !(pw > 0.0 && pd > 0.0) {
        return None;
    }
    let z = [zr[0] / pw, zr[1] / pw, zr[2] / pw];
    let xa = {
        let k = dot(back, z);
        sub(back, [k * z[0], k * z[1], k * z[2]])
    };
    let nx = norm(xa);
    if nx.is_nan() || nx <= 0.0 {
        return None;
    }
    let x = [xa[0] / nx, xa[1] / nx, xa[2] / nx];
    let y = cross(z, x);
    let sign = if side == Side::Right { 1.0 } else { -1.0 };
    let (hx, hy, hz) = (
        -0.24 * pd - 0.0099,
        -0.30 * pw - 0.0109,
        sign * (0.33 * pw + 0.0073),
    );
    let p = [
        o[0] + hx * x[0] + hy * y[0] + hz * z[0],
        o[1] + hx * x[1] + hy * y[1] + hz * z[1],
        o[2] + hx * x[2] + hy * y[2] + hz * z[2],
    ];
    p.iter().all(|v| v.is_finite()).then_some(p)
}

/// The sagittal leg of `side` from a Schreiber C3D trial (markers low-passed at
/// [`CUTOFF_HZ`]) and its first complete stride from the reference events. Hip, knee and ankle
/// per `landmarks`; the foot: FCC (calcaneus), FM5 (fifth metatarsal head) and FM2 (second
/// metatarsal head) as the toe — the data set has no toe-tip marker, so the "toes" are the
/// forefoot line FM5→FM2.
///
/// The model's legs are rigid, so its hip, knee and ankle must be points fixed on the thigh and
/// shank. The pelvis centre taken from the trochanter markers is not: its distance to the knee
/// marker shrinks by ≈ 2 cm from heel strike to mid-stance, which the rigid model (calibrated at
/// heel strike) renders as ≈ 14° of extra stance knee flexion. Joint centres keep the segment
/// lengths nearly constant, but with this data set's forefoot markers (no toe tip) they leave
/// the trailing foot out of reach in early stance and the model lowers the hip (up to 10 cm):
/// the model floor is worse (8.7 / 15.9 / 7.5° against 6.9 / 12.9 / 6.2° hip / knee / ankle).
/// [`Landmarks::LateralMarkers`] — as Winter's table, from which the bundled prototype is
/// built — is therefore the default; both variants are reported. Both the step W and the
/// measured target angles always use the same points.
pub fn schreiber_leg_with(
    trial: &Trial,
    side: Side,
    landmarks: Landmarks,
) -> Result<(SagittalLeg, StrideEvents), GenerateError> {
    let name = trial.source.display().to_string();
    let bad = |m: String| GenerateError::Numerical {
        stage: format!("{name}: {side} leg"),
        message: m,
    };
    let m = trial
        .markers
        .as_ref()
        .ok_or_else(|| bad("no markers".into()))?;
    let frame = trial
        .frame
        .as_ref()
        .ok_or_else(|| bad("laboratory frame unknown".into()))?;
    let (v, f, s) = (
        frame.vertical.index(),
        frame.forward.index(),
        frame.forward_sign,
    );
    let filt = Butterworth::low_pass(2, CUTOFF_HZ, m.rate_hz).map_err(|e| bad(e.to_string()))?;
    let p = if side == Side::Left { "L_" } else { "R_" };
    let raw = |label: &str| -> Result<&[[f64; 3]], GenerateError> {
        m.get(label)
            .ok_or_else(|| bad(format!("no marker {label}")))
    };
    let project = |name: &str, q: &[[f64; 3]]| -> Result<Vec<[f64; 2]>, GenerateError> {
        let xs: Vec<f64> = q.iter().map(|r| s * r[f]).collect();
        let ys: Vec<f64> = q.iter().map(|r| r[v]).collect();
        let xf = filt
            .filtfilt(&xs)
            .ok_or_else(|| bad(format!("{name}: too short or gaps to filter")))?;
        let yf = filt
            .filtfilt(&ys)
            .ok_or_else(|| bad(format!("{name}: too short or gaps to filter")))?;
        Ok(xf.into_iter().zip(yf).map(|(x, y)| [x, y]).collect())
    };
    let get = |label: &str| -> Result<Vec<[f64; 2]>, GenerateError> {
        let full = format!("{p}{label}");
        project(&full, raw(&full)?)
    };
    let midpoint = |a: &str, b: &str| -> Result<Vec<[f64; 2]>, GenerateError> {
        let (qa, qb) = (raw(&format!("{p}{a}"))?, raw(&format!("{p}{b}"))?);
        let q: Vec<[f64; 3]> = qa
            .iter()
            .zip(qb)
            .map(|(x, y)| {
                [
                    0.5 * (x[0] + y[0]),
                    0.5 * (x[1] + y[1]),
                    0.5 * (x[2] + y[2]),
                ]
            })
            .collect();
        project(&format!("{p}{a}/{p}{b} midpoint"), &q)
    };
    // Both hip joint centres (Harrington et al. 2007) and their midpoint, when the four pelvis
    // markers are there.
    let hips = match (raw("L_IAS"), raw("R_IAS"), raw("L_IPS"), raw("R_IPS")) {
        (Ok(la), Ok(ra), Ok(lp), Ok(rp)) => {
            let hjc = |sd: Side| -> Vec<[f64; 3]> {
                (0..la.len())
                    .map(|i| {
                        hip_joint_centre(la[i], ra[i], lp[i], rp[i], sd).unwrap_or([f64::NAN; 3])
                    })
                    .collect()
            };
            let (this, other) = (hjc(side), hjc(side.opposite()));
            let centre: Vec<[f64; 3]> = this
                .iter()
                .zip(&other)
                .map(|(a, b)| {
                    [
                        0.5 * (a[0] + b[0]),
                        0.5 * (a[1] + b[1]),
                        0.5 * (a[2] + b[2]),
                    ]
                })
                .collect();
            Some((this, centre))
        }
        _ => None,
    };
    // The pelvis' rotation and list seen from the side: this hip joint centre relative to the
    // midpoint of both, measured at the same instant (rigid pelvis markers, whichever landmarks
    // the legs use). A pelvis that cannot be filtered (gaps) leaves it unmeasured.
    let hip_offset = hips.as_ref().and_then(|(this, centre)| {
        let a = project(&format!("{p}hip joint centre"), this).ok()?;
        let c = project("pelvis centre (hip joint centres)", centre).ok()?;
        Some(
            a.iter()
                .zip(&c)
                .map(|(a, c)| [a[0] - c[0], a[1] - c[1]])
                .collect::<Vec<_>>(),
        )
    });
    let (hip, knee, ankle, pelvis) = match landmarks {
        Landmarks::LateralMarkers => (get("FTC")?, get("FLE")?, get("FAL")?, None),
        Landmarks::JointCentres => {
            let (this, centre) = hips
                .as_ref()
                .ok_or_else(|| bad("no pelvis markers L_IAS, R_IAS, L_IPS, R_IPS".into()))?;
            // The model's single hip H: the midpoint of both hip joint centres, measured at the
            // same instant (no symmetry assumption needed).
            (
                project(&format!("{p}hip joint centre"), this)?,
                midpoint("FLE", "FME")?,
                midpoint("FAL", "TAM")?,
                Some(project("pelvis centre (hip joint centres)", centre)?),
            )
        }
    };
    let leg = SagittalLeg {
        time_s: m.time_s.clone(),
        hip,
        knee,
        ankle,
        heel: get("FCC")?,
        ball: get("FM5")?,
        toe: get("FM2")?,
        pelvis,
        hip_offset,
    };
    let ev: Vec<_> = trial
        .reference_events
        .iter()
        .filter(|e| e.side == side)
        .collect();
    for (i, e) in ev.iter().enumerate() {
        if e.kind != EventKind::HeelStrike {
            continue;
        }
        let to = ev[i + 1..].iter().find(|x| x.kind == EventKind::ToeOff);
        let hs = ev[i + 1..].iter().find(|x| x.kind == EventKind::HeelStrike);
        if let (Some(to), Some(hs)) = (to, hs) {
            if to.time_s < hs.time_s {
                return Ok((
                    leg,
                    StrideEvents {
                        heel_strike: e.time_s,
                        toe_off: to.time_s,
                        next_heel_strike: hs.time_s,
                    },
                ));
            }
        }
    }
    Err(bad(
        "no complete stride (heel strike, toe off, heel strike) in the reference events".into(),
    ))
}

/// [`schreiber_leg_with`] with [`Landmarks::LateralMarkers`].
pub fn schreiber_leg(
    trial: &Trial,
    side: Side,
) -> Result<(SagittalLeg, StrideEvents), GenerateError> {
    schreiber_leg_with(trial, side, Landmarks::LateralMarkers)
}

/// Builds the measured stride: its step W (slopes `alpha`) and its measured angles.
pub fn measured_stride(
    leg: &SagittalLeg,
    ev: &StrideEvents,
    alpha: [f64; 4],
    subject: &str,
    condition: &str,
    side: Side,
) -> Result<MeasuredStride, GenerateError> {
    let (walk, mu, report) = build_prototype(leg, ev, alpha)?;
    let angles = super::angles::measured_angles(leg, ev, walk.step_length())?;
    Ok(MeasuredStride {
        subject: subject.into(),
        condition: condition.into(),
        side,
        prototype: Prototype {
            walk,
            mu_star: mu.mu_star(),
            step_duration_s: report.step_duration_s,
            source: format!("{subject} {condition} {side}"),
            citation: "Schreiber & Moissenet (2019), Sci Data 6:111".into(),
            angles: Some(angles.clone()),
        },
        angles,
    })
}

/// One row of the comparison table: a target and the mean scores of each candidate kind.
#[derive(Debug, Clone, PartialEq)]
pub struct CompareRow {
    /// Target subject.
    pub subject: String,
    /// Target condition.
    pub condition: String,
    /// Target leg.
    pub side: Side,
    /// Model floor: the target's own step rendered.
    pub floor: Scores,
    /// Generalized from other subjects (mean over sources), same condition.
    pub generalized_same: Scores,
    /// Generalized from other subjects at the other condition.
    pub generalized_other: Scores,
    /// Generalized, carried variant ([`Variant::Carried`]), from other subjects, same condition.
    pub carried_same: Scores,
    /// Naive (uniform scaling) from other subjects, same condition.
    pub naive_same: Scores,
    /// Naive from other subjects at the other condition.
    pub naive_other: Scores,
    /// Best case: own step at the other condition, generalized.
    pub best: Option<Scores>,
    /// Naive through the model: the other subjects' steps rendered unchanged (uniform scaling
    /// leaves angles as they are), same condition — the like-for-like baseline of
    /// `generalized_same`, sharing its rendering error.
    pub naive_rendered_same: Scores,
    /// Own step at the other condition, unchanged (measured angles): what φ has to improve on
    /// in the best case.
    pub own_other_naive: Option<Scores>,
    /// Sources that failed to generalize (reach or μ range), with the reason.
    pub failures: Vec<String>,
}

fn render(g: &Generalizer, w: &super::WalkData) -> Result<Angles, GenerateError> {
    model_angles(w, g.mu())
}

/// Generalizes `src` onto `dst`'s body and step length (τ: ψ then φ), the paper's variant.
pub fn generalize_onto(
    src: &MeasuredStride,
    dst: &MeasuredStride,
    alpha: [f64; 4],
) -> Result<Angles, GenerateError> {
    generalize_onto_with(src, dst, alpha, Variant::Paper)
}

/// Generalizes `src` onto `dst`'s body and step length (τ: ψ then φ) with `variant`.
pub fn generalize_onto_with(
    src: &MeasuredStride,
    dst: &MeasuredStride,
    alpha: [f64; 4],
    variant: Variant,
) -> Result<Angles, GenerateError> {
    generalize_onto_heel(src, dst, alpha, variant, None)
}

/// The measured heel rise at the other foot's heel strike (−F₂ at HSM⁺, rad) and the step
/// length per leg length of a stride's prototype: one sample of the relation μ₅
/// ([`super::HeelRise`]).
pub fn heel_rise_sample(s: &MeasuredStride) -> (f64, f64) {
    let w = &s.prototype.walk;
    (w.step_length() / w.body().leg_length(), -w.foot2().at(1.0))
}

/// α₅ of the heel-rise relation μ₅ ([`super::HeelRise`]): the ordinary least-squares slope of
/// the heel rise at HSM⁺ on sl/ll over `training` (rad per unit of sl/ll, every stride one
/// sample, pooled over subjects, speeds and legs); `None` with fewer than 3 samples or no spread
/// of sl/ll. The leave-one-out of [`compare`] fits it on the other subjects' strides only.
pub fn fit_heel_rise_slope<'a>(
    training: impl IntoIterator<Item = &'a MeasuredStride>,
) -> Option<f64> {
    let xy: Vec<(f64, f64)> = training.into_iter().map(heel_rise_sample).collect();
    ols_slope(&xy)
}

/// The ordinary least-squares slope of y on x (with an intercept) over `xy`; `None` with fewer
/// than 3 points or no spread of x.
fn ols_slope(xy: &[(f64, f64)]) -> Option<f64> {
    let n = xy.len() as f64;
    if xy.len() < 3 {
        return None;
    }
    let (mx, my) = (
        xy.iter().map(|p| p.0).sum::<f64>() / n,
        xy.iter().map(|p| p.1).sum::<f64>() / n,
    );
    let sxx: f64 = xy.iter().map(|p| (p.0 - mx).powi(2)).sum();
    let sxy: f64 = xy.iter().map(|p| (p.0 - mx) * (p.1 - my)).sum();
    (sxx > 0.0 && (sxy / sxx).is_finite()).then(|| sxy / sxx)
}

/// [`generalize_onto_with`], with the heel-rise relation μ₅ of slope `heel_alpha` (rad per unit
/// of sl/ll; μ₅* = `src`'s own heel rise at HSM⁺) when given — the paper's eq. 33 without.
pub fn generalize_onto_heel(
    src: &MeasuredStride,
    dst: &MeasuredStride,
    alpha: [f64; 4],
    variant: Variant,
    heel_alpha: Option<f64>,
) -> Result<Angles, GenerateError> {
    let mut mu = src.prototype.mu(alpha)?;
    if let Some(a) = heel_alpha {
        mu = mu.with_heel_rise(super::HeelRise {
            alpha: a,
            star: heel_rise_sample(src).1,
        })?;
    }
    let g = Generalizer::new(src.prototype.walk.clone(), mu)?;
    let w = psi(&src.prototype.walk, dst.prototype.walk.body(), &mu)?;
    let sl = dst.prototype.walk.step_length();
    let w = phi(&w, sl / w.step_length(), sl, &mu)?;
    match variant {
        Variant::Paper => render(&g, &w),
        Variant::Carried => {
            let c = Carried::from_measured(&src.angles, &src.prototype.walk)?;
            carried_angles(&w, &mu, &c)
        }
    }
}

/// Naive: `src`'s measured angles, its ankle path scaled by the leg-length ratio.
pub fn naive_onto(src: &MeasuredStride, dst: &MeasuredStride) -> Angles {
    let k = dst.prototype.walk.body().leg_length() / src.prototype.walk.body().leg_length();
    let mut a = src.angles.clone();
    for p in &mut a.ankle_path {
        p[0] *= k;
        p[1] *= k;
    }
    a
}

/// What the candidates are compared with.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Target {
    /// B's measured stride (markers): the absolute test, model floor included.
    Measured,
    /// B's own step rendered through the model, and the naive candidate is A's rendered step:
    /// isolates the generalization from what the model itself cannot reproduce.
    Model,
}

fn rendered(s: &MeasuredStride, alpha: [f64; 4]) -> Result<Angles, GenerateError> {
    let mu = s.prototype.mu(alpha)?;
    let g = Generalizer::new(s.prototype.walk.clone(), mu)?;
    render(&g, &s.prototype.walk)
}

/// The comparison over all measured strides (targets × sources).
pub fn compare(strides: &[MeasuredStride], alpha: [f64; 4], target: Target) -> Vec<CompareRow> {
    // In model space every stride's "measured" angles are its own rendered step.
    let model: Vec<MeasuredStride>;
    let strides = if target == Target::Model {
        model = strides
            .iter()
            .filter_map(|s| {
                rendered(s, alpha).ok().map(|a| MeasuredStride {
                    angles: a,
                    ..s.clone()
                })
            })
            .collect();
        &model[..]
    } else {
        strides
    };
    let mut rows = Vec::new();
    for b in strides {
        let floor = {
            let mu = b.prototype.mu(alpha);
            match mu.and_then(|mu| {
                Generalizer::new(b.prototype.walk.clone(), mu)
                    .and_then(|g| render(&g, &b.prototype.walk))
            }) {
                Ok(a) => Scores::of(&a, &b.angles),
                Err(_) => Scores::default(),
            }
        };
        let mut row = CompareRow {
            subject: b.subject.clone(),
            condition: b.condition.clone(),
            side: b.side,
            floor,
            generalized_same: Scores::default(),
            generalized_other: Scores::default(),
            carried_same: Scores::default(),
            naive_same: Scores::default(),
            naive_other: Scores::default(),
            best: None,
            naive_rendered_same: Scores::default(),
            own_other_naive: None,
            failures: Vec::new(),
        };
        let (mut n_same, mut n_other) = (0.0, 0.0);
        // μ₅'s slope from the training subjects of this fold only (never the target's subject).
        let heel_alpha = fit_heel_rise_slope(strides.iter().filter(|s| s.subject != b.subject));
        for a in strides {
            if a.side != b.side {
                continue;
            }
            if a.subject == b.subject {
                if a.condition != b.condition {
                    match generalize_onto(a, b, alpha) {
                        Ok(g) => row.best = Some(Scores::of(&g, &b.angles)),
                        Err(e) => row.failures.push(format!("best from {}: {e}", a.condition)),
                    }
                    row.own_other_naive = Some(Scores::of(&naive_onto(a, b), &b.angles));
                }
                continue;
            }
            let same = a.condition == b.condition;
            match generalize_onto(a, b, alpha) {
                Ok(g) => {
                    let s = Scores::of(&g, &b.angles);
                    let n = naive_onto(a, b);
                    let ns = Scores::of(&n, &b.angles);
                    if same {
                        row.generalized_same.add(&s);
                        match generalize_onto_heel(a, b, alpha, Variant::Carried, heel_alpha) {
                            Ok(c) => row.carried_same.add(&Scores::of(&c, &b.angles)),
                            Err(e) => row
                                .failures
                                .push(format!("carried from {} {}: {e}", a.subject, a.condition)),
                        }
                        row.naive_same.add(&ns);
                        let nr = match rendered(a, alpha) {
                            Ok(mut r) => {
                                let k = b.prototype.walk.body().leg_length()
                                    / a.prototype.walk.body().leg_length();
                                r.ankle_path.iter_mut().for_each(|p| {
                                    p[0] *= k;
                                    p[1] *= k;
                                });
                                Scores::of(&r, &b.angles)
                            }
                            Err(_) => Scores::default(),
                        };
                        row.naive_rendered_same.add(&nr);
                        n_same += 1.0;
                    } else {
                        row.generalized_other.add(&s);
                        row.naive_other.add(&ns);
                        n_other += 1.0;
                    }
                }
                Err(e) => row
                    .failures
                    .push(format!("from {} {}: {e}", a.subject, a.condition)),
            }
        }
        if n_same > 0.0 {
            row.generalized_same.scale(1.0 / n_same);
            row.carried_same.scale(1.0 / n_same);
            row.naive_same.scale(1.0 / n_same);
            row.naive_rendered_same.scale(1.0 / n_same);
        }
        if n_other > 0.0 {
            row.generalized_other.scale(1.0 / n_other);
            row.naive_other.scale(1.0 / n_other);
        }
        rows.push(row);
    }
    rows
}

/// The comparison as a Markdown table, with the mean row.
pub fn table_markdown(rows: &[CompareRow]) -> String {
    let f = |s: &Scores| {
        format!(
            "{:.1} / {:.1} / {:.1} / {:.1}",
            s.hip_deg, s.knee_deg, s.ankle_deg, s.ankle_path_cm
        )
    };
    let mut out = String::from(
        "RMS hip / knee / ankle (deg) / swing ankle path (cm) against the measured stride\n\n\
         | target | model floor | generalized (same speed) | carried (same speed) | naive (same speed) | naive rendered (same speed) | generalized (other speed) | naive (other speed) | best case (own other speed) | own other speed unchanged |\n\
         |---|---|---|---|---|---|---|---|---|---|\n",
    );
    let m = mean_scores(rows);
    for r in rows {
        let opt = |s: &Option<Scores>| s.map(|b| f(&b)).unwrap_or_else(|| "—".into());
        out += &format!(
            "| {} {} {} | {} | {} | {} | {} | {} | {} | {} | {} | {} |\n",
            r.subject,
            r.condition,
            r.side,
            f(&r.floor),
            f(&r.generalized_same),
            f(&r.carried_same),
            f(&r.naive_same),
            f(&r.naive_rendered_same),
            f(&r.generalized_other),
            f(&r.naive_other),
            opt(&r.best),
            opt(&r.own_other_naive)
        );
    }
    out += &format!(
        "| **mean** | {} | {} | {} | {} | {} | {} | {} | {} | {} |\n",
        f(&m.floor),
        f(&m.generalized_same),
        f(&m.carried_same),
        f(&m.naive_same),
        f(&m.naive_rendered_same),
        f(&m.generalized_other),
        f(&m.naive_other),
        f(&m.best),
        f(&m.own_other_naive)
    );
    out
}

/// Mean scores over the comparison rows (the table's last row).
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct MeanScores {
    /// Model floor.
    pub floor: Scores,
    /// Generalized, same speed.
    pub generalized_same: Scores,
    /// Generalized, carried variant, same speed.
    pub carried_same: Scores,
    /// Naive (measured angles), same speed.
    pub naive_same: Scores,
    /// Naive through the model, same speed.
    pub naive_rendered_same: Scores,
    /// Generalized, other speed.
    pub generalized_other: Scores,
    /// Naive, other speed.
    pub naive_other: Scores,
    /// Best case (rows that have one).
    pub best: Scores,
    /// Own other speed unchanged (rows that have one).
    pub own_other_naive: Scores,
}

/// The mean of every column over `rows`.
pub fn mean_scores(rows: &[CompareRow]) -> MeanScores {
    let mut m = MeanScores::default();
    let (mut nb, mut no) = (0.0, 0.0);
    for r in rows {
        m.floor.add(&r.floor);
        m.generalized_same.add(&r.generalized_same);
        m.carried_same.add(&r.carried_same);
        m.naive_same.add(&r.naive_same);
        m.naive_rendered_same.add(&r.naive_rendered_same);
        m.generalized_other.add(&r.generalized_other);
        m.naive_other.add(&r.naive_other);
        if let Some(b) = &r.best {
            m.best.add(b);
            nb += 1.0;
        }
        if let Some(b) = &r.own_other_naive {
            m.own_other_naive.add(b);
            no += 1.0;
        }
    }
    let n = rows.len().max(1) as f64;
    for s in [
        &mut m.floor,
        &mut m.generalized_same,
        &mut m.carried_same,
        &mut m.naive_same,
        &mut m.naive_rendered_same,
        &mut m.generalized_other,
        &mut m.naive_other,
    ] {
        s.scale(1.0 / n);
    }
    if nb > 0.0 {
        m.best.scale(1.0 / nb);
    }
    if no > 0.0 {
        m.own_other_naive.scale(1.0 / no);
    }
    m
}

/// Every stride of both legs in the Schreiber data set folder `root` (`<subject>/dynamic/*.c3d`),
/// and the reasons for the strides that could not be built.
pub fn schreiber_strides(
    root: &std::path::Path,
    alpha: [f64; 4],
) -> Result<(Vec<MeasuredStride>, Vec<String>), crate::Error> {
    schreiber_strides_with(root, alpha, Landmarks::LateralMarkers)
}

/// [`schreiber_strides`] with the hip, knee and ankle points of `landmarks`.
pub fn schreiber_strides_with(
    root: &std::path::Path,
    alpha: [f64; 4],
    landmarks: Landmarks,
) -> Result<(Vec<MeasuredStride>, Vec<String>), crate::Error> {
    let mut files = Vec::new();
    let subjects = std::fs::read_dir(root).map_err(|e| crate::fsio::FsError::io(root, e))?;
    for s in subjects.flatten() {
        let dynamic = s.path().join("dynamic");
        if let Ok(rd) = std::fs::read_dir(&dynamic) {
            for f in rd.flatten() {
                if f.path()
                    .extension()
                    .is_some_and(|e| e.eq_ignore_ascii_case("c3d"))
                {
                    files.push((s.file_name().to_string_lossy().into_owned(), f.path()));
                }
            }
        }
    }
    files.sort();
    let mut out = Vec::new();
    let mut failed = Vec::new();
    for (subject, path) in files {
        let stem = path
            .file_stem()
            .map(|s| s.to_string_lossy().into_owned())
            .unwrap_or_default();
        let condition = stem
            .split('_')
            .find(|p| p.starts_with('C') && p.len() == 2)
            .unwrap_or("?")
            .to_string();
        let trial = crate::ingest::read_trial(&path, &crate::ingest::ReadOptions::default())?;
        for side in [Side::Left, Side::Right] {
            match schreiber_leg_with(&trial, side, landmarks)
                .and_then(|(leg, ev)| measured_stride(&leg, &ev, alpha, &subject, &condition, side))
            {
                Ok(m) => out.push(m),
                Err(e) => failed.push(format!("{stem} {side}: {e}")),
            }
        }
    }
    Ok((out, failed))
}

#[cfg(test)]
mod tests {
    /// α₅'s least squares against an independent computation: numpy.polyfit(x, y, 1)[0] and
    /// scipy.stats.linregress(x, y).slope on these six points both give 0.860167483014695.
    #[test]
    fn the_heel_rise_slope_is_the_least_squares_slope() {
        let x = [0.62, 0.71, 0.80, 0.85, 0.93, 1.02];
        let y = [0.31, 0.38, 0.44, 0.52, 0.55, 0.66];
        let xy: Vec<(f64, f64)> = x.into_iter().zip(y).collect();
        let b = ols_slope(&xy).expect("a slope");
        assert!((b - 0.860167483014695).abs() < 1e-12, "{b}");
        assert_eq!(ols_slope(&xy[..2]), None, "two points");
        assert_eq!(
            ols_slope(&[(1.0, 0.2), (1.0, 0.3), (1.0, 0.4)]),
            None,
            "no spread"
        );
    }

    use super::*;

    /// Harrington et al. (2007): with the pelvis frame equal to the lab frame the hip joint
    /// centre is the regression itself (PW = 0.25 m, PD = 0.15 m, numbers by hand), and a rigid
    /// motion of the markers moves it rigidly.
    #[test]
    fn hip_joint_centre_is_the_harrington_regression() {
        let (la, ra) = ([0.0, 0.0, -0.125], [0.0, 0.0, 0.125]);
        let (lp, rp) = ([-0.15, 0.0, -0.05], [-0.15, 0.0, 0.05]);
        let r = hip_joint_centre(la, ra, lp, rp, Side::Right).unwrap();
        let want = [
            -0.24 * 0.15 - 0.0099,
            -0.30 * 0.25 - 0.0109,
            0.33 * 0.25 + 0.0073,
        ];
        for k in 0..3 {
            assert!((r[k] - want[k]).abs() < 1e-12, "{r:?} vs {want:?}");
        }
        let l = hip_joint_centre(la, ra, lp, rp, Side::Left).unwrap();
        assert!((l[2] + want[2]).abs() < 1e-12);
        // Rotate 30° about the vertical (y) and translate.
        let (c, s) = (30f64.to_radians().cos(), 30f64.to_radians().sin());
        let m = |p: [f64; 3]| {
            [
                c * p[0] + s * p[2] + 1.0,
                p[1] + 0.9,
                -s * p[0] + c * p[2] - 2.0,
            ]
        };
        let r2 = hip_joint_centre(m(la), m(ra), m(lp), m(rp), Side::Right).unwrap();
        let w2 = m(want);
        for k in 0..3 {
            assert!((r2[k] - w2[k]).abs() < 1e-12);
        }
        assert!(hip_joint_centre(la, la, lp, rp, Side::Right).is_none());
    }
}
