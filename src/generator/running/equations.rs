//! The published relations the generator is driven by (running paper eqs. 2, 4, 5), behind one
//! type so that refitted coefficients (`--fits DIR`) and the published ones are interchangeable.
//!
//! TEMPORARY: a private copy of the formulas until the relations layer (`crate::relations`)
//! lands; then [`RunRelations`] delegates to it and this copy goes.
use std::path::Path;

use crate::generator::GenerateError;
use crate::units::{hz_to_steps_per_min, m_per_min_to_m_per_s, m_per_s_to_m_per_min};

/// Coefficients of eq. 2 (step length from speed) and eqs. 4–5 (flight time from step
/// frequency), in the paper's units (m, m/min, steps/min, s).
#[derive(Debug, Clone, PartialEq)]
pub struct RunRelations {
    /// Eq. 2 intercept `a`, m (published 0.1394).
    pub a: f64,
    /// Eq. 2 slope `b`, m per m/min (published 0.00465).
    pub b: f64,
    /// Speed above which step length stays constant, m/min, for a 1.8 m figure (published 400).
    pub v_norm: f64,
    /// Eq. 5 (quadratic, below `k1`) coefficients q0, q1, q2 (published −0.675e-3, −0.15e-3,
    /// 0.542e-5).
    pub q: [f64; 3],
    /// Eq. 4 (cubic, `k1`..`k2`) coefficients c0..c3 (published −8.925, 0.131, −0.623e-3,
    /// 0.979e-6).
    pub c: [f64; 4],
    /// Knot between eq. 5 and eq. 4, steps/min (published 180).
    pub k1: f64,
    /// Knot above which the flight time is constant, steps/min (published 230).
    pub k2: f64,
    /// Where the coefficients came from (`published` or the fits folder).
    pub source: String,
}

/// The expertise `level` slider is normalised to [−1 (poor), 1 (skilled)]; the paper's two
/// level ranges are ±0.001 in eq. 2 and ±0.0001 in eqs. 4–5.
pub const LEVEL_SCALE_SL: f64 = 0.001;
/// See [`LEVEL_SCALE_SL`].
pub const LEVEL_SCALE_TFLIGHT: f64 = 0.0001;

impl RunRelations {
    /// The published coefficients of Bruderlin & Calvert (1996).
    pub fn published() -> Self {
        RunRelations {
            a: 0.1394,
            b: 0.00465,
            v_norm: 400.0,
            q: [-0.675e-3, -0.15e-3, 0.542e-5],
            c: [-8.925, 0.131, -0.623e-3, 0.979e-6],
            k1: 180.0,
            k2: 230.0,
            source: "published".into(),
        }
    }

    /// Reads refitted coefficients from `dir/run-sl-v.json` and `dir/run-tflight-sf.json`
    /// (`coefficients: [{name, value}, ...]`); a coefficient missing from a file keeps its
    /// published value.
    pub fn from_fits(dir: &Path) -> Result<Self, GenerateError> {
        let mut r = RunRelations::published();
        let sl = read_coefficients(&dir.join("run-sl-v.json"))?;
        let tf = read_coefficients(&dir.join("run-tflight-sf.json"))?;
        for (name, value) in sl {
            match name.as_str() {
                "a" => r.a = value,
                "b" => r.b = value,
                "v_norm" => r.v_norm = value,
                _ => {}
            }
        }
        for (name, value) in tf {
            match name.as_str() {
                "q0" => r.q[0] = value,
                "q1" => r.q[1] = value,
                "q2" => r.q[2] = value,
                "c0" => r.c[0] = value,
                "c1" => r.c[1] = value,
                "c2" => r.c[2] = value,
                "c3" => r.c[3] = value,
                "k1" => r.k1 = value,
                "k2" => r.k2 = value,
                _ => {}
            }
        }
        r.source = dir.display().to_string();
        Ok(r)
    }

    /// `√(h/1.8)`: the Froude factor of eq. 2.
    fn froude(body_height: f64) -> f64 {
        (body_height / 1.8).sqrt()
    }

    /// Eq. 2 slope for this level and height, m per m/min.
    fn slope(&self, level: f64, body_height: f64) -> f64 {
        (self.b + level * LEVEL_SCALE_SL) * Self::froude(body_height)
    }

    /// The speed (m/s) above which step length stays constant: v_norm·√(h/1.8).
    pub fn v_norm_m_per_s(&self, body_height: f64) -> f64 {
        m_per_min_to_m_per_s(self.v_norm * Self::froude(body_height))
    }

