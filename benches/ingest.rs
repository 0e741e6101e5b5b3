//! Reading a 30 s trial: markers at 150 Hz (28 markers, TRC) with GRF at 1000 Hz (two feet,
//! OpenSim MOT companion file), and the real 30 s WBDS treadmill GRF at 300 Hz. The synthetic
//! files are generated deterministically (fixed sinusoids, no randomness) into a temporary
//! folder; the real file is read from `../shared/data` when present.
//!
//! Two measurements of the same code: wall-clock time (criterion's default) and the CPU time of
//! the benchmarking thread (from `/proc/thread-self/schedstat`, Linux). The project's machine is
//! shared by several agents on 2 cores, so wall-clock time there is inflated by waiting for a
//! core; the CPU time is what one read costs.
//!
//! Run: `cargo bench --bench ingest`.
use criterion::measurement::{Measurement, ValueFormatter};
use criterion::{criterion_group, criterion_main, Criterion, Throughput};
use gaitfit::ingest::{read_trial, ReadOptions};
use std::fmt::Write as _;
use std::hint::black_box;
use std::path::Path;

const SECONDS: f64 = 30.0;

fn write_trc(dir: &Path) -> std::path::PathBuf {
    let (rate, markers) = (150.0, 28usize);
    let n = (SECONDS * rate) as usize;
    let names: Vec<String> = (0..markers)
        .map(|i| match i {
            0 => "RASI".to_string(),
            1 => "LASI".to_string(),
            2 => "RHEE".to_string(),
            3 => "LHEE".to_string(),
            4 => "RTOE".to_string(),
            5 => "LTOE".to_string(),
            i => format!("M{i}"),
        })
        .collect();
    let mut s = String::new();
    let _ = writeln!(s, "PathFileType\t4\t(X/Y/Z)\tbench.trc");
    let _ = writeln!(
        s,
        "DataRate\tCameraRate\tNumFrames\tNumMarkers\tUnits\tOrigDataRate\tOrigDataStartFrame\tOrigNumFrames"
    );
    let _ = writeln!(s, "{rate}\t{rate}\t{n}\t{markers}\tmm\t{rate}\t1\t{n}");
    let _ = write!(s, "Frame#\tTime");
    for m in &names {
        let _ = write!(s, "\t{m}\t\t");
    }
    let _ = write!(s, "\n\t");
    for i in 1..=markers {
        let _ = write!(s, "\tX{i}\tY{i}\tZ{i}");
    }
    s.push_str("\n\n");
    for f in 0..n {
        let t = f as f64 / rate;
        let _ = write!(s, "{}\t{t:.5}", f + 1);
        for m in 0..markers {
            let height = match m {
                0 | 1 => 950.0,
                2..=5 => 60.0,
                _ => 500.0,
            };
            let phase = 2.0 * std::f64::consts::PI * 1.8 * t + m as f64;
            let fwd = if m == 4 || m == 5 { 180.0 } else { 0.0 };
            let _ = write!(
                s,
                "\t{:.5}\t{:.5}\t{:.5}",
                1300.0 * t + fwd + 300.0 * phase.sin(),
                height + 30.0 * phase.cos(),
                100.0 * m as f64
            );
        }
        s.push('\n');
    }
    let p = dir.join("bench.trc");
    std::fs::write(&p, s).unwrap();
    p
}

fn write_grf(dir: &Path) {
    let rate = 1000.0;
    let n = (SECONDS * rate) as usize;
    let mut s = format!(
        "name bench\ndatacolumns 19\ndatarows {n}\nrange 0 {}\nendheader\ntime",
        (n - 1) as f64 / rate
    );
    for side in ["R", "L"] {
        for c in ["vx", "vy", "vz", "px", "py", "pz"] {
            let _ = write!(s, "\t{side}_ground_force_{c}");
        }
    }
    for side in ["R", "L"] {
        for c in ["x", "y", "z"] {
            let _ = write!(s, "\t{side}_ground_torque_{c}");
        }
    }
    s.push('\n');
    for i in 0..n {
        let t = i as f64 / rate;
        let _ = write!(s, "{t:.6}");
        for side in 0..2 {
            let ph =
                (2.0 * std::f64::consts::PI * 0.9 * t + side as f64 * std::f64::consts::PI).sin();
            let fy = if ph > 0.0 { 1400.0 * ph } else { 0.0 };
            let _ = write!(
                s,
                "\t{:.4}\t{fy:.4}\t{:.4}\t{:.5}\t0\t{:.5}",
                0.1 * fy * ph,
                0.02 * fy,
                1.0 + 0.1 * ph,
                0.1 * side as f64
            );
        }
        s.push_str("\t0\t1.5\t0\t0\t-1.5\t0\n");
    }
    std::fs::write(dir.join("bench_grf.mot"), s).unwrap();
}

