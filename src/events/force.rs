//! Heel strike and toe off from the vertical ground reaction force.
//!
//! Two steps, each on the signal that suits it:
//!
//! 1. **Finding the contacts** (robust): per plate, the vertical force is low-pass filtered
//!    (zero-phase Butterworth, default order 2 at 20 Hz), its unloaded baseline is measured on
//!    the unloaded samples and removed (an offset is noted; a drift above the tolerance is an
//!    error unless drift correction is asked for), then a threshold with hysteresis finds the
//!    contacts: a contact is a run of the filtered force at or above `off_n` (default 20 N) that
//!    reaches `on_n` (default 50 N; `on_n = off_n` is a single threshold). Short dips are
//!    merged, short blips dropped.
//! 2. **Timing the events** (unbiased): the filter smears every edge (a 20 Hz filter spreads
//!    a step over about ±25 ms, so the filtered force crosses 20 N before the force does at
//!    heel strike and after it at toe off), so each event is timed on the *unfiltered*
//!    baseline-corrected force (or on the force low-passed at `timing_cutoff_hz`, when given),
//!    where it crosses `off_n`, interpolated linearly between samples. The crossing is searched
//!    within one period of the detection cutoff (1/`cutoff_hz`, the farthest the filter moves
//!    an edge) of the filtered contact's edge: heel strike at the first sample of the contact
//!    at or above the level (extended backward while the force stays at or above it), toe off
//!    after its last. By default (20 N on the unfiltered vertical force, the guide's truth)
//!    the edges are those of the unfiltered force's runs at or above the level lasting at
//!    least `min_contact_s` (shorter runs are blips, as in the contact finding; a dip between
//!    two such runs is no swing): heel strike where the first rises through the level, toe off
//!    where the last falls through it, so a sample at zero in an unloading tail ends the
//!    contact.
//! 3. **Export dropouts** (opt-in bridging): the WBDS export zeroes isolated samples, some in
//!    the unloading tail, where the nonzero samples that follow still fall monotonically (the
//!    foot is still loaded; `tools/events/force_truth.py` prints the evidence). A contact that
//!    ends at an exactly-zero raw sample with the force back at or above the level within one
//!    detection period after it is counted as ending at a dropout
//!    ([`ForceResult::dropout_shifts_s`]: how much later bridging would time its toe off);
//!    `bridge_dropouts = true` (`--bridge-dropouts`) times such toe offs after the tail.
//!
//! Plates that carry one known foot (dual-belt treadmill belts, OpenSim `R_`/`L_` forces) give
//! that foot's events directly. Overground plates (`side: None`) are assigned to a foot by the
//! markers (the foot whose heel–metatarsal midpoint is nearest to the centre of pressure at
//! mid-contact), or, without markers, by alternation in time; contacts of one foot on
//! neighbouring plates are merged.
use super::filter::{filtfilt_gappy, Butterworth};
use super::kinematic::Kinematics;
use super::{path_of, EventError, EventKind, EventSource, GaitEvent, Side};
use crate::ingest::types::{ForcePlate, Trial};
use serde::{Deserialize, Serialize};

/// Force-event settings.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct ForceOptions {
    /// Low-pass cutoff, Hz (default 20).
    pub cutoff_hz: f64,
    /// Butterworth order of one pass (default 2; zero-phase doubles it).
    pub order: usize,
    /// Contact-on threshold, N (default 50).
    pub on_n: f64,
    /// Contact-off threshold, N (default 20); events are timed where the unfiltered force
    /// crosses this level.
    pub off_n: f64,
    /// Low-pass cutoff of the signal the events are timed on, Hz; `None` (the default) times
    /// them on the unfiltered force. Set it (≥ 100 Hz keeps the edge bias near a millisecond)
    /// for plates whose noise crosses the threshold outside contacts.
    #[serde(default)]
    pub timing_cutoff_hz: Option<f64>,
    /// Shortest contact kept, s (default 0.05): shorter ones are noise or a brush of the plate.
    pub min_contact_s: f64,
    /// Shortest unloaded gap between two contacts of one plate, s (default 0.05): shorter gaps
    /// are merged (a dip of the force under the threshold inside one contact).
    pub min_gap_s: f64,
    /// Largest baseline drift tolerated without correction, N (default 10).
    pub drift_tolerance_n: f64,
    /// Subtract a linear baseline fitted to the unloaded periods instead of failing on drift.
    pub correct_drift: bool,
    /// Bridge export dropouts (default `false`). `false` times each contact on the runs of
    /// the unfiltered force at or above `off_n` lasting `min_contact_s` (from the first one's
    /// rise to the last one's fall): 20 N on the
    /// unfiltered vertical force, the developers' guide's force-plate truth (issue 19's WBDS04
    /// double support figures). `true` times a contact's toe off after the last unfiltered
    /// sample at or above `off_n` near the filtered contact's end, so samples an export zeroed
    /// in the unloading tail (WBDS) do not end it (longer stance and double support; see the
    /// module docs and reports/events.md).
    #[serde(default)]
    pub bridge_dropouts: bool,
}

impl Default for ForceOptions {
    fn default() -> Self {
        ForceOptions {
            cutoff_hz: 20.0,
            order: 2,
            on_n: 50.0,
            off_n: 20.0,
            timing_cutoff_hz: None,
            min_contact_s: 0.05,
            min_gap_s: 0.05,
            drift_tolerance_n: 10.0,
            correct_drift: false,
            bridge_dropouts: false,
        }
    }
}

