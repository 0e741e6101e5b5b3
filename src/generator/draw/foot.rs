//! The drawn foot in contact: one roll coordinate `ρ` about its sole points (the paper's heel,
//! forefoot and toe rockers, §4.2), and the stance roll curve that holds the foot exactly flat
//! between foot flat and heel off.
//!
//! Conventions (as `walking::foot`): sagittal plane, x forward, y up; the pitch `φ = −ρ` is the
//! foot's rotation from flat, toes up positive; the toe bend `θ₆` is the toe segment's extension
//! relative to the foot. `ρ ≤ 0`: heel rocker, the heel fixed; `ρ ≥ 0`: forefoot then toe rocker,
//! the toe tip fixed, the toe segment first flat (`θ₆ = ρ`) and lifting off the ground once `θ₆`
//! nears its limit `θ₆max` ([`toe_lift`], C² here where the simulation's is C¹).
use super::track::{knots, spline_keys, C2Track, End, Key};
use crate::generator::GenerateError;

/// The foot's sole points relative to the ankle when the foot is flat on the ground, m.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Sole {
    /// Heel sole point.
    pub heel: [f64; 2],
    /// Metatarsal joint centre (the toe segment's hinge).
    pub mtp: [f64; 2],
    /// Toe tip.
    pub toe: [f64; 2],
}

/// A drawn foot: ankle position (m), pitch and toe bend (rad).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct FootPose {
    /// Ankle joint centre, sagittal (x, y), m.
    pub ankle: [f64; 2],
    /// Pitch `φ` from flat, toes up positive, rad.
    pub pitch: f64,
    /// Toe bend `θ₆`, rad.
    pub bend: f64,
}

/// Half-width `δ` of the forefoot → toe rocker blend, rad: 0.15 rad, at most half of `θ₆max`
/// (the simulation's foot, `walking::foot`, uses this one too).
#[inline]
pub fn toe_blend(bend_max: f64) -> f64 {
    (0.5 * bend_max).min(0.15)
}

/// The toe segment's lift `ψ(x)` off the ground for `x = ρ − θ₆max`: 0 for `x ≤ −δ`, `x` for
/// `x ≥ δ`, between them the integral of the smootherstep, so `ψ′` rises from 0 to 1 with zero
/// slope at both ends (C², where the simulation's quadratic blend is C¹). Convex, so
/// `ψ ≥ max(0, x)` and `θ₆ = ρ − ψ ≤ θ₆max`.
pub fn toe_lift(x: f64, delta: f64) -> f64 {
    if x <= -delta {
        0.0
    } else if x >= delta {
        x
    } else {
        let u = (x + delta) / (2.0 * delta);
        // ∫₀ᵘ (6s⁵ − 15s⁴ + 10s³) ds = u⁶ − 3u⁵ + 2.5u⁴, reaching ½ at u = 1.
        2.0 * delta * u * u * u * u * (u * (u - 3.0) + 2.5)
    }
}

fn rot(a: f64, v: [f64; 2]) -> [f64; 2] {
    let (s, c) = a.sin_cos();
    [c * v[0] - s * v[1], s * v[0] + c * v[1]]
}

impl Sole {
    /// The foot rolled by `ρ` with its flat ankle at `flat_ankle` (see the module doc). Exactly
    /// `flat_ankle`, pitch 0 and bend 0 at `ρ = 0`.
    pub fn rolled(&self, flat_ankle: [f64; 2], rho: f64, bend_max: f64) -> FootPose {
        if rho == 0.0 {
            return FootPose {
                ankle: flat_ankle,
                pitch: 0.0,
                bend: 0.0,
            };
        }
        if rho < 0.0 {
            self.heel_rocker(flat_ankle, rho)
        } else {
            self.toe_rocker(flat_ankle, rho, bend_max)
        }
    }

    /// The heel-rocker formula for any `ρ` (a smooth function of `ρ`).
    fn heel_rocker(&self, flat_ankle: [f64; 2], rho: f64) -> FootPose {
        let phi = -rho;
        let r = rot(phi, self.heel);
        FootPose {
            ankle: [
                flat_ankle[0] + self.heel[0] - r[0],
                flat_ankle[1] + self.heel[1] - r[1],
            ],
            pitch: phi,
            bend: 0.0,
        }
    }

    /// The toe-rocker formula for any `ρ` (a smooth function of `ρ`).
    fn toe_rocker(&self, flat_ankle: [f64; 2], rho: f64, bend_max: f64) -> FootPose {
        let phi = -rho;
        let bend = rho - toe_lift(rho - bend_max, toe_blend(bend_max));
        let t = rot(bend, [self.toe[0] - self.mtp[0], self.toe[1] - self.mtp[1]]);
        let r = rot(phi, [self.mtp[0] + t[0], self.mtp[1] + t[1]]);
        FootPose {
            ankle: [
                flat_ankle[0] + self.toe[0] - r[0],
                flat_ankle[1] + self.toe[1] - r[1],
            ],
            pitch: phi,
            bend,
        }
    }

