//! One row per event (`gaitfit events --events-out FILE`): what external tools need to score
//! gaitfit's events, and what the per-step table cannot hold (a toe off before the first heel
//! strike, the foot-marker phases).
//!
//! Columns: `subject`, `trial`, `time_s` (from the start of the trial), `side` (`left|right`),
//! `event` (`heel_strike|toe_off|foot_flat|heel_off|meta_off`), `method` (the event source:
//! `force`, `foot_speed`, …, see [`crate::gait::EventSource::as_str`]), `source` (the file). Rows are the
//! heel strikes and toe offs of the trial's primary source (the ones the steps are built from),
//! then the foot-marker phases of its stances, in time order.
use super::steps::{source_label, subject_label, Analysis};
use super::{EventError, EventKind, GaitEvent};
use crate::ingest::types::Trial;
use serde::{Deserialize, Serialize};
use std::io::Write;
use std::path::Path;

/// The column headers, in order.
pub const EVENT_COLUMNS: &[&str] = &[
    "subject", "trial", "time_s", "side", "event", "method", "source",
];

/// One event of one trial.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct EventRow {
    /// Subject id (as in the steps table).
    pub subject: String,
    /// Trial name.
    pub trial: String,
    /// The file (relative to the shared data folder when it lies there).
    pub source: String,
    /// The event.
    pub event: GaitEvent,
}

/// The primary events and foot phases of one analysed trial, in time order.
pub fn event_rows(trial: &Trial, an: &Analysis) -> Vec<EventRow> {
    let (subject, name, source) = (
        subject_label(trial),
        trial.name.clone(),
        source_label(trial),
    );
    let mut ev: Vec<GaitEvent> = an
        .events
        .primary_events()
        .iter()
        .filter(|e| matches!(e.kind, EventKind::HeelStrike | EventKind::ToeOff))
        .copied()
        .collect();
    // The phases' own toe off (from a distinct toe marker) would be a second toe off of one
    // stance: the primary one stands.
    ev.extend(
        an.events
            .phases
            .iter()
            .filter(|e| e.kind != EventKind::ToeOff)
            .copied(),
    );
    ev.sort_by(|a, b| a.time_s.total_cmp(&b.time_s).then(a.side.cmp(&b.side)));
    ev.into_iter()
        .map(|event| EventRow {
            subject: subject.clone(),
            trial: name.clone(),
            source: source.clone(),
            event,
        })
        .collect()
}

/// The CSV cells of one row, in [`EVENT_COLUMNS`] order (time to 0.1 ms).
fn cells(r: &EventRow) -> [String; 7] {
    [
        r.subject.clone(),
        r.trial.clone(),
        format!("{:.4}", r.event.time_s),
        r.event.side.to_string(),
        r.event.kind.as_str().to_string(),
        r.event.source.as_str().to_string(),
        r.source.clone(),
    ]
}

/// Writes event rows to `out` as CSV.
pub fn write_csv_to(out: &mut dyn Write, rows: &[EventRow]) -> std::io::Result<()> {
    let mut w = csv::Writer::from_writer(out);
    w.write_record(EVENT_COLUMNS)?;
    for r in rows {
        w.write_record(cells(r))?;
    }
    w.flush()?;
    Ok(())
}

/// Writes event rows to `path` atomically.
pub fn write_csv(path: &Path, rows: &[EventRow]) -> Result<(), EventError> {
    crate::fsio::write_atomic(path, |w| {
        write_csv_to(w, rows).map_err(|e| EventError::Write {
            path: path.display().to_string(),
            message: e.to_string(),
        })
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::gait::{EventSource, Side};

    #[test]
    fn rows_are_written_with_the_documented_columns() {
        let r = EventRow {
            subject: "S1".into(),
            trial: "T1".into(),
            source: "a/b.c3d".into(),
            event: GaitEvent {
                time_s: 1.23456,
                side: Side::Left,
                kind: EventKind::ToeOff,
                source: EventSource::FootSpeed,
            },
        };
        let mut buf = Vec::new();
        write_csv_to(&mut buf, &[r]).unwrap();
        let text = String::from_utf8(buf).unwrap();
        assert_eq!(
            text,
            "subject,trial,time_s,side,event,method,source\nS1,T1,1.2346,left,toe_off,foot_speed,a/b.c3d\n"
        );
    }
}
