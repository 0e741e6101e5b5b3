//! The one generic routine that turns any [`Relation`] and trials tables into a [`FitRecord`]
//! with every statistic of issue 3, plus what the report needs (fitted values, residuals, a
//! confidence band).
//!
//! # Method
//! Every relation is linear in its [`ParamKind::Linear`] coefficients once its breakpoints are
//! fixed (separable least squares), so:
//! 1. rows are reduced to [`Observation`]s (papers' units); rows lacking a needed quantity,
//!    flagged as inconsistent, or without a usable weight are **rejected and reported** by reason;
//! 2. [`Relation::plan`] says which coefficients the data can identify; the others are held at
//!    their published values (and the record says why);
//! 3. each free breakpoint is **profiled**: the linear coefficients are refitted (normal
//!    equations in the relation's well-conditioned basis) at each trial value and the residual
//!    sum of squares minimised with argmin's Brent method after a grid scan
//!    ([`minimize_1d`]); two breakpoints are profiled by coordinate descent. A breakpoint that
//!    marks a feature which may be absent (a plateau onset, see [`Relation::breakpoint_null`])
//!    is kept only when an F-test against the model without the feature rejects at 5 %;
//!    otherwise it is held at the published value with the test in the notes;
//! 4. at the breakpoints' estimates the linear coefficients are solved by QR ([`ols`]) in the
//!    relation's basis and mapped to the raw coefficients ([`Relation::basis_to_params`]); with a
//!    per-subject effect (the running paper's `level`), each subject gets its own slope, the
//!    global slope is their unweighted mean and `level[s]` the deviations (they sum to zero);
//! 5. statistics: r² (centred, or uncentred without intercept), adjusted r², rmse = √(RSS/n),
//!    residual mean square RSS/(n − p) with p counting breakpoints, AIC/BIC (Gaussian
//!    likelihood), PRESS (leave-one-out) rmse from the leverages with breakpoints held at their
//!    estimate, leave-one-subject-out rmse (everything refitted without the subject, which is
//!    predicted with level 0), the published coefficients' r² and rmse on the same rows, t-tests
//!    against the published values, profile-likelihood (F-based) intervals for breakpoints,
//!    optional Huber IRLS and weighted fits and a seeded bootstrap by subject.
//!
//! Standard errors of linear coefficients are conditional on the breakpoint estimates (the
//! usual profile approach); the bootstrap intervals, which refit the breakpoints in every
//! replicate, include that uncertainty.
//!
//! [`minimize_1d`]: super::nonlinear::minimize_1d
use super::ols::{huber_irls, ols, LinearFit, LinearProblem};
use super::stats::{
    aic, bic, bootstrap_by_group, leave_one_group_out, r2_centred, r2_uncentred, t_quantile, TTest,
};
use super::FitError;
use crate::export::coeffs::{
    BootstrapRecord, CoefficientRecord, DataFile, DataRecord, DerivedRecord, FitRecord,
    PublishedFit, RangeRecord, RejectionRecord, RobustRecord, TTestRecord,
};
use crate::ingest::trials::TrialsTable;
use crate::relations::{Observation, ParamKind, Relation};
use profile::{
    profile, profile_interval, refit, whole_subjects, Members, Profiler, SortedRows, Source, Subset,
};

mod profile;
use crate::units::parse_header;
use nalgebra::{DMatrix, DVector};
pub use profile::DISCRETE_MAX_EVALS;
use std::collections::BTreeMap;

/// Huber tuning constant (95 % efficiency under normal errors).
pub const HUBER_K: f64 = 1.345;
/// Maximum IRLS iterations of the robust fit.
pub const HUBER_MAX_ITER: usize = 100;
/// Significance level of the test that keeps an optional breakpoint (plateau onset).
pub const BREAKPOINT_TEST_ALPHA: f64 = 0.05;
/// Confidence level of every interval gaitfit reports.
pub const CONFIDENCE: f64 = 0.95;
/// Rows listed per rejection reason.
const MAX_EXAMPLES: usize = 10;

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
}

impl FitOptions {
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

fn weight_column<'a>(t: &'a TrialsTable, name: &str) -> Option<&'a [f64]> {
    if let Ok(Some(c)) = parse_header(name) {
        if let Some(col) = &t.columns[c.quantity as usize] {
            return Some(col);
        }
    }
    t.extra
        .iter()
        .find(|(n, _)| n.eq_ignore_ascii_case(name))
        .map(|(_, v)| v.as_slice())
}

/// The rows a relation can use, reduced to observations.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct Prepared {
    /// Observations (papers' units).
    pub obs: Vec<Observation>,
    /// Per observation: index into `subjects`.
    pub subject: Vec<usize>,
    /// Subjects among the used rows, in order of first appearance.
    pub subjects: Vec<String>,
    /// Per observation: index into `files`, the data set it came from (reports colour
    /// residuals by subject and data set, so treadmill and overground rows are not pooled).
    pub file: Vec<u32>,
    /// Per observation: weight (all 1 without `--weights`).
    pub weights: Vec<f64>,
    /// Rejections by reason.
    pub rejected: Vec<RejectionRecord>,
    /// Rows rejected.
    pub n_rejected: usize,
    /// Rows of the other gait.
    pub n_other_gait: usize,
    /// The files.
    pub files: Vec<DataFile>,
}

