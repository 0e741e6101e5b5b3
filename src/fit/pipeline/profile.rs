//! Breakpoint profiles: the residual sum of squares as a function of a breakpoint (the linear
//! coefficients refitted at every trial value), its minimisation, its likelihood interval, and
//! the refits of cross-validation and the bootstrap.
//!
//! # Sorted prefix sums
//! Relations with a [`SortedProfile`] give the normal equations at any trial value from sums
//! of per-row features over ranges of one key (their breakpoints split the rows by it): the
//! rows are sorted by key **once** (a radix sort, O(n)) and gathered into key order, and binary
//! trees of weighted feature sums are built over all rows and over each subject's rows (all
//! leaves in one sequential pass; the tree over all rows only when a fit without per-subject
//! columns asks for it). Every evaluation then costs a binary search per tree and range plus
//! O(log n) node sums and an O(p³) solve. A subject multiset (a leave-one-subject-out fold, a
//! bootstrap replicate) is a weighted sum of per-subject trees, so folds never touch the rows
//! either. Relations without one fall back to a pass over the rows per evaluation (exact, slow
//! on large tables).
//!
//! # Searches
//! - A breakpoint whose residual sum of squares varies continuously (a plateau onset, a knot
//!   with continuity) is minimised by a 64-cell grid scan followed by argmin's Brent method
//!   ([`minimize_1d`]), on all rows. When the form relaxes the breakpoint over a window of
//!   values ([`SortedProfile::window_relaxation`](crate::fit::forms::SortedProfile::window_relaxation):
//!   the rows whose piece depends on where in the window the breakpoint lies dropped, the
//!   model widened to contain every fit with the breakpoint in the window), the relaxed fit's
//!   RSS bounds the profile from below on the whole window, and the grid scan is a branch and
//!   bound ([`minimize_1d_bounded`]): windows whose bound exceeds the best grid value found are
//!   never evaluated. The grid's first minimum, hence the result, is the scan's, bit for bit.
//! - A *discrete* breakpoint ([`SortedProfile::discrete_breakpoint`]: the model depends on it
//!   only through which rows fall on each side, e.g. the knot between the flight-time paper's
//!   free pieces) has a step-function profile: any value between two adjacent distinct keys
//!   gives the same fit. It is minimised **exactly** over those partitions by branch and bound:
//!   fitting the rows of a key range's complement gives a lower bound for every partition inside
//!   the range (fewer rows never fit worse), so ranges whose bound exceeds the best partition
//!   found are discarded and the rest bisected. The first incumbent is the partition holding the
//!   breakpoint's current value (a fold's or a replicate's: the whole data's estimate, usually
//!   optimal or nearly so), so most ranges are discarded at their first bound; the start only
//!   changes how much is pruned, never which partition is optimal (every range not discarded by
//!   a valid bound is searched). The estimate is the midpoint of the optimal gap, and its
//!   interval ends are data keys (where the partition changes).
//! - Two breakpoints are profiled by coordinate descent; a breakpoint whose search would see the
//!   same other coordinates (bit for bit) as its previous search keeps that search's value (the
//!   search is a function of them: its result would be the same number).
//!
//! The partitions' search is exact to the rounding of the residual sums of squares: a
//! partition better than the incumbent by less than 1e-12 of it is not distinguishable, and
//! which of two such near-ties is reported may depend on the visit order.
use super::Prepared;
use crate::fit::design::solve_normal;
use crate::fit::design::{solve_rows, Layout};
use crate::fit::forms::{DistinctKeys, Fitting};
use crate::fit::nonlinear::{minimize_1d, minimize_1d_bounded};
use crate::fit::prec::PROFILE_BOUND_SLACK;
use crate::fit::record::BreakpointRecord;
use crate::fit::FitError;
use crate::relations::{Observation, ParamKind, Relation};
use nalgebra::DVector;
use std::cmp::Reverse;
use std::collections::BinaryHeap;

mod folds;
mod sorted;
pub(super) use folds::{FoldEngine, FoldKeys};
use sorted::{solve_sorted, Query};
pub(super) use sorted::{Members, SortedRows};

/// Evaluations after which the exact search of a discrete breakpoint stops and keeps the best
/// partition found (with a note): reached only by a profile that is flat over a great many
/// partitions (no knot in the data).
pub const DISCRETE_MAX_EVALS: usize = 20_000;

/// Where the rows of a profile come from.
#[derive(Clone, Copy)]
pub(super) enum Source<'b> {
    /// A pass over the rows per evaluation (relations without a sorted form).
    Rows {
        prep: &'b Prepared,
        rows: Option<&'b [usize]>,
        subj_map: Option<&'b [usize]>,
        n_subj: usize,
    },
    /// Trees over the rows sorted by key; `keys` are the members' rows' distinct keys.
    Sorted {
        sr: &'b SortedRows<'b>,
        members: Members<'b>,
        keys: DistinctKeys<'b>,
    },
    /// All subjects but `s`, from the folds' shared sums (module `folds`).
    Fold {
        engine: &'b FoldEngine<'b>,
        s: usize,
    },
}

