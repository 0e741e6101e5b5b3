//! Swing1's ankle curve `P` (§4.3: a 4th-order polynomial through five conditions) and the knee
//! slaved to it: the knee angle that puts the ankle on the curve, continuing its branch.
use crate::generator::numeric::bisect;

/// Where the ankle curve peaks, as a fraction of its travel `D` (§4.3: `C = 0.3·D`).
pub(super) const PEAK_AT: f64 = 0.3;

/// The ankle curve `P` of swing1: `y(x) = Σ c_i x^i`, x measured from the ankle at toe-off.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct AnkleCurve {
    /// Coefficients `c0..c4`.
    pub c: [f64; 5],
    /// Ankle x at toe-off (origin of x), m.
    pub x0: f64,
    /// `D`: the ankle's forward travel at t1, m.
    pub d: f64,
    /// `a0`, `a_max`, `a_min`, m.
    pub heights: [f64; 3],
}

impl AnkleCurve {
    /// Fits the five conditions `y(0) = a0, y(C) = a_max, y'(C) = 0, y(D) = a_min, y'(D) = 0`
    /// with `C = 0.3·D` (§4.3).
    pub fn fit(x0: f64, d: f64, a0: f64, a_max: f64, a_min: f64) -> Option<AnkleCurve> {
        let c = PEAK_AT * d;
        let m = nalgebra::Matrix4::new(
            c,
            c * c,
            c.powi(3),
            c.powi(4),
            1.0,
            2.0 * c,
            3.0 * c * c,
            4.0 * c.powi(3),
            d,
            d * d,
            d.powi(3),
            d.powi(4),
            1.0,
            2.0 * d,
            3.0 * d * d,
            4.0 * d.powi(3),
        );
        let rhs = nalgebra::Vector4::new(a_max - a0, 0.0, a_min - a0, 0.0);
        let sol = m.lu().solve(&rhs)?;
        Some(AnkleCurve {
            c: [a0, sol[0], sol[1], sol[2], sol[3]],
            x0,
            d,
            heights: [a0, a_max, a_min],
        })
    }

    /// The quartic that leaves `a0` level and peaks at `C = γ·D`: `y(0) = a0, y'(0) = 0,
    /// y'(C) = 0, y(D) = a_min, y'(D) = 0` (`γ` = `peak` in `[0, 0.3]`; its peak height follows).
    /// At `γ` = 0.3 it is §4.3's curve with the peak for which `y'(0) = 0`; at `γ = 0` (the
    /// condition at C read as `y''(0) = 0`) it has no peak and falls over all of `D`
    /// (`a_min + A0·(1 − 4u³ + 3u⁴)`). Used where the reach condition ([`REACH_SHARE`](super::swing::REACH_SHARE)) leaves
    /// no room for a peak at `0.3·D` (see `reach_curve`).
    pub fn fit_level(x0: f64, d: f64, peak: f64, a0: f64, a_min: f64) -> Option<AnkleCurve> {
        let c = peak * d;
        // c1 = 0; y'(C)/C = 2·c2 + 3·c3·C + 4·c4·C² = 0 (well-defined at C = 0).
        let m = nalgebra::Matrix3::new(
            2.0,
            3.0 * c,
            4.0 * c * c,
            d * d,
            d.powi(3),
            d.powi(4),
            2.0 * d,
            3.0 * d * d,
            4.0 * d.powi(3),
        );
        let rhs = nalgebra::Vector3::new(0.0, a_min - a0, 0.0);
        let sol = m.lu().solve(&rhs)?;
        let mut curve = AnkleCurve {
            c: [a0, 0.0, sol[0], sol[1], sol[2]],
            x0,
            d,
            heights: [a0, a0, a_min],
        };
        curve.heights[1] = curve.eval(x0 + c).0;
        Some(curve)
    }

    /// `d²y/dx²` at ankle position `x` (absolute).
    pub fn curvature(&self, x: f64) -> f64 {
        let u = x - self.x0;
        let c = &self.c;
        2.0 * c[2] + u * (6.0 * c[3] + u * 12.0 * c[4])
    }

    /// `(y, dy/dx)` at ankle position `x` (absolute).
    pub fn eval(&self, x: f64) -> (f64, f64) {
        let u = x - self.x0;
        let c = &self.c;
        let y = c[0] + u * (c[1] + u * (c[2] + u * (c[3] + u * c[4])));
        let dy = c[1] + u * (2.0 * c[2] + u * (3.0 * c[3] + u * 4.0 * c[4]));
        (y, dy)
    }
}

