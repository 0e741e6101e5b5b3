//! How the fit treats each relation's parameters: the fitting basis, the plan (what can be
//! fitted on given data) and the fast breakpoint profile (sorted prefix sums). The relations
//! (`crate::relations`) only specify a model — published values, formula, observe/predict; this
//! module holds the breakpoint machinery that was theirs until issue 20.
//!
//! The fit sees every relation through [`Fitting`], implemented once for `dyn Relation`: each
//! method asks the relation's [`Form`] ([`form_of`]). A relation whose parameters are all linear,
//! or whose breakpoints are held, needs no form of its own ([`Raw`]: the raw basis, every linear
//! parameter free, every breakpoint held). A relation with breakpoints to profile adds a form
//! here (one file, e.g. [`run_sl_v`]) and one line in [`form_of`].
//!
//! | relation | form |
//! |---|---|
//! | `run-sl-v` | [`run_sl_v::SlVForm`]: sorted profile over the height-normalised speed |
//! | `run-tflight-sf`, `run-tflight-sf-continuous` | [`run_tflight_sf::TflightForm`]: centred bases, continuity at k1, sorted profile over sf |
//! | `kb-mu` | [`kb_mu::MuForm`]: sl* and ll(S*) held (not identifiable beside free μ*) |
//! | `walk-sl-sf`, `walk-tds-sf` | [`Raw`] |
use crate::relations::{Inputs, Observation, ParamKind, Relation};
use nalgebra::{DMatrix, DVector};

pub mod kb_mu;
pub mod run_sl_v;
pub mod run_tflight_sf;

/// Raw linear parameters from the coefficients of the fitting basis: `raw = map · β + shift`
/// (rows: the relation's linear parameters in order; columns: basis coefficients).
#[derive(Debug, Clone, PartialEq)]
pub struct LinearMap {
    /// `n_linear × n_basis`.
    pub map: DMatrix<f64>,
    /// `n_linear`.
    pub shift: DVector<f64>,
}

/// What a relation can fit on given data: which parameters are free, with notes for those held
/// at their current (published) value, and the search bracket of each free breakpoint.
#[derive(Debug, Clone, PartialEq)]
pub struct Plan {
    /// Per parameter (in [`Card::parameters`](crate::relations::Card::parameters) order): `None` when free, or why it is held.
    pub held: Vec<Option<String>>,
    /// Per parameter: the search bracket of a free breakpoint (`None` for linear ones).
    pub search: Vec<Option<(f64, f64)>>,
}

/// Maximum number of per-row features of a [`SortedProfile`].
pub const MAX_PROFILE_FEATURES: usize = 16;

/// Sums of a [`SortedProfile`]'s per-row features (unused slots 0).
pub type FeatureSums = [f64; MAX_PROFILE_FEATURES];

/// Centre and half-width of the breakpoint key over the rows being fitted: polynomial relations
/// compute their features in powers of (key − c)/half_width about centres c near the rows, so
/// that the moments stay well conditioned (a cubic in sf ≈ 200 is not, raw).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct KeyScale {
    /// Middle of the key range.
    pub centre: f64,
    /// Half the key range (1 when the range is empty).
    pub half_width: f64,
}

impl KeyScale {
    /// The scale of keys spanning `[lo, hi]`.
    pub fn of_range(lo: f64, hi: f64) -> KeyScale {
        let half = 0.5 * (hi - lo);
        KeyScale {
            centre: 0.5 * (lo + hi),
            half_width: if half > 0.0 && half.is_finite() {
                half
            } else {
                1.0
            },
        }
    }
    /// ω of a key about `centre`.
    #[inline]
    pub fn omega(&self, key: f64, centre: f64) -> f64 {
        (key - centre) / self.half_width
    }
}

/// An interval of the breakpoint key: from `lo` to `hi`, each end included or not (±∞ for an
/// open end).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct KeyRange {
    /// Lower end.
    pub lo: f64,
    /// Whether `lo` itself belongs to the interval.
    pub lo_inclusive: bool,
    /// Upper end.
    pub hi: f64,
    /// Whether `hi` itself belongs to the interval.
    pub hi_inclusive: bool,
}

