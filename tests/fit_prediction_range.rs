//! Predictions outside the fitted range (issue 18, Build 5): every relation loaded from a fits
//! file knows the input range its coefficients were fitted on, reports whether a prediction's
//! inputs lie inside it, and holds the boundary value beyond it — the committed
//! `fits/run-tflight-sf.json` (steps between about 140 and 209 steps/min) must not follow its
//! cubic to 0.231 s at 230 steps/min.
use gaitfit::relations::{load_fit, CoefficientSet, Fitted, FittedRange, Inputs, RunTflightSf};
use std::path::{Path, PathBuf};

fn fits(id: &str) -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join(format!("fits/{id}.json"))
}

#[test]
fn flight_time_holds_the_boundary_beyond_the_fitted_steps() {
    for id in ["run-tflight-sf", "run-tflight-sf-continuous"] {
        let r = RunTflightSf::from_fit_file(&fits(id)).expect("committed fit");
        let f = load_fit(&fits(id)).expect("committed fit");
        let [lo, hi] = f.fitted_range().bounds[0].expect("sf range recorded");
        assert!(lo < hi);
        // Inside: the fitted curve itself, flagged inside.
        let mid = 0.5 * (lo + hi);
        let p = f.predict_checked(&Inputs::new(&[mid]));
        assert!(p.inside && p.at[0] == mid, "{id}");
        assert_eq!(p.value, f.predict(&Inputs::new(&[mid])));
        assert!(r.in_fitted_range(mid));
        // Beyond: the boundary value, flagged outside, for the typed method and the trait.
        let at_hi = r.flight_time(hi);
        let at_lo = r.flight_time(lo);
        for sf in [hi + 1e-9, 220.0, 230.0, 260.0] {
            assert!(!r.in_fitted_range(sf), "{id} {sf}");
            assert_eq!(r.flight_time(sf), at_hi, "{id} {sf}");
            let p = f.predict_checked(&Inputs::new(&[sf]));
            assert!(!p.inside);
            assert_eq!(p.at[0], hi);
        }
        for sf in [lo - 1e-9, 100.0, 0.0] {
            assert_eq!(r.flight_time(sf), at_lo, "{id} {sf}");
            assert!(!f.predict_checked(&Inputs::new(&[sf])).inside);
        }
        // Never running away: no prediction anywhere leaves the range the curve spans on the
        // fitted steps.
        let (mut mn, mut mx) = (f64::INFINITY, f64::NEG_INFINITY);
        for i in 0..=1000 {
            let v = r.flight_time(lo + (hi - lo) * i as f64 / 1000.0);
            mn = mn.min(v);
            mx = mx.max(v);
        }
        for i in 0..=400 {
            let v = r.flight_time(i as f64);
            // (1 µs: the 1000-step grid may miss an interior extremum by that much)
            assert!(
                v >= mn - 1e-6 && v <= mx + 1e-6,
                "{id}: {v} at {i} steps/min outside [{mn}, {mx}]"
            );
        }
    }
}

#[test]
fn every_committed_fit_carries_its_range_and_checks_it() {
    for id in [
        "run-sl-v",
        "run-tflight-sf",
        "run-tflight-sf-continuous",
        "walk-sl-sf",
        "walk-tds-sf",
        "kb-mu",
    ] {
        let r = load_fit(&fits(id)).expect("committed fit");
        let range = r.fitted_range();
        for (j, v) in r.card().inputs.iter().enumerate() {
            let [lo, hi] =
                range.bounds[j].unwrap_or_else(|| panic!("{id}: no range of {}", v.symbol));
            let mut x = [0.0; 4];
            for (k, b) in range.bounds.iter().enumerate().take(r.card().inputs.len()) {
                let [l, h] = b.expect("range");
                x[k] = 0.5 * (l + h);
            }
            assert!(r.predict_checked(&Inputs::new(&x)).inside, "{id}");
            x[j] = hi + (hi - lo).max(1.0);
            let out = r.predict_checked(&Inputs::new(&x));
            assert!(!out.inside, "{id}: {} above the range", v.symbol);
            assert_eq!(out.at[j], hi);
            let mut held = x;
            held[j] = hi;
            assert_eq!(out.value, r.predict(&Inputs::new(&held)), "{id}");
        }
    }
}

#[test]
fn published_and_rangeless_files_have_no_range() {
    let f = Fitted::published(Box::new(RunTflightSf::published()));
    assert_eq!(f.fitted_range(), FittedRange::default());
    assert!(f.predict_checked(&Inputs::new(&[250.0])).inside);
    let text = r#"{"relation": "walk-tds-sf", "coefficients": [
        {"name": "d0", "value": 30.0}, {"name": "d1", "value": -0.1}]}"#;
    let set = CoefficientSet::from_fit_json(Path::new("x.json"), text).expect("parse");
    assert!(set.ranges.is_empty());
    let f = gaitfit::relations::from_coefficients(&set).expect("relation");
    assert!(f.predict_checked(&Inputs::new(&[500.0])).inside);
    assert_eq!(
        f.predict_checked(&Inputs::new(&[500.0])).value,
        f.predict(&Inputs::new(&[500.0]))
    );
}
