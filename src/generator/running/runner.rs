//! The step-by-step state machine (Fig. 3's main loop): plan a step from the parameters and
//! attributes in force, evaluate frames from it, and at its end swap legs and plan the next —
//! "changes the user makes to any of the parameters or attributes become active on the next
//! running step". Starting from a stand and stopping in a stand are special steps.
use glam::DVec3;

use super::attributes::RunAttributes;
use super::frame::{eval_frame, FrameInfo};
use super::params::{RunModel, RunParams};
use super::schedule::Schedule;
use super::state::{
    carry_out, plan_step, plan_stop, standing_carry, state_keyframes, Carry, StepInput, StepKind,
    StepPlan, StepReport,
};
use crate::events::{EventKind, EventSource, GaitEvent, Side};
use crate::generator::skeleton::Pose;
use crate::generator::GenerateError;

/// One generated step, for reports and tests.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct StepRecord {
    /// Step index (0 = the first, from a stand).
    pub index: usize,
    /// Stance (landing) side.
    pub side: Side,
    /// Kind of step.
    pub kind: StepKind,
    /// Start time (heel strike of the stance leg), s.
    pub start_s: f64,
    /// Duration, s.
    pub duration_s: f64,
    /// Speed, m/s.
    pub speed: f64,
    /// Step length (heel to heel), m.
    pub step_length: f64,
    /// Step frequency, steps/s.
    pub step_freq: f64,
    /// Stance foot flat at (relative), s.
    pub t_flat: f64,
    /// Heel off at (relative), s.
    pub t_heel_off: f64,
    /// Toe off at (relative), s.
    pub t_toe_off: f64,
    /// Flight and state-constraint numbers.
    pub report: StepReport,
}

/// Where the runner is.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum RunState {
    /// Running (including the first step from a stand and any automatic deceleration).
    Running,
    /// In the final stop phase.
    Stopping,
    /// Standing still after a stop.
    Stopped,
}

/// Speed below which a requested stop is planned directly (m/s at 1.8 m, Froude-scaled);
/// faster runs first decelerate by [`STOP_DECELERATION`] per step.
pub const STOP_SPEED: f64 = 1.5;
/// Speed reduction per step while decelerating to a stop, m/s (at 1.8 m, Froude-scaled).
pub const STOP_DECELERATION: f64 = 0.6;

/// Speed of the first step from a stand, m/s at 1.8 m (Froude-scaled); faster runs build up to
/// their speed by [`START_ACCELERATION`] per step.
pub const START_SPEED: f64 = 2.5;
/// Speed gained per step while starting, m/s at 1.8 m (Froude-scaled).
pub const START_ACCELERATION: f64 = 0.8;

/// How far the pelvis at least rises from the stand to the first toe off, m at 1.8 m.
pub const START_RISE: f64 = 0.02;

/// The interactive running generator.
#[derive(Debug, Clone)]
pub struct Runner {
    model: RunModel,
    params: RunParams,
    attrs: RunAttributes,
    pending: Option<(RunParams, RunAttributes)>,
    ramp_target: Option<RunParams>,
    schedule: Option<Schedule>,
    stop_requested: bool,
    state: RunState,
    plan: StepPlan,
    carry: Carry,
    t0: f64,
    step: usize,
    records: Vec<StepRecord>,
    events: Vec<GaitEvent>,
}

fn side_of(sign: f64) -> Side {
    if sign > 0.0 {
        Side::Right
    } else {
        Side::Left
    }
}

