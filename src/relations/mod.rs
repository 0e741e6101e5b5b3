//! The published relations, one type per relation (one file each), behind one trait.
//!
//! | id | type | paper, equation |
//! |---|---|---|
//! | `run-sl-v` | [`RunSlV`] | running 1996, eq. 2 (with `v_norm`, §2.2) |
//! | `run-tflight-sf` | [`RunTflightSf`] (paper's free pieces) | running 1996, eqs. 4–5 |
//! | `run-tflight-sf-continuous` | [`RunTflightSf`] (continuous at `k1`) | running 1996, eqs. 4–5 |
//! | `walk-sl-sf` | [`WalkSlSf`] | walking 1989, eq. 1 |
//! | `walk-tds-sf` | [`WalkTdsSf`] | walking 1989, §3 (t_ds formula) |
//! | `kb-mu` | [`KbMu`] (four outputs, bounded) | Ko & Badler 1993, appendix A, eqs. 21–24 |
//!
//! # Using a relation (generators)
//! Every type has `published()` (the papers' coefficients), typed evaluation methods in the
//! papers' units (e.g. [`RunSlV::step_length`]), and `from_fit_file("fits/<id>.json")` to use
//! coefficients refitted by `gaitfit fit`. [`load_fit`] does the same behind the trait.
//!
//! ```
//! use gaitfit::relations::{RunSlV, RunTflightSf, WalkSlSf, WalkTdsSf};
//! let run = RunSlV::published();
//! let sl = run.step_length(200.0, 1.8, 0.0);        // 12 km/h = 200 m/min
//! assert!((sl - 1.07).abs() < 0.005);                // running paper §3.1: 1.07 m
//! assert!((200.0 / sl - 187.0).abs() < 0.5);         // … and 187 steps/min
//! let tf = RunTflightSf::published().flight_time(187.0);
//! assert!((tf - 0.188).abs() < 0.0005);
//! let walk = WalkSlSf::published();
//! let sf = walk.step_freq_for_speed(5000.0 / 60.0, 1.8); // 5 km/h
//! assert!((sf - 107.6).abs() < 0.05);
//! assert!((WalkTdsSf::published().double_support_pct(100.0) - 13.08).abs() < 1e-9);
//! ```
//!
//! # Adding a relation
//! Implement [`Relation`] in one new file: metadata, `observe` (which [`Quantity`]s of a row it
//! needs, converted to the papers' units), `parameters`, and `raw_basis` — the model must be
//! linear in its [`ParamKind::Linear`] parameters once the [`ParamKind::Breakpoint`] ones are
//! fixed (true of all the papers' relations); `predict` then comes for free. Register it in
//! [`registry`]. The generic fit routine (`gaitfit::fit::pipeline`) produces the statistics,
//! tables and plots without further code.
pub mod kb_mu;
pub mod run_sl_v;
pub mod run_tflight_sf;
pub mod walk_sl_sf;
pub mod walk_tds_sf;

pub use kb_mu::KbMu;
pub use run_sl_v::RunSlV;
pub use run_tflight_sf::{Continuity, RunTflightSf};
pub use walk_sl_sf::WalkSlSf;
pub use walk_tds_sf::WalkTdsSf;

use crate::events::Gait;
use crate::ingest::trials::FieldValues;
use crate::units::Quantity;
use nalgebra::{DMatrix, DVector};
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use thiserror::Error;

/// Maximum number of inputs of a relation (the length of [`Observation::x`]).
pub const MAX_INPUTS: usize = 4;

/// Errors of the relations layer (building a relation from coefficients or a fits file).
#[derive(Debug, Error)]
#[non_exhaustive]
pub enum RelationError {
    /// The fits file could not be read.
    #[error("{path}: {source}")]
    Io {
        /// The file.
        path: PathBuf,
        /// The underlying error.
        source: std::io::Error,
    },
    /// The fits file is not valid JSON of the expected shape.
    #[error("{path}: not a gaitfit fits file: {message}")]
    Format {
        /// The file.
        path: PathBuf,
        /// What is wrong.
        message: String,
    },
    /// The relation id is not known.
    #[error("unknown relation `{id}`; known: {known}")]
    UnknownRelation {
        /// The id found.
        id: String,
        /// The ids gaitfit knows.
        known: String,
    },
    /// A coefficient is missing or not finite.
    #[error("{relation}: coefficient `{name}` {message}")]
    Coefficient {
        /// Relation id.
        relation: String,
        /// Coefficient name.
        name: String,
        /// What is wrong.
        message: String,
    },
}

