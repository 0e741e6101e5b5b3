//! One row per step in the trials schema of the fitting layer
//! ([`crate::ingest::trials::StepRow`]), built from the primary events of a trial.
//!
//! A step runs from a heel strike of one foot (A, the row's `side`) to the next heel strike of
//! the other foot (B), as in both Bruderlin & Calvert papers. Per step:
//! - step time `t_B − t_A`, step frequency `1/(t_B − t_A)`; stance of A (its heel strike to its
//!   toe off), swing of A (its toe off to its next heel strike);
//! - walking (B lands before A lifts): double support `t_ds` = B's toe off after A's heel strike
//!   − `t_A` (walking paper §3: a step is the double support state followed by the single
//!   support state), and `t_ds / t_cycle · 100` with `t_cycle = 2 / sf` as in §3. It is one
//!   period per step (the initial double support of A, which is the terminal one of B), so the
//!   mean over steps is the mean over periods; a step whose period is unknown (no toe off of B
//!   between the two heel strikes) has none. With force events the toe off is where the foot's
//!   unloading tail crosses 20 N, across the zeroed samples some exports leave inside it
//!   (`tools/events/force_truth.py` shows they hide load);
//! - running (A lifts before B lands): flight time `t_B − toe off of A`, and the flight height
//!   H of the running paper's eq. 3 from the pelvis height at A's toe off (`y1`) and B's heel
//!   strike (`y2`): `H = (t_flight − 2(y1 − y2)/(g·t_flight))² · g/8`. H is the apex of the
//!   ballistic pelvis path above `y1`; the measured apex above `y1` during the flight is written
//!   beside it (`pelvis_apex_m`) as the check;
//! - step length: footprints in the belt frame. With heel markers,
//!   `sl = fwd(heel_B(t_B)) − fwd(heel_A(t_A)) + v_belt·(t_B − t_A)` (overground `v_belt = 0`:
//!   successive heel positions; on a treadmill the belt term plus the correction for the feet's
//!   displacement on the belt). Without markers on a treadmill, the stance-mean centre of
//!   pressure in the belt frame stands in for the heel, and without that `v_belt·(t_B − t_A)`;
//! - speed: `sl · sf` of the step, so each row satisfies v = sl·sf exactly (running paper eq. 1);
//!   the trial's belt speed or mean pelvis speed is written beside it;
//! - the Ko–Badler μ inputs of A's stance (see [`super::phases::mu_inputs`]).
//!
//! With events of one foot only (Winter's table), each stride gives one row with half the stride
//! as step (length and time); double support and flight are then unknown.
use super::force::{Contact, ForceResult};
use super::kinematic::Kinematics;
use super::phases::mu_inputs;
use super::{EventError, EventKind, EventOptions, Gait, GaitEvent, Side, TrialEvents};
use crate::ingest::trials::{StepRow, CANONICAL_COLUMNS};
use crate::ingest::types::{Setting, Trial};
use crate::units::G;
use serde::{Deserialize, Serialize};
use std::io::Write;
use std::path::Path;

/// Body height per leg length when only the leg length is known: Winter (2009),
/// *Biomechanics and Motor Control of Human Movement*, Fig. 4.1, greater-trochanter height
/// 0.530 × body height.
pub const LEG_LENGTH_PER_BODY_HEIGHT: f64 = 0.530;

/// What the trials schema lacks but a user checking the numbers wants; written after the
/// canonical columns.
#[derive(Debug, Clone, PartialEq, Default, Serialize, Deserialize)]
pub struct StepExtra {
    /// The event source the step was built from.
    pub event_source: String,
    /// `treadmill`, `overground` or `unknown`.
    pub setting: String,
    /// Stride time of the leading foot, s.
    pub stride_time_s: Option<f64>,
    /// Belt speed (treadmill) or mean pelvis speed over the trial (overground), m/s.
    pub trial_speed_m_per_s: Option<f64>,
    /// Measured apex of the pelvis above its toe-off height during the flight, m (the check of
    /// eq. 3).
    pub pelvis_apex_m: Option<f64>,
    /// How the step length was obtained (`heel`, `belt+heel`, `belt+cop`, `belt`,
    /// `half-stride`).
    pub step_length_method: String,
}

