//! What the generic pipeline ([`super::pipeline`]) adds for relations with bounded parameters
//! ([`Relation::bounds`]) or several outputs per row ([`Relation::outputs`]) — today `kb-mu`.
//!
//! # Bounds
//! The bounded least-squares problem is solved with argmin's bounded trust region
//! ([`super::nonlinear::nls`]) over the free parameters. A parameter that ends on a bound, and
//! whose residual-sum-of-squares gradient there points out of the allowed range (the KKT
//! condition, so that a solution merely *near* a bound is not mistaken for one *on* it), is then
//! held at the bound and the others refitted by the pipeline's QR: for a model linear in its
//! parameters that reproduces the bounded optimum exactly, and the record says "bound active".
//! Its standard error is undefined (none is reported); the others' are conditional on it.
//! Leave-one-subject-out and bootstrap refits keep an active parameter at its bound.
//! Per-subject effects are not part of the bounded problem (no bounded relation has one).
//!
//! # Several outputs
//! Each row gives one observation per output (a μ-function of `kb-mu`). The pooled r² centres
//! every output on its own mean, 1 − RSS/Σₖ Σ_{i∈k} (yᵢ − ȳₖ)², so that the different levels of
//! the outputs (a knee angle near 0, a foot angle near 70°) do not count as explained variance;
//! per output, n, r² (centred on its mean), rmse, leave-one-out rmse, leave-one-subject-out
//! rmse and the published coefficients' r² and rmse are reported as derived quantities. The
//! per-output leave-one-subject-out errors re-solve the bounded problem in every fold (argmin),
//! so they also count folds where a bound that is active on all data would not be; the
//! record's pooled `loso_rmse` (generic pipeline) keeps it on the bound.
use super::nonlinear::{nls, Model, NlsOptions, Rows};
use super::pipeline::Prepared;
use super::FitError;
use crate::export::coeffs::DerivedRecord;
use crate::relations::{Relation, MAX_INPUTS};

/// A parameter held on its bound.
#[derive(Debug, Clone, PartialEq)]
pub struct ActiveBound {
    /// Index among the relation's parameters.
    pub index: usize,
    /// The bound it sits on.
    pub value: f64,
    /// The allowed range.
    pub range: (f64, f64),
}

impl ActiveBound {
    /// The sentence the record and the summary show.
    pub fn describe(&self, name: &str) -> String {
        format!(
            "bound active: held on its bound {name} = {} (allowed [{}, {}]): the unconstrained \
             least-squares value lies beyond it; no standard error",
            self.value, self.range.0, self.range.1
        )
    }
}

struct Adapter<'a> {
    rel: &'a dyn Relation,
    p: &'a [f64],
    idx: &'a [usize],
}

impl Adapter<'_> {
    fn full(&self, theta: &[f64]) -> Vec<f64> {
        let mut q = self.p.to_vec();
        for (j, &i) in self.idx.iter().enumerate() {
            q[i] = theta[j];
        }
        q
    }
}

impl Model for Adapter<'_> {
    fn n_params(&self) -> usize {
        self.idx.len()
    }
    fn value(&self, x: &[f64], theta: &[f64]) -> f64 {
        self.rel.predict_with(&self.full(theta), 0.0, x)
    }
    fn gradient(&self, x: &[f64], theta: &[f64], out: &mut [f64]) {
        let q = self.full(theta);
        match self.rel.gradient(&q, x) {
            Some(g) => {
                for (j, &i) in self.idx.iter().enumerate() {
                    out[j] = g[i];
                }
            }
            None => {
                // Central differences (the trait's default, reached through a plain closure).
                let f = super::nonlinear::FnModel {
                    n_params: self.idx.len(),
                    f: |x: &[f64], t: &[f64]| self.rel.predict_with(&self.full(t), 0.0, x),
                };
                f.gradient(x, theta, out);
            }
        }
    }
}

