//! The linear part of a fit at fixed breakpoints, from per-subject sufficient statistics.
//!
//! A relation's basis row (at fixed breakpoints) is split into **global columns**, shared by
//! all rows, and at most one **per-subject column** (the running paper's `level` multiplies
//! the speed, so each subject has its own slope). The per-subject column is *absorbed*
//! (Frisch–Waugh–Lovell): each subject's cross-products `[X_o z]ᵀW[X_o z]` are reduced to those
//! of the global columns after partialling out `z` within the subject,
//! `S̃_s = S_oo − s_oz s_zoᵀ/s_zz`, `r̃_s = r_o − s_oz r_z/s_zz`, and the global coefficients
//! solve `(Σ_s S̃_s) β = Σ_s r̃_s`; each subject's slope is then `γ_s = (r_z − s_zoᵀβ)/s_zz`. Nothing
//! is ever of size rows × subjects: memory is subjects × columns², and leave-one-subject-out
//! folds and bootstrap replicates are sums of per-subject records ([`Totals`]).
//!
//! The reported fit ([`DesignFit::new`]) makes two passes over the rows: per-subject sums, then
//! residuals, leverages and per-subject scores (for clustered standard errors, module
//! [`super::inference`]). The normal equations are solved by an equilibrated Cholesky
//! factorisation ([`solve_normal`]) in the relation's own basis, which each relation keeps well
//! conditioned (centred polynomial pieces); `tests/nist_lls.rs` measures this path on the NIST
//! StRD linear sets.
use super::inference::{
    bm_df, cr1_factor, cr2_clusters, inverse_factor, meat, Cluster, Cr2Cluster, SeMethod,
};
use super::pipeline::Prepared;
use crate::fit::forms::{Fitting, NormalEquations};
use crate::relations::{Inputs, Observation, ParamKind, Relation};
use nalgebra::{DMatrix, DVector};

/// Most basis columns a relation may have (the fixed-size row buffers).
pub const MAX_BASIS: usize = 16;

/// How a relation's basis is laid out for given free coefficients: its `nb` columns, and the
/// one absorbed per subject (with two or more subjects and a per-subject effect).
#[derive(Debug, Clone, PartialEq)]
pub struct Layout {
    /// Free-parameter mask (all parameters).
    pub free: Vec<bool>,
    /// Basis columns ([`Form::basis_len`](crate::fit::forms::Form::basis_len)).
    pub nb: usize,
    /// The basis column absorbed per subject.
    pub subj_col: Option<usize>,
}

impl Layout {
    /// The layout of `rel` for the free mask `free` on rows from `n_subj` subjects.
    pub fn new(rel: &dyn Relation, free: Vec<bool>, n_subj: usize) -> Layout {
        let nb = rel.basis_len(&free);
        let subj_col = if n_subj >= 2 && rel.card().subject_effect.is_some() {
            rel.subject_column(&free)
        } else {
            None
        };
        Layout { free, nb, subj_col }
    }
    /// Number of global columns.
    pub fn m(&self) -> usize {
        self.nb - usize::from(self.subj_col.is_some())
    }
    /// The basis row of `x` at `p`: the global columns into `g` (length [`Layout::m`]), and
    /// `(offset, z)` with `z` the per-subject column's value (0 without one).
    #[inline]
    pub fn row(&self, rel: &dyn Relation, p: &[f64], x: &Inputs, g: &mut [f64]) -> (f64, f64) {
        let mut phi = [0.0; MAX_BASIS];
        let off = rel.basis(p, &self.free, x, &mut phi[..self.nb]);
        match self.subj_col {
            None => {
                g[..self.nb].copy_from_slice(&phi[..self.nb]);
                (off, 0.0)
            }
            Some(sc) => {
                g[..sc].copy_from_slice(&phi[..sc]);
                g[sc..self.nb - 1].copy_from_slice(&phi[sc + 1..self.nb]);
                (off, phi[sc])
            }
        }
    }
    /// The relation-basis coefficients from the global ones and the (mean) per-subject one.
    pub fn basis_coef(&self, beta: &[f64], gamma: f64) -> DVector<f64> {
        match self.subj_col {
            None => DVector::from_column_slice(beta),
            Some(sc) => {
                let mut v = DVector::zeros(self.nb);
                for j in 0..self.nb {
                    v[j] = match j.cmp(&sc) {
                        std::cmp::Ordering::Less => beta[j],
                        std::cmp::Ordering::Equal => gamma,
                        std::cmp::Ordering::Greater => beta[j - 1],
                    };
                }
                v
            }
        }
    }
    /// The full parameter vector (`p` with its linear parameters replaced) from basis
    /// coefficients.
    pub fn params(&self, rel: &dyn Relation, p: &[f64], coef: &DVector<f64>) -> Vec<f64> {
        let lm = rel.basis_to_params(p, &self.free);
        let out = &lm.map * coef + &lm.shift;
        let mut q = p.to_vec();
        let mut j = 0;
        for (i, s) in rel.card().parameters.iter().enumerate() {
            if s.kind == ParamKind::Linear {
                q[i] = out[j];
                j += 1;
            }
        }
        q
    }
}

