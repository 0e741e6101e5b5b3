//! The wild cluster bootstrap-t of `gaitfit fit` (Webb six-point weights, unrestricted, every
//! 6^G weight pattern enumerated) on the bundled `data/*.csv` against an independent numpy
//! enumeration.
//!
//! Source of every expected number: `tools/reference/wild.json`, written by
//! `tools/reference/wild.py` (numpy, all 6^10 and 6^9 patterns; its closed form checked against
//! statsmodels refits of 200 random patterns). Both sides are exact (no Monte Carlo error), so
//! they must agree to rounding. Regenerate with `/work/venv/bin/python tools/reference/wild.py`
//! after `data/` changes.
use gaitfit::fit::pipeline::{fit_relation, load_tables, FitOptions};
use gaitfit::relations::by_id;
use serde_json::Value;
use std::path::PathBuf;

fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

fn close(got: f64, want: f64, rel: f64, what: &str) {
    let err = (got - want).abs() / want.abs().max(1e-300);
    assert!(
        err <= rel,
        "{what}: gaitfit {got:e} vs reference {want:e} (rel {err:e})"
    );
}

#[test]
fn wild_cluster_bootstrap_matches_the_numpy_enumeration() {
    let reference: Value = serde_json::from_str(
        &std::fs::read_to_string(root().join("tools/reference/wild.json")).expect("wild.json"),
    )
    .expect("json");
    let mut files: Vec<PathBuf> = std::fs::read_dir(root().join("data"))
        .expect("data/")
        .filter_map(|e| e.ok().map(|e| e.path()))
        .filter(|p| p.extension().is_some_and(|x| x == "csv"))
        .collect();
    files.sort();
    let tables = load_tables(&files, None).expect("bundled data");
    for id in ["walk-sl-sf", "walk-tds-sf"] {
        let rel = by_id(id).expect("relation");
        let opts = FitOptions {
            bootstrap: 10,
            ..FitOptions::default()
        };
        let r = fit_relation(rel.as_ref(), &tables, &opts)
            .expect("fit")
            .record;
        let want = &reference[id];
        let w = r.wild_bootstrap.as_ref().expect("wild bootstrap record");
        assert!(w.enumerated, "{id}: every pattern enumerated");
        assert_eq!(Some(w.samples), want["samples"].as_u64(), "{id}: 6^G");
        assert_eq!(
            w.coefficients.len(),
            want["coefficients"]
                .as_object()
                .expect("coefficients")
                .len()
        );
        for c in &w.coefficients {
            let e = &want["coefficients"][&c.name];
            let num = |v: &Value| v.as_f64().expect("number");
            close(
                c.se_cr1,
                num(&e["se_cr1"]),
                1e-9,
                &format!("{id} {} SE_CR1", c.name),
            );
            for j in 0..2 {
                close(
                    c.t_quantiles[j],
                    num(&e["t_quantiles"][j]),
                    1e-9,
                    &format!("{id} {} t* quantile {j}", c.name),
                );
                let ci = c.ci95.expect("finite interval");
                close(
                    ci[j],
                    num(&e["ci95_wild"][j]),
                    1e-9,
                    &format!("{id} {} interval end {j}", c.name),
                );
            }
        }
    }
}
