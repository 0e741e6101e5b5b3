//! The four running parameters — speed v, step length sl, step frequency sf, flight height H —
//! plus expertise level and body height, coupled by eqs. 1–5 (§2.2, §3.1.1), with locks.
//!
//! "If one of the parameters is changed, the other ones are updated using equations 1, 2, 3, and
//! 4 or 5 … Parameters can be locked to produce somewhat unnatural strides." The paper does not
//! spell out which relation gives way when parameters are locked; the rule here (tested) is:
//!
//! * Eq. 1 (v = sl·sf) always holds.
//! * The fixed set is the parameter being changed plus the locked ones.
//! * Two of v, sl, sf fixed → the third by eq. 1; eq. 2 gives way (the paper's example: v locked
//!   at 12 km/h, sf raised 187 → 210 → sl 1.07 → 0.95 m).
//! * One of v, sl, sf fixed → eqs. 1–2 give the other two.
//! * H fixed (changed or locked) with at most one of v, sl, sf fixed → the free one of v, sl, sf
//!   moves along eqs. 1(–2) until eq. 3 (with eqs. 4–5 for t_flight) gives H: a 1-D root in sf
//!   (argmin's Brent). With sf also fixed, or two of v, sl, sf fixed, eqs. 4–5 give way instead:
//!   the flight time follows from H per step by case II (§3.2, Newton–Raphson).
//! * Three of v, sl, sf fixed while one of them changes → an error naming the locks.
//!
//! H depends on the pelvis heights at toe off and heel strike (y1, y2 in eq. 3), i.e. on the
//! figure and the attributes: it is computed from a steady-state step (the previous step ran
//! with the same parameters), exactly as the step planner does for every step.
use argmin::core::{CostFunction, Executor};
use argmin::solver::brent::BrentRoot;

use super::attributes::{Drivers, RunAttributes};
use super::dims::RunnerDims;
use super::equations::RunRelations;
use super::state::{state_keyframes, FlightSpec, Footprint, StepInput};
use crate::generator::skeleton::Skeleton;
use crate::generator::GenerateError;
use crate::units::{hz_to_steps_per_min, steps_per_min_to_hz};

/// One of the four parameters.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Param {
    /// Speed v, m/s.
    Speed,
    /// Step length sl, m.
    StepLength,
    /// Step frequency sf, steps/s.
    StepFreq,
    /// Flight height H, m.
    FlightHeight,
}

/// Which parameters are locked (kept when another one changes).
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct Locks {
    /// Speed locked.
    pub speed: bool,
    /// Step length locked.
    pub step_length: bool,
    /// Step frequency locked.
    pub step_freq: bool,
    /// Flight height locked.
    pub flight_height: bool,
}

impl Locks {
    /// Whether `p` is locked.
    pub fn get(&self, p: Param) -> bool {
        match p {
            Param::Speed => self.speed,
            Param::StepLength => self.step_length,
            Param::StepFreq => self.step_freq,
            Param::FlightHeight => self.flight_height,
        }
    }
    /// Locks or unlocks `p`.
    pub fn set(&mut self, p: Param, on: bool) {
        match p {
            Param::Speed => self.speed = on,
            Param::StepLength => self.step_length = on,
            Param::StepFreq => self.step_freq = on,
            Param::FlightHeight => self.flight_height = on,
        }
    }
}

/// A consistent set of running parameters (SI units).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RunParams {
    /// Speed, m/s.
    pub speed: f64,
    /// Step length, m.
    pub step_length: f64,
    /// Step frequency, steps/s.
    pub step_freq: f64,
    /// Steady-state flight height (eq. 3), m.
    pub flight_height: f64,
    /// Flight time, s.
    pub flight_time: f64,
    /// Expertise level in [−1 (poor), 1 (skilled)], scaled to the paper's ±0.001 (eq. 2) and
    /// ±0.0001 (eqs. 4–5).
    pub level: f64,
    /// Body height, m.
    pub body_height: f64,
    /// Locks.
    pub locks: Locks,
    /// When true the flight time of each step follows from H (case II); otherwise from sf by
    /// eqs. 4–5 (case I).
    pub flight_from_height: bool,
}

