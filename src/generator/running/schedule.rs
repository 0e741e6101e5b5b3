//! RUNNER's per-step schedule: the rows of a [`crate::generator::schedule::Schedule`] (the
//! schedule CSV shared by every generator; its columns are documented there) as the parameter
//! changes the runner applies at the start of a step.
//!
//! The parameters given in one row are applied in column order, each held fixed while the next
//! is set (so `speed` and `step_freq` together fix the step length by eq. 1), through the same
//! coupling as interactive changes ([`super::params::RunModel::set`]); the parameter locks of
//! the run still apply. An empty cell leaves a parameter to that coupling. `level` is kept
//! until changed; `action = stop` decelerates from that step on and ends in a stand.
use std::path::Path;

use super::params::Param;
use crate::generator::schedule::{self as shared, Action, Placement};
use crate::generator::GenerateError;
use crate::units::Quantity;

/// One schedule row.
#[derive(Debug, Clone, PartialEq)]
pub struct ScheduleRow {
    /// Step index at which it takes effect.
    pub step: usize,
    /// Parameters to set, in column order (SI values).
    pub set: Vec<(Param, f64)>,
    /// New expertise level.
    pub level: Option<f64>,
    /// Stop after this point.
    pub stop: bool,
    /// Data row in the file (1 = the first row under the header).
    pub row: usize,
}

/// A per-step schedule.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct Schedule {
    /// Rows in step order.
    pub rows: Vec<ScheduleRow>,
    /// Where it came from (for messages).
    pub source: String,
    /// The run ends when this step would begin (a schedule with a `steps` column, or
    /// `--count`); `None`: when the duration is over.
    pub end_step: Option<usize>,
}

impl Schedule {
    /// Reads a schedule CSV file.
    pub fn from_csv(path: &Path) -> Result<Schedule, GenerateError> {
        Schedule::from_shared(&shared::Schedule::from_csv(path)?)
    }

    /// Parses schedule CSV text (`source` names it in messages).
    pub fn parse(text: &str, source: &str) -> Result<Schedule, GenerateError> {
        Schedule::from_shared(&shared::Schedule::parse(text, source)?)
    }

    /// The runner's form of a schedule read by the shared reader. A schedule with its own
    /// length (a `steps` column) ends the run after it; one step per row (no `step` or `steps`
    /// column) only sets where the rows start, the run going on with the last row's parameters.
    pub fn from_shared(s: &shared::Schedule) -> Result<Schedule, GenerateError> {
        s.accept_only(
            "generate run",
            &[
                Quantity::Speed,
                Quantity::StepLength,
                Quantity::StepFreq,
                Quantity::FlightHeight,
            ],
            true,
            true,
        )?;
        let rows = s
            .rows
            .iter()
            .map(|r| ScheduleRow {
                step: r.step,
                set: r
                    .set
                    .iter()
                    .map(|&(q, v)| {
                        let p = match q {
                            Quantity::Speed => Param::Speed,
                            Quantity::StepLength => Param::StepLength,
                            Quantity::StepFreq => Param::StepFreq,
                            _ => Param::FlightHeight,
                        };
                        (p, v)
                    })
                    .collect(),
                level: r.level,
                stop: r.action == Action::Stop,
                row: r.row,
            })
            .collect();
        Ok(Schedule {
            rows,
            source: s.source.clone(),
            end_step: match s.placement {
                Placement::Counts => s.length(),
                _ => None,
            },
        })
    }

    /// The rows that take effect at `step`.
    pub fn rows_at(&self, step: usize) -> impl Iterator<Item = &ScheduleRow> {
        self.rows.iter().filter(move |r| r.step == step)
    }

    /// Whether the schedule asks for a stop.
    pub fn stops(&self) -> bool {
        self.rows.iter().any(|r| r.stop)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn schedule_rows_and_errors() {
        let s = Schedule::parse("speed_km_per_h,action\n8,\n12,\n,stop\n", "t.csv").unwrap();
        assert_eq!(s.rows.len(), 3);
        assert_eq!(s.rows[1].step, 1);
        assert_eq!(s.rows[1].set.len(), 1);
        assert_eq!(s.rows[1].set[0].0, Param::Speed);
        assert!((s.rows[1].set[0].1 - 12.0 / 3.6).abs() < 1e-12);
        assert!(s.rows[2].stop && s.stops());
        assert_eq!(s.end_step, None);
        let s = Schedule::parse("steps,speed_km_per_h\n4,8\n6,12\n", "t.csv").unwrap();
        assert_eq!(s.rows[1].step, 4);
        assert_eq!(s.end_step, Some(10));
        let e = Schedule::parse("speed_furlongs\n1\n", "t.csv")
            .unwrap_err()
            .to_string();
        assert!(e.contains("t.csv") && e.contains("speed_furlongs"), "{e}");
        let e = Schedule::parse("step,speed_km_per_h\n0,8\n1,abc\n", "t.csv")
            .unwrap_err()
            .to_string();
        assert!(e.contains("row 2") && e.contains("abc"), "{e}");
    }
}
