//! Readers: trial tables (CSV with unit-suffixed headers) and raw measured data (TRC, MOT/STO,
//! Cortex `.forces`, instrumented-treadmill GRF text, C3D, Winter's rotoscope table, a generic
//! per-frame CSV) → the typed in-memory tables of [`types`] and [`trials`], in SI units.
//!
//! Entry point: [`read_trial`] picks the reader from the file's extension (and, for `.txt` and
//! `.csv`, its first line), reads companion files beside it when [`ReadOptions::companions`] is
//! set, fills short marker gaps ([`gaps`]) and establishes the laboratory frame
//! ([`frame_detect`]). Every reader converts to SI once, from the units its file declares, and
//! records what it assumed in [`Trial::notes`].
pub mod c3d;
pub mod forces;
pub mod frame_csv;
pub mod frame_detect;
pub mod gaps;
pub mod hamner;
pub mod mot;
pub(crate) mod text;
pub mod trc;
pub mod treadmill;
pub mod trials;
pub mod types;
pub mod winter;

use crate::gait::Gait;
use std::path::{Path, PathBuf};
use thiserror::Error;
use types::{Axis, Setting, Trial};

/// Errors of the ingest layer. Every variant names the file and, where it applies, the row (or
/// frame) and the column (or channel/marker), and says what would fix it.
#[derive(Debug, Error)]
#[non_exhaustive]
pub enum IngestError {
    /// The file could not be opened or read.
    #[error("{path}: {source}")]
    Io {
        /// The file.
        path: PathBuf,
        /// The underlying error.
        source: std::io::Error,
    },
    /// The file's structure is wrong (bad header, truncated, wrong count, …).
    #[error("{path}: {message}")]
    Malformed {
        /// The file.
        path: PathBuf,
        /// What is wrong, including the line/frame where it was seen.
        message: String,
    },
    /// A cell could not be used.
    #[error("{path}: row {row}, column {column}: {message}")]
    Cell {
        /// The file.
        path: PathBuf,
        /// 1-based data row (the header is row 0) or frame number.
        row: usize,
        /// Column header, channel or marker name.
        column: String,
        /// What is wrong and how to fix it.
        message: String,
    },
    /// A required column is missing.
    #[error("{path}: missing column {column}: {message}")]
    MissingColumn {
        /// The file.
        path: PathBuf,
        /// The column (or one of the accepted spellings).
        column: String,
        /// What it is needed for, and the accepted unit suffixes.
        message: String,
    },
    /// A unit suffix gaitfit does not know.
    #[error("{path}: column {column}: unknown unit suffix; {message}")]
    UnknownUnit {
        /// The file.
        path: PathBuf,
        /// The offending header.
        column: String,
        /// The accepted spellings.
        message: String,
    },
    /// Writing a table failed (the destination is left untouched).
    #[error(transparent)]
    Write(#[from] crate::fsio::FsError),
}

impl IngestError {
    /// Wraps an I/O error with the file it concerns.
    pub fn io(path: impl Into<PathBuf>, source: std::io::Error) -> Self {
        IngestError::Io {
            path: path.into(),
            source,
        }
    }
    /// A structural error in `path`.
    pub fn malformed(path: impl Into<PathBuf>, message: impl Into<String>) -> Self {
        IngestError::Malformed {
            path: path.into(),
            message: message.into(),
        }
    }
    /// An error in one cell.
    pub fn cell(
        path: impl Into<PathBuf>,
        row: usize,
        column: impl Into<String>,
        message: impl Into<String>,
    ) -> Self {
        IngestError::Cell {
            path: path.into(),
            row,
            column: column.into(),
            message: message.into(),
        }
    }
}

/// Options shared by every reader.
#[derive(Debug, Clone, PartialEq)]
pub struct ReadOptions {
    /// The vertical axis (positive up), when the user knows it; otherwise detected.
    pub vertical: Option<Axis>,
    /// The walking direction (axis and sign, +1 or −1), when the user knows it; otherwise
    /// detected.
    pub forward: Option<(Axis, f64)>,
    /// How short marker gaps are filled (default: cubic, gaps ≤ 0.1 s).
    pub gap_fill: gaps::GapFill,
    /// Also read the companion files the reader knows about (default true): `X.forces` or
    /// `X_grf.mot` beside `X.trc`; `WBDSinfo.csv` beside a WBDS GRF file; the Hamner data set's
    /// `static.trc` and `README.md` (leg length, mass).
    pub companions: bool,
    /// Walk or run, when known (overrides what the reader infers).
    pub gait: Option<Gait>,
    /// Treadmill belt speed, m/s, when known (overrides the file name / metadata).
    pub belt_speed_m_per_s: Option<f64>,
    /// Centre of pressure is reported only while the vertical force exceeds this, N (default
    /// 20 N); below it the plate is unloaded and the COP is `NaN`.
    pub cop_min_force_n: f64,
    /// Sampling rate of force files that do not state one (WBDS GRF text, whose `Time` column
    /// holds sample numbers); `None` → the data set's documented rate (300 Hz for WBDS).
    pub grf_rate_hz: Option<f64>,
}

impl Default for ReadOptions {
    fn default() -> Self {
        ReadOptions {
            vertical: None,
            forward: None,
            gap_fill: gaps::GapFill::default(),
            companions: true,
            gait: None,
            belt_speed_m_per_s: None,
            cop_min_force_n: 20.0,
            grf_rate_hz: None,
        }
    }
}

/// The file formats [`read_trial`] knows.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[non_exhaustive]
pub enum Format {
    /// OpenSim / Cortex TRC markers.
    Trc,
    /// OpenSim MOT or STO table (GRF, joint angles).
    Mot,
    /// Cortex `.forces` force-plate export.
    Forces,
    /// Tab-separated instrumented-treadmill GRF (WBDS `*grf.txt`).
    TreadmillGrf,
    /// C3D.
    C3d,
    /// Winter's rotoscope table (Table A.1, `wn35b.txt`).
    Winter,
    /// gaitfit's documented per-frame CSV.
    FrameCsv,
}

/// Which reader `path` needs, from its extension and, for `.txt`/`.csv`, its first line.
pub fn detect_format(path: &Path) -> Result<Format, IngestError> {
    let ext = path
        .extension()
        .map(|e| e.to_string_lossy().to_ascii_lowercase())
        .unwrap_or_default();
    match ext.as_str() {
        "trc" => return Ok(Format::Trc),
        "mot" | "sto" => return Ok(Format::Mot),
        "forces" => return Ok(Format::Forces),
        "c3d" => return Ok(Format::C3d),
        _ => {}
    }
    let first = first_line(path)?;
    let f = first.trim_start_matches('\u{feff}');
    if ext == "txt" || ext == "csv" || ext == "tsv" {
        if f.starts_with("'FRAME'") || f.starts_with("wn") || winter::looks_like_winter(f) {
            return Ok(Format::Winter);
        }
        if f.starts_with("Time\t") && f.contains("Fy1") && f.contains("COPx1") {
            return Ok(Format::TreadmillGrf);
        }
        if f.starts_with("[Force Data]") {
            return Ok(Format::Forces);
        }
        if f.starts_with("PathFileType") {
            return Ok(Format::Trc);
        }
        if f.contains("endheader") || f.starts_with("name ") {
            return Ok(Format::Mot);
        }
        if ext == "csv" {
            return Ok(Format::FrameCsv);
        }
    }
    Err(IngestError::malformed(
        path,
        format!(
            "unknown file format (extension {ext:?}, first line {:?}): gaitfit reads .trc, \
             .mot/.sto, .forces, .c3d, WBDS *grf.txt, Winter's table (.txt) and the per-frame \
             .csv documented in ingest::frame_csv",
            f.chars().take(60).collect::<String>()
        ),
    ))
}

fn first_line(path: &Path) -> Result<String, IngestError> {
    use std::io::Read;
    let mut buf = vec![0u8; 4096];
    let mut f = std::fs::File::open(path).map_err(|e| IngestError::io(path, e))?;
    let n = f.read(&mut buf).map_err(|e| IngestError::io(path, e))?;
    buf.truncate(n);
    let line = buf.split(|&b| b == b'\n').next().unwrap_or(&[]);
    Ok(String::from_utf8_lossy(line)
        .trim_end_matches('\r')
        .to_string())
}

/// Reads one trial, choosing the reader by [`detect_format`]. Companion files are merged when
/// [`ReadOptions::companions`] is set (see there). The returned trial has its markers'
/// short gaps filled, its frame detected (or set by `opts`), and notes saying what was assumed.
pub fn read_trial(path: &Path, opts: &ReadOptions) -> Result<Trial, IngestError> {
    match detect_format(path)? {
        Format::Trc => trc::read(path, opts),
        Format::Mot => mot::read(path, opts),
        Format::Forces => forces::read(path, opts),
        Format::Winter => winter::read(path, opts),
        Format::TreadmillGrf => treadmill::read(path, opts),
        Format::C3d => c3d::read(path, opts),
        Format::FrameCsv => frame_csv::read(path, opts),
    }
}

/// The last step of every reader: fills short marker gaps, reports them, detects the frame
/// (markers by name first, then force plates, then the format's declared vertical `declared`,
/// then marker spread), and infers an overground setting from a travelling pelvis.
pub(crate) fn finish(
    trial: &mut Trial,
    opts: &ReadOptions,
    declared: Option<frame_detect::Direction>,
) {
    use frame_detect as fd;
    if let Some(m) = trial.markers.as_mut() {
        let reports = gaps::fill_gaps(m, &opts.gap_fill);
        let rate = m.rate_hz;
        trial
            .notes
            .extend(gaps::notes(&reports, &opts.gap_fill, rate));
    }
    if let Some(g) = opts.gait {
        trial.gait = Some(g);
    }
    let from_markers = trial.markers.as_ref().and_then(fd::vertical_from_markers);
    let from_plates = fd::vertical_from_plates(&trial.plates);
    if let (Some(a), Some(b)) = (&from_markers, &from_plates) {
        if (a.axis, a.sign) != (b.axis, b.sign) {
            trial.notes.push(format!(
                "warning: markers and force plates disagree on the vertical ({} / {})",
                a.how, b.how
            ));
        }
    }
    let vertical = from_markers
        .or(from_plates)
        .or(declared)
        .or_else(|| trial.markers.as_ref().and_then(fd::vertical_from_spread));
    let markers = trial.markers.as_ref();
    let plates = &trial.plates;
    let frame = fd::combine(opts.vertical, opts.forward, vertical, |v| {
        markers
            .and_then(|m| fd::forward_from_markers(m, v.axis))
            .or_else(|| fd::forward_from_plates(plates, v))
    });
    match frame {
        Ok(f) => {
            trial.notes.push(format!("frame: {}", f.how));
            trial.frame = Some(f);
        }
        Err(why) => trial.notes.push(format!("frame: {why}")),
    }
    if trial.setting == Setting::Unknown {
        if let (Some(m), Some(f)) = (trial.markers.as_ref(), trial.frame.as_ref()) {
            if let Some(d) = pelvis_travel(m, f.forward) {
                if d > 1.0 {
                    trial.setting = Setting::Overground;
                    trial.notes.push(format!(
                        "setting: overground (the pelvis travels {d:.2} m along the walking \
                         direction)"
                    ));
                }
            }
        }
    }
    if let Some(v) = opts.belt_speed_m_per_s {
        trial.setting = Setting::Treadmill {
            belt_speed_m_per_s: v,
        };
        trial
            .notes
            .push(format!("setting: treadmill at {v} m/s (set by the user)"));
    }
}

/// Distance the pelvis markers' centroid travels along `axis` between the first and last frames.
fn pelvis_travel(m: &types::MarkerSet, axis: Axis) -> Option<f64> {
    let k = axis.index();
    let at = |f: usize| -> Option<f64> {
        let v: Vec<f64> = m
            .names
            .iter()
            .zip(&m.positions)
            .filter(|(n, _)| frame_detect::is_pelvis_marker(n))
            .map(|(_, t)| t[f][k])
            .filter(|v| v.is_finite())
            .collect();
        (!v.is_empty()).then(|| v.iter().sum::<f64>() / v.len() as f64)
    };
    let n = m.len();
    let a = (0..n).find_map(at)?;
    let b = (0..n).rev().find_map(at)?;
    Some((b - a).abs())
}
