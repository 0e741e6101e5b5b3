//! One entry point for writing a [`Motion`]: the format follows the file extension.
use super::ExportError;
use crate::generator::motion::Motion;
use std::path::Path;

/// The motion file formats gaitfit writes.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum MotionFormat {
    /// Biovision hierarchy (`.bvh`), see [`super::bvh`].
    Bvh,
    /// Landmarks, contacts and joint angles (`.csv`) plus `<stem>_events.csv`, see
    /// [`super::motion_csv`].
    Csv,
    /// OpenSim marker file (`.trc`), see [`super::trc`].
    Trc,
    /// OpenSim motion (`.mot`): joint angles as the gait models' coordinates, see
    /// [`super::opensim`].
    Mot,
    /// OpenSim storage (`.sto`): the same content as `.mot`.
    Sto,
}

impl MotionFormat {
    /// The format of `path` from its extension (case-insensitive), or an error naming the path
    /// and the accepted extensions.
    pub fn from_path(path: &Path) -> Result<MotionFormat, ExportError> {
        let ext = path
            .extension()
            .map(|e| e.to_string_lossy().to_ascii_lowercase())
            .unwrap_or_default();
        match ext.as_str() {
            "bvh" => Ok(MotionFormat::Bvh),
            "csv" => Ok(MotionFormat::Csv),
            "trc" => Ok(MotionFormat::Trc),
            "mot" => Ok(MotionFormat::Mot),
            "sto" => Ok(MotionFormat::Sto),
            _ => {
                Err(ExportError::Format {
                    path: path.display().to_string(),
                    message: format!(
                    "unknown motion file extension {:?}: use .bvh (Blender and other animation \
                     tools), .csv (landmarks, contacts and joint angles; events go to \
                     <stem>_events.csv), .trc (OpenSim markers) or .mot/.sto (OpenSim joint \
                     angles)",
                    if ext.is_empty() { "(none)".to_string() } else { format!(".{ext}") }
                ),
                })
            }
        }
    }
}

/// Options of [`write_with`] (what a format leaves open).
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct MotionOptions {
    /// Length unit of a BVH file (metres by default).
    pub bvh_unit: super::bvh::BvhUnit,
    /// Coordinate conventions of a `.mot`/`.sto` file (gait2392 by default).
    pub opensim_model: super::opensim::OpenSimModel,
}

/// Writes `motion` to `path` in the format its extension names (`.bvh`, `.csv`, `.trc`, `.mot`,
/// `.sto`); a CSV also writes its events to `<stem>_events.csv` next to it. Files are written
/// atomically.
pub fn write(motion: &Motion, path: &Path) -> Result<(), ExportError> {
    write_with(motion, path, &MotionOptions::default())
}

/// [`write()`] with options.
pub fn write_with(motion: &Motion, path: &Path, opts: &MotionOptions) -> Result<(), ExportError> {
    match MotionFormat::from_path(path)? {
        MotionFormat::Bvh => super::bvh::write(
            motion,
            path,
            &super::bvh::BvhOptions {
                unit: opts.bvh_unit,
            },
        ),
        MotionFormat::Csv => {
            super::motion_csv::write(motion, path)?;
            super::motion_csv::write_events(motion, &super::motion_csv::events_path(path))
        }
        MotionFormat::Trc => super::trc::write(motion, path, &super::trc::TrcOptions::default()),
        MotionFormat::Mot | MotionFormat::Sto => super::opensim::write(
            motion,
            path,
            &super::opensim::MotOptions {
                model: opts.opensim_model,
            },
        ),
    }
}
