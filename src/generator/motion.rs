//! The [`Motion`] type shared by every generator: a skeleton, a frame rate, and per frame the
//! pose (root translation + joint rotations), the landmark positions computed from it by forward
//! kinematics, and the contact flag of each foot; plus gait events and metadata.
//!
//! Generators build a motion with [`Motion::new`] and [`Motion::push_frame`] (forward kinematics
//! runs there, allocation-free apart from the vectors' growth — reserve with
//! [`Motion::reserve`]). Frame `i` is at time `i / fps` seconds.
use super::skeleton::{
    side_index, Euler, GlobalPose, Landmark, Landmarks, Pose, Skeleton, JOINT_COUNT, LANDMARK_COUNT,
};
use super::GenerateError;
use crate::events::{Gait, GaitEvent, Side};
use crate::ingest::types::{Axis, LabFrame, MarkerSet, Setting, SubjectInfo, Trial};
use glam::DVec3;

/// Who made a motion and with what settings.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct MotionMetadata {
    /// Generator name (`"runner"`, `"klaw"`, `"ko-badler"`, …).
    pub generator: String,
    /// Walking or running.
    pub gait: Option<Gait>,
    /// Parameters and attributes as key/value pairs, in the order given, values with their unit
    /// in the key (`speed_m_per_s`, `step_length_m`, `level`).
    pub parameters: Vec<(String, String)>,
    /// Free-form notes (fits used, recoveries applied, …).
    pub notes: Vec<String>,
}

impl MotionMetadata {
    /// Units of every quantity a [`Motion`] holds.
    pub const UNITS: &'static str =
        "lengths m; time s; rotations unit quaternions (Euler angles rad, \
         degrees in exports); frame x forward, y up, z right";

    /// Metadata for `generator`.
    pub fn new(generator: impl Into<String>, gait: Option<Gait>) -> MotionMetadata {
        MotionMetadata {
            generator: generator.into(),
            gait,
            parameters: Vec::new(),
            notes: Vec::new(),
        }
    }

    /// Adds a parameter (`key` should carry its unit, e.g. `speed_m_per_s`).
    pub fn push(&mut self, key: impl Into<String>, value: impl ToString) {
        self.parameters.push((key.into(), value.to_string()));
    }
}

/// A generated motion.
#[derive(Debug, Clone, PartialEq)]
pub struct Motion {
    skeleton: Skeleton,
    fps: f64,
    poses: Vec<Pose>,
    landmarks: Vec<Landmarks>,
    contacts: Vec<[bool; 2]>,
    /// Gait events (source [`crate::events::EventSource::Generated`]), in time order.
    pub events: Vec<GaitEvent>,
    /// Generator and parameters.
    pub metadata: MotionMetadata,
}

impl Motion {
    /// An empty motion of `skeleton` sampled at `fps` frames per second.
    pub fn new(
        skeleton: Skeleton,
        fps: f64,
        metadata: MotionMetadata,
    ) -> Result<Motion, GenerateError> {
        if !(fps.is_finite() && fps > 0.0 && fps <= 100_000.0) {
            return Err(GenerateError::Parameter {
                name: "fps".into(),
                value: fps,
                message: "frames per second must be within (0, 100000]".into(),
            });
        }
        Ok(Motion {
            skeleton,
            fps,
            poses: Vec::new(),
            landmarks: Vec::new(),
            contacts: Vec::new(),
            events: Vec::new(),
            metadata,
        })
    }

    /// Reserves room for `frames` more frames.
    pub fn reserve(&mut self, frames: usize) {
        self.poses.reserve(frames);
        self.landmarks.reserve(frames);
        self.contacts.reserve(frames);
    }

    /// Appends a frame: the pose, and whether each foot (`[left, right]`) is in contact with the
    /// ground. Computes its landmarks by forward kinematics.
    #[inline]
    pub fn push_frame(&mut self, pose: Pose, contact: [bool; 2]) {
        let mut g = GlobalPose::default();
        self.skeleton.forward_into(&pose, &mut g);
        let mut lm = [DVec3::ZERO; LANDMARK_COUNT];
        self.skeleton.landmarks_into(&g, &mut lm);
        self.poses.push(pose);
        self.landmarks.push(lm);
        self.contacts.push(contact);
    }

