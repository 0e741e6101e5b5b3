//! Tab-separated instrumented-treadmill GRF (the WBDS data set: Fukuchi, Fukuchi & Duarte 2018,
//! PeerJ 6:e4640, `WBDSnnwalkTmmgrf.txt`) and its trial metadata `WBDSinfo.csv`.
//!
//! Layout: one header line `Time Fx1 Fy1 Fz1 COPx1 COPy1 COPz1 Ty1 Fx2 … Ty2`, then one row per
//! sample. Decisions:
//! - Units (not in the file; the data set's documentation): force N, COP mm, `Ty` N·mm (the free
//!   moment about the vertical y axis); converted to N, m, N·m. A loaded COP magnitude below 20
//!   would mean metres, and is read as such with a note.
//! - The `Time` column of WBDS holds sample numbers (1, 2, …, 9000), not seconds: when it is a
//!   run of consecutive integers the rate is [`ReadOptions::grf_rate_hz`] (default
//!   [`WBDS_RATE_HZ`] = 300 Hz, the data set's GRF rate) and sample k is at (k − 1)/rate;
//!   otherwise the column is taken as seconds.
//! - Each belt is one [`ForcePlate`] (`belt 1`, `belt 2`). Which foot each belt carries is
//!   decided from the data: the belt whose loaded centre of pressure lies further to the
//!   subject's right (right = forward × up in a right-handed lab frame; forward from the
//!   braking/propulsion pattern of the fore-aft force) carries the right foot. `WBDSinfo.csv`'s
//!   `FP_RightFoot`/`FP_LeftFoot` (given only for overground trials) overrides when present.
//!   A consistency check notes whether the COP travels backward during stance, as it must on a
//!   treadmill.
//! - `WBDSinfo.csv` (looked for beside the GRF file) gives the subject's height (cm → m), mass
//!   (kg), leg length (m) and the trial's speed (m/s; the belt speed for treadmill trials,
//!   `…walkT…`). A row for the file name itself is preferred, else the row of the same trial's
//!   `.c3d`.
use super::frame_detect;
use super::text::{self, Num};
use super::types::{ForcePlate, Setting, Trial};
use super::{finish, IngestError, ReadOptions};
use crate::gait::{Gait, Side};
use std::path::Path;

/// The GRF sampling rate of the WBDS treadmill files, Hz (Fukuchi et al. 2018).
pub const WBDS_RATE_HZ: f64 = 300.0;

/// One trial's row of `WBDSinfo.csv`, SI units.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct WbdsInfo {
    /// `Subject` number.
    pub subject: Option<u32>,
    /// `Height`, m (the file gives cm).
    pub height_m: Option<f64>,
    /// `Mass`, kg.
    pub mass_kg: Option<f64>,
    /// `LegLength`, m.
    pub leg_length_m: Option<f64>,
    /// `GaitSpeed(m/s)`.
    pub speed_m_per_s: Option<f64>,
    /// `FP_RightFoot` (plate names, `--` → empty).
    pub fp_right: Vec<String>,
    /// `FP_LeftFoot`.
    pub fp_left: Vec<String>,
    /// The `FileName` of the row used.
    pub file_name: String,
}

