//! Coefficient tables: the `fits/<id>.json` / `.toml` records `gaitfit fit` writes, and their
//! exports for other programs (Rust module of `pub const`s, JSON, TOML, CSV).
//!
//! The JSON keys of [`FitRecord`] are interface (issue 3): `relation`, `equation`, `units`, `n`,
//! `coefficients` (`name`, `value`, `std_error`, `ci95`, `published`, …), `r2`, `adj_r2`, `rmse`,
//! `residual_mean_square`, `aic`, `bic`, `loo_rmse`, `loso_rmse`, `published_fit`,
//! `valid_range`, `data`, `gaitfit_version`. `null` appears where a number does not exist (a
//! standard error of a coefficient held at its published value, an open confidence bound, a
//! leave-one-subject-out error with fewer than 3 subjects); TOML has no null, so those keys are
//! omitted there and open bounds are written as the string `"open"`.
use super::ExportError;
use crate::fsio::{write_atomic_bytes, FsError};
use serde::{Deserialize, Serialize};
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

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
    /// likelihood (F-based) interval for breakpoints; `null` bounds are open within the data.
    pub ci95: [Option<f64>; 2],
    /// The published value (0 for per-subject levels).
    pub published: f64,
    /// t-test of `value` against `published`.
    pub t_test: Option<TTestRecord>,
    /// Percentile 95 % interval from the seeded bootstrap by subject (`--bootstrap N`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub ci95_bootstrap: Option<[f64; 2]>,
    /// Why the coefficient was held at its published value instead of fitted.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub held: Option<String>,
    /// A warning about this coefficient (e.g. a level outside the paper's range).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub flag: Option<String>,
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
    /// Coefficients (breakpoints held at the least-squares estimate).
    pub coefficients: Vec<CoefficientRecord>,
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
    /// Notes a reader should see (held coefficients, flagged subjects, r² definition).
    pub notes: Vec<String>,
}

impl FitRecord {
    /// The coefficient named `name`.
    pub fn coefficient(&self, name: &str) -> Option<&CoefficientRecord> {
        self.coefficients.iter().find(|c| c.name == name)
    }
    /// As pretty JSON.
    pub fn to_json(&self) -> Result<String, ExportError> {
        serde_json::to_string_pretty(self).map_err(|e| ExportError::Format {
            path: format!("{}.json", self.relation),
            message: e.to_string(),
        })
    }
    /// As TOML (nulls omitted, open bounds as `"open"`).
    pub fn to_toml(&self) -> Result<String, ExportError> {
        let v = serde_json::to_value(self).map_err(|e| ExportError::Format {
            path: format!("{}.toml", self.relation),
            message: e.to_string(),
        })?;
        let t = json_to_toml(&v).ok_or_else(|| ExportError::Format {
            path: format!("{}.toml", self.relation),
            message: "cannot represent the record in TOML".to_string(),
        })?;
        toml::to_string_pretty(&t).map_err(|e| ExportError::Format {
            path: format!("{}.toml", self.relation),
            message: e.to_string(),
        })
    }
}

fn json_to_toml(v: &serde_json::Value) -> Option<toml::Value> {
    use serde_json::Value as J;
    Some(match v {
        J::Null => return None,
        J::Bool(b) => toml::Value::Boolean(*b),
        J::Number(n) => {
            if let Some(i) = n.as_i64() {
                toml::Value::Integer(i)
            } else {
                toml::Value::Float(n.as_f64()?)
            }
        }
        J::String(s) => toml::Value::String(s.clone()),
        J::Array(a) => toml::Value::Array(
            a.iter()
                .map(|x| json_to_toml(x).unwrap_or_else(|| toml::Value::String("open".into())))
                .collect(),
        ),
        J::Object(o) => {
            let mut t = toml::map::Map::new();
            for (k, x) in o {
                if let Some(x) = json_to_toml(x) {
                    t.insert(k.clone(), x);
                }
            }
            toml::Value::Table(t)
        }
    })
}

/// Writes `dir/<id>.json` and `dir/<id>.toml` atomically (each file is complete or untouched).
pub fn write_fit_files(dir: &Path, rec: &FitRecord) -> Result<Vec<PathBuf>, ExportError> {
    let json = rec.to_json()?;
    let toml = rec.to_toml()?;
    let pj = dir.join(format!("{}.json", rec.relation));
    let pt = dir.join(format!("{}.toml", rec.relation));
    write_atomic_bytes(&pj, format!("{json}\n").as_bytes())?;
    write_atomic_bytes(&pt, toml.as_bytes())?;
    Ok(vec![pj, pt])
}

/// Reads one `fits/<id>.json`.
pub fn read_fit_record(path: &Path) -> Result<FitRecord, ExportError> {
    let text = std::fs::read_to_string(path).map_err(|e| FsError::io(path, e))?;
    serde_json::from_str(&text).map_err(|e| ExportError::Format {
        path: path.display().to_string(),
        message: format!("not a gaitfit fits file: {e}"),
    })
}

/// Reads every `*.json` fit record in `dir`, sorted by file name.
pub fn read_fits_dir(dir: &Path) -> Result<Vec<(PathBuf, FitRecord)>, ExportError> {
    let rd = std::fs::read_dir(dir).map_err(|e| FsError::io(dir, e))?;
    let mut paths: Vec<PathBuf> = rd
        .filter_map(|e| e.ok().map(|e| e.path()))
        .filter(|p| p.extension().is_some_and(|x| x == "json"))
        .collect();
    paths.sort();
    paths
        .into_iter()
        .map(|p| read_fit_record(&p).map(|r| (p, r)))
        .collect()
}

