//! The linear layer against independent computations: normal equations (Cholesky), explicit
//! √w row scaling, row replication, brute-force leave-one-out refits, Huber's estimating
//! equations, and the typed errors.
use gaitfit::fit::ols::{
    huber_irls, ols, ols_coef_rss, polynomial_design, polynomial_fit, LinearProblem,
};
use gaitfit::fit::stats;
use gaitfit::fit::FitError;
use nalgebra::{DMatrix, DVector};
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;

fn random_problem(n: usize, seed: u64) -> (DMatrix<f64>, DVector<f64>) {
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    let beta = [1.5, -2.0, 0.25, 3.0, -0.75];
    let x = DMatrix::from_fn(n, 5, |_, j| {
        if j == 0 {
            1.0
        } else {
            rng.random_range(-2.0..2.0) + j as f64
        }
    });
    let y = DVector::from_fn(n, |i, _| {
        (0..5).map(|j| beta[j] * x[(i, j)]).sum::<f64>() + rng.random_range(-0.5..0.5)
    });
    (x, y)
}

fn rel(a: f64, b: f64) -> f64 {
    (a - b).abs() / b.abs().max(1e-300)
}

/// Normal equations, solved by Cholesky: an independent (if less stable) computation that is
/// exact enough on a well-conditioned problem.
fn normal_equations(
    x: &DMatrix<f64>,
    y: &DVector<f64>,
    w: Option<&DVector<f64>>,
) -> (DVector<f64>, DMatrix<f64>) {
    let wm = match w {
        Some(w) => DMatrix::from_diagonal(w),
        None => DMatrix::identity(x.nrows(), x.nrows()),
    };
    let xtwx = x.transpose() * &wm * x;
    let xtwy = x.transpose() * &wm * y;
    let chol = xtwx.clone().cholesky().expect("well-conditioned");
    (chol.solve(&xtwy), chol.inverse())
}

#[test]
fn ols_matches_normal_equations() {
    let (x, y) = random_problem(200, 1);
    let fit = ols(&LinearProblem::new(&x, &y)).unwrap();
    let (beta, xtx_inv) = normal_equations(&x, &y, None);
    for j in 0..5 {
        assert!(
            rel(fit.coef[j], beta[j]) < 1e-9,
            "coef {j}: {} vs {}",
            fit.coef[j],
            beta[j]
        );
    }
    let resid = &y - &x * &beta;
    let rss = resid.norm_squared();
    assert!(rel(fit.rss, rss) < 1e-9);
    let s2 = rss / 195.0;
    for a in 0..5 {
        for b in 0..5 {
            assert!(
                rel(fit.cov[(a, b)], s2 * xtx_inv[(a, b)]) < 1e-9,
                "cov {a},{b}"
            );
        }
    }
    let hat = &x * &xtx_inv * x.transpose();
    for i in 0..200 {
        assert!((fit.leverage[i] - hat[(i, i)]).abs() < 1e-12);
        assert!((fit.residuals[i] - resid[i]).abs() < 1e-9);
    }
    let ybar = y.mean();
    let tss: f64 = y.iter().map(|v| (v - ybar).powi(2)).sum();
    assert!(rel(fit.r2, 1.0 - rss / tss) < 1e-12);
    assert!(rel(fit.adj_r2, 1.0 - (1.0 - fit.r2) * 199.0 / 195.0) < 1e-12);
    assert_eq!((fit.n, fit.p, fit.df_resid, fit.rank), (200, 5, 195, 5));
    assert!(fit.condition_number >= 1.0 && fit.condition_number < 10.0);
    // The coefficient-only path agrees.
    let (c2, rss2) = ols_coef_rss(&LinearProblem::new(&x, &y)).unwrap();
    assert!((0..5).all(|j| rel(c2[j], fit.coef[j]) < 1e-12));
    assert!(rel(rss2, fit.rss) < 1e-9);
}

#[test]
fn ols_streams_many_blocks_identically() {
    // 5000 rows span ten QR blocks; the answer must not depend on the blocking.
    let (x, y) = random_problem(5000, 2);
    let fit = ols(&LinearProblem::new(&x, &y)).unwrap();
    let (beta, _) = normal_equations(&x, &y, None);
    for j in 0..5 {
        assert!(rel(fit.coef[j], beta[j]) < 1e-9);
    }
}

