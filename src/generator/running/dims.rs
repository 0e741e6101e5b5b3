//! The segment dimensions the running generator works with, and the small planar/3-D geometry
//! (leg forward and inverse kinematics) shared by the state and phase constraints.
//!
//! Frame: x forward, y up, z to the right, metres, radians. Sagittal angles are rotations about
//! +z, so a positive angle lifts the front: hip flexion, ankle dorsiflexion and toe dorsiflexion
//! are positive; knee flexion is stored as a positive number and applied as a negative rotation.
use glam::{DMat3, DQuat, DVec2, DVec3};

use crate::generator::anthropometry::Anthropometry;

/// Lengths of the figure the running algorithm needs (metres), read from the shared
/// [`Anthropometry`] (table B-1 of Bruderlin & Calvert 1989, scaled from body height) so that the
/// generator's geometry and the skeleton's forward kinematics agree exactly.
///
/// The foot: the ankle is `ankle_height` above the sole; the heel sole point `heel_back` behind
/// it; the metatarsal (toe) joint `ankle_to_ball` ahead of it and `mtp_height` above the sole; the
/// ball sole point is under the metatarsal joint and, like the toe tip (`toe` ahead of the joint
/// on the sole), rides on the toe segment.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RunnerDims {
    /// Body height, m.
    pub body_height: f64,
    /// Hip to knee, m.
    pub thigh: f64,
    /// Knee to ankle, m.
    pub shank: f64,
    /// Ankle above the sole (foot base), m.
    pub ankle_height: f64,
    /// Heel behind the ankle along the sole, m.
    pub heel_back: f64,
    /// Metatarsal joint ahead of the ankle, m.
    pub ankle_to_ball: f64,
    /// Metatarsal joint above the sole, m.
    pub mtp_height: f64,
    /// Metatarsal joint to toe tip along the sole, m.
    pub toe: f64,
    /// Right hip joint relative to the pelvis root, in the pelvis frame, m (the left hip is the
    /// mirror image in z).
    pub hip_offset: DVec3,
}

impl RunnerDims {
    /// The dimensions of a figure with the given anthropometry.
    pub fn from_anthropometry(a: &Anthropometry) -> Self {
        RunnerDims {
            body_height: a.height_m,
            thigh: a.thigh.length_m,
            shank: a.shank.length_m,
            ankle_height: a.foot.ankle_height_m,
            heel_back: a.foot.hind_foot_m,
            ankle_to_ball: a.foot.mid_foot_m,
            mtp_height: a.foot.metatarsal_height_m,
            toe: a.foot.toe_m,
            hip_offset: DVec3::new(0.0, 0.0, 0.5 * a.hip_width_m),
        }
    }

    /// Dimensions for a figure of `body_height` m with the table proportions.
    pub fn from_height(body_height: f64) -> Result<Self, crate::generator::GenerateError> {
        Ok(Self::from_anthropometry(&Anthropometry::from_height(
            body_height,
            70.0,
        )?))
    }

    /// Heel to toe tip along the sole of a flat foot, m.
    pub fn foot_length(&self) -> f64 {
        self.heel_back + self.ankle_to_ball + self.toe
    }

    /// Length of the fully extended leg, hip to ankle, m.
    pub fn leg_reach(&self) -> f64 {
        self.thigh + self.shank
    }

    /// Hip–ankle distance for a knee flexion `k` (rad, 0 = straight), by the law of cosines.
    pub fn hip_ankle(&self, k: f64) -> f64 {
        let (a, b) = (self.thigh, self.shank);
        (a * a + b * b + 2.0 * a * b * k.cos()).max(0.0).sqrt()
    }

    /// Knee flexion (rad) giving a hip–ankle distance `d`; clamped to the reachable range.
    pub fn knee_for_distance(&self, d: f64) -> f64 {
        let (a, b) = (self.thigh, self.shank);
        let c = ((d * d - a * a - b * b) / (2.0 * a * b)).clamp(-1.0, 1.0);
        c.acos()
    }

    /// The hip of `side_sign` (+1 right, −1 left) relative to the pelvis root, pelvis frame.
    pub fn hip_local(&self, side_sign: f64) -> DVec3 {
        DVec3::new(
            self.hip_offset.x,
            self.hip_offset.y,
            side_sign * self.hip_offset.z,
        )
    }