    /// Eq. 2: step length (m) for speed `v` (m/s), level in [−1, 1] and body height (m);
    /// constant above v_norm.
    pub fn step_length(&self, v: f64, level: f64, body_height: f64) -> f64 {
        let vn = self.v_norm_m_per_s(body_height);
        self.a + self.slope(level, body_height) * m_per_s_to_m_per_min(v.min(vn))
    }

    /// The constant step length above v_norm, m.
    pub fn step_length_norm(&self, level: f64, body_height: f64) -> f64 {
        self.step_length(f64::INFINITY, level, body_height)
    }

    /// Inverse of eq. 2 below v_norm: the speed (m/s) whose natural step length is `sl`, or
    /// `None` when `sl` is outside the rising part of the relation.
    pub fn speed_for_step_length(&self, sl: f64, level: f64, body_height: f64) -> Option<f64> {
        let b = self.slope(level, body_height);
        if b <= 0.0 || sl <= self.a || sl > self.step_length_norm(level, body_height) + 1e-12 {
            return None;
        }
        Some(m_per_min_to_m_per_s((sl - self.a) / b))
    }

    /// Eqs. 1 and 2 together: the natural step length (m) at step frequency `sf` (steps/s).
    /// Below v_norm, sl = a/(1 − b'·sf); above, sl = sl_norm. `None` when b'·sf ≥ 1.
    pub fn step_length_for_freq(&self, sf: f64, level: f64, body_height: f64) -> Option<f64> {
        let sf_min = hz_to_steps_per_min(sf);
        let b = self.slope(level, body_height);
        let sl_norm = self.step_length_norm(level, body_height);
        let vn = self.v_norm * Self::froude(body_height);
        if sf_min >= vn / sl_norm {
            return Some(sl_norm);
        }
        let den = 1.0 - b * sf_min;
        (den > 0.0 && self.a / den > 0.0).then(|| self.a / den)
    }

    /// Eqs. 4–5: flight time (s) at step frequency `sf` (steps/s) and level in [−1, 1]: eq. 5
    /// below k1, eq. 4 from k1 to k2, constant above k2. The level enters each equation with its
    /// published sign (eq. 5 subtracts it; see the module docs of the relations layer).
    pub fn flight_time(&self, sf: f64, level: f64) -> f64 {
        let f = hz_to_steps_per_min(sf);
        let lt = level * LEVEL_SCALE_TFLIGHT;
        if f < self.k1 {
            self.q[0] + (self.q[1] - lt) * f + self.q[2] * f * f
        } else {
            let f = f.min(self.k2);
            self.c[0] + (self.c[1] + lt) * f + self.c[2] * f * f + self.c[3] * f * f * f
        }
    }
}

fn read_coefficients(path: &Path) -> Result<Vec<(String, f64)>, GenerateError> {
    let bad = |message: String| GenerateError::Parameter {
        name: "fits".into(),
        value: f64::NAN,
        message: format!("{}: {message}", path.display()),
    };
    let text = std::fs::read_to_string(path)
        .map_err(|e| bad(format!("cannot read ({e}); run `gaitfit fit` first or drop --fits")))?;
    let json: serde_json::Value =
        serde_json::from_str(&text).map_err(|e| bad(format!("not valid JSON: {e}")))?;
    let list = json
        .get("coefficients")
        .and_then(|c| c.as_array())
        .ok_or_else(|| bad("no `coefficients` array".into()))?;
    let mut out = Vec::with_capacity(list.len());
    for (i, c) in list.iter().enumerate() {
        let name = c.get("name").and_then(|n| n.as_str());
        let value = c.get("value").and_then(|v| v.as_f64());
        match (name, value) {
            (Some(n), Some(v)) if v.is_finite() => out.push((n.to_string(), v)),
            _ => return Err(bad(format!("coefficient {i} lacks a name or a finite value"))),
        }
    }
    Ok(out)
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
        // Same via eqs. 1+2 from sf.
        let sl2 = r.step_length_for_freq(v / sl, 0.0, 1.8).unwrap();
        assert!((sl2 - sl).abs() < 1e-12);
        // eq. 4 at 187 steps/min ≈ 0.188 s.
        assert!((r.flight_time(187.0 / 60.0, 0.0) - 0.188).abs() < 5e-4);
        let back = r.speed_for_step_length(sl, 0.0, 1.8).unwrap();
        assert!((back - v).abs() < 1e-12);
    }
}
