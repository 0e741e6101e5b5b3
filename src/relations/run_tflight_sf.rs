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
//! The cubic in sf ≈ 200 is badly conditioned in the raw basis, so fits are solved in centred,
//! scaled bases u = (sf − m1)/s1 and w = (sf − m2)/s2 and mapped back to raw coefficients.
//!
//! ```
//! use gaitfit::relations::RunTflightSf;
//! let r = RunTflightSf::published();
//! assert!((r.flight_time(187.0) - 0.188).abs() < 0.0005); // running paper §3.1
//! assert!((r.jump_at_k1() - 0.0314).abs() < 0.0005);
//! ```
use super::{
    expect_id, required, sorted_keys, Citation, CoefficientSet, Domain, FeatureSums, FittedRange,
    KeyRange, KeyScale, KeySums, LinearMap, NormalEquations, Observation, ParamKind, ParameterSpec,
    Plan, Rejection, Relation, RelationError, SortedProfile, Variable,
};
use crate::events::Gait;
use crate::ingest::trials::FieldValues;
use crate::units::{hz_to_steps_per_min, Quantity};
use nalgebra::{DMatrix, DVector};
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

/// Minimum number of distinct step frequencies a piece needs to be fitted.
const MIN_DISTINCT: usize = 5;

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

fn quad(p: &[f64], sf: f64) -> f64 {
    p[0] + sf * (p[1] + sf * p[2])
}
fn cubic(p: &[f64], sf: f64) -> f64 {
    p[3] + sf * (p[4] + sf * (p[5] + sf * p[6]))
}
fn tflight(p: &[f64], sf: f64) -> f64 {
    if sf < p[7] {
        quad(p, sf)
    } else {
        cubic(p, sf.min(p[8]))
    }
}
fn jump(p: &[f64]) -> f64 {
    cubic(p, p[7]) - quad(p, p[7])
}

/// The centring of the fitting bases and which blocks are free.
struct Layout {
    qfree: bool,
    cfree: bool,
    continuous: bool,
    m1: f64,
    s1: f64,
    m2: f64,
    s2: f64,
}

impl Layout {
    fn new(p: &[f64], free: &[bool], continuity: Continuity) -> Layout {
        let k1 = p[7];
        // k2 = +∞ (the model without a plateau, tested against) would make the centring of the
        // cubic's basis infinite and every basis value NaN; any finite centring spans the same
        // cubics, so use the published gap.
        let k2 = if p[8].is_finite() { p[8] } else { k1 + 50.0 };
        let s2 = ((k2 - k1) / 2.0).abs().max(1.0);
        Layout {
            qfree: free[0],
            cfree: free[3],
            continuous: continuity == Continuity::Continuous,
            m1: k1 - 25.0,
            s1: 25.0,
            m2: (k1 + k2) / 2.0,
            s2,
        }
    }
    fn nb(&self) -> usize {
        match (self.qfree, self.cfree, self.continuous) {
            (true, true, false) => 7,
            (true, true, true) => 6,
            (false, true, false) => 4,
            (false, true, true) => 3,
            (true, false, false) => 3,
            (true, false, true) => 2,
            (false, false, _) => 0,
        }
    }
}

/// Raw coefficients of Σ βᵢ((x − m)/s)ⁱ: the matrix T with raw = T·β.
fn centred_to_raw(deg: usize, m: f64, s: f64) -> DMatrix<f64> {
    let mut t = DMatrix::zeros(deg + 1, deg + 1);
    for i in 0..=deg {
        let si = s.powi(-(i as i32));
        let mut binom = 1.0;
        for k in 0..=i {
            // C(i, k) (−m)^(i−k) / s^i
            t[(k, i)] = si * binom * (-m).powi((i - k) as i32);
            binom = binom * (i - k) as f64 / (k + 1) as f64;
        }
    }
    t
}

