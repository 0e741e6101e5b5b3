//! OpenSim MOT / STO tables: ground reaction forces (`grf_run.mot`, Hamner's `Run_V_grf.mot`)
//! and joint angles (`ik_output_run.mot`, Schreiber's `*_ik.mot`).
//!
//! Layout: header lines up to `endheader` (`name …`, `datacolumns 19`, `datarows 246`,
//! `range 0 0.82`, or `nRows=`, `nColumns=`, `inDegrees=yes`, …), then one line of column names
//! starting with `time`, then one row per sample, tab- (or space-) separated.
//!
//! Decisions:
//! - Every cell must be a finite number (`NaN`, `inf`, text and short rows are errors naming the
//!   row and column); a file with fewer rows than `datarows`/`nRows` is truncated (error).
//! - `inDegrees=yes`: rotational coordinates (every column except time, `*_tx/_ty/_tz`, forces,
//!   centres of pressure and torques) are converted to radians in [`MotTable`].
//! - GRF columns are grouped by their stem: `R_ground_force_v{x,y,z}` (N), `R_ground_force_p{x,y,z}`
//!   (centre of pressure, m) and `R_ground_torque_{x,y,z}` (N·m) form one [`ForcePlate`] with
//!   `side = Right` (`L_…` → Left; stems without a side, e.g. `ground_force_…` or
//!   `1_ground_force_…`, give `side = None`). The free moment is the torque about the vertical.
//!   OpenSim writes COP in metres; if the loaded COP exceeds 20 in magnitude it can only be
//!   millimetres, and it is scaled (with a note).
//! - While the vertical force is below [`ReadOptions::cop_min_force_n`] the COP is `NaN` (the
//!   files write 0 there).
use super::frame_detect;
use super::text::{self, Num};
use super::types::{ForcePlate, Trial};
use super::{finish, hamner, IngestError, ReadOptions};
use crate::gait::Side;
use std::path::Path;

/// A MOT/STO table in SI units (angles in radians when the file says `inDegrees=yes`).
#[derive(Debug, Clone, PartialEq)]
pub struct MotTable {
    /// Header entries (`key`, `value`) as written before `endheader`.
    pub header: Vec<(String, String)>,
    /// Sample times, s (the `time` column).
    pub time_s: Vec<f64>,
    /// Sampling rate implied by the time column, Hz.
    pub rate_hz: f64,
    /// Column names other than `time`, in file order.
    pub names: Vec<String>,
    /// `columns[i]` holds the values of `names[i]`.
    pub columns: Vec<Vec<f64>>,
    /// `Some(true)` when the file said `inDegrees=yes` (and angles were converted to radians).
    pub in_degrees: Option<bool>,
    /// Which columns were treated as angles (converted when `in_degrees == Some(true)`).
    pub is_angle: Vec<bool>,
}

impl MotTable {
    /// The column named `name` (exact, then case-insensitive).
    pub fn column(&self, name: &str) -> Option<&[f64]> {
        self.names
            .iter()
            .position(|n| n == name)
            .or_else(|| self.names.iter().position(|n| n.eq_ignore_ascii_case(name)))
            .map(|i| self.columns[i].as_slice())
    }
}

/// Reads a MOT/STO table.
pub fn read_table(path: &Path) -> Result<MotTable, IngestError> {
    let bytes = text::read_bytes(path)?;
    parse_table(&bytes, path)
}

fn is_angle_column(name: &str) -> bool {
    let n = name.to_ascii_lowercase();
    !(n == "time"
        || n.ends_with("_tx")
        || n.ends_with("_ty")
        || n.ends_with("_tz")
        || n.contains("force")
        || n.contains("torque")
        || n.contains("moment"))
}

