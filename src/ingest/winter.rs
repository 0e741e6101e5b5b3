//! Winter's rotoscope walk: *Biomechanics and Motor Control of Human Movement*, Appendix Table
//! A.1 (`WinterTableA1.txt`, raw, cm) and its filtered version `wn35b.txt`.
//!
//! Both are 2-D (x forward, y up) tables of eight right-side landmarks — rib cage, hip (greater
//! trochanter), knee, fibula head, ankle (lateral malleolus), heel, fifth metatarsal, toe — filmed
//! at 69.9 Hz. Layouts:
//! - Table A.1: `'FRAME' 'TIME' 'RIB CAGE' …` / `'N' 'S' 'X' 'Y' …` / rows `frame time x y …`;
//! - `wn35b.txt`: `wn95b Shoulder Shoulder Hip Hip …` / `Time "Mark01 X" …` / `s cm cm …` / rows
//!   `time x y …`.
//!
//! Decisions:
//! - The landmarks keep Table A.1's names (`RIGHT HEEL`, …) in both files; `wn35b.txt` labels the
//!   same columns Shoulder/Hip/Tib.Epic./Knee/Ankle/Heel/Ball/Toes (its "Tib.Epic." is A.1's knee
//!   and its "Knee" A.1's fibula head: the coordinates agree within the filtering, see the tests).
//! - Units come from the magnitudes, not the header: the highest landmark (rib cage/shoulder)
//!   must stand 0.5–2.5 m above the floor, which tells cm from m from mm. `wn35b.txt` says cm but
//!   is in metres; the reader says so in the notes.
//! - Time is uniform at Winter's published 69.9 Hz: the files' time columns are rounded
//!   (0.014, 0.029, … in A.1; 0.0143 steps in wn35b) and imply 69.93–69.95 Hz, which moves the last
//!   frame by ≈1 ms, far below one frame.
use super::frame_detect::Direction;
use super::text::{self, Num};
use super::types::{Axis, MarkerSet, Setting, Trial};
use super::{finish, IngestError, ReadOptions};
use crate::gait::Gait;
use std::path::Path;

/// Winter's film rate, Hz (Winter, Table A.1: Δt = 0.0143 s).
pub const WINTER_RATE_HZ: f64 = 69.9;

/// The landmark names of Table A.1, in column order.
pub const TABLE_A1_NAMES: [&str; 8] = [
    "RIB CAGE",
    "RIGHT HIP",
    "RIGHT KNEE",
    "RIGHT FIBULA",
    "RIGHT ANKLE",
    "RIGHT HEEL",
    "RIGHT MT5",
    "RIGHT TOE",
];

/// True when `first_line` is the first line of one of Winter's tables.
pub fn looks_like_winter(first_line: &str) -> bool {
    let f = first_line.trim_start();
    f.starts_with("'FRAME'") || (f.starts_with("wn") && f.contains("Heel") && f.contains("Toe"))
}

/// Reads Winter's Table A.1 or `wn35b.txt` into a trial: markers only (z = 0), walking,
/// overground, frame +Y up / +X forward (checked from the data), units detected.
pub fn read(path: &Path, opts: &ReadOptions) -> Result<Trial, IngestError> {
    let bytes = text::read_bytes(path)?;
    parse(&bytes, path, opts)
}