impl Relation for RunTflightSf {
    fn id(&self) -> &'static str {
        match self.continuity {
            Continuity::Free => Self::ID,
            Continuity::Continuous => Self::ID_CONTINUOUS,
        }
    }
    fn title(&self) -> &'static str {
        match self.continuity {
            Continuity::Free => "Running: flight time from step frequency (paper's free pieces)",
            Continuity::Continuous => "Running: flight time from step frequency (continuous at k1)",
        }
    }
    fn citation(&self) -> Citation {
        Citation {
            paper: "Bruderlin & Calvert (1996), Knowledge-driven, interactive animation of human running",
            equation: "eqs. 4–5 (§2.2)",
        }
    }
    fn equation(&self) -> &'static str {
        match self.continuity {
            Continuity::Free => {
                "t_flight = q0 + q1·sf + q2·sf² (sf < k1); c0 + c1·s + c2·s² + c3·s³ with s = min(sf, k2) (sf ≥ k1)"
            }
            Continuity::Continuous => {
                "t_flight = q0 + q1·sf + q2·sf² (sf < k1); c0 + c1·s + c2·s² + c3·s³ with s = min(sf, k2) (sf ≥ k1); q0 set so the pieces meet at k1"
            }
        }
    }
    fn response(&self) -> Variable {
        Variable {
            symbol: "t_flight",
            unit: "s",
            name: "flight time",
        }
    }
    fn inputs(&self) -> &'static [Variable] {
        INPUTS
    }
    fn gait(&self) -> Gait {
        Gait::Run
    }
    fn needs(&self) -> &'static [Quantity] {
        &[Quantity::StepFreq, Quantity::FlightTime]
    }
    fn observe(&self, row: &FieldValues) -> Result<Observation, Rejection> {
        let sf = required(row, Quantity::StepFreq)?;
        let tf = required(row, Quantity::FlightTime)?;
        Ok(Observation {
            x: [hz_to_steps_per_min(sf), 0.0, 0.0, 0.0],
            y: tf,
        })
    }
    fn parameters(&self) -> &'static [ParameterSpec] {
        PARAMS
    }
    fn has_intercept(&self) -> bool {
        true
    }
    fn domain(&self) -> Domain {
        Domain {
            input: "sf",
            lo: 160.0,
            hi: 230.0,
            note: "the cubic's data ranged about 160–230 steps/min (n = 20); below 180 the quadratic is an extrapolation",
        }
    }
    fn values(&self) -> &[f64] {
        &self.values
    }
    fn fitted_range(&self) -> FittedRange {
        self.range
    }
    fn set_fitted_range(&mut self, range: FittedRange) {
        self.range = range;
    }
    fn subject_levels(&self) -> &BTreeMap<String, f64> {
        &self.levels
    }
    fn raw_basis(&self, p: &[f64], x: &[f64], g: &mut [f64]) {
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
    fn predict_with(&self, p: &[f64], _subject_offset: f64, x: &[f64]) -> f64 {
        tflight(p, x[0])
    }
    fn gradient(&self, p: &[f64], x: &[f64]) -> Option<Vec<f64>> {
        let mut d = super::linear_gradient(self, p, x);
        // k1 moves a row between pieces (no derivative almost everywhere); k2 moves the plateau.
        if x[0] > p[8] && x[0] >= p[7] {
            let k2 = p[8];
            d[8] = p[4] + k2 * (2.0 * p[5] + 3.0 * k2 * p[6]);
        }
        Some(d)
    }
    fn plan(&self, obs: &[Observation]) -> Plan {
        self.plan_sorted(&sorted_keys(self, obs))
    }
    fn sorted_profile(&self) -> Option<&dyn SortedProfile> {
        Some(self)
    }
    fn breakpoint_null(&self, i: usize) -> Option<f64> {
        (i == 8).then_some(f64::INFINITY)
    }
    fn basis_len(&self, free: &[bool]) -> usize {
        Layout::new(&self.values, free, self.continuity).nb()
    }
    fn basis(&self, p: &[f64], free: &[bool], x: &[f64], phi: &mut [f64]) -> f64 {
        let l = Layout::new(p, free, self.continuity);
        let sf = x[0];
        let (k1, k2) = (p[7], p[8]);
        let below = sf < k1;
        let w = |s: f64| (s - l.m2) / l.s2;
        let u = |s: f64| (s - l.m1) / l.s1;
        let (u1, w1) = (u(k1), w(k1));
        let nb = l.nb();
        phi[..nb].fill(0.0);
        match (l.qfree, l.cfree, l.continuous) {
            (true, true, false) => {
                if below {
                    let uu = u(sf);
                    phi[0] = 1.0;
                    phi[1] = uu;
                    phi[2] = uu * uu;
                } else {
                    let ww = w(sf.min(k2));
                    phi[3] = 1.0;
                    phi[4] = ww;
                    phi[5] = ww * ww;
                    phi[6] = ww * ww * ww;
                }
                0.0
            }
            (true, true, true) => {
                if below {
                    let uu = u(sf);
                    phi[0] = 1.0;
                    phi[1] = w1;
                    phi[2] = w1 * w1;
                    phi[3] = w1 * w1 * w1;
                    phi[4] = uu - u1;
                    phi[5] = uu * uu - u1 * u1;
                } else {
                    let ww = w(sf.min(k2));
                    phi[0] = 1.0;
                    phi[1] = ww;
                    phi[2] = ww * ww;
                    phi[3] = ww * ww * ww;
                }
                0.0
            }
            (false, true, cont) => {
                if below {
                    quad(p, sf)
                } else {
                    let ww = w(sf.min(k2));
                    if cont {
                        phi[0] = ww - w1;
                        phi[1] = ww * ww - w1 * w1;
                        phi[2] = ww * ww * ww - w1 * w1 * w1;
                        quad(p, k1)
                    } else {
                        phi[0] = 1.0;
                        phi[1] = ww;
                        phi[2] = ww * ww;
                        phi[3] = ww * ww * ww;
                        0.0
                    }
                }
            }
            (true, false, cont) => {
                if below {
                    let uu = u(sf);
                    if cont {
                        phi[0] = uu - u1;
                        phi[1] = uu * uu - u1 * u1;
                        cubic(p, k1)
                    } else {
                        phi[0] = 1.0;
                        phi[1] = uu;
                        phi[2] = uu * uu;
                        0.0
                    }
                } else {
                    cubic(p, sf.min(k2))
                }
            }
            (false, false, _) => tflight(p, sf),
        }
    }
    fn basis_to_params(&self, p: &[f64], free: &[bool]) -> LinearMap {
        let l = Layout::new(p, free, self.continuity);
        let nb = l.nb();
        let (k1, _) = (p[7], p[8]);
        let u1 = (k1 - l.m1) / l.s1;
        let w1 = (k1 - l.m2) / l.s2;
        // Centred-basis coefficients of each piece as affine functions of β.
        let mut aq = DMatrix::zeros(3, nb);
        let mut bq = DVector::zeros(3);
        let mut ac = DMatrix::zeros(4, nb);
        let mut bc = DVector::zeros(4);
        let t1 = centred_to_raw(2, l.m1, l.s1);
        let t2 = centred_to_raw(3, l.m2, l.s2);
        let mut q_held = false;
        let mut c_held = false;
        match (l.qfree, l.cfree, l.continuous) {
            (true, true, false) => {
                for i in 0..3 {
                    aq[(i, i)] = 1.0;
                }
                for i in 0..4 {
                    ac[(i, 3 + i)] = 1.0;
                }
            }
            (true, true, true) => {
                for i in 0..4 {
                    ac[(i, i)] = 1.0;
                    aq[(0, i)] = w1.powi(i as i32);
                }
                aq[(0, 4)] = -u1;
                aq[(0, 5)] = -u1 * u1;
                aq[(1, 4)] = 1.0;
                aq[(2, 5)] = 1.0;
            }
            (false, true, cont) => {
                q_held = true;
                if cont {
                    bc[0] = quad(p, k1);
                    for i in 1..4 {
                        ac[(0, i - 1)] = -w1.powi(i as i32);
                        ac[(i, i - 1)] = 1.0;
                    }
                } else {
                    for i in 0..4 {
                        ac[(i, i)] = 1.0;
                    }
                }
            }
            (true, false, cont) => {
                c_held = true;
                if cont {
                    bq[0] = cubic(p, k1);
                    aq[(0, 0)] = -u1;
                    aq[(0, 1)] = -u1 * u1;
                    aq[(1, 0)] = 1.0;
                    aq[(2, 1)] = 1.0;
                } else {
                    for i in 0..3 {
                        aq[(i, i)] = 1.0;
                    }
                }
            }
            (false, false, _) => {
                q_held = true;
                c_held = true;
            }
        }
        let mut map = DMatrix::zeros(7, nb);
        let mut shift = DVector::zeros(7);
        if q_held {
            for i in 0..3 {
                shift[i] = p[i];
            }
        } else {
            map.rows_mut(0, 3).copy_from(&(&t1 * &aq));
            shift.rows_mut(0, 3).copy_from(&(&t1 * &bq));
        }
        if c_held {
            for i in 0..4 {
                shift[3 + i] = p[3 + i];
            }
        } else {
            map.rows_mut(3, 4).copy_from(&(&t2 * &ac));
            shift.rows_mut(3, 4).copy_from(&(&t2 * &bc));
        }
        LinearMap { map, shift }
    }
    fn subject_column(&self, _free: &[bool]) -> Option<usize> {
        None
    }
    fn with_values(&self, values: &[f64], levels: BTreeMap<String, f64>) -> Box<dyn Relation> {
        Box::new(RunTflightSf {
            values: values.to_vec(),
            continuity: self.continuity,
            levels,
            range: FittedRange::default(),
        })
    }
    fn derived(&self, p: &[f64]) -> Vec<(String, f64, &'static str)> {
        vec![
            ("jump_at_k1".to_string(), jump(p), "s"),
            ("t_flight(187)".to_string(), tflight(p, 187.0), "s"),
        ]
    }
}

