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
//!   ([`minimize_1d`]), on all rows.
//! - A *discrete* breakpoint ([`SortedProfile::discrete_breakpoint`]: the model depends on it
//!   only through which rows fall on each side, e.g. the knot between the flight-time paper's
//!   free pieces) has a step-function profile: any value between two adjacent distinct keys
//!   gives the same fit. It is minimised **exactly** over those partitions by branch and bound:
//!   fitting the rows of a key range's complement gives a lower bound for every partition inside
//!   the range (fewer rows never fit worse), so ranges whose bound exceeds the best partition
//!   found are discarded and the rest bisected. The estimate is the midpoint of the optimal gap,
//!   and its interval ends are data keys (where the partition changes).
//! - Two breakpoints are profiled by coordinate descent.
use super::Prepared;
use crate::fit::design::{solve_rows, Layout, SubjectSums, Totals};
use crate::fit::forms::{
    FeatureSums, Fitting, KeyRange, KeyScale, KeySums, SortedProfile, MAX_PROFILE_FEATURES,
};
use crate::fit::nonlinear::minimize_1d;
use crate::fit::prec::MIN1D_GRID;
use crate::fit::record::BreakpointRecord;
use crate::fit::FitError;
use crate::relations::{Observation, ParamKind, Relation};
use nalgebra::DVector;
use std::cmp::Reverse;
use std::collections::BinaryHeap;
use std::sync::OnceLock;

mod folds;
pub(super) use folds::{FoldEngine, FoldKeys};

/// Evaluations after which the exact search of a discrete breakpoint stops and keeps the best
/// partition found (with a note): reached only by a profile that is flat over a great many
/// partitions (no knot in the data).
pub const DISCRETE_MAX_EVALS: usize = 20_000;

/// Rows per leaf of a [`Tree`]: leaves partly inside a queried interval are summed row by row.
const LEAF: usize = 8;

/// Rows sorted by key under a binary tree of feature sums: each node holds the weighted sums of
/// its rows' features about the centre of its keys, so an interval's sums are O(log n) node
/// sums, each shifted over a distance within the interval (no cancellation), plus at most
/// 2·[`LEAF`] rows.
struct Tree {
    keys: Vec<f64>,
    /// Index of each row in the prepared rows, in key order.
    rows: Vec<u32>,
    /// Leaves, a power of two.
    size: usize,
    /// The node sums. Those of the subjects' trees are built with the index; the tree over all
    /// rows is built on first use (fits with a per-subject column never query it).
    nodes: OnceLock<Nodes>,
}

/// The nodes of a [`Tree`].
struct Nodes {
    /// Per node: lowest and highest key (`+∞, −∞` when empty).
    span: Vec<(f64, f64)>,
    /// Per node: `k` sums about the node's centre.
    sums: Vec<f64>,
}

/// What the trees' sums are made of: the relation's sorted form, the key scale, the number of
/// features and the rows in key order (trees index them through [`Tree::rows`]).
struct Ctx<'a> {
    form: &'a dyn SortedProfile,
    scale: KeyScale,
    k: usize,
    data: Vec<Row>,
}

/// A prepared row with its weight.
#[derive(Clone, Copy)]
struct Row {
    obs: Observation,
    weight: f64,
}

impl Ctx<'_> {
    /// Adds `mult` × row `i`'s weighted features about `centre` to `out`.
    #[inline]
    fn add_row(&self, i: usize, centre: f64, mult: f64, out: &mut [f64]) {
        let mut f = [0.0; MAX_PROFILE_FEATURES];
        self.form
            .features(&self.scale, centre, &self.data[i].obs, &mut f[..self.k]);
        let m = mult * self.data[i].weight;
        out.iter_mut()
            .zip(&f[..self.k])
            .for_each(|(s, f)| *s += m * f);
    }
}

impl Tree {
    /// A tree over rows `rows` (key order) with keys `keys`, its nodes not built yet.
    fn index(keys: Vec<f64>, rows: Vec<u32>) -> Tree {
        let leaves = keys.len().div_ceil(LEAF).max(1);
        Tree {
            keys,
            rows,
            size: leaves.next_power_of_two(),
            nodes: OnceLock::new(),
        }
    }

