//! C3D force platforms in the lab frame (part of the C3D reader, [`super`]).
//!
//! Force platforms (FORCE_PLATFORM group): types 2 (Fx Fy Fz Mx My Mz), 4 (the same after the
//! 6×6 CAL_MATRIX, stored column-major: output i = Σⱼ CAL[i + 6j]·channelⱼ), 1 (Fx Fy Fz COPx
//! COPy Tz, COP about the plate centre) and 3 (Kistler, 8 channels, ORIGIN = (a, b, az₀)). The
//! plate frame comes from CORNERS (corner 1 in the plate's +x+y quadrant, then 2: −x+y,
//! 3: −x−y, 4: +x−y): x̂ ∝ (c₁+c₄) − (c₂+c₃), ŷ ∝ (c₁+c₂) − (c₃+c₄), ẑ = x̂ × ŷ. ORIGIN is the
//! vector from the plate's coordinate origin to the centre of its working surface, in plate
//! coordinates, so the surface is the plane z = o_z and the centre of pressure is
//! p_x = (o_z·F_x − M_y)/F_z, p_y = (M_x + o_z·F_y)/F_z, placed in the lab at
//! centre + R·(p_x − o_x, p_y − o_y, 0); the free moment is T_z = M_z − p_x·F_y + p_y·F_x.
//! Whether the stored force is the subject's action on the plate or the plate's reaction on the
//! subject differs between systems; the reader decides from the data (the ground reaction on
//! the body points up while loaded) and says which in the notes. A non-zero ZERO range is
//! subtracted as a baseline from the plate channels.
use super::C3dFile;
use crate::ingest::text;
use crate::ingest::types::ForcePlate;
use crate::ingest::{IngestError, ReadOptions};
use std::path::Path;

fn unit_scale_force_moment(unit: &str) -> (f64, bool) {
    // (scale to SI, recognised)
    let u = unit
        .trim()
        .to_ascii_lowercase()
        .replace(['.', ' ', '*', '·'], "");
    match u.as_str() {
        "n" | "nm" => (1.0, true),
        "nmm" => (1e-3, true),
        "kn" => (1e3, true),
        "knm" => (1e3, true),
        _ => (1.0, false),
    }
}

fn norm(v: [f64; 3]) -> Option<[f64; 3]> {
    let n = (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt();
    (n > 0.0 && n.is_finite()).then(|| v.map(|x| x / n))
}

fn cross(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    ]
}

