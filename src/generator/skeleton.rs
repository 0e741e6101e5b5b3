//! The figure: a fixed joint hierarchy whose dimensions come from [`Anthropometry`], its poses,
//! and forward kinematics.
//!
//! # Conventions (shared by every generator — read once, use everywhere)
//!
//! **World frame.** x forward (direction of progression), y up, z to the walker's right;
//! right-handed; metres. The ground is y = 0. Left-side joints lie at −z, right-side at +z.
//!
//! **Rest pose.** All joint rotations identity: the figure stands upright facing +x, arms hanging
//! straight down at the sides, legs vertical and parallel, feet flat and pointing +x with the heel,
//! ball and toe sole points exactly on y = 0 when `Pose::root` is
//! `(x, anthropometry.hip_height_m(), z)` (see [`Skeleton::rest_pose`]). Every joint's local frame
//! is parallel to the world frame in the rest pose, so a local rotation is expressed about the
//! same x/y/z axes as the world, as seen by the parent segment.
//!
//! **Rotations.** `Pose::rotations[j]` is joint `j`'s rotation relative to its parent
//! (for the root `pelvis`, relative to the world). Forward kinematics:
//! `R_world(j) = R_world(parent) · R_local(j)`,
//! `p_world(j) = p_world(parent) + R_world(parent) · offset(j)`.
//!
//! **Euler angles** ([`Euler`]): intrinsic **Z, then X, then Y**: `R = Rz(z) · Rx(x) · Ry(y)`,
//! each a right-hand rotation in radians about the named axis. This is the order of the BVH
//! channels `Zrotation Xrotation Yrotation`. z is the sagittal (flexion/extension) axis, x the
//! frontal (ab/adduction, list) axis, y the long axis of the limbs and spine (axial rotation).
//!
//! **Signs.** Right-hand rule, the same for both sides: `Rz` turns +x toward +y, `Rx` turns +y
//! toward +z, `Ry` turns +z toward +x. Seen from the walker's right side, with the walker moving
//! to the right of the picture (the usual sagittal drawing), a positive z angle is
//! counter-clockwise. What that means at each joint (right side / left side where they differ):
//!
//! | joint | +z | +x | +y |
//! |---|---|---|---|
//! | `pelvis` (root, world) | posterior tilt (front up) | right side down, left up | turn to the left (front toward −z) |
//! | `lumbar`, `thoracic_*`, `neck`, `head` | extension (lean back); flexion negative | bend to the right (top toward +z) | turn to the left |
//! | `r_hip` / `l_hip` | **flexion** (thigh forward) | adduction / abduction | internal / external rotation |
//! | `r_knee`, `l_knee` (hinge) | extension: **knee flexion is negative** | keep 0 | keep 0 |
//! | `r_ankle` / `l_ankle` | **dorsiflexion** (toes up) | inversion / eversion | toe-in / toe-out |
//! | `r_metatarsal`, `l_metatarsal` | toe extension (toes up relative to the foot) | keep 0 | keep 0 |
//! | `r_clavicle` / `l_clavicle` | spin about the clavicle | depression / elevation | protraction / retraction |
//! | `r_shoulder` / `l_shoulder` | **flexion** (arm forward) | adduction / abduction | internal / external rotation |
//! | `r_elbow`, `l_elbow` | **flexion** (forearm forward) | keep 0 | forearm rotation |
//! | `r_wrist`, `l_wrist` | hand forward | hand toward −z | rotation |
//!
//! So a sagittal-plane generator sets hip flexion `+`, knee flexion `−`, ankle dorsiflexion `+`,
//! toe extension `+`, shoulder flexion `+`, elbow flexion `+`, trunk forward lean `−` (all about
//! z), identically on both sides.
//!
//! The raw right-hand convention is used for **both** sides, without mirroring: a mirror-image
//! pose of the left side has the same z angle and opposite x and y angles ([`Euler::mirrored`]).
//!
//! **Landmarks** ([`Landmark`]): points fixed to a segment, including joint centres and the foot's
//! sole points `heel` (under and behind the ankle), `ball` (on the sole under the metatarsal joint,
//! carried by the toe segment, so it stays fixed while the foot rolls about the metatarsal joint
//! with the toes flat) and `toe` (toe tip, end of the toe segment); `vertex` is the top of the
//! head.
//!
//! **One vocabulary.** A name means one point in every file gaitfit writes: a landmark that is a
//! joint centre has the joint's name (`l_knee` is the BVH joint, the CSV columns `l_knee_*_m` and
//! the TRC marker), and points that differ have different names (`head` is the C1 joint, `vertex`
//! the top of the head 0.13 × height above it; `l_metatarsal` is the joint centre, `l_ball` the
//! sole point under it). The table of every name, its point and the formats that carry it is in
//! the README ("Names of points and joints"); `tests/figure_vocabulary.rs` checks it against
//! [`Joint::ALL`] and [`Landmark::ALL`].
use super::anthropometry::Anthropometry;
use super::GenerateError;
use crate::events::Side;
use glam::{DMat3, DQuat, DVec3};
use std::ops::{Index, IndexMut};

