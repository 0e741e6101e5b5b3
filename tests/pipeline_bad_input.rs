//! Every bad input of issue 3 gets a clear error naming the file, row and column (or a reported
//! rejection), and nothing is lost.
use gaitfit::fit::pipeline::{fit_relation, FitOptions};
use gaitfit::fit::FitError;
use gaitfit::ingest::trials::{parse_trials, TrialsTable};
use gaitfit::relations::{RunSlV, RunTflightSf, WalkSlSf, WalkTdsSf};
use std::path::Path;

fn parse(s: &str) -> Result<TrialsTable, String> {
    parse_trials(Path::new("data/bad.csv"), s.as_bytes()).map_err(|e| e.to_string())
}

const HEAD: &str = "subject,gait,speed_m_per_s,step_length_m,step_freq_steps_per_min,flight_time_s,body_height_m\n";

#[test]
fn malformed_row_names_file_and_row() {
    let e = parse(&format!("{HEAD}A,run,3,1.0,180,0.1,1.8\nA,run,3,1.0\n")).unwrap_err();
    assert!(e.starts_with("data/bad.csv"), "{e}");
    assert!(
        e.contains("row 2") && e.contains("4 fields") && e.contains("7"),
        "{e}"
    );
}

#[test]
fn truncated_file_is_an_error_not_a_short_table() {
    let full = format!("{HEAD}A,run,3,1.0,180,0.1,1.8\nB,run,3.2,1.05,182.9,0.11,1.7\n");
    let cut = &full[..full.len() - 12];
    let e = parse(cut).unwrap_err();
    assert!(e.contains("row 2"), "{e}");
}

#[test]
fn empty_file_and_header_only() {
    assert!(parse("").unwrap_err().contains("empty file"));
    assert!(parse(HEAD).unwrap_err().contains("no data rows"));
}

#[test]
fn unknown_unit_suffix_lists_the_accepted_ones() {
    let e = parse("subject,gait,speed_mph\nA,run,7\n").unwrap_err();
    assert!(e.contains("column speed_mph"), "{e}");
    assert!(
        e.contains("speed_m_per_s") && e.contains("speed_km_per_h"),
        "{e}"
    );
}

#[test]
fn missing_required_column() {
    let e = parse("subject,speed_m_per_s\nA,3\n").unwrap_err();
    assert!(e.contains("missing column gait"), "{e}");
    let e = parse("gait,speed_m_per_s\nrun,3\n").unwrap_err();
    assert!(e.contains("missing column subject"), "{e}");
}

#[test]
fn missing_column_a_relation_needs_is_reported_with_the_reason() {
    let t = parse("subject,gait,speed_m_per_s,step_length_m,body_height_m\nA,run,3,1,1.8\nB,run,3.5,1.1,1.7\n").unwrap();
    let e = fit_relation(&RunTflightSf::published(), &[t], &FitOptions::default())
        .unwrap_err()
        .to_string();
    assert!(
        e.contains("too few rows") && e.contains("missing flight_time_s"),
        "{e}"
    );
}

#[test]
fn nan_and_inf_cells_are_errors_naming_row_and_column() {
    for bad in ["NaN", "nan", "inf", "-inf", "abc"] {
        let e = parse(&format!(
            "{HEAD}A,run,3,1.0,180,0.1,1.8\nA,run,{bad},1.0,180,0.1,1.8\n"
        ))
        .unwrap_err();
        assert!(e.contains("row 2, column speed_m_per_s"), "{bad}: {e}");
    }
}

#[test]
fn empty_cells_are_missing_values_and_rejected_rows_are_reported() {
    let mut csv = String::from(HEAD);
    for i in 0..30 {
        let v = 2.0 + 0.1 * i as f64;
        let sl = (0.1394 + 0.00465 * v * 60.0) + 0.01 * ((i * 7 % 5) as f64 - 2.0);
        csv.push_str(&format!(
            "S{},run,{v},{sl},,,{}\n",
            i % 3,
            if i == 4 { "" } else { "1.8" }
        ));
    }
    let t = parse(&csv).unwrap();
    let o = fit_relation(&RunSlV::published(), &[t], &FitOptions::default()).unwrap();
    assert_eq!(o.record.n, 29);
    assert_eq!(o.record.data.rows_rejected, 1);
    let r = &o.record.data.rejected[0];
    assert_eq!(r.reason, "missing body_height_m");
    assert_eq!(r.examples, vec!["data/bad.csv: row 5".to_string()]);
}

#[test]
fn negative_and_absurd_values_suggest_the_fix() {
    let e = parse(&format!("{HEAD}A,run,3,-1.0,180,0.1,1.8\n")).unwrap_err();
    assert!(
        e.contains("row 1, column step_length_m") && e.contains("negative"),
        "{e}"
    );
    let e = parse(&format!("{HEAD}A,run,3,80,180,0.1,1.8\n")).unwrap_err();
    assert!(e.contains("row 1, column step_length_m"), "{e}");
    assert!(e.contains("step_length_cm"), "hint missing: {e}");
    let e = parse("subject,gait,body_height_m\nA,walk,180\n").unwrap_err();
    assert!(e.contains("body_height_cm"), "{e}");
    let e = parse("subject,gait,flight_time_s\nA,run,120\n").unwrap_err();
    assert!(e.contains("flight_time_ms"), "{e}");
}

