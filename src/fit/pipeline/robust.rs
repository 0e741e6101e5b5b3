//! The Huber M-estimate beside least squares (`--robust`): Huber's H1 sandwich with rows
//! independent (`--se iid`), else the cluster-robust sandwich by subject (CR1).
use super::{opt, Prepared, CONFIDENCE, HUBER_K, HUBER_MAX_ITER};
use crate::fit::design::{Layout, MAX_BASIS};
use crate::fit::forms::Fitting;
use crate::fit::inference::SeMethod;
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
    method: SeMethod,
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
    // Clustered by subject when the fit is (and no column is one subject's alone: a
    // per-subject column's score sums to zero within its subject, so no clustered covariance of
    // the mean slope exists from this design); otherwise Huber's H1 sandwich (statsmodels RLM's
    // default), not the last weighted fit's covariance.
    let clustered = method != SeMethod::Iid && nfe == 0 && n_subj >= 2;
    let (dcov, df, how) = if clustered {
        let cov = clustered_m_sandwich(
            &x,
            &w,
            &h.fit.residuals,
            h.scale,
            h.k,
            &prep.subject,
            n_subj,
        );
        let how = format!(
            "cluster-robust sandwich of the M-estimator by subject (CR1, {n_subj} subjects): \
             s²·B⁻¹(Σ_g u_g u_gᵀ)B⁻¹·G/(G − 1)·(n − 1)/(n − p), B = Σψ'(rᵢ)xᵢxᵢᵀ, u_g = Σ_(i in g) \
             ψ(rᵢ)xᵢ, rᵢ = eᵢ/s at the final estimate and MAD scale s (the scale treated as \
             known); intervals t with {} df",
            n_subj - 1
        );
        (cov, (n_subj - 1) as f64, how)
    } else {
        let df = h.fit.df_resid as f64;
        let how = format!(
            "Huber's sandwich with his small-sample correction (H1, as statsmodels RLM's \
             default): κ²·[Σψ²/(n − p)]·s²/[Σψ'/n]²·(XᵀWX)⁻¹ on the design at the breakpoint \
             estimates{}; rows treated as independent{}; intervals t with {df} df",
            if nfe > 0 {
                " with one slope column per subject (the global slope is their mean)"
            } else {
                ""
            },
            if method != SeMethod::Iid && nfe > 0 {
                " (a per-subject column's score sums to zero within its subject: no clustered \
                 sandwich exists on this design)"
            } else {
                ""
            }
        );
        (h.cov.clone(), df, how)
    };
    let rcov = &gmap * &dcov * gmap.transpose();
    let tq = t_quantile(0.5 + 0.5 * CONFIDENCE, df);
    let mut rc = Vec::new();
    let mut j = 0;
    for (i, s) in rel.card().parameters.iter().enumerate() {
        if s.kind != ParamKind::Linear {
            continue;
        }
        let se = free[i].then(|| rcov[(j, j)].max(0.0).sqrt());
        rc.push(CoefficientRecord {
            std_error: se,
            ci95: se.map_or([None, None], |se| {
                [opt(rout[j] - tq * se), opt(rout[j] + tq * se)]
            }),
            published: s.cited.then_some(published[i]),
            held: if free[i] {
                None
            } else {
                held_reason[i].clone()
            },
            ..CoefficientRecord::new(s.name, s.unit, rout[j])
        });
        j += 1;
    }
    Ok(RobustRecord {
        k: h.k,
        scale: h.scale,
        iterations: h.iterations,
        converged: h.converged,
        rows_downweighted: h.robust_weights.iter().filter(|&&u| u < 1.0).count(),
        cov: Some(how),
        coefficients: rc,
    })
}

/// The cluster-robust (CR1) covariance of a Huber M-estimate: with `rᵢ = √wᵢ eᵢ / s` and
/// `x̃ᵢ = √wᵢ xᵢ`, `s² · B⁻¹ M B⁻¹ · G/(G − 1) · (n − 1)/(n − p)` where `B = Σ ψ'(rᵢ) x̃ᵢx̃ᵢᵀ`
/// (ψ' = 1 inside ±k, 0 outside) and `M = Σ_g u_g u_gᵀ`, `u_g = Σ_(i in g) ψ(rᵢ) x̃ᵢ` — the
/// sandwich of the estimating equations `Σ ψ(rᵢ) x̃ᵢ = 0` at the scale `s`, summed by subject,
/// with statsmodels' CR1 factor. NaN when `B` is singular.
pub(super) fn clustered_m_sandwich(
    x: &DMatrix<f64>,
    w: &DVector<f64>,
    e: &DVector<f64>,
    s: f64,
    k: f64,
    subject: &[usize],
    n_subj: usize,
) -> DMatrix<f64> {
    let (n, p) = (x.nrows(), x.ncols());
    let mut b = DMatrix::<f64>::zeros(p, p);
    let mut u = DMatrix::<f64>::zeros(n_subj, p);
    for i in 0..n {
        let sw = w[i].sqrt();
        let r = sw * e[i] / s;
        let psi = r.clamp(-k, k);
        let xi: Vec<f64> = (0..p).map(|j| sw * x[(i, j)]).collect();
        if r.abs() <= k {
            for a in 0..p {
                for c in 0..p {
                    b[(a, c)] += xi[a] * xi[c];
                }
            }
        }
        for a in 0..p {
            u[(subject[i], a)] += psi * xi[a];
        }
    }
    let Some(bi) = b.try_inverse() else {
        return DMatrix::from_element(p, p, f64::NAN);
    };
    let meat = u.transpose() * &u;
    let g = n_subj as f64;
    let factor = g / (g - 1.0) * (n as f64 - 1.0) / (n as f64 - p as f64);
    &bi * meat * &bi * (s * s * factor)
}
