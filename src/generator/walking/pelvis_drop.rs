//! The drawing's pelvis height: how far the drawn pelvis is lowered below the simulated hip over
//! a stance so that the flat foot stays within the drawn 3-D leg's soft reach (`PelvisDrop`,
//! issue 20 stage A; the stance simulation takes nothing from the drawn leg), and the whole
//! lowering once the drawn height is the least-bending curve below that (`PelvisLowering`,
//! stage B).
use crate::generator::curves::smootherstep;

/// How far the drawn pelvis is lowered below the simulated hip over one step, m: 0 at both heel
/// strikes, rising C² ([`smootherstep`]) to `height` by `rise` s (where the flat foot's need
/// starts), held, and falling back from `fall` s (the extension: the heel rises, §4.2) to 0 at
/// `end` (the next heel strike).
///
/// The simulation's stance leg is the paper's sagittal telescope locked at `l1` (§4.2); the
/// drawn leg is three-dimensional (its hip `dz` beside the foot) and its knee straightens softly
/// ([`KNEE_SOFT`](super::virtual_leg::KNEE_SOFT)): with the hip where the simulation puts it the flat foot is out of the drawn
/// leg's reach by ≈ `2σ + dz²/2l` (3–6 mm), and the virtual leg would roll it onto its ball. The
/// drawing lowers the pelvis by that much instead ([`flat_drop`]); the stance simulation takes
/// nothing from the drawn leg. The swing leg hangs from the lowered pelvis (a kinematic
/// determinant, as the pelvic list and rotation are), and lands where the simulation's does:
/// the drop is 0 at heel strike.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(super) struct PelvisDrop {
    /// Largest drop, m.
    pub(super) height: f64,
    /// End of the rise from heel strike, s.
    pub(super) rise: f64,
    /// Start of the fall, s.
    pub(super) fall: f64,
    /// End of the step (the next heel strike), s.
    pub(super) end: f64,
}

impl PelvisDrop {
    /// The drop at `tau` s after heel strike, m.
    pub(super) fn at(&self, tau: f64) -> f64 {
        self.rates(tau)[0]
    }

    /// The drop, its rate and its acceleration at `tau`.
    pub(super) fn rates(&self, tau: f64) -> [f64; 3] {
        // smootherstep((t − a)/w) and its first two derivatives in t.
        let blend = |a: f64, w: f64| {
            let w = w.max(1e-9);
            let s = ((tau - a) / w).clamp(0.0, 1.0);
            [
                smootherstep(s),
                30.0 * s * s * (1.0 - s) * (1.0 - s) / w,
                60.0 * s * (1.0 - s) * (1.0 - 2.0 * s) / (w * w),
            ]
        };
        let u = blend(0.0, self.rise);
        let f = blend(self.fall, self.end - self.fall);
        let v = [1.0 - f[0], -f[1], -f[2]];
        let h = self.height;
        [
            h * u[0] * v[0],
            h * (u[1] * v[0] + u[0] * v[1]),
            h * (u[2] * v[0] + 2.0 * u[1] * v[1] + u[0] * v[2]),
        ]
    }
}

/// The vertical drop of the hip at `hip` (sagittal x, y; `dz` beside the foot) that puts the
/// flat ankle at `ankle` within `reach` of it, m (0 when it already is). Where the foot is
/// farther than `reach` horizontally, the drop that brings the hip down to the ankle's height.
pub(super) fn flat_drop(hip: [f64; 2], dz: f64, ankle: [f64; 2], reach: f64) -> f64 {
    let dx = hip[0] - ankle[0];
    let h = (reach * reach - dx * dx - dz * dz).max(0.0).sqrt();
    (hip[1] - ankle[1] - h).max(0.0)
}