/// Number of joints of the figure.
pub const JOINT_COUNT: usize = 22;
/// Number of named landmarks.
pub const LANDMARK_COUNT: usize = 23;

/// A joint of the figure. The discriminants are indices into [`Pose::rotations`] and
/// [`GlobalPose`]; the order is the depth-first order of the BVH hierarchy, parents first.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord)]
#[repr(usize)]
pub enum Joint {
    /// Root: the midpoint of the hip joint centres; 6 DOF (translation = `Pose::root`).
    Pelvis = 0,
    /// L5/S1.
    Lumbar,
    /// T12/L1.
    ThoracicLower,
    /// T7: RUNNER's counter-rotation turns here (below: `lumbar`, `thoracic_lower`).
    ThoracicUpper,
    /// C7/T1, at shoulder height.
    Neck,
    /// C1 (head on neck), at chin height.
    Head,
    /// Left sternoclavicular joint.
    LClavicle,
    /// Left shoulder (glenohumeral).
    LShoulder,
    /// Left elbow.
    LElbow,
    /// Left wrist.
    LWrist,
    /// Right sternoclavicular joint.
    RClavicle,
    /// Right shoulder.
    RShoulder,
    /// Right elbow.
    RElbow,
    /// Right wrist.
    RWrist,
    /// Left hip (3 DOF).
    LHip,
    /// Left knee (hinge about z).
    LKnee,
    /// Left ankle.
    LAnkle,
    /// Left first metatarsal (ball) joint; the toe segment hangs from it.
    LMetatarsal,
    /// Right hip (3 DOF).
    RHip,
    /// Right knee.
    RKnee,
    /// Right ankle.
    RAnkle,
    /// Right metatarsal joint.
    RMetatarsal,
}

/// Parent index of each joint (`usize::MAX` for the root).
const PARENT: [usize; JOINT_COUNT] = [
    usize::MAX,
    0,
    1,
    2,
    3,
    4,
    3,
    6,
    7,
    8,
    3,
    10,
    11,
    12,
    0,
    14,
    15,
    16,
    0,
    18,
    19,
    20,
];

/// The side a paired joint's or landmark's name gives by its `l_` / `r_` prefix (`None` for
/// a midline name).
fn side_of_name(name: &str) -> Option<Side> {
    if name.starts_with("l_") {
        Some(Side::Left)
    } else if name.starts_with("r_") {
        Some(Side::Right)
    } else {
        None
    }
}

/// The other side's name of a paired joint's or landmark's name (`l_` ↔ `r_`; `None` for a
/// midline name).
fn mirrored_name(name: &str) -> Option<String> {
    if let Some(rest) = name.strip_prefix("l_") {
        Some(format!("r_{rest}"))
    } else {
        name.strip_prefix("r_").map(|rest| format!("l_{rest}"))
    }
}

impl Joint {
    /// Every joint in index (depth-first) order.
    pub const ALL: [Joint; JOINT_COUNT] = [
        Joint::Pelvis,
        Joint::Lumbar,
        Joint::ThoracicLower,
        Joint::ThoracicUpper,
        Joint::Neck,
        Joint::Head,
        Joint::LClavicle,
        Joint::LShoulder,
        Joint::LElbow,
        Joint::LWrist,
        Joint::RClavicle,
        Joint::RShoulder,
        Joint::RElbow,
        Joint::RWrist,
        Joint::LHip,
        Joint::LKnee,
        Joint::LAnkle,
        Joint::LMetatarsal,
        Joint::RHip,
        Joint::RKnee,
        Joint::RAnkle,
        Joint::RMetatarsal,
    ];

    /// Index into pose arrays.
    pub const fn index(self) -> usize {
        self as usize
    }

