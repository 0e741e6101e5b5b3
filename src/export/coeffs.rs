//! Coefficient tables: the `fits/<id>.json` / `.toml` records `gaitfit fit` writes, and their
//! exports for other programs (Rust constants or a crate, JSON, TOML, CSV).
//!
//! The JSON keys of [`FitRecord`] are interface (issue 3): `relation`, `equation`, `units`, `n`,
//! `coefficients` (`name`, `value`, `std_error`, `ci95`, `published`, …), `r2`, `adj_r2`, `rmse`,
//! `residual_mean_square`, `aic`, `bic`, `loo_rmse`, `loso_rmse`, `published_fit`,
//! `valid_range`, `data`, `gaitfit_version`.
//!
//! # JSON and TOML hold the same record
//! Both files are written from one [`FitRecord`] and read back through it (serde), with the same
//! keys, nesting and order, so a typed reader of one reads the other (Python: `json.load` and
//! `tomllib.load` give equal dictionaries once JSON's `null`s are dropped).
//! - **A number that does not exist is an absent key**, or `null` in JSON only (TOML has no
//!   null): a standard error of a coefficient held at its published value, a t-test without
//!   one, a leave-one-subject-out error with fewer than 3 subjects, and an **open end of an
//!   interval**. Intervals are tables, never arrays with holes:
//!   `ci95 = { lo = 0.173, hi = 0.203 }`; a profile-likelihood interval open above within the
//!   data is `ci95 = { lo = 0.173 }` in TOML and `"ci95": {"lo": 0.173, "hi": null}` in JSON.
//!   (Readers also accept the earlier JSON form `"ci95": [lo, hi]` with `null` for open ends.)
//! - **Floats are written as the shortest decimal that reads back to the same `f64`** (both
//!   writers), and gaitfit reads them back exactly (`serde_json`'s `float_roundtrip`), so every
//!   value is bit-identical across the JSON, the TOML and the Rust export.
use super::ExportError;
use crate::fsio::{write_atomic_bytes, FsError};
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

pub use crate::fit::record::*;

// Serialising the fitting layer's record (defined in `crate::fit::record`).
impl FitRecord {
    /// As pretty JSON.
    pub fn to_json(&self) -> Result<String, ExportError> {
        serde_json::to_string_pretty(self).map_err(|e| ExportError::Format {
            path: format!("{}.json", self.relation),
            message: e.to_string(),
        })
    }
    /// As TOML: the same keys in the same order as the JSON, absent where the JSON has `null`.
    pub fn to_toml(&self) -> Result<String, ExportError> {
        toml::to_string_pretty(self).map_err(|e| ExportError::Format {
            path: format!("{}.toml", self.relation),
            message: e.to_string(),
        })
    }
    /// Reads a record from TOML text (`source` names it in messages).
    pub fn from_toml(text: &str, source: &str) -> Result<FitRecord, ExportError> {
        toml::from_str(text).map_err(|e| ExportError::Format {
            path: source.to_string(),
            message: format!("not a gaitfit fits file: {e}"),
        })
    }
    /// Reads a record from JSON text (`source` names it in messages).
    pub fn from_json(text: &str, source: &str) -> Result<FitRecord, ExportError> {
        serde_json::from_str(text).map_err(|e| ExportError::Format {
            path: source.to_string(),
            message: format!("not a gaitfit fits file: {e}"),
        })
    }
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
    FitRecord::from_json(&text, &path.display().to_string())
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
    /// Rust source of documented constants, one module per relation; use it as a module or
    /// through `include!` (see [`rust_source`]).
    Rust,
    /// A crate folder (`Cargo.toml`, `src/lib.rs`) holding the Rust export, for another crate to
    /// depend on by path (see [`write_crate`]).
    Crate,
    /// One JSON array of the fit records.
    Json,
    /// One TOML document with a table per relation (the same records as the JSON).
    Toml,
    /// One CSV row per coefficient.
    Csv,
}

