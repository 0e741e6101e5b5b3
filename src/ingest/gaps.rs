//! Missing marker samples: detection, reporting and filling of short gaps.
//!
//! A sample is missing when any coordinate is `NaN` (an empty cell in a TRC file, a C3D residual
//! of −1) or when all three coordinates are exactly zero (how several systems write an occluded
//! marker). Every reader calls [`fill_gaps`] once and appends [`GapReport::note`] to the trial's
//! notes.
//!
//! Filling: a gap of at most [`GapFill::max_gap_s`] (default 0.1 s: 10 frames at 100 Hz, 15 at
//! 150 Hz) that has valid samples on both sides is filled by a cubic Hermite segment whose end
//! values and slopes match the trajectory (slopes from the one-sided difference just outside the
//! gap), i.e. a C¹ cubic spline across the gap; where one neighbour beyond the edge is itself
//! missing the slope is unknown and the gap is filled linearly. Gaps touching the first or last
//! frame are never extrapolated, and longer gaps stay `NaN`.
use super::types::MarkerSet;
use serde::{Deserialize, Serialize};

/// How short gaps are filled.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
pub enum FillMethod {
    /// Cubic Hermite across the gap, matching position and slope at both edges (linear where a
    /// slope cannot be estimated).
    Cubic,
    /// Straight line between the last sample before and the first after the gap.
    Linear,
    /// Report gaps but leave them `NaN`.
    None,
}

impl FillMethod {
    /// A short name for notes.
    pub fn as_str(self) -> &'static str {
        match self {
            FillMethod::Cubic => "cubic Hermite",
            FillMethod::Linear => "linear",
            FillMethod::None => "not filled",
        }
    }
}

/// Gap-filling settings.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct GapFill {
    /// The method.
    pub method: FillMethod,
    /// The longest gap that is filled, s. Converted to frames as ⌊max_gap_s · rate⌋.
    pub max_gap_s: f64,
}

impl Default for GapFill {
    fn default() -> Self {
        GapFill {
            method: FillMethod::Cubic,
            max_gap_s: 0.1,
        }
    }
}

impl GapFill {
    /// The longest fillable gap in frames at `rate_hz`.
    pub fn max_frames(&self, rate_hz: f64) -> usize {
        if !(rate_hz.is_finite() && rate_hz > 0.0 && self.max_gap_s > 0.0) {
            return 0;
        }
        (self.max_gap_s * rate_hz + 1e-9).floor() as usize
    }
}

/// A run of missing frames `[start, start + len)` (0-based frame indices).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
pub struct Gap {
    /// First missing frame (0-based).
    pub start: usize,
    /// Number of missing frames.
    pub len: usize,
    /// True when the gap was filled.
    pub filled: bool,
}

/// The gaps of one marker.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct GapReport {
    /// The marker.
    pub marker: String,
    /// Number of frames of the trial.
    pub frames: usize,
    /// The gaps, in order.
    pub gaps: Vec<Gap>,
}

impl GapReport {
    /// Missing frames before filling.
    pub fn missing(&self) -> usize {
        self.gaps.iter().map(|g| g.len).sum()
    }
    /// Frames filled.
    pub fn filled(&self) -> usize {
        self.gaps.iter().filter(|g| g.filled).map(|g| g.len).sum()
    }
    /// The longest gap, frames.
    pub fn longest(&self) -> usize {
        self.gaps.iter().map(|g| g.len).max().unwrap_or(0)
    }
    /// A one-line note: marker, missing count, longest gap, frames (1-based), what was filled.
    pub fn note(&self, fill: &GapFill, max_frames: usize) -> String {
        let ranges: Vec<String> = self
            .gaps
            .iter()
            .take(8)
            .map(|g| {
                let (a, b) = (g.start + 1, g.start + g.len);
                let tag = if g.filled { "" } else { " NaN" };
                if a == b {
                    format!("{a}{tag}")
                } else {
                    format!("{a}–{b}{tag}")
                }
            })
            .collect();
        let more = if self.gaps.len() > 8 {
            format!(", … ({} gaps in all)", self.gaps.len())
        } else {
            String::new()
        };
        if self.missing() == self.frames {
            return format!(
                "marker {}: missing in all {} frames",
                self.marker, self.frames
            );
        }
        format!(
            "marker {}: {} of {} frames missing in {} gap(s), longest {} frames (frames {}{}); \
             {} filled ({}, gaps ≤ {} frames / {} s), {} left NaN",
            self.marker,
            self.missing(),
            self.frames,
            self.gaps.len(),
            self.longest(),
            ranges.join(", "),
            more,
            self.filled(),
            fill.method.as_str(),
            max_frames,
            fill.max_gap_s,
            self.missing() - self.filled()
        )
    }
}

