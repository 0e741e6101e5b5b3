//! What `gaitfit calibrate` measures on a trial, measured or generated, with the same code:
//! the gait (decided from the data), the per-step quantities averaged over the steady steps,
//! the pelvis vertical excursion and the sagittal hip/knee/ankle angle curves over the
//! normalised stride.
use crate::events::kinematic::Kinematics;
use crate::events::{
    analyse, steps_from_analysis, EventKind, EventOptions, Gait, PrimarySource, Side,
};
use crate::ingest::trials::StepRow;
use crate::ingest::types::{MarkerSet, Trial};

/// Number of samples of a normalised-cycle curve (0, 1, …, 100 % of the stride).
pub const CYCLE_POINTS: usize = 101;

/// The averaged per-step quantities of one trial (or of one generated motion).
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct Quantities {
    /// Steps averaged.
    pub steps: usize,
    /// Mean speed over the steps, m/s (step length × step frequency).
    pub speed_m_per_s: f64,
    /// Cadence, steps/min (60 × mean step frequency).
    pub cadence_steps_per_min: f64,
    /// Mean step length, m.
    pub step_length_m: f64,
    /// Mean contact (stance) time, s.
    pub contact_time_s: Option<f64>,
    /// Mean flight time, s (runs).
    pub flight_time_s: Option<f64>,
    /// Mean double support, % of the cycle (walks; t_cycle = 2 / sf as in the steps table).
    pub double_support_pct_cycle: Option<f64>,
    /// Mean vertical excursion of the pelvis within a step (max − min), m.
    pub pelvis_excursion_m: Option<f64>,
    /// Step-to-step standard deviations of the same quantities (the objective's scales), in
    /// the order cadence, step length, contact, flight/double support, pelvis excursion.
    pub sd: [Option<f64>; 5],
}

/// Mean sagittal joint-angle curves over the normalised stride (heel strike to the next heel
/// strike of the same foot), degrees, [`CYCLE_POINTS`] samples each.
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct Curves {
    /// Strides averaged.
    pub strides: usize,
    /// Thigh angle: forward inclination of hip→knee from the downward vertical in the sagittal
    /// plane (hip flexion with the pelvis taken as upright), degrees.
    pub hip_deg: Vec<f64>,
    /// Knee flexion: 180° − the hip–knee–ankle angle, degrees.
    pub knee_deg: Vec<f64>,
    /// Ankle: angle between shank (knee→ankle) and foot (heel→toe) minus 90°, dorsiflexion
    /// positive, degrees.
    pub ankle_deg: Vec<f64>,
}

/// What one trial yields.
#[derive(Debug, Clone)]
pub struct Measurement {
    /// Walk or run, decided from the data.
    pub gait: Gait,
    /// How the gait was decided.
    pub gait_evidence: String,
    /// Averaged quantities.
    pub quantities: Quantities,
    /// Joint-angle curves, where hip, knee, ankle, heel and toe points exist.
    pub curves: Option<Curves>,
    /// Notes of the event detection.
    pub notes: Vec<String>,
}

/// Errors of the measurement.
pub type Result<T> = std::result::Result<T, crate::events::EventError>;

/// Walk or run from the data alone (never the file name): the steps are built with the gait
/// left open — from the force plates or the file's measured events where they exist, else
/// from the foot-marker heights — and a step is a run when the stance foot lifts before the
/// other lands (a flight phase), a walk when both feet are on the ground together (double
/// support); the majority decides. Returns the gait and a sentence of evidence.
pub fn gait_from_data(trial: &Trial) -> Result<(Gait, String)> {
    let mut t = trial.clone();
    t.gait = None;
    let primary = if t.plates.is_empty() && !has_measured_events(&t) {
        PrimarySource::FootHeight
    } else {
        PrimarySource::Auto
    };
    let run = |primary: PrimarySource| -> Result<_> {
        let opts = EventOptions {
            primary,
            gait: None,
            ..EventOptions::default()
        };
        let an = analyse(&t, &opts)?;
        let table = steps_from_analysis(&t, &an, &opts)?;
        Ok((an, table))
    };
    // The foot heights see no contact in a walk whose feet roll over the ground (they are
    // seeded by Zeni stances): the default detection then decides.
    let (an, table) = match run(primary) {
        Ok(x) => x,
        Err(_) if primary == PrimarySource::FootHeight => run(PrimarySource::Auto)?,
        Err(e) => return Err(e),
    };
    let n_flight = table
        .rows
        .iter()
        .filter(|r| r.flight_time_s.is_some())
        .count();
    let n_ds = table
        .rows
        .iter()
        .filter(|r| r.double_support_time_s.is_some())
        .count();
    let gait = if n_flight > n_ds {
        Gait::Run
    } else {
        Gait::Walk
    };
    Ok((
        gait,
        format!(
            "{gait}: {n_flight} step(s) with a flight phase, {n_ds} with double support ({} events)",
            an.events.primary.as_str()
        ),
    ))
}

