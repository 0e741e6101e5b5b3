//! The argmin layer against independent computations: on models that are linear in their
//! parameters `nls` must reproduce `ols` (coefficients, SEs, leverages, PRESS, bands); bounds
//! are reported as active; the 1-D minimiser finds a profiled breakpoint that a fine grid
//! confirms; bad input gives typed errors.
use gaitfit::fit::nonlinear::{minimize_1d, nls, FnModel, Model, NlsOptions, Rows};
use gaitfit::fit::ols::{ols, ols_coef_rss, LinearProblem};
use gaitfit::fit::FitError;
use nalgebra::{DMatrix, DVector};
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;

fn rel(a: f64, b: f64) -> f64 {
    (a - b).abs() / b.abs().max(1e-300)
}

/// y = a + b·x + c·x² as a "nonlinear" model with an analytic gradient.
struct Quadratic;
impl Model for Quadratic {
    fn n_params(&self) -> usize {
        3
    }
    fn value(&self, x: &[f64], t: &[f64]) -> f64 {
        t[0] + t[1] * x[0] + t[2] * x[0] * x[0]
    }
    fn gradient(&self, x: &[f64], _t: &[f64], g: &mut [f64]) {
        g[0] = 1.0;
        g[1] = x[0];
        g[2] = x[0] * x[0];
    }
}

fn data(n: usize, seed: u64) -> (Vec<f64>, Vec<f64>) {
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    let x: Vec<f64> = (0..n).map(|i| i as f64 / n as f64 * 4.0).collect();
    let y = x
        .iter()
        .map(|v| 1.0 - 0.5 * v + 0.3 * v * v + rng.random_range(-0.2..0.2))
        .collect();
    (x, y)
}

#[test]
fn nls_on_a_linear_model_equals_ols() {
    let (x, y) = data(50, 1);
    let fit = nls(
        &Quadratic,
        Rows::single(&x),
        &y,
        &[0.0, 0.0, 0.0],
        &NlsOptions::default(),
    )
    .unwrap();
    assert!(fit.converged, "{}", fit.termination);
    let xd = DMatrix::from_fn(50, 3, |i, j| x[i].powi(j as i32));
    let yv = DVector::from_vec(y.clone());
    let lin = ols(&LinearProblem::new(&xd, &yv)).unwrap();
    for j in 0..3 {
        assert!(
            rel(fit.theta[j], lin.coef[j]) < 1e-9,
            "θ{j} {} vs {}",
            fit.theta[j],
            lin.coef[j]
        );
        assert!(rel(fit.std_error[j], lin.std_error[j]) < 1e-8);
    }
    assert!(rel(fit.rss, lin.rss) < 1e-12);
    assert!(rel(fit.r2, lin.r2) < 1e-12);
    for i in 0..50 {
        assert!((fit.leverage[i] - lin.leverage[i]).abs() < 1e-10);
    }
    assert!(rel(fit.press_rmse(), lin.press_rmse()) < 1e-8);
    assert!(rel(fit.aic(), lin.aic()) < 1e-12 && rel(fit.bic(), lin.bic()) < 1e-12);
    let a = fit.mean_ci(&Quadratic, &[2.5], 0.95);
    let b = lin.mean_ci(&[1.0, 2.5, 6.25], 0.95);
    assert!((a[0] - b[0]).abs() < 1e-8 && (a[1] - b[1]).abs() < 1e-8);
    let ci = fit.ci(0.95);
    let lci = lin.ci(0.95);
    assert!((ci[2][0] - lci[2][0]).abs() < 1e-8);
    assert!(rel(fit.t_test(2, 0.3).t, lin.t_test(2, 0.3).t) < 1e-6);
    assert_eq!(fit.active_bounds, vec![false; 3]);
}

