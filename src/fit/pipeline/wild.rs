//! The wild cluster bootstrap-t of a fit linear in every free coefficient
//! ([`crate::fit::wild`]), from the subjects' normal equations at the estimate.
use super::Prepared;
use crate::fit::design::{subject_normal_equations, Layout};
use crate::fit::forms::Fitting;
use crate::fit::record::{WildCoefficient, WildRecord};
use crate::fit::wild::{wild_cluster_t, ClusterSums, Draws};
use crate::relations::{ParamKind, Relation};
use nalgebra::{DMatrix, DVector};

/// The wild cluster bootstrap-t record of the fit with layout `lay` at parameters `p`, whose
/// reported values are `values` (clusters = subjects). `None` when the normal equations are
/// singular.
pub(super) fn wild_record(
    rel: &dyn Relation,
    lay: &Layout,
    p: &[f64],
    prep: &Prepared,
    values: &[f64],
    draws: usize,
    seed: u64,
) -> Option<WildRecord> {
    let n_subj = prep.subjects.len();
    let nb = lay.nb;
    let nes = subject_normal_equations(rel, lay, p, prep, None, None, n_subj);
    // The OLS coefficients in the basis, from the summed normal equations.
    let mut a = DMatrix::<f64>::zeros(nb, nb);
    let mut r = DVector::<f64>::zeros(nb);
    for ne in &nes {
        a += DMatrix::from_row_slice(nb, nb, &ne.xtx);
        r += DVector::from_column_slice(&ne.xty);
    }
    let coef = a.cholesky()?.solve(&r);
    let clusters: Vec<ClusterSums> = nes
        .iter()
        .map(|ne| {
            let m = DMatrix::from_row_slice(nb, nb, &ne.xtx);
            let score = DVector::from_column_slice(&ne.xty) - m * &coef;
            ClusterSums {
                xtx: ne.xtx.clone(),
                score: score.as_slice().to_vec(),
            }
        })
        .collect();
    // Contrasts: each free linear parameter's row of the basis → parameters map.
    let lm = rel.basis_to_params(p, &lay.free);
    let specs = rel.card().parameters;
    let mut names = Vec::new();
    let mut contrasts = Vec::new();
    let mut estimates = Vec::new();
    let mut j = 0;
    for (i, s) in specs.iter().enumerate() {
        if s.kind != ParamKind::Linear {
            continue;
        }
        if lay.free[i] {
            names.push(s.name.to_string());
            contrasts.push(lm.map.row(j).iter().copied().collect::<Vec<f64>>());
            estimates.push(values[i]);
        }
        j += 1;
    }
    let n = prep.obs.len();
    let w = wild_cluster_t(
        &clusters,
        &contrasts,
        n,
        Draws::EnumerateOr { n: draws, seed },
    )?;
    let coefficients = names
        .into_iter()
        .enumerate()
        .map(|(k, name)| {
            let ci = w.interval(k, estimates[k]);
            WildCoefficient {
                name,
                ci95: ci.iter().all(|x| x.is_finite()).then_some(ci),
                t_quantiles: w.quantiles[k],
                se_cr1: w.se_cr1[k],
            }
        })
        .filter(|c| c.t_quantiles.iter().all(|x| x.is_finite()))
        .collect();
    Some(WildRecord {
        method: "unrestricted wild cluster bootstrap-t by subject (WCU: y* = Xβ̂ + w_g·û_g, each \
                 sample refitted and studentised by its own CR1 standard error); interval \
                 θ̂ − q*·SE_CR1 with q* the 2.5 % and 97.5 % order statistics of t*"
            .into(),
        weights: "Webb six-point: ±√(1/2), ±1, ±√(3/2), each 1/6 (MacKinnon & Webb 2017)".into(),
        samples: w.samples,
        enumerated: w.enumerated,
        seed: (!w.enumerated).then_some(seed),
        coefficients,
    })
}
