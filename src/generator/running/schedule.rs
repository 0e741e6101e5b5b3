//! Per-step parameter schedules: a CSV file that sets the running parameters step by step
//! ("accelerate from 8 to 20 km/h, then stop"), and value-with-unit parsing for the command
//! line (`12km/h`, `3.3m/s`, `200m/min`, `187/min`, `1.07m`, `4mm`, `15deg`).
//!
//! # Schedule CSV
//! One row per change, columns (all optional except at least one parameter or `action`):
//! - `step`: the step (0 = the first, from standing) at which the row takes effect; without
//!   the column, data row *i* applies at step *i*. Steps must not decrease.
//! - `speed_km_per_h` | `speed_m_per_s` | `speed_m_per_min`
//! - `step_length_m` | `step_length_cm` | `step_length_mm`
//! - `step_freq_steps_per_min` | `step_freq_hz` | `step_freq_steps_per_s`
//! - `flight_height_m` | `flight_height_cm` | `flight_height_mm`
//! - `level`: expertise, −1 (poor) … 1 (skilled)
//! - `action`: `run` (default) or `stop` (decelerate and end in a stand)
//!
//! Empty cells leave a parameter as it is. The parameters given in one row are applied in
//! column order, each held fixed while the next is set (so `speed` and `step_freq` together fix
//! the step length by eq. 1), through the same coupling as interactive changes
//! ([`super::params::RunModel::set`]); the parameter locks of the run still apply.
use std::path::Path;

use super::params::Param;
use crate::generator::GenerateError;
use crate::units::{parse_header, Dimension, Quantity, Unit};

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
    /// Line in the file (1-based, header = 1).
    pub line: usize,
}

/// A per-step schedule.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct Schedule {
    /// Rows in step order.
    pub rows: Vec<ScheduleRow>,
    /// Where it came from (for messages).
    pub source: String,
}

fn input_err(path: &str, message: String) -> GenerateError {
    GenerateError::Input {
        path: path.into(),
        message,
    }
}

impl Schedule {
    /// Reads a schedule CSV file.
    pub fn from_csv(path: &Path) -> Result<Schedule, GenerateError> {
        let text = std::fs::read_to_string(path).map_err(|e| {
            input_err(
                &path.display().to_string(),
                format!("cannot read the schedule: {e}"),
            )
        })?;
        Schedule::parse(&text, &path.display().to_string())
    }

