//! Golden test: the argmin layer (`gaitfit::fit::nonlinear::nls`) against the 8 NIST StRD
//! nonlinear sets in `../shared/data/nist-strd/nls/` (Misra1a, Chwirut2, DanWood, Thurber, MGH09,
//! Eckerle4, BoxBOD, Rat43), from both NIST starting points, with analytic gradients.
//!
//! Required (issue 3): certified parameters with LRE ≥ 6 from both starts, and a convergence
//! test met (not the iteration budget); the certified SDs and residual SD are asserted to
//! LRE ≥ 6 as well. A finite-difference-gradient run (the `Model::gradient` default) is printed
//! for information, not asserted.
//!
//! Rat43: the header prints 9 degrees of freedom, but n − p = 15 − 4 = 11 and the certified
//! residual SD uses 11; `nls` uses n − p.
//!
//! Run: `cargo test --release --test nist_nls -- --ignored --nocapture`
// `!(a >= b)` is deliberate: a NaN LRE must fail.
#![allow(clippy::neg_cmp_op_on_partial_ord)]

use gaitfit::fit::nonlinear::{nls, Model, NlsOptions, NonlinearFit, Rows};
use gaitfit::fit::stats::{lre, min_lre};
use gaitfit::fit::strd::{read, StrdDataset};

#[derive(Clone, Copy, Debug)]
enum Nist {
    Misra1a,
    Chwirut2,
    DanWood,
    Thurber,
    Mgh09,
    Eckerle4,
    BoxBod,
    Rat43,
}

impl Nist {
    fn file(self) -> &'static str {
        match self {
            Nist::Misra1a => "Misra1a",
            Nist::Chwirut2 => "Chwirut2",
            Nist::DanWood => "DanWood",
            Nist::Thurber => "Thurber",
            Nist::Mgh09 => "MGH09",
            Nist::Eckerle4 => "Eckerle4",
            Nist::BoxBod => "BoxBOD",
            Nist::Rat43 => "Rat43",
        }
    }
}

/// The NIST models with analytic gradients (formulas from the .dat headers).
struct Analytic(Nist);

impl Model for Analytic {
    fn n_params(&self) -> usize {
        match self.0 {
            Nist::Misra1a | Nist::DanWood | Nist::BoxBod => 2,
            Nist::Chwirut2 | Nist::Eckerle4 => 3,
            Nist::Mgh09 | Nist::Rat43 => 4,
            Nist::Thurber => 7,
        }
    }
    fn value(&self, x: &[f64], b: &[f64]) -> f64 {
        let x = x[0];
        match self.0 {
            Nist::Misra1a | Nist::BoxBod => b[0] * (1.0 - (-b[1] * x).exp()),
            Nist::Chwirut2 => (-b[0] * x).exp() / (b[1] + b[2] * x),
            Nist::DanWood => b[0] * x.powf(b[1]),
            Nist::Thurber => {
                let num = b[0] + b[1] * x + b[2] * x * x + b[3] * x * x * x;
                let den = 1.0 + b[4] * x + b[5] * x * x + b[6] * x * x * x;
                num / den
            }
            Nist::Mgh09 => b[0] * (x * x + x * b[1]) / (x * x + x * b[2] + b[3]),
            Nist::Eckerle4 => (b[0] / b[1]) * (-0.5 * ((x - b[2]) / b[1]).powi(2)).exp(),
            Nist::Rat43 => b[0] / (1.0 + (b[1] - b[2] * x).exp()).powf(1.0 / b[3]),
        }
    }
    fn gradient(&self, x: &[f64], b: &[f64], g: &mut [f64]) {
        let x = x[0];
        match self.0 {
            Nist::Misra1a | Nist::BoxBod => {
                let e = (-b[1] * x).exp();
                g[0] = 1.0 - e;
                g[1] = b[0] * x * e;
            }
            Nist::Chwirut2 => {
                let e = (-b[0] * x).exp();
                let d = b[1] + b[2] * x;
                g[0] = -x * e / d;
                g[1] = -e / (d * d);
                g[2] = -x * e / (d * d);
            }
            Nist::DanWood => {
                let p = x.powf(b[1]);
                g[0] = p;
                g[1] = b[0] * p * x.ln();
            }
            Nist::Thurber => {
                let num = b[0] + b[1] * x + b[2] * x * x + b[3] * x * x * x;
                let den = 1.0 + b[4] * x + b[5] * x * x + b[6] * x * x * x;
                let xp = [1.0, x, x * x, x * x * x];
                for k in 0..4 {
                    g[k] = xp[k] / den;
                }
                for k in 0..3 {
                    g[4 + k] = -num * xp[k + 1] / (den * den);
                }
            }
            Nist::Mgh09 => {
                let n = x * x + x * b[1];
                let d = x * x + x * b[2] + b[3];
                g[0] = n / d;
                g[1] = b[0] * x / d;
                g[2] = -b[0] * n * x / (d * d);
                g[3] = -b[0] * n / (d * d);
            }
            Nist::Eckerle4 => {
                let z = (x - b[2]) / b[1];
                let e = (-0.5 * z * z).exp();
                g[0] = e / b[1];
                g[1] = b[0] * e * (z * z - 1.0) / (b[1] * b[1]);
                g[2] = b[0] * e * z / (b[1] * b[1]);
            }
            Nist::Rat43 => {
                let e = (b[1] - b[2] * x).exp();
                let base = 1.0 + e;
                let f = b[0] / base.powf(1.0 / b[3]);
                g[0] = f / b[0];
                g[1] = -f * e / (b[3] * base);
                g[2] = f * e * x / (b[3] * base);
                g[3] = f * base.ln() / (b[3] * b[3]);
            }
        }
    }
}

