//! Shared low-level text parsing for the readers: lines without their `\r`, cells split on one
//! delimiter without allocating, and numbers parsed straight from the byte slices.
//!
//! Why hand-rolled instead of the `csv` crate: the motion-capture text formats have free-form
//! headers of several lines before the table, tab-separated cells where an empty cell means "marker
//! missing", and a 30 s trial holds ~10⁶ numbers; parsing from borrowed slices (cells found with
//! `memchr`, numbers with `fast-float2`) keeps a trial well under the 50 ms budget (see
//! `benches/ingest.rs`).
use super::IngestError;
use std::path::Path;

/// Reads a whole file.
pub(crate) fn read_bytes(path: &Path) -> Result<Vec<u8>, IngestError> {
    std::fs::read(path).map_err(|e| IngestError::io(path, e))
}

/// Lines of `bytes` with their 1-based line numbers; the `\n` and a trailing `\r` are removed.
pub(crate) fn lines(bytes: &[u8]) -> impl Iterator<Item = (usize, &[u8])> {
    let body = if bytes.is_empty() {
        None
    } else {
        Some(bytes.strip_suffix(b"\n").unwrap_or(bytes))
    };
    body.into_iter()
        .flat_map(|b| cells(b, b'\n'))
        .map(|l| l.strip_suffix(b"\r").unwrap_or(l))
        .enumerate()
        .map(|(i, l)| (i + 1, l))
}

/// True when the line holds nothing but spaces, tabs and commas.
pub(crate) fn is_blank(line: &[u8]) -> bool {
    line.iter().all(|b| matches!(b, b' ' | b'\t' | b','))
}

/// Cells of a line split on `delim` (every delimiter counts: empty cells are kept).
pub(crate) fn cells(line: &[u8], delim: u8) -> impl Iterator<Item = &[u8]> {
    let mut start = 0usize;
    let mut ends = memchr::memchr_iter(delim, line).chain(std::iter::once(line.len()));
    std::iter::from_fn(move || {
        let end = ends.next()?;
        let cell = &line[start..end];
        start = end + 1;
        Some(cell)
    })
}

/// Cells of a line split on runs of spaces and tabs (no empty cells).
pub(crate) fn words(line: &[u8]) -> impl Iterator<Item = &[u8]> {
    line.split(|&b| b == b' ' || b == b'\t')
        .filter(|w| !w.is_empty())
}

/// `cell` without leading/trailing spaces, tabs or quotes.
pub(crate) fn trim(cell: &[u8]) -> &[u8] {
    let is_pad = |b: &u8| matches!(b, b' ' | b'\t' | b'\r' | b'"' | b'\'');
    let start = cell.iter().position(|b| !is_pad(b)).unwrap_or(cell.len());
    let end = cell
        .iter()
        .rposition(|b| !is_pad(b))
        .map_or(start, |e| e + 1);
    &cell[start..end]
}

/// Lossy text of a cell, for messages and names.
pub(crate) fn text(cell: &[u8]) -> String {
    String::from_utf8_lossy(trim(cell)).into_owned()
}

/// A parsed numeric cell.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) enum Num {
    /// The cell is empty (after trimming spaces).
    Empty,
    /// A number (possibly NaN or ±inf, which the caller decides about).
    Value(f64),
    /// Not a number.
    Bad,
}

/// Parses one cell as `f64` (leading/trailing spaces allowed, `NaN`/`inf` accepted as such).
#[inline]
pub(crate) fn num(cell: &[u8]) -> Num {
    let t = trim_spaces(cell);
    if t.is_empty() {
        return Num::Empty;
    }
    match std::str::from_utf8(t)
        .ok()
        .and_then(|s| s.parse::<f64>().ok())
    {
        Some(v) => Num::Value(v),
        None => Num::Bad,
    }
}