impl RunParams {
    /// The value of `p`.
    pub fn get(&self, p: Param) -> f64 {
        match p {
            Param::Speed => self.speed,
            Param::StepLength => self.step_length,
            Param::StepFreq => self.step_freq,
            Param::FlightHeight => self.flight_height,
        }
    }

    /// The flight specification a step is planned with.
    pub fn flight_spec(&self) -> FlightSpec {
        if self.flight_from_height {
            FlightSpec::Height {
                height: self.flight_height,
                near: self.flight_time,
            }
        } else {
            FlightSpec::Time(self.flight_time)
        }
    }

    /// Attribute drivers for these parameters.
    pub fn drivers(&self) -> Drivers {
        Drivers {
            speed: self.speed,
            step_length: self.step_length,
            step_freq: self.step_freq,
            flight_height: self.flight_height,
        }
    }
}

/// Accepted speeds, m/s (the paper shows 2–25 km/h; a little room either side).
pub const SPEED_RANGE: (f64, f64) = (0.3, 12.0);
/// Accepted body heights, m.
pub const HEIGHT_RANGE: (f64, f64) = (0.5, 2.6);
/// Step frequencies searched when H drives sf, steps/min (also the studio's slider range).
pub const SF_SEARCH: (f64, f64) = (60.0, 260.0);
/// Accepted expertise levels: −1 (poor) … 1 (skilled).
pub const LEVEL_RANGE: (f64, f64) = (-1.0, 1.0);

/// The figure and the relations a run is generated with.
#[derive(Debug, Clone, PartialEq)]
pub struct RunModel {
    /// The figure.
    pub skeleton: Skeleton,
    /// Segment dimensions (from the skeleton's anthropometry).
    pub dims: RunnerDims,
    /// Eqs. 2, 4, 5 (published or refitted).
    pub relations: RunRelations,
}

fn param_err(name: &str, value: f64, message: String) -> GenerateError {
    GenerateError::Parameter {
        name: name.into(),
        value,
        message,
    }
}

#[derive(Clone, Copy)]
struct HRoot<'a> {
    model: &'a RunModel,
    attrs: &'a RunAttributes,
    level: f64,
    target: f64,
    along: Along,
}

#[derive(Clone, Copy)]
enum Along {
    /// v fixed, sl = v/sf.
    Speed(f64),
    /// sl fixed, v = sl·sf.
    StepLength(f64),
    /// Natural: sl from sf by eqs. 1–2.
    Natural,
}

impl HRoot<'_> {
    fn triple(&self, sf: f64) -> Option<(f64, f64, f64)> {
        let h = self.model.dims.body_height;
        match self.along {
            Along::Speed(v) => Some((v, v / sf, sf)),
            Along::StepLength(sl) => Some((sl * sf, sl, sf)),
            Along::Natural => {
                let sl = self
                    .model
                    .relations
                    .step_length_for_freq(sf, self.level, h)?;
                Some((sl * sf, sl, sf))
            }
        }
    }
    fn h_at(&self, sf: f64) -> Option<f64> {
        let (v, sl, sf) = self.triple(sf)?;
        let t_f = self.model.relations.flight_time(sf, self.level);
        self.model
            .steady_flight(v, sl, sf, FlightSpec::Time(t_f), self.attrs)
            .ok()
            .map(|(h, _)| h)
    }
}

impl CostFunction for HRoot<'_> {
    type Param = f64;
    type Output = f64;
    fn cost(&self, sf: &f64) -> Result<f64, argmin::core::Error> {
        self.h_at(*sf)
            .map(|h| h - self.target)
            .ok_or_else(|| argmin::core::Error::msg("no steady step at this step frequency"))
    }
}

impl RunModel {
    /// A model of `skeleton` driven by `relations`.
    pub fn new(skeleton: Skeleton, relations: RunRelations) -> Result<Self, GenerateError> {
        check_height(skeleton.anthropometry().height_m)?;
        let dims = RunnerDims::from_anthropometry(skeleton.anthropometry());
        Ok(RunModel {
            skeleton,
            dims,
            relations,
        })
    }