    /// Parses schedule CSV text (`source` names it in messages).
    pub fn parse(text: &str, source: &str) -> Result<Schedule, GenerateError> {
        let mut rdr = csv::ReaderBuilder::new()
            .trim(csv::Trim::All)
            .from_reader(text.as_bytes());
        let headers = rdr
            .headers()
            .map_err(|e| input_err(source, format!("line 1: cannot read the header: {e}")))?
            .clone();
        #[derive(Clone, Copy)]
        enum Col {
            Step,
            Level,
            Action,
            Param(Param, f64),
        }
        let mut cols = Vec::with_capacity(headers.len());
        for h in headers.iter() {
            let col = match h {
                "step" => Col::Step,
                "level" => Col::Level,
                "action" => Col::Action,
                _ => {
                    let c = parse_header(h)
                        .map_err(|u| input_err(source, format!("line 1, column `{h}`: unknown unit; use {}", u.accepted())))?
                        .ok_or_else(|| {
                            input_err(
                                source,
                                format!(
                                    "line 1, column `{h}`: not a schedule column (step, speed_*, step_length_*, step_freq_*, flight_height_*, level, action)"
                                ),
                            )
                        })?;
                    let p = match c.quantity {
                        Quantity::Speed => Param::Speed,
                        Quantity::StepLength => Param::StepLength,
                        Quantity::StepFreq => Param::StepFreq,
                        Quantity::FlightHeight => Param::FlightHeight,
                        _ => {
                            return Err(input_err(
                                source,
                                format!("line 1, column `{h}`: a schedule sets speed, step length, step frequency, flight height, level or action"),
                            ))
                        }
                    };
                    Col::Param(p, c.unit.to_si_factor())
                }
            };
            cols.push(col);
        }
        let mut rows: Vec<ScheduleRow> = Vec::new();
        for (i, rec) in rdr.records().enumerate() {
            let line = i + 2;
            let rec = rec.map_err(|e| input_err(source, format!("line {line}: {e}")))?;
            let mut row = ScheduleRow {
                step: i,
                set: Vec::new(),
                level: None,
                stop: false,
                line,
            };
            for (cell, (col, name)) in rec.iter().zip(cols.iter().zip(headers.iter())) {
                if cell.is_empty() {
                    continue;
                }
                let num = || {
                    cell.parse::<f64>()
                        .ok()
                        .filter(|v| v.is_finite())
                        .ok_or_else(|| {
                            input_err(
                                source,
                                format!("line {line}, column `{name}`: {cell:?} is not a number"),
                            )
                        })
                };
                match *col {
                    Col::Step => {
                        let v = num()?;
                        if v < 0.0 || v.fract() != 0.0 {
                            return Err(input_err(source, format!("line {line}, column `step`: {cell:?} is not a step index (0, 1, 2, …)")));
                        }
                        row.step = v as usize;
                    }
                    Col::Level => {
                        let v = num()?;
                        if !(-1.0..=1.0).contains(&v) {
                            return Err(input_err(source, format!("line {line}, column `level`: {v} is outside [−1, 1]")));
                        }
                        row.level = Some(v);
                    }
                    Col::Action => match cell.to_ascii_lowercase().as_str() {
                        "run" => {}
                        "stop" => row.stop = true,
                        _ => return Err(input_err(source, format!("line {line}, column `action`: {cell:?} is neither `run` nor `stop`"))),
                    },
                    Col::Param(p, factor) => {
                        let v = num()? * factor;
                        if v <= 0.0 {
                            return Err(input_err(source, format!("line {line}, column `{name}`: must be positive")));
                        }
                        row.set.push((p, v));
                    }
                }
            }
            if let Some(prev) = rows.last() {
                if row.step < prev.step {
                    return Err(input_err(
                        source,
                        format!("line {line}: step {} comes before the previous row's step {}; sort the rows by step", row.step, prev.step),
                    ));
                }
            }
            rows.push(row);
        }
        Ok(Schedule {
            rows,
            source: source.into(),
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

/// Parses a value with an optional unit into SI for `dim`: speed (`12km/h`, `3.3m/s`,
/// `200m/min`; bare = m/s), length (`1.07m`, `107cm`, `4mm`; bare = m), step frequency
/// (`187/min`, `187spm`, `187steps/min`, `3.1Hz`, `3.1/s`; bare = steps/min), angle (`15deg`,
/// `0.26rad`; bare = degrees).
pub fn parse_value(text: &str, dim: Dimension) -> Result<f64, String> {
    let t: String = text.trim().chars().filter(|c| !c.is_whitespace()).collect();
    let split = t
        .char_indices()
        .find(|(i, c)| {
            !(c.is_ascii_digit()
                || *c == '.'
                || *c == '-'
                || *c == '+'
                || ((*c == 'e' || *c == 'E')
                    && *i > 0
                    && t[i + 1..].starts_with(|d: char| d.is_ascii_digit() || d == '-')))
        })
        .map(|(i, _)| i)
        .unwrap_or(t.len());
    let (num, unit) = t.split_at(split);
    let v: f64 = num
        .parse()
        .map_err(|_| format!("{text:?}: no number at the start"))?;
    if !v.is_finite() {
        return Err(format!("{text:?}: not a finite number"));
    }
    let u = unit.to_ascii_lowercase();
    let factor = match (dim, u.as_str()) {
        (Dimension::Speed, "" | "m/s" | "mps") => Unit::MPerS.to_si_factor(),
        (Dimension::Speed, "km/h" | "kmh" | "kph") => Unit::KmPerH.to_si_factor(),
        (Dimension::Speed, "m/min") => Unit::MPerMin.to_si_factor(),
        (Dimension::Length, "" | "m") => 1.0,
        (Dimension::Length, "cm") => 0.01,
        (Dimension::Length, "mm") => 0.001,
        (Dimension::Frequency, "" | "/min" | "spm" | "steps/min" | "steps_per_min") => {
            Unit::StepsPerMin.to_si_factor()
        }
        (Dimension::Frequency, "hz" | "/s" | "steps/s") => 1.0,
        (Dimension::Angle, "" | "deg" | "°") => std::f64::consts::PI / 180.0,
        (Dimension::Angle, "rad") => 1.0,
        (Dimension::Time, "" | "s") => 1.0,
        (Dimension::Time, "ms") => 0.001,
        _ => {
            let ok = match dim {
                Dimension::Speed => "km/h, m/s, m/min",
                Dimension::Length => "m, cm, mm",
                Dimension::Frequency => "/min (steps/min), Hz (steps/s)",
                Dimension::Angle => "deg, rad",
                Dimension::Time => "s, ms",
                Dimension::PercentCycle => "%",
            };
            return Err(format!("{text:?}: unknown unit {unit:?}; use {ok}"));
        }
    };
    Ok(v * factor)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn values_with_units() {
        assert!((parse_value("12km/h", Dimension::Speed).unwrap() - 12.0 / 3.6).abs() < 1e-12);
        assert!((parse_value("3.3m/s", Dimension::Speed).unwrap() - 3.3).abs() < 1e-12);
        assert!((parse_value("200m/min", Dimension::Speed).unwrap() - 200.0 / 60.0).abs() < 1e-12);
        assert!(
            (parse_value("187/min", Dimension::Frequency).unwrap() - 187.0 / 60.0).abs() < 1e-12
        );
        assert!((parse_value("3.1Hz", Dimension::Frequency).unwrap() - 3.1).abs() < 1e-12);
        assert!((parse_value("4mm", Dimension::Length).unwrap() - 0.004).abs() < 1e-12);
        assert!((parse_value("1e-3m", Dimension::Length).unwrap() - 0.001).abs() < 1e-15);
        assert!(parse_value("12 furlongs", Dimension::Speed).is_err());
        assert!(parse_value("fast", Dimension::Speed).is_err());
    }

    #[test]
    fn schedule_rows_and_errors() {
        let s = Schedule::parse("speed_km_per_h,action\n8,\n12,\n,stop\n", "t.csv").unwrap();
        assert_eq!(s.rows.len(), 3);
        assert_eq!(s.rows[1].step, 1);
        assert_eq!(s.rows[1].set.len(), 1);
        assert_eq!(s.rows[1].set[0].0, Param::Speed);
        assert!((s.rows[1].set[0].1 - 12.0 / 3.6).abs() < 1e-12);
        assert!(s.rows[2].stop && s.stops());
        let e = Schedule::parse("speed_furlongs\n1\n", "t.csv")
            .unwrap_err()
            .to_string();
        assert!(e.contains("t.csv") && e.contains("speed_furlongs"), "{e}");
        let e = Schedule::parse("speed_km_per_h\nabc\n", "t.csv")
            .unwrap_err()
            .to_string();
        assert!(e.contains("line 2") && e.contains("abc"), "{e}");
        let e = Schedule::parse("step,speed_km_per_h\n3,8\n1,9\n", "t.csv")
            .unwrap_err()
            .to_string();
        assert!(e.contains("line 3"), "{e}");
    }
}
