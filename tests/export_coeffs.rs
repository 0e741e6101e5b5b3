//! Coefficient exports that other programs take as they are: the JSON and the TOML hold the same
//! record (one serde struct reads both), and the Rust export compiles in a downstream crate both
//! through `include!` and as a module, with every value bit-identical to the JSON.
//!
//! The independent readers: rustc's float-literal parser (the downstream crate's `const`
//! assertions compare the exported constants' bits with the JSON's, read by `serde_json`), and
//! Python's `json`/`tomllib` in `tools/export/check_toml_json.py` (optional, not run here).
use assert_cmd::Command;
use gaitfit::export::coeffs::{export, read_fits_dir, ExportFormat, FitRecord};
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

fn committed() -> Vec<FitRecord> {
    let fits = read_fits_dir(&root().join("fits")).expect("fits/ readable");
    assert!(fits.len() >= 5, "fits/ has {} records", fits.len());
    fits.into_iter().map(|(_, r)| r).collect()
}

#[test]
fn committed_json_and_toml_read_as_the_same_record() {
    for r in committed() {
        let dir = root().join("fits");
        let json = std::fs::read_to_string(dir.join(format!("{}.json", r.relation))).unwrap();
        let toml = std::fs::read_to_string(dir.join(format!("{}.toml", r.relation))).unwrap();
        let a = FitRecord::from_json(&json, "json").unwrap();
        let b = FitRecord::from_toml(&toml, "toml").unwrap();
        // PartialEq on f64: bit-identical values (no NaN in a fit record).
        assert_eq!(a, b, "{}: the JSON and the TOML differ", r.relation);
        assert!(!toml.contains("\"open\""), "{}", r.relation);
    }
}

/// A record with every kind of missing number: a half-open interval, a held coefficient (no
/// standard error, no t-test, both ends open), a bootstrap interval, no leave-one-subject-out.
fn record_with_holes() -> FitRecord {
    let mut r = committed()
        .into_iter()
        .find(|r| r.relation == "run-sl-v")
        .expect("fits/run-sl-v.json");
    r.coefficients[0].ci95 = [Some(0.1729832630215715), None];
    r.coefficients[0].ci95_bootstrap = Some([0.17, 0.21]);
    r.coefficients[1].std_error = None;
    r.coefficients[1].t_test = None;
    r.coefficients[1].ci95 = [None, None];
    r.coefficients[1].held = Some("held at the published value".into());
    r.loso_rmse = None;
    // Values whose shortest decimal is long, tiny or huge.
    r.coefficients[2].value = 0.1 + 0.2;
    r.rmse = 5e-324;
    r.aic = -1.7976931348623157e308;
    r
}

#[test]
fn missing_numbers_are_absent_keys_in_toml_and_null_in_json() {
    let r = record_with_holes();
    let json = r.to_json().unwrap();
    let toml = r.to_toml().unwrap();
    assert_eq!(FitRecord::from_json(&json, "json").unwrap(), r);
    assert_eq!(FitRecord::from_toml(&toml, "toml").unwrap(), r);
    // JSON: the open end is an explicit null in the interval table.
    let v: serde_json::Value = serde_json::from_str(&json).unwrap();
    let c0 = &v["coefficients"][0];
    assert_eq!(c0["ci95"]["lo"].as_f64(), Some(0.1729832630215715));
    assert!(c0["ci95"]["hi"].is_null(), "{}", c0["ci95"]);
    assert_eq!(c0["ci95_bootstrap"]["hi"].as_f64(), Some(0.21));
    assert!(v["coefficients"][1]["std_error"].is_null());
    assert!(v["loso_rmse"].is_null());
    // TOML: the same tables, the missing keys absent (TOML has no null; no placeholder strings).
    let t: toml::Value = toml::from_str(&toml).unwrap();
    let c = t["coefficients"].as_array().unwrap();
    let ci0 = c[0]["ci95"].as_table().unwrap();
    assert_eq!(
        ci0.get("lo").and_then(|x| x.as_float()),
        Some(0.1729832630215715)
    );
    assert!(ci0.get("hi").is_none(), "{ci0:?}");
    assert!(c[1]["ci95"].as_table().unwrap().is_empty());
    assert!(c[1].get("std_error").is_none() && c[1].get("t_test").is_none());
    assert!(t.get("loso_rmse").is_none());
    assert!(!toml.contains("open") && !toml.contains("null") && !toml.contains("nan"));
}

