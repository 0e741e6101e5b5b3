//! `walk-sl-sf`: the walking normalising formula, Bruderlin & Calvert (1989) §3, eq. 1
//! (after Inman).
//!
//! ```text
//! sl / (sf · h) = k          ⇔   sl = k · sf · h          (through the origin)
//! ⇔ sf² = v / (k · h)        because sl = v / sf
//! ```
//! sl and body height h in m, sf in steps/min, v in m/min; published k = 0.004 (m per
//! step/min per m of body height). The fit has no intercept, so its r² is the **uncentred** one,
//! 1 − RSS/Σy², as NIST StRD defines it for regressions through the origin (reported as such).
//!
//! ```
//! use gaitfit::relations::WalkSlSf;
//! let w = WalkSlSf::published();
//! // 5 km/h at h = 1.8 m: sf = √(83.33/(0.004·1.8)) = 107.6 steps/min, sl = 0.775 m.
//! let v = 5000.0 / 60.0;
//! assert!((w.step_freq_for_speed(v, 1.8) - 107.58).abs() < 0.01);
//! assert!((w.step_length_for_speed(v, 1.8) - 0.7746).abs() < 0.0005);
//! ```
use super::{expect_id, linear_gradient, required, Card, Citation, CoefficientSet, Domain, FittedRange, Inputs, Observation, Output, ParamKind, ParameterSpec, Rejection, Relation, RelationError, Variable};
use crate::gait::Gait;
use crate::ingest::trials::FieldValues;
use crate::units::{hz_to_steps_per_min, Quantity};
use std::collections::BTreeMap;
use std::path::Path;

const PARAMS: &[ParameterSpec] = &[ParameterSpec {
    name: "k",
    unit: "m per (step/min · m)",
    published: 0.004,
    cited: true,
    kind: ParamKind::Linear,
    description: "step length per step frequency per body height",
}];

const INPUTS: &[Variable] = &[
    Variable {
        symbol: "sf",
        unit: "steps/min",
        name: "step frequency",
    },
    Variable {
        symbol: "h",
        unit: "m",
        name: "body height",
    },
];

/// The walking normalising formula sl = k·sf·h (eq. 1).
#[derive(Debug, Clone, PartialEq)]
pub struct WalkSlSf {
    values: Vec<f64>,
    levels: BTreeMap<String, f64>,
    /// The fitted input range (from a fits file; empty otherwise).
    range: FittedRange,
}

impl WalkSlSf {
    /// The id.
    pub const ID: &'static str = "walk-sl-sf";

    /// The published coefficient k = 0.004.
    pub fn published() -> Self {
        Self::new(0.004)
    }
    /// An explicit k.
    pub fn new(k: f64) -> Self {
        WalkSlSf {
            values: vec![k],
            levels: BTreeMap::new(),
            range: FittedRange::default(),
        }
    }
    /// From a coefficient set.
    pub fn from_coefficients(set: &CoefficientSet) -> Result<Self, RelationError> {
        let (values, levels) = set.split(PARAMS, None)?;
        Ok(WalkSlSf {
            values,
            levels,
            range: FittedRange::of(set, INPUTS),
        })
    }
    /// From `fits/walk-sl-sf.json`.
    pub fn from_fit_file(path: &Path) -> Result<Self, RelationError> {
        let set = CoefficientSet::from_fit_file(path)?;
        expect_id(&set, Self::ID, path)?;
        Self::from_coefficients(&set)
    }
    /// The coefficient k.
    pub fn k(&self) -> f64 {
        self.values[0]
    }
    /// Step length (m) at step frequency `sf` (steps/min) for body height `h` (m).
    pub fn step_length(&self, sf: f64, h: f64) -> f64 {
        self.k() * sf * h
    }
    /// Step frequency (steps/min) at step length `sl` (m).
    pub fn step_freq(&self, sl: f64, h: f64) -> f64 {
        sl / (self.k() * h)
    }
    /// The "natural" step frequency (steps/min) at speed `v` (m/min): √(v/(k·h)).
    pub fn step_freq_for_speed(&self, v: f64, h: f64) -> f64 {
        (v / (self.k() * h)).sqrt()
    }
    /// The "natural" step length (m) at speed `v` (m/min): v / sf.
    pub fn step_length_for_speed(&self, v: f64, h: f64) -> f64 {
        v / self.step_freq_for_speed(v, h)
    }
}

/// What the relation is.
static CARD: Card = Card {
    id: WalkSlSf::ID,
    title: "Walking: step length from step frequency and body height (normalising formula)",
    citation: Citation {
            paper: "Bruderlin & Calvert (1989), Goal-directed, dynamic animation of human walking",
            equation: "eq. 1 (§3)",
        },
    equation: "sl = k·sf·h (through the origin)",
    response: Variable {
            symbol: "sl",
            unit: "m",
            name: "step length",
        },
    inputs: INPUTS,
    outputs: &[Output {
        name: "sl",
        label: "sl",
    }],
    gait: Gait::Walk,
    needs: &[
            Quantity::StepLength,
            Quantity::StepFreq,
            Quantity::BodyHeight,
        ],
    parameters: PARAMS,
    subject_effect: None,
    has_intercept: false,
    domain: Domain {
            input: "sf",
            lo: 0.0,
            hi: 182.0,
            note: "KLAW's anatomical limit sf_max = 182 steps/min (§3)",
        },
};

impl Relation for WalkSlSf {
    fn card(&self) -> &'static Card {
        &CARD
    }
    fn observe(&self, row: &FieldValues, _output: usize) -> Result<Observation, Rejection> {
        let sl = required(row, Quantity::StepLength)?;
        let sf = required(row, Quantity::StepFreq)?;
        let h = required(row, Quantity::BodyHeight)?;
        Ok(Observation {
            x: Inputs::new(&[hz_to_steps_per_min(sf), h, 0.0, 0.0]),
            y: sl,
        })
    }
    fn raw_basis(&self, _p: &[f64], x: &Inputs, g: &mut [f64]) {
        g[0] = x[0] * x[1];
    }
    fn gradient(&self, p: &[f64], x: &Inputs) -> Option<Vec<f64>> {
        Some(linear_gradient(self, p, x))
    }
}
