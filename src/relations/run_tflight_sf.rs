//! `run-tflight-sf` / `run-tflight-sf-continuous`: flight time from step frequency in running,
//! Bruderlin & Calvert (1996) §2.2, eqs. 4–5.
//!
//! ```text
//! t_flight = q0 + q1·sf + q2·sf²                      sf < k1          (eq. 5)
//! t_flight = c0 + c1·sf + c2·sf² + c3·sf³             k1 ≤ sf ≤ k2     (eq. 4)
//! t_flight = c0 + c1·k2 + c2·k2² + c3·k2³             sf > k2          (kept constant)
//! ```
//! t_flight in s, sf in steps/min. Published: q0 = −0.675e-3, q1 = −0.15e-3, q2 = 0.542e-5;
//! c0 = −8.925, c1 = 0.131, c2 = −0.623e-3, c3 = 0.979e-6; k1 = 180, k2 = 230 steps/min. The
//! cubic was fitted on n = 20 pairs between about 160 and 230 steps/min (residual mean square
//! 0.00087); the quadratic is the authors' extrapolation "from experience".
//!
//! The paper says "from 0—180 steps/min, equation 5 is used; from 180—230, equation 4": at
//! exactly 180 both apply; we use the cubic from k1 on (sf ≥ k1). The published pieces do not
//! meet at k1 — quadratic 0.1479 s, cubic 0.1793 s, a jump of 0.0314 s. Two variants:
//! - [`Continuity::Free`] (`run-tflight-sf`): the paper's independent pieces;
//! - [`Continuity::Continuous`] (`run-tflight-sf-continuous`): fitted with the constraint
//!   quadratic(k1) = cubic(k1), so q0 is determined by the other coefficients.
//!
//! Both report the jump at k1 ([`RunTflightSf::jump_at_k1`]). The paper's `level` term
//! (±0.0001) is not fitted here (the issue's interface has no per-subject flight level).
//!
//! How the pieces are fitted (centred bases, continuity at k1, the knots' profile) is the fit's
//! business: `gaitfit::fit::forms::run_tflight_sf`.
//!
//! ```
//! use gaitfit::relations::RunTflightSf;
//! let r = RunTflightSf::published();
//! assert!((r.flight_time(187.0) - 0.188).abs() < 0.0005); // running paper §3.1
//! assert!((r.jump_at_k1() - 0.0314).abs() < 0.0005);
//! ```
use super::{expect_id, required, Card, Citation, CoefficientSet, Domain, FittedRange, Inputs, Observation, Output, ParamKind, ParameterSpec, Rejection, Relation, RelationError, Variable};
use crate::gait::Gait;
use crate::ingest::trials::FieldValues;
use crate::units::{hz_to_steps_per_min, Quantity};
use std::collections::BTreeMap;
use std::path::Path;

const PARAMS: &[ParameterSpec] = &[
    ParameterSpec {
        name: "q0",
        unit: "s",
        published: -0.675e-3,
        cited: true,
        kind: ParamKind::Linear,
        description: "quadratic piece (eq. 5), constant",
    },
    ParameterSpec {
        name: "q1",
        unit: "s per step/min",
        published: -0.15e-3,
        cited: true,
        kind: ParamKind::Linear,
        description: "quadratic piece, linear coefficient",
    },
    ParameterSpec {
        name: "q2",
        unit: "s per (step/min)²",
        published: 0.542e-5,
        cited: true,
        kind: ParamKind::Linear,
        description: "quadratic piece, quadratic coefficient",
    },
    ParameterSpec {
        name: "c0",
        unit: "s",
        published: -8.925,
        cited: true,
        kind: ParamKind::Linear,
        description: "cubic piece (eq. 4), constant",
    },
    ParameterSpec {
        name: "c1",
        unit: "s per step/min",
        published: 0.131,
        cited: true,
        kind: ParamKind::Linear,
        description: "cubic piece, linear coefficient",
    },
    ParameterSpec {
        name: "c2",
        unit: "s per (step/min)²",
        published: -0.623e-3,
        cited: true,
        kind: ParamKind::Linear,
        description: "cubic piece, quadratic coefficient",
    },
    ParameterSpec {
        name: "c3",
        unit: "s per (step/min)³",
        published: 0.979e-6,
        cited: true,
        kind: ParamKind::Linear,
        description: "cubic piece, cubic coefficient",
    },
    ParameterSpec {
        name: "k1",
        unit: "steps/min",
        published: 180.0,
        cited: true,
        kind: ParamKind::Breakpoint,
        description: "knot between the quadratic and the cubic piece",
    },
    ParameterSpec {
        name: "k2",
        unit: "steps/min",
        published: 230.0,
        cited: true,
        kind: ParamKind::Breakpoint,
        description: "step frequency above which the flight time is kept constant",
    },
];