/// Solves the bounded least-squares problem over the `free` parameters (the others at `p`)
/// with argmin and returns the parameters on an active bound plus a note on the solver run;
/// empty when no free parameter has a finite bound.
pub fn active_bounds(
    rel: &dyn Relation,
    prep: &Prepared,
    free: &[bool],
    p: &[f64],
    weighted: bool,
) -> Result<(Vec<ActiveBound>, Option<String>), FitError> {
    let idx: Vec<usize> = (0..p.len()).filter(|&i| free[i]).collect();
    let ranges: Vec<(f64, f64)> = idx.iter().map(|&i| rel.bounds(i)).collect();
    if ranges
        .iter()
        .all(|b| b.0 == f64::NEG_INFINITY && b.1 == f64::INFINITY)
    {
        return Ok((Vec::new(), None));
    }
    let rows: Vec<f64> = prep.obs.iter().flat_map(|o| o.x).collect();
    let y: Vec<f64> = prep.obs.iter().map(|o| o.y).collect();
    let start: Vec<f64> = idx
        .iter()
        .zip(&ranges)
        .map(|(&i, b)| p[i].clamp(b.0, b.1))
        .collect();
    let model = Adapter { rel, p, idx: &idx };
    let opts = NlsOptions {
        name: rel.id().to_string(),
        bounds: Some(ranges.clone()),
        weights: weighted.then(|| prep.weights.clone()),
        ..NlsOptions::default()
    };
    let r = nls(&model, Rows::new(&rows, MAX_INPUTS)?, &y, &start, &opts)?;
    let mut out = Vec::new();
    let mut g = vec![0.0; idx.len()];
    for (j, &i) in idx.iter().enumerate() {
        if !r.active_bounds[j] {
            continue;
        }
        let (lo, hi) = ranges[j];
        let on_lo = (r.theta[j] - lo).abs() <= (r.theta[j] - hi).abs();
        // KKT: Σ w·e·∂f/∂θⱼ is −½ ∂RSS/∂θⱼ; on the lower bound the fit must want to go lower.
        let mut push = 0.0;
        for (k, o) in prep.obs.iter().enumerate() {
            model.gradient(&o.x, &r.theta, &mut g);
            push += prep.weights[k] * r.residuals[k] * g[j];
        }
        let wants_out = if on_lo { push < 0.0 } else { push > 0.0 };
        if wants_out {
            out.push(ActiveBound {
                index: i,
                value: if on_lo { lo } else { hi },
                range: (lo, hi),
            });
        }
    }
    // On a bound the bounds transform flattens the cost, so the trust region often stops on its
    // iteration budget there; the KKT test above and the QR refit make the result exact anyway.
    let note = format!(
        "bounds enforced by argmin's bounded trust region ({} iterations; {}); parameters on \
         an active bound (checked by the KKT condition) are held there and the rest refitted by \
         QR, which is the bounded optimum of a model linear in its parameters",
        r.iterations,
        if r.converged {
            "converged".to_string()
        } else {
            format!("stopped: {}", r.termination)
        }
    );
    Ok((out, Some(note)))
}

/// Statistics of a relation with several outputs.
#[derive(Debug, Clone, PartialEq)]
pub struct OutputStats {
    /// Pooled r², each output centred on its own (weighted) mean.
    pub r2: f64,
    /// Adjusted for the fitted parameters and one mean per output.
    pub adj_r2: f64,
    /// The published coefficients' pooled r² on the same rows.
    pub published_r2: f64,
    /// How r² is defined.
    pub definition: String,
    /// Per-output n, r², rmse, leave-one-out rmse (with their published counterparts).
    pub derived: Vec<DerivedRecord>,
}

fn within_ss(rel: &dyn Relation, prep: &Prepared, w: &[f64], k: usize) -> (usize, f64) {
    let rows: Vec<usize> = (0..prep.obs.len())
        .filter(|&i| rel.output_of(&prep.obs[i].x) == k)
        .collect();
    let sw: f64 = rows.iter().map(|&i| w[i]).sum();
    let mean = rows.iter().map(|&i| w[i] * prep.obs[i].y).sum::<f64>() / sw;
    let tss = rows
        .iter()
        .map(|&i| w[i] * (prep.obs[i].y - mean).powi(2))
        .sum();
    (rows.len(), tss)
}

/// Leave-one-subject-out squared prediction errors per observation, the bounded problem
/// re-solved by argmin on the other subjects in every fold over the parameters
/// [`Relation::plan`] leaves free (so a bound active on all data may be inactive in a fold);
/// NaN where a fold failed or with fewer than 3 subjects.
fn loso_bounded(rel: &dyn Relation, prep: &Prepared, values: &[f64], weighted: bool) -> Vec<f64> {
    let n = prep.obs.len();
    let mut sq = vec![f64::NAN; n];
    if prep.subjects.len() < 3 {
        return sq;
    }
    let idx: Vec<usize> = rel
        .plan(&prep.obs)
        .held
        .iter()
        .enumerate()
        .filter(|(_, h)| h.is_none())
        .map(|(i, _)| i)
        .collect();
    let ranges: Vec<(f64, f64)> = idx.iter().map(|&i| rel.bounds(i)).collect();
    let start: Vec<f64> = idx
        .iter()
        .zip(&ranges)
        .map(|(&i, b)| values[i].clamp(b.0, b.1))
        .collect();
    let model = Adapter {
        rel,
        p: values,
        idx: &idx,
    };
    for s in 0..prep.subjects.len() {
        let train: Vec<usize> = (0..n).filter(|&i| prep.subject[i] != s).collect();
        let rows: Vec<f64> = train.iter().flat_map(|&i| prep.obs[i].x).collect();
        let y: Vec<f64> = train.iter().map(|&i| prep.obs[i].y).collect();
        let opts = NlsOptions {
            name: rel.id().to_string(),
            bounds: Some(ranges.clone()),
            weights: weighted.then(|| train.iter().map(|&i| prep.weights[i]).collect()),
            ..NlsOptions::default()
        };
        let Ok(rows) = Rows::new(&rows, MAX_INPUTS) else {
            continue;
        };
        if let Ok(r) = nls(&model, rows, &y, &start, &opts) {
            let q = model.full(&r.theta);
            for i in (0..n).filter(|&i| prep.subject[i] == s) {
                let o = &prep.obs[i];
                sq[i] = (o.y - rel.predict_with(&q, 0.0, &o.x)).powi(2);
            }
        }
    }
    sq
}

