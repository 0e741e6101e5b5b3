//! The derived per-step tables committed in `data/` are what `gaitfit events` produces from
//! `../shared/data` today (the commands are listed in `data/README.md`).
use assert_cmd::Command;
use gaitfit::shared_data::require;

/// `(committed table, inputs relative to the shared data folder)`, as in `data/README.md`.
pub const TABLES: &[(&str, &[&str])] = &[
    ("run_hamner2013.csv", &["hamner2013"]),
    (
        "run_bmclab.csv",
        &["bmclab/motion_capture_run.trc+bmclab/grf_run.mot"],
    ),
    (
        "walk_bmclab.csv",
        &[
            "bmclab/walk1.trc",
            "bmclab/walk2.trc",
            "bmclab/WinterTableA1.txt",
        ],
    ),
    ("walk_schreiber2019.csv", &["schreiber2019"]),
    ("walk_wbds.csv", &["wbds"]),
];

#[test]
#[ignore = "needs ../shared/data"]
fn regenerating_the_tables_reproduces_the_committed_ones() {
    let root = require(".");
    let dir = tempfile::tempdir().unwrap();
    for (name, inputs) in TABLES {
        let out = dir.path().join(name);
        let mut cmd = Command::cargo_bin("gaitfit").unwrap();
        cmd.current_dir(env!("CARGO_MANIFEST_DIR")).arg("events");
        for i in *inputs {
            let arg: Vec<String> = i
                .split('+')
                .map(|p| root.join(p).display().to_string())
                .collect();
            cmd.arg(arg.join("+"));
        }
        cmd.arg("-o").arg(&out).assert().success();
        let fresh = std::fs::read_to_string(&out).unwrap();
        let committed =
            std::fs::read_to_string(format!("{}/data/{name}", env!("CARGO_MANIFEST_DIR"))).unwrap();
        assert!(
            fresh == committed,
            "data/{name} differs from a fresh `gaitfit events` run; regenerate it with the command \
             in data/README.md"
        );
    }
}

#[test]
fn committed_tables_are_valid_trials_tables() {
    for (name, _) in TABLES {
        let p = std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
            .join("data")
            .join(name);
        let t = gaitfit::ingest::trials::read_trials(&p).unwrap();
        assert!(!t.is_empty(), "data/{name} is empty");
        assert!(
            t.flagged.is_empty(),
            "data/{name}: flagged rows {:?}",
            t.flagged
        );
    }
}