const INPUTS: &[Variable] = &[Variable {
    symbol: "sf",
    unit: "steps/min",
    name: "step frequency",
}];

/// Whether the two pieces are fitted independently (as published) or joined at k1.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Continuity {
    /// The paper's independent pieces (they jump at k1).
    Free,
    /// Constrained so that the quadratic meets the cubic at k1.
    Continuous,
}

/// The running flight time–step frequency relation (eqs. 4–5).
#[derive(Debug, Clone, PartialEq)]
pub struct RunTflightSf {
    values: Vec<f64>,
    continuity: Continuity,
    levels: BTreeMap<String, f64>,
    /// The fitted input range (from a fits file; empty otherwise).
    range: FittedRange,
}

impl RunTflightSf {
    /// The id of the free-pieces variant.
    pub const ID: &'static str = "run-tflight-sf";
    /// The id of the continuous variant.
    pub const ID_CONTINUOUS: &'static str = "run-tflight-sf-continuous";

    /// The published coefficients, free pieces (the paper's form).
    pub fn published() -> Self {
        RunTflightSf {
            values: PARAMS.iter().map(|p| p.published).collect(),
            continuity: Continuity::Free,
            levels: BTreeMap::new(),
            range: FittedRange::default(),
        }
    }
    /// The published coefficients in the continuous variant (as published they still jump at
    /// k1; refits of this variant do not).
    pub fn published_continuous() -> Self {
        RunTflightSf {
            continuity: Continuity::Continuous,
            ..Self::published()
        }
    }
    /// Explicit coefficients `[q0, q1, q2, c0, c1, c2, c3, k1, k2]`.
    pub fn new(values: [f64; 9], continuity: Continuity) -> Self {
        RunTflightSf {
            values: values.to_vec(),
            continuity,
            levels: BTreeMap::new(),
            range: FittedRange::default(),
        }
    }
    /// From a coefficient set; the variant follows the set's relation id.
    pub fn from_coefficients(set: &CoefficientSet) -> Result<Self, RelationError> {
        let continuity = match set.relation.as_str() {
            Self::ID_CONTINUOUS => Continuity::Continuous,
            _ => Continuity::Free,
        };
        let (values, levels) = set.split(PARAMS, None)?;
        Ok(RunTflightSf {
            values,
            continuity,
            levels,
            range: FittedRange::of(set, INPUTS),
        })
    }
    /// From `fits/run-tflight-sf.json` or `fits/run-tflight-sf-continuous.json`.
    pub fn from_fit_file(path: &Path) -> Result<Self, RelationError> {
        let set = CoefficientSet::from_fit_file(path)?;
        if set.relation != Self::ID_CONTINUOUS {
            expect_id(&set, Self::ID, path)?;
        }
        Self::from_coefficients(&set)
    }
    /// The variant.
    pub fn continuity(&self) -> Continuity {
        self.continuity
    }
    /// Coefficients `[q0, q1, q2, c0, c1, c2, c3, k1, k2]`.
    pub fn coefficients(&self) -> &[f64] {
        &self.values
    }
    /// Flight time (s) at step frequency `sf` (steps/min). Coefficients read from a fits file
    /// hold the boundary value outside the fitted range of sf ([`super::FittedRange`]): the
    /// cubic is not followed where no step constrained it (the published coefficients keep the
    /// paper's pieces, constant beyond k2).
    pub fn flight_time(&self, sf: f64) -> f64 {
        tflight(&self.values, self.range.hold_input(0, sf))
    }
    /// Whether `sf` (steps/min) lies inside the fitted range (always true without one).
    pub fn in_fitted_range(&self, sf: f64) -> bool {
        self.range.contains(&[sf])
    }
    /// cubic(k1) − quadratic(k1), s: the discontinuity at the first knot.
    pub fn jump_at_k1(&self) -> f64 {
        jump(&self.values)
    }
}

