//! Which laboratory axis is vertical and which way the subject walks, from the data.
//!
//! Nothing is rotated: the data stay in the file's frame, and a [`LabFrame`] says which axis is
//! up and which is the direction of progression. Cues, in order of trust:
//! 1. the user's [`ReadOptions`](super::ReadOptions) (`vertical`, `forward`);
//! 2. marker names: the pelvis (ASIS/PSIS/hip joint centre/trochanter) lies ~0.5–1 m above the
//!    feet (heel/toe/metatarsal/ankle) along the vertical; the subject progresses along the axis
//!    of the pelvis's horizontal displacement (overground, > 0.5 m over the trial), or, when the
//!    pelvis barely moves (treadmill, standing), toward where the toes point from the heels;
//! 3. force plates: the vertical axis carries the largest mean |force| (body weight) and its sign
//!    is that of the mean; along the walking direction the horizontal force brakes in the first
//!    half of every stance and propels in the second (it increases through stance, on a
//!    treadmill as overground), and it is larger than the medio-lateral force.
//!
//! A laboratory frame is assumed right-handed when the lateral direction is derived
//! ([`right_axis`]).
use super::types::{Axis, ForcePlate, LabFrame, MarkerSet};

const AXES: [Axis; 3] = [Axis::X, Axis::Y, Axis::Z];

/// A detected vertical or forward direction, with how it was found.
#[derive(Debug, Clone, PartialEq)]
pub struct Direction {
    /// The axis.
    pub axis: Axis,
    /// +1 or −1.
    pub sign: f64,
    /// How it was found, for the notes.
    pub how: String,
}

fn contains_any(name: &str, keys: &[&str]) -> bool {
    let n = name.to_ascii_uppercase();
    keys.iter().any(|k| n.contains(k))
}

/// Marker names that belong to the pelvis.
pub fn is_pelvis_marker(name: &str) -> bool {
    contains_any(
        name,
        &[
            "ASI", "PSI", "IAS", "IPS", "HJC", "HIP", "GTR", "FTC", "TROCH", "PELV", "SAC", "ILIAC",
        ],
    )
}

/// Marker names that belong to a foot.
pub fn is_foot_marker(name: &str) -> bool {
    contains_any(
        name,
        &[
            "HEE", "CAL", "FCC", "TOE", "MT", "FM1", "FM2", "FM5", "MET", "BALL", "ANK", "MAL",
            "AJC", "FAL", "TAM",
        ],
    )
}

fn is_heel(name: &str) -> bool {
    contains_any(name, &["HEE", "CAL", "FCC"])
}
fn is_toe(name: &str) -> bool {
    contains_any(name, &["TOE", "MT1", "MT2", "FM1", "FM2", "MET", "BALL"])
        && !contains_any(name, &["STATIC"])
}

/// Side of a marker from its name prefix (`R.`, `R_`, `RHEE`, `RIGHT …`, `L…`).
fn side_of(name: &str) -> Option<char> {
    let n = name.trim().to_ascii_uppercase();
    if n.starts_with("RIGHT") || n.starts_with('R') {
        Some('R')
    } else if n.starts_with("LEFT") || n.starts_with('L') {
        Some('L')
    } else {
        None
    }
}

/// Mean position over frames and over the markers selected by `pick` (NaN samples skipped).
fn mean_of(m: &MarkerSet, pick: impl Fn(&str) -> bool) -> Option<[f64; 3]> {
    let mut s = [0.0; 3];
    let mut n = 0usize;
    for (name, traj) in m.names.iter().zip(&m.positions) {
        if !pick(name) {
            continue;
        }
        for p in traj {
            if p.iter().all(|v| v.is_finite()) {
                for k in 0..3 {
                    s[k] += p[k];
                }
                n += 1;
            }
        }
    }
    (n > 0).then(|| s.map(|v| v / n as f64))
}

fn argmax_abs(d: &[f64; 3], skip: Option<Axis>) -> (Axis, f64, f64) {
    // Returns (axis, value, second largest |value|).
    let mut idx: Vec<usize> = (0..3).filter(|&k| Some(AXES[k]) != skip).collect();
    idx.sort_by(|&a, &b| d[b].abs().total_cmp(&d[a].abs()));
    let second = idx.get(1).map_or(0.0, |&k| d[k].abs());
    (AXES[idx[0]], d[idx[0]], second)
}

