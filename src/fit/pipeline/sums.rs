//! Folds and replicates of fits with only linear coefficients to refit, from per-subject
//! sufficient statistics ([`SubjectSums`]): one pass over the rows, then sums of subjects.
use super::Prepared;
use crate::fit::constrained::{BoxStats, ColumnBounds};
use crate::fit::design::{Layout, SubjectSums, Totals};
use crate::relations::Relation;
use nalgebra::DVector;

/// Leave-one-subject-out for a fit with only linear coefficients to refit: every subject's
/// sums ([`SubjectSums`]) from one pass, each fold solved from the sums of the others (prefix +
/// suffix over subjects: no subtraction, no pass per fold). Per subject, in subject order: the
/// squared prediction errors of its rows (level 0), or `None` when the fold is singular.
pub(super) fn loso_from_subject_sums(
    rel: &dyn Relation,
    lay: &Layout,
    p: &[f64],
    prep: &Prepared,
    bounds: Option<(&ColumnBounds, &BoxStats)>,
) -> Vec<Option<Vec<f64>>> {
    let n_subj = prep.subjects.len();
    let m = lay.m();
    let nes = crate::fit::design::subject_normal_equations(rel, lay, p, prep, None, None, n_subj);
    let Some(sums) = nes
        .iter()
        .map(|ne| SubjectSums::absorb(ne, lay.subj_col))
        .collect::<Option<Vec<_>>>()
    else {
        return vec![None; n_subj];
    };
    drop(nes);
    let mut prefix = Vec::with_capacity(n_subj + 1);
    prefix.push(Totals::zeros(m));
    for s in &sums {
        let mut t = prefix[prefix.len() - 1].clone();
        t.add(s, 1.0);
        prefix.push(t);
    }
    let mut suffix = vec![Totals::zeros(m); n_subj + 1];
    for s in (0..n_subj).rev() {
        let mut t = suffix[s + 1].clone();
        t.add(&sums[s], 1.0);
        suffix[s] = t;
    }
    let mut rows_of = vec![Vec::new(); n_subj];
    for (i, &s) in prep.subject.iter().enumerate() {
        rows_of[s].push(i);
    }
    (0..n_subj)
        .map(|s| {
            let mut t = prefix[s].clone();
            t.add_totals(&suffix[s + 1]);
            let coef = solve_totals(&t, lay, bounds)?;
            let q = lay.params(rel, p, &coef);
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

/// The basis coefficients of some subjects' sums, by the bounded solver when there are bounds
/// (recording the solve), else by the normal equations.
pub(super) fn solve_totals(
    t: &Totals,
    lay: &Layout,
    bounds: Option<(&ColumnBounds, &BoxStats)>,
) -> Option<DVector<f64>> {
    match bounds {
        None => t.solve(lay).map(|r| r.0),
        Some((cb, stats)) => match t.solve_box(lay, &cb.lo, &cb.hi) {
            Some((coef, _, sol)) => {
                stats.record(&sol);
                Some(coef)
            }
            None => {
                stats.record_failure();
                None
            }
        },
    }
}

/// Every subject's [`SubjectSums`] at `p`, or `None` when a subject's own column is all zeros.
pub(super) fn all_subject_sums(
    rel: &dyn Relation,
    lay: &Layout,
    p: &[f64],
    prep: &Prepared,
) -> Option<Vec<SubjectSums>> {
    let n_subj = prep.subjects.len();
    crate::fit::design::subject_normal_equations(rel, lay, p, prep, None, None, n_subj)
        .iter()
        .map(|ne| SubjectSums::absorb(ne, lay.subj_col))
        .collect()
}