/// Evaluates a relation's fit on some rows at trial breakpoints.
pub(super) struct Profiler<'b> {
    pub rel: &'b dyn Relation,
    pub lay: &'b Layout,
    pub src: Source<'b>,
}

impl Profiler<'_> {
    /// Linear coefficients and weighted RSS at `p`, `None` when singular.
    pub fn solve(&self, p: &[f64]) -> Option<(DVector<f64>, f64)> {
        match self.src {
            Source::Rows {
                prep,
                rows,
                subj_map,
                n_subj,
            } => solve_rows(self.rel, self.lay, p, prep, rows, subj_map, n_subj),
            Source::Sorted { sr, members, .. } => solve_sorted(sr, self.lay, p, members, None),
            Source::Fold { engine, s } => engine.solve(p, s),
        }
    }

    /// Weighted RSS at `p` (+∞ when singular).
    pub fn rss(&self, p: &[f64]) -> f64 {
        self.solve(p).map_or(f64::INFINITY, |r| r.1)
    }

    fn rss_at(&self, p: &[f64], i: usize, t: f64) -> f64 {
        let mut q = p.to_vec();
        q[i] = t;
        self.rss(&q)
    }

    /// True when the form bounds breakpoint `i`'s profile over windows
    /// ([`SortedProfile::window_relaxation`](crate::fit::forms::SortedProfile::window_relaxation))
    /// and the rows are summed from trees without a per-subject column.
    fn bounds(&self, i: usize) -> bool {
        matches!(self.src, Source::Sorted { sr, .. } if sr.ctx.form.relaxes(i))
            && self.lay.subj_col.is_none()
    }

    /// `yᵀWy` of the normal equations at `p` (the scale of the profile's rounding).
    fn yty(&self, p: &[f64]) -> f64 {
        match self.src {
            Source::Sorted { sr, members, .. } => {
                let q = Query {
                    sr,
                    members,
                    remove: None,
                };
                let ne = sr
                    .ctx
                    .form
                    .normal_equations(p, &self.lay.free, &sr.ctx.scale, &q);
                ne.yty
            }
            _ => f64::NAN,
        }
    }

    /// A lower bound of the profile RSS of breakpoint `i` (the others at `p`) at every value in
    /// `[ta, tb]`, allowing for rounding: the form's relaxed fit on the rows outside `[ta, tb)`
    /// minus [`PROFILE_BOUND_SLACK`]·max(`yty`, that RSS) (`yty` from [`Self::yty`]); −∞ when
    /// there is none.
    fn window_bound(&self, p: &[f64], i: usize, ta: f64, tb: f64, yty: f64) -> f64 {
        let Source::Sorted { sr, members, .. } = self.src else {
            return f64::NEG_INFINITY;
        };
        let q = Query {
            sr,
            members,
            remove: Some((ta, tb)),
        };
        sr.ctx
            .form
            .window_relaxation(p, &self.lay.free, i, ta, tb, &sr.ctx.scale, &q)
            .and_then(|ne| solve_normal(ne.nb, &ne.xtx, &ne.xty, ne.yty))
            .map_or(f64::NEG_INFINITY, |(_, rss)| {
                rss - PROFILE_BOUND_SLACK * yty.max(rss)
            })
    }

    /// The sorted source when breakpoint `i` is discrete.
    fn discrete(&self, i: usize) -> Option<Discrete<'_>> {
        match self.src {
            Source::Sorted { sr, members, keys } if sr.ctx.form.discrete_breakpoint(i) => {
                Some(Discrete {
                    pr: self,
                    sr,
                    members,
                    keys,
                    i,
                })
            }
            _ => None,
        }
    }
}

/// A discrete breakpoint's profile over partitions. Partition `j` (1 ≤ j < keys.len()) puts the
/// rows with key < `keys[j]` below the breakpoint: every value in `(keys[j−1], keys[j]]`.
struct Discrete<'b> {
    pr: &'b Profiler<'b>,
    sr: &'b SortedRows<'b>,
    members: Members<'b>,
    keys: DistinctKeys<'b>,
    i: usize,
}

/// An f64 ordered by `total_cmp` (for the heap).
#[derive(PartialEq)]
struct Ordered(f64);
impl Eq for Ordered {}
impl PartialOrd for Ordered {
    fn partial_cmp(&self, o: &Self) -> Option<std::cmp::Ordering> {
        Some(self.cmp(o))
    }
}
impl Ord for Ordered {
    fn cmp(&self, o: &Self) -> std::cmp::Ordering {
        self.0.total_cmp(&o.0)
    }
}