/// The extra column headers, in order.
pub const EXTRA_COLUMNS: &[&str] = &[
    "event_source",
    "setting",
    "stride_time_s",
    "trial_speed_m_per_s",
    "pelvis_apex_m",
    "sl_method",
];

/// The per-step table of one trial.
#[derive(Debug, Clone, PartialEq, Default, Serialize, Deserialize)]
pub struct StepTable {
    /// One row per step.
    pub rows: Vec<StepRow>,
    /// The extra columns of each row.
    pub extra: Vec<StepExtra>,
    /// Notes (assumptions, estimates, dropped steps).
    pub notes: Vec<String>,
}

/// Everything detected in one trial.
#[derive(Debug, Clone, PartialEq)]
pub struct Analysis {
    /// The events by source.
    pub events: TrialEvents,
    /// The filtered marker kinematics, when the trial has markers.
    pub kinematics: Option<Kinematics>,
    /// The force-plate processing result.
    pub force: ForceResult,
}

/// The source text of a trial: its path relative to the shared data folder when it lies there
/// (`hamner2013/subject01/Run_3_grf.mot`), else its file name.
pub fn source_label(trial: &Trial) -> String {
    if let Some(root) = crate::shared_data::locate() {
        let root = root.canonicalize().unwrap_or(root);
        let src = trial
            .source
            .canonicalize()
            .unwrap_or_else(|_| trial.source.clone());
        if let Ok(rel) = src.strip_prefix(&root) {
            return rel.display().to_string();
        }
    }
    trial
        .source
        .file_name()
        .map(|n| n.to_string_lossy().into_owned())
        .unwrap_or_else(|| trial.source.display().to_string())
}

/// The subject id from the file, else `<folder>_<trial>`: without subject data, gaitfit cannot
/// tell whether two files of one folder are one person, and assumes they are not.
pub fn subject_label(trial: &Trial) -> String {
    if let Some(id) = &trial.subject.id {
        if !id.trim().is_empty() {
            return id.trim().to_string();
        }
    }
    // Folders named after the kind of trial (Schreiber's `2014001/dynamic/`) are skipped: the
    // subject's folder is the one above.
    const GENERIC: &[&str] = &["dynamic", "static", "trials", "data", "c3d", "raw", "gait"];
    let mut dir = trial.source.parent();
    while let Some(d) = dir {
        let name = d
            .file_name()
            .map(|n| n.to_string_lossy().into_owned())
            .unwrap_or_default();
        if GENERIC.contains(&name.to_ascii_lowercase().as_str()) {
            dir = d.parent();
            continue;
        }
        if name.is_empty() {
            break;
        }
        // A folder per subject (`2014001/…`) names the subject; a folder of several people's
        // files (`bmclab/`) does not, and each file is taken as its own subject.
        return if name.chars().any(|c| c.is_ascii_digit()) {
            name
        } else {
            format!("{name}_{}", trial.name)
        };
    }
    trial.name.clone()
}

/// The mean centre-of-pressure position of a contact in the belt frame along the forward axis.
fn belt_cop(c: &Contact, fwd: usize, sign: f64, v: f64) -> Option<f64> {
    let cop = c.cop_m?;
    let t = c.cop_time_mean_s?;
    Some(sign * cop[fwd] + v * t)
}

fn first_after(ev: &[&GaitEvent], t: f64, until: f64) -> Option<f64> {
    ev.iter().map(|e| e.time_s).find(|&x| x > t && x < until)
}

