//! Every fit's coefficients against an independent least-squares computation (closed-form or
//! normal equations written out here, in a basis of the test's own choosing), to 1e-9 relative.
#![allow(clippy::needless_range_loop)]
use gaitfit::fit::inference::SeMethod;
use gaitfit::fit::pipeline::{fit_relation, FitOptions};
use gaitfit::fit::synthetic::{synthetic_rows, SyntheticSpec};
use gaitfit::ingest::trials::TrialsTable;
use gaitfit::relations::{Inputs, Relation, RunSlV, RunTflightSf, WalkSlSf, WalkTdsSf};
use nalgebra::{DMatrix, DVector};

const REL: f64 = 1e-9;

fn table(spec: SyntheticSpec) -> TrialsTable {
    TrialsTable::from_step_rows("synthetic", &synthetic_rows(&spec))
}

fn close(a: f64, b: f64, what: &str) {
    let rel = (a - b).abs() / b.abs().max(1e-300);
    assert!(
        rel < REL,
        "{what}: pipeline {a:e} vs independent {b:e} (rel {rel:e})"
    );
}

/// Normal equations with column equilibration, solved by LU: independent of the pipeline's QR.
fn normal_equations(x: &DMatrix<f64>, y: &DVector<f64>) -> DVector<f64> {
    let d: Vec<f64> = (0..x.ncols()).map(|j| 1.0 / x.column(j).norm()).collect();
    let mut xs = x.clone();
    for j in 0..x.ncols() {
        xs.column_mut(j).scale_mut(d[j]);
    }
    let xtx = xs.transpose() * &xs;
    let xty = xs.transpose() * y;
    let z = xtx.lu().solve(&xty).unwrap();
    DVector::from_iterator(z.len(), (0..z.len()).map(|j| z[j] * d[j]))
}

fn data_of(rel: &dyn Relation, t: &TrialsTable) -> Vec<([f64; 4], f64, String)> {
    (0..t.len())
        .filter(|&i| t.gait[i] == Some(rel.card().gait))
        .filter_map(|i| {
            rel.observe(&t.values(i), 0)
                .ok()
                .map(|o| (o.x.values, o.y, t.subject_name(i).to_string()))
        })
        .collect()
}

#[test]
fn walk_sl_sf_is_the_closed_form_slope_through_the_origin() {
    let t = table(SyntheticSpec {
        rows: 600,
        seed: 11,
        ..Default::default()
    });
    let rel = WalkSlSf::published();
    let iid = FitOptions {
        se: Some(SeMethod::Iid),
        ..FitOptions::default()
    };
    let o = fit_relation(&rel, std::slice::from_ref(&t), &iid).unwrap();
    let d = data_of(&rel, &t);
    let (sxy, sxx, syy) = d.iter().fold((0.0, 0.0, 0.0), |a, (x, y, _)| {
        let z = x[0] * x[1];
        (a.0 + z * y, a.1 + z * z, a.2 + y * y)
    });
    let k = sxy / sxx;
    close(o.record.coefficient("k").unwrap().value, k, "k");
    // Uncentred r² (NIST): 1 − RSS/Σy².
    let rss: f64 = d
        .iter()
        .map(|(x, y, _)| (y - k * x[0] * x[1]).powi(2))
        .sum();
    close(o.record.r2, 1.0 - rss / syy, "uncentred r²");
    let n = d.len() as f64;
    close(
        o.record.coefficient("k").unwrap().std_error.unwrap(),
        (rss / (n - 1.0) / sxx).sqrt(),
        "se(k)",
    );
    assert!(o.record.r2_definition.starts_with("uncentred"));
}

#[test]
fn walk_tds_sf_is_the_closed_form_simple_regression() {
    let t = table(SyntheticSpec {
        rows: 600,
        seed: 12,
        ..Default::default()
    });
    let rel = WalkTdsSf::published();
    let iid = FitOptions {
        se: Some(SeMethod::Iid),
        ..FitOptions::default()
    };
    let o = fit_relation(&rel, std::slice::from_ref(&t), &iid).unwrap();
    let d = data_of(&rel, &t);
    let n = d.len() as f64;
    let mx = d.iter().map(|v| v.0[0]).sum::<f64>() / n;
    let my = d.iter().map(|v| v.1).sum::<f64>() / n;
    let sxx: f64 = d.iter().map(|v| (v.0[0] - mx).powi(2)).sum();
    let sxy: f64 = d.iter().map(|v| (v.0[0] - mx) * (v.1 - my)).sum();
    let d1 = sxy / sxx;
    let d0 = my - d1 * mx;
    close(o.record.coefficient("d1").unwrap().value, d1, "d1");
    close(o.record.coefficient("d0").unwrap().value, d0, "d0");
    let rss: f64 = d.iter().map(|v| (v.1 - d0 - d1 * v.0[0]).powi(2)).sum();
    let syy: f64 = d.iter().map(|v| (v.1 - my).powi(2)).sum();
    close(o.record.r2, 1.0 - rss / syy, "r²");
    close(
        o.record.residual_mean_square,
        rss / (n - 2.0),
        "residual mean square",
    );
    close(
        o.record.coefficient("d1").unwrap().std_error.unwrap(),
        (rss / (n - 2.0) / sxx).sqrt(),
        "se(d1)",
    );
    close(o.record.rmse, (rss / n).sqrt(), "rmse");
    // Leave-one-subject-out: the closed form on the other subjects, each subject predicted.
    let subjects: std::collections::BTreeSet<&str> = d.iter().map(|v| v.2.as_str()).collect();
    assert!(subjects.len() >= 3);
    let mut sq = 0.0;
    for s in &subjects {
        let train: Vec<_> = d.iter().filter(|v| v.2 != *s).collect();
        let m = train.len() as f64;
        let mx = train.iter().map(|v| v.0[0]).sum::<f64>() / m;
        let my = train.iter().map(|v| v.1).sum::<f64>() / m;
        let sxx: f64 = train.iter().map(|v| (v.0[0] - mx).powi(2)).sum();
        let sxy: f64 = train.iter().map(|v| (v.0[0] - mx) * (v.1 - my)).sum();
        let (b1, b0) = (sxy / sxx, my - sxy / sxx * mx);
        sq += d
            .iter()
            .filter(|v| v.2 == *s)
            .map(|v| (v.1 - b0 - b1 * v.0[0]).powi(2))
            .sum::<f64>();
    }
    close(o.record.loso_rmse.unwrap(), (sq / n).sqrt(), "loso rmse");
}