impl Discrete<'_> {
    /// The breakpoint value representing partition `j`: the middle of its gap.
    fn value(&self, j: usize) -> f64 {
        0.5 * (self.keys.get(j - 1) + self.keys.get(j))
    }
    fn rss(&self, p: &[f64], j: usize) -> f64 {
        self.pr.rss_at(p, self.i, self.value(j))
    }
    /// A lower bound of the RSS of partitions `a..=b`: the fit without the rows whose side
    /// differs between them (keys in `[keys[a], keys[b])`).
    fn lower_bound(&self, p: &[f64], a: usize, b: usize) -> f64 {
        let mut q = p.to_vec();
        q[self.i] = self.value(a);
        solve_sorted(
            self.sr,
            self.pr.lay,
            &q,
            self.members,
            Some((self.keys.get(a), self.keys.get(b))),
        )
        // Singular without those rows: no bound.
        .map_or(0.0, |r| r.1)
    }
    /// The partitions whose whole gap lies in `[lo, hi]`.
    fn candidates(&self, lo: f64, hi: f64) -> Option<(usize, usize)> {
        let j0 = self.keys.partition_point(|&d| d < lo) + 1;
        let j1 = self.keys.partition_point(|&d| d <= hi).checked_sub(1)?;
        (j0 <= j1 && j1 < self.keys.len()).then_some((j0, j1))
    }

    /// The exact minimum over the partitions in `[lo, hi]` (branch and bound from the whole
    /// range, the partition holding `p[i]` the first incumbent), as a value.
    fn minimise(&self, p: &[f64], lo: f64, hi: f64, notes: &mut Vec<String>) -> Option<f64> {
        let (j0, j1) = self.candidates(lo, hi)?;
        let mut evals = 0usize;
        let mut best = (f64::INFINITY, j0);
        let visit = |j: usize, best: &mut (f64, usize), evals: &mut usize| {
            let r = self.rss(p, j);
            *evals += 1;
            // Ties go to the lower partition, so the result does not depend on visit order.
            if r < best.0 || (r == best.0 && j < best.1) {
                *best = (r, j);
            }
        };
        // Partition j holds the values in (keys[j − 1], keys[j]]: the number of keys below.
        let warm = self.keys.partition_point(|&d| d < p[self.i]).clamp(j0, j1);
        visit(warm, &mut best, &mut evals);
        let mut heap: BinaryHeap<Reverse<(Ordered, usize, usize)>> = BinaryHeap::new();
        let push = |a: usize,
                    b: usize,
                    heap: &mut BinaryHeap<Reverse<(Ordered, usize, usize)>>,
                    best: &mut (f64, usize),
                    evals: &mut usize| {
            if a == b {
                visit(a, best, evals);
            } else {
                *evals += 1;
                heap.push(Reverse((Ordered(self.lower_bound(p, a, b)), a, b)));
            }
        };
        push(j0, j1, &mut heap, &mut best, &mut evals);
        while let Some(Reverse((Ordered(bound), a, b))) = heap.pop() {
            // Bounds agree with fits to rounding; a partition better than the best by less than
            // that is not distinguishable.
            if bound >= best.0 - 1e-12 * best.0.abs() {
                break;
            }
            if evals >= DISCRETE_MAX_EVALS {
                notes.push(format!(
                    "{}: the exact search over partitions stopped after {DISCRETE_MAX_EVALS} \
                     evaluations (the profile is flat over many partitions); the best partition \
                     found is reported",
                    self.pr.rel.card().parameters[self.i].name
                ));
                break;
            }
            let m = a + (b - a) / 2;
            visit(m, &mut best, &mut evals);
            if a < m {
                push(a, m - 1, &mut heap, &mut best, &mut evals);
            }
            if m < b {
                push(m + 1, b, &mut heap, &mut best, &mut evals);
            }
        }
        best.0.is_finite().then(|| self.value(best.1))
    }

    /// The F confidence set over every admissible partition in `[lo, hi]`: the partitions
    /// whose RSS is at most `thr`, found exactly by branch and bound (a range of partitions
    /// whose lower bound exceeds `thr` is rejected whole; the others are split down to single
    /// partitions, which are evaluated).
    fn confidence_set(&self, p: &[f64], lo: f64, hi: f64, thr: f64) -> Option<ConfidenceSet> {
        let (j0, j1) = self.candidates(lo, hi)?;
        let mut accepted: Vec<(usize, f64)> = Vec::new();
        let mut stack = vec![(j0, j1)];
        while let Some((a, b)) = stack.pop() {
            if a == b {
                let r = self.rss(p, a);
                if r <= thr {
                    accepted.push((a, r));
                }
                continue;
            }
            if self.lower_bound(p, a, b) > thr {
                continue;
            }
            let m = a + (b - a) / 2;
            stack.push((a, m));
            stack.push((m + 1, b));
        }
        accepted.sort_by_key(|a| a.0);
        let mut pieces = Vec::new();
        let mut minima = 0;
        let mut k = 0;
        while k < accepted.len() {
            let mut e = k;
            while e + 1 < accepted.len() && accepted[e + 1].0 == accepted[e].0 + 1 {
                e += 1;
            }
            // Partition j holds every value in (keys[j − 1], keys[j]].
            let (a, b) = (accepted[k].0, accepted[e].0);
            pieces.push([
                (a > j0).then(|| self.keys.get(a - 1)),
                (b < j1).then(|| self.keys.get(b)),
            ]);
            for q in k..=e {
                let r = accepted[q].1;
                let left = q == k || accepted[q - 1].1 > r;
                let right = q == e || accepted[q + 1].1 >= r;
                if left && right {
                    minima += 1;
                }
            }
            k = e + 1;
        }
        Some(ConfidenceSet {
            discrete: true,
            admissible: j1 - j0 + 1,
            accepted: accepted.len(),
            pieces,
            local_minima: minima,
            minima_in_set: minima,
        })
    }
}

