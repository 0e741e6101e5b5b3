//! Speed of the linear layer at the foundation's scale (1,000,000 rows), fixed seed.
//!
//! Run: `cargo bench --bench fit_numerics`
use criterion::{criterion_group, criterion_main, Criterion};
use gaitfit::fit::ols::{ols, polynomial_fit, LinearProblem};
use nalgebra::{DMatrix, DVector};
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use std::hint::black_box;

const N: usize = 1_000_000;

fn data() -> (DMatrix<f64>, DVector<f64>, Vec<f64>, Vec<f64>) {
    let mut rng = ChaCha8Rng::seed_from_u64(20240611);
    let x = DMatrix::from_fn(N, 4, |_, j| {
        if j == 0 {
            1.0
        } else {
            rng.random_range(0.0..10.0)
        }
    });
    let y = DVector::from_fn(N, |i, _| {
        1.0 + 0.5 * x[(i, 1)] - 0.25 * x[(i, 2)] + 2.0 * x[(i, 3)] + rng.random_range(-0.1..0.1)
    });
    // Step frequency (steps/min) and a cubic flight time, as in the running relations.
    let sf: Vec<f64> = (0..N).map(|_| rng.random_range(180.0..230.0)).collect();
    let t: Vec<f64> = sf
        .iter()
        .map(|s| {
            -8.925 + 0.131 * s - 0.623e-3 * s * s
                + 0.979e-6 * s * s * s
                + rng.random_range(-0.005..0.005)
        })
        .collect();
    (x, y, sf, t)
}

fn bench(c: &mut Criterion) {
    let (x, y, sf, t) = data();
    let mut g = c.benchmark_group("fit_numerics");
    g.sample_size(10);
    g.bench_function("ols_1e6x4", |b| {
        b.iter(|| ols(black_box(&LinearProblem::new(&x, &y))).map(|f| f.coef[0]))
    });
    g.bench_function("polynomial_fit_deg3_1e6", |b| {
        b.iter(|| polynomial_fit(black_box(&sf), black_box(&t), 3, None).map(|f| f.coef[0]))
    });
    g.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