/// The knee angle θ4 that puts the ankle, on the circle of radius `l4` about the knee `k`
/// with the thigh at `th3`, on `curve`, continuing the branch of `guess`.
///
/// The root is Newton's from `guess` when it lies on the knee's branch: the ankle residual
/// `F(θ4) = a_y − P(a_x)` rises with θ4 there (the ankle crosses the curve from below as the knee
/// flexes: the transversality `sin(φ − ψ)` of [`REACH_SHARE`](super::swing::REACH_SHARE) is positive) and the root is within
/// [`KNEE_BRANCH_STEP`] of `guess`. Otherwise, the extremum of `F` next to `guess`
/// (`∂F/∂θ4 = 0`, where the circle runs parallel to the curve) tells which case it is: where it
/// is a minimum below zero (or a maximum above), the branch's root lies on its rising side and is
/// found there by bisection (near a fold Newton can overshoot onto the partner root); where it
/// is not, the curve has left the ankle's reach about the knee (past a fold, where the branch's
/// root merged with its partner and vanished) and the ankle is put at that extremum, the point
/// of its circle nearest the curve. At the fold that is where the lost root was, so the knee
/// moves on continuously, and when the curve comes back within reach the root re-emerges
/// there. Failing all (no extremum within [`KNEE_BRANCH_STEP`]) the knee is held at `guess`.
/// Before this guard Newton went to whatever root it found.
pub fn knee_on_circle(k: [f64; 2], l4: f64, th3: f64, curve: &AnkleCurve, guess: f64) -> f64 {
    // F and ∂F/∂θ4 (the ankle moves by l4·(−cos, sin)(θ3 + θ4) per radian of knee flexion).
    let res = |th4: f64| {
        let (s, c) = (th3 + th4).sin_cos();
        let ax = k[0] - l4 * s;
        let (y, dy) = curve.eval(ax);
        (k[1] - l4 * c - y, l4 * (s + dy * c), ax, s, c, dy)
    };
    let (th4, _) = damped_newton(guess, 0.2, |t| {
        let (f, df, ..) = res(t);
        (f, df)
    });
    let (f, df, ..) = res(th4);
    if f.abs() < 1e-9 && df > 0.0 && (th4 - guess).abs() <= KNEE_BRANCH_STEP {
        return th4;
    }
    // Newton missed the branch (near a fold it can overshoot onto the partner root). The
    // extremum of F next to `guess`: Newton on ∂F/∂θ4 = l4·(s + P'·c) = 0.
    let (ext, curv) = damped_newton(guess, 0.05, |e| {
        let (_, g, ax, s, c, dy) = res(e);
        (g, l4 * (c - dy * s - l4 * c * c * curve.curvature(ax)))
    });
    let (fe, g, ..) = res(ext);
    if !(g.abs() < 1e-9 && ext.is_finite() && (ext - guess).abs() <= KNEE_BRANCH_STEP) {
        return guess;
    }
    // The branch's root (F rising through 0) next to the extremum: above a minimum below 0,
    // below a maximum above 0; else the curve is out of reach and the extremum is the point
    // nearest it.
    let dir = if curv > 0.0 && fe < 0.0 {
        1.0
    } else if curv < 0.0 && fe > 0.0 {
        -1.0
    } else {
        return ext;
    };
    let (mut a, mut b) = (ext, ext);
    let mut width = 1e-3;
    while width <= 2.0 * KNEE_BRANCH_STEP {
        b = ext + dir * width;
        if res(b).0 * dir > 0.0 {
            break;
        }
        a = b;
        width *= 2.0;
    }
    if res(b).0 * dir <= 0.0 {
        return ext;
    }
    let (a, b) = bisect(a, b, 60, 0.0, |m| res(m).0 * dir <= 0.0);
    let root = 0.5 * (a + b);
    if (root - guess).abs() <= KNEE_BRANCH_STEP {
        root
    } else {
        ext
    }
}

/// Damped Newton for a root of `f` (value, derivative) from `x`, each step at most `max_step`
/// (at most 30 steps; stops on a vanishing derivative or a step under 1e-14). Returns the last
/// iterate and the derivative last evaluated.
pub(super) fn damped_newton(
    mut x: f64,
    max_step: f64,
    f: impl Fn(f64) -> (f64, f64),
) -> (f64, f64) {
    let mut d = 0.0;
    for _ in 0..30 {
        let (v, dv) = f(x);
        d = dv;
        if dv.abs() < 1e-12 {
            break;
        }
        let step = (v / dv).clamp(-max_step, max_step);
        x -= step;
        if step.abs() < 1e-14 {
            break;
        }
    }
    (x, d)
}

