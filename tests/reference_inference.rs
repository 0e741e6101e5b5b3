//! Standard errors, degrees of freedom and breakpoint confidence sets of `gaitfit fit` on the
//! bundled `data/*.csv` against independent computations.
//!
//! Source of every expected number: `tools/reference/inference.json`, written by
//! `tools/reference/inference.py` (statsmodels 0.15 `OLS.fit(cov_type='cluster', use_t=True)`
//! for CR1; dense numpy implementations of CR2 with n_g × n_g adjustment matrices and of the
//! Bell–McCaffrey degrees of freedom from GᵀG; the F set of k1 by fitting every admissible
//! partition; the clustered standard error of a mean of subject slopes from the dense design).
//! Regenerate with `/work/venv/bin/python tools/reference/inference.py` after `data/` changes.
//!
//! The wild cluster bootstrap-t (Webb six-point weights, unrestricted, every 6^G weight pattern
//! enumerated) against `tools/reference/wild.json`, written by `tools/reference/wild.py` (numpy,
//! all 6^10 and 6^9 patterns; its closed form checked against statsmodels refits of 200 random
//! patterns). Both sides are exact (no Monte Carlo error), so they must agree to rounding.
//! Regenerate with `/work/venv/bin/python tools/reference/wild.py` after `data/` changes.
use gaitfit::export::coeffs::FitRecord;
use gaitfit::fit::inference::SeMethod;
use gaitfit::fit::pipeline::{fit_relation, load_tables, FitOptions};
use gaitfit::ingest::trials::TrialsTable;
use gaitfit::relations::by_id;
use serde_json::Value;
use std::path::PathBuf;

fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

fn reference() -> Value {
    let p = root().join("tools/reference/inference.json");
    serde_json::from_str(&std::fs::read_to_string(&p).expect("reference file")).expect("json")
}

fn bundled() -> Vec<TrialsTable> {
    let mut files: Vec<PathBuf> = std::fs::read_dir(root().join("data"))
        .expect("data/")
        .filter_map(|e| e.ok().map(|e| e.path()))
        .filter(|p| p.extension().is_some_and(|x| x == "csv"))
        .collect();
    files.sort();
    load_tables(&files, None).expect("bundled data")
}

fn fit(tables: &[TrialsTable], id: &str, se: SeMethod) -> FitRecord {
    let rel = by_id(id).expect("relation");
    let opts = FitOptions {
        se: Some(se),
        ..FitOptions::default()
    };
    fit_relation(rel.as_ref(), tables, &opts)
        .expect("fit")
        .record
}

fn close(got: f64, want: f64, rel: f64, what: &str) {
    let err = (got - want).abs() / want.abs().max(1e-300);
    assert!(
        err <= rel,
        "{what}: gaitfit {got:e} vs reference {want:e} (rel {err:e})"
    );
}

fn num(v: &Value) -> f64 {
    v.as_f64().expect("number")
}

fn nums(v: &Value) -> Vec<f64> {
    v.as_array().expect("array").iter().map(num).collect()
}

fn coef<'a>(r: &'a FitRecord, name: &str) -> &'a gaitfit::export::coeffs::CoefficientRecord {
    r.coefficient(name)
        .unwrap_or_else(|| panic!("{}: no {name}", r.relation))
}