/// The drawn pelvis's whole lowering below the simulated hip over one step, m: a natural cubic
/// spline through samples on a uniform grid (C², so the swing leg hanging from the drawn
/// pelvis gets its rate and acceleration), 0 at both heel strikes. Built by
/// `generate` from the [`PelvisDrop`] and the least-bending pelvis height below it
/// (`draw::smooth_roll`; see [`PELVIS_CUTOFF_STEP_HARMONIC`]).
#[derive(Debug, Clone, PartialEq)]
pub(super) struct PelvisLowering {
    /// Sample spacing, s.
    h: f64,
    /// The lowering at `i h`, m.
    d: Vec<f64>,
    /// The spline's second derivative at the samples.
    m: Vec<f64>,
}

/// Cutoff of the drawn pelvis height's smoothing, in multiples of the step frequency.
/// `draw::smooth_roll`'s penalty `τ⁴ ∫ ÿ²` is a low-pass of gain `1 / (1 + (ωτ)⁴)`, ½ at
/// `ω = 1/τ`. The pelvis rises and falls once per step, so the cutoff at the step's second
/// harmonic passes that oscillation (gain 0.94) and removes the simulated stance spring's
/// loading-response dip after heel strike (≈ 0.15 of a step, 5–7 mm: content from the ~6th
/// harmonic up, gain ≤ 0.012).
pub const PELVIS_CUTOFF_STEP_HARMONIC: f64 = 2.0;

/// `draw::smooth_roll`'s time scale `τ` for a step lasting `t_step` s: the cutoff
/// [`PELVIS_CUTOFF_STEP_HARMONIC`] × the step frequency, `τ = t_step / (2π · that multiple)`
/// (≈ 0.080 × `t_step`).
pub(super) fn pelvis_smooth_tau(t_step: f64) -> f64 {
    t_step / (std::f64::consts::TAU * PELVIS_CUTOFF_STEP_HARMONIC)
}

impl PelvisLowering {
    /// The natural cubic spline through `d` (at least 3 samples) spaced `h` s apart.
    pub(super) fn from_samples(h: f64, d: Vec<f64>) -> Self {
        let n = d.len();
        let mut m = vec![0.0; n];
        if n >= 3 {
            // Thomas algorithm for m[i−1] + 4 m[i] + m[i+1] = 6 Δ²d[i] / h², m[0] = m[n−1] = 0.
            let k = n - 2;
            let mut c = vec![0.0; k];
            let mut r = vec![0.0; k];
            for j in 0..k {
                let i = j + 1;
                let rhs = 6.0 * (d[i - 1] - 2.0 * d[i] + d[i + 1]) / (h * h);
                let (cp, rp) = if j == 0 {
                    (0.0, 0.0)
                } else {
                    (c[j - 1], r[j - 1])
                };
                let den = 4.0 - cp;
                c[j] = 1.0 / den;
                r[j] = (rhs - rp) / den;
            }
            for j in (0..k).rev() {
                let next = if j + 1 < k { m[j + 2] } else { 0.0 };
                m[j + 1] = r[j] - c[j] * next;
            }
        }
        PelvisLowering { h, d, m }
    }

    /// The lowering at `tau` s after heel strike, m.
    pub(super) fn at(&self, tau: f64) -> f64 {
        self.rates(tau)[0]
    }