/// Where a relation comes from.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Citation {
    /// Short reference (authors, year, title).
    pub paper: &'static str,
    /// Equation or section.
    pub equation: &'static str,
}

/// A model variable (input or response), in the papers' units.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Variable {
    /// Symbol as in the paper (`v`, `sf`, `sl`, `t_flight`, …).
    pub symbol: &'static str,
    /// Unit as the paper writes it (`m/min`, `steps/min`, `m`, `s`, `%`).
    pub unit: &'static str,
    /// Plain-language name.
    pub name: &'static str,
}

/// How a parameter enters the model.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum ParamKind {
    /// The prediction is linear in it (given the breakpoints): fitted by linear least squares.
    Linear,
    /// A breakpoint or other nonlinear parameter: profiled (the linear ones refitted at each
    /// trial value) and given a profile-likelihood confidence interval.
    Breakpoint,
}

/// A global parameter of a relation.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ParameterSpec {
    /// Name (interface: used in fits files and exports).
    pub name: &'static str,
    /// Unit in the papers' terms.
    pub unit: &'static str,
    /// The published value (the relation's value with published coefficients; where the paper
    /// gives none, see `cited`, a neutral reference such as 0).
    pub published: f64,
    /// Whether the paper gives `published`; when not, fits report no published value and no
    /// t-test against it.
    pub cited: bool,
    /// Linear or breakpoint.
    pub kind: ParamKind,
    /// What it is.
    pub description: &'static str,
}

/// A per-subject additive offset on one linear parameter (the running paper's `level`).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SubjectEffect {
    /// Name stem; coefficients are called `<name>[<subject>]`.
    pub name: &'static str,
    /// The linear parameter it offsets.
    pub on: &'static str,
    /// The paper's range: |offset| ≤ `paper_bound` (outside it a subject is flagged).
    pub paper_bound: f64,
    /// Unit.
    pub unit: &'static str,
}

/// The input domain the published relation was derived on (papers' units).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Domain {
    /// Input symbol.
    pub input: &'static str,
    /// Lower end.
    pub lo: f64,
    /// Upper end.
    pub hi: f64,
    /// Where the range comes from.
    pub note: &'static str,
}

/// One row reduced to what a relation uses: inputs and response in the papers' units.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Observation {
    /// Inputs, in the order of [`Relation::inputs`]; unused slots are 0.
    pub x: [f64; MAX_INPUTS],
    /// Response.
    pub y: f64,
}

/// Why a row cannot be used by a relation.
#[derive(Debug, Clone, PartialEq)]
pub enum Rejection {
    /// A needed quantity is missing (empty cell or no column).
    Missing(Quantity),
    /// A value is outside what the relation can use (e.g. a zero step frequency).
    Invalid(String),
}

/// The value of quantity `q` in `row`, or the rejection naming it: what every relation's
/// [`Relation::observe`] asks of a row for each quantity it [`Relation::needs`].
fn required(row: &FieldValues, q: Quantity) -> Result<f64, Rejection> {
    row.get(q).ok_or(Rejection::Missing(q))
}

impl std::fmt::Display for Rejection {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            Rejection::Missing(q) => write!(f, "missing {}", q.canonical_header()),
            Rejection::Invalid(s) => f.write_str(s),
        }
    }
}

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
    /// Per parameter (in [`Relation::parameters`] order): `None` when free, or why it is held.
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
/// of [`Relation::basis`], the response net of its offset).
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
    /// the offset: the default basis of [`Relation::basis`].
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