/// Reduces the tables' rows to the observations `rel` uses, recording every rejection.
pub fn prepare(rel: &dyn Relation, tables: &[TrialsTable], weights: Option<&str>) -> Prepared {
    let mut p = Prepared::default();
    let mut reasons: BTreeMap<String, (usize, Vec<String>)> = BTreeMap::new();
    let mut subj_index: BTreeMap<String, usize> = BTreeMap::new();
    let mut reject = |reason: String, file: &str, row: usize, p: &mut Prepared| {
        let e = reasons.entry(reason).or_insert((0, Vec::new()));
        e.0 += 1;
        if e.1.len() < MAX_EXAMPLES {
            e.1.push(format!("{file}: row {row}"));
        }
        p.n_rejected += 1;
    };
    p.obs.reserve(tables.iter().map(|t| t.len()).sum());
    for t in tables {
        let file = t.path.display().to_string();
        let file_index = p.files.len() as u32;
        p.files.push(DataFile {
            path: file.clone(),
            sha256: t.sha256.clone(),
            rows: t.len(),
        });
        let flags: BTreeMap<usize, &str> =
            t.flagged.iter().map(|(r, s)| (*r, s.as_str())).collect();
        let wcol = weights.and_then(|w| weight_column(t, w));
        let mut subj_of_table: Vec<Option<usize>> = vec![None; t.subjects.len()];
        for i in 0..t.len() {
            match t.gait[i] {
                Some(g) if g == rel.gait() => {}
                Some(_) => {
                    p.n_other_gait += 1;
                    continue;
                }
                None => {
                    reject("gait missing".into(), &file, i + 1, &mut p);
                    continue;
                }
            }
            if t.is_flagged[i] {
                let why = flags
                    .get(&(i + 1))
                    .copied()
                    .unwrap_or("inconsistent values");
                let kind = if why.contains("speed") {
                    "flagged: speed, step length and step frequency disagree by more than 2 %"
                } else {
                    "flagged: inconsistent double-support values"
                };
                reject(kind.into(), &file, i + 1, &mut p);
                continue;
            }
            let w = match wcol {
                Some(c) => {
                    let w = c[i];
                    if !(w.is_finite() && w > 0.0) {
                        reject(
                            "weight missing or not positive".into(),
                            &file,
                            i + 1,
                            &mut p,
                        );
                        continue;
                    }
                    w
                }
                None => 1.0,
            };
            // A row gives one observation per output; it is rejected when none is usable.
            let row = t.values(i);
            let mut first_err = None;
            let mut used = false;
            for out in 0..rel.outputs() {
                match rel.observe_output(&row, out) {
                    Ok(o) => {
                        // The table's subject id → ours, looked up by name once per id (not
                        // once per row: a string map per row was a fifth of this function).
                        let ts = t.subject[i] as usize;
                        let k = match subj_of_table.get(ts).copied().flatten() {
                            Some(k) => k,
                            None => {
                                let name = t.subject_name(i);
                                let k = match subj_index.get(name) {
                                    Some(&k) => k,
                                    None => {
                                        let k = p.subjects.len();
                                        p.subjects.push(name.to_string());
                                        subj_index.insert(name.to_string(), k);
                                        k
                                    }
                                };
                                if let Some(slot) = subj_of_table.get_mut(ts) {
                                    *slot = Some(k);
                                }
                                k
                            }
                        };
                        p.obs.push(o);
                        p.subject.push(k);
                        p.file.push(file_index);
                        p.weights.push(w);
                        used = true;
                    }
                    Err(r) => {
                        first_err.get_or_insert(r);
                    }
                }
            }
            if let (false, Some(r)) = (used, first_err) {
                reject(r.to_string(), &file, i + 1, &mut p);
            }
        }
    }
    p.rejected = reasons
        .into_iter()
        .map(|(reason, (count, examples))| RejectionRecord {
            reason,
            count,
            examples,
        })
        .collect();
    p
}

/// How the design is laid out for a given set of free coefficients and subjects.
#[derive(Debug, Clone)]
struct Layout {
    free: Vec<bool>,
    nb: usize,
    subj_col: Option<usize>,
    n_subj: usize,
}