/// Finds the row of `file_name` (or of the same trial's `.c3d`) in `WBDSinfo.csv`.
pub fn read_info(info_path: &Path, file_name: &str) -> Result<Option<WbdsInfo>, IngestError> {
    let bytes = text::read_bytes(info_path)?;
    let text = String::from_utf8_lossy(&bytes);
    let mut lines = text.lines();
    let Some(header) = lines.next() else {
        return Err(IngestError::malformed(info_path, "empty file"));
    };
    let cols: Vec<String> = parse_csv_line(header);
    let col = |n: &str| cols.iter().position(|c| c.trim().eq_ignore_ascii_case(n));
    let fname = col("FileName").ok_or_else(|| IngestError::MissingColumn {
        path: info_path.to_path_buf(),
        column: "FileName".into(),
        message: "WBDSinfo.csv lists one trial file per row under FileName".into(),
    })?;
    let stem = file_name
        .strip_suffix("grf.txt")
        .map(|s| format!("{s}.c3d"))
        .unwrap_or_default();
    let mut exact = None;
    let mut by_c3d = None;
    for (i, line) in lines.enumerate() {
        // Cheap pre-filter before splitting the row.
        if !line.contains(file_name) && (stem.is_empty() || !line.contains(&stem)) {
            continue;
        }
        let cells = parse_csv_line(line);
        match cells.get(fname).map(|s| s.trim()) {
            Some(f) if f == file_name => exact = Some((i + 2, cells)),
            Some(f) if !stem.is_empty() && f == stem => by_c3d = Some((i + 2, cells)),
            _ => {}
        }
    }
    let Some((row, cells)) = exact.or(by_c3d) else {
        return Ok(None);
    };
    let num = |name: &str| -> Result<Option<f64>, IngestError> {
        let Some(i) = col(name) else { return Ok(None) };
        let cell = cells.get(i).map(|s| s.trim()).unwrap_or("");
        if cell.is_empty() || cell == "--" {
            return Ok(None);
        }
        match text::num(cell.as_bytes()) {
            Num::Value(v) if v.is_finite() => Ok(Some(v)),
            _ => Err(IngestError::cell(
                info_path,
                row,
                name,
                format!("{cell:?} is not a number"),
            )),
        }
    };
    let plates = |name: &str| -> Vec<String> {
        col(name)
            .and_then(|i| cells.get(i))
            .map(|s| {
                s.split(',')
                    .map(|p| p.trim().to_string())
                    .filter(|p| !p.is_empty() && p != "--")
                    .collect()
            })
            .unwrap_or_default()
    };
    Ok(Some(WbdsInfo {
        subject: num("Subject")?.map(|v| v as u32),
        height_m: num("Height")?.map(|cm| cm / 100.0),
        mass_kg: num("Mass")?,
        leg_length_m: num("LegLength")?,
        speed_m_per_s: num("GaitSpeed(m/s)")?,
        fp_right: plates("FP_RightFoot"),
        fp_left: plates("FP_LeftFoot"),
        file_name: cells.get(fname).cloned().unwrap_or_default(),
    }))
}

/// Splits one CSV line (double quotes protect commas).
fn parse_csv_line(line: &str) -> Vec<String> {
    let mut out = Vec::new();
    let mut cur = String::new();
    let mut quoted = false;
    for c in line.chars() {
        match c {
            '"' => quoted = !quoted,
            ',' if !quoted => out.push(std::mem::take(&mut cur)),
            '\r' => {}
            _ => cur.push(c),
        }
    }
    out.push(cur);
    out
}

/// Reads a treadmill GRF file (and, with `opts.companions`, `WBDSinfo.csv` beside it).
pub fn read(path: &Path, opts: &ReadOptions) -> Result<Trial, IngestError> {
    let bytes = text::read_bytes(path)?;
    let info = if opts.companions {
        let info_path = path.with_file_name("WBDSinfo.csv");
        let fname = path
            .file_name()
            .map(|s| s.to_string_lossy().into_owned())
            .unwrap_or_default();
        if info_path.is_file() {
            read_info(&info_path, &fname)?.map(|i| (i, info_path))
        } else {
            None
        }
    } else {
        None
    };
    parse(&bytes, path, opts, info)
}