/// The fast profile of a relation with breakpoints (optional, [`Relation::sorted_profile`]).
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
    /// The normal equations in the basis of [`Relation::basis`] (with `free`) at the
    /// coefficients `p` (breakpoints and held values), from feature sums over the rows.
    /// Must agree with a pass over the rows to rounding.
    fn normal_equations(
        &self,
        p: &[f64],
        free: &[bool],
        scale: &KeyScale,
        sums: &dyn KeySums,
    ) -> NormalEquations;
    /// [`Relation::plan`] from the distinct keys of the rows, ascending (the relation's
    /// `plan` must equal this applied to its observations' keys).
    fn plan_sorted(&self, keys: &[f64]) -> Plan;
    /// True when the model depends on breakpoint `i` only through which rows fall on each side
    /// of it (the residual sum of squares is then constant between adjacent keys, and the
    /// search runs over those partitions exactly).
    fn discrete_breakpoint(&self, _i: usize) -> bool {
        false
    }
}

/// The distinct keys of observations, ascending.
pub fn sorted_keys(form: &dyn SortedProfile, obs: &[Observation]) -> Vec<f64> {
    let mut u: Vec<f64> = obs.iter().map(|o| form.key(&o.x)).collect();
    u.sort_by(f64::total_cmp);
    u.dedup();
    u
}

/// A published gait relation (see the module docs).
///
/// Coefficient vectors (`p`) hold the global parameters in [`Relation::parameters`] order;
/// per-subject effects are passed separately as an additive offset.
pub trait Relation: Send + Sync + std::fmt::Debug {
    /// The relation id (`run-sl-v`, …): interface, used for file names.
    fn id(&self) -> &'static str;
    /// One-line title.
    fn title(&self) -> &'static str;
    /// The paper and equation.
    fn citation(&self) -> Citation;
    /// The formula in the papers' units, as text.
    fn equation(&self) -> &'static str;
    /// The response variable.
    fn response(&self) -> Variable;
    /// The input variables (the first is the one plots use as abscissa).
    fn inputs(&self) -> &'static [Variable];
    /// The gait whose rows this relation uses.
    fn gait(&self) -> Gait;
    /// The row quantities it needs.
    fn needs(&self) -> &'static [Quantity];
    /// Reduces a row (SI) to inputs and response in the papers' units.
    fn observe(&self, row: &FieldValues) -> Result<Observation, Rejection>;
    /// The global parameters.
    fn parameters(&self) -> &'static [ParameterSpec];
    /// The per-subject effect, if the relation has one.
    fn subject_effect(&self) -> Option<SubjectEffect> {
        None
    }
    /// True when the model has an intercept (r² is then centred; otherwise uncentred, as NIST
    /// defines it for regressions through the origin).
    fn has_intercept(&self) -> bool;
    /// The input domain of the published relation.
    fn domain(&self) -> Domain;
    /// Current coefficient values (published, or loaded from a fit), in `parameters()` order.
    fn values(&self) -> &[f64];
    /// Per-subject effects of the loaded fit (empty for published coefficients).
    fn subject_levels(&self) -> &BTreeMap<String, f64>;

    /// The derivatives of the prediction with respect to each [`ParamKind::Linear`] parameter
    /// (in order), at the breakpoints in `p`: the model is `Σ_j p_lin[j] · g[j]`.
    fn raw_basis(&self, p: &[f64], x: &[f64], g: &mut [f64]);

    /// Number of linear parameters.
    fn n_linear(&self) -> usize {
        self.parameters()
            .iter()
            .filter(|s| s.kind == ParamKind::Linear)
            .count()
    }

    /// Prediction with coefficients `p` and a per-subject offset on the
    /// [`SubjectEffect::on`] parameter.
    fn predict_with(&self, p: &[f64], subject_offset: f64, x: &[f64]) -> f64 {
        let mut g = [0.0; 16];
        let nl = self.n_linear();
        self.raw_basis(p, x, &mut g[..nl]);
        let on = self.subject_effect().map(|e| e.on);
        let mut y = 0.0;
        let mut j = 0;
        for (i, s) in self.parameters().iter().enumerate() {
            if s.kind == ParamKind::Linear {
                let mut c = p[i];
                if Some(s.name) == on {
                    c += subject_offset;
                }
                y += c * g[j];
                j += 1;
            }
        }
        y
    }