#[test]
fn weighted_nls_equals_weighted_ols_and_fd_gradient_is_close() {
    let (x, y) = data(40, 2);
    let mut rng = ChaCha8Rng::seed_from_u64(22);
    let w: Vec<f64> = (0..40).map(|_| rng.random_range(0.5..4.0)).collect();
    let opts = NlsOptions {
        weights: Some(w.clone()),
        ..NlsOptions::default()
    };
    // Finite-difference gradient (the trait default) through a closure model.
    let fd = FnModel {
        n_params: 3,
        f: |x: &[f64], t: &[f64]| t[0] + t[1] * x[0] + t[2] * x[0] * x[0],
    };
    let fit = nls(&fd, Rows::single(&x), &y, &[1.0, 1.0, 1.0], &opts).unwrap();
    assert!(fit.converged, "{}", fit.termination);
    let xd = DMatrix::from_fn(40, 3, |i, j| x[i].powi(j as i32));
    let yv = DVector::from_vec(y.clone());
    let wv = DVector::from_vec(w);
    let lin = ols(&LinearProblem::new(&xd, &yv).with_weights(&wv)).unwrap();
    for j in 0..3 {
        assert!(rel(fit.theta[j], lin.coef[j]) < 1e-8, "θ{j}");
        assert!(rel(fit.std_error[j], lin.std_error[j]) < 1e-6);
    }
    assert!(rel(fit.sum_log_w, lin.sum_log_w) < 1e-12);
}

#[test]
fn exponential_from_a_poor_start() {
    // y = a(1 − e^{−b x}) (Misra1a/BoxBOD form), start two orders of magnitude off.
    let x: Vec<f64> = (1..=20).map(|i| i as f64 * 0.5).collect();
    let mut rng = ChaCha8Rng::seed_from_u64(3);
    let y: Vec<f64> = x
        .iter()
        .map(|v| 200.0 * (1.0 - (-0.4 * v).exp()) + rng.random_range(-1.0..1.0))
        .collect();
    let m = FnModel {
        n_params: 2,
        f: |x: &[f64], t: &[f64]| t[0] * (1.0 - (-t[1] * x[0]).exp()),
    };
    let fit = nls(
        &m,
        Rows::single(&x),
        &y,
        &[1.0, 0.01],
        &NlsOptions::default(),
    )
    .unwrap();
    assert!(fit.converged);
    assert!(
        (fit.theta[0] - 200.0).abs() < 2.0 && (fit.theta[1] - 0.4).abs() < 0.01,
        "{:?}",
        fit.theta
    );
    // First-order optimality: Jᵀr ≈ 0 relative to ‖J_k‖‖r‖.
    for k in 0..2 {
        let g: f64 = (0..20)
            .map(|i| fit.jacobian[(i, k)] * fit.residuals[i])
            .sum();
        let jn = fit.jacobian.column(k).norm();
        let rn = fit.residuals.iter().map(|r| r * r).sum::<f64>().sqrt();
        assert!(g.abs() / (jn * rn) < 1e-8);
    }
    // From b = 10 the model is saturated (e^{−5} at the first x) and the solver walks onto the
    // plateau where b has no effect: that is reported, not hidden behind a meaningless SE.
    match nls(
        &m,
        Rows::single(&x),
        &y,
        &[1.0, 10.0],
        &NlsOptions::default(),
    ) {
        Err(FitError::Singular { message, .. }) => assert!(message.contains("no effect")),
        Ok(f) => assert!((f.theta[1] - 0.4).abs() < 0.01, "{:?}", f.theta),
        Err(e) => panic!("{e}"),
    }
}

#[test]
fn bounds_active_and_inactive() {
    // Ko–Badler-style: α1 ∈ [0, 0.3] but the data want 0.5; α2 > 0 and the data want 2.
    let x: Vec<f64> = (0..30).map(|i| i as f64 / 10.0).collect();
    let y: Vec<f64> = x.iter().map(|v| 0.5 + 2.0 * v).collect();
    let m = FnModel {
        n_params: 2,
        f: |x: &[f64], t: &[f64]| t[0] + t[1] * x[0],
    };
    let opts = NlsOptions {
        bounds: Some(vec![(0.0, 0.3), (0.0, f64::INFINITY)]),
        ..NlsOptions::default()
    };
    let fit = nls(&m, Rows::single(&x), &y, &[0.1, 1.0], &opts).unwrap();
    assert!(fit.converged, "{}", fit.termination);
    assert_eq!(fit.active_bounds, vec![true, false]);
    assert!((fit.theta[0] - 0.3).abs() < 1e-6);
    // With α1 = 0.3 fixed, α2 = Σx(y − 0.3)/Σx².
    let sxy: f64 = x.iter().zip(&y).map(|(a, b)| a * (b - 0.3)).sum();
    let sxx: f64 = x.iter().map(|a| a * a).sum();
    assert!((fit.theta[1] - sxy / sxx).abs() < 1e-5, "{:?}", fit.theta);
    assert!(fit.std_error[0].is_nan() && fit.std_error[1].is_finite());
    let ci = fit.ci(0.95);
    assert!(ci[0][0].is_nan() && ci[1][0].is_finite());

    // Start on the bound is moved inside and still works; a start outside is an error.
    let fit2 = nls(&m, Rows::single(&x), &y, &[0.0, 1.0], &opts).unwrap();
    assert!((fit2.theta[0] - 0.3).abs() < 1e-6);
    let err = nls(&m, Rows::single(&x), &y, &[0.5, 1.0], &opts).unwrap_err();
    assert!(matches!(err, FitError::InvalidInput { .. }), "{err}");
}

