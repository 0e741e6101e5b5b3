//! Driving the generators at a measured condition with a subject's calibration attributes:
//! RUNNER (Bruderlin & Calvert 1996) for runs, KLAW (Bruderlin & Calvert 1989) for walks.
use crate::events::Gait;
use crate::generator::motion::Motion;
use crate::generator::running::equations::RunRelations;
use crate::generator::running::params::default_mass;
use crate::generator::running::state::FlightSpec;
use crate::generator::running::{
    generate_run, Attr, GenerateOptions, Param, RunAttributes, RunModel,
};
use crate::generator::skeleton::Skeleton;
use crate::generator::walking::{
    generate_walk, ScheduleEntry, WalkOptions, WalkParams, WalkRelations,
};
use crate::generator::GenerateError;
use crate::relations::WalkTdsSf;
use serde::{Deserialize, Serialize};

/// One calibrated generator attribute.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct AttrDef {
    /// Name (in calibrated.json and the report).
    pub name: &'static str,
    /// Unit.
    pub unit: &'static str,
    /// Finite-difference step of the Jacobian.
    pub step: f64,
    /// Admissible range.
    pub range: (f64, f64),
    /// What it is.
    pub doc: &'static str,
}

/// RUNNER's calibrated attributes: the subject's offsets in the step-length (eq. 2) and
/// flight-time (eqs. 4–5) relations — the flight height H follows from the flight time by
/// eq. 3 — and the stance leg's bounciness (knee flexion at mid-support).
pub const RUN_ATTRS: [AttrDef; 3] = [
    AttrDef {
        name: "step_length_offset_m",
        unit: "m",
        step: 0.01,
        range: (-0.4, 0.4),
        doc: "added to the step length of the relation run-sl-v (eq. 2) at the speed",
    },
    AttrDef {
        name: "flight_time_offset_s",
        unit: "s",
        step: 0.005,
        range: (-0.15, 0.15),
        doc: "added to the flight time of the relation run-tflight-sf (eqs. 4–5), driven as the flight time (case I); H reported (eq. 3)",
    },
    AttrDef {
        name: "bounciness_deg",
        unit: "deg",
        step: 2.0,
        range: (5.0, 80.0),
        doc: "RUNNER's stance knee flexion at mid-support (pelvis low point)",
    },
];

/// KLAW's calibrated attributes: the subject's offsets in the step-length (eq. 1) and
/// double-support relations, and the leg spring stiffness that sets the stance knee and the
/// hip (pelvis) height through the stance.
pub const WALK_ATTRS: [AttrDef; 3] = [
    AttrDef {
        name: "step_length_offset_m",
        unit: "m",
        step: 0.01,
        range: (-0.3, 0.3),
        doc: "added to the step length of the relation walk-sl-sf (eq. 1) at the speed",
    },
    AttrDef {
        name: "double_support_offset_pct",
        unit: "% cycle",
        step: 0.5,
        range: (-20.0, 20.0),
        doc: "added to d0 of the relation walk-tds-sf (double support, % of the cycle)",
    },
    AttrDef {
        name: "leg_stiffness",
        unit: "m·g/l1",
        step: 2.0,
        range: (5.0, 200.0),
        doc: "KLAW's stance leg spring (stance knee flexion and hip height)",
    },
];

/// The attribute definitions of `gait`.
pub fn attr_defs(gait: Gait) -> &'static [AttrDef; 3] {
    match gait {
        Gait::Run => &RUN_ATTRS,
        Gait::Walk => &WALK_ATTRS,
    }
}

/// Indices (in [`attr_defs`]) of the relation offsets that may vary with speed: the
/// step-length offset and the flight-time (run) or double-support (walk) offset. The third
/// attribute (bounciness, leg stiffness) is the generator's own and stays one value.
pub const SLOPED: [usize; 2] = [0, 1];

/// How a subject's parameter vector gives the attributes at a speed.
///
/// Without slopes the parameters are the three attributes of [`attr_defs`], the same at
/// every speed. With slopes (a subject measured at two or more speeds, so that a change with
/// speed is identifiable) two more parameters follow, the slopes of the [`SLOPED`] offsets per
/// m/s about the subject's reference speed `v_ref` (the mean of its speeds):
/// `offset(v) = a + b·(v − v_ref)`. A constant offset cannot fit a subject whose deviation
/// from the relation changes sign between speeds (Schreiber 2014001: cadence +1.7 and
/// −2.4 steps/min at 1.43 and 2.18 m/s with one step-length offset).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct AttrModel {
    /// Walk or run.
    pub gait: Gait,
    /// The speed (m/s) at which the offsets are the first parameters.
    pub reference_speed: f64,
    /// Half the spread of the subject's speeds (m/s), the scale of a slope's finite-difference
    /// step; `None`: no slopes.
    pub slope_scale: Option<f64>,
    /// Finite-difference steps of the three attributes (see [`AttrModel::for_speeds`]).
    pub steps: [f64; 3],
}