impl Layout {
    fn new(rel: &dyn Relation, free: Vec<bool>, n_subj: usize) -> Layout {
        let nb = rel.basis_len(&free);
        let subj_col = if n_subj >= 2 && rel.subject_effect().is_some() {
            rel.subject_column(&free)
        } else {
            None
        };
        Layout {
            free,
            nb,
            subj_col,
            n_subj,
        }
    }
    fn ncols(&self) -> usize {
        match self.subj_col {
            Some(_) => self.nb - 1 + self.n_subj,
            None => self.nb,
        }
    }
    /// Fills the design row (sparse: `idx`/`val`, returns the count) and returns the offset.
    #[inline]
    fn row(
        &self,
        rel: &dyn Relation,
        p: &[f64],
        o: &Observation,
        subject: usize,
        idx: &mut [usize; 17],
        val: &mut [f64; 17],
    ) -> (usize, f64) {
        let mut phi = [0.0; 16];
        let off = rel.basis(p, &self.free, &o.x, &mut phi[..self.nb]);
        let mut k = 0;
        for (j, &v) in phi[..self.nb].iter().enumerate() {
            if v == 0.0 {
                continue;
            }
            let col = match self.subj_col {
                Some(sc) if j == sc => self.nb - 1 + subject,
                Some(sc) if j > sc => j - 1,
                _ => j,
            };
            idx[k] = col;
            val[k] = v;
            k += 1;
        }
        (k, off)
    }
    /// The dense design row for the average subject (subject columns share the slope equally).
    fn mean_row(&self, rel: &dyn Relation, p: &[f64], x: &[f64]) -> (DVector<f64>, f64) {
        let mut phi = [0.0; 16];
        let off = rel.basis(p, &self.free, x, &mut phi[..self.nb]);
        let mut r = DVector::zeros(self.ncols());
        for (j, &v) in phi[..self.nb].iter().enumerate() {
            match self.subj_col {
                Some(sc) if j == sc => {
                    for s in 0..self.n_subj {
                        r[self.nb - 1 + s] = v / self.n_subj as f64;
                    }
                }
                Some(sc) if j > sc => r[j - 1] = v,
                _ => r[j] = v,
            }
        }
        (r, off)
    }
    /// The linear map from design coefficients to `[raw linear params; levels]`.
    fn output_map(&self, rel: &dyn Relation, p: &[f64]) -> (DMatrix<f64>, DVector<f64>) {
        let lm = rel.basis_to_params(p, &self.free);
        let nc = self.ncols();
        // A: design coefficients → relation-basis coefficients.
        let mut a = DMatrix::zeros(self.nb, nc);
        for j in 0..self.nb {
            match self.subj_col {
                Some(sc) if j == sc => {
                    for s in 0..self.n_subj {
                        a[(j, self.nb - 1 + s)] = 1.0 / self.n_subj as f64;
                    }
                }
                Some(sc) if j > sc => a[(j, j - 1)] = 1.0,
                _ => a[(j, j)] = 1.0,
            }
        }
        let n_lin = lm.map.nrows();
        let n_lev = if self.subj_col.is_some() {
            self.n_subj
        } else {
            0
        };
        let mut g = DMatrix::zeros(n_lin + n_lev, nc);
        let mut shift = DVector::zeros(n_lin + n_lev);
        g.rows_mut(0, n_lin).copy_from(&(&lm.map * &a));
        shift.rows_mut(0, n_lin).copy_from(&lm.shift);
        if let Some(sc) = self.subj_col {
            // level_s = β_s − mean(β); the relation-basis coefficient of column `sc` must equal
            // the `on` parameter (documented requirement of `subject_column`).
            for s in 0..self.n_subj {
                for t in 0..self.n_subj {
                    g[(n_lin + s, self.nb - 1 + t)] =
                        if s == t { 1.0 } else { 0.0 } - 1.0 / self.n_subj as f64;
                }
            }
            let _ = sc;
        }
        (g, shift)
    }
}