/// The vertical from marker names (pelvis above feet). `None` when the names do not tell.
pub fn vertical_from_markers(m: &MarkerSet) -> Option<Direction> {
    let pelvis = mean_of(m, is_pelvis_marker)?;
    let feet = mean_of(m, |n| is_foot_marker(n) && !is_pelvis_marker(n))?;
    let d = [0, 1, 2].map(|k| pelvis[k] - feet[k]);
    let (axis, v, second) = argmax_abs(&d, None);
    // A pelvis ≥ 0.3 m above the feet and clearly more than any horizontal offset.
    if v.abs() < 0.3 || v.abs() < 2.0 * second {
        return None;
    }
    Some(Direction {
        axis,
        sign: v.signum(),
        how: format!(
            "vertical = {}{:?} from marker names (pelvis markers {:.2} m above foot markers)",
            sign_str(v),
            axis,
            v.abs()
        ),
    })
}

/// The vertical as the axis of largest marker spread, sign assumed positive. A weak fallback for
/// files whose marker names are unknown.
pub fn vertical_from_spread(m: &MarkerSet) -> Option<Direction> {
    let n = m.len();
    if n == 0 || m.positions.is_empty() {
        return None;
    }
    let mut spread = [0.0f64; 3];
    let mut frames = 0usize;
    for f in (0..n).step_by((n / 50).max(1)) {
        let mut lo = [f64::INFINITY; 3];
        let mut hi = [f64::NEG_INFINITY; 3];
        for traj in &m.positions {
            let p = traj[f];
            if p.iter().all(|v| v.is_finite()) {
                for k in 0..3 {
                    lo[k] = lo[k].min(p[k]);
                    hi[k] = hi[k].max(p[k]);
                }
            }
        }
        if hi[0] >= lo[0] {
            for k in 0..3 {
                spread[k] += hi[k] - lo[k];
            }
            frames += 1;
        }
    }
    if frames == 0 {
        return None;
    }
    let (axis, _, _) = argmax_abs(&spread, None);
    Some(Direction {
        axis,
        sign: 1.0,
        how: format!(
            "vertical = +{axis:?} as the axis of largest marker spread (marker names not \
             recognised; sign assumed +)"
        ),
    })
}

/// The walking direction from markers: pelvis displacement if it exceeds 0.5 m, else the
/// heel→toe direction of the feet.
pub fn forward_from_markers(m: &MarkerSet, vertical: Axis) -> Option<Direction> {
    // Pelvis (or all-marker) centroid displacement between the first and last frames where it is
    // known.
    let centroid = |f: usize, pick: &dyn Fn(&str) -> bool| -> Option<[f64; 3]> {
        let mut s = [0.0; 3];
        let mut c = 0usize;
        for (name, traj) in m.names.iter().zip(&m.positions) {
            if pick(name) && traj[f].iter().all(|v| v.is_finite()) {
                for k in 0..3 {
                    s[k] += traj[f][k];
                }
                c += 1;
            }
        }
        (c > 0).then(|| s.map(|v| v / c as f64))
    };
    let n = m.len();
    let has_pelvis = m.names.iter().any(|n| is_pelvis_marker(n));
    let pick: &dyn Fn(&str) -> bool = if has_pelvis {
        &is_pelvis_marker
    } else {
        &|_| true
    };
    let first = (0..n).find_map(|f| centroid(f, pick));
    let last = (0..n).rev().find_map(|f| centroid(f, pick));
    if let (Some(a), Some(b)) = (first, last) {
        let mut d = [0, 1, 2].map(|k| b[k] - a[k]);
        d[vertical.index()] = 0.0;
        let (axis, v, _) = argmax_abs(&d, Some(vertical));
        if v.abs() > 0.5 {
            return Some(Direction {
                axis,
                sign: v.signum(),
                how: format!(
                    "forward = {}{axis:?} from the {} displacement ({:.2} m over the trial)",
                    sign_str(v),
                    if has_pelvis {
                        "pelvis"
                    } else {
                        "marker centroid"
                    },
                    v.abs()
                ),
            });
        }
    }
    // Heel → toe direction, averaged over both feet and all frames.
    let mut d = [0.0; 3];
    let mut pairs = 0;
    for side in ['R', 'L'] {
        let heel = mean_of(m, |n| is_heel(n) && side_of(n) == Some(side));
        let toe = mean_of(m, |n| is_toe(n) && side_of(n) == Some(side));
        if let (Some(h), Some(t)) = (heel, toe) {
            for k in 0..3 {
                d[k] += t[k] - h[k];
            }
            pairs += 1;
        }
    }
    if pairs == 0 {
        return None;
    }
    d[vertical.index()] = 0.0;
    let (axis, v, second) = argmax_abs(&d, Some(vertical));
    if v.abs() < 0.05 || v.abs() < 1.5 * second {
        return None;
    }
    Some(Direction {
        axis,
        sign: v.signum(),
        how: format!(
            "forward = {}{axis:?} from the heel→toe direction of the feet ({:.2} m; the pelvis \
             moved < 0.5 m: treadmill or standing)",
            sign_str(v),
            v.abs() / pairs as f64
        ),
    })
}

