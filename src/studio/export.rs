//! The export buttons: the current motion as a motion file through the library's exporters
//! ([`crate::export::motion::write`], which picks the format by extension, so every format the
//! library writes is offered), or its steps table in the trials schema
//! ([`crate::ingest::trials::write_trials`], what `gaitfit fit` reads). Files are written to a
//! temporary folder and sent back; nothing is left on disk.
use super::session::Generated;
use super::StudioError;
use crate::export::motion::MotionFormat;
use serde::Serialize;
use std::path::Path;

/// The motion file extensions the studio offers, in button order, if the library writes them.
const MOTION_EXTENSIONS: [&str; 5] = ["bvh", "trc", "csv", "mot", "sto"];

/// One export button.
#[derive(Debug, Clone, Serialize, PartialEq)]
pub struct ExportFormat {
    /// Name in the URL (`/api/export/<name>`).
    pub name: &'static str,
    /// Button label.
    pub label: &'static str,
    /// What the file is for.
    pub doc: &'static str,
}

fn doc_of(ext: &str) -> &'static str {
    match ext {
        "bvh" => "Biovision hierarchy (Blender and other animation tools)",
        "trc" => "OpenSim markers (gaitfit events reads it back)",
        "csv" => "landmarks, contacts and joint angles per frame",
        "mot" | "sto" => "OpenSim joint angles",
        _ => "",
    }
}

/// The formats offered: every motion format the library's writer accepts, then the steps table.
pub fn formats() -> Vec<ExportFormat> {
    let mut out: Vec<ExportFormat> = MOTION_EXTENSIONS
        .iter()
        .filter(|e| MotionFormat::from_path(Path::new(&format!("x.{e}"))).is_ok())
        .map(|e| ExportFormat {
            name: e,
            label: e,
            doc: doc_of(e),
        })
        .collect();
    out.push(ExportFormat {
        name: "steps",
        label: "steps",
        doc: "the steps table (trials schema, what `gaitfit fit` reads)",
    });
    out
}

/// A file to download.
#[derive(Debug, Clone, PartialEq)]
pub struct Download {
    /// File name suggested to the browser.
    pub filename: String,
    /// MIME type.
    pub content_type: &'static str,
    /// The bytes.
    pub bytes: Vec<u8>,
}

/// Writes `g` in `format` (a name from [`formats`]).
pub fn export(g: &Generated, format: &str) -> Result<Download, StudioError> {
    if !formats().iter().any(|f| f.name == format) {
        return Err(StudioError::Request(format!(
            "export {format:?}: use one of {}",
            formats()
                .iter()
                .map(|f| f.name)
                .collect::<Vec<_>>()
                .join(", ")
        )));
    }
    let dir = tempfile::tempdir()
        .map_err(|e| StudioError::Fs(crate::fsio::FsError::io(std::env::temp_dir(), e)))?;
    let stem = format!("gaitfit-{}", g.generator.name());
    let (filename, content_type) = if format == "steps" {
        (format!("{stem}_steps.csv"), "text/csv")
    } else {
        (
            format!("{stem}.{format}"),
            match format {
                "csv" => "text/csv",
                _ => "text/plain",
            },
        )
    };
    let path = dir.path().join(&filename);
    if format == "steps" {
        crate::ingest::trials::write_trials(&path, &g.steps).map_err(crate::Error::from)?;
    } else {
        crate::export::motion::write(&g.motion, &path)?;
    }
    let bytes = std::fs::read(&path).map_err(|e| crate::fsio::FsError::io(&path, e))?;
    Ok(Download {
        filename,
        content_type,
        bytes,
    })
}
