//! The trials table as a CSV file: [`read_trials`] / [`parse_trials`] (streamed, hashed,
//! validated cell by cell; see [`super`]) and [`write_trials`].
use super::{Builder, FieldValues, StepRow, TrialsTable, CANONICAL_COLUMNS, N_QUANTITIES};
use crate::gait::{Gait, Side};
use crate::ingest::IngestError;
use crate::units::{parse_header, Column};
use std::collections::HashMap;
use std::path::Path;

/// Hex SHA-256 of `bytes`.
pub fn sha256_hex(bytes: &[u8]) -> String {
    use sha2::{Digest, Sha256};
    hex(&Sha256::digest(bytes))
}

/// Lower-case hex of a digest.
fn hex(d: &[u8]) -> String {
    let mut s = String::with_capacity(2 * d.len());
    for b in d {
        s.push_str(&format!("{b:02x}"));
    }
    s
}

/// Reads and validates a trials CSV file (see the module docs and `data/README.md`).
///
/// Errors name the file, the 1-based data row and the column, and say what would fix the input.
pub fn read_trials(path: &Path) -> Result<TrialsTable, IngestError> {
    use std::io::Read;
    // Streamed in blocks that are hashed and parsed while in cache: no buffer of the whole
    // file (on a large table its page faults alone cost as much as the hashing).
    let mut file = std::fs::File::open(path).map_err(|e| IngestError::io(path, e))?;
    let len = file.metadata().map_or(0, |m| m.len()) as usize;
    let mut head = Vec::with_capacity(FIRST_BLOCK.min(len + 1));
    (&mut file)
        .take(FIRST_BLOCK as u64)
        .read_to_end(&mut head)
        .map_err(|e| IngestError::io(path, e))?;
    // Rows to reserve: the whole file's line count when it fits the first block, else the first
    // block's lines scaled to the file's length (a hint: columns still grow past it).
    let lines = memchr::memchr_iter(b'\n', &head).count();
    let rows = if head.len() < FIRST_BLOCK {
        lines
    } else {
        (lines as f64 * (len.max(head.len()) as f64 / head.len() as f64) * 1.02) as usize + 16
    };
    parse_from(path, std::io::Cursor::new(head).chain(file), rows)
}

/// The first block [`read_trials`] reads, to size the columns.
pub(super) const FIRST_BLOCK: usize = 1 << 16;

/// A reader that hashes what passes through it.
struct Hashing<R> {
    inner: R,
    hasher: sha2::Sha256,
}

impl<R: std::io::Read> std::io::Read for Hashing<R> {
    fn read(&mut self, buf: &mut [u8]) -> std::io::Result<usize> {
        use sha2::Digest;
        let n = self.inner.read(buf)?;
        self.hasher.update(&buf[..n]);
        Ok(n)
    }
}

#[derive(Clone, Copy)]
enum Role {
    Subject,
    Gait,
    Side,
    Source,
    Trial,
    Numeric(Column),
    Ignored,
}

/// Parses trials CSV content; `path` is used for messages and provenance.
pub fn parse_trials(path: &Path, bytes: &[u8]) -> Result<TrialsTable, IngestError> {
    parse_from(path, bytes, memchr::memchr_iter(b'\n', bytes).count())
}

