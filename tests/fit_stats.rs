//! Resampling helpers driven by real fits: leave-one-subject-out RMSE against a hand-written
//! loop, and the seeded group bootstrap (reproducible, thread-count independent, sensible CIs).
use gaitfit::fit::ols::{ols, LinearProblem};
use gaitfit::fit::stats::{bootstrap_by_group, leave_one_group_out, lre, unique_groups};
use nalgebra::{DMatrix, DVector};
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;

/// 8 subjects × 15 steps of sl = 0.14 + 0.18·v + subject offset + noise.
fn trials() -> (Vec<usize>, Vec<f64>, Vec<f64>) {
    let mut rng = ChaCha8Rng::seed_from_u64(11);
    let mut g = Vec::new();
    let mut v = Vec::new();
    let mut sl = Vec::new();
    for s in 0..8 {
        let off = rng.random_range(-0.05..0.05);
        for _ in 0..15 {
            let vi: f64 = rng.random_range(2.0..5.0);
            g.push(s * 10 + 3); // non-contiguous ids on purpose
            v.push(vi);
            sl.push(0.14 + 0.18 * vi + off + rng.random_range(-0.02..0.02));
        }
    }
    (g, v, sl)
}

fn fit_rows(rows: &[usize], v: &[f64], sl: &[f64]) -> Option<DVector<f64>> {
    let x = DMatrix::from_fn(rows.len(), 2, |r, j| if j == 0 { 1.0 } else { v[rows[r]] });
    let y = DVector::from_fn(rows.len(), |r, _| sl[rows[r]]);
    ols(&LinearProblem::new(&x, &y)).ok().map(|f| f.coef)
}

#[test]
fn loso_rmse_matches_a_hand_loop() {
    let (g, v, sl) = trials();
    let per_subject = leave_one_group_out(&g, |train, test| {
        let c = fit_rows(train, &v, &sl)?;
        Some(
            test.iter()
                .map(|&i| (sl[i] - c[0] - c[1] * v[i]).powi(2))
                .collect::<Vec<_>>(),
        )
    });
    assert_eq!(per_subject.len(), 8);
    let all: Vec<f64> = per_subject.into_iter().flatten().collect();
    let loso = (all.iter().sum::<f64>() / all.len() as f64).sqrt();

    let mut sse = 0.0;
    for s in unique_groups(&g) {
        let train: Vec<usize> = (0..g.len()).filter(|&i| g[i] != s).collect();
        let c = fit_rows(&train, &v, &sl).unwrap();
        for i in (0..g.len()).filter(|&i| g[i] == s) {
            sse += (sl[i] - c[0] - c[1] * v[i]).powi(2);
        }
    }
    let hand = (sse / g.len() as f64).sqrt();
    assert!(lre(loso, hand) > 12.0);
}

#[test]
fn group_bootstrap_is_reproducible_and_sane() {
    let (g, v, sl) = trials();
    let f = |rows: &[usize]| fit_rows(rows, &v, &sl).map(|c| c.iter().copied().collect());
    let a = bootstrap_by_group(&g, 400, 2024, f);
    let b = bootstrap_by_group(&g, 400, 2024, f);
    assert_eq!(a, b);
    for threads in [1, 2, 3] {
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .unwrap();
        assert_eq!(pool.install(|| bootstrap_by_group(&g, 400, 2024, f)), a);
    }
    assert_eq!(a.n_ok, 400);
    assert_eq!(a.n_failed, 0);
    // The slope CI covers the truth and is narrower than ±0.05.
    let [lo, hi] = a.ci95[1];
    assert!(lo < 0.18 && 0.18 < hi, "[{lo}, {hi}]");
    assert!(hi - lo < 0.1);
    // Percentile intervals nest.
    let ci90 = a.percentile_ci(0.90);
    assert!(ci90[1][0] >= lo && ci90[1][1] <= hi);
    // Full-data fit lies inside.
    let all: Vec<usize> = (0..g.len()).collect();
    let full = fit_rows(&all, &v, &sl).unwrap();
    assert!(lo < full[1] && full[1] < hi);
    assert_ne!(
        bootstrap_by_group(&g, 400, 2025, f).replicates,
        a.replicates
    );
}
