//! OpenSim / Cortex TRC marker files.
//!
//! Layout (tab-separated):
//! ```text
//! PathFileType  4  (X/Y/Z)  name
//! DataRate  CameraRate  NumFrames  NumMarkers  Units  OrigDataRate  OrigDataStartFrame  OrigNumFrames
//! 150.00    150.00      364        28          mm     150.00        1                   364
//! Frame#  Time  R.ASIS      L.ASIS  …
//!               X1  Y1  Z1  X2  Y2  Z2 …
//! (optional blank line)
//! 1  0.000  516.5  966.9  -306.1  …
//! ```
//! Decisions:
//! - `Units` (`mm`, `cm`, `m`, …) scales every coordinate to metres once; an unknown unit is an
//!   error. The time column is the file's (Hamner's files start at 0.05 s, on the same clock as
//!   their GRF); `DataRate` is the rate.
//! - An empty cell, `NaN`, or a marker at exactly (0, 0, 0) is a missing sample (gap-filled and
//!   reported by [`super::gaps`]); `±inf` and text are errors naming row and marker.
//! - A row with fewer cells than `Frame#`, `Time` and X/Y/Z for each of the `NumMarkers` declared
//!   markers is an error (truncated or corrupt file). Fewer whole data rows than `NumFrames`
//!   (a header that over-counts its frames, as in half of the upstream Hamner TRC files) are
//!   read, with a `warning:` note. Cortex writes extra (virtual, `V_…`) marker names beyond `NumMarkers` with
//!   empty columns: those are read when present and dropped, with a note, when they hold no data.
use super::text;
use super::types::{MarkerSet, Trial};
use super::{finish, forces, hamner, mot, IngestError, ReadOptions};
use std::path::Path;

/// The header of a TRC file.
#[derive(Debug, Clone, PartialEq)]
pub struct TrcHeader {
    /// `DataRate`, Hz.
    pub data_rate_hz: f64,
    /// `NumFrames`.
    pub num_frames: usize,
    /// `NumMarkers`.
    pub num_markers: usize,
    /// `Units` as written.
    pub units: String,
    /// Metres per file unit.
    pub scale_to_m: f64,
}

/// Reads a TRC file into a trial (markers; plus, with `opts.companions`, the force plates of a
/// same-named `.forces` or `_grf.mot` file beside it and the Hamner data set's subject data),
/// fills short gaps and detects the frame.
pub fn read(path: &Path, opts: &ReadOptions) -> Result<Trial, IngestError> {
    let bytes = text::read_bytes(path)?;
    let (markers, header, mut notes) = parse_markers(&bytes, path)?;
    let name = path
        .file_stem()
        .map(|s| s.to_string_lossy().into_owned())
        .unwrap_or_default();
    let mut trial = Trial::new(path, name);
    notes.insert(
        0,
        format!(
            "TRC: {} markers, {} frames at {} Hz, units {} → m",
            markers.names.len(),
            markers.len(),
            header.data_rate_hz,
            header.units
        ),
    );
    trial.notes = notes;
    trial.markers = Some(markers);
    if opts.companions {
        attach_companion_plates(&mut trial, path, opts)?;
        hamner::apply(&mut trial, path, opts)?;
    }
    finish(&mut trial, opts, None);
    Ok(trial)
}

/// Reads the plates of `X.forces` or `X_grf.mot` beside `X.trc`, if one exists.
fn attach_companion_plates(
    trial: &mut Trial,
    path: &Path,
    opts: &ReadOptions,
) -> Result<(), IngestError> {
    let Some(stem) = path.file_stem() else {
        return Ok(());
    };
    let dir = path.parent().unwrap_or(Path::new("."));
    let stem = stem.to_string_lossy();
    let forces_path = dir.join(format!("{stem}.forces"));
    let mot_path = dir.join(format!("{stem}_grf.mot"));
    if forces_path.is_file() {
        let (plates, notes) = forces::read_plates(&forces_path, opts)?;
        trial.plates.extend(plates);
        trial.notes.push(format!(
            "force plates from companion file {}",
            forces_path.display()
        ));
        trial.notes.extend(notes);
    } else if mot_path.is_file() {
        let (plates, notes) = mot::read_plates(&mot_path, opts)?;
        trial.plates.extend(plates);
        trial.notes.push(format!(
            "force plates from companion file {}",
            mot_path.display()
        ));
        trial.notes.extend(notes);
    }
    Ok(())
}