/// Parses MOT/STO bytes (see the module docs for the rules).
pub fn parse_table(bytes: &[u8], path: &Path) -> Result<MotTable, IngestError> {
    let mut it = text::lines(bytes);
    let mut header = Vec::new();
    let mut found_end = false;
    for (_, line) in it.by_ref() {
        let t = text::text(line);
        if t.eq_ignore_ascii_case("endheader") {
            found_end = true;
            break;
        }
        if t.is_empty() {
            continue;
        }
        let (k, v) = match t.split_once('=') {
            Some((k, v)) => (k.trim().to_string(), v.trim().to_string()),
            None => match t.split_once(char::is_whitespace) {
                Some((k, v)) => (k.trim().to_string(), v.trim().to_string()),
                None => (t.clone(), String::new()),
            },
        };
        header.push((k, v));
    }
    if !found_end {
        return Err(IngestError::malformed(
            path,
            "no `endheader` line: a MOT/STO file has a header ending in `endheader`, then the \
             column names",
        ));
    }
    let hget = |keys: &[&str]| -> Option<&str> {
        header
            .iter()
            .find(|(k, _)| keys.iter().any(|x| k.eq_ignore_ascii_case(x)))
            .map(|(_, v)| v.as_str())
    };
    let (nl, names_line) = it
        .by_ref()
        .find(|(_, l)| !text::is_blank(l))
        .ok_or_else(|| {
            IngestError::malformed(path, "file ends after `endheader`: no column names")
        })?;
    let delim = if names_line.contains(&b'\t') {
        Some(b'\t')
    } else {
        None
    };
    let mut name_cells: Vec<&[u8]> = match delim {
        Some(d) => text::cells(names_line, d).collect(),
        None => text::words(names_line).collect(),
    };
    while name_cells.last().is_some_and(|c| text::trim(c).is_empty()) {
        name_cells.pop();
    }
    let all_names: Vec<String> = name_cells.into_iter().map(text::text).collect();
    if all_names.first().map(|n| n.to_ascii_lowercase()) != Some("time".to_string()) {
        return Err(IngestError::MissingColumn {
            path: path.to_path_buf(),
            column: "time".to_string(),
            message: format!("line {nl}: the first column must be `time` (s)"),
        });
    }
    let ncol = all_names.len();
    if let Some(declared) = hget(&["datacolumns", "nColumns"]) {
        if let Ok(d) = declared.trim().parse::<usize>() {
            if d != ncol {
                return Err(IngestError::malformed(
                    path,
                    format!("line {nl}: {ncol} column names but the header declares {d} columns"),
                ));
            }
        }
    }
    let declared_rows = hget(&["datarows", "nRows"]).and_then(|v| v.trim().parse::<usize>().ok());
    let cap = declared_rows.unwrap_or(1024);
    let mut time = Vec::with_capacity(cap);
    let mut lines_of = Vec::with_capacity(cap);
    let mut columns: Vec<Vec<f64>> = (1..ncol).map(|_| Vec::with_capacity(cap)).collect();
    let mut row: Vec<f64> = Vec::with_capacity(ncol);
    for (ln, line) in it {
        if text::is_blank(line) {
            continue;
        }
        if let Some(d) = delim {
            text::numeric_row(line, d, ncol, &mut row)
                .map_err(|e| e.into_ingest(path, ln, line, d, &all_names))?;
        } else if let Err(bad) = parse_row(text::words(line), ncol, &mut row) {
            return Err(match bad {
                RowError::Cell(n, cell) => IngestError::cell(
                    path,
                    ln,
                    all_names[n].clone(),
                    format!("{cell:?} is not a finite number"),
                ),
                RowError::Short(n) => IngestError::cell(
                    path,
                    ln,
                    all_names[n].clone(),
                    format!(
                        "row has {n} of {ncol} columns: the file is truncated or a cell is missing"
                    ),
                ),
                RowError::Long => IngestError::cell(
                    path,
                    ln,
                    format!("column {}", ncol + 1),
                    format!("more cells than the {ncol} column names"),
                ),
            });
        }
        time.push(row[0]);
        for (c, v) in columns.iter_mut().zip(&row[1..]) {
            c.push(*v);
        }
        lines_of.push(ln);
    }
    if time.is_empty() {
        return Err(IngestError::malformed(
            path,
            "no data rows after the column names",
        ));
    }
    if let Some(d) = declared_rows {
        if time.len() < d {
            return Err(IngestError::malformed(
                path,
                format!(
                    "the header declares {d} rows but only {} follow: the file is truncated",
                    time.len()
                ),
            ));
        }
    }
    text::check_time(&time, &lines_of, path, "time")?;
    let rate = text::rate_from_time(&time).unwrap_or(f64::NAN);
    let in_degrees = hget(&["inDegrees"]).map(|v| v.trim().eq_ignore_ascii_case("yes"));
    let names: Vec<String> = all_names[1..].to_vec();
    let is_angle: Vec<bool> = names.iter().map(|n| is_angle_column(n)).collect();
    if in_degrees == Some(true) {
        for (c, &a) in columns.iter_mut().zip(&is_angle) {
            if a {
                c.iter_mut().for_each(|v| *v = v.to_radians());
            }
        }
    }
    Ok(MotTable {
        header,
        time_s: time,
        rate_hz: rate,
        names,
        columns,
        in_degrees,
        is_angle,
    })
}