    /// Prediction with the current coefficients for an average subject (offset 0).
    fn predict(&self, x: &[f64]) -> f64 {
        self.predict_with(self.values(), 0.0, x)
    }

    /// The input range the coefficients were fitted on (read from the fits file; empty for the
    /// published coefficients and for relations built in memory).
    fn fitted_range(&self) -> FittedRange {
        FittedRange::default()
    }

    /// Sets the fitted input range (relations that keep none ignore it).
    fn set_fitted_range(&mut self, _range: FittedRange) {}

    /// [`Relation::predict`] with the rule of [`FittedRange`]: whether `x` lies inside the
    /// fitted range, and outside it the boundary value held (inputs clamped to `[lo, hi]`).
    fn predict_checked(&self, x: &[f64]) -> Prediction {
        let r = self.fitted_range();
        let at = r.hold(x);
        Prediction {
            value: self.predict(&at),
            inside: r.contains(x),
            at,
        }
    }

    /// Analytic gradient of the prediction with respect to all global parameters, when
    /// available. The default gives the linear part exactly and leaves breakpoints to the
    /// caller (`None`).
    fn gradient(&self, _p: &[f64], _x: &[f64]) -> Option<Vec<f64>> {
        None
    }

    /// What can be fitted on these observations (default: every linear parameter free, every
    /// breakpoint held — relations with breakpoints override this).
    fn plan(&self, _obs: &[Observation]) -> Plan {
        Plan {
            held: self
                .parameters()
                .iter()
                .map(|s| match s.kind {
                    ParamKind::Linear => None,
                    ParamKind::Breakpoint => Some("not fitted by this relation".to_string()),
                })
                .collect(),
            search: vec![None; self.parameters().len()],
        }
    }

    /// Number of basis columns for the free linear parameters `free` (mask over all params).
    fn basis_len(&self, free: &[bool]) -> usize {
        self.parameters()
            .iter()
            .zip(free)
            .filter(|(s, f)| s.kind == ParamKind::Linear && **f)
            .count()
    }

