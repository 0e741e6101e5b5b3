//! A Gaussian random-intercept model by restricted maximum likelihood (REML), from per-subject
//! sufficient statistics (`gaitfit fit --random-subject`).
//!
//! Model: `y = Xβ + u_g + e`, `u_g ~ N(0, σ_u²)` per subject, `e ~ N(0, σ_e²)` per row. With
//! `λ = σ_u²/σ_e²`, subject `g`'s covariance is `σ_e² (I + λ 1 1ᵀ)`, whose inverse is
//! `(I − c_g 1 1ᵀ)/σ_e²` with `c_g = λ/(1 + λ n_g)`. So everything the likelihood needs is, per
//! subject, `n_g`, `XᵀX`, `Xᵀ1`, `Xᵀy`, `1ᵀy`, `yᵀy` (memory: subjects × p², not rows):
//!
//! - `A(λ) = Σ_g (X_gᵀX_g − c_g X_gᵀ1 1ᵀX_g)`, `b(λ) = Σ_g (X_gᵀy_g − c_g X_gᵀ1 1ᵀy_g)`,
//!   `Q(λ) = Σ_g (y_gᵀy_g − c_g (1ᵀy_g)²)`;
//! - `β̂(λ) = A⁻¹b` (generalised least squares), `σ̂_e²(λ) = (Q − bᵀβ̂)/(n − p)`;
//! - the REML criterion with `σ_e²` profiled out (Harville 1977; Pinheiro & Bates 2000 §2.2):
//!   `−2 ℓ_R(λ) = (n − p)(1 + log 2π σ̂_e²) + Σ_g log(1 + λ n_g) + log det A`.
//!
//! `λ` is found by a bounded 1-D search over `log λ` (and `λ = 0` compared, the boundary);
//! `cov(β̂) = σ̂_e² A⁻¹`, and intervals are normal (z), as statsmodels `MixedLM` reports them
//! (checked against it in `tests/reference_inference.rs`, numbers from
//! `tools/reference/mixed.py`).
use super::nonlinear::minimize_1d;
use super::pipeline::Prepared;
use super::record::{MixedCoefficient, MixedRecord};
use super::stats::normal_quantile;
use super::FitError;
use crate::relations::{ParamKind, Relation};
use nalgebra::{DMatrix, DVector};

/// One subject's sufficient statistics for [`reml_random_intercept`].
#[derive(Debug, Clone, PartialEq)]
pub struct GroupSums {
    /// Rows.
    pub n: f64,
    /// `XᵀX` (p × p).
    pub xx: DMatrix<f64>,
    /// `Xᵀ1`.
    pub x1: DVector<f64>,
    /// `Xᵀy`.
    pub xy: DVector<f64>,
    /// `1ᵀy`.
    pub y1: f64,
    /// `yᵀy`.
    pub yy: f64,
}

impl GroupSums {
    /// Empty sums for `p` columns.
    pub fn zeros(p: usize) -> GroupSums {
        GroupSums {
            n: 0.0,
            xx: DMatrix::zeros(p, p),
            x1: DVector::zeros(p),
            xy: DVector::zeros(p),
            y1: 0.0,
            yy: 0.0,
        }
    }
    /// Adds one row `(x, y)`.
    pub fn add(&mut self, x: &[f64], y: f64) {
        let p = self.x1.len();
        self.n += 1.0;
        for i in 0..p {
            self.x1[i] += x[i];
            self.xy[i] += x[i] * y;
            for j in 0..p {
                self.xx[(i, j)] += x[i] * x[j];
            }
        }
        self.y1 += y;
        self.yy += y * y;
    }
}

/// The REML fit of a random-intercept model.
#[derive(Debug, Clone, PartialEq)]
pub struct MixedFit {
    /// Fixed effects `β̂`.
    pub beta: DVector<f64>,
    /// `cov(β̂) = σ̂_e² A⁻¹`.
    pub cov: DMatrix<f64>,
    /// Between-subject variance `σ̂_u²`.
    pub subject_var: f64,
    /// Residual (within-subject) variance `σ̂_e²`.
    pub residual_var: f64,
    /// The restricted log-likelihood at the estimate.
    pub reml_log_likelihood: f64,
}