    /// Snake-case name used in BVH, CSV column names and metadata (`l_knee`).
    pub const fn name(self) -> &'static str {
        match self {
            Joint::Pelvis => "pelvis",
            Joint::Lumbar => "lumbar",
            Joint::ThoracicLower => "thoracic_lower",
            Joint::ThoracicUpper => "thoracic_upper",
            Joint::Neck => "neck",
            Joint::Head => "head",
            Joint::LClavicle => "l_clavicle",
            Joint::LShoulder => "l_shoulder",
            Joint::LElbow => "l_elbow",
            Joint::LWrist => "l_wrist",
            Joint::RClavicle => "r_clavicle",
            Joint::RShoulder => "r_shoulder",
            Joint::RElbow => "r_elbow",
            Joint::RWrist => "r_wrist",
            Joint::LHip => "l_hip",
            Joint::LKnee => "l_knee",
            Joint::LAnkle => "l_ankle",
            Joint::LMetatarsal => "l_metatarsal",
            Joint::RHip => "r_hip",
            Joint::RKnee => "r_knee",
            Joint::RAnkle => "r_ankle",
            Joint::RMetatarsal => "r_metatarsal",
        }
    }

    /// The joint named `name` (as in [`Joint::name`]).
    pub fn from_name(name: &str) -> Option<Joint> {
        Joint::ALL.into_iter().find(|j| j.name() == name)
    }

    /// The parent joint (`None` for the root).
    pub fn parent(self) -> Option<Joint> {
        let p = PARENT[self.index()];
        (p != usize::MAX).then(|| Joint::ALL[p])
    }

    /// The side of a paired joint.
    pub fn side(self) -> Option<Side> {
        side_of_name(self.name())
    }

    /// The same joint on the other side (itself for midline joints).
    pub fn mirrored(self) -> Joint {
        mirrored_name(self.name())
            .and_then(|other| Joint::from_name(&other))
            .unwrap_or(self)
    }

    /// Hip, knee, ankle and metatarsal joints of one side.
    pub const fn leg(side: Side) -> [Joint; 4] {
        match side {
            Side::Left => [Joint::LHip, Joint::LKnee, Joint::LAnkle, Joint::LMetatarsal],
            Side::Right => [Joint::RHip, Joint::RKnee, Joint::RAnkle, Joint::RMetatarsal],
        }
    }

    /// Clavicle, shoulder, elbow and wrist joints of one side.
    pub const fn arm(side: Side) -> [Joint; 4] {
        match side {
            Side::Left => [
                Joint::LClavicle,
                Joint::LShoulder,
                Joint::LElbow,
                Joint::LWrist,
            ],
            Side::Right => [
                Joint::RClavicle,
                Joint::RShoulder,
                Joint::RElbow,
                Joint::RWrist,
            ],
        }
    }
}

/// A named point of the figure whose position is computed by forward kinematics.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord)]
#[repr(usize)]
pub enum Landmark {
    /// Midpoint of the hip joint centres (the root joint).
    Pelvis = 0,
    /// Left hip joint centre.
    LHip,
    /// Right hip joint centre.
    RHip,
    /// Left knee joint centre.
    LKnee,
    /// Right knee joint centre.
    RKnee,
    /// Left ankle joint centre.
    LAnkle,
    /// Right ankle joint centre.
    RAnkle,
    /// Left heel sole point.
    LHeel,
    /// Right heel sole point.
    RHeel,
    /// Left ball: the sole point under the metatarsal joint (on the toe segment).
    LBall,
    /// Right ball.
    RBall,
    /// Left toe tip.
    LToe,
    /// Right toe tip.
    RToe,
    /// Vertex: the top of the head (the end site of the `head` joint, which is C1).
    Vertex,
    /// C7/T1 joint centre.
    Neck,
    /// Left shoulder joint centre.
    LShoulder,
    /// Right shoulder joint centre.
    RShoulder,
    /// Left elbow joint centre.
    LElbow,
    /// Right elbow joint centre.
    RElbow,
    /// Left wrist joint centre.
    LWrist,
    /// Right wrist joint centre.
    RWrist,
    /// Left hand end (knuckle II).
    LHand,
    /// Right hand end.
    RHand,
}

