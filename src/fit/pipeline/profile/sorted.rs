//! Rows sorted by a relation's breakpoint key under binary trees of feature sums (one over all
//! rows, one per subject), and the normal-equation solve of any subjects' rows from them: what
//! every profile evaluation, fold and bootstrap replicate of module `profile` is built on (see
//! its docs, "Sorted prefix sums").
use super::super::Prepared;
use crate::fit::design::{Layout, SubjectSums, Totals};
use crate::fit::forms::{
    FeatureSums, KeyRange, KeyScale, KeySums, SortedProfile, MAX_PROFILE_FEATURES,
};
use crate::relations::Observation;
use nalgebra::DVector;
use std::cell::RefCell;
use std::collections::HashMap;
use std::sync::OnceLock;

/// Subjects from which an evaluation with a per-subject column sums the subjects in parallel
/// (below, the threads' overhead outweighs the work).
const PAR_SUBJECTS: usize = 64;

/// Rows per leaf of a [`Tree`]: leaves partly inside a queried interval are summed row by row.
const LEAF: usize = 8;

/// Keys per block of a [`Tree`]'s search index: a search finds its block among every
/// `BLOCK`-th key (a short array that stays in cache), then its position inside the block.
const BLOCK: usize = 64;

/// Rows sorted by key under a binary tree of feature sums: each node holds the weighted sums of
/// its rows' features about the centre of its keys, so an interval's sums are O(log n) node
/// sums, each shifted over a distance within the interval (no cancellation), plus at most
/// 2·[`LEAF`] rows.
pub(super) struct Tree {
    pub(super) keys: Vec<f64>,
    /// Every [`BLOCK`]-th key (`keys[0]`, `keys[BLOCK]`, …): the first level of a search.
    sample: Vec<f64>,
    /// Index of each row in the prepared rows, in key order.
    pub(super) rows: Vec<u32>,
    /// Leaves, a power of two.
    pub(super) size: usize,
    /// The node sums. Those of the subjects' trees are built with the index; the tree over all
    /// rows is built on first use (fits with a per-subject column never query it).
    pub(super) nodes: OnceLock<Nodes>,
}

/// The nodes of a [`Tree`].
pub(super) struct Nodes {
    /// Per node: lowest and highest key (`+∞, −∞` when empty).
    span: Vec<(f64, f64)>,
    /// Per node: `k` sums about the node's centre.
    sums: Vec<f64>,
}

/// What the trees' sums are made of: the relation's sorted form, the key scale, the number of
/// features and the rows in key order (trees index them through [`Tree::rows`]).
pub(super) struct Ctx<'a> {
    pub(super) form: &'a dyn SortedProfile,
    pub(super) scale: KeyScale,
    pub(super) k: usize,
    pub(super) data: Vec<Row>,
}

/// A prepared row with its weight.
#[derive(Clone, Copy)]
pub(super) struct Row {
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
            sample: keys.iter().step_by(BLOCK).copied().collect(),
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

