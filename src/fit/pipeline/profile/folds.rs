//! Leave-one-subject-out folds at population scale: exact downdates of shared sums.
//!
//! # Why
//! With a per-subject column (run-sl-v's level) every evaluation of a profile sums the G
//! subjects' absorbed normal equations (each subject's own slope partialled out within the
//! subject, a rational function of the breakpoint), and each of the G folds re-profiles its
//! breakpoint with ~100 evaluations: O(G²) subject evaluations (> 150 s at G = 2,000).
//! Every fold also listed its distinct keys with a pass over all rows: O(G·n).
//!
//! # Method
//! - **Keys** ([`FoldKeys`]): a fold's distinct keys are all rows' distinct keys without those
//!   that only the left-out subject has (listed per subject once): a copy, no pass with tests.
//! - **Sums** ([`FoldEngine`], one free continuous breakpoint with a per-subject column): a
//!   fold's sums are the sums over all subjects minus the left-out subject's,
//!   `T₋ₛ(t) = T(t) − Tₛ(t)` (an exact downdate: the absorbed sums are additive over subjects),
//!   so a fold evaluation costs one subject plus `T(t)`, which every fold shares:
//!   - on the grid that [`minimize_1d`](crate::fit::nonlinear::minimize_1d) scans (the same for
//!     every fold whose search range is the whole data's), `T(t)` is summed exactly once; a
//!     fold whose range is narrower (its subject holds one of the extreme keys) has its own
//!     grid summed exactly once per range, shared by the folds with that range (before, such a
//!     fold summed its G − 1 subjects at every one of its ~100 evaluations);
//!   - elsewhere (Brent's iterates), from a lazily refined model over the search range: a cell
//!     `[a, b]` with at most [`CELL_ROWS`] rows splits the subjects into those with a key in
//!     `[a, b]` (summed exactly at every `t`) and the others, whose rows do not change side
//!     inside the cell, so their sum is analytic in `t` there (no pole on the real line: it
//!     divides by each subject's `s_zz > 0`). That sum is interpolated at [`CHEB_NODES`]
//!     Chebyshev points, and the interpolant is checked against the exact sum at the cell's
//!     midpoint to [`CHEB_TOL`] of the sum of the terms' magnitudes (rounding level); a cell
//!     failing the check is summed exactly at every evaluation.
//!
//!   Each fold's search is then the one it always was (the same grid, Brent's method in the
//!   best cell), on the same function to rounding; `tests` compare it with summing the other
//!   subjects directly.
use super::{Members, Query, SortedRows};
use crate::fit::design::{Layout, SubjectSums, Totals};
use crate::fit::forms::DistinctKeys;
use crate::fit::prec::MIN1D_GRID;
use nalgebra::DVector;
use std::collections::HashMap;
use std::sync::{Arc, Mutex, OnceLock};

/// Most rows in a cell of the model (its crossing subjects are summed exactly per evaluation).
pub const CELL_ROWS: usize = 32;
/// Chebyshev points per cell.
pub const CHEB_NODES: usize = 8;
/// Children of a cell that holds too many rows.
const SPLIT: usize = 8;
/// Deepest refinement (cells narrower than the range / 8¹² are leaves whatever they hold).
const MAX_DEPTH: usize = 12;
/// Accepted interpolation error, relative to the sum of the terms' magnitudes.
pub const CHEB_TOL: f64 = 1e-12;

/// The distinct keys of every fold without a pass over the rows.
pub(in crate::fit::pipeline) struct FoldKeys {
    /// All rows' distinct keys, ascending.
    keys: Vec<f64>,
    /// Per subject: positions in `keys` of the keys no other subject has, ascending.
    own: Vec<Vec<u32>>,
}

impl FoldKeys {
    /// From the sorted rows (one pass).
    pub fn new(sr: &SortedRows) -> FoldKeys {
        let ns = sr.subj.len();
        let mut keys: Vec<f64> = Vec::new();
        let mut owner: Vec<u32> = Vec::new();
        for (&k, &s) in sr.all.keys.iter().zip(&sr.key_subject) {
            if keys.last() == Some(&k) {
                let o = owner.last_mut().expect("a key has an owner entry");
                if *o != s {
                    *o = u32::MAX;
                }
            } else {
                keys.push(k);
                owner.push(s);
            }
        }
        let mut own = vec![Vec::new(); ns];
        for (j, &o) in owner.iter().enumerate() {
            if o != u32::MAX {
                own[o as usize].push(j as u32);
            }
        }
        FoldKeys { keys, own }
    }