/// Search range of `log λ`: `λ` from 1e-8 (indistinguishable from 0 beside any residual
/// variance) to 1e8 (subjects' levels unconstrained by the rows).
const LOG_LAMBDA: (f64, f64) = (-18.420680743952367, 18.420680743952367);

/// `A`, `b`, `Q` and the REML criterion at `λ` (`None` when `A` is singular or `n ≤ p`).
fn criterion(groups: &[GroupSums], lambda: f64) -> Option<(f64, DVector<f64>, DMatrix<f64>, f64)> {
    let p = groups.first()?.x1.len();
    let mut a = DMatrix::zeros(p, p);
    let mut b = DVector::zeros(p);
    let (mut q, mut n, mut logdet_v) = (0.0, 0.0, 0.0);
    for g in groups {
        let c = lambda / (1.0 + lambda * g.n);
        a += &g.xx - &g.x1 * g.x1.transpose() * c;
        b += &g.xy - &g.x1 * (c * g.y1);
        q += g.yy - c * g.y1 * g.y1;
        n += g.n;
        logdet_v += (lambda * g.n).ln_1p();
    }
    let dfr = n - p as f64;
    if dfr <= 0.0 {
        return None;
    }
    let chol = a.clone().cholesky()?;
    let beta = chol.solve(&b);
    let rss = q - b.dot(&beta);
    if rss.partial_cmp(&0.0) != Some(std::cmp::Ordering::Greater) {
        return None;
    }
    let s2 = rss / dfr;
    let logdet_a: f64 = 2.0 * chol.l().diagonal().iter().map(|d| d.ln()).sum::<f64>();
    let m2ll = dfr * (1.0 + (2.0 * std::f64::consts::PI * s2).ln()) + logdet_v + logdet_a;
    Some((m2ll, beta, chol.inverse() * s2, s2))
}

/// Fits `y = Xβ + u_g + e` by REML from the subjects' sums (see the module docs). Needs two or
/// more subjects and more rows than columns.
pub fn reml_random_intercept(groups: &[GroupSums]) -> Result<MixedFit, FitError> {
    let bad = |message: String| FitError::InvalidInput {
        relation: "random-intercept REML".into(),
        message,
    };
    if groups.len() < 2 {
        return Err(FitError::TooFew {
            relation: "random-intercept REML".into(),
            what: "subjects".into(),
            have: groups.len(),
            need: 2,
        });
    }
    let f = |t: f64| criterion(groups, t.exp()).map_or(f64::INFINITY, |c| c.0);
    let (t, _) = minimize_1d(f, LOG_LAMBDA.0, LOG_LAMBDA.1, 1e-10)?;
    // The boundary σ_u² = 0 (ordinary least squares) when it is at least as good.
    let inner = criterion(groups, t.exp());
    let zero = criterion(groups, 0.0);
    let (lambda, (m2ll, beta, cov, s2)) = match (inner, zero) {
        (Some(i), Some(z)) if z.0 <= i.0 => (0.0, z),
        (Some(i), _) => (t.exp(), i),
        (None, Some(z)) => (0.0, z),
        (None, None) => {
            return Err(bad(
                "singular design or zero residual: no REML estimate".to_string()
            ))
        }
    };
    Ok(MixedFit {
        beta,
        cov,
        subject_var: lambda * s2,
        residual_var: s2,
        reml_log_likelihood: -0.5 * m2ll,
    })
}