/// Leave-one-subject-out for a fit with only linear coefficients to refit and no per-subject
/// columns: every subject's weighted normal equations from one pass, each fold solved from the
/// sums of the others (prefix + suffix over subjects, so no subtraction and no pass per fold).
/// Per subject, in subject order: the squared prediction errors of its rows (level 0), or
/// `None` when the fold is singular — what [`leave_one_group_out`] with a refit per fold gives.
fn loso_from_subject_sums(
    rel: &dyn Relation,
    lay: &Layout,
    p: &[f64],
    prep: &Prepared,
    n_subj: usize,
) -> Vec<Option<Vec<f64>>> {
    let nc = lay.ncols();
    let m = nc * nc + nc + 1;
    // Per subject: XᵀWX (lower triangle by first index, as in `solve_ne`), XᵀWy, yᵀWy.
    let mut sums = vec![0.0f64; n_subj * m];
    let mut idx = [0usize; 17];
    let mut val = [0.0f64; 17];
    for (i, o) in prep.obs.iter().enumerate() {
        let s = prep.subject[i];
        let (k, off) = lay.row(rel, p, o, s, &mut idx, &mut val);
        let w = prep.weights[i];
        let y = o.y - off;
        let acc = &mut sums[s * m..(s + 1) * m];
        acc[m - 1] += w * y * y;
        for a in 0..k {
            let wa = w * val[a];
            let ia = idx[a];
            acc[nc * nc + ia] += wa * y;
            for b in 0..=a {
                acc[ia * nc + idx[b]] += wa * val[b];
            }
        }
    }
    let add = |into: &mut [f64], from: &[f64]| into.iter_mut().zip(from).for_each(|(a, b)| *a += b);
    let mut prefix = vec![0.0f64; (n_subj + 1) * m];
    for s in 0..n_subj {
        let (head, tail) = prefix.split_at_mut((s + 1) * m);
        tail[..m].copy_from_slice(&head[s * m..]);
        add(&mut tail[..m], &sums[s * m..(s + 1) * m]);
    }
    let mut suffix = vec![0.0f64; (n_subj + 1) * m];
    for s in (0..n_subj).rev() {
        let (head, tail) = suffix.split_at_mut((s + 1) * m);
        head[s * m..].copy_from_slice(&tail[..m]);
        add(&mut head[s * m..], &sums[s * m..(s + 1) * m]);
    }
    let mut rows_of = vec![Vec::new(); n_subj];
    for (i, &s) in prep.subject.iter().enumerate() {
        rows_of[s].push(i);
    }
    let (g, shift) = lay.output_map(rel, p);
    (0..n_subj)
        .map(|s| {
            let mut acc = prefix[s * m..(s + 1) * m].to_vec();
            add(&mut acc, &suffix[(s + 1) * m..(s + 2) * m]);
            let xtx = symmetric_xtx(nc, &acc);
            let (beta, _) = solve_normal(nc, &xtx, &acc[nc * nc..nc * nc + nc], acc[m - 1])?;
            let out = &g * &beta + &shift;
            let mut q = p.to_vec();
            let mut j = 0;
            for (i, spec) in rel.parameters().iter().enumerate() {
                if spec.kind == ParamKind::Linear {
                    q[i] = out[j];
                    j += 1;
                }
            }
            Some(
                rows_of[s]
                    .iter()
                    .map(|&i| {
                        let o = &prep.obs[i];
                        (o.y - rel.predict_with(&q, 0.0, &o.x)).powi(2)
                    })
                    .collect(),
            )
        })
        .collect()
}

/// Normal-equation solve on a subset of rows: (coefficients, weighted RSS). Used for profiling,
/// cross-validation and the bootstrap; the reported fit uses QR.
fn solve_ne(
    rel: &dyn Relation,
    lay: &Layout,
    p: &[f64],
    prep: &Prepared,
    rows: Option<&[usize]>,
    subj_map: Option<&[usize]>,
) -> Option<(DVector<f64>, f64)> {
    let nc = lay.ncols();
    // Accumulate into flat buffers (row-major, lower triangle by first index): this loop is the
    // cost of every profile evaluation.
    let mut acc = vec![0.0f64; nc * nc];
    let mut aty = vec![0.0f64; nc];
    let mut yty = 0.0;
    let mut idx = [0usize; 17];
    let mut val = [0.0f64; 17];
    let mut add = |i: usize| {
        let o = &prep.obs[i];
        let s = subj_map.map_or(prep.subject[i], |m| m[prep.subject[i]]);
        let (k, off) = lay.row(rel, p, o, s, &mut idx, &mut val);
        let w = prep.weights[i];
        let y = o.y - off;
        yty += w * y * y;
        for a in 0..k {
            let wa = w * val[a];
            let ia = idx[a];
            aty[ia] += wa * y;
            let rowa = &mut acc[ia * nc..ia * nc + nc];
            for b in 0..=a {
                rowa[idx[b]] += wa * val[b];
            }
        }
    };
    match rows {
        Some(r) => r.iter().for_each(|&i| add(i)),
        None => (0..prep.obs.len()).for_each(&mut add),
    }
    let xtx = symmetric_xtx(nc, &acc);
    solve_normal(nc, &xtx, &aty, yty)
}

/// Solves normal equations (`xtx` full `nc × nc` row-major): (coefficients, weighted RSS), or
/// `None` when the design is singular. Columns are equilibrated before Cholesky so that badly
/// scaled ones do not fail it.
fn solve_normal(nc: usize, xtx: &[f64], xty: &[f64], yty: f64) -> Option<(DVector<f64>, f64)> {
    let d: Vec<f64> = (0..nc)
        .map(|j| {
            let v = xtx[j * nc + j];
            if v > 0.0 {
                1.0 / v.sqrt()
            } else {
                0.0
            }
        })
        .collect();
    if d.contains(&0.0) || d.iter().any(|v| !v.is_finite()) {
        return None;
    }
    let s = DMatrix::from_fn(nc, nc, |a, b| xtx[a * nc + b] * (d[a] * d[b]));
    let rhs = DVector::from_iterator(nc, (0..nc).map(|j| xty[j] * d[j]));
    let chol = s.cholesky()?;
    let z = chol.solve(&rhs);
    let beta = DVector::from_iterator(nc, (0..nc).map(|j| z[j] * d[j]));
    let rss = (yty - beta.dot(&DVector::from_column_slice(xty))).max(0.0);
    Some((beta, rss))
}

