//! How well one event source agrees with another: detection F1 with a matching tolerance, and
//! the timing error (detected − reference, mean ± SD, ms) of the matched events, per event kind.
//!
//! Matching is one-to-one per foot and event kind: pairs closer than the tolerance (default
//! 60 ms, about a quarter of a running contact) are matched greedily, closest first.
//!
//! What can be judged depends on how complete the reference is:
//! - [`Coverage::Complete`]: the reference sees every contact (per-foot plates of a dual-belt
//!   treadmill or an OpenSim GRF file): every detected event inside the reference record counts;
//! - [`Coverage::Window`]: the reference marks every event within a window (a C3D's events):
//!   detected events outside `[first − tol, last + tol]` of that foot and kind are ignored;
//! - [`Coverage::MatchedOnly`]: the reference sees only some contacts (overground plates): an
//!   unmatched detected event may be a step beside the plates, so precision and F1 are not
//!   defined; the recall and the timing error are.
use super::{EventKind, GaitEvent, Side};
use serde::{Deserialize, Serialize};
use std::collections::BTreeMap;

/// Default matching tolerance, s.
pub const DEFAULT_TOLERANCE_S: f64 = 0.06;

/// How complete the reference events are.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
pub enum Coverage {
    /// Every event within `[start, end]` of the record (s).
    Complete,
    /// Every event between the first and the last reference event of each foot and kind.
    Window,
    /// Only some events (precision not assessable).
    MatchedOnly,
}

/// Match counts and timing errors of one event kind (one method, one reference).
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
pub struct KindCounts {
    /// Matched pairs.
    pub tp: usize,
    /// Detected events without a reference partner (counted only where assessable).
    pub fp: usize,
    /// Reference events without a detected partner.
    pub fn_: usize,
    /// Whether false positives could be assessed for every contribution.
    pub precision_assessable: bool,
    /// Timing errors of the matched pairs, detected − reference, s.
    pub errors_s: Vec<f64>,
}

impl KindCounts {
    /// Recall = tp / (tp + fn).
    pub fn recall(&self) -> Option<f64> {
        let d = self.tp + self.fn_;
        (d > 0).then(|| self.tp as f64 / d as f64)
    }
    /// Precision = tp / (tp + fp), when assessable.
    pub fn precision(&self) -> Option<f64> {
        let d = self.tp + self.fp;
        (self.precision_assessable && d > 0).then(|| self.tp as f64 / d as f64)
    }
    /// F1 = 2·tp / (2·tp + fp + fn), when precision is assessable.
    pub fn f1(&self) -> Option<f64> {
        let d = 2 * self.tp + self.fp + self.fn_;
        (self.precision_assessable && d > 0).then(|| 2.0 * self.tp as f64 / d as f64)
    }
    /// Mean timing error, ms.
    pub fn mean_ms(&self) -> Option<f64> {
        let n = self.errors_s.len();
        (n > 0).then(|| self.errors_s.iter().sum::<f64>() / n as f64 * 1000.0)
    }
    /// Sample standard deviation of the timing error, ms.
    pub fn sd_ms(&self) -> Option<f64> {
        let n = self.errors_s.len();
        if n < 2 {
            return None;
        }
        let m = self.errors_s.iter().sum::<f64>() / n as f64;
        let v = self.errors_s.iter().map(|e| (e - m) * (e - m)).sum::<f64>() / (n - 1) as f64;
        Some(v.sqrt() * 1000.0)
    }
    /// Adds another count.
    pub fn merge(&mut self, other: &KindCounts) {
        if self.tp + self.fp + self.fn_ == 0 && self.errors_s.is_empty() {
            self.precision_assessable = other.precision_assessable;
        } else {
            self.precision_assessable &= other.precision_assessable;
        }
        self.tp += other.tp;
        self.fp += other.fp;
        self.fn_ += other.fn_;
        self.errors_s.extend_from_slice(&other.errors_s);
    }
}

