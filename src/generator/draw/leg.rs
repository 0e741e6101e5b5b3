//! The one soft two-link leg IK of the drawing layer. A rigid two-link chain straightens at
//! `d = l₁ + l₂` with an unbounded knee rate (`dθ/dd ∝ 1/√(l₁ + l₂ − d)`), and cannot reach
//! beyond. Here the hip–ankle distance is first softened ([`SoftLeg::reach`]): exact up to
//! `l₁ + l₂ − 2b`, then `l₁ + l₂ − 2b + 2b·tanh((d − l₁ − l₂ + 2b)/2b)` — C² at the joint
//! (`tanh` is odd: value, slope 1 and curvature 0 match), smooth beyond, approaching the
//! straight leg only in the limit. The rigid chain is then solved exactly inside its reach, so
//! the knee angle is a smooth function of a smooth hip–ankle distance, and the ankle target is
//! reached exactly whenever it is `2b` inside the leg's length.
//!
//! The band is the caller's drawing parameter. A straight leg drawn at the exact reach bends
//! the knee by ≈ `√(4Lb/l₁l₂)` (≈ 24° at b = 1 cm, ≈ 8° at 1 mm), while the knee's rate near
//! extension is at most ≈ 1.09 × `√(2L/l₁l₂)/(2√(2b))` per metre of hip–ankle distance (≈ 11
//! rad/m at 1 cm, ≈ 37 at 1 mm): docs/klaw.md "Stage B, session 7" has what each did to the
//! walk.
use crate::events::Side;
use crate::generator::ik::{flexion_for_span, leg_ik, LimbIk};
use crate::generator::skeleton::{Joint, Pose, Skeleton};
use crate::generator::GenerateError;
use glam::DVec3;

/// A two-link leg drawn with a soft reach.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SoftLeg {
    upper: f64,
    lower: f64,
    band: f64,
}

impl SoftLeg {
    /// Thigh `upper` and shank `lower` lengths and soft band `band` (m, all positive; the band
    /// less than a quarter of the shorter segment).
    pub fn new(upper: f64, lower: f64, band: f64) -> Result<SoftLeg, GenerateError> {
        let ok = |x: f64| x.is_finite() && x > 0.0;
        if !(ok(upper) && ok(lower)) {
            return Err(GenerateError::Parameter {
                name: "leg segment length".into(),
                value: if ok(upper) { lower } else { upper },
                message: "thigh and shank lengths must be positive".into(),
            });
        }
        if !(ok(band) && band < 0.25 * upper.min(lower)) {
            return Err(GenerateError::Parameter {
                name: "soft band".into(),
                value: band,
                message: format!(
                    "must be positive and below a quarter of the shorter segment ({} m)",
                    0.25 * upper.min(lower)
                ),
            });
        }
        Ok(SoftLeg { upper, lower, band })
    }

    /// The leg of `skeleton` with soft band `band` (m; see the module doc).
    pub fn of(skeleton: &Skeleton, band: f64) -> Result<SoftLeg, GenerateError> {
        let a = skeleton.anthropometry();
        SoftLeg::new(a.thigh.length_m, a.shank.length_m, band)
    }

    /// Full length `l₁ + l₂`, m.
    pub fn length(&self) -> f64 {
        self.upper + self.lower
    }

    /// The longest hip–ankle distance drawn exactly, `l₁ + l₂ − 2b`, m.
    pub fn exact_reach(&self) -> f64 {
        self.length() - 2.0 * self.band
    }

    /// The drawn hip–ankle distance for a target `d` m from the hip (see the module doc).
    pub fn reach(&self, d: f64) -> f64 {
        let s0 = self.exact_reach();
        if d <= s0 {
            d
        } else {
            let w = 2.0 * self.band;
            s0 + w * ((d - s0) / w).tanh()
        }
    }

    /// Knee flexion (rad, ≥ 0) drawn for a target `d` m from the hip.
    pub fn flexion(&self, d: f64) -> f64 {
        flexion_for_span(self.upper, self.lower, self.reach(d))
    }

    /// The point the ankle is drawn at for `target` seen from `hip`: on the hip–target line at
    /// the soft reach.
    pub fn drawn_target(&self, hip: DVec3, target: DVec3) -> DVec3 {
        let v = target - hip;
        let d = v.length();
        if d <= self.exact_reach() || d < 1e-12 {
            return target;
        }
        hip + v * (self.reach(d) / d)
    }

