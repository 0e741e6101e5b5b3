//! The swing leg's kinematic foot (§4.3): the ankle angle θ5 and the toe bend θ6 interpolated
//! between their toe-off and heel-strike values, pitched up where the toe clearance needs it.
use super::foot::{FootPoints, FootShape};
use crate::generator::curves::smoothstep;
use std::f64::consts::FRAC_PI_2;

/// The kinematic swing foot (§4.3): the ankle angle θ5 and the toe bend θ6 are interpolated
/// (C¹ blends) between their toe-off values, a dorsiflexed value at the end of swing1 and the
/// heel-strike values; θ6 returns to 0 by the end of swing1.
///
/// The paper interpolates θ5 and θ6 between toe-off and heel strike only. In slow walks (long
/// swings, short steps) that foot pitches toe-down while the knee extends in swing2 and the toe
/// goes through the ground, and no temporary hip torque can lift it in time (the dip comes a few
/// centiseconds into swing2, faster than the thigh responds). The locomotion attribute "toe
/// clearance during swing" is therefore also honoured kinematically, as a person does: the ankle
/// dorsiflexes beyond the interpolated value just enough for the toe and ball to stay
/// `clearance` above the ground (the clearance ramps in from 0 at toe-off over the first 30 % of
/// swing1, at least 15 % of the swing, [`SwingFoot::clearance_ramp`], while the toe is leaving
/// the ground), up to the dorsiflexion limit `theta5_max`. The
/// dynamic recovery of swing2 still handles what this cannot (the heel).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SwingFoot {
    /// The foot.
    pub foot: FootShape,
    /// Toe-off, end of swing1, end of swing2, heel strike, s.
    pub times: [f64; 4],
    /// θ5 at toe-off, at the end of swing1 and at heel strike, rad.
    pub theta5: [f64; 3],
    /// θ6 at toe-off, rad.
    pub theta6_toe_off: f64,
    /// Toe clearance, m.
    pub clearance: f64,
    /// Dorsiflexion limit of θ5, rad.
    pub theta5_max: f64,
    /// Rate of θ5 at heel strike, rad/s: the landing foot's ankle rate just after heel strike
    /// (bounded by `generate`'s `MAX_CONTACT_ANKLE_RATE`), set once the next stance's heel rocker
    /// is planned; 0 while the swing is simulated (swing3's θ5 does not enter the dynamics).
    pub theta5_rate_hs: f64,
    /// Weight in [0, 1] of the [`SwingFoot::contact_ramp`] against the swing3 cubic (see
    /// [`SwingFoot::theta56`]), set with [`SwingFoot::theta5_rate_hs`] (`generate`'s
    /// `contact_ramp_weight`); 0 while the swing is simulated.
    pub contact_ramp_weight: f64,
}

impl SwingFoot {
    /// Interpolated θ5 and θ6 at `t` (before the clearance rule).
    pub fn theta56(&self, t: f64) -> (f64, f64) {
        let [t0, t1, t2, t3] = self.times;
        let [to, mid, hs] = self.theta5;
        let s1 = smoothstep((t - t0) / (t1 - t0));
        let mut th5 = if t <= t1 {
            to + (mid - to) * s1
        } else {
            mid + (hs - mid) * smoothstep((t - t1) / (t3 - t1))
        };
        if t > t2 && t3 > t2 {
            // Swing3 only: the cubic correction that leaves θ5 and its rate unchanged at t2 and
            // its value at heel strike, and ends with the rate the stance foot takes on.
            let u = ((t - t2) / (t3 - t2)).min(1.0);
            th5 += self.theta5_rate_hs * (t3 - t2) * (u - 1.0) * u * u;
        }
        let w = self.contact_ramp_weight.clamp(0.0, 1.0);
        if t > t1 && t3 > t1 && w > 0.0 {
            th5 = (1.0 - w) * th5 + w * self.contact_ramp(t);
        }
        (th5, self.theta6_toe_off * (1.0 - s1))
    }