#[test]
fn bad_text_cells() {
    let e = parse("subject,gait\nA,hop\n").unwrap_err();
    assert!(
        e.contains("row 1, column gait") && e.contains("walk or run"),
        "{e}"
    );
    let e = parse("subject,gait\n,run\n").unwrap_err();
    assert!(e.contains("row 1, column subject"), "{e}");
}

#[test]
fn duplicate_quantity_columns() {
    let e = parse("subject,gait,speed_m_per_s,speed_km_per_h\nA,run,3,10.8\n").unwrap_err();
    assert!(e.contains("both give speed"), "{e}");
}

#[test]
fn inconsistent_triple_is_reported_not_used() {
    let mut csv =
        String::from("subject,gait,speed_m_per_s,step_length_m,step_freq_hz,body_height_m\n");
    for i in 0..12 {
        let sf = 2.5 + 0.05 * i as f64;
        let sl = 0.6 + 0.02 * i as f64;
        let v = if i == 3 { sl * sf * 1.05 } else { sl * sf };
        csv.push_str(&format!("S{},walk,{v},{sl},{sf},1.75\n", i % 2));
    }
    let t = parse(&csv).unwrap();
    let o = fit_relation(&WalkSlSf::published(), &[t], &FitOptions::default()).unwrap();
    assert_eq!(o.record.n, 11);
    assert!(o.record.data.rejected[0]
        .reason
        .contains("disagree by more than 2 %"));
    assert_eq!(
        o.record.data.rejected[0].examples,
        vec!["data/bad.csv: row 4".to_string()]
    );
}

#[test]
fn too_few_rows_and_too_few_subjects() {
    let t =
        parse("subject,gait,step_freq_hz,double_support_pct_cycle\nA,walk,1.8,12\nA,walk,1.9,11\n")
            .unwrap();
    match fit_relation(
        &WalkTdsSf::published(),
        std::slice::from_ref(&t),
        &FitOptions::default(),
    ) {
        Err(FitError::TooFew { have, need, .. }) => assert!(have == 2 && need > 2),
        other => panic!("{other:?}"),
    }
    let mut csv = String::from("subject,gait,step_freq_hz,double_support_pct_cycle\n");
    for i in 0..20 {
        csv.push_str(&format!(
            "A,walk,{},{}\n",
            1.6 + 0.02 * i as f64,
            12.0 - 0.1 * i as f64
        ));
    }
    let t = parse(&csv).unwrap();
    let opts = FitOptions {
        bootstrap: 100,
        ..Default::default()
    };
    let e = fit_relation(&WalkTdsSf::published(), &[t], &opts)
        .unwrap_err()
        .to_string();
    assert!(e.contains("subjects") && e.contains("--bootstrap"), "{e}");
}

#[test]
fn singular_design_is_reported() {
    let mut csv = String::from("subject,gait,step_freq_hz,double_support_pct_cycle\n");
    for i in 0..20 {
        csv.push_str(&format!(
            "S{},walk,1.8,{}\n",
            i % 3,
            12.0 + 0.1 * (i % 4) as f64
        ));
    }
    let t = parse(&csv).unwrap();
    let e = fit_relation(&WalkTdsSf::published(), &[t], &FitOptions::default()).unwrap_err();
    assert!(matches!(e, FitError::Singular { .. }), "{e}");
    assert!(e.to_string().contains("walk-tds-sf"), "{e}");
}

#[test]
fn weights_column_must_exist_and_be_positive() {
    let mut csv = String::from("subject,gait,step_freq_hz,double_support_pct_cycle,w\n");
    for i in 0..20 {
        let w = if i == 5 { "0" } else { "2" };
        csv.push_str(&format!(
            "S{},walk,{},{},{w}\n",
            i % 3,
            1.6 + 0.02 * i as f64,
            12.0 - 0.1 * i as f64
        ));
    }
    let t = parse(&csv).unwrap();
    let bad = FitOptions {
        weights: Some("nope".into()),
        ..Default::default()
    };
    assert!(
        fit_relation(&WalkTdsSf::published(), std::slice::from_ref(&t), &bad)
            .unwrap_err()
            .to_string()
            .contains("no numeric column `nope`")
    );
    let ok = FitOptions {
        weights: Some("w".into()),
        ..Default::default()
    };
    let o = fit_relation(&WalkTdsSf::published(), &[t], &ok).unwrap();
    assert_eq!(o.record.n, 19);
    assert_eq!(
        o.record.data.rejected[0].reason,
        "weight missing or not positive"
    );
    assert_eq!(o.record.weights.as_deref(), Some("w"));
}