/// Builds the per-step table of `trial` from its analysis.
pub fn steps_from_analysis(
    trial: &Trial,
    an: &Analysis,
    opts: &EventOptions,
) -> Result<StepTable, EventError> {
    let path = an.events.path.clone();
    let ev = an.events.primary_events();
    let kin = an.kinematics.as_ref();
    let mut table = StepTable::default();
    let src_name = an.events.primary.as_str();
    let setting = opts.setting.unwrap_or(match (trial.setting, kin) {
        (Setting::Unknown, Some(k)) => k.setting,
        (s, _) => s,
    });
    let belt = match setting {
        Setting::Treadmill { belt_speed_m_per_s } => Some(belt_speed_m_per_s),
        _ => None,
    };
    let setting_name = match setting {
        Setting::Treadmill { .. } => "treadmill",
        Setting::Overground => "overground",
        Setting::Unknown => "unknown",
    };
    let v_belt = belt.unwrap_or(0.0);
    let hs: Vec<&GaitEvent> = ev
        .iter()
        .filter(|e| e.kind == EventKind::HeelStrike)
        .collect();
    let to: Vec<&GaitEvent> = ev.iter().filter(|e| e.kind == EventKind::ToeOff).collect();
    let hs_of =
        |s: Side| -> Vec<&GaitEvent> { hs.iter().copied().filter(|e| e.side == s).collect() };
    let to_of =
        |s: Side| -> Vec<&GaitEvent> { to.iter().copied().filter(|e| e.side == s).collect() };
    let sides_with_hs: Vec<Side> = [Side::Left, Side::Right]
        .into_iter()
        .filter(|s| !hs_of(*s).is_empty())
        .collect();
    if hs.len() < 2 {
        return Err(EventError::TooShort {
            path,
            reason: format!(
                "{} heel strike(s) from the {src_name} events; a step needs two",
                hs.len()
            ),
        });
    }
    // Subject data.
    let mut body_height = trial.subject.body_height_m;
    let mut leg_length = trial.subject.leg_length_m;
    if body_height.is_none() && leg_length.is_none() {
        if let Some((l, how)) = kin.and_then(leg_from_hip_markers) {
            leg_length = Some(l);
            table.notes.push(how);
        }
    }
    if body_height.is_none() {
        if let Some(l) = leg_length {
            body_height = Some(l / LEG_LENGTH_PER_BODY_HEIGHT);
            table.notes.push(format!(
                "warning: body height {:.3} m estimated from the leg length {l:.3} m as leg / {} \
                 (Winter 2009, Fig. 4.1)",
                l / LEG_LENGTH_PER_BODY_HEIGHT,
                LEG_LENGTH_PER_BODY_HEIGHT
            ));
        }
    }
    // Mean pelvis speed (overground).
    let pelvis_speed = kin.and_then(|k| {
        let n = k.pelvis.len();
        (n > 1).then(|| {
            (k.fwd(&k.pelvis[n - 1]) - k.fwd(&k.pelvis[0])) / (k.time_s[n - 1] - k.time_s[0])
        })
    });
    let trial_speed = belt.or(if matches!(setting, Setting::Overground) {
        pelvis_speed
    } else {
        None
    });
    // Forward axis and sign of the centres of pressure on a treadmill: the stance foot moves
    // backward with the belt, so the centre of pressure does too.
    let cop_axis = cop_forward_axis(&an.force.contacts, trial, kin);
    let heel_at = |side: Side, t: f64| -> Option<f64> {
        let k = kin?;
        let h = k.leg(side).heel.as_ref()?;
        k.sample3(h, t).map(|p| k.fwd(&p))
    };
    let contact_at = |side: Side, t: f64| -> Option<&Contact> {
        an.force
            .contacts
            .iter()
            .find(|c| c.side == side && c.on_s.is_some_and(|on| (on - t).abs() < 0.06))
    };
    let base_row = |side: Side, t: f64| StepRow {
        subject: subject_label(trial),
        gait: None,
        side: Some(side),
        source: source_label(trial),
        trial: trial.name.clone(),
        time_s: Some(t),
        body_height_m: body_height,
        leg_length_m: leg_length,
        ..StepRow::default()
    };
    let mut rows: Vec<(StepRow, StepExtra, Option<Gait>)> = Vec::new();
    if sides_with_hs.len() == 1 {
        // One foot only: one row per stride, half a stride per step.
        let side = sides_with_hs[0];
        let h = hs_of(side);
        let t_off = to_of(side);
        table.notes.push(format!(
            "events of the {side} foot only: one row per stride, step length and time are half \
             the stride's"
        ));
        for w in h.windows(2) {
            let (ta, tc) = (w[0].time_s, w[1].time_s);
            let stride_t = tc - ta;
            let stride_len = match (heel_at(side, ta), heel_at(side, tc), setting) {
                (_, _, Setting::Unknown) => None,
                (Some(a), Some(c), _) => Some(c - a + v_belt * stride_t),
                _ => belt.map(|v| v * stride_t),
            };
            let mut row = base_row(side, ta);
            let step_t = 0.5 * stride_t;
            row.step_freq_hz = Some(1.0 / step_t);
            row.step_length_m = stride_len.map(|l| 0.5 * l);
            row.speed_m_per_s = stride_len.map(|l| l / stride_t);
            if let Some(t1) = first_after(&t_off, ta, tc) {
                row.stance_time_s = Some(t1 - ta);
                row.swing_time_s = Some(tc - t1);
            }
            fill_mu(&mut row, kin, side, ta, first_after(&t_off, ta, tc));
            let extra = StepExtra {
                event_source: src_name.into(),
                setting: setting_name.into(),
                stride_time_s: Some(stride_t),
                trial_speed_m_per_s: trial_speed,
                pelvis_apex_m: None,
                step_length_method: "half-stride".into(),
            };
            let gait = row.stance_time_s.map(|st| {
                if st > 0.5 * stride_t {
                    Gait::Walk
                } else {
                    Gait::Run
                }
            });
            rows.push((row, extra, gait));
        }
    } else {
        let mut skipped_same_side = 0;
        for w in hs.windows(2) {
            let (a, b) = (w[0], w[1]);
            if a.side == b.side {
                skipped_same_side += 1;
                continue;
            }
            let (ta, tb) = (a.time_s, b.time_s);
            let step_t = tb - ta;
            if step_t <= 0.0 {
                continue;
            }
            let hs_a = hs_of(a.side);
            let next_a = hs_a.iter().map(|e| e.time_s).find(|&t| t > tb);
            let to_a = first_after(&to_of(a.side), ta, next_a.unwrap_or(ta + 3.0));
            let to_b = first_after(&to_of(b.side), ta, tb);
            let mut row = base_row(a.side, ta);
            row.step_freq_hz = Some(1.0 / step_t);
            let stride_t = next_a.map(|n| n - ta);
            if let Some(t1) = to_a {
                row.stance_time_s = Some(t1 - ta);
                if let Some(n) = next_a {
                    row.swing_time_s = Some(n - t1);
                }
            }
            let mut gait = None;
            let mut peak = None;
            if let Some(t1) = to_a.filter(|&t1| t1 < tb) {
                // A lifts before B lands: flight.
                gait = Some(Gait::Run);
                let tf = tb - t1;
                row.flight_time_s = Some(tf);
                if let Some(k) = kin {
                    if let (Some(y1), Some(y2)) = (
                        k.sample(&k.pelvis_height, t1),
                        k.sample(&k.pelvis_height, tb),
                    ) {
                        row.flight_height_m = Some(flight_height(tf, y1, y2));
                        let (i0, i1) = (k.frame_at(t1), k.frame_at(tb));
                        let top = k.pelvis_height[i0..=i1]
                            .iter()
                            .copied()
                            .fold(f64::NEG_INFINITY, f64::max);
                        peak = Some((top - y1).max(0.0));
                    }
                }
            } else if let Some(t2) = to_b {
                gait = Some(Gait::Walk);
                row.double_support_time_s = Some(t2 - ta);
                // t_cycle = 2 / sf, the walking paper's §3 (and the trials schema's) definition.
                row.double_support_pct_cycle = Some((t2 - ta) / (2.0 * step_t) * 100.0);
            }
            // Step length. On a treadmill of unknown speed the heels alone say nothing.
            let heel_pair = match setting {
                Setting::Overground | Setting::Treadmill { .. } => {
                    heel_at(a.side, ta).zip(heel_at(b.side, tb))
                }
                Setting::Unknown => None,
            };
            let (sl, method) = match heel_pair {
                Some((xa, xb)) => (
                    Some(xb - xa + v_belt * step_t),
                    if belt.is_some() { "belt+heel" } else { "heel" },
                ),
                None => match (belt, cop_axis) {
                    (Some(v), Some((fwd, sign))) => {
                        match (
                            contact_at(a.side, ta).and_then(|c| belt_cop(c, fwd, sign, v)),
                            contact_at(b.side, tb).and_then(|c| belt_cop(c, fwd, sign, v)),
                        ) {
                            (Some(xa), Some(xb)) => (Some(xb - xa), "belt+cop"),
                            _ => (Some(v * step_t), "belt"),
                        }
                    }
                    (Some(v), None) => (Some(v * step_t), "belt"),
                    _ => (None, ""),
                },
            };
            row.step_length_m = sl;
            row.speed_m_per_s = sl.map(|l| l / step_t);
            fill_mu(&mut row, kin, a.side, ta, to_a);
            let extra = StepExtra {
                event_source: src_name.into(),
                setting: setting_name.into(),
                stride_time_s: stride_t,
                trial_speed_m_per_s: trial_speed,
                pelvis_apex_m: peak,
                step_length_method: method.into(),
            };
            rows.push((row, extra, gait));
        }
        if skipped_same_side > 0 {
            table.notes.push(format!(
                "{skipped_same_side} pair(s) of successive heel strikes of the same foot skipped \
                 (an event of the other foot is missing there)"
            ));
        }
    }
    // Drop implausible steps: step time outside 0.6–1.6 × the median (a missed event).
    let mut times: Vec<f64> = rows
        .iter()
        .filter_map(|(r, _, _)| r.step_freq_hz.map(|f| 1.0 / f))
        .collect();
    times.sort_by(f64::total_cmp);
    if let Some(&med) = times.get(times.len() / 2) {
        let before = rows.len();
        rows.retain(|(r, _, _)| {
            r.step_freq_hz
                .map(|f| (0.6 * med..=1.6 * med).contains(&(1.0 / f)))
                .unwrap_or(false)
        });
        if rows.len() < before {
            table.notes.push(format!(
                "{} step(s) dropped: step time outside 0.6–1.6 × the median {med:.3} s",
                before - rows.len()
            ));
        }
    }
    if rows.is_empty() {
        return Err(EventError::TooShort {
            path,
            reason: format!(
                "the {src_name} events ({} heel strikes) give no complete step",
                hs.len()
            ),
        });
    }
    // Gait: the option, the trial, or the majority of the steps.
    let n_run = rows.iter().filter(|r| r.2 == Some(Gait::Run)).count();
    let n_walk = rows.iter().filter(|r| r.2 == Some(Gait::Walk)).count();
    let gait = opts.gait.or(trial.gait).unwrap_or(if n_run > n_walk {
        Gait::Run
    } else {
        Gait::Walk
    });
    for (mut row, mut extra, g) in rows {
        row.gait = Some(gait);
        if g.is_some() && g != Some(gait) {
            // A step whose events contradict the trial's gait keeps no phase time.
            row.flight_time_s = None;
            row.flight_height_m = None;
            extra.pelvis_apex_m = None;
            row.double_support_time_s = None;
            row.double_support_pct_cycle = None;
        }
        table.rows.push(row);
        table.extra.push(extra);
    }
    Ok(table)
}