impl KeyRange {
    /// Keys `< t` (`≤ t` when `inclusive`).
    pub fn below(t: f64, inclusive: bool) -> KeyRange {
        KeyRange {
            lo: f64::NEG_INFINITY,
            lo_inclusive: true,
            hi: t,
            hi_inclusive: inclusive,
        }
    }
    /// Keys `> t` (`≥ t` when `inclusive`).
    pub fn above(t: f64, inclusive: bool) -> KeyRange {
        KeyRange {
            lo: t,
            lo_inclusive: inclusive,
            hi: f64::INFINITY,
            hi_inclusive: true,
        }
    }
    /// Keys from `lo` to `hi`, both included.
    pub fn closed(lo: f64, hi: f64) -> KeyRange {
        KeyRange {
            lo,
            lo_inclusive: true,
            hi,
            hi_inclusive: true,
        }
    }
    /// Whether `key` lies in the interval.
    pub fn contains(&self, key: f64) -> bool {
        (key > self.lo || (self.lo_inclusive && key == self.lo))
            && (key < self.hi || (self.hi_inclusive && key == self.hi))
    }
}

/// Weighted sums of a relation's per-row features over the rows whose breakpoint key lies in
/// an interval, provided by the fit pipeline from a tree over the rows sorted by key (a query
/// costs O(log n), not a pass over the data).
pub trait KeySums {
    /// Sums over the rows with key in `range`, the features taken about `centre` (see
    /// [`SortedProfile::features`]).
    fn range(&self, range: KeyRange, centre: f64) -> FeatureSums;
}

/// The normal equations XᵀWX·β = XᵀWy of some rows in a relation's fitting basis (the columns
/// of [`Fitting::basis`], the response net of its offset).
#[derive(Debug, Clone, PartialEq)]
pub struct NormalEquations {
    /// Number of basis columns.
    pub nb: usize,
    /// XᵀWX, `nb × nb`, row-major, both triangles filled.
    pub xtx: Vec<f64>,
    /// XᵀWy, `nb`.
    pub xty: Vec<f64>,
    /// yᵀWy.
    pub yty: f64,
}

impl NormalEquations {
    /// All zero, `nb` columns.
    pub fn zeros(nb: usize) -> NormalEquations {
        NormalEquations {
            nb,
            xtx: vec![0.0; nb * nb],
            xty: vec![0.0; nb],
            yty: 0.0,
        }
    }

    /// From the normal equations of a relation's raw linear basis (all its linear parameters,
    /// [`Relation::raw_basis`]) by moving the held ones (`free[j]` false, value `held[j]`) into
    /// the offset: the default basis of [`Fitting::basis`].
    pub fn hold_raw(raw: &NormalEquations, free: &[bool], held: &[f64]) -> NormalEquations {
        let m = raw.nb;
        let idx: Vec<usize> = (0..m).filter(|&j| free[j]).collect();
        let hv: Vec<f64> = (0..m)
            .map(|j| if free[j] { 0.0 } else { held[j] })
            .collect();
        let g = |a: usize, b: usize| raw.xtx[a * m + b];
        let mut out = NormalEquations::zeros(idx.len());
        let nb = idx.len();
        for (a, &ia) in idx.iter().enumerate() {
            let gh: f64 = (0..m).map(|b| g(ia, b) * hv[b]).sum();
            out.xty[a] = raw.xty[ia] - gh;
            for (b, &ib) in idx.iter().enumerate() {
                out.xtx[a * nb + b] = g(ia, ib);
            }
        }
        let hh: f64 = (0..m)
            .map(|a| hv[a] * (0..m).map(|b| g(a, b) * hv[b]).sum::<f64>())
            .sum();
        let hy: f64 = (0..m).map(|a| hv[a] * raw.xty[a]).sum();
        out.yty = raw.yty - 2.0 * hy + hh;
        out
    }
}