/// True when the sample is missing (any NaN, or exactly (0, 0, 0)).
#[inline]
pub fn is_missing(p: &[f64; 3]) -> bool {
    p.iter().any(|v| v.is_nan()) || (p[0] == 0.0 && p[1] == 0.0 && p[2] == 0.0)
}

/// The runs of missing samples of one trajectory.
pub fn find_gaps(traj: &[[f64; 3]]) -> Vec<Gap> {
    let mut gaps = Vec::new();
    let mut i = 0;
    while i < traj.len() {
        if is_missing(&traj[i]) {
            let start = i;
            while i < traj.len() && is_missing(&traj[i]) {
                i += 1;
            }
            gaps.push(Gap {
                start,
                len: i - start,
                filled: false,
            });
        } else {
            i += 1;
        }
    }
    gaps
}

/// Sets every missing sample to `NaN`, fills the short gaps of every marker, and returns one
/// report per marker that had any gap (markers without gaps are not listed).
pub fn fill_gaps(markers: &mut MarkerSet, fill: &GapFill) -> Vec<GapReport> {
    let max_frames = fill.max_frames(markers.rate_hz);
    let mut reports = Vec::new();
    for (name, traj) in markers.names.iter().zip(markers.positions.iter_mut()) {
        let mut gaps = find_gaps(traj);
        if gaps.is_empty() {
            continue;
        }
        for g in &mut gaps {
            for p in &mut traj[g.start..g.start + g.len] {
                *p = [f64::NAN; 3];
            }
            g.filled = fill_one(traj, g, max_frames, fill.method);
        }
        reports.push(GapReport {
            marker: name.clone(),
            frames: traj.len(),
            gaps,
        });
    }
    reports
}

/// Fills one gap in place if it is short enough and bounded on both sides.
fn fill_one(traj: &mut [[f64; 3]], g: &Gap, max_frames: usize, method: FillMethod) -> bool {
    if method == FillMethod::None || g.len > max_frames || g.start == 0 {
        return false;
    }
    let a = g.start - 1; // last valid before
    let b = g.start + g.len; // first valid after
    if b >= traj.len() {
        return false;
    }
    let h = (b - a) as f64;
    // Slopes per frame from one-sided differences just outside the gap, when available.
    let slope_a = (a >= 1 && !is_missing(&traj[a - 1]))
        .then(|| [0, 1, 2].map(|k| traj[a][k] - traj[a - 1][k]));
    let slope_b = (b + 1 < traj.len() && !is_missing(&traj[b + 1]))
        .then(|| [0, 1, 2].map(|k| traj[b + 1][k] - traj[b][k]));
    let (pa, pb) = (traj[a], traj[b]);
    for (i, p) in traj.iter_mut().enumerate().take(b).skip(g.start) {
        let s = (i - a) as f64 / h;
        *p = match (method, slope_a, slope_b) {
            (FillMethod::Cubic, Some(ma), Some(mb)) => {
                let (s2, s3) = (s * s, s * s * s);
                let h00 = 2.0 * s3 - 3.0 * s2 + 1.0;
                let h10 = s3 - 2.0 * s2 + s;
                let h01 = -2.0 * s3 + 3.0 * s2;
                let h11 = s3 - s2;
                [0, 1, 2].map(|k| h00 * pa[k] + h10 * h * ma[k] + h01 * pb[k] + h11 * h * mb[k])
            }
            _ => [0, 1, 2].map(|k| pa[k] + s * (pb[k] - pa[k])),
        };
    }
    true
}