/// Everything a fit produced: the record plus what plots need.
#[derive(Debug)]
pub struct FitOutcome {
    /// The statistics (written to `fits/`).
    pub record: FitRecord,
    /// The relation with the refitted coefficients.
    pub refit: Box<dyn Relation>,
    /// The relation with the published coefficients.
    pub published: Box<dyn Relation>,
    /// The rows used.
    pub prepared: Prepared,
    /// Fitted values (each row with its subject's level).
    pub fitted: Vec<f64>,
    /// Residuals y − fitted.
    pub residuals: Vec<f64>,
    /// Refit coefficients (global, `parameters()` order).
    pub values: Vec<f64>,
    lay: Layout,
    beta: DVector<f64>,
    cov: DMatrix<f64>,
    df: f64,
}

impl FitOutcome {
    /// The refit prediction for an average subject at `x` with its 95 % confidence band
    /// (conditional on the breakpoint estimates): `(mean, lo, hi)`.
    pub fn band(&self, x: &[f64]) -> (f64, f64, f64) {
        let rel = self.refit.as_ref();
        let (r, off) = self.lay.mean_row(rel, &self.values, x);
        let m = off + r.dot(&self.beta);
        let var = (r.transpose() * &self.cov * &r)[(0, 0)].max(0.0);
        let q = t_quantile(0.5 + 0.5 * CONFIDENCE, self.df);
        (m, m - q * var.sqrt(), m + q * var.sqrt())
    }
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
    let id = rel.id().to_string();
    let prep = prepare(rel, tables, opts.weights.as_deref());
    let n = prep.obs.len();
    let specs = rel.parameters();
    let published = rel.values().to_vec();
    // Rows sorted once by the breakpoint key, with prefix sums: every profile evaluation
    // below (search, F-test, intervals, folds, bootstrap) then costs O(p³), not a pass.
    // The tree over all rows serves fits without per-subject columns; with them, every
    // evaluation (and fold, and replicate) sums subjects' trees.
    let with_all = !(rel.subject_effect().is_some() && prep.subjects.len() >= 2);
    let sorted = rel
        .sorted_profile()
        .map(|form| SortedRows::new(form, &prep, with_all));
    let all_keys: Vec<f64> = sorted.as_ref().map_or_else(Vec::new, |sr| {
        sr.distinct_keys(&vec![true; prep.subjects.len()])
    });
    let src = match &sorted {
        Some(sr) => Source::Sorted {
            sr,
            members: Members::All,
            keys: &all_keys,
        },
        None => Source::Rows {
            prep: &prep,
            rows: None,
            subj_map: None,
        },
    };
    let plan = match &sorted {
        Some(sr) => sr.form().plan_sorted(&all_keys),
        None => rel.plan(&prep.obs),
    };
    let mut free: Vec<bool> = plan.held.iter().map(|h| h.is_none()).collect();
    let mut held_reason: Vec<Option<String>> = plan.held.clone();
    let n_subj = prep.subjects.len();
    let mut notes = Vec::new();

    let n_params_max = Layout::new(rel, free.clone(), n_subj).ncols()
        + free
            .iter()
            .zip(specs)
            .filter(|(f, s)| **f && s.kind == ParamKind::Breakpoint)
            .count();
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
            what: format!("rows of gait `{}`", rel.gait()),
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
    let mut lay = Layout::new(rel, free.clone(), n_subj);
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
    // Bounded parameters (Relation::bounds): argmin's bounded fit decides which sit on a bound.
    let mut bound_flag: Vec<Option<String>> = vec![None; specs.len()];
    let (hits, bound_note) =
        super::constrained::active_bounds(rel, &prep, &free, &p, opts.weights.is_some())?;
    notes.extend(bound_note);
    for b in hits {
        free[b.index] = false;
        p[b.index] = b.value;
        held_reason[b.index] = Some(b.describe(specs[b.index].name));
        bound_flag[b.index] = Some("bound active".into());
    }
    lay = Layout::new(rel, free.clone(), n_subj);
    let nc = lay.ncols();
    let n_bp = free
        .iter()
        .zip(specs)
        .filter(|(f, s)| **f && s.kind == ParamKind::Breakpoint)
        .count();
    let k = nc + n_bp;
    if n < k + 2 {
        return Err(FitError::TooFew {
            relation: id.clone(),
            what: format!("rows of gait `{}`", rel.gait()),
            have: n,
            need: k + 2,
        });
    }