impl Landmark {
    /// Every landmark in index order.
    pub const ALL: [Landmark; LANDMARK_COUNT] = [
        Landmark::Pelvis,
        Landmark::LHip,
        Landmark::RHip,
        Landmark::LKnee,
        Landmark::RKnee,
        Landmark::LAnkle,
        Landmark::RAnkle,
        Landmark::LHeel,
        Landmark::RHeel,
        Landmark::LBall,
        Landmark::RBall,
        Landmark::LToe,
        Landmark::RToe,
        Landmark::Vertex,
        Landmark::Neck,
        Landmark::LShoulder,
        Landmark::RShoulder,
        Landmark::LElbow,
        Landmark::RElbow,
        Landmark::LWrist,
        Landmark::RWrist,
        Landmark::LHand,
        Landmark::RHand,
    ];

    /// Index into landmark arrays.
    pub const fn index(self) -> usize {
        self as usize
    }

    /// Snake-case name used as CSV column prefix and marker name (`l_heel`).
    pub const fn name(self) -> &'static str {
        match self {
            Landmark::Pelvis => "pelvis",
            Landmark::LHip => "l_hip",
            Landmark::RHip => "r_hip",
            Landmark::LKnee => "l_knee",
            Landmark::RKnee => "r_knee",
            Landmark::LAnkle => "l_ankle",
            Landmark::RAnkle => "r_ankle",
            Landmark::LHeel => "l_heel",
            Landmark::RHeel => "r_heel",
            Landmark::LBall => "l_ball",
            Landmark::RBall => "r_ball",
            Landmark::LToe => "l_toe",
            Landmark::RToe => "r_toe",
            Landmark::Vertex => "vertex",
            Landmark::Neck => "neck",
            Landmark::LShoulder => "l_shoulder",
            Landmark::RShoulder => "r_shoulder",
            Landmark::LElbow => "l_elbow",
            Landmark::RElbow => "r_elbow",
            Landmark::LWrist => "l_wrist",
            Landmark::RWrist => "r_wrist",
            Landmark::LHand => "l_hand",
            Landmark::RHand => "r_hand",
        }
    }

    /// The landmark named `name`.
    pub fn from_name(name: &str) -> Option<Landmark> {
        Landmark::ALL.into_iter().find(|l| l.name() == name)
    }

    /// The side of a paired landmark.
    pub fn side(self) -> Option<Side> {
        side_of_name(self.name())
    }

    /// The same landmark on the other side (itself for midline landmarks).
    pub fn mirrored(self) -> Landmark {
        mirrored_name(self.name())
            .and_then(|other| Landmark::from_name(&other))
            .unwrap_or(self)
    }

    /// Heel, ball and toe of one side: the foot's sole points.
    pub const fn foot(side: Side) -> [Landmark; 3] {
        match side {
            Side::Left => [Landmark::LHeel, Landmark::LBall, Landmark::LToe],
            Side::Right => [Landmark::RHeel, Landmark::RBall, Landmark::RToe],
        }
    }

    /// A sole point of one side.
    pub const fn foot_point(side: Side, point: FootPoint) -> Landmark {
        Landmark::foot(side)[point as usize]
    }
}

/// One of the three sole points of a foot.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
#[repr(usize)]
pub enum FootPoint {
    /// Heel.
    Heel = 0,
    /// Ball (sole under the metatarsal joint).
    Ball = 1,
    /// Toe tip.
    Toe = 2,
}

/// Index of a side in per-foot arrays (`[left, right]`).
pub const fn side_index(side: Side) -> usize {
    match side {
        Side::Left => 0,
        Side::Right => 1,
    }
}

/// Landmark positions of one frame, indexed by [`Landmark`].
pub type Landmarks = [DVec3; LANDMARK_COUNT];

/// Intrinsic Z–X–Y Euler angles in radians: `R = Rz(z)·Rx(x)·Ry(y)` (see the module docs for the
/// meaning and signs of each axis at each joint).
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct Euler {
    /// Sagittal angle about z (flexion/extension), rad.
    pub z: f64,
    /// Frontal angle about x (ab/adduction, list), rad.
    pub x: f64,
    /// Axial angle about y, rad.
    pub y: f64,
}

impl Euler {
    /// Angles in radians.
    pub const fn new(z: f64, x: f64, y: f64) -> Euler {
        Euler { z, x, y }
    }

    /// A pure sagittal rotation (about z), rad.
    pub const fn sagittal(z: f64) -> Euler {
        Euler { z, x: 0.0, y: 0.0 }
    }