/// Export formats of `gaitfit export`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, clap::ValueEnum)]
pub enum ExportFormat {
    /// A self-contained Rust module of documented `pub const`s.
    Rust,
    /// One JSON array of the fit records.
    Json,
    /// One TOML document with a table per relation.
    Toml,
    /// One CSV row per coefficient.
    Csv,
}

fn rust_ident(relation: &str, name: &str) -> String {
    let mut s = String::new();
    for c in format!("{relation}_{name}").chars() {
        if c.is_ascii_alphanumeric() {
            s.push(c.to_ascii_uppercase());
        } else if !s.ends_with('_') {
            s.push('_');
        }
    }
    s.trim_end_matches('_').to_string()
}

fn fmt_opt(v: Option<f64>) -> String {
    v.map_or("open".to_string(), |v| format!("{v:e}"))
}

/// Renders fit records in `format`.
pub fn export(records: &[FitRecord], format: ExportFormat) -> Result<String, ExportError> {
    match format {
        ExportFormat::Json => {
            serde_json::to_string_pretty(records).map_err(|e| ExportError::Format {
                path: "export.json".into(),
                message: e.to_string(),
            })
        }
        ExportFormat::Toml => {
            let mut out = String::new();
            let mut root = toml::map::Map::new();
            for r in records {
                let v: toml::Value =
                    toml::from_str(&r.to_toml()?).map_err(|e| ExportError::Format {
                        path: "export.toml".into(),
                        message: e.to_string(),
                    })?;
                root.insert(r.relation.clone(), v);
            }
            out.push_str(
                &toml::to_string_pretty(&toml::Value::Table(root)).map_err(|e| {
                    ExportError::Format {
                        path: "export.toml".into(),
                        message: e.to_string(),
                    }
                })?,
            );
            Ok(out)
        }
        ExportFormat::Csv => {
            let mut w = csv::Writer::from_writer(Vec::new());
            let fmt = |e: csv::Error| ExportError::Format {
                path: "export.csv".into(),
                message: e.to_string(),
            };
            w.write_record([
                "relation",
                "coefficient",
                "unit",
                "value",
                "std_error",
                "ci95_lo",
                "ci95_hi",
                "published",
                "held",
                "n",
                "r2",
                "rmse",
                "data_sha256",
            ])
            .map_err(fmt)?;
            for r in records {
                for c in &r.coefficients {
                    w.write_record([
                        r.relation.clone(),
                        c.name.clone(),
                        c.unit.clone(),
                        format!("{}", c.value),
                        c.std_error.map(|v| v.to_string()).unwrap_or_default(),
                        c.ci95[0].map(|v| v.to_string()).unwrap_or_default(),
                        c.ci95[1].map(|v| v.to_string()).unwrap_or_default(),
                        format!("{}", c.published),
                        c.held.is_some().to_string(),
                        r.n.to_string(),
                        r.r2.to_string(),
                        r.rmse.to_string(),
                        r.data.sha256.clone(),
                    ])
                    .map_err(fmt)?;
                }
            }
            let bytes = w.into_inner().map_err(|e| ExportError::Format {
                path: "export.csv".into(),
                message: e.to_string(),
            })?;
            String::from_utf8(bytes).map_err(|e| ExportError::Format {
                path: "export.csv".into(),
                message: e.to_string(),
            })
        }
        ExportFormat::Rust => {
            let mut s = String::new();
            s.push_str("//! Gait relation coefficients refitted by gaitfit (generated by `gaitfit export --format rust`; do not edit).\n");
            s.push_str("//!\n//! Units are the papers' (m, m/min, steps/min, s). Each constant's doc gives the 95 % CI, n, r²\n//! and the SHA-256 of the data it was fitted on.\n");
            s.push_str("#![allow(dead_code)]\n\n");
            for r in records {
                s.push_str(&format!(
                    "// {} — {} ({}); n = {}, r² = {:.6} ({}), rmse = {:e}; data sha256 {}\n",
                    r.relation,
                    r.title,
                    r.citation,
                    r.n,
                    r.r2,
                    r.r2_definition,
                    r.rmse,
                    r.data.sha256
                ));
                for c in &r.coefficients {
                    let ident = rust_ident(&r.relation, &c.name);
                    s.push_str(&format!(
                        "/// `{}` of `{}` ({}): {:e}; 95 % CI [{}, {}]; published {:e}; n = {}; r² = {:.6}; data sha256 {}.{}\n",
                        c.name,
                        r.relation,
                        c.unit.replace('`', "'"),
                        c.value,
                        fmt_opt(c.ci95[0]),
                        fmt_opt(c.ci95[1]),
                        c.published,
                        r.n,
                        r.r2,
                        r.data.sha256,
                        c.held
                            .as_ref()
                            .map(|h| format!(" Held: {}.", h.replace('\n', " ")))
                            .unwrap_or_default()
                    ));
                    s.push_str(&format!("pub const {ident}: f64 = {:?};\n", c.value));
                }
                s.push('\n');
            }
            Ok(s)
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn identifiers_are_valid_rust() {
        assert_eq!(rust_ident("run-sl-v", "level[S 01]"), "RUN_SL_V_LEVEL_S_01");
        assert_eq!(rust_ident("walk-sl-sf", "k"), "WALK_SL_SF_K");
    }
}