#[test]
fn earlier_json_interval_arrays_still_read() {
    let r = record_with_holes();
    let mut v: serde_json::Value = serde_json::from_str(&r.to_json().unwrap()).unwrap();
    v["coefficients"][0]["ci95"] = serde_json::json!([0.1729832630215715, null]);
    let back: FitRecord = serde_json::from_value(v).unwrap();
    assert_eq!(back, r);
}

#[test]
fn exported_toml_and_json_documents_hold_the_same_records() {
    let records = committed();
    let json = export(&records, ExportFormat::Json).unwrap();
    let toml = export(&records, ExportFormat::Toml).unwrap();
    let from_json: Vec<FitRecord> = serde_json::from_str(&json).unwrap();
    let from_toml: BTreeMap<String, FitRecord> = toml::from_str(&toml).unwrap();
    assert_eq!(from_json, records);
    assert_eq!(from_toml.len(), records.len());
    for r in &records {
        assert_eq!(from_toml.get(&r.relation), Some(r), "{}", r.relation);
    }
}

#[test]
fn rust_docs_give_equation_unit_range_ci_n_r2_and_data_hash() {
    let records = committed();
    let src = export(&records, ExportFormat::Rust).unwrap();
    // No inner attributes or inner doc comments (E0753 under include!).
    assert!(!src.contains("//!") && !src.contains("#!["));
    for r in &records {
        for c in &r.coefficients {
            // The doc block right above the constant.
            let ident = format!("pub const {}: f64 = ", const_ident(&c.name));
            let at = src
                .find(&format!("/// `{}` of `{}`", c.name, r.relation))
                .unwrap_or_else(|| panic!("{} {}: no doc", r.relation, c.name));
            let block = &src[at..at + src[at..].find(&ident).expect("const after its doc")];
            for must in [
                format!("(unit: {})", c.unit),
                format!("Equation: `{}`", r.equation.replace('`', "'")),
                "Valid range:".to_string(),
                "95 % CI: `[".to_string(),
                format!("n = {}", r.n),
                format!("r² = {:?}", r.r2),
                r.data.sha256.clone(),
            ] {
                assert!(
                    block.contains(&must),
                    "{} {}: {must:?} in\n{block}",
                    r.relation,
                    c.name
                );
            }
            for g in &r.valid_range {
                assert!(block.contains(&format!("{} ∈ [", g.input)), "{block}");
            }
        }
    }
}

fn const_ident(name: &str) -> String {
    let mut s = String::new();
    for ch in name.chars() {
        if ch.is_ascii_alphanumeric() {
            s.push(ch.to_ascii_uppercase());
        } else if !s.is_empty() && !s.ends_with('_') {
            s.push('_');
        }
    }
    s.trim_end_matches('_').to_string()
}

fn module_ident(relation: &str) -> String {
    const_ident(relation).to_ascii_lowercase()
}

/// `const` assertions a downstream crate checks at compile time: each constant's bits equal the
/// JSON value's (read by serde_json; the literal is read by rustc).
fn bit_assertions(records: &[FitRecord], path: &str) -> String {
    let mut s = String::new();
    for r in records {
        for c in &r.coefficients {
            s += &format!(
                "const _: () = assert!({path}{}::{}.to_bits() == {:#018x}_u64);\n",
                module_ident(&r.relation),
                const_ident(&c.name),
                c.value.to_bits()
            );
        }
        s += &format!(
            "const _: () = assert!({path}{}::FIT_N == {});\n",
            module_ident(&r.relation),
            r.n
        );
    }
    s
}

fn write(path: &Path, text: &str) {
    std::fs::create_dir_all(path.parent().unwrap()).unwrap();
    std::fs::write(path, text).unwrap();
}