/// The fast profile of a relation with breakpoints (optional, [`Fitting::sorted_profile`]).
///
/// Profiling a breakpoint refits the linear coefficients at many trial values; done naively
/// that is a pass over the data per trial value. A relation whose breakpoints all split the
/// rows by one scalar *key* (the speed normalised by height, the step frequency), and whose
/// design row within each piece is a fixed linear function of a few per-row *features*, can
/// instead give the normal equations of any trial value from sums of those features over key
/// ranges: the pipeline sorts the rows by key once, keeps prefix sums per subject, and every
/// evaluation costs a few binary searches and an O(p³) solve, independent of the row count.
pub trait SortedProfile: Sync {
    /// The scalar input the breakpoints split the rows by.
    fn key(&self, x: &[f64]) -> f64;
    /// Number of features per row (≤ [`MAX_PROFILE_FEATURES`]).
    fn n_features(&self) -> usize;
    /// The features of one observation about `centre` (a key value; features that depend on
    /// the key are taken in ω = (key − centre)/`scale.half_width`), unweighted: the pipeline
    /// multiplies them by the row's weight before summing.
    fn features(&self, scale: &KeyScale, centre: f64, o: &Observation, out: &mut [f64]);
    /// Re-centres feature sums taken about `from` to sums about `to`. The pipeline keeps sums
    /// about the centre of each node of its tree and shifts them only within the queried
    /// interval, so polynomial moments of a narrow piece keep their digits (a prefix sum about
    /// one global centre would lose them to cancellation). The default suits features that do
    /// not depend on the centre.
    fn shift(&self, _scale: &KeyScale, _sums: &mut FeatureSums, _from: f64, _to: f64) {}
    /// The normal equations in the basis of [`Fitting::basis`] (with `free`) at the
    /// coefficients `p` (breakpoints and held values), from feature sums over the rows.
    /// Must agree with a pass over the rows to rounding.
    fn normal_equations(
        &self,
        p: &[f64],
        free: &[bool],
        scale: &KeyScale,
        sums: &dyn KeySums,
    ) -> NormalEquations;
    /// [`Fitting::plan`] from the distinct keys of the rows, ascending (the relation's
    /// `plan` must equal this applied to its observations' keys).
    fn plan_sorted(&self, keys: DistinctKeys) -> Plan;
    /// True when the model depends on breakpoint `i` only through which rows fall on each side
    /// of it (the residual sum of squares is then constant between adjacent keys, and the
    /// search runs over those partitions exactly).
    fn discrete_breakpoint(&self, _i: usize) -> bool {
        false
    }
    /// True when [`window_relaxation`](Self::window_relaxation) gives lower bounds for
    /// breakpoint `i` (the default: no).
    fn relaxes(&self, _i: usize) -> bool {
        false
    }
    /// A relaxation of breakpoint `i`'s profile over a window `[ta, tb]` of its values: normal
    /// equations, from `sums` over the rows *without those with key in `[ta, tb)`*, whose
    /// least-squares residual sum of squares is at most the profile's (the fit with the
    /// breakpoint at `t`, the other coefficients as in `p`) at every `t` in the window. `None`
    /// when there is none for these values.
    #[allow(clippy::too_many_arguments)]
    fn window_relaxation(
        &self,
        _p: &[f64],
        _free: &[bool],
        _i: usize,
        _ta: f64,
        _tb: f64,
        _scale: &KeyScale,
        _sums: &dyn KeySums,
    ) -> Option<NormalEquations> {
        None
    }
}

/// Distinct keys, ascending, seen as a sorted list without some of its positions: a
/// leave-one-subject-out fold's keys are all rows' keys without those only the left-out subject
/// has, so no fold copies the (up to n) keys. Indexing and [`partition_point`](Self::partition_point)
/// are O(log) in the number of skipped positions.
#[derive(Debug, Clone, Copy)]
pub struct DistinctKeys<'a> {
    all: &'a [f64],
    /// Positions in `all` left out, strictly ascending.
    skip: &'a [u32],
}

impl<'a> DistinctKeys<'a> {
    /// Every key of `all` (distinct, ascending).
    pub fn new(all: &'a [f64]) -> DistinctKeys<'a> {
        DistinctKeys { all, skip: &[] }
    }
    /// The keys of `all` but those at positions `skip` (strictly ascending).
    pub fn without(all: &'a [f64], skip: &'a [u32]) -> DistinctKeys<'a> {
        debug_assert!(skip.windows(2).all(|w| w[0] < w[1]));
        debug_assert!(skip.last().is_none_or(|&j| (j as usize) < all.len()));
        DistinctKeys { all, skip }
    }
    /// Number of keys.
    pub fn len(&self) -> usize {
        self.all.len() - self.skip.len()
    }
    /// True when there is no key.
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }
    /// The `j`-th key (ascending). Panics when `j ≥ len()`, as slice indexing does.
    pub fn get(&self, j: usize) -> f64 {
        // Skipped positions before the j-th kept one: those e_k with e_k − k ≤ j (e_k − k, the
        // kept positions before e_k, is non-decreasing in k).
        let (mut lo, mut hi) = (0, self.skip.len());
        while lo < hi {
            let mid = (lo + hi) / 2;
            if self.skip[mid] as usize - mid <= j {
                lo = mid + 1;
            } else {
                hi = mid;
            }
        }
        assert!(j < self.len(), "key {j} of {}", self.len());
        self.all[j + lo]
    }
    /// The number of keys for which `pred` holds, `pred` being true on a prefix (as
    /// [`slice::partition_point`]).
    pub fn partition_point(&self, pred: impl FnMut(&f64) -> bool) -> usize {
        let f = self.all.partition_point(pred);
        f - self.skip.partition_point(|&e| (e as usize) < f)
    }
    /// The keys, copied.
    pub fn to_vec(&self) -> Vec<f64> {
        let mut out = Vec::with_capacity(self.len());
        let mut from = 0;
        for &j in self.skip {
            out.extend_from_slice(&self.all[from..j as usize]);
            from = j as usize + 1;
        }
        out.extend_from_slice(&self.all[from..]);
        out
    }
}

