//! The finer stance phases of Ko & Badler (1993) §3 from the foot markers, and the foot and knee
//! angles their μ-functions (appendix A) take as inputs.
//!
//! Within each stance (a heel strike and the same foot's next toe off, from the primary event
//! source), each foot marker's *flat level* is its lowest height during that stance. Then:
//! - foot flat (FGM): the metatarsal marker first comes within `height_tol_m` of its flat level;
//! - heel off: the heel marker last leaves its flat level (+ tolerance) before toe off;
//! - meta off (MOM): the metatarsal marker last leaves its flat level before toe off;
//! - toe off (TOM): the toe marker leaves its flat level (only when the toe marker is distinct
//!   from the metatarsal marker), searched up to 0.15 s after the primary toe off.
//!
//! Crossings are interpolated linearly between frames. The default tolerance is 1 cm: large
//! enough for marker noise after the 6 Hz filter, small against the 3–6 cm the heel rises before
//! toe off.
//!
//! Angles (sagittal plane: forward and vertical axes, radians):
//! - foot-sole angle: of the heel→metatarsal line to the floor, less its value during foot flat
//!   (the markers sit at different heights above the sole). At heel strike it is reported
//!   positive toes-up; at toe off positive heel-up, so both grow with step length as the paper's
//!   α2, α3 > 0 require.
//! - meta angle: of the metatarsal→toe line, less its flat value, positive with the metatarsal
//!   heads above the toe tip (the toes bent, the paper's "angle between the floor and the toes").
//! - knee angle: flexion between the thigh (hip→knee) and the shank (knee→ankle); 0 straight.
use super::kinematic::Kinematics;
use super::{EventKind, EventSource, GaitEvent, Side};
use serde::{Deserialize, Serialize};

/// Phase-detection settings.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct PhaseOptions {
    /// Height above a marker's flat level that counts as off the ground, m (default 0.01).
    pub height_tol_m: f64,
}

impl Default for PhaseOptions {
    fn default() -> Self {
        PhaseOptions { height_tol_m: 0.01 }
    }
}

/// The stances `(side, heel strike, toe off)` in `events`: each heel strike paired with the next
/// toe off of the same foot before that foot's next heel strike.
pub fn stances(events: &[GaitEvent]) -> Vec<(Side, f64, f64)> {
    let mut out = Vec::new();
    for side in [Side::Left, Side::Right] {
        let mut ev: Vec<&GaitEvent> = events.iter().filter(|e| e.side == side).collect();
        ev.sort_by(|a, b| a.time_s.total_cmp(&b.time_s));
        for (i, e) in ev.iter().enumerate() {
            if e.kind != EventKind::HeelStrike {
                continue;
            }
            if let Some(next) = ev[i + 1..]
                .iter()
                .find(|x| x.kind == EventKind::HeelStrike || x.kind == EventKind::ToeOff)
            {
                if next.kind == EventKind::ToeOff {
                    out.push((side, e.time_s, next.time_s));
                }
            }
        }
    }
    out.sort_by(|a, b| a.1.total_cmp(&b.1));
    out
}

/// Heights of a marker per frame.
fn heights(k: &Kinematics, m: &[[f64; 3]]) -> Vec<f64> {
    m.iter().map(|p| k.up(p)).collect()
}

/// Frames `[a, b]` covering times `[t0, t1]`.
fn frames(k: &Kinematics, t0: f64, t1: f64) -> (usize, usize) {
    (k.frame_at(t0), k.frame_at(t1))
}

fn crossing_time(k: &Kinematics, h: &[f64], i: usize, level: f64) -> f64 {
    // Between frames i and i+1.
    let (a, b) = (h[i], h[i + 1]);
    let w = if (b - a).abs() < 1e-12 {
        0.0
    } else {
        ((level - a) / (b - a)).clamp(0.0, 1.0)
    };
    k.time_s[i] + w / k.rate_hz
}

/// First time in `[a, b]` the height comes down to `level` (None if never, or already there at
/// `a`).
fn first_down(k: &Kinematics, h: &[f64], a: usize, b: usize, level: f64) -> Option<f64> {
    if h[a] <= level {
        return Some(k.time_s[a]);
    }
    (a..b)
        .find(|&i| h[i] > level && h[i + 1] <= level)
        .map(|i| crossing_time(k, h, i, level))
}

/// Last time in `[a, b]` the height rises above `level` after being at or below it.
fn last_up(k: &Kinematics, h: &[f64], a: usize, b: usize, level: f64) -> Option<f64> {
    (a..b)
        .rev()
        .find(|&i| h[i] <= level && h[i + 1] > level)
        .map(|i| crossing_time(k, h, i, level))
}