    /// Recomputes every frame's landmarks from its pose (after editing poses through
    /// [`Motion::poses_mut`]).
    pub fn compute_landmarks(&mut self) {
        let mut g = GlobalPose::default();
        for (pose, lm) in self.poses.iter().zip(self.landmarks.iter_mut()) {
            self.skeleton.forward_into(pose, &mut g);
            self.skeleton.landmarks_into(&g, lm);
        }
    }

    /// The skeleton.
    pub fn skeleton(&self) -> &Skeleton {
        &self.skeleton
    }
    /// Frames per second.
    pub fn fps(&self) -> f64 {
        self.fps
    }
    /// Time between frames, s.
    pub fn frame_interval_s(&self) -> f64 {
        1.0 / self.fps
    }
    /// Number of frames.
    pub fn len(&self) -> usize {
        self.poses.len()
    }
    /// True when there are no frames.
    pub fn is_empty(&self) -> bool {
        self.poses.is_empty()
    }
    /// Time of frame `i`, s (`i / fps`).
    pub fn frame_time(&self, i: usize) -> f64 {
        i as f64 / self.fps
    }
    /// Time from the first to the last frame, s (`(len − 1) / fps`; 0 for fewer than 2 frames).
    pub fn duration_s(&self) -> f64 {
        self.len().saturating_sub(1) as f64 / self.fps
    }
    /// The poses, one per frame.
    pub fn poses(&self) -> &[Pose] {
        &self.poses
    }
    /// Mutable poses; call [`Motion::compute_landmarks`] afterwards.
    pub fn poses_mut(&mut self) -> &mut [Pose] {
        &mut self.poses
    }
    /// The pose of frame `i`.
    pub fn pose(&self, i: usize) -> &Pose {
        &self.poses[i]
    }
    /// All landmarks of frame `i`, indexed by [`Landmark`].
    pub fn landmarks(&self, i: usize) -> &Landmarks {
        &self.landmarks[i]
    }
    /// Every frame's landmarks.
    pub fn all_landmarks(&self) -> &[Landmarks] {
        &self.landmarks
    }
    /// One landmark in frame `i`, m.
    pub fn landmark(&self, i: usize, l: Landmark) -> DVec3 {
        self.landmarks[i][l.index()]
    }
    /// One landmark's trajectory, m.
    pub fn landmark_series(&self, l: Landmark) -> Vec<DVec3> {
        self.landmarks.iter().map(|f| f[l.index()]).collect()
    }
    /// Whether `side`'s foot is on the ground in frame `i`.
    pub fn contact(&self, i: usize, side: Side) -> bool {
        self.contacts[i][side_index(side)]
    }
    /// Contact flags of every frame, `[left, right]`.
    pub fn contacts(&self) -> &[[bool; 2]] {
        &self.contacts
    }
    /// Mutable contact flags.
    pub fn contacts_mut(&mut self) -> &mut [[bool; 2]] {
        &mut self.contacts
    }

    /// Euler angles (Z–X–Y convention of [`super::skeleton`]) of every joint in frame `i`,
    /// degrees, `[z, x, y]` per joint, indexed by [`super::skeleton::Joint`]; the pelvis's are its world
    /// orientation. Each angle is in (−180°, 180°]; see [`Motion::joint_angle_series_deg`] for
    /// curves unwrapped across frames.
    pub fn joint_angles_deg(&self, i: usize) -> [[f64; 3]; JOINT_COUNT] {
        let mut out = [[0.0; 3]; JOINT_COUNT];
        for (o, q) in out.iter_mut().zip(self.poses[i].rotations.iter()) {
            *o = Euler::from_quat(*q).to_degrees();
        }
        out
    }

