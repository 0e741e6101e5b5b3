//! Heel strike and toe off from marker kinematics: the coordinate method of Zeni, Richards &
//! Higginson (2008), *Two simple methods for determining gait events during treadmill and
//! overground walking using kinematic data*, Gait & Posture 27:710–714, and its velocity
//! variant.
//!
//! - Coordinate method: along the direction of progression, the heel position relative to the
//!   pelvis reaches its maximum at heel strike and the toe position relative to the pelvis its
//!   minimum at toe off. Extrema are confirmed with a hysteresis of a fraction of the signal's
//!   range (default 30 %, at least 5 cm) and refined to sub-frame time by a parabola through the
//!   three samples around the extremum.
//! - Velocity variant: the velocity of the foot centre (mean of heel and toe markers) relative to
//!   the pelvis, along the direction of progression, changes sign from positive to negative at
//!   heel strike and from negative to positive at toe off (linear interpolation of the zero
//!   crossing). Each crossing is paired with the nearest confirmed extremum of the foot-centre
//!   position so that jitter around zero during stance does not create events.
//!
//! Both work on a treadmill and overground (the pelvis reference removes the forward travel),
//! for walking and running. Markers are low-pass filtered first (default order-2 Butterworth,
//! 6 Hz, zero-phase).
//!
//! In walking the coordinate method's heel strike is early by 30–40 ms against force plates
//! (the heel leads the pelvis most while it still moves forward over the ground), so
//! [`Kinematics::foot_speed`] refines it: a two-stage detector after Bonci et al. (2022), *An
//! algorithm for accurate marker-based gait event detection in healthy and pathological
//! populations during complex motor tasks*, Front. Bioeng. Biotechnol. 10:868928 (their
//! rearfoot rules, Zeni pre-detection then 3-D marker speed): within a window around each Zeni
//! event, heel strike is when the heel's 3-D speed over the ground falls below 0.5 × the
//! walking speed, toe off when the toe marker's rises above 0.8 × the walking speed.
use super::filter::{filtfilt_gappy, Butterworth};
use super::markers::{trajectory, LegMarkers, MarkerMap};
use super::{path_of, EventError, EventKind, EventSource, GaitEvent, Side};
use crate::ingest::types::{MarkerSet, Setting, Trial};
use serde::{Deserialize, Serialize};

mod walk;
pub use walk::WalkHeelStrike;

/// Kinematic detection settings.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct KinematicOptions {
    /// Marker low-pass cutoff, Hz (default 6).
    pub cutoff_hz: f64,
    /// Butterworth order of one pass (default 2).
    pub order: usize,
    /// Cutoff for the pelvis height used by the flight height, Hz (default 12: the flight
    /// parabola lasts about 0.1 s and a 6 Hz filter would flatten it).
    pub height_cutoff_hz: f64,
    /// Hysteresis for extrema, as a fraction of the signal's 5–95 % range (default 0.3).
    pub prominence: f64,
    /// Smallest hysteresis, m (default 0.05): below this excursion the foot is not stepping.
    pub min_excursion_m: f64,
    /// Extrema closer than this many frames to the ends of the valid record are dropped
    /// (default 2): they may be cut by the record, not turning points.
    pub edge_frames: usize,
    /// Foot-speed detector: heel strike when the heel's speed over the ground falls below this
    /// fraction of the walking speed (default 0.5, Bonci et al. 2022). Measured alternative
    /// (not the default): 0.3, the fraction in 0.20…0.50 with the smallest mean error against
    /// the plates on Schreiber subjects 2014001/2014004/2014007, finds every plate heel strike
    /// of the shared walks with markers (Schreiber held out, BMClab), but its SD on the
    /// held-out Schreiber subjects is 17 ms (11 ms at 0.5) and it shortens a generated KLAW
    /// walk's double support by 31 ms (tests/klaw_events.rs; tests/events_walk_kinematic.rs
    /// measures both).
    #[serde(default = "default_hs_fraction")]
    pub hs_speed_fraction: f64,
    /// Foot-speed detector's heel-strike rule ([`WalkHeelStrike`]). `None` (default): the
    /// scale-free tangent onset when the markers' events are asked for
    /// ([`super::PrimarySource::Kinematic`], `--events kinematic`), the fraction rule above
    /// otherwise (`--events foot-speed`, and the automatic choice's fallback for marker-only
    /// walks, which builds `data/walk_bmclab.csv`'s Winter row and the KLAW closing-the-loop
    /// checks: switching it moves the fits, a coordinated regeneration).
    #[serde(default)]
    pub walk_heel_strike: Option<WalkHeelStrike>,
    /// Foot-speed detector: toe off when the toe's speed over the ground rises above this
    /// fraction of the walking speed (default 0.8, Bonci et al. 2022).
    #[serde(default = "default_to_fraction")]
    pub to_speed_fraction: f64,
    /// Running foot detector ([`Kinematics::run_foot`]): low-pass cutoff of the heel,
    /// metatarsal and toe markers whose derivatives it reads, Hz (default 15; chosen on Hamner
    /// subject01 Run_2 and Run_3, where 10–20 Hz give the same events within 1 ms). The
    /// walking tangent heel strike ([`WalkHeelStrike::Tangent`]) reads the heel's speed and its
    /// derivative on the heel low-passed here too.
    #[serde(default = "default_run_cutoff")]
    pub run_cutoff_hz: f64,
    /// Running foot detector: toe off when the toe's 3-D speed over the ground rises through
    /// this fraction of the running speed (default 0.35; chosen on Hamner subject01 Run_2 and
    /// Run_3 — 0.30/0.35/0.40 give −12/−2/+7 ms there — and validated on Run_4 and Run_5).
    #[serde(default = "default_run_to_fraction")]
    pub run_to_speed_fraction: f64,
}

