//! Standard errors for repeated-measures data: the covariance of least-squares coefficients
//! under independent rows (`iid`) or clustered by subject (`CR1`, `CR2`), computed from
//! per-cluster sufficient statistics only (never an n × n or rows × subjects matrix).
//!
//! Notation (weighted least squares, rows scaled by √wᵢ): `A = Σ_g S_g` with
//! `S_g = X_gᵀW_gX_g` the cluster's cross-products, `M = A⁻¹`, `u_g = X_gᵀW_g e_g` the cluster's
//! score at the estimate, `n` rows, `K` estimated coefficients, `G` clusters.
//!
//! - **iid**: `σ² M`, `σ² = RSS/(n − K)`; t-tests with `n − K` degrees of freedom.
//! - **CR1** (Liang & Zeger 1986 with the Stata/statsmodels small-sample factor):
//!   `V = G/(G−1) · (n−1)/(n−K) · M (Σ_g u_g u_gᵀ) M`, t-tests with `G − 1` degrees of freedom —
//!   exactly statsmodels' `OLS(...).fit(cov_type='cluster', use_t=True)`.
//! - **CR2** (Bell & McCaffrey 2002; Imbens & Kolesár 2016; Pustejovsky & Tipton 2018):
//!   `V = M (Σ_g ũ_g ũ_gᵀ) M` with `ũ_g = X_gᵀ A_g e_g`, `A_g = (I − H_gg)^{−1/2}` (symmetric,
//!   Moore–Penrose on a unit leverage), and for each contrast ℓ the Satterthwaite degrees of
//!   freedom `(Σλ)²/Σλ²` of Bell & McCaffrey (λ: eigenvalues of `G'G` under a working
//!   `Ω = σ²I`, Imbens & Kolesár eq. 10). CR2 is unbiased under that working model and its
//!   degrees of freedom follow the clusters' leverage, so with few or unbalanced subjects it
//!   keeps the nominal coverage where CR1 with `G − 1` does not (Imbens & Kolesár 2016 §3;
//!   Pustejovsky & Tipton 2018). Below [`CR2_RECOMMENDED_BELOW`] subjects it is gaitfit's default.
//!
//! # Never forming `H_gg`
//! `H_gg = X_g M X_gᵀ` has rank ≤ p, so any function of it is one of a p × p matrix: with
//! `M = L Lᵀ` (`L = R⁻¹`, `A = RᵀR`) and `C_g = Lᵀ S_g L`,
//! `f(H_gg) = f(0) I + X_g L φ(C_g) Lᵀ X_gᵀ` with `φ(λ) = (f(λ) − f(0))/λ`. Hence
//! `X_gᵀ A_g e_g = u_g + S_g L φ₁(C_g) Lᵀ u_g` (`f = (1−λ)^{−1/2}`), and the degrees-of-freedom
//! sums need `X_gᵀ A_g X_g` and `X_gᵀ A_g² X_g` the same way: every cluster costs O(p³).
use nalgebra::{DMatrix, DVector, SymmetricEigen};

/// Below this many subjects `gaitfit` uses CR2 by default (and says so in `--help` and in
/// the report): CR1 with `G − 1` degrees of freedom over-rejects with fewer than about 20–40
/// clusters, more so when cluster sizes are unbalanced (Cameron & Miller 2015, §VI; Imbens &
/// Kolesár 2016, Table 1), while CR2 with Bell–McCaffrey degrees of freedom stays close to
/// nominal down to a handful of clusters.
pub const CR2_RECOMMENDED_BELOW: usize = 20;

/// An eigenvalue of `H_gg` within this of 1 is a unit leverage (a coefficient determined by one
/// cluster alone); its direction gets the Moore–Penrose treatment (`A_g` is 0 there).
const UNIT_LEVERAGE: f64 = 1e-10;

/// How standard errors are computed.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum SeMethod {
    /// Rows independent with one variance (per output for several outputs).
    Iid,
    /// Clustered by subject, CR1 (statsmodels `cov_type='cluster'`), t with G − 1 df.
    #[default]
    Cluster,
    /// Clustered by subject, CR2 (Bell–McCaffrey) with Satterthwaite degrees of freedom.
    Cr2,
}