/// Foot flat, heel off, meta off and (with a distinct toe marker) toe off for every stance of
/// `primary`.
pub fn detect(k: &Kinematics, primary: &[GaitEvent], opts: &PhaseOptions) -> Vec<GaitEvent> {
    let mut out = Vec::new();
    let n = k.time_s.len();
    if n < 3 {
        return out;
    }
    for (side, hs, to) in stances(primary) {
        let l = k.leg(side);
        let (a, b) = frames(k, hs, to);
        if b <= a + 2 || hs < k.time_s[0] || to > k.time_s[n - 1] {
            continue;
        }
        let tol = opts.height_tol_m;
        let mut push = |t: Option<f64>, kind| {
            if let Some(t) = t {
                out.push(GaitEvent {
                    time_s: t,
                    side,
                    kind,
                    source: EventSource::FootMarkers,
                });
            }
        };
        let flat = |h: &[f64]| h[a..=b].iter().copied().fold(f64::INFINITY, f64::min);
        let front = l.meta.as_ref().or(l.toe.as_ref());
        if let Some(m) = front {
            let h = heights(k, m);
            let lv = flat(&h) + tol;
            push(first_down(k, &h, a, b, lv), EventKind::FootFlat);
            push(last_up(k, &h, a, b, lv), EventKind::MetaOff);
        }
        if let Some(heel) = &l.heel {
            let h = heights(k, heel);
            let lv = flat(&h) + tol;
            push(last_up(k, &h, a, b, lv), EventKind::HeelOff);
        }
        let distinct_toe = !l.names.toe.is_empty() && l.names.toe != l.names.meta;
        if let (Some(toe), true) = (&l.toe, distinct_toe) {
            let h = heights(k, toe);
            let lv = flat(&h) + tol;
            let b2 = k.frame_at(to + 0.15).min(n - 1);
            push(last_up(k, &h, a, b2, lv), EventKind::ToeOff);
        }
    }
    out.sort_by(|x, y| x.time_s.total_cmp(&y.time_s));
    out
}

/// Initial contact and toe off from the foot-marker heights, seeded by kinematic stances (the
/// Zeni events): for each seed stance, every foot marker's flat level is its lowest height
/// during the stance; initial contact is the first time, from 0.15 s before the seed heel
/// strike, that the heel or the metatarsal/toe marker (whichever lands first: heel strikers
/// and forefoot strikers alike) comes down to its flat level + `height_tol_m`; toe off is the
/// last time before 0.15 s after the seed toe off that the toe (else metatarsal) marker rises
/// through its flat level + tolerance. Unlike the pelvis-relative extrema of Zeni et al., this
/// looks at the foot touching the floor itself, which is what a force plate sees.
pub fn foot_contact_events(
    k: &Kinematics,
    seeds: &[GaitEvent],
    opts: &PhaseOptions,
) -> Vec<GaitEvent> {
    let mut out = Vec::new();
    let n = k.time_s.len();
    if n < 3 {
        return out;
    }
    let tol = opts.height_tol_m;
    for (side, hs, to) in stances(seeds) {
        let l = k.leg(side);
        let (a, b) = frames(k, hs, to);
        if b <= a + 2 {
            continue;
        }
        let a0 = k.frame_at(hs - 0.15);
        let b2 = k.frame_at(to + 0.15).min(n - 1);
        let flat = |h: &[f64]| h[a..=b].iter().copied().fold(f64::INFINITY, f64::min);
        let mut contact: Option<f64> = None;
        let front = l.meta.as_ref().or(l.toe.as_ref());
        for m in [l.heel.as_ref(), front].into_iter().flatten() {
            let h = heights(k, m);
            let lv = flat(&h) + tol;
            // Only a real descent counts: the marker must be above the level at the window start.
            if h[a0] > lv {
                if let Some(t) = first_down(k, &h, a0, b, lv) {
                    contact = Some(contact.map_or(t, |c: f64| c.min(t)));
                }
            }
        }
        if let Some(t) = contact {
            out.push(GaitEvent {
                time_s: t,
                side,
                kind: EventKind::HeelStrike,
                source: EventSource::FootMarkers,
            });
        }
        if let Some(m) = l.toe.as_ref().or(l.meta.as_ref()) {
            let h = heights(k, m);
            let lv = flat(&h) + tol;
            if h[b2] > lv {
                if let Some(t) = last_up(k, &h, a, b2, lv) {
                    out.push(GaitEvent {
                        time_s: t,
                        side,
                        kind: EventKind::ToeOff,
                        source: EventSource::FootMarkers,
                    });
                }
            }
        }
    }
    out.sort_by(|x, y| x.time_s.total_cmp(&y.time_s));
    out
}

/// Sagittal 2-D coordinates `(forward, up)` of a point.
fn sag(k: &Kinematics, p: &[f64; 3]) -> (f64, f64) {
    (k.fwd(p), k.up(p))
}

