//! The calibration objective and its minimisation: Gauss–Newton in a trust region (argmin's
//! `TrustRegion` with the Steihaug subproblem on the Gauss–Newton Hessian `JᵀJ`).
//!
//! Objective, per subject: `½ Σ_c Σ_q ((g_cq(θ) − m_cq) / σ_cq)²` over the subject's
//! conditions c (trials) and quantities q — cadence, step length, flight time (runs) or double
//! support (walks), pelvis vertical excursion — where `g` is the quantity
//! measured on the generated motion and `m` on the measured trial. The weight `σ_cq` is the
//! measured step-to-step standard deviation of the quantity in that trial (the subject's own
//! variability), floored at the resolution of the measurement (0.5 steps/min, 5 mm, one
//! generated frame, 0.5 % of the cycle, 2 mm). A quantity the generated motion does not show
//! (no flight detected, a failed generation) enters as a residual of 10 σ.
//!
//! The contact (stance) time is reported but not fitted: it is not a quantity of its own but
//! the step time and the flight or double support together (run: contact = 1/sf − t_flight;
//! walk: stance = t_cycle/2 + t_ds), so fitting it counts the cadence's residual a second
//! time, in the flight or double support's place. With it in the objective, Schreiber 2014001
//! (C4, C5), whose cadence one step-length offset cannot fit at both speeds (+1.0 and
//! −2.8 steps/min), had its double support pushed to +1.4/+1.0 % of the cycle to make up the
//! contact the cadence missed.
//!
//! The parameters are the attributes of [`drive::attr_defs`], plus the offsets' speed slopes
//! with `--speed-slopes` for a subject measured at two or more speeds ([`AttrModel`]).
//!
//! The Jacobian is by forward differences (steps in [`AttrModel::params`]); the standard errors
//! are those of the Gauss–Newton covariance `s² (JᵀJ)⁻¹`, `s²` the residual variance
//! (RSS / (n − p)).
//!
//! Why a trust region and not plain Gauss–Newton (argmin's `GaussNewton`, used before): the
//! generated quantities move in whole frames (every generated step is alike), so the
//! finite-difference Jacobian is noisy and `JᵀJ` near-singular along the weakly identified
//! attributes (leg stiffness, slopes). The full Gauss–Newton step then left the admissible
//! range (Schreiber 2014004 and 2014007: the double-support offset to ±20 %, the objective up
//! from 38 to 550) and no iterate improved on the start, which was kept (2014007's double
//! support −1.8 / −4.0 % of the cycle after "calibration"). The trust region accepts a step
//! only when the objective falls, and shrinks it otherwise.
//!
//! Stopping: MINPACK's convergence tests, through the same argmin wrapper as
//! [`crate::fit::nonlinear::nls`] (`fit::stopping::Stopping`): an accepted step that lowered
//! the objective by at most [`FTOL`] relative (and the model predicted no more), a step or a
//! trust radius below [`XTOL`] relative to the parameters, every Jacobian column within cosine
//! [`GTOL`] of orthogonal to the residuals, or a zero residual. Otherwise the solver stops at
//! `CalibrateOptions::max_iters`, and says so ([`Termination`]: "NOT converged: iteration cap
//! (N) reached" in the summary line, report.html and calibrated.json). On a quantised
//! objective the usual stop is the radius test: steps shorter than the objective's resolution
//! are rejected until the radius falls below [`XTOL`].
use super::drive::{self, AttrModel, Relations};
use super::measure::Measurement;
use super::{measure_generated, CalibrateError, CalibrateOptions, Subject, SubjectResult};
use crate::events::Gait;
use crate::fit::stopping::Stopping;
use argmin::core::{CostFunction, Executor, Gradient, Hessian, State, TerminationReason};
use argmin::solver::trustregion::{Steihaug, TrustRegion};
use nalgebra::{DMatrix, DVector};
use rayon::prelude::*;
use serde::{Deserialize, Serialize};
use std::sync::atomic::{AtomicUsize, Ordering};

/// MINPACK's `ftol` of the calibration: stop when an accepted step lowered the objective by at
/// most this fraction and the Gauss–Newton model predicted no more. The objective is in units
/// of the subject's step-to-step variability; a thousandth of it is far below what the
/// generated motion resolves (its quantities move in whole frames).
pub const FTOL: f64 = 1e-3;

