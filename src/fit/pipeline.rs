//! The one generic routine that turns any [`Relation`] and trials tables into a [`FitRecord`]
//! with every statistic of issue 3, plus what the report needs (fitted values, residuals, a
//! confidence band).
//!
//! # Method
//! Every relation is linear in its [`ParamKind::Linear`] coefficients once its breakpoints are
//! fixed (separable least squares), so:
//! 1. rows are reduced to [`Observation`](crate::relations::Observation)s (papers' units); rows lacking a needed quantity,
//!    flagged as inconsistent, or without a usable weight are **rejected and reported** by reason;
//! 2. [`Form::plan`](crate::fit::forms::Form::plan) says which coefficients the data can identify; the others are held at
//!    their published values (and the record says why);
//! 3. each free breakpoint is **profiled**: the linear coefficients are refitted at each trial
//!    value and the residual sum of squares minimised (module `profile`: exactly over the
//!    partitions of the rows for a breakpoint the model depends on only through which rows lie
//!    on each side, by a grid scan and argmin's Brent method otherwise); two breakpoints are
//!    profiled by coordinate descent. A breakpoint that marks a feature which may be absent (a
//!    plateau onset, see [`Form::breakpoint_null`](crate::fit::forms::Form::breakpoint_null)) is kept only when an F-test against the
//!    model without the feature rejects at 5 %; otherwise it is held at the published value;
//! 4. at the breakpoints' estimates the linear coefficients come from per-subject sufficient
//!    statistics ([`super::design`]); a per-subject effect (the running paper's `level`, an
//!    offset on the slope) is absorbed subject by subject (Frisch–Waugh–Lovell): the global
//!    slope is the subjects' mean slope and `level[s]` the deviations (they sum to zero);
//! 5. **inference** ([`super::inference`]): gait rows are repeated measures, so with two or more
//!    subjects standard errors are clustered by subject (CR1, as statsmodels
//!    `cov_type='cluster'`, t with G − 1 degrees of freedom) unless `--se iid` or `--se cr2`
//!    (Bell–McCaffrey with Satterthwaite degrees of freedom) is asked for. The global slope under
//!    a per-subject effect is a mean of G subject slopes; its clustered standard error follows
//!    each subject's influence on that mean (its slope's deviation from the mean, and its pull on
//!    the shared coefficients), so it estimates the spread a new sample of subjects would show;
//! 6. **breakpoints**: the 95 % confidence set is the set of breakpoint values whose profile RSS
//!    passes the F-test against the minimum, over every admissible partition of the rows (or a
//!    grid over the whole search range for a continuous breakpoint), recorded as its pieces
//!    and their hull (`ci95`). Only a regular profile — continuous model, one piece inside the
//!    range, one local minimum in it — gives a breakpoint a standard error and a t-test; then
//!    the linear coefficients' standard errors are those with the breakpoints free (Gauss–Newton
//!    over all parameters), and the conditional ones are recorded beside them;
//! 7. statistics: r² (centred, or uncentred without intercept — the centred one is always
//!    recorded too), adjusted r², rmse = √(RSS/n), residual mean square RSS/(n − p) with p
//!    counting breakpoints and per-subject slopes, AIC/BIC (Gaussian likelihood), PRESS
//!    (leave-one-out) rmse from the leverages with breakpoints held at their estimate,
//!    leave-one-subject-out rmse (everything refitted without the subject, which is predicted
//!    with level 0), the published coefficients' r² and rmse on the same rows, t-tests against
//!    the published values (where the paper gives one), optional Huber IRLS and weighted fits and
//!    a seeded bootstrap by subject.
use super::constrained::{column_bounds, ActiveBound, BoxStats};
use super::design::{augment, Covariance, DesignFit, Layout, Totals, MAX_BASIS};
use super::inference::{SeMethod, CR2_RECOMMENDED_BELOW};
use super::prec::ILL_CONDITIONED;
use super::record::{
    BootstrapRecord, CoefficientRecord, DataRecord, DerivedRecord, FitRecord, PublishedFit,
    RangeRecord, TTestRecord,
};
use super::stats::{
    aic, bic, bootstrap_by_group, leave_one_group_out, r2_centred, r2_uncentred, t_quantile, TTest,
};
use super::FitError;
use crate::fit::forms::{DistinctKeys, Fitting};
use crate::ingest::trials::TrialsTable;
use crate::relations::{Fitted, Inputs, ParamKind, Relation};
use profile::{
    confidence_set, profile, refit, share_first_grid, whole_subjects, FoldEngine, FoldKeys,
    Members, ProfileGrid, Profiler, SortedRows, Source, Subset,
};

mod band;
mod describe;
mod prepare;
mod profile;
mod robust;
mod sums;
mod wild;
use band::{step, Band};
use describe::{design_effect, inference_record};
use nalgebra::{DMatrix, DVector};
use prepare::weight_column;
pub use prepare::{is_trials_table, load_tables, prepare, Prepared, RawStepReader};
pub use profile::{DISCRETE_MAX_EVALS, PROFILE_GRID};
use robust::robust_refit;
use std::collections::BTreeMap;
use sums::{all_subject_sums, loso_from_subject_sums, solve_totals};

/// Huber tuning constant (95 % efficiency under normal errors).
pub const HUBER_K: f64 = 1.345;
/// Maximum IRLS iterations of the robust fit.
pub const HUBER_MAX_ITER: usize = 100;
/// Significance level of the test that keeps an optional breakpoint (plateau onset).
pub const BREAKPOINT_TEST_ALPHA: f64 = 0.05;
/// Confidence level of every interval gaitfit reports.
pub const CONFIDENCE: f64 = 0.95;
/// Settings of a fit (validated once, by [`FitOptions::validate`]).
#[derive(Debug, Clone, PartialEq, Default)]
pub struct FitOptions {
    /// Also fit a Huber M-estimate (IRLS).
    pub robust: bool,
    /// Weight rows by this column (inverse variances, > 0).
    pub weights: Option<String>,
    /// Bootstrap replicates by subject (0 = none).
    pub bootstrap: usize,
    /// Seed of the bootstrap.
    pub seed: u64,
    /// Standard errors: `None` = clustered by subject with two or more subjects — CR2 with
    /// Bell–McCaffrey degrees of freedom below [`CR2_RECOMMENDED_BELOW`] subjects, CR1 from
    /// there on — else iid.
    pub se: Option<SeMethod>,
    /// Also fit the random-intercept model by REML ([`super::mixed`]).
    pub random_subject: bool,
}

