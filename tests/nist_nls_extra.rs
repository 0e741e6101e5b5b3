//! Golden test: the argmin layer (`gaitfit::fit::nonlinear::nls`) against the 19 NIST StRD
//! nonlinear sets of `../shared/data/nist-strd/nls/extra/` (the other 8 are in `nist_nls.rs`),
//! from both NIST starting points, with analytic gradients (formulas from the `.dat` headers).
//!
//! Required: certified parameters with LRE ≥ 6 and a convergence test met from both starts;
//! certified SDs and residual SD LRE ≥ 6 — except where f64 cannot resolve the certified value
//! (Lanczos1: certified RSS 1.4e-25, residual SD 8.9e-13, below the rounding of its y values;
//! its parameter SDs follow from that residual SD), for which the table prints what is reached.
//!
//! **Known failure: MGH17 from start 1** (50, 150, −100, 1, 2; "higher difficulty"): the
//! trust-region solver creeps along the valley b4 ≈ 1, b5 ≈ 0.004 and stops at the iteration
//! budget (2000) with LRE 0. The test asserts that it *says so* (converged = false, so
//! `gaitfit` reports an optimizer failure rather than wrong coefficients); from start 2 MGH17
//! is certified to LRE 10.9. 53 of the 54 runs meet LRE ≥ 6 (measured 2026-12-07: lowest
//! 6.42, Lanczos3 start 2).
//!
//! Run: `cargo test --release --test nist_nls_extra -- --ignored --nocapture`
// `!(a >= b)` is deliberate: a NaN LRE must fail.
#![allow(clippy::neg_cmp_op_on_partial_ord)]

use gaitfit::fit::nonlinear::{nls, Model, NlsOptions, Rows};
use gaitfit::fit::stats::{lre, min_lre};
use gaitfit::fit::strd::read;
use std::f64::consts::PI;

type Value = fn(&[f64], &[f64]) -> f64;
type Grad = fn(&[f64], &[f64], &mut [f64]);

/// A NIST model: parameters, value and analytic gradient over one row of inputs.
struct Nist {
    name: &'static str,
    p: usize,
    /// Inputs per row (Nelson has two).
    width: usize,
    /// Nelson's response is ln y.
    log_y: bool,
    f: Value,
    g: Grad,
}

impl Model for &Nist {
    fn n_params(&self) -> usize {
        self.p
    }
    fn value(&self, x: &[f64], b: &[f64]) -> f64 {
        (self.f)(x, b)
    }
    fn gradient(&self, x: &[f64], b: &[f64], g: &mut [f64]) {
        (self.g)(x, b, g)
    }
}