/// A polynomial in ω = (sf − c)/half_width (c: the piece's centre) of degree ≤ 3, coefficients
/// of 1, ω, ω², ω³: within a piece, every basis column and offset of [`Relation::basis`] is one.
type Poly = [f64; 4];

fn pc(c: f64) -> Poly {
    [c, 0.0, 0.0, 0.0]
}
fn padd(a: &Poly, b: &Poly) -> Poly {
    [a[0] + b[0], a[1] + b[1], a[2] + b[2], a[3] + b[3]]
}
fn psub(a: &Poly, b: &Poly) -> Poly {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2], a[3] - b[3]]
}
fn pscale(a: &Poly, c: f64) -> Poly {
    [a[0] * c, a[1] * c, a[2] * c, a[3] * c]
}
/// Product, truncated at degree 3 (the products used here never exceed it).
fn pmul(a: &Poly, b: &Poly) -> Poly {
    let mut r = [0.0; 4];
    for i in 0..4 {
        for j in 0..4 - i {
            r[i + j] += a[i] * b[j];
        }
    }
    r
}
fn quad_poly(p: &[f64], s: &Poly) -> Poly {
    padd(
        &padd(&pc(p[0]), &pscale(s, p[1])),
        &pscale(&pmul(s, s), p[2]),
    )
}
fn cubic_poly(p: &[f64], s: &Poly) -> Poly {
    let s2 = pmul(s, s);
    padd(
        &padd(&pc(p[3]), &pscale(s, p[4])),
        &padd(&pscale(&s2, p[5]), &pscale(&pmul(&s2, s), p[6])),
    )
}