    /// The distinct keys of all rows but subject `s`'s (a view: nothing is copied).
    pub fn without(&self, s: usize) -> DistinctKeys<'_> {
        DistinctKeys::without(&self.keys, &self.own[s])
    }
}

/// Set once a search range's grid is in the exact cache (its first fold sums it; the others
/// wait for it).
type GridOnce = Arc<OnceLock<()>>;

/// A cell of the model of `T(t)`.
struct Cell {
    lo: f64,
    hi: f64,
    depth: usize,
    children: OnceLock<Vec<Cell>>,
    model: OnceLock<Model>,
}

/// `T(t)` inside a leaf cell.
struct Model {
    /// Subjects with a key in the cell (summed exactly).
    crossing: Vec<usize>,
    /// Per component of the others' sum: Chebyshev coefficients (`None`: sum exactly).
    cheb: Option<Vec<[f64; CHEB_NODES]>>,
}

/// The shared sums of the folds of one fit (see the module docs).
pub(in crate::fit::pipeline) struct FoldEngine<'b> {
    sr: &'b SortedRows<'b>,
    lay: Layout,
    /// The whole data's estimate; folds vary `p[i]` only.
    p: Vec<f64>,
    i: usize,
    search: (f64, f64),
    exact: Mutex<HashMap<u64, Totals>>,
    /// The search ranges whose grids are in `exact` (summed once, by the first fold asking).
    grids: Mutex<HashMap<(u64, u64), GridOnce>>,
    root: Cell,
}

/// Components of a [`Totals`] (its `count` aside): `s`, `r`, `yy`, `rho`, `d`.
fn n_comp(m: usize) -> usize {
    m * m + 2 * m + 2
}

fn flatten(t: &SubjectSums, out: &mut [f64]) {
    let m = t.r.len();
    out[..m * m].copy_from_slice(&t.s);
    out[m * m..m * m + m].copy_from_slice(&t.r);
    out[m * m + m] = t.yy;
    out[m * m + m + 1] = t.rho;
    out[m * m + m + 2..].copy_from_slice(&t.d);
}

fn totals_of(m: usize, comp: &[f64], count: f64) -> Totals {
    Totals {
        m,
        s: comp[..m * m].to_vec(),
        r: comp[m * m..m * m + m].to_vec(),
        yy: comp[m * m + m],
        rho: comp[m * m + m + 1],
        d: comp[m * m + m + 2..].to_vec(),
        count,
    }
}

