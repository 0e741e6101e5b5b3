//! The fit record: what a fit of one relation found (coefficients, statistics, inference, data
//! provenance), as the fitting layer produces it. The export layer only serialises it
//! ([`crate::export::coeffs`]: JSON, TOML, Rust constants); the record and its serde form are
//! defined here so that fitting never depends on exporting.
use serde::{Deserialize, Serialize};
use std::collections::BTreeMap;

/// A t-test of a refit coefficient against its published value.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct TTestRecord {
    /// `(value − published) / std_error`.
    pub t: Option<f64>,
    /// Residual degrees of freedom.
    pub df: f64,
    /// Two-sided p-value.
    pub p_value: Option<f64>,
}

/// One coefficient of a fit.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct CoefficientRecord {
    /// Name (interface): `a`, `b`, `v_norm`, `level[S01]`, `q0`, …
    pub name: String,
    /// Unit, in the papers' terms.
    pub unit: String,
    /// Refit value (the published value when `held`).
    pub value: f64,
    /// Standard error (`null` when held, or for a breakpoint whose profile interval is open).
    pub std_error: Option<f64>,
    /// 95 % confidence interval `[lo, hi]`: t interval for linear coefficients, profile
    /// likelihood (F-based) interval for breakpoints; `None` bounds are open within the data.
    /// Written as the table `{ lo, hi }` (see the module docs), an open end as an absent key.
    #[serde(with = "bounds")]
    pub ci95: [Option<f64>; 2],
    /// The published value; `null` where the paper gives none (then there is no t-test).
    pub published: Option<f64>,
    /// t-test of `value` against `published`.
    pub t_test: Option<TTestRecord>,
    /// The standard error conditional on the breakpoint estimates, when `std_error` is the one
    /// with the breakpoints free (Gauss–Newton over all parameters).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub std_error_conditional: Option<f64>,
    /// How this coefficient's standard error and interval were computed.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub inference: Option<String>,
    /// Percentile 95 % interval `[lo, hi]` from the seeded bootstrap by subject
    /// (`--bootstrap N`); written as the table `{ lo, hi }` like `ci95`.
    #[serde(
        default,
        skip_serializing_if = "Option::is_none",
        with = "closed_bounds"
    )]
    pub ci95_bootstrap: Option<[f64; 2]>,
    /// Standard deviation of the bootstrap replicates (`--bootstrap N`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub se_bootstrap: Option<f64>,
    /// Why the coefficient was held at its published value instead of fitted.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub held: Option<String>,
    /// A warning about this coefficient (e.g. a level outside the paper's range).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub flag: Option<String>,
}

impl CoefficientRecord {
    /// A coefficient with its value only: no standard error, interval, published value, test,
    /// bootstrap or notes. The fit fills in what it computed (struct update syntax).
    pub fn new(name: impl Into<String>, unit: impl Into<String>, value: f64) -> Self {
        Self {
            name: name.into(),
            unit: unit.into(),
            value,
            std_error: None,
            ci95: [None, None],
            published: None,
            t_test: None,
            std_error_conditional: None,
            inference: None,
            ci95_bootstrap: None,
            se_bootstrap: None,
            held: None,
            flag: None,
        }
    }
}

/// r² and rmse of the published coefficients on the same rows.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct PublishedFit {
    /// r² (same definition as the refit's).
    pub r2: f64,
    /// Root mean square error.
    pub rmse: f64,
}

/// The range of one input covered by the rows used.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct RangeRecord {
    /// Input symbol.
    pub input: String,
    /// Unit.
    pub unit: String,
    /// Smallest value.
    pub lo: f64,
    /// Largest value.
    pub hi: f64,
}

/// One data file of a fit.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct DataFile {
    /// Path as given.
    pub path: String,
    /// SHA-256 of its bytes.
    pub sha256: String,
    /// Its rows.
    pub rows: usize,
}

/// Rows rejected for one reason.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct RejectionRecord {
    /// Why (e.g. `missing flight_time_s`).
    pub reason: String,
    /// How many rows.
    pub count: usize,
    /// The first few rows (`file: row N`, 1-based data rows).
    pub examples: Vec<String>,
}

