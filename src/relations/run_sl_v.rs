//! `run-sl-v`: step length from speed in running, Bruderlin & Calvert (1996) §2.2, eq. 2.
//!
//! ```text
//! sl = a + (b + level) · v · √(h/1.8)            for v ≤ v_norm · √(h/1.8)
//! sl = a + (b + level) · v_norm · (h/1.8)        above (sl_norm: only sf increases)
//! ```
//! sl in m, v in m/min, body height h in m; published a = 0.1394 m, b = 0.00465 m per m/min,
//! v_norm = 400 m/min (for h = 1.8 m), −0.001 ≤ level ≤ 0.001 (poor … skilled runner). The
//! paper derived a and b by linear regression on n = 80 pairs with v ≤ 400 m/min (r² = 0.94442).
//!
//! Decision (the paper is not explicit): the plateau starts where the Froude-scaled speed
//! reaches v_norm, i.e. at v = v_norm·√(h/1.8), and the step length stays at its value there, so
//! the curve is continuous. Tested in `tests/reference_run_sl_v.rs`.
//!
//! ```
//! use gaitfit::relations::RunSlV;
//! let r = RunSlV::published();
//! // Running paper §3.1 (Figure 4): at 12 km/h the chosen step length is 1.07 m, 187 steps/min.
//! assert!((r.step_length(200.0, 1.8, 0.0) - 1.0694).abs() < 1e-9);
//! assert!((r.step_freq(200.0, 1.8, 0.0) - 187.02).abs() < 0.01);
//! ```
use super::{expect_id, linear_gradient, required, Card, Citation, CoefficientSet, Domain, FittedRange, Inputs, Observation, Output, ParamKind, ParameterSpec, Rejection, Relation, RelationError, SubjectEffect, Variable};
use crate::gait::Gait;
use crate::ingest::trials::FieldValues;
use crate::units::{m_per_s_to_m_per_min, Quantity};
use std::collections::BTreeMap;
use std::path::Path;

/// The reference body height of the running paper's normalisation, m.
pub const REFERENCE_HEIGHT_M: f64 = 1.8;

const PARAMS: &[ParameterSpec] = &[
    ParameterSpec {
        name: "a",
        unit: "m",
        published: 0.1394,
        cited: true,
        kind: ParamKind::Linear,
        description: "intercept",
    },
    ParameterSpec {
        name: "b",
        unit: "m per m/min",
        published: 0.00465,
        cited: true,
        kind: ParamKind::Linear,
        description: "slope on the height-normalised speed v·√(h/1.8)",
    },
    ParameterSpec {
        name: "v_norm",
        unit: "m/min",
        published: 400.0,
        cited: true,
        kind: ParamKind::Breakpoint,
        description: "speed (at h = 1.8 m) above which step length stays constant",
    },
];

const INPUTS: &[Variable] = &[
    Variable {
        symbol: "v",
        unit: "m/min",
        name: "speed",
    },
    Variable {
        symbol: "h",
        unit: "m",
        name: "body height",
    },
];

/// The running step length–speed relation (eq. 2) with its plateau above `v_norm`.
#[derive(Debug, Clone, PartialEq)]
pub struct RunSlV {
    values: Vec<f64>,
    levels: BTreeMap<String, f64>,
    /// The fitted input range (from a fits file; empty otherwise).
    range: FittedRange,
}

impl RunSlV {
    /// The id.
    pub const ID: &'static str = "run-sl-v";

    /// The published coefficients (a = 0.1394, b = 0.00465, v_norm = 400).
    pub fn published() -> Self {
        RunSlV {
            values: PARAMS.iter().map(|p| p.published).collect(),
            levels: BTreeMap::new(),
            range: FittedRange::default(),
        }
    }
    /// Explicit coefficients.
    pub fn new(a: f64, b: f64, v_norm: f64) -> Self {
        RunSlV {
            values: vec![a, b, v_norm],
            levels: BTreeMap::new(),
            range: FittedRange::default(),
        }
    }
    /// From a coefficient set (e.g. a fits file's).
    pub fn from_coefficients(set: &CoefficientSet) -> Result<Self, RelationError> {
        let (values, levels) = set.split(PARAMS, Some(LEVEL))?;
        Ok(RunSlV {
            values,
            levels,
            range: FittedRange::of(set, INPUTS),
        })
    }
    /// From `fits/run-sl-v.json` written by `gaitfit fit`.
    pub fn from_fit_file(path: &Path) -> Result<Self, RelationError> {
        let set = CoefficientSet::from_fit_file(path)?;
        expect_id(&set, Self::ID, path)?;
        Self::from_coefficients(&set)
    }
    /// Intercept a, m.
    pub fn a(&self) -> f64 {
        self.values[0]
    }
    /// Slope b, m per m/min.
    pub fn b(&self) -> f64 {
        self.values[1]
    }
    /// Plateau onset v_norm at h = 1.8 m, m/min.
    pub fn v_norm(&self) -> f64 {
        self.values[2]
    }
    /// The fitted level of `subject` (0 when unknown).
    pub fn level(&self, subject: &str) -> f64 {
        self.levels.get(subject).copied().unwrap_or(0.0)
    }