/// One parameter of an [`AttrModel`]: finite-difference step and admissible range.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ParamDef {
    /// Name: the attribute's, or the attribute's with `_slope` for a slope.
    pub name: &'static str,
    /// Finite-difference step of the Jacobian.
    pub step: f64,
    /// Admissible range.
    pub range: (f64, f64),
}

/// Frames of the generated motion that the finite-difference step of the flight or
/// double-support offset spans at least (see [`AttrModel::for_speeds`]): the quantisation error
/// of a difference is at most one frame at each end, so four frames keep it ≤ 50 % of the
/// step (usually ≤ 25 %).
pub const FD_FRAMES: f64 = 4.0;

/// Names of the slope parameters, in the order of [`SLOPED`] (per gait).
const SLOPE_NAMES: [[&str; 2]; 2] = [
    ["step_length_offset_m_slope", "flight_time_offset_s_slope"],
    [
        "step_length_offset_m_slope",
        "double_support_offset_pct_slope",
    ],
];

impl AttrModel {
    /// The model of a subject measured at `speeds` (m/s): slopes when `slopes` and there are
    /// two or more distinct speeds (≥ 0.1 m/s apart), none otherwise.
    ///
    /// The generated motion is steady, every step alike, so its mean flight or double support
    /// moves in whole frames (1/`fps`; in % of the cycle `100/(fps·cycle_s)`, `cycle_s` the
    /// subject's longest measured stride time): a finite-difference step of the flight or
    /// double-support offset below a few frames measures the quantisation, not the slope
    /// (2014007 at 0.92 m/s: a 0.5 % step moved the double support 0.0 or 0.9 %). That offset's
    /// step is therefore at least [`FD_FRAMES`] frames.
    pub fn for_speeds(
        gait: Gait,
        speeds: &[f64],
        slopes: bool,
        fps: f64,
        cycle_s: f64,
    ) -> AttrModel {
        let n = speeds.len().max(1) as f64;
        let reference_speed = speeds.iter().sum::<f64>() / n;
        let (lo, hi) = speeds
            .iter()
            .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), &v| {
                (a.min(v), b.max(v))
            });
        let half = 0.5 * (hi - lo);
        let defs = attr_defs(gait);
        let frame = match gait {
            Gait::Run => 1.0 / fps,
            Gait::Walk => 100.0 / (fps * cycle_s),
        };
        AttrModel {
            gait,
            reference_speed,
            slope_scale: (slopes && half >= 0.05).then_some(half),
            steps: [
                defs[0].step,
                defs[1].step.max(FD_FRAMES * frame),
                defs[2].step,
            ],
        }
    }

    /// Number of parameters (3, or 5 with slopes).
    pub fn len(&self) -> usize {
        3 + if self.slope_scale.is_some() { 2 } else { 0 }
    }

    /// Never empty (there are always the three attributes).
    pub fn is_empty(&self) -> bool {
        false
    }

    /// The parameters: the attributes, then the slopes. A slope's step moves its offset by the
    /// offset's own step at the subject's extreme speeds; its range lets the offset cross its
    /// whole range over that spread.
    pub fn params(&self) -> Vec<ParamDef> {
        let defs = attr_defs(self.gait);
        let mut out: Vec<ParamDef> = defs
            .iter()
            .zip(self.steps)
            .map(|(d, step)| ParamDef {
                name: d.name,
                step,
                range: d.range,
            })
            .collect();
        if let Some(half) = self.slope_scale {
            let names = SLOPE_NAMES[usize::from(self.gait == Gait::Walk)];
            for (k, &i) in SLOPED.iter().enumerate() {
                let (lo, hi) = defs[i].range;
                let r = (hi - lo) / (2.0 * half);
                out.push(ParamDef {
                    name: names[k],
                    step: self.steps[i] / half,
                    range: (-r, r),
                });
            }
        }
        out
    }

    /// The starting parameters: [`initial`] and zero slopes.
    pub fn initial(&self, body_height: f64) -> Vec<f64> {
        let mut p = initial(self.gait, body_height).to_vec();
        p.resize(self.len(), 0.0);
        p
    }

    /// The attributes at speed `v` (m/s).
    pub fn at(&self, p: &[f64], v: f64) -> [f64; 3] {
        let mut t = [p[0], p[1], p[2]];
        if self.slope_scale.is_some() {
            for (k, &i) in SLOPED.iter().enumerate() {
                t[i] += p.get(3 + k).copied().unwrap_or(0.0) * (v - self.reference_speed);
            }
        }
        t
    }
}

