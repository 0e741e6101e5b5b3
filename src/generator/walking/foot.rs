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
    pub fn rolled(&self, flat_ankle: [f64; 2], rho: f64, theta6_max: f64) -> ([f64; 2], f64, f64) {
        if rho <= 0.0 {
            let heel_g = add(flat_ankle, self.heel);
            let phi = -rho;
            (sub(heel_g, rot(phi, self.heel)), phi, 0.0)
        } else if rho <= theta6_max {
            let mtp_g = add(flat_ankle, self.mtp);
            let phi = -rho;
            (sub(mtp_g, rot(phi, self.mtp)), phi, rho)
        } else {
            let toe_g = add(flat_ankle, self.toe);
            let phi = -rho;
            let toe_rel = add(self.mtp, rot(theta6_max, sub(self.toe, self.mtp)));
            (sub(toe_g, rot(phi, toe_rel)), phi, theta6_max)
        }
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

/// `3s² − 2s³` on [0, 1] (clamped): a C¹ blend used for the kinematic interpolations.
#[inline]
pub fn smoothstep(s: f64) -> f64 {
    let s = s.clamp(0.0, 1.0);
    s * s * (3.0 - 2.0 * s)
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
            } else if rho <= m {
                assert!((p.toe[0] - fp.toe[0]).abs() < 1e-12 && p.toe[1].abs() < 1e-12);
                assert!(p.ball[1].abs() < 1e-12);
            } else {
                assert!((p.toe[0] - fp.toe[0]).abs() < 1e-12 && p.toe[1].abs() < 1e-12);
            }
            assert!(p.lowest() > -1e-12);
        }
    }
}