#[test]
fn run_sl_v_with_levels_matches_normal_equations_at_the_profiled_v_norm() {
    let t = table(SyntheticSpec {
        rows: 1200,
        subjects: 4,
        seed: 13,
        ..Default::default()
    });
    let rel = RunSlV::published();
    let o = fit_relation(&rel, std::slice::from_ref(&t), &FitOptions::default()).unwrap();
    let vn = o.record.coefficient("v_norm").unwrap().value;
    assert!(o.record.coefficient("v_norm").unwrap().held.is_none());
    assert!((vn - 400.0).abs() < 10.0, "v_norm {vn}");
    let d = data_of(&rel, &t);
    let subjects: Vec<String> = {
        let mut s: Vec<String> = d.iter().map(|v| v.2.clone()).collect();
        s.sort();
        s.dedup();
        s
    };
    let ns = subjects.len();
    assert_eq!(ns, 2, "synthetic runners: subjects S01, S03");
    // Independent parameterisation: sl = a + Σ_s b_s·z·[s]; b = mean b_s, level_s = b_s − b.
    let z = |v: f64, h: f64, vn: f64| {
        let r = (h / 1.8f64).sqrt();
        v.min(vn * r) * r
    };
    let rss_at = |vn: f64| -> (DVector<f64>, f64) {
        let mut x = DMatrix::zeros(d.len(), 1 + ns);
        let mut y = DVector::zeros(d.len());
        for (i, (xi, yi, s)) in d.iter().enumerate() {
            x[(i, 0)] = 1.0;
            let k = subjects.iter().position(|n| n == s).unwrap();
            x[(i, 1 + k)] = z(xi[0], xi[1], vn);
            y[i] = *yi;
        }
        let beta = normal_equations(&x, &y);
        let rss = (&y - &x * &beta).norm_squared();
        (beta, rss)
    };
    let (beta, rss) = rss_at(vn);
    let b = beta.rows(1, ns).mean();
    close(o.record.coefficient("a").unwrap().value, beta[0], "a");
    close(o.record.coefficient("b").unwrap().value, b, "b");
    for (k, s) in subjects.iter().enumerate() {
        close(
            o.record.coefficient(&format!("level[{s}]")).unwrap().value,
            beta[1 + k] - b,
            "level",
        );
    }
    // The profiled v_norm is a minimum of the independent RSS.
    for dv in [-0.5, 0.5, -2.0, 2.0] {
        assert!(
            rss_at(vn + dv).1 >= rss * (1.0 - 1e-12),
            "RSS lower at v_norm {}",
            vn + dv
        );
    }
}

/// Fits a polynomial of `deg` by normal equations in the basis ((x − 200)/30)^i, returns raw.
fn raw_poly(xs: &[f64], ys: &[f64], deg: usize) -> Vec<f64> {
    let (m, s) = (200.0, 30.0);
    let mut x = DMatrix::zeros(xs.len(), deg + 1);
    for (i, &v) in xs.iter().enumerate() {
        for j in 0..=deg {
            x[(i, j)] = ((v - m) / s).powi(j as i32);
        }
    }
    let beta = normal_equations(&x, &DVector::from_column_slice(ys));
    // Expand Σ β_j ((x − m)/s)^j into raw powers.
    let mut raw = vec![0.0; deg + 1];
    for j in 0..=deg {
        let mut binom = 1.0;
        for k in 0..=j {
            raw[k] += beta[j] / s.powi(j as i32) * binom * (-m).powi((j - k) as i32);
            binom = binom * (j - k) as f64 / (k + 1) as f64;
        }
    }
    raw
}