/// Linear relations without breakpoints: coefficients, iid / CR1 / CR2 standard errors and the
/// degrees of freedom of each method.
#[test]
fn linear_relations_match_statsmodels_and_dense_cr2() {
    let tables = bundled();
    let refs = reference();
    for (id, names) in [
        ("walk-tds-sf", &["d0", "d1"][..]),
        ("walk-sl-sf", &["k"][..]),
    ] {
        let want = &refs[id];
        for (method, se_key, df) in [
            (SeMethod::Iid, "se_iid", None),
            (SeMethod::Cluster, "se_cr1", Some(num(&want["df_cr1"]))),
            (SeMethod::Cr2, "se_cr2", None),
        ] {
            let r = fit(&tables, id, method);
            assert_eq!(r.n as f64, num(&want["n"]), "{id} n");
            assert_eq!(r.n_subjects as f64, num(&want["clusters"]), "{id} G");
            let inf = r.inference.as_ref().expect("inference record");
            assert_eq!(inf.method, method.label());
            for (j, name) in names.iter().enumerate() {
                let c = coef(&r, name);
                let what = format!("{id} {name} {}", method.label());
                close(c.value, nums(&want["coef"])[j], 1e-10, &what);
                let se = c.std_error.expect("se");
                close(se, nums(&want[se_key])[j], 1e-9, &format!("{what} se"));
                let t = c.t_test.as_ref().expect("t-test");
                match method {
                    SeMethod::Iid => assert_eq!(t.df, (r.n - names.len()) as f64),
                    SeMethod::Cluster => assert_eq!(Some(t.df), df),
                    SeMethod::Cr2 => {
                        close(t.df, nums(&want["df_cr2"])[j], 1e-8, &format!("{what} df"))
                    }
                }
            }
        }
    }
}

/// k1 of the flight-time relation: the F set over all admissible partitions (pieces, counts)
/// and the linear coefficients' CR1 standard errors conditional on k1.
#[test]
fn flight_time_knot_set_and_conditional_cr1() {
    let tables = bundled();
    let want = &reference()["run-tflight-sf"];
    let r = fit(&tables, "run-tflight-sf", SeMethod::Cluster);
    let k1 = coef(&r, "k1");
    close(k1.value, num(&want["k1"]), 1e-12, "k1");
    let bp = r
        .breakpoints
        .iter()
        .find(|b| b.name == "k1")
        .expect("k1 set");
    assert_eq!(bp.admissible as f64, num(&want["k1_admissible"]));
    assert_eq!(bp.accepted as f64, num(&want["k1_accepted"]));
    close(
        bp.design_effect.expect("design effect"),
        num(&want["k1_design_effect"]),
        1e-9,
        "k1 design effect",
    );
    let same = |got: &[[Option<f64>; 2]], want: &Value, what: &str| {
        let want = want.as_array().expect("pieces");
        assert_eq!(got.len(), want.len(), "{what}: {got:?}");
        for (g, w) in got.iter().zip(want) {
            for e in 0..2 {
                match (g[e], w[e].as_f64()) {
                    (Some(a), Some(b)) => close(a, b, 1e-12, what),
                    (None, None) => {}
                    (a, b) => panic!("{what}: piece end {a:?} vs {b:?}"),
                }
            }
        }
    };
    same(&bp.pieces, &want["k1_pieces"], "k1 clustered set");
    same(&bp.pieces_iid, &want["k1_pieces_iid"], "k1 iid set");
    // The figure: the set covers 152–173 steps/min; the estimate has no standard error.
    assert!(k1.ci95[0].is_none_or(|v| v <= 152.0) && k1.ci95[1].is_none_or(|v| v >= 173.0));
    assert!(k1.std_error.is_none() && k1.t_test.is_none() && !bp.regular);
    for (j, name) in ["q0", "q1", "q2", "c0", "c1", "c2", "c3"]
        .iter()
        .enumerate()
    {
        let c = coef(&r, name);
        close(c.value, nums(&want["coef"])[j], 1e-8, name);
        close(
            c.std_error.expect("se"),
            nums(&want["se_cr1_conditional"])[j],
            1e-7,
            &format!("{name} se"),
        );
        assert_eq!(c.t_test.as_ref().map(|t| t.df), Some(5.0));
    }
}