    /// Nodes with zero sums and the leaves' key spans set.
    fn empty_nodes(&self, k: usize) -> Nodes {
        let n = self.keys.len();
        let mut span = vec![(f64::INFINITY, f64::NEG_INFINITY); 2 * self.size];
        for l in 0..n.div_ceil(LEAF) {
            let (a, b) = (l * LEAF, ((l + 1) * LEAF).min(n));
            span[self.size + l] = (self.keys[a], self.keys[b - 1]);
        }
        Nodes {
            span,
            sums: vec![0.0; 2 * self.size * k],
        }
    }

    /// The centre of a node's keys.
    #[inline]
    fn centre(span: (f64, f64)) -> f64 {
        0.5 * (span.0 + span.1)
    }

    /// Sums the inner nodes from the leaves.
    fn finish(&self, ctx: &Ctx, nodes: &mut Nodes) {
        let k = ctx.k;
        let Nodes { span, sums } = nodes;
        for i in (1..self.size).rev() {
            let (l, r) = (span[2 * i], span[2 * i + 1]);
            let sp = (l.0.min(r.0), l.1.max(r.1));
            span[i] = sp;
            if sp.0 > sp.1 {
                continue;
            }
            let c = Tree::centre(sp);
            let mut acc = [0.0; MAX_PROFILE_FEATURES];
            for child in [2 * i, 2 * i + 1] {
                let (lo, hi) = span[child];
                if lo > hi {
                    continue;
                }
                let mut t = [0.0; MAX_PROFILE_FEATURES];
                t[..k].copy_from_slice(&sums[child * k..(child + 1) * k]);
                ctx.form
                    .shift(&ctx.scale, &mut t, Tree::centre((lo, hi)), c);
                acc.iter_mut().zip(&t).for_each(|(a, t)| *a += t);
            }
            sums[i * k..(i + 1) * k].copy_from_slice(&acc[..k]);
        }
    }

    /// Builds the nodes with one pass over the tree's rows.
    fn build(&self, ctx: &Ctx) -> Nodes {
        let k = ctx.k;
        let mut nodes = self.empty_nodes(k);
        for (j, &i) in self.rows.iter().enumerate() {
            let node = self.size + j / LEAF;
            let c = Tree::centre(nodes.span[node]);
            ctx.add_row(
                i as usize,
                c,
                1.0,
                &mut nodes.sums[node * k..(node + 1) * k],
            );
        }
        self.finish(ctx, &mut nodes);
        nodes
    }

    /// The nodes, built on first use.
    fn nodes(&self, ctx: &Ctx) -> &Nodes {
        self.nodes.get_or_init(|| self.build(ctx))
    }

    /// First row whose key is `≥ t` (`> t` unless `inclusive`).
    #[inline]
    fn lower(&self, t: f64, inclusive: bool) -> usize {
        if inclusive {
            self.keys.partition_point(|&x| x < t)
        } else {
            self.keys.partition_point(|&x| x <= t)
        }
    }
    /// One past the last row whose key is `≤ t` (`< t` unless `inclusive`).
    #[inline]
    fn upper(&self, t: f64, inclusive: bool) -> usize {
        if inclusive {
            self.keys.partition_point(|&x| x <= t)
        } else {
            self.keys.partition_point(|&x| x < t)
        }
    }