/// Notes for a set of reports (one line per marker with gaps), or a single "no gaps" line.
pub fn notes(reports: &[GapReport], fill: &GapFill, rate_hz: f64) -> Vec<String> {
    let max_frames = fill.max_frames(rate_hz);
    if reports.is_empty() {
        return vec!["markers: no missing samples".to_string()];
    }
    reports.iter().map(|r| r.note(fill, max_frames)).collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    fn set(traj: Vec<[f64; 3]>, rate: f64) -> MarkerSet {
        MarkerSet {
            rate_hz: rate,
            time_s: (0..traj.len()).map(|i| i as f64 / rate).collect(),
            names: vec!["M".into()],
            positions: vec![traj],
        }
    }

    #[test]
    fn cubic_fill_reproduces_a_cubic_and_linear_a_line() {
        // x(t) = t³ is reproduced exactly only by a scheme with exact slopes; with one-sided
        // differences a quadratic-free line must be exact for both methods.
        let line: Vec<[f64; 3]> = (0..30)
            .map(|i| [i as f64 * 0.01, 1.0, -2.0 + 0.5 * i as f64])
            .collect();
        for method in [FillMethod::Cubic, FillMethod::Linear] {
            let mut t = line.clone();
            for p in &mut t[10..15] {
                *p = [f64::NAN; 3];
            }
            let mut m = set(t, 100.0);
            let r = fill_gaps(
                &mut m,
                &GapFill {
                    method,
                    max_gap_s: 0.1,
                },
            );
            assert_eq!(r.len(), 1);
            assert_eq!(r[0].filled(), 5);
            for (a, b) in m.positions[0].iter().zip(&line) {
                for k in 0..3 {
                    assert!((a[k] - b[k]).abs() < 1e-12);
                }
            }
        }
    }

    #[test]
    fn cubic_fill_is_close_on_a_smooth_curve() {
        let f = |i: usize| (i as f64 * 0.1).sin();
        let truth: Vec<[f64; 3]> = (0..60).map(|i| [f(i), 0.5, 0.5]).collect();
        let mut t = truth.clone();
        for p in &mut t[20..28] {
            *p = [0.0; 3]; // zeros mean missing
        }
        let mut m = set(t, 100.0);
        fill_gaps(&mut m, &GapFill::default());
        let err = (20..28)
            .map(|i| (m.positions[0][i][0] - truth[i][0]).abs())
            .fold(0.0, f64::max);
        assert!(err < 0.01, "max error {err}");
    }

    #[test]
    fn long_and_edge_gaps_stay_nan() {
        let mut t: Vec<[f64; 3]> = (0..50).map(|i| [i as f64, 1.0, 1.0]).collect();
        t[0] = [f64::NAN; 3];
        for p in &mut t[10..25] {
            *p = [f64::NAN; 3];
        }
        t[49] = [f64::NAN; 3];
        let mut m = set(t, 100.0);
        let r = fill_gaps(&mut m, &GapFill::default());
        assert_eq!(r[0].gaps.len(), 3);
        assert_eq!(r[0].longest(), 15);
        assert_eq!(r[0].filled(), 0);
        assert!(m.positions[0][0][0].is_nan());
        assert!(m.positions[0][12][1].is_nan());
        let note = r[0].note(&GapFill::default(), 10);
        assert!(note.contains("17 of 50"), "{note}");
        assert!(note.contains("11–25 NaN"), "{note}");
    }

    #[test]
    fn max_frames_follows_rate() {
        let f = GapFill::default();
        assert_eq!(f.max_frames(100.0), 10);
        assert_eq!(f.max_frames(150.0), 15);
        assert_eq!(f.max_frames(69.9), 6);
        assert_eq!(f.max_frames(f64::NAN), 0);
    }
}