/// The attributes before calibration: zero offsets and the generator's defaults.
pub fn initial(gait: Gait, body_height: f64) -> [f64; 3] {
    match gait {
        Gait::Run => [
            0.0,
            0.0,
            RunAttributes::defaults(body_height)
                .get(Attr::Bounciness)
                .to_degrees(),
        ],
        Gait::Walk => [
            0.0,
            0.0,
            crate::generator::walking::WalkAttributes::default().leg_stiffness,
        ],
    }
}

/// The relations a drive uses.
#[derive(Debug, Clone)]
pub struct Relations {
    /// RUNNER's.
    pub run: RunRelations,
    /// KLAW's.
    pub walk: WalkRelations,
    /// Where they came from.
    pub source: String,
}

/// One generation: the motion and the time window of its steady steps.
pub struct Driven {
    /// The motion.
    pub motion: Motion,
    /// Start and end (s) of the steady steps to measure.
    pub window: (f64, f64),
    /// Notes of the generator (recoveries, stubbing).
    pub notes: Vec<String>,
}

/// Frame rate and duration of the generated motions.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct DriveOptions {
    /// Frames per second.
    pub fps: f64,
    /// Steady steps generated per condition.
    pub steps: usize,
}

impl Default for DriveOptions {
    fn default() -> Self {
        DriveOptions {
            fps: 200.0,
            steps: 12,
        }
    }
}

fn clamp(theta: &[f64; 3], gait: Gait) -> [f64; 3] {
    let d = attr_defs(gait);
    [0, 1, 2].map(|i| theta[i].clamp(d[i].range.0, d[i].range.1))
}

/// Drives the generator of `gait` at speed `v` (m/s) for a body of height `h` (m), mass
/// `mass` (kg), with attributes `theta` (see [`RUN_ATTRS`], [`WALK_ATTRS`]).
pub fn drive(
    rel: &Relations,
    gait: Gait,
    v: f64,
    h: f64,
    mass: f64,
    theta: &[f64; 3],
    o: &DriveOptions,
) -> Result<Driven, GenerateError> {
    let theta = clamp(theta, gait);
    match gait {
        Gait::Run => drive_run(&rel.run, v, h, mass, &theta, o),
        Gait::Walk => drive_walk(&rel.walk, v, h, mass, &theta, o),
    }
}

/// RUNNER's parameters at speed `v` with the calibration `theta` applied: the natural step
/// length (eq. 2) plus the offset, speed held; the relation's flight time at the resulting
/// frequency (eqs. 4–5) plus the offset, driven as the flight time itself (case I of §3.2),
/// with the flight height H of eq. 3 only reported.
///
/// The flight is not handed to RUNNER as H (case II): with the toe-off leg of eq. 8 the pelvis
/// takes off higher the longer the flight, so H is not monotone in the flight time and one H
/// has several flight times (Hamner subject01 at 3 m/s, refitted relations: H = 0.0070 m for
/// 0.080 s and for 0.196 s of flight; case II's Newton–Raphson found the 0.196 s one, and the
/// generated contact was 0.17 s instead of the planned 0.28 s).
pub fn run_params(
    model: &RunModel,
    attrs: &RunAttributes,
    v: f64,
    theta: &[f64; 3],
) -> Result<crate::generator::running::RunParams, GenerateError> {
    let mut p = model.natural(v, 0.0, attrs)?;
    p.locks.set(Param::Speed, true);
    if theta[0] != 0.0 {
        p = model.set(&p, Param::StepLength, p.step_length + theta[0], attrs)?;
    }
    let tf = (model.relations.flight_time(p.step_freq, 0.0) + theta[1]).max(0.01);
    let (hgt, _) =
        model.steady_flight(v, p.step_length, p.step_freq, FlightSpec::Time(tf), attrs)?;
    p.flight_time = tf;
    p.flight_height = hgt;
    p.flight_from_height = false;
    p.locks = Default::default();
    Ok(p)
}