/// run-tflight-sf's k1 set with CR2 (the default below 20 subjects): the design effect from
/// the CR2 covariance (dense, `common.cr2`), the accepted partitions and the pieces, against the
/// script's exhaustive partitions; the hull covers 152–173 as the issue asks.
#[test]
fn flight_time_knot_set_with_cr2() {
    let tables = bundled();
    let want = &reference()["run-tflight-sf"];
    let r = fit(&tables, "run-tflight-sf", SeMethod::Cr2);
    let bp = r
        .breakpoints
        .iter()
        .find(|b| b.name == "k1")
        .expect("k1 set");
    close(
        bp.design_effect.expect("design effect"),
        num(&want["k1_design_effect_cr2"]),
        1e-9,
        "k1 CR2 design effect",
    );
    assert_eq!(bp.accepted as f64, num(&want["k1_accepted_cr2"]));
    let pieces = want["k1_pieces_cr2"].as_array().expect("pieces");
    assert_eq!(bp.pieces.len(), pieces.len(), "{:?}", bp.pieces);
    for (g, w) in bp.pieces.iter().zip(pieces) {
        for e in 0..2 {
            match (g[e], w[e].as_f64()) {
                (Some(a), Some(b)) => close(a, b, 1e-12, "k1 CR2 piece end"),
                (None, None) => {}
                (a, b) => panic!("k1 CR2 piece end {a:?} vs {b:?}"),
            }
        }
    }
    let k1 = coef(&r, "k1");
    assert!(k1.ci95[0].is_none_or(|v| v <= 152.0) && k1.ci95[1].is_none_or(|v| v >= 173.0));
}

/// run-sl-v: v_norm from the profile, a and the mean slope b with per-subject slopes absorbed,
/// their CR1 standard errors conditional on v_norm and with v_norm free, the levels' iid ones.
#[test]
fn step_length_with_subject_slopes_matches_the_dense_design() {
    let tables = bundled();
    let want = &reference()["run-sl-v"];
    let r = fit(&tables, "run-sl-v", SeMethod::Cluster);
    close(
        coef(&r, "v_norm").value,
        num(&want["v_norm"]),
        1e-7,
        "v_norm",
    );
    close(coef(&r, "a").value, num(&want["a"]), 1e-7, "a");
    close(coef(&r, "b").value, num(&want["b"]), 1e-7, "b");
    let a = coef(&r, "a");
    let b = coef(&r, "b");
    close(
        a.std_error_conditional.expect("cond"),
        num(&want["se_a_cr1"]),
        1e-6,
        "se a",
    );
    close(
        b.std_error_conditional.expect("cond"),
        num(&want["se_b_cr1"]),
        1e-6,
        "se b",
    );
    close(
        a.std_error.expect("free"),
        num(&want["se_a_cr1_free"]),
        1e-6,
        "se a free",
    );
    close(
        b.std_error.expect("free"),
        num(&want["se_b_cr1_free"]),
        1e-6,
        "se b free",
    );
    let vn = coef(&r, "v_norm");
    close(
        vn.std_error.expect("v_norm se"),
        num(&want["se_v_norm_cr1_free"]),
        1e-6,
        "se v_norm",
    );
    let subjects: Vec<&str> = want["subjects"]
        .as_array()
        .expect("subjects")
        .iter()
        .map(|s| s.as_str().expect("name"))
        .collect();
    for (s, name) in subjects.iter().enumerate() {
        let l = coef(&r, &format!("level[{name}]"));
        close(l.value, nums(&want["levels"])[s], 1e-6, name);
        close(
            l.std_error.expect("se"),
            nums(&want["se_levels_iid"])[s],
            1e-6,
            name,
        );
        assert!(l.published.is_none() && l.t_test.is_none());
    }
}

