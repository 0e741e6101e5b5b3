//! `kb-mu`: the μ-functions of Ko & Badler (1993), appendix A, eqs. 21–24, fitted to measured
//! per-step angles.
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
//! (enforced as ≥ 0); μ* free. sl* is the bundled prototype's step length (Winter's), held: with
//! a free intercept μᵢ* it is not identifiable. ll(S*) is Winter's leg length *as the trials
//! tables measure leg length* (the `bmclab_WinterTableA1` row), so that x compares like with like;
//! without that row, the prototype's model leg length.
//!
//! One trials row (one step) gives up to four observations, one per μ; the fit is argmin's
//! bounded trust region ([`crate::fit::nonlinear::nls`]) on all of them at once, and a
//! coefficient that ends on its bound is reported (its standard error is then undefined).
//! Sign conventions are those of the events layer (`events::phases::mu_inputs`): knee flexion
//! positive, foot angle at heel strike toes-up positive, at toe off heel-up positive, meta angle
//! metatarsal heads above the toe tip positive — the generator's conventions
//! ([`crate::generator::generalize::mu`]). The events layer measures the meta angle from the
//! mid-stance toe line and the generator's prototype from the toe line at meta off (see
//! `generator::generalize::prototype`), so the fitted μ₄* and the prototype's differ by that
//! offset; the slope α₄ does not depend on it.
use crate::fit::nonlinear::{nls, Model, NlsOptions, Rows};
use crate::fit::FitError;
use crate::ingest::trials::TrialsTable;
use crate::units::Quantity;
use serde::Serialize;

/// Relation id.
pub const ID: &str = "kb-mu";
/// Upper bound of α₁ (appendix A, after Inman), rad/m.
pub const ALPHA1_MAX: f64 = 0.3;
/// Subject name of Winter's row in the bundled tables (its leg length defines ll(S*)).
pub const WINTER_SUBJECT: &str = "bmclab_WinterTableA1";
/// The μ columns, in μ₁…μ₄ order.
pub const MU_QUANTITIES: [Quantity; 4] = [
    Quantity::KneeAngleHs,
    Quantity::FootAngleHs,
    Quantity::FootAngleTo,
    Quantity::MetaAngleTo,
];
/// Coefficient names, in θ order.
pub const NAMES: [&str; 8] = [
    "alpha1", "alpha2", "alpha3", "alpha4", "mu1_star", "mu2_star", "mu3_star", "mu4_star",
];

/// One observation: which μ (0…3), the argument x (m) and the measured angle (rad).
#[derive(Debug, Clone, PartialEq)]
pub struct MuObservation {
    /// Subject.
    pub subject: String,
    /// 0…3 for μ₁…μ₄.
    pub index: usize,
    /// x = sl·ll(S*)/ll(S), m.
    pub x: f64,
    /// Measured μ, rad.
    pub y: f64,
}

/// The μ-function model for [`nls`]: row = (x, index), θ = (α₁…α₄, μ₁*…μ₄*).
#[derive(Debug, Clone, Copy)]
pub struct MuModel {
    /// sl*, m.
    pub sl_star: f64,
}

impl MuModel {
    fn sign(i: usize) -> f64 {
        if i == 0 {
            -1.0
        } else {
            1.0
        }
    }
}

impl Model for MuModel {
    fn n_params(&self) -> usize {
        8
    }
    fn value(&self, x: &[f64], t: &[f64]) -> f64 {
        let i = x[1] as usize;
        Self::sign(i) * t[i] * (x[0] - self.sl_star) + t[4 + i]
    }
    fn gradient(&self, x: &[f64], _t: &[f64], out: &mut [f64]) {
        out.iter_mut().for_each(|g| *g = 0.0);
        let i = x[1] as usize;
        out[i] = Self::sign(i) * (x[0] - self.sl_star);
        out[4 + i] = 1.0;
    }
}

fn col(t: &TrialsTable, q: Quantity) -> Option<&Vec<f64>> {
    t.columns[q as usize].as_ref()
}