/// One foot contact seen by the force plates.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Contact {
    /// Names of the plates it was seen on.
    pub plates: Vec<String>,
    /// The foot (known from the plate, or assigned).
    pub side: Side,
    /// How the foot was assigned ("plate", "markers", "alternation").
    pub assigned_by: String,
    /// Start, s (`None` when the record starts loaded: the heel strike was not seen).
    pub on_s: Option<f64>,
    /// End, s (`None` when the record ends loaded).
    pub off_s: Option<f64>,
    /// First and last sample of the contact (time, s).
    pub span_s: (f64, f64),
    /// Peak vertical force, N.
    pub peak_n: f64,
    /// Mean centre of pressure over the loaded part of the contact (force above 20 % of its
    /// peak; laboratory frame, m), when known.
    pub cop_m: Option<[f64; 3]>,
    /// Mean time of the samples averaged into `cop_m`, s.
    pub cop_time_mean_s: Option<f64>,
    /// Velocity of the centre of pressure over those samples (least-squares slope per axis),
    /// m/s.
    pub cop_slope: Option<[f64; 3]>,
}

/// Per-plate diagnostics.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct PlateReport {
    /// Plate name.
    pub name: String,
    /// Baseline removed (median unloaded level; with drift correction, the mean of the fitted
    /// line), N.
    pub offset_n: f64,
    /// Baseline drift over the trial (end − start of the fitted line), N.
    pub drift_n: f64,
    /// Number of contacts found.
    pub contacts: usize,
}

/// The filtered, baseline-corrected vertical force of one plate.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct VerticalForce {
    /// Plate name.
    pub name: String,
    /// The foot it carries, if known.
    pub side: Option<Side>,
    /// Sample times, s.
    pub time_s: Vec<f64>,
    /// Vertical force, N.
    pub force_n: Vec<f64>,
}

/// The force-plate result of one trial.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, Default)]
pub struct ForceResult {
    /// Contacts, per foot, in time order.
    pub contacts: Vec<Contact>,
    /// Heel strike and toe off of every contact whose start/end was seen.
    pub events: Vec<GaitEvent>,
    /// True when every plate carries one known foot (all contacts of both feet are seen).
    pub complete: bool,
    /// Per-plate diagnostics.
    pub plates: Vec<PlateReport>,
    /// The processed vertical forces (for plots).
    pub vertical: Vec<VerticalForce>,
    /// What was found or assumed.
    pub notes: Vec<String>,
    /// Per contact that ends at an export dropout (an exactly-zero raw sample, the force back
    /// at or above `off_n` within one detection period after it): how much later its toe off
    /// would be with [`ForceOptions::bridge_dropouts`], s. Its toe off as timed (bridged or
    /// not) is in `events`.
    #[serde(default)]
    pub dropout_shifts_s: Vec<f64>,
}

/// The index of the vertical axis of the trial (its frame, else Y, the OpenSim and treadmill
/// convention of the shared data).
fn vertical_axis(trial: &Trial) -> usize {
    trial
        .frame
        .as_ref()
        .map(|f| f.vertical.index())
        .unwrap_or(1)
}

/// The `p` quantile (nearest rank) of `v`, which it reorders: a selection, O(n), instead of a
/// sort (a 30 s plate at 1 kHz has 30 000 samples).
fn percentile(v: &mut [f64], p: f64) -> f64 {
    if v.is_empty() {
        return f64::NAN;
    }
    let k = (((v.len() - 1) as f64 * p).round() as usize).min(v.len() - 1);
    *v.select_nth_unstable_by(k, f64::total_cmp).1
}