/// Leg length estimated from the hip (greater trochanter or hip joint centre) markers while
/// walking: the median height of the hip markers above the floor, the floor taken at 0 and
/// checked by the lowest foot marker standing 0–12 cm above it. Walking flexes the knee a little,
/// so this reads a centimetre or two under the standing value.
fn leg_from_hip_markers(k: &Kinematics) -> Option<(f64, String)> {
    let mut hips: Vec<f64> = Vec::new();
    let mut lowest = f64::INFINITY;
    let mut names = Vec::new();
    for side in [Side::Left, Side::Right] {
        let l = k.leg(side);
        if let Some(h) = &l.hip {
            hips.extend(h.iter().map(|p| k.up(p)).filter(|v| v.is_finite()));
            names.push(l.names.hip.clone());
        }
        for m in [&l.heel, &l.toe, &l.meta].into_iter().flatten() {
            lowest = lowest.min(m.iter().map(|p| k.up(p)).fold(f64::INFINITY, f64::min));
        }
    }
    if hips.is_empty() || !(0.0..=0.12).contains(&lowest) {
        return None;
    }
    hips.sort_by(f64::total_cmp);
    let leg = hips[hips.len() / 2];
    (0.5..1.3).contains(&leg).then(|| {
        (
            leg,
            format!(
                "leg length {leg:.3} m estimated as the median height of the hip markers ({}) \
                 during the trial (no subject data in the file; the lowest foot marker is \
                 {lowest:.3} m above the floor)",
                names.join(", ")
            ),
        )
    })
}