/// Provenance of a fit's data.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct DataRecord {
    /// The data file (paths joined with `;` when several).
    pub path: String,
    /// SHA-256 of the data file; for several files, of the lines `<sha256>  <path>\n`.
    pub sha256: String,
    /// Rows used by this fit.
    pub rows_used: usize,
    /// Rows of this relation's gait that could not be used.
    pub rows_rejected: usize,
    /// Rows of the other gait (not this relation's; not counted as rejected).
    pub rows_other_gait: usize,
    /// The files.
    pub files: Vec<DataFile>,
    /// Rejected rows by reason.
    pub rejected: Vec<RejectionRecord>,
}

/// A derived quantity (e.g. the jump of the flight-time curve at k1).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct DerivedRecord {
    /// Name.
    pub name: String,
    /// Unit.
    pub unit: String,
    /// Value with the refit coefficients.
    pub value: f64,
    /// Value with the published coefficients.
    pub published: f64,
}

/// How a fit's standard errors, t-tests and intervals were computed.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct InferenceRecord {
    /// `iid`, `CR1` or `CR2`.
    pub method: String,
    /// What the method is, in one sentence.
    pub description: String,
    /// Subjects (clusters).
    pub clusters: usize,
    /// Degrees of freedom of the t-tests (`null` when they differ by coefficient: CR2).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub df: Option<f64>,
    /// How breakpoints enter the linear coefficients' standard errors.
    pub breakpoints: String,
    /// Which method gaitfit recommends for these data, and why.
    pub recommendation: String,
}

/// The confidence set of a breakpoint from its profile.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct BreakpointRecord {
    /// Breakpoint name.
    pub name: String,
    /// How the set was found.
    pub method: String,
    /// Admissible values examined: partitions of the rows (a breakpoint the model depends on
    /// only through which rows lie on each side) or grid values.
    pub admissible: usize,
    /// Of those, accepted at 95 %.
    pub accepted: usize,
    /// The set's disjoint pieces `{ lo, hi }` (an absent end: the piece reaches the end of the
    /// admissible range).
    #[serde(with = "piece_list")]
    pub pieces: Vec<[Option<f64>; 2]>,
    /// Local minima of the profile over the admissible range.
    pub local_minima: usize,
    /// Whether the profile is regular (one piece inside the range, one local minimum in it,
    /// a continuous model): only then has the breakpoint a standard error and a t-test.
    pub regular: bool,
    /// Why not, when not.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub irregular_because: Option<String>,
    /// The design effect the likelihood ratio was divided by (clustered inference).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub design_effect: Option<f64>,
    /// The uncorrected F set's pieces (rows treated as independent), for comparison.
    #[serde(default, skip_serializing_if = "Vec::is_empty", with = "piece_list")]
    pub pieces_iid: Vec<[Option<f64>; 2]>,
}

/// Serde for a list of `[lo, hi]` pieces as `{ lo, hi }` tables (like `ci95`).
mod piece_list {
    use serde::{Deserialize, Deserializer, Serialize, Serializer};

    #[derive(Serialize, Deserialize)]
    struct Piece {
        #[serde(default, skip_serializing_if = "Option::is_none")]
        lo: Option<f64>,
        #[serde(default, skip_serializing_if = "Option::is_none")]
        hi: Option<f64>,
    }

    pub fn serialize<S: Serializer>(v: &[[Option<f64>; 2]], s: S) -> Result<S::Ok, S::Error> {
        v.iter()
            .map(|p| Piece { lo: p[0], hi: p[1] })
            .collect::<Vec<_>>()
            .serialize(s)
    }

    pub fn deserialize<'de, D: Deserializer<'de>>(d: D) -> Result<Vec<[Option<f64>; 2]>, D::Error> {
        Ok(Vec::<Piece>::deserialize(d)?
            .into_iter()
            .map(|p| [p.lo, p.hi])
            .collect())
    }
}

/// The bounded least-squares solves of a fit (relations with bounded coefficients).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct BoundedRecord {
    /// The solver.
    pub solver: String,
    /// Bounded solves made (the fit, leave-one-subject-out folds, bootstrap replicates).
    pub solves: usize,
    /// Of those, the ones whose KKT conditions were verified at the solution.
    pub converged: usize,
    /// Most active-set iterations any solve took.
    pub max_iterations: usize,
}

/// The Huber robust refit (`--robust`).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct RobustRecord {
    /// Huber tuning constant.
    pub k: f64,
    /// Robust residual scale.
    pub scale: f64,
    /// IRLS iterations.
    pub iterations: usize,
    /// Whether IRLS converged.
    pub converged: bool,
    /// Rows down-weighted (robust weight < 1).
    pub rows_downweighted: usize,
    /// How the robust standard errors were computed.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub cov: Option<String>,
    /// Coefficients (breakpoints held at the least-squares estimate).
    pub coefficients: Vec<CoefficientRecord>,
}

