//! Ko–Badler (1993) in `gaitfit calibrate`: where a walking subject has a measured walk at
//! another speed, that walk is the subject's own prototype W(S*, sl*) (§2): one of its measured
//! strides is built into a step W (as `gaitfit generate generalize --build-prototype` does, the
//! paper's μ-functions with [`default_alpha()`]), generalized (τ = φ∘ψ, eqs. 11–12) to the figure
//! of the subject's body height and to the other condition's measured step length and step
//! duration, rendered, and measured by the same event pipeline as the trials. Nothing is
//! calibrated: the generator's input is the subject's own other walk, so its residuals show
//! what kinematic generalization alone reproduces of a change of speed.
//!
//! The strides are read with the Schreiber & Moissenet (2019) marker set
//! ([`schreiber_leg`]); a trial without it has no Ko–Badler stage (the reason is kept).
use std::path::Path;

use super::drive::Driven;
use super::{measure_generated, Subject};
use crate::events::{Gait, Side};
use crate::generator::generalize::compare::{
    compare, mean_scores, measured_stride, schreiber_leg, MeanScores, MeasuredStride, Target,
    Variant,
};
use crate::generator::generalize::figure::{metadata, walk_motion_with, StepPlan};
use crate::generator::generalize::{default_alpha, Generalizer};
use crate::generator::skeleton::Skeleton;
use crate::ingest::{read_trial, ReadOptions};

/// The condition of `subject` whose walk serves as the prototype for condition `target`: the
/// nearest other speed.
pub fn source_for(subject: &Subject, target: usize) -> Option<usize> {
    let v = subject.conditions.get(target)?.speed();
    (0..subject.conditions.len())
        .filter(|&c| c != target)
        .min_by(|&a, &b| {
            let da = (subject.conditions[a].speed() - v).abs();
            let db = (subject.conditions[b].speed() - v).abs();
            da.total_cmp(&db)
        })
}

/// Generates condition `target` of `subject` by Ko–Badler from the walk of condition `source`
/// (`steps` steps at `fps`): the first stride (right leg, else left) of the source trial that
/// builds into a step is the prototype. With [`Variant::Carried`] the stride's measured
/// hip/knee/ankle curves are carried in W (the paper's feet, the hip placed where the drawn
/// angles come nearest them, [`crate::generator::generalize::carried`]).
pub fn drive_kb(
    subject: &Subject,
    target: usize,
    source: usize,
    fps: f64,
    steps: usize,
    variant: Variant,
) -> Result<Driven, String> {
    let src = &subject.conditions[source];
    let trial = read_trial(Path::new(&src.path), &ReadOptions::default())
        .map_err(|e| format!("{}: {e}", src.path))?;
    let q = &subject.conditions[target].measured.quantities;
    let h = subject.body_height_m;
    let mass = if subject.mass_kg > 0.0 {
        subject.mass_kg
    } else {
        75.0 * (h / 1.8).powi(2)
    };
    let mut why = Vec::new();
    for side in [Side::Right, Side::Left] {
        let built = schreiber_leg(&trial, side).and_then(|(leg, ev)| {
            measured_stride(&leg, &ev, default_alpha(), &subject.name, &src.trial, side)
        });
        let stride = match built {
            Ok(s) => s,
            Err(e) => {
                why.push(format!("{side} leg: {e}"));
                continue;
            }
        };
        let g = stride
            .prototype
            .mu(default_alpha())
            .and_then(|mu| Generalizer::new(stride.prototype.walk.clone(), mu))
            .map_err(|e| e.to_string())?;
        let plan = vec![
            StepPlan {
                step_length_m: q.step_length_m,
                duration_s: 60.0 / q.cadence_steps_per_min,
            };
            steps.max(4)
        ];
        let skeleton = Skeleton::from_height(h, mass).map_err(|e| e.to_string())?;
        let carried = match variant {
            Variant::Paper => None,
            Variant::Carried => Some(
                stride
                    .prototype
                    .carried()
                    .map_err(|e| e.to_string())?
                    .ok_or("the measured stride carries no angle curves")?,
            ),
        };
        let mut meta = metadata(&g, h, &stride.prototype.source);
        meta.push("kb_variant", variant.name());
        let (motion, rep) = walk_motion_with(
            &g,
            carried.as_ref(),
            skeleton,
            &plan,
            Side::Right,
            fps,
            meta,
        )
        .map_err(|e| e.to_string())?;
        let note = format!(
            "Ko–Badler ({} variant): prototype {} {side} stride (step {:.3} m), generalized to {:.3} m in {:.3} s; hip lowered at most {:.3} m to reach the feet",
            src.trial,
            g.prototype().step_length(),
            q.step_length_m,
            60.0 / q.cadence_steps_per_min,
            variant.name(),
            rep.max_hip_drop_m
        );
        return Ok(Driven {
            window: (0.0, motion.duration_s()),
            notes: vec![note],
            motion,
        });
    }
    Err(format!(
        "{}: no stride builds a prototype ({})",
        src.trial,
        why.join("; ")
    ))
}