#[test]
fn nls_bad_inputs() {
    let (x, y) = data(10, 4);
    let o = NlsOptions::default();
    assert!(matches!(
        nls(&Quadratic, Rows::single(&x), &y, &[0.0, 0.0], &o),
        Err(FitError::InvalidInput { .. })
    ));
    assert!(matches!(
        nls(&Quadratic, Rows::single(&x[..3]), &y[..3], &[0.0; 3], &o),
        Err(FitError::TooFew {
            have: 3,
            need: 4,
            ..
        })
    ));
    let mut y2 = y.clone();
    y2[4] = f64::NAN;
    assert!(matches!(
        nls(&Quadratic, Rows::single(&x), &y2, &[0.0; 3], &o),
        Err(FitError::NonFinite { row: 4, .. })
    ));
    assert!(Rows::new(&x, 3).is_err());
    let bad_w = NlsOptions {
        weights: Some(vec![0.0; 10]),
        ..NlsOptions::default()
    };
    assert!(nls(&Quadratic, Rows::single(&x), &y, &[0.0; 3], &bad_w).is_err());
    // Model not finite at the start.
    let m = FnModel {
        n_params: 1,
        f: |x: &[f64], t: &[f64]| (x[0] - t[0]).ln(),
    };
    assert!(nls(&m, Rows::single(&x), &y, &[100.0], &o).is_err());
}

#[test]
fn multi_input_rows() {
    // y = a·x0 + b·x1² with two inputs per row.
    let n = 25;
    let xs: Vec<f64> = (0..n).flat_map(|i| [i as f64, (i % 5) as f64]).collect();
    let rows = Rows::new(&xs, 2).unwrap();
    let y: Vec<f64> = (0..n)
        .map(|i| 1.5 * rows.row(i)[0] - 0.5 * rows.row(i)[1].powi(2))
        .collect();
    let m = FnModel {
        n_params: 2,
        f: |x: &[f64], t: &[f64]| t[0] * x[0] + t[1] * x[1] * x[1],
    };
    let fit = nls(&m, rows, &y, &[0.0, 0.0], &NlsOptions::default()).unwrap();
    assert!((fit.theta[0] - 1.5).abs() < 1e-8 && (fit.theta[1] + 0.5).abs() < 1e-8);
}

#[test]
fn profiled_breakpoint_matches_a_fine_grid() {
    // sl = a + b·min(v, v_norm): a hinge like the running relation's v_norm, with noise.
    let mut rng = ChaCha8Rng::seed_from_u64(5);
    let v: Vec<f64> = (0..300).map(|_| rng.random_range(2.0..8.0)).collect();
    let y: Vec<f64> = v
        .iter()
        .map(|s| 0.14 + 0.18 * s.min(6.3) + rng.random_range(-0.03..0.03))
        .collect();
    let yv = DVector::from_vec(y);
    let rss = |vn: f64| {
        let x = DMatrix::from_fn(300, 2, |i, j| if j == 0 { 1.0 } else { v[i].min(vn) });
        ols_coef_rss(&LinearProblem::new(&x, &yv)).map_or(f64::INFINITY, |r| r.1)
    };
    let (best, fbest) = minimize_1d(rss, 3.0, 7.9, 1e-8).unwrap();
    let grid_best = (0..=4900)
        .map(|k| 3.0 + k as f64 * 0.001)
        .map(|vn| (vn, rss(vn)))
        .min_by(|a, b| a.1.total_cmp(&b.1))
        .unwrap();
    assert!(fbest <= grid_best.1 + 1e-12, "{fbest} vs {}", grid_best.1);
    assert!((best - grid_best.0).abs() < 0.002);
    assert!((best - 6.3).abs() < 0.2);
}
