//! Seeded synthetic trials tables drawn from the published relations plus Gaussian noise: test
//! and benchmark data whose true coefficients are known (never fitted into `fits/`).
use crate::events::Gait;
use crate::ingest::trials::StepRow;
use crate::relations::{RunSlV, RunTflightSf, WalkSlSf, WalkTdsSf};
use crate::units::{m_per_min_to_m_per_s, steps_per_min_to_hz};
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;

/// Settings of [`synthetic_rows`].
#[derive(Debug, Clone, PartialEq)]
pub struct SyntheticSpec {
    /// Rows in total (half running, half walking).
    pub rows: usize,
    /// Subjects (each both runs and walks).
    pub subjects: usize,
    /// Seed.
    pub seed: u64,
    /// Running speed range, m/min.
    pub run_speed: (f64, f64),
    /// Walking step-frequency range, steps/min.
    pub walk_sf: (f64, f64),
    /// Noise SD of step length, m.
    pub sl_noise: f64,
    /// Noise SD of flight time, s.
    pub tf_noise: f64,
    /// Noise SD of double support, % of cycle.
    pub ds_noise: f64,
    /// Per-subject level range ±, m per m/min.
    pub level: f64,
}

impl Default for SyntheticSpec {
    fn default() -> Self {
        SyntheticSpec {
            rows: 1000,
            subjects: 6,
            seed: 1,
            run_speed: (100.0, 480.0),
            walk_sf: (85.0, 135.0),
            sl_noise: 0.03,
            tf_noise: 0.01,
            ds_noise: 1.0,
            level: 0.0005,
        }
    }
}

fn normal(rng: &mut ChaCha8Rng) -> f64 {
    // Box–Muller.
    let u1: f64 = rng.random::<f64>().max(f64::MIN_POSITIVE);
    let u2: f64 = rng.random::<f64>();
    (-2.0 * u1.ln()).sqrt() * (2.0 * std::f64::consts::PI * u2).cos()
}

/// Rows drawn from the published relations: running rows carry speed, step length, step
/// frequency (consistent: v = sl·sf), flight time and body height; walking rows carry speed, step
/// length, step frequency, double support (time and % of cycle) and body height.
pub fn synthetic_rows(spec: &SyntheticSpec) -> Vec<StepRow> {
    let mut rng = ChaCha8Rng::seed_from_u64(spec.seed);
    let subj: Vec<(String, f64, f64)> = (0..spec.subjects.max(1))
        .map(|s| {
            let h = 1.6 + 0.35 * rng.random::<f64>();
            let level = spec.level * (2.0 * rng.random::<f64>() - 1.0);
            (format!("S{:02}", s + 1), h, level)
        })
        .collect();
    let (run, tf, walk, tds) = (
        RunSlV::published(),
        RunTflightSf::published(),
        WalkSlSf::published(),
        WalkTdsSf::published(),
    );
    let mut rows = Vec::with_capacity(spec.rows);
    for i in 0..spec.rows {
        let (name, h, level) = &subj[i % subj.len()];
        let mut r = StepRow {
            subject: name.clone(),
            source: "synthetic".into(),
            trial: format!("T{}", i / 100),
            body_height_m: Some(*h),
            ..StepRow::default()
        };
        if i % 2 == 0 {
            let v = spec.run_speed.0 + (spec.run_speed.1 - spec.run_speed.0) * rng.random::<f64>();
            let sl = run.step_length(v, *h, *level) + spec.sl_noise * normal(&mut rng);
            let sf = v / sl;
            let t = tf.flight_time(sf) + spec.tf_noise * normal(&mut rng);
            r.gait = Some(Gait::Run);
            r.speed_m_per_s = Some(m_per_min_to_m_per_s(v));
            r.step_length_m = Some(sl);
            r.step_freq_hz = Some(steps_per_min_to_hz(sf));
            r.flight_time_s = Some(t.max(0.0));
        } else {
            let sf = spec.walk_sf.0 + (spec.walk_sf.1 - spec.walk_sf.0) * rng.random::<f64>();
            let sl = walk.step_length(sf, *h) + spec.sl_noise * normal(&mut rng);
            let pct = tds.double_support_pct(sf) + spec.ds_noise * normal(&mut rng);
            r.gait = Some(Gait::Walk);
            r.speed_m_per_s = Some(m_per_min_to_m_per_s(sl * sf));
            r.step_length_m = Some(sl);
            r.step_freq_hz = Some(steps_per_min_to_hz(sf));
            r.double_support_pct_cycle = Some(pct);
            r.double_support_time_s = Some(pct / 100.0 * 2.0 / steps_per_min_to_hz(sf));
        }
        rows.push(r);
    }
    rows
}