    /// Angles given in degrees.
    pub fn from_degrees(z: f64, x: f64, y: f64) -> Euler {
        Euler::new(z.to_radians(), x.to_radians(), y.to_radians())
    }

    /// `[z, x, y]` in degrees.
    pub fn to_degrees(self) -> [f64; 3] {
        [
            self.z.to_degrees(),
            self.x.to_degrees(),
            self.y.to_degrees(),
        ]
    }

    /// The rotation `Rz(z)·Rx(x)·Ry(y)`.
    pub fn to_quat(self) -> DQuat {
        DQuat::from_rotation_z(self.z)
            * DQuat::from_rotation_x(self.x)
            * DQuat::from_rotation_y(self.y)
    }

    /// Decomposes a rotation into Z–X–Y angles: x ∈ [−π/2, π/2], z and y ∈ (−π, π]. At
    /// x = ±π/2 (gimbal lock) the split between z and y is arbitrary but the rotation is
    /// reproduced.
    pub fn from_quat(q: DQuat) -> Euler {
        let m = DMat3::from_quat(q.normalize());
        // m = Rz·Rx·Ry: m[1][2] (row 2, col 1) = sin x; row 0 col 1 = −sz·cx; row 1 col 1 = cz·cx;
        // row 2 col 0 = −cx·sy; row 2 col 2 = cx·cy. glam matrices are column-major: m.col(c)[r].
        let r21 = m.y_axis.z;
        let r01 = m.y_axis.x;
        let r11 = m.y_axis.y;
        let r20 = m.x_axis.z;
        let r22 = m.z_axis.z;
        let x = r21.atan2((r20 * r20 + r22 * r22).sqrt());
        if (r20 * r20 + r22 * r22) > 1e-24 {
            Euler {
                z: (-r01).atan2(r11),
                x,
                y: (-r20).atan2(r22),
            }
        } else {
            // Gimbal lock: put everything into z. With cx = 0, m = Rz(z ± y) · Rx(±π/2).
            let r00 = m.x_axis.x;
            let r10 = m.x_axis.y;
            Euler {
                z: r10.atan2(r00),
                x,
                y: 0.0,
            }
        }
    }

    /// The mirror image across the sagittal (x–y) plane: same z, opposite x and y. Use it to
    /// turn a right-side pose into the left-side one (and back).
    pub fn mirrored(self) -> Euler {
        Euler {
            z: self.z,
            x: -self.x,
            y: -self.y,
        }
    }
}

/// Mirror image of a rotation across the sagittal plane (z → −z): `(w, x, y, z) → (w, −x, −y, z)`.
pub fn mirror_quat(q: DQuat) -> DQuat {
    DQuat::from_xyzw(-q.x, -q.y, q.z, q.w)
}

/// Mirror image of a point or vector across the sagittal plane (z → −z).
pub fn mirror_vec(v: DVec3) -> DVec3 {
    DVec3::new(v.x, v.y, -v.z)
}

/// A pose: root translation and every joint's local rotation. `Copy`, no heap.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Pose {
    /// World position of the root joint (`pelvis`: midpoint of the hip joint centres), m.
    pub root: DVec3,
    /// Local rotation of each joint relative to its parent, indexed by [`Joint`]; the pelvis's
    /// is its world orientation.
    pub rotations: [DQuat; JOINT_COUNT],
}

impl Pose {
    /// All rotations identity, root at `root`.
    pub fn identity_at(root: DVec3) -> Pose {
        Pose {
            root,
            rotations: [DQuat::IDENTITY; JOINT_COUNT],
        }
    }

    /// Sets a joint's local rotation from Euler angles.
    pub fn set_euler(&mut self, joint: Joint, angles: Euler) {
        self.rotations[joint.index()] = angles.to_quat();
    }

    /// A joint's local rotation as Euler angles.
    pub fn euler(&self, joint: Joint) -> Euler {
        Euler::from_quat(self.rotations[joint.index()])
    }

    /// The world orientation of `joint`'s segment (product of the rotations from the root).
    pub fn world_rotation(&self, joint: Joint) -> DQuat {
        let mut q = self.rotations[joint.index()];
        let mut p = PARENT[joint.index()];
        while p != usize::MAX {
            q = self.rotations[p] * q;
            p = PARENT[p];
        }
        q
    }

