//! The 95 % confidence band of the mean prediction (under the fit's inference method, with the
//! breakpoints free where their profile is regular).
use super::{FitOutcome, CONFIDENCE};
use crate::fit::design::{Covariance, Layout, MAX_BASIS};
use crate::fit::forms::Fitting;
use crate::fit::stats::t_quantile;
use crate::relations::{Inputs, Relation};
use nalgebra::DVector;

/// What the confidence band of the mean prediction needs.
#[derive(Debug, Clone)]
pub(super) struct Band {
    pub(super) lay: Layout,
    pub(super) coef: DVector<f64>,
    pub(super) cov: Covariance,
    /// Free breakpoints in θ (parameter index), when the covariance has them free.
    pub(super) bps: Vec<usize>,
}

impl Band {
    /// The mean prediction at `x` for parameters `p` and basis coefficients `coef`.
    fn mean(&self, rel: &dyn Relation, p: &[f64], coef: &DVector<f64>, x: &Inputs) -> f64 {
        let mut phi = [0.0; MAX_BASIS];
        let off = rel.basis(p, &self.lay.free, x, &mut phi[..self.lay.nb]);
        off + (0..self.lay.nb).map(|j| phi[j] * coef[j]).sum::<f64>()
    }
    /// The gradient of the mean prediction over θ.
    fn ell(&self, rel: &dyn Relation, p: &[f64], x: &Inputs) -> DVector<f64> {
        let lay = &self.lay;
        let mut phi = [0.0; MAX_BASIS];
        rel.basis(p, &lay.free, x, &mut phi[..lay.nb]);
        let k = self.cov.k;
        let dim = k + usize::from(self.cov.has_fe);
        let mut ell = DVector::zeros(dim);
        let mut g = 0;
        for (j, &v) in phi[..lay.nb].iter().enumerate() {
            if Some(j) == lay.subj_col {
                ell[k] = v;
            } else {
                ell[g] = v;
                g += 1;
            }
        }
        for (b, &i) in self.bps.iter().enumerate() {
            let h = step(p[i]);
            let (mut up, mut dn) = (p.to_vec(), p.to_vec());
            up[i] += h;
            dn[i] -= h;
            ell[g + b] = (self.mean(rel, &up, &self.coef, x) - self.mean(rel, &dn, &self.coef, x))
                / (2.0 * h);
        }
        ell
    }
}

/// Step of the central differences with respect to a breakpoint at `t`.
pub(super) fn step(t: f64) -> f64 {
    1e-6 * t.abs().max(1.0)
}

impl FitOutcome {
    /// The refit prediction for an average subject at `x` with its 95 % confidence band
    /// (under the fit's inference method): `(mean, lo, hi)`.
    pub fn band(&self, x: &Inputs) -> (f64, f64, f64) {
        let rel = self.refit.relation();
        let b = &self.band;
        let m = b.mean(rel, &self.values, &b.coef, x);
        let ell = b.ell(rel, &self.values, x);
        let var = ell.dot(&(&b.cov.v * &ell)).max(0.0);
        let q = t_quantile(0.5 + 0.5 * CONFIDENCE, b.cov.df(&ell));
        (m, m - q * var.sqrt(), m + q * var.sqrt())
    }
}
