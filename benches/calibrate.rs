//! `gaitfit calibrate` speed (issue 21): one subject × 4 speeds end to end — reading, events and
//! steps of every trial, the generators driven at each measured speed, the generated motion
//! measured by the same event pipeline, and the per-subject Gauss–Newton calibration (argmin).
//! Hamner et al. (2013) subject01's four treadmill runs (Run_2–Run_5, 2–5 m/s) from
//! `../shared/data` (or `GAITFIT_SHARED_DATA`), with the committed `fits/`; skipped, with a
//! message, when the shared data are absent. Target (issue 21): ≤ 5 s.
use criterion::{criterion_group, criterion_main, Criterion};
use gaitfit::calibrate::{calibrate, CalibrateOptions};
use std::hint::black_box;
use std::path::PathBuf;
use std::time::Duration;

fn bench(c: &mut Criterion) {
    let Ok(subject) = gaitfit::shared_data::path("hamner2013/subject01") else {
        eprintln!(
            "skipping the calibrate bench: shared data not found ({})",
            gaitfit::shared_data::where_looked()
        );
        return;
    };
    let opts = CalibrateOptions {
        fits: Some(PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("fits")),
        ..CalibrateOptions::default()
    };
    let inputs = vec![subject];
    let mut g = c.benchmark_group("calibrate");
    g.sample_size(10).measurement_time(Duration::from_secs(20));
    g.bench_function("Hamner subject01, 4 speeds, --fits fits/", |b| {
        b.iter(|| black_box(calibrate(black_box(&inputs), &opts, |_, _, _| {}).unwrap()))
    });
    g.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
