//! The walking foot-speed detector ([`Kinematics::foot_speed`]) and its heel-strike rules.
//!
//! Toe off (both rules): Bonci et al. (2022), the toe marker's 3-D speed over the ground rising
//! through 0.8 × the walking speed in a window around each Zeni toe off.
//!
//! Heel strike, tangent onset ([`WalkHeelStrike::Tangent`], the default of `--events
//! kinematic`): the landing heel decelerates from its
//! swing speed to rest; the heel strike is where the tangent at the steepest point of that
//! descent reaches zero speed. Nothing in it is a fraction of the walking speed: the time
//! comes from the shape of the heel's own deceleration, so it neither moves with the walking
//! speed (Bonci's fixed 0.5 × speed is crossed earlier before contact at slower speeds,
//! reports/events.md) nor needs the whole descent inside the record (one point and its slope
//! suffice at a record start). The heel speed is differentiated once more, so it is read on
//! the foot markers low-passed at [`KinematicOptions::run_cutoff_hz`], the cutoff the
//! pipeline already uses where it differentiates the foot markers twice (the running foot
//! detector's impact accelerations), not the 6 Hz of the positions.
//!
//! Heel strike, fraction ([`WalkHeelStrike::Fraction`], the default otherwise): Bonci's rearfoot rule, the heel's
//! 3-D speed over the ground falling through `hs_speed_fraction` × the walking speed.
use super::{EventKind, EventSource, GaitEvent, KinematicOptions, Kinematics, Side};
use serde::{Deserialize, Serialize};

/// How the walking foot-speed detector times heel strike.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum WalkHeelStrike {
    /// The tangent at the steepest descent of the heel's speed over the ground, extrapolated
    /// to zero speed (see the module documentation; scale-free; the default of
    /// `--events kinematic`).
    Tangent,
    /// The heel's speed over the ground falling through
    /// [`KinematicOptions::hs_speed_fraction`] × the walking speed (Bonci et al. 2022; the
    /// default of `--events foot-speed` and of the automatic choice).
    Fraction,
}

impl WalkHeelStrike {
    /// Parses `tangent|fraction` (also `bonci` for the fraction rule).
    pub fn parse(s: &str) -> Option<Self> {
        match s.trim().to_ascii_lowercase().as_str() {
            "tangent" | "tangent-onset" => Some(Self::Tangent),
            "fraction" | "bonci" => Some(Self::Fraction),
            _ => None,
        }
    }

    /// The name `parse` accepts.
    pub fn as_str(self) -> &'static str {
        match self {
            Self::Tangent => "tangent",
            Self::Fraction => "fraction",
        }
    }
}

/// Index of the smallest (`min`) or largest value of `x[a..=b]`; `a` when the range is empty.
fn arg_extreme(x: &[f64], a: usize, b: usize, min: bool) -> usize {
    let mut best = a;
    for i in a..=b.min(x.len().saturating_sub(1)) {
        if (min && x[i] < x[best]) || (!min && x[i] > x[best]) {
            best = i;
        }
    }
    best
}

/// Tangent onset of one landing in frames `lo..=hi` of the heel speed `s` (frame times
/// `time_s`, rate `rate_hz`; `ds` its time derivative) (one stance of
/// the foot and the swing before it, or what the record holds of them): the descent runs
/// from the swing's fastest frame to the stance's slowest; at its steepest frame `k` (least
/// `ds`, an interior minimum of `ds`, refined by a parabola) the tangent
/// `s(t_k) + ds(t_k)(t − t_k)` reaches zero at the heel strike. `None` without a descent
/// whose steepest point the record holds, or when the tangent reaches zero before the
/// descent starts or after the stance's slowest frame (no landing in the window).
fn tangent_onset(
    time_s: &[f64],
    rate_hz: f64,
    s: &[f64],
    ds: &[f64],
    lo: usize,
    hi: usize,
) -> Option<f64> {
    let n = s.len().min(ds.len()).min(time_s.len());
    if n < 3 || lo >= hi {
        return None;
    }
    let hi = hi.min(n - 1);
    let floor = arg_extreme(s, lo, hi, true);
    let peak = arg_extreme(s, lo, floor, false);
    if floor <= peak + 1 {
        return None;
    }
    let k = arg_extreme(ds, peak, floor, true);
    if k == 0 || k + 1 >= n || ds[k] >= 0.0 || ds[k - 1] < ds[k] || ds[k + 1] < ds[k] {
        return None;
    }
    // Sub-frame steepest point: the parabola through ds[k−1..=k+1].
    let (a, b, c) = (ds[k - 1], ds[k], ds[k + 1]);
    let den = a - 2.0 * b + c;
    let u = if den.abs() > 1e-15 {
        (0.5 * (a - c) / den).clamp(-0.5, 0.5)
    } else {
        0.0
    };
    let slope = b - 0.25 * (a - c) * u;
    let j = if u < 0.0 { k - 1 } else { k };
    let w = if u < 0.0 { 1.0 + u } else { u };
    let speed = s[j] * (1.0 - w) + s[j + 1] * w;
    let tk = time_s[k] + u / rate_hz;
    let t = tk - speed / slope;
    (t >= time_s[peak] && t <= time_s[floor]).then_some(t)
}