/// The observations of the trials tables: every row with a step length, a leg length and any
/// of the four μ columns. Returns the observations, the ll(S*) used and the rows skipped (with
/// why).
pub fn observations(
    tables: &[TrialsTable],
    prototype_leg_length: f64,
) -> (Vec<MuObservation>, f64, Vec<String>) {
    // ll(S*) in the tables' own definition of leg length, from Winter's row.
    let mut ll_star = prototype_leg_length;
    for t in tables {
        if let Some(ll) = col(t, Quantity::LegLength) {
            for (i, &v) in ll.iter().enumerate() {
                if t.subject_name(i) == WINTER_SUBJECT && v.is_finite() {
                    ll_star = v;
                }
            }
        }
    }
    let mut out = Vec::new();
    let mut skipped = Vec::new();
    for t in tables {
        let (Some(sl), Some(ll)) = (col(t, Quantity::StepLength), col(t, Quantity::LegLength))
        else {
            continue;
        };
        for i in 0..t.len() {
            let mus: Vec<(usize, f64)> = MU_QUANTITIES
                .iter()
                .enumerate()
                .filter_map(|(k, q)| col(t, *q).map(|c| (k, c[i])))
                .filter(|(_, v)| v.is_finite())
                .collect();
            if mus.is_empty() {
                continue;
            }
            if t.is_flagged[i] {
                skipped.push(format!("{}: row {}: flagged", t.path.display(), i + 1));
                continue;
            }
            if !(sl[i].is_finite() && ll[i].is_finite() && ll[i] > 0.0) {
                skipped.push(format!(
                    "{}: row {}: step length or leg length missing",
                    t.path.display(),
                    i + 1
                ));
                continue;
            }
            let x = sl[i] * ll_star / ll[i];
            for (k, y) in mus {
                out.push(MuObservation {
                    subject: t.subject_name(i).to_string(),
                    index: k,
                    x,
                    y,
                });
            }
        }
    }
    (out, ll_star, skipped)
}

/// One fitted coefficient.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Coefficient {
    /// Name (`alpha1`, …, `mu4_star`, `sl_star`).
    pub name: String,
    /// Unit.
    pub unit: String,
    /// Value.
    pub value: f64,
    /// Standard error (`None` when held or on a bound).
    pub std_error: Option<f64>,
    /// Why it is held, if it is.
    pub held: Option<String>,
    /// Active bound or other remark.
    pub flag: Option<String>,
}

/// Per-μ statistics.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct PerMu {
    /// `mu1` … `mu4`.
    pub mu: String,
    /// Observations.
    pub n: usize,
    /// RMS residual, rad.
    pub rmse_rad: f64,
    /// RMS residual, degrees.
    pub rmse_deg: f64,
    /// Centred r² of this μ's line.
    pub r_squared: f64,
    /// Range of x, m.
    pub x_range_m: [f64; 2],
}

/// The fitted μ-functions with their statistics (written as `fits/ko-badler/kb-mu.json`).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct KbMuFit {
    /// `kb-mu`.
    pub relation: String,
    /// Title.
    pub title: String,
    /// Paper and equations.
    pub citation: String,
    /// The formula.
    pub equation: String,
    /// Observations (μ values).
    pub n: usize,
    /// Distinct subjects.
    pub n_subjects: usize,
    /// Coefficients: α₁…α₄, μ₁*…μ₄*, sl* (held) and ll(S*) (held).
    pub coefficients: Vec<Coefficient>,
    /// Overall RMS residual, rad.
    pub rmse: f64,
    /// Leave-one-out RMS residual (linearized), rad.
    pub loo_rmse: f64,
    /// Residual mean square RSS/(n − p), rad².
    pub residual_mean_square: f64,
    /// Per-μ statistics.
    pub per_mu: Vec<PerMu>,
    /// Whether the optimizer converged, and how it stopped.
    pub termination: String,
    /// Notes (active bounds, skipped rows, sources).
    pub notes: Vec<String>,
    /// gaitfit version.
    pub gaitfit_version: String,
}