    /// `self.keys.partition_point(pred)` for a predicate true on a prefix of the keys, in two
    /// levels: the block among the sampled keys, then the position inside the block (the same
    /// index, with a few cache misses instead of one per halving).
    #[inline]
    fn partition_point(&self, pred: impl Fn(&f64) -> bool) -> usize {
        // Samples 0..b satisfy `pred`: the first key that does not lies in
        // ((b − 1)·BLOCK, b·BLOCK] (key b·BLOCK, when it exists, does not).
        let b = self.sample.partition_point(&pred);
        let start = (b.max(1) - 1) * BLOCK + usize::from(b > 0);
        let end = (b * BLOCK).min(self.keys.len());
        start + self.keys[start..end].partition_point(pred)
    }
    /// First row whose key is `≥ t` (`> t` unless `inclusive`).
    #[inline]
    fn lower(&self, t: f64, inclusive: bool) -> usize {
        if inclusive {
            self.partition_point(|&x| x < t)
        } else {
            self.partition_point(|&x| x <= t)
        }
    }
    /// One past the last row whose key is `≤ t` (`< t` unless `inclusive`).
    #[inline]
    fn upper(&self, t: f64, inclusive: bool) -> usize {
        if inclusive {
            self.partition_point(|&x| x <= t)
        } else {
            self.partition_point(|&x| x < t)
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
pub(in crate::fit::pipeline) struct SortedRows<'a> {
    /// The relation's sorted form, the key scale (features are powers of
    /// (key − c)/half_width) and the prepared rows.
    pub(super) ctx: Ctx<'a>,
    pub(super) all: Tree,
    /// Subject of each row of `all`, in key order.
    pub(super) key_subject: Vec<u32>,
    pub(super) subj: Vec<Tree>,
    /// The tree over all rows' sums at some queries (see [`SortedRows::memoise_all`]).
    all_memo: OnceLock<HashMap<MemoKey, FeatureSums>>,
}

/// Every input of a query of the tree over all rows, bit for bit: range ends, inclusiveness,
/// centre and the removed key interval (if any).
type MemoKey = [u64; 6];

fn memo_key(r: KeyRange, centre: f64, remove: Option<(f64, f64)>) -> MemoKey {
    let flags =
        r.lo_inclusive as u64 | (r.hi_inclusive as u64) << 1 | (remove.is_some() as u64) << 2;
    let (c1, c2) = remove.unwrap_or((0.0, 0.0));
    [
        r.lo.to_bits(),
        r.hi.to_bits(),
        flags,
        centre.to_bits(),
        c1.to_bits(),
        c2.to_bits(),
    ]
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
        // The rows are stored by subject, each subject's in key order: a subject's tree reads
        // its rows (a query's edge rows, its leaves) from one contiguous block, and the prepared
        // rows (grouped by subject as the tables list them) are read almost in order. The tree
        // over all rows reaches them through its index, in key order. Which slot a row occupies
        // changes no sum: every tree adds its rows in its own key order.
        let mut next: Vec<usize> = count
            .iter()
            .scan(0usize, |acc, &c| {
                let start = *acc;
                *acc += c;
                Some(start)
            })
            .collect();
        let mut data: Vec<Row> = vec![
            Row {
                obs: Observation {
                    x: Default::default(),
                    y: 0.0,
                },
                weight: 0.0,
            };
            n
        ];
        for &v in &order {
            let i = ((v >> 32) as u32) as usize;
            let s = (v as u32) as usize;
            let slot = next[s];
            next[s] += 1;
            data[slot] = Row {
                obs: prep.obs[i],
                weight: prep.weights[i],
            };
            let key = key_of(v);
            per_keys[s].push(key);
            per_rows[s].push(slot as u32);
            keys.push(key);
            rows.push(slot as u32);
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
            all_memo: OnceLock::new(),
        }
    }

    /// Memoises the tree over all rows' sums at every query the form's normal equations make at
    /// each of `ps` (free parameters `free`). A later query with the same inputs (bit for bit)
    /// starts from the memoised sums, which are the very numbers its own pass over the tree
    /// would add to zero: results do not change. The leave-one-subject-out folds' first
    /// breakpoint search evaluates the same grid of the same parameters in every fold, each
    /// fold only subtracting its subject's sums, so this shares that grid's whole-tree part.
    /// Only the first call has an effect.
    pub fn memoise_all(&self, ps: &[Vec<f64>], free: &[bool]) {
        use rayon::prelude::*;
        struct Recorder<'q> {
            q: Query<'q>,
            log: RefCell<Vec<(MemoKey, FeatureSums)>>,
        }
        impl KeySums for Recorder<'_> {
            fn range(&self, r: KeyRange, centre: f64) -> FeatureSums {
                let mut out = [0.0; MAX_PROFILE_FEATURES];
                self.q.add(&self.q.sr.all, r, centre, 1.0, &mut out);
                self.log.borrow_mut().push((memo_key(r, centre, None), out));
                out
            }
        }
        let logs: Vec<Vec<(MemoKey, FeatureSums)>> = ps
            .par_iter()
            .map(|p| {
                let rec = Recorder {
                    q: Query {
                        sr: self,
                        members: Members::All,
                        remove: None,
                    },
                    log: RefCell::new(Vec::new()),
                };
                let _ = self
                    .ctx
                    .form
                    .normal_equations(p, free, &self.ctx.scale, &rec);
                rec.log.into_inner()
            })
            .collect();
        let _ = self.all_memo.set(logs.into_iter().flatten().collect());
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
pub(in crate::fit::pipeline) enum Members<'b> {
    /// All of them.
    All,
    /// All but one (a leave-one-subject-out fold).
    AllBut(usize),
    /// A multiset `(subject, multiplicity)` (a bootstrap replicate), in column order.
    List(&'b [(usize, f64)]),
}

impl Members<'_> {
    /// The subjects with their multiplicities, in column order (`n` subjects in all).
    pub(super) fn list(&self, n: usize) -> Vec<(usize, f64)> {
        match *self {
            Members::All => (0..n).map(|s| (s, 1.0)).collect(),
            Members::AllBut(x) => (0..n).filter(|&s| s != x).map(|s| (s, 1.0)).collect(),
            Members::List(l) => l.to_vec(),
        }
    }
}