impl FitOptions {
    /// The standard-error method for rows from `n_subj` subjects: the one asked for, else
    /// clustered by subject with two or more subjects — CR2 with Bell–McCaffrey degrees of
    /// freedom below [`CR2_RECOMMENDED_BELOW`] subjects (CR1 with G − 1 degrees of freedom
    /// under-covers with few or unbalanced subjects: Cameron & Miller 2015 §VI, Imbens & Kolesár
    /// 2016; measured on the bundled walking designs by `tools/reference/coverage.py`), CR1
    /// from there on — and iid with one. Clustered methods need two subjects.
    pub fn se_method(&self, relation: &str, n_subj: usize) -> Result<SeMethod, FitError> {
        match self.se {
            None if n_subj >= CR2_RECOMMENDED_BELOW => Ok(SeMethod::Cluster),
            None if n_subj >= 2 => Ok(SeMethod::Cr2),
            None => Ok(SeMethod::Iid),
            Some(SeMethod::Iid) => Ok(SeMethod::Iid),
            Some(m) if n_subj >= 2 => Ok(m),
            Some(m) => Err(FitError::TooFew {
                relation: format!(
                    "{relation} (--se {} clusters by subject; use --se iid for one subject)",
                    m.label()
                ),
                what: "subjects".into(),
                have: n_subj,
                need: 2,
            }),
        }
    }

    /// Checks the settings against the tables (the weights column must exist).
    pub fn validate(&self, tables: &[TrialsTable]) -> Result<(), FitError> {
        if let Some(w) = &self.weights {
            for t in tables {
                if weight_column(t, w).is_none() {
                    return Err(FitError::InvalidInput {
                        relation: "fit".into(),
                        message: format!(
                            "{}: no numeric column `{w}` for --weights",
                            t.path.display()
                        ),
                    });
                }
            }
        }
        Ok(())
    }
}

/// Everything a fit produced: the record plus what plots need.
#[derive(Debug)]
pub struct FitOutcome {
    /// The statistics (written to `fits/`).
    pub record: FitRecord,
    /// The relation with the refitted coefficients.
    pub refit: Fitted,
    /// The relation with the published coefficients.
    pub published: Fitted,
    /// The rows used.
    pub prepared: Prepared,
    /// Fitted values (each row with its subject's level).
    pub fitted: Vec<f64>,
    /// Residuals y − fitted.
    pub residuals: Vec<f64>,
    /// Refit coefficients (global, `parameters()` order).
    pub values: Vec<f64>,
    band: Band,
}

fn opt(v: f64) -> Option<f64> {
    v.is_finite().then_some(v)
}