/// The event options `calibrate` measures a trial with: the defaults (force plates where they
/// cover every contact, else the file's measured events, else the walking foot-speed
/// detector), except that runs seen by markers alone use the foot-marker heights (the Zeni
/// stances mistime the flight of runs), and noise-free generated motion is filtered at
/// `cutoff_hz` with a `tol_m` foot-height tolerance instead of the measured defaults.
pub fn event_options(trial: &Trial, gait: Gait, generated: Option<(f64, f64)>) -> EventOptions {
    let mut o = EventOptions {
        gait: Some(gait),
        ..EventOptions::default()
    };
    if gait == Gait::Run && trial.plates.is_empty() && !has_measured_events(trial) {
        o.primary = PrimarySource::FootHeight;
    }
    if let Some((cutoff_hz, tol_m)) = generated {
        o.kinematic.cutoff_hz = cutoff_hz;
        o.phases.height_tol_m = tol_m;
    }
    o
}

/// Whether the trial carries measured events (a laboratory's C3D events), not a generator's own.
fn has_measured_events(trial: &Trial) -> bool {
    trial
        .reference_events
        .iter()
        .any(|e| e.source != crate::events::EventSource::Generated)
}

fn mean_sd(v: &[f64]) -> Option<(f64, Option<f64>)> {
    if v.is_empty() {
        return None;
    }
    let n = v.len() as f64;
    let m = v.iter().sum::<f64>() / n;
    let sd =
        (v.len() > 1).then(|| (v.iter().map(|x| (x - m).powi(2)).sum::<f64>() / (n - 1.0)).sqrt());
    Some((m, sd))
}

/// Measures `trial` as `gait` with `opts`, averaging the steps that start within
/// `[t0, t1]` (s).
pub fn measure(
    trial: &Trial,
    gait: Gait,
    gait_evidence: String,
    opts: &EventOptions,
    window: (f64, f64),
) -> Result<Measurement> {
    let an = analyse(trial, opts)?;
    let table = steps_from_analysis(trial, &an, opts)?;
    let path = an.events.path.clone();
    let mut notes = an.events.notes.clone();
    notes.extend(table.notes.iter().cloned());
    let rows: Vec<_> = table
        .rows
        .iter()
        .filter(|r| r.time_s.is_some_and(|t| t >= window.0 && t <= window.1))
        .collect();
    let no_steps = || {
        let within = if window.0.is_finite() || window.1.is_finite() {
            format!(" starting between {:.2} and {:.2} s", window.0, window.1)
        } else {
            String::new()
        };
        // Steps timed by the forces but without a length: nothing in the trial measures
        // distance (no markers, no belt speed), which is not a short record.
        let unmeasured = rows
            .iter()
            .any(|r| r.step_freq_hz.is_some() && r.step_length_m.is_none());
        if unmeasured && trial.markers.is_none() {
            crate::events::EventError::Missing {
                path: path.clone(),
                what: format!(
                    "step lengths{within}: the steps are timed by the forces, but force data alone \
                     measures no distance; give the trial's markers (e.g. its TRC beside the \
                     MOT) or a treadmill's belt speed"
                ),
            }
        } else {
            crate::events::EventError::TooShort {
                path: path.clone(),
                reason: format!("no step with a step length and frequency{within}"),
            }
        }
    };
    // Pelvis excursion per step: max − min of the pelvis height between successive heel
    // strikes of the primary events.
    let mut exc = Vec::new();
    let hs: Vec<f64> = an
        .events
        .primary_events()
        .iter()
        .filter(|e| e.kind == EventKind::HeelStrike)
        .map(|e| e.time_s)
        .filter(|t| *t >= window.0 && *t <= window.1)
        .collect();
    if let Some(k) = &an.kinematics {
        for w in hs.windows(2) {
            let (i0, i1) = (k.frame_at(w[0]), k.frame_at(w[1]));
            if i1 <= i0 + 2 {
                continue;
            }
            let seg = &k.pelvis_height[i0..=i1];
            let hi = seg.iter().copied().fold(f64::NEG_INFINITY, f64::max);
            let lo = seg.iter().copied().fold(f64::INFINITY, f64::min);
            if hi.is_finite() && lo.is_finite() {
                exc.push(hi - lo);
            }
        }
    }
    let quantities = quantities_of(&rows, gait, mean_sd(&exc)).ok_or_else(no_steps)?;
    let curves = an.kinematics.as_ref().and_then(|k| {
        curves(
            k,
            an.events.primary_events().iter().filter(|e| {
                e.kind == EventKind::HeelStrike && e.time_s >= window.0 && e.time_s <= window.1
            }),
        )
    });
    Ok(Measurement {
        gait,
        gait_evidence,
        quantities,
        curves,
        notes,
    })
}

