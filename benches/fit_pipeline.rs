//! End-to-end fit of the four relations on a generated 1,000,000-row trials CSV: parse,
//! validate, fit, statistics (no bootstrap); once without and once with the reports (plots and
//! summary.md, as the default `gaitfit fit` writes them). Fixed seed.
//!
//! `cargo bench --bench fit_pipeline`. Set `GAITFIT_BENCH_ROWS` to change the size, and
//! `GAITFIT_BENCH_CSV` to keep the generated table at that path.
//!
//! Before the criterion groups, one pass of every stage is timed and printed twice: wall clock
//! and the CPU time of the benchmarking thread (`/proc/thread-self/schedstat`, Linux). The
//! project's machine is shared by several agents on 2 cores, so wall clock there is inflated by
//! waiting for a core; the CPU time is what the work costs. `GAITFIT_BENCH_STAGES_ONLY=1` stops
//! after that pass (quick measurements while iterating).
use criterion::{criterion_group, criterion_main, Criterion};
use gaitfit::fit::pipeline::{fit_relation, FitOptions};
use gaitfit::fit::synthetic::{synthetic_rows, SyntheticSpec};
use gaitfit::ingest::trials::read_trials;
use gaitfit::relations::{Relation, RunSlV, RunTflightSf, WalkSlSf, WalkTdsSf};
use gaitfit::report::write_report;
use std::io::Write;
use std::time::{Duration, Instant};

/// A compact trials CSV (only the columns the four relations use, 6 significant digits).
fn write_csv(path: &std::path::Path, rows: usize, subjects: usize) {
    let data = synthetic_rows(&SyntheticSpec {
        rows,
        subjects,
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

/// On-CPU time of the current thread, ns (Linux schedstat); 0 elsewhere.
fn thread_cpu_ns() -> u64 {
    std::fs::read_to_string("/proc/thread-self/schedstat")
        .ok()
        .and_then(|s| s.split_whitespace().next()?.parse().ok())
        .unwrap_or(0)
}

/// Runs `f` once and prints its wall-clock and thread CPU time.
fn stage<T>(name: &str, total: &mut (f64, f64), f: impl FnOnce() -> T) -> T {
    let (c0, w0) = (thread_cpu_ns(), Instant::now());
    let out = f();
    let (cpu, wall) = (
        (thread_cpu_ns() - c0) as f64 * 1e-9,
        w0.elapsed().as_secs_f64(),
    );
    total.0 += cpu;
    total.1 += wall;
    eprintln!("  {name:<28} cpu {cpu:8.4} s   wall {wall:8.4} s");
    out
}

fn rels() -> Vec<Box<dyn Relation>> {
    vec![
        Box::new(RunSlV::published()),
        Box::new(RunTflightSf::published()),
        Box::new(WalkSlSf::published()),
        Box::new(WalkTdsSf::published()),
    ]
}

fn bench(c: &mut Criterion) {
    // One core: the target is single-threaded (the pipeline's folds use rayon's global
    // pool, which this makes one thread; same as RAYON_NUM_THREADS=1).
    if rayon::ThreadPoolBuilder::new()
        .num_threads(1)
        .build_global()
        .is_err()
    {
        eprintln!("fit_pipeline: rayon's pool was already built; the figures may use more threads");
    }
    eprintln!(
        "fit_pipeline: rayon threads = {}",
        rayon::current_num_threads()
    );
    let rows: usize = std::env::var("GAITFIT_BENCH_ROWS")
        .ok()
        .and_then(|s| s.parse().ok())
        .unwrap_or(1_000_000);
    let subjects: usize = std::env::var("GAITFIT_BENCH_SUBJECTS")
        .ok()
        .and_then(|s| s.parse().ok())
        .unwrap_or(10);
    let dir = tempfile::tempdir().expect("tempdir");
    // GAITFIT_BENCH_CSV=<path> keeps the generated table there (to diff fits across versions).
    let path = std::env::var_os("GAITFIT_BENCH_CSV")
        .map(std::path::PathBuf::from)
        .unwrap_or_else(|| dir.path().join("trials.csv"));
    write_csv(&path, rows, subjects);
    let rels = rels();
    let opts = FitOptions::default();

    // One untimed read first: the generator's millions of freed small strings make glibc's
    // first large allocation consolidate its free lists (≈ 25 ms, profiled), which a CLI run
    // does not pay and criterion's warm-up absorbs.
    drop(read_trials(&path).expect("read"));
    eprintln!("fit_pipeline stages, {rows} rows (one pass):");
    let mut total = (0.0, 0.0);
    let t = stage("read", &mut total, || read_trials(&path).expect("read"));
    let tables = [t];
    let mut outcomes = Vec::new();
    for r in &rels {
        outcomes.push(stage(r.card().id, &mut total, || {
            fit_relation(r.as_ref(), &tables, &opts).expect("fit")
        }));
    }
    eprintln!(
        "  {:<28} cpu {:8.4} s   wall {:8.4} s",
        "total", total.0, total.1
    );
    // The default `gaitfit fit` also writes reports/ (plots and summary.md): issue 24.
    let reports = tempfile::tempdir().expect("tempdir");
    stage("reports (not in total)", &mut (0.0, 0.0), || {
        write_report(reports.path(), &outcomes, &[]).expect("report")
    });
    if std::env::var_os("GAITFIT_BENCH_STAGES_ONLY").is_some() {
        return;
    }

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
    g.bench_function(
        format!("end_to_end_{rows}_rows_4_relations_with_reports"),
        |b| {
            b.iter(|| {
                let t = read_trials(&path).expect("read");
                let tables = [t];
                let o: Vec<_> = rels
                    .iter()
                    .map(|r| fit_relation(r.as_ref(), &tables, &opts).expect("fit"))
                    .collect();
                write_report(reports.path(), &o, &[]).expect("report")
            })
        },
    );
    g.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
