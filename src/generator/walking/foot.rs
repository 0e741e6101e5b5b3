//! The kinematic foot (§3, §4.2, §4.3): its sole points for a given ankle position, pitch and
//! toe bend, in the sagittal plane (x forward, y up, ground at y = 0).
//!
//! Angles: the foot pitch `φ` is the rotation of the foot from flat, toes up positive; the toe
//! bend `θ6` is the toe segment's extension relative to the foot (toes up positive). The ankle
//! angle `θ5` of §3 is the angle between the shank and the sole, 90° for a neutral foot under a
//! vertical shank: `θ5 = π/2 + φ + (shank tilt)`, the shank tilt being the forward inclination of
//! the knee over the ankle.
use super::body::Body;

/// Rotates `v` by `a` (counter-clockwise: toes up for a foot pointing +x).
#[inline]
pub fn rot(a: f64, v: [f64; 2]) -> [f64; 2] {
    let (s, c) = a.sin_cos();
    [c * v[0] - s * v[1], s * v[0] + c * v[1]]
}

#[inline]
fn add(a: [f64; 2], b: [f64; 2]) -> [f64; 2] {
    [a[0] + b[0], a[1] + b[1]]
}

#[inline]
fn sub(a: [f64; 2], b: [f64; 2]) -> [f64; 2] {
    [a[0] - b[0], a[1] - b[1]]
}

/// The foot's points relative to the ankle in the foot frame (flat foot), m.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct FootShape {
    /// Heel sole point.
    pub heel: [f64; 2],
    /// Metatarsal joint centre.
    pub mtp: [f64; 2],
    /// Ball sole point (on the toe segment, under the metatarsal joint).
    pub ball: [f64; 2],
    /// Toe tip (on the toe segment).
    pub toe: [f64; 2],
}

impl FootShape {
    /// The foot of `body`.
    pub fn new(body: &Body) -> FootShape {
        FootShape {
            heel: body.heel,
            mtp: body.mtp,
            ball: body.ball,
            toe: body.toe,
        }
    }

    /// Heel, ball and toe positions for an ankle at `ankle`, pitch `phi` and toe bend `theta6`.
    pub fn points(&self, ankle: [f64; 2], phi: f64, theta6: f64) -> FootPoints {
        let heel = add(ankle, rot(phi, self.heel));
        let mtp = add(ankle, rot(phi, self.mtp));
        let ball = add(mtp, rot(phi + theta6, sub(self.ball, self.mtp)));
        let toe = add(mtp, rot(phi + theta6, sub(self.toe, self.mtp)));
        FootPoints {
            heel,
            mtp,
            ball,
            toe,
        }
    }

    /// The stance foot rolling on the ground (§4.2), parametrized by one roll coordinate `ρ`
    /// continuous through the periods: `ρ ≤ 0` heel rocker (pitch `−ρ`, toes up, heel fixed);
    /// `0 ≤ ρ ≤ θ6max` forefoot rocker (heel-off: pitch `−ρ`, toes flat so `θ6 = ρ`, metatarsal
    /// joint fixed); `ρ > θ6max` toe rocker (meta-off: pitch `−ρ`, `θ6 = θ6max`, toe tip fixed).
    /// `flat_ankle` is the ankle's position when the foot is flat. Returns the ankle position,
    /// the pitch and the toe bend.
    ///
    /// The paper switches from the forefoot to the toe rocker at `θ6 = θ6max`, where the toe
    /// bend stops dead (its rate drops from the roll rate to 0 in one instant: a one-frame jump
    /// of the metatarsal joint's motion). Here the toe segment's lift off the ground, `ψ = ρ −
    /// θ6`, is the C¹ ramp [`toe_lift`] of `ρ − θ6max` over `±δ`: `θ6` reaches `θ6max` with zero
    /// rate, never exceeds it, and the toe tip stays the fixed pivot throughout (for `ψ = 0`
    /// the toe-pivot formula is the forefoot rocker's, so both rockers are one formula).
    pub fn rolled(&self, flat_ankle: [f64; 2], rho: f64, theta6_max: f64) -> ([f64; 2], f64, f64) {
        if rho <= 0.0 {
            let heel_g = add(flat_ankle, self.heel);
            let phi = -rho;
            (sub(heel_g, rot(phi, self.heel)), phi, 0.0)
        } else {
            let toe_g = add(flat_ankle, self.toe);
            let phi = -rho;
            let theta6 = rho - toe_lift(rho - theta6_max, toe_blend(theta6_max));
            let toe_rel = add(self.mtp, rot(theta6, sub(self.toe, self.mtp)));
            (sub(toe_g, rot(phi, toe_rel)), phi, theta6)
        }
    }
}