/// Profiles the free breakpoints of `pr.lay` (coordinate descent), returning the updated
/// parameters.
pub(super) fn profile(
    pr: &Profiler,
    p0: &[f64],
    search: &[Option<(f64, f64)>],
    notes: &mut Vec<String>,
) -> Result<Vec<f64>, FitError> {
    let rel = pr.rel;
    let bps: Vec<usize> = (0..p0.len())
        .filter(|&i| pr.lay.free[i] && rel.card().parameters[i].kind == ParamKind::Breakpoint)
        .collect();
    let mut p = p0.to_vec();
    let max_rounds = if bps.len() > 1 { 4 } else { 1 };
    // Per breakpoint: the parameters its last search saw, and its result.
    let mut last: Vec<Option<(Vec<f64>, f64)>> = vec![None; bps.len()];
    let mut yty: Option<f64> = None;
    let same_but = |i: usize, a: &[f64], b: &[f64]| {
        a.iter()
            .zip(b)
            .enumerate()
            .all(|(j, (x, y))| j == i || x.to_bits() == y.to_bits())
    };
    for _ in 0..max_rounds {
        let mut moved = 0.0f64;
        for (slot, &i) in last.iter_mut().zip(&bps) {
            let Some((lo, hi)) = search[i] else { continue };
            let t = match slot {
                // The same search as last time (it does not read p[i] but for the discrete
                // search's first incumbent, which does not change its optimum): its value.
                Some((q, t)) if same_but(i, q, &p) => *t,
                _ => match pr.discrete(i) {
                    Some(d) => {
                        d.minimise(&p, lo, hi, notes)
                            .ok_or_else(|| FitError::Optimizer {
                                relation: rel.card().id.into(),
                                message: format!(
                                    "no partition of the rows by {} in [{lo}, {hi}] can be fitted",
                                    rel.card().parameters[i].name
                                ),
                            })?
                    }
                    None => {
                        let tol = (hi - lo).abs() * 1e-7;
                        let f = |t| pr.rss_at(&p, i, t);
                        if pr.bounds(i) {
                            let yty = *yty.get_or_insert_with(|| pr.yty(&p));
                            let lower = |a, b| pr.window_bound(&p, i, a, b, yty);
                            minimize_1d_bounded(f, lower, p[i], lo, hi, tol)?.0
                        } else {
                            minimize_1d(f, lo, hi, tol)?.0
                        }
                    }
                },
            };
            *slot = Some((p.clone(), t));
            moved = moved.max((t - p[i]).abs() / (hi - lo).abs().max(f64::MIN_POSITIVE));
            p[i] = t;
        }
        if moved < 1e-6 {
            break;
        }
    }
    Ok(p)
}

/// Cells of the grid over a continuous breakpoint's whole search range on which its profile
/// is evaluated for the confidence set (and its local minima counted): fine enough to resolve
/// a set a few tenths of a percent of the range wide; each crossing is then bisected.
pub const PROFILE_GRID: usize = 256;

/// A breakpoint's 95 % confidence set from its profile.
#[derive(Debug, Clone, PartialEq)]
pub(super) struct ConfidenceSet {
    /// The model depends on the breakpoint only through which rows lie on each side.
    discrete: bool,
    /// Partitions (discrete) or grid values examined.
    admissible: usize,
    /// Of those, accepted.
    accepted: usize,
    /// Pieces `[lo, hi]`; `None` where a piece reaches the end of the admissible range.
    pieces: Vec<[Option<f64>; 2]>,
    /// Local minima of the profile over the admissible range.
    local_minima: usize,
    /// Local minima inside the set.
    minima_in_set: usize,
}