/// The averaged quantities of step rows (`None` without a step that has both a step length
/// and a frequency); `excursion` is the pelvis excursion's mean and SD, measured elsewhere.
fn quantities_of(
    rows: &[&StepRow],
    gait: Gait,
    excursion: Option<(f64, Option<f64>)>,
) -> Option<Quantities> {
    let col = |f: &dyn Fn(&StepRow) -> Option<f64>| -> Vec<f64> {
        rows.iter()
            .filter_map(|r| f(r))
            .filter(|x| x.is_finite())
            .collect()
    };
    let cad = mean_sd(&col(&|r| r.step_freq_hz.map(|f| 60.0 * f)))?;
    let slm = mean_sd(&col(&|r| r.step_length_m))?;
    let contact = mean_sd(&col(&|r| r.stance_time_s));
    let phase = match gait {
        Gait::Run => mean_sd(&col(&|r| r.flight_time_s)),
        Gait::Walk => mean_sd(&col(&|r| r.double_support_pct_cycle)),
    };
    Some(Quantities {
        steps: rows.len(),
        speed_m_per_s: slm.0 * cad.0 / 60.0,
        cadence_steps_per_min: cad.0,
        step_length_m: slm.0,
        contact_time_s: contact.map(|c| c.0),
        flight_time_s: (gait == Gait::Run).then(|| phase.map(|p| p.0)).flatten(),
        double_support_pct_cycle: (gait == Gait::Walk).then(|| phase.map(|p| p.0)).flatten(),
        pelvis_excursion_m: excursion.map(|e| e.0),
        sd: [
            cad.1,
            slm.1,
            contact.and_then(|c| c.1),
            phase.and_then(|p| p.1),
            excursion.and_then(|e| e.1),
        ],
    })
}

/// Measures one trial's rows of a steps table (`gaitfit events` output, or a table of
/// `data/`): the same averages as [`measure`] from the rows' own step quantities; no pelvis
/// excursion and no angle curves (a steps table has no per-frame data). `None` without a step
/// that has both a step length and a frequency.
pub fn measure_rows(rows: &[StepRow], gait: Gait, gait_evidence: String) -> Option<Measurement> {
    let rows: Vec<&StepRow> = rows.iter().collect();
    Some(Measurement {
        gait,
        gait_evidence,
        quantities: quantities_of(&rows, gait, None)?,
        curves: None,
        notes: Vec::new(),
    })
}

fn sub(a: &[f64; 3], b: &[f64; 3]) -> [f64; 3] {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}