fn default_run_cutoff() -> f64 {
    15.0
}

fn default_run_to_fraction() -> f64 {
    0.35
}

fn default_hs_fraction() -> f64 {
    0.5
}

fn default_to_fraction() -> f64 {
    0.8
}

impl Default for KinematicOptions {
    fn default() -> Self {
        KinematicOptions {
            cutoff_hz: 6.0,
            order: 2,
            height_cutoff_hz: 12.0,
            prominence: 0.3,
            min_excursion_m: 0.05,
            edge_frames: 2,
            hs_speed_fraction: default_hs_fraction(),
            walk_heel_strike: None,
            to_speed_fraction: default_to_fraction(),
            run_cutoff_hz: default_run_cutoff(),
            run_to_speed_fraction: default_run_to_fraction(),
        }
    }
}

/// The filtered trajectories of one leg (`None` for a role the marker set lacks).
#[derive(Debug, Clone, PartialEq, Default, Serialize, Deserialize)]
pub struct LegTrajectories {
    /// Heel.
    pub heel: Option<Vec<[f64; 3]>>,
    /// Toe.
    pub toe: Option<Vec<[f64; 3]>>,
    /// Metatarsal heads.
    pub meta: Option<Vec<[f64; 3]>>,
    /// Ankle.
    pub ankle: Option<Vec<[f64; 3]>>,
    /// Knee.
    pub knee: Option<Vec<[f64; 3]>>,
    /// Hip.
    pub hip: Option<Vec<[f64; 3]>>,
    /// The marker (or `A+B` mean) used for each role; empty where unresolved.
    pub names: LegMarkers,
}

/// Filtered marker kinematics of one trial in gait axes.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Kinematics {
    /// The trial's source file.
    pub path: String,
    /// Frame times, s (the valid range only).
    pub time_s: Vec<f64>,
    /// Frame rate, Hz.
    pub rate_hz: f64,
    /// Index (1-based, in the file) of the first valid frame.
    pub first_frame: usize,
    /// Vertical axis index.
    pub vertical: usize,
    /// Forward axis index.
    pub forward: usize,
    /// +1 or −1: the direction of progression along the forward axis.
    pub forward_sign: f64,
    /// Treadmill or overground (as given or detected).
    pub setting: Setting,
    /// The pelvis reference, filtered at the marker cutoff.
    pub pelvis: Vec<[f64; 3]>,
    /// The pelvis height filtered at the height cutoff, m.
    pub pelvis_height: Vec<f64>,
    /// Left and right legs (index 0 left, 1 right).
    pub legs: [LegTrajectories; 2],
    /// Heel, metatarsal and toe of each leg (index 0 left, 1 right) low-passed at
    /// [`KinematicOptions::run_cutoff_hz`], for the running foot detector's derivatives and
    /// the walking tangent heel strike's.
    #[serde(default)]
    pub run_feet: [LegTrajectories; 2],
    /// The marker map in use.
    pub map: MarkerMap,
    /// What was detected or assumed.
    pub notes: Vec<String>,
}

fn side_index(side: Side) -> usize {
    match side {
        Side::Left => 0,
        Side::Right => 1,
    }
}

/// The first and one-past-last frames where every trajectory is finite, or the first interior
/// gap as `(trajectory index, frame, length)`.
fn common_valid_range(
    trajs: &[&[[f64; 3]]],
    n: usize,
) -> Result<(usize, usize), (usize, usize, usize)> {
    let ok = |i: usize| trajs.iter().all(|t| t[i].iter().all(|v| v.is_finite()));
    let a = (0..n).find(|&i| ok(i)).unwrap_or(n);
    let b = (0..n).rev().find(|&i| ok(i)).map(|i| i + 1).unwrap_or(a);
    for (k, t) in trajs.iter().enumerate() {
        let mut i = a;
        while i < b {
            if t[i].iter().all(|v| v.is_finite()) {
                i += 1;
                continue;
            }
            let s = i;
            while i < b && !t[i].iter().all(|v| v.is_finite()) {
                i += 1;
            }
            return Err((k, s, i - s));
        }
    }
    Ok((a, b))
}

fn filter_traj(f: &Butterworth, t: &[[f64; 3]]) -> Vec<[f64; 3]> {
    let mut out = t.to_vec();
    for a in 0..3 {
        let x: Vec<f64> = t.iter().map(|p| p[a]).collect();
        let y = filtfilt_gappy(f, &x);
        for (o, v) in out.iter_mut().zip(y) {
            o[a] = v;
        }
    }
    out
}

/// Median of the finite values of `x` (reordered in place); `None` when there are none.
fn median(x: &mut Vec<f64>) -> Option<f64> {
    x.retain(|v| v.is_finite());
    if x.is_empty() {
        return None;
    }
    x.sort_by(f64::total_cmp);
    Some(x[x.len() / 2])
}