#[test]
fn run_tflight_sf_free_pieces_match_separate_polynomial_fits() {
    let t = table(SyntheticSpec {
        rows: 1500,
        seed: 14,
        ..Default::default()
    });
    let rel = RunTflightSf::published();
    let o = fit_relation(&rel, std::slice::from_ref(&t), &FitOptions::default()).unwrap();
    let k1 = o.record.coefficient("k1").unwrap().value;
    let k2 = o.record.coefficient("k2").unwrap().value;
    let d = data_of(&rel, &t);
    let (lo, hi): (Vec<_>, Vec<_>) = d.iter().partition(|v| v.0[0] < k1);
    let q = raw_poly(
        &lo.iter().map(|v| v.0[0]).collect::<Vec<_>>(),
        &lo.iter().map(|v| v.1).collect::<Vec<_>>(),
        2,
    );
    let c = raw_poly(
        &hi.iter().map(|v| v.0[0].min(k2)).collect::<Vec<_>>(),
        &hi.iter().map(|v| v.1).collect::<Vec<_>>(),
        3,
    );
    for (i, name) in ["q0", "q1", "q2"].iter().enumerate() {
        close(o.record.coefficient(name).unwrap().value, q[i], name);
    }
    for (i, name) in ["c0", "c1", "c2", "c3"].iter().enumerate() {
        close(o.record.coefficient(name).unwrap().value, c[i], name);
    }
    let jump = o
        .record
        .derived
        .iter()
        .find(|d| d.name == "jump_at_k1")
        .unwrap();
    let cubic = |x: f64| c[0] + x * (c[1] + x * (c[2] + x * c[3]));
    let quad = |x: f64| q[0] + x * (q[1] + x * q[2]);
    assert!((jump.value - (cubic(k1) - quad(k1))).abs() < 1e-9);
    assert!((jump.published - 0.031395).abs() < 1e-6);
}

#[test]
fn run_tflight_sf_continuous_matches_a_substituted_normal_equation_fit() {
    let t = table(SyntheticSpec {
        rows: 1500,
        seed: 15,
        ..Default::default()
    });
    let rel = RunTflightSf::published_continuous();
    let o = fit_relation(&rel, std::slice::from_ref(&t), &FitOptions::default()).unwrap();
    let k1 = o.record.coefficient("k1").unwrap().value;
    let k2 = o.record.coefficient("k2").unwrap().value;
    let d = data_of(&rel, &t);
    // Basis: cubic in w = (x − 200)/30 for x ≥ k1; below, cubic(k1) + γ1(w − w1) + γ2(w² − w1²).
    let w = |x: f64| (x - 200.0) / 30.0;
    let w1 = w(k1);
    let mut x = DMatrix::zeros(d.len(), 6);
    let mut y = DVector::zeros(d.len());
    for (i, (xi, yi, _)) in d.iter().enumerate() {
        if xi[0] < k1 {
            for j in 0..4 {
                x[(i, j)] = w1.powi(j as i32);
            }
            x[(i, 4)] = w(xi[0]) - w1;
            x[(i, 5)] = w(xi[0]).powi(2) - w1 * w1;
        } else {
            let ww = w(xi[0].min(k2));
            for j in 0..4 {
                x[(i, j)] = ww.powi(j as i32);
            }
        }
        y[i] = *yi;
    }
    let beta = normal_equations(&x, &y);
    let cub = |x: f64| (0..4).map(|j| beta[j] * w(x).powi(j as i32)).sum::<f64>();
    let quad = |x: f64| cub(k1) + beta[4] * (w(x) - w1) + beta[5] * (w(x).powi(2) - w1 * w1);
    let r = &o.refit;
    // Above k2 the model is the plateau cubic(k2).
    for sf in [150.0, 170.0, 179.0, k1, 190.0, 210.0, 229.0, 240.0] {
        let want = if sf < k1 { quad(sf) } else { cub(sf.min(k2)) };
        close(
            r.predict(&Inputs::new(&[sf])),
            want,
            &format!("t_flight({sf})"),
        );
    }
    let jump = o
        .record
        .derived
        .iter()
        .find(|d| d.name == "jump_at_k1")
        .unwrap();
    assert!(
        jump.value.abs() < 1e-9,
        "continuous variant jumps by {}",
        jump.value
    );
}

/// Noise-free data: the breakpoint F-test is F = ∞ (RSS 0 with the breakpoint, > 0 without); the
/// breakpoint must be fitted, not held at the published value as a "degenerate" test.
#[test]
fn run_sl_v_on_exact_data_fits_v_norm() {
    let t = table(SyntheticSpec {
        rows: 600,
        subjects: 4,
        seed: 5,
        sl_noise: 0.0,
        level: 0.0,
        ..Default::default()
    });
    let rel = RunSlV::published();
    let o = fit_relation(&rel, std::slice::from_ref(&t), &FitOptions::default()).unwrap();
    let c = o.record.coefficient("v_norm").unwrap();
    assert!(c.held.is_none(), "v_norm held: {:?}", c.held);
    assert!((c.value - 400.0).abs() < 10.0, "v_norm {}", c.value);
}