/// A Rust identifier from a name: ASCII letters and digits kept, every other run of characters
/// one `_`, upper case for constants (`level[S 01]` → `LEVEL_S_01`), lower case for modules.
fn rust_ident(name: &str, upper: bool) -> String {
    let mut s = String::new();
    for c in name.chars() {
        if c.is_ascii_alphanumeric() {
            s.push(if upper {
                c.to_ascii_uppercase()
            } else {
                c.to_ascii_lowercase()
            });
        } else if !s.is_empty() && !s.ends_with('_') {
            s.push('_');
        }
    }
    let s = s.trim_end_matches('_').to_string();
    if s.is_empty() || s.starts_with(|c: char| c.is_ascii_digit()) {
        format!("_{s}")
    } else {
        s
    }
}

fn fmt_opt(v: Option<f64>) -> String {
    v.map_or("open".to_string(), |v| format!("{v:?}"))
}

/// A Rust `f64` literal that reads back to exactly `v`: Rust's `{:?}` writes the shortest decimal
/// that round-trips (as the JSON writer does), always with a `.` or an exponent.
fn f64_literal(v: f64, what: &str) -> Result<String, ExportError> {
    if v.is_finite() {
        Ok(format!("{v:?}"))
    } else {
        Err(ExportError::Format {
            path: "export.rs".into(),
            message: format!("{what} = {v} has no Rust literal"),
        })
    }
}

/// `v` to 4 significant digits, for reading (the exact ends are the `RANGE_*` constants).
fn sig4(v: f64) -> String {
    format!("{:?}", format!("{v:.3e}").parse::<f64>().unwrap_or(v))
}

/// Text for a doc comment: backticks of the source would end a code span early.
fn doc_text(s: &str) -> String {
    s.replace('`', "'").replace('\n', " ")
}

/// Renders fit records in `format` (every format but [`ExportFormat::Crate`], a folder: see
/// [`write_crate`]).
pub fn export(records: &[FitRecord], format: ExportFormat) -> Result<String, ExportError> {
    match format {
        ExportFormat::Json => {
            serde_json::to_string_pretty(records).map_err(|e| ExportError::Format {
                path: "export.json".into(),
                message: e.to_string(),
            })
        }
        ExportFormat::Toml => {
            let root: BTreeMap<&str, &FitRecord> =
                records.iter().map(|r| (r.relation.as_str(), r)).collect();
            toml::to_string_pretty(&root).map_err(|e| ExportError::Format {
                path: "export.toml".into(),
                message: e.to_string(),
            })
        }
        ExportFormat::Csv => export_csv(records),
        ExportFormat::Rust => rust_source(records),
        ExportFormat::Crate => Err(ExportError::Format {
            path: "export".into(),
            message: "the crate format is a folder: use write_crate (`-o DIR`)".into(),
        }),
    }
}