enum RowError {
    /// Column index and the cell's text.
    Cell(usize, String),
    /// Only this many cells.
    Short(usize),
    /// Non-empty cells beyond the last column.
    Long,
}

/// Parses one row of `ncol` finite numbers into `row` (cleared first).
fn parse_row<'a>(
    mut cells: impl Iterator<Item = &'a [u8]>,
    ncol: usize,
    row: &mut Vec<f64>,
) -> Result<(), RowError> {
    row.clear();
    for (n, cell) in cells.by_ref().take(ncol).enumerate() {
        match text::num(cell) {
            Num::Value(v) if v.is_finite() => row.push(v),
            _ => return Err(RowError::Cell(n, text::text(cell))),
        }
    }
    if row.len() < ncol {
        return Err(RowError::Short(row.len()));
    }
    if cells.any(|c| !text::trim(c).is_empty()) {
        return Err(RowError::Long);
    }
    Ok(())
}

/// One GRF column group found in a table.
struct Group {
    stem: String,
    v: [usize; 3],
    p: Option<[usize; 3]>,
    torque: Option<[usize; 3]>,
}

fn find_groups(t: &MotTable) -> Vec<Group> {
    let idx = |name: &str| t.names.iter().position(|n| n.eq_ignore_ascii_case(name));
    let mut out = Vec::new();
    for n in &t.names {
        let lower = n.to_ascii_lowercase();
        if !lower.ends_with("force_vx") {
            continue;
        }
        let stem = &n[..n.len() - 2];
        let tri = |base: &str| -> Option<[usize; 3]> {
            Some([
                idx(&format!("{base}x"))?,
                idx(&format!("{base}y"))?,
                idx(&format!("{base}z"))?,
            ])
        };
        let Some(v) = tri(&format!("{stem}v")) else {
            continue;
        };
        let p = tri(&format!("{stem}p"));
        let torque_stem = {
            let s = stem.to_ascii_lowercase();
            let at = s.rfind("force").unwrap_or(0);
            format!("{}torque{}", &stem[..at], &stem[at + 5..])
        };
        let torque = tri(&torque_stem);
        out.push(Group {
            stem: stem.trim_end_matches('_').to_string(),
            v,
            p,
            torque,
        });
    }
    out
}

fn side_of_stem(stem: &str) -> Option<Side> {
    let s = stem.to_ascii_lowercase();
    if s.starts_with("r_") || s.starts_with("right") {
        Some(Side::Right)
    } else if s.starts_with("l_") || s.starts_with("left") {
        Some(Side::Left)
    } else {
        None
    }
}

