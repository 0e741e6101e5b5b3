//! Ko–Badler generalization speed: one step generalized from the bundled Winter prototype to a
//! figure of another size and step length (ψ then φ, eqs. 25–48) and sampled at 120 fps
//! (the lower-body pose of every frame, `pose::pose`), and the same rendered on the shared
//! skeleton as a `Motion`. Fixed inputs; throughput = steps per second.
use criterion::{criterion_group, criterion_main, Criterion, Throughput};
use gaitfit::events::Side;
use gaitfit::generator::generalize::figure::{metadata, walk_motion, StepPlan};
use gaitfit::generator::generalize::pose::pose;
use gaitfit::generator::generalize::prototype::Prototype;
use gaitfit::generator::generalize::{default_alpha, Anthropometry, Generalizer};
use gaitfit::generator::skeleton::Skeleton;
use std::hint::black_box;

fn bench(c: &mut Criterion) {
    let p = Prototype::bundled();
    let g = Generalizer::new(p.walk.clone(), p.mu(default_alpha()).unwrap()).unwrap();
    let sk = Skeleton::from_height(1.9, 80.0).unwrap();
    let body = Anthropometry::from_figure(sk.anthropometry()).unwrap();
    let duration = 0.55;
    let frames = (duration * 120.0_f64).round() as usize;

    let mut grp = c.benchmark_group("generalize");
    grp.throughput(Throughput::Elements(1));
    grp.bench_function("step_generalize_and_sample_120fps", |b| {
        b.iter(|| {
            let w = g.step(black_box(&body), 0.85, black_box(0.9)).unwrap();
            let mut acc = 0.0;
            for i in 0..=frames {
                let q = pose(&w, g.mu(), i as f64 / frames as f64).unwrap();
                acc += q.hip[1] + q.stance.knee[0] + q.swing.knee[0];
            }
            black_box(acc)
        })
    });
    grp.bench_function("step_generalize_only", |b| {
        b.iter(|| black_box(g.step(black_box(&body), 0.85, black_box(0.9)).unwrap()))
    });
    let plan = [StepPlan {
        step_length_m: 0.9,
        duration_s: duration,
    }];
    grp.bench_function("step_rendered_on_skeleton_120fps", |b| {
        b.iter(|| {
            let (m, _) = walk_motion(
                &g,
                sk.clone(),
                black_box(&plan),
                Side::Right,
                120.0,
                metadata(&g, 1.9, "bench"),
            )
            .unwrap();
            black_box(m.len())
        })
    });
    grp.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