fn exp3(x: f64, b: &[f64]) -> f64 {
    b[0] * (-b[1] * x).exp() + b[2] * (-b[3] * x).exp() + b[4] * (-b[5] * x).exp()
}
fn exp3_g(x: f64, b: &[f64], g: &mut [f64]) {
    for k in 0..3 {
        let e = (-b[2 * k + 1] * x).exp();
        g[2 * k] = e;
        g[2 * k + 1] = -b[2 * k] * x * e;
    }
}
fn gauss(x: f64, b: &[f64]) -> f64 {
    b[0] * (-b[1] * x).exp()
        + b[2] * (-((x - b[3]) / b[4]).powi(2)).exp()
        + b[5] * (-((x - b[6]) / b[7]).powi(2)).exp()
}
fn gauss_g(x: f64, b: &[f64], g: &mut [f64]) {
    let e = (-b[1] * x).exp();
    g[0] = e;
    g[1] = -b[0] * x * e;
    for (a, c, w) in [(2, 3, 4), (5, 6, 7)] {
        let d = x - b[c];
        let e = (-(d / b[w]).powi(2)).exp();
        g[a] = e;
        g[c] = b[a] * e * 2.0 * d / (b[w] * b[w]);
        g[w] = b[a] * e * 2.0 * d * d / (b[w] * b[w] * b[w]);
    }
}
fn rational(x: f64, b: &[f64], nn: usize, nd: usize) -> (f64, f64) {
    let num: f64 = (0..nn).map(|k| b[k] * x.powi(k as i32)).sum();
    let den: f64 = 1.0
        + (0..nd)
            .map(|k| b[nn + k] * x.powi(k as i32 + 1))
            .sum::<f64>();
    (num, den)
}
fn rational_g(x: f64, b: &[f64], nn: usize, nd: usize, g: &mut [f64]) {
    let (num, den) = rational(x, b, nn, nd);
    for (k, gk) in g.iter_mut().enumerate().take(nn) {
        *gk = x.powi(k as i32) / den;
    }
    for k in 0..nd {
        g[nn + k] = -num * x.powi(k as i32 + 1) / (den * den);
    }
}
fn enso_g(x: f64, b: &[f64], g: &mut [f64]) {
    let w0 = 2.0 * PI * x / 12.0;
    g[0] = 1.0;
    g[1] = w0.cos();
    g[2] = w0.sin();
    for (per, c, s) in [(3, 4, 5), (6, 7, 8)] {
        let w = 2.0 * PI * x / b[per];
        g[c] = w.cos();
        g[s] = w.sin();
        g[per] = (-b[c] * w.sin() + b[s] * w.cos()) * (-2.0 * PI * x / (b[per] * b[per]));
    }
}