#[test]
fn weighted_fit_equals_explicit_sqrt_w_scaling() {
    let (x, y) = random_problem(60, 3);
    let mut rng = ChaCha8Rng::seed_from_u64(33);
    let w = DVector::from_fn(60, |_, _| rng.random_range(0.2..5.0));
    let fit = ols(&LinearProblem::new(&x, &y).with_weights(&w)).unwrap();
    // Scale rows by √w and fit unweighted (no intercept column any more, so r² differs by
    // definition; coefficients, SEs and RSS must not).
    let sw = w.map(f64::sqrt);
    let xs = DMatrix::from_fn(60, 5, |i, j| sw[i] * x[(i, j)]);
    let ys = y.component_mul(&sw);
    let scaled = ols(&LinearProblem::new(&xs, &ys).with_intercept(false)).unwrap();
    for j in 0..5 {
        assert!(rel(fit.coef[j], scaled.coef[j]) < 1e-10);
        assert!(rel(fit.std_error[j], scaled.std_error[j]) < 1e-10);
    }
    assert!(rel(fit.rss, scaled.rss) < 1e-10);
    let (beta, _) = normal_equations(&x, &y, Some(&w));
    for j in 0..5 {
        assert!(rel(fit.coef[j], beta[j]) < 1e-9);
    }
    // Weighted r² is 1 − RSS_w / Σ w (y − ȳ_w)².
    let ybar = w.dot(&y) / w.sum();
    let tss: f64 = (0..60).map(|i| w[i] * (y[i] - ybar).powi(2)).sum();
    assert!(rel(fit.r2, 1.0 - fit.rss / tss) < 1e-12);
}

#[test]
fn integer_weights_equal_replicated_rows() {
    let (x, y) = random_problem(20, 4);
    let reps: Vec<usize> = (0..20).map(|i| 1 + i % 3).collect();
    let w = DVector::from_iterator(20, reps.iter().map(|&r| r as f64));
    let fit = ols(&LinearProblem::new(&x, &y).with_weights(&w)).unwrap();
    let rows: Vec<usize> = (0..20)
        .flat_map(|i| std::iter::repeat_n(i, reps[i]))
        .collect();
    let xr = DMatrix::from_fn(rows.len(), 5, |r, j| x[(rows[r], j)]);
    let yr = DVector::from_fn(rows.len(), |r, _| y[rows[r]]);
    let rep = ols(&LinearProblem::new(&xr, &yr)).unwrap();
    for j in 0..5 {
        assert!(rel(fit.coef[j], rep.coef[j]) < 1e-10);
    }
    assert!(rel(fit.rss, rep.rss) < 1e-10);
}

#[test]
fn press_equals_brute_force_refits() {
    let (x, y) = random_problem(30, 5);
    let fit = ols(&LinearProblem::new(&x, &y)).unwrap();
    let mut sse = 0.0;
    for i in 0..30 {
        let keep: Vec<usize> = (0..30).filter(|&r| r != i).collect();
        let xt = DMatrix::from_fn(29, 5, |r, j| x[(keep[r], j)]);
        let yt = DVector::from_fn(29, |r, _| y[keep[r]]);
        let f = ols(&LinearProblem::new(&xt, &yt)).unwrap();
        let row: Vec<f64> = (0..5).map(|j| x[(i, j)]).collect();
        sse += (y[i] - f.predict(&row)).powi(2);
    }
    let brute = (sse / 30.0).sqrt();
    assert!(
        rel(fit.press_rmse(), brute) < 1e-10,
        "{} vs {brute}",
        fit.press_rmse()
    );
}

#[test]
fn no_intercept_fit_reports_uncentred_r2() {
    let x = DMatrix::from_column_slice(5, 1, &[1.0, 2.0, 3.0, 4.0, 5.0]);
    let y = DVector::from_vec(vec![2.1, 3.9, 6.2, 7.8, 10.1]);
    let fit = ols(&LinearProblem::new(&x, &y).with_intercept(false)).unwrap();
    // k = Σxy/Σx² = (2.1 + 7.8 + 18.6 + 31.2 + 50.5)/55 = 110.2/55.
    assert!(rel(fit.coef[0], 110.2 / 55.0) < 1e-14);
    assert!(fit.uncentred);
    let syy: f64 = y.iter().map(|v| v * v).sum();
    assert!(rel(fit.r2, 1.0 - fit.rss / syy) < 1e-14);
    assert!(rel(fit.adj_r2, 1.0 - (1.0 - fit.r2) * 5.0 / 4.0) < 1e-14);
}