    // The reported fit: QR at the breakpoint estimates.
    let mut x = DMatrix::<f64>::zeros(n, nc);
    let mut y = DVector::<f64>::zeros(n);
    let mut offsets = vec![0.0; n];
    let mut idx = [0usize; 17];
    let mut val = [0.0f64; 17];
    for i in 0..n {
        let (kk, off) = lay.row(rel, &p, &prep.obs[i], prep.subject[i], &mut idx, &mut val);
        for a in 0..kk {
            x[(i, idx[a])] = val[a];
        }
        offsets[i] = off;
        y[i] = prep.obs[i].y - off;
    }
    let w = DVector::from_vec(prep.weights.clone());
    let weighted = opts.weights.is_some();
    let col_names: Vec<String> = (0..nc)
        .map(|j| match lay.subj_col {
            Some(_) if j >= lay.nb - 1 => format!(
                "{}[{}]",
                rel.subject_effect().map_or("", |e| e.on),
                prep.subjects[j - (lay.nb - 1)]
            ),
            _ => format!("basis column {j}"),
        })
        .collect();
    let mut problem = LinearProblem::new(&x, &y)
        .named(&id)
        .with_column_names(&col_names);
    if weighted {
        problem = problem.with_weights(&w);
    }
    let lf: LinearFit = ols(&problem)?;
    if lf.ill_conditioned() {
        notes.push(format!(
            "the design is ill-conditioned (condition number {:.2e}); coefficients may have lost digits",
            lf.condition_number
        ));
    }
    let (g, shift) = lay.output_map(rel, &p);
    let out = &g * &lf.coef + &shift;
    let cov_out = &g * &lf.cov * g.transpose();
    let df = (n - k) as f64;
    let rss = lf.rss;
    let sigma2 = rss / df;
    // ols counted only the linear columns; rescale its covariance to the full p.
    let cov_scale = if lf.df_resid > 0 {
        sigma2 / (lf.rss / lf.df_resid as f64)
    } else {
        1.0
    };
    let cov_out = cov_out * cov_scale;
    let cov_beta = &lf.cov * cov_scale;
    let tq = t_quantile(0.5 + 0.5 * CONFIDENCE, df);

    let mut values = p.clone();
    {
        let mut j = 0;
        for (i, s) in specs.iter().enumerate() {
            if s.kind == ParamKind::Linear {
                values[i] = out[j];
                j += 1;
            }
        }
    }
    notes.extend(super::constrained::violations(rel, &values, &free));
    // Fitted values and residuals in the response's terms.
    let fitted: Vec<f64> = (0..n).map(|i| offsets[i] + lf.fitted[i]).collect();
    let obs_y: Vec<f64> = prep.obs.iter().map(|o| o.y).collect();
    let residuals: Vec<f64> = (0..n).map(|i| obs_y[i] - fitted[i]).collect();
    let wopt = weighted.then_some(prep.weights.as_slice());
    let (r2, r2_def) = if rel.has_intercept() {
        (
            r2_centred(&obs_y, rss, wopt),
            "centred: 1 − RSS/Σ(y − ȳ)²".to_string(),
        )
    } else {
        (
            r2_uncentred(&obs_y, rss, wopt),
            "uncentred (regression through the origin, as NIST StRD defines it): 1 − RSS/Σy²"
                .to_string(),
        )
    };
    let adj_r2 = if rel.has_intercept() {
        1.0 - (1.0 - r2) * (n as f64 - 1.0) / df
    } else {
        1.0 - (1.0 - r2) * n as f64 / df
    };
    let rmse = (residuals.iter().map(|e| e * e).sum::<f64>() / n as f64).sqrt();
    let press: f64 = (0..n)
        .map(|i| (residuals[i] / (1.0 - lf.leverage[i])).powi(2))
        .sum::<f64>()
        / n as f64;
    let sum_log_w = if weighted { lf.sum_log_w } else { 0.0 };

