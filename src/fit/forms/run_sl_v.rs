//! The fit form of `run-sl-v` (running 1996, eq. 2): the plateau onset v_norm is profiled over
//! the height-normalised speed u = v/√(h/1.8) with sorted prefix sums of a few per-row features.
use super::{
    sorted_keys, DistinctKeys, Form, KeyRange, KeyScale, KeySums, NormalEquations, Plan,
    SortedProfile,
};
use crate::relations::run_sl_v::REFERENCE_HEIGHT_M;
use crate::relations::{Observation, Relation};

/// The form of [`crate::relations::RunSlV`].
#[derive(Debug, Clone, Copy)]
pub struct SlVForm;

impl Form for SlVForm {
    fn plan(&self, _rel: &dyn Relation, obs: &[Observation]) -> Plan {
        self.plan_sorted(DistinctKeys::new(&sorted_keys(self, obs)))
    }
    fn sorted_profile(&self) -> Option<&dyn SortedProfile> {
        Some(self)
    }
    /// The plateau vanishes from the data at v_norm = +∞.
    fn breakpoint_null(&self, _i: usize) -> Option<f64> {
        Some(f64::INFINITY)
    }
}

/// Feature slots of the sorted profile: below the plateau the regressor is z₀ = v·r, on it
/// v_norm·q with q = r² (r = √(h/1.8)).
mod feat {
    pub const ONE: usize = 0;
    pub const Z: usize = 1;
    pub const ZZ: usize = 2;
    pub const Y: usize = 3;
    pub const ZY: usize = 4;
    pub const Q: usize = 5;
    pub const QQ: usize = 6;
    pub const QY: usize = 7;
    pub const YY: usize = 8;
    pub const N: usize = 9;
}

impl SortedProfile for SlVForm {
    /// The height-normalised speed u = v/√(h/1.8): a row is on the plateau when u > v_norm.
    fn key(&self, x: &[f64]) -> f64 {
        x[0] / (x[1] / REFERENCE_HEIGHT_M).sqrt()
    }
    fn n_features(&self) -> usize {
        feat::N
    }
    fn features(&self, _scale: &KeyScale, _centre: f64, o: &Observation, out: &mut [f64]) {
        let r = (o.x[1] / REFERENCE_HEIGHT_M).sqrt();
        let (z, q, y) = (o.x[0] * r, r * r, o.y);
        out[feat::ONE] = 1.0;
        out[feat::Z] = z;
        out[feat::ZZ] = z * z;
        out[feat::Y] = y;
        out[feat::ZY] = z * y;
        out[feat::Q] = q;
        out[feat::QQ] = q * q;
        out[feat::QY] = q * y;
        out[feat::YY] = y * y;
    }
    fn normal_equations(
        &self,
        p: &[f64],
        free: &[bool],
        _scale: &KeyScale,
        sums: &dyn KeySums,
    ) -> NormalEquations {
        let t = p[2];
        // Rows with u ≤ v_norm use z₀; the others v_norm·q (equal at u = v_norm).
        let lo = sums.range(KeyRange::below(t, true), t);
        let hi = sums.range(KeyRange::above(t, false), t);
        let (mut sz, mut szz, mut szy) = (lo[feat::Z], lo[feat::ZZ], lo[feat::ZY]);
        if hi[feat::ONE] != 0.0 {
            sz += t * hi[feat::Q];
            szz += t * t * hi[feat::QQ];
            szy += t * hi[feat::QY];
        }
        let tot = |j: usize| lo[j] + hi[j];
        let raw = NormalEquations {
            nb: 2,
            xtx: vec![tot(feat::ONE), sz, sz, szz],
            xty: vec![tot(feat::Y), szy],
            yty: tot(feat::YY),
        };
        NormalEquations::hold_raw(&raw, &free[..2], &p[..2])
    }
    fn plan_sorted(&self, u: DistinctKeys) -> Plan {
        // At least 3 distinct normalised speeds on each side of any trial breakpoint.
        let (held, search) = if u.len() >= 8 {
            (None, Some((u.get(2), u.get(u.len() - 3))))
        } else {
            (
                Some(format!(
                    "needs at least 8 distinct speeds to locate the plateau (have {})",
                    u.len()
                )),
                None,
            )
        };
        Plan {
            held: vec![None, None, held],
            search: vec![None, None, search],
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::relations::Inputs;
    use crate::relations::RunSlV;

    #[test]
    fn sorted_normal_equations_match_the_basis_rows() {
        let sl = |p: &[f64], level: f64, v: f64, h: f64| {
            RunSlV::new(p[0], p[1], p[2]).step_length(v, h, level)
        };
        let obs: Vec<Observation> = (0..300)
            .map(|i| {
                let v = 100.0 + 1.3 * (i % 290) as f64;
                let h = 1.6 + 0.05 * (i % 7) as f64;
                Observation {
                    x: Inputs::new(&[v, h, 0.0, 0.0]),
                    y: sl(&[0.14, 0.0046, 400.0], 0.0, v, h) + 0.01 * ((i % 3) as f64 - 1.0),
                }
            })
            .collect();
        let r = RunSlV::published();
        for t in [150.0, 283.7, 400.0, 1e4, f64::INFINITY] {
            for free in [[true, true], [false, true], [true, false], [false, false]] {
                let p = [0.1394, 0.00465, t];
                crate::fit::forms::sorted_check::check(
                    &r,
                    &obs,
                    &p,
                    &[free[0], free[1], true],
                    1e-11,
                );
            }
        }
    }
}