/// Solves normal equations (`xtx` full `nc × nc` row-major): (coefficients, weighted RSS), or
/// `None` when the matrix is not positive definite. Columns are equilibrated (unit diagonal)
/// before the Cholesky factorisation so that badly scaled ones do not fail it; accuracy is that
/// of the normal equations, about `ε·κ²` for a design of condition number κ (see
/// `tests/nist_lls.rs` for what that means on the NIST StRD sets).
pub fn solve_normal(nc: usize, xtx: &[f64], xty: &[f64], yty: f64) -> Option<(DVector<f64>, f64)> {
    if nc == 0 {
        return Some((DVector::zeros(0), yty.max(0.0)));
    }
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

/// One subject's sums with the per-subject column absorbed (see the module docs). Additive:
/// folds and replicates add records with multiplicities ([`Totals`]).
#[derive(Debug, Clone, PartialEq)]
pub struct SubjectSums {
    /// `S̃`, `m × m` row-major.
    pub s: Vec<f64>,
    /// `r̃`, `m`.
    pub r: Vec<f64>,
    /// `ỹᵀWỹ`.
    pub yy: f64,
    /// `r_z/s_zz`: the subject's slope at β = 0 (0 without a per-subject column).
    pub rho: f64,
    /// `s_oz/s_zz`, `m` (zeros without a per-subject column).
    pub d: Vec<f64>,
    /// `s_zz` (0 without a per-subject column).
    pub szz: f64,
}

impl SubjectSums {
    /// Absorbs column `sc` of a subject's normal equations (`None`: nothing to absorb).
    /// `None` when the subject's own column is all zeros (its slope is not identified).
    pub fn absorb(ne: &NormalEquations, sc: Option<usize>) -> Option<SubjectSums> {
        let nb = ne.nb;
        let Some(c) = sc else {
            return Some(SubjectSums {
                s: ne.xtx.clone(),
                r: ne.xty.clone(),
                yy: ne.yty,
                rho: 0.0,
                d: vec![0.0; nb],
                szz: 0.0,
            });
        };
        let szz = ne.xtx[c * nb + c];
        if !(szz > 0.0 && szz.is_finite()) {
            return None;
        }
        let o: Vec<usize> = (0..nb).filter(|&j| j != c).collect();
        let m = o.len();
        let rz = ne.xty[c];
        let d: Vec<f64> = o.iter().map(|&a| ne.xtx[a * nb + c] / szz).collect();
        let mut s = vec![0.0; m * m];
        for (a, &ia) in o.iter().enumerate() {
            for (b, &ib) in o.iter().enumerate() {
                s[a * m + b] = ne.xtx[ia * nb + ib] - d[a] * ne.xtx[c * nb + ib];
            }
        }
        let r = o
            .iter()
            .enumerate()
            .map(|(a, &ia)| ne.xty[ia] - d[a] * rz)
            .collect();
        Some(SubjectSums {
            s,
            r,
            yy: ne.yty - rz * rz / szz,
            rho: rz / szz,
            d,
            szz,
        })
    }
}

/// Sums of [`SubjectSums`] over some subjects (with multiplicities): what a fit of those
/// subjects' rows needs.
#[derive(Debug, Clone, PartialEq)]
pub struct Totals {
    /// Global columns.
    pub m: usize,
    /// `Σ S̃`.
    pub s: Vec<f64>,
    /// `Σ r̃`.
    pub r: Vec<f64>,
    /// `Σ ỹᵀWỹ`.
    pub yy: f64,
    /// `Σ ρ` (multiplicity-weighted).
    pub rho: f64,
    /// `Σ d`.
    pub d: Vec<f64>,
    /// Number of subjects (with multiplicity).
    pub count: f64,
}

impl Totals {
    /// Zero sums for `m` global columns.
    pub fn zeros(m: usize) -> Totals {
        Totals {
            m,
            s: vec![0.0; m * m],
            r: vec![0.0; m],
            yy: 0.0,
            rho: 0.0,
            d: vec![0.0; m],
            count: 0.0,
        }
    }
    /// Adds `mult` × a subject's record.
    pub fn add(&mut self, x: &SubjectSums, mult: f64) {
        self.s
            .iter_mut()
            .zip(&x.s)
            .for_each(|(a, b)| *a += mult * b);
        self.r
            .iter_mut()
            .zip(&x.r)
            .for_each(|(a, b)| *a += mult * b);
        self.d
            .iter_mut()
            .zip(&x.d)
            .for_each(|(a, b)| *a += mult * b);
        self.yy += mult * x.yy;
        self.rho += mult * x.rho;
        self.count += mult;
    }
    /// Adds other totals.
    pub fn add_totals(&mut self, x: &Totals) {
        self.s.iter_mut().zip(&x.s).for_each(|(a, b)| *a += b);
        self.r.iter_mut().zip(&x.r).for_each(|(a, b)| *a += b);
        self.d.iter_mut().zip(&x.d).for_each(|(a, b)| *a += b);
        self.yy += x.yy;
        self.rho += x.rho;
        self.count += x.count;
    }
    /// The bounded fit of these sums (no per-subject column): relation-basis coefficients,
    /// weighted RSS and the solver's outcome, or `None` when singular.
    pub fn solve_box(
        &self,
        lay: &Layout,
        lo: &[f64],
        hi: &[f64],
    ) -> Option<(DVector<f64>, f64, super::bounded::BoxSolution)> {
        let m = self.m;
        let a = DMatrix::from_row_slice(m, m, &self.s);
        let c = DVector::from_column_slice(&self.r);
        let sol = super::bounded::solve_box(&a, &c, lo, hi)?;
        let b = &sol.beta;
        let rss = (self.yy - 2.0 * c.dot(b) + b.dot(&(&a * b))).max(0.0);
        Some((lay.basis_coef(b.as_slice(), 0.0), rss, sol))
    }
    /// The fit of these sums: relation-basis coefficients (the per-subject column set to the
    /// subjects' mean slope) and the weighted RSS, or `None` when singular.
    pub fn solve(&self, lay: &Layout) -> Option<(DVector<f64>, f64)> {
        let (beta, rss) = solve_normal(self.m, &self.s, &self.r, self.yy)?;
        let gamma = if lay.subj_col.is_some() {
            if self.count <= 0.0 {
                return None;
            }
            (self.rho - beta.iter().zip(&self.d).map(|(b, d)| b * d).sum::<f64>()) / self.count
        } else {
            0.0
        };
        Some((lay.basis_coef(beta.as_slice(), gamma), rss))
    }
}

/// Every subject's normal equations in the relation's basis (all `nb` columns, the per-subject
/// one included) over the rows `rows` (all when `None`); `subj_map` renumbers subjects.
pub fn subject_normal_equations(
    rel: &dyn Relation,
    lay: &Layout,
    p: &[f64],
    prep: &Prepared,
    rows: Option<&[usize]>,
    subj_map: Option<&[usize]>,
    n_subj: usize,
) -> Vec<NormalEquations> {
    let nb = lay.nb;
    let mut out = vec![NormalEquations::zeros(nb); n_subj];
    let mut phi = [0.0; MAX_BASIS];
    let mut add = |i: usize| {
        let o = &prep.obs[i];
        let s = subj_map.map_or(prep.subject[i], |m| m[prep.subject[i]]);
        let off = rel.basis(p, &lay.free, &o.x, &mut phi[..nb]);
        let w = prep.weights[i];
        let y = o.y - off;
        let ne = &mut out[s];
        ne.yty += w * y * y;
        for a in 0..nb {
            let wa = w * phi[a];
            if wa == 0.0 {
                continue;
            }
            ne.xty[a] += wa * y;
            for (x, &pb) in ne.xtx[a * nb..=a * nb + a].iter_mut().zip(&phi[..=a]) {
                *x += wa * pb;
            }
        }
    };
    match rows {
        Some(r) => r.iter().for_each(|&i| add(i)),
        None => (0..prep.obs.len()).for_each(&mut add),
    }
    for ne in &mut out {
        for a in 0..nb {
            for b in 0..a {
                ne.xtx[b * nb + a] = ne.xtx[a * nb + b];
            }
        }
    }
    out
}

/// The fit of some rows at fixed breakpoints: relation-basis coefficients and weighted RSS
/// (one pass over the rows; for profiles and refits without a sorted form).
pub fn solve_rows(
    rel: &dyn Relation,
    lay: &Layout,
    p: &[f64],
    prep: &Prepared,
    rows: Option<&[usize]>,
    subj_map: Option<&[usize]>,
    n_subj: usize,
) -> Option<(DVector<f64>, f64)> {
    let nes = subject_normal_equations(rel, lay, p, prep, rows, subj_map, n_subj);
    let mut t = Totals::zeros(lay.m());
    for ne in &nes {
        // Subjects without rows in this subset contribute nothing.
        if ne.xtx.iter().all(|&v| v == 0.0) && ne.yty == 0.0 {
            continue;
        }
        t.add(&SubjectSums::absorb(ne, lay.subj_col)?, 1.0);
    }
    t.solve(lay)
}

/// The reported fit at fixed breakpoints (see the module docs) with everything its statistics
/// need.
#[derive(Debug, Clone)]
pub struct DesignFit {
    /// The layout.
    pub lay: Layout,
    /// Global coefficients.
    pub beta: DVector<f64>,
    /// Per-subject slopes (empty without a per-subject column).
    pub gammas: Vec<f64>,
    /// Their mean (0 without a per-subject column).
    pub gamma_bar: f64,
    /// Relation-basis coefficients (the per-subject column at `gamma_bar`).
    pub coef: DVector<f64>,
    /// `Σ S̃`, m × m.
    pub a: DMatrix<f64>,
    /// Per subject: absorbed cross-products and score.
    pub clusters: Vec<Cluster>,
    /// Per subject: `d` (`s_oz/s_zz`) and `s_zz` (per-subject column only).
    pub fe: Vec<(DVector<f64>, f64)>,
    /// Fitted values (each row with its subject's slope).
    pub fitted: Vec<f64>,
    /// Residuals y − fitted.
    pub residuals: Vec<f64>,
    /// Leverages (weighted hat matrix diagonal, per-subject column included).
    pub leverage: Vec<f64>,
    /// Weighted RSS.
    pub rss: f64,
    /// `Σ ln w` (0 unweighted).
    pub sum_log_w: f64,
    /// Per output (several outputs per row): `(weighted RSS, rows, A_k)`.
    pub outputs: Vec<(f64, usize, DMatrix<f64>)>,
    /// 2-norm condition number of the equilibrated design (√ of that of `Σ S̃`).
    pub condition_number: f64,
}

impl DesignFit {
    /// Fits the rows of `prep` at the breakpoints in `p` (two passes; see the module docs).
    /// `None` when the design is singular.
    pub fn new(rel: &dyn Relation, lay: &Layout, p: &[f64], prep: &Prepared) -> Option<DesignFit> {
        let n_subj = prep.subjects.len();
        let m = lay.m();
        let nes = subject_normal_equations(rel, lay, p, prep, None, None, n_subj);
        let mut sums = Vec::with_capacity(n_subj);
        let mut tot = Totals::zeros(m);
        for ne in &nes {
            let s = SubjectSums::absorb(ne, lay.subj_col)?;
            tot.add(&s, 1.0);
            sums.push(s);
        }
        drop(nes);
        let (beta, _) = solve_normal(m, &tot.s, &tot.r, tot.yy)?;
        let gammas: Vec<f64> = if lay.subj_col.is_some() {
            sums.iter()
                .map(|s| s.rho - beta.iter().zip(&s.d).map(|(b, d)| b * d).sum::<f64>())
                .collect()
        } else {
            Vec::new()
        };
        let gamma_bar = if gammas.is_empty() {
            0.0
        } else {
            gammas.iter().sum::<f64>() / gammas.len() as f64
        };
        let coef = lay.basis_coef(beta.as_slice(), gamma_bar);
        let a = DMatrix::from_row_slice(m, m, &tot.s);
        let minv = if m > 0 {
            inverse_factor(&a).map(|l| &l * l.transpose())?
        } else {
            DMatrix::zeros(0, 0)
        };
        // Second pass: residuals, leverages, scores.
        let n = prep.obs.len();
        let mut fitted = vec![0.0; n];
        let mut residuals = vec![0.0; n];
        let mut leverage = vec![0.0; n];
        let mut scores = vec![DVector::<f64>::zeros(m); n_subj];
        let n_out = rel.card().outputs.len();
        let mut outputs = vec![(0.0, 0usize, DMatrix::<f64>::zeros(m, m)); n_out];
        let (mut rss, mut sum_log_w) = (0.0, 0.0);
        let mut g = [0.0; MAX_BASIS];
        let mut xt = DVector::<f64>::zeros(m);
        for i in 0..n {
            let o: &Observation = &prep.obs[i];
            let s = prep.subject[i];
            let w = prep.weights[i];
            let (off, z) = lay.row(rel, p, &o.x, &mut g[..m]);
            let mut f = off
                + g[..m]
                    .iter()
                    .zip(beta.iter())
                    .map(|(a, b)| a * b)
                    .sum::<f64>();
            let mut h_fe = 0.0;
            if lay.subj_col.is_some() {
                f += z * gammas[s];
                h_fe = w * z * z / sums[s].szz;
                for j in 0..m {
                    xt[j] = g[j] - z * sums[s].d[j];
                }
            } else {
                xt.as_mut_slice().copy_from_slice(&g[..m]);
            }
            let e = o.y - f;
            fitted[i] = f;
            residuals[i] = e;
            leverage[i] = w * xt.dot(&(&minv * &xt)) + h_fe;
            rss += w * e * e;
            if w != 1.0 {
                sum_log_w += w.ln();
            }
            scores[s].axpy(w * e, &xt, 1.0);
            if n_out > 1 {
                let k = o.x.output;
                let out = &mut outputs[k];
                out.0 += w * e * e;
                out.1 += 1;
                out.2.ger(w, &xt, &xt, 1.0);
            }
        }
        let clusters = sums
            .iter()
            .zip(scores)
            .map(|(s, u)| Cluster {
                s: DMatrix::from_row_slice(m, m, &s.s),
                u,
            })
            .collect();
        let fe = if lay.subj_col.is_some() {
            sums.iter()
                .map(|s| (DVector::from_column_slice(&s.d), s.szz))
                .collect()
        } else {
            Vec::new()
        };
        let condition_number = if m > 0 {
            let d: Vec<f64> = (0..m).map(|j| a[(j, j)].sqrt()).collect();
            let ah = DMatrix::from_fn(m, m, |i, j| a[(i, j)] / (d[i] * d[j]));
            let ev = ah.symmetric_eigenvalues();
            (ev.max() / ev.min().max(f64::MIN_POSITIVE)).sqrt()
        } else {
            1.0
        };
        Some(DesignFit {
            lay: lay.clone(),
            beta,
            gammas,
            gamma_bar,
            coef,
            a,
            clusters,
            fe,
            fitted,
            residuals,
            leverage,
            rss,
            sum_log_w,
            outputs: if n_out > 1 { outputs } else { Vec::new() },
            condition_number,
        })
    }
}

/// Extra global columns appended to the design for the covariance only: the derivatives of the
/// prediction with respect to free breakpoints (Gauss–Newton with the breakpoints free).
#[derive(Debug, Clone)]
pub struct Augmented {
    /// `Σ S̃` of `[X_o J]`, (m+q) × (m+q).
    pub a: DMatrix<f64>,
    /// Per subject: cross-products and scores of `[X_o J]`.
    pub clusters: Vec<Cluster>,
    /// Per subject: `s_oz/s_zz` of `[X_o J]` (per-subject column only).
    pub d: Vec<DVector<f64>>,
}

/// Per-subject sums of the global columns plus `q` Jacobian columns `jac(i, out)` (absorbing
/// the per-subject column), with scores from the fit's residuals.
pub fn augment(
    rel: &dyn Relation,
    fit: &DesignFit,
    p: &[f64],
    prep: &Prepared,
    q: usize,
    jac: &dyn Fn(usize, &mut [f64]),
) -> Augmented {
    let lay = &fit.lay;
    let m = lay.m();
    let k = m + q;
    let n_subj = prep.subjects.len();
    // Per subject: [x_o J z] normal-equation style sums (z last).
    let kk = k + 1;
    let mut sxx = vec![DMatrix::<f64>::zeros(kk, kk); n_subj];
    let mut u = vec![DVector::<f64>::zeros(k); n_subj];
    let mut g = [0.0; MAX_BASIS];
    let mut v = DVector::<f64>::zeros(kk);
    for i in 0..prep.obs.len() {
        let o = &prep.obs[i];
        let s = prep.subject[i];
        let w = prep.weights[i];
        let (_, z) = lay.row(rel, p, &o.x, &mut g[..m]);
        v.as_mut_slice()[..m].copy_from_slice(&g[..m]);
        jac(i, &mut v.as_mut_slice()[m..k]);
        v[k] = z;
        sxx[s].ger(w, &v, &v, 1.0);
        let e = fit.residuals[i];
        for j in 0..k {
            u[s][j] += w * v[j] * e;
        }
    }
    let mut a = DMatrix::zeros(k, k);
    let mut clusters = Vec::with_capacity(n_subj);
    let mut d = Vec::new();
    for (sx, us) in sxx.into_iter().zip(u) {
        let (sk, ds) = if lay.subj_col.is_some() && sx[(k, k)] > 0.0 {
            let szz = sx[(k, k)];
            let dz = DVector::from_fn(k, |j, _| sx[(j, k)] / szz);
            let so = sx.view((0, 0), (k, k)).into_owned();
            let col = sx.view((0, k), (k, 1)).into_owned();
            (so - &col * dz.transpose(), Some(dz))
        } else {
            (sx.view((0, 0), (k, k)).into_owned(), None)
        };
        // Absorbing z leaves the score unchanged: Σ w z e = 0 within every subject.
        a += &sk;
        clusters.push(Cluster { s: sk, u: us });
        if let Some(dz) = ds {
            d.push(dz);
        }
    }
    Augmented { a, clusters, d }
}

/// The covariance of θ = [global coefficients (and any Jacobian columns); mean per-subject
/// slope] under a [`SeMethod`], with what its degrees of freedom need.
#[derive(Debug, Clone)]
pub struct Covariance {
    /// The method.
    pub method: SeMethod,
    /// Covariance of θ.
    pub v: DMatrix<f64>,
    /// Global columns in θ (the mean slope, if any, is last).
    pub k: usize,
    /// Whether θ ends with the mean per-subject slope.
    pub has_fe: bool,
    /// Residual degrees of freedom `n − K` (iid).
    pub df_resid: f64,
    /// Clusters.
    pub g: usize,
    m_inv: DMatrix<f64>,
    cr2: Vec<Cr2Cluster>,
}

impl Covariance {
    /// The covariance of θ for `a`, `clusters` (global columns, possibly augmented), the fit's
    /// per-subject slopes and residual variance. `n_params` counts every estimated coefficient
    /// (per-subject slopes and breakpoints included) for the iid `n − K`; `k_linear` the linear
    /// columns of the design at the breakpoint estimates (per-subject slopes included), the `K`
    /// of CR1's factor, as statsmodels counts them for that design.
    #[allow(clippy::too_many_arguments)]
    pub fn new(
        method: SeMethod,
        a: &DMatrix<f64>,
        clusters: &[Cluster],
        fit: &DesignFit,
        fe_d: &[DVector<f64>],
        n: usize,
        n_params: usize,
        k_linear: usize,
    ) -> Option<Covariance> {
        let k = a.nrows();
        let has_fe = fit.lay.subj_col.is_some();
        let g = clusters.len();
        let df_resid = n as f64 - n_params as f64;
        let l = if k > 0 {
            inverse_factor(a)?
        } else {
            DMatrix::zeros(0, 0)
        };
        let m_inv = &l * l.transpose();
        let dim = k + usize::from(has_fe);
        let gf = g as f64;
        // κ = mean of the subjects' d (how the mean slope moves with the global coefficients).
        let kappa = if has_fe {
            let mut s = DVector::zeros(k);
            for d in fe_d {
                s += d;
            }
            s / gf
        } else {
            DVector::zeros(k)
        };
        let mut cr2 = Vec::new();
        let v = match method {
            SeMethod::Iid => {
                let sigma2 = fit.rss / df_resid;
                let mut v = DMatrix::zeros(dim, dim);
                // One variance per output when rows give several (coefficients of different
                // outputs are then independent blocks); the Jacobian columns are not part of
                // that split, so it applies without them.
                let vb = if !fit.outputs.is_empty() && k == fit.lay.m() {
                    let mut b = DMatrix::zeros(k, k);
                    for (rss_k, n_k, a_k) in &fit.outputs {
                        let p_k = (0..k).filter(|&j| a_k[(j, j)] > 0.0).count();
                        let s2 = rss_k / (*n_k as f64 - p_k as f64);
                        b += a_k * s2;
                    }
                    &m_inv * b * &m_inv
                } else {
                    &m_inv * sigma2
                };
                v.view_mut((0, 0), (k, k)).copy_from(&vb);
                if has_fe {
                    let mk = &m_inv * &kappa;
                    let inv_szz: f64 = fit.fe.iter().map(|(_, s)| 1.0 / s).sum::<f64>() / (gf * gf);
                    v[(k, k)] = sigma2 * (inv_szz + kappa.dot(&mk));
                    for j in 0..k {
                        v[(j, k)] = -sigma2 * mk[j];
                        v[(k, j)] = -sigma2 * mk[j];
                    }
                }
                v
            }
            SeMethod::Cluster | SeMethod::Cr2 => {
                let (us, factor, between): (Vec<DVector<f64>>, f64, f64) = match method {
                    SeMethod::Cluster => (
                        clusters.iter().map(|c| c.u.clone()).collect(),
                        cr1_factor(n, k_linear, g),
                        1.0,
                    ),
                    _ => {
                        cr2 = cr2_clusters(&l, clusters);
                        (
                            cr2.iter().map(|c| c.u.clone()).collect(),
                            1.0,
                            (gf / (gf - 1.0)).sqrt(),
                        )
                    }
                };
                let psi: Vec<DVector<f64>> = us
                    .iter()
                    .enumerate()
                    .map(|(c, u)| {
                        let pb = &m_inv * u;
                        let mut psi = DVector::zeros(dim);
                        psi.rows_mut(0, k).copy_from(&pb);
                        if has_fe {
                            psi[k] =
                                (fit.gammas[c] - fit.gamma_bar) / gf * between - kappa.dot(&pb);
                        }
                        psi
                    })
                    .collect();
                meat(&psi, dim) * factor
            }
        };
        Some(Covariance {
            method,
            v,
            k,
            has_fe,
            df_resid,
            g,
            m_inv,
            cr2,
        })
    }

    /// Degrees of freedom of the t-test of the contrast `ell` (over θ): `n − K` (iid), `G − 1`
    /// (CR1), Bell–McCaffrey (CR2; `G − 1` for contrasts involving the mean per-subject slope,
    /// a mean of G subject slopes).
    pub fn df(&self, ell: &DVector<f64>) -> f64 {
        match self.method {
            SeMethod::Iid => self.df_resid,
            SeMethod::Cluster => self.g as f64 - 1.0,
            SeMethod::Cr2 => {
                if self.has_fe && ell[self.k] != 0.0 {
                    self.g as f64 - 1.0
                } else {
                    let l = ell.rows(0, self.k).into_owned();
                    bm_df(&self.m_inv, &self.cr2, &l)
                }
            }
        }
    }
}