/// On-CPU time of the current thread, ns (Linux schedstat); 0 elsewhere.
fn thread_cpu_ns() -> u64 {
    std::fs::read_to_string("/proc/thread-self/schedstat")
        .ok()
        .and_then(|s| s.split_whitespace().next()?.parse().ok())
        .unwrap_or(0)
}

/// Criterion measurement: CPU time of the benchmarking thread.
struct ThreadCpu;

struct CpuFormatter;

impl ValueFormatter for CpuFormatter {
    fn scale_values(&self, typical: f64, values: &mut [f64]) -> &'static str {
        let (d, u) = if typical < 1e3 {
            (1.0, "ns cpu")
        } else if typical < 1e6 {
            (1e3, "µs cpu")
        } else {
            (1e6, "ms cpu")
        };
        values.iter_mut().for_each(|v| *v /= d);
        u
    }
    fn scale_throughputs(&self, _: f64, _: &Throughput, _: &mut [f64]) -> &'static str {
        "n/a"
    }
    fn scale_for_machines(&self, _: &mut [f64]) -> &'static str {
        "ns cpu"
    }
}

impl Measurement for ThreadCpu {
    type Intermediate = u64;
    type Value = u64;
    fn start(&self) -> u64 {
        thread_cpu_ns()
    }
    fn end(&self, i: u64) -> u64 {
        thread_cpu_ns().saturating_sub(i)
    }
    fn add(&self, a: &u64, b: &u64) -> u64 {
        a + b
    }
    fn zero(&self) -> u64 {
        0
    }
    fn to_f64(&self, v: &u64) -> f64 {
        *v as f64
    }
    fn formatter(&self) -> &dyn ValueFormatter {
        &CpuFormatter
    }
}

fn benches_cpu(c: &mut Criterion<ThreadCpu>) {
    run(c, "ingest_cpu");
}

fn benches(c: &mut Criterion) {
    run(c, "ingest");
}

fn run<M: Measurement>(c: &mut Criterion<M>, group: &str) {
    let dir = tempfile::tempdir().unwrap();
    let trc = write_trc(dir.path());
    write_grf(dir.path());
    let opts = ReadOptions::default();
    let t = read_trial(&trc, &opts).unwrap();
    assert_eq!(t.plates.len(), 2);
    let mut g = c.benchmark_group(group);
    g.sample_size(20);
    g.bench_function("trc_150Hz_28markers_plus_grf_mot_1000Hz_30s", |b| {
        b.iter(|| black_box(read_trial(black_box(&trc), &opts).unwrap()))
    });
    let trc_only = ReadOptions {
        companions: false,
        ..ReadOptions::default()
    };
    g.bench_function("trc_150Hz_28markers_30s", |b| {
        b.iter(|| black_box(read_trial(black_box(&trc), &trc_only).unwrap()))
    });
    if let Ok(wbds) = gaitfit::shared_data::path("wbds/WBDS04walkT05grf.txt") {
        g.bench_function("wbds_treadmill_grf_300Hz_30s_with_info", |b| {
            b.iter(|| black_box(read_trial(black_box(&wbds), &opts).unwrap()))
        });
    }
    if let Ok(c3d) = gaitfit::shared_data::path("schreiber2019/2014001/dynamic/2014001_C4_05.c3d") {
        g.bench_function("c3d_schreiber_1.55s_52markers_1500Hz", |b| {
            b.iter(|| black_box(read_trial(black_box(&c3d), &opts).unwrap()))
        });
    }
    g.finish();
}

criterion_group!(ingest, benches);
criterion_group! {
    name = ingest_cpu;
    config = Criterion::default().with_measurement(ThreadCpu);
    targets = benches_cpu
}
criterion_main!(ingest, ingest_cpu);
