//! Inverse kinematics helpers shared by the generators: the two-link (thigh–shank) leg, placing a
//! foot by one of its sole points, and setting a segment's world orientation.
//!
//! Conventions are those of [`super::skeleton`]: the knee is a hinge about the thigh's local z
//! axis with flexion negative, so the knee always points along the thigh frame's +x.
use super::skeleton::{FootPoint, Joint, Pose, Skeleton};
use crate::events::Side;
use glam::{DMat3, DQuat, DVec3};

/// Solution of a two-link chain (e.g. hip → knee → ankle).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct TwoLink {
    /// Position of the middle joint (knee), m.
    pub middle: DVec3,
    /// Position actually reached by the end (equals the target when `reached`), m.
    pub end: DVec3,
    /// False when the target was out of reach (too far or too close) and was clamped onto the
    /// reachable shell along the same direction.
    pub reached: bool,
    /// Flexion of the middle joint, rad, ≥ 0 (0 = straight chain).
    pub flexion: f64,
}

/// Places the middle joint of a chain `root → middle → end` with segment lengths `upper` and
/// `lower` so that the end reaches `target`, the chain bending toward `pole` (a direction: the
/// knee points to the side of the root–target line where `pole` points). Targets out of reach are
/// clamped to the nearest reachable distance along the root–target direction.
///
/// If `pole` is parallel to the root–target line, the world +x (then +z) is used instead.
pub fn two_link(root: DVec3, target: DVec3, upper: f64, lower: f64, pole: DVec3) -> TwoLink {
    let to = target - root;
    let d_raw = to.length();
    let e = if d_raw > 1e-12 {
        to / d_raw
    } else {
        DVec3::NEG_Y
    };
    let d_min = (upper - lower).abs() + 1e-9;
    let d_max = upper + lower;
    let d = d_raw.clamp(d_min, d_max);
    let reached = (d - d_raw).abs() <= 1e-9;
    let mut p = pole - e * pole.dot(e);
    if p.length_squared() < 1e-18 {
        p = DVec3::X - e * e.x;
        if p.length_squared() < 1e-18 {
            p = DVec3::Z - e * e.z;
        }
    }
    let p = p.normalize();
    // Law of cosines: angle at the root between the upper segment and the root–end line.
    let cos_a = ((upper * upper + d * d - lower * lower) / (2.0 * upper * d)).clamp(-1.0, 1.0);
    let sin_a = (1.0 - cos_a * cos_a).sqrt();
    let middle = root + upper * (cos_a * e + sin_a * p);
    TwoLink {
        middle,
        end: root + d * e,
        reached,
        flexion: flexion_for_span(upper, lower, d),
    }
}

/// Flexion of the middle joint, rad (0 = straight), of a two-link chain (`upper`, `lower`) whose
/// ends are `d` apart, by the law of cosines; `d` is clamped to the reachable range.
pub fn flexion_for_span(upper: f64, lower: f64, d: f64) -> f64 {
    let d = d.clamp((upper - lower).abs() + 1e-12, upper + lower);
    std::f64::consts::PI
        - ((upper * upper + lower * lower - d * d) / (2.0 * upper * lower))
            .clamp(-1.0, 1.0)
            .acos()
}

/// Distance between the ends of a two-link chain (`upper`, `lower`) with the middle joint flexed
/// by `flexion` rad: the inverse of [`flexion_for_span`].
pub fn span_for_flexion(upper: f64, lower: f64, flexion: f64) -> f64 {
    (upper * upper + lower * lower + 2.0 * upper * lower * flexion.cos())
        .max(0.0)
        .sqrt()
}

/// The planar two-link chain from `root` to `end` (sagittal `(x, y)`, y up) with the middle joint
/// bending forward (+x): `[θ, flexion]`, rad, the upper segment pointing along `(−sin θ, −cos θ)`
/// from the root (KLAW's thigh angle θ3) and the middle joint's flexion ([`flexion_for_span`]).
pub fn planar_two_link(root: [f64; 2], end: [f64; 2], upper: f64, lower: f64) -> [f64; 2] {
    let dx = root[0] - end[0];
    let dy = root[1] - end[1];
    let d = dx
        .hypot(dy)
        .clamp((upper - lower).abs() + 1e-12, upper + lower);
    let flexion = flexion_for_span(upper, lower, d);
    // Angle at the root between the root–end line and the upper segment.
    let cos_r = ((upper * upper + d * d - lower * lower) / (2.0 * upper * d)).clamp(-1.0, 1.0);
    [dx.atan2(dy) - cos_r.acos(), flexion]
}