/// Reads only the markers of a TRC file (no gap filling, no companions).
pub fn read_markers(path: &Path) -> Result<(MarkerSet, TrcHeader, Vec<String>), IngestError> {
    let bytes = text::read_bytes(path)?;
    parse_markers(&bytes, path)
}

/// Parses TRC bytes: markers in metres (missing samples `NaN`, not yet filled), the header, and
/// notes (dropped empty virtual markers, non-contiguous frame numbers).
pub fn parse_markers(
    bytes: &[u8],
    path: &Path,
) -> Result<(MarkerSet, TrcHeader, Vec<String>), IngestError> {
    let mut it = text::lines(bytes);
    let mut next = |what: &str| {
        it.next().ok_or_else(|| {
            IngestError::malformed(
                path,
                format!("file ends before the {what}: a TRC file has 5 header lines"),
            )
        })
    };
    let (_, l1) = next("PathFileType line")?;
    if !text::trim(l1).starts_with(b"PathFileType") {
        return Err(IngestError::malformed(
            path,
            "line 1: a TRC file starts with PathFileType",
        ));
    }
    let (_, keys) = next("header keys (DataRate …)")?;
    let (vl, values) = next("header values")?;
    let keys: Vec<String> = text::cells(keys, b'\t').map(text::text).collect();
    let values: Vec<&[u8]> = text::cells(values, b'\t').collect();
    let get = |key: &str| -> Result<&[u8], IngestError> {
        keys.iter()
            .position(|k| k.eq_ignore_ascii_case(key))
            .and_then(|i| values.get(i).copied())
            .ok_or_else(|| IngestError::MissingColumn {
                path: path.to_path_buf(),
                column: key.to_string(),
                message: "line 2/3 of a TRC file must give DataRate, NumFrames, NumMarkers and \
                          Units"
                    .to_string(),
            })
    };
    let rate = text::finite(get("DataRate")?, path, vl, "DataRate")?;
    if rate <= 0.0 {
        return Err(IngestError::cell(
            path,
            vl,
            "DataRate",
            format!("{rate} Hz: the rate must be positive"),
        ));
    }
    let count = |key: &str| -> Result<usize, IngestError> {
        let v = text::finite(get(key)?, path, vl, key)?;
        if v < 0.0 || v.fract() != 0.0 {
            return Err(IngestError::cell(
                path,
                vl,
                key,
                format!("{v} is not a whole number"),
            ));
        }
        Ok(v as usize)
    };
    let num_frames = count("NumFrames")?;
    let num_markers = count("NumMarkers")?;
    let units = text::text(get("Units")?);
    let scale = text::length_scale(&units).ok_or_else(|| IngestError::UnknownUnit {
        path: path.to_path_buf(),
        column: "Units".to_string(),
        message: format!("{units:?} is not a length unit: use mm, cm or m"),
    })?;

    let (nl, names_line) = next("marker names (Frame# Time …)")?;
    // Names sit in columns 2, 5, 8, …
    let mut names: Vec<String> = Vec::new();
    for (c, cell) in text::cells(names_line, b'\t').enumerate().skip(2) {
        let t = text::text(cell);
        if t.is_empty() {
            continue;
        }
        if (c - 2) % 3 != 0 {
            return Err(IngestError::cell(
                path,
                nl,
                t,
                format!(
                    "marker name in column {}: names must sit every third column from column 3",
                    c + 1
                ),
            ));
        }
        while names.len() < (c - 2) / 3 {
            names.push(format!("unnamed{}", names.len() + 1));
        }
        names.push(t);
    }
    if names.len() < num_markers {
        return Err(IngestError::malformed(
            path,
            format!(
                "line {nl}: {} marker names for NumMarkers = {num_markers}: the header is \
                 truncated or NumMarkers is wrong",
                names.len()
            ),
        ));
    }
    let _ = next("coordinate labels (X1 Y1 Z1 …)")?;
    let nmk = names.len();
    let need = 2 + 3 * num_markers;
    let mut time: Vec<f64> = Vec::with_capacity(num_frames);
    let mut frames: Vec<f64> = Vec::with_capacity(num_frames);
    let mut lines_of: Vec<usize> = Vec::with_capacity(num_frames);
    let mut pos: Vec<Vec<[f64; 3]>> = (0..nmk).map(|_| Vec::with_capacity(num_frames)).collect();
    let mut has_data = vec![false; nmk];
    let mut vals: Vec<f64> = Vec::with_capacity(2 + 3 * nmk);
    for (ln, line) in it {
        if text::is_blank(line) {
            continue;
        }
        let ncells = match text::sparse_row(line, b'\t', 2 + 3 * nmk, &mut vals) {
            Ok(n) => n,
            Err(text::RowError::Bad(c)) => {
                let cell = text::cells(line, b'\t')
                    .nth(c)
                    .map(text::text)
                    .unwrap_or_default();
                let column = match c {
                    0 => "Frame#".to_string(),
                    1 => "Time".to_string(),
                    c => format!("{} {}", names[(c - 2) / 3], ["X", "Y", "Z"][(c - 2) % 3]),
                };
                return Err(IngestError::cell(
                    path,
                    ln,
                    column,
                    format!(
                        "{cell:?} is not a finite number (leave the cell empty for a missing \
                         marker)"
                    ),
                ));
            }
            Err(_) => {
                return Err(IngestError::cell(
                    path,
                    ln,
                    format!("column {}", 3 + 3 * nmk),
                    "data beyond the last named marker: the header is missing a marker name",
                ))
            }
        };
        for (i, what) in [(0, "Frame#"), (1, "Time")] {
            if vals.get(i).is_none_or(|v| v.is_nan()) && ncells >= need {
                return Err(IngestError::cell(
                    path,
                    ln,
                    what,
                    "empty cell: give a number",
                ));
            }
        }
        if ncells < need {
            let first_missing = ncells.saturating_sub(2) / 3;
            let col = names
                .get(first_missing)
                .cloned()
                .unwrap_or_else(|| "Time".to_string());
            return Err(IngestError::cell(
                path,
                ln,
                col,
                format!(
                    "{ncells} columns, but Frame#, Time and X/Y/Z of {num_markers} markers need \
                     {need}: the file is truncated or NumMarkers is wrong"
                ),
            ));
        }
        // Markers whose columns the row does not reach (trailing empty cells left out) are
        // missing in this frame.
        for (m, traj) in pos.iter_mut().enumerate() {
            let p = match vals.get(2 + 3 * m..5 + 3 * m) {
                Some(&[x, y, z]) if !(x.is_nan() || y.is_nan() || z.is_nan()) => {
                    has_data[m] = true;
                    [x * scale, y * scale, z * scale]
                }
                _ => [f64::NAN; 3],
            };
            traj.push(p);
        }
        let (frame_no, t) = (vals[0], vals[1]);
        time.push(t);
        frames.push(frame_no);
        lines_of.push(ln);
    }
    if time.is_empty() {
        return Err(IngestError::malformed(path, "no data rows"));
    }
    text::check_time(&time, &lines_of, path, "Time")?;
    let mut notes = Vec::new();
    if time.len() < num_frames {
        // Every row is whole (a row cut short is an error above): the header over-counts its
        // frames, as half of the upstream Hamner TRC files do.
        notes.push(format!(
            "warning: NumFrames = {num_frames} but the file holds {} whole data rows; those \
             rows read (the header over-counts its frames, or the file was cut at a row end)",
            time.len()
        ));
    }
    if time.len() > num_frames {
        notes.push(format!(
            "{} data rows although NumFrames = {num_frames}; all rows read",
            time.len()
        ));
    }
    let gaps_in_numbering = frames.windows(2).filter(|w| w[1] - w[0] != 1.0).count();
    if gaps_in_numbering > 0 {
        notes.push(format!(
            "frame numbers jump in {gaps_in_numbering} place(s) (frames {}–{} over {} rows): \
             the time column is used as given",
            frames[0],
            frames[frames.len() - 1],
            frames.len()
        ));
    }
    let jitter = text::max_jitter(&time, rate);
    if gaps_in_numbering == 0 && jitter > 0.5 / rate {
        notes.push(format!(
            "the time column departs from DataRate = {rate} Hz by up to {:.1} ms; the time \
             column is used as given",
            jitter * 1e3
        ));
    }
    // Drop names beyond NumMarkers that hold no data at all (Cortex virtual markers).
    let mut dropped = Vec::new();
    let mut keep_names = Vec::with_capacity(nmk);
    let mut keep_pos = Vec::with_capacity(nmk);
    for (i, (n, p)) in names.into_iter().zip(pos).enumerate() {
        if i >= num_markers && !has_data[i] {
            dropped.push(n);
        } else {
            keep_names.push(n);
            keep_pos.push(p);
        }
    }
    if !dropped.is_empty() {
        notes.push(format!(
            "{} marker name(s) beyond NumMarkers = {num_markers} have no data and were dropped: {}",
            dropped.len(),
            dropped.join(", ")
        ));
    }
    let header = TrcHeader {
        data_rate_hz: rate,
        num_frames,
        num_markers,
        units,
        scale_to_m: scale,
    };
    Ok((
        MarkerSet {
            rate_hz: rate,
            time_s: time,
            names: keep_names,
            positions: keep_pos,
        },
        header,
        notes,
    ))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn trc(rows: &[&str], num_frames: usize, units: &str) -> String {
        let mut s = format!(
            "PathFileType\t4\t(X/Y/Z)\tx.trc\nDataRate\tCameraRate\tNumFrames\tNumMarkers\tUnits\n\
             100\t100\t{num_frames}\t2\t{units}\nFrame#\tTime\tRHEE\t\t\tRASI\t\t\t\n\t\tX1\tY1\tZ1\tX2\tY2\tZ2\n\n"
        );
        for r in rows {
            s.push_str(r);
            s.push('\n');
        }
        s
    }

    #[test]
    fn parses_units_and_missing_cells() {
        let s = trc(
            &[
                "1\t0.00\t1\t2\t3\t10\t900\t30",
                "2\t0.01\t\t\t\t11\t900\t30",
            ],
            2,
            "mm",
        );
        let (m, h, _) = parse_markers(s.as_bytes(), Path::new("x.trc")).unwrap();
        assert_eq!(h.num_markers, 2);
        assert_eq!(m.names, vec!["RHEE", "RASI"]);
        assert_eq!(m.positions[0][0], [0.001, 0.002, 0.003]);
        assert!(m.positions[0][1][0].is_nan());
        assert_eq!(m.positions[1][1], [0.011, 0.9, 0.03]);
    }

    #[test]
    fn errors_name_row_and_marker() {
        let p = Path::new("x.trc");
        let short = trc(&["1\t0.00\t1\t2\t3\t10"], 1, "mm");
        let e = parse_markers(short.as_bytes(), p).unwrap_err().to_string();
        assert!(e.contains("row 7") && e.contains("RASI"), "{e}");
        let bad = trc(&["1\t0.00\t1\t2\tx\t10\t1\t1"], 1, "mm");
        let e = parse_markers(bad.as_bytes(), p).unwrap_err().to_string();
        assert!(e.contains("RHEE Z"), "{e}");
        let unit = trc(&["1\t0.00\t1\t2\t3\t10\t1\t1"], 1, "furlongs");
        let e = parse_markers(unit.as_bytes(), p).unwrap_err().to_string();
        assert!(e.contains("Units") && e.contains("furlongs"), "{e}");
        let over = trc(&["1\t0.00\t1\t2\t3\t10\t1\t1"], 5, "mm");
        let (m, _, notes) = parse_markers(over.as_bytes(), p).unwrap();
        assert_eq!(m.len(), 1);
        assert!(
            notes
                .iter()
                .any(|n| n.starts_with("warning:") && n.contains("NumFrames = 5")),
            "{notes:?}"
        );
        let back = trc(
            &["1\t0.01\t1\t2\t3\t10\t1\t1", "2\t0.00\t1\t2\t3\t10\t1\t1"],
            2,
            "mm",
        );
        let e = parse_markers(back.as_bytes(), p).unwrap_err().to_string();
        assert!(e.contains("row 8") && e.contains("Time"), "{e}");
    }
}