/// [`read`] on bytes already in memory; `path` is used for messages and the trial's name.
pub fn parse(bytes: &[u8], path: &Path, opts: &ReadOptions) -> Result<Trial, IngestError> {
    let mut header: Vec<(usize, &[u8])> = Vec::new();
    let mut rows: Vec<(usize, Vec<f64>)> = Vec::new();
    for (ln, line) in text::lines(bytes) {
        if text::is_blank(line) {
            continue;
        }
        let first = text::words(line).next().unwrap_or(&[]);
        let numeric = matches!(text::num(first), Num::Value(_));
        if !numeric && rows.is_empty() {
            header.push((ln, line));
            continue;
        }
        let mut vals = Vec::with_capacity(18);
        for (c, w) in text::words(line).enumerate() {
            match text::num(w) {
                Num::Value(v) if !v.is_infinite() => vals.push(v),
                _ => {
                    return Err(IngestError::cell(
                        path,
                        ln,
                        format!("column {}", c + 1),
                        format!("{:?} is not a number", text::text(w)),
                    ))
                }
            }
        }
        rows.push((ln, vals));
    }
    let Some((first_ln, first_row)) = rows.first() else {
        return Err(IngestError::malformed(
            path,
            "no data rows: the table must have numeric rows after its header",
        ));
    };
    // 18 columns: frame, time, 8 × (x, y) (Table A.1); 17: time, 8 × (x, y) (wn35b).
    let ncols = first_row.len();
    let (has_frame, nm) = match ncols {
        18 => (true, 8),
        17 => (false, 8),
        n if n >= 4 && n % 2 == 0 => (true, (n - 2) / 2),
        n if n >= 3 => (false, (n - 1) / 2),
        n => {
            return Err(IngestError::cell(
                path,
                *first_ln,
                "row",
                format!("{n} columns: expected [frame] time x1 y1 x2 y2 …"),
            ))
        }
    };
    for (ln, r) in &rows {
        if r.len() != ncols {
            let which = if r.len() < ncols {
                let m = (r.len().saturating_sub(ncols - 2 * nm)) / 2;
                format!("marker {} and after", m + 1)
            } else {
                "row".to_string()
            };
            return Err(IngestError::cell(
                path,
                *ln,
                which,
                format!(
                    "{} columns where the first data row (line {first_ln}) has {ncols}: the file \
                     is truncated or corrupt",
                    r.len()
                ),
            ));
        }
    }
    let t0 = if has_frame { 1 } else { 0 };
    let file_time: Vec<f64> = rows.iter().map(|(_, r)| r[t0]).collect();
    let lines: Vec<usize> = rows.iter().map(|(l, _)| *l).collect();
    text::check_time(&file_time, &lines, path, "TIME")?;
    let mut notes = Vec::new();

    // Names.
    let header_names = header_names(&header);
    let names: Vec<String> = if nm == 8 {
        if !header_names.is_empty() && header_names != TABLE_A1_NAMES {
            notes.push(format!(
                "landmarks {} renamed to Winter's Table A.1 names {} (same order and subject)",
                header_names.join("/"),
                TABLE_A1_NAMES.join("/")
            ));
        }
        TABLE_A1_NAMES.iter().map(|s| s.to_string()).collect()
    } else if header_names.len() == nm {
        header_names
    } else {
        (1..=nm).map(|i| format!("M{i}")).collect()
    };

    // Units from magnitudes: the highest landmark's mean height.
    let n = rows.len();
    let mean_y = |m: usize| rows.iter().map(|(_, r)| r[t0 + 2 + 2 * m]).sum::<f64>() / n as f64;
    let top = (0..nm).map(mean_y).fold(f64::NEG_INFINITY, f64::max);
    let (scale, unit) = if (0.5..=2.5).contains(&top) {
        (1.0, "m")
    } else if (50.0..=250.0).contains(&top) {
        (0.01, "cm")
    } else if (500.0..=2500.0).contains(&top) {
        (0.001, "mm")
    } else {
        return Err(IngestError::UnknownUnit {
            path: path.to_path_buf(),
            column: names[0].clone(),
            message: format!(
                "the highest landmark stands at {top} units, which is not a body height in m, cm \
                 or mm: check the file"
            ),
        });
    };
    let declared = declared_unit(&header);
    match declared.as_deref() {
        Some(d) if d != unit => notes.push(format!(
            "units: the header says {d} but the values are in {unit} (highest landmark at {top:.3}, \
             i.e. {:.2} m); read as {unit}",
            top * scale
        )),
        Some(d) => notes.push(format!(
            "units: {d} (header), confirmed by magnitudes (highest landmark {:.2} m)",
            top * scale
        )),
        None => notes.push(format!(
            "units: {unit}, from magnitudes (highest landmark at {top:.3} → {:.2} m); the header \
             gives none",
            top * scale
        )),
    }

    // Rate.
    let implied = text::rate_from_time(&file_time).unwrap_or(WINTER_RATE_HZ);
    let rate = if (implied / WINTER_RATE_HZ - 1.0).abs() < 2e-3 {
        notes.push(format!(
            "rate: {WINTER_RATE_HZ} Hz (Winter's film rate); the rounded time column implies \
             {implied:.2} Hz, time made uniform"
        ));
        WINTER_RATE_HZ
    } else {
        notes.push(format!("rate: {implied} Hz from the time column"));
        implied
    };
    let time: Vec<f64> = (0..n).map(|i| file_time[0] + i as f64 / rate).collect();
    let positions: Vec<Vec<[f64; 3]>> = (0..nm)
        .map(|m| {
            rows.iter()
                .map(|(_, r)| [r[t0 + 1 + 2 * m] * scale, r[t0 + 2 + 2 * m] * scale, 0.0])
                .collect()
        })
        .collect();
    let name = path
        .file_stem()
        .map(|s| s.to_string_lossy().into_owned())
        .unwrap_or_default();
    let mut trial = Trial::new(path, name);
    trial.gait = Some(Gait::Walk);
    trial.setting = Setting::Overground;
    trial.markers = Some(MarkerSet {
        rate_hz: rate,
        time_s: time,
        names,
        positions,
    });
    trial
        .subject
        .notes
        .push("Winter's table gives no body height, leg length or mass".to_string());
    trial.notes = notes;
    trial
        .notes
        .push("2-D table: x horizontal, y vertical, z set to 0".to_string());
    let declared_up = Direction {
        axis: Axis::Y,
        sign: 1.0,
        how: "vertical = +Y (2-D table: x horizontal, y vertical)".to_string(),
    };
    finish(&mut trial, opts, Some(declared_up));
    Ok(trial)
}

