//! `kb-mu`: the μ-functions of Ko & Badler (1993), appendix A, eqs. 21–24, fitted to measured
//! per-step angles by the generic pipeline (`gaitfit fit --relation kb-mu`).
//!
//! ```text
//! μ₁ = −α₁ (x − sl*) + μ₁*   knee flexion at heel strike          knee_angle_hs
//! μ₂ =  α₂ (x − sl*) + μ₂*   foot (sole) angle at heel strike     foot_angle_hs
//! μ₃ =  α₃ (x − sl*) + μ₃*   foot (sole) angle at toe off         foot_angle_to
//! μ₄ =  α₄ (x − sl*) + μ₄*   meta (toe) angle at toe off          meta_angle_to
//! x  = sl · ll(S*) / ll(S)   (the corrected argument, see generator::generalize::mu)
//! ```
//!
//! Units: angles rad, lengths m, α rad/m. Bounds (appendix A): α₁ ∈ [0, 0.3], α₂…α₄ > 0
//! (enforced as ≥ 0 by argmin in the pipeline, which reports an active bound). sl* and ll(S*)
//! are held: with a free intercept μᵢ* the pair (sl*, μᵢ*) is not identifiable.
//!
//! **Several outputs.** One trials row (one step) gives up to four observations, one per μ
//! ([`Card::outputs`]): the observation's input is `x`, its [`Inputs::output`] the μ index (0…3). The
//! model is linear in α and μ* (a separate line per μ), so the generic linear machinery applies;
//! r² is pooled with each μ centred on its own mean, and per-μ n, r², rmse and leave-one-out
//! rmse are reported as derived quantities (see `fit::constrained`).
//!
//! **"Published" values.** The paper gives no α (only α₁'s range); the published α are 0 — the
//! similarity assumption alone (angles independent of step length), so each t-test asks whether
//! the data show a slope. μ₁*…μ₄* and sl* are the bundled prototype's (`data/prototype_winter.json`,
//! Winter's walk), the values the generator uses. The events layer measures the knee and meta
//! angles with other zero references than the prototype builder (see
//! `generator::generalize::prototype`), so the fitted μ₁*, μ₄* differ from the prototype's by
//! that offset as much as by subject; the slopes α do not depend on it.
//!
//! ll(S*) is Winter's leg length *as the trials tables measure leg length* (the
//! `bmclab_WinterTableA1` row of `data/walk_bmclab.csv`, [`WINTER_TABLE_LEG_LENGTH`]), so that x
//! compares like with like.
//!
//! Sign conventions are those of the events layer (`events::phases::mu_inputs`): knee flexion
//! positive, foot angle at heel strike toes-up positive, at toe off heel-up positive, meta angle
//! metatarsal heads above the toe tip positive — the generator's conventions
//! ([`crate::generator::generalize::mu`]).
//!
//! ```
//! use gaitfit::relations::{kb_mu::KbMu, Relation};
//! let r = KbMu::published();
//! // At the prototype's own step length and leg length every μ is the prototype's μ*.
//! let x = r.argument(r.sl_star(), r.ll_star());
//! assert!((r.mu(2, x) - r.mu_star()[2]).abs() < 1e-15);
//! assert_eq!(r.card().outputs.len(), 4);
//! ```
use super::{expect_id, linear_gradient, required, Card, Citation, CoefficientSet, Domain, FittedRange, Inputs, Observation, Output, ParamKind, ParameterSpec, Rejection, Relation, RelationError, Variable};
use crate::gait::Gait;
use crate::ingest::trials::FieldValues;
use crate::units::Quantity;
use std::collections::BTreeMap;
use std::path::Path;
use std::sync::OnceLock;

