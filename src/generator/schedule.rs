//! Per-step schedules: one CSV vocabulary and one reader for every generator
//! (`gaitfit generate run | walk | generalize --schedule FILE`).
//!
//! A schedule is a CSV file with one row per change; headers carry their unit as in every
//! gaitfit table ([`crate::units::parse_header`]).
//!
//! | column | meaning | run | walk | generalize |
//! |---|---|:-:|:-:|:-:|
//! | `step` | the step (0 = the first) at which the row takes effect; rows sorted by it | ✓ | ✓ | ✓ |
//! | `steps` | how many steps the row holds (the next row starts after them) | ✓ | ✓ | ✓ |
//! | `speed_m_per_s`, `speed_km_per_h`, `speed_m_per_min` | speed | ✓ | ✓ | ✓ |
//! | `step_length_m`, `_cm`, `_mm`, `_in` | step length | ✓ | ✓ | ✓ |
//! | `step_freq_steps_per_min`, `_hz`, `_steps_per_s` | step frequency (cadence) | ✓ | ✓ | ✓ |
//! | `flight_height_m`, `_cm`, `_mm` | flight height H (running eq. 3) | ✓ | | |
//! | `level` | expertise, −1 (poor) … 1 (skilled) | ✓ | | |
//! | `action` | `go` (default; `run` and `walk` mean the same) or `stop` | ✓ | ✓ | |
//!
//! - **Where rows start.** With a `step` column a row takes effect at that step and holds until
//!   the next row's; with a `steps` column each row holds that many steps, one after the other,
//!   and the schedule's length is their sum; with neither, row *i* is step *i* (one step per
//!   row). `step` and `steps` do not go together.
//! - **An empty cell is not commanded by that row**: the generator completes it — RUNNER from
//!   its relations (eqs. 1–2, the parameter coupling and `--lock`), KLAW by the normalizing
//!   formula (eq. 1), Ko–Badler from the previous row (step length; the first row needs one)
//!   and the prototype's cadence. Several quantities in one row are applied in column order.
//! - **`action = stop`** ends the motion in a stand: RUNNER decelerates from that step on;
//!   KLAW's `stop` must be on the last row, whose last step is then the stop's half step.
//! - **How long.** A schedule with `steps` has its own length; otherwise the last row holds
//!   until `--seconds` or `--count` ends the motion.
//!
//! Errors name the file, the data row (1 = the first row under the header) and the column.
use crate::generator::GenerateError;
use crate::units::{parse_header, Quantity};
use std::path::Path;

/// What a row asks for besides its quantities.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Action {
    /// Go on (the default; `go`, `run`, `walk`).
    #[default]
    Go,
    /// End in a stand.
    Stop,
}

/// One row of a schedule.
#[derive(Debug, Clone, PartialEq)]
pub struct ScheduleRow {
    /// Data row in the file (1 = the first row under the header).
    pub row: usize,
    /// The step (0-based) at which the row takes effect.
    pub step: usize,
    /// Steps the row holds, when the file says (a `steps` column).
    pub steps: Option<usize>,
    /// The quantities commanded, in column order, in SI (m, m/s, steps/s).
    pub set: Vec<(Quantity, f64)>,
    /// Expertise level (running).
    pub level: Option<f64>,
    /// `go` or `stop`.
    pub action: Action,
}

impl ScheduleRow {
    /// The value commanded for `q`, if any.
    pub fn get(&self, q: Quantity) -> Option<f64> {
        self.set.iter().find(|(x, _)| *x == q).map(|&(_, v)| v)
    }
}

/// A per-step schedule (see the module docs for its columns).
#[derive(Debug, Clone, PartialEq, Default)]
pub struct Schedule {
    /// Rows in step order.
    pub rows: Vec<ScheduleRow>,
    /// The file (for messages).
    pub source: String,
    /// The header, as written.
    pub columns: Vec<String>,
    /// How the rows are placed: by a `step` column, a `steps` column, or one step per row.
    pub placement: Placement,
}

/// How a schedule's rows are placed on steps.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Placement {
    /// Row *i* is step *i*.
    #[default]
    OnePerRow,
    /// A `step` column: the step at which each row takes effect.
    AtStep,
    /// A `steps` column: how many steps each row holds.
    Counts,
}