    /// Sets the hip and knee of `side` in `pose` (root and pelvis already set) so the ankle is at
    /// the soft target of `target` (world), the knee toward `knee_direction`.
    pub fn place(
        &self,
        skeleton: &Skeleton,
        pose: &mut Pose,
        side: Side,
        target: DVec3,
        knee_direction: DVec3,
    ) -> LimbIk {
        let hip_joint = Joint::leg(side)[0];
        let hip = match hip_joint.parent() {
            Some(p) => {
                let (rot, pos) = skeleton.joint_world(pose, p);
                pos + rot * skeleton.offset(hip_joint)
            }
            None => pose.root,
        };
        leg_ik(
            skeleton,
            pose,
            side,
            self.drawn_target(hip, target),
            knee_direction,
        )
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::generator::anthropometry::Anthropometry;

    fn leg() -> SoftLeg {
        SoftLeg::new(0.441, 0.443, 0.01).unwrap()
    }

    #[test]
    fn the_reach_is_exact_inside_and_c2_at_the_band() {
        let l = leg();
        for i in 0..=100 {
            let d = 0.1 + (l.exact_reach() - 0.1) * i as f64 / 100.0;
            assert_eq!(l.reach(d), d);
        }
        // Value, slope and curvature continuous across the band's start (finite differences).
        let s0 = l.exact_reach();
        let e = 1e-5;
        let slope = |d: f64| (l.reach(d + e) - l.reach(d - e)) / (2.0 * e);
        let curv = |d: f64| (l.reach(d + e) - 2.0 * l.reach(d) + l.reach(d - e)) / (e * e);
        assert!((slope(s0 - 2.0 * e) - slope(s0 + 2.0 * e)).abs() < 1e-5);
        // Curvature 0 below, O(d − s0) above (a C¹ quadratic blend's would jump to 1/2b = 50 /m).
        assert!(curv(s0 - 2.0 * e).abs() < 1e-3 && curv(s0 + 2.0 * e).abs() < 0.2);
        // Monotone, below the full length, never straight.
        let mut last = 0.0;
        for i in 0..2000 {
            let d = s0 - 0.01 + 0.0001 * i as f64;
            let r = l.reach(d);
            assert!(r > last && r < l.length());
            last = r;
        }
    }

    #[test]
    fn the_knee_is_smooth_through_full_extension_and_the_rigid_knee_is_not() {
        let l = leg();
        let rigid = |d: f64| flexion_for_span(l.upper, l.lower, d.min(l.length()));
        // Knee rate per metre of hip–ankle distance over the last 5 cm and 5 cm beyond.
        let e = 1e-6;
        let mut worst = [0.0f64; 2];
        let mut worst_curv_jump = 0.0f64;
        let mut last_rate: Option<f64> = None;
        for i in 0..10_000 {
            let d = l.length() - 0.05 + 1e-5 * i as f64;
            let soft = (l.flexion(d + e) - l.flexion(d - e)).abs() / (2.0 * e);
            worst[0] = worst[0].max(soft);
            if d + e < l.length() {
                worst[1] = worst[1].max((rigid(d + e) - rigid(d - e)).abs() / (2.0 * e));
            }
            if let Some(r) = last_rate {
                worst_curv_jump = worst_curv_jump.max((soft - r).abs());
            }
            last_rate = Some(soft);
        }
        // Bounded: at most (4/3)·√(2/3) ≈ 1.089 times the rigid knee's rate at the band's start
        // (≈ 11 rad/m at b = 1 cm; the maximum of (1 + u)·√(1 − u), u = tanh, at u = 1/3),
        // while the rigid knee's grows without bound (≈ 1,000 rad/m 1e-6 m short).
        let s0 = l.exact_reach();
        let bound = (rigid(s0 - e) - rigid(s0 + e)).abs() / (2.0 * e);
        assert!(worst[0] <= 1.09 * bound, "{} > {}", worst[0], bound);
        assert!(worst[1] > 20.0 * bound, "{}", worst[1]);
        // The rate changes by little from one 10 µm sample to the next: no kink.
        assert!(worst_curv_jump < 0.05 * bound, "{worst_curv_jump}");
    }

    #[test]
    fn a_target_inside_the_exact_reach_is_reached_exactly() {
        let sk = Skeleton::new(Anthropometry::from_height(1.8, 80.0).unwrap()).unwrap();
        let l = SoftLeg::of(&sk, 0.01).unwrap();
        let mut pose = sk.rest_pose();
        pose.root = DVec3::new(0.2, 0.9, 0.0);
        let hip = sk.forward(&pose).position(Joint::RHip);
        for (dx, dy) in [(0.1, -0.7), (-0.25, -0.78), (0.0, -0.5), (0.3, -0.6)] {
            let target = hip + DVec3::new(dx, dy, 0.02);
            assert!((target - hip).length() <= l.exact_reach());
            let r = l.place(&sk, &mut pose, Side::Right, target, DVec3::X);
            assert!(r.reached);
            let ankle = sk.forward(&pose).position(Joint::RAnkle);
            assert!(
                (ankle - target).length() < 1e-9,
                "{}",
                (ankle - target).length()
            );
        }
        // Beyond: drawn on the hip–target line, short by no more than the target's excess.
        let target = hip + DVec3::new(0.05, -(l.length() + 0.02), 0.0);
        l.place(&sk, &mut pose, Side::Right, target, DVec3::X);
        let ankle = sk.forward(&pose).position(Joint::RAnkle);
        let d = (ankle - hip).length();
        assert!(d < l.length() && d > l.exact_reach());
        assert!((ankle - hip).normalize().dot((target - hip).normalize()) > 1.0 - 1e-9);
    }

    #[test]
    fn bad_lengths_are_parameter_errors() {
        assert!(SoftLeg::new(0.4, 0.0, 0.01).is_err());
        assert!(SoftLeg::new(0.4, 0.4, 0.2).is_err());
        assert!(SoftLeg::new(0.4, 0.4, f64::NAN).is_err());
    }
}
