//! The three `gaitfit generate` subcommands share their flags and their schedule vocabulary:
//! `--seconds`, `--count`, `--fps` (one default), `--steps-out`, `--schedule` (`step` or
//! `steps`, `speed_*`, `step_length_*`, `step_freq_*`), `--bvh-units`, `-o`. Each runs the real
//! binary in a fresh temp folder.
use assert_cmd::Command;
use clap::CommandFactory;
use std::path::Path;

fn gaitfit(dir: &Path) -> Command {
    let mut c = Command::cargo_bin("gaitfit").unwrap();
    c.current_dir(dir);
    c
}

/// Data rows of a trials table written by `--steps-out`, as (speed m/s, step length m).
fn steps(path: &Path) -> Vec<(f64, f64)> {
    let text = std::fs::read_to_string(path).unwrap();
    let mut lines = text.lines();
    let head: Vec<&str> = lines.next().unwrap().split(',').collect();
    let col = |n: &str| head.iter().position(|h| *h == n).unwrap();
    let (v, sl) = (col("speed_m_per_s"), col("step_length_m"));
    lines
        .map(|l| {
            let f: Vec<&str> = l.split(',').collect();
            (f[v].parse().unwrap(), f[sl].parse().unwrap())
        })
        .collect()
}

#[test]
fn the_command_line_is_well_formed() {
    gaitfit::cli::Cli::command().debug_assert();
}

#[test]
fn every_generator_shows_the_same_shared_flags() {
    let dir = tempfile::tempdir().unwrap();
    for g in ["run", "walk", "generalize"] {
        let out = gaitfit(dir.path())
            .args(["generate", g, "--help"])
            .output()
            .unwrap();
        let help = String::from_utf8_lossy(&out.stdout).to_string();
        for flag in [
            "--schedule <FILE>",
            "--seconds <S>",
            "--count <N>",
            "--fps <HZ>",
            "[default: 120]",
            "--steps-out <FILE>",
            "--bvh-units <UNIT>",
            "-o, --output <FILE>",
        ] {
            assert!(help.contains(flag), "{g}: no {flag:?} in\n{help}");
        }
        assert!(!help.contains("--steps <"), "{g}: --steps is gone\n{help}");
    }
    let out = gaitfit(dir.path())
        .args(["generate", "generalize", "--help"])
        .output()
        .unwrap();
    let help = String::from_utf8_lossy(&out.stdout).to_string();
    assert_eq!(help.matches("<A1,A2,A3,A4>").count(), 1, "{help}");
}

#[test]
fn count_gives_that_many_steps_in_every_generator() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    for (g, extra) in [
        ("run", &["--no-stop"][..]),
        ("walk", &["--speed", "4.5km/h"][..]),
        ("generalize", &["--step-length", "70cm"][..]),
    ] {
        let out = gaitfit(d)
            .args(["generate", g, "--count", "5"])
            .args(extra)
            .args([
                "--steps-out",
                &format!("{g}.csv"),
                "-o",
                &format!("{g}.trc"),
            ])
            .output()
            .unwrap();
        let err = String::from_utf8_lossy(&out.stderr);
        assert!(out.status.success(), "{g}: {err}");
        assert!(
            !err.contains("whole step"),
            "{g}: a count is not rounded: {err}"
        );
        assert_eq!(steps(&d.join(format!("{g}.csv"))).len(), 5, "{g}");
    }
    // --count and --seconds exclude each other.
    let out = gaitfit(d)
        .args([
            "generate",
            "walk",
            "--count",
            "3",
            "--seconds",
            "3",
            "-o",
            "x.csv",
        ])
        .output()
        .unwrap();
    assert!(!out.status.success());
}

#[test]
fn walk_and_generalize_say_when_they_round_a_duration_to_whole_steps() {
    let dir = tempfile::tempdir().unwrap();
    for (g, extra) in [
        ("walk", ["--speed", "5km/h"]),
        ("generalize", ["--step-length", "0.7"]),
    ] {
        let out = gaitfit(dir.path())
            .args(["generate", g, "--seconds", "3", "--fps", "60"])
            .args(extra)
            .args(["--steps-out", "s.csv", "-o", "w.csv"])
            .output()
            .unwrap();
        assert!(out.status.success());
        let err = String::from_utf8_lossy(&out.stderr).to_string();
        let n = steps(&dir.path().join("s.csv")).len();
        assert!(
            err.contains("--seconds 3 holds") && err.contains(&format!("walking {n} whole step")),
            "{g}: {err}"
        );
    }
}