/// The force plates of a GRF table (see the module docs); empty when it has no GRF columns.
pub fn plates_from_table(
    t: &MotTable,
    path: &Path,
    opts: &ReadOptions,
) -> (Vec<ForcePlate>, Vec<String>) {
    let groups = find_groups(t);
    let mut notes = Vec::new();
    let mut plates: Vec<ForcePlate> = groups
        .iter()
        .map(|g| {
            let n = t.time_s.len();
            let col = |i: usize| &t.columns[i];
            ForcePlate {
                name: g.stem.clone(),
                rate_hz: t.rate_hz,
                time_s: t.time_s.clone(),
                force_n: (0..n)
                    .map(|s| [col(g.v[0])[s], col(g.v[1])[s], col(g.v[2])[s]])
                    .collect(),
                cop_m: match g.p {
                    Some(p) => (0..n)
                        .map(|s| [col(p[0])[s], col(p[1])[s], col(p[2])[s]])
                        .collect(),
                    None => vec![[f64::NAN; 3]; n],
                },
                free_moment_nm: Vec::new(),
                side: side_of_stem(&g.stem),
            }
        })
        .collect();
    if plates.is_empty() {
        return (plates, notes);
    }
    let vertical = opts
        .vertical
        .map(|axis| frame_detect::Direction {
            axis,
            sign: 1.0,
            how: String::new(),
        })
        .or_else(|| frame_detect::vertical_from_plates(&plates));
    // COP in metres unless its loaded magnitude says millimetres.
    let loaded_max = plates
        .iter()
        .flat_map(|p| p.force_n.iter().zip(&p.cop_m))
        .filter(|(f, _)| f.iter().map(|v| v.abs()).fold(0.0, f64::max) > opts.cop_min_force_n)
        .flat_map(|(_, c)| c.iter().copied())
        .filter(|v| v.is_finite())
        .fold(0.0, |a: f64, v| a.max(v.abs()));
    if loaded_max > 20.0 {
        notes.push(format!(
            "{}: centre of pressure up to {loaded_max:.0} — read as mm (OpenSim writes m)",
            path.display()
        ));
        for p in &mut plates {
            for c in &mut p.cop_m {
                *c = c.map(|v| v * 1e-3);
            }
        }
    }
    for (p, g) in plates.iter_mut().zip(&groups) {
        if let Some(v) = &vertical {
            let k = v.axis.index();
            for (f, c) in p.force_n.iter().zip(p.cop_m.iter_mut()) {
                if v.sign * f[k] < opts.cop_min_force_n {
                    *c = [f64::NAN; 3];
                }
            }
            if let Some(tq) = g.torque {
                p.free_moment_nm = t.columns[tq[k]].iter().map(|m| v.sign * m).collect();
            }
        }
    }
    let sides: Vec<String> = plates
        .iter()
        .map(|p| match p.side {
            Some(s) => format!("{} ({s} foot)", p.name),
            None => p.name.clone(),
        })
        .collect();
    notes.push(format!(
        "GRF: {} plate(s) at {} Hz from {}: {}; force N, COP m (NaN below {} N)",
        plates.len(),
        t.rate_hz,
        path.display(),
        sides.join(", "),
        opts.cop_min_force_n
    ));
    (plates, notes)
}

/// Reads the force plates of a GRF MOT file, with notes.
pub fn read_plates(
    path: &Path,
    opts: &ReadOptions,
) -> Result<(Vec<ForcePlate>, Vec<String>), IngestError> {
    let t = read_table(path)?;
    let (plates, notes) = plates_from_table(&t, path, opts);
    if plates.is_empty() {
        return Err(IngestError::MissingColumn {
            path: path.to_path_buf(),
            column: "R_ground_force_vx".to_string(),
            message: "no ground-reaction-force columns (…force_vx/vy/vz) in this table".to_string(),
        });
    }
    Ok((plates, notes))
}

/// Reads a MOT/STO file into a trial: a GRF table becomes force plates; any other table (joint
/// angles) gives a trial without markers or plates and a note (read it with [`read_table`]).
pub fn read(path: &Path, opts: &ReadOptions) -> Result<Trial, IngestError> {
    let bytes = text::read_bytes(path)?;
    parse(&bytes, path, opts)
}

