//! RUNNER speed: frames generated per second, single thread, at 120 frames/s output, with all
//! nineteen attributes of §3.1.2 active (every default is non-zero and the couplings act; the
//! second case also switches to toe strike and raises arm swing, overstride and bounciness).
//! Each iteration generates a whole run from a stand — planning every step (state constraints,
//! Newton–Raphson of case II where H is set, recoveries) and evaluating every frame into a
//! `Motion` (joint rotations, landmarks, contacts, events). Deterministic (no random input).
//! Throughput is reported in frames ("elements"/s). Target: ≥ 200,000 frames/s.
use criterion::{criterion_group, criterion_main, Criterion, Throughput};
use gaitfit::generator::running::{
    generate_run, Attr, GenerateOptions, RunAttributes, RunModel, Schedule,
};
use std::hint::black_box;

fn bench(c: &mut Criterion) {
    let model = RunModel::published(1.8).expect("1.8 m figure");
    let defaults = RunAttributes::defaults(1.8);
    let mut styled = defaults.clone();
    for (a, v) in [
        (Attr::Strike, 1.0),
        (Attr::ArmSwing, 1.5),
        (Attr::Overstride, 0.06),
        (Attr::Bounciness, 50f64.to_radians()),
        (Attr::TorsoSway, 4f64.to_radians()),
    ] {
        styled.set(a, v).expect("in range");
    }
    let accelerate = Schedule::parse(
        "step,speed_km_per_h,action\n0,8,run\n4,11,run\n8,14,run\n12,17,run\n16,20,run\n24,,stop\n",
        "bench",
    )
    .expect("schedule");
    let opts = GenerateOptions {
        seconds: 10.0,
        fps: 120.0,
        stop_at_end: true,
    };
    let mut g = c.benchmark_group("runner");
    let cases: [(&str, RunAttributes, Option<Schedule>); 3] = [
        ("10 s at 12 km/h, 120 fps, defaults", defaults.clone(), None),
        (
            "10 s at 12 km/h, 120 fps, toe strike + styled",
            styled,
            None,
        ),
        ("8 → 20 km/h then stop, 120 fps", defaults, Some(accelerate)),
    ];
    for (name, attrs, sched) in cases {
        let p = model.natural(12.0 / 3.6, 0.0, &attrs).expect("natural run");
        let (m, _) = generate_run(&model, p, attrs.clone(), sched.clone(), &opts).expect("run");
        g.throughput(Throughput::Elements(m.len() as u64));
        g.bench_function(name, |b| {
            b.iter(|| {
                generate_run(
                    black_box(&model),
                    black_box(p),
                    attrs.clone(),
                    sched.clone(),
                    &opts,
                )
                .expect("run")
            })
        });
    }
    g.finish();
}

criterion_group! {
    name = benches;
    config = Criterion::default().sample_size(20);
    targets = bench
}
criterion_main!(benches);