/// [`read`] on bytes in memory, with the metadata row already found (if any).
pub fn parse(
    bytes: &[u8],
    path: &Path,
    opts: &ReadOptions,
    info: Option<(WbdsInfo, std::path::PathBuf)>,
) -> Result<Trial, IngestError> {
    let mut it = text::lines(bytes);
    let (hl, header) = it
        .next()
        .ok_or_else(|| IngestError::malformed(path, "empty file"))?;
    let names: Vec<String> = text::cells(header, b'\t').map(text::text).collect();
    if names.first().map(|n| n.eq_ignore_ascii_case("time")) != Some(true) {
        return Err(IngestError::MissingColumn {
            path: path.to_path_buf(),
            column: "Time".into(),
            message: format!("line {hl}: the first column must be Time"),
        });
    }
    let col = |n: &str| names.iter().position(|x| x.eq_ignore_ascii_case(n));
    let mut belts: Vec<[usize; 7]> = Vec::new();
    for b in 1.. {
        let want = ["Fx", "Fy", "Fz", "COPx", "COPy", "COPz", "Ty"].map(|c| format!("{c}{b}"));
        let found: Vec<Option<usize>> = want.iter().map(|n| col(n)).collect();
        if found.iter().all(|f| f.is_none()) {
            break;
        }
        let mut idx = [0usize; 7];
        for (j, f) in found.iter().enumerate() {
            idx[j] = f.ok_or_else(|| IngestError::MissingColumn {
                path: path.to_path_buf(),
                column: want[j].clone(),
                message: format!("belt {b} needs Fx, Fy, Fz, COPx, COPy, COPz and Ty columns"),
            })?;
        }
        belts.push(idx);
    }
    if belts.is_empty() {
        return Err(IngestError::MissingColumn {
            path: path.to_path_buf(),
            column: "Fx1".into(),
            message: "no belt columns (Fx1 Fy1 Fz1 COPx1 COPy1 COPz1 Ty1 …)".into(),
        });
    }
    let ncol = names.len();
    let mut data: Vec<Vec<f64>> = (0..ncol).map(|_| Vec::with_capacity(9000)).collect();
    let mut lines_of = Vec::with_capacity(9000);
    let mut row = Vec::with_capacity(ncol);
    for (ln, line) in it {
        if text::is_blank(line) {
            continue;
        }
        text::numeric_row(line, b'\t', ncol, &mut row)
            .map_err(|e| e.into_ingest(path, ln, line, b'\t', &names))?;
        for (d, v) in data.iter_mut().zip(&row) {
            d.push(*v);
        }
        lines_of.push(ln);
    }
    let rows = lines_of.len();
    if rows < 2 {
        return Err(IngestError::malformed(path, "fewer than two data rows"));
    }
    text::check_time(&data[0], &lines_of, path, &names[0])?;
    let mut notes = Vec::new();
    let t = &data[0];
    let sample_numbers =
        t.iter().all(|v| v.fract() == 0.0) && t[rows - 1] - t[0] == (rows - 1) as f64;
    let (rate, time): (f64, Vec<f64>) = if sample_numbers {
        let rate = opts.grf_rate_hz.unwrap_or(WBDS_RATE_HZ);
        notes.push(format!(
            "the Time column holds sample numbers {}–{}: time = (sample − 1)/{rate} Hz ({})",
            t[0],
            t[rows - 1],
            if opts.grf_rate_hz.is_some() {
                "rate set by the user"
            } else {
                "the WBDS GRF rate"
            }
        ));
        (rate, t.iter().map(|s| (s - 1.0) / rate).collect())
    } else {
        let rate = text::rate_from_time(t).unwrap_or(f64::NAN);
        (rate, t.clone())
    };
    // COP unit: mm unless the loaded magnitudes are metre-sized.
    let mut loaded_cop_max = 0.0f64;
    for b in &belts {
        for ((fy, x), z) in data[b[1]].iter().zip(&data[b[3]]).zip(&data[b[5]]) {
            if fy.abs() > opts.cop_min_force_n {
                loaded_cop_max = loaded_cop_max.max(x.abs().max(z.abs()));
            }
        }
    }
    let cop_scale = if loaded_cop_max > 0.0 && loaded_cop_max < 20.0 {
        notes.push(format!(
            "COP up to {loaded_cop_max:.2}: read as metres (WBDS writes mm)"
        ));
        1.0
    } else {
        1e-3
    };
    let mut plates: Vec<ForcePlate> = belts
        .iter()
        .enumerate()
        .map(|(i, b)| ForcePlate {
            name: format!("belt {}", i + 1),
            rate_hz: rate,
            time_s: time.clone(),
            force_n: (0..rows)
                .map(|s| [data[b[0]][s], data[b[1]][s], data[b[2]][s]])
                .collect(),
            cop_m: (0..rows)
                .map(|s| [0, 1, 2].map(|k| data[b[3 + k]][s] * cop_scale))
                .collect(),
            free_moment_nm: data[b[6]].iter().map(|m| m * 1e-3).collect(),
            side: None,
        })
        .collect();
    let vertical = match opts.vertical {
        Some(axis) => Some(frame_detect::Direction {
            axis,
            sign: 1.0,
            how: format!("vertical = +{axis:?} set by the user"),
        }),
        None => frame_detect::vertical_from_plates(&plates),
    };
    if let Some(v) = &vertical {
        let k = v.axis.index();
        for p in &mut plates {
            for (f, c) in p.force_n.iter().zip(p.cop_m.iter_mut()) {
                if v.sign * f[k] < opts.cop_min_force_n {
                    *c = [f64::NAN; 3];
                }
            }
        }
    }
    notes.push(format!(
        "treadmill GRF: {} belt(s), {rows} samples at {rate} Hz ({:.1} s); force N, COP mm → m, \
         Ty N·mm → N·m (WBDS units); COP NaN below {} N",
        plates.len(),
        rows as f64 / rate,
        opts.cop_min_force_n
    ));

    let name = path
        .file_stem()
        .map(|s| s.to_string_lossy().trim_end_matches("grf").to_string())
        .unwrap_or_default();
    let mut trial = Trial::new(path, name.clone());
    trial.notes = notes;
    // WBDS names treadmill trials `…walkTnn` and overground ones `…walkOnn…`.
    let is_treadmill_trial = name.to_ascii_lowercase().contains("walkt");
    if name.to_ascii_lowercase().contains("walk") {
        trial.gait = Some(Gait::Walk);
    }
    if let Some((info, info_path)) = &info {
        let s = &mut trial.subject;
        s.id = info.subject.map(|n| format!("WBDS{n:02}"));
        s.body_height_m = info.height_m;
        s.mass_kg = info.mass_kg;
        s.leg_length_m = info.leg_length_m;
        s.notes.push(format!(
            "height (cm → m), mass, leg length from {} row {}",
            info_path.display(),
            info.file_name
        ));
        if let Some(v) = info.speed_m_per_s {
            if is_treadmill_trial {
                trial.setting = Setting::Treadmill {
                    belt_speed_m_per_s: v,
                };
                trial.notes.push(format!(
                    "setting: treadmill, belt speed {v} m/s from {} (GaitSpeed)",
                    info_path.display()
                ));
            } else {
                trial.setting = Setting::Overground;
            }
        }
    } else if is_treadmill_trial {
        trial.notes.push(
            "setting: treadmill trial by its name, belt speed unknown (no WBDSinfo.csv row)"
                .to_string(),
        );
    }
    trial.plates = plates;
    // Frame and sides.
    finish(&mut trial, opts, None);
    assign_sides(&mut trial, info.as_ref().map(|(i, _)| i));
    Ok(trial)
}

