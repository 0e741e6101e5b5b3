//! Checks every generator's property tests run on a [`Motion`]: stance-foot sliding, ground
//! penetration, contact flags that touch the ground, swing-foot clearance, continuity, left/right
//! symmetry and flight/double-support timing.
//!
//! Each check returns a [`CheckReport`]: the worst value found, where (frame and landmark, joint
//! or side), the threshold it was compared with, and whether it passed. Values are SI (metres,
//! seconds, radians) unless the report's `unit` says otherwise.
use super::motion::Motion;
use super::skeleton::{
    mirror_quat, mirror_vec, side_index, Joint, Landmark, JOINT_COUNT, LANDMARK_COUNT,
};
use crate::events::Side;
use glam::{DQuat, DVec3};
use std::fmt;
use std::ops::Range;

/// The outcome of one check.
#[derive(Debug, Clone, PartialEq)]
pub struct CheckReport {
    /// Check name (`stance_sliding`, `ground_penetration`, …).
    pub check: &'static str,
    /// The worst value found (see `unit`); 0 or `NaN`-free neutral value when nothing applied.
    pub worst: f64,
    /// Unit of `worst` and `threshold`.
    pub unit: &'static str,
    /// Frame where the worst value occurred.
    pub frame: Option<usize>,
    /// Landmark, joint or side concerned.
    pub subject: Option<String>,
    /// The threshold `worst` was compared with.
    pub threshold: f64,
    /// Whether the check passed.
    pub passed: bool,
    /// How many items (frames, runs, steps) were examined; 0 means the check had nothing to
    /// look at (it then passes vacuously; callers that expect data should test `examined`).
    pub examined: usize,
}

impl fmt::Display for CheckReport {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{}: worst {:.6} {}", self.check, self.worst, self.unit)?;
        if let Some(fr) = self.frame {
            write!(f, " at frame {fr}")?;
        }
        if let Some(s) = &self.subject {
            write!(f, " ({s})")?;
        }
        write!(
            f,
            "; threshold {:.6} {}; {} over {} examined: {}",
            self.threshold,
            self.unit,
            if self.passed { "within" } else { "beyond" },
            self.examined,
            if self.passed { "pass" } else { "FAIL" }
        )
    }
}

/// Running maximum with its location.
struct Worst {
    value: f64,
    frame: Option<usize>,
    subject: Option<String>,
    examined: usize,
}

impl Worst {
    fn new(start: f64) -> Worst {
        Worst {
            value: start,
            frame: None,
            subject: None,
            examined: 0,
        }
    }
    fn max(&mut self, v: f64, frame: usize, subject: impl FnOnce() -> String) {
        if v > self.value || self.frame.is_none() && v >= self.value {
            self.value = v;
            self.frame = Some(frame);
            self.subject = Some(subject());
        }
    }
    fn min(&mut self, v: f64, frame: usize, subject: impl FnOnce() -> String) {
        if v < self.value || self.frame.is_none() && v <= self.value {
            self.value = v;
            self.frame = Some(frame);
            self.subject = Some(subject());
        }
    }
    fn report(
        self,
        check: &'static str,
        unit: &'static str,
        threshold: f64,
        passed: bool,
    ) -> CheckReport {
        CheckReport {
            check,
            worst: self.value,
            unit,
            frame: self.frame,
            subject: self.subject,
            threshold,
            passed,
            examined: self.examined,
        }
    }
}

/// Maximal runs of frames in which `side`'s contact flag is set.
pub fn contact_runs(motion: &Motion, side: Side) -> Vec<Range<usize>> {
    runs(motion.contacts().iter().map(|c| c[side_index(side)]))
}

/// Maximal runs of frames in which `side`'s contact flag is clear.
pub fn swing_runs(motion: &Motion, side: Side) -> Vec<Range<usize>> {
    runs(motion.contacts().iter().map(|c| !c[side_index(side)]))
}