    /// The rolled foot and its rates for a roll with value, rate and acceleration `rho`: the
    /// ankle x, ankle y, pitch and bend, each as (value, rate, acceleration) — the chain rule on
    /// the rocker's formula, its derivatives in `ρ` by central differences on the rocker the
    /// roll is on (the heel's for `ρ < 0`, or `ρ = 0` rolling back).
    pub fn rolled_rates(
        &self,
        flat_ankle: [f64; 2],
        rho: [f64; 3],
        bend_max: f64,
    ) -> [[f64; 3]; 4] {
        let heel = rho[0] < 0.0 || (rho[0] == 0.0 && rho[1] < 0.0);
        let f = |r: f64| {
            let p = if heel {
                self.heel_rocker(flat_ankle, r)
            } else {
                self.toe_rocker(flat_ankle, r, bend_max)
            };
            [p.ankle[0], p.ankle[1], p.pitch, p.bend]
        };
        let h = 1e-4;
        let (m, c, p) = (
            f(rho[0] - h),
            self.rolled(flat_ankle, rho[0], bend_max),
            f(rho[0] + h),
        );
        let c = [c.ankle[0], c.ankle[1], c.pitch, c.bend];
        let mut out = [[0.0; 3]; 4];
        for q in 0..4 {
            let d1 = (p[q] - m[q]) / (2.0 * h);
            let d2 = (p[q] - 2.0 * f(rho[0])[q] + m[q]) / (h * h);
            out[q] = [c[q], d1 * rho[1], d2 * rho[1] * rho[1] + d1 * rho[2]];
        }
        out
    }

    /// Heel, metatarsal joint, ball (under the metatarsal joint, on the toe segment) and toe
    /// tip of a drawn foot, m, for a sole whose ball is `ball` (relative to the ankle, flat).
    pub fn points(&self, pose: &FootPose, ball: [f64; 2]) -> [[f64; 2]; 4] {
        let at = |o: [f64; 2], v: [f64; 2], a: f64| {
            let r = rot(a, v);
            [o[0] + r[0], o[1] + r[1]]
        };
        let mtp = at(pose.ankle, self.mtp, pose.pitch);
        let seg = |p: [f64; 2]| [p[0] - self.mtp[0], p[1] - self.mtp[1]];
        [
            at(pose.ankle, self.heel, pose.pitch),
            mtp,
            at(mtp, seg(ball), pose.pitch + pose.bend),
            at(mtp, seg(self.toe), pose.pitch + pose.bend),
        ]
    }
}

/// The stance roll `ρ(t)` over one contact, from the simulated roll `samples` (time s, `ρ`; in
/// time order, at least two): exactly 0 on the flat foot `flat = (foot flat, heel off)` (s,
/// inside the contact) with rate and acceleration 0 at both its ends, and elsewhere the spline
/// through the samples read at knots about `spacing` s apart (the drawing's one time scale: the
/// simulated collision and rocker switches are smoothed over it). Without a flat foot, a sign
/// change of the samples is a momentary flat foot (the rockers' pivots switch only at rest).
pub fn stance_roll(
    samples: &[(f64, f64)],
    flat: Option<(f64, f64)>,
    spacing: f64,
) -> Result<C2Track, GenerateError> {
    if samples.len() < 2 {
        return Err(GenerateError::Numerical {
            stage: "drawing the stance roll".into(),
            message: format!("{} roll samples, at least two needed", samples.len()),
        });
    }
    let (t0, t1) = (samples[0].0, samples[samples.len() - 1].0);
    let at = |t: f64| {
        let i = samples
            .partition_point(|s| s.0 <= t)
            .clamp(1, samples.len() - 1);
        let (a, b) = (samples[i - 1], samples[i]);
        let w = if b.0 > a.0 {
            ((t - a.0) / (b.0 - a.0)).clamp(0.0, 1.0)
        } else {
            1.0
        };
        a.1 + w * (b.1 - a.1)
    };
    let flat = flat
        .map(|(a, b)| (a.clamp(t0, t1), b.clamp(t0, t1)))
        .filter(|(a, b)| a <= b)
        .or_else(|| {
            samples.windows(2).find(|w| w[0].1 * w[1].1 < 0.0).map(|w| {
                let tc = w[0].0 + (w[1].0 - w[0].0) * w[0].1 / (w[0].1 - w[1].1);
                (tc, tc)
            })
        });
    // One piece: knots over [a, b] with each end free or at rest on the flat foot.
    let piece = |a: f64, b: f64, rest_start: bool, rest_end: bool| {
        let ts = knots(a, b, spacing);
        let ys: Vec<f64> = ts
            .iter()
            .enumerate()
            .map(|(i, &t)| {
                if (i == 0 && rest_start) || (i + 1 == ts.len() && rest_end) {
                    0.0
                } else {
                    at(t)
                }
            })
            .collect();
        let end = |rest: bool| {
            if rest {
                End::Given(0.0, 0.0)
            } else {
                End::Natural
            }
        };
        spline_keys(&ts, &ys, end(rest_start), end(rest_end))
    };
    let keys: Vec<Key> = match flat {
        None => piece(t0, t1, false, false),
        Some((ff, ho)) => {
            let mut keys = Vec::new();
            if ff - t0 > MIN_PHASE_S && samples[0].1 < 0.0 {
                keys.extend(heel_rocker(samples[0].1, at(t0 + 0.25 * (ff - t0)), t0, ff));
            } else if ff - t0 > MIN_PHASE_S {
                keys.extend(piece(t0, ff, false, true));
            } else {
                keys.push(Key::rest(ff, 0.0));
            }
            if ho - ff > MIN_PHASE_S {
                keys.push(Key::rest(ho, 0.0));
            }
            if t1 - ho > MIN_PHASE_S {
                keys.extend(piece(ho, t1, true, false).into_iter().skip(1));
            }
            keys
        }
    };
    C2Track::new(keys)
}