/// Pooled and per-output statistics from the residuals of the refit (`residuals`, with their
/// `leverage`, at coefficients `values`) and of the published coefficients
/// (`published_residuals`). `df` is the residual degrees of freedom of the fit. `None` for
/// single-output relations.
#[allow(clippy::too_many_arguments)]
pub fn output_stats(
    rel: &dyn Relation,
    prep: &Prepared,
    values: &[f64],
    residuals: &[f64],
    leverage: &[f64],
    published_residuals: &[f64],
    weighted: bool,
    df: f64,
) -> Option<OutputStats> {
    let m = rel.outputs();
    if m <= 1 {
        return None;
    }
    let n = prep.obs.len();
    let loso = loso_bounded(rel, prep, values, weighted);
    let loso_rmse = |rows: &[usize]| {
        let v: Vec<f64> = rows
            .iter()
            .map(|&i| loso[i])
            .filter(|v| v.is_finite())
            .collect();
        if v.len() == rows.len() && !v.is_empty() {
            (v.iter().sum::<f64>() / v.len() as f64).sqrt()
        } else {
            f64::NAN
        }
    };
    let ones = vec![1.0; n];
    let w: &[f64] = if weighted { &prep.weights } else { &ones };
    let (mut tss, mut rss, mut prss) = (0.0, 0.0, 0.0);
    let unit = rel.response().unit;
    let mut derived = Vec::new();
    let mut n_groups = 0usize;
    for k in 0..m {
        let (nk, tk) = within_ss(rel, prep, w, k);
        if nk == 0 {
            continue;
        }
        n_groups += 1;
        let rows: Vec<usize> = (0..n)
            .filter(|&i| rel.output_of(&prep.obs[i].x) == k)
            .collect();
        let rk: f64 = rows.iter().map(|&i| w[i] * residuals[i].powi(2)).sum();
        let pk: f64 = rows
            .iter()
            .map(|&i| w[i] * published_residuals[i].powi(2))
            .sum();
        let rmse = (rows.iter().map(|&i| residuals[i].powi(2)).sum::<f64>() / nk as f64).sqrt();
        let prmse = (rows
            .iter()
            .map(|&i| published_residuals[i].powi(2))
            .sum::<f64>()
            / nk as f64)
            .sqrt();
        let loo = (rows
            .iter()
            .map(|&i| (residuals[i] / (1.0 - leverage[i])).powi(2))
            .sum::<f64>()
            / nk as f64)
            .sqrt();
        tss += tk;
        rss += rk;
        prss += pk;
        let name = rel.output_name(k);
        let rec = |what: &str, unit: &str, value: f64, published: f64| DerivedRecord {
            name: format!("{name}: {what}"),
            unit: unit.to_string(),
            value,
            published,
        };
        derived.push(rec("n", "rows", nk as f64, nk as f64));
        derived.push(rec("r² (centred)", "-", 1.0 - rk / tk, 1.0 - pk / tk));
        derived.push(rec("rmse", unit, rmse, prmse));
        // Fixed (published) coefficients are not refitted, so their held-out error is their rmse.
        derived.push(rec("leave-one-out rmse", unit, loo, prmse));
        let ls = loso_rmse(&rows);
        if ls.is_finite() {
            derived.push(rec(
                "leave-one-subject-out rmse (bounded refits)",
                unit,
                ls,
                prmse,
            ));
        }
    }
    let all: Vec<usize> = (0..n).collect();
    let ls = loso_rmse(&all);
    if ls.is_finite() {
        let prmse = (published_residuals.iter().map(|e| e * e).sum::<f64>() / n as f64).sqrt();
        derived.push(DerivedRecord {
            name: "all outputs: leave-one-subject-out rmse (bounded refits)".into(),
            unit: unit.to_string(),
            value: ls,
            published: prmse,
        });
    }
    let r2 = 1.0 - rss / tss;
    Some(OutputStats {
        r2,
        adj_r2: 1.0 - (1.0 - r2) * (n as f64 - n_groups as f64) / df,
        published_r2: 1.0 - prss / tss,
        definition: format!(
            "pooled over the {n_groups} outputs with each output centred on its own mean: \
             1 − RSS/Σₖ Σ_(i∈k) (y − ȳₖ)² (per-output values under derived)"
        ),
        derived,
    })
}

/// Notes for free parameters whose refit value lies outside their bounds (the active set
/// missed one; should not happen, but a silent violation would be worse than a note).
pub fn violations(rel: &dyn Relation, values: &[f64], free: &[bool]) -> Vec<String> {
    let specs = rel.parameters();
    (0..values.len())
        .filter(|&i| free[i])
        .filter_map(|i| {
            let (lo, hi) = rel.bounds(i);
            let v = values[i];
            (v < lo || v > hi).then(|| {
                format!(
                    "WARNING: {} = {v} lies outside its bounds [{lo}, {hi}] after the refit",
                    specs[i].name
                )
            })
        })
        .collect()
}