/// The same model with the default (finite-difference) gradient.
struct Numeric(Nist);

impl Model for Numeric {
    fn n_params(&self) -> usize {
        Analytic(self.0).n_params()
    }
    fn value(&self, x: &[f64], b: &[f64]) -> f64 {
        Analytic(self.0).value(x, b)
    }
}

struct Row {
    coef: f64,
    sd: f64,
    resid_sd: f64,
    fit: NonlinearFit,
}

fn run<M: Model>(model: &M, d: &StrdDataset, start: &[f64]) -> Result<Row, String> {
    let x = d.column("x").ok_or("no x column")?;
    let y = d.column("y").ok_or("no y column")?;
    let opts = NlsOptions {
        name: d.name.clone(),
        ..NlsOptions::default()
    };
    let fit = nls(model, Rows::single(&x), &y, start, &opts).map_err(|e| e.to_string())?;
    let cert: Vec<f64> = d.certified_values();
    let cert_sd: Vec<f64> = d.parameters.iter().map(|p| p.std_dev).collect();
    Ok(Row {
        coef: min_lre(&fit.theta, &cert),
        sd: min_lre(&fit.std_error, &cert_sd),
        resid_sd: lre(fit.sigma, d.residual_sd),
        fit,
    })
}

#[test]
#[ignore = "needs ../shared/data"]
fn nist_nls_both_starts() {
    let sets = [
        Nist::Misra1a,
        Nist::Chwirut2,
        Nist::DanWood,
        Nist::Thurber,
        Nist::Mgh09,
        Nist::Eckerle4,
        Nist::BoxBod,
        Nist::Rat43,
    ];
    let mut table = format!(
        "{:<9} {:>5} {:<8} {:>6} {:>6} {:>8} {:>5} {:>4} {:<5} {}\n",
        "set", "start", "gradient", "coef", "SD", "resid SD", "iter", "runs", "conv", "termination"
    );
    let mut failures = Vec::new();
    for set in sets {
        let path = gaitfit::shared_data::require(format!("nist-strd/nls/{}.dat", set.file()));
        let d = read(&path).unwrap_or_else(|e| panic!("{e}"));
        if let Nist::Rat43 = set {
            // NIST prints 9 degrees of freedom; n − p = 11 is what the certified SD uses.
            assert_eq!(d.n_obs - d.parameters.len(), 11);
        }
        for k in 1..=2 {
            let start = d.start(k).expect("NLS sets have two starts");
            for (label, res) in [
                ("analytic", run(&Analytic(set), &d, &start)),
                ("numeric", run(&Numeric(set), &d, &start)),
            ] {
                match res {
                    Ok(r) => {
                        table.push_str(&format!(
                            "{:<9} {:>5} {:<8} {:>6.2} {:>6.2} {:>8.2} {:>5} {:>4} {:<5} {}\n",
                            d.name,
                            k,
                            label,
                            r.coef,
                            r.sd,
                            r.resid_sd,
                            r.fit.iterations,
                            r.fit.runs,
                            r.fit.converged,
                            r.fit.termination
                        ));
                        if label == "analytic" {
                            if !(r.coef >= 6.0 && r.fit.converged) {
                                failures.push(format!(
                                    "{} start {k}: LRE {:.2}, converged {} ({}), θ = {:?}",
                                    d.name, r.coef, r.fit.converged, r.fit.termination, r.fit.theta
                                ));
                            }
                            if !(r.sd >= 6.0 && r.resid_sd >= 6.0) {
                                failures.push(format!(
                                    "{} start {k}: SD LRE {:.2}, residual SD LRE {:.2}",
                                    d.name, r.sd, r.resid_sd
                                ));
                            }
                        }
                    }
                    Err(e) => {
                        table
                            .push_str(&format!("{:<9} {:>5} {:<8} error: {e}\n", d.name, k, label));
                        if label == "analytic" {
                            failures.push(format!("{} start {k}: {e}", d.name));
                        }
                    }
                }
            }
        }
    }
    table.push_str(
        "note: Rat43's header prints 9 degrees of freedom; n − p = 11 is used (and is what its \
         certified residual SD implies).\n\
         method: argmin TrustRegion + Steihaug on the Gauss–Newton model, Moré scaling, \
         MINPACK stopping tests; no set fails from either start.\n",
    );
    println!("NIST StRD nonlinear least squares — LRE (digits), minimum over parameters\n{table}");
    assert!(
        failures.is_empty(),
        "NLS failures:\n{}\n{table}",
        failures.join("\n")
    );
}