/// Fits `rel` (its current coefficients are the published reference and the values of held
/// coefficients) on the rows of `tables`.
pub fn fit_relation(
    rel: &dyn Relation,
    tables: &[TrialsTable],
    opts: &FitOptions,
) -> Result<FitOutcome, FitError> {
    opts.validate(tables)?;
    let id = rel.card().id.to_string();
    let prep = prepare(rel, tables, opts.weights.as_deref());
    let n = prep.obs.len();
    let specs = rel.card().parameters;
    let published = rel.card().published_values();
    let n_subj = prep.subjects.len();
    let method = opts.se_method(&id, n_subj)?;
    // Rows sorted once by the breakpoint key, with prefix sums: every profile evaluation
    // below (search, F-test, confidence sets, folds, bootstrap) then costs O(p³), not a pass.
    // The tree over all rows serves fits without per-subject columns; with them, every
    // evaluation (and fold, and replicate) sums subjects' trees.
    let with_all = !(rel.card().subject_effect.is_some() && n_subj >= 2);
    let sorted = rel
        .sorted_profile()
        .map(|form| SortedRows::new(form, &prep, with_all));
    let all_keys: Vec<f64> = sorted
        .as_ref()
        .map_or_else(Vec::new, |sr| sr.distinct_keys(&vec![true; n_subj]));
    let src = match &sorted {
        Some(sr) => Source::Sorted {
            sr,
            members: Members::All,
            keys: DistinctKeys::new(&all_keys),
        },
        None => Source::Rows {
            prep: &prep,
            rows: None,
            subj_map: None,
            n_subj,
        },
    };
    let plan = match &sorted {
        Some(sr) => sr.form().plan_sorted(DistinctKeys::new(&all_keys)),
        None => rel.plan(&prep.obs),
    };
    let mut free: Vec<bool> = plan.held.iter().map(|h| h.is_none()).collect();
    let mut held_reason: Vec<Option<String>> = plan.held.clone();
    let mut notes = Vec::new();

    let n_fe = |lay: &Layout| if lay.subj_col.is_some() { n_subj } else { 0 };
    let n_bp_free = |free: &[bool]| {
        free.iter()
            .zip(specs)
            .filter(|(f, s)| **f && s.kind == ParamKind::Breakpoint)
            .count()
    };
    let lay0 = Layout::new(rel, free.clone(), n_subj);
    let n_params_max = lay0.m() + n_fe(&lay0) + n_bp_free(&free);
    if n < n_params_max + 2 {
        let mut why = String::new();
        if let Some(r) = prep.rejected.first() {
            why = format!(
                " ({} rows rejected; most common: {})",
                prep.n_rejected, r.reason
            );
        }
        return Err(FitError::TooFew {
            relation: format!("{id}{why}"),
            what: format!("rows of gait `{}`", rel.card().gait),
            have: n,
            need: n_params_max + 2,
        });
    }
    if opts.bootstrap > 0 && n_subj < 2 {
        return Err(FitError::TooFew {
            relation: format!("{id} (--bootstrap resamples subjects)"),
            what: "subjects".into(),
            have: n_subj,
            need: 2,
        });
    }

    // Profile the breakpoints; drop optional ones the data do not support.
    let mut p = published.clone();
    let mut lay = lay0;
    p = profile(
        &Profiler {
            rel,
            lay: &lay,
            src,
        },
        &p,
        &plan.search,
        &mut notes,
    )?;
    for i in 0..specs.len() {
        if !(free[i] && specs[i].kind == ParamKind::Breakpoint) {
            continue;
        }
        let Some(null) = rel.breakpoint_null(i) else {
            continue;
        };
        let pr = Profiler {
            rel,
            lay: &lay,
            src,
        };
        let rss1 = pr.solve(&p).map_or(f64::NAN, |r| r.1);
        let mut q = p.clone();
        q[i] = null;
        let rss0 = pr.solve(&q).map_or(f64::NAN, |r| r.1);
        let df = n as f64 - n_params_max as f64;
        let f = (rss0 - rss1) / (rss1 / df);
        let pval = super::stats::t_two_sided_p(f.max(0.0).sqrt(), df);
        // A NaN p-value (degenerate test) also keeps the published value.
        if pval.is_nan() || pval >= BREAKPOINT_TEST_ALPHA {
            free[i] = false;
            held_reason[i] = Some(format!(
                "held at the published value: the data show no {} (best {} = {:.4}, F-test \
                 against none: F = {f:.3}, p = {pval:.3} ≥ {BREAKPOINT_TEST_ALPHA})",
                specs[i].description, specs[i].name, p[i]
            ));
            p[i] = published[i];
            lay = Layout::new(rel, free.clone(), n_subj);
            p = profile(
                &Profiler {
                    rel,
                    lay: &lay,
                    src,
                },
                &p,
                &plan.search,
                &mut notes,
            )?;
        }
    }
    // Bounded parameters (Relation::bounds): the exact bounded least-squares solution decides
    // which sit on a bound (module constrained).
    let mut bound_flag: Vec<Option<String>> = vec![None; specs.len()];
    let col_bounds = column_bounds(rel, &lay, &p)?;
    let box_stats = BoxStats::default();
    let (lay_pre, p_pre) = (lay.clone(), p.clone());
    if let Some(cb) = &col_bounds {
        let sums = all_subject_sums(rel, &lay, &p, &prep).ok_or_else(|| FitError::Singular {
            relation: id.clone(),
            message: "a subject's own column is all zeros".into(),
        })?;
        let mut t = Totals::zeros(lay.m());
        sums.iter().for_each(|s| t.add(s, 1.0));
        let (_, _, sol) = t
            .solve_box(&lay, &cb.lo, &cb.hi)
            .ok_or_else(|| FitError::Singular {
                relation: id.clone(),
                message: "the bounded least-squares problem is singular".into(),
            })?;
        box_stats.record(&sol);
        for (c, &side) in sol.active.iter().enumerate() {
            let Some(i) = cb.param[c].filter(|_| side != 0) else {
                continue;
            };
            let b = ActiveBound {
                index: i,
                value: if side < 0 { cb.lo[c] } else { cb.hi[c] },
                range: rel.bounds(i),
            };
            free[i] = false;
            p[i] = b.value;
            held_reason[i] = Some(b.describe(specs[i].name));
            bound_flag[i] = Some("bound active".into());
        }
        notes.push(
            "bounds enforced exactly: box-constrained least squares on the normal equations by \
             an active-set method (KKT conditions checked); coefficients on an active bound are \
             held there and the rest refitted; leave-one-subject-out folds and bootstrap \
             replicates re-solve the bounded problem (see bounded for every solve's convergence)"
                .into(),
        );
    }
    lay = Layout::new(rel, free.clone(), n_subj);
    let bps: Vec<usize> = (0..specs.len())
        .filter(|&i| free[i] && specs[i].kind == ParamKind::Breakpoint)
        .collect();
    let n_bp = bps.len();
    let k = lay.m() + n_fe(&lay) + n_bp;
    if n < k + 2 {
        return Err(FitError::TooFew {
            relation: id.clone(),
            what: format!("rows of gait `{}`", rel.card().gait),
            have: n,
            need: k + 2,
        });
    }

    // The reported fit at the breakpoint estimates.
    let fit = DesignFit::new(rel, &lay, &p, &prep).ok_or_else(|| FitError::Singular {
        relation: id.clone(),
        message: "the normal equations at the breakpoint estimates are not positive definite \
                  (too few distinct inputs for the free coefficients)"
            .into(),
    })?;
    if fit.condition_number > ILL_CONDITIONED {
        notes.push(format!(
            "the design is ill-conditioned (condition number {:.2e}); coefficients may have lost digits",
            fit.condition_number
        ));
    }
    let weighted = opts.weights.is_some();
    let values = lay.params(rel, &p, &fit.coef);
    notes.extend(super::constrained::violations(rel, &values, &free));
    let df = (n - k) as f64;
    let rss = fit.rss;
    let sigma2 = rss / df;
    let fitted = fit.fitted.clone();
    let residuals = fit.residuals.clone();
    let obs_y: Vec<f64> = prep.obs.iter().map(|o| o.y).collect();
    let wopt = weighted.then_some(prep.weights.as_slice());
    let r2c = r2_centred(&obs_y, rss, wopt);
    let (r2, r2_def) = if rel.card().has_intercept {
        (r2c, "centred: 1 − RSS/Σ(y − ȳ)²".to_string())
    } else {
        (
            r2_uncentred(&obs_y, rss, wopt),
            "uncentred (regression through the origin, as NIST StRD defines it): 1 − RSS/Σy²"
                .to_string(),
        )
    };
    let adj_r2 = if rel.card().has_intercept {
        1.0 - (1.0 - r2) * (n as f64 - 1.0) / df
    } else {
        1.0 - (1.0 - r2) * n as f64 / df
    };
    let rmse = (residuals.iter().map(|e| e * e).sum::<f64>() / n as f64).sqrt();
    let press: f64 = (0..n)
        .map(|i| (residuals[i] / (1.0 - fit.leverage[i])).powi(2))
        .sum::<f64>()
        / n as f64;
    let sum_log_w = if weighted { fit.sum_log_w } else { 0.0 };

    // Covariances: conditional on the breakpoints, and (regular profiles) with them free.
    let fe_d: Vec<DVector<f64>> = fit.fe.iter().map(|(d, _)| d.clone()).collect();
    let cov_c = Covariance::new(method, &fit.a, &fit.clusters, &fit, &fe_d, n, k, k - n_bp)
        .ok_or_else(|| FitError::Singular {
            relation: id.clone(),
            message: "the covariance of the coefficients is singular".into(),
        })?;
    let tq_iid = t_quantile(0.5 + 0.5 * CONFIDENCE, df);
    // Breakpoint sets: the profile likelihood-ratio (F) test. With clustered inference the
    // likelihood ratio is divided by a design effect (Rao & Scott 1984) and compared with
    // F(1, G − 1): the breakpoint's own, V_clustered/V_iid from the Gauss–Newton covariances,
    // when its profile is regular; otherwise Rao & Scott's first-order δ̄ = tr(V_iid⁻¹ V)/p of
    // the linear coefficients. With iid inference this is the plain F-test.
    let pr = Profiler {
        rel,
        lay: &lay,
        src,
    };
    let rmin = if n_bp > 0 { pr.rss(&p) } else { rss };
    let sigma2_min = rmin / df;
    // Each breakpoint's profile on the grid, shared by its plain and clustered sets.
    let grids: Vec<ProfileGrid> = bps
        .iter()
        .map(|&i| ProfileGrid::new(&pr, &p, i, &plan.search))
        .collect();
    let plain: Vec<_> = bps
        .iter()
        .zip(&grids)
        .map(|(&i, grid)| {
            let set = confidence_set(
                &pr,
                &p,
                i,
                &plan.search,
                rmin + sigma2_min * tq_iid * tq_iid,
                grid,
            );
            set.record(specs[i].name)
        })
        .collect();
    // Gauss–Newton covariances with the breakpoints free (all plain profiles regular).
    let aug_covs = if n_bp > 0 && plain.iter().all(|(r, _)| r.regular) {
        let coef = fit.coef.clone();
        let sc = lay.subj_col;
        let subj_coefs: Vec<DVector<f64>> = (0..n_subj)
            .map(|s| {
                let mut c = coef.clone();
                if let Some(sc) = sc {
                    c[sc] = fit.gammas[s];
                }
                c
            })
            .collect();
        let mean_at = |q: &[f64], c: &DVector<f64>, x: &Inputs| {
            let mut phi = [0.0; MAX_BASIS];
            let off = rel.basis(q, &lay.free, x, &mut phi[..lay.nb]);
            off + (0..lay.nb).map(|j| phi[j] * c[j]).sum::<f64>()
        };
        let jac = |row: usize, out: &mut [f64]| {
            let o = &prep.obs[row];
            let c = &subj_coefs[prep.subject[row]];
            for (b, &i) in bps.iter().enumerate() {
                let h = step(p[i]);
                let (mut up, mut dn) = (p.clone(), p.clone());
                up[i] += h;
                dn[i] -= h;
                out[b] = (mean_at(&up, c, &o.x) - mean_at(&dn, c, &o.x)) / (2.0 * h);
            }
        };
        let aug = augment(rel, &fit, &p, &prep, n_bp, &jac);
        let cv = |m: SeMethod| Covariance::new(m, &aug.a, &aug.clusters, &fit, &aug.d, n, k, k);
        match (cv(method), cv(SeMethod::Iid)) {
            (Some(c), Some(i)) => Some((c, i)),
            _ => None,
        }
    } else {
        None
    };
    let delta_bar = match method {
        SeMethod::Iid => 1.0,
        _ => Covariance::new(
            SeMethod::Iid,
            &fit.a,
            &fit.clusters,
            &fit,
            &fe_d,
            n,
            k,
            k - n_bp,
        )
        .map_or(f64::NAN, |ci| design_effect(&ci.v, &cov_c.v)),
    };
    let tq_cl = t_quantile(0.5 + 0.5 * CONFIDENCE, n_subj as f64 - 1.0);
    let mut bp_records = Vec::new();
    let mut bp_hull: BTreeMap<usize, [Option<f64>; 2]> = BTreeMap::new();
    let mut all_regular = n_bp > 0;
    for (b, (&i, (plain_rec, plain_hull))) in bps.iter().zip(plain).enumerate() {
        let (rec, hull) = if method == SeMethod::Iid {
            (plain_rec, plain_hull)
        } else {
            let m = lay.m();
            let (delta, whose) = match &aug_covs {
                Some((c, ci)) => (
                    c.v[(m + b, m + b)] / ci.v[(m + b, m + b)],
                    format!("{}'s own, V_clustered/V_iid", specs[i].name),
                ),
                None => (
                    delta_bar,
                    "first-order δ̄ of the linear coefficients".to_string(),
                ),
            };
            let thr = rmin + sigma2_min * delta * tq_cl * tq_cl;
            let (mut rec, hull) =
                confidence_set(&pr, &p, i, &plan.search, thr, &grids[b]).record(specs[i].name);
            rec.pieces_iid = plain_rec.pieces;
            rec.design_effect = opt(delta);
            rec.method = format!(
                "{}; the likelihood ratio divided by the design effect of the clustering (Rao & \
                 Scott 1984; {whose}: {delta:.3}) against F(1, {}) (pieces_iid: the uncorrected \
                 F set, rows treated as independent)",
                rec.method,
                n_subj - 1
            );
            (rec, hull)
        };
        all_regular &= rec.regular;
        bp_hull.insert(i, hull);
        bp_records.push(rec);
    }
    let cov_f = if all_regular {
        aug_covs.map(|(c, _)| c)
    } else {
        None
    };
    if all_regular && cov_f.is_none() {
        notes.push(
            "the covariance with the breakpoints free is singular: standard errors are \
             conditional on the breakpoint estimates"
                .into(),
        );
    }

    // Linear parameters as functions of θ: H (rows: linear params; columns: θ).
    let lm = rel.basis_to_params(&p, &free);
    let n_lin = lm.map.nrows();
    let m = lay.m();
    let theta_map = |cov: &Covariance, with_bps: bool| -> DMatrix<f64> {
        let dim = cov.k + usize::from(cov.has_fe);
        // θ → basis coefficients.
        let mut e = DMatrix::zeros(lay.nb, dim);
        let mut g = 0;
        for j in 0..lay.nb {
            if Some(j) == lay.subj_col {
                e[(j, cov.k)] = 1.0;
            } else {
                e[(j, g)] = 1.0;
                g += 1;
            }
        }
        let mut h = &lm.map * e;
        if with_bps {
            for (b, &i) in bps.iter().enumerate() {
                let st = step(p[i]);
                let (mut up, mut dn) = (p.clone(), p.clone());
                up[i] += st;
                dn[i] -= st;
                let lu = rel.basis_to_params(&up, &free);
                let ld = rel.basis_to_params(&dn, &free);
                let d = ((&lu.map * &fit.coef + &lu.shift) - (&ld.map * &fit.coef + &ld.shift))
                    / (2.0 * st);
                h.column_mut(m + b).copy_from(&d);
            }
        }
        h
    };
    let h_c = theta_map(&cov_c, false);
    let h_f = cov_f.as_ref().map(|c| theta_map(c, true));
    let (cov, h_main) = match (&cov_f, &h_f) {
        (Some(c), Some(h)) => (c, h),
        _ => (&cov_c, &h_c),
    };
    let bp_text = if n_bp == 0 {
        "no free breakpoints".to_string()
    } else if cov_f.is_some() {
        "free: linear standard errors are Gauss–Newton over all parameters, breakpoints \
         included (std_error); those conditional on the breakpoint estimates are recorded as \
         std_error_conditional"
            .to_string()
    } else {
        "conditional on the breakpoint estimates: a breakpoint whose profile is irregular has \
         no standard error, so the linear coefficients' are conditional on it (see breakpoints \
         and the subject bootstrap for the uncertainty it adds)"
            .to_string()
    };
    let inference = inference_record(method, n_subj, df, bp_text);
    let how = |cov: &Covariance, free_bps: bool| {
        format!(
            "{}{}",
            match cov.method {
                SeMethod::Iid => format!("iid, t with {} df", cov.df_resid),
                SeMethod::Cluster => format!(
                    "CR1 by subject ({} clusters), t with {} df",
                    cov.g,
                    cov.g - 1
                ),
                SeMethod::Cr2 => format!(
                    "CR2 by subject ({} clusters), t with Bell–McCaffrey df",
                    cov.g
                ),
            },
            match (n_bp, free_bps) {
                (0, _) => "",
                (_, true) => "; breakpoints free",
                (_, false) => "; conditional on the breakpoint estimates",
            }
        )
    };

    // Coefficients.
    let mut coefs = Vec::new();
    let mut lin_j = 0;
    for (i, s) in specs.iter().enumerate() {
        let cited = s.cited.then_some(published[i]);
        let mut rec = CoefficientRecord {
            published: cited,
            held: if free[i] {
                None
            } else {
                held_reason[i].clone()
            },
            flag: bound_flag[i].clone(),
            ..CoefficientRecord::new(s.name, s.unit, values[i])
        };
        let mut se_df: Option<(f64, f64)> = None;
        if s.kind == ParamKind::Linear {
            let j = lin_j;
            lin_j += 1;
            if free[i] {
                let ell = h_main.row(j).transpose();
                let se = ell.dot(&(&cov.v * &ell)).max(0.0).sqrt();
                se_df = Some((se, cov.df(&ell)));
                if cov_f.is_some() {
                    let lc = h_c.row(j).transpose();
                    rec.std_error_conditional = Some(lc.dot(&(&cov_c.v * &lc)).max(0.0).sqrt());
                }
                rec.inference = Some(how(cov, cov_f.is_some()));
            }
        } else if free[i] {
            let hull = bp_hull.get(&i).copied().unwrap_or([None, None]);
            rec.ci95 = hull;
            match (&cov_f, bps.iter().position(|&b| b == i)) {
                (Some(c), Some(b)) => {
                    let mut ell = DVector::zeros(c.k + usize::from(c.has_fe));
                    ell[m + b] = 1.0;
                    let se = c.v[(m + b, m + b)].max(0.0).sqrt();
                    let d = c.df(&ell);
                    rec.std_error = Some(se);
                    if let Some(pv) = cited {
                        let t = TTest::new(values[i], pv, se, d);
                        rec.t_test = Some(TTestRecord {
                            t: opt(t.t),
                            df: d,
                            p_value: opt(t.p_value),
                        });
                    }
                    rec.inference = Some(format!(
                        "95 % interval: F-based profile confidence set (see breakpoints); \
                         standard error and t-test: {}",
                        how(c, true)
                    ));
                }
                _ => {
                    rec.inference = Some(
                        "95 % interval: hull of the F-based profile confidence set (see \
                         breakpoints); irregular profile: no standard error, no t-test"
                            .into(),
                    );
                }
            }
        }
        if let Some((se, d)) = se_df {
            let tq = t_quantile(0.5 + 0.5 * CONFIDENCE, d);
            rec.std_error = Some(se);
            rec.ci95 = [opt(values[i] - tq * se), opt(values[i] + tq * se)];
            if let Some(pv) = cited {
                let t = TTest::new(values[i], pv, se, d);
                rec.t_test = Some(TTestRecord {
                    t: opt(t.t),
                    df: d,
                    p_value: opt(t.p_value),
                });
            }
        }
        coefs.push(rec);
    }
    let _ = n_lin;
    if let (Some(e), Some(_)) = (rel.card().subject_effect, lay.subj_col) {
        // A subject's own slope is informed by that subject's rows only: no cluster-robust
        // standard error exists for it; its standard error is the iid one within the subject,
        // conditional on the subjects fitted.
        let gf = n_subj as f64;
        let kappa = fe_d.iter().fold(DVector::zeros(m), |a, d| a + d) / gf;
        let minv = super::inference::inverse_factor(&fit.a)
            .map(|l| &l * l.transpose())
            .unwrap_or_else(|| DMatrix::zeros(m, m));
        let inv_szz_mean: f64 = fit.fe.iter().map(|(_, s)| 1.0 / s).sum::<f64>() / (gf * gf);
        let tq = tq_iid;
        for (s, name) in prep.subjects.iter().enumerate() {
            let v = fit.gammas[s] - fit.gamma_bar;
            let (d, szz) = &fit.fe[s];
            let dk = d - &kappa;
            let var =
                sigma2 * ((1.0 / szz) * (1.0 - 2.0 / gf) + inv_szz_mean + dk.dot(&(&minv * &dk)));
            let se = var.max(0.0).sqrt();
            let flag = (v.abs() > e.paper_bound).then(|| {
                format!(
                    "outside the paper's range ±{} {} for {}",
                    e.paper_bound, e.unit, e.name
                )
            });
            if flag.is_some() {
                notes.push(format!(
                    "subject {name}: {}[{name}] = {v:.5} is outside the paper's range ±{}",
                    e.name, e.paper_bound
                ));
            }
            coefs.push(CoefficientRecord {
                std_error: Some(se),
                ci95: [opt(v - tq * se), opt(v + tq * se)],
                inference: Some(format!(
                    "iid within the subject, conditional on the subjects fitted (t with {df} df): \
                     one subject's rows alone inform its level, so no cluster-robust standard \
                     error exists; the paper gives a range (±{}), not a value",
                    e.paper_bound
                )),
                flag,
                ..CoefficientRecord::new(format!("{}[{name}]", e.name), e.unit, v)
            });
        }
        notes.push(format!(
            "{} is fitted per subject as an offset on {} (absorbed subject by subject; the \
             offsets sum to zero, so {} is the average subject's); held-out and new subjects are \
             predicted with {} = 0",
            e.name, e.on, e.on, e.name
        ));
    } else if rel.card().subject_effect.is_some() {
        notes.push(format!(
            "one subject only: no per-subject {} fitted",
            rel.card().subject_effect.map_or("", |e| e.name)
        ));
    }

    // Leave-one-subject-out: each row's squared prediction error from its subject's fold.
    let plan_fixed = rel.plan(&[]) == plan;
    let linear_folds = n_bp == 0 && (plan_fixed || sorted.is_some());
    let fold_bounds = col_bounds.as_ref().map(|cb| (cb, &box_stats));
    let mut rows_of = vec![Vec::new(); n_subj];
    for (i, &s) in prep.subject.iter().enumerate() {
        rows_of[s].push(i);
    }
    let mut loso_sq = vec![f64::NAN; n];
    let (loso_rmse, loso_note) = if n_subj >= 3 {
        let sq_err = |q: &[f64], i: usize| {
            let o = &prep.obs[i];
            (o.y - rel.predict_with(q, 0.0, &o.x)).powi(2)
        };
        // Per subject (in subject order): its rows' errors, or None when the fold failed.
        let res: Vec<Option<Vec<f64>>> = match &sorted {
            // Folds are subject multisets: no pass over the training rows.
            Some(sr) if n_bp > 0 => {
                use rayon::prelude::*;
                // Folds' keys without a pass over the rows; with a per-subject column, their
                // sums as exact downdates of sums shared by all folds (module profile::folds).
                let fold_keys = FoldKeys::new(sr);
                let engine = match bps[..] {
                    [i] => plan.search[i].and_then(|r| FoldEngine::new(sr, &lay, &p, i, r)),
                    _ => None,
                };
                if engine.is_none() {
                    share_first_grid(sr, rel, &free, &plan.search, &p, &bps);
                }
                (0..n_subj)
                    .into_par_iter()
                    .map(|s| {
                        let fold = Subset::Fold(sr, &fold_keys, engine.as_ref(), s);
                        let q = refit(rel, &free, &p, fold)?;
                        Some(rows_of[s].iter().map(|&i| sq_err(&q, i)).collect())
                    })
                    .collect()
            }
            // Nothing but linear coefficients to refit, and a plan that does not depend on the
            // rows: a fold's sums are the other subjects' sums, all from one pass (bounded
            // problems re-solved over every coefficient the data identify).
            _ if linear_folds => match fold_bounds {
                Some(_) => loso_from_subject_sums(rel, &lay_pre, &p_pre, &prep, fold_bounds),
                None => loso_from_subject_sums(rel, &lay, &p, &prep, None),
            },
            _ => leave_one_group_out(&prep.subject, |train, test| {
                Some(
                    refit(rel, &free, &p, Subset::Rows(&prep, train))
                        .map(|q| test.iter().map(|&i| sq_err(&q, i)).collect::<Vec<f64>>()),
                )
            }),
        };
        let mut folds = 0;
        for (s, r) in res.into_iter().enumerate() {
            if let Some(v) = r {
                folds += 1;
                for (&i, e) in rows_of[s].iter().zip(v) {
                    loso_sq[i] = e;
                }
            }
        }
        if folds == n_subj && loso_sq.iter().all(|v| v.is_finite()) {
            (
                Some((loso_sq.iter().sum::<f64>() / n as f64).sqrt()),
                format!(
                    "{n_subj} folds; each subject predicted (level 0) from a full refit{}, on \
                     the others",
                    if n_bp > 0 {
                        ", breakpoints included"
                    } else if col_bounds.is_some() {
                        ", the bounded problem re-solved"
                    } else {
                        ""
                    }
                ),
            )
        } else {
            (
                None,
                format!(
                    "{} of {n_subj} leave-one-subject-out refits failed",
                    n_subj - folds
                ),
            )
        }
    } else {
        (None, format!("needs at least 3 subjects (have {n_subj})"))
    };

    // Published coefficients on the same rows.
    let pub_res: Vec<f64> = prep
        .obs
        .iter()
        .map(|o| o.y - rel.predict_with(&published, 0.0, &o.x))
        .collect();
    let pub_rss: f64 = pub_res
        .iter()
        .zip(&prep.weights)
        .map(|(e, w)| w * e * e)
        .sum();
    let pub_r2 = if rel.card().has_intercept {
        r2_centred(&obs_y, pub_rss, wopt)
    } else {
        r2_uncentred(&obs_y, pub_rss, wopt)
    };
    let pub_rmse = (pub_res.iter().map(|e| e * e).sum::<f64>() / n as f64).sqrt();
    // Several outputs per row (kb-mu): r² centred within each output, per-output statistics.
    let multi = super::constrained::output_stats(
        rel,
        &prep,
        &residuals,
        &fit.leverage,
        &pub_res,
        &loso_sq,
        weighted,
        df,
    );
    let (r2, r2_def, adj_r2, pub_r2) = match &multi {
        Some(m) => (m.r2, m.definition.clone(), m.adj_r2, m.published_r2),
        None => (r2, r2_def, adj_r2, pub_r2),
    };

    let random_subject = opts
        .random_subject
        .then(|| super::mixed::random_subject_record(rel, &prep, &p, weighted));
    // Robust refit.
    let robust = if opts.robust {
        Some(robust_refit(
            rel,
            &lay,
            &p,
            &prep,
            &free,
            &held_reason,
            &published,
            weighted,
            method,
        )?)
    } else {
        None
    };

    // Bootstrap by subject.
    let bootstrap = if opts.bootstrap > 0 {
        let groups = prep.subject.clone();
        // Bounded problems report every coefficient the data identify (a bound active on all
        // data may be inactive in a replicate).
        let idx_free: Vec<usize> = (0..specs.len())
            .filter(|&i| free[i] || (fold_bounds.is_some() && lay_pre.free[i]))
            .collect();
        let summary = if linear_folds {
            // Replicates are sums of per-subject records: no pass over the rows (bounded
            // problems re-solved over every coefficient the data identify).
            let (bl, bp_) = if fold_bounds.is_some() {
                (&lay_pre, &p_pre)
            } else {
                (&lay, &p)
            };
            let sums = all_subject_sums(rel, bl, bp_, &prep).ok_or_else(|| FitError::Singular {
                relation: id.clone(),
                message: "a subject's own slope column is all zeros".into(),
            })?;
            bootstrap_by_group(&groups, opts.bootstrap, opts.seed, |rows| {
                let m_list = whole_subjects(&prep, rows)?;
                let mut t = Totals::zeros(bl.m());
                for (s, mult) in m_list {
                    t.add(&sums[s], mult);
                }
                let coef = solve_totals(&t, bl, fold_bounds)?;
                let q = bl.params(rel, bp_, &coef);
                Some(idx_free.iter().map(|&i| q[i]).collect())
            })
        } else {
            bootstrap_by_group(&groups, opts.bootstrap, opts.seed, |rows| {
                let q = match (&sorted, whole_subjects(&prep, rows)) {
                    (Some(sr), Some(m)) => {
                        refit(rel, &free, &p, Subset::Subjects(sr, Members::List(&m)))
                    }
                    _ => refit(rel, &free, &p, Subset::Rows(&prep, rows)),
                }?;
                Some(idx_free.iter().map(|&i| q[i]).collect())
            })
        };
        for (k, &i) in idx_free.iter().enumerate() {
            if summary.n_ok > 1 {
                coefs[i].ci95_bootstrap = Some(summary.ci95[k]);
                coefs[i].se_bootstrap = opt(summary.std_dev[k]);
            }
        }
        Some(BootstrapRecord {
            n: opts.bootstrap,
            seed: opts.seed,
            failed: summary.n_failed,
            unit: "subjects (cluster bootstrap; breakpoints refitted in every replicate)".into(),
        })
    } else {
        None
    };

    // Wild cluster bootstrap-t, for fits linear in every free coefficient.
    let wild_linear = n_bp == 0 && lay.subj_col.is_none() && col_bounds.is_none() && !weighted;
    let wild_bootstrap = (opts.bootstrap > 0 && wild_linear && n_subj >= 2)
        .then(|| wild::wild_record(rel, &lay, &p, &prep, &values, opts.bootstrap, opts.seed))
        .flatten();

    for (i, h) in held_reason.iter().enumerate() {
        if let (false, Some(h)) = (free[i], h) {
            notes.push(format!("{}: {h}", specs[i].name));
        }
    }
    notes.push(format!("r² is {r2_def}"));
    if n_bp > 0 {
        notes.push(
            "breakpoint intervals are the hulls of F-based profile confidence sets (other \
             breakpoints held at their estimates; see breakpoints for the pieces); leave-one-out \
             (PRESS) holds the breakpoints fixed"
                .into(),
        );
    }

    let mut units = BTreeMap::new();
    let resp = rel.card().response;
    units.insert(resp.symbol.to_string(), resp.unit.to_string());
    for v in rel.card().inputs {
        units.insert(v.symbol.to_string(), v.unit.to_string());
    }
    for s in specs {
        units.insert(s.name.to_string(), s.unit.to_string());
    }
    if let Some(e) = rel.card().subject_effect {
        units.insert(e.name.to_string(), e.unit.to_string());
    }
    let valid_range = rel
        .card()
        .inputs
        .iter()
        .enumerate()
        .map(|(j, v)| {
            let (lo, hi) = prep
                .obs
                .iter()
                .fold((f64::INFINITY, f64::NEG_INFINITY), |a, o| {
                    (a.0.min(o.x[j]), a.1.max(o.x[j]))
                });
            RangeRecord {
                input: v.symbol.to_string(),
                unit: v.unit.to_string(),
                lo,
                hi,
            }
        })
        .collect();
    let derived_ref: BTreeMap<String, f64> = rel
        .derived(&published)
        .into_iter()
        .map(|(n, v, _)| (n, v))
        .collect();
    let derived = rel
        .derived(&values)
        .into_iter()
        .map(|(name, v, unit)| DerivedRecord {
            published: derived_ref.get(&name).copied().unwrap_or(f64::NAN),
            name,
            unit: unit.to_string(),
            value: v,
        })
        .chain(multi.into_iter().flat_map(|m| m.derived))
        .collect();
    let (path, sha256) = if prep.files.len() == 1 {
        (prep.files[0].path.clone(), prep.files[0].sha256.clone())
    } else {
        let joined: String = prep
            .files
            .iter()
            .map(|f| format!("{}  {}\n", f.sha256, f.path))
            .collect();
        (
            prep.files
                .iter()
                .map(|f| f.path.as_str())
                .collect::<Vec<_>>()
                .join(";"),
            crate::ingest::trials::sha256_hex(joined.as_bytes()),
        )
    };
    let c = rel.card().citation;
    let mut levels = BTreeMap::new();
    for c in &coefs {
        if let Some(s) = c
            .name
            .strip_prefix("level[")
            .and_then(|r| r.strip_suffix(']'))
        {
            levels.insert(s.to_string(), c.value);
        }
    }
    let band = Band {
        lay: lay.clone(),
        coef: fit.coef.clone(),
        cov: cov.clone(),
        bps: if cov_f.is_some() {
            bps.clone()
        } else {
            Vec::new()
        },
    };
    let record = FitRecord {
        relation: id.clone(),
        title: rel.card().title.to_string(),
        citation: format!("{}, {}", c.paper, c.equation),
        equation: rel.card().equation.to_string(),
        units,
        n,
        n_subjects: n_subj,
        coefficients: coefs,
        r2,
        r2_centred: Some(r2c),
        r2_definition: r2_def,
        adj_r2,
        rmse,
        residual_mean_square: sigma2,
        aic: aic(rss, n, k, sum_log_w),
        bic: bic(rss, n, k, sum_log_w),
        loo_rmse: press.sqrt(),
        loso_rmse,
        loso_note,
        published_fit: PublishedFit {
            r2: pub_r2,
            rmse: pub_rmse,
        },
        valid_range,
        outside_range: Some(crate::relations::OUTSIDE_RANGE_RULE.to_string()),
        inference: Some(inference),
        breakpoints: bp_records,
        bounded: col_bounds.as_ref().map(|_| box_stats.to_record()),
        data: DataRecord {
            path,
            sha256,
            rows_used: n,
            rows_rejected: prep.n_rejected,
            rows_other_gait: prep.n_other_gait,
            files: prep.files.clone(),
            rejected: prep.rejected.clone(),
        },
        gaitfit_version: crate::GAITFIT_VERSION.to_string(),
        derived,
        weights: opts.weights.clone(),
        robust,
        bootstrap,
        wild_bootstrap,
        random_subject: random_subject.and_then(|r| r.map_err(|why| notes.push(why)).ok()),
        notes,
    };
    // The refit knows the range it was fitted on (predictions beyond it hold the boundary).
    let mut fitted_range = crate::relations::FittedRange::default();
    for (b, g) in fitted_range.bounds.iter_mut().zip(&record.valid_range) {
        *b = (g.lo <= g.hi).then_some([g.lo, g.hi]);
    }
    let registered = || {
        crate::relations::by_id(&id).map_err(|e| FitError::InvalidInput {
            relation: id.clone(),
            message: e.to_string(),
        })
    };
    let refit = Fitted::new(registered()?, values.clone(), levels, fitted_range);
    Ok(FitOutcome {
        refit,
        published: Fitted::published(registered()?),
        record,
        prepared: prep,
        fitted,
        residuals,
        values,
        band,
    })
}