#[test]
fn one_schedule_vocabulary_drives_every_generator() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    // `steps`: how many steps each row holds; the schedule has its own length.
    std::fs::write(
        d.join("walk.csv"),
        "steps,step_length_cm,step_freq_steps_per_min\n3,70,110\n3,75,115\n",
    )
    .unwrap();
    for g in ["walk", "generalize"] {
        let out = gaitfit(d)
            .args(["generate", g, "--schedule", "walk.csv"])
            .args([
                "--steps-out",
                &format!("{g}_steps.csv"),
                "-o",
                &format!("{g}.bvh"),
            ])
            .output()
            .unwrap();
        assert!(
            out.status.success(),
            "{g}: {}",
            String::from_utf8_lossy(&out.stderr)
        );
        let s = steps(&d.join(format!("{g}_steps.csv")));
        assert_eq!(s.len(), 6, "{g}");
        for (i, &(v, sl)) in s.iter().enumerate() {
            let (sl0, sf) = if i < 3 { (0.70, 110.0) } else { (0.75, 115.0) };
            assert!((sl - sl0).abs() < 1e-9, "{g} step {i}: sl {sl}");
            assert!((v - sl0 * sf / 60.0).abs() < 1e-9, "{g} step {i}: v {v}");
        }
    }
    // `step`: where each row starts; --count says how long the last row holds.
    std::fs::write(d.join("run.csv"), "step,speed_km_per_h\n0,10\n3,12\n").unwrap();
    let out = gaitfit(d)
        .args([
            "generate",
            "run",
            "--schedule",
            "run.csv",
            "--count",
            "6",
            "--no-stop",
        ])
        .args(["--steps-out", "run_steps.csv", "-o", "run.bvh"])
        .output()
        .unwrap();
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let s = steps(&d.join("run_steps.csv"));
    assert_eq!(s.len(), 6);
    assert!((s[5].0 - 12.0 / 3.6).abs() < 1e-9, "{s:?}");
    std::fs::write(d.join("walk2.csv"), "step,speed_km_per_h\n0,4\n3,4.5\n").unwrap();
    let out = gaitfit(d)
        .args([
            "generate",
            "walk",
            "--schedule",
            "walk2.csv",
            "--count",
            "6",
        ])
        .args(["--steps-out", "walk2_steps.csv", "-o", "walk2.trc"])
        .output()
        .unwrap();
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let s = steps(&d.join("walk2_steps.csv"));
    assert_eq!(s.len(), 6);
    assert!(
        (s[0].0 - 4.0 / 3.6).abs() < 1e-9 && (s[5].0 - 4.5 / 3.6).abs() < 1e-9,
        "{s:?}"
    );
    // A column a generator cannot use is refused, naming it.
    std::fs::write(d.join("lvl.csv"), "steps,step_length_m,level\n3,0.7,0.5\n").unwrap();
    let out = gaitfit(d)
        .args([
            "generate",
            "generalize",
            "--schedule",
            "lvl.csv",
            "-o",
            "x.bvh",
        ])
        .output()
        .unwrap();
    assert!(!out.status.success());
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(err.contains("lvl.csv") && err.contains("level"), "{err}");
    assert!(!d.join("x.bvh").exists());
}

#[test]
fn bvh_units_scale_every_length() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    for unit in ["m", "cm"] {
        gaitfit(d)
            .args([
                "generate",
                "generalize",
                "--step-length",
                "0.7",
                "--count",
                "2",
            ])
            .args(["--bvh-units", unit, "-o", &format!("{unit}.bvh")])
            .assert()
            .success();
    }
    let m = gaitfit::export::bvh::read(&d.join("m.bvh")).unwrap();
    let cm = gaitfit::export::bvh::read(&d.join("cm.bvh")).unwrap();
    let (pm, pcm) = (m.positions(1), cm.positions(1));
    assert_eq!(pm.len(), pcm.len());
    for (a, b) in pm.iter().zip(&pcm) {
        assert!((*a * 100.0 - *b).length() < 1e-4, "{a} m vs {b} cm");
    }
    let out = gaitfit(d)
        .args(["generate", "walk", "--bvh-units", "ft", "-o", "x.bvh"])
        .output()
        .unwrap();
    assert!(!out.status.success());
    assert!(String::from_utf8_lossy(&out.stderr).contains("use m or cm"));
}