impl ConfidenceSet {
    /// The record and the hull (the reported `ci95`).
    pub fn record(&self, name: &str) -> (BreakpointRecord, [Option<f64>; 2]) {
        let hull = match (self.pieces.first(), self.pieces.last()) {
            (Some(a), Some(b)) => [a[0], b[1]],
            _ => [None, None],
        };
        let why = if self.discrete {
            Some(format!(
                "the model jumps at {name}, so the residual sum of squares is a step function of \
                 it: no derivative, no Wald standard error (the estimate converges at rate n, \
                 with a non-normal limit)"
            ))
        } else if self.pieces.len() != 1 {
            Some(format!(
                "the confidence set has {} separate pieces",
                self.pieces.len()
            ))
        } else if hull[0].is_none() || hull[1].is_none() {
            Some("the confidence set reaches the end of the admissible range".into())
        } else if self.minima_in_set > 1 {
            Some(format!(
                "the profile has {} local minima inside the confidence set",
                self.minima_in_set
            ))
        } else {
            None
        };
        let method = if self.discrete {
            format!(
                "F-test of the profile residual sum of squares against its minimum, over all {} \
                 admissible partitions of the rows (exact: branch and bound)",
                self.admissible
            )
        } else {
            format!(
                "F-test of the profile residual sum of squares against its minimum, on a grid of \
                 {} values over the whole search range (crossings bisected)",
                self.admissible
            )
        };
        (
            BreakpointRecord {
                name: name.to_string(),
                method,
                admissible: self.admissible,
                accepted: self.accepted,
                pieces: self.pieces.clone(),
                local_minima: self.local_minima,
                regular: why.is_none(),
                irregular_because: why,
                design_effect: None,
                pieces_iid: Vec::new(),
            },
            hull,
        )
    }
}

/// A continuous breakpoint's profile on the [`PROFILE_GRID`] grid over its search range (and at
/// the estimate): computed once per breakpoint and shared by its confidence sets (the plain F
/// set and the clustered one differ only in the threshold). Empty for a discrete breakpoint or
/// one without a search range.
pub(super) struct ProfileGrid {
    ts: Vec<f64>,
    r: Vec<f64>,
}

impl ProfileGrid {
    /// The profile of breakpoint `i` (the others held at `p`), the grid's values evaluated in
    /// parallel (each is the same number whichever thread computes it).
    pub fn new(pr: &Profiler, p: &[f64], i: usize, search: &[Option<(f64, f64)>]) -> ProfileGrid {
        let empty = ProfileGrid {
            ts: Vec::new(),
            r: Vec::new(),
        };
        let Some((lo, hi)) = search[i] else {
            return empty;
        };
        if pr.discrete(i).is_some() {
            return empty;
        }
        let cells = PROFILE_GRID;
        let mut ts: Vec<f64> = (0..=cells)
            .map(|c| lo + (hi - lo) * c as f64 / cells as f64)
            .collect();
        if p[i] > lo && p[i] < hi {
            ts.push(p[i]);
            ts.sort_by(f64::total_cmp);
            ts.dedup();
        }
        use rayon::prelude::*;
        let r: Vec<f64> = ts.par_iter().map(|&t| pr.rss_at(p, i, t)).collect();
        ProfileGrid { ts, r }
    }
}

/// The 95 % confidence set of breakpoint `i` (the others held at `p`): the values where the
/// profile RSS ≤ `thr` = RSS_min·(1 + F(1, df; 0.95)/df), over every admissible partition of
/// the rows (discrete breakpoints) or the grid `grid` ([`ProfileGrid::new`] of the same
/// `pr`, `p`, `i`, `search`; crossings bisected).
pub(super) fn confidence_set(
    pr: &Profiler,
    p: &[f64],
    i: usize,
    search: &[Option<(f64, f64)>],
    thr: f64,
    grid: &ProfileGrid,
) -> ConfidenceSet {
    let empty = ConfidenceSet {
        discrete: pr.discrete(i).is_some(),
        admissible: 0,
        accepted: 0,
        pieces: Vec::new(),
        local_minima: 0,
        minima_in_set: 0,
    };
    let Some((lo, hi)) = search[i] else {
        return empty;
    };
    if let Some(d) = pr.discrete(i) {
        return d.confidence_set(p, lo, hi, thr).unwrap_or(empty);
    }
    let rss = |t: f64| pr.rss_at(p, i, t);
    let cells = PROFILE_GRID;
    let (ts, r) = (&grid.ts, &grid.r);
    let ok: Vec<bool> = r.iter().map(|&v| v <= thr).collect();
    let tol = 1e-3 * (hi - lo) / cells as f64;
    // The crossing between an accepted `a` and a rejected `b`.
    let cross = |a: f64, b: f64| {
        let (mut a, mut b) = (a, b);
        while (b - a).abs() > tol {
            let m = 0.5 * (a + b);
            if rss(m) <= thr {
                a = m;
            } else {
                b = m;
            }
        }
        0.5 * (a + b)
    };
    let n = ts.len();
    let mut pieces = Vec::new();
    let mut k = 0;
    while k < n {
        if !ok[k] {
            k += 1;
            continue;
        }
        let mut e = k;
        while e + 1 < n && ok[e + 1] {
            e += 1;
        }
        pieces.push([
            (k > 0).then(|| cross(ts[k], ts[k - 1])),
            (e + 1 < n).then(|| cross(ts[e], ts[e + 1])),
        ]);
        k = e + 1;
    }
    let mut minima = 0;
    let mut in_set = 0;
    for c in 0..n {
        let left = c == 0 || r[c - 1] > r[c];
        let right = c + 1 == n || r[c + 1] >= r[c];
        if left && right {
            minima += 1;
            if ok[c] {
                in_set += 1;
            }
        }
    }
    ConfidenceSet {
        discrete: false,
        admissible: n,
        accepted: ok.iter().filter(|&&v| v).count(),
        pieces,
        local_minima: minima,
        minima_in_set: in_set,
    }
}