fn drive_run(
    rel: &RunRelations,
    v: f64,
    h: f64,
    mass: f64,
    theta: &[f64; 3],
    o: &DriveOptions,
) -> Result<Driven, GenerateError> {
    let skeleton = Skeleton::from_height(h, if mass > 0.0 { mass } else { default_mass(h) })?;
    let model = RunModel::new(skeleton, rel.clone())?;
    let mut attrs = RunAttributes::defaults(h);
    attrs.set(Attr::Bounciness, theta[2].to_radians())?;
    let p = run_params(&model, &attrs, v, theta)?;
    // The run starts from a jog and reaches the speed within a few steps; generate those and
    // `o.steps` steady ones.
    let seconds = (o.steps as f64 + 6.0) / p.step_freq;
    let opts = GenerateOptions {
        seconds,
        fps: o.fps,
        stop_at_end: false,
    };
    let (motion, rep) = generate_run(&model, p, attrs, None, &opts)?;
    let steady = rep
        .steps
        .iter()
        .find(|s| (s.speed - p.speed).abs() < 1e-9)
        .map_or(0.0, |s| s.start_s);
    let end = motion.duration_s() - 0.6 / p.step_freq;
    Ok(Driven {
        window: (steady + 0.05, end),
        notes: motion.metadata.notes.clone(),
        motion,
    })
}

fn drive_walk(
    rel: &WalkRelations,
    v: f64,
    h: f64,
    mass: f64,
    theta: &[f64; 3],
    o: &DriveOptions,
) -> Result<Driven, GenerateError> {
    let mut relations = rel.clone();
    relations.tds_sf = WalkTdsSf::new(rel.tds_sf.d0() + theta[1], rel.tds_sf.d1());
    let mut opts = WalkOptions {
        height_m: h,
        mass_kg: if mass > 0.0 {
            mass
        } else {
            75.0 * (h / 1.8).powi(2)
        },
        fps: o.fps,
        relations,
        ..Default::default()
    };
    opts.attributes.set("leg_stiffness", theta[2])?;
    // The relation is in m/min.
    let sl = rel.sl_sf.step_length_for_speed(v * 60.0, h) + theta[0];
    let entry = ScheduleEntry {
        params: WalkParams {
            speed_m_per_s: Some(v),
            step_length_m: Some(sl),
            step_freq_steps_per_min: None,
        },
        steps: o.steps,
    };
    let (motion, rep) = generate_walk(&[entry], &opts)?;
    Ok(Driven {
        window: (0.0, motion.duration_s()),
        notes: rep.notes,
        motion,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Slopes only with two or more speeds; the offsets are the first parameters at the
    /// reference speed and change linearly with it; the third attribute never has a slope.
    #[test]
    fn attr_model_slopes() {
        let one = AttrModel::for_speeds(Gait::Run, &[3.0], true, 200.0, 0.7);
        assert_eq!(one.len(), 3);
        assert_eq!(one.at(&[0.1, 0.02, 40.0], 5.0), [0.1, 0.02, 40.0]);
        let off = AttrModel::for_speeds(Gait::Run, &[2.0, 4.0], false, 200.0, 0.7);
        assert_eq!(off.len(), 3);
        let m = AttrModel::for_speeds(Gait::Walk, &[1.0, 1.4, 1.6], true, 200.0, 1.2);
        assert_eq!(m.len(), 5);
        assert!((m.reference_speed - 4.0 / 3.0).abs() < 1e-12);
        let p = [0.01, 2.0, 30.0, 0.05, -4.0];
        let at_ref = m.at(&p, m.reference_speed);
        assert!((at_ref[0] - 0.01).abs() < 1e-12 && (at_ref[1] - 2.0).abs() < 1e-12);
        let t = m.at(&p, m.reference_speed + 0.5);
        assert!((t[0] - 0.035).abs() < 1e-12 && (t[1] - 0.0).abs() < 1e-12 && t[2] == 30.0);
        // The slope's step moves the offset by the offset's step at the extreme speeds.
        let d = m.params();
        assert!((d[3].step * 0.3 - d[0].step).abs() < 1e-12);
        assert!((d[4].step * 0.3 - d[1].step).abs() < 1e-12);
    }

    /// The flight or double-support offset's step spans FD_FRAMES frames of the generated
    /// motion: 4 frames at 200 fps are 20 ms of flight, or 100·4/(200·1.2) % of a 1.2 s cycle.
    #[test]
    fn offset_step_spans_frames() {
        let r = AttrModel::for_speeds(Gait::Run, &[3.0], false, 200.0, 0.7);
        assert!((r.params()[1].step - 0.02).abs() < 1e-12);
        let w = AttrModel::for_speeds(Gait::Walk, &[1.2], false, 200.0, 1.2);
        assert!((w.params()[1].step - 100.0 * 4.0 / 240.0).abs() < 1e-12);
        // Never below the attribute's own step.
        let fine = AttrModel::for_speeds(Gait::Walk, &[1.2], false, 2000.0, 1.2);
        assert_eq!(fine.params()[1].step, WALK_ATTRS[1].step);
    }
}