/// Angle of the line `from → to` above the floor, rad (positive when `to` is higher).
fn incline(k: &Kinematics, from: &[f64; 3], to: &[f64; 3]) -> f64 {
    let (x0, y0) = sag(k, from);
    let (x1, y1) = sag(k, to);
    (y1 - y0).atan2((x1 - x0).abs())
}

/// The Ko–Badler μ inputs of one stance, rad; `None` where the markers do not allow it.
#[derive(Debug, Clone, Copy, PartialEq, Default, Serialize, Deserialize)]
pub struct MuInputs {
    /// μ1: knee flexion at heel strike.
    pub knee_hs: Option<f64>,
    /// μ2: foot-sole angle at heel strike (toes up positive).
    pub foot_hs: Option<f64>,
    /// μ3: foot-sole angle at toe off (heel up positive).
    pub foot_to: Option<f64>,
    /// μ4: meta (toe) angle at toe off (metatarsal heads above the toe tip positive).
    pub meta_to: Option<f64>,
}

/// The μ inputs of the stance `(side, hs, to)`; the flat references are the medians over the
/// middle of stance (30–50 % of the heel strike → toe off interval, when the foot is flat in
/// walking and running alike).
pub fn mu_inputs(k: &Kinematics, side: Side, hs: f64, to: f64) -> MuInputs {
    let l = k.leg(side);
    let mut mu = MuInputs::default();
    let n = k.time_s.len();
    if n < 2 || hs < k.time_s[0] || to > k.time_s[n - 1] || to <= hs {
        return mu;
    }
    let median_over = |f: &dyn Fn(usize) -> f64| -> Option<f64> {
        let (a, b) = frames(k, hs + 0.3 * (to - hs), hs + 0.5 * (to - hs));
        let mut v: Vec<f64> = (a..=b).map(f).filter(|x| x.is_finite()).collect();
        if v.is_empty() {
            return None;
        }
        v.sort_by(f64::total_cmp);
        Some(v[v.len() / 2])
    };
    if let (Some(heel), Some(meta)) = (&l.heel, &l.meta) {
        let sole = |i: usize| incline(k, &heel[i], &meta[i]);
        if let Some(flat) = median_over(&sole) {
            let at = |t: f64| -> Option<f64> {
                let h = k.sample3(heel, t)?;
                let m = k.sample3(meta, t)?;
                Some(incline(k, &h, &m))
            };
            mu.foot_hs = at(hs).map(|a| a - flat);
            mu.foot_to = at(to).map(|a| flat - a);
        }
    }
    let distinct_toe = !l.names.toe.is_empty() && l.names.toe != l.names.meta;
    if let (Some(meta), Some(toe), true) = (&l.meta, &l.toe, distinct_toe) {
        let toes = |i: usize| incline(k, &toe[i], &meta[i]);
        if let Some(flat) = median_over(&toes) {
            if let (Some(m), Some(t)) = (k.sample3(meta, to), k.sample3(toe, to)) {
                mu.meta_to = Some(incline(k, &t, &m) - flat);
            }
        }
    }
    if let (Some(hip), Some(knee), Some(ankle)) = (&l.hip, &l.knee, &l.ankle) {
        if let (Some(h), Some(kn), Some(an)) = (
            k.sample3(hip, hs),
            k.sample3(knee, hs),
            k.sample3(ankle, hs),
        ) {
            let (hx, hy) = sag(k, &h);
            let (kx, ky) = sag(k, &kn);
            let (ax, ay) = sag(k, &an);
            let (ux, uy) = (kx - hx, ky - hy);
            let (wx, wy) = (ax - kx, ay - ky);
            let cross = ux * wy - uy * wx;
            let dot = ux * wx + uy * wy;
            mu.knee_hs = Some((-cross).atan2(dot));
        }
    }
    mu
}

#[cfg(test)]
mod tests {
    use super::*;

    fn ev(t: f64, side: Side, kind: EventKind) -> GaitEvent {
        GaitEvent {
            time_s: t,
            side,
            kind,
            source: EventSource::Force,
        }
    }

    #[test]
    fn stances_pair_heel_strike_with_next_toe_off() {
        let e = vec![
            ev(0.1, Side::Right, EventKind::ToeOff),
            ev(0.2, Side::Right, EventKind::HeelStrike),
            ev(0.8, Side::Right, EventKind::ToeOff),
            ev(1.2, Side::Right, EventKind::HeelStrike),
            ev(0.7, Side::Left, EventKind::HeelStrike),
            ev(1.3, Side::Left, EventKind::ToeOff),
        ];
        let s = stances(&e);
        assert_eq!(s, vec![(Side::Right, 0.2, 0.8), (Side::Left, 0.7, 1.3)]);
    }
}