/// Relation id.
pub const ID: &str = "kb-mu";
/// Upper bound of α₁ (appendix A, after Inman), rad/m.
pub const ALPHA1_MAX: f64 = 0.3;
/// Subject name of Winter's row in the bundled tables (its leg length defines ll(S*)).
pub const WINTER_SUBJECT: &str = "bmclab_WinterTableA1";
/// Winter's leg length as the trials tables measure it (`leg_length_m` of the
/// `bmclab_WinterTableA1` row of `data/walk_bmclab.csv`; checked by `tests/kb_mu_fit.rs`), m.
pub const WINTER_TABLE_LEG_LENGTH: f64 = 0.81;
/// The μ columns, in μ₁…μ₄ order.
pub const MU_QUANTITIES: [Quantity; 4] = [
    Quantity::KneeAngleHs,
    Quantity::FootAngleHs,
    Quantity::FootAngleTo,
    Quantity::MetaAngleTo,
];
/// Coefficient names, in [`Card::parameters`] order.
pub const NAMES: [&str; 10] = [
    "alpha1", "alpha2", "alpha3", "alpha4", "mu1_star", "mu2_star", "mu3_star", "mu4_star",
    "sl_star", "ll_star",
];
/// Index of sl* among the parameters.
pub const SL_STAR: usize = 8;
/// Index of ll(S*) among the parameters.
pub const LL_STAR: usize = 9;
/// The four outputs, μ₁…μ₄ (an observation's [`Inputs::output`] indexes them).
const OUTPUTS: &[Output] = &[
    Output {
        name: "mu1",
        label: "μ1: knee flexion at heel strike",
    },
    Output {
        name: "mu2",
        label: "μ2: foot angle at heel strike",
    },
    Output {
        name: "mu3",
        label: "μ3: foot angle at toe off",
    },
    Output {
        name: "mu4",
        label: "μ4: meta angle at toe off",
    },
];

const INPUTS: &[Variable] = &[
    Variable {
        symbol: "x",
        unit: "m",
        name: "leg-length-normalized step length sl·ll(S*)/ll(S)",
    },
];

fn sign(i: usize) -> f64 {
    if i == 0 {
        -1.0
    } else {
        1.0
    }
}

/// The two numbers of the bundled prototype (`data/prototype_winter.json`, Winter's walk) that
/// the published relation uses: its step length sl* and its μ₁*…μ₄*. Read from the same file
/// the generator's `Prototype::bundled` reads (tests/kb_mu_fit.rs checks they agree), so the
/// relation needs no generator import.
#[derive(serde::Deserialize)]
struct BundledPrototype {
    step_length_m: f64,
    mu_star_rad: [f64; 4],
}

/// The bundled prototype's sl* and μ* (the file is committed; parsing it cannot fail unless the
/// repository itself is broken, which `tests/kb_prototype.rs` would report first).
fn bundled_prototype() -> BundledPrototype {
    const TEXT: &str = include_str!("../../data/prototype_winter.json");
    match serde_json::from_str(TEXT) {
        Ok(p) => p,
        Err(e) => panic!("the bundled prototype data/prototype_winter.json is broken: {e}"),
    }
}

/// The parameter table: α not published (the paper gives none; 0, the similarity assumption
/// alone, is the reference value the published relation uses), μ* and sl* the bundled
/// prototype's. Built once (it reads the bundled prototype).
fn params() -> &'static [ParameterSpec] {
    static P: OnceLock<Vec<ParameterSpec>> = OnceLock::new();
    P.get_or_init(|| {
        let proto = bundled_prototype();
        let alpha = |name: &'static str, description: &'static str| ParameterSpec {
            name,
            unit: "rad/m",
            published: 0.0,
            // The paper gives no α (only α₁'s range): no published value, no t-test.
            cited: false,
            kind: ParamKind::Linear,
            description,
        };
        let star = |k: usize, description: &'static str| ParameterSpec {
            name: NAMES[4 + k],
            unit: "rad",
            published: proto.mu_star_rad[k],
            cited: true,
            kind: ParamKind::Linear,
            description,
        };
        vec![
            alpha(
                "alpha1",
                "slope of μ1 (knee flexion at heel strike, decreasing) with x; the paper gives \
                 only [0, 0.3]; reference 0 = the similarity assumption alone",
            ),
            alpha(
                "alpha2",
                "slope of μ2 (foot angle at heel strike) with x; the paper gives none",
            ),
            alpha(
                "alpha3",
                "slope of μ3 (foot angle at toe off) with x; the paper gives none",
            ),
            alpha(
                "alpha4",
                "slope of μ4 (meta angle at toe off) with x; the paper gives none",
            ),
            star(
                0,
                "μ1 at sl* (published: the bundled prototype's knee angle at heel strike)",
            ),
            star(
                1,
                "μ2 at sl* (published: the bundled prototype's foot angle at heel strike)",
            ),
            star(
                2,
                "μ3 at sl* (published: the bundled prototype's foot angle at toe off)",
            ),
            star(
                3,
                "μ4 at sl* (published: the bundled prototype's meta angle at toe off)",
            ),
            ParameterSpec {
                name: "sl_star",
                unit: "m",
                published: proto.step_length_m,
                cited: true,
                kind: ParamKind::Breakpoint,
                description: "the bundled prototype's step length",
            },
            ParameterSpec {
                name: "ll_star",
                unit: "m",
                published: WINTER_TABLE_LEG_LENGTH,
                cited: true,
                kind: ParamKind::Breakpoint,
                description: "Winter's leg length as the trials tables measure it",
            },
        ]
    })
}