/// A downstream crate (offline, path dependency only) compiles the export three ways: as a
/// module file, through `include!` (at the crate root and inside a private module), and as the
/// `--format crate` dependency; `-D warnings` and `deny(missing_docs)` hold, and its `const`
/// assertions check every value bit for bit against the JSON.
#[test]
fn downstream_crate_compiles_the_export_through_include_and_as_a_module() {
    let records = committed();
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let fits = root().join("fits");
    let run = |args: &[&str]| {
        let out = Command::cargo_bin("gaitfit")
            .unwrap()
            .current_dir(d)
            .arg("export")
            .arg("--fits")
            .arg(&fits)
            .args(args)
            .output()
            .unwrap();
        assert!(
            out.status.success(),
            "{args:?}: {}",
            String::from_utf8_lossy(&out.stderr)
        );
    };
    run(&["--format", "rust", "-o", "downstream/gait_coeffs.rs"]);
    run(&["--format", "crate", "-o", "gait_coeffs"]);
    std::fs::create_dir_all(d.join("downstream/src")).unwrap();
    std::fs::copy(
        d.join("downstream/gait_coeffs.rs"),
        d.join("downstream/src/coeffs_module.rs"),
    )
    .unwrap();
    write(
        &d.join("downstream/Cargo.toml"),
        "[package]\nname = \"downstream\"\nversion = \"0.0.0\"\nedition = \"2021\"\npublish = false\n\n\
         [dependencies]\ngait_coeffs = { path = \"../gait_coeffs\" }\n\n[workspace]\n",
    );
    let mut lib = String::from(
        "//! Uses gaitfit's Rust export three ways.\n#![deny(missing_docs)]\n\n\
         /// The export as a module file.\npub mod coeffs_module;\n\n\
         /// The export included in a private module (no dead-code warnings).\n\
         mod private_include {\n    include!(\"../gait_coeffs.rs\");\n}\n\n\
         include!(\"../gait_coeffs.rs\");\n\n\
         /// A value read through each route.\npub fn walk_k() -> [f64; 3] {\n    \
         [walk_sl_sf::K, coeffs_module::walk_sl_sf::K, gait_coeffs::walk_sl_sf::K]\n}\n\n",
    );
    lib += &bit_assertions(&records, "crate::");
    lib += &bit_assertions(&records, "crate::coeffs_module::");
    lib += &bit_assertions(&records, "crate::private_include::");
    lib += &bit_assertions(&records, "gait_coeffs::");
    write(&d.join("downstream/src/lib.rs"), &lib);
    let cargo = std::env::var("CARGO").unwrap_or_else(|_| "cargo".into());
    let out = std::process::Command::new(cargo)
        .current_dir(d.join("downstream"))
        .args(["check", "--offline", "--quiet"])
        .env("CARGO_TARGET_DIR", d.join("target"))
        .env("RUSTFLAGS", "-D warnings")
        .env_remove("CARGO_BUILD_RUSTFLAGS")
        .env_remove("CARGO_ENCODED_RUSTFLAGS")
        .output()
        .unwrap();
    assert!(
        out.status.success(),
        "the downstream crate does not compile:\n{}\n--- lib.rs ---\n{lib}",
        String::from_utf8_lossy(&out.stderr)
    );
    let manifest = std::fs::read_to_string(d.join("gait_coeffs/Cargo.toml")).unwrap();
    assert!(manifest.contains("name = \"gait_coeffs\"") && manifest.contains("[dependencies]"));
}

#[test]
fn crate_format_needs_a_folder_and_a_valid_name() {
    let dir = tempfile::tempdir().unwrap();
    let fits = root().join("fits");
    let out = Command::cargo_bin("gaitfit")
        .unwrap()
        .current_dir(dir.path())
        .args(["export", "--format", "crate", "--fits"])
        .arg(&fits)
        .output()
        .unwrap();
    assert!(!out.status.success());
    assert!(String::from_utf8_lossy(&out.stderr).contains("-o DIR"));
    let out = Command::cargo_bin("gaitfit")
        .unwrap()
        .current_dir(dir.path())
        .args([
            "export",
            "--format",
            "crate",
            "-o",
            "c",
            "--crate-name",
            "9 lives",
            "--fits",
        ])
        .arg(&fits)
        .output()
        .unwrap();
    assert!(!out.status.success());
    assert!(String::from_utf8_lossy(&out.stderr).contains("crate name"));
    assert!(!dir.path().join("c").exists());
}