    /// Heel relative to the ankle in the foot frame (sagittal).
    pub fn heel_f(&self) -> DVec2 {
        DVec2::new(-self.heel_back, -self.ankle_height)
    }
    /// Metatarsal joint relative to the ankle in the foot frame.
    pub fn mtp_f(&self) -> DVec2 {
        DVec2::new(self.ankle_to_ball, self.mtp_height - self.ankle_height)
    }
    /// Ball relative to the ankle in the foot frame with the toes dorsiflexed by `m` rad.
    pub fn ball_f(&self, m: f64) -> DVec2 {
        self.mtp_f() + rot2(m, DVec2::new(0.0, -self.mtp_height))
    }
    /// Toe tip relative to the ankle in the foot frame with the toes dorsiflexed by `m` rad.
    pub fn toe_f(&self, m: f64) -> DVec2 {
        self.mtp_f() + rot2(m, DVec2::new(self.toe, -self.mtp_height))
    }
}

/// Rotates a sagittal vector by `a` rad (positive lifts the front).
#[inline]
pub fn rot2(a: f64, v: DVec2) -> DVec2 {
    let (s, c) = a.sin_cos();
    DVec2::new(c * v.x - s * v.y, s * v.x + c * v.y)
}

/// Pitch of a sagittal vector measured from straight down, positive forward (rad).
#[inline]
pub fn pitch_from_down(v: DVec2) -> f64 {
    v.x.atan2(-v.y)
}

/// The angles of one leg: world pitch of the thigh in its leg plane, roll of the leg plane about
/// the forward axis, knee flexion, ankle dorsiflexion (foot pitch minus shank pitch) and toe
/// dorsiflexion, all rad. The foot always stays in a vertical plane pointing forward (§3.3.1: "we
/// assume the motion of the foot to be planar (vertical)"); the ankle absorbs the leg roll.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct LegAngles {
    /// Thigh pitch from vertical (down), positive forward (hip flexion in the world), rad.
    pub pitch: f64,
    /// Roll of the leg plane about +x, rad.
    pub roll: f64,
    /// Knee flexion, rad (0 = straight).
    pub knee: f64,
    /// Ankle dorsiflexion, rad (0 = foot flat when the shank is vertical; plantarflexion < 0).
    pub ankle: f64,
    /// Toe (metatarsal joint) dorsiflexion, rad.
    pub meta: f64,
}

impl LegAngles {
    /// Component `i` (0 pitch, 1 roll, 2 knee, 3 ankle, 4 meta).
    #[inline]
    pub fn get(&self, i: usize) -> f64 {
        match i {
            0 => self.pitch,
            1 => self.roll,
            2 => self.knee,
            3 => self.ankle,
            _ => self.meta,
        }
    }
    /// Sets component `i`.
    #[inline]
    pub fn set(&mut self, i: usize, v: f64) {
        match i {
            0 => self.pitch = v,
            1 => self.roll = v,
            2 => self.knee = v,
            3 => self.ankle = v,
            _ => self.meta = v,
        }
    }
    /// Shank pitch from vertical, rad.
    #[inline]
    pub fn shank_pitch(&self) -> f64 {
        self.pitch - self.knee
    }
    /// Foot (sole) pitch relative to the ground, rad, positive toe up.
    #[inline]
    pub fn foot_pitch(&self) -> f64 {
        self.shank_pitch() + self.ankle
    }
}

/// World positions of one leg's joints and foot points.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct LegPoints {
    /// Hip joint.
    pub hip: DVec3,
    /// Knee joint.
    pub knee: DVec3,
    /// Ankle joint.
    pub ankle: DVec3,
    /// Heel (back of the sole).
    pub heel: DVec3,
    /// Ball (first metatarsal head, on the sole; the toe joint).
    pub ball: DVec3,
    /// Toe tip.
    pub toe: DVec3,
}

impl LegPoints {
    /// Height of the lowest foot point (heel, ball or toe tip; the sole is straight between them).
    #[inline]
    pub fn lowest(&self) -> f64 {
        self.heel.y.min(self.ball.y).min(self.toe.y)
    }
}

#[inline]
fn in_plane(roll: f64, v: DVec2) -> DVec3 {
    let (s, c) = roll.sin_cos();
    DVec3::new(v.x, v.y * c, v.y * s)
}

/// Forward kinematics of one leg from its hip position.
#[inline]
pub fn leg_fk(d: &RunnerDims, hip: DVec3, a: &LegAngles) -> LegPoints {
    let down = DVec2::new(0.0, -1.0);
    let knee = hip + in_plane(a.roll, rot2(a.pitch, down) * d.thigh);
    let ankle = knee + in_plane(a.roll, rot2(a.shank_pitch(), down) * d.shank);
    let fp = a.foot_pitch();
    let foot = |v: DVec2| {
        let r = rot2(fp, v);
        ankle + DVec3::new(r.x, r.y, 0.0)
    };
    let heel = foot(d.heel_f());
    let mtp = foot(d.mtp_f());
    let on_toe = |v: DVec2| {
        let r = rot2(fp + a.meta, v);
        mtp + DVec3::new(r.x, r.y, 0.0)
    };
    let ball = on_toe(DVec2::new(0.0, -d.mtp_height));
    let toe = on_toe(DVec2::new(d.toe, -d.mtp_height));
    LegPoints {
        hip,
        knee,
        ankle,
        heel,
        ball,
        toe,
    }
}