fn angle_between(a: &[f64; 3], b: &[f64; 3]) -> f64 {
    let dot = a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
    let na = (a[0] * a[0] + a[1] * a[1] + a[2] * a[2]).sqrt();
    let nb = (b[0] * b[0] + b[1] * b[1] + b[2] * b[2]).sqrt();
    (dot / (na * nb)).clamp(-1.0, 1.0).acos().to_degrees()
}

/// The three sagittal angles (degrees) at one instant from hip, knee, ankle, heel and toe.
fn angles(k: &Kinematics, p: [[f64; 3]; 5]) -> [f64; 3] {
    let [hip, knee, ankle, heel, toe] = p;
    let thigh = sub(&knee, &hip);
    let shank = sub(&ankle, &knee);
    let foot = sub(&toe, &heel);
    let hip_deg = k.fwd(&thigh).atan2(-k.up(&thigh)).to_degrees();
    let knee_deg = angle_between(&thigh, &shank);
    let ankle_deg = angle_between(&sub(&knee, &ankle), &foot) - 90.0;
    [hip_deg, knee_deg, ankle_deg]
}

/// Mean curves over the strides between successive heel strikes of each foot (both feet
/// pooled, each stride resampled to [`CYCLE_POINTS`] points).
fn curves<'a>(
    k: &Kinematics,
    hs: impl Iterator<Item = &'a crate::events::GaitEvent>,
) -> Option<Curves> {
    let hs: Vec<_> = hs.collect();
    let mut sum = [[0.0; CYCLE_POINTS]; 3];
    let mut strides = 0usize;
    for side in [Side::Left, Side::Right] {
        let leg = k.leg(side);
        let (Some(hip), Some(knee), Some(ankle), Some(heel), Some(toe)) = (
            leg.hip.as_ref(),
            leg.knee.as_ref(),
            leg.ankle.as_ref(),
            leg.heel.as_ref(),
            leg.toe.as_ref(),
        ) else {
            continue;
        };
        let times: Vec<f64> = hs
            .iter()
            .filter(|e| e.side == side)
            .map(|e| e.time_s)
            .collect();
        'stride: for w in times.windows(2) {
            let mut one = [[0.0; CYCLE_POINTS]; 3];
            for (j, o) in (0..CYCLE_POINTS).zip(0..) {
                let t = w[0] + (w[1] - w[0]) * j as f64 / (CYCLE_POINTS - 1) as f64;
                let pts = [
                    k.sample3(hip, t),
                    k.sample3(knee, t),
                    k.sample3(ankle, t),
                    k.sample3(heel, t),
                    k.sample3(toe, t),
                ];
                let mut p = [[0.0; 3]; 5];
                for (dst, src) in p.iter_mut().zip(pts) {
                    match src {
                        Some(v) => *dst = v,
                        None => continue 'stride,
                    }
                }
                let a = angles(k, p);
                for c in 0..3 {
                    one[c][o] = a[c];
                }
            }
            if one.iter().flatten().all(|v| v.is_finite()) {
                for c in 0..3 {
                    for j in 0..CYCLE_POINTS {
                        sum[c][j] += one[c][j];
                    }
                }
                strides += 1;
            }
        }
    }
    (strides > 0).then(|| {
        let avg = |c: usize| sum[c].iter().map(|v| v / strides as f64).collect();
        Curves {
            strides,
            hip_deg: avg(0),
            knee_deg: avg(1),
            ankle_deg: avg(2),
        }
    })
}

/// RMS difference and Pearson correlation of two curves of equal length.
pub fn rms_corr(a: &[f64], b: &[f64]) -> (f64, f64) {
    let n = a.len().min(b.len());
    if n == 0 {
        return (f64::NAN, f64::NAN);
    }
    let rms = (a.iter().zip(b).map(|(x, y)| (x - y).powi(2)).sum::<f64>() / n as f64).sqrt();
    let ma = a[..n].iter().sum::<f64>() / n as f64;
    let mb = b[..n].iter().sum::<f64>() / n as f64;
    let (mut sab, mut saa, mut sbb) = (0.0, 0.0, 0.0);
    for (x, y) in a.iter().zip(b) {
        sab += (x - ma) * (y - mb);
        saa += (x - ma).powi(2);
        sbb += (y - mb).powi(2);
    }
    (rms, sab / (saa * sbb).sqrt())
}