fn fill_mu(row: &mut StepRow, kin: Option<&Kinematics>, side: Side, hs: f64, to: Option<f64>) {
    let (Some(k), Some(to)) = (kin, to) else {
        return;
    };
    let mu = mu_inputs(k, side, hs, to);
    row.knee_angle_hs_rad = mu.knee_hs;
    row.foot_angle_hs_rad = mu.foot_hs;
    row.foot_angle_to_rad = mu.foot_to;
    row.meta_angle_to_rad = mu.meta_to;
}

/// The running paper's eq. 3: flight height `H = (t − 2(y1 − y2)/(g t))² · g/8`, m, from the
/// flight time `t` (s) and the pelvis heights at toe off `y1` and heel strike `y2` (m): the apex
/// of the ballistic path above `y1`.
///
/// ```
/// use gaitfit::events::steps::flight_height;
/// // Level take-off and landing, 0.1 s of flight: apex g·t²/8 ≈ 12.3 mm.
/// assert!((flight_height(0.1, 1.0, 1.0) - 9.80665 * 0.01 / 8.0).abs() < 1e-12);
/// ```
pub fn flight_height(t_flight: f64, y1: f64, y2: f64) -> f64 {
    let a = t_flight - 2.0 * (y1 - y2) / (G * t_flight);
    a * a * G / 8.0
}