/// The random-intercept REML record of a relation on its prepared rows (`p`: the coefficients,
/// for the basis), or why the model does not apply: it needs a single-output relation with
/// every parameter linear and free, no per-subject column of its own, unweighted rows and two
/// or more subjects.
pub fn random_subject_record(
    rel: &dyn Relation,
    prep: &Prepared,
    p: &[f64],
    weighted: bool,
) -> Result<MixedRecord, String> {
    let card = rel.card();
    if card.parameters.iter().any(|s| s.kind != ParamKind::Linear) {
        return Err(
            "--random-subject: not fitted (the relation has breakpoints; the \
                    random-intercept model is for the linear relations)"
                .into(),
        );
    }
    if card.subject_effect.is_some() || card.outputs.len() != 1 {
        return Err(
            "--random-subject: not fitted (the relation has its own per-subject \
                    column or several outputs)"
                .into(),
        );
    }
    if weighted {
        return Err(
            "--random-subject: not fitted (rows are weighted; the REML model is \
                    unweighted)"
                .into(),
        );
    }
    let k = card.n_linear();
    let mut groups = vec![GroupSums::zeros(k); prep.subjects.len()];
    let mut x = vec![0.0; k];
    for (o, &s) in prep.obs.iter().zip(&prep.subject) {
        rel.raw_basis(p, &o.x, &mut x);
        groups[s].add(&x, o.y);
    }
    let fit = reml_random_intercept(&groups).map_err(|e| format!("--random-subject: {e}"))?;
    let z = normal_quantile(0.5 + 0.5 * super::pipeline::CONFIDENCE);
    let coefficients = card
        .parameters
        .iter()
        .enumerate()
        .map(|(j, spec)| {
            let (v, se) = (fit.beta[j], fit.cov[(j, j)].sqrt());
            MixedCoefficient {
                name: spec.name.to_string(),
                unit: spec.unit.to_string(),
                value: v,
                std_error: se,
                ci95: [v - z * se, v + z * se],
            }
        })
        .collect();
    Ok(MixedRecord {
        method: format!(
            "Gaussian random intercept per subject (y = Xβ + u_subject + e), restricted maximum \
             likelihood from per-subject sums ({} subjects); fixed-effect standard errors \
             σ_e²(XᵀV⁻¹X)⁻¹ at the estimate, normal intervals (as statsmodels MixedLM)",
            groups.len()
        ),
        coefficients,
        subject_sd: fit.subject_var.sqrt(),
        residual_sd: fit.residual_var.sqrt(),
        icc: fit.subject_var / (fit.subject_var + fit.residual_var),
        reml_log_likelihood: fit.reml_log_likelihood,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The REML criterion from the sums equals the dense one, `V = σ²(I + λ ZZᵀ)` built row by
    /// row: `(n − p) log 2π + log det V + log det XᵀV⁻¹X + rᵀV⁻¹r` at σ² = σ̂².
    #[test]
    fn sums_give_the_dense_restricted_likelihood() {
        let sizes = [3usize, 7, 1, 5];
        let mut rows = Vec::new();
        for (g, &m) in sizes.iter().enumerate() {
            for i in 0..m {
                let x = 1.0 + 0.37 * (i as f64) + 0.9 * g as f64;
                let y = 0.5 + 0.8 * x + 0.3 * (g as f64 - 1.5) + 0.11 * ((i * 7 + g) % 5) as f64;
                rows.push((g, [1.0, x], y));
            }
        }
        let mut groups = vec![GroupSums::zeros(2); sizes.len()];
        for &(g, x, y) in &rows {
            groups[g].add(&x, y);
        }
        let n = rows.len();
        let lambda = 0.7;
        let (m2ll, beta, cov, s2) = criterion(&groups, lambda).expect("criterion");
        let x = DMatrix::from_fn(n, 2, |i, j| rows[i].1[j]);
        let y = DVector::from_fn(n, |i, _| rows[i].2);
        let v = DMatrix::from_fn(n, n, |i, j| {
            s2 * (f64::from(u8::from(i == j))
                + lambda * f64::from(u8::from(rows[i].0 == rows[j].0)))
        });
        let vi = v.clone().try_inverse().expect("V");
        let xvx = x.transpose() * &vi * &x;
        let b = xvx.clone().try_inverse().expect("XᵀV⁻¹X") * x.transpose() * &vi * &y;
        let r = &y - &x * &b;
        let dense = (n - 2) as f64 * (2.0 * std::f64::consts::PI).ln()
            + v.determinant().ln()
            + xvx.determinant().ln()
            + (r.transpose() * &vi * &r)[0];
        assert!((m2ll - dense).abs() < 1e-9 * dense.abs(), "{m2ll} {dense}");
        assert!((beta - &b).amax() < 1e-12);
        let cov_dense = xvx.try_inverse().expect("inverse");
        assert!((cov - cov_dense).amax() < 1e-12);
    }
}