/// Parses a row of `ncol` delimited finite numbers into `out` (cleared first): the hot loop of
/// every numeric table. Cells may carry spaces around the number. On failure returns the
/// 0-based column and what went wrong; non-empty cells beyond `ncol` are an error too.
#[inline]
pub(crate) fn numeric_row(
    line: &[u8],
    delim: u8,
    ncol: usize,
    out: &mut Vec<f64>,
) -> Result<(), RowError> {
    out.clear();
    let mut rest = line;
    loop {
        let end = memchr::memchr(delim, rest).unwrap_or(rest.len());
        let cell = &rest[..end];
        if out.len() == ncol {
            if !trim_spaces(cell).is_empty() {
                return Err(RowError::Long);
            }
        } else {
            let t = trim_spaces(cell);
            match fast_float2::parse_partial::<f64, _>(t) {
                Ok((v, n)) if n == t.len() && v.is_finite() => out.push(v),
                _ if t.is_empty() => return Err(RowError::Empty(out.len())),
                _ => return Err(RowError::Bad(out.len())),
            }
        }
        if end == rest.len() {
            break;
        }
        rest = &rest[end + 1..];
    }
    if out.len() < ncol {
        return Err(RowError::Short(out.len()));
    }
    Ok(())
}

/// Like [`numeric_row`] but an empty cell (or `NaN`) gives `NaN` and the row may end early:
/// returns the number of cells present (at most `ncol`). `±inf` and text are errors.
#[inline]
pub(crate) fn sparse_row(
    line: &[u8],
    delim: u8,
    ncol: usize,
    out: &mut Vec<f64>,
) -> Result<usize, RowError> {
    out.clear();
    let mut rest = line;
    loop {
        let end = memchr::memchr(delim, rest).unwrap_or(rest.len());
        let t = trim_spaces(&rest[..end]);
        if out.len() == ncol {
            if !t.is_empty() {
                return Err(RowError::Long);
            }
        } else if t.is_empty() {
            out.push(f64::NAN);
        } else {
            match fast_float2::parse_partial::<f64, _>(t) {
                Ok((v, n)) if n == t.len() && !v.is_infinite() => out.push(v),
                _ => return Err(RowError::Bad(out.len())),
            }
        }
        if end == rest.len() {
            break;
        }
        rest = &rest[end + 1..];
    }
    Ok(out.len())
}

/// Why [`numeric_row`] failed.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum RowError {
    /// The cell in this column is not a finite number.
    Bad(usize),
    /// The cell in this column is empty.
    Empty(usize),
    /// Only this many cells.
    Short(usize),
    /// Non-empty cells beyond the last column.
    Long,
}

impl RowError {
    /// The error for row `row` of `path`, with column names `names`.
    pub(crate) fn into_ingest(
        self,
        path: &Path,
        row: usize,
        line: &[u8],
        delim: u8,
        names: &[String],
    ) -> IngestError {
        let name = |i: usize| {
            names
                .get(i)
                .cloned()
                .unwrap_or_else(|| format!("column {}", i + 1))
        };
        match self {
            RowError::Bad(i) => {
                let cell = cells(line, delim).nth(i).map(text).unwrap_or_default();
                IngestError::cell(
                    path,
                    row,
                    name(i),
                    format!("{cell:?} is not a finite number"),
                )
            }
            RowError::Empty(i) => {
                IngestError::cell(path, row, name(i), "empty cell: give a number")
            }
            RowError::Short(n) => IngestError::cell(
                path,
                row,
                name(n),
                format!(
                    "row has {n} of {} columns: the file is truncated or corrupt",
                    names.len()
                ),
            ),
            RowError::Long => IngestError::cell(
                path,
                row,
                format!("column {}", names.len() + 1),
                format!("more cells than the {} column names", names.len()),
            ),
        }
    }
}

#[inline]
fn trim_spaces(cell: &[u8]) -> &[u8] {
    let mut s = cell;
    while let [b' ' | b'\t' | b'\r', rest @ ..] = s {
        s = rest;
    }
    while let [rest @ .., b' ' | b'\t' | b'\r'] = s {
        s = rest;
    }
    s
}

/// Parses a finite number or explains why not, as an [`IngestError::Cell`].
pub(crate) fn finite(
    cell: &[u8],
    path: &Path,
    row: usize,
    column: &str,
) -> Result<f64, IngestError> {
    match num(cell) {
        Num::Value(v) if v.is_finite() => Ok(v),
        Num::Value(v) => Err(IngestError::cell(
            path,
            row,
            column,
            format!("{v} is not allowed here: give a finite number"),
        )),
        Num::Empty => Err(IngestError::cell(
            path,
            row,
            column,
            "empty cell: give a number",
        )),
        Num::Bad => Err(IngestError::cell(
            path,
            row,
            column,
            format!("{:?} is not a number", text(cell)),
        )),
    }
}

