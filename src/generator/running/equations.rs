//! The published relations the generator is driven by (running paper eqs. 2, 4, 5), as an
//! adapter over the relations layer ([`RunSlV`], [`RunTflightSf`]) in SI units, so that refitted
//! coefficients (`--fits DIR`) and the published ones are interchangeable.
//!
//! Level: the generator's expertise slider is normalised to [−1 (poor), 1 (skilled)] and scaled
//! to the paper's two ranges, ±0.001 in eq. 2 and ±0.0001 in eqs. 4–5. The relations layer does
//! not carry eqs. 4–5's level term (it is not fitted), so it is added here with the paper's
//! printed signs: `+level·sf` in eq. 4 and `−level·sf` in eq. 5 (eq. 5 prints
//! `−(0.15·10⁻³ + level)·sf`, which makes skilled runners' flights *shorter* below 180 steps/min,
//! against the text's "expert runners tend to have a longer flight"; kept as printed and noted).
use std::path::Path;

use crate::generator::GenerateError;
use crate::relations::{RunSlV, RunTflightSf};
use crate::units::{hz_to_steps_per_min, m_per_min_to_m_per_s, m_per_s_to_m_per_min};

/// Eq. 2's level range: level = normalised level × this (m per m/min).
pub const LEVEL_SCALE_SL: f64 = 0.001;
/// Eqs. 4–5's level range: level = normalised level × this (s per step/min).
pub const LEVEL_SCALE_TFLIGHT: f64 = 0.0001;

/// Eqs. 2 and 4–5 with published or refitted coefficients.
#[derive(Debug, Clone, PartialEq)]
pub struct RunRelations {
    /// Eq. 2 (step length from speed).
    pub sl_v: RunSlV,
    /// Eqs. 4–5 (flight time from step frequency).
    pub tflight: RunTflightSf,
    /// Where the coefficients came from (`published` or the fits folder).
    pub source: String,
}

fn fits_err(path: &Path, e: impl std::fmt::Display) -> GenerateError {
    GenerateError::Parameter {
        name: "fits".into(),
        value: f64::NAN,
        message: format!(
            "{}: {e}; run `gaitfit fit` first, or drop --fits to use the published coefficients",
            path.display()
        ),
    }
}

impl RunRelations {
    /// The published coefficients of Bruderlin & Calvert (1996).
    pub fn published() -> Self {
        RunRelations {
            sl_v: RunSlV::published(),
            tflight: RunTflightSf::published(),
            source: "published".into(),
        }
    }

    /// Refitted coefficients from `dir/run-sl-v.json` and `dir/run-tflight-sf.json` (or, when
    /// that is absent, `dir/run-tflight-sf-continuous.json`), as written by `gaitfit fit`.
    pub fn from_fits(dir: &Path) -> Result<Self, GenerateError> {
        let sl_path = dir.join(format!("{}.json", RunSlV::ID));
        let sl_v = RunSlV::from_fit_file(&sl_path).map_err(|e| fits_err(&sl_path, e))?;
        let mut tf_path = dir.join(format!("{}.json", RunTflightSf::ID));
        if !tf_path.exists() {
            let cont = dir.join(format!("{}.json", RunTflightSf::ID_CONTINUOUS));
            if cont.exists() {
                tf_path = cont;
            }
        }
        let tflight = RunTflightSf::from_fit_file(&tf_path).map_err(|e| fits_err(&tf_path, e))?;
        Ok(RunRelations {
            sl_v,
            tflight,
            source: dir.display().to_string(),
        })
    }

    /// The speed (m/s) above which step length stays constant: v_norm·√(h/1.8).
    pub fn v_norm_m_per_s(&self, body_height: f64) -> f64 {
        m_per_min_to_m_per_s(self.sl_v.v_norm() * (body_height / 1.8).sqrt())
    }

    /// Eq. 2: step length (m) at speed `v` (m/s), normalised level, body height (m); constant
    /// above v_norm.
    pub fn step_length(&self, v: f64, level: f64, body_height: f64) -> f64 {
        self.sl_v
            .step_length(m_per_s_to_m_per_min(v), body_height, level * LEVEL_SCALE_SL)
    }

    /// The constant step length above v_norm, m.
    pub fn step_length_norm(&self, level: f64, body_height: f64) -> f64 {
        self.sl_v.sl_norm(body_height, level * LEVEL_SCALE_SL)
    }

    /// Inverse of eq. 2 below v_norm: the speed (m/s) whose natural step length is `sl`.
    pub fn speed_for_step_length(&self, sl: f64, level: f64, body_height: f64) -> Option<f64> {
        self.sl_v
            .speed_for_step_length(sl, body_height, level * LEVEL_SCALE_SL)
            .filter(|v| *v > 0.0)
            .map(m_per_min_to_m_per_s)
    }

    /// Eqs. 1 and 2 together: the natural step length (m) at step frequency `sf` (steps/s).
    pub fn step_length_for_freq(&self, sf: f64, level: f64, body_height: f64) -> Option<f64> {
        let f = hz_to_steps_per_min(sf);
        let v = self
            .sl_v
            .speed_for_step_freq(f, body_height, level * LEVEL_SCALE_SL)?;
        (v > 0.0).then(|| v / f)
    }

    /// Eqs. 4–5: flight time (s) at step frequency `sf` (steps/s) with the normalised level
    /// (see the module docs for its sign in each piece).
    pub fn flight_time(&self, sf: f64, level: f64) -> f64 {
        let f = hz_to_steps_per_min(sf);
        let c = self.tflight.coefficients();
        let (k1, k2) = (c[7], c[8]);
        let lt = level * LEVEL_SCALE_TFLIGHT;
        let lvl = if f < k1 { -lt * f } else { lt * f.min(k2) };
        self.tflight.flight_time(f) + lvl
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn paper_worked_numbers() {
        let r = RunRelations::published();
        // §2.2/§3.1.1: 12 km/h at 1.8 m → sl 1.07 m, sf 187 steps/min.
        let v = 12.0 / 3.6;
        let sl = r.step_length(v, 0.0, 1.8);
        assert!((sl - 1.0694).abs() < 1e-4);
        assert!((hz_to_steps_per_min(v / sl) - 187.0).abs() < 0.1);
        let sl2 = r.step_length_for_freq(v / sl, 0.0, 1.8).unwrap();
        assert!((sl2 - sl).abs() < 1e-12);
        assert!((r.flight_time(187.0 / 60.0, 0.0) - 0.188).abs() < 5e-4);
        let back = r.speed_for_step_length(sl, 0.0, 1.8).unwrap();
        assert!((back - v).abs() < 1e-12);
        // Level: skilled runners take longer steps (eq. 2) and fly longer above 180 (eq. 4).
        assert!(r.step_length(v, 1.0, 1.8) > sl);
        assert!(r.flight_time(3.2, 1.0) > r.flight_time(3.2, 0.0));
    }
}