impl<'b> FoldEngine<'b> {
    /// The engine for folds of the fit `lay` at `p`, breakpoint `i` continuous and searched
    /// over `search`; `None` unless that is the only free breakpoint and there is a per-subject
    /// column (otherwise a fold evaluation is already O(log n), or the engine does not apply).
    pub fn new(
        sr: &'b SortedRows<'b>,
        lay: &Layout,
        p: &[f64],
        i: usize,
        search: (f64, f64),
    ) -> Option<FoldEngine<'b>> {
        if lay.subj_col.is_none() || sr.ctx.form.discrete_breakpoint(i) || sr.subj.len() < 3 {
            return None;
        }
        let e = FoldEngine {
            sr,
            lay: lay.clone(),
            p: p.to_vec(),
            i,
            search,
            exact: Mutex::new(HashMap::new()),
            grids: Mutex::new(HashMap::new()),
            root: Cell {
                lo: search.0,
                hi: search.1,
                depth: 0,
                children: OnceLock::new(),
                model: OnceLock::new(),
            },
        };
        e.sum_grid(search);
        Some(e)
    }

    /// `T(t)` summed exactly on the grid that [`minimize_1d`](crate::fit::nonlinear::minimize_1d)
    /// scans over `search` (in parallel over the grid), once per range.
    fn sum_grid(&self, search: (f64, f64)) {
        let once = {
            let Ok(mut grids) = self.grids.lock() else {
                return;
            };
            grids
                .entry((search.0.to_bits(), search.1.to_bits()))
                .or_default()
                .clone()
        };
        once.get_or_init(|| {
            // As minimize_1d builds it.
            let (lo, hi) = search;
            let h = (hi - lo) / MIN1D_GRID as f64;
            let grid: Vec<f64> = (0..=MIN1D_GRID)
                .map(|k| {
                    if k == MIN1D_GRID {
                        hi
                    } else {
                        lo + h * k as f64
                    }
                })
                .collect();
            let known: Vec<bool> = match self.exact.lock() {
                Ok(map) => grid
                    .iter()
                    .map(|t| map.contains_key(&t.to_bits()))
                    .collect(),
                Err(_) => return,
            };
            use rayon::prelude::*;
            let sums: Vec<(u64, Option<Totals>)> = grid
                .par_iter()
                .zip(&known)
                .filter(|(_, &k)| !k)
                .map(|(&t, _)| (t.to_bits(), self.sum_exact(t, None)))
                .collect();
            if let Ok(mut map) = self.exact.lock() {
                for (k, v) in sums {
                    if let Some(v) = v {
                        map.insert(k, v);
                    }
                }
            }
        });
    }

    /// Whether a fold with layout `lay`, starting values `p` and search ranges `search` can use
    /// the engine: the same layout, the same parameters but for the breakpoint, no other free
    /// breakpoint searched, and the breakpoint's search range inside the engine's. A fold
    /// whose range differs from the engine's (its subject held one of the extreme keys) has
    /// its own grid summed exactly here (once per range, shared by the folds with that range);
    /// its other evaluations use the model, as every fold's do.
    pub fn applies(&self, lay: &Layout, p: &[f64], search: &[Option<(f64, f64)>]) -> bool {
        let Some(range) = search.get(self.i).copied().flatten() else {
            return false;
        };
        let ok = *lay == self.lay
            && range.0 >= self.search.0
            && range.1 <= self.search.1
            && range.0 < range.1
            && self.same_but_i(p)
            && search
                .iter()
                .enumerate()
                .all(|(j, s)| j == self.i || s.is_none() || !lay.free[j]);
        if ok && range != self.search {
            self.sum_grid(range);
        }
        ok
    }

    fn same_but_i(&self, p: &[f64]) -> bool {
        p.len() == self.p.len()
            && p.iter()
                .zip(&self.p)
                .enumerate()
                .all(|(j, (a, b))| j == self.i || a.to_bits() == b.to_bits())
    }

    /// Subject `s`'s absorbed sums at parameters `q`.
    fn subject(&self, q: &[f64], s: usize) -> Option<SubjectSums> {
        let one = [(s, 1.0)];
        let query = Query {
            sr: self.sr,
            members: Members::List(&one),
            remove: None,
        };
        let ne = self
            .sr
            .ctx
            .form
            .normal_equations(q, &self.lay.free, &self.sr.ctx.scale, &query);
        if ne.nb != self.lay.nb {
            return None;
        }
        SubjectSums::absorb(&ne, self.lay.subj_col)
    }

    fn at(&self, t: f64) -> Vec<f64> {
        let mut q = self.p.clone();
        q[self.i] = t;
        q
    }

    /// The sum over all subjects (but those with `skip[s]`) at breakpoint `t`, in subject
    /// order.
    fn sum_exact(&self, t: f64, skip: Option<&[bool]>) -> Option<Totals> {
        let q = self.at(t);
        let mut tot = Totals::zeros(self.lay.m());
        for s in 0..self.sr.subj.len() {
            if skip.is_some_and(|k| k[s]) {
                continue;
            }
            tot.add(&self.subject(&q, s)?, 1.0);
        }
        Some(tot)
    }

    /// The leaf cell holding `t`.
    fn leaf(&self, t: f64) -> &Cell {
        let keys = &self.sr.all.keys;
        let mut c = &self.root;
        loop {
            let rows = keys.partition_point(|&k| k <= c.hi) - keys.partition_point(|&k| k < c.lo);
            if rows <= CELL_ROWS || c.depth >= MAX_DEPTH {
                return c;
            }
            let kids = c.children.get_or_init(|| {
                (0..SPLIT)
                    .map(|j| Cell {
                        lo: c.lo + (c.hi - c.lo) * j as f64 / SPLIT as f64,
                        hi: if j + 1 == SPLIT {
                            c.hi
                        } else {
                            c.lo + (c.hi - c.lo) * (j + 1) as f64 / SPLIT as f64
                        },
                        depth: c.depth + 1,
                        children: OnceLock::new(),
                        model: OnceLock::new(),
                    })
                    .collect()
            });
            c = kids.iter().find(|k| t <= k.hi).unwrap_or(&kids[SPLIT - 1]);
        }
    }

    /// The model of a leaf: its crossing subjects, and the others' sum interpolated (checked).
    fn model(&self, c: &Cell) -> Model {
        let sr = self.sr;
        let keys = &sr.all.keys;
        let (a, b) = (
            keys.partition_point(|&k| k < c.lo),
            keys.partition_point(|&k| k <= c.hi),
        );
        let ns = sr.subj.len();
        let mut skip = vec![false; ns];
        let mut crossing = Vec::new();
        for &s in &sr.key_subject[a..b] {
            if !skip[s as usize] {
                skip[s as usize] = true;
                crossing.push(s as usize);
            }
        }
        let m = self.lay.m();
        let nc = n_comp(m);
        let (mid, half) = (0.5 * (c.lo + c.hi), 0.5 * (c.hi - c.lo));
        // Values and magnitudes of the others' sum at the Chebyshev points and the midpoint.
        let sum_abs = |t: f64| -> Option<(Vec<f64>, Vec<f64>)> {
            let q = self.at(t);
            let (mut v, mut mag) = (vec![0.0; nc], vec![0.0; nc]);
            let mut f = vec![0.0; nc];
            for s in (0..ns).filter(|&s| !skip[s]) {
                flatten(&self.subject(&q, s)?, &mut f);
                for j in 0..nc {
                    v[j] += f[j];
                    mag[j] += f[j].abs();
                }
            }
            Some((v, mag))
        };
        let cheb = (|| {
            if half.is_nan() || half <= 0.0 {
                return None;
            }
            let n = CHEB_NODES;
            let theta = |j: usize| std::f64::consts::PI * (j as f64 + 0.5) / n as f64;
            let mut vals = Vec::with_capacity(n);
            for j in 0..n {
                vals.push(sum_abs(mid + half * theta(j).cos())?.0);
            }
            let coef: Vec<[f64; CHEB_NODES]> = (0..nc)
                .map(|comp| {
                    let mut c = [0.0; CHEB_NODES];
                    for (k, ck) in c.iter_mut().enumerate() {
                        *ck = 2.0 / n as f64
                            * (0..n)
                                .map(|j| vals[j][comp] * (k as f64 * theta(j)).cos())
                                .sum::<f64>();
                    }
                    c
                })
                .collect();
            let (v, mag) = sum_abs(mid)?;
            let ok = (0..nc).all(|j| (clenshaw(&coef[j], 0.0) - v[j]).abs() <= CHEB_TOL * mag[j]);
            ok.then_some(coef)
        })();
        Model { crossing, cheb }
    }

    /// `T(t) − Tₛ(t)`: the sums of every subject but `s` at breakpoint `t`.
    fn fold_totals(&self, t: f64, s: usize) -> Option<Totals> {
        let q = self.at(t);
        let cached = self
            .exact
            .lock()
            .ok()
            .and_then(|m| m.get(&t.to_bits()).cloned());
        let mut tot = match cached {
            Some(tot) => tot,
            None if t < self.search.0 || t > self.search.1 => self.sum_exact(t, None)?,
            None => {
                let c = self.leaf(t);
                let model = c.model.get_or_init(|| self.model(c));
                match &model.cheb {
                    None => self.sum_exact(t, None)?,
                    Some(coef) => {
                        let m = self.lay.m();
                        let u =
                            ((t - 0.5 * (c.lo + c.hi)) / (0.5 * (c.hi - c.lo))).clamp(-1.0, 1.0);
                        let comp: Vec<f64> = coef.iter().map(|c| clenshaw(c, u)).collect();
                        let count = (self.sr.subj.len() - model.crossing.len()) as f64;
                        let mut tot = totals_of(m, &comp, count);
                        for &x in &model.crossing {
                            if x != s {
                                tot.add(&self.subject(&q, x)?, 1.0);
                            }
                        }
                        if model.crossing.contains(&s) {
                            return Some(tot);
                        }
                        tot
                    }
                }
            }
        };
        tot.add(&self.subject(&q, s)?, -1.0);
        Some(tot)
    }

    /// Fold `s`'s linear coefficients and weighted RSS at `p` (`p` equal to the engine's but
    /// for the breakpoint; otherwise summed directly).
    pub fn solve(&self, p: &[f64], s: usize) -> Option<(DVector<f64>, f64)> {
        if !self.same_but_i(p) {
            return super::solve_sorted(self.sr, &self.lay, p, Members::AllBut(s), None);
        }
        self.fold_totals(p[self.i], s)?.solve(&self.lay)
    }
}