/// The quantities a schedule may command.
const QUANTITIES: [Quantity; 4] = [
    Quantity::Speed,
    Quantity::StepLength,
    Quantity::StepFreq,
    Quantity::FlightHeight,
];

impl Schedule {
    /// Reads a schedule CSV file.
    pub fn from_csv(path: &Path) -> Result<Schedule, GenerateError> {
        let text = std::fs::read_to_string(path).map_err(|e| GenerateError::Input {
            path: path.display().to_string(),
            message: format!("cannot read the schedule: {e}"),
        })?;
        Schedule::parse(&text, &path.display().to_string())
    }

    /// Parses schedule CSV text (`source` names it in messages).
    pub fn parse(text: &str, source: &str) -> Result<Schedule, GenerateError> {
        let err = |message: String| GenerateError::Input {
            path: source.to_string(),
            message,
        };
        let mut rdr = csv::ReaderBuilder::new()
            .trim(csv::Trim::All)
            .comment(Some(b'#'))
            .from_reader(text.as_bytes());
        let headers = rdr
            .headers()
            .map_err(|e| err(format!("header: {e}")))?
            .clone();
        #[derive(Clone, Copy)]
        enum Col {
            Step,
            Steps,
            Level,
            Action,
            Q(Quantity, f64),
        }
        let known = "step or steps, speed_*, step_length_*, step_freq_*, flight_height_*, \
                     level, action";
        let mut cols = Vec::with_capacity(headers.len());
        for h in headers.iter() {
            let col = match h.to_ascii_lowercase().as_str() {
                "step" => Col::Step,
                "steps" => Col::Steps,
                "level" => Col::Level,
                "action" => Col::Action,
                "duration_s" => {
                    return Err(err("column duration_s: give the step frequency instead, \
                         step_freq_steps_per_min = 60 / duration_s"
                        .into()))
                }
                _ => {
                    let c = parse_header(h)
                        .map_err(|u| {
                            err(format!("column {h}: unknown unit; use {}", u.accepted()))
                        })?
                        .ok_or_else(|| {
                            err(format!("column {h}: not a schedule column (use {known})"))
                        })?;
                    if !QUANTITIES.contains(&c.quantity) {
                        return Err(err(format!(
                            "column {h}: a schedule does not set {}; use {known}",
                            c.quantity.stem()
                        )));
                    }
                    Col::Q(c.quantity, c.unit.to_si_factor())
                }
            };
            cols.push(col);
        }
        let has = |f: fn(&Col) -> bool| cols.iter().filter(|c| f(c)).count();
        if has(|c| matches!(c, Col::Step)) > 0 && has(|c| matches!(c, Col::Steps)) > 0 {
            return Err(err(
                "columns step and steps: give where each row starts (step) or how many steps \
                 it holds (steps), not both"
                    .into(),
            ));
        }
        for (i, a) in headers.iter().enumerate() {
            if headers
                .iter()
                .skip(i + 1)
                .any(|b| b.eq_ignore_ascii_case(a))
            {
                return Err(err(format!("column {a} appears twice")));
            }
        }
        let mut dup = Vec::new();
        for c in &cols {
            if let Col::Q(q, _) = c {
                if dup.contains(q) {
                    return Err(err(format!("two columns give {}: use one unit", q.stem())));
                }
                dup.push(*q);
            }
        }
        let placement = if has(|c| matches!(c, Col::Step)) > 0 {
            Placement::AtStep
        } else if has(|c| matches!(c, Col::Steps)) > 0 {
            Placement::Counts
        } else {
            Placement::OnePerRow
        };
        let mut rows: Vec<ScheduleRow> = Vec::new();
        let mut next_step = 0usize;
        for (i, rec) in rdr.records().enumerate() {
            let r = i + 1;
            let rec = rec.map_err(|e| err(format!("row {r}: {e}")))?;
            let mut row = ScheduleRow {
                row: r,
                step: next_step,
                steps: None,
                set: Vec::new(),
                level: None,
                action: Action::Go,
            };
            for (cell, (col, name)) in rec.iter().zip(cols.iter().zip(headers.iter())) {
                let at = |m: String| err(format!("row {r}, column {name}: {m}"));
                if cell.is_empty() {
                    if matches!(col, Col::Steps) {
                        return Err(at("empty: how many steps does this row hold?".into()));
                    }
                    continue;
                }
                let num = || {
                    cell.parse::<f64>()
                        .ok()
                        .filter(|v| v.is_finite())
                        .ok_or_else(|| at(format!("{cell:?} is not a number")))
                };
                let count = || {
                    cell.parse::<usize>()
                        .map_err(|_| at(format!("{cell:?} is not a whole number of steps")))
                };
                match *col {
                    Col::Step => row.step = count()?,
                    Col::Steps => row.steps = Some(count()?),
                    Col::Level => {
                        let v = num()?;
                        if !(-1.0..=1.0).contains(&v) {
                            return Err(at(format!("{v} is outside [−1, 1]")));
                        }
                        row.level = Some(v);
                    }
                    Col::Action => {
                        row.action = match cell.to_ascii_lowercase().as_str() {
                            "go" | "run" | "walk" => Action::Go,
                            "stop" => Action::Stop,
                            _ => return Err(at(format!("{cell:?} is neither go nor stop"))),
                        }
                    }
                    Col::Q(q, factor) => {
                        let v = num()? * factor;
                        if v <= 0.0 {
                            return Err(at(format!("{cell} must be positive")));
                        }
                        row.set.push((q, v));
                    }
                }
            }
            if let Some(prev) = rows.last() {
                if row.step < prev.step {
                    return Err(err(format!(
                        "row {r}, column step: step {} comes before the previous row's step {}; \
                         sort the rows by step",
                        row.step, prev.step
                    )));
                }
            }
            next_step = match placement {
                Placement::Counts => row.step + row.steps.unwrap_or(0),
                Placement::OnePerRow => row.step + 1,
                Placement::AtStep => row.step,
            };
            if placement == Placement::OnePerRow {
                row.steps = Some(1);
            }
            rows.push(row);
        }
        if rows.is_empty() {
            return Err(err("no rows under the header".into()));
        }
        Ok(Schedule {
            rows,
            source: source.to_string(),
            columns: headers.iter().map(str::to_string).collect(),
            placement,
        })
    }