    /// Adds `mult` × the sums of rows `a..b` about `centre` to `out`.
    fn add_span(
        &self,
        ctx: &Ctx,
        a: usize,
        b: usize,
        centre: f64,
        mult: f64,
        out: &mut FeatureSums,
    ) {
        if a >= b {
            return;
        }
        let k = ctx.k;
        let rows = |a: usize, b: usize, out: &mut FeatureSums| {
            for &i in &self.rows[a..b] {
                ctx.add_row(i as usize, centre, mult, &mut out[..]);
            }
        };
        let (fa, fb) = (a.div_ceil(LEAF), b / LEAF);
        if fa >= fb {
            rows(a, b, out);
            return;
        }
        rows(a, fa * LEAF, out);
        rows(fb * LEAF, b, out);
        let nodes = self.nodes(ctx);
        let node = |i: usize, out: &mut FeatureSums| {
            let (lo, hi) = nodes.span[i];
            if lo > hi {
                return;
            }
            let mut t = [0.0; MAX_PROFILE_FEATURES];
            t[..k].copy_from_slice(&nodes.sums[i * k..(i + 1) * k]);
            ctx.form
                .shift(&ctx.scale, &mut t, Tree::centre((lo, hi)), centre);
            out.iter_mut()
                .zip(&t[..k])
                .for_each(|(s, t)| *s += mult * t);
        };
        let (mut l, mut r) = (fa + self.size, fb + self.size);
        while l < r {
            if l & 1 == 1 {
                node(l, out);
                l += 1;
            }
            if r & 1 == 1 {
                r -= 1;
                node(r, out);
            }
            l /= 2;
            r /= 2;
        }
    }
}

/// The rows of a fit sorted by the relation's breakpoint key: one tree over all rows and one per
/// subject (folds subtract a subject from the whole; bootstrap replicates add subjects).
pub(super) struct SortedRows<'a> {
    /// The relation's sorted form, the key scale (features are powers of
    /// (key − c)/half_width) and the prepared rows.
    ctx: Ctx<'a>,
    all: Tree,
    /// Subject of each row of `all`, in key order.
    key_subject: Vec<u32>,
    subj: Vec<Tree>,
}

/// A key mapped to an integer of the same order as `f64::total_cmp` (for a fast sort).
#[inline]
fn ordered_bits(x: f64) -> u64 {
    let b = x.to_bits();
    if b >> 63 == 1 {
        !b
    } else {
        b | (1 << 63)
    }
}

/// The inverse of [`ordered_bits`].
#[inline]
fn from_ordered_bits(b: u64) -> f64 {
    f64::from_bits(if b >> 63 == 1 { b & !(1 << 63) } else { !b })
}

/// Sorts `v` ascending. Below a few thousand items by comparison; above, by a stable
/// least-significant-digit radix sort on the high 64 bits (11-bit digits; digits that all items
/// share are skipped), which gives the same order when the low 64 bits ascend with the position
/// (`SortedRows::new`: the row index, unique): ties in the high bits keep that order.
fn sort_by_high_bits(v: &mut Vec<u128>) {
    const BITS: usize = 11;
    const PASSES: usize = 64_usize.div_ceil(BITS);
    const RADIX: usize = 1 << BITS;
    let n = v.len();
    if n < 4096 {
        v.sort_unstable();
        return;
    }
    let digit = |x: u128, p: usize| (((x >> 64) as u64 >> (p * BITS)) as usize) & (RADIX - 1);
    let mut hist = vec![[0usize; RADIX]; PASSES];
    for &x in v.iter() {
        for (p, h) in hist.iter_mut().enumerate() {
            h[digit(x, p)] += 1;
        }
    }
    let mut buf = vec![0u128; n];
    let mut in_buf = false;
    for (p, h) in hist.iter().enumerate() {
        if h.contains(&n) {
            continue;
        }
        let mut off = [0usize; RADIX];
        let mut acc = 0;
        for (o, &c) in off.iter_mut().zip(h) {
            *o = acc;
            acc += c;
        }
        let (src, dst) = if in_buf {
            (&buf[..], &mut v[..])
        } else {
            (&v[..], &mut buf[..])
        };
        for &x in src {
            let d = digit(x, p);
            dst[off[d]] = x;
            off[d] += 1;
        }
        in_buf = !in_buf;
    }
    if in_buf {
        std::mem::swap(v, &mut buf);
    }
}