/// The outcome of fitting several relations.
#[derive(Debug, Default)]
pub struct FitRun {
    /// Successful fits, in the order requested.
    pub outcomes: Vec<FitOutcome>,
    /// Relations that could not be fitted, with the reason.
    pub failures: Vec<(String, String)>,
    /// Relations skipped because the data have no rows of their gait.
    pub skipped: Vec<(String, String)>,
}

/// Fits each relation on the tables. A relation whose gait has no rows, or none that it can
/// use, is *skipped* when `skip_missing_gait` (the default run over all relations), otherwise
/// it fails.
pub fn fit_all(
    relations: &[Box<dyn Relation>],
    tables: &[TrialsTable],
    opts: &FitOptions,
    skip_missing_gait: bool,
    mut progress: impl FnMut(&str),
) -> FitRun {
    let mut run = FitRun::default();
    for rel in relations {
        progress(rel.card().id);
        let has_gait = tables
            .iter()
            .any(|t| t.gait.iter().any(|g| *g == Some(rel.card().gait)));
        if !has_gait && skip_missing_gait {
            run.skipped.push((
                rel.card().id.to_string(),
                format!("no rows with gait = {}", rel.card().gait),
            ));
            continue;
        }
        match fit_relation(rel.as_ref(), tables, opts) {
            Ok(o) => run.outcomes.push(o),
            // Rows of the gait but none usable (e.g. no μ columns for kb-mu): nothing to fit.
            Err(e @ FitError::TooFew { have: 0, .. }) if skip_missing_gait => run
                .skipped
                .push((rel.card().id.to_string(), format!("no usable rows: {e}"))),
            Err(e) => run
                .failures
                .push((rel.card().id.to_string(), e.to_string())),
        }
    }
    run
}
