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