/// Compares `detected` with `reference` for every event kind present in the reference. `span`
/// is the time interval both sources cover (events outside it are ignored).
pub fn compare(
    detected: &[GaitEvent],
    reference: &[GaitEvent],
    coverage: Coverage,
    span: (f64, f64),
    tol_s: f64,
) -> BTreeMap<EventKind, KindCounts> {
    let mut out: BTreeMap<EventKind, KindCounts> = BTreeMap::new();
    let kinds: Vec<EventKind> = {
        let mut k: Vec<EventKind> = reference.iter().map(|e| e.kind).collect();
        k.sort();
        k.dedup();
        k
    };
    for kind in kinds {
        let counts = out.entry(kind).or_insert_with(|| KindCounts {
            precision_assessable: coverage != Coverage::MatchedOnly,
            ..KindCounts::default()
        });
        for side in [Side::Left, Side::Right] {
            let inside = |e: &&GaitEvent| {
                e.kind == kind && e.side == side && e.time_s >= span.0 && e.time_s <= span.1
            };
            let refs: Vec<f64> = reference.iter().filter(inside).map(|e| e.time_s).collect();
            let mut det: Vec<f64> = detected.iter().filter(inside).map(|e| e.time_s).collect();
            if coverage == Coverage::Window {
                if refs.is_empty() {
                    continue;
                }
                let lo = refs.iter().copied().fold(f64::INFINITY, f64::min) - tol_s;
                let hi = refs.iter().copied().fold(f64::NEG_INFINITY, f64::max) + tol_s;
                det.retain(|&t| t >= lo && t <= hi);
            }
            let mut pairs: Vec<(f64, usize, usize)> = Vec::new();
            for (i, &d) in det.iter().enumerate() {
                for (j, &r) in refs.iter().enumerate() {
                    if (d - r).abs() <= tol_s {
                        pairs.push(((d - r).abs(), i, j));
                    }
                }
            }
            pairs.sort_by(|a, b| a.0.total_cmp(&b.0));
            let mut used_d = vec![false; det.len()];
            let mut used_r = vec![false; refs.len()];
            for (_, i, j) in pairs {
                if used_d[i] || used_r[j] {
                    continue;
                }
                used_d[i] = true;
                used_r[j] = true;
                counts.tp += 1;
                counts.errors_s.push(det[i] - refs[j]);
            }
            counts.fn_ += used_r.iter().filter(|u| !**u).count();
            if coverage != Coverage::MatchedOnly {
                counts.fp += used_d.iter().filter(|u| !**u).count();
            }
        }
    }
    out
}

/// Double-support errors (detected − reference) of the double supports the reference saw
/// whole: a heel strike of one foot followed within 0.3 s by the other foot's toe off, both
/// inside `span` and both matched by a detected event of the same foot and kind within `tol_s`
/// (the nearest). Each error is `(seconds, fraction of the gait cycle)`, the cycle being the
/// median interval between successive heel strikes of one foot in `detected` (else in
/// `reference`); none when neither gives a cycle.
pub fn double_support_errors(
    detected: &[GaitEvent],
    reference: &[GaitEvent],
    span: (f64, f64),
    tol_s: f64,
) -> Vec<(f64, f64)> {
    let cycle = |ev: &[GaitEvent]| -> Option<f64> {
        let mut c: Vec<f64> = Vec::new();
        for side in [Side::Left, Side::Right] {
            let mut hs: Vec<f64> = ev
                .iter()
                .filter(|e| e.side == side && e.kind == EventKind::HeelStrike)
                .map(|e| e.time_s)
                .collect();
            hs.sort_by(f64::total_cmp);
            c.extend(hs.windows(2).map(|w| w[1] - w[0]));
        }
        c.sort_by(f64::total_cmp);
        c.get(c.len() / 2).copied()
    };
    let Some(cycle) = cycle(detected).or_else(|| cycle(reference)) else {
        return Vec::new();
    };
    let nearest = |side: Side, kind: EventKind, t: f64| -> Option<f64> {
        detected
            .iter()
            .filter(|e| e.side == side && e.kind == kind && (e.time_s - t).abs() <= tol_s)
            .map(|e| e.time_s)
            .min_by(|a, b| (a - t).abs().total_cmp(&(b - t).abs()))
    };
    let inside = |t: f64| t >= span.0 && t <= span.1;
    let mut out = Vec::new();
    for h in reference
        .iter()
        .filter(|e| e.kind == EventKind::HeelStrike && inside(e.time_s))
    {
        let to = reference
            .iter()
            .filter(|e| {
                e.kind == EventKind::ToeOff
                    && e.side != h.side
                    && e.time_s > h.time_s
                    && e.time_s < h.time_s + 0.3
                    && inside(e.time_s)
            })
            .min_by(|a, b| a.time_s.total_cmp(&b.time_s));
        let Some(to) = to else { continue };
        if let (Some(dh), Some(dt)) = (
            nearest(h.side, EventKind::HeelStrike, h.time_s),
            nearest(to.side, EventKind::ToeOff, to.time_s),
        ) {
            let err = (dt - dh) - (to.time_s - h.time_s);
            out.push((err, err / cycle));
        }
    }
    out
}

/// Double-support errors of one method against one reference, accumulated over trials.
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
pub struct DoubleSupportCounts {
    /// Errors, detected − reference, s.
    pub errors_s: Vec<f64>,
    /// The same errors as fractions of the gait cycle.
    pub errors_cycle: Vec<f64>,
}

