//! Closing the loop through the fitting layer: `gaitfit generate run --fits fits/ --steps …` at
//! several speeds and body heights, then `gaitfit fit` on the generated steps, gives back the
//! coefficients the runs were generated with (the repository's refitted `fits/run-sl-v.json`
//! and `fits/run-tflight-sf.json`).
use assert_cmd::Command;
use serde_json::Value;
use std::path::{Path, PathBuf};

fn coefficients(path: &Path) -> Vec<(String, f64)> {
    let v: Value = serde_json::from_slice(&std::fs::read(path).unwrap()).unwrap();
    v["coefficients"]
        .as_array()
        .unwrap()
        .iter()
        .map(|c| {
            (
                c["name"].as_str().unwrap().to_string(),
                c["value"].as_f64().unwrap(),
            )
        })
        .collect()
}

fn get(c: &[(String, f64)], name: &str) -> f64 {
    c.iter()
        .find(|x| x.0 == name)
        .unwrap_or_else(|| panic!("no {name}"))
        .1
}

fn round_table(path: &Path) {
    let text = std::fs::read_to_string(path).unwrap();
    let mut lines = text.lines();
    let head: Vec<&str> = lines.next().unwrap().split(',').collect();
    let mut out = head.join(",") + "\n";
    for l in lines {
        let cells: Vec<String> = l
            .split(',')
            .zip(&head)
            .map(|(c, h)| match (c.parse::<f64>(), *h) {
                (Ok(v), "step_freq_steps_per_min") => format!("{v:.3}"),
                (Ok(v), h) if h.ends_with("_m") || h.ends_with("_s") || h.ends_with("_per_s") => {
                    format!("{v:.4}")
                }
                _ => c.to_string(),
            })
            .collect();
        out += &(cells.join(",") + "\n");
    }
    std::fs::write(path, out).unwrap();
}

/// Drops the steps whose step frequency lies outside `[lo, hi]` (steps/min).
fn keep_fitted_range(path: &Path, (lo, hi): (f64, f64)) {
    let text = std::fs::read_to_string(path).unwrap();
    let mut lines = text.lines();
    let head = lines.next().unwrap();
    let col = head
        .split(',')
        .position(|h| h == "step_freq_steps_per_min")
        .unwrap();
    let mut out = format!("{head}\n");
    for l in lines {
        let sf: f64 = l.split(',').nth(col).unwrap().parse().unwrap();
        if (lo..=hi).contains(&sf) {
            out += &format!("{l}\n");
        }
    }
    std::fs::write(path, out).unwrap();
}

