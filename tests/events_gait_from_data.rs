//! `gaitfit events` tells walking from running from the data, never from the file name
//! (issue 21 item 4): a generated run saved under a name with "walk" in it reads back as a run
//! with flight phases, and a generated walk saved as "run…" as a walk with double support.
use std::path::Path;
use std::process::Command;

fn gaitfit(args: &[&str]) -> String {
    let out = Command::new(env!("CARGO_BIN_EXE_gaitfit"))
        .args(args)
        .output()
        .expect("run gaitfit");
    assert!(
        out.status.success(),
        "gaitfit {args:?}: {}",
        String::from_utf8_lossy(&out.stderr)
    );
    String::from_utf8(out.stdout).expect("utf-8")
}

/// The steps table's rows as (gait, flight_time_s, double_support_time_s) cells.
fn rows(csv: &str) -> Vec<(String, String, String)> {
    let mut lines = csv.lines();
    let header: Vec<&str> = lines.next().expect("a header").split(',').collect();
    let col = |name: &str| {
        header
            .iter()
            .position(|h| *h == name)
            .unwrap_or_else(|| panic!("no column {name}"))
    };
    let (g, f, d) = (
        col("gait"),
        col("flight_time_s"),
        col("double_support_time_s"),
    );
    lines
        .map(|l| {
            let c: Vec<&str> = l.split(',').collect();
            (c[g].to_string(), c[f].to_string(), c[d].to_string())
        })
        .collect()
}

fn generated(dir: &Path, gen: &str, speed: &str, name: &str) -> String {
    let path = dir.join(name);
    let p = path.to_str().expect("utf-8 path");
    gaitfit(&["generate", gen, "--speed", speed, "--seconds", "6", "-o", p]);
    gaitfit(&["events", p])
}

#[test]
fn a_run_named_walk_is_a_run_and_a_walk_named_run_is_a_walk() {
    let tmp = tempfile::tempdir().expect("temp dir");
    for name in ["walk_trial.trc", "walk_trial.csv"] {
        let r = rows(&generated(tmp.path(), "run", "3.5", name));
        assert!(r.len() >= 6, "{name}: {} steps", r.len());
        assert!(r.iter().all(|(g, _, _)| g == "run"), "{name}: {r:?}");
        let flights = r.iter().filter(|(_, f, _)| !f.is_empty()).count();
        assert!(
            flights * 2 > r.len(),
            "{name}: flight in {flights} of {}",
            r.len()
        );
    }
    for name in ["run_trial.trc", "run_trial.csv"] {
        let r = rows(&generated(tmp.path(), "walk", "1.3", name));
        assert!(r.len() >= 4, "{name}: {} steps", r.len());
        assert!(r.iter().all(|(g, _, _)| g == "walk"), "{name}: {r:?}");
        let ds = r.iter().filter(|(_, _, d)| !d.is_empty()).count();
        assert!(
            ds * 2 > r.len(),
            "{name}: double support in {ds} of {}",
            r.len()
        );
    }
}
