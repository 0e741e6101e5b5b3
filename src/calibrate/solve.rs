//! The calibration objective and its Gauss–Newton minimisation (argmin's `GaussNewton`).
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
//! The Jacobian is by forward differences (steps in [`super::drive::AttrDef::step`]); the
//! standard errors are those of the Gauss–Newton covariance `s² (JᵀJ)⁻¹`, `s²` the residual
//! variance (RSS / (n − p)).
use super::drive::{self, attr_defs, Relations};
use super::measure::Measurement;
use super::{measure_generated, CalibrateError, CalibrateOptions, Subject, SubjectResult};
use crate::events::Gait;
use argmin::core::{CostFunction, Executor, Jacobian, Operator, State};
use argmin::solver::gaussnewton::GaussNewton;
use nalgebra::{DMatrix, DVector};
use rayon::prelude::*;
use std::sync::atomic::{AtomicUsize, Ordering};

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
    /// The attributes (see [`drive::attr_defs`]).
    pub theta: [f64; 3],
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
    rel: &'a Relations,
    opts: &'a CalibrateOptions,
    /// (condition, quantity, measured, σ)
    terms: Vec<(usize, usize, f64, f64)>,
    evals: AtomicUsize,
}

impl Problem<'_> {
    fn new<'a>(
        subject: &'a Subject,
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
            rel,
            opts,
            terms,
            evals: AtomicUsize::new(0),
        }
    }

    fn stage(&self, theta: &[f64; 3]) -> Stage {
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
                    theta,
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
            theta: *theta,
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

    fn theta_of(p: &DVector<f64>) -> [f64; 3] {
        [p[0], p[1], p[2]]
    }

    fn clamp(&self, p: &DVector<f64>) -> [f64; 3] {
        let d = attr_defs(self.subject.gait);
        let t = Self::theta_of(p);
        [0, 1, 2].map(|i| t[i].clamp(d[i].range.0, d[i].range.1))
    }
}

impl Operator for Problem<'_> {
    type Param = DVector<f64>;
    type Output = DVector<f64>;
    fn apply(&self, p: &Self::Param) -> Result<Self::Output, argmin::core::Error> {
        let st = self.stage(&self.clamp(p));
        Ok(self.residuals_of(&st.generated))
    }
}

impl CostFunction for Problem<'_> {
    type Param = DVector<f64>;
    type Output = f64;
    fn cost(&self, p: &Self::Param) -> Result<f64, argmin::core::Error> {
        Ok(self.stage(&self.clamp(p)).cost)
    }
}

impl Jacobian for Problem<'_> {
    type Param = DVector<f64>;
    type Jacobian = DMatrix<f64>;
    fn jacobian(&self, p: &Self::Param) -> Result<Self::Jacobian, argmin::core::Error> {
        Ok(self.jacobian_at(&self.clamp(p)))
    }
}

impl Problem<'_> {
    /// Forward differences, stepping inward at the upper bound.
    fn jacobian_at(&self, theta: &[f64; 3]) -> DMatrix<f64> {
        let defs = attr_defs(self.subject.gait);
        let r0 = self.residuals_of(&self.stage(theta).generated);
        let cols: Vec<DVector<f64>> = (0..3)
            .into_par_iter()
            .map(|j| {
                let mut t = *theta;
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

/// Runs both stages for one subject: the relations with the attributes' initial values, then
/// Gauss–Newton from there (the best point visited is kept).
pub fn calibrate_subject(
    subject: Subject,
    rel: &Relations,
    opts: &CalibrateOptions,
) -> Result<SubjectResult, CalibrateError> {
    let init = drive::initial(subject.gait, subject.body_height_m);
    let (before, after, se, iters, evals) = {
        let problem = Problem::new(&subject, rel, opts);
        let before = problem.stage(&init);
        let solver: GaussNewton<f64> = GaussNewton::new();
        let res = Executor::new(problem, solver)
            .configure(|s| {
                s.param(DVector::from_row_slice(&init))
                    .max_iters(opts.max_iters)
            })
            .run();
        let problem = Problem::new(&subject, rel, opts);
        let (theta, iters) = match res {
            Ok(r) => {
                let st = r.state();
                let p = st
                    .get_best_param()
                    .cloned()
                    .unwrap_or_else(|| DVector::from_row_slice(&init));
                (problem.clamp(&p), st.get_iter())
            }
            Err(_) => (init, 0),
        };
        let mut after = problem.stage(&theta);
        let mut theta = theta;
        if after.cost > before.cost {
            // Gauss–Newton did not improve on the start (noisy objective): keep the start.
            after = before.clone();
            theta = init;
        }
        let j = problem.jacobian_at(&theta);
        let r = problem.residuals_of(&after.generated);
        let (n, p) = (r.len(), 3usize);
        let s2 = if n > p {
            r.norm_squared() / (n - p) as f64
        } else {
            1.0
        };
        let jtj = j.transpose() * &j;
        let se = match jtj.try_inverse() {
            Some(inv) => [0, 1, 2].map(|i| {
                let v = s2 * inv[(i, i)];
                (v.is_finite() && v >= 0.0).then(|| v.sqrt())
            }),
            None => [None; 3],
        };
        let evals = problem.evals.load(Ordering::Relaxed);
        (before, after, se, iters, evals)
    };
    Ok(SubjectResult {
        subject,
        before,
        after,
        se,
        iterations: iters,
        evaluations: evals,
        kb: None,
    })
}