impl KbMuFit {
    /// The value of coefficient `name`.
    pub fn get(&self, name: &str) -> Option<f64> {
        self.coefficients
            .iter()
            .find(|c| c.name == name)
            .map(|c| c.value)
    }
    /// α₁…α₄.
    pub fn alpha(&self) -> [f64; 4] {
        let g = |n: &str| self.get(n).unwrap_or(f64::NAN);
        [g("alpha1"), g("alpha2"), g("alpha3"), g("alpha4")]
    }
}

/// Fits α₁…α₄ and μ₁*…μ₄* to `obs` with sl* = `sl_star`, bounds α₁ ∈ [0, 0.3], α₂…α₄ ≥ 0.
pub fn fit(
    obs: &[MuObservation],
    sl_star: f64,
    ll_star: f64,
    notes: Vec<String>,
) -> Result<KbMuFit, FitError> {
    let mut counts = [0usize; 4];
    for o in obs {
        counts[o.index] += 1;
    }
    if let Some(i) = counts.iter().position(|&c| c < 2) {
        return Err(FitError::TooFew {
            relation: ID.into(),
            what: format!("observations of mu{}", i + 1),
            have: counts[i],
            need: 2,
        });
    }
    let rows: Vec<f64> = obs.iter().flat_map(|o| [o.x, o.index as f64]).collect();
    let y: Vec<f64> = obs.iter().map(|o| o.y).collect();
    // Start: each μ's own least-squares line, slope clamped into its bounds.
    let bounds = bounds();
    let mut start = [0.0; 8];
    for i in 0..4 {
        let (s, b) = separable_line(obs, i, sl_star, (f64::NEG_INFINITY, f64::INFINITY));
        start[i] = s.clamp(bounds[i].0, bounds[i].1.min(1e3));
        start[4 + i] = b;
    }
    let model = MuModel { sl_star };
    let opts = NlsOptions {
        name: ID.into(),
        bounds: Some(bounds.to_vec()),
        ..NlsOptions::default()
    };
    let r = nls(&model, Rows::new(&rows, 2)?, &y, &start, &opts)?;
    let mut notes = notes;
    let mut coefficients = Vec::new();
    for (k, name) in NAMES.iter().enumerate() {
        let flag = r.active_bounds[k].then(|| {
            let (lo, hi) = bounds[k];
            let which = if (r.theta[k] - lo).abs() <= (r.theta[k] - hi).abs() {
                lo
            } else {
                hi
            };
            let msg = format!(
                "bound active: {name} = {which} (allowed [{lo}, {hi}]; the data alone want it \
                 beyond)"
            );
            notes.push(msg.clone());
            msg
        });
        coefficients.push(Coefficient {
            name: name.to_string(),
            unit: if k < 4 { "rad/m" } else { "rad" }.into(),
            value: r.theta[k],
            std_error: r.std_error[k].is_finite().then_some(r.std_error[k]),
            held: None,
            flag,
        });
    }
    coefficients.push(Coefficient {
        name: "sl_star".into(),
        unit: "m".into(),
        value: sl_star,
        std_error: None,
        held: Some(
            "the bundled prototype's step length (Winter); not identifiable beside a free μ*"
                .into(),
        ),
        flag: None,
    });
    coefficients.push(Coefficient {
        name: "ll_star".into(),
        unit: "m".into(),
        value: ll_star,
        std_error: None,
        held: Some("Winter's leg length as the trials tables measure it".into()),
        flag: None,
    });
    let per_mu = (0..4)
        .map(|i| {
            let idx: Vec<usize> = (0..obs.len()).filter(|&j| obs[j].index == i).collect();
            let n = idx.len();
            let rss: f64 = idx.iter().map(|&j| r.residuals[j].powi(2)).sum();
            let mean = idx.iter().map(|&j| y[j]).sum::<f64>() / n as f64;
            let tss: f64 = idx.iter().map(|&j| (y[j] - mean).powi(2)).sum();
            let xs = idx.iter().map(|&j| obs[j].x);
            let lo = xs.clone().fold(f64::INFINITY, f64::min);
            let hi = xs.fold(f64::NEG_INFINITY, f64::max);
            let rmse = (rss / n as f64).sqrt();
            PerMu {
                mu: format!("mu{}", i + 1),
                n,
                rmse_rad: rmse,
                rmse_deg: rmse.to_degrees(),
                r_squared: if tss > 0.0 { 1.0 - rss / tss } else { f64::NAN },
                x_range_m: [lo, hi],
            }
        })
        .collect();
    let mut subjects: Vec<&str> = obs.iter().map(|o| o.subject.as_str()).collect();
    subjects.sort();
    subjects.dedup();
    Ok(KbMuFit {
        relation: ID.into(),
        title: "Ko–Badler μ-functions: joint angles at heel strike and toe off vs step length"
            .into(),
        citation: "Ko & Badler (1993), Straight line walking animation based on kinematic \
                   generalization that preserves the original characteristics, appendix A, \
                   eqs. 21–24 (argument corrected to sl·ll(S*)/ll(S))"
            .into(),
        equation: "mu1 = -alpha1 (x - sl*) + mu1*; mu_i = alpha_i (x - sl*) + mu_i* (i = 2..4); \
                   x = sl ll(S*)/ll(S)"
            .into(),
        n: obs.len(),
        n_subjects: subjects.len(),
        coefficients,
        rmse: (r.rss / obs.len() as f64).sqrt(),
        loo_rmse: r.press_rmse(),
        residual_mean_square: r.rss / r.df_resid.max(1) as f64,
        per_mu,
        termination: format!("converged: {}; {}", r.converged, r.termination),
        notes,
        gaitfit_version: crate::GAITFIT_VERSION.into(),
    })
}