/// Largest change of the slaved swing1 knee between two evaluations of [`knee_on_circle`] (at most
/// one integration step apart, ≤ 5 ms), rad.
pub const KNEE_BRANCH_STEP: f64 = 0.25;

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_slaved_knee_follows_its_branch_past_a_fold() {
        // The ankle held on a straight flank descending at ψ = 0.5 rad; the knee (thigh fixed)
        // moves away from it, perpendicular, from 0.3 m to 0.6 m and back (shank 0.45 m). While
        // the flank is within reach the ankle is on it, on the knee's branch (φ > ψ); beyond,
        // no root exists and the ankle is at the circle's point nearest the flank (φ = ψ, where
        // the two roots merged); the knee never jumps, and comes back onto its branch.
        let psi: f64 = 0.5;
        let line = AnkleCurve {
            c: [0.0, -psi.tan(), 0.0, 0.0, 0.0],
            x0: 0.0,
            d: 1.0,
            heights: [0.0; 3],
        };
        let (l4, th3) = (0.45, -0.2);
        let normal = [psi.sin(), psi.cos()];
        let foot = [0.4, -0.4 * psi.tan()];
        let n = 3000;
        let dists: Vec<f64> = (0..=2 * n)
            .map(|i| 0.3 + 0.3 * (1.0 - (i as f64 / n as f64 - 1.0).abs()))
            .collect();
        let mut th4 = {
            // Start on the branch: φ − ψ = acos(0.3/0.45).
            (0.3f64 / l4).acos() + psi - th3
        };
        let (mut lost, mut on) = (0, 0);
        for &dist in &dists {
            let k = [foot[0] + dist * normal[0], foot[1] + dist * normal[1]];
            let next = knee_on_circle(k, l4, th3, &line, th4);
            assert!((next - th4).abs() < 0.03, "jump {th4} -> {next} at {dist}");
            th4 = next;
            let phi = th3 + th4;
            let ankle = [k[0] - l4 * phi.sin(), k[1] - l4 * phi.cos()];
            let f = ankle[1] - line.eval(ankle[0]).0;
            if dist < l4 - 1e-3 {
                assert!(
                    f.abs() < 1e-9 && phi > psi,
                    "off the branch at {dist}: {f} {phi}"
                );
                on += 1;
            } else if dist > l4 + 1e-3 {
                assert!(
                    (phi - psi).abs() < 1e-6,
                    "not the nearest point at {dist}: {phi}"
                );
                assert!((f * psi.cos() - (dist - l4)).abs() < 1e-9, "{f} at {dist}");
                lost += 1;
            }
        }
        assert!(lost > 1000 && on > 1000, "{lost} {on}");
    }

    #[test]
    fn the_level_curves_join_the_papers_and_lose_their_peak() {
        let (d, a0, a_min) = (0.4, 0.2, 0.1);
        // At γ = 0.3: §4.3's quartic with the peak for which y'(0) = 0 (H = 1.115·A0).
        let at = AnkleCurve::fit_level(0.0, d, PEAK_AT, a0, a_min).unwrap();
        let paper = AnkleCurve::fit(0.0, d, a0, at.heights[1], a_min).unwrap();
        for i in 0..=20 {
            let x = d * i as f64 / 20.0;
            assert!((at.eval(x).0 - paper.eval(x).0).abs() < 1e-12);
        }
        assert!(paper.eval(0.0).1.abs() < 1e-12);
        let h = (at.heights[1] - a_min) / (a0 - a_min);
        assert!((h - 1.115).abs() < 1e-3, "{h}");
        // At γ = 0: a_min + A0·(1 − 4u³ + 3u⁴), monotone.
        let flat = AnkleCurve::fit_level(0.0, d, 0.0, a0, a_min).unwrap();
        for i in 0..=20 {
            let u = i as f64 / 20.0;
            let want = a_min + (a0 - a_min) * (1.0 - 4.0 * u.powi(3) + 3.0 * u.powi(4));
            assert!((flat.eval(u * d).0 - want).abs() < 1e-12);
            assert!(flat.eval(u * d).1 <= 1e-12);
        }
    }
}