#[test]
fn generated_steps_refit_to_the_generating_coefficients() {
    let fits = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("fits");
    let dir = tempfile::tempdir().unwrap();
    // Speeds from 6 km/h up in 1.5 km/h, two steps each, then a stop: both sides of v_norm
    // (eq. 2's plateau, 16–17.7 km/h for these heights) and of eq. 5's breakpoint k1. Not
    // faster than 18 km/h at 1.6 m and 21 km/h above: beyond, the refitted eq. 5 leaves under
    // a quarter of the step for support, which the generator refuses.
    let schedule = |top: f64| {
        let mut s = String::from("step,speed_km_per_h,action\n");
        let mut i = 0;
        while 6.0 + 1.5 * i as f64 <= top + 1e-9 {
            s += &format!("{},{},run\n", 2 * i, 6.0 + 1.5 * i as f64);
            i += 1;
        }
        s + &format!("{},,stop\n", 2 * i)
    };
    std::fs::write(dir.path().join("sched_1.6.csv"), schedule(18.0)).unwrap();
    std::fs::write(dir.path().join("sched_1.8.csv"), schedule(21.0)).unwrap();
    std::fs::write(dir.path().join("sched_1.95.csv"), schedule(21.0)).unwrap();
    // The generator follows eqs. 4–5 only inside the step frequencies the generating fit saw;
    // beyond them it holds the boundary value (relations::FittedRange), so only the steps
    // inside that range carry the curve to refit.
    let v: Value =
        serde_json::from_slice(&std::fs::read(fits.join("run-tflight-sf.json")).unwrap()).unwrap();
    let r = &v["valid_range"][0];
    assert_eq!(r["input"], "sf");
    let sf_range = (r["lo"].as_f64().unwrap(), r["hi"].as_f64().unwrap());
    let mut tables = Vec::new();
    for h in ["1.6", "1.8", "1.95"] {
        let steps = dir.path().join(format!("steps_{h}.csv"));
        Command::cargo_bin("gaitfit")
            .unwrap()
            .current_dir(dir.path())
            .args([
                "generate",
                "run",
                "--schedule",
                &format!("sched_{h}.csv"),
                "--height",
                h,
                "--fits",
            ])
            .arg(&fits)
            .args(["--seconds", "10", "--steps-out"])
            .arg(&steps)
            .args(["-o", &format!("run_{h}.csv")])
            .assert()
            .success();
        // As measured: 0.1 mm, 0.1 mm/s, 0.001 steps/min, 0.1 ms (the precision of the events
        // layer's step tables). Exact values would leave no residual at all, and the fit layer's
        // breakpoint F-test is then degenerate (RSS = 0 → F = ∞ → p = NaN), which holds v_norm
        // at its published value — a limitation of `gaitfit fit` on noise-free data, not of
        // the generated steps.
        round_table(&steps);
        keep_fitted_range(&steps, sf_range);
        tables.push(steps);
    }
    let out = dir.path().join("refit");
    Command::cargo_bin("gaitfit")
        .unwrap()
        .current_dir(dir.path())
        .arg("fit")
        .arg("--data")
        .args(&tables)
        .args([
            "--relation",
            "run-sl-v",
            "run-tflight-sf",
            "--no-report",
            "--fits",
        ])
        .arg(&out)
        .assert()
        .success();

    // Eq. 2: a, b and v_norm come back; every generated figure runs at level 0.
    let want = coefficients(&fits.join("run-sl-v.json"));
    let got = coefficients(&out.join("run-sl-v.json"));
    for name in ["a", "b", "v_norm"] {
        let (w, g) = (get(&want, name), get(&got, name));
        println!(
            "run-sl-v {name}: generated with {w}, refitted {g} ({:+.4} %)",
            (g / w - 1.0) * 100.0
        );
        assert!((g / w - 1.0).abs() < 2e-3, "run-sl-v {name}: {g} vs {w}");
    }
    for (name, g) in got.iter().filter(|c| c.0.starts_with("level")) {
        assert!(g.abs() < 1e-5, "{name} = {g}");
    }
    // Eqs. 4–5: the cubic's coefficients are strongly correlated, so the curves are compared
    // over the step frequencies generated (and the breakpoint k1 directly).
    let want = coefficients(&fits.join("run-tflight-sf.json"));
    let got = coefficients(&out.join("run-tflight-sf.json"));
    let curve = |c: &[(String, f64)], sf: f64| {
        if sf < get(c, "k1") {
            get(c, "q0") + get(c, "q1") * sf + get(c, "q2") * sf * sf
        } else {
            let s = sf.min(get(c, "k2"));
            get(c, "c0") + get(c, "c1") * s + get(c, "c2") * s * s + get(c, "c3") * s * s * s
        }
    };
    let mut sfs = Vec::new();
    for t in &tables {
        let text = std::fs::read_to_string(t).unwrap();
        let mut lines = text.lines();
        let head: Vec<&str> = lines.next().unwrap().split(',').collect();
        let col = head
            .iter()
            .position(|h| *h == "step_freq_steps_per_min")
            .unwrap();
        sfs.extend(lines.map(|l| l.split(',').nth(col).unwrap().parse::<f64>().unwrap()));
    }
    // The breakpoint k1 is identified only up to the gap between the generated step
    // frequencies around it: both must split the data alike.
    let (k1w, k1g) = (get(&want, "k1"), get(&got, "k1"));
    let (lo, hi) = (k1w.min(k1g), k1w.max(k1g));
    let between = sfs.iter().filter(|sf| **sf > lo && **sf < hi).count();
    println!("run-tflight-sf k1: generated with {k1w}, refitted {k1g}, {between} steps between");
    assert_eq!(between, 0, "k1 {k1g} vs {k1w} split the data differently");
    let worst = sfs
        .iter()
        .map(|&sf| (curve(&got, sf) - curve(&want, sf)).abs())
        .fold(0.0, f64::max);
    println!(
        "run-tflight-sf: {} steps, worst |Δ t_flight| {:.2e} s",
        sfs.len(),
        worst
    );
    assert!(worst < 2e-4, "t_flight curves differ by {worst} s");
}