    /// Sets `joint`'s local rotation so that its segment's world orientation is `world`
    /// (given the current rotations of its ancestors).
    pub fn set_world_rotation(&mut self, joint: Joint, world: DQuat) {
        let parent_world = match joint.parent() {
            Some(p) => self.world_rotation(p),
            None => DQuat::IDENTITY,
        };
        self.rotations[joint.index()] = (parent_world.inverse() * world).normalize();
    }

    /// The mirror image of this pose across the sagittal plane through the world origin: left
    /// and right joints swapped, rotations mirrored, root z negated.
    pub fn mirrored(&self) -> Pose {
        let mut out = *self;
        out.root = mirror_vec(self.root);
        for j in Joint::ALL {
            out.rotations[j.mirrored().index()] = mirror_quat(self.rotations[j.index()]);
        }
        out
    }
}

impl Index<Joint> for Pose {
    type Output = DQuat;
    fn index(&self, j: Joint) -> &DQuat {
        &self.rotations[j.index()]
    }
}

impl IndexMut<Joint> for Pose {
    fn index_mut(&mut self, j: Joint) -> &mut DQuat {
        &mut self.rotations[j.index()]
    }
}

/// World orientation and position of every joint, the output of [`Skeleton::forward`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct GlobalPose {
    /// World orientation of each joint's segment.
    pub rotations: [DQuat; JOINT_COUNT],
    /// World position of each joint centre, m.
    pub positions: [DVec3; JOINT_COUNT],
}

impl GlobalPose {
    /// World position of a joint centre.
    pub fn position(&self, j: Joint) -> DVec3 {
        self.positions[j.index()]
    }
    /// World orientation of a joint's segment.
    pub fn rotation(&self, j: Joint) -> DQuat {
        self.rotations[j.index()]
    }
}

impl Default for GlobalPose {
    fn default() -> Self {
        GlobalPose {
            rotations: [DQuat::IDENTITY; JOINT_COUNT],
            positions: [DVec3::ZERO; JOINT_COUNT],
        }
    }
}

/// The figure: the fixed hierarchy of [`Joint`]s with offsets computed from an [`Anthropometry`].
#[derive(Debug, Clone, PartialEq)]
pub struct Skeleton {
    anthropometry: Anthropometry,
    offsets: [DVec3; JOINT_COUNT],
    end_sites: [Option<DVec3>; JOINT_COUNT],
    landmark_attach: [(Joint, DVec3); LANDMARK_COUNT],
}