impl Kinematics {
    /// The heel's 3-D speed over the ground per frame (the ground's forward velocity
    /// `ground_vel`, lab axes, removed first).
    fn speed_over_ground(&self, x: &[[f64; 3]], ground_vel: f64) -> Vec<f64> {
        let fwd_axis = self.forward;
        self.velocity(x)
            .into_iter()
            .map(|mut v| {
                v[fwd_axis] -= ground_vel;
                (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt()
            })
            .collect()
    }

    /// Two-stage walking events after Bonci et al. (2022), rearfoot contacts: the Zeni events
    /// of `seeds` split each foot's record into swings and stances, and the heel and toe
    /// markers' speeds over the ground time the events in them. Heel strike: by
    /// `opts.walk_heel_strike` — the tangent onset (see the module documentation),
    /// searched from the foot's previous Zeni toe off (or the record start) to its next one
    /// (or the record end), or Bonci's first fall of the heel speed through
    /// `hs_speed_fraction` × the walking speed in [−0.1 s, +0.2 s] around the Zeni heel
    /// strike. Toe off: the first time in [−0.15 s, +0.1 s] around the Zeni toe off that the
    /// toe's speed rises through `to_speed_fraction` × the walking speed (crossings
    /// interpolated linearly). Speeds are over the ground: on a treadmill the belt's velocity
    /// (see [`Kinematics::ground_and_walking_speed`]) is removed first.
    ///
    /// Record ends: an event whose Zeni extremum the record cuts has no seed. A foot whose
    /// first seed is a toe off may land just inside the record, one whose last seed is a toe
    /// off may land again before the end, one whose last seed is a heel strike may lift: each
    /// opens a window there (the fraction rule's heel window at the start ends 0.2 s before the
    /// first toe off and finds the heel strike only if the heel is still faster than its level
    /// at the first frame). A window with no event gives none. Walking only: the rules were
    /// published and measured for walking.
    pub fn foot_speed(&self, seeds: &[GaitEvent], opts: &KinematicOptions) -> Vec<GaitEvent> {
        let mut out = Vec::new();
        let Some((ground, speed)) = self.ground_and_walking_speed(seeds) else {
            return out;
        };
        let n = self.time_s.len();
        let ground_vel = ground * self.forward_sign;
        let dt = 1.0 / self.rate_hz;
        for side in [Side::Left, Side::Right] {
            let l = self.leg(side);
            let (Some(heel), Some(toe)) = (&l.heel, &l.toe) else {
                continue;
            };
            let (sh, st) = (
                self.speed_over_ground(heel, ground_vel),
                self.speed_over_ground(toe, ground_vel),
            );
            // The tangent rule's heel speed and its derivative (foot-marker derivative cutoff).
            let fast = self.run_feet[super::side_index(side)].heel.as_ref();
            let sf = fast.map_or_else(|| sh.clone(), |h| self.speed_over_ground(h, ground_vel));
            let dsf: Vec<f64> = (0..sf.len())
                .map(|i| {
                    let (a, b) = (i.saturating_sub(1), (i + 1).min(sf.len() - 1));
                    (sf[b] - sf[a]) / ((b - a).max(1) as f64 * dt)
                })
                .collect();
            let mut push = |time_s: f64, kind: EventKind| {
                out.push(GaitEvent {
                    time_s,
                    side,
                    kind,
                    source: EventSource::FootSpeed,
                })
            };
            let mine: Vec<&GaitEvent> = seeds.iter().filter(|e| e.side == side).collect();
            let t_end = self.time_s[n - 1];
            // Toe offs: each seed's window, and one after a last heel strike.
            let to_level = opts.to_speed_fraction * speed;
            for e in mine.iter().filter(|e| e.kind == EventKind::ToeOff) {
                let (a, b) = (
                    self.frame_at(e.time_s - 0.15),
                    self.frame_at(e.time_s + 0.1),
                );
                if let Some(t) = self.level_crossing(&st, to_level, false, a, b) {
                    push(t, EventKind::ToeOff);
                }
            }
            if let Some(last) = mine.last() {
                if last.kind == EventKind::HeelStrike && last.time_s + 0.25 < t_end {
                    let a = self.frame_at(last.time_s + 0.25);
                    if let Some(t) = self.level_crossing(&st, to_level, false, a, n - 1) {
                        push(t, EventKind::ToeOff);
                    }
                }
            }
            // Heel strikes.
            let first_to = mine.first().filter(|e| e.kind == EventKind::ToeOff);
            let last_to = mine.last().filter(|e| e.kind == EventKind::ToeOff);
            match opts.walk_heel_strike.unwrap_or(WalkHeelStrike::Fraction) {
                WalkHeelStrike::Tangent => {
                    let to_frames: Vec<usize> = mine
                        .iter()
                        .filter(|e| e.kind == EventKind::ToeOff)
                        .map(|e| self.frame_at(e.time_s))
                        .collect();
                    let mut windows: Vec<(usize, usize)> = Vec::new();
                    if let Some(f) = first_to {
                        windows.push((0, self.frame_at(f.time_s)));
                    }
                    for e in mine.iter().filter(|e| e.kind == EventKind::HeelStrike) {
                        let i = self.frame_at(e.time_s);
                        let lo = to_frames.iter().rev().find(|&&f| f < i).copied();
                        let hi = to_frames.iter().find(|&&f| f > i).copied();
                        windows.push((lo.unwrap_or(0), hi.unwrap_or(n - 1)));
                    }
                    if let Some(l) = last_to {
                        windows.push((self.frame_at(l.time_s), n - 1));
                    }
                    for (a, b) in windows {
                        if let Some(t) = tangent_onset(&self.time_s, self.rate_hz, &sf, &dsf, a, b)
                        {
                            push(t, EventKind::HeelStrike);
                        }
                    }
                }
                WalkHeelStrike::Fraction => {
                    let level = opts.hs_speed_fraction * speed;
                    let mut windows: Vec<(usize, usize)> = Vec::new();
                    if let Some(f) = first_to.filter(|f| f.time_s - 0.2 > self.time_s[0]) {
                        windows.push((0, self.frame_at(f.time_s - 0.2)));
                    }
                    for e in mine.iter().filter(|e| e.kind == EventKind::HeelStrike) {
                        windows
                            .push((self.frame_at(e.time_s - 0.1), self.frame_at(e.time_s + 0.2)));
                    }
                    if let Some(l) = last_to.filter(|l| l.time_s + 0.2 < t_end) {
                        windows.push((self.frame_at(l.time_s + 0.2), n - 1));
                    }
                    for (a, b) in windows {
                        if let Some(t) = self.level_crossing(&sh, level, true, a, b) {
                            push(t, EventKind::HeelStrike);
                        }
                    }
                }
            }
        }
        out.sort_by(|a, b| a.time_s.total_cmp(&b.time_s));
        out.dedup_by(|b, a| {
            a.side == b.side && a.kind == b.kind && (b.time_s - a.time_s).abs() < dt
        });
        out
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A logistic descent `A / (1 + exp((t − t0)/τ))` is steepest at `t0`, where it is `A/2`
    /// and falls at `A/(4τ)`: its tangent there reaches zero at `t0 + 2τ`.
    fn logistic(start: f64, n: usize) -> (Vec<f64>, Vec<f64>, Vec<f64>) {
        let (rate, t0, tau, a) = (100.0, 0.5, 0.03, 3.0);
        let t: Vec<f64> = (0..n).map(|i| start + i as f64 / rate).collect();
        let s: Vec<f64> = t
            .iter()
            .map(|t| a / (1.0 + ((t - t0) / tau).exp()))
            .collect();
        let ds: Vec<f64> = t
            .iter()
            .map(|t| {
                let e = ((t - t0) / tau).exp();
                -a * e / (tau * (1.0 + e) * (1.0 + e))
            })
            .collect();
        (t, s, ds)
    }

    #[test]
    fn the_tangent_at_the_steepest_descent_reaches_zero_at_t0_plus_two_tau() {
        let (t, s, ds) = logistic(0.0, 120);
        let hs = tangent_onset(&t, 100.0, &s, &ds, 0, 119).unwrap();
        assert!((hs - 0.56).abs() < 1e-3, "{hs}");
        // A record starting three frames before the steepest point still times it.
        let (t, s, ds) = logistic(0.47, 60);
        let hs = tangent_onset(&t, 100.0, &s, &ds, 0, 59).unwrap();
        assert!((hs - 0.56).abs() < 1e-3, "{hs}");
        // One that starts after it does not (the steepest point is not in the record).
        let (t, s, ds) = logistic(0.52, 60);
        assert_eq!(tangent_onset(&t, 100.0, &s, &ds, 0, 59), None);
    }

    #[test]
    fn a_heel_at_rest_has_no_landing() {
        let t: Vec<f64> = (0..50).map(|i| i as f64 / 100.0).collect();
        let s = vec![0.02; 50];
        let ds = vec![0.0; 50];
        assert_eq!(tangent_onset(&t, 100.0, &s, &ds, 0, 49), None);
    }
}