fn sets() -> Vec<Nist> {
    vec![
        Nist {
            name: "Misra1b",
            p: 2,
            width: 1,
            log_y: false,
            f: |x, b| b[0] * (1.0 - (1.0 + b[1] * x[0] / 2.0).powi(-2)),
            g: |x, b, g| {
                let u = 1.0 + b[1] * x[0] / 2.0;
                g[0] = 1.0 - u.powi(-2);
                g[1] = b[0] * x[0] * u.powi(-3);
            },
        },
        Nist {
            name: "Misra1c",
            p: 2,
            width: 1,
            log_y: false,
            f: |x, b| b[0] * (1.0 - (1.0 + 2.0 * b[1] * x[0]).powf(-0.5)),
            g: |x, b, g| {
                let u = 1.0 + 2.0 * b[1] * x[0];
                g[0] = 1.0 - u.powf(-0.5);
                g[1] = b[0] * x[0] * u.powf(-1.5);
            },
        },
        Nist {
            name: "Misra1d",
            p: 2,
            width: 1,
            log_y: false,
            f: |x, b| b[0] * b[1] * x[0] / (1.0 + b[1] * x[0]),
            g: |x, b, g| {
                let u = 1.0 + b[1] * x[0];
                g[0] = b[1] * x[0] / u;
                g[1] = b[0] * x[0] / (u * u);
            },
        },
        Nist {
            name: "Chwirut1",
            p: 3,
            width: 1,
            log_y: false,
            f: |x, b| (-b[0] * x[0]).exp() / (b[1] + b[2] * x[0]),
            g: |x, b, g| {
                let (x, e) = (x[0], (-b[0] * x[0]).exp());
                let d = b[1] + b[2] * x;
                g[0] = -x * e / d;
                g[1] = -e / (d * d);
                g[2] = -x * e / (d * d);
            },
        },
        Nist {
            name: "Lanczos1",
            p: 6,
            width: 1,
            log_y: false,
            f: |x, b| exp3(x[0], b),
            g: |x, b, g| exp3_g(x[0], b, g),
        },
        Nist {
            name: "Lanczos2",
            p: 6,
            width: 1,
            log_y: false,
            f: |x, b| exp3(x[0], b),
            g: |x, b, g| exp3_g(x[0], b, g),
        },
        Nist {
            name: "Lanczos3",
            p: 6,
            width: 1,
            log_y: false,
            f: |x, b| exp3(x[0], b),
            g: |x, b, g| exp3_g(x[0], b, g),
        },
        Nist {
            name: "Gauss1",
            p: 8,
            width: 1,
            log_y: false,
            f: |x, b| gauss(x[0], b),
            g: |x, b, g| gauss_g(x[0], b, g),
        },
        Nist {
            name: "Gauss2",
            p: 8,
            width: 1,
            log_y: false,
            f: |x, b| gauss(x[0], b),
            g: |x, b, g| gauss_g(x[0], b, g),
        },
        Nist {
            name: "Gauss3",
            p: 8,
            width: 1,
            log_y: false,
            f: |x, b| gauss(x[0], b),
            g: |x, b, g| gauss_g(x[0], b, g),
        },
        Nist {
            name: "Roszman1",
            p: 4,
            width: 1,
            log_y: false,
            f: |x, b| b[0] - b[1] * x[0] - (b[2] / (x[0] - b[3])).atan() / PI,
            g: |x, b, g| {
                let d = x[0] - b[3];
                let z = b[2] / d;
                let k = 1.0 / (PI * (1.0 + z * z));
                g[0] = 1.0;
                g[1] = -x[0];
                g[2] = -k / d;
                g[3] = -k * b[2] / (d * d);
            },
        },
        Nist {
            name: "ENSO",
            p: 9,
            width: 1,
            log_y: false,
            f: |x, b| {
                let mut g = [0.0; 9];
                enso_g(x[0], b, &mut g);
                b[0] + b[1] * g[1]
                    + b[2] * g[2]
                    + b[4] * g[4]
                    + b[5] * g[5]
                    + b[7] * g[7]
                    + b[8] * g[8]
            },
            g: |x, b, g| enso_g(x[0], b, g),
        },
        Nist {
            name: "Kirby2",
            p: 5,
            width: 1,
            log_y: false,
            f: |x, b| {
                let (n, d) = rational(x[0], b, 3, 2);
                n / d
            },
            g: |x, b, g| rational_g(x[0], b, 3, 2, g),
        },
        Nist {
            name: "Hahn1",
            p: 7,
            width: 1,
            log_y: false,
            f: |x, b| {
                let (n, d) = rational(x[0], b, 4, 3);
                n / d
            },
            g: |x, b, g| rational_g(x[0], b, 4, 3, g),
        },
        Nist {
            name: "Nelson",
            p: 3,
            width: 2,
            log_y: true,
            f: |x, b| b[0] - b[1] * x[0] * (-b[2] * x[1]).exp(),
            g: |x, b, g| {
                let e = (-b[2] * x[1]).exp();
                g[0] = 1.0;
                g[1] = -x[0] * e;
                g[2] = b[1] * x[0] * x[1] * e;
            },
        },
        Nist {
            name: "MGH17",
            p: 5,
            width: 1,
            log_y: false,
            f: |x, b| b[0] + b[1] * (-x[0] * b[3]).exp() + b[2] * (-x[0] * b[4]).exp(),
            g: |x, b, g| {
                let (e4, e5) = ((-x[0] * b[3]).exp(), (-x[0] * b[4]).exp());
                g[0] = 1.0;
                g[1] = e4;
                g[2] = e5;
                g[3] = -b[1] * x[0] * e4;
                g[4] = -b[2] * x[0] * e5;
            },
        },
        Nist {
            name: "MGH10",
            p: 3,
            width: 1,
            log_y: false,
            f: |x, b| b[0] * (b[1] / (x[0] + b[2])).exp(),
            g: |x, b, g| {
                let d = x[0] + b[2];
                let e = (b[1] / d).exp();
                g[0] = e;
                g[1] = b[0] * e / d;
                g[2] = -b[0] * e * b[1] / (d * d);
            },
        },
        Nist {
            name: "Rat42",
            p: 3,
            width: 1,
            log_y: false,
            f: |x, b| b[0] / (1.0 + (b[1] - b[2] * x[0]).exp()),
            g: |x, b, g| {
                let e = (b[1] - b[2] * x[0]).exp();
                let d = 1.0 + e;
                g[0] = 1.0 / d;
                g[1] = -b[0] * e / (d * d);
                g[2] = b[0] * e * x[0] / (d * d);
            },
        },
        Nist {
            name: "Bennett5",
            p: 3,
            width: 1,
            log_y: false,
            f: |x, b| b[0] * (b[1] + x[0]).powf(-1.0 / b[2]),
            g: |x, b, g| {
                let u = b[1] + x[0];
                let p = u.powf(-1.0 / b[2]);
                g[0] = p;
                g[1] = -b[0] * p / (b[2] * u);
                g[2] = b[0] * p * u.ln() / (b[2] * b[2]);
            },
        },
    ]
}

