//! The trials table: one row per trial or per step, the input of every fit.
//!
//! Values are held in SI units (m, m/s, s, steps/s, radians) once read; the CSV headers carry
//! their unit (`speed_m_per_s`, `step_freq_steps_per_min`, …) and are converted at the boundary
//! by [`crate::units`]. The schema is documented in `data/README.md`.
//!
//! Two in-memory forms:
//! - [`StepRow`]: one owned struct per row, convenient for code that builds rows (the events
//!   layer) or inspects them;
//! - [`TrialsTable`]: columnar, with interned subject names, what [`read_trials`] returns and the
//!   fit pipeline consumes (no allocation per row, so a million rows read in well under a second).
//!
//! Reading validates every cell (finite, non-negative, physically plausible in SI — a step length
//! of 80 under `_m` is an error suggesting `_cm`), completes the speed / step length / step
//! frequency triple from any two of them (v = sl·sf), derives the double-support percentage from
//! the double-support time and the step frequency when only the time is given, and **flags** (does
//! not silently use) rows whose given values disagree by more than [`CONSISTENCY_TOLERANCE`].
mod csv_file;

use crate::gait::{Gait, Side};
use crate::units::Quantity;
pub use csv_file::{parse_trials, read_trials, sha256_hex, write_trials};
use serde::{Deserialize, Serialize};
use std::collections::HashMap;
use std::path::PathBuf;

/// One row of a trials table (a trial or a single step), SI units.
///
/// Every quantity is optional: each relation states which it needs, and rows lacking them are
/// reported as rejected for that relation, not silently dropped.
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
pub struct StepRow {
    /// Subject identifier.
    pub subject: String,
    /// Walk or run.
    pub gait: Option<Gait>,
    /// The foot whose contact starts the step (the leading foot at its heel strike).
    pub side: Option<Side>,
    /// Data source (data set and file), for provenance.
    pub source: String,
    /// Trial name within the source.
    pub trial: String,
    /// Time of the step's initial heel strike, s from the start of the trial.
    pub time_s: Option<f64>,
    /// Speed of progression, m/s.
    pub speed_m_per_s: Option<f64>,
    /// Step length, m.
    pub step_length_m: Option<f64>,
    /// Step frequency, steps/s (CSV: `step_freq_steps_per_min` or `step_freq_hz`).
    pub step_freq_hz: Option<f64>,
    /// Stance time of the leading foot, s.
    pub stance_time_s: Option<f64>,
    /// Swing time, s.
    pub swing_time_s: Option<f64>,
    /// Double-support time of the step, s (walking): ONE double-support period (the one that
    /// ends the step), the `t_ds` of the walking paper §3.
    pub double_support_time_s: Option<f64>,
    /// That double-support period as a percentage of the gait cycle (walking), %:
    /// `100 · t_ds / t_cycle` with `t_cycle = 2 / sf`.
    pub double_support_pct_cycle: Option<f64>,
    /// Flight time of the step, s (running).
    pub flight_time_s: Option<f64>,
    /// Flight height H of the running paper's eq. 3, m.
    pub flight_height_m: Option<f64>,
    /// Body height, m.
    pub body_height_m: Option<f64>,
    /// Leg length, m.
    pub leg_length_m: Option<f64>,
    /// Ko–Badler μ1 input: knee flexion angle at heel strike, rad.
    pub knee_angle_hs_rad: Option<f64>,
    /// Ko–Badler μ2 input: foot-sole angle to the floor at heel strike, rad.
    pub foot_angle_hs_rad: Option<f64>,
    /// Ko–Badler μ3 input: foot-sole angle to the floor at toe off, rad.
    pub foot_angle_to_rad: Option<f64>,
    /// Ko–Badler μ4 input: metatarsal (toe) angle to the floor at toe off, rad.
    pub meta_angle_to_rad: Option<f64>,
}