/// The soft reach of a two-link chain ("soft IK", as in Mixamo's and Unity's rigs): the distance
/// at which the chain is drawn for a target `d` from its root, where `max` is the longest span
/// allowed and `soft` the width of the softening, m. Equal to `d` up to `max − 2·soft`, then a
/// C¹ quadratic blend that reaches `max − soft` at `max` and holds it beyond, so the middle joint
/// approaches straight at a vanishing rate instead of at `√(max − d)` (the straight-knee
/// singularity of a rigid two-link IK, where `dθ/dd` is unbounded).
pub fn soft_reach(d: f64, max: f64, soft: f64) -> f64 {
    let start = max - 2.0 * soft;
    if d <= start {
        d
    } else if d >= max {
        max - soft
    } else {
        d - (d - start).powi(2) / (4.0 * soft)
    }
}

/// Result of [`leg_ik`] and [`arm_ik`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct LimbIk {
    /// True when the end joint reached its target exactly.
    pub reached: bool,
    /// Distance between the target and the end joint actually reached, m.
    pub residual_m: f64,
    /// Flexion of the middle joint (knee or elbow), rad, ≥ 0. The knee's z angle is its
    /// negative, the elbow's z angle is equal to it.
    pub flexion: f64,
}

/// Former name of [`LimbIk`].
pub type LegIk = LimbIk;

/// Sets the hip (3 DOF) and knee (hinge) rotations of `side` in `pose` so that the ankle joint
/// centre is at `ankle_target` (world), with the knee pointing toward `knee_direction` (world; for
/// a forward-walking figure usually the pelvis's forward axis, turned to control hip rotation).
/// Uses the pose's current root and pelvis rotation; leaves the ankle's local rotation unchanged
/// (set the foot afterwards, e.g. with [`Pose::set_world_rotation`]). Out-of-reach targets are
/// clamped (straight leg toward the target) and reported with `reached = false`.
pub fn leg_ik(
    skeleton: &Skeleton,
    pose: &mut Pose,
    side: Side,
    ankle_target: DVec3,
    knee_direction: DVec3,
) -> LimbIk {
    let [hip, knee, _, _] = Joint::leg(side);
    let a = skeleton.anthropometry();
    let (l1, l2) = (a.thigh.length_m, a.shank.length_m);
    chain_ik(
        skeleton,
        pose,
        hip,
        knee,
        l1,
        l2,
        ankle_target,
        knee_direction,
        1.0,
    )
}

/// Sets the shoulder (3 DOF) and elbow (hinge) rotations of `side` so that the wrist joint centre
/// is at `wrist_target` (world), the elbow pointing toward `elbow_direction` (world; usually
/// backward and slightly outward). Uses the current rotations of the pelvis, spine and clavicle.
pub fn arm_ik(
    skeleton: &Skeleton,
    pose: &mut Pose,
    side: Side,
    wrist_target: DVec3,
    elbow_direction: DVec3,
) -> LimbIk {
    let [_, shoulder, elbow, _] = Joint::arm(side);
    let a = skeleton.anthropometry();
    let (l1, l2) = (a.upper_arm.length_m, a.forearm.length_m);
    chain_ik(
        skeleton,
        pose,
        shoulder,
        elbow,
        l1,
        l2,
        wrist_target,
        elbow_direction,
        -1.0,
    )
}