/// Parses trials CSV from `input` (hashed as it is read), with room for `rows` rows.
fn parse_from(
    path: &Path,
    input: impl std::io::Read,
    rows: usize,
) -> Result<TrialsTable, IngestError> {
    use sha2::Digest;
    let mut rdr = csv::ReaderBuilder::new()
        .has_headers(true)
        .flexible(false)
        .trim(csv::Trim::None)
        .buffer_capacity(1 << 18)
        .from_reader(Hashing {
            inner: input,
            hasher: sha2::Sha256::new(),
        });
    let headers = rdr
        .byte_headers()
        .map_err(|e| IngestError::malformed(path, format!("cannot read the header line: {e}")))?
        .clone();
    if headers.is_empty() || (headers.len() == 1 && headers[0].is_empty()) {
        return Err(IngestError::malformed(
            path,
            "empty file: expected a header line such as `subject,gait,speed_m_per_s,...`",
        ));
    }
    let mut roles = Vec::with_capacity(headers.len());
    let mut seen: HashMap<String, String> = HashMap::new();
    let mut ignored = Vec::new();
    for h in headers.iter() {
        let name = std::str::from_utf8(h)
            .map_err(|_| IngestError::malformed(path, "header line is not valid UTF-8"))?
            .trim()
            .to_string();
        let role = match name.to_ascii_lowercase().as_str() {
            "subject" => Role::Subject,
            "gait" => Role::Gait,
            "side" => Role::Side,
            "source" => Role::Source,
            "trial" => Role::Trial,
            _ => match parse_header(&name) {
                Ok(Some(c)) => Role::Numeric(c),
                Ok(None) => {
                    ignored.push(name.clone());
                    Role::Ignored
                }
                Err(u) => {
                    return Err(IngestError::UnknownUnit {
                        path: path.to_path_buf(),
                        column: name,
                        message: format!(
                            "`{}` is not a unit gaitfit knows for {}; accepted: {}",
                            u.suffix,
                            u.quantity.stem(),
                            u.accepted()
                        ),
                    })
                }
            },
        };
        roles.push(role);
        let key = match role {
            Role::Numeric(c) => c.quantity.stem().to_string(),
            Role::Ignored => continue,
            _ => name.to_ascii_lowercase(),
        };
        if let Some(prev) = seen.insert(key.clone(), name.clone()) {
            return Err(IngestError::malformed(
                path,
                format!("columns `{prev}` and `{name}` both give {key}: keep one"),
            ));
        }
    }
    for required in ["subject", "gait"] {
        if !seen.contains_key(required) {
            return Err(IngestError::MissingColumn {
                path: path.to_path_buf(),
                column: required.to_string(),
                message: format!(
                    "every trials table needs `subject` and `gait` (walk|run); found columns: {}",
                    headers
                        .iter()
                        .map(|h| String::from_utf8_lossy(h).into_owned())
                        .collect::<Vec<_>>()
                        .join(", ")
                ),
            });
        }
    }
    let mut present = [false; N_QUANTITIES];
    for r in &roles {
        if let Role::Numeric(c) = r {
            present[c.quantity as usize] = true;
        }
    }
    let mut b = Builder::default();
    // One line per row: sizing the columns once saves their regrowth on large tables.
    b.reserve(rows, &present);
    let present_idx: Vec<usize> = (0..N_QUANTITIES).filter(|&q| present[q]).collect();
    let extra_idx: Vec<usize> = (0..roles.len())
        .filter(|&k| matches!(roles[k], Role::Ignored))
        .collect();
    let mut extra: Vec<Vec<f64>> = vec![Vec::new(); extra_idx.len()];
    let mut rec = csv::ByteRecord::new();
    let mut row = 0usize;
    loop {
        match rdr.read_byte_record(&mut rec) {
            Ok(true) => {}
            Ok(false) => break,
            Err(e) if e.is_io_error() => {
                // Reading the file failed (the table is streamed): an I/O error, not bad CSV.
                return Err(match e.into_kind() {
                    csv::ErrorKind::Io(io) => IngestError::io(path, io),
                    k => IngestError::malformed(path, format!("row {}: {k:?}", row + 1)),
                });
            }
            Err(e) => {
                let what = match e.kind() {
                    csv::ErrorKind::UnequalLengths {
                        expected_len, len, ..
                    } => format!(
                        "row {}: {len} fields where the header has {expected_len} \
                         (truncated or malformed line; every row needs one cell per column, \
                         empty cells are allowed)",
                        row + 1
                    ),
                    _ => format!("row {}: malformed CSV: {e}", row + 1),
                };
                return Err(IngestError::malformed(path, what));
            }
        }
        row += 1;
        let mut vals = FieldValues::default();
        let (mut subject, mut source, mut trial): (&[u8], &[u8], &[u8]) = (b"", b"", b"");
        let (mut gait, mut side) = (None, None);
        for (k, cell) in rec.iter().enumerate() {
            let cell = cell.trim_ascii();
            match roles[k] {
                Role::Subject => subject = cell,
                Role::Source => source = cell,
                Role::Trial => trial = cell,
                // The spellings gaitfit writes, without the allocation of the general parse.
                Role::Gait if cell == b"run" => gait = Some(Gait::Run),
                Role::Gait if cell == b"walk" => gait = Some(Gait::Walk),
                Role::Side if cell == b"left" => side = Some(Side::Left),
                Role::Side if cell == b"right" => side = Some(Side::Right),
                Role::Gait => {
                    if !cell.is_empty() {
                        let s = text(path, row, &headers[k], cell)?;
                        gait = Some(Gait::parse(s).ok_or_else(|| {
                            IngestError::cell(
                                path,
                                row,
                                "gait",
                                format!("`{s}` is not a gait: write walk or run"),
                            )
                        })?);
                    }
                }
                Role::Side => {
                    if !cell.is_empty() {
                        let s = text(path, row, &headers[k], cell)?;
                        side = Some(Side::parse(s).ok_or_else(|| {
                            IngestError::cell(
                                path,
                                row,
                                "side",
                                format!("`{s}` is not a side: write left or right (l/r)"),
                            )
                        })?);
                    }
                }
                Role::Numeric(c) => {
                    if !cell.is_empty() {
                        vals.0[c.quantity as usize] = number(path, row, &headers[k], c, cell)?;
                    }
                }
                Role::Ignored => {}
            }
        }
        for (e, &k) in extra.iter_mut().zip(&extra_idx) {
            let v = std::str::from_utf8(rec[k].trim_ascii())
                .ok()
                .and_then(|s| s.parse::<f64>().ok())
                .unwrap_or(f64::NAN);
            e.push(v);
        }
        if subject.is_empty() {
            return Err(IngestError::cell(
                path,
                row,
                "subject",
                "empty subject: every row needs a subject id (used for per-subject levels and \
                 leave-one-subject-out validation)",
            ));
        }
        let subject = std::str::from_utf8(subject)
            .map_err(|_| IngestError::cell(path, row, "subject", "not valid UTF-8"))?;
        b.push_parsed(
            subject,
            gait,
            side,
            &String::from_utf8_lossy(source),
            &String::from_utf8_lossy(trial),
            &vals,
            &present_idx,
        );
    }
    if row == 0 {
        return Err(IngestError::malformed(
            path,
            "no data rows after the header",
        ));
    }
    let sha = hex(&rdr.into_inner().hasher.finalize());
    let mut t = b.finish(path.to_path_buf(), sha, ignored.clone());
    t.extra = ignored.into_iter().zip(extra).collect();
    // Columns the file has but all of whose cells are empty are still "present".
    for (k, p) in present.iter().enumerate() {
        if *p && t.columns[k].is_none() {
            t.columns[k] = Some(vec![f64::NAN; t.len()]);
        }
    }
    t.complete();
    Ok(t)
}