    /// The schedule's own length in steps, when it has one (a `steps` column, or one step per
    /// row): the step after its last row.
    pub fn length(&self) -> Option<usize> {
        match self.placement {
            Placement::AtStep => None,
            _ => self.rows.last().map(|r| r.step + r.steps.unwrap_or(0)),
        }
    }

    /// Whether a row asks for a stop.
    pub fn stops(&self) -> bool {
        self.rows.iter().any(|r| r.action == Action::Stop)
    }

    /// Refuses the columns `generator` cannot use (`quantities` it accepts; `level`, `action`).
    pub fn accept_only(
        &self,
        generator: &str,
        quantities: &[Quantity],
        level: bool,
        action: bool,
    ) -> Result<(), GenerateError> {
        let bad = |what: &str| GenerateError::Input {
            path: self.source.clone(),
            message: format!("{generator} does not take a {what} column"),
        };
        for r in &self.rows {
            if let Some((q, _)) = r.set.iter().find(|(q, _)| !quantities.contains(q)) {
                return Err(bad(q.stem()));
            }
            if r.level.is_some() && !level {
                return Err(bad("level"));
            }
            if r.action == Action::Stop && !action {
                return Err(bad("stop action"));
            }
        }
        Ok(())
    }

    /// How many steps each row holds, the last row holding until `total` (steps) when the
    /// schedule has no length of its own. Rows that hold no step are dropped.
    pub fn stretches(
        &self,
        total: Option<usize>,
    ) -> Result<Vec<(&ScheduleRow, usize)>, GenerateError> {
        let end = match (self.length(), total) {
            (Some(n), _) => n,
            (None, Some(n)) => n,
            (None, None) => {
                return Err(GenerateError::Input {
                    path: self.source.clone(),
                    message: "the schedule has a step column but no length: give --count N or \
                              --seconds S, or a steps column (how many steps each row holds)"
                        .into(),
                })
            }
        };
        let mut out = Vec::new();
        for (i, r) in self.rows.iter().enumerate() {
            let next = self.rows.get(i + 1).map_or(end, |n| n.step.min(end));
            let n = next.saturating_sub(r.step.min(end));
            if n > 0 {
                out.push((r, n));
            }
        }
        Ok(out)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn three_placements() {
        let s = Schedule::parse("speed_km_per_h,action\n8,\n12,\n,stop\n", "t.csv").unwrap();
        assert_eq!(s.placement, Placement::OnePerRow);
        assert_eq!(s.rows.len(), 3);
        assert_eq!(s.rows[1].step, 1);
        assert!((s.rows[1].get(Quantity::Speed).unwrap() - 12.0 / 3.6).abs() < 1e-12);
        assert!(s.rows[2].action == Action::Stop && s.stops());
        assert_eq!(s.length(), Some(3));

        let s = Schedule::parse("steps,speed_km_per_h\n4,2\n3,5\n2,\n", "t.csv").unwrap();
        assert_eq!(s.placement, Placement::Counts);
        assert_eq!(s.rows.iter().map(|r| r.step).collect::<Vec<_>>(), [0, 4, 7]);
        assert_eq!(s.length(), Some(9));
        let st = s.stretches(None).unwrap();
        assert_eq!(st.iter().map(|x| x.1).collect::<Vec<_>>(), [4, 3, 2]);

        let s = Schedule::parse("step,speed_m_per_s\n0,3\n5,4\n", "t.csv").unwrap();
        assert_eq!(s.placement, Placement::AtStep);
        assert_eq!(s.length(), None);
        assert!(s.stretches(None).is_err());
        let st = s.stretches(Some(8)).unwrap();
        assert_eq!(st.iter().map(|x| x.1).collect::<Vec<_>>(), [5, 3]);
        // A total shorter than the schedule cuts it.
        let st = s.stretches(Some(3)).unwrap();
        assert_eq!(st.iter().map(|x| x.1).collect::<Vec<_>>(), [3]);
    }

    #[test]
    fn units_and_errors_name_file_row_and_column() {
        let s = Schedule::parse("step_length_cm,step_freq_hz\n70,2\n", "t.csv").unwrap();
        assert!((s.rows[0].get(Quantity::StepLength).unwrap() - 0.7).abs() < 1e-12);
        assert!((s.rows[0].get(Quantity::StepFreq).unwrap() - 2.0).abs() < 1e-12);
        for (text, needles) in [
            (
                "speed_furlongs\n1\n",
                &["t.csv", "speed_furlongs", "speed_km_per_h"][..],
            ),
            (
                "speed_km_per_h\n8\nabc\n",
                &["t.csv: row 2, column speed_km_per_h", "abc"],
            ),
            (
                "step,speed_km_per_h\n3,8\n1,9\n",
                &["row 2, column step", "sort"],
            ),
            ("step,steps,speed_km_per_h\n0,1,8\n", &["not both"]),
            (
                "steps,speed_km_per_h\n1.5,8\n",
                &["row 1, column steps", "whole number"],
            ),
            ("speed_km_per_h,speed_m_per_s\n8,2\n", &["use one unit"]),
            (
                "mass_kg\n80\n",
                &["column mass_kg", "not a schedule column"],
            ),
            ("body_height_m\n1.8\n", &["does not set body_height"]),
            (
                "step_length_m,duration_s\n0.7,0.5\n",
                &["step_freq_steps_per_min = 60 / duration_s"],
            ),
            ("level\n2\n", &["row 1, column level", "[−1, 1]"]),
            (
                "action\njump\n",
                &["row 1, column action", "neither go nor stop"],
            ),
            ("speed_km_per_h\n-3\n", &["must be positive"]),
            ("speed_km_per_h\n", &["no rows"]),
        ] {
            let e = Schedule::parse(text, "t.csv").unwrap_err().to_string();
            for n in needles {
                assert!(e.contains(n), "{text:?}: {e}");
            }
        }
    }

    #[test]
    fn a_generator_refuses_columns_it_cannot_use() {
        let s =
            Schedule::parse("speed_km_per_h,flight_height_mm,level\n12,4,0.5\n", "t.csv").unwrap();
        assert!(s.accept_only("run", &QUANTITIES, true, true).is_ok());
        let e = s
            .accept_only("walk", &QUANTITIES[..3], false, true)
            .unwrap_err()
            .to_string();
        assert!(
            e.contains("walk does not take a flight_height column"),
            "{e}"
        );
    }
}
