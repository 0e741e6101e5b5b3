//! End-to-end fit of the four relations on a generated 1,000,000-row trials CSV: parse,
//! validate, fit, statistics (no bootstrap, no plots). Fixed seed.
//!
//! `cargo bench --bench fit_pipeline`. Set `GAITFIT_BENCH_ROWS` to change the size.
use criterion::{criterion_group, criterion_main, Criterion};
use gaitfit::fit::pipeline::{fit_relation, FitOptions};
use gaitfit::fit::synthetic::{synthetic_rows, SyntheticSpec};
use gaitfit::ingest::trials::read_trials;
use gaitfit::relations::{Relation, RunSlV, RunTflightSf, WalkSlSf, WalkTdsSf};
use std::io::Write;
use std::time::Duration;

/// A compact trials CSV (only the columns the four relations use, 6 significant digits).
fn write_csv(path: &std::path::Path, rows: usize) {
    let data = synthetic_rows(&SyntheticSpec {
        rows,
        subjects: 10,
        seed: 42,
        ..Default::default()
    });
    let mut f = std::io::BufWriter::new(std::fs::File::create(path).expect("bench file"));
    writeln!(
        f,
        "subject,gait,speed_m_per_s,step_length_m,step_freq_steps_per_min,flight_time_s,double_support_pct_cycle,body_height_m"
    )
    .expect("write");
    let o = |v: Option<f64>| v.map(|v| format!("{v:.6}")).unwrap_or_default();
    for r in &data {
        writeln!(
            f,
            "{},{},{},{},{},{},{},{}",
            r.subject,
            r.gait.map(|g| g.to_string()).unwrap_or_default(),
            o(r.speed_m_per_s),
            o(r.step_length_m),
            o(r.step_freq_hz.map(|h| h * 60.0)),
            o(r.flight_time_s),
            o(r.double_support_pct_cycle),
            o(r.body_height_m)
        )
        .expect("write");
    }
}

fn bench(c: &mut Criterion) {
    let rows: usize = std::env::var("GAITFIT_BENCH_ROWS")
        .ok()
        .and_then(|s| s.parse().ok())
        .unwrap_or(1_000_000);
    let dir = tempfile::tempdir().expect("tempdir");
    let path = dir.path().join("trials.csv");
    write_csv(&path, rows);
    let rels: Vec<Box<dyn Relation>> = vec![
        Box::new(RunSlV::published()),
        Box::new(RunTflightSf::published()),
        Box::new(WalkSlSf::published()),
        Box::new(WalkTdsSf::published()),
    ];
    let opts = FitOptions::default();
    let mut g = c.benchmark_group("fit_pipeline");
    g.sample_size(10).measurement_time(Duration::from_secs(30));
    g.bench_function(format!("read_{rows}_rows"), |b| {
        b.iter(|| read_trials(&path).expect("read"))
    });
    g.bench_function(format!("end_to_end_{rows}_rows_4_relations"), |b| {
        b.iter(|| {
            let t = read_trials(&path).expect("read");
            let tables = [t];
            for r in &rels {
                fit_relation(r.as_ref(), &tables, &opts).expect("fit");
            }
        })
    });
    g.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