/// The distinct keys of observations, ascending.
pub fn sorted_keys(form: &dyn SortedProfile, obs: &[Observation]) -> Vec<f64> {
    let mut u: Vec<f64> = obs.iter().map(|o| form.key(&o.x)).collect();
    u.sort_by(f64::total_cmp);
    u.dedup();
    u
}

/// The fit's treatment of one relation. Every method has the default of a relation without
/// breakpoints to profile (the raw basis of [`Relation::raw_basis`], every linear parameter
/// free, every breakpoint held); a form overrides what its relation fits differently.
pub trait Form: Sync {
    /// What can be fitted on these observations (default: every linear parameter free, every
    /// breakpoint held).
    fn plan(&self, rel: &dyn Relation, _obs: &[Observation]) -> Plan {
        Plan {
            held: rel
                .card()
                .parameters
                .iter()
                .map(|s| match s.kind {
                    ParamKind::Linear => None,
                    ParamKind::Breakpoint => Some("not fitted by this relation".to_string()),
                })
                .collect(),
            search: vec![None; rel.card().parameters.len()],
        }
    }

    /// Number of basis columns for the free linear parameters `free` (mask over all params).
    fn basis_len(&self, rel: &dyn Relation, free: &[bool]) -> usize {
        rel.card()
            .parameters
            .iter()
            .zip(free)
            .filter(|(s, f)| s.kind == ParamKind::Linear && **f)
            .count()
    }

    /// The fitting basis for the free linear parameters at the breakpoints in `p`: fills `phi`
    /// (length [`Form::basis_len`]) and returns the offset (the contribution of held linear
    /// parameters). The default is the raw basis; a form overrides this (with
    /// [`Form::basis_to_params`]) to fit in a better-conditioned or constrained basis.
    fn basis(
        &self,
        rel: &dyn Relation,
        p: &[f64],
        free: &[bool],
        x: &Inputs,
        phi: &mut [f64],
    ) -> f64 {
        let mut g = [0.0; 16];
        let nl = rel.card().n_linear();
        rel.raw_basis(p, x, &mut g[..nl]);
        let mut k = 0;
        let mut offset = 0.0;
        for (j, (i, _)) in rel
            .card()
            .parameters
            .iter()
            .enumerate()
            .filter(|(_, s)| s.kind == ParamKind::Linear)
            .enumerate()
        {
            if free[i] {
                phi[k] = g[j];
                k += 1;
            } else {
                offset += p[i] * g[j];
            }
        }
        offset
    }

    /// Maps basis coefficients to the linear parameters (see [`LinearMap`]); must match
    /// [`Form::basis`].
    fn basis_to_params(&self, rel: &dyn Relation, p: &[f64], free: &[bool]) -> LinearMap {
        let specs = rel.card().parameters;
        let lin: Vec<usize> = (0..specs.len())
            .filter(|&i| specs[i].kind == ParamKind::Linear)
            .collect();
        let nb = self.basis_len(rel, free);
        let mut map = DMatrix::zeros(lin.len(), nb);
        let mut shift = DVector::zeros(lin.len());
        let mut k = 0;
        for (j, &i) in lin.iter().enumerate() {
            if free[i] {
                map[(j, k)] = 1.0;
                k += 1;
            } else {
                shift[j] = p[i];
            }
        }
        LinearMap { map, shift }
    }