fn runs(flags: impl Iterator<Item = bool>) -> Vec<Range<usize>> {
    let mut out = Vec::new();
    let mut start = None;
    let mut n = 0;
    for (i, f) in flags.enumerate() {
        n = i + 1;
        match (f, start) {
            (true, None) => start = Some(i),
            (false, Some(s)) => {
                out.push(s..i);
                start = None;
            }
            _ => {}
        }
    }
    if let Some(s) = start {
        out.push(s..n);
    }
    out
}

/// Stance-foot sliding: while a foot's contact flag is set, every sole point (heel, ball, toe)
/// that is on the ground (height ≤ `on_ground_m`) must stay where it touched down. For each sole
/// point and each maximal run of frames in which it is on the ground with the flag set, the drift
/// is the largest horizontal (x–z) distance from its position in the run's first frame; `worst` is
/// the largest drift, m. Passes when `worst ≤ threshold_m` (generators' target: 0.002 m).
/// `on_ground_m` of 1–3 mm suits generated motion.
pub fn stance_sliding(motion: &Motion, on_ground_m: f64, threshold_m: f64) -> CheckReport {
    let mut w = Worst::new(0.0);
    for side in [Side::Left, Side::Right] {
        for l in Landmark::foot(side) {
            let mut anchor: Option<DVec3> = None;
            for i in 0..motion.len() {
                let p = motion.landmark(i, l);
                if motion.contact(i, side) && p.y <= on_ground_m {
                    w.examined += 1;
                    let a = *anchor.get_or_insert(p);
                    let d = DVec3::new(p.x - a.x, 0.0, p.z - a.z).length();
                    w.max(d, i, || l.name().to_string());
                } else {
                    anchor = None;
                }
            }
        }
    }
    let passed = w.value <= threshold_m;
    w.report("stance_sliding", "m", threshold_m, passed)
}

/// Ground penetration: the lowest height of any sole point (heel, ball, toe of both feet) over all
/// frames. `worst` is the depth below the ground, m (positive = below y = 0; negative = the
/// feet never reach the ground). Passes when `worst ≤ threshold_m` (generators: 0.001 m).
pub fn ground_penetration(motion: &Motion, threshold_m: f64) -> CheckReport {
    let mut w = Worst::new(f64::NEG_INFINITY);
    for i in 0..motion.len() {
        for side in [Side::Left, Side::Right] {
            for l in Landmark::foot(side) {
                w.examined += 1;
                w.max(-motion.landmark(i, l).y, i, || l.name().to_string());
            }
        }
    }
    if w.examined == 0 {
        w.value = 0.0;
    }
    let passed = w.value <= threshold_m;
    w.report("ground_penetration", "m", threshold_m, passed)
}

/// Contact flags that touch the ground: in every frame where a foot's contact flag is set, its
/// lowest sole point must be within `threshold_m` of the ground (|y| ≤ threshold). `worst` is the
/// largest |height| of the lowest sole point of a foot flagged in contact, m.
pub fn contact_on_ground(motion: &Motion, threshold_m: f64) -> CheckReport {
    let mut w = Worst::new(0.0);
    for side in [Side::Left, Side::Right] {
        for i in 0..motion.len() {
            if !motion.contact(i, side) {
                continue;
            }
            w.examined += 1;
            let (l, y) = Landmark::foot(side)
                .into_iter()
                .map(|l| (l, motion.landmark(i, l).y))
                .fold((Landmark::foot(side)[0], f64::INFINITY), |a, b| {
                    if b.1 < a.1 {
                        b
                    } else {
                        a
                    }
                });
            w.max(y.abs(), i, || format!("{side} foot ({})", l.name()));
        }
    }
    let passed = w.value <= threshold_m;
    w.report("contact_on_ground", "m", threshold_m, passed)
}