impl Runner {
    /// A runner standing with its feet side by side at the origin, about to start with the
    /// right leg as the first stance leg, with the given parameters and attributes (and an
    /// optional per-step schedule whose step-0 rows apply to the first step).
    pub fn new(
        model: RunModel,
        params: RunParams,
        attrs: RunAttributes,
        schedule: Option<Schedule>,
    ) -> Result<Runner, GenerateError> {
        let eff = attrs.effective(&params.drivers());
        let carry = standing_carry(&model.dims, &eff, 0.0, 1.0, f64::INFINITY);
        // Replaced by the first step's plan below, once the schedule's step-0 rows are applied.
        let placeholder = plan_stop(&model.dims, &carry, &eff);
        let mut r = Runner {
            model,
            params,
            attrs,
            pending: None,
            ramp_target: None,
            schedule,
            stop_requested: false,
            state: RunState::Running,
            plan: placeholder,
            carry,
            t0: 0.0,
            step: 0,
            records: Vec::new(),
            events: Vec::new(),
        };
        r.apply_schedule()?;
        if r.pending.is_none() {
            r.ramp_target = Some(r.params);
        }
        r.adapt_stand()?;
        r.plan_current(StepKind::Start)?;
        Ok(r)
    }

    /// The model (figure and relations).
    pub fn model(&self) -> &RunModel {
        &self.model
    }
    /// Parameters of the current step.
    pub fn params(&self) -> &RunParams {
        &self.params
    }
    /// Attributes of the current step.
    pub fn attributes(&self) -> &RunAttributes {
        &self.attrs
    }
    /// Index of the current step.
    pub fn step_index(&self) -> usize {
        self.step
    }
    /// Where the runner is.
    pub fn state(&self) -> RunState {
        self.state
    }
    /// Steps planned so far (including the current one).
    pub fn steps(&self) -> &[StepRecord] {
        &self.records
    }
    /// Gait events planned so far (exact times; the current step's lie partly ahead).
    pub fn events(&self) -> &[GaitEvent] {
        &self.events
    }
    /// Start time of the current step, s.
    pub fn step_start(&self) -> f64 {
        self.t0
    }
    /// End time of the current step, s.
    pub fn step_end(&self) -> f64 {
        self.t0 + self.plan.t_step
    }

    /// New parameters, effective from the next step.
    pub fn set_params(&mut self, params: RunParams) {
        let attrs = self
            .pending
            .as_ref()
            .map(|p| p.1.clone())
            .unwrap_or_else(|| self.attrs.clone());
        self.pending = Some((params, attrs));
    }

    /// New attribute settings, effective from the next step.
    pub fn set_attributes(&mut self, attrs: RunAttributes) {
        let params = self.pending.as_ref().map(|p| p.0).unwrap_or(self.params);
        self.pending = Some((params, attrs));
    }

    /// Asks the runner to stop: it decelerates step by step to [`STOP_SPEED`] and then comes to
    /// a stand.
    pub fn request_stop(&mut self) {
        self.stop_requested = true;
    }

    fn froude(&self) -> f64 {
        (self.model.dims.body_height / 1.8).sqrt()
    }

    fn apply_schedule(&mut self) -> Result<(), GenerateError> {
        let Some(schedule) = self.schedule.take() else {
            return Ok(());
        };
        let mut result = Ok(());
        for row in schedule.rows_at(self.step) {
            let base = self.pending.as_ref().map(|p| p.0).unwrap_or(self.params);
            let attrs = self
                .pending
                .as_ref()
                .map(|p| p.1.clone())
                .unwrap_or_else(|| self.attrs.clone());
            let mut p = base;
            let locks = p.locks;
            let mut apply = || -> Result<RunParams, GenerateError> {
                if let Some(l) = row.level {
                    p.level = l;
                    if row.set.is_empty() {
                        p = self
                            .model
                            .set(&p, super::params::Param::Speed, p.speed, &attrs)?;
                    }
                }
                for &(param, value) in &row.set {
                    p = self.model.set(&p, param, value, &attrs)?;
                    p.locks.set(param, true);
                }
                p.locks = locks;
                Ok(p)
            };
            match apply() {
                Ok(p) => self.pending = Some((p, attrs)),
                Err(e) => {
                    result = Err(GenerateError::Input {
                        path: schedule.source.clone(),
                        message: format!("row {}: {e}", row.row),
                    });
                    break;
                }
            }
            if row.stop {
                self.stop_requested = true;
            }
        }
        self.schedule = Some(schedule);
        result
    }