/// A contact's phase (heel rocker, foot flat, roll-off) shorter than this (s, far below one
/// frame) is left out of the roll curve.
const MIN_PHASE_S: f64 = 1e-6;

/// The heel rocker's roll from `rho0 < 0` at `t0` (the heel strike) to rest at 0 at `ff` (foot
/// flat): one quintic, never past 0 (the heel stays the pivot). Its starting rate is the
/// simulated secant to `rho_q` at a quarter of the way, within the quintic's monotone range: with
/// `q = ρ/ρ₀` and a start at zero acceleration, `q′(s) = −(1 − s)²(30s² + w(1 + 2s − 15s²))`
/// (`s` the fraction of the way, `w = −q′(0)`) is ≤ 0 on [0, 1] exactly for `0 ≤ w ≤ 2.5`.
fn heel_rocker(rho0: f64, rho_q: f64, t0: f64, ff: f64) -> [Key; 2] {
    let h = ff - t0;
    let w = ((rho_q - rho0) / (0.25 * h) * h / -rho0).clamp(0.0, 2.5);
    [
        Key {
            t: t0,
            p: rho0,
            v: -w * rho0 / h,
            a: 0.0,
        },
        Key::rest(ff, 0.0),
    ]
}

#[cfg(test)]
pub(super) mod tests {
    use super::*;

    /// The test foot shared by the drawing's tests.
    pub(in crate::generator::draw) fn sole() -> Sole {
        // A 1.8 m figure's foot: heel 5 cm behind, metatarsals 14 cm ahead, toe tip 19 cm ahead
        // of the ankle, all 8 cm below it.
        Sole {
            heel: [-0.05, -0.08],
            mtp: [0.14, -0.08],
            toe: [0.19, -0.08],
        }
    }

    /// A simulated-looking roll over a 0.6 s contact: heel rocker from −0.25 rad to flat at
    /// 0.1 s (arriving at −2.5 rad/s), flat to heel off at 0.35 s, then rolling to 1.2 rad.
    fn samples() -> Vec<(f64, f64)> {
        (0..=600)
            .map(|i| {
                let t = i as f64 * 1e-3;
                let r = if t < 0.1 {
                    -0.25 * (1.0 - t / 0.1)
                } else if t <= 0.35 {
                    0.0
                } else {
                    1.2 * ((t - 0.35) / 0.25).powf(1.5)
                };
                (t, r)
            })
            .collect()
    }

    #[test]
    fn the_planted_foot_is_fixed_while_flat_and_the_roll_is_c2() {
        let c = stance_roll(&samples(), Some((0.1, 0.35)), 0.04).unwrap();
        let s = sole();
        let flat = [1.0, 0.08];
        for i in 0..=2500 {
            let t = 0.1 + 0.25 * i as f64 / 2500.0;
            let p = s.rolled(flat, c.value(t), 0.8);
            assert!((p.ankle[0] - 1.0).abs() <= 1e-9 && (p.ankle[1] - 0.08).abs() <= 1e-9);
            assert_eq!((p.pitch, p.bend), (0.0, 0.0), "{t} {:?}", c.keys());
        }
        // C² at every knot: one-sided limits agree to O(probe).
        for k in c.keys() {
            let (l, r) = (c.at(k.t - 1e-8), c.at(k.t + 1e-8));
            assert!(
                (l[0] - r[0]).abs() < 1e-6
                    && (l[1] - r[1]).abs() < 1e-4
                    && (l[2] - r[2]).abs() < 1e-2,
                "{k:?}"
            );
        }
        // Heel rocker ends, toe rocker starts, at rest.
        assert_eq!(c.at(0.1), [0.0, 0.0, 0.0]);
        assert_eq!(c.at(0.35), [0.0, 0.0, 0.0]);
        // The curve follows the simulated roll at its knots.
        assert!((c.value(0.6) - 1.2).abs() < 1e-12 && (c.value(0.0) + 0.25).abs() < 1e-12);
    }

