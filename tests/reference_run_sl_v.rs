//! Reference tests for `run-sl-v` against the running paper's own numbers
//! (Bruderlin & Calvert 1996, §2.2 eq. 2 and §3.1 / Figure 4).
use gaitfit::relations::{load_fit, CoefficientSet, Inputs, Relation, RunSlV};
use std::path::Path;

/// §3.1: "the velocity was locked at 12 km/h … the normally chosen step length of 1.07 m"
/// and "the default 187 steps/sec [sic: steps/min]".
#[test]
fn twelve_km_per_h_gives_1_07_m_and_187_steps_per_min() {
    let r = RunSlV::published();
    let v = 12.0 * 1000.0 / 60.0; // 200 m/min
    let sl = r.step_length(v, 1.8, 0.0);
    assert!((sl - 1.07).abs() < 0.005, "sl = {sl}");
    assert!((sl - (0.1394 + 0.00465 * 200.0)).abs() < 1e-12);
    let sf = r.step_freq(v, 1.8, 0.0);
    assert!((sf - 187.0).abs() < 0.5, "sf = {sf}");
    // The inverse: at 187.02 steps/min the relation gives back 200 m/min.
    let back = r.speed_for_step_freq(sf, 1.8, 0.0).unwrap();
    assert!((back - v).abs() < 1e-9);
    assert!((r.speed_for_step_length(sl, 1.8, 0.0).unwrap() - v).abs() < 1e-9);
}

/// Figure 2: taller runners take longer steps at the same speed (√(h/1.8) scaling), and level
/// ±0.001 gives the steepest/shallowest lines.
#[test]
fn body_height_and_level_order_the_figure_2_lines() {
    let r = RunSlV::published();
    let v = 300.0;
    let (s17, s18, s19) = (
        r.step_length(v, 1.7, 0.0),
        r.step_length(v, 1.8, 0.0),
        r.step_length(v, 1.9, 0.0),
    );
    assert!(s17 < s18 && s18 < s19);
    assert!((s19 - (0.1394 + 0.00465 * v * (1.9f64 / 1.8).sqrt())).abs() < 1e-12);
    assert!(r.step_length(v, 1.8, -0.001) < s17);
    assert!(r.step_length(v, 1.8, 0.001) > s19);
}

/// v_norm = 400 m/min (~24 km/h) at 1.8 m: constant step length above, continuous at the onset.
#[test]
fn plateau_above_v_norm_is_continuous() {
    let r = RunSlV::published();
    let at = r.step_length(400.0, 1.8, 0.0);
    assert!((at - (0.1394 + 0.00465 * 400.0)).abs() < 1e-12);
    assert_eq!(r.step_length(500.0, 1.8, 0.0), at);
    assert!((r.step_length(400.0 - 1e-9, 1.8, 0.0) - at).abs() < 1e-9);
    // For h = 1.6 the onset moves to 400·√(1.6/1.8).
    let onset = 400.0 * (1.6f64 / 1.8).sqrt();
    assert!((r.step_length(onset + 50.0, 1.6, 0.0) - r.sl_norm(1.6, 0.0)).abs() < 1e-12);
    assert!((r.step_length(onset, 1.6, 0.0) - r.sl_norm(1.6, 0.0)).abs() < 1e-12);
    // Above the plateau sf grows with v: v = sl_norm·sf.
    let sf = 500.0 / at;
    assert!((r.speed_for_step_freq(sf, 1.8, 0.0).unwrap() - 500.0).abs() < 1e-9);
}

#[test]
fn trait_predict_matches_typed_method_and_gradient_is_consistent() {
    let r = RunSlV::published();
    for (v, h) in [(150.0, 1.7), (250.0, 1.85), (450.0, 1.8)] {
        assert!(
            (r.predict_with(&r.card().published_values(), 0.0, &Inputs::new(&[v, h]))
                - r.step_length(v, h, 0.0))
            .abs()
                < 1e-15
        );
        let g = r
            .gradient(&r.card().published_values(), &Inputs::new(&[v, h]))
            .unwrap();
        for (i, gi) in g.iter().enumerate() {
            let mut p = r.card().published_values();
            let e = 1e-6 * p[i].abs().max(1e-3);
            p[i] += e;
            let up = r.predict_with(&p, 0.0, &Inputs::new(&[v, h]));
            p[i] -= 2.0 * e;
            let dn = r.predict_with(&p, 0.0, &Inputs::new(&[v, h]));
            assert!(
                ((up - dn) / (2.0 * e) - gi).abs() < 1e-6,
                "param {i} at v={v}"
            );
        }
    }
}

#[test]
fn loads_refitted_coefficients_and_levels_from_a_fits_file() {
    let json = r#"{"relation":"run-sl-v","coefficients":[
        {"name":"a","value":0.2},{"name":"b","value":0.004},{"name":"v_norm","value":380},
        {"name":"level[S01]","value":0.0005}]}"#;
    let dir = tempfile::tempdir().unwrap();
    let p = dir.path().join("run-sl-v.json");
    std::fs::write(&p, json).unwrap();
    let r = RunSlV::from_fit_file(&p).unwrap();
    assert_eq!((r.a(), r.b(), r.v_norm()), (0.2, 0.004, 380.0));
    assert_eq!(r.level("S01"), 0.0005);
    assert_eq!(r.level("nobody"), 0.0);
    let dynr = load_fit(&p).unwrap();
    assert_eq!(dynr.card().id, "run-sl-v");
    assert!((dynr.predict(&Inputs::new(&[200.0, 1.8])) - (0.2 + 0.004 * 200.0)).abs() < 1e-12);
    // Wrong relation or a missing coefficient are clear errors.
    let set = CoefficientSet::from_fit_json(
        Path::new("x.json"),
        r#"{"relation":"run-sl-v","coefficients":[{"name":"a","value":1}]}"#,
    )
    .unwrap();
    let e = RunSlV::from_coefficients(&set).unwrap_err().to_string();
    assert!(e.contains("`b` is missing"), "{e}");
    std::fs::write(
        &p,
        r#"{"relation":"walk-sl-sf","coefficients":[{"name":"k","value":0.004}]}"#,
    )
    .unwrap();
    assert!(RunSlV::from_fit_file(&p)
        .unwrap_err()
        .to_string()
        .contains("not of `run-sl-v`"));
}