/// A Chebyshev series `c₀/2 + Σ cₖ Tₖ(u)` at `u` (Clenshaw).
fn clenshaw(c: &[f64; CHEB_NODES], u: f64) -> f64 {
    let (mut b1, mut b2) = (0.0, 0.0);
    for &ck in c.iter().skip(1).rev() {
        let b0 = 2.0 * u * b1 - b2 + ck;
        b2 = b1;
        b1 = b0;
    }
    u * b1 - b2 + 0.5 * c[0]
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::fit::forms::Fitting;
    use crate::fit::pipeline::Prepared;
    use crate::relations::{Observation, Relation, RunSlV};

    /// Run-sl-v rows from `g` subjects with their own slopes and a plateau.
    fn prepared(g: usize, per: usize) -> Prepared {
        let mut p = Prepared::default();
        let mut state = 0x2545_f491_4f6c_dd1du64;
        let mut u = || {
            state ^= state << 13;
            state ^= state >> 7;
            state ^= state << 17;
            (state >> 11) as f64 / (1u64 << 53) as f64
        };
        for s in 0..g {
            let h = 1.6 + 0.35 * u();
            let level = 0.0008 * (2.0 * u() - 1.0);
            for _ in 0..per {
                let v = 100.0 + 380.0 * u();
                let r = RunSlV::new(0.1394, 0.00465, 400.0);
                let y = r.step_length(v, h, level) + 0.03 * (u() - 0.5);
                p.obs.push(Observation {
                    x: crate::relations::Inputs::new(&[v, h]),
                    y,
                });
                p.subject.push(s);
                p.weights.push(1.0);
            }
        }
        p.subjects = (0..g).map(|s| format!("S{s}")).collect();
        p
    }

    #[test]
    fn fold_keys_are_the_other_subjects_distinct_keys() {
        let rel = RunSlV::published();
        let rel: &dyn Relation = &rel;
        let mut prep = prepared(7, 40);
        // Shared keys: subject 1 repeats some of subject 0's rows.
        for i in 0..10 {
            let o = prep.obs[i];
            prep.obs.push(o);
            prep.subject.push(1);
            prep.weights.push(1.0);
        }
        let sr = SortedRows::new(rel.sorted_profile().expect("sorted"), &prep, false);
        let fk = FoldKeys::new(&sr);
        for s in 0..7 {
            let include: Vec<bool> = (0..7).map(|x| x != s).collect();
            assert_eq!(
                fk.without(s).to_vec(),
                sr.distinct_keys(&include),
                "subject {s}"
            );
        }
    }

    #[test]
    fn downdated_fold_sums_equal_the_other_subjects_summed() {
        let rel = RunSlV::published();
        let rel: &dyn Relation = &rel;
        let prep = prepared(12, 300);
        let form = rel.sorted_profile().expect("sorted");
        let sr = SortedRows::new(form, &prep, false);
        let lay = Layout::new(rel, vec![true; 3], 11);
        assert!(lay.subj_col.is_some());
        let p = [0.14, 0.0046, 395.0];
        let keys = sr.distinct_keys(&[true; 12]);
        let search = (keys[2], keys[keys.len() - 3]);
        let e = FoldEngine::new(&sr, &lay, &p, 2, search).expect("engine");
        let mut interpolated = 0;
        for s in [0, 5, 11] {
            for k in 0..200 {
                let t = search.0 + (search.1 - search.0) * (k as f64 + 0.37) / 200.0;
                let mut q = p.to_vec();
                q[2] = t;
                let (c1, r1) = e.solve(&q, s).expect("engine fold");
                let (c2, r2) = super::super::solve_sorted(&sr, &lay, &q, Members::AllBut(s), None)
                    .expect("direct fold");
                assert!((r1 - r2).abs() <= 1e-10 * r2, "t = {t}: rss {r1} vs {r2}");
                for j in 0..c1.len() {
                    assert!(
                        (c1[j] - c2[j]).abs() <= 1e-9 * c2[j].abs().max(1e-6),
                        "t = {t}: coef {j} {} vs {}",
                        c1[j],
                        c2[j]
                    );
                }
            }
        }
        // The interpolated cells were used (not only the exact fallback).
        let mut stack = vec![&e.root];
        while let Some(c) = stack.pop() {
            if let Some(k) = c.children.get() {
                stack.extend(k.iter());
            }
            if let Some(Model { cheb: Some(_), .. }) = c.model.get() {
                interpolated += 1;
            }
        }
        assert!(interpolated > 0);
    }
    #[test]
    fn folds_with_a_narrower_search_range_use_the_engine_on_their_own_grid() {
        let rel = RunSlV::published();
        let rel: &dyn Relation = &rel;
        let prep = prepared(12, 300);
        let form = rel.sorted_profile().expect("sorted");
        let sr = SortedRows::new(form, &prep, false);
        let lay = Layout::new(rel, vec![true; 3], 11);
        let p = [0.14, 0.0046, 395.0];
        let keys = sr.distinct_keys(&[true; 12]);
        let search = (keys[2], keys[keys.len() - 3]);
        let e = FoldEngine::new(&sr, &lay, &p, 2, search).expect("engine");
        let ranges = |r: (f64, f64)| vec![None, None, Some(r)];
        let narrow = (keys[3], keys[keys.len() - 4]);
        assert!(e.applies(&lay, &p, &ranges(search)));
        assert!(!e.applies(&lay, &p, &ranges((keys[1], search.1))));
        assert!(!e.applies(&lay, &p, &[None, None, None]));
        assert!(!e.applies(&lay, &[0.14, 0.0047, 395.0], &ranges(search)));
        assert!(e.applies(&lay, &p, &ranges(narrow)));
        // The narrow range's grid (as minimize_1d scans it) is summed exactly, and a fold's sums
        // there equal the other subjects summed directly.
        let h = (narrow.1 - narrow.0) / MIN1D_GRID as f64;
        for k in 0..=MIN1D_GRID {
            let t = if k == MIN1D_GRID {
                narrow.1
            } else {
                narrow.0 + h * k as f64
            };
            assert!(e.exact.lock().expect("lock").contains_key(&t.to_bits()));
            for s in [0, 7] {
                let q = [p[0], p[1], t];
                let (_, r1) = e.solve(&q, s).expect("engine fold");
                let (_, r2) = super::super::solve_sorted(&sr, &lay, &q, Members::AllBut(s), None)
                    .expect("direct fold");
                assert!((r1 - r2).abs() <= 1e-10 * r2, "t = {t}: rss {r1} vs {r2}");
            }
        }
        // A fold whose subject holds an extreme key has its own search range; its refit through
        // the engine finds the optimum the direct refit finds.
        let fk = FoldKeys::new(&sr);
        let s = sr.key_subject[0] as usize;
        let own = form.plan_sorted(fk.without(s)).search[2].expect("fold range");
        assert!(own != search, "subject {s} holds the lowest key");
        let free = vec![true; 3];
        let via_engine = super::super::refit(
            rel,
            &free,
            &p,
            super::super::Subset::Fold(&sr, &fk, Some(&e), s),
        )
        .expect("engine refit");
        let direct = super::super::refit(
            rel,
            &free,
            &p,
            super::super::Subset::Fold(&sr, &fk, None, s),
        )
        .expect("direct refit");
        for j in 0..3 {
            assert!(
                (via_engine[j] - direct[j]).abs() <= 1e-6 * direct[j].abs(),
                "parameter {j}: {} vs {}",
                via_engine[j],
                direct[j]
            );
        }
    }
}