/// Swing-foot clearance: for every complete swing (a run of frames with the foot's contact flag
/// clear, preceded and followed by contact), the lowest sole-point height over the central
/// `central_fraction` of the swing (e.g. 0.5: from 25 % to 75 % of it, where the foot must be off
/// the ground; at toe off and heel strike clearance is zero by definition). `worst` is the
/// smallest such clearance over all swings, m; passes when `worst ≥ threshold_m`.
pub fn swing_clearance(motion: &Motion, central_fraction: f64, threshold_m: f64) -> CheckReport {
    let mut w = Worst::new(f64::INFINITY);
    let frac = central_fraction.clamp(0.0, 1.0);
    for side in [Side::Left, Side::Right] {
        for r in swing_runs(motion, side) {
            if r.start == 0 || r.end >= motion.len() {
                continue; // not a complete swing
            }
            let n = r.len() as f64;
            let a = r.start + ((0.5 - frac / 2.0) * n).floor() as usize;
            let b = (r.start + ((0.5 + frac / 2.0) * n).ceil() as usize).min(r.end);
            for i in a..b.max(a + 1) {
                w.examined += 1;
                for l in Landmark::foot(side) {
                    w.min(motion.landmark(i, l).y, i, || l.name().to_string());
                }
            }
        }
    }
    if w.examined == 0 {
        w.value = 0.0;
        return w.report("swing_clearance", "m", threshold_m, true);
    }
    let passed = w.value >= threshold_m;
    w.report("swing_clearance", "m", threshold_m, passed)
}

/// Options of [`continuity`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ContinuityOptions {
    /// A step is a jump when larger than `k` × the local median step.
    pub k: f64,
    /// Neighbouring steps on each side used for the local median.
    pub window: usize,
    /// Smallest local step for landmarks, m: below it the median is replaced by this floor, so a
    /// figure at rest does not turn numerical noise into jumps.
    pub floor_m: f64,
    /// Smallest local step for joint rotations, rad.
    pub floor_rad: f64,
}

impl Default for ContinuityOptions {
    fn default() -> Self {
        ContinuityOptions {
            k: 5.0,
            window: 3,
            floor_m: 1e-4,
            floor_rad: 1e-3,
        }
    }
}

/// Continuity: for every landmark (step = distance moved between frames) and every joint (step =
/// angle of the relative rotation between frames, so Euler wrapping cannot fake a jump), each
/// frame-to-frame step is compared with the median of the `window` steps on either side (at least
/// the floor). `worst` is the largest ratio step / local median (dimensionless); the frame is the
/// first frame of the step. Passes when `worst ≤ options.k`.
pub fn continuity(motion: &Motion, options: &ContinuityOptions) -> CheckReport {
    continuity_over(motion, options, 0..motion.len())
}

/// [`continuity`] restricted to the steps that begin at the frames `frames` (e.g. the first step
/// of a walk, or its stop); the local medians still use the whole motion, so a step at the
/// range's edge is judged exactly as in [`continuity`].
pub fn continuity_over(
    motion: &Motion,
    options: &ContinuityOptions,
    frames: Range<usize>,
) -> CheckReport {
    let n = motion.len();
    let mut w = Worst::new(0.0);
    if n < 3 {
        return w.report("continuity", "ratio", options.k, true);
    }
    let mut steps = vec![0.0; n - 1];
    let scan = |steps: &[f64], floor: f64, name: &str, w: &mut Worst| {
        let ratios = step_ratios(steps, options.window, floor);
        for (i, r) in ratios
            .iter()
            .enumerate()
            .take(frames.end)
            .skip(frames.start)
        {
            if let Some(r) = *r {
                w.examined += 1;
                w.max(r, i, || name.to_string());
            }
        }
    };
    for l in 0..LANDMARK_COUNT {
        let lms = motion.all_landmarks();
        for (s, pair) in steps.iter_mut().zip(lms.windows(2)) {
            *s = (pair[1][l] - pair[0][l]).length();
        }
        scan(&steps, options.floor_m, Landmark::ALL[l].name(), &mut w);
    }
    for j in 0..JOINT_COUNT {
        let poses = motion.poses();
        for (s, pair) in steps.iter_mut().zip(poses.windows(2)) {
            *s = rotation_angle(pair[0].rotations[j], pair[1].rotations[j]);
        }
        scan(&steps, options.floor_rad, Joint::ALL[j].name(), &mut w);
    }
    let passed = w.value <= options.k;
    w.report("continuity", "ratio", options.k, passed)
}

