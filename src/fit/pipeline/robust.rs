//! The Huber M-estimate beside least squares (`--robust`), with Huber's H1 sandwich.
use super::{opt, Prepared, CONFIDENCE, HUBER_K, HUBER_MAX_ITER};
use crate::fit::design::{Layout, MAX_BASIS};
use crate::fit::forms::Fitting;
use crate::fit::ols::{huber_irls, LinearProblem};
use crate::fit::record::{CoefficientRecord, RobustRecord};
use crate::fit::stats::t_quantile;
use crate::fit::FitError;
use crate::relations::{ParamKind, Relation};
use nalgebra::{DMatrix, DVector};

/// The Huber refit of the linear coefficients at the breakpoint estimates (dense design: the
/// per-subject column, if any, as one column per subject).
#[allow(clippy::too_many_arguments)]
pub(super) fn robust_refit(
    rel: &dyn Relation,
    lay: &Layout,
    p: &[f64],
    prep: &Prepared,
    free: &[bool],
    held_reason: &[Option<String>],
    published: &[f64],
    weighted: bool,
) -> Result<RobustRecord, FitError> {
    let n = prep.obs.len();
    let n_subj = prep.subjects.len();
    let m = lay.m();
    let nfe = if lay.subj_col.is_some() { n_subj } else { 0 };
    let nc = m + nfe;
    let mut x = DMatrix::<f64>::zeros(n, nc);
    let mut y = DVector::<f64>::zeros(n);
    let mut g = [0.0; MAX_BASIS];
    for i in 0..n {
        let (off, z) = lay.row(rel, p, &prep.obs[i].x, &mut g[..m]);
        for j in 0..m {
            x[(i, j)] = g[j];
        }
        if nfe > 0 {
            x[(i, m + prep.subject[i])] = z;
        }
        y[i] = prep.obs[i].y - off;
    }
    let w = DVector::from_vec(prep.weights.clone());
    let id = rel.card().id;
    let mut problem = LinearProblem::new(&x, &y).named(id);
    if weighted {
        problem = problem.with_weights(&w);
    }
    let h = huber_irls(&problem, HUBER_K, HUBER_MAX_ITER)?;
    // Design coefficients → basis coefficients (mean slope) → raw linear parameters.
    let mut e = DMatrix::zeros(lay.nb, nc);
    let mut gi = 0;
    for j in 0..lay.nb {
        if Some(j) == lay.subj_col {
            for s in 0..n_subj {
                e[(j, m + s)] = 1.0 / n_subj as f64;
            }
        } else {
            e[(j, gi)] = 1.0;
            gi += 1;
        }
    }
    let lm = rel.basis_to_params(p, free);
    let gmap = &lm.map * e;
    let rout = &gmap * &h.fit.coef + &lm.shift;
    // Huber's H1 sandwich (statsmodels RLM's default), not the last weighted fit's covariance.
    let rcov = &gmap * &h.cov * gmap.transpose();
    let df = h.fit.df_resid as f64;
    let tq = t_quantile(0.5 + 0.5 * CONFIDENCE, df);
    let mut rc = Vec::new();
    let mut j = 0;
    for (i, s) in rel.card().parameters.iter().enumerate() {
        if s.kind != ParamKind::Linear {
            continue;
        }
        let se = free[i].then(|| rcov[(j, j)].max(0.0).sqrt());
        rc.push(CoefficientRecord {
            name: s.name.to_string(),
            unit: s.unit.to_string(),
            value: rout[j],
            std_error: se,
            ci95: se.map_or([None, None], |se| {
                [opt(rout[j] - tq * se), opt(rout[j] + tq * se)]
            }),
            published: s.cited.then_some(published[i]),
            t_test: None,
            std_error_conditional: None,
            inference: None,
            ci95_bootstrap: None,
            se_bootstrap: None,
            held: if free[i] {
                None
            } else {
                held_reason[i].clone()
            },
            flag: None,
        });
        j += 1;
    }
    Ok(RobustRecord {
        k: h.k,
        scale: h.scale,
        iterations: h.iterations,
        converged: h.converged,
        rows_downweighted: h.robust_weights.iter().filter(|&&u| u < 1.0).count(),
        cov: Some(format!(
            "Huber's sandwich with his small-sample correction (H1, as statsmodels RLM's \
             default): κ²·[Σψ²/(n − p)]·s²/[Σψ'/n]²·(XᵀWX)⁻¹ on the design at the breakpoint \
             estimates{}; rows treated as independent; intervals t with {df} df",
            if nfe > 0 {
                " with one slope column per subject (the global slope is their mean)"
            } else {
                ""
            }
        )),
        coefficients: rc,
    })
}
