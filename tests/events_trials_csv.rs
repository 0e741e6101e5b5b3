//! The per-step CSV that `gaitfit events` writes is a valid trials table for `gaitfit fit`:
//! every row read back, none flagged, extra columns ignored, values round-trip.
use gaitfit::events::steps::write_csv;
use gaitfit::events::synthetic::SyntheticGait;
use gaitfit::events::{steps_from_trial, EventOptions};
use gaitfit::ingest::trials::read_trials;

#[test]
fn events_csv_reads_back_as_a_trials_table() {
    let dir = tempfile::tempdir().unwrap();
    let p = dir.path().join("steps.csv");
    let walk = steps_from_trial(&SyntheticGait::walk().trial(), &EventOptions::default()).unwrap();
    let run = steps_from_trial(&SyntheticGait::run().trial(), &EventOptions::default()).unwrap();
    write_csv(&p, &[walk.clone(), run.clone()]).unwrap();
    let t = read_trials(&p).unwrap();
    assert_eq!(t.len(), walk.rows.len() + run.rows.len());
    assert!(t.flagged.is_empty(), "flagged rows: {:?}", t.flagged);
    for c in ["event_source", "setting", "stride_time_s", "sl_method"] {
        assert!(
            t.ignored_columns.iter().any(|x| x == c),
            "{c} not ignored: {:?}",
            t.ignored_columns
        );
    }
    let back = t.to_step_rows();
    let r0 = &walk.rows[0];
    let b0 = &back[0];
    assert_eq!(b0.subject, r0.subject);
    assert_eq!(b0.gait, r0.gait);
    let rel = |a: Option<f64>, b: Option<f64>| (a.unwrap() - b.unwrap()).abs() / b.unwrap().abs();
    assert!(rel(b0.step_length_m, r0.step_length_m) < 1e-4);
    assert!(rel(b0.step_freq_hz, r0.step_freq_hz) < 1e-4);
    assert!(rel(b0.double_support_pct_cycle, r0.double_support_pct_cycle) < 1e-3);
    // Angles are written in degrees with two decimals.
    let d = (b0.foot_angle_hs_rad.unwrap() - r0.foot_angle_hs_rad.unwrap()).abs();
    assert!(d < 1e-4, "{d}");
}