/// The μ-functions (eqs. 21–24) as a fittable relation.
#[derive(Debug, Clone, PartialEq)]
pub struct KbMu {
    values: Vec<f64>,
    levels: BTreeMap<String, f64>,
    /// The fitted input range (from a fits file; empty otherwise).
    range: FittedRange,
}

impl KbMu {
    /// The id.
    pub const ID: &'static str = ID;

    /// α = 0 and the bundled prototype's μ*, sl*; ll(S*) = [`WINTER_TABLE_LEG_LENGTH`].
    pub fn published() -> Self {
        KbMu {
            values: params().iter().map(|s| s.published).collect(),
            levels: BTreeMap::new(),
            range: FittedRange::default(),
        }
    }
    /// From a coefficient set.
    pub fn from_coefficients(set: &CoefficientSet) -> Result<Self, RelationError> {
        let (values, levels) = set.split(params(), None)?;
        Ok(KbMu {
            values,
            levels,
            range: FittedRange::of(set, INPUTS),
        })
    }
    /// From `fits/kb-mu.json`.
    pub fn from_fit_file(path: &Path) -> Result<Self, RelationError> {
        let set = CoefficientSet::from_fit_file(path)?;
        expect_id(&set, ID, path)?;
        Self::from_coefficients(&set)
    }
    /// As [`KbMu::from_fit_file`], from the file's JSON text (`path` names it in messages).
    pub fn from_fit_json(path: &Path, text: &str) -> Result<Self, RelationError> {
        let set = CoefficientSet::from_fit_json(path, text)?;
        expect_id(&set, ID, path)?;
        Self::from_coefficients(&set)
    }
    /// α₁…α₄ (rad/m).
    pub fn alpha(&self) -> [f64; 4] {
        [
            self.values[0],
            self.values[1],
            self.values[2],
            self.values[3],
        ]
    }
    /// μ₁*…μ₄* (rad).
    pub fn mu_star(&self) -> [f64; 4] {
        [
            self.values[4],
            self.values[5],
            self.values[6],
            self.values[7],
        ]
    }
    /// sl* (m).
    pub fn sl_star(&self) -> f64 {
        self.values[SL_STAR]
    }
    /// ll(S*) in the tables' definition of leg length (m).
    pub fn ll_star(&self) -> f64 {
        self.values[LL_STAR]
    }
    /// The μ argument x = sl·ll(S*)/ll(S) (m).
    pub fn argument(&self, step_length: f64, leg_length: f64) -> f64 {
        step_length * self.ll_star() / leg_length
    }
    /// μᵢ (rad, i = 0…3 for μ₁…μ₄) at argument `x` (m).
    pub fn mu(&self, i: usize, x: f64) -> f64 {
        sign(i) * self.values[i] * (x - self.sl_star()) + self.values[4 + i]
    }
}