/// Checks that `time` is strictly increasing and finite; names the first offending row.
/// `rows[i]` is the file line (or sample number) of `time[i]`.
pub(crate) fn check_time(
    time: &[f64],
    rows: &[usize],
    path: &Path,
    column: &str,
) -> Result<(), IngestError> {
    for i in 1..time.len() {
        if time[i] <= time[i - 1] || time[i].is_nan() {
            return Err(IngestError::cell(
                path,
                rows.get(i).copied().unwrap_or(i + 1),
                column,
                format!(
                    "time {} s does not increase (previous row: {} s): sort the rows or remove \
                     duplicates",
                    time[i],
                    time[i - 1]
                ),
            ));
        }
    }
    Ok(())
}

/// The sampling rate implied by a time column: (n − 1)/(t_last − t_first), snapped to a whole or
/// to a hundredth of a hertz when within 0.01 % of it (time columns are rounded in the files).
pub(crate) fn rate_from_time(time: &[f64]) -> Option<f64> {
    if time.len() < 2 {
        return None;
    }
    let span = time[time.len() - 1] - time[0];
    if span <= 0.0 || !span.is_finite() {
        return None;
    }
    let r = (time.len() - 1) as f64 / span;
    Some(snap_rate(r))
}

/// Snaps a rate to a whole number of hertz (or to 0.01 Hz) when within 0.01 % of it.
pub(crate) fn snap_rate(r: f64) -> f64 {
    let whole = r.round();
    if whole > 0.0 && ((r - whole) / whole).abs() < 1e-4 {
        return whole;
    }
    let centi = (r * 100.0).round() / 100.0;
    if ((r - centi) / r).abs() < 1e-4 {
        centi
    } else {
        r
    }
}

/// The largest deviation of `time` from a uniform grid `time[0] + i/rate`, s.
pub(crate) fn max_jitter(time: &[f64], rate: f64) -> f64 {
    time.iter()
        .enumerate()
        .map(|(i, t)| (t - (time[0] + i as f64 / rate)).abs())
        .fold(0.0, f64::max)
}

/// Length unit → metres per unit, from a unit string found in a file (`mm`, `cm`, `m`, …).
pub(crate) fn length_scale(unit: &str) -> Option<f64> {
    match unit.trim().to_ascii_lowercase().as_str() {
        "mm" | "millimeter" | "millimeters" | "millimetre" | "millimetres" => Some(1e-3),
        "cm" | "centimeter" | "centimeters" | "centimetre" | "centimetres" => Some(1e-2),
        "m" | "meter" | "meters" | "metre" | "metres" => Some(1.0),
        "dm" => Some(0.1),
        "in" | "inch" | "inches" => Some(0.0254),
        _ => None,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn lines_strip_cr_and_keep_numbers() {
        let b = b"a\r\nb\n\nc";
        let v: Vec<_> = lines(b).collect();
        assert_eq!(
            v,
            vec![
                (1, &b"a"[..]),
                (2, &b"b"[..]),
                (3, &b""[..]),
                (4, &b"c"[..])
            ]
        );
        assert_eq!(lines(b"").count(), 0);
        assert_eq!(lines(b"x\n").count(), 1);
    }

    #[test]
    fn numbers() {
        assert_eq!(num(b"  1.5 "), Num::Value(1.5));
        assert_eq!(num(b"-0.00"), Num::Value(-0.0));
        assert_eq!(num(b"9.45E-02"), Num::Value(0.0945));
        assert_eq!(num(b""), Num::Empty);
        assert_eq!(num(b"   "), Num::Empty);
        assert_eq!(num(b"abc"), Num::Bad);
        assert!(matches!(num(b"NaN"), Num::Value(v) if v.is_nan()));
        assert!(finite(b"inf", Path::new("f"), 3, "c").is_err());
    }

    #[test]
    fn rates_snap() {
        let t: Vec<f64> = (0..100)
            .map(|i| (i as f64 / 960.0 * 1e6).round() / 1e6)
            .collect();
        assert_eq!(rate_from_time(&t), Some(960.0));
        assert_eq!(snap_rate(69.9001), 69.9);
        assert_eq!(trim(b" 'RIGHT HIP' "), b"RIGHT HIP");
        assert_eq!(length_scale(" mm"), Some(1e-3));
        assert_eq!(length_scale("furlong"), None);
    }
}
