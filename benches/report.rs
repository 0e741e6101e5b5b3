//! The report stage alone: `write_report` (every plot as SVG and PNG, and summary.md) for the
//! four relations fitted on a generated trials table, 10 subjects, fixed seed. The fits are
//! made once, untimed.
//!
//! `cargo bench --bench report`. `GAITFIT_BENCH_ROWS` sets the size (default 1,000,000);
//! `GAITFIT_BENCH_STAGES_ONLY=1` stops after the one-pass timing printed first.
//!
//! The one-pass timing prints wall clock and the CPU time of the whole process (all threads,
//! `/proc/self/task/*/schedstat`, Linux): the report draws its figures on rayon's pool, and on
//! the project's shared 2-core machine wall clock is inflated by waiting for a core.
use criterion::{criterion_group, criterion_main, Criterion};
use gaitfit::fit::pipeline::{fit_relation, FitOptions, FitOutcome};
use gaitfit::fit::synthetic::{synthetic_rows, SyntheticSpec};
use gaitfit::ingest::trials::TrialsTable;
use gaitfit::relations::{Relation, RunSlV, RunTflightSf, WalkSlSf, WalkTdsSf};
use gaitfit::report::write_report;
use std::time::{Duration, Instant};

/// On-CPU time of all threads of this process, ns (Linux); 0 elsewhere.
fn process_cpu_ns() -> u64 {
    let Ok(dir) = std::fs::read_dir("/proc/self/task") else {
        return 0;
    };
    dir.filter_map(|e| e.ok())
        .filter_map(|e| std::fs::read_to_string(e.path().join("schedstat")).ok())
        .filter_map(|s| s.split_whitespace().next()?.parse::<u64>().ok())
        .sum()
}

fn outcomes(rows: usize) -> Vec<FitOutcome> {
    let data = synthetic_rows(&SyntheticSpec {
        rows,
        subjects: 10,
        seed: 42,
        ..Default::default()
    });
    let tables = [TrialsTable::from_step_rows("trials.csv", &data)];
    let rels: Vec<Box<dyn Relation>> = vec![
        Box::new(RunSlV::published()),
        Box::new(RunTflightSf::published()),
        Box::new(WalkSlSf::published()),
        Box::new(WalkTdsSf::published()),
    ];
    rels.iter()
        .map(|r| fit_relation(r.as_ref(), &tables, &FitOptions::default()).expect("fit"))
        .collect()
}

fn bench(c: &mut Criterion) {
    let rows: usize = std::env::var("GAITFIT_BENCH_ROWS")
        .ok()
        .and_then(|s| s.parse().ok())
        .unwrap_or(1_000_000);
    eprintln!(
        "report: rayon threads = {}; fitting {rows} rows (untimed)",
        rayon::current_num_threads()
    );
    let dir = tempfile::tempdir().expect("tempdir");
    let mut g = c.benchmark_group("report");
    g.sample_size(10).measurement_time(Duration::from_secs(20));
    for n in [1_000, rows] {
        let o = outcomes(n);
        let (c0, w0) = (process_cpu_ns(), Instant::now());
        let files = write_report(dir.path(), &o, &[]).expect("report");
        let (cpu, wall) = (
            (process_cpu_ns() - c0) as f64 * 1e-9,
            w0.elapsed().as_secs_f64(),
        );
        let bytes: u64 = files
            .iter()
            .map(|f| std::fs::metadata(f).map_or(0, |m| m.len()))
            .sum();
        eprintln!(
            "  write_report, {n} rows, {} files, {:.2} MB: cpu {cpu:.4} s   wall {wall:.4} s",
            files.len(),
            bytes as f64 / 1e6
        );
        if std::env::var_os("GAITFIT_BENCH_STAGES_ONLY").is_some() {
            continue;
        }
        g.bench_function(format!("write_report_{n}_rows_4_relations"), |b| {
            b.iter(|| write_report(dir.path(), &o, &[]).expect("report"))
        });
    }
    g.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
