//! KLAW speed: the 12 s natural walk of Fig. 10 (top) — v = 5 km/h, h = 1.8 m, sl and sf chosen
//! by eq. (1) — which took the paper 37.3 s of CPU time on a SUN 3/50. Deterministic (no random
//! input). Reports the time to generate the walk (dynamics, shooting, kinematics, 100 frames/s
//! Motion) and, once, the shooting simulations per phase.
use criterion::{criterion_group, criterion_main, Criterion};
use gaitfit::generator::walking::{
    generate_walk, steps_for_duration, ScheduleEntry, WalkOptions, WalkParams,
};
use std::hint::black_box;

fn klaw(c: &mut Criterion) {
    let opts = WalkOptions {
        height_m: 1.8,
        mass_kg: 80.0,
        ..Default::default()
    };
    let params = WalkParams {
        speed_m_per_s: Some(5.0 / 3.6),
        ..Default::default()
    };
    let steps = steps_for_duration(&params, 12.0, &opts).expect("valid walk");
    let sched = [ScheduleEntry { params, steps }];
    let (m, r) = generate_walk(&sched, &opts).expect("walk generates");
    let it = r.total_iterations();
    eprintln!(
        "klaw bench: {} steps, {:.2} s, {} frames; shooting simulations (stance, swing1, swing2, swing3): {:?}, per step {:.1}/{:.1}/{:.1}/{:.1}",
        r.steps.len(),
        m.duration_s(),
        m.len(),
        it,
        it[0] as f64 / steps as f64,
        it[1] as f64 / steps as f64,
        it[2] as f64 / steps as f64,
        it[3] as f64 / steps as f64
    );
    c.bench_function("klaw_walk_12s_5kmh", |b| {
        b.iter(|| generate_walk(black_box(&sched), black_box(&opts)).expect("walk generates"))
    });
}

criterion_group! {
    name = benches;
    config = Criterion::default().sample_size(10);
    targets = klaw
}
criterion_main!(benches);