    /// The fitting basis for the free linear parameters at the breakpoints in `p`: fills `phi`
    /// (length [`Relation::basis_len`]) and returns the offset (the contribution of held
    /// linear parameters). The default is the raw basis; a relation overrides this (with
    /// [`Relation::basis_to_params`]) to fit in a better-conditioned or constrained basis.
    fn basis(&self, p: &[f64], free: &[bool], x: &[f64], phi: &mut [f64]) -> f64 {
        let mut g = [0.0; 16];
        let nl = self.n_linear();
        self.raw_basis(p, x, &mut g[..nl]);
        let mut k = 0;
        let mut offset = 0.0;
        for (j, (i, _)) in self
            .parameters()
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
    /// [`Relation::basis`].
    fn basis_to_params(&self, p: &[f64], free: &[bool]) -> LinearMap {
        let specs = self.parameters();
        let lin: Vec<usize> = (0..specs.len())
            .filter(|&i| specs[i].kind == ParamKind::Linear)
            .collect();
        let nb = self.basis_len(free);
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
    /// [`SubjectEffect::on`] parameter). The default finds `on` among the free linear
    /// parameters of the raw basis.
    fn subject_column(&self, free: &[bool]) -> Option<usize> {
        let on = self.subject_effect()?.on;
        let mut k = 0;
        for (i, s) in self.parameters().iter().enumerate() {
            if s.kind == ParamKind::Linear && free[i] {
                if s.name == on {
                    return Some(k);
                }
                k += 1;
            }
        }
        None
    }

    /// The fast profile form, when the relation has one (see [`SortedProfile`]); relations
    /// with breakpoints should provide it, or every trial value costs a pass over the data.
    fn sorted_profile(&self) -> Option<&dyn SortedProfile> {
        None
    }

    /// A copy of this relation with other coefficient values (and per-subject levels).
    fn with_values(&self, values: &[f64], levels: BTreeMap<String, f64>) -> Box<dyn Relation>;

    /// For a breakpoint `i`: the value at which the feature it marks vanishes from the data
    /// (e.g. `+∞` for a plateau onset), so the fit can test whether the data show the feature
    /// at all. `None` when the breakpoint is structural (always present).
    fn breakpoint_null(&self, _i: usize) -> Option<f64> {
        None
    }

    /// Derived quantities worth reporting for a coefficient vector (name, value, unit), e.g.
    /// the jump of the flight-time curve at `k1`.
    fn derived(&self, _p: &[f64]) -> Vec<(String, f64, &'static str)> {
        Vec::new()
    }

    /// The published coefficients, in `parameters()` order.
    fn published_values(&self) -> Vec<f64> {
        self.parameters().iter().map(|s| s.published).collect()
    }

    /// The index of parameter `name`.
    fn index_of(&self, name: &str) -> Option<usize> {
        self.parameters().iter().position(|s| s.name == name)
    }

    /// Number of observations one row can give (1; `kb-mu` gives one per μ-function). The
    /// pipeline then pools them, centres r² within each output and reports per-output
    /// statistics.
    fn outputs(&self) -> usize {
        1
    }

    /// Reduces a row to its `k`-th observation (`k <` [`Relation::outputs`]); by default
    /// [`Relation::observe`]. A row is rejected only when none of its outputs is usable.
    fn observe_output(&self, row: &FieldValues, k: usize) -> Result<Observation, Rejection> {
        let _ = k;
        self.observe(row)
    }

    /// Which output an observation's inputs belong to (0 for single-output relations).
    fn output_of(&self, x: &[f64]) -> usize {
        let _ = x;
        0
    }

    /// Name of output `k` (for reports).
    fn output_name(&self, k: usize) -> String {
        let _ = k;
        self.response().symbol.to_string()
    }

    /// What output `k` is, for a plot panel's label; by default its name.
    fn output_label(&self, k: usize) -> String {
        self.output_name(k)
    }

    /// Sets the inputs that select output `k` (for plotting one curve per output).
    fn select_output(&self, x: &mut [f64], k: usize) {
        let _ = (x, k);
    }

    /// The allowed range of parameter `i` (unbounded by default). Where a bound is finite the
    /// pipeline enforces it with argmin's bounded least squares and reports an active bound.
    fn bounds(&self, i: usize) -> (f64, f64) {
        let _ = i;
        (f64::NEG_INFINITY, f64::INFINITY)
    }
}

/// The input range a relation's coefficients were fitted on (a fits file's `valid_range`),
/// one `[lo, hi]` per input in [`Relation::inputs`] order (`None`: not recorded, e.g. the
/// published coefficients).
///
/// # Beyond the fitted range (the rule every prediction follows)
/// [`Relation::predict_checked`] reports whether the inputs lie inside the range and, outside
/// it, **holds the boundary value**: each input is clamped to `[lo, hi]` before the relation is
/// evaluated, so no fitted curve is followed where no data constrained it. The typed methods the
/// generators call follow the same rule for polynomial pieces of degree ≥ 2
/// ([`RunTflightSf::flight_time`]: the cubic past the data ran to 0.231 s at 230 steps/min);
/// the relations that are straight lines in their inputs ([`RunSlV`], [`WalkSlSf`],
/// [`WalkTdsSf`], [`KbMu`]) extrapolate their line in the typed methods, which the generators
/// invert (a line cannot turn back the way a cubic does), while `predict_checked` holds.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct FittedRange {
    /// `[lo, hi]` per input.
    pub bounds: [Option<[f64; 2]>; MAX_INPUTS],
}

impl FittedRange {
    /// The range of `inputs` recorded in `set` (inputs matched by symbol).
    pub fn of(set: &CoefficientSet, inputs: &[Variable]) -> FittedRange {
        let mut r = FittedRange::default();
        for (j, v) in inputs.iter().enumerate().take(MAX_INPUTS) {
            r.bounds[j] = set
                .ranges
                .iter()
                .find(|(name, lo, hi)| name == v.symbol && lo <= hi)
                .map(|&(_, lo, hi)| [lo, hi]);
        }
        r
    }
    /// Whether every input with a recorded range lies inside it (NaN inputs are outside).
    pub fn contains(&self, x: &[f64]) -> bool {
        x.iter().zip(&self.bounds).all(|(&v, b)| match b {
            Some([lo, hi]) => v >= *lo && v <= *hi,
            None => true,
        })
    }
    /// Input `j` held at the range's boundary (unchanged without a recorded range).
    pub fn hold_input(&self, j: usize, v: f64) -> f64 {
        match self.bounds.get(j).copied().flatten() {
            Some([lo, hi]) => v.clamp(lo, hi),
            None => v,
        }
    }
    /// All inputs held at the range's boundary.
    pub fn hold(&self, x: &[f64]) -> [f64; MAX_INPUTS] {
        let mut out = [0.0; MAX_INPUTS];
        for (j, (o, &v)) in out.iter_mut().zip(x).enumerate() {
            *o = self.hold_input(j, v);
        }
        out
    }
}

/// A prediction with where it was evaluated ([`Relation::predict_checked`]).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Prediction {
    /// The predicted response (papers' units), at `at`.
    pub value: f64,
    /// Whether the inputs asked for lie inside the fitted range ([`FittedRange`]); always true
    /// when no range is recorded.
    pub inside: bool,
    /// The inputs the relation was evaluated at: those asked for, held at the range's boundary.
    pub at: [f64; MAX_INPUTS],
}