impl<'a> SortedRows<'a> {
    /// Sorts the prepared rows by key and builds the subjects' trees, and the tree over all
    /// rows when `with_all` (otherwise on first use).
    pub fn new(form: &'a dyn SortedProfile, prep: &Prepared, with_all: bool) -> SortedRows<'a> {
        // Ties by row index: the order (and so every rounding) is deterministic.
        let mut order: Vec<u128> = prep
            .obs
            .iter()
            .enumerate()
            .zip(&prep.subject)
            .map(|((i, o), &s)| {
                // key | row | subject: the subject rides along (one random read less below).
                ((ordered_bits(form.key(&o.x)) as u128) << 64) | ((i as u128) << 32) | s as u128
            })
            .collect();
        sort_by_high_bits(&mut order);
        let n = order.len();
        let key_of = |v: u128| from_ordered_bits((v >> 64) as u64);
        let scale = match (order.first(), order.last()) {
            (Some(&a), Some(&b)) => KeyScale::of_range(key_of(a), key_of(b)),
            _ => KeyScale::of_range(0.0, 0.0),
        };
        let k = form.n_features().min(MAX_PROFILE_FEATURES);
        let ns = prep.subjects.len();
        let mut count = vec![0usize; ns];
        for &s in &prep.subject {
            count[s] += 1;
        }
        let mut per_keys: Vec<Vec<f64>> = count.iter().map(|&c| Vec::with_capacity(c)).collect();
        let mut per_rows: Vec<Vec<u32>> = count.iter().map(|&c| Vec::with_capacity(c)).collect();
        let mut keys = Vec::with_capacity(n);
        let mut rows = Vec::with_capacity(n);
        let mut key_subject = Vec::with_capacity(n);
        // One gather of the rows into key order (a tight loop: many reads in flight), after
        // which every tree reads them sequentially.
        let data: Vec<Row> = order
            .iter()
            .map(|&v| {
                let i = ((v >> 32) as u32) as usize;
                Row {
                    obs: prep.obs[i],
                    weight: prep.weights[i],
                }
            })
            .collect();
        for (j, &v) in order.iter().enumerate() {
            let key = key_of(v);
            let s = (v as u32) as usize;
            per_keys[s].push(key);
            per_rows[s].push(j as u32);
            keys.push(key);
            rows.push(j as u32);
            key_subject.push(s as u32);
        }
        drop(order);
        let ctx = Ctx {
            form,
            scale,
            k,
            data,
        };
        let all = Tree::index(keys, rows);
        let subj: Vec<Tree> = per_keys
            .into_iter()
            .zip(per_rows)
            .map(|(kk, rr)| Tree::index(kk, rr))
            .collect();
        // The leaves of every tree in one pass in key order: each row is read once (a random
        // read of the prepared rows) for its leaf in the tree over all rows and in its subject's.
        let mut all_nodes = with_all.then(|| all.empty_nodes(k));
        let mut subj_nodes: Vec<Nodes> = subj.iter().map(|t| t.empty_nodes(k)).collect();
        let mut pos = vec![0usize; ns];
        for (j, (&i, &s)) in all.rows.iter().zip(&key_subject).enumerate() {
            let (i, s) = (i as usize, s as usize);
            if let Some(nd) = &mut all_nodes {
                let node = all.size + j / LEAF;
                let c = Tree::centre(nd.span[node]);
                ctx.add_row(i, c, 1.0, &mut nd.sums[node * k..(node + 1) * k]);
            }
            let nd = &mut subj_nodes[s];
            let node = subj[s].size + pos[s] / LEAF;
            pos[s] += 1;
            let c = Tree::centre(nd.span[node]);
            ctx.add_row(i, c, 1.0, &mut nd.sums[node * k..(node + 1) * k]);
        }
        if let Some(mut nd) = all_nodes {
            all.finish(&ctx, &mut nd);
            let _ = all.nodes.set(nd);
        }
        for (t, mut nd) in subj.iter().zip(subj_nodes) {
            t.finish(&ctx, &mut nd);
            let _ = t.nodes.set(nd);
        }
        SortedRows {
            ctx,
            all,
            key_subject,
            subj,
        }
    }

    /// The relation's sorted form.
    pub fn form(&self) -> &'a dyn SortedProfile {
        self.ctx.form
    }

    /// The distinct keys of the rows of the subjects with `include[s]`, ascending.
    pub fn distinct_keys(&self, include: &[bool]) -> Vec<f64> {
        let mut out: Vec<f64> = Vec::with_capacity(self.all.keys.len());
        // NaN: the first key is always new (as `out.last() != Some(&k)` had it).
        let mut last = f64::NAN;
        for (&k, &s) in self.all.keys.iter().zip(&self.key_subject) {
            if include[s as usize] && k != last {
                out.push(k);
                last = k;
            }
        }
        out
    }
}