/// The paper's bounds in θ order: α₁ ∈ [0, 0.3], α₂…α₄ ≥ 0, μ* free.
pub fn bounds() -> [(f64, f64); 8] {
    let free = (f64::NEG_INFINITY, f64::INFINITY);
    [
        (0.0, ALPHA1_MAX),
        (0.0, f64::INFINITY),
        (0.0, f64::INFINITY),
        (0.0, f64::INFINITY),
        free,
        free,
        free,
        free,
    ]
}

/// The least-squares line of μᵢ on x with its slope (in the μ's own sign convention) restricted
/// to `slope_bounds`: the closed form a bounded fit of this separable model must reproduce
/// (an independent check of [`fit`]). Returns (αᵢ, μᵢ*).
pub fn separable_line(
    obs: &[MuObservation],
    i: usize,
    sl_star: f64,
    slope_bounds: (f64, f64),
) -> (f64, f64) {
    let pts: Vec<(f64, f64)> = obs
        .iter()
        .filter(|o| o.index == i)
        .map(|o| (MuModel::sign(i) * (o.x - sl_star), o.y))
        .collect();
    let n = pts.len() as f64;
    let mx = pts.iter().map(|p| p.0).sum::<f64>() / n;
    let my = pts.iter().map(|p| p.1).sum::<f64>() / n;
    let sxy: f64 = pts.iter().map(|p| (p.0 - mx) * (p.1 - my)).sum();
    let sxx: f64 = pts.iter().map(|p| (p.0 - mx).powi(2)).sum();
    let slope = (sxy / sxx).clamp(slope_bounds.0, slope_bounds.1);
    (slope, my - slope * mx)
}

/// Reads the trials tables, fits and writes `out` (JSON, via `fsio::write_atomic_bytes`).
pub fn fit_tables(
    paths: &[std::path::PathBuf],
    prototype: &crate::generator::generalize::prototype::Prototype,
    out: Option<&std::path::Path>,
) -> crate::Result<KbMuFit> {
    let mut tables = Vec::new();
    for p in paths {
        tables.push(crate::ingest::trials::read_trials(p)?);
    }
    let (obs, ll_star, skipped) = observations(&tables, prototype.walk.body().leg_length());
    let mut notes: Vec<String> = paths
        .iter()
        .map(|p| format!("data: {}", p.display()))
        .collect();
    notes.extend(skipped.into_iter().map(|s| format!("skipped: {s}")));
    let f = fit(&obs, prototype.walk.step_length(), ll_star, notes)?;
    if let Some(out) = out {
        let text = serde_json::to_string_pretty(&f).unwrap_or_default() + "\n";
        crate::fsio::write_atomic_bytes(out, text.as_bytes())?;
    }
    Ok(f)
}
