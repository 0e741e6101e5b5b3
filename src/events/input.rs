//! Which measured files make a trial: files, folders (searched recursively) and explicit pairs
//! `MARKERS+FORCES` (`motion_capture_run.trc+grf_run.mot`) for force files whose name does not
//! follow the `X.trc` / `X.forces` / `X_grf.mot` companion convention of the readers.
use super::{EventError, EventOptions, StepTable};
use crate::ingest::{read_trial, types::Trial, ReadOptions};
use std::path::{Path, PathBuf};

/// One trial to read: a file, or markers plus a separate force file.
#[derive(Debug, Clone, PartialEq, Eq, PartialOrd, Ord)]
pub struct TrialInput {
    /// The main file.
    pub path: PathBuf,
    /// A force file to attach to it (`.mot`/`.sto` GRF or `.forces`).
    pub forces: Option<PathBuf>,
}

impl TrialInput {
    /// A label for messages (`a.trc+b.mot`).
    pub fn label(&self) -> String {
        match &self.forces {
            Some(f) => format!("{}+{}", self.path.display(), f.display()),
            None => self.path.display().to_string(),
        }
    }
}

fn ext(p: &Path) -> String {
    p.extension()
        .map(|e| e.to_string_lossy().to_ascii_lowercase())
        .unwrap_or_default()
}

/// Whether a file found in a folder is a gait trial gaitfit should read: `.trc`, `.c3d`,
/// `.forces`, GRF `.mot` (`*grf*.mot`), WBDS `*grf.txt`, Winter's table. Skipped: static
/// trials (`*static*`, `*_ST.c3d`), companions of a TRC beside them (`X.forces`, `X_grf.mot`),
/// joint-angle MOT files, metadata (`WBDSinfo.csv`, READMEs, licences).
fn is_trial_file(p: &Path) -> bool {
    let name = p
        .file_name()
        .map(|n| n.to_string_lossy().to_string())
        .unwrap_or_default();
    let lower = name.to_ascii_lowercase();
    let stem = p
        .file_stem()
        .map(|n| n.to_string_lossy().to_string())
        .unwrap_or_default();
    if lower.contains("static") || lower.ends_with("_st.c3d") || lower.starts_with('.') {
        return false;
    }
    let sibling_trc = |s: &str| p.with_file_name(format!("{s}.trc")).is_file();
    match ext(p).as_str() {
        "trc" | "c3d" => true,
        "forces" => !sibling_trc(&stem),
        "mot" | "sto" => {
            lower.contains("grf") && !stem.strip_suffix("_grf").is_some_and(sibling_trc)
        }
        "txt" => lower.ends_with("grf.txt") || lower.starts_with("wintertable"),
        _ => false,
    }
}

fn walk(dir: &Path, out: &mut Vec<PathBuf>) -> Result<(), EventError> {
    let rd = std::fs::read_dir(dir).map_err(|e| crate::fsio::FsError::io(dir, e))?;
    let mut entries: Vec<PathBuf> = rd.filter_map(|e| e.ok().map(|e| e.path())).collect();
    entries.sort();
    for p in entries {
        if p.is_dir() {
            walk(&p, out)?;
        } else if is_trial_file(&p) {
            out.push(p);
        }
    }
    Ok(())
}

/// Expands command-line inputs: folders into their trial files (sorted), `A+B` into a pair.
pub fn expand_inputs(inputs: &[PathBuf]) -> Result<Vec<TrialInput>, EventError> {
    let mut out = Vec::new();
    for p in inputs {
        let s = p.to_string_lossy();
        if let Some((a, b)) = s.split_once('+').filter(|_| !p.exists()) {
            out.push(TrialInput {
                path: PathBuf::from(a),
                forces: Some(PathBuf::from(b)),
            });
        } else if p.is_dir() {
            let mut files = Vec::new();
            walk(p, &mut files)?;
            if files.is_empty() {
                return Err(EventError::Missing {
                    path: p.display().to_string(),
                    what: "gait trial files (.trc, .c3d, .forces, *grf.mot, *grf.txt) in this \
                           folder"
                        .into(),
                });
            }
            out.extend(
                files
                    .into_iter()
                    .map(|path| TrialInput { path, forces: None }),
            );
        } else if p.is_file() {
            out.push(TrialInput {
                path: p.clone(),
                forces: None,
            });
        } else {
            return Err(EventError::Missing {
                path: p.display().to_string(),
                what: "this file or folder (it does not exist)".into(),
            });
        }
    }
    Ok(out)
}

/// Reads one input: the main file with the readers' companions, plus the explicit force file.
pub fn read_input(input: &TrialInput, read: &ReadOptions) -> Result<Trial, EventError> {
    let mut trial = read_trial(&input.path, read)?;
    if let Some(f) = &input.forces {
        let (plates, notes) = match ext(f).as_str() {
            "forces" => crate::ingest::forces::read_plates(f, read)?,
            _ => crate::ingest::mot::read_plates(f, read)?,
        };
        trial.notes.extend(notes);
        trial
            .notes
            .push(format!("force plates from {}", f.display()));
        trial.plates = plates;
    }
    Ok(trial)
}

/// Reads `input` and builds its per-step table: what `gaitfit fit` calls on raw files.
pub fn steps_from_input(
    input: &TrialInput,
    read: &ReadOptions,
    opts: &EventOptions,
) -> Result<StepTable, EventError> {
    let trial = read_input(input, read)?;
    super::steps_from_trial(&trial, opts)
}

/// [`steps_from_input`] for a single path (a file, or `A+B`).
pub fn steps_from_path(
    path: &Path,
    read: &ReadOptions,
    opts: &EventOptions,
) -> Result<StepTable, EventError> {
    let inputs = expand_inputs(&[path.to_path_buf()])?;
    let mut table = StepTable::default();
    for i in &inputs {
        let t = steps_from_input(i, read, opts)?;
        table.rows.extend(t.rows);
        table.extra.extend(t.extra);
        table.notes.extend(t.notes);
    }
    Ok(table)
}

/// The raw-file hook of `gaitfit fit` ([`crate::fit::pipeline::RawStepReader`]): reads a
/// measured file, a folder of them or an `A+B` pair with the default reading and event
/// options (metadata such as belt speed and body height from the files themselves) and returns
/// its per-step rows.
pub fn raw_step_rows(path: &Path) -> crate::Result<Vec<crate::ingest::trials::StepRow>> {
    let table = steps_from_path(path, &ReadOptions::default(), &EventOptions::default())?;
    Ok(table.rows)
}

/// Whether `path` is a measured file for the events layer rather than a trials table: anything
/// but `.csv`, and a `.csv` whose header (first line not starting with `#`) has neither a
/// `subject` nor a `gait` column — gaitfit's per-frame CSV ([`crate::ingest::frame_csv`]); a
/// trials table needs both columns, so no trials table is mistaken for a raw file.
pub fn is_raw_input(path: &Path) -> bool {
    if path.is_dir() || ext(path) != "csv" {
        return true;
    }
    use std::io::BufRead;
    // Unreadable: let the trials reader report it with its own message.
    let Ok(file) = std::fs::File::open(path) else {
        return false;
    };
    let Some(header) = std::io::BufReader::new(file)
        .lines()
        .map_while(Result::ok)
        .map(|l| l.trim_start_matches('\u{feff}').trim().to_string())
        .find(|l| !l.is_empty() && !l.starts_with('#'))
    else {
        return false;
    };
    let cols: Vec<String> = header
        .split(',')
        .map(|c| c.trim().trim_matches('"').to_ascii_lowercase())
        .collect();
    !cols.iter().any(|c| c == "subject" || c == "gait")
}