impl Skeleton {
    /// The skeleton of a validated anthropometry.
    pub fn new(anthropometry: Anthropometry) -> Result<Skeleton, GenerateError> {
        anthropometry.validate()?;
        let a = &anthropometry;
        let f = &a.foot;
        let mut offsets = [DVec3::ZERO; JOINT_COUNT];
        let y = |v: f64| DVec3::new(0.0, v, 0.0);
        offsets[Joint::Lumbar.index()] = y(a.pelvis_to_lumbar_m);
        offsets[Joint::ThoracicLower.index()] = y(a.lumbar_to_thoracic_lower_m);
        offsets[Joint::ThoracicUpper.index()] = y(a.thoracic_lower_to_upper_m);
        offsets[Joint::Neck.index()] = y(a.thoracic_upper_to_neck_m);
        offsets[Joint::Head.index()] = y(a.neck_to_head_m);
        let mut end_sites = [None; JOINT_COUNT];
        end_sites[Joint::Head.index()] = Some(y(a.head_to_vertex_m));
        let mut landmark_attach = [(Joint::Pelvis, DVec3::ZERO); LANDMARK_COUNT];
        for side in [Side::Left, Side::Right] {
            // Left is −z.
            let s = match side {
                Side::Left => -1.0,
                Side::Right => 1.0,
            };
            let [clav, shoulder, elbow, wrist] = Joint::arm(side);
            offsets[clav.index()] = DVec3::new(
                0.0,
                a.thoracic_upper_to_neck_m,
                s * 0.5 * a.clavicle_base_width_m,
            );
            offsets[shoulder.index()] = DVec3::new(
                0.0,
                0.0,
                s * 0.5 * (a.shoulder_width_m - a.clavicle_base_width_m),
            );
            offsets[elbow.index()] = y(-a.upper_arm.length_m);
            offsets[wrist.index()] = y(-a.forearm.length_m);
            end_sites[wrist.index()] = Some(y(-a.hand.length_m));
            let [hip, knee, ankle, mtp] = Joint::leg(side);
            offsets[hip.index()] = DVec3::new(0.0, 0.0, s * 0.5 * a.hip_width_m);
            offsets[knee.index()] = y(-a.thigh.length_m);
            offsets[ankle.index()] = y(-a.shank.length_m);
            offsets[mtp.index()] =
                DVec3::new(f.mid_foot_m, f.metatarsal_height_m - f.ankle_height_m, 0.0);
            let toe = DVec3::new(f.toe_m, -f.metatarsal_height_m, 0.0);
            end_sites[mtp.index()] = Some(toe);
            let lm = |l: Landmark, j: Joint, o: DVec3| (l, (j, o));
            let pick = |l: Landmark, r: Landmark| if s < 0.0 { l } else { r };
            for (l, att) in [
                lm(pick(Landmark::LHip, Landmark::RHip), hip, DVec3::ZERO),
                lm(pick(Landmark::LKnee, Landmark::RKnee), knee, DVec3::ZERO),
                lm(pick(Landmark::LAnkle, Landmark::RAnkle), ankle, DVec3::ZERO),
                lm(
                    pick(Landmark::LHeel, Landmark::RHeel),
                    ankle,
                    DVec3::new(-f.hind_foot_m, -f.ankle_height_m, 0.0),
                ),
                lm(
                    pick(Landmark::LBall, Landmark::RBall),
                    mtp,
                    DVec3::new(0.0, -f.metatarsal_height_m, 0.0),
                ),
                lm(pick(Landmark::LToe, Landmark::RToe), mtp, toe),
                lm(
                    pick(Landmark::LShoulder, Landmark::RShoulder),
                    shoulder,
                    DVec3::ZERO,
                ),
                lm(pick(Landmark::LElbow, Landmark::RElbow), elbow, DVec3::ZERO),
                lm(pick(Landmark::LWrist, Landmark::RWrist), wrist, DVec3::ZERO),
                lm(
                    pick(Landmark::LHand, Landmark::RHand),
                    wrist,
                    y(-a.hand.length_m),
                ),
            ] {
                landmark_attach[l.index()] = att;
            }
        }
        landmark_attach[Landmark::Pelvis.index()] = (Joint::Pelvis, DVec3::ZERO);
        landmark_attach[Landmark::Vertex.index()] = (Joint::Head, y(a.head_to_vertex_m));
        landmark_attach[Landmark::Neck.index()] = (Joint::Neck, DVec3::ZERO);
        Ok(Skeleton {
            anthropometry,
            offsets,
            end_sites,
            landmark_attach,
        })
    }

    /// The skeleton of a figure of body height `height_m` and mass `mass_kg` with the table
    /// proportions ([`Anthropometry::from_height`]).
    pub fn from_height(height_m: f64, mass_kg: f64) -> Result<Skeleton, GenerateError> {
        Skeleton::new(Anthropometry::from_height(height_m, mass_kg)?)
    }

    /// The anthropometry the skeleton was built from.
    pub fn anthropometry(&self) -> &Anthropometry {
        &self.anthropometry
    }

    /// Offset of `joint` from its parent in the parent's frame (rest pose), m.
    pub fn offset(&self, joint: Joint) -> DVec3 {
        self.offsets[joint.index()]
    }

    /// End site of a terminal joint (head → vertex, wrist → hand end, metatarsal → toe tip) in
    /// the joint's frame, m; `None` for joints with children.
    pub fn end_site(&self, joint: Joint) -> Option<DVec3> {
        self.end_sites[joint.index()]
    }

    /// The joint a landmark is attached to and its offset in that joint's frame, m.
    pub fn landmark_attachment(&self, landmark: Landmark) -> (Joint, DVec3) {
        self.landmark_attach[landmark.index()]
    }

    /// Offset of a foot sole point from the ankle, in the ankle (foot) frame, for a given local
    /// rotation of the metatarsal joint (ball and toe ride on the toe segment), m.
    pub fn foot_point_offset(&self, side: Side, point: FootPoint, metatarsal: DQuat) -> DVec3 {
        let (j, o) = self.landmark_attachment(Landmark::foot_point(side, point));
        if j == Joint::leg(side)[3] {
            self.offset(j) + metatarsal * o
        } else {
            o
        }
    }

    /// Height of the hip joint centres above the ground in the rest pose, m.
    pub fn hip_height(&self) -> f64 {
        self.anthropometry.hip_height_m()
    }