/// Two-link IK on `upper → middle → end`, both segments hanging along −y at rest and the middle
/// joint a hinge about z. `bend = 1` for a knee (bulges toward local +x, flexion negative z),
/// `−1` for an elbow (bulges toward local −x, flexion positive z).
#[allow(clippy::too_many_arguments)]
fn chain_ik(
    skeleton: &Skeleton,
    pose: &mut Pose,
    upper: Joint,
    middle: Joint,
    l1: f64,
    l2: f64,
    target: DVec3,
    pole: DVec3,
    bend: f64,
) -> LimbIk {
    let (parent_rot, root_pos) = match upper.parent() {
        Some(p) => {
            let (rot, pos) = skeleton.joint_world(pose, p);
            (rot, pos + rot * skeleton.offset(upper))
        }
        None => (DQuat::IDENTITY, pose.root),
    };
    let sol = two_link(root_pos, target, l1, l2, pole);
    // Segment frame in world: −y along the upper segment; the middle joint's bulge (away from
    // the root–end line, orthogonal to the segment) is local +x·bend.
    let y_axis = -(sol.middle - root_pos).normalize();
    let toward_end = (sol.end - root_pos).normalize();
    let bulge = sol.middle - (root_pos + toward_end * toward_end.dot(sol.middle - root_pos));
    let mut x_axis = bulge - y_axis * bulge.dot(y_axis);
    if x_axis.length_squared() < 1e-18 {
        // Straight limb: the bulge direction is the pole.
        x_axis = pole - y_axis * pole.dot(y_axis);
        if x_axis.length_squared() < 1e-18 {
            x_axis = parent_rot * DVec3::X;
            x_axis -= y_axis * x_axis.dot(y_axis);
        }
    }
    let x_axis = bend * x_axis.normalize();
    let z_axis = x_axis.cross(y_axis);
    let world = DQuat::from_mat3(&DMat3::from_cols(x_axis, y_axis, z_axis)).normalize();
    pose.rotations[upper.index()] = (parent_rot.inverse() * world).normalize();
    pose.rotations[middle.index()] = DQuat::from_rotation_z(-bend * sol.flexion);
    LimbIk {
        reached: sol.reached,
        residual_m: (target - sol.end).length(),
        flexion: sol.flexion,
    }
}

