//! The report's plots: bounded size whatever the rows, a legend and a caption that say what was
//! drawn, colours by subject and data set, one labelled panel per kb-mu output.
use gaitfit::fit::pipeline::{fit_all, FitOptions, FitRun};
use gaitfit::fit::synthetic::{synthetic_rows, SyntheticSpec};
use gaitfit::ingest::trials::{read_trials, StepRow, TrialsTable};
use gaitfit::relations::{registry, Relation};
use gaitfit::report::layers::{MAX_GROUPS, MEAN_BINS, PALETTE};
use gaitfit::report::write_report;
use std::path::Path;

/// Bounds of issue 24.
const MAX_SVG_BYTES: u64 = 1_000_000;
const MAX_PNG_BYTES: u64 = 300_000;

/// Two data sets (tables) from one synthetic draw: subjects S01–S05 "on a treadmill", the
/// others "overground" (only the table names differ; the point is that they are kept apart).
fn tables(rows: usize, subjects: usize, seed: u64) -> Vec<TrialsTable> {
    let all = synthetic_rows(&SyntheticSpec {
        rows,
        subjects,
        seed,
        ..Default::default()
    });
    let (a, b): (Vec<StepRow>, Vec<StepRow>) =
        all.into_iter().partition(|r| r.subject.as_str() <= "S05");
    vec![
        TrialsTable::from_step_rows("treadmill.csv", &a),
        TrialsTable::from_step_rows("overground.csv", &b),
    ]
}

fn set_of(subject: &str) -> &'static str {
    if subject <= "S05" {
        "treadmill"
    } else {
        "overground"
    }
}

fn fit(tables: &[TrialsTable]) -> FitRun {
    let rels: Vec<Box<dyn Relation>> = registry();
    let run = fit_all(&rels, tables, &FitOptions::default(), true, |_| {});
    assert!(run.failures.is_empty(), "{:?}", run.failures);
    run
}

fn read(dir: &Path, name: &str) -> String {
    std::fs::read_to_string(dir.join(name)).unwrap_or_else(|e| panic!("{name}: {e}"))
}

#[test]
fn plots_of_1e5_rows_stay_small_and_say_they_draw_densities() {
    let t = tables(100_000, 10, 11);
    let run = fit(&t);
    let dir = tempfile::tempdir().unwrap();
    let files = write_report(dir.path(), &run.outcomes, &run.failures).unwrap();
    let mut total = 0;
    for f in &files {
        let len = std::fs::metadata(f).unwrap().len();
        total += len;
        match f.extension().and_then(|e| e.to_str()) {
            Some("svg") => assert!(len <= MAX_SVG_BYTES, "{}: {len} bytes", f.display()),
            Some("png") => assert!(len <= MAX_PNG_BYTES, "{}: {len} bytes", f.display()),
            _ => {}
        }
    }
    // Four figures per fitted relation, SVG and PNG, and summary.md.
    assert_eq!(files.len(), 8 * run.outcomes.len() + 1);
    assert!(total < 20_000_000, "{total} bytes in all");
    let summary = read(dir.path(), "summary.md");
    for o in &run.outcomes {
        let id = &o.record.relation;
        let n = o.prepared.obs.len();
        assert!(n > 5_000, "{id}: {n}");
        let n_txt = thousands(n);
        // The legend (first lines of the SVG's legend strip) names what was drawn.
        let main = read(dir.path(), &format!("{id}.svg"));
        assert!(
            main.contains(&format!("density of all {n_txt} rows")),
            "{id}.svg legend"
        );
        // No marker per row: at most the binned means' markers (groups × bins).
        let markers = main.matches("<circle").count();
        assert!(
            markers <= MAX_GROUPS * MEAN_BINS,
            "{id}.svg: {markers} markers"
        );
        let res = read(dir.path(), &format!("{id}-residuals.svg"));
        assert!(res.contains(&format!("density of all {n_txt} residuals")));
        let qq = read(dir.path(), &format!("{id}-qq.svg"));
        assert!(qq.contains("order statistics of"), "{id}-qq.svg");
        assert!(
            qq.contains(&format!("all {n_txt} residuals")),
            "{id}-qq.svg"
        );
        // The caption says the same for each plot.
        let section = &summary[summary.find(&format!("\n## {id}\n")).unwrap()..];
        let section = &section[..section[4..].find("\n## ").map_or(section.len(), |e| e + 4)];
        for stem in ["", "-residuals", "-residuals-inputs", "-qq"] {
            assert!(
                section.contains(&format!("![{id}{stem}]({id}{stem}.svg)")),
                "{id}{stem} in summary.md"
            );
        }
        assert_eq!(
            section
                .matches(&format!("the density of all {n_txt}"))
                .count(),
            3,
            "{id}: captions of the three density figures"
        );
        assert!(section.contains(&format!("exact order statistics of all {n_txt} residuals")));
        // At most ten subjects: each has its colour, named with its data set.
        for s in &o.prepared.subjects {
            assert!(
                main.contains(&format!("{s} · {}", set_of(s))),
                "{id}: {s} in legend"
            );
        }
    }
}