/// Leave-one-out across the walking subjects of one calibration (issue 21 item 5): every
/// measured stride (Schreiber marker set) generalized from every other subject's stride of the
/// same leg and condition, by the paper's variant and the carried one, against naive scaling.
#[derive(Debug, Clone, PartialEq)]
pub struct KbLeaveOneOut {
    /// Subjects with at least one stride.
    pub subjects: usize,
    /// Strides (targets).
    pub strides: usize,
    /// Mean scores over the targets ([`compare`]'s protocol).
    pub mean: MeanScores,
    /// Source–target pairs that could not be generalized (a μ out of its range).
    pub left_out: usize,
}

/// The leave-one-out comparison over `subjects` (walking subjects whose trials carry the
/// Schreiber marker set); `None` with fewer than two such subjects.
pub fn leave_one_out(subjects: &[&Subject]) -> Option<KbLeaveOneOut> {
    let mut strides: Vec<MeasuredStride> = Vec::new();
    let mut with = 0;
    for s in subjects.iter().filter(|s| s.gait == Gait::Walk) {
        let before = strides.len();
        for c in &s.conditions {
            let Ok(trial) = read_trial(Path::new(&c.path), &ReadOptions::default()) else {
                continue;
            };
            for side in [Side::Left, Side::Right] {
                if let Ok(m) = schreiber_leg(&trial, side).and_then(|(leg, ev)| {
                    measured_stride(&leg, &ev, default_alpha(), &s.name, &c.trial, side)
                }) {
                    strides.push(m);
                }
            }
        }
        with += usize::from(strides.len() > before);
    }
    if with < 2 {
        return None;
    }
    // Conditions are compared by name across subjects (Schreiber's C1…C5 in the file names).
    for m in &mut strides {
        if let Some(c) = m
            .condition
            .split('_')
            .find(|p| p.starts_with('C') && p.len() == 2)
        {
            m.condition = c.to_string();
        }
    }
    let rows = compare(&strides, default_alpha(), Target::Measured);
    let left_out = rows
        .iter()
        .flat_map(|r| &r.failures)
        .filter(|f| f.starts_with("from "))
        .count();
    Some(KbLeaveOneOut {
        subjects: with,
        strides: strides.len(),
        mean: mean_scores(&rows),
        left_out,
    })
}

/// The Ko–Badler stage of a walking subject with two or more conditions: per condition, the
/// measurement of its generalization from the nearest other condition (`None` for runs,
/// single-condition subjects and subjects without markers, e.g. from a steps table).
pub fn kb_stage(
    subject: &Subject,
    fps: f64,
    steps: usize,
    variant: Variant,
) -> Option<super::solve::Stage> {
    // A subject without markers (a steps table) has no prototype walk to generalize.
    if subject.gait != Gait::Walk
        || subject.conditions.len() < 2
        || subject
            .conditions
            .iter()
            .all(|c| c.measured.curves.is_none())
    {
        return None;
    }
    let mut notes = Vec::new();
    let generated = (0..subject.conditions.len())
        .map(|c| {
            let source = source_for(subject, c).ok_or("no other condition")?;
            let d = drive_kb(subject, c, source, fps, steps, variant)?;
            notes.extend(d.notes.iter().cloned());
            measure_generated(&d, Gait::Walk).map_err(|e| e.to_string())
        })
        .collect();
    Some(super::solve::Stage {
        params: Vec::new(),
        generated,
        cost: f64::NAN,
        notes,
    })
}