/// Which subjects' rows an evaluation uses.
#[derive(Clone, Copy)]
pub(super) enum Members<'b> {
    /// All of them.
    All,
    /// All but one (a leave-one-subject-out fold).
    AllBut(usize),
    /// A multiset `(subject, multiplicity)` (a bootstrap replicate), in column order.
    List(&'b [(usize, f64)]),
}

impl Members<'_> {
    /// The subjects with their multiplicities, in column order (`n` subjects in all).
    fn list(&self, n: usize) -> Vec<(usize, f64)> {
        match *self {
            Members::All => (0..n).map(|s| (s, 1.0)).collect(),
            Members::AllBut(x) => (0..n).filter(|&s| s != x).map(|s| (s, 1.0)).collect(),
            Members::List(l) => l.to_vec(),
        }
    }
}

/// [`KeySums`] over some subjects' rows, optionally without those with key in `[c1, c2)`.
struct Query<'b> {
    sr: &'b SortedRows<'b>,
    members: Members<'b>,
    remove: Option<(f64, f64)>,
}

impl Query<'_> {
    fn add(&self, tree: &Tree, r: KeyRange, centre: f64, mult: f64, out: &mut FeatureSums) {
        let sr = self.sr;
        let a = tree.lower(r.lo, r.lo_inclusive);
        let b = tree.upper(r.hi, r.hi_inclusive);
        let span = |a, b, out: &mut FeatureSums| tree.add_span(&sr.ctx, a, b, centre, mult, out);
        match self.remove {
            None => span(a, b, out),
            Some((c1, c2)) => {
                span(a, b.min(tree.lower(c1, true)), out);
                span(a.max(tree.lower(c2, true)), b, out);
            }
        }
    }
}

impl KeySums for Query<'_> {
    fn range(&self, r: KeyRange, centre: f64) -> FeatureSums {
        let mut out = [0.0; MAX_PROFILE_FEATURES];
        match self.members {
            Members::All => self.add(&self.sr.all, r, centre, 1.0, &mut out),
            Members::AllBut(s) => {
                self.add(&self.sr.all, r, centre, 1.0, &mut out);
                self.add(&self.sr.subj[s], r, centre, -1.0, &mut out);
            }
            Members::List(l) => {
                for &(s, m) in l {
                    self.add(&self.sr.subj[s], r, centre, m, &mut out);
                }
            }
        }
        out
    }
}