/// MINPACK's `xtol` of the calibration: stop when the step, or the trust radius after a
/// rejected step, is below `XTOL·(‖u‖ + XTOL)`, `u` the parameters in finite-difference steps.
/// ‖u‖ is 10–25 (bounciness or leg stiffness in steps of 2), so the test stops at ~0.01–0.03
/// of a finite-difference step: 0.1–0.3 mm of step-length offset, ~0.1 ms of flight offset,
/// far below one generated frame and below every attribute's standard error.
pub const XTOL: f64 = 1e-3;

/// MINPACK's `gtol` of the calibration: stop when every Jacobian column is within this cosine
/// of orthogonal to the residual vector (a stationary point of the objective).
pub const GTOL: f64 = 1e-3;

/// How a subject's trust region stopped.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Termination {
    /// A convergence test ([`FTOL`], [`XTOL`], [`GTOL`], zero residual, step below machine
    /// precision) was met; `false`: the iteration cap was reached or the solver failed.
    pub converged: bool,
    /// Why it stopped, e.g. "relative reduction below ftol", "iteration cap (8) reached".
    pub reason: String,
    /// Trust-region iterations run (accepted and rejected steps).
    pub iterations: u64,
    /// Objective evaluations (each one generates and measures every condition of the subject).
    pub evaluations: usize,
}

impl Termination {
    /// "converged after 5 iteration(s): relative reduction below ftol", or "NOT converged: …".
    pub fn describe(&self) -> String {
        if self.converged {
            format!(
                "converged after {} iteration(s): {}",
                self.iterations, self.reason
            )
        } else {
            format!("NOT converged: {}", self.reason)
        }
    }
}

/// Residual given to a quantity the generated motion does not show, in units of σ.
pub const MISSING_RESIDUAL: f64 = 10.0;

/// The quantities of the objective, in the order of `Quantities::sd`.
pub const QUANTITIES: [&str; 5] = [
    "cadence_steps_per_min",
    "step_length_m",
    "contact_time_s",
    "flight_or_double_support",
    "pelvis_excursion_m",
];

/// A stage: the attributes and what the generator made of them at every condition.
#[derive(Debug, Clone)]
pub struct Stage {
    /// The parameters: the attributes (see [`drive::attr_defs`]), then their speed slopes
    /// when the subject's [`AttrModel`] has them.
    pub params: Vec<f64>,
    /// The generated measurement per condition (`Err`: why there is none).
    pub generated: Vec<Result<Measurement, String>>,
    /// Objective value ½‖r‖².
    pub cost: f64,
    /// Generator notes (deduplicated).
    pub notes: Vec<String>,
}

/// The quantities the objective fits (indices in [`QUANTITIES`]): all but the contact time,
/// which the cadence and the flight or double support determine (see the module docs).
pub const FITTED: [usize; 4] = [0, 1, 3, 4];

/// The value of quantity `q` (index in [`QUANTITIES`]) of a measurement.
pub fn value(m: &Measurement, q: usize) -> Option<f64> {
    let x = &m.quantities;
    match q {
        0 => Some(x.cadence_steps_per_min),
        1 => Some(x.step_length_m),
        2 => x.contact_time_s,
        3 => match m.gait {
            Gait::Run => x.flight_time_s,
            Gait::Walk => x.double_support_pct_cycle,
        },
        4 => x.pelvis_excursion_m,
        _ => None,
    }
}

fn floor(q: usize, gait: Gait, fps: f64) -> f64 {
    match q {
        0 => 0.5,
        1 => 0.005,
        2 => 1.0 / fps,
        3 if gait == Gait::Run => 1.0 / fps,
        3 => 0.5,
        _ => 0.002,
    }
}

struct Problem<'a> {
    subject: &'a Subject,
    model: AttrModel,
    rel: &'a Relations,
    opts: &'a CalibrateOptions,
    /// (condition, quantity, measured, σ)
    terms: Vec<(usize, usize, f64, f64)>,
    evals: AtomicUsize,
}