/// The vertical from force plates: the axis of largest mean |force|, sign of the mean.
pub fn vertical_from_plates(plates: &[ForcePlate]) -> Option<Direction> {
    let mut s = [0.0; 3];
    let mut n = 0usize;
    for p in plates {
        for f in &p.force_n {
            if f.iter().all(|v| v.is_finite()) {
                for k in 0..3 {
                    s[k] += f[k];
                }
                n += 1;
            }
        }
    }
    if n == 0 {
        return None;
    }
    let m = s.map(|v| v / n as f64);
    let (axis, v, second) = argmax_abs(&m, None);
    if v.abs() < 5.0 || v.abs() < 2.0 * second {
        return None;
    }
    Some(Direction {
        axis,
        sign: v.signum(),
        how: format!(
            "vertical = {}{axis:?} from the force plates (largest mean force, {:.0} N)",
            sign_str(v),
            v.abs()
        ),
    })
}

/// Stance intervals `[start, end)` of one plate: vertical force above `threshold_n` for at least
/// `min_len` samples.
pub fn stances(
    p: &ForcePlate,
    vertical: Axis,
    sign: f64,
    threshold_n: f64,
    min_len: usize,
) -> Vec<(usize, usize)> {
    let v = vertical.index();
    let mut out = Vec::new();
    let mut start = None;
    for (i, f) in p.force_n.iter().enumerate() {
        let on = sign * f[v] > threshold_n;
        match (on, start) {
            (true, None) => start = Some(i),
            (false, Some(s)) => {
                if i - s >= min_len {
                    out.push((s, i));
                }
                start = None;
            }
            _ => {}
        }
    }
    if let Some(s) = start {
        if p.force_n.len() - s >= min_len {
            out.push((s, p.force_n.len()));
        }
    }
    out
}

/// The walking direction from the fore-aft force pattern (braking then propulsion) of complete
/// stance phases (those not cut by the start or end of the recording).
pub fn forward_from_plates(plates: &[ForcePlate], vertical: Direction) -> Option<Direction> {
    let horiz: Vec<usize> = (0..3).filter(|&k| k != vertical.axis.index()).collect();
    let mut power = [0.0; 3];
    let mut trend = [0.0; 3];
    let mut count = 0usize;
    for p in plates {
        let min_len = ((0.1 * p.rate_hz) as usize).max(3);
        for (a, b) in stances(p, vertical.axis, vertical.sign, 50.0, min_len) {
            if a == 0 || b == p.force_n.len() {
                continue;
            }
            count += 1;
            let mid = (a + b - 1) as f64 / 2.0;
            let half = (b - a) as f64 / 2.0;
            for &k in &horiz {
                let mut pw = 0.0;
                let mut tr = 0.0;
                for i in a..b {
                    let f = p.force_n[i][k];
                    pw += f * f;
                    tr += f * (i as f64 - mid) / half;
                }
                power[k] += pw / (b - a) as f64;
                trend[k] += tr / (b - a) as f64;
            }
        }
    }
    if count == 0 {
        return None;
    }
    let (axis, _, _) = argmax_abs(&power, Some(vertical.axis));
    let t = trend[axis.index()];
    if t == 0.0 {
        return None;
    }
    Some(Direction {
        axis,
        sign: t.signum(),
        how: format!(
            "forward = {}{axis:?} from the fore-aft force of {count} stance phase(s) (braking \
             then propulsion)",
            sign_str(t)
        ),
    })
}

fn sign_str(v: f64) -> &'static str {
    if v < 0.0 {
        "−"
    } else {
        "+"
    }
}

/// The lateral axis pointing to the subject's right, assuming a right-handed laboratory frame:
/// right = forward × up. Returns the axis and its sign.
pub fn right_axis(frame: &LabFrame) -> Option<(Axis, f64)> {
    let v = frame.vertical.index();
    let f = frame.forward.index();
    if v == f {
        return None;
    }
    let mut fwd = [0.0; 3];
    fwd[f] = frame.forward_sign;
    let mut up = [0.0; 3];
    up[v] = 1.0;
    let r = [
        fwd[1] * up[2] - fwd[2] * up[1],
        fwd[2] * up[0] - fwd[0] * up[2],
        fwd[0] * up[1] - fwd[1] * up[0],
    ];
    let k = (0..3).find(|&k| r[k] != 0.0)?;
    Some((AXES[k], r[k]))
}