#[test]
fn polynomial_fit_matches_raw_ols_and_bands() {
    let mut rng = ChaCha8Rng::seed_from_u64(6);
    let x: Vec<f64> = (0..40).map(|i| 1.0 + 0.05 * i as f64).collect();
    let y: Vec<f64> = x
        .iter()
        .map(|v| 0.3 - 1.2 * v + 0.4 * v * v + rng.random_range(-0.01..0.01))
        .collect();
    let pf = polynomial_fit(&x, &y, 2, None).unwrap();
    let xd = polynomial_design(&x, 2);
    let yv = DVector::from_vec(y.clone());
    let raw = ols(&LinearProblem::new(&xd, &yv)).unwrap();
    for j in 0..3 {
        assert!(rel(pf.coef[j], raw.coef[j]) < 1e-9);
        assert!(rel(pf.std_error[j], raw.std_error[j]) < 1e-9);
    }
    assert!(rel(pf.rss, raw.rss) < 1e-9);
    for &xv in &[1.0, 1.7, 2.95] {
        let row = [1.0, xv, xv * xv];
        assert!(rel(pf.poly_predict(xv), raw.predict(&row)) < 1e-12);
        let a = pf.poly_mean_ci(xv, 0.95);
        let b = raw.mean_ci(&row, 0.95);
        assert!((a[0] - b[0]).abs() < 1e-9 && (a[1] - b[1]).abs() < 1e-9);
        // Hand computation of the band half-width.
        let r = DVector::from_column_slice(&row);
        let se = (r.transpose() * &raw.cov * &r)[(0, 0)].sqrt();
        let half = stats::t_quantile(0.975, 37.0) * se;
        assert!(((b[1] - b[0]) / 2.0 - half).abs() < 1e-12);
        let pi = raw.predict_interval(&row, 0.95);
        assert!(pi[1] - pi[0] > b[1] - b[0]);
    }
    let ci = pf.ci(0.95);
    let t = pf.t_test(1, -1.2);
    assert!(ci[1][0] < pf.coef[1] && pf.coef[1] < ci[1][1]);
    assert!(rel(t.t, (pf.coef[1] + 1.2) / pf.std_error[1]) < 1e-12);
    assert!(t.p_value > 0.0 && t.p_value <= 1.0);
}

#[test]
fn information_criteria_by_hand() {
    let (x, y) = random_problem(50, 7);
    let fit = ols(&LinearProblem::new(&x, &y)).unwrap();
    let n = 50.0;
    let ll = -0.5 * n * ((2.0 * std::f64::consts::PI).ln() + (fit.rss / n).ln() + 1.0);
    assert!(rel(fit.aic(), 2.0 * 6.0 - 2.0 * ll) < 1e-12);
    assert!(rel(fit.bic(), 6.0 * n.ln() - 2.0 * ll) < 1e-12);
}

/// Huber ψ.
fn psi(r: f64, k: f64) -> f64 {
    r.clamp(-k, k)
}

#[test]
fn huber_location_satisfies_its_estimating_equations() {
    // Intercept-only: the Huber M-estimate of location with MAD scale.
    let y = DVector::from_vec(vec![1.0, 2.0, 3.0, 4.0, 5.0, 6.0, 7.0, 8.0, 9.0, 50.0]);
    let x = DMatrix::from_element(10, 1, 1.0);
    let h = huber_irls(&LinearProblem::new(&x, &y), 1.345, 100).unwrap();
    assert!(h.converged);
    let mu = h.fit.coef[0];
    // Hand check: at the fixed point s = 1.4826·median|yᵢ − μ| and Σ ψ((yᵢ − μ)/s) = 0.
    let abs: Vec<f64> = y.iter().map(|v| (v - mu).abs()).collect();
    let s = 1.482_602_218_505_602 * stats::median(&abs);
    assert!(rel(h.scale, s) < 1e-8);
    let eq: f64 = y.iter().map(|v| psi((v - mu) / s, 1.345)).sum();
    assert!(eq.abs() < 1e-7, "Σψ = {eq}");
    // The mean is 9.5; the outlier pulls it far less: μ lies between median 5.5 and 6.5.
    assert!(mu > 5.5 && mu < 6.5, "μ = {mu}");
    // Only the outlier (and maybe the extreme inliers) are down-weighted.
    assert!(h.robust_weights[9] < 0.2);
    assert_eq!(h.robust_weights[4], 1.0);
}