impl Problem<'_> {
    fn new<'a>(
        subject: &'a Subject,
        model: AttrModel,
        rel: &'a Relations,
        opts: &'a CalibrateOptions,
    ) -> Problem<'a> {
        let mut terms = Vec::new();
        for (c, cond) in subject.conditions.iter().enumerate() {
            for q in FITTED {
                if let Some(m) = value(&cond.measured, q) {
                    let sd = cond.measured.quantities.sd[q].unwrap_or(0.0);
                    let s = sd.max(floor(q, subject.gait, opts.drive.fps));
                    terms.push((c, q, m, s));
                }
            }
        }
        Problem {
            subject,
            model,
            rel,
            opts,
            terms,
            evals: AtomicUsize::new(0),
        }
    }

    fn stage(&self, params: &[f64]) -> Stage {
        self.evals.fetch_add(1, Ordering::Relaxed);
        let s = self.subject;
        let results: Vec<(Result<Measurement, String>, Vec<String>)> = s
            .conditions
            .par_iter()
            .map(|c| {
                match drive::drive(
                    self.rel,
                    s.gait,
                    c.speed(),
                    s.body_height_m,
                    s.mass_kg,
                    &self.model.at(params, c.speed()),
                    &self.opts.drive,
                ) {
                    Ok(d) => (
                        measure_generated(&d, s.gait).map_err(|e| e.to_string()),
                        d.notes,
                    ),
                    Err(e) => (Err(e.to_string()), Vec::new()),
                }
            })
            .collect();
        let mut notes: Vec<String> = results.iter().flat_map(|r| r.1.clone()).collect();
        notes.sort();
        notes.dedup();
        let generated: Vec<_> = results.into_iter().map(|r| r.0).collect();
        let r = self.residuals_of(&generated);
        Stage {
            params: params.to_vec(),
            cost: 0.5 * r.norm_squared(),
            generated,
            notes,
        }
    }

    fn residuals_of(&self, generated: &[Result<Measurement, String>]) -> DVector<f64> {
        DVector::from_iterator(
            self.terms.len(),
            self.terms.iter().map(|&(c, q, m, s)| {
                match generated[c].as_ref().ok().and_then(|g| value(g, q)) {
                    Some(g) => (g - m) / s,
                    None => MISSING_RESIDUAL,
                }
            }),
        )
    }

    fn clamp(&self, p: &DVector<f64>) -> Vec<f64> {
        self.model
            .params()
            .iter()
            .zip(p.iter())
            .map(|(d, &x)| x.clamp(d.range.0, d.range.1))
            .collect()
    }
}

/// A Jacobian (in scaled coordinates) and the residuals at a parameter vector.
type JacobianAt = (Vec<f64>, DMatrix<f64>, DVector<f64>);

/// The objective in scaled coordinates `u = p / step` (each parameter in units of its
/// finite-difference step, so that one trust radius suits offsets in metres, percentages and
/// stiffnesses alike), with the Gauss–Newton Hessian `JᵀJ`: argmin's trust region on this is a
/// Levenberg–Marquardt-like Gauss–Newton that only accepts a step that lowers the objective.
struct Scaled<'a, 'b> {
    problem: &'b Problem<'a>,
    steps: Vec<f64>,
    /// The last Jacobian (in u) and residuals, by parameter: the gradient and the Hessian of a
    /// point share one.
    cache: std::sync::Mutex<Option<JacobianAt>>,
}

impl Scaled<'_, '_> {
    fn params(&self, u: &DVector<f64>) -> Vec<f64> {
        let p = DVector::from_iterator(u.len(), u.iter().zip(&self.steps).map(|(u, s)| u * s));
        self.problem.clamp(&p)
    }

    fn jacobian_residuals(&self, u: &DVector<f64>) -> (DMatrix<f64>, DVector<f64>) {
        let p = self.params(u);
        let mut cache = self.cache.lock().unwrap_or_else(|e| e.into_inner());
        if let Some((q, j, r)) = cache.as_ref() {
            if *q == p {
                return (j.clone(), r.clone());
            }
        }
        let mut j = self.problem.jacobian_at(&p);
        for (mut col, s) in j.column_iter_mut().zip(&self.steps) {
            col *= *s;
        }
        let r = self.problem.residuals_of(&self.problem.stage(&p).generated);
        *cache = Some((p, j.clone(), r.clone()));
        (j, r)
    }
}

