//! Event detection speed: a 30 s synthetic treadmill walk (150 Hz markers, 1000 Hz forces, two
//! belts) analysed end to end (filtering, force events, both Zeni methods, foot phases, steps),
//! in memory and read from TRC + GRF MOT files;
//! and, when `../shared/data` is present, reading + detecting the real 30 s WBDS trial (300 Hz
//! GRF) and Hamner's subject01 run (100 Hz markers + 2000 Hz GRF).
use criterion::{criterion_group, criterion_main, Criterion};
use gaitfit::events::input::{read_input, TrialInput};
use gaitfit::events::synthetic::SyntheticGait;
use gaitfit::events::{analyse, steps_from_analysis, EventOptions};
use gaitfit::ingest::ReadOptions;
use std::hint::black_box;

fn bench(c: &mut Criterion) {
    let opts = EventOptions::default();
    let g = SyntheticGait {
        duration_s: 30.0,
        ..SyntheticGait::walk()
    };
    let trial = g.trial();
    c.bench_function(
        "events: detect + steps, 30 s walk (150 Hz markers, 1 kHz forces)",
        |b| {
            b.iter(|| {
                let an = analyse(black_box(&trial), &opts).unwrap();
                black_box(steps_from_analysis(&trial, &an, &opts).unwrap())
            })
        },
    );
    let read = ReadOptions::default();
    // The case end to end: the same 30 s walk as files (TRC at 150 Hz, OpenSim GRF at
    // 1 kHz), read, detected and tabulated.
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(dir.path().join("walk.trc"), g.trc()).unwrap();
    std::fs::write(dir.path().join("walk_grf.mot"), g.grf_mot()).unwrap();
    let input = TrialInput {
        path: dir.path().join("walk.trc"),
        forces: None,
    };
    c.bench_function(
        "events: read + detect + steps, 30 s walk files (TRC 150 Hz, GRF MOT 1 kHz)",
        |b| {
            b.iter(|| {
                let t = read_input(black_box(&input), &read).unwrap();
                let an = analyse(&t, &opts).unwrap();
                black_box(steps_from_analysis(&t, &an, &opts).unwrap())
            })
        },
    );
    for rel in [
        "wbds/WBDS04walkT05grf.txt",
        "hamner2013/subject01/Run_3.trc",
    ] {
        let Ok(path) = gaitfit::shared_data::path(rel) else {
            eprintln!("skipping {rel}: shared data not found");
            continue;
        };
        let input = TrialInput { path, forces: None };
        c.bench_function(&format!("events: read + detect + steps, {rel}"), |b| {
            b.iter(|| {
                let t = read_input(black_box(&input), &read).unwrap();
                let an = analyse(&t, &opts).unwrap();
                black_box(steps_from_analysis(&t, &an, &opts).unwrap())
            })
        });
    }
}

criterion_group! {
    name = benches;
    config = Criterion::default().sample_size(20).measurement_time(std::time::Duration::from_secs(3));
    targets = bench
}
criterion_main!(benches);