/// The canonical column headers gaitfit writes, in order, with their units.
///
/// Readers accept these and the alternative unit suffixes documented in `data/README.md`
/// (`_cm`, `_mm`, `_km_per_h`, `_m_per_min`, `_hz`, `_ms`, `_deg`, …).
pub const CANONICAL_COLUMNS: &[&str] = &[
    "subject",
    "gait",
    "side",
    "source",
    "trial",
    "time_s",
    "speed_m_per_s",
    "step_length_m",
    "step_freq_steps_per_min",
    "stance_time_s",
    "swing_time_s",
    "double_support_time_s",
    "double_support_pct_cycle",
    "flight_time_s",
    "flight_height_m",
    "body_height_m",
    "leg_length_m",
    "knee_angle_hs_deg",
    "foot_angle_hs_deg",
    "foot_angle_to_deg",
    "meta_angle_to_deg",
];

/// Relative disagreement above which a row's redundant values (v vs sl·sf; double-support time
/// vs percentage) make the row *flagged*: reported and not used by any fit.
pub const CONSISTENCY_TOLERANCE: f64 = 0.02;

/// Number of numeric quantities (the length of [`FieldValues`]).
pub const N_QUANTITIES: usize = Quantity::ALL.len();

/// The numeric values of one row, SI, indexed by [`Quantity`]; `NaN` where missing. Plain data
/// (no allocation), what a relation reads its inputs from.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct FieldValues(pub [f64; N_QUANTITIES]);

impl Default for FieldValues {
    fn default() -> Self {
        FieldValues([f64::NAN; N_QUANTITIES])
    }
}

impl FieldValues {
    /// The value of `q` in SI, if present.
    #[inline]
    pub fn get(&self, q: Quantity) -> Option<f64> {
        let v = self.0[q as usize];
        (!v.is_nan()).then_some(v)
    }
    /// Sets `q` (SI); `None` clears it.
    #[inline]
    pub fn set(&mut self, q: Quantity, v: Option<f64>) {
        self.0[q as usize] = v.unwrap_or(f64::NAN);
    }
}

impl StepRow {
    /// The value of quantity `q` in SI.
    pub fn get(&self, q: Quantity) -> Option<f64> {
        match q {
            Quantity::Time => self.time_s,
            Quantity::Speed => self.speed_m_per_s,
            Quantity::StepLength => self.step_length_m,
            Quantity::StepFreq => self.step_freq_hz,
            Quantity::StanceTime => self.stance_time_s,
            Quantity::SwingTime => self.swing_time_s,
            Quantity::DoubleSupportTime => self.double_support_time_s,
            Quantity::DoubleSupportPct => self.double_support_pct_cycle,
            Quantity::FlightTime => self.flight_time_s,
            Quantity::FlightHeight => self.flight_height_m,
            Quantity::BodyHeight => self.body_height_m,
            Quantity::LegLength => self.leg_length_m,
            Quantity::KneeAngleHs => self.knee_angle_hs_rad,
            Quantity::FootAngleHs => self.foot_angle_hs_rad,
            Quantity::FootAngleTo => self.foot_angle_to_rad,
            Quantity::MetaAngleTo => self.meta_angle_to_rad,
        }
    }
    /// Sets quantity `q` (SI).
    pub fn set(&mut self, q: Quantity, v: Option<f64>) {
        let slot = match q {
            Quantity::Time => &mut self.time_s,
            Quantity::Speed => &mut self.speed_m_per_s,
            Quantity::StepLength => &mut self.step_length_m,
            Quantity::StepFreq => &mut self.step_freq_hz,
            Quantity::StanceTime => &mut self.stance_time_s,
            Quantity::SwingTime => &mut self.swing_time_s,
            Quantity::DoubleSupportTime => &mut self.double_support_time_s,
            Quantity::DoubleSupportPct => &mut self.double_support_pct_cycle,
            Quantity::FlightTime => &mut self.flight_time_s,
            Quantity::FlightHeight => &mut self.flight_height_m,
            Quantity::BodyHeight => &mut self.body_height_m,
            Quantity::LegLength => &mut self.leg_length_m,
            Quantity::KneeAngleHs => &mut self.knee_angle_hs_rad,
            Quantity::FootAngleHs => &mut self.foot_angle_hs_rad,
            Quantity::FootAngleTo => &mut self.foot_angle_to_rad,
            Quantity::MetaAngleTo => &mut self.meta_angle_to_rad,
        };
        *slot = v;
    }
    /// All numeric values as a [`FieldValues`].
    pub fn values(&self) -> FieldValues {
        let mut f = FieldValues::default();
        for q in Quantity::ALL {
            f.set(q, self.get(q));
        }
        f
    }
}