fn text<'a>(
    path: &Path,
    row: usize,
    header: &[u8],
    cell: &'a [u8],
) -> Result<&'a str, IngestError> {
    std::str::from_utf8(cell).map_err(|_| {
        IngestError::cell(
            path,
            row,
            String::from_utf8_lossy(header),
            "not valid UTF-8",
        )
    })
}

fn number(
    path: &Path,
    row: usize,
    header: &[u8],
    c: Column,
    cell: &[u8],
) -> Result<f64, IngestError> {
    let col = || String::from_utf8_lossy(header).trim().to_string();
    // fast-float2 parses the bytes directly (no UTF-8 pass) and accepts what `str::parse`
    // does; the text is only needed for messages.
    let Ok(v) = fast_float2::parse::<f64, _>(cell) else {
        let s = std::str::from_utf8(cell)
            .map_err(|_| IngestError::cell(path, row, col(), "not valid UTF-8"))?;
        return Err(IngestError::cell(
            path,
            row,
            col(),
            format!("`{s}` is not a number (leave the cell empty when the value is missing)"),
        ));
    };
    if !v.is_finite() {
        let s = String::from_utf8_lossy(cell);
        return Err(IngestError::cell(
            path,
            row,
            col(),
            format!("`{s}` is not finite: leave the cell empty when the value is missing"),
        ));
    }
    let q = c.quantity;
    if v < 0.0 && !q.may_be_negative() {
        return Err(IngestError::cell(
            path,
            row,
            col(),
            format!(
                "{v} is negative; a {} cannot be",
                q.stem().replace('_', " ")
            ),
        ));
    }
    let si = c.to_si(v);
    let (lo, hi) = q.plausible_si();
    if si < lo || si > hi {
        let units = q.dimension().units();
        let hint = units
            .iter()
            .filter(|u| **u != c.unit)
            .find(|u| {
                let alt = v * u.to_si_factor();
                alt >= lo && alt <= hi && alt > 0.0
            })
            .map(|u| {
                format!(
                    "; probably the column is in {} (name it {}_{})",
                    u.suffix(),
                    q.stem(),
                    u.suffix()
                )
            })
            .unwrap_or_default();
        return Err(IngestError::cell(
            path,
            row,
            col(),
            format!(
                "{v} {} = {si} in SI is outside the plausible range [{lo}, {hi}] for {}{hint}",
                c.unit.suffix(),
                q.stem().replace('_', " ")
            ),
        ));
    }
    Ok(si)
}

/// Writes rows as a trials CSV with the [`CANONICAL_COLUMNS`] (SI headers; step frequency in
/// steps/min and angles in degrees, as the canonical headers say), atomically.
pub fn write_trials(path: &Path, rows: &[StepRow]) -> Result<(), IngestError> {
    use crate::fsio::FsError;
    crate::fsio::write_atomic(path, |w| {
        let mut wtr = csv::Writer::from_writer(w);
        let io = |e: csv::Error| FsError::io(path, std::io::Error::other(e.to_string()));
        wtr.write_record(CANONICAL_COLUMNS).map_err(io)?;
        let cols: Vec<Option<Column>> = CANONICAL_COLUMNS
            .iter()
            .map(|h| parse_header(h).ok().flatten())
            .collect();
        let mut rec: Vec<String> = Vec::with_capacity(CANONICAL_COLUMNS.len());
        for r in rows {
            rec.clear();
            for (h, c) in CANONICAL_COLUMNS.iter().zip(&cols) {
                rec.push(match (*h, c) {
                    ("subject", _) => r.subject.clone(),
                    ("gait", _) => r.gait.map(|g| g.to_string()).unwrap_or_default(),
                    ("side", _) => r.side.map(|s| s.to_string()).unwrap_or_default(),
                    ("source", _) => r.source.clone(),
                    ("trial", _) => r.trial.clone(),
                    (_, Some(c)) => r
                        .get(c.quantity)
                        .map(|v| format!("{}", c.from_si(v)))
                        .unwrap_or_default(),
                    _ => String::new(),
                });
            }
            wtr.write_record(&rec).map_err(io)?;
        }
        wtr.flush().map_err(|e| FsError::io(path, e))?;
        Ok::<(), IngestError>(())
    })
}
