//! Synthetic walk data for tests and benchmarks: a smooth, plausible step (shaped like Winter's
//! measured step) with random perturbations from a seed, made consistent with its μ-functions
//! by φ₁. Never used to generate motion for users.
use super::mu::MuFunctions;
use super::phi::phi;
use super::walk_data::{Anthropometry, Moments, TimedSequence, WalkData};
use crate::generator::GenerateError;
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use std::f64::consts::PI;

/// A random, consistent walk W(S, sl) and its μ-functions, reproducible from `seed`. Body
/// segments, step length, moments, μ values, slopes and the shapes of every sequence vary
/// with the seed (and the time grids differ between sequences).
pub fn synthetic_walk(seed: u64) -> Result<(WalkData, MuFunctions), GenerateError> {
    let mut r = ChaCha8Rng::seed_from_u64(seed);
    let mut u = |a: f64, b: f64| a + (b - a) * r.random::<f64>();
    let body = Anthropometry::new(
        u(0.36, 0.46),
        u(0.38, 0.48),
        u(0.04, 0.06),
        u(0.10, 0.13),
        u(0.05, 0.08),
        u(0.05, 0.08),
    )?;
    // Half the walks hinge the toes above the sole, as gaitfit's figure does.
    let hm = if seed % 2 == 1 { u(0.01, 0.03) } else { 0.0 };
    let body = body.with_ball_height(hm)?;
    let sl = u(0.6, 0.8) * body.leg_length() / 0.8;
    let (fgm, mom, tom) = (u(0.12, 0.2), u(1.02, 1.12), u(0.18, 0.26));
    let moments = Moments::new(fgm, mom, tom)?;
    let mu_star = [u(0.0, 0.12), u(0.25, 0.45), u(1.0, 1.4), u(0.7, 1.1)];
    let alpha = [u(0.0, 0.3), u(0.1, 0.6), u(0.1, 0.8), u(0.1, 0.8)];
    let mu = MuFunctions::new(alpha, mu_star, sl, body.leg_length())?;
    let wig = [u(-1.0, 1.0), u(-1.0, 1.0), u(-1.0, 1.0), u(-1.0, 1.0)];

    let grid = |a: f64, b: f64, n: usize, jitter: f64| -> Vec<f64> {
        (0..n)
            .map(|i| {
                let s = i as f64 / (n - 1) as f64;
                // A non-uniform but strictly increasing grid.
                let s2 = s + jitter * (PI * s).sin() * 0.1;
                a + (b - a) * s2
            })
            .collect()
    };
    let n_h = 24 + (seed % 7) as usize;
    let th = grid(0.0, 1.0, n_h, wig[0] * 0.5);
    let x0 = -0.5 * sl - 0.05 * body.leg_length();
    let hip = TimedSequence::new(
        "H",
        th.clone(),
        th.iter()
            .map(|&t| {
                [
                    x0 + sl * t + 0.01 * wig[1] * (2.0 * PI * t).sin(),
                    0.95 * body.leg_length() + 0.02 * (2.0 * PI * t).cos(),
                ]
            })
            .collect(),
    )?;
    let t1 = grid(0.0, fgm, 8, wig[2] * 0.5);
    let foot1 = TimedSequence::new(
        "F1",
        t1.clone(),
        t1.iter()
            .map(|&t| {
                let s = t / fgm;
                [mu_star[1] * (1.0 - s) * (1.0 + 0.2 * wig[3] * s)]
            })
            .collect(),
    )?;
    let t2 = grid(fgm, 1.0 + tom, 40, wig[1] * 0.3);
    let heel_off = 0.6 + 0.1 * wig[2];
    let foot2 = TimedSequence::new(
        "F2",
        t2.clone(),
        t2.iter()
            .map(|&t| {
                let s = ((t - heel_off) / (1.0 + tom - heel_off)).max(0.0);
                [-mu_star[2] * s.powf(1.5)]
            })
            .collect(),
    )?;
    let t3 = grid(tom, 1.0, 30, wig[3] * 0.3);
    let foot3 = TimedSequence::new(
        "F3",
        t3.clone(),
        t3.iter()
            .map(|&t| {
                let s = (t - tom) / (1.0 - tom);
                [-mu_star[2]
                    + (mu_star[1] + mu_star[2]) * (1.0 - (PI * s).cos()) * 0.5
                    + 0.05 * wig[0] * (PI * s).sin()]
            })
            .collect(),
    )?;
    let tm = grid(mom, 1.0 + tom, 10, wig[0] * 0.4);
    let meta = TimedSequence::new(
        "M",
        tm.clone(),
        tm.iter()
            .map(|&t| [mu_star[3] * ((t - mom) / (1.0 + tom - mom)).powf(1.2)])
            .collect(),
    )?;
    let ta = grid(tom, 1.0, 30, wig[2] * 0.3);
    let start = -sl + 0.1;
    let ankle = TimedSequence::new(
        "A",
        ta.clone(),
        ta.iter()
            .map(|&t| {
                let s = (t - tom) / (1.0 - tom);
                let x = start + (2.0 * sl - 0.1) * (3.0 * s * s - 2.0 * s * s * s);
                let y = 0.1 + 0.07 * (PI * s).sin() * (1.0 + 0.2 * wig[3]);
                [x, y]
            })
            .collect(),
    )?;
    let raw = WalkData::new(body, sl, sl, moments, hip, foot1, foot2, foot3, meta, ankle)?;
    // φ₁ pins every end point onto the μ-functions and the foot geometry.
    let w = phi(&raw, 1.0, sl, &mu)?;
    Ok((w, mu))
}
