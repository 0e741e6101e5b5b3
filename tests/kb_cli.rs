//! `gaitfit generate generalize` run as a binary in a fresh temporary folder.
use assert_cmd::Command;

#[test]
fn writes_a_bvh_for_a_tall_figure() {
    let dir = tempfile::tempdir().unwrap();
    Command::cargo_bin("gaitfit")
        .unwrap()
        .current_dir(dir.path())
        .args([
            "generate",
            "generalize",
            "--height",
            "1.9",
            "--step-length",
            "0.9",
        ])
        .args(["--count", "4", "-o", "walk.bvh"])
        .assert()
        .success();
    let bvh = gaitfit::export::bvh::read(&dir.path().join("walk.bvh")).unwrap();
    let text = std::fs::read_to_string(dir.path().join("walk.bvh")).unwrap();
    assert!(text.starts_with("HIERARCHY"));
    // 4 steps of √(ll/ll*)·0.494 s at 120 fps.
    let frames: usize = text
        .lines()
        .find_map(|l| l.strip_prefix("Frames:"))
        .unwrap()
        .trim()
        .parse()
        .unwrap();
    assert!((250..300).contains(&frames), "{frames} frames");
    assert!(
        bvh.index("r_knee").is_some(),
        "the figure's joints are in the BVH"
    );
}

#[test]
fn follows_a_schedule_and_reports_bad_rows() {
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(
        dir.path().join("steps.csv"),
        "step_length_m,step_freq_steps_per_min\n0.6,120\n0.7,\n0.65,115.4\n",
    )
    .unwrap();
    Command::cargo_bin("gaitfit")
        .unwrap()
        .current_dir(dir.path())
        .args([
            "generate",
            "generalize",
            "--height",
            "1.6",
            "--schedule",
            "steps.csv",
        ])
        .args(["-o", "walk.csv"])
        .assert()
        .success();
    assert!(dir.path().join("walk.csv").exists());
    std::fs::write(dir.path().join("bad.csv"), "step_length_m\n0.6\nabc\n").unwrap();
    let out = Command::cargo_bin("gaitfit")
        .unwrap()
        .current_dir(dir.path())
        .args([
            "generate",
            "generalize",
            "--schedule",
            "bad.csv",
            "-o",
            "w.bvh",
        ])
        .assert()
        .failure();
    let err = String::from_utf8_lossy(&out.get_output().stderr).to_string();
    assert!(
        err.contains("bad.csv: row 2, column step_length_m"),
        "{err}"
    );
}

#[test]
fn a_written_prototype_reads_back() {
    let dir = tempfile::tempdir().unwrap();
    Command::cargo_bin("gaitfit")
        .unwrap()
        .current_dir(dir.path())
        .args(["generate", "generalize", "--write-prototype", "p.json"])
        .assert()
        .success();
    Command::cargo_bin("gaitfit")
        .unwrap()
        .current_dir(dir.path())
        .args([
            "generate",
            "generalize",
            "--prototype",
            "p.json",
            "--step-length",
            "0.7",
        ])
        .args(["--count", "2", "-o", "w.trc"])
        .assert()
        .success();
    assert!(dir.path().join("w.trc").exists());
}