/// Half-width `δ` of the forefoot → toe rocker blend (one definition, the drawing layer's).
pub use crate::generator::draw::foot::toe_blend;

/// The toe segment's lift `ψ(x)` for `x = ρ − θ6max`: 0 for `x ≤ −δ`, `x` for `x ≥ δ`, the C¹
/// quadratic `(x + δ)² / 4δ` between — always `≥ max(0, x)`, so `θ6 = ρ − ψ ≤ θ6max`.
#[inline]
pub fn toe_lift(x: f64, delta: f64) -> f64 {
    if x <= -delta {
        0.0
    } else if x >= delta {
        x
    } else {
        (x + delta).powi(2) / (4.0 * delta)
    }
}

/// A foot's sole points, m.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct FootPoints {
    /// Heel sole point.
    pub heel: [f64; 2],
    /// Metatarsal joint centre.
    pub mtp: [f64; 2],
    /// Ball sole point.
    pub ball: [f64; 2],
    /// Toe tip.
    pub toe: [f64; 2],
}

impl FootPoints {
    /// Lowest height of the heel, ball and toe, m.
    pub fn lowest(&self) -> f64 {
        self.heel[1].min(self.ball[1]).min(self.toe[1])
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn rolling_is_continuous_and_keeps_the_pivot_on_the_ground() {
        let b = Body::from_height(1.8, 80.0).unwrap();
        let f = FootShape::new(&b);
        let flat = [0.3, b.l9];
        let m = 0.5;
        let mut prev: Option<[f64; 2]> = None;
        for k in -200..=400 {
            let rho = k as f64 * 0.004;
            let (ankle, phi, t6) = f.rolled(flat, rho, m);
            let p = f.points(ankle, phi, t6);
            if let Some(pr) = prev {
                let d = ((ankle[0] - pr[0]).powi(2) + (ankle[1] - pr[1]).powi(2)).sqrt();
                assert!(d < 0.004 * 0.3, "jump at ρ = {rho}");
            }
            prev = Some(ankle);
            // The pivot stays where the flat foot put it, on the ground; nothing goes below.
            let fp = f.points(flat, 0.0, 0.0);
            if rho <= 0.0 {
                assert!((p.heel[0] - fp.heel[0]).abs() < 1e-12 && p.heel[1].abs() < 1e-12);
            } else if rho <= m - toe_blend(m) {
                assert!((p.toe[0] - fp.toe[0]).abs() < 1e-12 && p.toe[1].abs() < 1e-12);
                assert!(p.ball[1].abs() < 1e-12);
                assert!((t6 - rho).abs() < 1e-12);
            } else {
                assert!(t6 <= m + 1e-12 && t6 >= m - toe_blend(m) - 1e-12);
                assert!((p.toe[0] - fp.toe[0]).abs() < 1e-12 && p.toe[1].abs() < 1e-12);
            }
            assert!(p.lowest() > -1e-12);
        }
    }

    #[test]
    fn toe_bend_reaches_its_limit_with_zero_rate() {
        // C¹: the toe bend's rate dθ6/dρ goes from 1 to 0 through the blend without a jump.
        let b = Body::from_height(1.8, 80.0).unwrap();
        let f = FootShape::new(&b);
        let m = 0.5;
        let h = 1e-4;
        let t6 = |rho: f64| f.rolled([0.3, b.l9], rho, m).2;
        let mut prev_rate = 1.0;
        for k in 1..2000 {
            let rho = k as f64 * 5e-4;
            let rate = (t6(rho + h) - t6(rho - h)) / (2.0 * h);
            assert!((rate - prev_rate).abs() < 0.01, "rate jumps at ρ = {rho}");
            assert!((-1e-9..=1.0 + 1e-9).contains(&rate));
            prev_rate = rate;
        }
        assert!(prev_rate.abs() < 1e-9 && (t6(0.99) - m).abs() < 1e-12);
    }
}