/// The rows of a refit (cross-validation, bootstrap).
pub(super) enum Subset<'b> {
    /// Row indices (relations without a sorted form).
    Rows(&'b Prepared, &'b [usize]),
    /// Some subjects' rows.
    Subjects(&'b SortedRows<'b>, Members<'b>),
    /// All subjects but one (a leave-one-subject-out fold): its keys from `FoldKeys`, its sums
    /// from the engine when one applies.
    Fold(
        &'b SortedRows<'b>,
        &'b FoldKeys,
        Option<&'b FoldEngine<'b>>,
        usize,
    ),
}

/// Maps subject ids of a row subset to dense 0..S indices (order of first appearance).
fn dense_subjects(prep: &Prepared, rows: &[usize]) -> (Vec<usize>, usize) {
    let mut map = vec![usize::MAX; prep.subjects.len()];
    let mut n = 0;
    for &i in rows {
        let s = prep.subject[i];
        if map[s] == usize::MAX {
            map[s] = n;
            n += 1;
        }
    }
    (map, n)
}

/// The subject multiset of a row subset made of whole subjects (a bootstrap sample), in order
/// of first appearance; `None` when some subject is only partly included.
pub(super) fn whole_subjects(prep: &Prepared, rows: &[usize]) -> Option<Vec<(usize, f64)>> {
    let ns = prep.subjects.len();
    let mut size = vec![0usize; ns];
    for &s in &prep.subject {
        size[s] += 1;
    }
    let mut count = vec![0usize; ns];
    let mut order = Vec::new();
    for &i in rows {
        let s = prep.subject[i];
        if count[s] == 0 {
            order.push(s);
        }
        count[s] += 1;
    }
    order
        .into_iter()
        .map(|s| (count[s] % size[s] == 0).then(|| (s, (count[s] / size[s]) as f64)))
        .collect()
}

/// Before leave-one-subject-out folds without a [`FoldEngine`]: every fold's first breakpoint
/// search (when continuous, [`minimize_1d`]) first scans the same grid at the same other
/// parameters `p` (the whole data's estimate) whenever its range is the whole data's `search`,
/// and its evaluations subtract the fold's subject from the tree over all rows: that tree's
/// part of the grid is computed once ([`SortedRows::memoise_all`]; the same numbers).
pub(super) fn share_first_grid(
    sr: &SortedRows,
    rel: &dyn Relation,
    free: &[bool],
    search: &[Option<(f64, f64)>],
    p: &[f64],
    bps: &[usize],
) {
    let Some(&i) = bps.first() else { return };
    let Some((lo, hi)) = search[i] else { return };
    if sr.form().discrete_breakpoint(i) {
        return;
    }
    // The free parameters as `refit` passes them on (breakpoints without a range fixed).
    let params = &rel.card().parameters;
    let fold_free: Vec<bool> = (0..free.len())
        .map(|j| free[j] && !(params[j].kind == ParamKind::Breakpoint && search[j].is_none()))
        .collect();
    let ps: Vec<Vec<f64>> = crate::fit::nonlinear::minimize_1d_grid(lo, hi)
        .into_iter()
        .map(|x| {
            let mut q = p.to_vec();
            q[i] = x;
            q
        })
        .collect();
    sr.memoise_all(&ps, &fold_free);
}