/// The vertical force of `plate`, filtered for finding contacts and unfiltered (or filtered at
/// [`ForceOptions::timing_cutoff_hz`]) for timing them, both with the unloaded baseline
/// removed: `(filtered, timing, report)`.
pub fn vertical_force(
    plate: &ForcePlate,
    axis: usize,
    path: &str,
    opts: &ForceOptions,
    notes: &mut Vec<String>,
) -> Result<(Vec<f64>, Vec<f64>, PlateReport), EventError> {
    let raw: Vec<f64> = plate.force_n.iter().map(|f| f[axis]).collect();
    let n = raw.len();
    let plate_err = |message: String| EventError::Plate {
        path: path.to_string(),
        channel: plate.name.clone(),
        message,
    };
    if n != plate.time_s.len() {
        return Err(plate_err(format!(
            "{} force samples but {} sample times",
            n,
            plate.time_s.len()
        )));
    }
    let filter = Butterworth::low_pass(opts.order, opts.cutoff_hz, plate.rate_hz)?;
    if n < filter.min_len() {
        return Err(EventError::TooShort {
            path: path.to_string(),
            reason: format!("force plate {} has only {n} samples", plate.name),
        });
    }
    let mut f = filtfilt_gappy(&filter, &raw);
    let mut g = match opts.timing_cutoff_hz {
        None => raw,
        Some(c) => filtfilt_gappy(&Butterworth::low_pass(opts.order, c, plate.rate_hz)?, &raw),
    };
    let mut finite: Vec<f64> = f.iter().copied().filter(|v| v.is_finite()).collect();
    let (p2, p98) = (percentile(&mut finite, 0.02), percentile(&mut finite, 0.98));
    let mut report = PlateReport {
        name: plate.name.clone(),
        offset_n: 0.0,
        drift_n: 0.0,
        contacts: 0,
    };
    if finite.is_empty() {
        return Ok((f, g, report));
    }
    if p98 < opts.on_n && p2 < -opts.on_n {
        return Err(plate_err(format!(
            "the vertical force is negative (down to {p2:.0} N): the file gives the force on \
             the plate, not on the body; flip the sign of the vertical channel"
        )));
    }
    if p98 < opts.on_n {
        // Never loaded: nobody stepped on this plate.
        return Ok((f, g, report));
    }
    if p2 > 0.25 * p98 {
        return Err(plate_err(format!(
            "never unloaded (lowest force {p2:.0} N, peak {p98:.0} N): a standing trial has \
             no gait events, and a single belt carrying both feet cannot be split into foot \
             contacts; use markers (--events zeni) or per-belt forces"
        )));
    }
    // Unloaded samples: within `off_n` of the lowest level.
    let unloaded: Vec<usize> = (0..n)
        .filter(|&i| f[i].is_finite() && f[i] < p2 + opts.off_n)
        .collect();
    if unloaded.len() >= 10 {
        let t: Vec<f64> = unloaded.iter().map(|&i| plate.time_s[i]).collect();
        let y: Vec<f64> = unloaded.iter().map(|&i| f[i]).collect();
        let m = t.len() as f64;
        let (tm, ym) = (t.iter().sum::<f64>() / m, y.iter().sum::<f64>() / m);
        let sxx: f64 = t.iter().map(|v| (v - tm) * (v - tm)).sum();
        let sxy: f64 = t.iter().zip(&y).map(|(a, b)| (a - tm) * (b - ym)).sum();
        let slope = if sxx > 0.0 { sxy / sxx } else { 0.0 };
        let (t0, t1) = (plate.time_s[0], plate.time_s[n - 1]);
        let start = ym + slope * (t0 - tm);
        let end = ym + slope * (t1 - tm);
        report.offset_n = ym;
        report.drift_n = end - start;
        if report.drift_n.abs() > opts.drift_tolerance_n {
            if !opts.correct_drift {
                return Err(EventError::PlateDrift {
                    path: path.to_string(),
                    channel: plate.name.clone(),
                    drift_n: report.drift_n,
                    start_n: start,
                    end_n: end,
                    first_frame: unloaded[0] + 1,
                    last_frame: unloaded[unloaded.len() - 1] + 1,
                    tolerance_n: opts.drift_tolerance_n,
                });
            }
            for ((v, w), &ti) in f.iter_mut().zip(g.iter_mut()).zip(&plate.time_s) {
                *v -= ym + slope * (ti - tm);
                *w -= ym + slope * (ti - tm);
            }
            notes.push(format!(
                "force plate {}: baseline drift of {:.1} N over the trial subtracted (linear fit \
                 to {} unloaded samples)",
                plate.name,
                report.drift_n,
                unloaded.len()
            ));
        } else {
            // The median of the unfiltered unloaded samples: spikes of the unloaded signal
            // (WBDS has isolated −20 to −30 N samples) would pull a mean, and the filter
            // spreads them; the level the events are timed against is the typical one.
            let mut u: Vec<f64> = unloaded
                .iter()
                .map(|&i| g[i])
                .filter(|v| v.is_finite())
                .collect();
            let level = if u.is_empty() {
                ym
            } else {
                percentile(&mut u, 0.5)
            };
            report.offset_n = level;
            for v in f.iter_mut().chain(g.iter_mut()) {
                *v -= level;
            }
            if level.abs() > 2.0 {
                notes.push(format!(
                    "force plate {}: unloaded offset of {level:.1} N removed (median of {} \
                     unloaded samples); drift {:.1} N is within tolerance",
                    plate.name,
                    unloaded.len(),
                    report.drift_n
                ));
            }
        }
    }
    Ok((f, g, report))
}

/// One contact of one plate: first and last index of the filtered force at or above `off_n`,
/// and the heel-strike and toe-off times (`None` when the record starts/ends loaded).
type RawContact = (usize, usize, Option<f64>, Option<f64>);

/// Time between samples `i` and `i + 1` where `x` crosses `level` (linear interpolation).
fn crossing(t: &[f64], x: &[f64], i: usize, level: f64) -> f64 {
    let (a, b) = (x[i], x[i + 1]);
    if !(a.is_finite() && b.is_finite()) || (b - a).abs() < 1e-12 {
        return if a.is_finite() { t[i] } else { t[i + 1] };
    }
    t[i] + ((level - a) / (b - a)).clamp(0.0, 1.0) * (t[i + 1] - t[i])
}

/// Contacts of one plate: found on the filtered force `f` by threshold with hysteresis, timed
/// on `g` (see the module docs).
/// Also returns the toe-off shifts of the contacts that end at an export dropout (see
/// [`retime`]); `raw` is the plate's unfiltered force before the baseline removal.
fn threshold_contacts(
    t: &[f64],
    f: &[f64],
    g: &[f64],
    raw: &[f64],
    opts: &ForceOptions,
) -> (Vec<RawContact>, Vec<f64>) {
    let n = f.len();
    let level = opts.off_n;
    let mut out: Vec<RawContact> = Vec::new();
    let mut i = 0;
    while i < n {
        if f[i].is_nan() || f[i] < opts.on_n {
            i += 1;
            continue;
        }
        // Walk back to where the force last rose through off_n.
        let mut s = i;
        while s > 0 && f[s - 1].is_finite() && f[s - 1] >= level {
            s -= 1;
        }
        let on = (s > 0 && f[s - 1].is_finite()).then(|| crossing(t, f, s - 1, level));
        let mut e = i;
        while e + 1 < n && f[e + 1].is_finite() && f[e + 1] >= level {
            e += 1;
        }
        let off = (e + 1 < n && f[e + 1].is_finite()).then(|| crossing(t, f, e, level));
        out.push((s, e, on, off));
        i = e + 1;
    }
    // Merge contacts separated by a short gap; drop short ones (unless truncated by the record).
    let mut merged: Vec<RawContact> = Vec::new();
    for c in out {
        if let Some(last) = merged.last_mut() {
            if t[c.0] - t[last.1] < opts.min_gap_s {
                last.1 = c.1;
                last.3 = c.3;
                continue;
            }
        }
        merged.push(c);
    }
    merged.retain(|c| c.2.is_none() || c.3.is_none() || t[c.1] - t[c.0] >= opts.min_contact_s);
    let dropouts = retime(t, f, g, raw, opts, &mut merged);
    (merged, dropouts)
}