/// Helper of the formula (also used by the fit form `fit::forms::run_tflight_sf`).
pub(crate) fn quad(p: &[f64], sf: f64) -> f64 {
    p[0] + sf * (p[1] + sf * p[2])
}
/// Helper of the formula (also used by the fit form `fit::forms::run_tflight_sf`).
pub(crate) fn cubic(p: &[f64], sf: f64) -> f64 {
    p[3] + sf * (p[4] + sf * (p[5] + sf * p[6]))
}
/// Helper of the formula (also used by the fit form `fit::forms::run_tflight_sf`).
pub(crate) fn tflight(p: &[f64], sf: f64) -> f64 {
    if sf < p[7] {
        quad(p, sf)
    } else {
        cubic(p, sf.min(p[8]))
    }
}
/// Helper of the formula (also used by the fit form `fit::forms::run_tflight_sf`).
pub(crate) fn jump(p: &[f64]) -> f64 {
    cubic(p, p[7]) - quad(p, p[7])
}

/// What the free-pieces variant is.
const CARD_FREE: Card = Card {
    id: RunTflightSf::ID,
    title: "Running: flight time from step frequency (paper's free pieces)",
    equation: "t_flight = q0 + q1·sf + q2·sf² (sf < k1); c0 + c1·s + c2·s² + c3·s³ with s = min(sf, k2) (sf ≥ k1)",
    ..CARD_CONTINUOUS
};

/// What the continuous variant is.
const CARD_CONTINUOUS: Card = Card {
    id: RunTflightSf::ID_CONTINUOUS,
    title: "Running: flight time from step frequency (continuous at k1)",
    citation: Citation {
        paper: "Bruderlin & Calvert (1996), Knowledge-driven, interactive animation of human running",
        equation: "eqs. 4–5 (§2.2)",
    },
    equation: "t_flight = q0 + q1·sf + q2·sf² (sf < k1); c0 + c1·s + c2·s² + c3·s³ with s = min(sf, k2) (sf ≥ k1); q0 set so the pieces meet at k1",
    response: Variable {
        symbol: "t_flight",
        unit: "s",
        name: "flight time",
    },
    inputs: INPUTS,
    outputs: &[Output {
        name: "t_flight",
        label: "t_flight",
    }],
    gait: Gait::Run,
    needs: &[Quantity::StepFreq, Quantity::FlightTime],
    parameters: PARAMS,
    subject_effect: None,
    has_intercept: true,
    domain: Domain {
        input: "sf",
        lo: 160.0,
        hi: 230.0,
        note: "the cubic's data ranged about 160–230 steps/min (n = 20); below 180 the quadratic is an extrapolation",
    },
};

impl Relation for RunTflightSf {
    fn card(&self) -> &'static Card {
        match self.continuity {
            Continuity::Free => &CARD_FREE,
            Continuity::Continuous => &CARD_CONTINUOUS,
        }
    }
    fn observe(&self, row: &FieldValues, _output: usize) -> Result<Observation, Rejection> {
        let sf = required(row, Quantity::StepFreq)?;
        let tf = required(row, Quantity::FlightTime)?;
        Ok(Observation {
            x: Inputs::new(&[hz_to_steps_per_min(sf)]),
            y: tf,
        })
    }
    fn raw_basis(&self, p: &[f64], x: &Inputs, g: &mut [f64]) {
        g[..7].fill(0.0);
        let sf = x[0];
        if sf < p[7] {
            g[0] = 1.0;
            g[1] = sf;
            g[2] = sf * sf;
        } else {
            let s = sf.min(p[8]);
            g[3] = 1.0;
            g[4] = s;
            g[5] = s * s;
            g[6] = s * s * s;
        }
    }
    fn predict_with(&self, p: &[f64], _subject_offset: f64, x: &Inputs) -> f64 {
        tflight(p, x[0])
    }
    fn gradient(&self, p: &[f64], x: &Inputs) -> Option<Vec<f64>> {
        let mut d = super::linear_gradient(self, p, x);
        // k1 moves a row between pieces (no derivative almost everywhere); k2 moves the plateau.
        if x[0] > p[8] && x[0] >= p[7] {
            let k2 = p[8];
            d[8] = p[4] + k2 * (2.0 * p[5] + 3.0 * k2 * p[6]);
        }
        Some(d)
    }
    fn derived(&self, p: &[f64]) -> Vec<(String, f64, &'static str)> {
        vec![
            ("jump_at_k1".to_string(), jump(p), "s"),
            ("t_flight(187)".to_string(), tflight(p, 187.0), "s"),
        ]
    }
}
