//! Golden round trip: refitting the bundled `data/` reproduces the committed `fits/` (same data
//! hash, same rows, coefficients and statistics to 1e-9 relative). After regenerating `data/` or
//! changing the fit, run `cargo run --release -- fit` and commit `fits/` and `reports/`.
use gaitfit::export::coeffs::read_fits_dir;
use gaitfit::fit::inference::SeMethod;
use gaitfit::fit::pipeline::{fit_relation, load_tables, FitOptions};
use gaitfit::relations::by_id;
use std::path::{Path, PathBuf};

fn close(a: f64, b: f64) -> bool {
    a == b || (a - b).abs() <= 1e-9 * a.abs().max(b.abs()).max(1e-300)
}

#[test]
fn refitting_bundled_data_reproduces_committed_fits() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let mut bad: Vec<String> = Vec::new();
    let fits = read_fits_dir(&root.join("fits")).expect("fits/ readable");
    let have_data = std::fs::read_dir(root.join("data"))
        .map(|d| {
            d.filter_map(|e| e.ok())
                .any(|e| e.path().extension().is_some_and(|x| x == "csv"))
        })
        .unwrap_or(false);
    if have_data {
        assert!(
            fits.len() >= 5,
            "data/*.csv exist but fits/ has {} records: run `gaitfit fit`",
            fits.len()
        );
    }
    for (path, committed) in fits {
        let files: Vec<PathBuf> = committed
            .data
            .files
            .iter()
            .map(|f| root.join(&f.path))
            .collect();
        let tables = load_tables(&files, None).expect("committed data readable");
        for (t, f) in tables.iter().zip(&committed.data.files) {
            assert_eq!(
                t.sha256,
                f.sha256,
                "{} changed since {} was fitted: rerun `gaitfit fit`",
                f.path,
                path.display()
            );
        }
        let rel = by_id(&committed.relation).unwrap();
        let opts = FitOptions {
            robust: committed.robust.is_some(),
            weights: committed.weights.clone(),
            bootstrap: committed.bootstrap.as_ref().map_or(0, |b| b.n),
            seed: committed.bootstrap.as_ref().map_or(0, |b| b.seed),
            se: committed
                .inference
                .as_ref()
                .and_then(|i| match i.method.as_str() {
                    "iid" => Some(SeMethod::Iid),
                    "CR1" => Some(SeMethod::Cluster),
                    "CR2" => Some(SeMethod::Cr2),
                    _ => None,
                }),
            random_subject: committed.random_subject.is_some(),
        };
        let now = fit_relation(rel.as_ref(), &tables, &opts).unwrap().record;
        assert_eq!(now.n, committed.n, "{}", committed.relation);
        assert_eq!(now.coefficients.len(), committed.coefficients.len());
        for (a, b) in now.coefficients.iter().zip(&committed.coefficients) {
            assert_eq!(a.name, b.name);
            if !close(a.value, b.value) {
                bad.push(format!(
                    "{} {}: {} vs committed {}",
                    committed.relation, a.name, a.value, b.value
                ));
            }
            assert_eq!(
                a.held.is_some(),
                b.held.is_some(),
                "{} {}",
                committed.relation,
                a.name
            );
        }
        for (what, a, b) in [
            ("r2", now.r2, committed.r2),
            ("rmse", now.rmse, committed.rmse),
            ("loo_rmse", now.loo_rmse, committed.loo_rmse),
            ("aic", now.aic, committed.aic),
        ] {
            if !close(a, b) {
                bad.push(format!(
                    "{} {what}: {a} vs committed {b}",
                    committed.relation
                ));
            }
        }
        match (now.loso_rmse, committed.loso_rmse) {
            (Some(a), Some(b)) => {
                if !close(a, b) {
                    bad.push(format!("{} loso: {a} vs committed {b}", committed.relation));
                }
            }
            (a, b) => assert_eq!(a, b),
        }
    }
    assert!(
        bad.is_empty(),
        "differences from the committed fits:\n{}",
        bad.join("\n")
    );
}