/// Refits everything (breakpoints included) on a subset: the global coefficient vector, or
/// `None` if the subset cannot be fitted.
pub(super) fn refit(
    rel: &dyn Relation,
    free: &[bool],
    p_start: &[f64],
    subset: Subset,
) -> Option<Vec<f64>> {
    let (plan, n_subj, map, keys);
    let own_keys;
    match subset {
        Subset::Rows(prep, rows) => {
            let (m, n) = dense_subjects(prep, rows);
            let sub_obs: Vec<Observation> = rows.iter().map(|&i| prep.obs[i]).collect();
            plan = rel.plan(&sub_obs);
            (n_subj, map, keys) = (n, m, DistinctKeys::new(&[]));
        }
        Subset::Subjects(sr, members) => {
            let list = members.list(sr.subj.len());
            let mut include = vec![false; sr.subj.len()];
            for &(s, _) in &list {
                include[s] = true;
            }
            own_keys = sr.distinct_keys(&include);
            keys = DistinctKeys::new(&own_keys);
            plan = sr.ctx.form.plan_sorted(keys);
            (n_subj, map) = (list.len(), Vec::new());
        }
        Subset::Fold(sr, fk, _, s) => {
            keys = fk.without(s);
            plan = sr.ctx.form.plan_sorted(keys);
            (n_subj, map) = (sr.subj.len() - 1, Vec::new());
        }
    }
    let mut free = free.to_vec();
    let mut search = plan.search.clone();
    for i in 0..free.len() {
        if rel.card().parameters[i].kind == ParamKind::Breakpoint
            && (!free[i] || search[i].is_none())
        {
            free[i] = false;
            search[i] = None;
        }
    }
    let lay = Layout::new(rel, free, n_subj);
    let src = match subset {
        Subset::Rows(prep, rows) => Source::Rows {
            prep,
            rows: Some(rows),
            subj_map: Some(&map),
            n_subj,
        },
        Subset::Subjects(sr, members) => Source::Sorted { sr, members, keys },
        Subset::Fold(sr, _, engine, s) => {
            match engine.filter(|e| e.applies(&lay, p_start, &search)) {
                Some(engine) => Source::Fold { engine, s },
                None => Source::Sorted {
                    sr,
                    members: Members::AllBut(s),
                    keys,
                },
            }
        }
    };
    let pr = Profiler {
        rel,
        lay: &lay,
        src,
    };
    let p = profile(&pr, p_start, &search, &mut Vec::new()).ok()?;
    let (coef, _) = pr.solve(&p)?;
    Some(lay.params(rel, &p, &coef))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::fit::forms::Fitting;
    use crate::relations::{Inputs, RunTflightSf};

    /// A profiler over every sorted row (the tests' common source).
    fn all_rows<'b>(
        rel: &'b dyn Relation,
        lay: &'b Layout,
        sr: &'b SortedRows<'b>,
        keys: &'b [f64],
    ) -> Profiler<'b> {
        Profiler {
            rel,
            lay,
            src: Source::Sorted {
                sr,
                members: Members::All,
                keys: DistinctKeys::new(keys),
            },
        }
    }

    /// Flight times on a line with two jumps the free pieces cannot follow inside a piece: a
    /// small one at sf = 170 and a large one at sf = 196, so the profile of
    /// k1 has a local minimum at the small jump and its global minimum at the large one.
    fn two_jumps() -> Prepared {
        let mut prep = Prepared::default();
        let n = 420;
        for i in 0..n {
            let sf = 150.0 + 85.0 * i as f64 / n as f64 + 0.013 * ((i * 37) % 11) as f64;
            let jumps =
                if sf >= 170.0 { 0.006 } else { 0.0 } + if sf >= 196.0 { 0.02 } else { 0.0 };
            let noise = 2e-4 * (((i * 7919) % 17) as f64 / 8.0 - 1.0);
            prep.obs.push(Observation {
                x: Inputs::new(&[sf]),
                y: 0.1 - 4e-4 * (sf - 190.0) + jumps + noise,
            });
            prep.subject.push(i % 3);
            prep.weights.push(1.0);
        }
        prep.subjects = (0..3).map(|s| format!("s{s}")).collect();
        prep
    }

    #[test]
    fn the_warm_started_partition_search_finds_the_global_minimum_from_a_local_one() {
        let published = RunTflightSf::published();
        let rel: &dyn Relation = &published;
        let prep = two_jumps();
        let form = rel.sorted_profile().expect("sorted form");
        let sr = SortedRows::new(form, &prep, true);
        let keys = sr.distinct_keys(&[true; 3]);
        // k2 held beyond the data (no plateau): only k1 is searched.
        let mut free = vec![true; 9];
        free[8] = false;
        let lay = Layout::new(rel, free, 3);
        let pr = all_rows(rel, &lay, &sr, &keys);
        let d = pr.discrete(7).expect("k1 is discrete");
        let mut p = published.coefficients().to_vec();
        p[8] = 250.0;
        let (lo, hi) = (keys[4], keys[keys.len() - 5]);
        let (j0, j1) = d.candidates(lo, hi).expect("partitions");
        // Every partition's residual sum of squares.
        let rss: Vec<f64> = (j0..=j1).map(|j| d.rss(&p, j)).collect();
        let global = j0
            + (0..rss.len())
                .min_by(|&a, &b| rss[a].total_cmp(&rss[b]))
                .expect("some");
        assert!(
            (d.value(global) - 196.0).abs() < 0.5,
            "global minimum at {}",
            d.value(global)
        );
        // A naive warm start (descend to the better neighbour while there is one) from the
        // partition at the small jump stops there: a local minimum, not the global one.
        let mut j = d.keys.partition_point(|&k| k < 170.0);
        loop {
            let r = |j: usize| rss[j - j0];
            let next = [j.saturating_sub(1).max(j0), (j + 1).min(j1)]
                .into_iter()
                .filter(|&k| r(k) < r(j))
                .min_by(|&a, &b| r(a).total_cmp(&r(b)));
            match next {
                Some(k) => j = k,
                None => break,
            }
        }
        assert!(
            (d.value(j) - 170.0).abs() < 0.5,
            "naive descent stops at {}",
            d.value(j)
        );
        assert!(rss[j - j0] > rss[global - j0] * (1.0 + 1e-6));
        // The branch and bound, warm-started at the local minimum (or anywhere else), finds the
        // global one.
        for start in [170.0, d.value(j0), d.value(j1), 196.0, 183.3, f64::NAN] {
            let mut q = p.clone();
            q[7] = start;
            let mut notes = Vec::new();
            let t = d.minimise(&q, lo, hi, &mut notes).expect("a partition");
            assert_eq!(t.to_bits(), d.value(global).to_bits(), "start {start}");
            assert!(notes.is_empty());
        }
    }

    /// The continuous variant's k1 (k2 beyond the data) and k2 (k1 held) on [`two_jumps`]: the
    /// bounded grid search returns the plain scan's result bit for bit from any warm start, its
    /// window bounds never exceed the profile inside the window, and it evaluates fewer points.
    #[test]
    fn the_bounded_scan_of_a_continuous_knot_is_the_plain_scan_bit_for_bit() {
        use crate::fit::nonlinear::minimize_1d_grid;
        use std::cell::Cell;
        let continuous = RunTflightSf::published_continuous();
        let rel: &dyn Relation = &continuous;
        let prep = two_jumps();
        let form = rel.sorted_profile().expect("sorted form");
        let sr = SortedRows::new(form, &prep, true);
        let keys = sr.distinct_keys(&[true; 3]);
        let lay = Layout::new(rel, vec![true; 9], 3);
        let pr = all_rows(rel, &lay, &sr, &keys);
        let n = keys.len();
        let mut p = continuous.coefficients().to_vec();
        // (breakpoint, the other knot, search range)
        let cases = [
            (7, 250.0, (keys[4], keys[n - 5])),
            (8, 160.0, (keys[n / 8], keys[n - 4])),
        ];
        let mut irregular = 0;
        for (i, other, (lo, hi)) in cases {
            // The other knot: k2 for k1's profile, k1 for k2's.
            p[if i == 7 { 8 } else { 7 }] = other;
            assert!(pr.bounds(i));
            let yty = pr.yty(&p);
            let xs = minimize_1d_grid(lo, hi);
            let f: Vec<f64> = xs.iter().map(|&t| pr.rss_at(&p, i, t)).collect();
            let first = (0..f.len())
                .min_by(|&a, &b| f[a].total_cmp(&f[b]))
                .expect("grid");
            // The bounds hold inside every window of 1, 2, 5 and 16 cells.
            for w in [1, 2, 5, 16] {
                for a in (0..xs.len() - w).step_by(3) {
                    let lb = pr.window_bound(&p, i, xs[a], xs[a + w], yty);
                    for q in 0..=16 {
                        let t = xs[a] + (xs[a + w] - xs[a]) * q as f64 / 16.0;
                        let r = pr.rss_at(&p, i, t);
                        assert!(lb <= r, "k{}: window {a}+{w}, t {t}: {lb} > {r}", i - 6);
                    }
                }
            }
            // Grid local minima other than the first minimum: a descent to the better neighbour
            // from one of them would stop there.
            let local: Vec<usize> = (1..f.len() - 1)
                .filter(|&k| k != first && f[k - 1] > f[k] && f[k + 1] >= f[k])
                .collect();
            irregular += local.len();
            let tol = (hi - lo) * 1e-7;
            let plain_evals = Cell::new(0usize);
            let plain = minimize_1d(
                |t| {
                    plain_evals.set(plain_evals.get() + 1);
                    pr.rss_at(&p, i, t)
                },
                lo,
                hi,
                tol,
            )
            .expect("scan");
            let starts =
                local
                    .iter()
                    .map(|&k| xs[k])
                    .chain([lo, hi, xs[first], 0.5 * (lo + hi), f64::NAN]);
            for warm in starts {
                let evals = Cell::new(0usize);
                let g = |t| {
                    evals.set(evals.get() + 1);
                    pr.rss_at(&p, i, t)
                };
                let lower = |a, b| pr.window_bound(&p, i, a, b, yty);
                let bounded = minimize_1d_bounded(g, lower, warm, lo, hi, tol).expect("bounded");
                assert_eq!(
                    bounded.0.to_bits(),
                    plain.0.to_bits(),
                    "k{}, warm {warm}",
                    i - 6
                );
                assert_eq!(
                    bounded.1.to_bits(),
                    plain.1.to_bits(),
                    "k{}, warm {warm}",
                    i - 6
                );
                assert!(
                    evals.get() < plain_evals.get(),
                    "k{}: nothing pruned",
                    i - 6
                );
            }
        }
        assert!(
            irregular > 0,
            "no local minimum besides the first: not a test of the bound"
        );
    }
}