/// [`read`] on bytes already in memory.
pub fn parse(bytes: &[u8], path: &Path, opts: &ReadOptions) -> Result<Trial, IngestError> {
    let t = parse_table(bytes, path)?;
    let name = path
        .file_stem()
        .map(|s| s.to_string_lossy().into_owned())
        .unwrap_or_default();
    let mut trial = Trial::new(path, name);
    let (plates, notes) = plates_from_table(&t, path, opts);
    if plates.is_empty() {
        trial.notes.push(format!(
            "MOT table with {} columns at {} Hz and no GRF columns (angles {}): read it with \
             ingest::mot::read_table",
            t.names.len(),
            t.rate_hz,
            match t.in_degrees {
                Some(true) => "in degrees in the file, radians in the table",
                Some(false) => "in radians",
                None => "unit not stated",
            }
        ));
    }
    trial.plates = plates;
    trial.notes.extend(notes);
    if opts.companions {
        hamner::apply(&mut trial, path, opts)?;
    }
    finish(&mut trial, opts, None);
    Ok(trial)
}

#[cfg(test)]
mod tests {
    use super::*;

    const GRF: &str = "name x\ndatacolumns 7\ndatarows 3\nendheader\n\
        time\tR_ground_force_vx\tR_ground_force_vy\tR_ground_force_vz\tR_ground_force_px\tR_ground_force_py\tR_ground_force_pz\n\
        0.000\t1\t700\t2\t0.5\t0\t0.1\n\
        0.001\t1\t10\t2\t0.5\t0\t0.1\n\
        0.002\t1\t710\t2\t0.6\t0\t0.1\n";

    #[test]
    fn grf_table_becomes_a_right_plate() {
        let t = parse_table(GRF.as_bytes(), Path::new("g.mot")).unwrap();
        assert_eq!(t.rate_hz, 1000.0);
        let (p, _) = plates_from_table(&t, Path::new("g.mot"), &ReadOptions::default());
        assert_eq!(p.len(), 1);
        assert_eq!(p[0].side, Some(Side::Right));
        assert_eq!(p[0].force_n[0], [1.0, 700.0, 2.0]);
        assert!(p[0].cop_m[1][0].is_nan());
        assert_eq!(p[0].cop_m[2], [0.6, 0.0, 0.1]);
    }

    #[test]
    fn degrees_become_radians_but_translations_stay() {
        let s = "Coordinates\nnRows=2\nnColumns=3\ninDegrees=yes\nendheader\n\
                 time\tknee_angle_r\tpelvis_tx\n0\t90\t1.5\n0.01\t180\t1.6\n";
        let t = parse_table(s.as_bytes(), Path::new("ik.mot")).unwrap();
        assert!((t.column("knee_angle_r").unwrap()[0] - std::f64::consts::FRAC_PI_2).abs() < 1e-12);
        assert_eq!(t.column("pelvis_tx").unwrap()[1], 1.6);
    }

    #[test]
    fn bad_tables_are_errors() {
        let p = Path::new("g.mot");
        let trunc = GRF.replace("0.002\t1\t710\t2\t0.6\t0\t0.1\n", "");
        let e = parse_table(trunc.as_bytes(), p).unwrap_err().to_string();
        assert!(e.contains("truncated"), "{e}");
        let nan = GRF.replace("0.001\t1\t10", "0.001\tNaN\t10");
        let e = parse_table(nan.as_bytes(), p).unwrap_err().to_string();
        assert!(
            e.contains("row 7") && e.contains("R_ground_force_vx"),
            "{e}"
        );
        let short = GRF.replace("0.001\t1\t10\t2\t0.5\t0\t0.1", "0.001\t1\t10\t2");
        let e = parse_table(short.as_bytes(), p).unwrap_err().to_string();
        assert!(e.contains("R_ground_force_px"), "{e}");
        let back = GRF.replace("0.002\t", "0.0005\t");
        let e = parse_table(back.as_bytes(), p).unwrap_err().to_string();
        assert!(e.contains("does not increase"), "{e}");
        let noend = GRF.replace("endheader\n", "");
        assert!(parse_table(noend.as_bytes(), p).is_err());
    }
}
