//! KLAW's reading of the shared per-step schedule ([`crate::generator::schedule`]): each row's
//! speed, step length and step frequency as [`ScheduleEntry`] stretches. The shared reader knows
//! no generator; each generator turns its rows into its own terms (RUNNER's in
//! `running::schedule`).
use super::{ScheduleEntry, WalkParams};
use crate::generator::schedule::{Action, Schedule, ScheduleRow};
use crate::generator::GenerateError;
use crate::units::Quantity;

/// KLAW's locomotion parameters of one row (those given; eq. 1 completes the others).
pub fn walk_params(r: &ScheduleRow) -> WalkParams {
    WalkParams {
        speed_m_per_s: r.get(Quantity::Speed),
        step_length_m: r.get(Quantity::StepLength),
        step_freq_steps_per_min: r
            .get(Quantity::StepFreq)
            .map(crate::units::hz_to_steps_per_min),
    }
}

/// A walk's schedule in KLAW's terms ([`Schedule::walk`]).
#[derive(Debug, Clone, PartialEq)]
pub struct WalkSchedule {
    /// The stretches, in order.
    pub entries: Vec<ScheduleEntry>,
    /// The last row asks for a stop.
    pub stop: bool,
}

impl Schedule {
    /// KLAW's stretches: each row's speed, step length and step frequency (those given; eq. 1
    /// completes the others) for the steps it holds. Steps before the first row walk with
    /// `before` (the command line's parameters); the last row holds until `total` steps when the
    /// schedule has no length of its own. A `stop` may only be on the last row.
    pub fn walk(
        &self,
        total: Option<usize>,
        before: WalkParams,
    ) -> Result<WalkSchedule, GenerateError> {
        self.accept_only(
            "generate walk",
            &[Quantity::Speed, Quantity::StepLength, Quantity::StepFreq],
            false,
            true,
        )?;
        if let Some(r) = self
            .rows
            .iter()
            .rev()
            .skip(1)
            .find(|r| r.action == Action::Stop)
        {
            return Err(GenerateError::Input {
                path: self.source.clone(),
                message: format!(
                    "row {}, column action: a walk stops at its end; put stop on the last row",
                    r.row
                ),
            });
        }
        let mut entries = Vec::new();
        let first = self.rows.first().map_or(0, |r| r.step);
        let end = self.length().or(total);
        if first > 0 {
            entries.push(ScheduleEntry {
                params: before,
                steps: end.map_or(first, |e| first.min(e)),
            });
        }
        for (r, n) in self.stretches(total)? {
            entries.push(ScheduleEntry {
                params: walk_params(r),
                steps: n,
            });
        }
        Ok(WalkSchedule {
            entries,
            stop: self.stops(),
        })
    }
}