    /// The basis column that the subject effect multiplies (its coefficient must equal the
    /// [`crate::relations::SubjectEffect::on`] parameter). The default finds `on` among the free
    /// linear parameters of the raw basis.
    fn subject_column(&self, rel: &dyn Relation, free: &[bool]) -> Option<usize> {
        let on = rel.card().subject_effect?.on;
        let mut k = 0;
        for (i, s) in rel.card().parameters.iter().enumerate() {
            if s.kind == ParamKind::Linear && free[i] {
                if s.name == on {
                    return Some(k);
                }
                k += 1;
            }
        }
        None
    }

    /// The fast profile, when the form has one (see [`SortedProfile`]); forms with breakpoints
    /// to profile should provide it, or every trial value costs a pass over the data.
    fn sorted_profile(&self) -> Option<&dyn SortedProfile> {
        None
    }

    /// For a breakpoint `i`: the value at which the feature it marks vanishes from the data
    /// (e.g. `+∞` for a plateau onset), so the fit can test whether the data show the feature
    /// at all. `None` when the breakpoint is structural (always present).
    fn breakpoint_null(&self, _i: usize) -> Option<f64> {
        None
    }
}

/// The default form: raw basis, every linear parameter free, every breakpoint held.
#[derive(Debug, Clone, Copy)]
pub struct Raw;

impl Form for Raw {}

/// The form of the relation with id `id` ([`Raw`] for relations without one of their own).
pub fn form_of(id: &str) -> &'static dyn Form {
    use crate::relations::{KbMu, RunSlV, RunTflightSf};
    match id {
        RunSlV::ID => &run_sl_v::SlVForm,
        RunTflightSf::ID => &run_tflight_sf::FREE,
        RunTflightSf::ID_CONTINUOUS => &run_tflight_sf::CONTINUOUS,
        KbMu::ID => &kb_mu::MuForm,
        _ => &Raw,
    }
}

/// The fit's view of a relation: its [`Form`]'s methods, called on the relation itself
/// (`use gaitfit::fit::forms::Fitting` and call `rel.basis(…)` on a `&dyn Relation`).
pub trait Fitting {
    /// [`Form::plan`].
    fn plan(&self, obs: &[Observation]) -> Plan;
    /// [`Form::basis_len`].
    fn basis_len(&self, free: &[bool]) -> usize;
    /// [`Form::basis`].
    fn basis(&self, p: &[f64], free: &[bool], x: &Inputs, phi: &mut [f64]) -> f64;
    /// [`Form::basis_to_params`].
    fn basis_to_params(&self, p: &[f64], free: &[bool]) -> LinearMap;
    /// [`Form::subject_column`].
    fn subject_column(&self, free: &[bool]) -> Option<usize>;
    /// [`Form::sorted_profile`].
    fn sorted_profile(&self) -> Option<&'static dyn SortedProfile>;
    /// [`Form::breakpoint_null`].
    fn breakpoint_null(&self, i: usize) -> Option<f64>;
}

impl Fitting for dyn Relation + '_ {
    fn plan(&self, obs: &[Observation]) -> Plan {
        form_of(self.card().id).plan(self, obs)
    }
    fn basis_len(&self, free: &[bool]) -> usize {
        form_of(self.card().id).basis_len(self, free)
    }
    fn basis(&self, p: &[f64], free: &[bool], x: &Inputs, phi: &mut [f64]) -> f64 {
        form_of(self.card().id).basis(self, p, free, x, phi)
    }
    fn basis_to_params(&self, p: &[f64], free: &[bool]) -> LinearMap {
        form_of(self.card().id).basis_to_params(self, p, free)
    }
    fn subject_column(&self, free: &[bool]) -> Option<usize> {
        form_of(self.card().id).subject_column(self, free)
    }
    fn sorted_profile(&self) -> Option<&'static dyn SortedProfile> {
        form_of(self.card().id).sorted_profile()
    }
    fn breakpoint_null(&self, i: usize) -> Option<f64> {
        form_of(self.card().id).breakpoint_null(i)
    }
}

/// Test support: a relation's [`SortedProfile::normal_equations`] against a pass over the rows
/// with [`Fitting::basis`].
#[cfg(test)]
pub(crate) mod sorted_check {
    use super::*;