    /// θ5 from the end of swing1 to heel strike (`t1 → t3`, `u` the fraction of that time
    /// `T13`): from its mid-swing value `θm` at rest to its heel-strike value `θh` at the contact
    /// rate `ṙ` ([`SwingFoot::theta5_rate_hs`]), through `θm + (θh − θm)·u^s`,
    /// `s = ṙ·T13 / (θh − θm)`, when `s ≥ 2`: monotone (never beyond either end, no extra
    /// dorsiflexion), C¹ at both ends, its rate rising steadily into the contact. For `s < 2`
    /// (a slow landing, or a rate against the interpolation's direction) the cubic Hermite of
    /// the same ends (equal to `u²` at `s = 2`).
    pub fn contact_ramp(&self, t: f64) -> f64 {
        let [_, t1, _, t3] = self.times;
        let [_, mid, hs] = self.theta5;
        let big_t = t3 - t1;
        if big_t <= 0.0 {
            return hs;
        }
        let u = ((t - t1) / big_t).clamp(0.0, 1.0);
        let d = hs - mid;
        let r_t = self.theta5_rate_hs * big_t;
        if d * r_t > 0.0 && r_t / d >= 2.0 {
            mid + d * u.powf(r_t / d)
        } else {
            mid + d * (3.0 - 2.0 * u) * u * u + r_t * (u - 1.0) * u * u
        }
    }

    /// Foot pitch φ (toes up positive) and toe bend θ6 at `t`, for the ankle at `ankle` (ground
    /// frame) and the shank at `shank = θ3 + θ4` from the vertical.
    ///
    /// The clearance rule takes the larger of the interpolated pitch and the pitch that holds
    /// the lower of toe and ball at the clearance, through a smooth maximum of width
    /// [`CLEARANCE_SOFT`] (ramped in with the clearance after toe-off, faded out over swing3,
    /// so toe-off and heel strike keep their pitches):
    /// a hard maximum engages and releases with a kink in the ankle's rate (measured:
    /// docs/klaw.md). The smooth maximum is never below either, so the foot clears at least as
    /// before.
    pub fn pose(&self, t: f64, ankle: [f64; 2], shank: f64) -> (f64, f64) {
        let [t0, _, t2, t3] = self.times;
        let (th5, th6) = self.theta56(t);
        let phi_i = th5 - FRAC_PI_2 - shank;
        let need = self.clearance * smoothstep((t - t0) / self.clearance_ramp());
        let phi_max = self.theta5_max - FRAC_PI_2 - shank;
        if phi_i >= phi_max {
            return (phi_i, th6);
        }
        // Newton on the lower of toe and ball: d(point_y)/dφ = (point − ankle)_x.
        let mut phi_c = phi_i;
        for _ in 0..8 {
            let p = self.foot.points(ankle, phi_c, th6);
            let (low, lx) = if p.toe[1] < p.ball[1] {
                (p.toe[1], p.toe[0])
            } else {
                (p.ball[1], p.ball[0])
            };
            let slope = lx - ankle[0];
            if slope <= 1e-6 {
                break;
            }
            let step = ((need - low) / slope).clamp(-0.5, 0.5);
            phi_c += step;
            if step.abs() < 1e-10 {
                break;
            }
        }
        // The width ramps in with the clearance (at toe-off the toe is on the ground, where the
        // two pitches agree: a full width would pitch the foot up at once).
        let ramp = smoothstep((t - t0) / self.clearance_ramp());
        let e = CLEARANCE_SOFT * ramp * (1.0 - smoothstep((t - t2) / (t3 - t2)));
        let phi = 0.5 * (phi_i + phi_c + ((phi_i - phi_c).powi(2) + e * e).sqrt());
        (phi.min(phi_max), th6)
    }