/// The forward axis and sign of the centre of pressure on a treadmill: the horizontal axis
/// along which the centre of pressure moves most during contacts, and the sign opposite to its
/// median velocity (the stance foot travels backward with the belt).
fn cop_forward_axis(
    contacts: &[Contact],
    trial: &Trial,
    kin: Option<&Kinematics>,
) -> Option<(usize, f64)> {
    let vertical = trial
        .frame
        .as_ref()
        .map(|f| f.vertical.index())
        .or(kin.map(|k| k.vertical))
        .unwrap_or(1);
    let slopes: Vec<[f64; 3]> = contacts.iter().filter_map(|c| c.cop_slope).collect();
    if slopes.is_empty() {
        return None;
    }
    let median = |a: usize| {
        let mut v: Vec<f64> = slopes.iter().map(|s| s[a]).collect();
        v.sort_by(f64::total_cmp);
        v[v.len() / 2]
    };
    let axis = (0..3)
        .filter(|&a| a != vertical)
        .max_by(|&a, &b| median(a).abs().total_cmp(&median(b).abs()))?;
    let m = median(axis);
    (m != 0.0).then_some((axis, -m.signum()))
}

/// Formats an optional number for CSV (empty when absent).
fn num(v: Option<f64>, decimals: usize) -> String {
    match v {
        Some(x) if x.is_finite() => {
            let s = format!("{x:.decimals$}");
            if s.contains('.') {
                s.trim_end_matches('0').trim_end_matches('.').to_string()
            } else {
                s
            }
        }
        _ => String::new(),
    }
}