    /// Feature sums by brute force (no sorting, no tree).
    struct Direct<'a> {
        form: &'a dyn SortedProfile,
        scale: KeyScale,
        obs: &'a [Observation],
    }

    impl KeySums for Direct<'_> {
        fn range(&self, range: KeyRange, centre: f64) -> FeatureSums {
            let mut out = [0.0; MAX_PROFILE_FEATURES];
            let mut f = [0.0; MAX_PROFILE_FEATURES];
            for o in self.obs {
                if range.contains(self.form.key(&o.x)) {
                    self.form.features(&self.scale, centre, o, &mut f);
                    out.iter_mut().zip(&f).for_each(|(a, b)| *a += b);
                }
            }
            out
        }
    }

    /// Asserts that the sorted normal equations equal the basis rows' to `tol` (relative to
    /// the Cauchy–Schwarz scale of each entry).
    pub(crate) fn check(
        rel: &dyn Relation,
        obs: &[Observation],
        p: &[f64],
        free: &[bool],
        tol: f64,
    ) {
        let form = rel.sorted_profile().expect("sorted form");
        let (lo, hi) = obs.iter().fold((f64::INFINITY, f64::NEG_INFINITY), |a, o| {
            let k = form.key(&o.x);
            (a.0.min(k), a.1.max(k))
        });
        let scale = KeyScale::of_range(lo, hi);
        let ne = form.normal_equations(p, free, &scale, &Direct { form, scale, obs });
        let nb = rel.basis_len(free);
        assert_eq!(ne.nb, nb);
        let mut want = NormalEquations::zeros(nb);
        let mut phi = [0.0; 16];
        let mut yy_raw = 0.0;
        for o in obs {
            let off = rel.basis(p, free, &o.x, &mut phi[..nb]);
            let y = o.y - off;
            yy_raw += o.y * o.y + off * off;
            want.yty += y * y;
            for a in 0..nb {
                want.xty[a] += phi[a] * y;
                for b in 0..nb {
                    want.xtx[a * nb + b] += phi[a] * phi[b];
                }
            }
        }
        let what = format!("{} p={p:?} free={free:?}", rel.card().id);
        // Entries of all-but-zero columns carry the rounding of their terms, not of their
        // value: floor the diagonal at a millionth of the largest.
        let floor = 1e-6 * (0..nb).map(|a| want.xtx[a * nb + a]).fold(0.0, f64::max);
        let diag = |a: usize| want.xtx[a * nb + a].max(floor);
        for a in 0..nb {
            for b in 0..nb {
                let sc = (diag(a) * diag(b)).sqrt();
                let (x, w) = (ne.xtx[a * nb + b], want.xtx[a * nb + b]);
                assert!((x - w).abs() <= tol * sc, "{what}: xtx[{a},{b}] {x} vs {w}");
            }
            let sc = (diag(a) * yy_raw).sqrt();
            let (x, w) = (ne.xty[a], want.xty[a]);
            assert!((x - w).abs() <= tol * sc, "{what}: xty[{a}] {x} vs {w}");
        }
        assert!(
            (ne.yty - want.yty).abs() <= tol * yy_raw,
            "{what}: yty {} vs {}",
            ne.yty,
            want.yty
        );
    }
}

#[cfg(test)]
mod tests {
    use super::DistinctKeys;

    #[test]
    fn a_view_without_positions_indexes_and_searches_like_the_copied_keys() {
        let all: Vec<f64> = (0..40).map(|i| 100.0 + 1.5 * i as f64).collect();
        let skips: [&[u32]; 5] = [
            &[],
            &[0],
            &[39],
            &[0, 1, 2, 17, 18, 38, 39],
            &[5, 9, 10, 11, 30],
        ];
        for skip in skips {
            let view = DistinctKeys::without(&all, skip);
            let copy: Vec<f64> = all
                .iter()
                .enumerate()
                .filter(|(j, _)| !skip.contains(&(*j as u32)))
                .map(|(_, &k)| k)
                .collect();
            assert_eq!(view.len(), copy.len());
            assert_eq!(view.to_vec(), copy);
            for (j, &k) in copy.iter().enumerate() {
                assert_eq!(view.get(j), k, "skip {skip:?}, key {j}");
            }
            for t in [90.0, 100.0, 100.5, 113.5, 125.0, 158.5, 200.0] {
                assert_eq!(
                    view.partition_point(|&k| k < t),
                    copy.partition_point(|&k| k < t),
                    "skip {skip:?}, < {t}"
                );
                assert_eq!(
                    view.partition_point(|&k| k <= t),
                    copy.partition_point(|&k| k <= t),
                    "skip {skip:?}, <= {t}"
                );
            }
        }
    }
}