/// A random-intercept mixed model fitted by REML (`--random-subject`): the fixed effects with
/// their model-based standard errors, and the two variance components.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct MixedRecord {
    /// The model and how it was fitted.
    pub method: String,
    /// Fixed effects: value, standard error from `σ̂_e² (XᵀV̂⁻¹X)⁻¹`, normal 95 % interval.
    pub coefficients: Vec<MixedCoefficient>,
    /// Between-subject standard deviation `σ̂_u` (response unit).
    pub subject_sd: f64,
    /// Within-subject (residual) standard deviation `σ̂_e`.
    pub residual_sd: f64,
    /// Intraclass correlation `σ̂_u² / (σ̂_u² + σ̂_e²)`.
    pub icc: f64,
    /// Restricted log-likelihood at the estimate.
    pub reml_log_likelihood: f64,
}

/// A fixed effect of a [`MixedRecord`].
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct MixedCoefficient {
    /// Name (as in [`FitRecord::coefficients`]).
    pub name: String,
    /// Unit.
    pub unit: String,
    /// Estimate.
    pub value: f64,
    /// Standard error.
    pub std_error: f64,
    /// Normal (z) 95 % interval `[lo, hi]`.
    pub ci95: [f64; 2],
}

/// The bootstrap settings and outcome.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct BootstrapRecord {
    /// Replicates requested.
    pub n: usize,
    /// Seed.
    pub seed: u64,
    /// Replicates that failed (e.g. too few distinct values after resampling).
    pub failed: usize,
    /// What was resampled.
    pub unit: String,
}

/// The wild cluster bootstrap-t (see [`crate::fit::wild`]): percentile-t intervals.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct WildRecord {
    /// What was bootstrapped and how the interval is formed.
    pub method: String,
    /// The weight distribution.
    pub weights: String,
    /// Bootstrap samples evaluated (6^G when every weight pattern was enumerated).
    pub samples: u64,
    /// True when every weight pattern was evaluated: exact quantiles, no Monte Carlo error.
    pub enumerated: bool,
    /// Seed of the draws (absent when enumerated).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub seed: Option<u64>,
    /// Per free coefficient.
    pub coefficients: Vec<WildCoefficient>,
}

/// One coefficient's wild cluster bootstrap-t interval.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct WildCoefficient {
    /// Coefficient name (as in `coefficients`).
    pub name: String,
    /// The percentile-t 95 % interval `θ̂ − q*·SE_CR1` (`{ lo, hi }`).
    #[serde(default, with = "closed_bounds")]
    pub ci95: Option<[f64; 2]>,
    /// The bootstrap t quantiles `q*_{0.025}`, `q*_{0.975}`.
    pub t_quantiles: [f64; 2],
    /// The CR1 standard error the quantiles scale (G/(G−1)·(n−1)/(n−p), as statsmodels).
    pub se_cr1: f64,
}