/// The normal-equation solve of some subjects' rows from the trees (optionally without the rows
/// whose key lies in `remove = [c1, c2)`): the same numbers as a pass over those rows, to
/// rounding.
fn solve_sorted(
    sr: &SortedRows,
    lay: &Layout,
    p: &[f64],
    members: Members,
    remove: Option<(f64, f64)>,
) -> Option<(DVector<f64>, f64)> {
    match lay.subj_col {
        // A per-subject column: each subject's normal equations, that column absorbed, summed.
        Some(_) => {
            let mut t = Totals::zeros(lay.m());
            for (s, mult) in members.list(sr.subj.len()) {
                let one = [(s, 1.0)];
                let q = Query {
                    sr,
                    members: Members::List(&one),
                    remove,
                };
                let ne = sr
                    .ctx
                    .form
                    .normal_equations(p, &lay.free, &sr.ctx.scale, &q);
                if ne.nb != lay.nb {
                    return None;
                }
                t.add(&SubjectSums::absorb(&ne, lay.subj_col)?, mult);
            }
            t.solve(lay)
        }
        None => {
            let q = Query {
                sr,
                members,
                remove,
            };
            let ne = sr
                .ctx
                .form
                .normal_equations(p, &lay.free, &sr.ctx.scale, &q);
            if ne.nb != lay.nb {
                return None;
            }
            let mut t = Totals::zeros(lay.m());
            t.add(&SubjectSums::absorb(&ne, None)?, 1.0);
            t.solve(lay)
        }
    }
}

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
        keys: &'b [f64],
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
    keys: &'b [f64],
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
        0.5 * (self.keys[j - 1] + self.keys[j])
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
            Some((self.keys[a], self.keys[b])),
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

    /// The exact minimum over the partitions in `[lo, hi]` (branch and bound), as a value.
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
        let cells = MIN1D_GRID.min(j1 - j0).max(1);
        let mut grid: Vec<usize> = (0..=cells).map(|c| j0 + (j1 - j0) * c / cells).collect();
        grid.dedup();
        for &j in &grid {
            visit(j, &mut best, &mut evals);
        }
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
        for w in grid.windows(2) {
            if w[1] > w[0] + 1 {
                push(w[0] + 1, w[1] - 1, &mut heap, &mut best, &mut evals);
            }
        }
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
                    self.pr.rel.parameters()[self.i].name
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
                (a > j0).then(|| self.keys[a - 1]),
                (b < j1).then(|| self.keys[b]),
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
        .filter(|&i| pr.lay.free[i] && rel.parameters()[i].kind == ParamKind::Breakpoint)
        .collect();
    let mut p = p0.to_vec();
    let max_rounds = if bps.len() > 1 { 4 } else { 1 };
    for _ in 0..max_rounds {
        let mut moved = 0.0f64;
        for &i in &bps {
            let Some((lo, hi)) = search[i] else { continue };
            let t = match pr.discrete(i) {
                Some(d) => d
                    .minimise(&p, lo, hi, notes)
                    .ok_or_else(|| FitError::Optimizer {
                        relation: rel.id().into(),
                        message: format!(
                            "no partition of the rows by {} in [{lo}, {hi}] can be fitted",
                            rel.parameters()[i].name
                        ),
                    })?,
                None => {
                    let tol = (hi - lo).abs() * 1e-7;
                    minimize_1d(|t| pr.rss_at(&p, i, t), lo, hi, tol)?.0
                }
            };
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

/// The 95 % confidence set of breakpoint `i` (the others held at `p`): the values where the
/// profile RSS ≤ `thr` = RSS_min·(1 + F(1, df; 0.95)/df), over every admissible partition of
/// the rows (discrete breakpoints) or a [`PROFILE_GRID`] grid over the whole search range.
pub(super) fn confidence_set(
    pr: &Profiler,
    p: &[f64],
    i: usize,
    search: &[Option<(f64, f64)>],
    thr: f64,
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
    let mut ts: Vec<f64> = (0..=cells)
        .map(|c| lo + (hi - lo) * c as f64 / cells as f64)
        .collect();
    if p[i] > lo && p[i] < hi {
        ts.push(p[i]);
        ts.sort_by(f64::total_cmp);
        ts.dedup();
    }
    let r: Vec<f64> = ts.iter().map(|&t| rss(t)).collect();
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

/// Refits everything (breakpoints included) on a subset: the global coefficient vector, or
/// `None` if the subset cannot be fitted.
pub(super) fn refit(
    rel: &dyn Relation,
    free: &[bool],
    p_start: &[f64],
    subset: Subset,
) -> Option<Vec<f64>> {
    let (plan, n_subj, map, keys);
    match subset {
        Subset::Rows(prep, rows) => {
            let (m, n) = dense_subjects(prep, rows);
            let sub_obs: Vec<Observation> = rows.iter().map(|&i| prep.obs[i]).collect();
            plan = rel.plan(&sub_obs);
            (n_subj, map, keys) = (n, m, Vec::new());
        }
        Subset::Subjects(sr, members) => {
            let list = members.list(sr.subj.len());
            let mut include = vec![false; sr.subj.len()];
            for &(s, _) in &list {
                include[s] = true;
            }
            keys = sr.distinct_keys(&include);
            plan = sr.ctx.form.plan_sorted(&keys);
            (n_subj, map) = (list.len(), Vec::new());
        }
        Subset::Fold(sr, fk, _, s) => {
            keys = fk.without(s);
            plan = sr.ctx.form.plan_sorted(&keys);
            (n_subj, map) = (sr.subj.len() - 1, Vec::new());
        }
    }
    let mut free = free.to_vec();
    let mut search = plan.search.clone();
    for i in 0..free.len() {
        if rel.parameters()[i].kind == ParamKind::Breakpoint && (!free[i] || search[i].is_none()) {
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
        Subset::Subjects(sr, members) => Source::Sorted {
            sr,
            members,
            keys: &keys,
        },
        Subset::Fold(sr, _, engine, s) => {
            match engine.filter(|e| e.applies(&lay, p_start, &search)) {
                Some(engine) => Source::Fold { engine, s },
                None => Source::Sorted {
                    sr,
                    members: Members::AllBut(s),
                    keys: &keys,
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
    use crate::relations::{Relation, RunTflightSf};

    #[test]
    fn radix_sort_orders_like_a_comparison_sort() {
        // Many ties in the high bits (keys from a small set) and negative keys; the low bits
        // ascend with the position, as `SortedRows::new` builds them.
        let mut state = 0x9e37_79b9_7f4a_7c15u64;
        let mut next = || {
            state ^= state << 13;
            state ^= state >> 7;
            state ^= state << 17;
            state
        };
        for n in [10usize, 5000, 70_000] {
            let v: Vec<u128> = (0..n)
                .map(|i| {
                    let key = match next() % 3 {
                        0 => ((next() % 50) as f64) * 0.5 - 3.0,
                        1 => 150.0 + (next() % 1_000_000) as f64 * 1e-4,
                        _ => f64::from_bits(next() >> 2),
                    };
                    ((ordered_bits(key) as u128) << 64) | ((i as u128) << 32) | (next() % 7) as u128
                })
                .collect();
            let mut a = v.clone();
            a.sort_unstable();
            let mut b = v;
            sort_by_high_bits(&mut b);
            assert!(a == b, "n = {n}");
        }
    }

    #[test]
    fn the_lazy_tree_over_all_rows_equals_the_eager_one() {
        let rel = RunTflightSf::published();
        let form = (&rel as &dyn Relation)
            .sorted_profile()
            .expect("sorted form");
        let mut prep = Prepared::default();
        for i in 0..3000usize {
            let sf = 150.0 + ((i * 7919) % 1000) as f64 * 0.1;
            prep.obs.push(Observation {
                x: [sf, 0.0, 0.0, 0.0],
                y: 0.1 + 1e-4 * (sf - 200.0) + 1e-3 * ((i % 13) as f64 - 6.0),
            });
            prep.subject.push(i % 4);
            prep.weights.push(1.0 + (i % 3) as f64);
        }
        prep.subjects = (0..4).map(|s| format!("s{s}")).collect();
        let eager = SortedRows::new(form, &prep, true);
        let lazy = SortedRows::new(form, &prep, false);
        assert!(lazy.all.nodes.get().is_none());
        for (lo, hi) in [
            (140.0, 260.0),
            (170.3, 181.05),
            (199.95, 200.0),
            (230.0, 231.0),
        ] {
            for members in [Members::All, Members::AllBut(2)] {
                let r = KeyRange::closed(lo, hi);
                let q = |sr| Query {
                    sr,
                    members,
                    remove: None,
                };
                let (a, b) = (q(&eager).range(r, lo), q(&lazy).range(r, lo));
                assert!(a == b, "[{lo}, {hi}]");
            }
        }
        assert!(lazy.all.nodes.get().is_some());
    }

    #[test]
    fn ordered_bits_sort_like_total_cmp_and_invert() {
        let xs = [
            f64::NEG_INFINITY,
            -1e300,
            -2.5,
            -f64::MIN_POSITIVE,
            -0.0,
            0.0,
            f64::MIN_POSITIVE,
            1.0,
            1.0 + f64::EPSILON,
            283.25,
            1e300,
            f64::INFINITY,
        ];
        for a in xs {
            assert_eq!(from_ordered_bits(ordered_bits(a)).to_bits(), a.to_bits());
            for b in xs {
                assert_eq!(
                    ordered_bits(a).cmp(&ordered_bits(b)),
                    a.total_cmp(&b),
                    "{a} {b}"
                );
            }
        }
    }
}