/// The force plates of a C3D file in the lab frame, SI, at the analog rate (see the module
/// docs). `up` is the lab's vertical (axis, sign), used to decide the force sign convention.
pub fn force_plates(
    c: &C3dFile,
    path: &Path,
    opts: &ReadOptions,
    up: Option<(crate::ingest::types::Axis, f64)>,
) -> Result<(Vec<ForcePlate>, Vec<String>), IngestError> {
    let mut notes = Vec::new();
    let used = c
        .numbers("FORCE_PLATFORM", "USED")
        .and_then(|v| v.first().copied())
        .unwrap_or(0.0) as usize;
    if used == 0 {
        return Ok((Vec::new(), notes));
    }
    let missing = |n: &str| IngestError::MissingColumn {
        path: path.to_path_buf(),
        column: format!("FORCE_PLATFORM:{n}"),
        message: format!("FORCE_PLATFORM:USED = {used} but {n} is missing"),
    };
    let types = c
        .numbers("FORCE_PLATFORM", "TYPE")
        .ok_or_else(|| missing("TYPE"))?;
    let chan_p = c
        .param("FORCE_PLATFORM", "CHANNEL")
        .ok_or_else(|| missing("CHANNEL"))?;
    let chans = chan_p.numbers().unwrap_or_default();
    let per = chan_p.dims.first().copied().unwrap_or(6).max(1);
    let corners = c
        .numbers("FORCE_PLATFORM", "CORNERS")
        .ok_or_else(|| missing("CORNERS"))?;
    let origins = c
        .numbers("FORCE_PLATFORM", "ORIGIN")
        .unwrap_or_else(|| vec![0.0; 3 * used]);
    let cal = c.numbers("FORCE_PLATFORM", "CAL_MATRIX");
    let zero = c.numbers("FORCE_PLATFORM", "ZERO").unwrap_or_default();
    let to_m = text::length_scale(&c.point_units).unwrap_or(1e-3);
    let n_samples = c.analog.first().map_or(0, |a| a.len());
    let rate = c.analog_rate_hz;
    let spf = if c.markers.is_empty() {
        0
    } else {
        n_samples / c.markers.len()
    };
    let mut plates = Vec::new();
    for k in 0..used {
        let ptype = types.get(k).copied().unwrap_or(0.0) as i32;
        let nch = match ptype {
            1 | 2 | 4 => 6,
            3 => 8,
            other => {
                notes.push(format!(
                    "force platform {}: type {other} is not supported; skipped",
                    k + 1
                ));
                continue;
            }
        };
        let mut ch = Vec::with_capacity(nch);
        for j in 0..nch {
            let idx = chans.get(k * per + j).copied().unwrap_or(0.0) as usize;
            if idx == 0 || idx > c.analog.len() {
                return Err(IngestError::cell(
                    path,
                    k + 1,
                    "FORCE_PLATFORM:CHANNEL",
                    format!(
                        "plate {}: channel {} of {} is {idx}, not an analog channel (1–{})",
                        k + 1,
                        j + 1,
                        nch,
                        c.analog.len()
                    ),
                ));
            }
            ch.push(idx - 1);
        }
        // Channel values in file units, baseline removed; the CAL_MATRIX of type 4 applies to
        // these, and the SI scaling comes after it (from each output channel's unit).
        let mut sig: Vec<Vec<f64>> = ch.iter().map(|&i| c.analog[i].clone()).collect();
        if zero.len() >= 2 && zero[0] >= 1.0 && zero[1] >= zero[0] && spf > 0 {
            let a = (zero[0] as usize - 1) * spf;
            let b = (zero[1] as usize * spf).min(n_samples);
            if b > a {
                for s in sig.iter_mut() {
                    let m = s[a..b].iter().sum::<f64>() / (b - a) as f64;
                    s.iter_mut().for_each(|v| *v -= m);
                }
                if k == 0 {
                    notes.push(format!(
                        "force plates: baseline of frames {}–{} (FORCE_PLATFORM:ZERO) subtracted",
                        zero[0], zero[1]
                    ));
                }
            }
        }
        if ptype == 4 {
            let Some(m) = cal.as_ref().filter(|m| m.len() >= 36 * (k + 1)) else {
                return Err(missing("CAL_MATRIX"));
            };
            let m = &m[36 * k..36 * (k + 1)];
            let mut out = vec![vec![0.0; n_samples]; 6];
            for (i, o) in out.iter_mut().enumerate() {
                for (j, s) in sig.iter().enumerate() {
                    let w = m[i + 6 * j];
                    if w != 0.0 {
                        o.iter_mut().zip(s).for_each(|(o, v)| *o += w * v);
                    }
                }
            }
            sig = out;
        }
        for (j, s) in sig.iter_mut().enumerate() {
            let unit = &c.analog_units[ch[j]];
            let scale = if ptype == 1 && (j == 3 || j == 4) {
                to_m // type 1 COP channels are lengths in POINT units
            } else {
                let (sc, ok) = unit_scale_force_moment(unit);
                if !ok && !unit.trim().is_empty() {
                    notes.push(format!(
                        "plate {} channel {}: unit {unit:?} not recognised, read as N or N·m",
                        k + 1,
                        c.analog_labels[ch[j]]
                    ));
                }
                sc
            };
            if scale != 1.0 {
                s.iter_mut().for_each(|v| *v *= scale);
            }
        }
        // Plate frame from the corners (POINT units → m).
        let cs: Vec<[f64; 3]> = (0..4)
            .map(|i| {
                let b = 12 * k + 3 * i;
                [0, 1, 2].map(|j| corners.get(b + j).copied().unwrap_or(f64::NAN) * to_m)
            })
            .collect();
        let centre = [0, 1, 2].map(|j| cs.iter().map(|c| c[j]).sum::<f64>() / 4.0);
        let xv = [0, 1, 2].map(|j| (cs[0][j] + cs[3][j]) - (cs[1][j] + cs[2][j]));
        let yv = [0, 1, 2].map(|j| (cs[0][j] + cs[1][j]) - (cs[2][j] + cs[3][j]));
        let (Some(xh), Some(yh0)) = (norm(xv), norm(yv)) else {
            return Err(IngestError::cell(
                path,
                k + 1,
                "FORCE_PLATFORM:CORNERS",
                format!("plate {}: degenerate corners {cs:?}", k + 1),
            ));
        };
        let zh = norm(cross(xh, yh0)).unwrap_or([0.0, 0.0, 1.0]);
        let yh = cross(zh, xh);
        let o = [0, 1, 2].map(|j| origins.get(3 * k + j).copied().unwrap_or(0.0) * to_m);
        let o = if ptype == 3 {
            // Kistler: ORIGIN = (a, b, az0): sensor offsets and the depth of the sensor plane.
            [0.0, 0.0, o[2]]
        } else {
            o
        };
        let rot = |v: [f64; 3]| [0, 1, 2].map(|j| xh[j] * v[0] + yh[j] * v[1] + zh[j] * v[2]);
        let mut force = Vec::with_capacity(n_samples);
        let mut cop = Vec::with_capacity(n_samples);
        let mut tz = Vec::with_capacity(n_samples);
        #[allow(clippy::needless_range_loop)] // s indexes 6–8 channel vectors at once
        for s in 0..n_samples {
            let (f, m, p_plate) = match ptype {
                1 => {
                    let f = [sig[0][s], sig[1][s], sig[2][s]];
                    (f, None, Some([sig[3][s], sig[4][s], sig[5][s]]))
                }
                3 => {
                    let (a, b) = (
                        origins.get(3 * k).copied().unwrap_or(0.0) * to_m,
                        origins.get(3 * k + 1).copied().unwrap_or(0.0) * to_m,
                    );
                    let v: Vec<f64> = (0..8).map(|j| sig[j][s]).collect();
                    let f = [v[0] + v[1], v[2] + v[3], v[4] + v[5] + v[6] + v[7]];
                    let m = [
                        b * (v[4] + v[5] - v[6] - v[7]),
                        a * (-v[4] + v[5] + v[6] - v[7]),
                        b * (-v[0] + v[1]) + a * (v[2] - v[3]),
                    ];
                    (f, Some(m), None)
                }
                _ => (
                    [sig[0][s], sig[1][s], sig[2][s]],
                    Some([sig[3][s], sig[4][s], sig[5][s]]),
                    None,
                ),
            };
            let (px, py, t) = match (m, p_plate) {
                (Some(m), _) => {
                    let px = (o[2] * f[0] - m[1]) / f[2];
                    let py = (m[0] + o[2] * f[1]) / f[2];
                    (px - o[0], py - o[1], m[2] - px * f[1] + py * f[0])
                }
                (None, Some(pp)) => (pp[0], pp[1], pp[2]),
                _ => (f64::NAN, f64::NAN, f64::NAN),
            };
            force.push(rot(f));
            let pl = rot([px, py, 0.0]);
            cop.push([0, 1, 2].map(|j| centre[j] + pl[j]));
            tz.push(t);
        }
        // Sign convention: the ground reaction on the body points up while the plate is loaded.
        let (v_axis, v_sign) = up.unwrap_or_else(|| {
            let mut s = [0.0f64; 3];
            for f in &force {
                for j in 0..3 {
                    s[j] += f[j].abs();
                }
            }
            let ax = (0..3).max_by(|&a, &b| s[a].total_cmp(&s[b])).unwrap_or(2);
            (
                [
                    crate::ingest::types::Axis::X,
                    crate::ingest::types::Axis::Y,
                    crate::ingest::types::Axis::Z,
                ][ax],
                1.0,
            )
        });
        let vi = v_axis.index();
        let mut sum_up = 0.0;
        for f in &force {
            let fv = v_sign * f[vi];
            if fv.abs() > opts.cop_min_force_n {
                sum_up += fv;
            }
        }
        let stored_is_reaction = sum_up >= 0.0;
        let sign = if stored_is_reaction { 1.0 } else { -1.0 };
        let z_up = v_sign * zh[vi];
        let mut loaded = 0usize;
        for (s, f) in force.iter_mut().enumerate() {
            *f = f.map(|x| sign * x);
            if v_sign * f[vi] < opts.cop_min_force_n {
                cop[s] = [f64::NAN; 3];
            } else {
                loaded += 1;
            }
        }
        let free: Vec<f64> = tz.iter().map(|t| sign * t * z_up).collect();
        notes.push(format!(
            "force plate {} (type {ptype}, channels {}): stored force is the {} (read as the \
             ground reaction on the body), plate z axis points {} in the lab; loaded in {loaded} \
             of {n_samples} samples",
            k + 1,
            ch.iter()
                .map(|&i| c.analog_labels[i].trim().to_string())
                .collect::<Vec<_>>()
                .join(" "),
            if stored_is_reaction {
                "reaction on the body"
            } else {
                "action on the plate"
            },
            if z_up > 0.0 { "up" } else { "down" }
        ));
        if ptype == 3 {
            notes.push(format!(
                "force plate {}: type 3 (Kistler) support follows the C3D guide and is untested \
                 on real data",
                k + 1
            ));
        }
        plates.push(ForcePlate {
            name: format!("FP{}", k + 1),
            rate_hz: rate,
            time_s: (0..n_samples).map(|s| s as f64 / rate).collect(),
            force_n: force,
            cop_m: cop,
            free_moment_nm: free,
            side: None,
        });
    }
    Ok((plates, notes))
}