#[test]
#[ignore = "needs ../shared/data"]
fn nist_nls_extra_both_starts() {
    let mut table = format!(
        "{:<9} {:>5} {:>6} {:>6} {:>8} {:>5} {:<5} {}\n",
        "set", "start", "coef", "SD", "resid SD", "iter", "conv", "termination"
    );
    let mut failures = Vec::new();
    for set in sets() {
        let path = gaitfit::shared_data::require(format!("nist-strd/nls/extra/{}.dat", set.name));
        let d = read(&path).unwrap_or_else(|e| panic!("{e}"));
        assert_eq!(d.parameters.len(), set.p, "{}", set.name);
        let y: Vec<f64> = d
            .column("y")
            .expect("y")
            .into_iter()
            .map(|v| if set.log_y { v.ln() } else { v })
            .collect();
        let xs: Vec<f64> = if set.width == 1 {
            d.column("x").expect("x")
        } else {
            let (a, b) = (d.column("x1").expect("x1"), d.column("x2").expect("x2"));
            a.iter().zip(&b).flat_map(|(&p, &q)| [p, q]).collect()
        };
        let rows = Rows::new(&xs, set.width).expect("rows");
        let cert = d.certified_values();
        let cert_sd: Vec<f64> = d.parameters.iter().map(|p| p.std_dev).collect();
        // Lanczos1: certified residual SD 8.9e-13 is below what its data resolve in f64.
        let unresolvable = set.name == "Lanczos1";
        for k in 1..=2 {
            let start = d.start(k).expect("two starts");
            let opts = NlsOptions {
                name: d.name.clone(),
                ..NlsOptions::default()
            };
            match nls(&&set, rows, &y, &start, &opts) {
                Ok(fit) if set.name == "MGH17" && k == 1 && !fit.converged => {
                    table.push_str(&format!(
                        "{:<9} {:>5} known failure: not converged ({}, {} iterations), reported\n",
                        d.name, k, fit.termination, fit.iterations
                    ));
                }
                Ok(fit) => {
                    let (c, sd, rs) = (
                        min_lre(&fit.theta, &cert),
                        min_lre(&fit.std_error, &cert_sd),
                        lre(fit.sigma, d.residual_sd),
                    );
                    table.push_str(&format!(
                        "{:<9} {:>5} {:>6.2} {:>6.2} {:>8.2} {:>5} {:<5} {}\n",
                        d.name, k, c, sd, rs, fit.iterations, fit.converged, fit.termination
                    ));
                    if !(c >= 6.0 && fit.converged) {
                        failures.push(format!(
                            "{} start {k}: LRE {c:.2}, converged {} ({}), θ = {:?}",
                            d.name, fit.converged, fit.termination, fit.theta
                        ));
                    }
                    let digits = sd >= 6.0 && rs >= 6.0;
                    if !(unresolvable || digits) {
                        failures.push(format!(
                            "{} start {k}: SD LRE {sd:.2}, residual SD LRE {rs:.2}",
                            d.name
                        ));
                    }
                }
                Err(e) => {
                    table.push_str(&format!("{:<9} {:>5} error: {e}\n", d.name, k));
                    failures.push(format!("{} start {k}: {e}", d.name));
                }
            }
        }
    }
    println!("{table}");
    assert!(failures.is_empty(), "{}", failures.join("\n"));
}
