//! A [`Motion`] as the page draws it: the landmarks of every frame (m, x forward, y up, z right,
//! rounded to 0.1 mm), the bones joining them, each foot's contact flag and the gait events.
use crate::events::Side;
use crate::generator::motion::Motion;
use crate::generator::skeleton::Landmark;
use serde::Serialize;

/// Landmark coordinates are sent rounded to this many metres (0.1 mm: far below a pixel, and
/// the response stays a third the size of full precision).
const ROUND_M: f64 = 1e-4;

/// The bones of the stick figure, as pairs of landmarks.
pub const BONES: [(Landmark, Landmark); 24] = [
    (Landmark::Pelvis, Landmark::LHip),
    (Landmark::Pelvis, Landmark::RHip),
    (Landmark::LHip, Landmark::LKnee),
    (Landmark::RHip, Landmark::RKnee),
    (Landmark::LKnee, Landmark::LAnkle),
    (Landmark::RKnee, Landmark::RAnkle),
    (Landmark::LAnkle, Landmark::LHeel),
    (Landmark::RAnkle, Landmark::RHeel),
    (Landmark::LHeel, Landmark::LBall),
    (Landmark::RHeel, Landmark::RBall),
    (Landmark::LAnkle, Landmark::LBall),
    (Landmark::RAnkle, Landmark::RBall),
    (Landmark::LBall, Landmark::LToe),
    (Landmark::RBall, Landmark::RToe),
    (Landmark::Pelvis, Landmark::Neck),
    (Landmark::Neck, Landmark::Vertex),
    (Landmark::Neck, Landmark::LShoulder),
    (Landmark::Neck, Landmark::RShoulder),
    (Landmark::LShoulder, Landmark::LElbow),
    (Landmark::RShoulder, Landmark::RElbow),
    (Landmark::LElbow, Landmark::LWrist),
    (Landmark::RElbow, Landmark::RWrist),
    (Landmark::LWrist, Landmark::LHand),
    (Landmark::RWrist, Landmark::RHand),
];

/// One gait event.
#[derive(Debug, Clone, Serialize, PartialEq)]
pub struct EventJson {
    /// Time, s.
    pub t: f64,
    /// `left` or `right`.
    pub side: &'static str,
    /// The event's name (`heel_strike`, `toe_off`, …).
    pub kind: String,
}

/// The figure's frames.
#[derive(Debug, Clone, Serialize, PartialEq)]
pub struct FigureJson {
    /// Frames per second of the frames sent.
    pub fps: f64,
    /// Number of frames.
    pub frames: usize,
    /// Landmark names, in the order of each frame's coordinates.
    pub landmarks: Vec<&'static str>,
    /// Bones as index pairs into `landmarks`.
    pub bones: Vec<[usize; 2]>,
    /// Which landmarks belong to the left side (drawn in the left colour).
    pub left: Vec<bool>,
    /// Coordinates, frame after frame, landmark after landmark, x y z (m).
    pub xyz: Vec<f64>,
    /// Contact flags, two per frame: left, right (1 = on the ground).
    pub contacts: Vec<u8>,
    /// Gait events.
    pub events: Vec<EventJson>,
}

fn round(x: f64) -> f64 {
    (x / ROUND_M).round() * ROUND_M
}

/// Frames per second sent to the page at most: a screen refreshes about this often, so more
/// frames would only lengthen the answer (the exports carry every frame of the motion).
pub const DISPLAY_FPS: f64 = 60.0;

/// The page's view of `motion`: every k-th frame, k the smallest whole number that brings the
/// rate to [`DISPLAY_FPS`] or below; events keep their exact times.
pub fn figure_json(motion: &Motion) -> FigureJson {
    let stride = ((motion.fps() / DISPLAY_FPS).ceil() as usize).max(1);
    let frames: Vec<usize> = (0..motion.len()).step_by(stride).collect();
    let n = frames.len();
    let all = motion.all_landmarks();
    let mut xyz = Vec::with_capacity(n * Landmark::ALL.len() * 3);
    let mut contacts = Vec::with_capacity(2 * n);
    for &i in &frames {
        for p in all[i].iter() {
            xyz.extend([round(p.x), round(p.y), round(p.z)]);
        }
        let c = motion.contacts()[i];
        contacts.extend([u8::from(c[0]), u8::from(c[1])]);
    }
    FigureJson {
        fps: motion.fps() / stride as f64,
        frames: n,
        landmarks: Landmark::ALL.iter().map(|l| l.name()).collect(),
        bones: BONES.iter().map(|(a, b)| [a.index(), b.index()]).collect(),
        left: Landmark::ALL
            .iter()
            .map(|l| l.name().starts_with("l_"))
            .collect(),
        xyz,
        contacts,
        events: motion
            .events
            .iter()
            .map(|e| EventJson {
                t: e.time_s,
                side: match e.side {
                    Side::Left => "left",
                    Side::Right => "right",
                },
                kind: e.kind.as_str().to_string(),
            })
            .collect(),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::generator::motion::MotionMetadata;
    use crate::generator::skeleton::Skeleton;

    #[test]
    fn frames_are_thinned_to_the_display_rate() {
        let sk = Skeleton::from_height(1.8, 75.0).unwrap();
        let mut m = Motion::new(sk.clone(), 120.0, MotionMetadata::default()).unwrap();
        for i in 0..241 {
            m.push_frame(sk.rest_pose(), [i % 2 == 0, true]);
        }
        let f = figure_json(&m);
        assert_eq!((f.frames, f.fps), (121, 60.0));
        assert_eq!(f.xyz.len(), 121 * Landmark::ALL.len() * 3);
        assert_eq!(&f.contacts[..4], &[1, 1, 1, 1]);
        let mut m = Motion::new(sk.clone(), 50.0, MotionMetadata::default()).unwrap();
        m.push_frame(sk.rest_pose(), [true, true]);
        assert_eq!(figure_json(&m).fps, 50.0);
    }
}
