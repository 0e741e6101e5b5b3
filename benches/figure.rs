//! Forward kinematics of the figure: one pose → every joint's world transform and every
//! landmark, and `Motion::push_frame` (FK + landmarks + storage). Fixed inputs, no randomness.
use criterion::{criterion_group, criterion_main, Criterion, Throughput};
use gaitfit::generator::motion::{Motion, MotionMetadata};
use gaitfit::generator::skeleton::{Euler, GlobalPose, Joint, Pose, Skeleton, LANDMARK_COUNT};
use glam::DVec3;

fn pose(sk: &Skeleton, i: usize) -> Pose {
    let mut p = sk.rest_pose();
    let t = i as f64 / 120.0;
    p.root.x = 3.0 * t;
    for (k, j) in Joint::ALL.iter().enumerate() {
        let a = 0.3 * (6.0 * t + k as f64).sin();
        p.set_euler(*j, Euler::new(a, 0.2 * a, -0.3 * a));
    }
    p
}

fn bench(c: &mut Criterion) {
    let sk = Skeleton::from_height(1.8, 75.0).unwrap();
    let poses: Vec<Pose> = (0..1024).map(|i| pose(&sk, i)).collect();
    let mut g = c.benchmark_group("figure");
    g.throughput(Throughput::Elements(poses.len() as u64));
    g.bench_function("fk_and_landmarks_1024_frames", |b| {
        let mut gp = GlobalPose::default();
        let mut lm = [DVec3::ZERO; LANDMARK_COUNT];
        b.iter(|| {
            let mut acc = 0.0;
            for p in &poses {
                sk.forward_into(std::hint::black_box(p), &mut gp);
                sk.landmarks_into(&gp, &mut lm);
                acc += lm[3].x;
            }
            acc
        })
    });
    g.bench_function("motion_push_frame_1024_frames", |b| {
        b.iter(|| {
            let mut m = Motion::new(sk.clone(), 120.0, MotionMetadata::default()).unwrap();
            m.reserve(poses.len());
            for p in &poses {
                m.push_frame(*std::hint::black_box(p), [true, false]);
            }
            m.len()
        })
    });
    g.finish();
}

criterion_group! {
    name = benches;
    // No plots: the plotters backend needs system fonts the CI machine does not have.
    config = Criterion::default().without_plots();
    targets = bench
}
criterion_main!(benches);