fn percentile_range(x: &[f64], lo: f64, hi: f64) -> f64 {
    let mut s: Vec<f64> = x.iter().copied().filter(|v| v.is_finite()).collect();
    if s.is_empty() {
        return 0.0;
    }
    s.sort_by(f64::total_cmp);
    let q = |p: f64| s[((s.len() - 1) as f64 * p).round() as usize];
    q(hi) - q(lo)
}

/// Turning points of `x` confirmed by a reversal of at least `delta`: `(index, is_maximum)`,
/// alternating maxima and minima. The last turning point needs only a reversal of `delta/10`
/// before the end of the record (trimmed overground trials end soon after a heel strike).
pub fn hysteresis_extrema(x: &[f64], delta: f64) -> Vec<(usize, bool)> {
    #[derive(PartialEq)]
    enum State {
        Unknown,
        SeekMax,
        SeekMin,
    }
    let mut out = Vec::new();
    if x.is_empty() {
        return out;
    }
    let (mut imax, mut imin) = (0usize, 0usize);
    let mut state = State::Unknown;
    for i in 1..x.len() {
        let v = x[i];
        match state {
            State::Unknown => {
                if v > x[imax] {
                    imax = i;
                }
                if v < x[imin] {
                    imin = i;
                }
                if v < x[imax] - delta {
                    out.push((imax, true));
                    state = State::SeekMin;
                    imin = i;
                } else if v > x[imin] + delta {
                    out.push((imin, false));
                    state = State::SeekMax;
                    imax = i;
                }
            }
            State::SeekMin => {
                if v < x[imin] {
                    imin = i;
                } else if v > x[imin] + delta {
                    out.push((imin, false));
                    state = State::SeekMax;
                    imax = i;
                }
            }
            State::SeekMax => {
                if v > x[imax] {
                    imax = i;
                } else if v < x[imax] - delta {
                    out.push((imax, true));
                    state = State::SeekMin;
                    imin = i;
                }
            }
        }
    }
    // A record cut shortly after the last turning point: accept it once the signal has come
    // back by a tenth of the hysteresis (the caller still drops extrema at the very edge).
    let last = x[x.len() - 1];
    match state {
        State::SeekMax if x[imax] - last >= 0.1 * delta => out.push((imax, true)),
        State::SeekMin if last - x[imin] >= 0.1 * delta => out.push((imin, false)),
        _ => {}
    }
    out
}

/// Sub-frame offset (−0.5…0.5) of the extremum at `i` by a parabola through `i−1, i, i+1`.
fn parabolic_offset(x: &[f64], i: usize) -> f64 {
    if i == 0 || i + 1 >= x.len() {
        return 0.0;
    }
    let (a, b, c) = (x[i - 1], x[i], x[i + 1]);
    let den = a - 2.0 * b + c;
    if den.abs() < 1e-15 {
        0.0
    } else {
        (0.5 * (a - c) / den).clamp(-0.5, 0.5)
    }
}

