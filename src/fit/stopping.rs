//! MINPACK's stopping tests for argmin's trust region (argmin's `TrustRegion` has none of its
//! own): the relative step or trust radius below `xtol`, every Jacobian column within cosine
//! `gtol` of orthogonal to the residuals, a zero residual, a step below machine precision and,
//! when asked, the relative reduction below `ftol` (Moré, Garbow & Hillstrom 1980, MINPACK
//! `lmder`). Used by [`crate::fit::nonlinear::nls`] and by [`crate::calibrate`]'s trust region.
use argmin::core::{
    IterState, KvValue, Problem, Solver, State, TerminationReason, TerminationStatus, KV,
};
use nalgebra::{DMatrix, DVector};

/// The argmin state of a trust region on `DVector` parameters with a `DMatrix` Hessian.
pub(crate) type TrState = IterState<DVector<f64>, DVector<f64>, (), DMatrix<f64>, (), f64>;

/// Wraps an argmin trust-region solver and adds MINPACK-style stopping tests (argmin's
/// `TrustRegion` has none of its own). Also used by [`crate::calibrate`]'s trust region
/// (with the `ftol` test, which [`crate::fit::nonlinear::nls`] does not use).
pub(crate) struct Stopping<S> {
    inner: S,
    xtol: f64,
    gtol: f64,
    /// MINPACK's `ftol` (relative reduction of the sum of squares), tested on accepted steps.
    ftol: Option<f64>,
    accepted: u64,
    status: Option<String>,
    /// Trust radius of the previous iteration if its step was rejected.
    last_rejected_radius: Option<f64>,
}

impl<S> Stopping<S> {
    /// `inner` with MINPACK's `xtol` and `gtol` tests (and the zero-residual and
    /// machine-precision stops); no `ftol` test.
    pub(crate) fn new(inner: S, xtol: f64, gtol: f64) -> Self {
        Stopping {
            inner,
            xtol,
            gtol,
            ftol: None,
            accepted: 0,
            status: None,
            last_rejected_radius: None,
        }
    }

    /// Adds MINPACK's `ftol` test on every accepted step: the actual and the predicted
    /// (Gauss–Newton model) relative reductions of the objective both at most `ftol`, and the
    /// actual at most twice the predicted.
    pub(crate) fn with_ftol(mut self, ftol: f64) -> Self {
        self.ftol = Some(ftol);
        self
    }

    /// Steps accepted so far.
    pub(crate) fn accepted(&self) -> u64 {
        self.accepted
    }
}

fn vnorm(v: &DVector<f64>) -> f64 {
    v.norm()
}

impl<O, S> Solver<O, TrState> for Stopping<S>
where
    S: Solver<O, TrState>,
{
    fn name(&self) -> &str {
        "Trust region (Steihaug, Gauss-Newton Hessian) with MINPACK stopping tests"
    }
    fn init(
        &mut self,
        problem: &mut Problem<O>,
        state: TrState,
    ) -> Result<(TrState, Option<KV>), argmin::core::Error> {
        self.inner.init(problem, state)
    }
    fn next_iter(
        &mut self,
        problem: &mut Problem<O>,
        state: TrState,
    ) -> Result<(TrState, Option<KV>), argmin::core::Error> {
        let before = state.get_param().cloned();
        // The Gauss–Newton model at the current point, for the ftol test's predicted reduction.
        let model = self.ftol.and_then(|_| {
            Some((
                state.get_cost(),
                state.get_gradient()?.clone(),
                state.get_hessian()?.clone(),
            ))
        });
        let (state, kv) = self.inner.next_iter(problem, state)?;
        if let (Some(b), Some(a)) = (before, state.get_param()) {
            let scale = self.xtol * (vnorm(a) + self.xtol);
            if *a != b {
                self.accepted += 1;
                let step = a - &b;
                if vnorm(&step) <= scale {
                    self.status = Some("relative step below xtol".into());
                }
                if let (Some(ftol), Some((f0, g, h))) = (self.ftol, model) {
                    let predicted = -(step.dot(&g) + 0.5 * step.dot(&(&h * &step)));
                    let actual = f0 - state.get_cost();
                    if f0 > 0.0
                        && actual.abs() <= ftol * f0
                        && predicted <= ftol * f0
                        && actual <= 2.0 * predicted
                    {
                        self.status
                            .get_or_insert_with(|| "relative reduction below ftol".into());
                    }
                }
                self.last_rejected_radius = None;
            } else if let Some(KvValue::Float(radius)) = kv.as_ref().and_then(|k| k.get("radius")) {
                if *radius <= scale {
                    self.status = Some("trust radius below xtol".into());
                } else if self.last_rejected_radius == Some(*radius) {
                    // A rejected step shrinks the radius unless the reduction ratio is 0/0:
                    // the step is below the resolution of θ, i.e. converged to machine precision.
                    self.status = Some("step below machine precision".into());
                }
                self.last_rejected_radius = Some(*radius);
            }
        }
        Ok((state, kv))
    }
    fn terminate(&mut self, state: &TrState) -> TerminationStatus {
        if let Some(s) = &self.status {
            return TerminationStatus::Terminated(TerminationReason::SolverExit(s.clone()));
        }
        let cost = state.get_cost();
        if cost == 0.0 {
            return TerminationStatus::Terminated(TerminationReason::SolverExit(
                "zero residual".into(),
            ));
        }
        if let (Some(g), Some(h)) = (state.get_gradient(), state.get_hessian()) {
            let rn = (2.0 * cost).sqrt();
            let worst = (0..g.len())
                .map(|k| {
                    let cn = h[(k, k)].sqrt();
                    if cn > 0.0 {
                        g[k].abs() / (cn * rn)
                    } else {
                        0.0
                    }
                })
                .fold(0.0, f64::max);
            if worst <= self.gtol {
                return TerminationStatus::Terminated(TerminationReason::SolverExit(
                    "gradient orthogonal to residuals within gtol".into(),
                ));
            }
        }
        TerminationStatus::NotTerminated
    }
}