    /// From a stand the pelvis must rise to the first toe off (so the swing foot, starting on
    /// the ground, lifts off): crouch as needed below the first step's toe-off height.
    fn adapt_stand(&mut self) -> Result<(), GenerateError> {
        let (mut params, attrs) = match &self.pending {
            Some((p, a)) => (*p, a.clone()),
            None => (self.params, self.attrs.clone()),
        };
        let v_start = START_SPEED * self.froude();
        if params.speed > v_start {
            params = self.model.natural(v_start, params.level, &attrs)?;
        }
        let eff = attrs.effective(&params.drivers());
        let inp = StepInput {
            speed: params.speed,
            step_length: params.step_length,
            step_freq: params.step_freq,
            flight: params.flight_spec(),
            eff,
            next_eff: eff,
            p: 0.75,
        };
        let d = self.model.dims;
        let k = state_keyframes(&d, &inp, self.carry.stance_sign, &self.carry.stance_print)?;
        let max_y = k.p1.y - START_RISE * d.body_height / 1.8;
        self.carry = standing_carry(&d, &eff, 0.0, 1.0, max_y);
        Ok(())
    }

    /// The speed expected on the next step (for the hind leg's fraction p).
    fn next_speed(&self) -> f64 {
        if let Some((p, _)) = &self.pending {
            return p.speed;
        }
        if let Some(target) = &self.ramp_target {
            return (self.params.speed + START_ACCELERATION * self.froude()).min(target.speed);
        }
        if let Some(s) = &self.schedule {
            for row in s.rows_at(self.step + 1) {
                if row.stop {
                    return (self.params.speed - STOP_DECELERATION * self.froude()).max(0.0);
                }
                if let Some(&(_, v)) = row
                    .set
                    .iter()
                    .find(|(p, _)| *p == super::params::Param::Speed)
                {
                    return v;
                }
            }
        }
        if self.stop_requested {
            return (self.params.speed - STOP_DECELERATION * self.froude())
                .max(STOP_SPEED * self.froude());
        }
        self.params.speed
    }

    /// Plans the current step (index `self.step`) from `self.carry`.
    fn plan_current(&mut self, kind: StepKind) -> Result<(), GenerateError> {
        if let Some((p, a)) = self.pending.take() {
            self.params = p;
            self.attrs = a;
            // New parameters replace whatever the start was ramping toward…
            self.ramp_target = None;
            if kind == StepKind::Start {
                self.ramp_target = Some(self.params);
            }
        }
        let fr = self.froude();
        // …and a start from a stand accelerates step by step: the first step at most
        // START_SPEED, then START_ACCELERATION more per step (p rises toward 0.9 meanwhile).
        if let Some(target) = self.ramp_target {
            let v = if kind == StepKind::Start {
                START_SPEED * fr
            } else {
                self.params.speed + START_ACCELERATION * fr
            };
            if v >= target.speed - 1e-9 {
                self.params = target;
                self.ramp_target = None;
            } else {
                let level = target.level;
                self.params = self.model.natural(v, level, &self.attrs)?;
            }
        }
        let d = self.model.dims;
        if self.stop_requested && kind != StepKind::Start {
            let v_stop = STOP_SPEED * self.froude();
            if self.params.speed > v_stop + 1e-9 {
                let v = (self.params.speed - STOP_DECELERATION * self.froude()).max(v_stop);
                let level = self.params.level;
                self.params = self.model.natural(v, level, &self.attrs)?;
            } else {
                let eff = self.attrs.effective(&self.params.drivers());
                self.plan = plan_stop(&d, &self.carry, &eff);
                self.state = RunState::Stopping;
                self.record();
                return Ok(());
            }
        }
        let eff = self.attrs.effective(&self.params.drivers());
        let next_eff = match &self.pending {
            Some((p, a)) => a.effective(&p.drivers()),
            None => eff,
        };
        let v = self.params.speed;
        let dv = self.next_speed() - v;
        // §3.3.2: p between 0.6 (decelerating) and 0.9 (accelerating), 0.75 at constant speed;
        // a 10 % speed change per step saturates it.
        let p = 0.75 + 0.15 * (dv / (0.1 * v.max(0.5))).clamp(-1.0, 1.0);
        let inp = StepInput {
            speed: v,
            step_length: self.params.step_length,
            step_freq: self.params.step_freq,
            flight: self.params.flight_spec(),
            eff,
            next_eff,
            p,
        };
        self.plan = plan_step(&d, &inp, &self.carry, kind).map_err(|e| match e {
            GenerateError::Numerical { stage, message } => GenerateError::Numerical {
                stage: format!("step {}, {stage}", self.step),
                message,
            },
            other => other,
        })?;
        self.record();
        Ok(())
    }

