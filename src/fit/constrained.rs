//! What the generic pipeline ([`super::pipeline`]) adds for relations with bounded parameters
//! ([`Relation::bounds`]) or several outputs per row ([`Card::outputs`](crate::relations::Card::outputs)) — today `kb-mu`.
//!
//! # Bounds
//! A relation linear in its coefficients with bounds on some of them is a convex quadratic
//! programme, solved exactly from the normal equations by the active-set method of
//! [`super::bounded`] — for the fit, in every leave-one-subject-out fold and in every bootstrap
//! replicate (each from summed per-subject normal equations). Every solve's KKT conditions are
//! checked, and the record counts the solves and how many passed ([`BoxStats`]). A coefficient
//! on an active bound in the fit is then held at the bound and the others refitted: for a model
//! linear in its parameters that is the bounded optimum, and the record says "bound active". Its
//! standard error is undefined (none is reported); the others' are conditional on it. Folds and
//! replicates re-solve the bounded problem over every coefficient the data could identify, so a
//! bound active on all data may be inactive in a fold. Bounds apply to coefficients of the raw
//! basis (the default [`Form::basis`](crate::fit::forms::Form::basis)); per-subject effects are not bounded.
//!
//! # Several outputs
//! Each row gives one observation per output (a μ-function of `kb-mu`). The pooled r² centres
//! every output on its own mean, 1 − RSS/Σₖ Σ_{i∈k} (yᵢ − ȳₖ)², so that the different levels of
//! the outputs (a knee angle near 0, a foot angle near 70°) do not count as explained variance;
//! per output, n, r² (centred on its mean), rmse, leave-one-out rmse, leave-one-subject-out
//! rmse and the published coefficients' r² and rmse are reported as derived quantities. Each
//! output has its own residual variance: clustered standard errors (the default) are sandwich
//! estimates and need no common variance, and `--se iid` uses one variance per output
//! ([`super::design::Covariance`]).
use super::bounded::BoxSolution;
use super::design::Layout;
use super::pipeline::Prepared;
use super::FitError;
use crate::fit::forms::Fitting;
use crate::fit::record::{BoundedRecord, DerivedRecord};
use crate::relations::{ParamKind, Relation};
use std::sync::atomic::{AtomicUsize, Ordering};

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

/// The bounds of a layout's global columns, and which parameter each bounded column is.
#[derive(Debug, Clone, PartialEq)]
pub struct ColumnBounds {
    /// Lower bounds per global column (−∞ when unbounded).
    pub lo: Vec<f64>,
    /// Upper bounds per global column (+∞ when unbounded).
    pub hi: Vec<f64>,
    /// The parameter index of each global column (`None` for a column that is not one
    /// parameter alone).
    pub param: Vec<Option<usize>>,
}

/// The bounds of the free parameters of `lay` as bounds on its global columns, or `None` when no
/// free parameter has a finite bound. An error when a bounded parameter is not a column of the
/// basis by itself (bounds need the raw basis) or sits beside a per-subject effect.
pub fn column_bounds(
    rel: &dyn Relation,
    lay: &Layout,
    p: &[f64],
) -> Result<Option<ColumnBounds>, FitError> {
    let specs = rel.card().parameters;
    let bounded: Vec<usize> = (0..specs.len())
        .filter(|&i| lay.free[i] && specs[i].kind == ParamKind::Linear)
        .filter(|&i| {
            let (lo, hi) = rel.bounds(i);
            lo > f64::NEG_INFINITY || hi < f64::INFINITY
        })
        .collect();
    if bounded.is_empty() {
        return Ok(None);
    }
    let bad = |why: &str| FitError::InvalidInput {
        relation: rel.card().id.to_string(),
        message: format!("bounded coefficients: {why}"),
    };
    if lay.subj_col.is_some() {
        return Err(bad("not supported beside a per-subject effect"));
    }
    let m = lay.m();
    let lm = rel.basis_to_params(p, &lay.free);
    let mut out = ColumnBounds {
        lo: vec![f64::NEG_INFINITY; m],
        hi: vec![f64::INFINITY; m],
        param: vec![None; m],
    };
    let mut row = 0;
    for (i, s) in specs.iter().enumerate() {
        if s.kind != ParamKind::Linear {
            continue;
        }
        let r = lm.map.row(row);
        let nz: Vec<usize> = (0..m).filter(|&c| r[c] != 0.0).collect();
        if lay.free[i] && nz.len() == 1 && r[nz[0]] == 1.0 && lm.shift[row] == 0.0 {
            out.param[nz[0]] = Some(i);
        }
        if bounded.contains(&i) {
            let Some(c) = out.param.iter().position(|&q| q == Some(i)) else {
                return Err(bad(&format!(
                    "{} is not a column of the basis by itself (bounds need the raw basis)",
                    s.name
                )));
            };
            let (lo, hi) = rel.bounds(i);
            out.lo[c] = lo;
            out.hi[c] = hi;
        }
        row += 1;
    }
    Ok(Some(out))
}

