//! Planar leg and foot geometry shared by φ, ψ and the figure: where the ankle is for a given
//! foot pivot and foot/meta angle, the leg's two-link inverse kinematics, and the hip height that
//! realizes a knee angle (the ỹ₁, ỹₙ of eq. 27).
//!
//! The stance foot rolls over three pivots fixed on the floor — heel, ball, toe tip — so it can
//! neither slide nor penetrate (§1: "no skidding nor penetration of the supporting foot"):
//! heel rocker while the foot angle is positive (toes up), ball rocker while it is negative
//! before MOM, toe rocker from MOM to TOM with the meta angle M.
use super::walk_data::Anthropometry;
use crate::generator::GenerateError;

/// A point in the step frame (x forward, y up), m.
pub type P2 = [f64; 2];

/// Rotates foot-frame coordinates (u along the sole from heel to ball, v up from the sole) by
/// the foot angle `f`.
#[inline]
pub fn rotate(f: f64, u: f64, v: f64) -> P2 {
    let (s, c) = f.sin_cos();
    [u * c - v * s, u * s + v * c]
}

/// Which point of the stance foot touches the floor.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Pivot {
    /// Heel rocker: the heel at x on the floor, foot angle ≥ 0.
    Heel(f64),
    /// Ball rocker: the ball at x, foot angle ≤ 0, toes flat.
    Ball(f64),
    /// Toe rocker: the toe tip at x, foot angle ≤ 0, meta angle m ≥ 0.
    Toe(f64),
}

/// Key points of a foot (m), step frame.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct FootPoints {
    /// Ankle joint.
    pub ankle: P2,
    /// Heel (sole, back).
    pub heel: P2,
    /// Ball (metatarsal heads).
    pub ball: P2,
    /// Toe tip.
    pub toe: P2,
}

/// The foot's points when it rests on `pivot` with foot angle `f` and meta angle `m` (the angle
/// between floor and toes; used only on the toe rocker). On the heel rocker the toes continue
/// the sole; on the ball rocker they lie flat. The toe hinge J sits `ball_height` above the ball
/// sole point (0 for Table 2's foot): on the ball rocker the foot turns about J, which stays
/// still because the flat toes carry it.
pub fn foot_on_pivot(b: &Anthropometry, pivot: Pivot, f: f64, m: f64) -> FootPoints {
    let hb = b.heel_to_ball();
    let (hn, an, bt, hm) = (
        b.heel_to_n(),
        b.ankle_to_n(),
        b.ball_to_toe(),
        b.ball_height(),
    );
    let add = |p: P2, q: P2| [p[0] + q[0], p[1] + q[1]];
    match pivot {
        Pivot::Heel(x) => {
            let heel = [x, 0.0];
            let j = add(heel, rotate(f, hb, hm));
            FootPoints {
                ankle: add(heel, rotate(f, hn, an)),
                heel,
                ball: add(j, rotate(f, 0.0, -hm)),
                toe: add(j, rotate(f, bt, -hm)),
            }
        }
        Pivot::Ball(x) => {
            let j = [x, hm];
            FootPoints {
                ankle: add(j, rotate(f, hn - hb, an - hm)),
                heel: add(j, rotate(f, -hb, -hm)),
                ball: [x, 0.0],
                toe: [x + bt, 0.0],
            }
        }
        Pivot::Toe(x) => {
            // The toe segment turns about its tip, heel side up (clockwise by m).
            let j = add([x, 0.0], rotate(-m, -bt, hm));
            FootPoints {
                ankle: add(j, rotate(f, hn - hb, an - hm)),
                heel: add(j, rotate(f, -hb, -hm)),
                ball: add(j, rotate(-m, 0.0, -hm)),
                toe: [x, 0.0],
            }
        }
    }
}

/// A free (swing) foot placed by its ankle and foot angle; the toes are bent up from the sole by
/// `toe_rel` (rad, positive = toes extended).
pub fn foot_from_ankle(b: &Anthropometry, ankle: P2, f: f64, toe_rel: f64) -> FootPoints {
    let add = |p: P2, q: P2| [p[0] + q[0], p[1] + q[1]];
    let hm = b.ball_height();
    let a = rotate(f, b.heel_to_n(), b.ankle_to_n());
    let heel = [ankle[0] - a[0], ankle[1] - a[1]];
    let j = add(heel, rotate(f, b.heel_to_ball(), hm));
    FootPoints {
        ankle,
        heel,
        ball: add(j, rotate(f + toe_rel, 0.0, -hm)),
        toe: add(j, rotate(f + toe_rel, b.ball_to_toe(), -hm)),
    }
}

/// Hip-to-ankle distance of a leg whose knee is flexed by `knee` (rad, 0 = straight).
pub fn hip_ankle_distance(b: &Anthropometry, knee: f64) -> f64 {
    let (t, s) = (b.thigh(), b.shin());
    (t * t + s * s + 2.0 * t * s * knee.cos()).sqrt()
}