/// Times each edge of `contacts` on the timing signal `g`: within one period of the detection
/// cutoff of the filtered edge (the farthest a zero-phase low-pass at that cutoff moves an
/// edge) and never past the middle of the gap to the neighbouring contact. An edge whose
/// timing signal never reaches the level there keeps its filtered time. Returns, per contact
/// that ends at an export dropout (see the module docs), how much later bridging times its toe
/// off, s.
fn retime(
    t: &[f64],
    f: &[f64],
    g: &[f64],
    raw: &[f64],
    opts: &ForceOptions,
    contacts: &mut [RawContact],
) -> Vec<f64> {
    let n = f.len();
    let level = opts.off_n;
    let w = (opts.cutoff_hz.recip() / median_dt(t)).ceil() as usize;
    let m = contacts.len();
    let mut dropouts = Vec::new();
    for k in 0..m {
        let (s, e) = (contacts[k].0, contacts[k].1);
        // First index this contact may claim, last index it may claim.
        let floor = if k > 0 {
            (contacts[k - 1].1 + s) / 2 + 1
        } else {
            0
        };
        let ceil = if k + 1 < m {
            (e + contacts[k + 1].0).div_ceil(2) - 1
        } else {
            n - 1
        };
        let (lo, hi) = (floor.max(s.saturating_sub(w)), ceil.min(e + w));
        let plain = plain_runs(t, g, level, lo, hi, opts.min_contact_s);
        let bridged_on = (lo..=e).find(|&j| g[j] >= level).map(|mut j| {
            while j > floor && g[j - 1] >= level {
                j -= 1;
            }
            j
        });
        let bridged_off = (s..=hi).rev().find(|&j| g[j] >= level).map(|mut j| {
            while j < ceil && g[j + 1] >= level {
                j += 1;
            }
            j
        });
        // An export dropout: the plain run ends at an exactly-zero raw sample and the force is
        // back at or above the level before the bridged end.
        if let (Some((_, pe)), Some(be)) = (plain, bridged_off) {
            if contacts[k].3.is_some() && be > pe && pe + 1 < n && raw[pe + 1] == 0.0 {
                dropouts.push(crossing(t, g, be, level) - crossing(t, g, pe, level));
            }
        }
        let (on, off) = if opts.bridge_dropouts {
            (bridged_on, bridged_off)
        } else {
            match plain {
                Some((a, b)) => (Some(a), Some(b)),
                None => (None, None),
            }
        };
        if let Some(j) = on.filter(|&j| j > 0 && contacts[k].2.is_some()) {
            contacts[k].2 = Some(crossing(t, g, j - 1, level));
        }
        if let Some(j) = off.filter(|&j| j + 1 < n && contacts[k].3.is_some()) {
            contacts[k].3 = Some(crossing(t, g, j, level));
        }
    }
    dropouts
}

/// The contact a plain threshold on the force sees within `lo..=hi`: the runs of `g` at or
/// above `level` lasting at least `min_s` (shorter runs are blips; a run the record cuts is a
/// contact of unknown length and is kept), taken together — a dip between two such runs is
/// no swing. Returns the first index of the first of them and the last index of the last.
fn plain_runs(
    t: &[f64],
    g: &[f64],
    level: f64,
    lo: usize,
    hi: usize,
    min_s: f64,
) -> Option<(usize, usize)> {
    let n = g.len();
    let mut out: Option<(usize, usize)> = None;
    let mut j = lo;
    while j <= hi {
        if g[j].is_nan() || g[j] < level {
            j += 1;
            continue;
        }
        let a = j;
        while j < hi && g[j + 1] >= level {
            j += 1;
        }
        if t[j] - t[a] >= min_s || a == 0 || j + 1 >= n {
            out = Some(out.map_or((a, j), |(s, _)| (s, j)));
        }
        j += 1;
    }
    out
}

/// Median sample interval of `t`, s (1 when it cannot be told).
fn median_dt(t: &[f64]) -> f64 {
    let mut d: Vec<f64> = t
        .windows(2)
        .map(|w| w[1] - w[0])
        .filter(|d| d.is_finite() && *d > 0.0)
        .collect();
    if d.is_empty() {
        return 1.0;
    }
    let k = d.len() / 2;
    *d.select_nth_unstable_by(k, f64::total_cmp).1
}