    /// The rest pose standing on the ground at the origin (root at `(0, hip_height, 0)`).
    pub fn rest_pose(&self) -> Pose {
        Pose::identity_at(DVec3::new(0.0, self.hip_height(), 0.0))
    }

    /// World orientation and position of one joint, walking its chain from the root (cheaper
    /// than a full [`Skeleton::forward`] when only one joint is needed).
    pub fn joint_world(&self, pose: &Pose, joint: Joint) -> (DQuat, DVec3) {
        let mut chain = [0usize; 8];
        let mut n = 0;
        let mut j = joint.index();
        while j != 0 {
            chain[n] = j;
            n += 1;
            j = PARENT[j];
        }
        let mut rot = pose.rotations[0];
        let mut pos = pose.root;
        for &k in chain[..n].iter().rev() {
            pos += rot * self.offsets[k];
            rot *= pose.rotations[k];
        }
        (rot, pos)
    }

    /// Forward kinematics into `out` (no allocation).
    #[inline]
    pub fn forward_into(&self, pose: &Pose, out: &mut GlobalPose) {
        out.rotations[0] = pose.rotations[0];
        out.positions[0] = pose.root;
        // Index loop on purpose: three arrays are read and written with the same index.
        #[allow(clippy::needless_range_loop)]
        for j in 1..JOINT_COUNT {
            let p = PARENT[j];
            let pr = out.rotations[p];
            out.positions[j] = out.positions[p] + pr * self.offsets[j];
            out.rotations[j] = pr * pose.rotations[j];
        }
    }

    /// Forward kinematics: world orientation and position of every joint.
    #[inline]
    pub fn forward(&self, pose: &Pose) -> GlobalPose {
        let mut g = GlobalPose::default();
        self.forward_into(pose, &mut g);
        g
    }

    /// Landmark positions from a computed [`GlobalPose`] (no allocation).
    #[inline]
    pub fn landmarks_into(&self, global: &GlobalPose, out: &mut Landmarks) {
        for (o, &(j, off)) in out.iter_mut().zip(self.landmark_attach.iter()) {
            let j = j.index();
            // Most landmarks are joint centres: skip their (zero) rotation.
            *o = if off == DVec3::ZERO {
                global.positions[j]
            } else {
                global.positions[j] + global.rotations[j] * off
            };
        }
    }

    /// Landmark positions of a pose.
    #[inline]
    pub fn landmarks(&self, pose: &Pose) -> Landmarks {
        let g = self.forward(pose);
        let mut out = [DVec3::ZERO; LANDMARK_COUNT];
        self.landmarks_into(&g, &mut out);
        out
    }

    /// World position of the end site of a terminal joint, if it has one.
    pub fn end_site_position(&self, global: &GlobalPose, joint: Joint) -> Option<DVec3> {
        self.end_site(joint)
            .map(|o| global.position(joint) + global.rotation(joint) * o)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::f64::consts::FRAC_PI_2;

    #[test]
    fn euler_round_trip_and_order() {
        let e = Euler::new(0.3, -0.4, 1.1);
        let q = e.to_quat();
        let expected = DMat3::from_rotation_z(0.3)
            * DMat3::from_rotation_x(-0.4)
            * DMat3::from_rotation_y(1.1);
        assert!((DMat3::from_quat(q) - expected)
            .abs()
            .to_cols_array()
            .iter()
            .all(|v| *v < 1e-12));
        let back = Euler::from_quat(q);
        assert!(
            (back.z - 0.3).abs() < 1e-12
                && (back.x + 0.4).abs() < 1e-12
                && (back.y - 1.1).abs() < 1e-12
        );
        let lock = Euler::new(0.2, FRAC_PI_2, 0.5).to_quat();
        let back = Euler::from_quat(lock).to_quat();
        assert!(back.dot(lock).abs() > 1.0 - 1e-12);
    }

    #[test]
    fn joint_order_is_depth_first_with_parents_first() {
        for (i, j) in Joint::ALL.iter().enumerate() {
            assert_eq!(j.index(), i);
            if let Some(p) = j.parent() {
                assert!(p.index() < i);
            }
            assert_eq!(j.mirrored().mirrored(), *j);
        }
        for (i, l) in Landmark::ALL.iter().enumerate() {
            assert_eq!(l.index(), i);
            assert_eq!(Landmark::from_name(l.name()), Some(*l));
        }
    }
}