impl CostFunction for Scaled<'_, '_> {
    type Param = DVector<f64>;
    type Output = f64;
    fn cost(&self, u: &Self::Param) -> Result<f64, argmin::core::Error> {
        Ok(self.problem.stage(&self.params(u)).cost)
    }
}

impl Gradient for Scaled<'_, '_> {
    type Param = DVector<f64>;
    type Gradient = DVector<f64>;
    fn gradient(&self, u: &Self::Param) -> Result<Self::Gradient, argmin::core::Error> {
        let (j, r) = self.jacobian_residuals(u);
        Ok(j.transpose() * r)
    }
}

impl Hessian for Scaled<'_, '_> {
    type Param = DVector<f64>;
    type Hessian = DMatrix<f64>;
    fn hessian(&self, u: &Self::Param) -> Result<Self::Hessian, argmin::core::Error> {
        let (j, _) = self.jacobian_residuals(u);
        Ok(j.transpose() * j)
    }
}

impl Problem<'_> {
    /// Forward differences, stepping inward at the upper bound.
    fn jacobian_at(&self, theta: &[f64]) -> DMatrix<f64> {
        let defs = self.model.params();
        let r0 = self.residuals_of(&self.stage(theta).generated);
        let cols: Vec<DVector<f64>> = (0..defs.len())
            .into_par_iter()
            .map(|j| {
                let mut t = theta.to_vec();
                let h = if t[j] + defs[j].step > defs[j].range.1 {
                    -defs[j].step
                } else {
                    defs[j].step
                };
                t[j] += h;
                (self.residuals_of(&self.stage(&t).generated) - &r0) / h
            })
            .collect();
        DMatrix::from_columns(&cols)
    }
}

/// The attribute model of `subject`: speed slopes on the relation offsets when
/// `opts.speed_slopes` and the subject has two or more speeds ([`AttrModel::for_speeds`]).
pub fn model_of(subject: &Subject, opts: &CalibrateOptions) -> AttrModel {
    let speeds: Vec<f64> = subject.conditions.iter().map(|c| c.speed()).collect();
    // The longest measured stride (two steps) of the subject.
    let cycle_s = subject
        .conditions
        .iter()
        .map(|c| 120.0 / c.measured.quantities.cadence_steps_per_min)
        .filter(|t| t.is_finite())
        .fold(0.0, f64::max);
    AttrModel::for_speeds(
        subject.gait,
        &speeds,
        opts.speed_slopes,
        opts.drive.fps,
        if cycle_s > 0.0 { cycle_s } else { 1.0 },
    )
}

/// Initial and largest trust radius, in finite-difference steps of each parameter (see
/// the scaled objective): the first step moves no parameter by more than 3 of its steps (an offset by
/// 3 cm, 15 ms of flight or ~5 % of double support), the radius then grows up to 40 steps as
/// the quadratic model keeps predicting the objective.
pub const TRUST_RADIUS: (f64, f64) = (3.0, 40.0);