impl Kinematics {
    /// Resolves the marker roles, checks for gaps, filters, and establishes the gait axes and
    /// the setting. `map` `None` picks the best-matching preset.
    pub fn from_trial(
        trial: &Trial,
        map: Option<&MarkerMap>,
        opts: &KinematicOptions,
        setting: Option<Setting>,
    ) -> Result<Kinematics, EventError> {
        let path = path_of(trial);
        let ms: &MarkerSet = trial.markers.as_ref().ok_or_else(|| EventError::Missing {
            path: path.clone(),
            what: "marker trajectories".into(),
        })?;
        let map = map.cloned().unwrap_or_else(|| MarkerMap::auto(ms));
        let mut notes = vec![format!("marker roles: preset '{}'", map.name)];
        let n = ms.len();
        let (pelvis_name, pelvis_raw) =
            trajectory(&map.pelvis, ms).ok_or_else(|| EventError::Missing {
                path: path.clone(),
                what: format!(
                    "a pelvis marker (tried {}); map one with --marker pelvis=NAME or choose \
                     another --markers preset",
                    map.pelvis
                ),
            })?;
        // Resolve legs (raw).
        type Resolved = Vec<(&'static str, String, Vec<[f64; 3]>)>;
        let mut raw_legs: [Resolved; 2] = [Vec::new(), Vec::new()];
        for side in [Side::Left, Side::Right] {
            let l = map.leg(side);
            for (role, spec) in [
                ("heel", &l.heel),
                ("toe", &l.toe),
                ("meta", &l.meta),
                ("ankle", &l.ankle),
                ("knee", &l.knee),
                ("hip", &l.hip),
            ] {
                if let Some((name, t)) = trajectory(spec, ms) {
                    raw_legs[side_index(side)].push((role, name, t));
                }
            }
        }
        let has = |s: usize, role: &str| raw_legs[s].iter().any(|(r, _, _)| *r == role);
        let stepping: Vec<usize> = (0..2)
            .filter(|&s| has(s, "heel") && has(s, "toe"))
            .collect();
        if stepping.is_empty() {
            return Err(EventError::Missing {
                path,
                what: format!(
                    "heel and toe markers of either foot (tried heel {} / {}, toe {} / {}); map \
                     them with --marker r_heel=NAME --marker r_toe=NAME",
                    map.left.heel, map.right.heel, map.left.toe, map.right.toe
                ),
            });
        }
        // Critical trajectories: pelvis, heel and toe of the stepping legs.
        let mut crit: Vec<(String, String, &[[f64; 3]])> =
            vec![("pelvis".into(), pelvis_name.clone(), pelvis_raw.as_slice())];
        for &s in &stepping {
            let side = if s == 0 { Side::Left } else { Side::Right };
            for (role, name, t) in &raw_legs[s] {
                if *role == "heel" || *role == "toe" {
                    crit.push((
                        format!("{}_{role}", side.prefix()),
                        name.clone(),
                        t.as_slice(),
                    ));
                }
            }
        }
        let slices: Vec<&[[f64; 3]]> = crit.iter().map(|c| c.2).collect();
        let (a, b) =
            common_valid_range(&slices, n).map_err(|(k, frame, len)| EventError::MarkerGap {
                path: path.clone(),
                marker: crit[k].1.clone(),
                role: crit[k].0.clone(),
                frame: frame + 1,
                time_s: ms.time_s.get(frame).copied().unwrap_or(f64::NAN),
                frames: len,
            })?;
        if a > 0 || b < n {
            notes.push(format!(
                "markers: frames {}–{} of {} used (the pelvis, heel and toe markers are missing \
                 outside them)",
                a + 1,
                b,
                n
            ));
        }
        let filter = Butterworth::low_pass(opts.order, opts.cutoff_hz, ms.rate_hz)?;
        let hfilter = Butterworth::low_pass(
            opts.order,
            opts.height_cutoff_hz.min(0.45 * ms.rate_hz),
            ms.rate_hz,
        )?;
        if b - a < filter.min_len().max(3) {
            return Err(EventError::TooShort {
                path,
                reason: format!(
                    "{} frames with all of the pelvis, heel and toe markers present",
                    b - a
                ),
            });
        }
        let cut = |t: &[[f64; 3]]| filter_traj(&filter, &t[a..b]);
        let pelvis = cut(&pelvis_raw);
        let mut legs: [LegTrajectories; 2] = Default::default();
        for s in 0..2 {
            for (role, name, t) in &raw_legs[s] {
                let ft = Some(cut(t));
                let (slot, nm) = match *role {
                    "heel" => (&mut legs[s].heel, &mut legs[s].names.heel),
                    "toe" => (&mut legs[s].toe, &mut legs[s].names.toe),
                    "meta" => (&mut legs[s].meta, &mut legs[s].names.meta),
                    "ankle" => (&mut legs[s].ankle, &mut legs[s].names.ankle),
                    "knee" => (&mut legs[s].knee, &mut legs[s].names.knee),
                    _ => (&mut legs[s].hip, &mut legs[s].names.hip),
                };
                *slot = ft;
                *nm = name.clone();
            }
        }
        let rfilter = Butterworth::low_pass(
            opts.order,
            opts.run_cutoff_hz.min(0.45 * ms.rate_hz),
            ms.rate_hz,
        )?;
        let mut run_feet: [LegTrajectories; 2] = Default::default();
        if b - a >= rfilter.min_len().max(3) {
            for s in 0..2 {
                for (role, _, t) in &raw_legs[s] {
                    let slot = match *role {
                        "heel" => &mut run_feet[s].heel,
                        "toe" => &mut run_feet[s].toe,
                        "meta" => &mut run_feet[s].meta,
                        _ => continue,
                    };
                    *slot = Some(filter_traj(&rfilter, &t[a..b]));
                }
            }
        }
        let time_s = ms.time_s[a..b].to_vec();
        // Axes.
        let (vertical, forward, forward_sign) = match &trial.frame {
            Some(f) => (f.vertical.index(), f.forward.index(), f.forward_sign),
            None => {
                let (v, f, s, how) = detect_axes(&pelvis, &legs, stepping[0]);
                notes.push(how);
                (v, f, s)
            }
        };
        let travel = {
            let p0 = pelvis[0][forward];
            let p1 = pelvis[pelvis.len() - 1][forward];
            (p1 - p0) * forward_sign
        };
        let setting = match setting.unwrap_or(trial.setting) {
            Setting::Unknown => {
                if travel.abs() > 1.0 {
                    notes.push(format!(
                        "setting: overground (the pelvis travels {travel:.2} m)"
                    ));
                    Setting::Overground
                } else {
                    notes.push(format!(
                        "setting: treadmill assumed (the pelvis travels only {travel:.2} m); \
                         belt speed unknown"
                    ));
                    Setting::Unknown
                }
            }
            s => s,
        };
        let ph: Vec<f64> = pelvis_raw[a..b].iter().map(|p| p[vertical]).collect();
        let pelvis_height = filtfilt_gappy(&hfilter, &ph);
        Ok(Kinematics {
            path,
            time_s,
            rate_hz: ms.rate_hz,
            first_frame: a + 1,
            vertical,
            forward,
            forward_sign,
            setting,
            pelvis,
            pelvis_height,
            legs,
            run_feet,
            map,
            notes,
        })
    }

    /// The trajectories of `side`.
    pub fn leg(&self, side: Side) -> &LegTrajectories {
        &self.legs[side_index(side)]
    }

    /// Forward coordinate (along the direction of progression) of `p`.
    pub fn fwd(&self, p: &[f64; 3]) -> f64 {
        p[self.forward] * self.forward_sign
    }

    /// Height of `p`.
    pub fn up(&self, p: &[f64; 3]) -> f64 {
        p[self.vertical]
    }

    /// The first time in frames `a..b` where the per-frame signal `s` crosses `level` (falling
    /// through it, or rising), linearly interpolated between frames.
    fn level_crossing(
        &self,
        s: &[f64],
        level: f64,
        falling: bool,
        a: usize,
        b: usize,
    ) -> Option<f64> {
        let last = s.len().min(self.time_s.len()).checked_sub(1)?;
        let i = (a..b.min(last)).find(|&i| {
            if falling {
                s[i] >= level && s[i + 1] < level
            } else {
                s[i] <= level && s[i + 1] > level
            }
        })?;
        let w = (level - s[i]) / (s[i + 1] - s[i]);
        Some(self.time_s[i] + w.clamp(0.0, 1.0) / self.rate_hz)
    }

    /// The frame nearest to time `t` (clamped to the valid range).
    pub fn frame_at(&self, t: f64) -> usize {
        let n = self.time_s.len();
        if n == 0 {
            return 0;
        }
        let i = ((t - self.time_s[0]) * self.rate_hz).round();
        (i.max(0.0) as usize).min(n - 1)
    }

    /// Linear interpolation of `x` (one value per frame) at time `t`; `None` outside the record.
    pub fn sample(&self, x: &[f64], t: f64) -> Option<f64> {
        let n = self.time_s.len().min(x.len());
        if n < 2 {
            return None;
        }
        let u = (t - self.time_s[0]) * self.rate_hz;
        if u < 0.0 || u > (n - 1) as f64 {
            return None;
        }
        let i = (u.floor() as usize).min(n - 2);
        let w = u - i as f64;
        let v = x[i] * (1.0 - w) + x[i + 1] * w;
        v.is_finite().then_some(v)
    }

    /// Linear interpolation of a trajectory at time `t`.
    pub fn sample3(&self, x: &[[f64; 3]], t: f64) -> Option<[f64; 3]> {
        let n = self.time_s.len().min(x.len());
        if n < 2 {
            return None;
        }
        let u = (t - self.time_s[0]) * self.rate_hz;
        if u < 0.0 || u > (n - 1) as f64 {
            return None;
        }
        let i = (u.floor() as usize).min(n - 2);
        let w = u - i as f64;
        let mut out = [0.0; 3];
        for (a, o) in out.iter_mut().enumerate() {
            *o = x[i][a] * (1.0 - w) + x[i + 1][a] * w;
        }
        out.iter().all(|v| v.is_finite()).then_some(out)
    }

    /// The signal `fwd(marker) − fwd(pelvis)` per frame.
    pub fn relative_forward(&self, marker: &[[f64; 3]]) -> Vec<f64> {
        marker
            .iter()
            .zip(&self.pelvis)
            .map(|(m, p)| self.fwd(m) - self.fwd(p))
            .collect()
    }

    fn delta(&self, x: &[f64], opts: &KinematicOptions) -> Option<f64> {
        let range = percentile_range(x, 0.05, 0.95);
        if range < 2.0 * opts.min_excursion_m {
            return None;
        }
        Some((opts.prominence * range).max(opts.min_excursion_m))
    }

    fn push_extrema(
        &self,
        x: &[f64],
        want_max: bool,
        (side, kind): (Side, EventKind),
        opts: &KinematicOptions,
        out: &mut Vec<GaitEvent>,
    ) {
        let Some(delta) = self.delta(x, opts) else {
            return;
        };
        let n = x.len();
        let dt = 1.0 / self.rate_hz;
        for (i, is_max) in hysteresis_extrema(x, delta) {
            if is_max != want_max || i < opts.edge_frames || i + opts.edge_frames >= n {
                continue;
            }
            let t = self.time_s[i] + parabolic_offset(x, i) * dt;
            out.push(GaitEvent {
                time_s: t,
                side,
                kind,
                source: EventSource::ZeniCoordinate,
            });
        }
    }

    /// Zeni coordinate method: heel strike at maxima of the heel's forward position relative to
    /// the pelvis, toe off at minima of the toe's.
    pub fn zeni_coordinate(&self, opts: &KinematicOptions) -> Vec<GaitEvent> {
        let mut out = Vec::new();
        for side in [Side::Left, Side::Right] {
            let l = self.leg(side);
            let (Some(heel), Some(toe)) = (&l.heel, &l.toe) else {
                continue;
            };
            let h = self.relative_forward(heel);
            self.push_extrema(&h, true, (side, EventKind::HeelStrike), opts, &mut out);
            let t = self.relative_forward(toe);
            self.push_extrema(&t, false, (side, EventKind::ToeOff), opts, &mut out);
        }
        out.sort_by(|a, b| a.time_s.total_cmp(&b.time_s));
        out
    }

    /// Zeni velocity variant: zero crossings of the foot centre's forward velocity relative to
    /// the pelvis (+ → − heel strike, − → + toe off).
    pub fn zeni_velocity(&self, opts: &KinematicOptions) -> Vec<GaitEvent> {
        let mut out = Vec::new();
        for side in [Side::Left, Side::Right] {
            let l = self.leg(side);
            let (Some(heel), Some(toe)) = (&l.heel, &l.toe) else {
                continue;
            };
            let centre: Vec<[f64; 3]> = heel
                .iter()
                .zip(toe)
                .map(|(h, t)| {
                    [
                        0.5 * (h[0] + t[0]),
                        0.5 * (h[1] + t[1]),
                        0.5 * (h[2] + t[2]),
                    ]
                })
                .collect();
            let x = self.relative_forward(&centre);
            let n = x.len();
            if n < 3 {
                continue;
            }
            let Some(delta) = self.delta(&x, opts) else {
                continue;
            };
            // Central differences (one-sided at the ends).
            let v: Vec<f64> = (0..n)
                .map(|i| {
                    let (a, b) = (i.saturating_sub(1), (i + 1).min(n - 1));
                    (x[b] - x[a]) / ((b - a) as f64 / self.rate_hz)
                })
                .collect();
            for (i, is_max) in hysteresis_extrema(&x, delta) {
                if i < opts.edge_frames || i + opts.edge_frames >= n {
                    continue;
                }
                // The zero crossing of v nearest to the extremum with the right polarity.
                let want_pos_to_neg = is_max;
                let mut best: Option<f64> = None;
                let lo = i.saturating_sub(3).max(1);
                let hi = (i + 3).min(n - 1);
                for j in lo..=hi {
                    let (a, b) = (v[j - 1], v[j]);
                    let crosses = if want_pos_to_neg {
                        a > 0.0 && b <= 0.0
                    } else {
                        a < 0.0 && b >= 0.0
                    };
                    if crosses {
                        let frac = a / (a - b);
                        let t = self.time_s[j - 1] + frac / self.rate_hz;
                        if best.is_none_or(|bt| {
                            (t - self.time_s[i]).abs() < (bt - self.time_s[i]).abs()
                        }) {
                            best = Some(t);
                        }
                    }
                }
                if let Some(t) = best {
                    out.push(GaitEvent {
                        time_s: t,
                        side,
                        kind: if is_max {
                            EventKind::HeelStrike
                        } else {
                            EventKind::ToeOff
                        },
                        source: EventSource::ZeniVelocity,
                    });
                }
            }
        }
        out.sort_by(|a, b| a.time_s.total_cmp(&b.time_s));
        out
    }

    /// Per-frame velocity of a trajectory (central differences, one-sided at the ends), m/s.
    fn velocity(&self, x: &[[f64; 3]]) -> Vec<[f64; 3]> {
        let n = x.len();
        (0..n)
            .map(|i| {
                let (a, b) = (i.saturating_sub(1), (i + 1).min(n - 1));
                let dt = (b - a).max(1) as f64 / self.rate_hz;
                let mut v = [0.0; 3];
                for (ax, o) in v.iter_mut().enumerate() {
                    *o = (x[b][ax] - x[a][ax]) / dt;
                }
                v
            })
            .collect()
    }

    /// The ground's forward velocity in the lab (0 overground, minus the belt speed on a
    /// treadmill) and the walking speed over the ground, m/s, from the stances of `seeds`: the
    /// ground moves as the toe marker does in mid-stance (25–65 % of each seed stance, when
    /// the forefoot is flat in walking), and the walking speed is the median forward velocity
    /// of the pelvis relative to it (the median ignores a start from standing or a stop).
    /// Without a seed stance inside the record the ground is taken at rest overground (0) and
    /// is unknown on a treadmill (`None`); `None` too when the speed is not positive.
    pub fn ground_and_walking_speed(&self, seeds: &[GaitEvent]) -> Option<(f64, f64)> {
        let n = self.time_s.len();
        if n < 3 {
            return None;
        }
        let mut ground = Vec::new();
        for (side, hs, to) in super::phases::stances(seeds) {
            let Some(toe) = &self.leg(side).toe else {
                continue;
            };
            if hs < self.time_s[0] || to > self.time_s[n - 1] {
                continue;
            }
            let v = self.velocity(toe);
            let (a, b) = (
                self.frame_at(hs + 0.25 * (to - hs)),
                self.frame_at(hs + 0.65 * (to - hs)),
            );
            ground.extend((a..=b).map(|i| self.fwd(&v[i])));
        }
        let ground = match median(&mut ground) {
            Some(g) => g,
            // No seed stance inside the record (a short overground record cut around one
            // step): the ground of an overground lab is at rest.
            None if self.setting == Setting::Overground => 0.0,
            None => return None,
        };
        let pv = self.velocity(&self.pelvis);
        let mut rel: Vec<f64> = pv.iter().map(|v| self.fwd(v) - ground).collect();
        let speed = median(&mut rel)?;
        (speed > 0.0).then_some((ground, speed))
    }

    /// Running events from the foot markers (treadmill or overground). Stances and swings are
    /// the minima and maxima of the foot centre's height (mean of heel and toe at the marker
    /// cutoff, hysteresis as for Zeni). In each stance, with the heel, metatarsal and toe
    /// markers low-passed at `run_cutoff_hz`:
    /// - heel strike: for the heel and for the metatarsal marker, the landing impact is the
    ///   last peak of upward vertical acceleration before the marker's lowest point of the
    ///   stance, and touchdown the vertical jerk peak that leads it (the onset of the impact
    ///   deceleration); the earlier of the two markers (Handsaker et al. 2016, *A kinematic
    ///   algorithm to identify gait events during running at different speeds and with
    ///   different footstrike types*, J Biomech 49:4128–4133: heel or first-metatarsal
    ///   marker, whichever lands first; they tested acceleration and jerk peaks, and
    ///   recommend the acceleration peak at 250 Hz — at 100 Hz it is 9–22 ms late on Hamner,
    ///   growing with speed, the jerk peak −8 to +2 ms);
    /// - toe off: the first time after the stance's lowest point that the toe marker's 3-D
    ///   speed over the ground rises through `run_to_speed_fraction` × the running speed
    ///   (as [`Kinematics::foot_speed`], with the running fraction chosen on Hamner
    ///   subject01 Run_2/Run_3 and validated on Run_4/Run_5).
    ///
    /// A stance cut by the record keeps the event the record still holds (its window runs to
    /// the record's end). `seeds` (Zeni events) give the ground's velocity and the running
    /// speed. Running only: the rules were chosen and validated on running.
    pub fn run_foot(&self, seeds: &[GaitEvent], opts: &KinematicOptions) -> Vec<GaitEvent> {
        let mut out = Vec::new();
        let Some((ground, speed)) = self.ground_and_walking_speed(seeds) else {
            return out;
        };
        let n = self.time_s.len();
        if n < 5 {
            return out;
        }
        let dt = 1.0 / self.rate_hz;
        let ground_vel = ground * self.forward_sign;
        let fwd_axis = self.forward;
        let deriv = |x: &[f64]| -> Vec<f64> {
            (0..x.len())
                .map(|i| {
                    let (a, b) = (i.saturating_sub(1), (i + 1).min(x.len() - 1));
                    (x[b] - x[a]) / ((b - a).max(1) as f64 * dt)
                })
                .collect()
        };
        let peaks = |x: &[f64], lo: usize, hi: usize| -> Vec<usize> {
            (lo.max(1)..hi.min(x.len() - 1))
                .filter(|&i| x[i] >= x[i - 1] && x[i] > x[i + 1])
                .collect()
        };
        for side in [Side::Left, Side::Right] {
            let (l, f) = (self.leg(side), &self.run_feet[side_index(side)]);
            let (Some(heel), Some(toe), Some(fheel), Some(ftoe)) =
                (&l.heel, &l.toe, &f.heel, &f.toe)
            else {
                continue;
            };
            let centre: Vec<f64> = heel
                .iter()
                .zip(toe)
                .map(|(h, t)| 0.5 * (self.up(h) + self.up(t)))
                .collect();
            let Some(delta) = self.delta(&centre, opts) else {
                continue;
            };
            let ext = hysteresis_extrema(&centre, delta);
            let landing: Vec<&Vec<[f64; 3]>> = [Some(fheel), f.meta.as_ref()]
                .into_iter()
                .flatten()
                .collect();
            let heights: Vec<Vec<f64>> = landing
                .iter()
                .map(|m| m.iter().map(|p| self.up(p)).collect())
                .collect();
            let accel: Vec<Vec<f64>> = heights.iter().map(|h| deriv(&deriv(h))).collect();
            let jerk: Vec<Vec<f64>> = accel.iter().map(|a| deriv(a)).collect();
            let toe_speed: Vec<f64> = self
                .velocity(ftoe)
                .into_iter()
                .map(|mut v| {
                    v[fwd_axis] -= ground_vel;
                    (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt()
                })
                .collect();
            let level = opts.run_to_speed_fraction * speed;
            for (k, &(m, is_max)) in ext.iter().enumerate() {
                if is_max {
                    continue;
                }
                let before = ext[..k].iter().rev().find(|e| e.1).map_or(0, |e| e.0);
                let after = ext[k + 1..].iter().find(|e| e.1).map_or(n - 1, |e| e.0);
                // Heel strike: per landing marker, the jerk peak leading its impact.
                let mut hs: Option<f64> = None;
                for ((h, a), j) in heights.iter().zip(&accel).zip(&jerk) {
                    let low = (before..=after)
                        .min_by(|&x, &y| h[x].total_cmp(&h[y]))
                        .unwrap_or(m);
                    let Some(&impact) = peaks(a, before + 1, low + 1)
                        .iter()
                        .rev()
                        .find(|&&i| a[i] > 0.0)
                    else {
                        continue;
                    };
                    let Some(&onset) = peaks(j, before + 1, impact + 1).last() else {
                        continue;
                    };
                    let t = self.time_s[onset] + parabolic_offset(j, onset) * dt;
                    hs = Some(hs.map_or(t, |u| u.min(t)));
                }
                if let Some(t) = hs {
                    out.push(GaitEvent {
                        time_s: t,
                        side,
                        kind: EventKind::HeelStrike,
                        source: EventSource::FootJerk,
                    });
                }
                // Toe off: the toe's speed over the ground rising through the level.
                if let Some(i) = (m..after.min(n - 1))
                    .find(|&i| toe_speed[i] <= level && toe_speed[i + 1] > level)
                {
                    let w = (level - toe_speed[i]) / (toe_speed[i + 1] - toe_speed[i]);
                    out.push(GaitEvent {
                        time_s: self.time_s[i] + w.clamp(0.0, 1.0) * dt,
                        side,
                        kind: EventKind::ToeOff,
                        source: EventSource::FootJerk,
                    });
                }
            }
        }
        out.sort_by(|a, b| a.time_s.total_cmp(&b.time_s));
        out
    }

    /// The foot in contact at time `t`: nearest (horizontally) to the centre of pressure `cop`
    /// when given and within 0.4 m, else the lower foot.
    pub fn foot_nearest(&self, t: f64, cop: Option<[f64; 3]>) -> Option<Side> {
        let mut cands: Vec<(Side, [f64; 3])> = Vec::new();
        for side in [Side::Left, Side::Right] {
            let l = self.leg(side);
            let Some(heel) = &l.heel else { continue };
            let front = l.meta.as_ref().or(l.toe.as_ref());
            let h = self.sample3(heel, t)?;
            let p = match front.and_then(|f| self.sample3(f, t)) {
                Some(f) => [
                    0.5 * (h[0] + f[0]),
                    0.5 * (h[1] + f[1]),
                    0.5 * (h[2] + f[2]),
                ],
                None => h,
            };
            cands.push((side, p));
        }
        if cands.is_empty() {
            return None;
        }
        if cands.len() == 1 {
            return Some(cands[0].0);
        }
        if let Some(c) = cop {
            let d = |p: &[f64; 3]| {
                let mut s = 0.0;
                for a in 0..3 {
                    if a != self.vertical {
                        s += (p[a] - c[a]).powi(2);
                    }
                }
                s.sqrt()
            };
            let (d0, d1) = (d(&cands[0].1), d(&cands[1].1));
            if d0.min(d1) < 0.4 {
                return Some(if d0 <= d1 { cands[0].0 } else { cands[1].0 });
            }
        }
        let (h0, h1) = (self.up(&cands[0].1), self.up(&cands[1].1));
        Some(if h0 <= h1 { cands[0].0 } else { cands[1].0 })
    }
}

/// Vertical axis: the one along which the pelvis is furthest above the heel. Forward: of the
/// other two, the one with the larger pelvis travel (overground), else the larger heel
/// excursion relative to the pelvis (treadmill). Sign: the pelvis travel overground; on a
/// treadmill the stance foot moves backward, so the sign is opposite to the heel's mean forward
/// velocity while the heel is low.
fn detect_axes(
    pelvis: &[[f64; 3]],
    legs: &[LegTrajectories; 2],
    stepping: usize,
) -> (usize, usize, f64, String) {
    let heel = legs[stepping].heel.as_deref().unwrap_or(pelvis);
    let n = pelvis.len() as f64;
    let mean = |t: &[[f64; 3]], a: usize| t.iter().map(|p| p[a]).sum::<f64>() / n;
    let vertical = (0..3)
        .max_by(|&a, &b| {
            (mean(pelvis, a) - mean(heel, a)).total_cmp(&(mean(pelvis, b) - mean(heel, b)))
        })
        .unwrap_or(1);
    let others: Vec<usize> = (0..3).filter(|&a| a != vertical).collect();
    let travel = |a: usize| pelvis[pelvis.len() - 1][a] - pelvis[0][a];
    let excursion = |a: usize| {
        let x: Vec<f64> = heel.iter().zip(pelvis).map(|(h, p)| h[a] - p[a]).collect();
        percentile_range(&x, 0.05, 0.95)
    };
    let axis_name = |a: usize| ["X", "Y", "Z"][a];
    let t0 = travel(others[0]).abs();
    let t1 = travel(others[1]).abs();
    if t0.max(t1) > 1.0 {
        let forward = if t0 >= t1 { others[0] } else { others[1] };
        let sign = travel(forward).signum();
        let how = format!(
            "axes detected: vertical {}, forward {}{} (pelvis travel {:.2} m)",
            axis_name(vertical),
            if sign > 0.0 { "+" } else { "−" },
            axis_name(forward),
            travel(forward).abs()
        );
        return (vertical, forward, sign, how);
    }
    let forward = if excursion(others[0]) >= excursion(others[1]) {
        others[0]
    } else {
        others[1]
    };
    let heights: Vec<f64> = heel.iter().map(|p| p[vertical]).collect();
    let low = {
        let mut s = heights.clone();
        s.sort_by(f64::total_cmp);
        s[(s.len() as f64 * 0.25) as usize]
    };
    let mut v_sum = 0.0;
    for i in 1..heel.len() {
        if heights[i] <= low {
            v_sum += heel[i][forward] - heel[i - 1][forward];
        }
    }
    let sign = if v_sum > 0.0 { -1.0 } else { 1.0 };
    let how = format!(
        "axes detected: vertical {}, forward {}{} (treadmill: the stance foot moves backward)",
        axis_name(vertical),
        if sign > 0.0 { "+" } else { "−" },
        axis_name(forward)
    );
    (vertical, forward, sign, how)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn hysteresis_finds_alternating_extrema() {
        let x: Vec<f64> = (0..400)
            .map(|i| (i as f64 * 0.05).sin() + 0.01 * ((i * 7919) % 13) as f64)
            .collect();
        let e = hysteresis_extrema(&x, 0.5);
        assert!(e.len() >= 5);
        for w in e.windows(2) {
            assert_ne!(w[0].1, w[1].1);
        }
        // Maxima of sin(0.05 i) near i = (π/2 + 2πk)/0.05 ≈ 31.4, 157, 283.
        let maxima: Vec<usize> = e.iter().filter(|p| p.1).map(|p| p.0).collect();
        assert!((maxima[0] as f64 - 31.4).abs() < 4.0, "{maxima:?}");
    }

    #[test]
    fn parabola_recovers_subframe_peak() {
        let x: Vec<f64> = (0..5).map(|i| -(i as f64 - 2.3).powi(2)).collect();
        assert!((parabolic_offset(&x, 2) - 0.3).abs() < 1e-12);
    }
}