impl SeMethod {
    /// Short name as in the records (`iid`, `CR1`, `CR2`).
    pub fn label(self) -> &'static str {
        match self {
            SeMethod::Iid => "iid",
            SeMethod::Cluster => "CR1",
            SeMethod::Cr2 => "CR2",
        }
    }
    /// One sentence saying what the method is.
    pub fn describe(self) -> &'static str {
        match self {
            SeMethod::Iid => {
                "rows treated as independent with a common variance (σ² = RSS/(n − K); one σ² per \
                 output where a row gives several); t with n − K degrees of freedom"
            }
            SeMethod::Cluster => {
                "cluster-robust by subject, CR1: G/(G−1)·(n−1)/(n−K)·M(Σ_g u_g u_gᵀ)M, as \
                 statsmodels cov_type='cluster'; t with G − 1 degrees of freedom"
            }
            SeMethod::Cr2 => {
                "cluster-robust by subject, CR2 (Bell–McCaffrey): M(Σ_g X_gᵀA_g e_g e_gᵀA_g X_g)M \
                 with A_g = (I − H_gg)^(−1/2); t with Bell–McCaffrey (Satterthwaite) degrees of \
                 freedom per coefficient"
            }
        }
    }
}

/// One cluster's sufficient statistics: `S_g = X_gᵀW_gX_g` and the score `u_g = X_gᵀW_g e_g`.
#[derive(Debug, Clone, PartialEq)]
pub struct Cluster {
    /// Cross-products, p × p.
    pub s: DMatrix<f64>,
    /// Score at the estimate, p.
    pub u: DVector<f64>,
}

/// CR1's small-sample factor `G/(G−1) · (n−1)/(n−K)` (statsmodels' default correction).
pub fn cr1_factor(n: usize, k: usize, g: usize) -> f64 {
    let (n, k, g) = (n as f64, k as f64, g as f64);
    g / (g - 1.0) * (n - 1.0) / (n - k)
}

/// The symmetric "meat" `Σ_g v_g v_gᵀ`.
pub fn meat(scores: &[DVector<f64>], p: usize) -> DMatrix<f64> {
    let mut b = DMatrix::zeros(p, p);
    for v in scores {
        b.ger(1.0, v, v, 1.0);
    }
    b
}

/// The factor `L = R⁻¹` of `M = A⁻¹ = L Lᵀ` (`A = RᵀR`, Cholesky), or `None` when `A` is not
/// positive definite.
pub fn inverse_factor(a: &DMatrix<f64>) -> Option<DMatrix<f64>> {
    let p = a.nrows();
    // Equilibrate: A = D Â D with unit diagonal, so a badly scaled column does not fail Cholesky.
    let d: Vec<f64> = (0..p).map(|j| a[(j, j)].sqrt()).collect();
    if d.iter().any(|v| !(v.is_finite() && *v > 0.0)) {
        return None;
    }
    let ah = DMatrix::from_fn(p, p, |i, j| a[(i, j)] / (d[i] * d[j]));
    let chol = ah.cholesky()?;
    // Â = Lc Lcᵀ; A = (D Lc)(D Lc)ᵀ, so R = (D Lc)ᵀ and L = R⁻¹ = (D Lc)⁻ᵀ.
    let dl = DMatrix::from_fn(p, p, |i, j| d[i] * chol.l()[(i, j)]);
    let inv = dl.try_inverse()?;
    Some(inv.transpose())
}

/// The per-cluster matrices of the CR2 adjustment, from `C_g = Lᵀ S_g L` (eigenvalues in
/// [0, 1]): `(Φ₁, Φ₂)` with `φ₁(λ) = ((1−λ)^{−1/2} − 1)/λ` and `φ₂(λ) = ((1−λ)^{−1} − 1)/λ`
/// (Moore–Penrose at λ = 1: `f = 0`, so `φ₁ = φ₂ = −1`).
fn cr2_phis(c: &DMatrix<f64>) -> (DMatrix<f64>, DMatrix<f64>) {
    let e = SymmetricEigen::new(c.clone());
    let p = c.nrows();
    let mut d1 = DVector::zeros(p);
    let mut d2 = DVector::zeros(p);
    for (k, &l) in e.eigenvalues.iter().enumerate() {
        let l = l.clamp(0.0, 1.0);
        let (a, b) = if 1.0 - l <= UNIT_LEVERAGE {
            (-1.0 / l, -1.0 / l)
        } else if l < 1e-8 {
            // Series about 0: (1−λ)^{−1/2} = 1 + λ/2 + 3λ²/8 + …; (1−λ)^{−1} = 1 + λ + λ² + …
            (0.5 + 0.375 * l, 1.0 + l)
        } else {
            (((1.0 - l).powf(-0.5) - 1.0) / l, 1.0 / (1.0 - l))
        };
        d1[k] = a;
        d2[k] = b;
    }
    let q = &e.eigenvectors;
    let phi = |d: &DVector<f64>| q * DMatrix::from_diagonal(d) * q.transpose();
    (phi(&d1), phi(&d2))
}