    /// Joint angles of every frame, degrees, each angle unwrapped across frames (a multiple of
    /// 360° added so that successive frames never differ by more than 180°), so curves stay
    /// continuous; the rotations they represent are unchanged.
    pub fn joint_angle_series_deg(&self) -> Vec<[[f64; 3]; JOINT_COUNT]> {
        let mut out: Vec<[[f64; 3]; JOINT_COUNT]> = Vec::with_capacity(self.len());
        for i in 0..self.len() {
            let mut a = self.joint_angles_deg(i);
            if let Some(prev) = out.last() {
                for (row, prow) in a.iter_mut().zip(prev.iter()) {
                    for (v, p) in row.iter_mut().zip(prow.iter()) {
                        *v += 360.0 * ((p - *v) / 360.0).round();
                    }
                }
            }
            out.push(a);
        }
        out
    }

    /// The landmarks as a marker set (names = landmark names, metres, the motion's frame:
    /// x forward, y up, z right), so gaitfit's event detection can run on generated motion.
    pub fn to_marker_set(&self) -> MarkerSet {
        MarkerSet {
            rate_hz: self.fps,
            time_s: (0..self.len()).map(|i| self.frame_time(i)).collect(),
            names: Landmark::ALL.iter().map(|l| l.name().to_string()).collect(),
            positions: Landmark::ALL
                .iter()
                .map(|l| {
                    self.landmarks
                        .iter()
                        .map(|f| f[l.index()].to_array())
                        .collect()
                })
                .collect(),
        }
    }

    /// A [`Trial`] of this motion: overground, lab frame vertical Y and forward +X, the landmarks
    /// as markers, the generated events as reference events, subject height, mass and leg length
    /// (hip joint centre height at rest) from the anthropometry.
    pub fn to_trial(&self, name: impl Into<String>) -> Trial {
        let a = self.skeleton.anthropometry();
        let mut t = Trial::new(format!("generated by {}", self.metadata.generator), name);
        t.subject = SubjectInfo {
            id: Some(format!("{}-figure", self.metadata.generator)),
            body_height_m: Some(a.height_m),
            leg_length_m: Some(a.hip_height_m()),
            mass_kg: Some(a.mass_kg),
            notes: vec!["leg length = hip joint centre height of the figure standing".into()],
        };
        t.gait = self.metadata.gait;
        t.setting = Setting::Overground;
        t.frame = Some(LabFrame {
            vertical: Axis::Y,
            forward: Axis::X,
            forward_sign: 1.0,
            how: "generated motion: x forward, y up, z right".into(),
        });
        t.markers = Some(self.to_marker_set());
        t.reference_events = self.events.clone();
        t.notes = self.metadata.notes.clone();
        t
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::generator::skeleton::Joint;

    #[test]
    fn times_and_angles() {
        let sk = Skeleton::from_height(1.8, 75.0).unwrap();
        let mut m = Motion::new(sk.clone(), 100.0, MotionMetadata::new("test", None)).unwrap();
        for i in 0..5 {
            let mut p = sk.rest_pose();
            p.set_euler(Joint::RKnee, Euler::sagittal(-(i as f64) * 0.1));
            m.push_frame(p, [true, i < 3]);
        }
        assert_eq!(m.len(), 5);
        assert!((m.duration_s() - 0.04).abs() < 1e-12);
        assert!((m.frame_time(2) - 0.02).abs() < 1e-12);
        assert!(
            (m.joint_angles_deg(3)[Joint::RKnee.index()][0] + 0.3f64.to_degrees()).abs() < 1e-9
        );
        assert!(!m.contact(4, Side::Right) && m.contact(4, Side::Left));
        assert!(Motion::new(sk, 0.0, MotionMetadata::default()).is_err());
    }

    #[test]
    fn unwrapping_keeps_curves_continuous() {
        let sk = Skeleton::from_height(1.8, 75.0).unwrap();
        let mut m = Motion::new(sk.clone(), 100.0, MotionMetadata::default()).unwrap();
        for i in 0..40 {
            let mut p = sk.rest_pose();
            p.set_euler(Joint::Pelvis, Euler::new(0.0, 0.0, 2.5 + 0.05 * i as f64));
            m.push_frame(p, [true, true]);
        }
        let s = m.joint_angle_series_deg();
        for w in s.windows(2) {
            assert!((w[1][0][2] - w[0][0][2]).abs() < 5.0);
        }
        assert!(s[39][0][2] > 180.0);
    }
}