/// Landmark names from the first header line: quoted names (`'RIGHT HEEL'`) or pairs of words
/// (`Heel Heel`), without the frame/time columns.
fn header_names(header: &[(usize, &[u8])]) -> Vec<String> {
    let Some((_, line)) = header.first() else {
        return Vec::new();
    };
    let s = String::from_utf8_lossy(line);
    if s.contains('\'') {
        s.split('\'')
            .skip(1)
            .step_by(2)
            .map(|t| t.trim().to_string())
            .filter(|t| !t.is_empty() && t != "FRAME" && t != "TIME")
            .collect()
    } else {
        let words: Vec<&str> = s.split_whitespace().skip(1).collect();
        words.chunks(2).map(|c| c[0].to_string()).collect()
    }
}

/// The length unit a header line declares (`s cm cm …`), if any.
fn declared_unit(header: &[(usize, &[u8])]) -> Option<String> {
    header.iter().find_map(|(_, l)| {
        let s = String::from_utf8_lossy(l);
        let w: Vec<&str> = s.split_whitespace().collect();
        let unit = *w.get(1)?;
        (w.len() > 2 && text::length_scale(unit).is_some() && w[1..].iter().all(|x| *x == unit))
            .then(|| unit.to_string())
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn reads_table_a1_layout_in_cm() {
        let mut s = String::from(
            "'FRAME' 'TIME' 'RIB CAGE' 'RIGHT HIP' 'RIGHT KNEE' 'RIGHT FIBULA' 'RIGHT ANKLE' \
             'RIGHT HEEL' 'RIGHT MT5' 'RIGHT TOE'\n 'N' 'S' 'X' 'Y' 'X' 'Y' 'X' 'Y' 'X' 'Y' 'X' \
             'Y' 'X' 'Y' 'X' 'Y' 'X' 'Y'\n",
        );
        for i in 0..80 {
            let x = 2.0 * i as f64;
            s.push_str(&format!(
                "{} {:.3} {x} 104 {x} 78 {x} 47 {x} 40 {x} 9 {} 3 {} 2 {} 3\n",
                i + 1,
                i as f64 / 69.9,
                x - 5.0,
                x + 10.0,
                x + 14.0
            ));
        }
        let t = parse(s.as_bytes(), Path::new("w.txt"), &ReadOptions::default()).unwrap();
        let m = t.markers.as_ref().unwrap();
        assert_eq!(m.names.len(), 8);
        assert_eq!(m.rate_hz, 69.9);
        assert!((m.get("RIB CAGE").unwrap()[0][1] - 1.04).abs() < 1e-12);
        let f = t.frame.as_ref().unwrap();
        assert_eq!(
            (f.vertical, f.forward, f.forward_sign),
            (Axis::Y, Axis::X, 1.0)
        );
    }

    #[test]
    fn short_row_is_an_error_naming_the_line() {
        let s = "'FRAME' 'TIME' 'A' 'B'\n1 0 1 100 2 50\n2 0.014 1 100 2\n";
        let e = parse(s.as_bytes(), Path::new("w.txt"), &ReadOptions::default()).unwrap_err();
        let msg = e.to_string();
        assert!(msg.contains("row 3"), "{msg}");
        assert!(msg.contains("marker 2"), "{msg}");
    }
}