/// The CSV cells of one row, in [`CANONICAL_COLUMNS`] then [`EXTRA_COLUMNS`] order.
pub fn row_cells(r: &StepRow, x: &StepExtra) -> Vec<String> {
    let deg = |v: Option<f64>| num(v.map(f64::to_degrees), 2);
    let mut cells = vec![
        r.subject.clone(),
        r.gait.map(|g| g.to_string()).unwrap_or_default(),
        r.side.map(|s| s.to_string()).unwrap_or_default(),
        r.source.clone(),
        r.trial.clone(),
        num(r.time_s, 4),
        num(r.speed_m_per_s, 4),
        num(r.step_length_m, 4),
        num(r.step_freq_hz.map(crate::units::hz_to_steps_per_min), 3),
        num(r.stance_time_s, 4),
        num(r.swing_time_s, 4),
        num(r.double_support_time_s, 4),
        num(r.double_support_pct_cycle, 2),
        num(r.flight_time_s, 4),
        num(r.flight_height_m, 5),
        num(r.body_height_m, 4),
        num(r.leg_length_m, 4),
        deg(r.knee_angle_hs_rad),
        deg(r.foot_angle_hs_rad),
        deg(r.foot_angle_to_rad),
        deg(r.meta_angle_to_rad),
    ];
    debug_assert_eq!(cells.len(), CANONICAL_COLUMNS.len());
    cells.extend([
        x.event_source.clone(),
        x.setting.clone(),
        num(x.stride_time_s, 4),
        num(x.trial_speed_m_per_s, 4),
        num(x.pelvis_apex_m, 5),
        x.step_length_method.clone(),
    ]);
    cells
}

/// Writes the step tables to `out` as CSV (canonical columns, then the extra columns).
pub fn write_csv_to(out: &mut dyn Write, tables: &[StepTable]) -> std::io::Result<()> {
    let mut w = csv::Writer::from_writer(out);
    let header: Vec<&str> = CANONICAL_COLUMNS
        .iter()
        .chain(EXTRA_COLUMNS)
        .copied()
        .collect();
    w.write_record(&header)?;
    for t in tables {
        for (r, x) in t.rows.iter().zip(&t.extra) {
            w.write_record(row_cells(r, x))?;
        }
    }
    w.flush()?;
    Ok(())
}

/// Writes the step tables to `path` atomically.
pub fn write_csv(path: &Path, tables: &[StepTable]) -> Result<(), EventError> {
    crate::fsio::write_atomic(path, |w| {
        write_csv_to(w, tables).map_err(|e| EventError::Write {
            path: path.display().to_string(),
            message: e.to_string(),
        })
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn flight_height_matches_a_ballistic_path() {
        // Take off at y1 = 1.00 m with vertical speed 0.5 m/s; land 0.12 s later.
        let (y1, vy, t) = (1.0, 0.5, 0.12);
        let y2 = y1 + vy * t - 0.5 * G * t * t;
        let apex = vy * vy / (2.0 * G);
        assert!((flight_height(t, y1, y2) - apex).abs() < 1e-12);
    }

    #[test]
    fn num_trims() {
        assert_eq!(num(Some(1.5), 4), "1.5");
        assert_eq!(num(Some(2.0), 4), "2");
        assert_eq!(num(None, 4), "");
        assert_eq!(num(Some(f64::NAN), 4), "");
    }
}
