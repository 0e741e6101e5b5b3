//! `walk-tds-sf`: double-support time from step frequency in walking, Bruderlin & Calvert
//! (1989) §3 (state-phase timings).
//!
//! ```text
//! t_ds = (d1·sf + d0) · t_cycle / 100,   t_cycle = 2 / sf
//! ⇔ 100 · t_ds / t_cycle = d0 + d1 · sf
//! ```
//! sf in steps/min, t_ds in s (one double-support period: each step has one); published
//! d0 = 29.08 %, d1 = −0.16 % per step/min. The fit's response is the double support of one step
//! as a percentage of the cycle (`double_support_pct_cycle`).
//!
//! ```
//! use gaitfit::relations::WalkTdsSf;
//! let w = WalkTdsSf::published();
//! assert!((w.double_support_pct(107.6) - 11.864).abs() < 1e-9);
//! // t_ds at 120 steps/min: (29.08 − 19.2) % of a 1 s cycle = 0.0988 s.
//! assert!((w.double_support_time(120.0) - 0.0988).abs() < 1e-12);
//! ```
use super::{expect_id, linear_gradient, required, Card, Citation, CoefficientSet, Domain, FittedRange, Inputs, Observation, Output, ParamKind, ParameterSpec, Rejection, Relation, RelationError, Variable};
use crate::gait::Gait;
use crate::ingest::trials::FieldValues;
use crate::units::{hz_to_steps_per_min, Quantity};
use std::collections::BTreeMap;
use std::path::Path;

const PARAMS: &[ParameterSpec] = &[
    ParameterSpec {
        name: "d0",
        unit: "% of cycle",
        published: 29.08,
        cited: true,
        kind: ParamKind::Linear,
        description: "intercept",
    },
    ParameterSpec {
        name: "d1",
        unit: "% of cycle per step/min",
        published: -0.16,
        cited: true,
        kind: ParamKind::Linear,
        description: "slope on step frequency",
    },
];

const INPUTS: &[Variable] = &[Variable {
    symbol: "sf",
    unit: "steps/min",
    name: "step frequency",
}];

/// The walking double-support relation t_ds/t_cycle·100 = d0 + d1·sf.
#[derive(Debug, Clone, PartialEq)]
pub struct WalkTdsSf {
    values: Vec<f64>,
    levels: BTreeMap<String, f64>,
    /// The fitted input range (from a fits file; empty otherwise).
    range: FittedRange,
}

impl WalkTdsSf {
    /// The id.
    pub const ID: &'static str = "walk-tds-sf";

    /// The published coefficients d0 = 29.08, d1 = −0.16.
    pub fn published() -> Self {
        Self::new(29.08, -0.16)
    }
    /// Explicit coefficients.
    pub fn new(d0: f64, d1: f64) -> Self {
        WalkTdsSf {
            values: vec![d0, d1],
            levels: BTreeMap::new(),
            range: FittedRange::default(),
        }
    }
    /// From a coefficient set.
    pub fn from_coefficients(set: &CoefficientSet) -> Result<Self, RelationError> {
        let (values, levels) = set.split(PARAMS, None)?;
        Ok(WalkTdsSf {
            values,
            levels,
            range: FittedRange::of(set, INPUTS),
        })
    }
    /// From `fits/walk-tds-sf.json`.
    pub fn from_fit_file(path: &Path) -> Result<Self, RelationError> {
        let set = CoefficientSet::from_fit_file(path)?;
        expect_id(&set, Self::ID, path)?;
        Self::from_coefficients(&set)
    }
    /// d0, % of cycle.
    pub fn d0(&self) -> f64 {
        self.values[0]
    }
    /// d1, % of cycle per step/min.
    pub fn d1(&self) -> f64 {
        self.values[1]
    }
    /// One double-support period as a percentage of the cycle at `sf` (steps/min).
    pub fn double_support_pct(&self, sf: f64) -> f64 {
        self.d0() + self.d1() * sf
    }
    /// One double-support period t_ds in s at `sf` (steps/min), with t_cycle = 2/sf.
    pub fn double_support_time(&self, sf: f64) -> f64 {
        let t_cycle_s = 2.0 / (sf / 60.0);
        self.double_support_pct(sf) * t_cycle_s / 100.0
    }
}

/// What the relation is.
static CARD: Card = Card {
    id: WalkTdsSf::ID,
    title: "Walking: double support (% of cycle) from step frequency",
    citation: Citation {
            paper: "Bruderlin & Calvert (1989), Goal-directed, dynamic animation of human walking",
            equation: "t_ds formula (§3, state-phase timings)",
        },
    equation: "100·t_ds/t_cycle = d0 + d1·sf",
    response: Variable {
            symbol: "t_ds/t_cycle",
            unit: "%",
            name: "double support (one step) as % of the cycle",
        },
    inputs: INPUTS,
    outputs: &[Output {
        name: "t_ds/t_cycle",
        label: "t_ds/t_cycle",
    }],
    gait: Gait::Walk,
    needs: &[Quantity::StepFreq, Quantity::DoubleSupportPct],
    parameters: PARAMS,
    subject_effect: None,
    has_intercept: true,
    domain: Domain {
            input: "sf",
            lo: 0.0,
            hi: 182.0,
            note: "walking; t_ds vanishes (walk → run) at sf = 181.75 steps/min with the published values",
        },
};

impl Relation for WalkTdsSf {
    fn card(&self) -> &'static Card {
        &CARD
    }
    fn observe(&self, row: &FieldValues, _output: usize) -> Result<Observation, Rejection> {
        let sf = required(row, Quantity::StepFreq)?;
        let pct = required(row, Quantity::DoubleSupportPct)?;
        Ok(Observation {
            x: Inputs::new(&[hz_to_steps_per_min(sf), 0.0, 0.0, 0.0]),
            y: pct,
        })
    }
    fn raw_basis(&self, _p: &[f64], x: &Inputs, g: &mut [f64]) {
        g[0] = 1.0;
        g[1] = x[0];
    }
    fn gradient(&self, p: &[f64], x: &Inputs) -> Option<Vec<f64>> {
        Some(linear_gradient(self, p, x))
    }
}