    /// Step length (m) at speed `v` (m/min) for body height `h` (m) and expertise `level`.
    pub fn step_length(&self, v: f64, h: f64, level: f64) -> f64 {
        sl(&self.values, level, v, h)
    }
    /// Step frequency (steps/min) = v / sl (eq. 1).
    pub fn step_freq(&self, v: f64, h: f64, level: f64) -> f64 {
        v / self.step_length(v, h, level)
    }
    /// The plateau step length sl_norm (m) for body height `h`.
    pub fn sl_norm(&self, h: f64, level: f64) -> f64 {
        let r2 = h / REFERENCE_HEIGHT_M;
        self.a() + (self.b() + level) * self.v_norm() * r2
    }
    /// The speed (m/min) at which the relation gives step frequency `sf` (steps/min), solving
    /// v = sl(v)·sf; `None` when no speed gives that frequency (sf too high for the linear part
    /// and below the plateau's).
    pub fn speed_for_step_freq(&self, sf: f64, h: f64, level: f64) -> Option<f64> {
        let r = (h / REFERENCE_HEIGHT_M).sqrt();
        let (a, b) = (self.a(), self.b() + level);
        let den = 1.0 - b * r * sf;
        if den > 0.0 {
            let v = a * sf / den;
            if v <= self.v_norm() * r && v >= 0.0 {
                return Some(v);
            }
        }
        let v = self.sl_norm(h, level) * sf;
        (v >= self.v_norm() * r).then_some(v)
    }
    /// The speed (m/min) at which the relation gives step length `sl` (m) below the plateau.
    pub fn speed_for_step_length(&self, sl: f64, h: f64, level: f64) -> Option<f64> {
        let r = (h / REFERENCE_HEIGHT_M).sqrt();
        let v = (sl - self.a()) / ((self.b() + level) * r);
        (v >= 0.0 && v <= self.v_norm() * r).then_some(v)
    }
}

const LEVEL: SubjectEffect = SubjectEffect {
    name: "level",
    on: "b",
    paper_bound: 0.001,
    unit: "m per m/min",
};

/// The regressor z = min(v, v_norm·r)·r with r = √(h/1.8).
fn z(v_norm: f64, v: f64, h: f64) -> f64 {
    let r = (h / REFERENCE_HEIGHT_M).sqrt();
    v.min(v_norm * r) * r
}

fn sl(p: &[f64], level: f64, v: f64, h: f64) -> f64 {
    p[0] + (p[1] + level) * z(p[2], v, h)
}

/// What the relation is.
static CARD: Card = Card {
    id: RunSlV::ID,
    title: "Running: step length from speed (Froude-normalised, with plateau)",
    citation: Citation {
            paper: "Bruderlin & Calvert (1996), Knowledge-driven, interactive animation of human running",
            equation: "eq. 2 and v_norm (§2.2)",
        },
    equation: "sl = a + (b + level)·min(v, v_norm·√(h/1.8))·√(h/1.8)",
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
    gait: Gait::Run,
    needs: &[Quantity::Speed, Quantity::StepLength, Quantity::BodyHeight],
    parameters: PARAMS,
    subject_effect: Some(LEVEL),
    has_intercept: true,
    domain: Domain {
            input: "v",
            lo: 0.0,
            hi: 400.0,
            note: "regression data had v ≤ 400 m/min (n = 80, r² = 0.94442); constant above v_norm",
        },
};

impl Relation for RunSlV {
    fn card(&self) -> &'static Card {
        &CARD
    }
    fn observe(&self, row: &FieldValues, _output: usize) -> Result<Observation, Rejection> {
        let v = required(row, Quantity::Speed)?;
        let sl = required(row, Quantity::StepLength)?;
        let h = required(row, Quantity::BodyHeight)?;
        if h <= 0.0 {
            return Err(Rejection::Invalid(format!(
                "body height {h} m is not positive"
            )));
        }
        Ok(Observation {
            x: Inputs::new(&[m_per_s_to_m_per_min(v), h, 0.0, 0.0]),
            y: sl,
        })
    }
    fn raw_basis(&self, p: &[f64], x: &Inputs, g: &mut [f64]) {
        g[0] = 1.0;
        g[1] = z(p[2], x[0], x[1]);
    }
    fn gradient(&self, p: &[f64], x: &Inputs) -> Option<Vec<f64>> {
        let mut d = linear_gradient(self, p, x);
        let r = (x[1] / REFERENCE_HEIGHT_M).sqrt();
        // On the plateau sl = a + b·v_norm·r², so ∂sl/∂v_norm = b·r²; 0 below.
        d[2] = if x[0] > p[2] * r { p[1] * r * r } else { 0.0 };
        Some(d)
    }
    fn derived(&self, p: &[f64]) -> Vec<(String, f64, &'static str)> {
        let r = RunSlV::new(p[0], p[1], p[2]);
        vec![("sl_norm(h=1.8)".to_string(), r.sl_norm(1.8, 0.0), "m")]
    }
}
