//! From tables to observations: loading trials tables (and raw measured files through the
//! events layer) and reducing their rows to the observations a relation uses, every rejected
//! row recorded by reason.
use crate::fit::record::{DataFile, RejectionRecord};
use crate::ingest::trials::TrialsTable;
use crate::relations::{Observation, Relation};
use crate::units::parse_header;
use std::collections::BTreeMap;

/// Rows listed per rejection reason.
const MAX_EXAMPLES: usize = 10;

pub(super) fn weight_column<'a>(t: &'a TrialsTable, name: &str) -> Option<&'a [f64]> {
    if let Ok(Some(c)) = parse_header(name) {
        if let Some(col) = &t.columns[c.quantity as usize] {
            return Some(col);
        }
    }
    t.extra
        .iter()
        .find(|(n, _)| n.eq_ignore_ascii_case(name))
        .map(|(_, v)| v.as_slice())
}

/// The rows a relation can use, reduced to observations.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct Prepared {
    /// Observations (papers' units).
    pub obs: Vec<Observation>,
    /// Per observation: index into `subjects`.
    pub subject: Vec<usize>,
    /// Subjects among the used rows, in order of first appearance.
    pub subjects: Vec<String>,
    /// Per observation: index into `files`, the data set it came from (reports colour
    /// residuals by subject and data set, so treadmill and overground rows are not pooled).
    pub file: Vec<u32>,
    /// Per observation: weight (all 1 without `--weights`).
    pub weights: Vec<f64>,
    /// Rejections by reason.
    pub rejected: Vec<RejectionRecord>,
    /// Rows rejected.
    pub n_rejected: usize,
    /// Rows of the other gait.
    pub n_other_gait: usize,
    /// The files.
    pub files: Vec<DataFile>,
}

/// Reduces the tables' rows to the observations `rel` uses, recording every rejection.
pub fn prepare(rel: &dyn Relation, tables: &[TrialsTable], weights: Option<&str>) -> Prepared {
    let mut p = Prepared::default();
    let mut reasons: BTreeMap<String, (usize, Vec<String>)> = BTreeMap::new();
    let mut subj_index: BTreeMap<String, usize> = BTreeMap::new();
    let mut reject = |reason: String, file: &str, row: usize, p: &mut Prepared| {
        let e = reasons.entry(reason).or_insert((0, Vec::new()));
        e.0 += 1;
        if e.1.len() < MAX_EXAMPLES {
            e.1.push(format!("{file}: row {row}"));
        }
        p.n_rejected += 1;
    };
    p.obs.reserve(tables.iter().map(|t| t.len()).sum());
    for t in tables {
        let file = t.path.display().to_string();
        let file_index = p.files.len() as u32;
        p.files.push(DataFile {
            path: file.clone(),
            sha256: t.sha256.clone(),
            rows: t.len(),
        });
        let flags: BTreeMap<usize, &str> =
            t.flagged.iter().map(|(r, s)| (*r, s.as_str())).collect();
        let wcol = weights.and_then(|w| weight_column(t, w));
        let mut subj_of_table: Vec<Option<usize>> = vec![None; t.subjects.len()];
        for i in 0..t.len() {
            match t.gait[i] {
                Some(g) if g == rel.card().gait => {}
                Some(_) => {
                    p.n_other_gait += 1;
                    continue;
                }
                None => {
                    reject("gait missing".into(), &file, i + 1, &mut p);
                    continue;
                }
            }
            if t.is_flagged[i] {
                let why = flags
                    .get(&(i + 1))
                    .copied()
                    .unwrap_or("inconsistent values");
                let kind = if why.contains("speed") {
                    "flagged: speed, step length and step frequency disagree by more than 2 %"
                } else {
                    "flagged: inconsistent double-support values"
                };
                reject(kind.into(), &file, i + 1, &mut p);
                continue;
            }
            let w = match wcol {
                Some(c) => {
                    let w = c[i];
                    if !(w.is_finite() && w > 0.0) {
                        reject(
                            "weight missing or not positive".into(),
                            &file,
                            i + 1,
                            &mut p,
                        );
                        continue;
                    }
                    w
                }
                None => 1.0,
            };
            // A row gives one observation per output; it is rejected when none is usable.
            let row = t.values(i);
            let mut first_err = None;
            let mut used = false;
            for out in 0..rel.card().outputs.len() {
                match rel.observe(&row, out) {
                    Ok(o) => {
                        // The table's subject id → ours, looked up by name once per id (not
                        // once per row: a string map per row was a fifth of this function).
                        let ts = t.subject[i] as usize;
                        let k = match subj_of_table.get(ts).copied().flatten() {
                            Some(k) => k,
                            None => {
                                let name = t.subject_name(i);
                                let k = match subj_index.get(name) {
                                    Some(&k) => k,
                                    None => {
                                        let k = p.subjects.len();
                                        p.subjects.push(name.to_string());
                                        subj_index.insert(name.to_string(), k);
                                        k
                                    }
                                };
                                if let Some(slot) = subj_of_table.get_mut(ts) {
                                    *slot = Some(k);
                                }
                                k
                            }
                        };
                        p.obs.push(o);
                        p.subject.push(k);
                        p.file.push(file_index);
                        p.weights.push(w);
                        used = true;
                    }
                    Err(r) => {
                        first_err.get_or_insert(r);
                    }
                }
            }
            if let (false, Some(r)) = (used, first_err) {
                reject(r.to_string(), &file, i + 1, &mut p);
            }
        }
    }
    p.rejected = reasons
        .into_iter()
        .map(|(reason, (count, examples))| RejectionRecord {
            reason,
            count,
            examples,
        })
        .collect();
    p
}

/// Reads raw measured files (C3D, TRC + forces, treadmill GRF, …) into per-step rows: the hook
/// through which the events layer feeds `gaitfit fit` (pass it to [`load_tables`]).
pub type RawStepReader = fn(&std::path::Path) -> crate::Result<Vec<crate::ingest::trials::StepRow>>;

/// Whether `path` names a trials table (`.csv`) rather than a raw measured file.
pub fn is_trials_table(path: &std::path::Path) -> bool {
    path.extension()
        .is_some_and(|e| e.eq_ignore_ascii_case("csv"))
}

/// Loads trials tables (`.csv`) and, through `raw`, raw measured files.
pub fn load_tables(
    paths: &[std::path::PathBuf],
    raw: Option<RawStepReader>,
) -> crate::Result<Vec<TrialsTable>> {
    let mut out = Vec::with_capacity(paths.len());
    for p in paths {
        if is_trials_table(p) {
            out.push(crate::ingest::trials::read_trials(p)?);
        } else if let Some(raw) = raw {
            let rows = raw(p)?;
            let mut t = TrialsTable::from_step_rows(p, &rows);
            if let Ok(bytes) = std::fs::read(p) {
                t.sha256 = crate::ingest::trials::sha256_hex(&bytes);
            }
            out.push(t);
        } else {
            return Err(crate::ingest::IngestError::malformed(
                p,
                "not a trials table (.csv); raw measured files need the events layer: \
                 derive per-step rows with `gaitfit events` and pass the resulting CSV",
            )
            .into());
        }
    }
    Ok(out)
}