/// What CR2 needs per cluster, computed once: `T1_g = X_gᵀA_gX_g`, `T2_g = X_gᵀA_g²X_g` and the
/// adjusted score `ũ_g = X_gᵀA_g e_g`.
#[derive(Debug, Clone)]
pub struct Cr2Cluster {
    /// `X_gᵀ A_g X_g`.
    pub t1: DMatrix<f64>,
    /// `X_gᵀ A_g² X_g`.
    pub t2: DMatrix<f64>,
    /// `X_gᵀ A_g e_g`.
    pub u: DVector<f64>,
}

/// The CR2 pieces of every cluster (`l`: the factor of [`inverse_factor`]).
pub fn cr2_clusters(l: &DMatrix<f64>, clusters: &[Cluster]) -> Vec<Cr2Cluster> {
    clusters
        .iter()
        .map(|c| {
            let cg = l.transpose() * &c.s * l;
            let (p1, p2) = cr2_phis(&cg);
            let sl = &c.s * l;
            let k1 = &sl * &p1 * sl.transpose();
            let k2 = &sl * &p2 * sl.transpose();
            let u = &c.u + &sl * (&p1 * (l.transpose() * &c.u));
            Cr2Cluster {
                t1: &c.s + k1,
                t2: &c.s + k2,
                u,
            }
        })
        .collect()
}