/// Joint centres for a marker set that has only segment clusters (the Hamner running trials):
/// each centre given in the static trial (`RHJC`, `RKJC`, `RAJC`, `L…`) is carried by the
/// rigid cluster of its segment (pelvis: ASIS/PSIS; thigh: `#TH1–3`; shank: `#TB1–3`), fitted
/// frame by frame with the Kabsch (SVD) least-squares rotation. Adds the centres to `dynamic`
/// and returns the names added.
pub fn add_joint_centres(dynamic: &mut MarkerSet, stat: &MarkerSet) -> Vec<String> {
    let mut added = Vec::new();
    for s in ["R", "L"] {
        let segs: [(String, Vec<String>); 3] = [
            (
                format!("{s}HJC"),
                ["RASI", "LASI", "RPSI", "LPSI"].map(String::from).to_vec(),
            ),
            (
                format!("{s}KJC"),
                (1..=3).map(|i| format!("{s}TH{i}")).collect(),
            ),
            (
                format!("{s}AJC"),
                (1..=3).map(|i| format!("{s}TB{i}")).collect(),
            ),
        ];
        for (centre, cluster) in segs {
            if dynamic.index(&centre).is_some() {
                continue;
            }
            let Some(c_static) = static_mean(stat, &centre) else {
                continue;
            };
            let refs: Option<Vec<[f64; 3]>> =
                cluster.iter().map(|m| static_mean(stat, m)).collect();
            let dyn_idx: Option<Vec<usize>> = cluster.iter().map(|m| dynamic.index(m)).collect();
            let (Some(refs), Some(dyn_idx)) = (refs, dyn_idx) else {
                continue;
            };
            let traj: Vec<[f64; 3]> = (0..dynamic.len())
                .map(|f| {
                    let cur: Vec<[f64; 3]> =
                        dyn_idx.iter().map(|&i| dynamic.positions[i][f]).collect();
                    carry(&refs, &cur, c_static)
                })
                .collect();
            dynamic.names.push(centre.clone());
            dynamic.positions.push(traj);
            added.push(centre);
        }
    }
    added
}

fn static_mean(m: &MarkerSet, name: &str) -> Option<[f64; 3]> {
    let p = m.get(name)?;
    let mut s = [0.0; 3];
    let mut n = 0.0;
    for q in p.iter().filter(|q| q.iter().all(|v| v.is_finite())) {
        for a in 0..3 {
            s[a] += q[a];
        }
        n += 1.0;
    }
    (n > 0.0).then(|| s.map(|v| v / n))
}

/// The point `c` rigidly attached to the cluster `refs`, where the cluster is now at `cur`.
fn carry(refs: &[[f64; 3]], cur: &[[f64; 3]], c: [f64; 3]) -> [f64; 3] {
    use nalgebra::{Matrix3, Vector3};
    if cur.iter().flatten().any(|v| !v.is_finite()) {
        return [f64::NAN; 3];
    }
    let n = refs.len() as f64;
    let cen = |v: &[[f64; 3]]| {
        v.iter()
            .fold(Vector3::zeros(), |a, p| a + Vector3::new(p[0], p[1], p[2]))
            / n
    };
    let (cr, cc) = (cen(refs), cen(cur));
    let mut h = Matrix3::zeros();
    for (r, q) in refs.iter().zip(cur) {
        let a = Vector3::new(r[0], r[1], r[2]) - cr;
        let b = Vector3::new(q[0], q[1], q[2]) - cc;
        h += a * b.transpose();
    }
    let svd = h.svd(true, true);
    let (Some(u), Some(vt)) = (svd.u, svd.v_t) else {
        return [f64::NAN; 3];
    };
    let mut d = Matrix3::identity();
    if (vt.transpose() * u.transpose()).determinant() < 0.0 {
        d[(2, 2)] = -1.0;
    }
    let rot = vt.transpose() * d * u.transpose();
    let out = rot * (Vector3::new(c[0], c[1], c[2]) - cr) + cc;
    [out.x, out.y, out.z]
}