    /// A model with the published relations for a figure of `body_height` m with table B-1
    /// proportions (body mass, which running kinematics do not use, set to a BMI of 22.5).
    pub fn published(body_height: f64) -> Result<Self, GenerateError> {
        check_height(body_height)?;
        let skeleton = Skeleton::from_height(body_height, default_mass(body_height))?;
        RunModel::new(skeleton, RunRelations::published())
    }

    /// Steady-state flight: (H, t_flight) of a step with these parameters when the previous
    /// step ran with the same ones.
    pub fn steady_flight(
        &self,
        v: f64,
        sl: f64,
        sf: f64,
        flight: FlightSpec,
        attrs: &RunAttributes,
    ) -> Result<(f64, f64), GenerateError> {
        let h_guess = match flight {
            FlightSpec::Height { height, .. } => height,
            FlightSpec::Time(_) => super::attributes::H_REF * self.dims.body_height / 1.8,
        };
        // Bounciness (the only H-coupled attribute) does not enter eq. 3, so any H will do here.
        let eff = attrs.effective(&Drivers {
            speed: v,
            step_length: sl,
            step_freq: sf,
            flight_height: h_guess,
        });
        let inp = StepInput {
            speed: v,
            step_length: sl,
            step_freq: sf,
            flight,
            eff,
            next_eff: eff,
            p: 0.75,
        };
        let fp = Footprint {
            heel: glam::DVec3::new(0.0, 0.0, eff.stride_width / 2.0),
            strike: eff.strike,
            impact_pitch: eff.impact_pitch,
        };
        let k = state_keyframes(&self.dims, &inp, 1.0, &fp)?;
        Ok((k.flight_height, k.t_flight))
    }

    fn finish(
        &self,
        v: f64,
        sl: f64,
        sf: f64,
        base: &RunParams,
        from_h: Option<f64>,
        attrs: &RunAttributes,
    ) -> Result<RunParams, GenerateError> {
        check_speed(v)?;
        if !(sl > 0.0 && sf > 0.0 && sl.is_finite() && sf.is_finite()) {
            return Err(param_err(
                "step_length",
                sl,
                format!("no positive step length/frequency (sl = {sl}, sf = {sf})"),
            ));
        }
        let (h, t_f, flight_from_height) = match from_h {
            Some(h) => {
                let near = self.relations.flight_time(sf, base.level);
                let spec = FlightSpec::Height { height: h, near };
                let (_, t_f) = self.steady_flight(v, sl, sf, spec, attrs)?;
                (h, t_f, true)
            }
            None => {
                let t_f = self.relations.flight_time(sf, base.level);
                let (h, _) = self.steady_flight(v, sl, sf, FlightSpec::Time(t_f), attrs)?;
                (h, t_f, false)
            }
        };
        Ok(RunParams {
            speed: v,
            step_length: sl,
            step_freq: sf,
            flight_height: h,
            flight_time: t_f,
            flight_from_height,
            ..*base
        })
    }

    /// The natural parameters at speed `v` (m/s): sl by eq. 2, sf by eq. 1, t_flight by eqs. 4–5,
    /// H by eq. 3.
    pub fn natural(
        &self,
        v: f64,
        level: f64,
        attrs: &RunAttributes,
    ) -> Result<RunParams, GenerateError> {
        check_level(level)?;
        check_speed(v)?;
        let h = self.dims.body_height;
        let sl = self.relations.step_length(v, level, h);
        let base = RunParams {
            speed: v,
            step_length: sl,
            step_freq: v / sl,
            flight_height: 0.0,
            flight_time: 0.0,
            level,
            body_height: h,
            locks: Locks::default(),
            flight_from_height: false,
        };
        self.finish(v, sl, v / sl, &base, None, attrs)
    }