    /// How long after toe off the toe clearance takes to ramp in, s: 30 % of swing1, but at
    /// least [`CLEARANCE_RAMP_MIN`] of the swing.
    pub fn clearance_ramp(&self) -> f64 {
        let [t0, t1, _, t3] = self.times;
        (0.3 * (t1 - t0)).max(CLEARANCE_RAMP_MIN * (t3 - t0))
    }

    /// Foot sole points at `t` (see [`SwingFoot::pose`]).
    pub fn points(&self, t: f64, ankle: [f64; 2], shank: f64) -> FootPoints {
        let (phi, th6) = self.pose(t, ankle, shank);
        self.foot.points(ankle, phi, th6)
    }
}

/// Least time over which the swing toe's clearance ramps in after toe off, as a fraction of the
/// swing (see [`SwingFoot::clearance_ramp`]): 30 % of a swing1 that ends at half the swing.
pub const CLEARANCE_RAMP_MIN: f64 = 0.15;

/// Width of the swing foot's smooth maximum between its interpolated pitch and the pitch the toe
/// clearance needs, rad (see [`SwingFoot::pose`]).
pub const CLEARANCE_SOFT: f64 = 0.05;

#[cfg(test)]
mod tests {
    use super::*;
    use crate::generator::walking::body::Body;

    fn test_swing_foot(rate: f64) -> SwingFoot {
        let body = Body::from_height(1.8, 75.0).unwrap();
        SwingFoot {
            foot: FootShape::new(&body),
            times: [0.1, 0.3, 0.44, 0.5],
            theta5: [1.2, 1.75, 1.6],
            theta6_toe_off: 0.3,
            clearance: 0.005,
            theta5_max: 2.0,
            theta5_rate_hs: rate,
            contact_ramp_weight: 1.0,
        }
    }

    #[test]
    fn swing_ankle_ends_with_the_contact_rate_and_keeps_its_ends() {
        let plain = test_swing_foot(0.0);
        let th = |f: &SwingFoot, t: f64| f.theta56(t).0;
        let e = 1e-6;
        let rate = |f: &SwingFoot, t: f64| (th(f, t + e) - th(f, t - e)) / (2.0 * e);
        let end_rate = |f: &SwingFoot| (th(f, 0.5) - th(f, 0.5 - e)) / e;
        // The plain interpolation comes to rest at heel strike.
        assert!(end_rate(&plain).abs() < 1e-3, "{}", end_rate(&plain));
        for r in [-6.0, -3.0, -1.0, 2.0] {
            let f = test_swing_foot(r);
            // Unchanged through swing1, C¹ at its end; the heel-strike value kept, reached
            // at the contact rate.
            for t in [0.1, 0.2, 0.3] {
                assert_eq!(th(&f, t), th(&plain, t), "{r}: {t}");
            }
            assert!(
                (rate(&f, 0.3 + e) - rate(&plain, 0.3 + e)).abs() < 1e-4,
                "{r}"
            );
            assert!((th(&f, 0.5) - 1.6).abs() < 1e-12, "{r}");
            assert!((end_rate(&f) - r).abs() < 1e-3, "{r}: {}", end_rate(&f));
        }
        // At the full contact rate the ankle plantarflexes monotonically from its mid-swing
        // value to its heel-strike value (no dorsiflexion bump, as the swing3 cubic alone
        // made: 4/27 · |ṙ| · T3 beyond the plain interpolation), and its steps at 100 fps rise
        // frame by frame into the contact.
        let f = test_swing_foot(-super::super::generate::MAX_CONTACT_ANKLE_RATE);
        let mut last = th(&f, 0.3);
        for i in 1..=200 {
            let v = th(&f, 0.3 + 0.2 * i as f64 / 200.0);
            assert!(
                v <= last + 1e-15 && (1.6 - 1e-15..=1.75).contains(&v),
                "{i}: {v}"
            );
            last = v;
        }
        let steps: Vec<f64> = (0..6)
            .map(|k| th(&f, 0.5 - 0.01 * (k + 1) as f64) - th(&f, 0.5 - 0.01 * k as f64))
            .collect();
        for k in 0..5 {
            assert!(steps[k] > steps[k + 1] && steps[k + 1] > 0.0, "{steps:?}");
        }
        // The ramp alone below s = 2 is the cubic Hermite of the same ends.
        let g = test_swing_foot(-1.0);
        let u = 0.4;
        let herm = 1.75 - 0.15 * (3.0 - 2.0 * u) * u * u - 0.2 * (u - 1.0) * u * u;
        assert!((g.contact_ramp(0.3 + 0.2 * u) - herm).abs() < 1e-12);
    }