/// Feature slots of the sorted profile: ω⁰…ω⁶, ω⁰y…ω³y, y².
mod feat {
    pub const Y: usize = 7;
    pub const YY: usize = 11;
    pub const N: usize = 12;
}

impl RunTflightSf {
    /// The basis columns and offset of the quadratic piece (sf < k1) as polynomials, given u and
    /// sf as polynomials in ω (mirrors [`Relation::basis`]).
    fn below_polys(&self, l: &Layout, p: &[f64], u: &Poly, s: &Poly, out: &mut [Poly; 7]) -> Poly {
        let k1 = p[7];
        let u1 = (k1 - l.m1) / l.s1;
        let w1 = (k1 - l.m2) / l.s2;
        let uu = pmul(u, u);
        match (l.qfree, l.cfree, l.continuous) {
            (true, true, false) => {
                out[0] = pc(1.0);
                out[1] = *u;
                out[2] = uu;
                pc(0.0)
            }
            (true, true, true) => {
                out[0] = pc(1.0);
                out[1] = pc(w1);
                out[2] = pc(w1 * w1);
                out[3] = pc(w1 * w1 * w1);
                out[4] = psub(u, &pc(u1));
                out[5] = psub(&uu, &pc(u1 * u1));
                pc(0.0)
            }
            (true, false, true) => {
                out[0] = psub(u, &pc(u1));
                out[1] = psub(&uu, &pc(u1 * u1));
                pc(cubic(p, k1))
            }
            (true, false, false) => {
                out[0] = pc(1.0);
                out[1] = *u;
                out[2] = uu;
                pc(0.0)
            }
            (false, _, _) => quad_poly(p, s),
        }
    }