/// Bell–McCaffrey (Satterthwaite) degrees of freedom of the contrast `ell` under CR2:
/// `(Σλ)²/Σλ²` with λ the eigenvalues of `G'G` (see the module docs), from the clusters' CR2
/// pieces and `M = A⁻¹`. NaN when undefined (e.g. a contrast no cluster informs).
pub fn bm_df(m: &DMatrix<f64>, cr2: &[Cr2Cluster], ell: &DVector<f64>) -> f64 {
    let v = m * ell;
    let p = m.nrows();
    let mut sum_d = 0.0;
    let mut sum_d2 = 0.0;
    let mut sum_wmw = 0.0;
    let mut sum_dwmw = 0.0;
    let mut pmat = DMatrix::zeros(p, p);
    for c in cr2 {
        let w = &c.t1 * &v;
        let d = v.dot(&(&c.t2 * &v));
        let wmw = w.dot(&(m * &w));
        sum_d += d;
        sum_d2 += d * d;
        sum_wmw += wmw;
        sum_dwmw += d * wmw;
        pmat.ger(1.0, &w, &w, 1.0);
    }
    let mp = m * &pmat;
    let tr_mp2 = (&mp * &mp).trace();
    let t1 = sum_d - sum_wmw;
    let t2 = sum_d2 - 2.0 * sum_dwmw + tr_mp2;
    if t2 > 0.0 && t1.is_finite() {
        t1 * t1 / t2
    } else {
        f64::NAN
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A small clustered design, dense, to check the p × p identities against the n_g × n_g
    /// definitions written out directly.
    fn design() -> (DMatrix<f64>, DVector<f64>, Vec<usize>) {
        let rows = [
            (0, 1.0, 0.3, 1.1),
            (0, 2.0, -0.1, 2.3),
            (0, 2.5, 0.7, 2.2),
            (1, 0.5, 0.2, 0.4),
            (1, 3.0, -0.4, 3.6),
            (2, 1.5, 0.9, 1.0),
            (2, 1.7, 0.1, 2.4),
            (2, 4.0, -0.6, 3.9),
            (2, 0.2, 0.5, 0.1),
            (3, 2.2, 0.0, 2.0),
            (3, 3.3, 0.4, 3.5),
        ];
        let x = DMatrix::from_fn(rows.len(), 3, |i, j| match j {
            0 => 1.0,
            1 => rows[i].1,
            _ => rows[i].2,
        });
        let y = DVector::from_fn(rows.len(), |i, _| rows[i].3);
        (x, y, rows.iter().map(|r| r.0).collect())
    }

    fn inv_sqrt_psd(h: &DMatrix<f64>) -> DMatrix<f64> {
        let n = h.nrows();
        let e = SymmetricEigen::new(DMatrix::identity(n, n) - h);
        let d = e
            .eigenvalues
            .map(|l| if l > 1e-10 { l.powf(-0.5) } else { 0.0 });
        &e.eigenvectors * DMatrix::from_diagonal(&d) * e.eigenvectors.transpose()
    }

    #[test]
    fn cr2_from_sums_equals_the_dense_definition() {
        let (x, y, g) = design();
        let a = x.transpose() * &x;
        let m = a.clone().try_inverse().unwrap();
        let beta = &m * x.transpose() * &y;
        let e = &y - &x * &beta;
        let ng = 4;
        let idx = |c: usize| -> Vec<usize> { (0..g.len()).filter(|&i| g[i] == c).collect() };
        let sub = |rows: &[usize]| DMatrix::from_fn(rows.len(), 3, |i, j| x[(rows[i], j)]);
        let clusters: Vec<Cluster> = (0..ng)
            .map(|c| {
                let r = idx(c);
                let xg = sub(&r);
                let eg = DVector::from_fn(r.len(), |i, _| e[r[i]]);
                Cluster {
                    s: xg.transpose() * &xg,
                    u: xg.transpose() * eg,
                }
            })
            .collect();
        let l = inverse_factor(&a).unwrap();
        assert!((&l * l.transpose() - &m).amax() < 1e-12);
        let cr2 = cr2_clusters(&l, &clusters);
        // Dense: A_g = (I − X_g M X_gᵀ)^{−1/2}.
        let mut dense_u = Vec::new();
        let mut ag_all = Vec::new();
        for (c, cc) in cr2.iter().enumerate() {
            let r = idx(c);
            let xg = sub(&r);
            let h = &xg * &m * xg.transpose();
            let ag = inv_sqrt_psd(&h);
            let eg = DVector::from_fn(r.len(), |i, _| e[r[i]]);
            dense_u.push(xg.transpose() * &ag * eg);
            assert!((xg.transpose() * &ag * &xg - &cc.t1).amax() < 1e-10);
            assert!((xg.transpose() * &ag * &ag * &xg - &cc.t2).amax() < 1e-10);
            ag_all.push((r, ag));
        }
        for c in 0..ng {
            assert!((&dense_u[c] - &cr2[c].u).amax() < 1e-12, "cluster {c}");
        }
        // Satterthwaite df, dense: G = (I − H)[:, g] A_g X_g M ℓ, λ = eig(GᵀG).
        let n = x.nrows();
        let h = &x * &m * x.transpose();
        let imh = DMatrix::identity(n, n) - h;
        for ell in [
            DVector::from_vec(vec![0.0, 1.0, 0.0]),
            DVector::from_vec(vec![1.0, 0.5, -2.0]),
        ] {
            let mut gm = DMatrix::<f64>::zeros(n, ng);
            for (c, (r, ag)) in ag_all.iter().enumerate() {
                let xg = sub(r);
                let pg = ag * &xg * &m * &ell;
                for (k, &i) in r.iter().enumerate() {
                    for row in 0..n {
                        gm[(row, c)] += imh[(row, i)] * pg[k];
                    }
                }
            }
            let gtg = gm.transpose() * &gm;
            let lam: DVector<f64> = SymmetricEigen::new(gtg).eigenvalues;
            let want = lam.sum().powi(2) / lam.iter().map(|l| l * l).sum::<f64>();
            let got = bm_df(&m, &cr2, &ell);
            assert!((got - want).abs() < 1e-9 * want, "{got} vs {want}");
        }
    }

    #[test]
    fn a_unit_leverage_gets_the_pseudo_inverse() {
        // A cluster that alone determines a coefficient (its own dummy column).
        let x = DMatrix::from_row_slice(5, 2, &[1., 1., 1., 1., 1., 0., 1., 0., 1., 0.]);
        let a = x.transpose() * &x;
        let l = inverse_factor(&a).unwrap();
        let xg = x.rows(0, 2).into_owned();
        let c = Cluster {
            s: xg.transpose() * &xg,
            u: DVector::from_vec(vec![0.0, 0.0]),
        };
        let cr2 = cr2_clusters(&l, &[c]);
        let m = a.try_inverse().unwrap();
        let h = &xg * &m * xg.transpose();
        let ag = inv_sqrt_psd(&h);
        assert!((xg.transpose() * &ag * &xg - &cr2[0].t1).amax() < 1e-10);
    }
}