    fn record(&mut self) {
        let pl = &self.plan;
        let side = side_of(pl.s);
        let other = side.opposite();
        let t0 = self.t0;
        let ev = |t: f64, side: Side, kind: EventKind| GaitEvent {
            time_s: t0 + t,
            side,
            kind,
            source: EventSource::Generated,
        };
        match pl.kind {
            StepKind::Start => {
                self.events.push(ev(0.0, side, EventKind::FootFlat));
                self.events.push(ev(0.0, other, EventKind::ToeOff));
                self.events
                    .push(ev(pl.t_heel_off, side, EventKind::HeelOff));
                self.events.push(ev(pl.t_stance, side, EventKind::ToeOff));
            }
            StepKind::Normal => {
                self.events.push(ev(0.0, side, EventKind::HeelStrike));
                self.events.push(ev(pl.t_flat, side, EventKind::FootFlat));
                self.events
                    .push(ev(pl.t_heel_off, side, EventKind::HeelOff));
                self.events.push(ev(pl.t_stance, side, EventKind::ToeOff));
            }
            StepKind::Stop => {
                self.events.push(ev(0.0, side, EventKind::HeelStrike));
                self.events.push(ev(pl.t_flat, side, EventKind::FootFlat));
                self.events
                    .push(ev(pl.stop.t_land, other, EventKind::HeelStrike));
                self.events
                    .push(ev(pl.stop.t_land, other, EventKind::FootFlat));
            }
        }
        self.records.push(StepRecord {
            index: self.step,
            side,
            kind: pl.kind,
            start_s: t0,
            duration_s: pl.t_step,
            speed: pl.speed,
            step_length: pl.step_length,
            step_freq: pl.step_freq,
            t_flat: pl.t_flat,
            t_heel_off: pl.t_heel_off,
            t_toe_off: pl.t_stance,
            report: pl.report,
        });
    }

    /// Moves to the step containing time `t` (planning the steps in between).
    fn advance_to(&mut self, t: f64) -> Result<(), GenerateError> {
        while self.state != RunState::Stopped && t >= self.t0 + self.plan.t_step {
            if self.state == RunState::Stopping {
                self.state = RunState::Stopped;
                break;
            }
            self.carry = carry_out(&self.plan, &self.model.dims);
            self.t0 += self.plan.t_step;
            self.step += 1;
            self.apply_schedule()?;
            self.plan_current(StepKind::Normal)?;
        }
        Ok(())
    }

    /// The pose at time `t` (s, non-decreasing between calls), written into `pose`; returns the
    /// frame's contacts and foot points.
    pub fn pose_at(&mut self, t: f64, pose: &mut Pose) -> Result<FrameInfo, GenerateError> {
        self.advance_to(t)?;
        let rel = if self.state == RunState::Stopped {
            self.plan.t_step
        } else {
            (t - self.t0).max(0.0)
        };
        Ok(eval_frame(&self.plan, &self.model.dims, rel, pose))
    }

    /// Where the figure is now (pelvis), m.
    pub fn pelvis_start(&self) -> DVec3 {
        self.carry.pelvis
    }
}