/// What the relation is (built once: its parameters carry the bundled prototype's values).
fn card() -> &'static Card {
    static C: OnceLock<Card> = OnceLock::new();
    C.get_or_init(|| Card {
        id: ID,
        title: "Ko–Badler μ-functions: joint angles at heel strike and toe off vs step length",
        citation: Citation {
            paper: "Ko & Badler (1993), Straight line walking animation based on kinematic \
                    generalization that preserves the original characteristics",
            equation: "appendix A, eqs. 21–24 (argument corrected to sl·ll(S*)/ll(S))",
        },
        equation: "mu1 = -alpha1 (x - sl*) + mu1*; mu_i = alpha_i (x - sl*) + mu_i* (i = 2..4); \
                   x = sl ll(S*)/ll(S)",
        response: Variable {
            symbol: "mu",
            unit: "rad",
            name: "μ angle (knee at heel strike, foot at heel strike, foot at toe off, meta at toe off)",
        },
        inputs: INPUTS,
        outputs: OUTPUTS,
        gait: Gait::Walk,
        needs: &[
            Quantity::StepLength,
            Quantity::LegLength,
            Quantity::KneeAngleHs,
            Quantity::FootAngleHs,
            Quantity::FootAngleTo,
            Quantity::MetaAngleTo,
        ],
        parameters: params(),
        subject_effect: None,
        has_intercept: true,
        domain: Domain {
            input: "x",
            lo: 0.0,
            hi: f64::INFINITY,
            note: "the paper states no range; μ₂…μ₄ must stay positive (they scale F₁, F₂, M)",
        },
    })
}

impl Relation for KbMu {
    fn card(&self) -> &'static Card {
        card()
    }
    /// Observation `output` (μ₁…μ₄ for 0…3) of the row.
    fn observe(&self, row: &FieldValues, output: usize) -> Result<Observation, Rejection> {
        let k = output.min(3);
        let y = required(row, MU_QUANTITIES[k])?;
        let sl = required(row, Quantity::StepLength)?;
        let ll = required(row, Quantity::LegLength)?;
        if !(ll > 0.0 && sl > 0.0) {
            return Err(Rejection::Invalid(format!(
                "step length {sl} m and leg length {ll} m must be positive"
            )));
        }
        Ok(Observation {
            x: Inputs::new(&[self.argument(sl, ll)]).of_output(k),
            y,
        })
    }
    fn bounds(&self, i: usize) -> (f64, f64) {
        match i {
            0 => (0.0, ALPHA1_MAX),
            1..=3 => (0.0, f64::INFINITY),
            _ => (f64::NEG_INFINITY, f64::INFINITY),
        }
    }
    fn raw_basis(&self, p: &[f64], x: &Inputs, g: &mut [f64]) {
        g.iter_mut().for_each(|v| *v = 0.0);
        let i = x.output.min(3);
        g[i] = sign(i) * (x[0] - p[SL_STAR]);
        g[4 + i] = 1.0;
    }
    fn gradient(&self, p: &[f64], x: &Inputs) -> Option<Vec<f64>> {
        Some(linear_gradient(self, p, x))
    }
}

/// The least-squares line of μᵢ on x (points `(x, μ)`) with its slope (in the μ's own sign
/// convention) restricted to `slope_bounds`: the closed form a bounded fit of this separable
/// model must reproduce (an independent check of the pipeline). Returns (αᵢ, μᵢ*).
pub fn separable_line(
    points: &[(f64, f64)],
    i: usize,
    sl_star: f64,
    slope_bounds: (f64, f64),
) -> (f64, f64) {
    let pts: Vec<(f64, f64)> = points
        .iter()
        .map(|&(x, y)| (sign(i) * (x - sl_star), y))
        .collect();
    let n = pts.len() as f64;
    let mx = pts.iter().map(|p| p.0).sum::<f64>() / n;
    let my = pts.iter().map(|p| p.1).sum::<f64>() / n;
    let sxy: f64 = pts.iter().map(|p| (p.0 - mx) * (p.1 - my)).sum();
    let sxx: f64 = pts.iter().map(|p| (p.0 - mx).powi(2)).sum();
    let slope = (sxy / sxx).clamp(slope_bounds.0, slope_bounds.1);
    (slope, my - slope * mx)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn basis_reproduces_the_mu_functions() {
        let mut r = KbMu::published();
        r.values[..8].copy_from_slice(&[0.1, 0.5, 0.9, 1.3, 0.05, 0.4, 1.2, 0.9]);
        for i in 0..4 {
            let x = Inputs::new(&[0.63]).of_output(i);
            let want = sign(i) * r.values[i] * (0.63 - r.sl_star()) + r.values[4 + i];
            assert!((r.predict_with(&r.values, 0.0, &x) - want).abs() < 1e-15);
            assert!((r.mu(i, 0.63) - want).abs() < 1e-15);
        }
    }
}