    /// The same for the cubic piece, given w and s = min(sf, k2) as polynomials in ω.
    fn upper_polys(&self, l: &Layout, p: &[f64], w: &Poly, s: &Poly, out: &mut [Poly; 7]) -> Poly {
        let k1 = p[7];
        let w1 = (k1 - l.m2) / l.s2;
        let ww = pmul(w, w);
        let www = pmul(&ww, w);
        match (l.qfree, l.cfree, l.continuous) {
            (true, true, false) => {
                out[3] = pc(1.0);
                out[4] = *w;
                out[5] = ww;
                out[6] = www;
                pc(0.0)
            }
            (true, true, true) => {
                out[0] = pc(1.0);
                out[1] = *w;
                out[2] = ww;
                out[3] = www;
                pc(0.0)
            }
            (false, true, true) => {
                out[0] = psub(w, &pc(w1));
                out[1] = psub(&ww, &pc(w1 * w1));
                out[2] = psub(&www, &pc(w1 * w1 * w1));
                pc(quad(p, k1))
            }
            (false, true, false) => {
                out[0] = pc(1.0);
                out[1] = *w;
                out[2] = ww;
                out[3] = www;
                pc(0.0)
            }
            (_, false, _) => cubic_poly(p, s),
        }
    }
}

/// Adds the normal equations of the rows summarised by `f` (a piece) whose basis columns and
/// offset are the polynomials `cols`, `off` in ω.
fn add_piece(ne: &mut NormalEquations, f: &FeatureSums, cols: &[Poly], off: &Poly) {
    if f[0] == 0.0 {
        // No rows (their polynomials may not even be finite, e.g. at k2 = +∞).
        return;
    }
    let m = |i: usize, j: usize| f[i + j];
    let my = |i: usize| f[feat::Y + i];
    let mv = |a: &Poly| -> Poly {
        let mut r = [0.0; 4];
        for (i, ri) in r.iter_mut().enumerate() {
            *ri = (0..4).map(|j| m(i, j) * a[j]).sum();
        }
        r
    };
    let dot = |a: &Poly, b: &Poly| a.iter().zip(b).map(|(a, b)| a * b).sum::<f64>();
    let mo = mv(off);
    let ymy: Poly = [my(0), my(1), my(2), my(3)];
    let nb = ne.nb;
    for a in 0..nb {
        if cols[a] == [0.0; 4] {
            continue;
        }
        let ma = mv(&cols[a]);
        ne.xty[a] += dot(&cols[a], &ymy) - dot(&cols[a], &mo);
        for (b, cb) in cols.iter().enumerate().take(nb) {
            if *cb != [0.0; 4] {
                ne.xtx[a * nb + b] += dot(cb, &ma);
            }
        }
    }
    ne.yty += f[feat::YY] - 2.0 * dot(off, &ymy) + dot(off, &mo);
}

