//! `kb-mu`: the bounded fit of the μ-functions (Ko & Badler 1993, appendix A) against an
//! independent closed form, on synthetic data with known coefficients, and the committed
//! `fits/ko-badler/kb-mu.json` against a refit of the bundled trials tables.
use gaitfit::generator::generalize::prototype::Prototype;
use gaitfit::generator::generalize::DEFAULT_ALPHA;
use gaitfit::relations::kb_mu::{bounds, fit, fit_tables, separable_line, MuObservation};
use rand::{Rng, SeedableRng};
use std::path::PathBuf;

fn bundled_tables() -> Vec<PathBuf> {
    let d = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("data");
    vec![d.join("walk_schreiber2019.csv"), d.join("walk_bmclab.csv")]
}

/// The model is separable per μ, so the bounded least-squares optimum is each μ's own line
/// with its slope clamped into the bounds and the intercept refitted — computed here in closed
/// form, independently of argmin.
#[test]
fn bounded_fit_equals_clamped_separable_lines() {
    let p = Prototype::bundled();
    let f = fit_tables(&bundled_tables(), &p, None).unwrap();
    let sl = p.walk.step_length();
    let tables: Vec<_> = bundled_tables()
        .iter()
        .map(|p| gaitfit::ingest::trials::read_trials(p).unwrap())
        .collect();
    let (obs, _, _) = gaitfit::relations::kb_mu::observations(&tables, p.walk.body().leg_length());
    let b = bounds();
    for (i, bi) in b.iter().enumerate().take(4) {
        let (alpha, mu) = separable_line(&obs, i, sl, *bi);
        let a = f.get(&format!("alpha{}", i + 1)).unwrap();
        let m = f.get(&format!("mu{}_star", i + 1)).unwrap();
        // On an active bound MINUIT's sine transform flattens the cost, and the stopping rule
        // leaves the coupled intercept ≈ 3e-5 rad (0.002°) short; elsewhere 1e-6.
        let on_bound = f.coefficients[i].flag.is_some();
        let tol = if on_bound { 1e-4 } else { 1e-6 };
        assert!(
            (a - alpha).abs() < tol,
            "alpha{}: nls {a} vs closed form {alpha}",
            i + 1
        );
        assert!(
            (m - mu).abs() < tol,
            "mu{}_star: nls {m} vs closed form {mu}",
            i + 1
        );
    }
}

fn synthetic(alpha: [f64; 4], mu: [f64; 4], seed: u64) -> Vec<MuObservation> {
    let mut r = rand_chacha::ChaCha8Rng::seed_from_u64(seed);
    let mut out = Vec::new();
    for s in 0..8 {
        for _ in 0..5 {
            let x = r.random_range(0.55..0.9);
            for i in 0..4 {
                let sign = if i == 0 { -1.0 } else { 1.0 };
                let noise: f64 = r.random_range(-0.01..0.01);
                out.push(MuObservation {
                    subject: format!("s{s}"),
                    index: i,
                    x,
                    y: sign * alpha[i] * (x - 0.7) + mu[i] + noise,
                });
            }
        }
    }
    out
}

#[test]
fn recovers_known_coefficients_inside_the_bounds() {
    let (alpha, mu) = ([0.15, 0.4, 0.8, 1.1], [0.05, 0.4, 1.2, 0.9]);
    let f = fit(&synthetic(alpha, mu, 1), 0.7, 0.8, vec![]).unwrap();
    for i in 0..4 {
        assert!((f.alpha()[i] - alpha[i]).abs() < 0.05, "{:?}", f.alpha());
        assert!((f.get(&format!("mu{}_star", i + 1)).unwrap() - mu[i]).abs() < 0.01);
    }
    assert!(f.coefficients.iter().all(|c| c.flag.is_none()));
}

#[test]
fn reports_an_active_bound() {
    // True α₁ = −0.2 (knee flexes more in longer steps): the fit must stop at 0 and say so.
    let obs = synthetic([-0.2, 0.4, 0.8, 1.1], [0.05, 0.4, 1.2, 0.9], 2);
    let f = fit(&obs, 0.7, 0.8, vec![]).unwrap();
    assert!(f.alpha()[0].abs() < 1e-6);
    let c = f.coefficients.iter().find(|c| c.name == "alpha1").unwrap();
    assert!(c.flag.as_deref().unwrap_or("").contains("bound active"));
    assert!(c.std_error.is_none());
    let (a, m) = separable_line(&obs, 0, 0.7, bounds()[0]);
    assert!(a.abs() < 1e-12 && (f.get("mu1_star").unwrap() - m).abs() < 1e-6);
    // α₁ above 0.3 stops at 0.3.
    let f = fit(
        &synthetic([0.6, 0.4, 0.8, 1.1], [0.05, 0.4, 1.2, 0.9], 3),
        0.7,
        0.8,
        vec![],
    )
    .unwrap();
    assert!((f.alpha()[0] - 0.3).abs() < 1e-6);
}

/// `fits/ko-badler/kb-mu.json` is what refitting the bundled tables gives, and the generator's default
/// slopes are its α.
#[test]
fn committed_fit_is_reproducible_and_is_the_default() {
    let p = Prototype::bundled();
    let f = fit_tables(&bundled_tables(), &p, None).unwrap();
    let path = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("fits/ko-badler/kb-mu.json");
    let set = gaitfit::relations::CoefficientSet::from_fit_file(&path).unwrap();
    assert_eq!(set.relation, "kb-mu");
    for c in &f.coefficients {
        let v = set.get(&c.name).unwrap();
        assert!(
            (v - c.value).abs() < 1e-9,
            "{}: committed {v}, refit {}",
            c.name,
            c.value
        );
    }
    for (i, a) in DEFAULT_ALPHA.iter().enumerate() {
        let v = set.get(&format!("alpha{}", i + 1)).unwrap();
        assert!((v - a).abs() < 1e-12);
    }
}