/// Builds a frame from optional overrides and detected directions, with an explanation.
/// `Err` carries the reason when no vertical or forward direction could be established.
pub fn combine(
    vertical_override: Option<Axis>,
    forward_override: Option<(Axis, f64)>,
    vertical: Option<Direction>,
    forward: impl FnOnce(Direction) -> Option<Direction>,
) -> Result<LabFrame, String> {
    let v = match vertical_override {
        Some(axis) => Direction {
            axis,
            sign: 1.0,
            how: format!("vertical = +{axis:?} set by the user"),
        },
        None => vertical.ok_or("vertical axis not detected: set it explicitly")?,
    };
    let v_how = v.how.clone();
    let (v_axis, v_sign) = (v.axis, v.sign);
    let f = match forward_override {
        Some((axis, sign)) => Direction {
            axis,
            sign: if sign < 0.0 { -1.0 } else { 1.0 },
            how: format!("forward = {}{axis:?} set by the user", sign_str(sign)),
        },
        None => forward(v).ok_or("walking direction not detected: set it explicitly")?,
    };
    if f.axis == v_axis {
        return Err(format!(
            "the walking direction {:?} is the vertical axis: set them explicitly",
            f.axis
        ));
    }
    let mut how = format!("{v_how}; {}", f.how);
    if v_sign < 0.0 {
        how.push_str(&format!(
            "; note: up is −{v_axis:?} (the data are not flipped)"
        ));
    }
    Ok(LabFrame {
        vertical: v_axis,
        forward: f.axis,
        forward_sign: f.sign,
        how,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn right_axis_of_y_up_x_forward_is_z() {
        let f = LabFrame {
            vertical: Axis::Y,
            forward: Axis::X,
            forward_sign: 1.0,
            how: String::new(),
        };
        assert_eq!(right_axis(&f), Some((Axis::Z, 1.0)));
        let f = LabFrame {
            vertical: Axis::Z,
            forward: Axis::X,
            forward_sign: 1.0,
            how: String::new(),
        };
        assert_eq!(right_axis(&f), Some((Axis::Y, -1.0)));
    }

    #[test]
    fn markers_give_vertical_and_forward() {
        // Pelvis at 1 m on +Z, feet at 0.05 m; walking toward −Y by 2 m.
        let n = 50;
        let walk = |y0: f64, z: f64| -> Vec<[f64; 3]> {
            (0..n)
                .map(|i| [0.1, y0 - 2.0 * i as f64 / n as f64, z])
                .collect()
        };
        let m = MarkerSet {
            rate_hz: 100.0,
            time_s: (0..n).map(|i| i as f64 / 100.0).collect(),
            names: vec!["RASI".into(), "RHEE".into(), "RTOE".into()],
            positions: vec![walk(0.0, 1.0), walk(0.1, 0.05), walk(-0.1, 0.04)],
        };
        let v = vertical_from_markers(&m).unwrap();
        assert_eq!((v.axis, v.sign), (Axis::Z, 1.0));
        let f = forward_from_markers(&m, v.axis).unwrap();
        assert_eq!((f.axis, f.sign), (Axis::Y, -1.0));
    }

    #[test]
    fn plates_give_vertical_and_forward() {
        // One stance of 100 samples: Fy = 700 N up, Fz goes from −100 to +100 (braking then
        // propulsion toward +Z), Fx small.
        let mut force = vec![[0.0; 3]; 20];
        for i in 0..100 {
            let s = i as f64 / 99.0;
            force.push([10.0, 700.0, -100.0 + 200.0 * s]);
        }
        force.extend(vec![[0.0; 3]; 20]);
        let p = ForcePlate {
            name: "p".into(),
            rate_hz: 1000.0,
            time_s: (0..force.len()).map(|i| i as f64 / 1000.0).collect(),
            cop_m: vec![[f64::NAN; 3]; force.len()],
            force_n: force,
            free_moment_nm: vec![],
            side: None,
        };
        let v = vertical_from_plates(std::slice::from_ref(&p)).unwrap();
        assert_eq!((v.axis, v.sign), (Axis::Y, 1.0));
        let f = forward_from_plates(&[p], v).unwrap();
        assert_eq!((f.axis, f.sign), (Axis::Z, 1.0));
    }
}
