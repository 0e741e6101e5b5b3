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
//! - **naive**: A's measured stride unchanged in angles and time-normalized, its ankle path
//!   scaled by ll(B)/ll(A) (A's step scaled uniformly in size and time);
//! - **best case**: B's own step at the other condition, generalized to this step length;
//! - **model floor**: B's own step at this condition rendered through the model (what the
//!   point-pivot foot, rigid legs and symmetric hip cost even without generalizing).
//!
//! Each is scored by RMS differences over 101 samples per step.
use super::angles::{model_angles, Angles};
use super::prototype::{build_prototype, Prototype, SagittalLeg, StrideEvents};
use super::{phi, psi, Generalizer};
use crate::events::filter::Butterworth;
use crate::events::{EventKind, Side};
use crate::generator::GenerateError;
use crate::ingest::types::Trial;

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

/// The sagittal leg of `side` from a Schreiber C3D trial (markers low-passed at
/// [`CUTOFF_HZ`]) and its first complete stride from the reference events. Landmarks: FTC
/// (greater trochanter), FLE (lateral femoral epicondyle), FAL (lateral malleolus), FCC
/// (calcaneus), FM5 (fifth metatarsal head) and FM2 (second metatarsal head) as the toe — the
/// data set has no toe-tip marker, so the "toes" are the forefoot line FM5→FM2.
pub fn schreiber_leg(
    trial: &Trial,
    side: Side,
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
    let get = |label: &str| -> Result<Vec<[f64; 2]>, GenerateError> {
        let full = format!("{p}{label}");
        let q = m
            .get(&full)
            .ok_or_else(|| bad(format!("no marker {full}")))?;
        let xs: Vec<f64> = q.iter().map(|r| s * r[f]).collect();
        let ys: Vec<f64> = q.iter().map(|r| r[v]).collect();
        let xf = filt
            .filtfilt(&xs)
            .ok_or_else(|| bad(format!("{full}: too short or gaps to filter")))?;
        let yf = filt
            .filtfilt(&ys)
            .ok_or_else(|| bad(format!("{full}: too short or gaps to filter")))?;
        Ok(xf.into_iter().zip(yf).map(|(x, y)| [x, y]).collect())
    };
    let leg = SagittalLeg {
        time_s: m.time_s.clone(),
        hip: get("FTC")?,
        knee: get("FLE")?,
        ankle: get("FAL")?,
        heel: get("FCC")?,
        ball: get("FM5")?,
        toe: get("FM2")?,
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
    /// Naive (uniform scaling) from other subjects, same condition.
    pub naive_same: Scores,
    /// Naive from other subjects at the other condition.
    pub naive_other: Scores,
    /// Best case: own step at the other condition, generalized.
    pub best: Option<Scores>,
    /// Sources that failed to generalize (reach or μ range), with the reason.
    pub failures: Vec<String>,
}

fn render(g: &Generalizer, w: &super::WalkData) -> Result<Angles, GenerateError> {
    model_angles(w, g.mu())
}

/// Generalizes `src` onto `dst`'s body and step length (τ: ψ then φ).
pub fn generalize_onto(
    src: &MeasuredStride,
    dst: &MeasuredStride,
    alpha: [f64; 4],
) -> Result<Angles, GenerateError> {
    let mu = src.prototype.mu(alpha)?;
    let g = Generalizer::new(src.prototype.walk.clone(), mu)?;
    let w = psi(&src.prototype.walk, dst.prototype.walk.body(), &mu)?;
    let sl = dst.prototype.walk.step_length();
    let w = phi(&w, sl / w.step_length(), sl, &mu)?;
    render(&g, &w)
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
            naive_same: Scores::default(),
            naive_other: Scores::default(),
            best: None,
            failures: Vec::new(),
        };
        let (mut n_same, mut n_other) = (0.0, 0.0);
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
                        row.naive_same.add(&ns);
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
            row.naive_same.scale(1.0 / n_same);
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
         | target | model floor | generalized (same speed) | naive (same speed) | generalized (other speed) | naive (other speed) | best case (own other speed) |\n\
         |---|---|---|---|---|---|---|\n",
    );
    let mut mean = [Scores::default(); 6];
    let mut nb = 0.0;
    for r in rows {
        let best = r.best.map(|b| f(&b)).unwrap_or_else(|| "—".into());
        out += &format!(
            "| {} {} {} | {} | {} | {} | {} | {} | {} |\n",
            r.subject,
            r.condition,
            r.side,
            f(&r.floor),
            f(&r.generalized_same),
            f(&r.naive_same),
            f(&r.generalized_other),
            f(&r.naive_other),
            best
        );
        for (m, s) in mean.iter_mut().zip([
            &r.floor,
            &r.generalized_same,
            &r.naive_same,
            &r.generalized_other,
            &r.naive_other,
        ]) {
            m.add(s);
        }
        if let Some(b) = &r.best {
            mean[5].add(b);
            nb += 1.0;
        }
    }
    let n = rows.len().max(1) as f64;
    for m in mean.iter_mut().take(5) {
        m.scale(1.0 / n);
    }
    if nb > 0.0 {
        mean[5].scale(1.0 / nb);
    }
    out += &format!(
        "| **mean** | {} | {} | {} | {} | {} | {} |\n",
        f(&mean[0]),
        f(&mean[1]),
        f(&mean[2]),
        f(&mean[3]),
        f(&mean[4]),
        f(&mean[5])
    );
    out
}

/// Every stride of both legs in the Schreiber data set folder `root` (`<subject>/dynamic/*.c3d`),
/// and the reasons for the strides that could not be built.
pub fn schreiber_strides(
    root: &std::path::Path,
    alpha: [f64; 4],
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
            match schreiber_leg(&trial, side)
                .and_then(|(leg, ev)| measured_stride(&leg, &ev, alpha, &subject, &condition, side))
            {
                Ok(m) => out.push(m),
                Err(e) => failed.push(format!("{stem} {side}: {e}")),
            }
        }
    }
    Ok((out, failed))
}