/// kb-mu: each μ-line has its own residual variance (iid: per-output OLS), the clustered
/// standard errors of the stacked outputs match statsmodels, the α have no published value and
/// no t-test, and every bounded solve (fit, folds, replicates) meets its KKT conditions.
#[test]
fn ko_badler_lines_have_per_output_variances_and_checked_bounded_solves() {
    let tables = bundled();
    let want = &reference()["kb-mu"];
    let names: Vec<&str> = want["names"]
        .as_array()
        .expect("names")
        .iter()
        .map(|v| v.as_str().expect("name"))
        .collect();
    let cr1 = fit(&tables, "kb-mu", SeMethod::Cluster);
    let iid = fit(&tables, "kb-mu", SeMethod::Iid);
    assert_eq!(cr1.n as f64, num(&want["n"]));
    assert_eq!(cr1.n_subjects as f64, num(&want["clusters"]));
    for name in &names {
        close(coef(&cr1, name).value, num(&want["coef"][name]), 1e-9, name);
        close(
            coef(&cr1, name).std_error.expect("se"),
            num(&want["se_cr1"][name]),
            1e-9,
            &format!("{name} CR1"),
        );
        close(
            coef(&iid, name).std_error.expect("se"),
            num(&want["se_iid_per_output"][name]),
            1e-9,
            &format!("{name} iid per output"),
        );
    }
    for a in ["alpha1", "alpha2", "alpha3", "alpha4"] {
        let c = coef(&cr1, a);
        assert!(c.published.is_none() && c.t_test.is_none(), "{a}");
    }
    assert!(coef(&cr1, "alpha1").held.is_some());
    let b = cr1.bounded.as_ref().expect("bounded record");
    // The fit and one solve per fold (no bootstrap here).
    assert_eq!(b.solves, 1 + cr1.n_subjects);
    assert_eq!(b.converged, b.solves);
    assert!(cr1.loso_rmse.is_some());
}

/// Huber (`--robust`): the M-estimate, its scale and Huber's H1 sandwich standard errors (with
/// `--se iid`) against statsmodels RLM, and the clustered CR1 sandwich (the default with several
/// subjects) against numpy from RLM's own residuals, scale and ψ (`tools/reference/robust.json`,
/// made by `tools/reference/robust.py`: `RLM(y, X, M=HuberT(1.345)).fit(scale_est='mad',
/// cov='H1')` on the same rows).
#[test]
fn huber_standard_errors_match_statsmodels_rlm_h1_and_the_clustered_sandwich() {
    let p = root().join("tools/reference/robust.json");
    let want: Value =
        serde_json::from_str(&std::fs::read_to_string(&p).expect("reference file")).expect("json");
    let tables = bundled();
    for (id, names) in [
        ("walk-tds-sf", &["d0", "d1"][..]),
        ("walk-sl-sf", &["k"][..]),
    ] {
        let w = &want[id];
        // Rows independent: H1 (statsmodels RLM). Clustered (the default with several
        // subjects, and --se cluster): the M-estimator's CR1 sandwich by subject, computed in
        // the script from RLM's residuals, scale and ψ.
        for (se, key, df) in [
            (SeMethod::Iid, "se_h1", None),
            (SeMethod::Cluster, "se_cr1", Some(num(&w["clusters"]) - 1.0)),
            (SeMethod::Cr2, "se_cr1", Some(num(&w["clusters"]) - 1.0)),
        ] {
            let opts = FitOptions {
                robust: true,
                se: Some(se),
                ..FitOptions::default()
            };
            let rel = by_id(id).expect("relation");
            let rec = fit_relation(rel.as_ref(), &tables, &opts)
                .expect("fit")
                .record;
            assert_eq!(rec.n as f64, num(&w["n"]), "{id} rows");
            let rob = rec.robust.as_ref().expect("robust record");
            assert!(rob.converged, "{id}: IRLS did not converge");
            close(rob.scale, num(&w["scale"]), 1e-6, &format!("{id} scale"));
            assert_eq!(rob.rows_downweighted as f64, num(&w["rows_downweighted"]));
            let how = rob.cov.as_deref().expect("cov text");
            assert_eq!(how.contains("by subject (CR1"), df.is_some(), "{id}: {how}");
            let coefs = nums(&w["coef"]);
            let ses = nums(&w[key]);
            for (j, name) in names.iter().enumerate() {
                let c = rob
                    .coefficients
                    .iter()
                    .find(|c| c.name == *name)
                    .expect("robust coefficient");
                close(c.value, coefs[j], 1e-6, &format!("{id} {name}"));
                let se_got = c.std_error.expect("robust se");
                close(se_got, ses[j], 1e-6, &format!("{id} {name} {key}"));
                if let Some(df) = df {
                    let [lo, hi] = c.ci95;
                    let t = gaitfit::fit::stats::t_quantile(0.975, df);
                    close(
                        hi.expect("hi") - lo.expect("lo"),
                        2.0 * t * ses[j],
                        1e-6,
                        &format!("{id} {name} interval width (t, {df} df)"),
                    );
                }
            }
        }
    }
}

