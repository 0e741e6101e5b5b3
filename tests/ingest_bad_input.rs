//! Bad input: every reader answers a corrupt file with an `IngestError` naming the file, the
//! row (frame/line) and the column (marker/channel), never a panic and never partial output.
use gaitfit::ingest::{read_trial, IngestError, ReadOptions};
use std::path::{Path, PathBuf};

fn write(dir: &Path, name: &str, body: &str) -> PathBuf {
    let p = dir.join(name);
    std::fs::write(&p, body).unwrap();
    p
}

fn err(p: &Path) -> String {
    match read_trial(p, &ReadOptions::default()) {
        Ok(t) => panic!("{} read without error: {:?}", p.display(), t.notes),
        Err(e) => {
            let s = e.to_string();
            assert!(
                s.contains(&p.display().to_string()),
                "message lacks the path: {s}"
            );
            s
        }
    }
}

const TRC_HEAD: &str = "PathFileType\t4\t(X/Y/Z)\tt.trc\n\
DataRate\tCameraRate\tNumFrames\tNumMarkers\tUnits\tOrigDataRate\tOrigDataStartFrame\tOrigNumFrames\n\
100\t100\t3\t3\tUNIT\t100\t1\t3\n\
Frame#\tTime\tRHEE\t\t\tRTOE\t\t\tRASI\t\t\t\n\
\t\tX1\tY1\tZ1\tX2\tY2\tZ2\tX3\tY3\tZ3\n\n";

fn trc(unit: &str, rows: &[&str]) -> String {
    let mut s = TRC_HEAD.replace("UNIT", unit);
    for r in rows {
        s.push_str(r);
        s.push('\n');
    }
    s
}

const ROW1: &str = "1\t0.00\t0\t50\t0\t200\t40\t0\t100\t950\t0";
const ROW2: &str = "2\t0.01\t10\t50\t0\t210\t40\t0\t110\t950\t0";
const ROW3: &str = "3\t0.02\t20\t50\t0\t220\t40\t0\t120\t950\t0";

#[test]
fn good_trc_reads() {
    let d = tempfile::tempdir().unwrap();
    let p = write(d.path(), "ok.trc", &trc("mm", &[ROW1, ROW2, ROW3]));
    let t = read_trial(&p, &ReadOptions::default()).unwrap();
    assert_eq!(t.markers.unwrap().len(), 3);
}

#[test]
fn trc_with_fewer_columns_than_markers() {
    let d = tempfile::tempdir().unwrap();
    let p = write(
        d.path(),
        "short.trc",
        &trc("mm", &[ROW1, "2\t0.01\t10\t50\t0\t210\t40\t0", ROW3]),
    );
    let e = err(&p);
    assert!(e.contains("row 8") && e.contains("RASI"), "{e}");
}

#[test]
fn truncated_trc() {
    let d = tempfile::tempdir().unwrap();
    // A header that over-counts its frames (whole rows, fewer than NumFrames): read, warned.
    let p = write(d.path(), "over.trc", &trc("mm", &[ROW1, ROW2]));
    let t = read_trial(&p, &ReadOptions::default()).unwrap();
    assert_eq!(t.markers.as_ref().unwrap().len(), 2);
    assert!(
        t.notes
            .iter()
            .any(|n| n.starts_with("warning:") && n.contains("NumFrames = 3")),
        "{:?}",
        t.notes
    );
    // A row cut short is still an error.
    let p = write(
        d.path(),
        "trunc.trc",
        &trc("mm", &[ROW1, ROW2, "3\t0.02\t20\t50"]),
    );
    assert!(err(&p).contains("row"), "{}", err(&p));
    let p = write(d.path(), "head.trc", &TRC_HEAD[..60]);
    let e = err(&p);
    assert!(e.contains("header"), "{e}");
}

#[test]
fn trc_unknown_units() {
    let d = tempfile::tempdir().unwrap();
    let p = write(d.path(), "u.trc", &trc("parsecs", &[ROW1, ROW2, ROW3]));
    let e = err(&p);
    assert!(matches!(
        read_trial(&p, &ReadOptions::default()),
        Err(IngestError::UnknownUnit { .. })
    ));
    assert!(e.contains("parsecs"), "{e}");
}

#[test]
fn trc_non_monotonic_time_and_infinite_values() {
    let d = tempfile::tempdir().unwrap();
    let back = ROW3.replace("\t0.02\t", "\t0.005\t");
    let p = write(d.path(), "t.trc", &trc("mm", &[ROW1, ROW2, &back]));
    let e = err(&p);
    assert!(e.contains("row 9") && e.contains("Time"), "{e}");
    let inf = ROW2.replace("\t210\t", "\tinf\t");
    let p = write(d.path(), "i.trc", &trc("mm", &[ROW1, &inf, ROW3]));
    let e = err(&p);
    assert!(e.contains("row 8") && e.contains("RTOE X"), "{e}");
}

const FORCES: &str = "[Force Data]\nNumberOfForcePlates=1\nSampleRate=450.000000\nNumberOfSamples=N\n\
#Sample\tFX1\tFY1\tFZ1\tX1\tY1\tZ1\tMZ1\n\
1\t0\t0\t0\t2149\t0\t976.7\t0\n2\t1\t600\t2\t2149\t0\t976.7\t-10\n3\t1\t610\t2\t2150\t0\t976.7\t-10\n";