    /// The lowering, its rate and its acceleration at `tau` (held outside the step).
    pub(super) fn rates(&self, tau: f64) -> [f64; 3] {
        let n = self.d.len();
        let end = self.h * (n - 1) as f64;
        if tau.is_nan() || tau <= 0.0 {
            return [self.d[0], 0.0, 0.0];
        }
        if tau >= end {
            return [self.d[n - 1], 0.0, 0.0];
        }
        let i = ((tau / self.h).floor() as usize).min(n - 2);
        let h = self.h;
        let (a, b) = ((i + 1) as f64 * h - tau, tau - i as f64 * h);
        let (m0, m1, y0, y1) = (self.m[i], self.m[i + 1], self.d[i], self.d[i + 1]);
        let v = m0 * a.powi(3) / (6.0 * h)
            + m1 * b.powi(3) / (6.0 * h)
            + (y0 / h - m0 * h / 6.0) * a
            + (y1 / h - m1 * h / 6.0) * b;
        let r = -m0 * a * a / (2.0 * h) + m1 * b * b / (2.0 * h) - (y0 / h - m0 * h / 6.0)
            + (y1 / h - m1 * h / 6.0);
        let acc = (m0 * a + m1 * b) / h;
        [v, r, acc]
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_flat_drop_puts_the_flat_ankle_in_reach_and_blends_c2() {
        let (ankle, reach) = ([0.1, 0.08], 0.85);
        // Hip straight above the ankle, 5 cm beside it, 0.85 m up: out of reach by
        // √(0.85² + 0.05²) − 0.85; the drop brings the 3-D distance back to the reach.
        let hip = [0.1, 0.93];
        let d = flat_drop(hip, 0.05, ankle, reach);
        let dist = |y: f64| ((y - ankle[1]).powi(2) + 0.05f64.powi(2)).sqrt();
        assert!((dist(hip[1] - d) - reach).abs() < 1e-12);
        assert!(d > 1e-3 && d < 2e-3, "{d}");
        // Within reach: no drop.
        assert_eq!(flat_drop([0.1, 0.5], 0.05, ankle, reach), 0.0);
        // The drop rises from 0 and falls back to 0 with zero rate at both heel strikes.
        let p = PelvisDrop {
            height: 0.005,
            rise: 0.1,
            fall: 0.3,
            end: 0.5,
        };
        assert_eq!(p.at(0.0), 0.0);
        assert_eq!(p.at(0.1), 0.005);
        assert_eq!(p.at(0.3), 0.005);
        assert_eq!(p.at(0.5), 0.0);
        let rate = |t: f64| (p.at(t + 1e-6) - p.at(t - 1e-6)) / 2e-6;
        for t in [1e-6, 0.1 - 1e-6, 0.3 + 1e-6, 0.5 - 1e-6] {
            assert!(rate(t).abs() < 1e-6, "{t}: {}", rate(t));
        }
        for t in [0.02, 0.05, 0.08, 0.35, 0.45] {
            let [_, r, acc] = p.rates(t);
            assert!((r - rate(t)).abs() < 1e-6, "{r} vs {}", rate(t));
            let acc_fd = (rate(t + 1e-4) - rate(t - 1e-4)) / 2e-4;
            assert!(
                (acc - acc_fd).abs() < 1e-4 * acc.abs().max(1.0),
                "{acc} vs {acc_fd}"
            );
        }
    }

    #[test]
    fn the_lowering_interpolates_its_samples_c2() {
        // Samples of a smooth bump (0 at both ends); the spline passes through them, and its
        // rate and acceleration are the derivatives of its value.
        let h = 0.01;
        let d: Vec<f64> = (0..=50)
            .map(|i| 0.004 * (std::f64::consts::PI * i as f64 / 50.0).sin().powi(2))
            .collect();
        let p = PelvisLowering::from_samples(h, d.clone());
        for (i, &v) in d.iter().enumerate() {
            assert!((p.at(h * i as f64) - v).abs() < 1e-12, "{i}");
        }
        let value = |t: f64| p.at(t);
        for t in [0.013, 0.1, 0.2549, 0.37, 0.488] {
            let [_, r, acc] = p.rates(t);
            let r_fd = (value(t + 1e-6) - value(t - 1e-6)) / 2e-6;
            assert!((r - r_fd).abs() < 1e-6, "{t}: {r} vs {r_fd}");
            let acc_fd = (p.rates(t + 1e-6)[1] - p.rates(t - 1e-6)[1]) / 2e-6;
            assert!((acc - acc_fd).abs() < 1e-4, "{t}: {acc} vs {acc_fd}");
        }
        // The acceleration is continuous across a sample.
        let [_, _, a0] = p.rates(0.2 - 1e-9);
        let [_, _, a1] = p.rates(0.2 + 1e-9);
        assert!((a0 - a1).abs() < 1e-5, "{a0} vs {a1}");
        // Held outside the step.
        assert_eq!(p.rates(-0.1), [0.0, 0.0, 0.0]);
        assert_eq!(p.rates(0.6)[1], 0.0);
    }
}