/// Runs both stages for one subject: the relations with the attributes' initial values, then
/// the trust-region Gauss–Newton (parameters scaled by their finite-difference steps) from there (the best point visited is kept).
pub fn calibrate_subject(
    subject: Subject,
    rel: &Relations,
    opts: &CalibrateOptions,
) -> Result<SubjectResult, CalibrateError> {
    let mut subject = subject;
    let model = model_of(&subject, opts);
    let init = model.initial(subject.body_height_m);
    let (before, after, se, termination, note) = {
        let problem = Problem::new(&subject, model, rel, opts);
        let before = problem.stage(&init);
        let steps: Vec<f64> = model.params().iter().map(|d| d.step).collect();
        let u0 = DVector::from_iterator(init.len(), init.iter().zip(&steps).map(|(p, s)| p / s));
        let scaled = Scaled {
            problem: &problem,
            steps: steps.clone(),
            cache: std::sync::Mutex::new(None),
        };
        let res = TrustRegion::new(Steihaug::new())
            .with_radius(TRUST_RADIUS.0)
            .and_then(|t| t.with_max_radius(TRUST_RADIUS.1))
            .and_then(|tr| {
                let solver = Stopping::new(tr, XTOL, GTOL).with_ftol(FTOL);
                Executor::new(scaled, solver)
                    .configure(|s| s.param(u0.clone()).max_iters(opts.max_iters))
                    .timer(false)
                    .run()
            });
        let mut note = None;
        let (theta, termination) = match res {
            Ok(r) => {
                let st = r.state();
                let u = st.get_best_param().cloned().unwrap_or(u0);
                let p = DVector::from_iterator(u.len(), u.iter().zip(&steps).map(|(u, s)| u * s));
                let (converged, reason) = match st.get_termination_reason() {
                    Some(TerminationReason::SolverExit(why)) => (true, why.clone()),
                    Some(TerminationReason::MaxItersReached) => {
                        (false, format!("iteration cap ({}) reached", opts.max_iters))
                    }
                    Some(other) => (false, other.text().to_string()),
                    None => (false, "the solver stopped without a reason".into()),
                };
                let t = Termination {
                    converged,
                    reason,
                    iterations: st.get_iter(),
                    evaluations: 0,
                };
                (problem.clamp(&p), t)
            }
            Err(e) => {
                note = Some(format!(
                    "calibration: the trust-region solver failed ({e}); the relations' attributes are kept"
                ));
                let t = Termination {
                    converged: false,
                    reason: format!("the solver failed: {e}"),
                    iterations: 0,
                    evaluations: 0,
                };
                (init.clone(), t)
            }
        };
        let mut after = problem.stage(&theta);
        let mut theta = theta;
        if after.cost > before.cost {
            // Gauss–Newton did not improve on the start (noisy objective): keep the start.
            note = Some(format!(
                "calibration: the best point found (objective {:.3}) is worse than the relations' \
                 attributes ({:.3}); they are kept",
                after.cost, before.cost
            ));
            after = before.clone();
            theta = init;
        }
        let j = problem.jacobian_at(&theta);
        let r = problem.residuals_of(&after.generated);
        let (n, p) = (r.len(), model.len());
        let s2 = if n > p {
            r.norm_squared() / (n - p) as f64
        } else {
            1.0
        };
        let jtj = j.transpose() * &j;
        let se = match jtj.try_inverse() {
            Some(inv) => (0..p)
                .map(|i| {
                    let v = s2 * inv[(i, i)];
                    (v.is_finite() && v >= 0.0).then(|| v.sqrt())
                })
                .collect(),
            None => vec![None; p],
        };
        let mut termination = termination;
        termination.evaluations = problem.evals.load(Ordering::Relaxed);
        (before, after, se, termination, note)
    };
    // Said in the report and the summary, not only by an unchanged objective.
    subject.notes.extend(note);
    Ok(SubjectResult {
        subject,
        model,
        before,
        after,
        se,
        termination,
        kb: None,
        held_out: None,
    })
}

/// Leave one speed out: for every condition of a subject with two or more, the attributes are
/// calibrated on the subject's other conditions (with speed slopes when two or more remain,
/// as [`model_of`] decides) and the left-out condition is generated with them at its speed —
/// a prediction, extrapolated at the subject's slowest and fastest speeds. The stage's cost is
/// that of these predictions on the full objective; its `params` are empty (one set per
/// condition). `None` for a subject with one condition.
pub fn leave_one_speed_out(
    subject: &Subject,
    rel: &Relations,
    opts: &CalibrateOptions,
) -> Result<Option<Stage>, CalibrateError> {
    if subject.conditions.len() < 2 {
        return Ok(None);
    }
    let mut generated = Vec::new();
    let mut notes = Vec::new();
    for c in 0..subject.conditions.len() {
        let mut rest = subject.clone();
        let held = rest.conditions.remove(c);
        let r = calibrate_subject(rest, rel, opts)?;
        let theta = r.model.at(&r.after.params, held.speed());
        match drive::drive(
            rel,
            subject.gait,
            held.speed(),
            subject.body_height_m,
            subject.mass_kg,
            &theta,
            &opts.drive,
        ) {
            Ok(d) => {
                generated.push(measure_generated(&d, subject.gait).map_err(|e| e.to_string()));
                notes.extend(d.notes);
            }
            Err(e) => generated.push(Err(e.to_string())),
        }
    }
    notes.sort();
    notes.dedup();
    let model = model_of(subject, opts);
    let problem = Problem::new(subject, model, rel, opts);
    let cost = 0.5 * problem.residuals_of(&generated).norm_squared();
    Ok(Some(Stage {
        params: Vec::new(),
        generated,
        cost,
        notes,
    }))
}