/// The measure behind [`continuity`] for one channel's frame-to-frame `steps`: each step's
/// ratio to the median of the `window` steps on either side of it (the median at least
/// `floor`). `None` for a step without neighbours (a motion of two frames), which
/// [`continuity`] does not examine. For a check restricted to chosen channels (e.g. the swing
/// leg's ankle and knee) build their steps with [`Landmark`] distances or [`rotation_angle`].
pub fn step_ratios(steps: &[f64], window: usize, floor: f64) -> Vec<Option<f64>> {
    let mut scratch = Vec::with_capacity(2 * window);
    (0..steps.len())
        .map(|i| {
            scratch.clear();
            let lo = i.saturating_sub(window);
            let hi = (i + window + 1).min(steps.len());
            scratch.extend(steps[lo..i].iter().chain(steps[i + 1..hi].iter()));
            if scratch.is_empty() {
                return None;
            }
            scratch.sort_by(f64::total_cmp);
            let m = scratch.len();
            let median = if m % 2 == 1 {
                scratch[m / 2]
            } else {
                0.5 * (scratch[m / 2 - 1] + scratch[m / 2])
            };
            Some(steps[i] / median.max(floor))
        })
        .collect()
}

/// Angle of the rotation taking `a` to `b`, rad, in [0, π]: a joint's frame-to-frame step in
/// [`continuity`].
pub fn rotation_angle(a: DQuat, b: DQuat) -> f64 {
    // atan2 form: accurate for tiny angles, where acos(w) loses half the digits.
    let r = a.conjugate() * b;
    2.0 * r.xyz().length().atan2(r.w.abs())
}

/// Result of [`symmetry`]: landmarks and joint rotations compared separately.
#[derive(Debug, Clone, PartialEq)]
pub struct SymmetryReport {
    /// Landmarks relative to the pelvis: largest distance between the mirrored left-side (and
    /// midline) position at t and the right-side position at t + step, m.
    pub landmarks: CheckReport,
    /// Joint rotations: largest angle between the mirrored rotation at t and the opposite joint's
    /// rotation at t + step, rad.
    pub joints: CheckReport,
}

/// Left/right symmetry at constant parameters: one step later the figure should be the mirror
/// image (across its sagittal plane) of itself. For every frame `i` in `frames` with
/// `t_i + step_s` still inside the motion, compares
/// - each landmark `l` relative to the pelvis, mirrored (z → −z), with landmark `mirror(l)`
///   relative to the pelvis at `t_i + step_s` (linear interpolation between frames);
/// - each joint's rotation, mirrored, with the opposite joint's rotation at `t_i + step_s`
///   (spherical interpolation); the pelvis's world rotation is mirrored too, so a straight walk
///   along +x is assumed.
///
/// Passes when the landmark error ≤ `threshold_m` and the rotation error ≤ `threshold_rad`.
pub fn symmetry(
    motion: &Motion,
    frames: Range<usize>,
    step_s: f64,
    threshold_m: f64,
    threshold_rad: f64,
) -> SymmetryReport {
    let mut wl = Worst::new(0.0);
    let mut wj = Worst::new(0.0);
    let n = motion.len();
    let shift = step_s * motion.fps();
    for i in frames.start..frames.end.min(n) {
        let t = i as f64 + shift;
        if !(t >= 0.0 && t <= (n - 1) as f64) {
            continue;
        }
        let k = (t.floor() as usize).min(n.saturating_sub(2));
        let u = t - k as f64;
        let lm_at = |l: usize| motion.landmarks(k)[l].lerp(motion.landmarks(k + 1)[l], u);
        let pelvis_i = motion.landmark(i, Landmark::Pelvis);
        let pelvis_t = lm_at(Landmark::Pelvis.index());
        for l in Landmark::ALL {
            if l == Landmark::Pelvis {
                continue;
            }
            let a = mirror_vec(motion.landmark(i, l) - pelvis_i);
            let b = lm_at(l.mirrored().index()) - pelvis_t;
            wl.examined += 1;
            wl.max((a - b).length(), i, || {
                format!("{} vs {}", l.name(), l.mirrored().name())
            });
        }
        for j in Joint::ALL {
            let a = mirror_quat(motion.pose(i).rotations[j.index()]);
            let qa = motion.pose(k).rotations[j.mirrored().index()];
            let qb = motion.pose(k + 1).rotations[j.mirrored().index()];
            let b = qa.slerp(qb, u);
            wj.examined += 1;
            wj.max(rotation_angle(a, b), i, || {
                format!("{} vs {}", j.name(), j.mirrored().name())
            });
        }
    }
    let pl = wl.value <= threshold_m;
    let pj = wj.value <= threshold_rad;
    SymmetryReport {
        landmarks: wl.report("symmetry_landmarks", "m", threshold_m, pl),
        joints: wj.report("symmetry_joints", "rad", threshold_rad, pj),
    }
}