    /// Changes parameter `which` to `value` and updates the others by the rule in the module
    /// docs, keeping locked parameters.
    pub fn set(
        &self,
        cur: &RunParams,
        which: Param,
        value: f64,
        attrs: &RunAttributes,
    ) -> Result<RunParams, GenerateError> {
        let name = match which {
            Param::Speed => "speed",
            Param::StepLength => "step_length",
            Param::StepFreq => "step_freq",
            Param::FlightHeight => "flight_height",
        };
        if !(value.is_finite() && value > 0.0) {
            return Err(param_err(name, value, "must be a positive number".into()));
        }
        let fixed = |p: Param| p == which || cur.locks.get(p);
        let (fv, fsl, fsf, fh) = (
            fixed(Param::Speed),
            fixed(Param::StepLength),
            fixed(Param::StepFreq),
            fixed(Param::FlightHeight),
        );
        let val = |p: Param| if p == which { value } else { cur.get(p) };
        let n = [fv, fsl, fsf].iter().filter(|b| **b).count();
        let lvl = cur.level;
        let h = self.dims.body_height;
        let rel = &self.relations;
        let target_h = fh.then(|| val(Param::FlightHeight));
        match n {
            3 => {
                if which == Param::FlightHeight {
                    let (v, sl, sf) = (cur.speed, cur.step_length, cur.step_freq);
                    return self.finish(v, sl, sf, cur, target_h, attrs);
                }
                Err(param_err(
                    name,
                    value,
                    "speed, step length and step frequency cannot all be fixed (eq. 1: v = sl·sf); unlock one of the other two".into(),
                ))
            }
            2 => {
                let (v, sl, sf) = if !fv {
                    (
                        val(Param::StepLength) * val(Param::StepFreq),
                        val(Param::StepLength),
                        val(Param::StepFreq),
                    )
                } else if !fsl {
                    (
                        val(Param::Speed),
                        val(Param::Speed) / val(Param::StepFreq),
                        val(Param::StepFreq),
                    )
                } else {
                    (
                        val(Param::Speed),
                        val(Param::StepLength),
                        val(Param::Speed) / val(Param::StepLength),
                    )
                };
                self.finish(v, sl, sf, cur, target_h, attrs)
            }
            1 if fsf && target_h.is_some() => {
                let sf = val(Param::StepFreq);
                let sl = rel
                    .step_length_for_freq(sf, lvl, h)
                    .ok_or_else(|| no_natural(sf))?;
                self.finish(sl * sf, sl, sf, cur, target_h, attrs)
            }
            1 if target_h.is_none() => {
                if fv {
                    let v = val(Param::Speed);
                    check_speed(v)?;
                    let sl = rel.step_length(v, lvl, h);
                    self.finish(v, sl, v / sl, cur, None, attrs)
                } else if fsl {
                    let sl = val(Param::StepLength);
                    match rel.speed_for_step_length(sl, lvl, h) {
                        Some(v) => self.finish(v, sl, v / sl, cur, None, attrs),
                        // Beyond the rising part of eq. 2 (sl above sl_norm or below a): keep
                        // the step frequency, and v follows by eq. 1.
                        None => {
                            self.finish(sl * cur.step_freq, sl, cur.step_freq, cur, None, attrs)
                        }
                    }
                } else {
                    let sf = val(Param::StepFreq);
                    let sl = rel
                        .step_length_for_freq(sf, lvl, h)
                        .ok_or_else(|| no_natural(sf))?;
                    self.finish(sl * sf, sl, sf, cur, None, attrs)
                }
            }
            _ => {
                // H fixed with v or sl or nothing among v, sl, sf: 1-D root in sf.
                let target = target_h.unwrap_or(cur.flight_height);
                let along = if fv {
                    Along::Speed(val(Param::Speed))
                } else if fsl {
                    Along::StepLength(val(Param::StepLength))
                } else {
                    Along::Natural
                };
                let root = HRoot {
                    model: self,
                    attrs,
                    level: lvl,
                    target,
                    along,
                };
                let sf = solve_sf(&root, cur.step_freq)?;
                let (v, sl, sf) = root.triple(sf).ok_or_else(|| no_natural(sf))?;
                self.finish(v, sl, sf, cur, None, attrs)
            }
        }
    }
}

fn no_natural(sf: f64) -> GenerateError {
    param_err(
        "step_freq",
        hz_to_steps_per_min(sf),
        "no natural step length at this step frequency (eqs. 1–2 need b·sf < 1); lock the speed or the step length".into(),
    )
}