/// Mean centre of pressure, its mean time and its velocity over the samples `s..=e` whose
/// force exceeds 20 % of `peak` (the centre of pressure is meaningless under a light load).
#[allow(clippy::type_complexity)]
fn cop_stats(
    plate: &ForcePlate,
    f: &[f64],
    s: usize,
    e: usize,
    peak: f64,
) -> (Option<[f64; 3]>, Option<f64>, Option<[f64; 3]>) {
    let idx: Vec<usize> = (s..=e)
        .filter(|&i| {
            f[i] > 0.2 * peak
                && plate
                    .cop_m
                    .get(i)
                    .is_some_and(|c| c.iter().all(|v| v.is_finite()))
        })
        .collect();
    if idx.len() < 3 {
        return (None, None, None);
    }
    let m = idx.len() as f64;
    let tm = idx.iter().map(|&i| plate.time_s[i]).sum::<f64>() / m;
    let mut mean = [0.0; 3];
    for &i in &idx {
        for (mv, c) in mean.iter_mut().zip(plate.cop_m[i]) {
            *mv += c / m;
        }
    }
    let sxx: f64 = idx.iter().map(|&i| (plate.time_s[i] - tm).powi(2)).sum();
    let mut slope = [0.0; 3];
    if sxx > 0.0 {
        for (a, sl) in slope.iter_mut().enumerate() {
            let sxy: f64 = idx
                .iter()
                .map(|&i| (plate.time_s[i] - tm) * (plate.cop_m[i][a] - mean[a]))
                .sum();
            *sl = sxy / sxx;
        }
    }
    (Some(mean), Some(tm), Some(slope))
}

/// Finds the contacts and events of every plate of `trial`; `kin` (when the trial has markers)
/// assigns overground contacts to a foot.
pub fn detect(
    trial: &Trial,
    kin: Option<&Kinematics>,
    opts: &ForceOptions,
) -> Result<ForceResult, EventError> {
    let path = path_of(trial);
    let axis = vertical_axis(trial);
    let mut res = ForceResult::default();
    if trial.plates.is_empty() {
        return Ok(res);
    }
    if !(opts.on_n >= opts.off_n && opts.off_n > 0.0) {
        return Err(EventError::Options(format!(
            "force thresholds: on ({} N) must be at least off ({} N), and off above 0",
            opts.on_n, opts.off_n
        )));
    }
    if let Some(c) = opts.timing_cutoff_hz {
        if c.is_nan() || c < opts.cutoff_hz {
            return Err(EventError::Options(format!(
                "force timing cutoff {c} Hz is below the detection cutoff {} Hz: the events \
                 are timed on the sharper signal",
                opts.cutoff_hz
            )));
        }
    }
    let mut unassigned: Vec<Contact> = Vec::new();
    for plate in &trial.plates {
        let (f, g, mut report) = vertical_force(plate, axis, &path, opts, &mut res.notes)?;
        let unfiltered: Vec<f64> = plate.force_n.iter().map(|v| v[axis]).collect();
        let (raw, dropouts) = threshold_contacts(&plate.time_s, &f, &g, &unfiltered, opts);
        res.dropout_shifts_s.extend(dropouts);
        report.contacts = raw.len();
        for (s, e, on, off) in raw {
            let peak = f[s..=e].iter().copied().fold(f64::NEG_INFINITY, f64::max);
            let (cop, cop_t, cop_slope) = cop_stats(plate, &f, s, e, peak);
            let c = Contact {
                plates: vec![plate.name.clone()],
                side: plate.side.unwrap_or(Side::Right),
                assigned_by: "plate".into(),
                on_s: on,
                off_s: off,
                span_s: (plate.time_s[s], plate.time_s[e]),
                peak_n: peak,
                cop_m: cop,
                cop_time_mean_s: cop_t,
                cop_slope,
            };
            if plate.side.is_some() {
                res.contacts.push(c);
            } else {
                unassigned.push(c);
            }
        }
        res.vertical.push(VerticalForce {
            name: plate.name.clone(),
            side: plate.side,
            time_s: plate.time_s.clone(),
            force_n: f,
        });
        res.plates.push(report);
    }
    res.complete = trial.plates.iter().all(|p| p.side.is_some())
        && [Side::Left, Side::Right]
            .iter()
            .all(|s| trial.plates.iter().any(|p| p.side == Some(*s)));
    resolve_cross_belt(&mut res.contacts, &mut res.notes);
    if !unassigned.is_empty() {
        assign_feet(&mut unassigned, kin, &mut res.notes);
        res.contacts.extend(unassigned);
    }
    res.contacts = merge_same_foot(std::mem::take(&mut res.contacts));
    for c in &res.contacts {
        if let Some(t) = c.on_s {
            res.events.push(GaitEvent {
                time_s: t,
                side: c.side,
                kind: EventKind::HeelStrike,
                source: EventSource::Force,
            });
        }
        if let Some(t) = c.off_s {
            res.events.push(GaitEvent {
                time_s: t,
                side: c.side,
                kind: EventKind::ToeOff,
                source: EventSource::Force,
            });
        }
    }
    res.events.sort_by(|a, b| a.time_s.total_cmp(&b.time_s));
    Ok(res)
}

/// Assigns overground contacts to a foot: by the markers when there are any, else by
/// alternation in time.
fn assign_feet(contacts: &mut [Contact], kin: Option<&Kinematics>, notes: &mut Vec<String>) {
    contacts.sort_by(|a, b| a.span_s.0.total_cmp(&b.span_s.0));
    let mut by_markers = 0;
    if let Some(k) = kin {
        for c in contacts.iter_mut() {
            let mid = 0.5 * (c.span_s.0 + c.span_s.1);
            if let Some(side) = k.foot_nearest(mid, c.cop_m) {
                c.side = side;
                c.assigned_by = "markers".into();
                by_markers += 1;
            }
        }
    }
    if by_markers == contacts.len() {
        return;
    }
    // Alternation: contacts that overlap in time by more than half the shorter one are one foot
    // on two plates; otherwise consecutive contacts belong to alternate feet.
    let mut side = Side::Right;
    let mut prev: Option<(f64, f64)> = None;
    for c in contacts.iter_mut() {
        if let Some((a, b)) = prev {
            let overlap = (b.min(c.span_s.1) - a.max(c.span_s.0)).max(0.0);
            let shorter = (b - a).min(c.span_s.1 - c.span_s.0).max(1e-9);
            if overlap <= 0.5 * shorter {
                side = side.opposite();
            }
        }
        if c.assigned_by != "markers" {
            c.side = side;
            c.assigned_by = "alternation".into();
        }
        prev = Some(c.span_s);
    }
    notes.push(
        "overground force plates without markers: contacts assigned to the feet by alternation, \
         the first to the right foot (pass markers to assign by foot position)"
            .into(),
    );
}