/// A trials table held by column (SI units), with interned subject, source and trial names.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct TrialsTable {
    /// Where it was read from (or a description for tables built in memory).
    pub path: PathBuf,
    /// SHA-256 of the file's bytes (hex), or of nothing for in-memory tables.
    pub sha256: String,
    /// Distinct subject names, in order of first appearance.
    pub subjects: Vec<String>,
    /// Per row: index into `subjects`.
    pub subject: Vec<u32>,
    /// Per row: gait.
    pub gait: Vec<Option<Gait>>,
    /// Per row: side.
    pub side: Vec<Option<Side>>,
    /// Distinct source names.
    pub sources: Vec<String>,
    /// Per row: index into `sources`.
    pub source: Vec<u32>,
    /// Distinct trial names.
    pub trials: Vec<String>,
    /// Per row: index into `trials`.
    pub trial: Vec<u32>,
    /// Per quantity (indexed by `Quantity as usize`): the column in SI, `NaN` where missing;
    /// `None` when the file has no such column and it could not be derived.
    pub columns: Vec<Option<Vec<f64>>>,
    /// Rows flagged during validation (1-based data row, reason). Flagged rows are not used by
    /// any fit and appear in every fit's rejected-rows report.
    pub flagged: Vec<(usize, String)>,
    /// Per row: true when flagged.
    pub is_flagged: Vec<bool>,
    /// Columns present in the file that gaitfit does not use.
    pub ignored_columns: Vec<String>,
    /// Those columns' values where numeric (`NaN` elsewhere), e.g. for `--weights <column>`.
    pub extra: Vec<(String, Vec<f64>)>,
}

impl TrialsTable {
    /// Number of rows.
    pub fn len(&self) -> usize {
        self.subject.len()
    }
    /// True when there are no rows.
    pub fn is_empty(&self) -> bool {
        self.subject.is_empty()
    }
    /// Whether the table has a column for `q` (read or derived).
    pub fn has(&self, q: Quantity) -> bool {
        self.columns[q as usize].is_some()
    }
    /// The numeric values of row `i` (0-based).
    #[inline]
    pub fn values(&self, i: usize) -> FieldValues {
        let mut f = FieldValues::default();
        for (k, c) in self.columns.iter().enumerate() {
            if let Some(c) = c {
                f.0[k] = c[i];
            }
        }
        f
    }
    /// The subject name of row `i`.
    pub fn subject_name(&self, i: usize) -> &str {
        &self.subjects[self.subject[i] as usize]
    }

    /// Builds a table from rows (e.g. from the events layer), then completes and validates it like
    /// a file: derived quantities are filled in and inconsistent rows flagged. `label` stands for
    /// the path in messages.
    pub fn from_step_rows(label: impl Into<PathBuf>, rows: &[StepRow]) -> TrialsTable {
        let mut b = Builder::default();
        for r in rows {
            let vals = r.values();
            b.push(
                &r.subject,
                r.gait,
                r.side,
                &r.source,
                &r.trial,
                &vals,
                &[true; N_QUANTITIES],
            );
        }
        let mut t = b.finish(label.into(), String::new(), Vec::new());
        t.complete();
        t
    }