/// [`KeySums`] over some subjects' rows, optionally without those with key in `[c1, c2)`.
pub(super) struct Query<'b> {
    pub(super) sr: &'b SortedRows<'b>,
    pub(super) members: Members<'b>,
    pub(super) remove: Option<(f64, f64)>,
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

impl Query<'_> {
    /// Adds the tree over all rows' sums over `r` to `out` (zero): from the memo when it holds
    /// this query (the same numbers).
    fn add_all(&self, r: KeyRange, centre: f64, out: &mut FeatureSums) {
        let memo = self.sr.all_memo.get();
        match memo.and_then(|m| m.get(&memo_key(r, centre, self.remove))) {
            Some(v) => *out = *v,
            None => self.add(&self.sr.all, r, centre, 1.0, out),
        }
    }
}

impl KeySums for Query<'_> {
    fn range(&self, r: KeyRange, centre: f64) -> FeatureSums {
        let mut out = [0.0; MAX_PROFILE_FEATURES];
        match self.members {
            Members::All => self.add_all(r, centre, &mut out),
            Members::AllBut(s) => {
                self.add_all(r, centre, &mut out);
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
pub(super) fn solve_sorted(
    sr: &SortedRows,
    lay: &Layout,
    p: &[f64],
    members: Members,
    remove: Option<(f64, f64)>,
) -> Option<(DVector<f64>, f64)> {
    let mut t = Totals::zeros(lay.m());
    match lay.subj_col {
        // A per-subject column: each subject's normal equations, that column absorbed, summed.
        Some(_) => {
            let list = members.list(sr.subj.len());
            let subject = |s: usize| {
                let one = [(s, 1.0)];
                let q = Query {
                    sr,
                    members: Members::List(&one),
                    remove,
                };
                absorbed(&q, p, lay)
            };
            if list.len() >= PAR_SUBJECTS {
                // The subjects' sums in parallel, added in subject order: the same number.
                use rayon::prelude::*;
                let sums: Vec<Option<SubjectSums>> =
                    list.par_iter().map(|&(s, _)| subject(s)).collect();
                for (x, &(_, mult)) in sums.iter().zip(&list) {
                    t.add(x.as_ref()?, mult);
                }
            } else {
                for (s, mult) in list {
                    t.add(&subject(s)?, mult);
                }
            }
        }
        None => {
            let q = Query {
                sr,
                members,
                remove,
            };
            t.add(&absorbed(&q, p, lay)?, 1.0);
        }
    }
    t.solve(lay)
}

/// The normal equations of the rows `q` selects, with the per-subject column (if any) absorbed;
/// `None` when the form's basis does not have the layout's size.
fn absorbed(q: &Query, p: &[f64], lay: &Layout) -> Option<SubjectSums> {
    let ne =
        q.sr.ctx
            .form
            .normal_equations(p, &lay.free, &q.sr.ctx.scale, q);
    if ne.nb != lay.nb {
        return None;
    }
    SubjectSums::absorb(&ne, lay.subj_col)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::fit::forms::Fitting;
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

    /// 3,000 weighted rows of 4 subjects, step frequencies 150–250 steps/min spread over the
    /// knots, flight times linear with a subject-periodic wobble.
    fn four_subject_rows() -> Prepared {
        let mut prep = Prepared::default();
        for i in 0..3000usize {
            let sf = 150.0 + ((i * 7919) % 1000) as f64 * 0.1;
            prep.obs.push(Observation {
                x: crate::relations::Inputs::new(&[sf]),
                y: 0.1 + 1e-4 * (sf - 200.0) + 1e-3 * ((i % 13) as f64 - 6.0),
            });
            prep.subject.push(i % 4);
            prep.weights.push(1.0 + (i % 3) as f64);
        }
        prep.subjects = (0..4).map(|s| format!("s{s}")).collect();
        prep
    }

    #[test]
    fn the_lazy_tree_over_all_rows_equals_the_eager_one() {
        let rel = RunTflightSf::published();
        let form = (&rel as &dyn Relation)
            .sorted_profile()
            .expect("sorted form");
        let prep = four_subject_rows();
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
    fn memoised_whole_tree_sums_give_the_same_fold_solves() {
        let published = RunTflightSf::published();
        let rel: &dyn Relation = &published;
        let form = rel.sorted_profile().expect("sorted form");
        let prep = four_subject_rows();
        let plain = SortedRows::new(form, &prep, true);
        let memo = SortedRows::new(form, &prep, true);
        let free = vec![true; 9];
        let lay = Layout::new(rel, free.clone(), 3);
        let p0 = published.coefficients().to_vec();
        let at = |k2: f64| {
            let mut p = p0.clone();
            p[8] = k2;
            p
        };
        let grid: Vec<Vec<f64>> = [185.0, 190.5, 201.25, 230.0].map(at).to_vec();
        memo.memoise_all(&grid, &free);
        assert!(!memo.all_memo.get().expect("memo").is_empty());
        // Memoised points and others, every fold: the same solves, bit for bit.
        for p in grid.iter().cloned().chain([at(195.0)]) {
            for s in 0..4 {
                let solve = |sr: &SortedRows| solve_sorted(sr, &lay, &p, Members::AllBut(s), None);
                let (a, b) = (solve(&plain).expect("a"), solve(&memo).expect("b"));
                assert!(
                    a.0 == b.0 && a.1.to_bits() == b.1.to_bits(),
                    "{p:?} fold {s}"
                );
            }
        }
    }

    #[test]
    fn the_two_level_search_finds_the_slice_search_position() {
        // Repeated keys across block boundaries, every length around a block's multiples.
        for n in [0usize, 1, 2, 63, 64, 65, 127, 128, 129, 1000] {
            let keys: Vec<f64> = (0..n).map(|i| (i / 3) as f64 * 0.5).collect();
            let tree = Tree::index(keys.clone(), (0..n as u32).collect());
            let mut probes: Vec<f64> = keys.clone();
            probes.extend(keys.iter().map(|k| k + 0.25));
            probes.extend([-1.0, f64::NEG_INFINITY, f64::INFINITY, f64::NAN, 1e9]);
            for t in probes {
                for inclusive in [false, true] {
                    let lo = if inclusive {
                        keys.partition_point(|&x| x < t)
                    } else {
                        keys.partition_point(|&x| x <= t)
                    };
                    let hi = if inclusive {
                        keys.partition_point(|&x| x <= t)
                    } else {
                        keys.partition_point(|&x| x < t)
                    };
                    assert_eq!(tree.lower(t, inclusive), lo, "n {n} t {t} {inclusive}");
                    assert_eq!(tree.upper(t, inclusive), hi, "n {n} t {t} {inclusive}");
                }
            }
        }
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