/// Knee flexion (rad, 0 = straight) for a hip-to-ankle distance `d`; `None` if the leg cannot
/// span it.
pub fn knee_flexion_for_distance(b: &Anthropometry, d: f64) -> Option<f64> {
    let (t, s) = (b.thigh(), b.shin());
    let c = (d * d - t * t - s * s) / (2.0 * t * s);
    if (-1.0 - 1e-12..=1.0 + 1e-12).contains(&c) {
        Some(c.clamp(-1.0, 1.0).acos())
    } else {
        None
    }
}

/// The hip height ỹ at horizontal position `hip_x` for which the leg from `ankle` has knee
/// flexion `knee` — the ỹ₁ and ỹₙ of eq. 27 (hip above the ankle).
pub fn hip_height_for_knee(
    b: &Anthropometry,
    ankle: P2,
    hip_x: f64,
    knee: f64,
    stage: &str,
) -> Result<f64, GenerateError> {
    let d = hip_ankle_distance(b, knee);
    let dx = hip_x - ankle[0];
    let h2 = d * d - dx * dx;
    if h2 < 0.0 {
        return Err(GenerateError::Numerical {
            stage: stage.to_string(),
            message: format!(
                "the hip is {:.3} m ahead of the ankle but a leg with knee flexion {knee:.3} rad \
                 spans only {d:.3} m: the step length is too far from the prototype's",
                dx.abs()
            ),
        });
    }
    Ok(ankle[1] + h2.sqrt())
}

/// Two-link inverse kinematics: the knee position for a hip and an ankle, the knee in front of
/// the hip–ankle line (a human knee). Returns the knee and whether the leg had to be treated as
/// straight because the hip–ankle distance exceeded thigh + shin (or was shorter than
/// |thigh − shin|).
pub fn knee_position(b: &Anthropometry, hip: P2, ankle: P2) -> (P2, bool) {
    let (t, s) = (b.thigh(), b.shin());
    let (dx, dy) = (ankle[0] - hip[0], ankle[1] - hip[1]);
    let d = dx.hypot(dy);
    let (ux, uy) = if d > 0.0 {
        (dx / d, dy / d)
    } else {
        (0.0, -1.0)
    };
    let max = t + s;
    let min = (t - s).abs();
    let clamped = d > max || d < min;
    let dc = d.clamp(min, max);
    // Distance along hip→ankle to the knee's foot point, and the knee's offset from the line.
    let a = (t * t - s * s + dc * dc) / (2.0 * dc);
    let h = (t * t - a * a).max(0.0).sqrt();
    // Perpendicular pointing forward (+x) for a leg hanging down: rotate (ux, uy) by +90°.
    let (px, py) = (-uy, ux);
    (
        [hip[0] + a * ux + h * px, hip[1] + a * uy + h * py],
        clamped,
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    fn body() -> Anthropometry {
        Anthropometry::new(0.36, 0.38, 0.05, 0.11, 0.057, 0.07).unwrap()
    }

    #[test]
    fn pivots_agree_at_the_transitions() {
        for h in [0.0, 0.02] {
            pivots_agree(&body().with_ball_height(h).unwrap());
        }
    }

    fn pivots_agree(b: &Anthropometry) {
        let b = *b;
        let hb = b.heel_to_ball();
        let h = foot_on_pivot(&b, Pivot::Heel(0.2), 0.0, 0.0);
        let ba = foot_on_pivot(&b, Pivot::Ball(0.2 + hb), 0.0, 0.0);
        let to = foot_on_pivot(&b, Pivot::Toe(0.2 + hb + b.ball_to_toe()), -0.3, 0.0);
        let bb = foot_on_pivot(&b, Pivot::Ball(0.2 + hb), -0.3, 0.0);
        for k in 0..2 {
            assert!((h.ankle[k] - ba.ankle[k]).abs() < 1e-15);
            assert!((to.ankle[k] - bb.ankle[k]).abs() < 1e-15);
            assert!((to.heel[k] - bb.heel[k]).abs() < 1e-15);
        }
        assert!((h.ankle[1] - b.ankle_to_n()).abs() < 1e-15);
    }

    #[test]
    fn ik_reproduces_segment_lengths_and_knee_angle() {
        let b = body();
        let hip = [0.1, 0.8];
        let ankle = [0.25, 0.1];
        let (k, clamped) = knee_position(&b, hip, ankle);
        assert!(!clamped);
        let th = (k[0] - hip[0]).hypot(k[1] - hip[1]);
        let sh = (k[0] - ankle[0]).hypot(k[1] - ankle[1]);
        assert!((th - b.thigh()).abs() < 1e-12 && (sh - b.shin()).abs() < 1e-12);
        // The knee lies in front of the hip–ankle line.
        let cross = (ankle[0] - hip[0]) * (k[1] - hip[1]) - (ankle[1] - hip[1]) * (k[0] - hip[0]);
        assert!(cross > 0.0);
        let d = (ankle[0] - hip[0]).hypot(ankle[1] - hip[1]);
        let knee = knee_flexion_for_distance(&b, d).unwrap();
        assert!((hip_ankle_distance(&b, knee) - d).abs() < 1e-12);
        let y = hip_height_for_knee(&b, ankle, hip[0], knee, "t").unwrap();
        assert!((y - hip[1]).abs() < 1e-12);
    }
}