    /// The rows as owned [`StepRow`]s.
    pub fn to_step_rows(&self) -> Vec<StepRow> {
        (0..self.len())
            .map(|i| {
                let mut r = StepRow {
                    subject: self.subjects[self.subject[i] as usize].clone(),
                    gait: self.gait[i],
                    side: self.side[i],
                    source: self.sources[self.source[i] as usize].clone(),
                    trial: self.trials[self.trial[i] as usize].clone(),
                    ..StepRow::default()
                };
                let v = self.values(i);
                for q in Quantity::ALL {
                    r.set(q, v.get(q));
                }
                r
            })
            .collect()
    }

    /// Appends another table's rows (for fitting several files together). Flags keep their row
    /// numbers prefixed with the other file's name.
    pub fn append(&mut self, other: &TrialsTable) {
        let n0 = self.len();
        let remap = |names: &mut Vec<String>, other_names: &[String], idx: &[u32]| -> Vec<u32> {
            let mut map: HashMap<String, u32> = names
                .iter()
                .enumerate()
                .map(|(i, s)| (s.clone(), i as u32))
                .collect();
            let table: Vec<u32> = other_names
                .iter()
                .map(|s| {
                    *map.entry(s.clone()).or_insert_with(|| {
                        names.push(s.clone());
                        (names.len() - 1) as u32
                    })
                })
                .collect();
            idx.iter().map(|&k| table[k as usize]).collect()
        };
        let s = remap(&mut self.subjects, &other.subjects, &other.subject);
        self.subject.extend(s);
        let s = remap(&mut self.sources, &other.sources, &other.source);
        self.source.extend(s);
        let s = remap(&mut self.trials, &other.trials, &other.trial);
        self.trial.extend(s);
        self.gait.extend_from_slice(&other.gait);
        self.side.extend_from_slice(&other.side);
        let n1 = other.len();
        for k in 0..N_QUANTITIES {
            match (&mut self.columns[k], &other.columns[k]) {
                (Some(a), Some(b)) => a.extend_from_slice(b),
                (Some(a), None) => a.extend(std::iter::repeat_n(f64::NAN, n1)),
                (None, Some(b)) => {
                    let mut a = vec![f64::NAN; n0];
                    a.extend_from_slice(b);
                    self.columns[k] = Some(a);
                }
                (None, None) => {}
            }
        }
        for (r, why) in &other.flagged {
            self.flagged
                .push((n0 + r, format!("{} row {r}: {why}", other.path.display())));
        }
        self.is_flagged.extend_from_slice(&other.is_flagged);
        for c in &other.ignored_columns {
            if !self.ignored_columns.contains(c) {
                self.ignored_columns.push(c.clone());
            }
        }
        let mut extra = std::mem::take(&mut self.extra);
        for (name, col) in &mut extra {
            match other.extra.iter().find(|(n, _)| n == name) {
                Some((_, o)) => col.extend_from_slice(o),
                None => col.extend(std::iter::repeat_n(f64::NAN, n1)),
            }
        }
        for (name, o) in &other.extra {
            if !extra.iter().any(|(n, _)| n == name) {
                let mut col = vec![f64::NAN; n0];
                col.extend_from_slice(o);
                extra.push((name.clone(), col));
            }
        }
        self.extra = extra;
    }