fn export_csv(records: &[FitRecord]) -> Result<String, ExportError> {
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
                format!("{:?}", c.value),
                c.std_error.map(|v| format!("{v:?}")).unwrap_or_default(),
                c.ci95[0].map(|v| format!("{v:?}")).unwrap_or_default(),
                c.ci95[1].map(|v| format!("{v:?}")).unwrap_or_default(),
                c.published.map(|v| format!("{v:?}")).unwrap_or_default(),
                c.held.is_some().to_string(),
                r.n.to_string(),
                format!("{:?}", r.r2),
                format!("{:?}", r.rmse),
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

/// The Rust export: one `pub mod <relation>` per record (`run-sl-v` → `run_sl_v`) holding a
/// documented `pub const` per coefficient (`A`, `V_NORM`, `LEVEL_S01`, …), and the fit's `FIT_N`,
/// `FIT_R2`, `DATA_SHA256` and `RANGE_<input>: [f64; 2]` (the input range covered by the data).
///
/// The text has only plain `//` comments and items with outer attributes and docs, so it
/// compiles both as a module file (`mod gait_coeffs;`) and pasted with
/// `include!("gait_coeffs.rs")` (which rejects inner attributes and inner doc comments, E0753),
/// under `-D warnings -D missing_docs`. Each constant's doc gives its relation's equation, the
/// unit, the valid input range, the 95 % interval, the published value, n, r² and the data's
/// SHA-256. Values are written as the shortest decimal that reads back to the same `f64`, so
/// they are bit-identical to the `fits/<id>.json` they come from.
pub fn rust_source(records: &[FitRecord]) -> Result<String, ExportError> {
    let mut s = String::new();
    s.push_str(&format!(
        "// Gait relation coefficients refitted by gaitfit {} (`gaitfit export --format rust`; do not edit).\n\
         //\n\
         // Use as a module (`mod gait_coeffs;`) or in place (`include!(\"gait_coeffs.rs\");`).\n\
         // One module per relation; units are the papers' (m, m/min, steps/min, s, rad, % of cycle).\n\
         // Every value is bit-identical to the fit record (fits/<relation>.json) it comes from.\n",
        records
            .first()
            .map_or(env!("CARGO_PKG_VERSION"), |r| r.gaitfit_version.as_str())
    ));
    let mut modules = std::collections::BTreeSet::new();
    for r in records {
        let module = rust_ident(&r.relation, false);
        if !modules.insert(module.clone()) {
            return Err(ExportError::Format {
                path: "export.rs".into(),
                message: format!(
                    "relation {:?}: its module name `{module}` is taken by another relation",
                    r.relation
                ),
            });
        }
        let range = r
            .valid_range
            .iter()
            .map(|g| format!("{} ∈ [{}, {}] {}", g.input, sig4(g.lo), sig4(g.hi), g.unit))
            .collect::<Vec<_>>()
            .join(", ");
        let range = if range.is_empty() {
            "not recorded".to_string()
        } else {
            range
        };
        let fit_line = format!(
            "n = {} ({} subjects), r² = {:?} ({}), rmse = {:?}",
            r.n,
            r.n_subjects,
            r.r2,
            doc_text(&r.r2_definition),
            r.rmse
        );
        let data_line = format!(
            "SHA-256 `{}` of `{}` ({} rows used)",
            r.data.sha256,
            doc_text(&r.data.path),
            r.data.rows_used
        );
        s.push_str(&format!(
            "\n/// `{}`: {}.\n///\n/// {}.\n///\n/// - Equation: `{}`\n/// - Valid range (covered by the data, 4 digits): {}\n/// - Fit: {}\n/// - Data: {}\n#[allow(dead_code)]\npub mod {module} {{\n",
            r.relation,
            doc_text(&r.title),
            doc_text(&r.citation),
            doc_text(&r.equation),
            doc_text(&range),
            doc_text(&fit_line),
            data_line,
        ));
        let mut idents = std::collections::BTreeSet::new();
        let mut item = |ident: String, doc: String, ty: &str, value: String| {
            if !idents.insert(ident.clone()) {
                return Err(ExportError::Format {
                    path: "export.rs".into(),
                    message: format!(
                        "relation {:?}: two constants are named `{ident}`",
                        r.relation
                    ),
                });
            }
            s.push_str(&doc);
            s.push_str(&format!("    pub const {ident}: {ty} = {value};\n"));
            Ok(())
        };
        for c in &r.coefficients {
            let mut doc = format!(
                "    /// `{}` of `{}` (unit: {}): {:?}.\n    ///\n",
                doc_text(&c.name),
                r.relation,
                doc_text(&c.unit),
                c.value
            );
            doc.push_str(&format!(
                "    /// - Equation: `{}`\n",
                doc_text(&r.equation)
            ));
            doc.push_str(&format!("    /// - Valid range: {}\n", doc_text(&range)));
            doc.push_str(&format!(
                "    /// - 95 % CI: `[{}, {}]`{}\n",
                fmt_opt(c.ci95[0]),
                fmt_opt(c.ci95[1]),
                if c.ci95.iter().any(Option::is_none) {
                    " (open: not bounded within the data)"
                } else {
                    ""
                }
            ));
            if let Some([lo, hi]) = c.ci95_bootstrap {
                doc.push_str(&format!(
                    "    /// - Bootstrap 95 % interval: `[{lo:?}, {hi:?}]`\n"
                ));
            }
            doc.push_str(&match c.published {
                Some(v) => format!("    /// - Published: {v:?}\n"),
                None => "    /// - Published: none (the paper gives no value)\n".to_string(),
            });
            doc.push_str(&format!("    /// - Fit: {}\n", doc_text(&fit_line)));
            doc.push_str(&format!("    /// - Data: {data_line}\n"));
            if let Some(h) = &c.held {
                doc.push_str(&format!("    /// - Held: {}\n", doc_text(h)));
            }
            if let Some(f) = &c.flag {
                doc.push_str(&format!("    /// - Flag: {}\n", doc_text(f)));
            }
            let value = f64_literal(c.value, &format!("{} {}", r.relation, c.name))?;
            item(rust_ident(&c.name, true), doc, "f64", value)?;
        }
        item(
            "FIT_N".into(),
            format!("    /// Rows the `{}` fit used.\n", r.relation),
            "usize",
            r.n.to_string(),
        )?;
        item(
            "FIT_R2".into(),
            format!(
                "    /// r² of the `{}` fit ({}).\n",
                r.relation,
                doc_text(&r.r2_definition)
            ),
            "f64",
            f64_literal(r.r2, &format!("{} r2", r.relation))?,
        )?;
        item(
            "DATA_SHA256".into(),
            format!(
                "    /// SHA-256 of the data the `{}` fit used ({}).\n",
                r.relation,
                doc_text(&r.data.path)
            ),
            "&str",
            format!("{:?}", r.data.sha256),
        )?;
        for g in &r.valid_range {
            item(
                format!("RANGE_{}", rust_ident(&g.input, true)),
                format!(
                    "    /// Range of `{}` ({}) covered by the `{}` fit's data: `[lo, hi]`.\n",
                    doc_text(&g.input),
                    doc_text(&g.unit),
                    r.relation
                ),
                "[f64; 2]",
                format!(
                    "[{}, {}]",
                    f64_literal(g.lo, &g.input)?,
                    f64_literal(g.hi, &g.input)?
                ),
            )?;
        }
        s.push_str("}\n");
    }
    Ok(s)
}

/// Writes the Rust export as a crate another crate depends on by path:
/// `dir/Cargo.toml` (package `name`, no dependencies, `publish = false`) and `dir/src/lib.rs`
/// (`#![no_std]`, crate docs, then [`rust_source`]). Each file is written atomically.
///
/// ```toml
/// [dependencies]
/// gait_coeffs = { path = "../gait_coeffs" }   # then gait_coeffs::run_sl_v::A
/// ```
pub fn write_crate(records: &[FitRecord], dir: &Path, name: &str) -> Result<(), ExportError> {
    let valid = name.starts_with(|c: char| c.is_ascii_alphabetic())
        && name
            .chars()
            .all(|c| c.is_ascii_alphanumeric() || c == '_' || c == '-');
    if !valid {
        return Err(ExportError::Format {
            path: dir.display().to_string(),
            message: format!(
                "crate name {name:?}: use ASCII letters, digits, `_` or `-`, starting with a letter"
            ),
        });
    }
    let source = rust_source(records)?;
    let relations = records
        .iter()
        .map(|r| format!("`{}`", r.relation))
        .collect::<Vec<_>>()
        .join(", ");
    let version = records
        .first()
        .map_or(env!("CARGO_PKG_VERSION"), |r| r.gaitfit_version.as_str());
    let cargo = format!(
        "# Generated by `gaitfit export --format crate` (gaitfit {version}); do not edit.\n\
         [package]\n\
         name = {name:?}\n\
         version = \"0.1.0\"\n\
         edition = \"2021\"\n\
         publish = false\n\
         description = \"Gait relation coefficients refitted by gaitfit\"\n\
         \n\
         [dependencies]\n"
    );
    let lib = format!(
        "//! Gait relation coefficients refitted by gaitfit {version}: {relations}.\n\
         //!\n\
         //! One module per relation, one documented constant per coefficient (value, unit,\n\
         //! equation, valid range, 95 % interval, n, r², data SHA-256). Generated by\n\
         //! `gaitfit export --format crate`; do not edit.\n\
         #![no_std]\n\
         #![forbid(unsafe_code)]\n\
         #![warn(missing_docs)]\n\n{source}"
    );
    write_atomic_bytes(&dir.join("Cargo.toml"), cargo.as_bytes())?;
    write_atomic_bytes(&dir.join("src").join("lib.rs"), lib.as_bytes())?;
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn identifiers_are_valid_rust() {
        assert_eq!(rust_ident("level[S 01]", true), "LEVEL_S_01");
        assert_eq!(rust_ident("run-sl-v", false), "run_sl_v");
        assert_eq!(rust_ident("sl(h=1.8)", true), "SL_H_1_8");
        assert_eq!(rust_ident("2x", true), "_2X");
        assert_eq!(rust_ident("[]", true), "_");
    }
}