/// On per-foot plates (treadmill belts), a foot that lands across both belts shows as two
/// simultaneous contacts, one on each belt. Contacts of different belts that overlap by more
/// than half of the shorter one cannot be two feet (running has no overlap, walking's double
/// support is a fifth of a stance or less): they are one foot, the one that alternates with the
/// previous contact, and are merged.
fn resolve_cross_belt(contacts: &mut [Contact], notes: &mut Vec<String>) {
    contacts.sort_by(|a, b| a.span_s.0.total_cmp(&b.span_s.0));
    let n = contacts.len();
    let mut last_clean: Option<Side> = None;
    let mut i = 0;
    while i < n {
        let overlapping = if i + 1 < n {
            let (a, b) = (&contacts[i], &contacts[i + 1]);
            let overlap = (a.span_s.1.min(b.span_s.1) - b.span_s.0.max(a.span_s.0)).max(0.0);
            let shorter = (a.span_s.1 - a.span_s.0).min(b.span_s.1 - b.span_s.0);
            // Contacts cut by the record have unknown durations: the rule does not apply.
            let whole = |c: &Contact| c.on_s.is_some() && c.off_s.is_some();
            a.side != b.side && whole(a) && whole(b) && overlap > 0.5 * shorter
        } else {
            false
        };
        if overlapping {
            let side = match last_clean {
                Some(s) => s.opposite(),
                None => contacts
                    .get(i + 2)
                    .map(|c| c.side.opposite())
                    .unwrap_or(contacts[i].side),
            };
            notes.push(format!(
                "one foot on both belts at {:.3}–{:.3} s ({} and {}): merged into one {side} \
                 contact (the foot that alternates with the previous contact)",
                contacts[i].span_s.0.min(contacts[i + 1].span_s.0),
                contacts[i].span_s.1.max(contacts[i + 1].span_s.1),
                contacts[i].plates.join("+"),
                contacts[i + 1].plates.join("+"),
            ));
            for c in &mut contacts[i..i + 2] {
                c.side = side;
                c.assigned_by = "alternation (one foot on both belts)".into();
            }
            last_clean = Some(side);
            i += 2;
        } else {
            last_clean = Some(contacts[i].side);
            i += 1;
        }
    }
}