    // Coefficients.
    let mut coefs = Vec::new();
    let mut lin_j = 0;
    for (i, s) in specs.iter().enumerate() {
        let (value, se, ci) = if s.kind == ParamKind::Linear {
            let j = lin_j;
            lin_j += 1;
            if free[i] {
                let se = cov_out[(j, j)].max(0.0).sqrt();
                let v = out[j];
                (v, Some(se), [opt(v - tq * se), opt(v + tq * se)])
            } else {
                (p[i], None, [None, None])
            }
        } else if free[i] {
            let (lo, hi) = profile_interval(
                &Profiler {
                    rel,
                    lay: &lay,
                    src,
                },
                &p,
                i,
                &plan.search,
                df,
                tq,
            );
            let se = match (lo, hi) {
                (Some(a), Some(b)) => Some((b - a) / (2.0 * tq)),
                _ => None,
            };
            (p[i], se, [lo, hi])
        } else {
            (published[i], None, [None, None])
        };
        let t_test = se.map(|se| {
            let t = TTest::new(value, published[i], se, df);
            TTestRecord {
                t: opt(t.t),
                df,
                p_value: opt(t.p_value),
            }
        });
        coefs.push(CoefficientRecord {
            name: s.name.to_string(),
            unit: s.unit.to_string(),
            value,
            std_error: se,
            ci95: ci,
            published: published[i],
            t_test,
            ci95_bootstrap: None,
            held: if free[i] {
                None
            } else {
                held_reason[i].clone()
            },
            flag: bound_flag[i].clone(),
        });
    }
    let n_lin = rel.n_linear();
    if let (Some(e), Some(_)) = (rel.subject_effect(), lay.subj_col) {
        for (s, name) in prep.subjects.iter().enumerate() {
            let j = n_lin + s;
            let v = out[j];
            let se = cov_out[(j, j)].max(0.0).sqrt();
            let t = TTest::new(v, 0.0, se, df);
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
                name: format!("{}[{name}]", e.name),
                unit: e.unit.to_string(),
                value: v,
                std_error: Some(se),
                ci95: [opt(v - tq * se), opt(v + tq * se)],
                published: 0.0,
                t_test: Some(TTestRecord {
                    t: opt(t.t),
                    df,
                    p_value: opt(t.p_value),
                }),
                ci95_bootstrap: None,
                held: None,
                flag,
            });
        }
        notes.push(format!(
            "{} is fitted per subject as an offset on {} (the offsets sum to zero, so {} is the \
             average subject's); held-out and new subjects are predicted with {} = 0",
            e.name, e.on, e.on, e.name
        ));
    } else if rel.subject_effect().is_some() {
        notes.push(format!(
            "one subject only: no per-subject {} fitted",
            rel.subject_effect().map_or("", |e| e.name)
        ));
    }

    // Leave-one-subject-out.
    let (loso_rmse, loso_note) = if n_subj >= 3 {
        let sq_err = |q: &[f64], i: usize| {
            let o = &prep.obs[i];
            (o.y - rel.predict_with(q, 0.0, &o.x)).powi(2)
        };
        let res: Vec<Vec<f64>> = match &sorted {
            // Folds are subject multisets: no pass over the training rows.
            Some(sr) => {
                let mut rows_of = vec![Vec::new(); n_subj];
                for (i, &s) in prep.subject.iter().enumerate() {
                    rows_of[s].push(i);
                }
                use rayon::prelude::*;
                (0..n_subj)
                    .into_par_iter()
                    .map(|s| {
                        let fold = Subset::Subjects(sr, Members::AllBut(s));
                        let q = refit(rel, &free, &p, fold)?;
                        Some(rows_of[s].iter().map(|&i| sq_err(&q, i)).collect())
                    })
                    .collect::<Vec<Option<Vec<f64>>>>()
                    .into_iter()
                    .flatten()
                    .collect()
            }
            // Nothing but linear coefficients to refit, and a plan that does not depend on the
            // rows: a fold's normal equations are the other subjects' sums, all from one pass.
            None if n_bp == 0 && lay.subj_col.is_none() && rel.plan(&[]) == plan => {
                loso_from_subject_sums(rel, &lay, &p, &prep, n_subj)
                    .into_iter()
                    .flatten()
                    .collect()
            }
            None => leave_one_group_out(&prep.subject, |train, test| {
                let q = refit(rel, &free, &p, Subset::Rows(&prep, train))?;
                Some(test.iter().map(|&i| sq_err(&q, i)).collect::<Vec<f64>>())
            }),
        };
        let folds = res.len();
        let sq: Vec<f64> = res.into_iter().flatten().collect();
        if folds == n_subj && !sq.is_empty() {
            (
                Some((sq.iter().sum::<f64>() / sq.len() as f64).sqrt()),
                format!(
                    "{n_subj} folds; each subject predicted (level 0) from a full refit{}, on \
                     the others",
                    if n_bp > 0 {
                        ", breakpoints included"
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
    let pub_r2 = if rel.has_intercept() {
        r2_centred(&obs_y, pub_rss, wopt)
    } else {
        r2_uncentred(&obs_y, pub_rss, wopt)
    };
    let pub_rmse = (pub_res.iter().map(|e| e * e).sum::<f64>() / n as f64).sqrt();
    // Several outputs per row (kb-mu): r² centred within each output, per-output statistics.
    let multi = super::constrained::output_stats(
        rel,
        &prep,
        &values,
        &residuals,
        lf.leverage.as_slice(),
        &pub_res,
        weighted,
        df,
    );
    let (r2, r2_def, adj_r2, pub_r2) = match &multi {
        Some(m) => (m.r2, m.definition.clone(), m.adj_r2, m.published_r2),
        None => (r2, r2_def, adj_r2, pub_r2),
    };

    // Robust refit.
    let robust = if opts.robust {
        let h = huber_irls(&problem, HUBER_K, HUBER_MAX_ITER)?;
        let rout = &g * &h.fit.coef + &shift;
        let rcov = &g * &h.fit.cov * g.transpose();
        let mut rc = Vec::new();
        let mut j = 0;
        for (i, s) in specs.iter().enumerate() {
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
                published: published[i],
                t_test: None,
                ci95_bootstrap: None,
                held: if free[i] {
                    None
                } else {
                    held_reason[i].clone()
                },
                flag: None,
            });
            j += 1;
        }
        Some(RobustRecord {
            k: h.k,
            scale: h.scale,
            iterations: h.iterations,
            converged: h.converged,
            rows_downweighted: h.robust_weights.iter().filter(|&&u| u < 1.0).count(),
            coefficients: rc,
        })
    } else {
        None
    };

    // Bootstrap by subject.
    let bootstrap = if opts.bootstrap > 0 {
        let groups = prep.subject.clone();
        let idx_free: Vec<usize> = (0..specs.len()).filter(|&i| free[i]).collect();
        let summary = bootstrap_by_group(&groups, opts.bootstrap, opts.seed, |rows| {
            let q = match (&sorted, whole_subjects(&prep, rows)) {
                (Some(sr), Some(m)) => {
                    refit(rel, &free, &p, Subset::Subjects(sr, Members::List(&m)))
                }
                _ => refit(rel, &free, &p, Subset::Rows(&prep, rows)),
            }?;
            Some(idx_free.iter().map(|&i| q[i]).collect())
        });
        for (k, &i) in idx_free.iter().enumerate() {
            if summary.n_ok > 1 {
                coefs[i].ci95_bootstrap = Some(summary.ci95[k]);
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

    for (i, h) in held_reason.iter().enumerate() {
        if let (false, Some(h)) = (free[i], h) {
            notes.push(format!("{}: {h}", specs[i].name));
        }
    }
    notes.push(format!("r² is {r2_def}"));
    if n_bp > 0 {
        notes.push(
            "breakpoint intervals are profile-likelihood (F-based) intervals with the other \
             breakpoints held at their estimates; linear standard errors are conditional on the \
             breakpoint estimates; leave-one-out (PRESS) holds the breakpoints fixed"
                .into(),
        );
    }

    let mut units = BTreeMap::new();
    let resp = rel.response();
    units.insert(resp.symbol.to_string(), resp.unit.to_string());
    for v in rel.inputs() {
        units.insert(v.symbol.to_string(), v.unit.to_string());
    }
    for s in specs {
        units.insert(s.name.to_string(), s.unit.to_string());
    }
    if let Some(e) = rel.subject_effect() {
        units.insert(e.name.to_string(), e.unit.to_string());
    }
    let valid_range = rel
        .inputs()
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
    let c = rel.citation();
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
    let record = FitRecord {
        relation: id.clone(),
        title: rel.title().to_string(),
        citation: format!("{}, {}", c.paper, c.equation),
        equation: rel.equation().to_string(),
        units,
        n,
        n_subjects: n_subj,
        coefficients: coefs,
        r2,
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
        notes,
    };
    Ok(FitOutcome {
        refit: rel.with_values(&values, levels),
        published: rel.with_values(&published, BTreeMap::new()),
        record,
        prepared: prep,
        fitted,
        residuals,
        values,
        lay,
        beta: lf.coef.clone(),
        cov: cov_beta,
        df,
    })
}

/// Reads raw measured files (C3D, TRC + forces, treadmill GRF, …) into per-step rows: the hook
/// through which the events layer feeds `gaitfit fit` (pass it to [`load_tables`]).
pub type RawStepReader = fn(&std::path::Path) -> crate::Result<Vec<crate::ingest::trials::StepRow>>;

/// Whether `path` names a trials table (`.csv`) rather than a raw measured file.
pub fn is_trials_table(path: &std::path::Path) -> bool {
    path.extension()
        .is_some_and(|e| e.eq_ignore_ascii_case("csv"))
}

/// Loads trials tables (`.csv`) and, through `raw`, raw measured files.
pub fn load_tables(
    paths: &[std::path::PathBuf],
    raw: Option<RawStepReader>,
) -> crate::Result<Vec<TrialsTable>> {
    let mut out = Vec::with_capacity(paths.len());
    for p in paths {
        if is_trials_table(p) {
            out.push(crate::ingest::trials::read_trials(p)?);
        } else if let Some(raw) = raw {
            let rows = raw(p)?;
            let mut t = TrialsTable::from_step_rows(p, &rows);
            if let Ok(bytes) = std::fs::read(p) {
                t.sha256 = crate::ingest::trials::sha256_hex(&bytes);
            }
            out.push(t);
        } else {
            return Err(crate::ingest::IngestError::malformed(
                p,
                "not a trials table (.csv); raw measured files need the events layer: \
                 derive per-step rows with `gaitfit events` and pass the resulting CSV",
            )
            .into());
        }
    }
    Ok(out)
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
        progress(rel.id());
        let has_gait = tables
            .iter()
            .any(|t| t.gait.iter().any(|g| *g == Some(rel.gait())));
        if !has_gait && skip_missing_gait {
            run.skipped.push((
                rel.id().to_string(),
                format!("no rows with gait = {}", rel.gait()),
            ));
            continue;
        }
        match fit_relation(rel.as_ref(), tables, opts) {
            Ok(o) => run.outcomes.push(o),
            // Rows of the gait but none usable (e.g. no μ columns for kb-mu): nothing to fit.
            Err(e @ FitError::TooFew { have: 0, .. }) if skip_missing_gait => run
                .skipped
                .push((rel.id().to_string(), format!("no usable rows: {e}"))),
            Err(e) => run.failures.push((rel.id().to_string(), e.to_string())),
        }
    }
    run
}

/// The full XᵀX (row-major nc × nc) from sums accumulated in either triangle (entries are added
/// in whichever order the columns came; the diagonal once).
fn symmetric_xtx(nc: usize, acc: &[f64]) -> Vec<f64> {
    let mut xtx = vec![0.0f64; nc * nc];
    for a in 0..nc {
        for b in 0..nc {
            xtx[a * nc + b] = if a == b {
                acc[a * nc + a]
            } else {
                acc[a * nc + b] + acc[b * nc + a]
            };
        }
    }
    xtx
}