/// Sets each belt's `side` from the metadata or from the lateral COP positions.
fn assign_sides(trial: &mut Trial, info: Option<&WbdsInfo>) {
    if let Some(i) = info {
        let mut set_any = false;
        for (k, p) in trial.plates.iter_mut().enumerate() {
            let fp = format!("FP{}", k + 1);
            if i.fp_right.contains(&fp) {
                p.side = Some(Side::Right);
                set_any = true;
            } else if i.fp_left.contains(&fp) {
                p.side = Some(Side::Left);
                set_any = true;
            }
        }
        if set_any {
            trial
                .notes
                .push("belt sides from WBDSinfo.csv FP_RightFoot/FP_LeftFoot".to_string());
            return;
        }
    }
    let Some(frame) = trial.frame.clone() else {
        trial
            .notes
            .push("belt sides unknown: no laboratory frame".to_string());
        return;
    };
    let Some((rax, rsign)) = frame_detect::right_axis(&frame) else {
        return;
    };
    let lateral: Vec<Option<f64>> = trial
        .plates
        .iter()
        .map(|p| {
            let v: Vec<f64> = p
                .cop_m
                .iter()
                .map(|c| rsign * c[rax.index()])
                .filter(|v| v.is_finite())
                .collect();
            (!v.is_empty()).then(|| v.iter().sum::<f64>() / v.len() as f64)
        })
        .collect();
    if trial.plates.len() != 2 {
        trial.notes.push(format!(
            "belt sides not assigned: {} belts (dual-belt treadmills have 2)",
            trial.plates.len()
        ));
        return;
    }
    let (Some(a), Some(b)) = (lateral[0], lateral[1]) else {
        trial
            .notes
            .push("belt sides unknown: a belt is never loaded".to_string());
        return;
    };
    if (a - b).abs() < 0.03 {
        trial.notes.push(format!(
            "belt sides unknown: mean loaded COPs only {:.0} mm apart laterally",
            (a - b).abs() * 1e3
        ));
        return;
    }
    let (r, l) = if a > b { (0, 1) } else { (1, 0) };
    trial.plates[r].side = Some(Side::Right);
    trial.plates[l].side = Some(Side::Left);
    // Consistency: on a treadmill the COP moves backward during stance.
    let fwd = frame.forward.index();
    let mut back = 0usize;
    let mut total = 0usize;
    let v = frame.vertical;
    for p in &trial.plates {
        let min_len = ((0.2 * p.rate_hz) as usize).max(3);
        for (s, e) in frame_detect::stances(p, v, 1.0, 100.0, min_len) {
            let (c0, c1) = (p.cop_m[s][fwd], p.cop_m[e - 1][fwd]);
            if c0.is_finite() && c1.is_finite() {
                total += 1;
                if frame.forward_sign * (c1 - c0) < 0.0 {
                    back += 1;
                }
            }
        }
    }
    trial.notes.push(format!(
        "belt sides from the centre of pressure: {} carries the right foot (mean COP {:.0} mm \
         further right, right = {}{rax:?} = forward × up, assuming a right-handed lab frame), {} \
         the left; the COP moves backward in {back} of {total} stance phases",
        trial.plates[r].name,
        (a - b).abs() * 1e3,
        if rsign < 0.0 { "−" } else { "+" },
        trial.plates[l].name
    ));
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn csv_line_with_quotes() {
        assert_eq!(
            parse_csv_line("4,a.c3d,\"FP4, FP1\",--"),
            vec!["4", "a.c3d", "FP4, FP1", "--"]
        );
    }
}