/// World position of the ankle joint centre that puts the foot sole point `pivot` at
/// `pivot_world` when the foot (ankle segment) has world orientation `foot_world` and the
/// metatarsal joint the local rotation `metatarsal` — e.g. the stance ankle while the foot rolls
/// about a fixed heel, ball or toe.
pub fn ankle_for_foot_point(
    skeleton: &Skeleton,
    side: Side,
    pivot: FootPoint,
    pivot_world: DVec3,
    foot_world: DQuat,
    metatarsal: DQuat,
) -> DVec3 {
    pivot_world - foot_world * skeleton.foot_point_offset(side, pivot, metatarsal)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::generator::skeleton::Landmark;

    #[test]
    fn two_link_reaches_and_respects_lengths() {
        let s = two_link(
            DVec3::ZERO,
            DVec3::new(0.2, -0.7, 0.05),
            0.45,
            0.43,
            DVec3::X,
        );
        assert!(s.reached);
        assert!(((s.middle).length() - 0.45).abs() < 1e-12);
        assert!(((s.end - s.middle).length() - 0.43).abs() < 1e-12);
        assert!(s.middle.x > 0.1); // bends toward +x
        let far = two_link(
            DVec3::ZERO,
            DVec3::new(0.0, -2.0, 0.0),
            0.45,
            0.43,
            DVec3::X,
        );
        assert!(!far.reached && far.flexion.abs() < 1e-6);
    }

    #[test]
    fn leg_ik_places_the_ankle_and_points_the_knee_forward() {
        let sk = Skeleton::from_height(1.8, 75.0).unwrap();
        let mut pose = sk.rest_pose();
        pose.set_euler(
            Joint::Pelvis,
            crate::generator::skeleton::Euler::new(0.05, 0.04, 0.2),
        );
        let target = DVec3::new(0.25, 0.2, 0.12);
        let r = leg_ik(&sk, &mut pose, Side::Right, target, DVec3::X);
        assert!(r.reached);
        let lm = sk.landmarks(&pose);
        assert!((lm[Landmark::RAnkle.index()] - target).length() < 1e-9);
        let knee = lm[Landmark::RKnee.index()];
        let hip = lm[Landmark::RHip.index()];
        let mid = 0.5 * (hip + target);
        assert!((knee - mid).x > 0.0);
        assert!(pose.euler(Joint::RKnee).z < 0.0);
    }

    #[test]
    fn arm_ik_places_the_wrist_and_flexes_the_elbow_positively() {
        let sk = Skeleton::from_height(1.7, 60.0).unwrap();
        let mut pose = sk.rest_pose();
        pose.set_euler(
            Joint::Lumbar,
            crate::generator::skeleton::Euler::new(-0.1, 0.05, 0.1),
        );
        let sh = sk.landmarks(&pose)[Landmark::LShoulder.index()];
        let target = sh + DVec3::new(0.2, -0.3, 0.05);
        let r = arm_ik(&sk, &mut pose, Side::Left, target, -DVec3::X);
        assert!(r.reached && r.flexion > 0.0);
        let lm = sk.landmarks(&pose);
        assert!((lm[Landmark::LWrist.index()] - target).length() < 1e-9);
        assert!(pose.euler(Joint::LElbow).z > 0.0);
        // The elbow points backward of the shoulder–wrist line.
        let mid = 0.5 * (sh + target);
        assert!((lm[Landmark::LElbow.index()] - mid).x < 0.0);
    }

    #[test]
    fn span_and_flexion_are_inverse_and_planar_matches_the_3d_chain() {
        let (u, l) = (0.43, 0.44);
        for k in [0.0, 0.1, 0.5, 1.2, 2.5] {
            let d = span_for_flexion(u, l, k);
            assert!((flexion_for_span(u, l, d) - k).abs() < 1e-6, "{k}");
        }
        // A hip above and behind the ankle: the planar chain's knee lies where the 3-D one's does.
        let (hip, ankle) = ([0.1, 0.85], [0.25, 0.05]);
        let [th, k] = planar_two_link(hip, ankle, u, l);
        let knee = [hip[0] - u * th.sin(), hip[1] - u * th.cos()];
        let shank = (knee[0] - ankle[0]).hypot(knee[1] - ankle[1]);
        assert!((shank - l).abs() < 1e-9, "{shank}");
        let t = two_link(
            DVec3::new(hip[0], hip[1], 0.0),
            DVec3::new(ankle[0], ankle[1], 0.0),
            u,
            l,
            DVec3::X,
        );
        assert!((t.flexion - k).abs() < 1e-9);
        assert!((t.middle.x - knee[0]).abs() < 1e-9 && (t.middle.y - knee[1]).abs() < 1e-9);
    }

    #[test]
    fn the_soft_reach_is_c1_and_bounds_the_knee_rate() {
        let (max, soft) = (0.87, 0.0015);
        let h = 1e-7;
        let slope =
            |d: f64| (soft_reach(d + h, max, soft) - soft_reach(d - h, max, soft)) / (2.0 * h);
        // C¹ at both joins, slope within [0, 1], monotone, saturating at max − soft.
        for d in [max - 2.0 * soft, max] {
            assert!(
                (slope(d - 2.0 * h) - slope(d + 2.0 * h)).abs() < 1e-3,
                "{d}"
            );
        }
        let mut last = 0.0;
        for i in 0..=400 {
            let d = max - 0.01 + 0.02 * i as f64 / 400.0;
            let r = soft_reach(d, max, soft);
            assert!(r >= last && r <= max - soft + 1e-15);
            assert!((-1e-9..=1.0 + 1e-9).contains(&slope(d)));
            last = r;
        }
        // The knee's rate per metre of target distance stays bounded through full extension, at
        // √(2L/(u·l)) / (2√soft) (near straight, L − span = u·l·k²/(2L); inside the blend
        // L − span = (2·soft − x)²/(4·soft) and its slope is (2·soft − x)/(2·soft), x = d − start,
        // so the rate is constant there); the rigid chain's grows without bound.
        let (u, l) = (0.43, 0.44);
        let rate = |f: &dyn Fn(f64) -> f64, d: f64| (f(d + h) - f(d - h)).abs() / (2.0 * h);
        let soft_k = |d: f64| flexion_for_span(u, l, soft_reach(d, u + l, soft));
        let rigid_k = |d: f64| flexion_for_span(u, l, d);
        let worst = (0..200)
            .map(|i| rate(&soft_k, u + l - 0.004 + 0.005 * i as f64 / 200.0))
            .fold(0.0, f64::max);
        let bound = (2.0 * (u + l) / (u * l)).sqrt() / (2.0 * soft.sqrt());
        assert!(worst < 1.01 * bound, "{worst} against {bound}");
        assert!(rate(&rigid_k, u + l - 1e-6) > 1000.0);
    }
}