/// Finds the step frequency whose steady flight height is the target: scan for sign changes,
/// take the bracket nearest the current sf, refine with argmin's Brent root finder. A bracket
/// across the jump of eqs. 4–5 at the knot is not a root and is rejected.
fn solve_sf(root: &HRoot<'_>, current: f64) -> Result<f64, GenerateError> {
    let n = 400;
    let (lo, hi) = (
        steps_per_min_to_hz(SF_SEARCH.0),
        steps_per_min_to_hz(SF_SEARCH.1),
    );
    let mut prev: Option<(f64, f64)> = None;
    let mut best: Option<(f64, f64, f64)> = None; // (distance, a, b)
    let (mut hmin, mut hmax) = (f64::INFINITY, f64::NEG_INFINITY);
    for i in 0..=n {
        let sf = lo + (hi - lo) * i as f64 / n as f64;
        let Some(hv) = root.h_at(sf) else {
            prev = None;
            continue;
        };
        hmin = hmin.min(hv);
        hmax = hmax.max(hv);
        let g = hv - root.target;
        if let Some((sa, ga)) = prev {
            if ga * g <= 0.0 {
                let dist = (0.5 * (sa + sf) - current).abs();
                if best.is_none_or(|b| dist < b.0) {
                    // Reject the jump at the eqs. 4–5 knot: check the bracket is continuous.
                    let mid = 0.5 * (sa + sf);
                    if root.h_at(mid).is_some() {
                        best = Some((dist, sa, sf));
                    }
                }
            }
        }
        prev = Some((sf, g));
    }
    let no = || {
        param_err(
            "flight_height",
            root.target,
            format!(
                "not reachable here: steady flight heights range over [{hmin:.4}, {hmax:.4}] m"
            ),
        )
    };
    let (_, a, b) = best.ok_or_else(no)?;
    let target = root.target;
    let solver = BrentRoot::new(a, b, 1e-12);
    let problem = HRoot { ..*root };
    let res = Executor::new(problem, solver)
        .configure(|s| s.max_iters(200))
        .run()
        .map_err(|e| {
            param_err(
                "flight_height",
                target,
                format!("root search for sf failed: {e}"),
            )
        })?;
    let sf = res.state.best_param.ok_or_else(no)?;
    let resid = root
        .h_at(sf)
        .map(|h| (h - target).abs())
        .unwrap_or(f64::INFINITY);
    if resid > 1e-7 {
        return Err(param_err(
            "flight_height",
            target,
            format!(
                "falls in the jump of eqs. 4–5 at the knot (closest {:.4} m at {:.1} steps/min)",
                root.h_at(sf).unwrap_or(f64::NAN),
                hz_to_steps_per_min(sf)
            ),
        ));
    }
    Ok(sf)
}

/// Body mass used when none is given, kg (BMI 22.5; running kinematics do not depend on it).
pub fn default_mass(body_height: f64) -> f64 {
    22.5 * body_height * body_height
}

fn check_speed(v: f64) -> Result<(), GenerateError> {
    if !(v >= SPEED_RANGE.0 && v <= SPEED_RANGE.1) {
        return Err(param_err(
            "speed",
            v,
            format!(
                "m/s must be within [{}, {}] m/s ({:.1}–{:.1} km/h)",
                SPEED_RANGE.0,
                SPEED_RANGE.1,
                SPEED_RANGE.0 * 3.6,
                SPEED_RANGE.1 * 3.6
            ),
        ));
    }
    Ok(())
}

fn check_height(h: f64) -> Result<(), GenerateError> {
    if !(h >= HEIGHT_RANGE.0 && h <= HEIGHT_RANGE.1) {
        return Err(param_err(
            "body_height",
            h,
            format!(
                "m must be within [{}, {}] m",
                HEIGHT_RANGE.0, HEIGHT_RANGE.1
            ),
        ));
    }
    Ok(())
}

fn check_level(level: f64) -> Result<(), GenerateError> {
    if !(LEVEL_RANGE.0..=LEVEL_RANGE.1).contains(&level) {
        return Err(param_err(
            "level",
            level,
            "must be within [−1 (poor), 1 (skilled)]".into(),
        ));
    }
    Ok(())
}