#[test]
fn huber_line_with_outliers() {
    let mut rng = ChaCha8Rng::seed_from_u64(8);
    let xs: Vec<f64> = (0..40).map(|i| i as f64 * 0.25).collect();
    let mut y: Vec<f64> = xs
        .iter()
        .map(|v| 2.0 + 0.5 * v + rng.random_range(-0.2..0.2))
        .collect();
    y[5] += 8.0;
    y[30] -= 10.0;
    let x = DMatrix::from_fn(40, 2, |i, j| if j == 0 { 1.0 } else { xs[i] });
    let yv = DVector::from_vec(y);
    let p = LinearProblem::new(&x, &yv);
    let plain = ols(&p).unwrap();
    let h = huber_irls(&p, 1.345, 200).unwrap();
    assert!(h.converged);
    assert!((h.fit.coef[1] - 0.5).abs() < (plain.coef[1] - 0.5).abs());
    assert!((h.fit.coef[1] - 0.5).abs() < 0.02);
    // Estimating equations Xᵀψ(r/s) = 0 at the solution.
    for j in 0..2 {
        let eq: f64 = (0..40)
            .map(|i| x[(i, j)] * psi(h.fit.residuals[i] / h.scale, 1.345))
            .sum();
        assert!(eq.abs() < 1e-6, "equation {j}: {eq}");
    }
    assert!(h.robust_weights[5] < 0.5 && h.robust_weights[30] < 0.5);
    assert!(huber_irls(&p, 0.0, 10).is_err());
}

#[test]
fn singular_designs_name_the_columns() {
    let x = DMatrix::from_fn(10, 3, |i, j| match j {
        0 => 1.0,
        1 => i as f64,
        _ => 2.0 * i as f64 + 1.0, // = 1 + 2·column 1: collinear with the intercept and x
    });
    let y = DVector::from_fn(10, |i, _| (i as f64).sin());
    let names = vec!["one".to_string(), "speed".to_string(), "speed2".to_string()];
    let err = ols(&LinearProblem::new(&x, &y)
        .named("run-sl-v")
        .with_column_names(&names))
    .unwrap_err();
    match &err {
        FitError::Singular { relation, message } => {
            assert_eq!(relation, "run-sl-v");
            assert!(
                message.contains("speed") && message.contains("speed2"),
                "{message}"
            );
        }
        other => panic!("expected Singular, got {other:?}"),
    }
    // A second constant column duplicates the intercept.
    let x = DMatrix::from_fn(10, 3, |i, j| match j {
        0 => 1.0,
        1 => i as f64,
        _ => 3.0,
    });
    assert!(matches!(
        ols(&LinearProblem::new(&x, &y)),
        Err(FitError::Singular { .. })
    ));
    // polynomial_fit with a single distinct x.
    assert!(matches!(
        polynomial_fit(&[2.0; 5], &[1.0, 2.0, 3.0, 4.0, 5.0], 1, None),
        Err(FitError::Singular { .. })
    ));
}

#[test]
fn bad_inputs_give_typed_errors() {
    let x = DMatrix::from_fn(3, 3, |i, j| (i * j) as f64 + if j == 0 { 1.0 } else { 0.0 });
    let y = DVector::from_vec(vec![1.0, 2.0, 3.0]);
    assert!(matches!(
        ols(&LinearProblem::new(&x, &y)),
        Err(FitError::TooFew {
            have: 3,
            need: 4,
            ..
        })
    ));
    assert!(matches!(
        polynomial_fit(&[1.0, 2.0, 3.0], &[1.0, 2.0, 3.0], 2, None),
        Err(FitError::TooFew { .. })
    ));
    let (x, y) = random_problem(10, 9);
    let mut w = DVector::from_element(10, 1.0);
    w[3] = -1.0;
    assert!(matches!(
        ols(&LinearProblem::new(&x, &y).with_weights(&w)),
        Err(FitError::InvalidInput { .. })
    ));
    w[3] = f64::INFINITY;
    assert!(matches!(
        ols(&LinearProblem::new(&x, &y).with_weights(&w)),
        Err(FitError::NonFinite { row: 3, .. })
    ));
    let mut y2 = y.clone();
    y2[7] = f64::NAN;
    let e = ols(&LinearProblem::new(&x, &y2)).unwrap_err();
    assert!(e.to_string().contains("row 7"), "{e}");
    let short = DVector::from_element(9, 1.0);
    assert!(matches!(
        ols(&LinearProblem::new(&x, &short)),
        Err(FitError::InvalidInput { .. })
    ));
}