/// Counts of bounded solves and their KKT checks (shared by parallel folds and replicates).
#[derive(Debug, Default)]
pub struct BoxStats {
    solves: AtomicUsize,
    converged: AtomicUsize,
    max_iterations: AtomicUsize,
}

impl BoxStats {
    /// Records one solve.
    pub fn record(&self, s: &BoxSolution) {
        self.solves.fetch_add(1, Ordering::Relaxed);
        if s.converged {
            self.converged.fetch_add(1, Ordering::Relaxed);
        }
        self.max_iterations
            .fetch_max(s.iterations, Ordering::Relaxed);
    }
    /// Records a solve that failed (a singular fold or replicate).
    pub fn record_failure(&self) {
        self.solves.fetch_add(1, Ordering::Relaxed);
    }
    /// The record.
    pub fn to_record(&self) -> BoundedRecord {
        BoundedRecord {
            solver: "box-constrained least squares on the normal equations, primal active set \
                     (Lawson & Hanson 1974); converged = KKT conditions verified at the solution"
                .into(),
            solves: self.solves.load(Ordering::Relaxed),
            converged: self.converged.load(Ordering::Relaxed),
            max_iterations: self.max_iterations.load(Ordering::Relaxed),
        }
    }
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

fn within_ss(prep: &Prepared, w: &[f64], k: usize) -> (usize, f64) {
    let rows: Vec<usize> = (0..prep.obs.len())
        .filter(|&i| prep.obs[i].x.output == k)
        .collect();
    let sw: f64 = rows.iter().map(|&i| w[i]).sum();
    let mean = rows.iter().map(|&i| w[i] * prep.obs[i].y).sum::<f64>() / sw;
    let tss = rows
        .iter()
        .map(|&i| w[i] * (prep.obs[i].y - mean).powi(2))
        .sum();
    (rows.len(), tss)
}

/// Pooled and per-output statistics from the residuals of the refit (`residuals`, with their
/// `leverage`) and of the published coefficients (`published_residuals`); `loso_sq` holds each
/// row's leave-one-subject-out squared prediction error (NaN where its fold failed or there is
/// none). `df` is the residual degrees of freedom of the fit. `None` for single-output relations.
#[allow(clippy::too_many_arguments)]
pub fn output_stats(
    rel: &dyn Relation,
    prep: &Prepared,
    residuals: &[f64],
    leverage: &[f64],
    published_residuals: &[f64],
    loso_sq: &[f64],
    weighted: bool,
    df: f64,
) -> Option<OutputStats> {
    let m = rel.card().outputs.len();
    if m <= 1 {
        return None;
    }
    let n = prep.obs.len();
    let loso_rmse = |rows: &[usize]| {
        let v: Vec<f64> = rows
            .iter()
            .filter_map(|&i| loso_sq.get(i).copied())
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
    let unit = rel.card().response.unit;
    let mut derived = Vec::new();
    let mut n_groups = 0usize;
    for k in 0..m {
        let (nk, tk) = within_ss(prep, w, k);
        if nk == 0 {
            continue;
        }
        n_groups += 1;
        let rows: Vec<usize> = (0..n).filter(|&i| prep.obs[i].x.output == k).collect();
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
        let name = rel.card().outputs[k].name.to_string();
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
            derived.push(rec("leave-one-subject-out rmse", unit, ls, prmse));
        }
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
    let specs = rel.card().parameters;
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
