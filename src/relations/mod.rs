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
//! # Specification and fitted values
//! A [`Relation`] is the specification only: its [`Card`] (id, formula, variables, outputs,
//! parameters with their published values, domain), `observe` (a row → an [`Observation`] per
//! output) and the formula (`raw_basis`, `predict_with`). Coefficient values live in a
//! [`Fitted`] (values, per-subject levels, fitted range, `predict_checked`): published
//! ([`Fitted::published`]), refitted by `gaitfit::fit::pipeline`, or read by [`load_fit`]. How
//! the fit treats the parameters (plan, basis, breakpoint profiles) is `gaitfit::fit::forms`;
//! the relations import nothing from fit or the generators.
//!
//! # Using a relation (generators)
//! Every type has `published()` (the papers' coefficients), typed evaluation methods in the
//! papers' units (e.g. [`RunSlV::step_length`]) at the coefficients it carries, and
//! `from_fit_file("fits/<id>.json")` to use coefficients refitted by `gaitfit fit`.
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
//! One new file implementing [`Relation`] (its [`Card`], `observe` converting a row's
//! [`Quantity`]s to the papers' units, and `raw_basis` — the model must be linear in its
//! [`ParamKind::Linear`] parameters once the [`ParamKind::Breakpoint`] ones are fixed, true of
//! all the papers' relations), plus one line in the `relations!` list below (module, type,
//! constructor): the registry, the CLI's ids and help and the generic fit routine
//! (`gaitfit::fit::pipeline`: statistics, tables, plots) follow from it. Breakpoints are held at
//! their published values unless the relation also gets a fit form in `gaitfit::fit::forms`
//! (how they are profiled).
/// Declares the relation modules and the registry in one list: each line is a module, its type
/// (re-exported here) and the relations it registers, in report order.
macro_rules! relations {
    ($($(#[$doc:meta])* $module:ident :: $ty:ident => [$($make:expr),+ $(,)?]),+ $(,)?) => {
        $($(#[$doc])* pub mod $module; pub use $module::$ty;)+

        /// Every relation gaitfit knows, in report order: the single list the fit, the CLI
        /// (ids and help) and the reports read.
        pub fn registry() -> Vec<Box<dyn Relation>> {
            vec![$($(Box::new($make)),+),+]
        }
    };
}

relations! {
    run_sl_v::RunSlV => [RunSlV::published()],
    run_tflight_sf::RunTflightSf => [RunTflightSf::published(), RunTflightSf::published_continuous()],
    walk_sl_sf::WalkSlSf => [WalkSlSf::published()],
    walk_tds_sf::WalkTdsSf => [WalkTdsSf::published()],
    kb_mu::KbMu => [KbMu::published()],
}

pub use run_tflight_sf::Continuity;

use crate::gait::Gait;
use crate::ingest::trials::FieldValues;
use crate::units::Quantity;
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

/// The inputs of one prediction or observation, in the papers' units, with the output they
/// belong to: `values` in [`Card::inputs`] order (unused slots 0), `output` the index of the
/// relation's output ([`Card::outputs`]; 0 for single-output relations — `kb-mu` has four, one
/// per μ-function). Dereferences to the input values (`x[0]` is the first input).
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct Inputs {
    /// Input values, in [`Card::inputs`] order; unused slots are 0.
    pub values: [f64; MAX_INPUTS],
    /// Which output of the relation (index into [`Card::outputs`]).
    pub output: usize,
}

impl Inputs {
    /// Inputs of output 0 (single-output relations): the first `x.len()` values (≤
    /// [`MAX_INPUTS`]), the rest 0.
    pub fn new(x: &[f64]) -> Inputs {
        let mut values = [0.0; MAX_INPUTS];
        for (v, &s) in values.iter_mut().zip(x) {
            *v = s;
        }
        Inputs { values, output: 0 }
    }
    /// The same inputs for output `k`.
    pub fn of_output(self, k: usize) -> Inputs {
        Inputs { output: k, ..self }
    }
}

impl std::ops::Deref for Inputs {
    type Target = [f64];
    fn deref(&self) -> &[f64] {
        &self.values
    }
}

/// One row reduced to what a relation uses: inputs and response in the papers' units.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Observation {
    /// Inputs (with the output they belong to).
    pub x: Inputs,
    /// Response.
    pub y: f64,
}

/// One output of a relation: a row gives one observation per output (`kb-mu`: one per μ).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Output {
    /// Name (for reports: per-output statistics are named after it).
    pub name: &'static str,
    /// What it is, for a plot panel's label.
    pub label: &'static str,
}

/// What a relation is, as its paper states it: identity, formula, variables, parameters with
/// their published values, domain. Static data; [`Relation::card`] gives it.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Card {
    /// The relation id (`run-sl-v`, …): interface, used for file names.
    pub id: &'static str,
    /// One-line title.
    pub title: &'static str,
    /// The paper and equation.
    pub citation: Citation,
    /// The formula in the papers' units, as text.
    pub equation: &'static str,
    /// The response variable.
    pub response: Variable,
    /// The input variables (the first is the one plots use as abscissa).
    pub inputs: &'static [Variable],
    /// The outputs a row gives (at least one).
    pub outputs: &'static [Output],
    /// The gait whose rows this relation uses.
    pub gait: Gait,
    /// The row quantities it needs.
    pub needs: &'static [Quantity],
    /// The global parameters (coefficient vectors `p` hold them in this order).
    pub parameters: &'static [ParameterSpec],
    /// The per-subject effect, if the relation has one.
    pub subject_effect: Option<SubjectEffect>,
    /// True when the model has an intercept (r² is then centred; otherwise uncentred, as NIST
    /// defines it for regressions through the origin).
    pub has_intercept: bool,
    /// The input domain of the published relation.
    pub domain: Domain,
}

impl Card {
    /// Number of linear parameters.
    pub fn n_linear(&self) -> usize {
        self.parameters
            .iter()
            .filter(|s| s.kind == ParamKind::Linear)
            .count()
    }
    /// The published coefficients, in [`Card::parameters`] order.
    pub fn published_values(&self) -> Vec<f64> {
        self.parameters.iter().map(|s| s.published).collect()
    }
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
/// [`Relation::observe`] asks of a row for each quantity it needs ([`Card::needs`]).
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

/// A published gait relation, the specification (see the module docs): what the paper states
/// ([`Relation::card`]), how a row is observed, and the formula. Coefficient values live
/// elsewhere: in a [`Fitted`] (published, or read from a fits file) or in the typed structs the
/// generators use; how the fit treats the parameters is `gaitfit::fit::forms`.
///
/// Coefficient vectors (`p`) hold the global parameters in [`Card::parameters`] order;
/// per-subject effects are passed separately as an additive offset.
pub trait Relation: Send + Sync + std::fmt::Debug {
    /// What the relation is (static).
    fn card(&self) -> &'static Card;

    /// Reduces a row (SI) to the observation of output `output` (< `card().outputs.len()`),
    /// inputs and response in the papers' units. A row is rejected only when none of its
    /// outputs is usable.
    fn observe(&self, row: &FieldValues, output: usize) -> Result<Observation, Rejection>;

    /// The derivatives of the prediction with respect to each [`ParamKind::Linear`] parameter
    /// (in order), at the breakpoints in `p`: the model is `Σ_j p_lin[j] · g[j]`.
    fn raw_basis(&self, p: &[f64], x: &Inputs, g: &mut [f64]);

    /// Prediction with coefficients `p` and a per-subject offset on the
    /// [`SubjectEffect::on`] parameter.
    fn predict_with(&self, p: &[f64], subject_offset: f64, x: &Inputs) -> f64 {
        let card = self.card();
        let mut g = [0.0; 16];
        let nl = card.n_linear();
        self.raw_basis(p, x, &mut g[..nl]);
        let on = card.subject_effect.map(|e| e.on);
        let mut y = 0.0;
        let mut j = 0;
        for (i, s) in card.parameters.iter().enumerate() {
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

    /// Analytic gradient of the prediction with respect to all global parameters, when
    /// available (`None`: the caller differentiates numerically).
    fn gradient(&self, _p: &[f64], _x: &Inputs) -> Option<Vec<f64>> {
        None
    }

    /// Derived quantities worth reporting for a coefficient vector (name, value, unit), e.g.
    /// the jump of the flight-time curve at `k1`.
    fn derived(&self, _p: &[f64]) -> Vec<(String, f64, &'static str)> {
        Vec::new()
    }

    /// The allowed range of parameter `i` (unbounded by default). Where a bound is finite the
    /// pipeline enforces it with argmin's bounded least squares and reports an active bound.
    fn bounds(&self, i: usize) -> (f64, f64) {
        let _ = i;
        (f64::NEG_INFINITY, f64::INFINITY)
    }
}

/// A relation with coefficient values: published, refitted by the pipeline, or read from a
/// fits file (with the per-subject levels and the fitted input range).
#[derive(Debug)]
pub struct Fitted {
    relation: Box<dyn Relation>,
    values: Vec<f64>,
    levels: BTreeMap<String, f64>,
    range: FittedRange,
}

impl Fitted {
    /// `relation` with coefficient `values` (in [`Card::parameters`] order), per-subject
    /// `levels` and the fitted input `range`.
    pub fn new(
        relation: Box<dyn Relation>,
        values: Vec<f64>,
        levels: BTreeMap<String, f64>,
        range: FittedRange,
    ) -> Fitted {
        Fitted {
            relation,
            values,
            levels,
            range,
        }
    }
    /// `relation` with its published coefficients.
    pub fn published(relation: Box<dyn Relation>) -> Fitted {
        let values = relation.card().published_values();
        Fitted::new(relation, values, BTreeMap::new(), FittedRange::default())
    }
    /// The relation.
    pub fn relation(&self) -> &dyn Relation {
        self.relation.as_ref()
    }
    /// What the relation is.
    pub fn card(&self) -> &'static Card {
        self.relation.card()
    }
    /// The coefficients, in [`Card::parameters`] order.
    pub fn values(&self) -> &[f64] {
        &self.values
    }
    /// Per-subject effects (empty for published coefficients).
    pub fn subject_levels(&self) -> &BTreeMap<String, f64> {
        &self.levels
    }
    /// The input range the coefficients were fitted on (empty for the published coefficients
    /// and for fits built in memory).
    pub fn fitted_range(&self) -> FittedRange {
        self.range
    }
    /// Sets the fitted input range.
    pub fn set_fitted_range(&mut self, range: FittedRange) {
        self.range = range;
    }
    /// Prediction for an average subject (offset 0).
    pub fn predict(&self, x: &Inputs) -> f64 {
        self.relation.predict_with(&self.values, 0.0, x)
    }
    /// Prediction with a per-subject offset on the [`SubjectEffect::on`] parameter.
    pub fn predict_with_offset(&self, subject_offset: f64, x: &Inputs) -> f64 {
        self.relation.predict_with(&self.values, subject_offset, x)
    }
    /// [`Fitted::predict`] with the rule of [`FittedRange`]: whether `x` lies inside the
    /// fitted range, and outside it the boundary value held (inputs clamped to `[lo, hi]`).
    pub fn predict_checked(&self, x: &Inputs) -> Prediction {
        let at = Inputs {
            values: self.range.hold(x),
            output: x.output,
        };
        Prediction {
            value: self.predict(&at),
            inside: self.range.contains(x),
            at: at.values,
        }
    }
    /// Derived quantities at these coefficients ([`Relation::derived`]).
    pub fn derived(&self) -> Vec<(String, f64, &'static str)> {
        self.relation.derived(&self.values)
    }
}

/// The input range a relation's coefficients were fitted on (a fits file's `valid_range`),
/// one `[lo, hi]` per input in [`Card::inputs`] order (`None`: not recorded, e.g. the
/// published coefficients).
///
/// # Beyond the fitted range (the rule every prediction follows)
/// [`Fitted::predict_checked`] reports whether the inputs lie inside the range and, outside
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

/// A prediction with where it was evaluated ([`Fitted::predict_checked`]).
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
    before evaluating: Fitted::predict_checked); the generators' polynomial pieces of degree \
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

/// The ids of every relation, in report order.
pub fn ids() -> Vec<&'static str> {
    registry().iter().map(|r| r.card().id).collect()
}

/// The relation with id `id` (published coefficients).
pub fn by_id(id: &str) -> Result<Box<dyn Relation>, RelationError> {
    registry()
        .into_iter()
        .find(|r| r.card().id == id)
        .ok_or_else(|| RelationError::UnknownRelation {
            id: id.to_string(),
            known: ids().join(", "),
        })
}

/// The relation of a fits file, with the refitted coefficients.
pub fn from_coefficients(set: &CoefficientSet) -> Result<Fitted, RelationError> {
    let r = by_id(&set.relation)?;
    let card = r.card();
    let (vals, levels) = set.split(card.parameters, card.subject_effect)?;
    let range = FittedRange::of(set, card.inputs);
    Ok(Fitted::new(r, vals, levels, range))
}

/// Loads `fits/<id>.json` as a relation with the refitted coefficients.
pub fn load_fit(path: &Path) -> Result<Fitted, RelationError> {
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
pub fn linear_gradient(r: &dyn Relation, p: &[f64], x: &Inputs) -> Vec<f64> {
    let mut g = [0.0; 16];
    let nl = r.card().n_linear();
    r.raw_basis(p, x, &mut g[..nl]);
    let mut out = vec![0.0; p.len()];
    let mut j = 0;
    for (i, s) in r.card().parameters.iter().enumerate() {
        if s.kind == ParamKind::Linear {
            out[i] = g[j];
            j += 1;
        }
    }
    out
}