/// Inverse kinematics of one leg: hip and ankle positions, foot pitch and toe angle given.
/// The knee bends forward in the plane through hip and ankle that contains the forward axis.
/// Returns the angles and whether the ankle was out of reach (then the leg is straight and
/// points at it).
#[inline]
pub fn leg_ik(
    d: &RunnerDims,
    hip: DVec3,
    ankle: DVec3,
    foot_pitch: f64,
    meta: f64,
) -> (LegAngles, bool) {
    let v = ankle - hip;
    let roll = (-v.z).atan2(-v.y);
    let down = -(v.y * v.y + v.z * v.z).sqrt();
    let p = DVec2::new(v.x, down);
    let reach = d.leg_reach();
    let lo = (d.thigh - d.shank).abs() + 1e-9;
    let dist_raw = p.length();
    let out = dist_raw > reach;
    let dist = dist_raw.clamp(lo, reach);
    let knee = d.knee_for_distance(dist);
    let cos_alpha = ((d.thigh * d.thigh + dist * dist - d.shank * d.shank)
        / (2.0 * d.thigh * dist))
        .clamp(-1.0, 1.0);
    let pitch = pitch_from_down(p) + cos_alpha.acos();
    let shank = pitch - knee;
    (
        LegAngles {
            pitch,
            roll,
            knee,
            ankle: foot_pitch - shank,
            meta,
        },
        out,
    )
}

/// Rotation about +z (sagittal pitch).
#[inline]
pub fn rz(a: f64) -> DQuat {
    DQuat::from_rotation_z(a)
}

/// World orientations of thigh, shank, foot and toes for the given angles.
#[inline]
pub fn leg_orientations(a: &LegAngles) -> [DQuat; 4] {
    let roll = DQuat::from_rotation_x(a.roll);
    let thigh = roll * rz(a.pitch);
    let shank = roll * rz(a.shank_pitch());
    let foot = rz(a.foot_pitch());
    let toe = rz(a.foot_pitch() + a.meta);
    [thigh, shank, foot, toe]
}

/// Pelvis orientation from rotation (yaw about +y) and list (roll about +x), §3.2 / Fig. 7.
#[inline]
pub fn pelvis_orientation(yaw: f64, roll: f64) -> DQuat {
    DQuat::from_rotation_y(yaw) * DQuat::from_rotation_x(roll)
}

/// `DMat3` for a pelvis orientation (cheaper to apply repeatedly).
#[inline]
pub fn pelvis_matrix(yaw: f64, roll: f64) -> DMat3 {
    DMat3::from_rotation_y(yaw) * DMat3::from_rotation_x(roll)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn b1_lengths_at_1_8_m() {
        let d = RunnerDims::from_height(1.8).unwrap();
        assert!((d.thigh - 0.426).abs() < 1e-3); // walking paper's own example: l3 = 0.426 m
                                                 // l8 + l5 + l6 of table B-1.
        assert!((d.foot_length() - (0.02959 + 0.0858 + 0.04734) * 1.8).abs() < 1e-12);
        // A flat foot has heel, ball and toe on the sole.
        let p = leg_fk(
            &d,
            DVec3::new(0.0, d.leg_reach() + d.ankle_height, 0.0),
            &LegAngles::default(),
        );
        assert!(p.heel.y.abs() < 1e-12 && p.ball.y.abs() < 1e-12 && p.toe.y.abs() < 1e-12);
    }

    #[test]
    fn ik_then_fk_reaches_the_ankle() {
        let d = RunnerDims::from_height(1.75).unwrap();
        let hip = DVec3::new(0.1, 0.9, 0.12);
        let ankle = DVec3::new(0.25, 0.08, 0.05);
        let (a, out) = leg_ik(&d, hip, ankle, 0.2, 0.1);
        assert!(!out);
        let p = leg_fk(&d, hip, &a);
        assert!(
            (p.ankle - ankle).length() < 1e-12,
            "{:?} vs {ankle:?}",
            p.ankle
        );
        assert!((a.foot_pitch() - 0.2).abs() < 1e-12);
        assert!(p.knee.x > hip.x.min(ankle.x), "knee bends forward");
    }
}