/// The text a fit record carries under `outside_range` (the rule of [`FittedRange`]).
pub const OUTSIDE_RANGE_RULE: &str = "predictions report whether their inputs lie inside \
    valid_range; outside it gaitfit holds the boundary value (each input clamped to [lo, hi] \
    before evaluating: Relation::predict_checked); the generators' polynomial pieces of degree \
    ≥ 2 (run-tflight-sf) do the same, straight-line relations extrapolate their line";

/// A named set of coefficient values for one relation (what a fits file carries).
#[derive(Debug, Clone, PartialEq, Default)]
pub struct CoefficientSet {
    /// Relation id.
    pub relation: String,
    /// `(name, value)` in file order; per-subject effects are named `<stem>[<subject>]`.
    pub values: Vec<(String, f64)>,
    /// `(input symbol, lo, hi)`: the fitted range (`valid_range`), empty when not recorded.
    pub ranges: Vec<(String, f64, f64)>,
}

impl CoefficientSet {
    /// The value of `name`.
    pub fn get(&self, name: &str) -> Option<f64> {
        self.values.iter().find(|(n, _)| n == name).map(|(_, v)| *v)
    }

    /// Reads the `relation` id and the `coefficients[].name/value` of a fits JSON file written
    /// by `gaitfit fit` (other keys are ignored).
    pub fn from_fit_file(path: &Path) -> Result<CoefficientSet, RelationError> {
        let text = std::fs::read_to_string(path).map_err(|e| RelationError::Io {
            path: path.to_path_buf(),
            source: e,
        })?;
        Self::from_fit_json(path, &text)
    }

    /// As [`CoefficientSet::from_fit_file`], from JSON text (`path` is for messages).
    pub fn from_fit_json(path: &Path, text: &str) -> Result<CoefficientSet, RelationError> {
        #[derive(serde::Deserialize)]
        struct C {
            name: String,
            value: f64,
        }
        #[derive(serde::Deserialize)]
        struct R {
            input: String,
            lo: Option<f64>,
            hi: Option<f64>,
        }
        #[derive(serde::Deserialize)]
        struct F {
            relation: String,
            coefficients: Vec<C>,
            #[serde(default)]
            valid_range: Vec<R>,
        }
        let f: F = serde_json::from_str(text).map_err(|e| RelationError::Format {
            path: path.to_path_buf(),
            message: e.to_string(),
        })?;
        Ok(CoefficientSet {
            relation: f.relation,
            values: f
                .coefficients
                .into_iter()
                .map(|c| (c.name, c.value))
                .collect(),
            ranges: f
                .valid_range
                .into_iter()
                .filter_map(|r| Some((r.input, r.lo?, r.hi?)))
                .collect(),
        })
    }