    #[test]
    fn swing_foot_takes_up_the_clearance_without_a_kink() {
        // The ankle held low and still, the shank vertical: early in swing1 the plantarflexed
        // interpolated foot would put its toe in the ground, so the clearance pitches it up,
        // until the interpolation dorsiflexes it past that.
        let body = Body::from_height(1.8, 75.0).unwrap();
        let sf = SwingFoot {
            foot: FootShape::new(&body),
            times: [0.0, 0.2, 0.34, 0.4],
            theta5: [1.3, 1.65, 1.57],
            theta6_toe_off: 0.3,
            clearance: 0.01,
            theta5_max: 115f64.to_radians(),
            theta5_rate_hs: 0.0,
            contact_ramp_weight: 0.0,
        };
        let ankle = [0.0, body.l9 + 0.005];
        let h = 5e-4;
        let ts: Vec<f64> = (0..=400).map(|i| i as f64 * h).collect();
        let pitch: Vec<f64> = ts.iter().map(|&t| sf.pose(t, ankle, 0.0).0).collect();
        let interp: Vec<f64> = ts.iter().map(|&t| sf.theta56(t).0 - FRAC_PI_2).collect();
        let mut lifted = 0.0f64;
        for (i, &t) in ts.iter().enumerate() {
            // Never below the interpolation, the clearance kept (it ramps in over 30 % of
            // swing1).
            assert!(
                pitch[i] >= interp[i] - 1e-12,
                "below the interpolation at {t}"
            );
            let need = sf.clearance * smoothstep(t / (0.3 * 0.2));
            let p = sf.points(t, ankle, 0.0);
            assert!(
                p.toe[1].min(p.ball[1]) >= need - 1e-9,
                "toe {} ball {} below {need} at {t}",
                p.toe[1],
                p.ball[1]
            );
            lifted = lifted.max(pitch[i] - interp[i]);
        }
        assert!(lifted > 0.1, "the clearance must act here: {lifted}");
        // C¹: the pitch's rate changes by a bounded amount per sample where the clearance takes
        // over and lets go (a hard maximum jumps by the difference of the two rates there).
        let rate: Vec<f64> = pitch.windows(2).map(|w| (w[1] - w[0]) / h).collect();
        let jump = rate
            .windows(2)
            .map(|w| (w[1] - w[0]).abs())
            .fold(0.0, f64::max);
        let hard: Vec<f64> = ts
            .iter()
            .zip(&interp)
            .map(|(&t, &pi)| {
                let need = sf.clearance * smoothstep(t / (0.3 * 0.2));
                let (mut lo, mut hi) = (pi - 1.0, pi + 1.0);
                for _ in 0..60 {
                    let m = 0.5 * (lo + hi);
                    let p = sf.foot.points(ankle, m, sf.theta56(t).1);
                    if p.toe[1].min(p.ball[1]) >= need {
                        hi = m;
                    } else {
                        lo = m;
                    }
                }
                pi.max(hi)
            })
            .collect();
        let hard_rate: Vec<f64> = hard.windows(2).map(|w| (w[1] - w[0]) / h).collect();
        let hard_jump = hard_rate
            .windows(2)
            .map(|w| (w[1] - w[0]).abs())
            .fold(0.0, f64::max);
        assert!(
            jump < 0.2 * hard_jump,
            "rate jump {jump} rad/s vs {hard_jump} with a hard maximum"
        );
    }
}