    /// Fills derived quantities and flags inconsistent rows (see the module docs).
    fn complete(&mut self) {
        let n = self.len();
        let (v, sl, sf) = (
            Quantity::Speed as usize,
            Quantity::StepLength as usize,
            Quantity::StepFreq as usize,
        );
        let have = |c: &Vec<Option<Vec<f64>>>, k: usize| c[k].is_some();
        let any_two = have(&self.columns, v) as u8
            + have(&self.columns, sl) as u8
            + have(&self.columns, sf) as u8
            >= 2;
        if any_two {
            for k in [v, sl, sf] {
                if self.columns[k].is_none() {
                    self.columns[k] = Some(vec![f64::NAN; n]);
                }
            }
        }
        let (dt, dp) = (
            Quantity::DoubleSupportTime as usize,
            Quantity::DoubleSupportPct as usize,
        );
        if have(&self.columns, dt) && have(&self.columns, sf) && !have(&self.columns, dp) {
            self.columns[dp] = Some(vec![f64::NAN; n]);
        }
        self.is_flagged.resize(n, false);
        for i in 0..n {
            if any_two {
                let get =
                    |c: &Vec<Option<Vec<f64>>>, k: usize| c[k].as_ref().map_or(f64::NAN, |c| c[i]);
                let (a, b, c) = (
                    get(&self.columns, v),
                    get(&self.columns, sl),
                    get(&self.columns, sf),
                );
                match (a.is_nan(), b.is_nan(), c.is_nan()) {
                    (true, false, false) => self.set(v, i, b * c),
                    (false, true, false) if c > 0.0 => self.set(sl, i, a / c),
                    (false, false, true) if b > 0.0 => self.set(sf, i, a / b),
                    (false, false, false) => {
                        let prod = b * c;
                        let rel = (a - prod).abs() / a.abs().max(prod.abs()).max(f64::MIN_POSITIVE);
                        if rel > CONSISTENCY_TOLERANCE {
                            self.flag(
                                i,
                                format!(
                                    "speed {a:.4} m/s disagrees with step length × step frequency \
                                     = {b:.4} m × {c:.4} steps/s = {prod:.4} m/s by {:.1} % \
                                     (> {:.0} %); fix or drop one of the three",
                                    100.0 * rel,
                                    100.0 * CONSISTENCY_TOLERANCE
                                ),
                            );
                        }
                    }
                    _ => {}
                }
            }
            if let (Some(tc), Some(fc)) = (&self.columns[dt], &self.columns[sf]) {
                let (t, f) = (tc[i], fc[i]);
                if !t.is_nan() && !f.is_nan() && f > 0.0 {
                    // t_cycle = 2 / sf (walking paper §3), so pct = 100·t_ds·sf/2.
                    let derived = 100.0 * t * f / 2.0;
                    if let Some(pc) = &self.columns[dp] {
                        let p = pc[i];
                        if p.is_nan() {
                            self.set(dp, i, derived);
                        } else {
                            let rel = (p - derived).abs() / p.abs().max(derived.abs()).max(1e-12);
                            if rel > CONSISTENCY_TOLERANCE && (p - derived).abs() > 0.05 {
                                self.flag(
                                    i,
                                    format!(
                                        "double_support_pct_cycle {p:.3} % disagrees with \
                                         100·double_support_time·sf/2 = {derived:.3} % by {:.1} %",
                                        100.0 * rel
                                    ),
                                );
                            }
                        }
                    }
                }
            }
        }
    }

    fn set(&mut self, k: usize, i: usize, v: f64) {
        if let Some(c) = &mut self.columns[k] {
            c[i] = v;
        }
    }

    fn flag(&mut self, i: usize, why: String) {
        if !self.is_flagged[i] {
            self.is_flagged[i] = true;
            self.flagged.push((i + 1, why));
        } else if let Some(last) = self.flagged.iter_mut().rev().find(|(r, _)| *r == i + 1) {
            last.1.push_str("; ");
            last.1.push_str(&why);
        }
    }
}

#[derive(Default)]
struct Interner {
    names: Vec<String>,
    /// `names` packed (see [`pack`]), for the scans below.
    packed: Vec<Option<(u128, usize)>>,
    map: HashMap<Vec<u8>, u32>,
    /// The id returned last.
    last: u32,
}

/// Up to this many distinct names, [`Interner::get`] scans them instead of hashing.
const INTERNER_SCAN: usize = 16;

/// A name of at most 16 bytes as one integer and its length (compared without a `memcmp`
/// call, which profiled at a third of parsing a large table).
#[inline]
fn pack(s: &[u8]) -> Option<(u128, usize)> {
    let mut b = [0u8; 16];
    b.get_mut(..s.len())?.copy_from_slice(s);
    Some((u128::from_le_bytes(b), s.len()))
}