    #[test]
    fn the_heel_rocker_never_rolls_past_flat() {
        // A slap: the simulated roll reaches flat at 6 rad/s (far beyond the quintic's range).
        let samples: Vec<(f64, f64)> = (0..=300)
            .map(|i| {
                let t = i as f64 * 1e-3;
                (t, (-0.25 + 6.0 * t).min(0.0))
            })
            .collect();
        let c = stance_roll(&samples, Some((0.25 / 6.0, 0.2)), 0.04).unwrap();
        let mut last = -0.25;
        for i in 0..=1000 {
            let r = c.value(0.25 / 6.0 * i as f64 / 1000.0);
            assert!(r <= 0.0 && r >= last - 1e-15, "{i}: {r}");
            last = r;
        }
    }

    #[test]
    fn the_drawn_foot_never_goes_below_the_ground_and_its_pivot_stays_put() {
        let s = sole();
        let ball = [0.14, -0.08];
        let flat = [0.3, 0.08];
        let bend_max = 0.6;
        for i in -400..=1600 {
            let rho = i as f64 * 1e-3;
            let p = s.rolled(flat, rho, bend_max);
            let pts = s.points(&p, ball);
            for q in pts {
                assert!(q[1] >= -1e-12, "ρ {rho}: {pts:?}");
            }
            assert!(p.bend <= bend_max + 1e-12);
            let pivot = if rho <= 0.0 { pts[0] } else { pts[3] };
            let want = if rho <= 0.0 { [0.25, 0.0] } else { [0.49, 0.0] };
            assert!(
                (pivot[0] - want[0]).abs() < 1e-12 && (pivot[1] - want[1]).abs() < 1e-12,
                "ρ {rho}"
            );
        }
    }

    #[test]
    fn the_toe_lift_is_c2_convex_and_above_its_corner() {
        let d = 0.15;
        let e = 1e-5;
        for i in -300..=300 {
            let x = i as f64 * 1e-3;
            assert!(toe_lift(x, d) >= x.max(0.0) - 1e-15);
            let d2 = (toe_lift(x + e, d) - 2.0 * toe_lift(x, d) + toe_lift(x - e, d)) / (e * e);
            assert!(
                d2 >= -1e-4 && d2 <= 30.0 / 16.0 / (2.0 * d) * 1.01,
                "{x}: {d2}"
            );
        }
        // Curvature vanishes at both ends of the blend (C²; the C¹ quadratic's is 1/2δ there).
        for x in [-d, d] {
            let d2 = (toe_lift(x + e, d) - 2.0 * toe_lift(x, d) + toe_lift(x - e, d)) / (e * e);
            assert!(d2.abs() < 1e-3, "{x}: {d2}");
        }
    }

    #[test]
    fn rolled_rates_are_the_time_derivatives_of_the_rolled_foot() {
        let s = sole();
        let flat = [0.3, 0.08];
        let roll = |t: f64| [-0.2 + 1.5 * t * t, 3.0 * t, 3.0];
        for t in [0.05, 0.2, 0.5, 0.7] {
            let r = s.rolled_rates(flat, roll(t), 0.6);
            let e = 1e-5;
            let f = |t: f64| {
                let p = s.rolled(flat, roll(t)[0], 0.6);
                [p.ankle[0], p.ankle[1], p.pitch, p.bend]
            };
            let (a, b, c) = (f(t - e), f(t), f(t + e));
            for q in 0..4 {
                assert!(
                    (r[q][1] - (c[q] - a[q]) / (2.0 * e)).abs() < 1e-5,
                    "{t} {q}"
                );
                assert!(
                    (r[q][2] - (c[q] - 2.0 * b[q] + a[q]) / (e * e)).abs() < 1e-2,
                    "{t} {q}"
                );
            }
        }
    }

    #[test]
    fn a_contact_without_flat_foot_stops_where_the_roll_changes_sign() {
        let samples: Vec<(f64, f64)> = (0..=100)
            .map(|i| (i as f64 * 0.005, -0.2 + 0.9 * i as f64 * 0.005))
            .collect();
        let c = stance_roll(&samples, None, 0.04).unwrap();
        let tc = 0.2 / 0.9;
        let r = c.at(tc);
        assert!(r[0].abs() < 1e-12 && r[1] == 0.0 && r[2] == 0.0, "{r:?}");
        assert!(stance_roll(&samples[..1], None, 0.04).is_err());
    }
}