/// Merges contacts of the same foot that overlap in time (one foot on two plates).
fn merge_same_foot(mut contacts: Vec<Contact>) -> Vec<Contact> {
    contacts.sort_by(|a, b| {
        (a.side, a.span_s.0)
            .partial_cmp(&(b.side, b.span_s.0))
            .unwrap_or(std::cmp::Ordering::Equal)
    });
    let mut out: Vec<Contact> = Vec::new();
    for c in contacts {
        if let Some(last) = out.last_mut() {
            if last.side == c.side && c.span_s.0 <= last.span_s.1 {
                last.plates.extend(c.plates);
                last.on_s = match (last.on_s, c.on_s) {
                    (Some(a), Some(b)) => Some(a.min(b)),
                    _ => None,
                };
                if c.span_s.1 >= last.span_s.1 {
                    last.off_s = c.off_s;
                }
                last.span_s = (last.span_s.0.min(c.span_s.0), last.span_s.1.max(c.span_s.1));
                last.peak_n = last.peak_n.max(c.peak_n);
                // The centre of pressure of one plate is not the foot's: drop it.
                last.cop_m = None;
                last.cop_time_mean_s = None;
                last.cop_slope = None;
                continue;
            }
        }
        out.push(c);
    }
    out.sort_by(|a, b| a.span_s.0.total_cmp(&b.span_s.0));
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A synthetic vertical force: half-sine contacts of `peak` N.
    fn plate(side: Option<Side>, contacts: &[(f64, f64)], rate: f64, dur: f64) -> ForcePlate {
        let n = (dur * rate) as usize;
        let time_s: Vec<f64> = (0..n).map(|i| i as f64 / rate).collect();
        let force_n = time_s
            .iter()
            .map(|&t| {
                let mut fy = 0.0;
                for &(a, b) in contacts {
                    if t > a && t < b {
                        fy += 800.0 * (std::f64::consts::PI * (t - a) / (b - a)).sin();
                    }
                }
                [0.0, fy, 0.0]
            })
            .collect();
        ForcePlate {
            name: "FP".into(),
            rate_hz: rate,
            cop_m: vec![[f64::NAN; 3]; n],
            time_s,
            force_n,
            free_moment_nm: vec![],
            side,
        }
    }

    fn trial(plates: Vec<ForcePlate>) -> Trial {
        let mut t = Trial::new("synthetic.mot", "synthetic");
        t.plates = plates;
        t
    }

    #[test]
    fn events_near_true_contact_times() {
        // A half-sine of 800 N crosses 20 N at 0.8 % of the contact: 2.5 ms after 0.3 s for a
        // 0.25 s contact; filtering at 20 Hz rounds the corner a little more.
        let p = plate(Some(Side::Right), &[(0.3, 0.55), (1.0, 1.25)], 1000.0, 2.0);
        let r = detect(&trial(vec![p]), None, &ForceOptions::default()).unwrap();
        let hs: Vec<f64> = r
            .events
            .iter()
            .filter(|e| e.kind == EventKind::HeelStrike)
            .map(|e| e.time_s)
            .collect();
        let to: Vec<f64> = r
            .events
            .iter()
            .filter(|e| e.kind == EventKind::ToeOff)
            .map(|e| e.time_s)
            .collect();
        assert_eq!(hs.len(), 2);
        assert_eq!(to.len(), 2);
        assert!((hs[0] - 0.3).abs() < 0.006, "{hs:?}");
        assert!((to[1] - 1.25).abs() < 0.006, "{to:?}");
        assert!(r.events.iter().all(|e| e.side == Side::Right));
    }

    fn times(r: &ForceResult, kind: EventKind) -> Vec<f64> {
        r.events
            .iter()
            .filter(|e| e.kind == kind)
            .map(|e| e.time_s)
            .collect()
    }

    #[test]
    fn events_are_timed_on_the_unfiltered_force() {
        // An 800 N half-sine over (a, b) crosses 20 N at a + (b − a)/π · asin(20/800) and
        // symmetrically before b. Sampled at 1 kHz, linear interpolation is within 0.1 ms.
        let (a, b) = (0.3, 0.55);
        let dt = (b - a) / std::f64::consts::PI * (20.0f64 / 800.0).asin();
        let p = plate(Some(Side::Right), &[(a, b)], 1000.0, 1.0);
        let r = detect(&trial(vec![p.clone()]), None, &ForceOptions::default()).unwrap();
        assert!((times(&r, EventKind::HeelStrike)[0] - (a + dt)).abs() < 1e-4);
        assert!((times(&r, EventKind::ToeOff)[0] - (b - dt)).abs() < 1e-4);
        // Timed on the 20 Hz filtered force instead, the contact is longer at both ends.
        let filtered = ForceOptions {
            timing_cutoff_hz: Some(20.0),
            ..ForceOptions::default()
        };
        let r = detect(&trial(vec![p]), None, &filtered).unwrap();
        assert!(times(&r, EventKind::HeelStrike)[0] < a + dt - 1e-3);
        assert!(times(&r, EventKind::ToeOff)[0] > b - dt + 1e-3);
    }

    #[test]
    fn a_sharp_edge_and_dropouts_in_the_tail_are_timed_as_the_force_crosses() {
        // 300 Hz, like WBDS: the force jumps from 0 to 300 N between two samples, one sample
        // is zeroed in mid stance, and the unloading tail has isolated zero samples (121, 0,
        // 83, 0, 0, 0, 56, 0, 0, 29, 0 N).
        let rate = 300.0;
        let mut fy = vec![0.0; 300];
        for v in fy.iter_mut().take(200).skip(60) {
            *v = 600.0;
        }
        fy[60] = 300.0;
        fy[130] = 0.0;
        let tail = [121.0, 0.0, 83.0, 0.0, 0.0, 0.0, 56.0, 0.0, 0.0, 29.0];
        fy[200..210].copy_from_slice(&tail);
        let mut p = plate(Some(Side::Left), &[], rate, 1.0);
        for (f, v) in p.force_n.iter_mut().zip(&fy) {
            f[1] = *v;
        }
        let t = trial(vec![p]);
        let r = detect(&t, None, &ForceOptions::default()).unwrap();
        // One contact: the mid-stance zero splits two runs of 70 samples, no swing.
        assert_eq!(r.contacts.len(), 1);
        // Heel strike between samples 59 (0 N) and 60 (300 N): 59 + 20/300.
        let hs = times(&r, EventKind::HeelStrike);
        assert!(
            (hs[0] - (59.0 + 20.0 / 300.0) / rate).abs() < 1e-9,
            "{hs:?}"
        );
        // Default (20 N on the unfiltered force): the tail's first zero ends the contact,
        // between samples 200 (121 N) and 201 (0 N): 200 + 101/121.
        let to = times(&r, EventKind::ToeOff);
        let plain = (200.0 + 101.0 / 121.0) / rate;
        assert!((to[0] - plain).abs() < 1e-9, "{to:?}");
        // Bridged: after the last loaded sample (209, 29 N) and before 210 (0 N): 209 + 9/29.
        let bridged = (209.0 + 9.0 / 29.0) / rate;
        assert_eq!(r.dropout_shifts_s.len(), 1);
        assert!((r.dropout_shifts_s[0] - (bridged - plain)).abs() < 1e-9);
        let opts = ForceOptions {
            bridge_dropouts: true,
            ..ForceOptions::default()
        };
        let rb = detect(&t, None, &opts).unwrap();
        let to = times(&rb, EventKind::ToeOff);
        assert!((to[0] - bridged).abs() < 1e-9, "{to:?}");
        assert_eq!(times(&rb, EventKind::HeelStrike), hs);
    }

    #[test]
    fn a_single_threshold_is_allowed_and_thresholds_are_checked() {
        let p = plate(Some(Side::Right), &[(0.3, 0.55)], 1000.0, 1.0);
        let single = ForceOptions {
            on_n: 50.0,
            off_n: 50.0,
            ..ForceOptions::default()
        };
        let r = detect(&trial(vec![p.clone()]), None, &single).unwrap();
        let dt = 0.25 / std::f64::consts::PI * (50.0f64 / 800.0).asin();
        assert!((times(&r, EventKind::HeelStrike)[0] - (0.3 + dt)).abs() < 1e-4);
        let inverted = ForceOptions {
            on_n: 20.0,
            off_n: 50.0,
            ..ForceOptions::default()
        };
        assert!(detect(&trial(vec![p.clone()]), None, &inverted).is_err());
        let blunt = ForceOptions {
            timing_cutoff_hz: Some(10.0),
            ..ForceOptions::default()
        };
        let msg = detect(&trial(vec![p]), None, &blunt)
            .unwrap_err()
            .to_string();
        assert!(msg.contains("timing cutoff"), "{msg}");
    }

    #[test]
    fn truncated_contact_has_no_heel_strike() {
        let p = plate(Some(Side::Left), &[(-0.1, 0.2), (0.7, 0.95)], 500.0, 1.5);
        let r = detect(&trial(vec![p]), None, &ForceOptions::default()).unwrap();
        assert_eq!(r.contacts.len(), 2);
        assert!(r.contacts[0].on_s.is_none());
        assert!(r.contacts[0].off_s.is_some());
        let n_hs = r
            .events
            .iter()
            .filter(|e| e.kind == EventKind::HeelStrike)
            .count();
        assert_eq!(n_hs, 1);
    }

    #[test]
    fn offset_is_removed_and_reported() {
        let mut p = plate(Some(Side::Right), &[(0.3, 0.55), (1.0, 1.25)], 1000.0, 2.0);
        for f in p.force_n.iter_mut() {
            f[1] += 35.0;
        }
        let r = detect(&trial(vec![p]), None, &ForceOptions::default()).unwrap();
        assert!((r.plates[0].offset_n - 35.0).abs() < 1.0);
        assert!(r.notes.iter().any(|n| n.contains("offset")));
        let hs = r
            .events
            .iter()
            .find(|e| e.kind == EventKind::HeelStrike)
            .unwrap();
        assert!((hs.time_s - 0.3).abs() < 0.006);
    }

    #[test]
    fn drift_is_an_error_naming_the_channel_unless_corrected() {
        let mut p = plate(Some(Side::Right), &[(0.3, 0.55), (1.0, 1.25)], 1000.0, 2.0);
        for (f, t) in p.force_n.iter_mut().zip(p.time_s.clone()) {
            f[1] += 15.0 * t;
        }
        let err = detect(&trial(vec![p.clone()]), None, &ForceOptions::default()).unwrap_err();
        let msg = err.to_string();
        assert!(msg.contains("synthetic.mot") && msg.contains("FP") && msg.contains("drift"));
        let opts = ForceOptions {
            correct_drift: true,
            ..ForceOptions::default()
        };
        let r = detect(&trial(vec![p]), None, &opts).unwrap();
        assert!((r.plates[0].drift_n - 30.0).abs() < 2.0);
        assert_eq!(r.events.len(), 4);
    }

    #[test]
    fn negative_force_and_never_unloaded_are_errors() {
        let mut p = plate(Some(Side::Right), &[(0.3, 0.55)], 1000.0, 1.0);
        for f in p.force_n.iter_mut() {
            f[1] = -f[1];
        }
        assert!(detect(&trial(vec![p]), None, &ForceOptions::default())
            .unwrap_err()
            .to_string()
            .contains("flip"));
        let mut p = plate(Some(Side::Right), &[(0.3, 0.55)], 1000.0, 1.0);
        for f in p.force_n.iter_mut() {
            f[1] += 600.0;
        }
        assert!(detect(&trial(vec![p]), None, &ForceOptions::default())
            .unwrap_err()
            .to_string()
            .contains("never unloaded"));
    }

    #[test]
    fn overground_plates_alternate_and_merge() {
        // Foot 1 on plate A then B (overlapping: straddles), foot 2 on plate C.
        let mut a = plate(None, &[(0.2, 0.8)], 500.0, 2.0);
        a.name = "A".into();
        let mut b = plate(None, &[(0.5, 0.85)], 500.0, 2.0);
        b.name = "B".into();
        let mut c = plate(None, &[(0.75, 1.4)], 500.0, 2.0);
        c.name = "C".into();
        let r = detect(&trial(vec![a, b, c]), None, &ForceOptions::default()).unwrap();
        assert!(!r.complete);
        assert_eq!(r.contacts.len(), 2, "{:?}", r.contacts);
        assert_ne!(r.contacts[0].side, r.contacts[1].side);
        assert_eq!(r.contacts[0].plates.len(), 2);
    }

    #[test]
    fn a_foot_on_both_belts_is_one_contact() {
        // Running: R 0.1–0.35, L 0.5–0.75, then the right foot lands across both belts
        // (0.9–1.15 on both), then L 1.3–1.55.
        let r = plate(Some(Side::Right), &[(0.1, 0.35), (0.9, 1.15)], 1000.0, 2.0);
        let mut l = plate(
            Some(Side::Left),
            &[(0.5, 0.75), (0.92, 1.12), (1.3, 1.55)],
            1000.0,
            2.0,
        );
        l.name = "L".into();
        let res = detect(&trial(vec![r, l]), None, &ForceOptions::default()).unwrap();
        let sides: Vec<Side> = res.contacts.iter().map(|c| c.side).collect();
        assert_eq!(
            sides,
            vec![Side::Right, Side::Left, Side::Right, Side::Left]
        );
        assert!(res.notes.iter().any(|n| n.contains("both belts")));
    }

    #[test]
    fn noise_spike_is_not_a_contact() {
        let mut p = plate(Some(Side::Right), &[(0.3, 0.55)], 1000.0, 1.0);
        for i in 800..815 {
            p.force_n[i][1] = 400.0; // 15 ms spike
        }
        let r = detect(&trial(vec![p]), None, &ForceOptions::default()).unwrap();
        assert_eq!(r.contacts.len(), 1);
    }
}