#[test]
fn forces_sample_count_disagrees() {
    let d = tempfile::tempdir().unwrap();
    let p = write(d.path(), "ok.forces", &FORCES.replace("=N", "=3"));
    assert!(read_trial(&p, &ReadOptions::default()).is_ok());
    let p = write(d.path(), "bad.forces", &FORCES.replace("=N", "=4"));
    let e = err(&p);
    assert!(
        e.contains("NumberOfSamples = 4") && e.contains("3 data rows"),
        "{e}"
    );
    let p = write(
        d.path(),
        "cut.forces",
        &FORCES.replace("=N", "=3").replace("\t976.7\t-10\n3", "\n3"),
    );
    let e = err(&p);
    assert!(e.contains("row 7") && e.contains("Z1"), "{e}");
    let p = write(
        d.path(),
        "nan.forces",
        &FORCES.replace("=N", "=3").replace("\t610\t", "\tNaN\t"),
    );
    let e = err(&p);
    assert!(e.contains("row 8") && e.contains("FY1"), "{e}");
}

const MOT: &str = "name g\ndatacolumns 4\ndatarows 3\nrange 0 0.002\nendheader\n\
time\tR_ground_force_vx\tR_ground_force_vy\tR_ground_force_vz\n\
0.000\t1\t700\t2\n0.001\t1\t710\t2\n0.002\t1\t720\t2\n";

#[test]
fn mot_errors() {
    let d = tempfile::tempdir().unwrap();
    let p = write(d.path(), "ok_grf.mot", MOT);
    assert_eq!(
        read_trial(&p, &ReadOptions::default())
            .unwrap()
            .plates
            .len(),
        1
    );
    let p = write(
        d.path(),
        "trunc_grf.mot",
        &MOT.replace("0.002\t1\t720\t2\n", ""),
    );
    assert!(err(&p).contains("truncated"));
    let p = write(d.path(), "inf_grf.mot", &MOT.replace("\t710\t", "\t-inf\t"));
    let e = err(&p);
    assert!(
        e.contains("row 8") && e.contains("R_ground_force_vy"),
        "{e}"
    );
    let p = write(d.path(), "t_grf.mot", &MOT.replace("0.002\t", "0.001\t"));
    let e = err(&p);
    assert!(e.contains("row 9") && e.contains("time"), "{e}");
    let p = write(
        d.path(),
        "cols_grf.mot",
        &MOT.replace("datacolumns 4", "datacolumns 5"),
    );
    assert!(err(&p).contains("declares 5 columns"));
}

#[test]
fn winter_errors() {
    let d = tempfile::tempdir().unwrap();
    let head = "'FRAME' 'TIME' 'A' 'B'\n 'N' 'S' 'X' 'Y' 'X' 'Y'\n";
    let p = write(
        d.path(),
        "w.txt",
        &format!("{head}1 0 10 100 12 5\n2 0.014 11 x 12 5\n"),
    );
    let e = err(&p);
    assert!(e.contains("row 4") && e.contains("column 4"), "{e}");
    let p = write(
        d.path(),
        "w2.txt",
        &format!("{head}1 0 10 100 12 5\n2 0.014 11 100\n"),
    );
    assert!(err(&p).contains("truncated"));
    // Heights that are no body height in any unit.
    let p = write(
        d.path(),
        "w3.txt",
        &format!("{head}1 0 10 9 12 5\n2 0.014 11 9 12 5\n"),
    );
    assert!(err(&p).contains("not a body height"));
}

#[test]
fn unknown_format_and_missing_file() {
    let d = tempfile::tempdir().unwrap();
    let p = write(d.path(), "x.xyz", "hello\n");
    assert!(err(&p).contains("unknown file format"));
    let e = read_trial(&d.path().join("nope.trc"), &ReadOptions::default()).unwrap_err();
    assert!(matches!(e, IngestError::Io { .. }));
}

#[test]
fn treadmill_grf_errors() {
    let d = tempfile::tempdir().unwrap();
    let head = "Time\tFx1\tFy1\tFz1\tCOPx1\tCOPy1\tCOPz1\tTy1\n";
    let p = write(
        d.path(),
        "a_grf.txt",
        &format!("{head}1\t1\t600\t2\t2000\t0\t1100\t10\n2\t1\t610\t2\t2001\t0\t1100\n"),
    );
    let e = err(&p);
    assert!(e.contains("row 3") && e.contains("Ty1"), "{e}");
    let p = write(
        d.path(),
        "b_grf.txt",
        &format!("{head}1\t1\t600\t2\t2000\t0\t1100\t10\n1\t1\t610\t2\t2001\t0\t1100\t10\n"),
    );
    let e = err(&p);
    assert!(e.contains("row 3") && e.contains("Time"), "{e}");
    let p = write(
        d.path(),
        "c_grf.txt",
        "Time\tFx1\tFy1\tFz1\tCOPx1\n1\t1\t2\t3\t4\n",
    );
    let e = err(&p);
    assert!(e.contains("COPy1"), "{e}");
}

#[test]
fn c3d_bad_header_and_truncation() {
    let d = tempfile::tempdir().unwrap();
    let mut b = vec![0u8; 1536];
    b[0] = 2;
    b[1] = 0x42;
    let p = write_bytes(d.path(), "key.c3d", &b);
    assert!(err(&p).contains("not the C3D key 0x50"));
    b[1] = 0x50;
    b[512 + 3] = 7;
    let p = write_bytes(d.path(), "proc.c3d", &b);
    assert!(err(&p).contains("processor type 7"));
    let p = write_bytes(d.path(), "short.c3d", &b[..300]);
    assert!(err(&p).contains("512-byte header"));
}

fn write_bytes(dir: &Path, name: &str, body: &[u8]) -> PathBuf {
    let p = dir.join(name);
    std::fs::write(&p, body).unwrap();
    p
}