impl Interner {
    fn get(&mut self, s: &[u8]) -> u32 {
        // Tables repeat a handful of names row after row: the last one, then a short scan,
        // are cheaper than hashing every cell.
        let key = pack(s);
        if key.is_some() {
            if self.packed.get(self.last as usize) == Some(&key) {
                return self.last;
            }
            if self.names.len() <= INTERNER_SCAN {
                if let Some(k) = self.packed.iter().position(|p| *p == key) {
                    self.last = k as u32;
                    return self.last;
                }
            }
        }
        let k = match self.map.get(s) {
            Some(&k) => k,
            None => {
                let k = self.names.len() as u32;
                self.names.push(String::from_utf8_lossy(s).into_owned());
                self.packed.push(key);
                self.map.insert(s.to_vec(), k);
                k
            }
        };
        self.last = k;
        k
    }
}

#[derive(Default)]
struct Builder {
    subjects: Interner,
    sources: Interner,
    trials: Interner,
    subject: Vec<u32>,
    source: Vec<u32>,
    trial: Vec<u32>,
    gait: Vec<Option<Gait>>,
    side: Vec<Option<Side>>,
    columns: Vec<Option<Vec<f64>>>,
}

impl Builder {
    /// Room for `rows` rows in the columns the file has.
    fn reserve(&mut self, rows: usize, present: &[bool; N_QUANTITIES]) {
        self.subject.reserve(rows);
        self.source.reserve(rows);
        self.trial.reserve(rows);
        self.gait.reserve(rows);
        self.side.reserve(rows);
        self.columns = present
            .iter()
            .map(|&p| p.then(|| Vec::with_capacity(rows)))
            .collect();
    }

    #[allow(clippy::too_many_arguments)]
    fn push(
        &mut self,
        subject: &str,
        gait: Option<Gait>,
        side: Option<Side>,
        source: &str,
        trial: &str,
        vals: &FieldValues,
        present: &[bool; N_QUANTITIES],
    ) {
        if self.columns.is_empty() {
            self.columns = vec![None; N_QUANTITIES];
        }
        let n = self.subject.len();
        self.push_keys(subject, gait, side, source, trial);
        for ((col, &v), &p) in self.columns.iter_mut().zip(&vals.0).zip(present) {
            if !p {
                continue;
            }
            match col {
                Some(c) => c.push(v),
                None if !v.is_nan() => {
                    let mut c = vec![f64::NAN; n];
                    c.push(v);
                    *col = Some(c);
                }
                None => {}
            }
        }
        // Keep every existing column the same length.
        for c in self.columns.iter_mut().flatten() {
            if c.len() < n + 1 {
                c.push(f64::NAN);
            }
        }
    }

    /// A row's keys: subject, source and trial interned, gait and side as given.
    fn push_keys(
        &mut self,
        subject: &str,
        gait: Option<Gait>,
        side: Option<Side>,
        source: &str,
        trial: &str,
    ) {
        self.subject.push(self.subjects.get(subject.as_bytes()));
        self.source.push(self.sources.get(source.as_bytes()));
        self.trial.push(self.trials.get(trial.as_bytes()));
        self.gait.push(gait);
        self.side.push(side);
    }

    /// [`Builder::push`] for a parsed file's rows, after [`Builder::reserve`]: every column the
    /// file has (`present`, the quantities' indices) already exists, so a row is one push per
    /// column.
    #[allow(clippy::too_many_arguments)]
    fn push_parsed(
        &mut self,
        subject: &str,
        gait: Option<Gait>,
        side: Option<Side>,
        source: &str,
        trial: &str,
        vals: &FieldValues,
        present: &[usize],
    ) {
        self.push_keys(subject, gait, side, source, trial);
        for &q in present {
            if let Some(c) = &mut self.columns[q] {
                c.push(vals.0[q]);
            }
        }
    }