fn mean_sd(v: &[f64]) -> (Option<f64>, Option<f64>) {
    let n = v.len();
    if n == 0 {
        return (None, None);
    }
    let m = v.iter().sum::<f64>() / n as f64;
    let sd =
        (n > 1).then(|| (v.iter().map(|x| (x - m) * (x - m)).sum::<f64>() / (n - 1) as f64).sqrt());
    (Some(m), sd)
}

impl DoubleSupportCounts {
    /// Mean and sample SD of the error, ms.
    pub fn ms(&self) -> (Option<f64>, Option<f64>) {
        let (m, sd) = mean_sd(&self.errors_s);
        (m.map(|x| x * 1000.0), sd.map(|x| x * 1000.0))
    }
    /// Mean and sample SD of the error, % of the gait cycle.
    pub fn pct_cycle(&self) -> (Option<f64>, Option<f64>) {
        let (m, sd) = mean_sd(&self.errors_cycle);
        (m.map(|x| x * 100.0), sd.map(|x| x * 100.0))
    }
}

/// A table of comparisons accumulated over trials: `(method, reference, kind) → counts`, and
/// the double-support errors per `(method, reference)`.
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
pub struct CompareTable {
    /// The accumulated counts.
    pub rows: BTreeMap<(String, String, EventKind), KindCounts>,
    /// The accumulated double-support errors (see [`double_support_errors`]).
    #[serde(default)]
    pub double_support: BTreeMap<(String, String), DoubleSupportCounts>,
    /// Reference events (heel strikes and toe offs) within the matching tolerance of either end
    /// of the marker record: scored like the others (a miss counts against recall); counted so
    /// the table can say so.
    #[serde(default)]
    pub near_ends: usize,
    /// All reference events scored (heel strikes and toe offs).
    #[serde(default)]
    pub scored: usize,
}

impl CompareTable {
    /// Adds the result of one [`compare`] call.
    pub fn add(&mut self, method: &str, reference: &str, res: &BTreeMap<EventKind, KindCounts>) {
        for (kind, c) in res {
            self.rows
                .entry((method.to_string(), reference.to_string(), *kind))
                .or_default()
                .merge(c);
        }
    }

    /// Adds the double-support errors of one method (see [`double_support_errors`]).
    pub fn add_double_support(&mut self, method: &str, reference: &str, errors: &[(f64, f64)]) {
        let d = self
            .double_support
            .entry((method.to_string(), reference.to_string()))
            .or_default();
        d.errors_s.extend(errors.iter().map(|e| e.0));
        d.errors_cycle.extend(errors.iter().map(|e| e.1));
    }

    /// Adds every row of another table.
    pub fn merge(&mut self, other: &CompareTable) {
        self.near_ends += other.near_ends;
        self.scored += other.scored;
        for (k, c) in &other.rows {
            self.rows.entry(k.clone()).or_default().merge(c);
        }
        for (k, d) in &other.double_support {
            let e = self.double_support.entry(k.clone()).or_default();
            e.errors_s.extend_from_slice(&d.errors_s);
            e.errors_cycle.extend_from_slice(&d.errors_cycle);
        }
    }