    /// Splits into global values in `specs` order and per-subject levels named
    /// `<stem>[<subject>]`. Missing or non-finite global coefficients are errors.
    pub fn split(
        &self,
        specs: &[ParameterSpec],
        effect: Option<SubjectEffect>,
    ) -> Result<(Vec<f64>, BTreeMap<String, f64>), RelationError> {
        let mut vals = Vec::with_capacity(specs.len());
        for s in specs {
            let v = self.get(s.name).ok_or_else(|| RelationError::Coefficient {
                relation: self.relation.clone(),
                name: s.name.to_string(),
                message: "is missing".to_string(),
            })?;
            if !v.is_finite() {
                return Err(RelationError::Coefficient {
                    relation: self.relation.clone(),
                    name: s.name.to_string(),
                    message: format!("is not finite ({v})"),
                });
            }
            vals.push(v);
        }
        let mut levels = BTreeMap::new();
        if let Some(e) = effect {
            let prefix = format!("{}[", e.name);
            for (n, v) in &self.values {
                if let Some(s) = n.strip_prefix(&prefix).and_then(|r| r.strip_suffix(']')) {
                    levels.insert(s.to_string(), *v);
                }
            }
        }
        Ok((vals, levels))
    }
}

/// Every relation gaitfit knows, with published coefficients, in report order.
pub fn registry() -> Vec<Box<dyn Relation>> {
    vec![
        Box::new(RunSlV::published()),
        Box::new(RunTflightSf::published()),
        Box::new(RunTflightSf::published_continuous()),
        Box::new(WalkSlSf::published()),
        Box::new(WalkTdsSf::published()),
        Box::new(KbMu::published()),
    ]
}

/// The relation with id `id` (published coefficients).
pub fn by_id(id: &str) -> Result<Box<dyn Relation>, RelationError> {
    registry()
        .into_iter()
        .find(|r| r.id() == id)
        .ok_or_else(|| RelationError::UnknownRelation {
            id: id.to_string(),
            known: registry()
                .iter()
                .map(|r| r.id())
                .collect::<Vec<_>>()
                .join(", "),
        })
}

/// The relation of a fits file, with the refitted coefficients.
pub fn from_coefficients(set: &CoefficientSet) -> Result<Box<dyn Relation>, RelationError> {
    let r = by_id(&set.relation)?;
    let (vals, levels) = set.split(r.parameters(), r.subject_effect())?;
    let mut out = r.with_values(&vals, levels);
    out.set_fitted_range(FittedRange::of(set, out.inputs()));
    Ok(out)
}

/// Loads `fits/<id>.json` as a relation with the refitted coefficients.
pub fn load_fit(path: &Path) -> Result<Box<dyn Relation>, RelationError> {
    from_coefficients(&CoefficientSet::from_fit_file(path)?)
}

/// Checks that `set` is for relation `id` (used by the typed `from_fit_file` constructors).
pub(crate) fn expect_id(set: &CoefficientSet, id: &str, path: &Path) -> Result<(), RelationError> {
    if set.relation == id {
        Ok(())
    } else {
        Err(RelationError::Format {
            path: path.to_path_buf(),
            message: format!("is a fit of `{}`, not of `{id}`", set.relation),
        })
    }
}

/// The analytic gradient of the linear part (helper for relations whose breakpoints have no
/// useful derivative): `∂y/∂p_i = g_j` for linear `i`, 0 for breakpoints.
pub fn linear_gradient(r: &dyn Relation, p: &[f64], x: &[f64]) -> Vec<f64> {
    let mut g = [0.0; 16];
    let nl = r.n_linear();
    r.raw_basis(p, x, &mut g[..nl]);
    let mut out = vec![0.0; p.len()];
    let mut j = 0;
    for (i, s) in r.parameters().iter().enumerate() {
        if s.kind == ParamKind::Linear {
            out[i] = g[j];
            j += 1;
        }
    }
    out
}

/// Test support: a relation's [`SortedProfile::normal_equations`] against a pass over the rows
/// with [`Relation::basis`].
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
        let what = format!("{} p={p:?} free={free:?}", rel.id());
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