fn thousands(n: usize) -> String {
    let s = n.to_string();
    let mut out = String::new();
    for (i, c) in s.chars().enumerate() {
        if i > 0 && (s.len() - i) % 3 == 0 {
            out.push(',');
        }
        out.push(c);
    }
    out
}

fn hex((r, g, b): (u8, u8, u8)) -> String {
    format!("#{r:02X}{g:02X}{b:02X}")
}

#[test]
fn few_rows_are_all_drawn_coloured_by_subject_with_each_subjects_curve() {
    let t = tables(1_200, 8, 3);
    let run = fit(&t);
    let dir = tempfile::tempdir().unwrap();
    write_report(dir.path(), &run.outcomes, &run.failures).unwrap();
    let o = run
        .outcomes
        .iter()
        .find(|o| o.record.relation == "run-sl-v")
        .unwrap();
    let n = o.prepared.obs.len();
    let svg = read(dir.path(), "run-sl-v.svg");
    assert!(svg.contains(&format!("all {n} rows as points")));
    // Every row is one marker, in its subject's colour.
    assert_eq!(svg.matches("<circle").count(), n);
    for (k, s) in o.prepared.subjects.iter().enumerate() {
        assert!(
            svg.contains(&format!("{s} · {}", set_of(s))),
            "legend names {s}"
        );
        let c = hex(PALETTE[k]);
        assert!(
            svg.contains(&format!("fill=\"{c}\"")),
            "{s}'s points in {c}"
        );
        // run-sl-v has per-subject levels and body height: one refit curve per subject.
        assert!(
            svg.contains(&format!("stroke=\"{c}\"")),
            "{s}'s curve in {c}"
        );
    }
    let summary = read(dir.path(), "summary.md");
    assert!(summary.contains("each subject's refit at its mean h and its level"));
    let res = read(dir.path(), "run-sl-v-residuals-inputs.svg");
    assert_eq!(
        res.matches("<circle").count(),
        2 * n,
        "residuals vs v and vs h"
    );
}

#[test]
fn kb_mu_draws_one_labelled_panel_per_mu() {
    let data = Path::new(env!("CARGO_MANIFEST_DIR")).join("data");
    let t: Vec<TrialsTable> = ["walk_bmclab.csv", "walk_schreiber2019.csv"]
        .iter()
        .map(|f| read_trials(&data.join(f)).unwrap())
        .collect();
    let rels: Vec<Box<dyn Relation>> = vec![gaitfit::relations::by_id("kb-mu").unwrap()];
    let run = fit_all(&rels, &t, &FitOptions::default(), false, |_| {});
    assert!(run.failures.is_empty(), "{:?}", run.failures);
    let dir = tempfile::tempdir().unwrap();
    write_report(dir.path(), &run.outcomes, &run.failures).unwrap();
    let svg = read(dir.path(), "kb-mu.svg");
    for label in [
        "μ1: knee flexion at heel strike",
        "μ2: foot angle at heel strike",
        "μ3: foot angle at toe off",
        "μ4: meta angle at toe off",
    ] {
        assert!(svg.contains(label), "{label}");
    }
    for k in 1..=4 {
        assert!(svg.contains(&format!("mu{k} (rad)")), "y axis of panel {k}");
    }
    let n = run.outcomes[0].prepared.obs.len();
    assert_eq!(
        svg.matches("<circle").count(),
        n,
        "each row in its μ's panel"
    );
    let summary = read(dir.path(), "summary.md");
    assert!(summary.contains("one panel per output (4)"));
    // The paper gives μ* at sl* and only ranges for α (appendix A): its constraint is drawn and
    // named so, and nothing is labelled "published" — no flat α = 0 lines.
    assert!(svg.contains("constraint: μ* at sl*"), "legend");
    assert!(
        !svg.lines().any(|l| l.trim() == "published"),
        "a 'published' legend entry"
    );
    assert!(summary.contains("alpha1 ∈ [0, 0.3], alpha2 ≥ 0, alpha3 ≥ 0, alpha4 ≥ 0"));
    assert!(summary.contains("so no published curve"));
    // The coefficient table: no published α, no t-test for α; the overview's "published" r²
    // is marked as a reference curve.
    for k in 1..=4 {
        let row = summary
            .lines()
            .find(|l| l.starts_with(&format!("| `alpha{k}` |")))
            .unwrap_or_else(|| panic!("alpha{k} row"));
        let cells: Vec<&str> = row.split('|').map(str::trim).collect();
        assert_eq!(cells[3], "—", "published alpha{k}: {row}");
        assert_eq!(cells[7], "—", "t-test of alpha{k}: {row}");
    }
    assert!(summary.contains("so this is a reference, not a published curve"));
}