/// `--random-subject`: the random-intercept REML fit of the linear relations against statsmodels
/// `MixedLM(reml=True)` (`tools/reference/mixed.json`, written by `tools/reference/mixed.py`):
/// fixed effects, both variance components and the REML log-likelihood to 1e-6; fixed-effect
/// standard errors against sqrt(diag((XᵀV̂⁻¹X)⁻¹)) computed densely in the script at
/// statsmodels' estimates (the usual REML standard errors; statsmodels' own `bse_fe` come from
/// a joint Hessian, see the script).
#[test]
fn random_intercept_reml_matches_statsmodels_mixedlm() {
    let tables = bundled();
    let p = root().join("tools/reference/mixed.json");
    let refs: Value =
        serde_json::from_str(&std::fs::read_to_string(&p).expect("mixed.json")).expect("json");
    for (id, names) in [
        ("walk-tds-sf", &["d0", "d1"][..]),
        ("walk-sl-sf", &["k"][..]),
    ] {
        let want = &refs[id];
        let rel = by_id(id).expect("relation");
        let opts = FitOptions {
            random_subject: true,
            ..FitOptions::default()
        };
        let r = fit_relation(rel.as_ref(), &tables, &opts)
            .expect("fit")
            .record;
        let m = r.random_subject.as_ref().expect("random_subject record");
        assert_eq!(r.n as u64, want["n"].as_u64().expect("n"), "{id}: rows");
        for (j, name) in names.iter().enumerate() {
            let c = &m.coefficients[j];
            assert_eq!(c.name, *name);
            close(
                c.value,
                num(&want["coef"][j]),
                1e-6,
                &format!("{id} {name}"),
            );
            close(
                c.std_error,
                num(&want["se"][j]),
                1e-6,
                &format!("{id} se({name})"),
            );
        }
        // σ_u² = λ σ_e² sits where the REML criterion is flat: −2ℓ ≈ 1.4e3 with a curvature of
        // ≈ 0.5 per (log λ)², so f64 resolves its minimum only to ≈ √(2·1.4e3·2.2e-16/0.5) ≈
        // 1e-6 in log λ, i.e. 1e-6 relative in σ_u² for any optimiser (walk-sl-sf on the data
        // regenerated for the event defaults: gaitfit 1.8e-6 from statsmodels, statsmodels 1.4e-7
        // from a numpy profile of the criterion). Hence 1e-5 here, 1e-6 elsewhere.
        close(
            m.subject_sd.powi(2),
            num(&want["subject_var"]),
            1e-5,
            &format!("{id} σ_u²"),
        );
        close(
            m.residual_sd.powi(2),
            num(&want["residual_var"]),
            1e-6,
            &format!("{id} σ_e²"),
        );
        close(
            m.reml_log_likelihood,
            num(&want["reml_llf"]),
            1e-9,
            &format!("{id} REML log-likelihood"),
        );
    }
}

#[test]
fn wild_cluster_bootstrap_matches_the_numpy_enumeration() {
    let reference: Value = serde_json::from_str(
        &std::fs::read_to_string(root().join("tools/reference/wild.json")).expect("wild.json"),
    )
    .expect("json");
    let tables = bundled();
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