impl SortedProfile for RunTflightSf {
    fn key(&self, x: &[f64]) -> f64 {
        x[0]
    }
    fn n_features(&self) -> usize {
        feat::N
    }
    fn features(&self, scale: &KeyScale, centre: f64, o: &Observation, out: &mut [f64]) {
        let w = scale.omega(o.x[0], centre);
        let mut pw = 1.0;
        for v in out.iter_mut().take(7) {
            *v = pw;
            pw *= w;
        }
        let y = o.y;
        out[feat::Y] = y;
        out[feat::Y + 1] = w * y;
        out[feat::Y + 2] = w * w * y;
        out[feat::Y + 3] = w * w * w * y;
        out[feat::YY] = y * y;
    }
    fn shift(&self, scale: &KeyScale, f: &mut FeatureSums, from: f64, to: f64) {
        // (sf − to)/h = ω + d with ω = (sf − from)/h: binomial expansion of the moments.
        let d = (from - to) / scale.half_width;
        if d == 0.0 {
            return;
        }
        let mut dp = [1.0; 7];
        for k in 1..7 {
            dp[k] = dp[k - 1] * d;
        }
        let shifted = |m: &[f64], k: usize| -> f64 {
            let mut binom = 1.0;
            let mut acc = 0.0;
            for j in (0..=k).rev() {
                // C(k, j) for j = k, k − 1, …: multiply by j/(k − j + 1).
                acc += binom * dp[k - j] * m[j];
                binom = binom * j as f64 / (k - j + 1) as f64;
            }
            acc
        };
        let m: [f64; 7] = [f[0], f[1], f[2], f[3], f[4], f[5], f[6]];
        for k in (1..7).rev() {
            f[k] = shifted(&m, k);
        }
        let my: [f64; 4] = [f[feat::Y], f[feat::Y + 1], f[feat::Y + 2], f[feat::Y + 3]];
        for k in (1..4).rev() {
            f[feat::Y + k] = shifted(&my, k);
        }
    }
    fn normal_equations(
        &self,
        p: &[f64],
        free: &[bool],
        scale: &KeyScale,
        sums: &dyn KeySums,
    ) -> NormalEquations {
        let l = Layout::new(p, free, self.continuity);
        let nb = l.nb();
        let (k1, k2) = (p[7], p[8]);
        let mut ne = NormalEquations::zeros(nb);
        let h = scale.half_width;
        // Each piece's sums are taken about the middle of its rows' key range, so the
        // polynomials below are well conditioned however narrow the piece.
        let (dlo, dhi) = (scale.centre - h, scale.centre + h);
        let centre = |a: f64, b: f64| {
            let (a, b) = (a.max(dlo), b.min(dhi));
            if a <= b {
                0.5 * (a + b)
            } else {
                scale.centre
            }
        };
        let sf = |c: f64| [c, h, 0.0, 0.0];
        let u = |c: f64| [(c - l.m1) / l.s1, h / l.s1, 0.0, 0.0];
        let w = |c: f64| [(c - l.m2) / l.s2, h / l.s2, 0.0, 0.0];
        // Pieces: sf < k1 quadratic; k1 ≤ sf ≤ k2 cubic; above both, the cubic at k2.
        let cb = centre(f64::NEG_INFINITY, k1);
        let below = sums.range(KeyRange::below(k1, false), cb);
        let mut cols = [[0.0; 4]; 7];
        let off = self.below_polys(&l, p, &u(cb), &sf(cb), &mut cols);
        add_piece(&mut ne, &below, &cols[..nb], &off);
        let plateau = if k1 <= k2 {
            let cm = centre(k1, k2);
            let middle = sums.range(KeyRange::closed(k1, k2), cm);
            let mut cols = [[0.0; 4]; 7];
            let off = self.upper_polys(&l, p, &w(cm), &sf(cm), &mut cols);
            add_piece(&mut ne, &middle, &cols[..nb], &off);
            sums.range(KeyRange::above(k2, false), scale.centre)
        } else {
            sums.range(KeyRange::above(k1, true), scale.centre)
        };
        if plateau[0] != 0.0 {
            let mut cols = [[0.0; 4]; 7];
            let wk = (k2 - l.m2) / l.s2;
            let off = self.upper_polys(&l, p, &pc(wk), &pc(k2), &mut cols);
            add_piece(&mut ne, &plateau, &cols[..nb], &off);
        }
        ne
    }
    fn plan_sorted(&self, d: &[f64]) -> Plan {
        let (k1, k2) = (self.values[7], self.values[8]);
        let below: Vec<f64> = d.iter().copied().filter(|&s| s < k1).collect();
        let mid: Vec<f64> = d.iter().copied().filter(|&s| s >= k1 && s <= k2).collect();
        let above: Vec<f64> = d.iter().copied().filter(|&s| s > k2).collect();
        let mut held: Vec<Option<String>> = vec![None; 9];
        let mut search = vec![None; 9];
        if below.len() < MIN_DISTINCT {
            let why = format!(
                "held at the published value: {} distinct step frequencies below k1 = {k1} (need {MIN_DISTINCT})",
                below.len()
            );
            for h in held.iter_mut().take(3) {
                *h = Some(why.clone());
            }
        }
        if mid.len() < MIN_DISTINCT {
            let why = format!(
                "held at the published value: {} distinct step frequencies in [k1, k2] = [{k1}, {k2}] (need {MIN_DISTINCT})",
                mid.len()
            );
            for h in held.iter_mut().take(7).skip(3) {
                *h = Some(why.clone());
            }
        }
        let n = d.len();
        if held[0].is_none() && held[3].is_none() && n >= 2 * MIN_DISTINCT {
            let lo = d[MIN_DISTINCT - 1];
            let hi_candidates: Vec<f64> = d.iter().copied().filter(|&s| s <= k2).collect();
            let hi = if hi_candidates.len() >= MIN_DISTINCT {
                hi_candidates[hi_candidates.len() - MIN_DISTINCT]
            } else {
                lo
            };
            if hi > lo {
                search[7] = Some((lo, hi));
            }
        }
        if search[7].is_none() {
            held[7] = Some(
                "held at the published value: the data do not cover both pieces well enough to place the knot"
                    .to_string(),
            );
        }
        if held[3].is_none() && above.len() >= 3 && mid.len() >= MIN_DISTINCT {
            let lo = mid[mid.len().min(MIN_DISTINCT) - 1].max(k1 + 1.0);
            let hi = d[n - 3];
            if hi > lo {
                search[8] = Some((lo, hi));
            }
        }
        if search[8].is_none() {
            held[8] = Some(format!(
                "held at the published value: {} distinct step frequencies above k2 = {k2} (need 3) — the plateau is not in the data",
                above.len()
            ));
        }
        Plan { held, search }
    }
    fn discrete_breakpoint(&self, i: usize) -> bool {
        // Free pieces: k1 only decides which rows each piece fits (no continuity at k1).
        i == 7 && self.continuity == Continuity::Free
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn centred_basis_maps_to_the_raw_polynomial() {
        let t = centred_to_raw(3, 205.0, 25.0);
        let beta = DVector::from_vec(vec![0.18, -0.01, 0.003, 0.0004]);
        let raw = &t * &beta;
        for sf in [170.0, 200.0, 230.0] {
            let w: f64 = (sf - 205.0) / 25.0;
            let centred: f64 = (0..4).map(|i| beta[i] * w.powi(i as i32)).sum();
            let rawv: f64 = (0..4).map(|i| raw[i] * sf.powi(i as i32)).sum();
            assert!((centred - rawv).abs() < 1e-12, "{centred} {rawv}");
        }
    }

    #[test]
    fn every_basis_layout_reproduces_predictions_through_its_map() {
        // For any β, Σ φ·β + offset must equal the raw prediction with the mapped coefficients.
        let base = RunTflightSf::published();
        for cont in [Continuity::Free, Continuity::Continuous] {
            let r = RunTflightSf {
                continuity: cont,
                ..base.clone()
            };
            for (qf, cf) in [(true, true), (false, true), (true, false), (false, false)] {
                let mut free = vec![false; 9];
                for f in free.iter_mut().take(3) {
                    *f = qf;
                }
                for f in free.iter_mut().take(7).skip(3) {
                    *f = cf;
                }
                let p = r.values.clone();
                let nb = r.basis_len(&free);
                let beta: Vec<f64> = (0..nb).map(|i| 0.01 * (i as f64 + 1.0)).collect();
                let m = r.basis_to_params(&p, &free);
                let raw = &m.map * DVector::from_vec(beta.clone()) + &m.shift;
                let mut p2 = p.clone();
                for i in 0..7 {
                    p2[i] = raw[i];
                }
                let mut phi = vec![0.0; 8];
                for sf in [150.0, 179.9, 180.0, 200.0, 229.0, 240.0] {
                    let off = r.basis(&p, &free, &[sf], &mut phi);
                    let y: f64 = off + (0..nb).map(|i| phi[i] * beta[i]).sum::<f64>();
                    let want = tflight(&p2, sf);
                    assert!(
                        (y - want).abs() < 1e-9,
                        "{cont:?} {qf} {cf} sf={sf}: {y} vs {want}"
                    );
                }
                if cont == Continuity::Continuous && (qf || cf) {
                    assert!(jump(&p2).abs() < 1e-9, "{qf} {cf}: jump {}", jump(&p2));
                }
            }
        }
    }

    #[test]
    fn sorted_normal_equations_match_the_basis_rows() {
        // Step frequencies 120–260 with repeats, flight times from the published curve.
        let obs: Vec<Observation> = (0..400)
            .map(|i| {
                let sf = 120.0 + (i % 141) as f64 + 0.37 * ((i * 7) % 3) as f64;
                Observation {
                    x: [sf, 0.0, 0.0, 0.0],
                    y: tflight(&RunTflightSf::published().values, sf)
                        + 0.002 * ((i % 5) as f64 - 2.0),
                }
            })
            .collect();
        for cont in [Continuity::Free, Continuity::Continuous] {
            let base = RunTflightSf {
                continuity: cont,
                ..RunTflightSf::published()
            };
            for (k1, k2) in [
                (180.0, 230.0),
                (171.3, 245.0),
                (205.0, 190.0),
                (175.0, f64::INFINITY),
                (180.0, 181.5),
            ] {
                let mut p = base.values.clone();
                p[7] = k1;
                p[8] = k2;
                for (qf, cf) in [(true, true), (false, true), (true, false), (false, false)] {
                    let mut free = vec![true; 9];
                    for f in free.iter_mut().take(3) {
                        *f = qf;
                    }
                    for f in free.iter_mut().take(7).skip(3) {
                        *f = cf;
                    }
                    crate::relations::sorted_check::check(&base, &obs, &p, &free, 1e-11);
                }
            }
        }
    }

    #[test]
    fn plan_sorted_is_plan() {
        let r = RunTflightSf::published();
        let obs: Vec<Observation> = (0..60)
            .map(|i| Observation {
                x: [150.0 + 2.0 * (i % 45) as f64, 0.0, 0.0, 0.0],
                y: 0.1,
            })
            .collect();
        let keys = crate::relations::sorted_keys(&r, &obs);
        assert_eq!(r.plan(&obs), r.plan_sorted(&keys));
        assert!(r.plan(&obs).search[7].is_some() && r.plan(&obs).search[8].is_some());
    }
}