    /// A plain-text table: method, reference, event, n, F1, recall, mean ± SD (ms).
    pub fn render(&self) -> String {
        let mut s = format!(
            "{:<16} {:<10} {:<12} {:>5} {:>6} {:>7} {:>17}\n",
            "method", "vs", "event", "n", "F1", "recall", "error ms (mean±SD)"
        );
        let f = |v: Option<f64>, d: usize| v.map(|x| format!("{x:.d$}")).unwrap_or("–".into());
        for ((m, r, k), c) in &self.rows {
            s.push_str(&format!(
                "{:<16} {:<10} {:<12} {:>5} {:>6} {:>7} {:>9} ± {:<6}\n",
                m,
                r,
                k.as_str(),
                c.tp,
                f(c.f1(), 3),
                f(c.recall(), 3),
                f(c.mean_ms(), 1),
                f(c.sd_ms(), 1)
            ));
        }
        if self.scored > 0 {
            s.push_str(&format!(
                "every reference event inside the marker record is scored: {} event(s), {} of \
                 them within the matching tolerance of a record end (a miss there counts \
                 against recall like any other)\n",
                self.scored, self.near_ends
            ));
        }
        if self.double_support.values().any(|d| !d.errors_s.is_empty()) {
            s.push_str(&format!(
                "\n{:<16} {:<10} {:<14} {:>5} {:>17} {:>19}\n",
                "method", "vs", "period", "n", "error ms (mean±SD)", "error % of cycle"
            ));
            for ((m, r), d) in &self.double_support {
                let (ms, ms_sd) = d.ms();
                let (p, p_sd) = d.pct_cycle();
                s.push_str(&format!(
                    "{:<16} {:<10} {:<14} {:>5} {:>9} ± {:<6} {:>9} ± {:<6}\n",
                    m,
                    r,
                    "double_support",
                    d.errors_s.len(),
                    f(ms, 1),
                    f(ms_sd, 1),
                    f(p, 2),
                    f(p_sd, 2)
                ));
            }
        }
        s
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::events::EventSource;

    fn hs(t: f64, side: Side) -> GaitEvent {
        GaitEvent {
            time_s: t,
            side,
            kind: EventKind::HeelStrike,
            source: EventSource::Force,
        }
    }

    #[test]
    fn f1_and_timing() {
        let r = vec![
            hs(1.0, Side::Left),
            hs(2.0, Side::Left),
            hs(3.0, Side::Left),
        ];
        let d = vec![
            hs(1.01, Side::Left),
            hs(2.03, Side::Left),
            hs(2.5, Side::Left),
            hs(1.0, Side::Right),
        ];
        let c = compare(&d, &r, Coverage::Complete, (0.0, 10.0), 0.06);
        let k = &c[&EventKind::HeelStrike];
        assert_eq!((k.tp, k.fp, k.fn_), (2, 2, 1));
        assert!((k.f1().unwrap() - 4.0 / 7.0).abs() < 1e-12);
        assert!((k.mean_ms().unwrap() - 20.0).abs() < 1e-9);
        assert!((k.sd_ms().unwrap() - (200.0f64).sqrt()).abs() < 1e-9);
    }

    #[test]
    fn window_and_matched_only() {
        let r = vec![hs(2.0, Side::Left)];
        let d = vec![
            hs(1.0, Side::Left),
            hs(2.01, Side::Left),
            hs(3.0, Side::Left),
        ];
        let w = compare(&d, &r, Coverage::Window, (0.0, 10.0), 0.06);
        assert_eq!(w[&EventKind::HeelStrike].fp, 0);
        assert_eq!(w[&EventKind::HeelStrike].f1(), Some(1.0));
        let m = compare(&d, &r, Coverage::MatchedOnly, (0.0, 10.0), 0.06);
        assert_eq!(m[&EventKind::HeelStrike].f1(), None);
        assert_eq!(m[&EventKind::HeelStrike].recall(), Some(1.0));
    }

    fn ev(t: f64, side: Side, kind: EventKind) -> GaitEvent {
        GaitEvent {
            time_s: t,
            side,
            kind,
            source: EventSource::Force,
        }
    }

    #[test]
    fn double_support_error_in_time_and_cycle() {
        use EventKind::{HeelStrike as H, ToeOff as T};
        use Side::{Left as L, Right as R};
        // Reference: right heel strike at 1.00, left toe off at 1.10 (0.10 s double support).
        let r = vec![ev(1.0, R, H), ev(1.1, L, T), ev(1.6, L, H)];
        // Detected: heel strike 8 ms early, toe off 4 ms late; cycle 1.1 s (left heel strikes).
        let d = vec![
            ev(0.5, L, H),
            ev(0.992, R, H),
            ev(1.104, L, T),
            ev(1.6, L, H),
        ];
        let e = double_support_errors(&d, &r, (0.0, 10.0), 0.06);
        assert_eq!(e.len(), 1);
        assert!((e[0].0 - 0.012).abs() < 1e-12);
        assert!((e[0].1 - 0.012 / 1.1).abs() < 1e-12);
        // A toe off outside the tolerance: no pair; outside the span: no pair.
        let far = vec![ev(0.5, L, H), ev(0.992, R, H), ev(1.2, L, T), ev(1.6, L, H)];
        assert!(double_support_errors(&far, &r, (0.0, 10.0), 0.06).is_empty());
        assert!(double_support_errors(&d, &r, (0.0, 1.05), 0.06).is_empty());
        let mut t = CompareTable::default();
        t.add_double_support("m", "force", &e);
        t.add_double_support("m", "force", &[(0.002, 0.002)]);
        let (m, sd) = t.double_support[&("m".into(), "force".into())].ms();
        assert!((m.unwrap() - 7.0).abs() < 1e-9);
        assert!((sd.unwrap() - 50f64.sqrt()).abs() < 1e-9);
    }

    #[test]
    fn one_to_one_matching_prefers_closest() {
        let r = vec![hs(1.0, Side::Left)];
        let d = vec![hs(0.97, Side::Left), hs(1.01, Side::Left)];
        let c = compare(&d, &r, Coverage::Complete, (0.0, 10.0), 0.06);
        let k = &c[&EventKind::HeelStrike];
        assert_eq!((k.tp, k.fp), (1, 1));
        assert!((k.errors_s[0] - 0.01).abs() < 1e-12);
    }
}
