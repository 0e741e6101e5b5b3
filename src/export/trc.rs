//! OpenSim marker files (`.trc`) from a [`Motion`]'s landmarks.
//!
//! Layout (tab-separated, as OpenSim writes and reads it):
//! ```text
//! PathFileType  4  (X/Y/Z)  <file name>
//! DataRate  CameraRate  NumFrames  NumMarkers  Units  OrigDataRate  OrigDataStartFrame  OrigNumFrames
//! 120.000000  120.000000  1200  23  mm  120.000000  1  1200
//! Frame#  Time  pelvis  (2 empty)  l_hip  …
//!               X1  Y1  Z1  X2  Y2  Z2  …
//! (empty line)
//! 1  0.000000  x y z …
//! ```
//! Markers are the landmarks in [`Landmark::ALL`] order. Axes are OpenSim's: X forward, Y up,
//! Z right — the motion's own frame, so no rotation is applied. Units millimetres by default
//! (the usual motion-capture unit; OpenSim converts using the `Units` field), or metres.
use super::ExportError;
use crate::fsio::{write_atomic, FsError};
use crate::generator::motion::Motion;
use crate::generator::skeleton::Landmark;
use std::fmt::Write as _;
use std::path::Path;

/// Length unit of a TRC file.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum TrcUnit {
    /// Millimetres (default).
    #[default]
    Millimetres,
    /// Metres.
    Metres,
}

impl TrcUnit {
    /// The `Units` header value.
    pub fn as_str(self) -> &'static str {
        match self {
            TrcUnit::Millimetres => "mm",
            TrcUnit::Metres => "m",
        }
    }
    /// Metres → this unit.
    pub fn scale(self) -> f64 {
        match self {
            TrcUnit::Millimetres => 1000.0,
            TrcUnit::Metres => 1.0,
        }
    }
}

/// Options of the TRC writer.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct TrcOptions {
    /// Length unit.
    pub unit: TrcUnit,
}

/// Writes the landmarks of `motion` as a TRC marker file to `path` (atomically).
pub fn write(motion: &Motion, path: &Path, options: &TrcOptions) -> Result<(), ExportError> {
    if motion.is_empty() {
        return Err(ExportError::Format {
            path: path.display().to_string(),
            message: "the motion has no frames; a TRC file needs at least one".into(),
        });
    }
    let s = options.unit.scale();
    let n = motion.len();
    let m = Landmark::ALL.len();
    let file_name = path
        .file_name()
        .map(|f| f.to_string_lossy().into_owned())
        .unwrap_or_default();
    let mut head = String::new();
    let _ = writeln!(head, "PathFileType\t4\t(X/Y/Z)\t{file_name}");
    let _ = writeln!(
        head,
        "DataRate\tCameraRate\tNumFrames\tNumMarkers\tUnits\tOrigDataRate\tOrigDataStartFrame\tOrigNumFrames"
    );
    let fps = motion.fps();
    let _ = writeln!(
        head,
        "{fps:.6}\t{fps:.6}\t{n}\t{m}\t{}\t{fps:.6}\t1\t{n}",
        options.unit.as_str()
    );
    head.push_str("Frame#\tTime");
    for l in Landmark::ALL {
        let _ = write!(head, "\t{}\t\t", l.name());
    }
    head.push_str("\n\t");
    for k in 1..=m {
        let _ = write!(head, "\tX{k}\tY{k}\tZ{k}");
    }
    head.push_str("\n\n");
    write_atomic(path, |w| {
        let io = |e| ExportError::from(FsError::io(path, e));
        w.write_all(head.as_bytes()).map_err(io)?;
        let mut line = String::with_capacity(64 * m);
        for i in 0..n {
            line.clear();
            let _ = write!(line, "{}\t{:.6}", i + 1, motion.frame_time(i));
            for p in motion.landmarks(i) {
                let _ = write!(line, "\t{:.6}\t{:.6}\t{:.6}", p.x * s, p.y * s, p.z * s);
            }
            writeln!(w, "{line}").map_err(io)?;
        }
        Ok(())
    })
}