    fn finish(self, path: PathBuf, sha256: String, ignored: Vec<String>) -> TrialsTable {
        let n = self.subject.len();
        TrialsTable {
            path,
            sha256,
            subjects: self.subjects.names,
            subject: self.subject,
            gait: self.gait,
            side: self.side,
            sources: self.sources.names,
            source: self.source,
            trials: self.trials.names,
            trial: self.trial,
            columns: if self.columns.is_empty() {
                vec![None; N_QUANTITIES]
            } else {
                self.columns
            },
            flagged: Vec::new(),
            is_flagged: vec![false; n],
            ignored_columns: ignored,
            extra: Vec::new(),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::csv_file::FIRST_BLOCK;
    use super::*;
    use crate::ingest::IngestError;
    use std::path::Path;

    fn parse(s: &str) -> Result<TrialsTable, IngestError> {
        parse_trials(Path::new("t.csv"), s.as_bytes())
    }

    #[test]
    fn a_streamed_file_reads_as_its_bytes_parse() {
        // Larger than the first block (sizing from a sample), with mixed spellings of gait and
        // side (the fast paths and the general parse), and a small file read whole.
        let mut text = String::from(
            "subject,gait,side,speed_m_per_s,step_length_m,step_freq_steps_per_min,weight\n",
        );
        let mut k = 0usize;
        while text.len() < 3 * FIRST_BLOCK + 17 {
            let gait = ["run", "walk", "Running", " walk "][k % 4];
            let side = ["left", "r", "", "right"][k % 4];
            let sl = 0.6 + 0.001 * (k % 500) as f64;
            let sf = 150.0 + (k % 37) as f64;
            let w = if k % 5 == 0 {
                "x".to_string()
            } else {
                k.to_string()
            };
            text.push_str(&format!(
                "s{},{gait},{side},{},{sl},{sf},{w}\n",
                k % 11,
                sl * sf / 60.0
            ));
            k += 1;
        }
        let dir = tempfile::tempdir().unwrap();
        for t in [&text[..], &text[..300]] {
            let t = &t[..t.rfind('\n').unwrap() + 1];
            let p = dir.path().join("big.csv");
            std::fs::write(&p, t).unwrap();
            let read = read_trials(&p).unwrap();
            let parsed = parse_trials(&p, t.as_bytes()).unwrap();
            assert_eq!(read.sha256, sha256_hex(t.as_bytes()));
            // Debug text: NaN cells (the non-numeric `weight`s) compare equal.
            assert_eq!(format!("{read:?}"), format!("{parsed:?}"));
            assert_eq!(read.len(), t.lines().count() - 1);
        }
        assert!(matches!(
            read_trials(&dir.path().join("missing.csv")),
            Err(IngestError::Io { .. })
        ));
    }

    #[test]
    fn names_are_interned_by_scan_and_by_hash() {
        // 40 subjects (beyond the scan limit), one with a name longer than 16 bytes, in an
        // interleaved order; every row keeps its own name.
        let names: Vec<String> = (0..40)
            .map(|k| {
                if k == 7 {
                    "a-subject-name-longer-than-sixteen-bytes".to_string()
                } else {
                    format!("S{k}")
                }
            })
            .collect();
        let mut csv = String::from("subject,gait,speed_m_per_s\n");
        let order: Vec<usize> = (0..200).map(|i| (i * 7 + i / 40) % 40).collect();
        for &k in &order {
            csv.push_str(&format!("{},run,3.0\n", names[k]));
        }
        let t = parse(&csv).unwrap();
        assert_eq!(t.subjects.len(), 40);
        for (i, &k) in order.iter().enumerate() {
            assert_eq!(t.subject_name(i), names[k]);
        }
    }

    #[test]
    fn numbers_parse_as_str_parse_does() {
        for cell in ["3", "3.25", ".5", "2.", "1e0", "2.5E-0", "+1.5"] {
            let t = parse(&format!("subject,gait,speed_m_per_s\ns,run,{cell}\n")).unwrap();
            let want: f64 = cell.parse().unwrap();
            assert_eq!(t.values(0).get(Quantity::Speed), Some(want), "{cell}");
        }
        for cell in ["abc", "1.2.3", "3 m", "0x10", "1e", "--1"] {
            let e = parse(&format!("subject,gait,speed_m_per_s\ns,run,{cell}\n"));
            assert!(e.is_err(), "{cell} accepted");
        }
    }

    #[test]
    fn reads_units_and_completes_the_triple() {
        let t = parse(
            "subject,gait,speed_km_per_h,step_length_cm,step_freq_steps_per_min,body_height_mm\n\
             A,run,12,,187,1800\n\
             B,walk,,77.5,107.6,1800\n",
        )
        .unwrap();
        assert_eq!(t.len(), 2);
        let r0 = t.values(0);
        assert!((r0.get(Quantity::Speed).unwrap() - 12.0 / 3.6).abs() < 1e-12);
        let sl = r0.get(Quantity::StepLength).unwrap();
        assert!((sl - (12.0 / 3.6) / (187.0 / 60.0)).abs() < 1e-12);
        let r1 = t.values(1);
        assert!((r1.get(Quantity::Speed).unwrap() - 0.775 * 107.6 / 60.0).abs() < 1e-12);
        assert_eq!(r1.get(Quantity::BodyHeight), Some(1.8));
        assert!(t.flagged.is_empty());
    }

    #[test]
    fn inconsistent_triple_is_flagged_not_used() {
        let t = parse(
            "subject,gait,speed_m_per_s,step_length_m,step_freq_hz\nA,run,3.0,1.0,3.0\nA,run,3.0,1.0,3.1\n",
        )
        .unwrap();
        assert_eq!(t.flagged.len(), 1);
        assert_eq!(t.flagged[0].0, 2);
        assert!(t.flagged[0].1.contains("disagrees"));
        assert!(t.is_flagged[1] && !t.is_flagged[0]);
    }

    #[test]
    fn double_support_pct_is_derived_from_time() {
        let t =
            parse("subject,gait,step_freq_steps_per_min,double_support_time_ms\nA,walk,120,100\n")
                .unwrap();
        // sf = 2 steps/s, t_cycle = 1 s, t_ds = 0.1 s → 10 %.
        assert!((t.values(0).get(Quantity::DoubleSupportPct).unwrap() - 10.0).abs() < 1e-12);
    }

    #[test]
    fn round_trip_through_step_rows_and_writer() {
        let t = parse(
            "subject,gait,side,source,trial,speed_m_per_s,step_freq_hz,knee_angle_hs_deg\n\
             A,run,l,src,t1,3.0,3.0,10\n",
        )
        .unwrap();
        let rows = t.to_step_rows();
        assert_eq!(rows[0].side, Some(Side::Left));
        assert!((rows[0].knee_angle_hs_rad.unwrap() - 10f64.to_radians()).abs() < 1e-12);
        let dir = tempfile::tempdir().unwrap();
        let p = dir.path().join("out.csv");
        write_trials(&p, &rows).unwrap();
        let back = read_trials(&p).unwrap().to_step_rows();
        assert_eq!(back.len(), 1);
        for q in Quantity::ALL {
            match (rows[0].get(q), back[0].get(q)) {
                (Some(a), Some(b)) => assert!((a - b).abs() < 1e-12 * a.abs().max(1.0), "{q:?}"),
                (a, b) => assert_eq!(a, b, "{q:?}"),
            }
        }
        let again = TrialsTable::from_step_rows("mem", &back);
        assert_eq!(again.len(), 1);
    }

    #[test]
    fn append_merges_subjects_and_columns() {
        let mut a = parse("subject,gait,speed_m_per_s\nA,run,3\n").unwrap();
        let b = parse("subject,gait,flight_time_s\nA,run,0.1\nB,run,0.12\n").unwrap();
        a.append(&b);
        assert_eq!(a.len(), 3);
        assert_eq!(a.subjects, vec!["A", "B"]);
        assert!(a.values(0).get(Quantity::FlightTime).is_none());
        assert_eq!(a.values(2).get(Quantity::FlightTime), Some(0.12));
        assert!(a.values(2).get(Quantity::Speed).is_none());
    }
}