/// Timing of one step, from one foot's touchdown to the other foot's, read from the contact
/// flags (resolution: one frame).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct StepTiming {
    /// Frame of the touchdown that starts the step.
    pub start_frame: usize,
    /// Frame of the next touchdown (of the other foot) that ends it.
    pub end_frame: usize,
    /// The foot that touched down at the start.
    pub side: Side,
    /// Step duration, s.
    pub duration_s: f64,
    /// Time with neither foot in contact, s (frames with both flags clear / fps).
    pub flight_s: f64,
    /// Time with both feet in contact, s.
    pub double_support_s: f64,
}

/// The steps of a motion: every interval between a touchdown (contact flag rising) of one foot and
/// the next touchdown of the other foot.
pub fn step_timings(motion: &Motion) -> Vec<StepTiming> {
    let c = motion.contacts();
    let mut touchdowns: Vec<(usize, Side)> = Vec::new();
    for i in 1..c.len() {
        for side in [Side::Left, Side::Right] {
            let k = side_index(side);
            if c[i][k] && !c[i - 1][k] {
                touchdowns.push((i, side));
            }
        }
    }
    touchdowns.sort_by_key(|t| t.0);
    let dt = 1.0 / motion.fps();
    let mut out = Vec::new();
    for pair in touchdowns.windows(2) {
        let ((a, side), (b, next)) = (pair[0], pair[1]);
        if next == side {
            continue; // a foot touched down twice in a row: not a step
        }
        let (mut flight, mut ds) = (0usize, 0usize);
        for f in &c[a..b] {
            match (f[0], f[1]) {
                (false, false) => flight += 1,
                (true, true) => ds += 1,
                _ => {}
            }
        }
        out.push(StepTiming {
            start_frame: a,
            end_frame: b,
            side,
            duration_s: (b - a) as f64 * dt,
            flight_s: flight as f64 * dt,
            double_support_s: ds as f64 * dt,
        });
    }
    out
}

/// Flight time of every step against `expected_s`: `worst` is the largest |flight − expected|, s;
/// passes when ≤ `tolerance_s` (RUNNER: one frame, 1/fps).
pub fn flight_timing(motion: &Motion, expected_s: f64, tolerance_s: f64) -> CheckReport {
    timing(
        motion,
        "flight_timing",
        |s| s.flight_s,
        expected_s,
        tolerance_s,
    )
}

/// Double-support time of every step against `expected_s`: `worst` is the largest
/// |double support − expected|, s; passes when ≤ `tolerance_s`.
pub fn double_support_timing(motion: &Motion, expected_s: f64, tolerance_s: f64) -> CheckReport {
    timing(
        motion,
        "double_support_timing",
        |s| s.double_support_s,
        expected_s,
        tolerance_s,
    )
}

fn timing(
    motion: &Motion,
    name: &'static str,
    value: impl Fn(&StepTiming) -> f64,
    expected_s: f64,
    tolerance_s: f64,
) -> CheckReport {
    let mut w = Worst::new(0.0);
    for s in step_timings(motion) {
        w.examined += 1;
        w.max((value(&s) - expected_s).abs(), s.start_frame, || {
            format!("step starting with {} touchdown", s.side)
        });
    }
    let passed = w.value <= tolerance_s;
    w.report(name, "s", tolerance_s, passed)
}