/// Everything one fit produced (written to `fits/<id>.json` and `.toml`).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct FitRecord {
    /// Relation id.
    pub relation: String,
    /// Title.
    pub title: String,
    /// Paper and equation.
    pub citation: String,
    /// The formula (papers' units).
    pub equation: String,
    /// Units of the response, the inputs and every coefficient.
    pub units: BTreeMap<String, String>,
    /// Rows used.
    pub n: usize,
    /// Subjects among the rows used.
    pub n_subjects: usize,
    /// Coefficients: the global ones in the relation's order, then per-subject levels.
    pub coefficients: Vec<CoefficientRecord>,
    /// Coefficient of determination (see `r2_definition`).
    pub r2: f64,
    /// The centred r², 1 − RSS/Σw(y − ȳ)², also for fits through the origin (what
    /// `gaitfit check` gates on).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub r2_centred: Option<f64>,
    /// How r² is defined here (centred, or uncentred for fits through the origin).
    pub r2_definition: String,
    /// Adjusted r².
    pub adj_r2: f64,
    /// √(RSS/n).
    pub rmse: f64,
    /// RSS/(n − p), p counting fitted linear coefficients and breakpoints.
    pub residual_mean_square: f64,
    /// Akaike information criterion (Gaussian likelihood, σ counted).
    pub aic: f64,
    /// Bayesian information criterion.
    pub bic: f64,
    /// Leave-one-out (PRESS) rmse, breakpoints held at their estimate.
    pub loo_rmse: f64,
    /// Leave-one-subject-out rmse (held-out subjects predicted with level 0), or `null`.
    pub loso_rmse: Option<f64>,
    /// Why `loso_rmse` is null, or how it was computed.
    pub loso_note: String,
    /// The published coefficients on the same rows.
    pub published_fit: PublishedFit,
    /// The input range the rows covered.
    pub valid_range: Vec<RangeRecord>,
    /// What predictions do outside `valid_range`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub outside_range: Option<String>,
    /// How standard errors, t-tests and intervals were computed.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub inference: Option<InferenceRecord>,
    /// Breakpoints' confidence sets.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub breakpoints: Vec<BreakpointRecord>,
    /// Bounded least-squares solves and their convergence.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub bounded: Option<BoundedRecord>,
    /// Where the rows came from.
    pub data: DataRecord,
    /// gaitfit's version.
    pub gaitfit_version: String,
    /// Derived quantities, refit vs published.
    pub derived: Vec<DerivedRecord>,
    /// Weights column (`--weights`), if any.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub weights: Option<String>,
    /// Huber refit (`--robust`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub robust: Option<RobustRecord>,
    /// Bootstrap (`--bootstrap N --seed S`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub bootstrap: Option<BootstrapRecord>,
    /// Random-intercept REML model (`--random-subject`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub random_subject: Option<MixedRecord>,
    /// Wild cluster bootstrap-t intervals (with `--bootstrap N`, for fits linear in every free
    /// coefficient: no breakpoint, bound, per-subject column or weights).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub wild_bootstrap: Option<WildRecord>,
    /// Notes a reader should see (held coefficients, flagged subjects, r² definition).
    pub notes: Vec<String>,
}

impl FitRecord {
    /// The coefficient named `name`.
    pub fn coefficient(&self, name: &str) -> Option<&CoefficientRecord> {
        self.coefficients.iter().find(|c| c.name == name)
    }
}

/// The interval table `{ lo, hi }` of [`CoefficientRecord::ci95`]: an open end is `null` in
/// JSON and an absent key in TOML; the earlier JSON array form `[lo, hi]` is read too.
mod bounds {
    use serde::{Deserialize, Deserializer, Serialize, Serializer};

    #[derive(Serialize, Deserialize)]
    pub(super) struct Bounds {
        #[serde(default)]
        pub(super) lo: Option<f64>,
        #[serde(default)]
        pub(super) hi: Option<f64>,
    }

    #[derive(Deserialize)]
    #[serde(untagged)]
    pub(super) enum Either {
        Table(Bounds),
        Array([Option<f64>; 2]),
    }

    impl Either {
        pub(super) fn pair(self) -> [Option<f64>; 2] {
            match self {
                Either::Table(b) => [b.lo, b.hi],
                Either::Array(a) => a,
            }
        }
    }

    pub fn serialize<S: Serializer>(v: &[Option<f64>; 2], s: S) -> Result<S::Ok, S::Error> {
        Bounds { lo: v[0], hi: v[1] }.serialize(s)
    }

    pub fn deserialize<'de, D: Deserializer<'de>>(d: D) -> Result<[Option<f64>; 2], D::Error> {
        Ok(Either::deserialize(d)?.pair())
    }
}

/// [`CoefficientRecord::ci95_bootstrap`]: a closed interval, the same `{ lo, hi }` table.
mod closed_bounds {
    use super::bounds::{Bounds, Either};
    use serde::{de::Error, Deserialize, Deserializer, Serialize, Serializer};

    pub fn serialize<S: Serializer>(v: &Option<[f64; 2]>, s: S) -> Result<S::Ok, S::Error> {
        v.map(|[lo, hi]| Bounds {
            lo: Some(lo),
            hi: Some(hi),
        })
        .serialize(s)
    }

    pub fn deserialize<'de, D: Deserializer<'de>>(d: D) -> Result<Option<[f64; 2]>, D::Error> {
        match Option::<Either>::deserialize(d)?.map(Either::pair) {
            None => Ok(None),
            Some([Some(lo), Some(hi)]) => Ok(Some([lo, hi])),
            Some(_) => Err(D::Error::custom("a bootstrap interval has both ends")),
        }
    }
}
