//! File output that never leaves a half-written file: every writer goes through
//! [`write_atomic`], which writes a temporary file in the destination folder and renames it over
//! the destination only once everything has been written and flushed.
use std::io::Write;
use std::path::{Path, PathBuf};
use thiserror::Error;

/// A failure to create, write or rename a file.
#[derive(Debug, Error)]
#[non_exhaustive]
pub enum FsError {
    /// An I/O error on `path`.
    #[error("{path}: {source}")]
    Io {
        /// The file or folder concerned.
        path: PathBuf,
        /// The underlying error.
        source: std::io::Error,
    },
}

impl FsError {
    /// Wraps an `std::io::Error` with the path it concerns.
    pub fn io(path: impl Into<PathBuf>, source: std::io::Error) -> Self {
        FsError::Io {
            path: path.into(),
            source,
        }
    }
}

/// Writes `path` atomically: `fill` writes into a temporary file created next to `path`; on
/// success the temporary file is flushed, synced and renamed over `path`; on any error (from
/// `fill` or from the file system) the temporary file is removed and `path` is left untouched.
///
/// Missing parent folders are created.
pub fn write_atomic<E, F>(path: &Path, fill: F) -> Result<(), E>
where
    E: From<FsError>,
    F: FnOnce(&mut dyn Write) -> Result<(), E>,
{
    let dir = match path.parent() {
        Some(p) if !p.as_os_str().is_empty() => p.to_path_buf(),
        _ => PathBuf::from("."),
    };
    std::fs::create_dir_all(&dir).map_err(|e| FsError::io(&dir, e))?;
    let file_name = path
        .file_name()
        .map(|n| n.to_string_lossy().into_owned())
        .unwrap_or_else(|| "out".to_string());
    let mut tmp = tempfile::Builder::new()
        .prefix(&format!(".gaitfit-tmp-{file_name}-"))
        .tempfile_in(&dir)
        .map_err(|e| FsError::io(&dir, e))?;
    {
        let mut buf = std::io::BufWriter::new(tmp.as_file_mut());
        fill(&mut buf)?;
        buf.flush().map_err(|e| FsError::io(path, e))?;
    }
    tmp.as_file().sync_all().map_err(|e| FsError::io(path, e))?;
    // tempfile creates files readable by the owner only; give the result the permissions of
    // the file it replaces, or ordinary rw-r--r-- for a new file.
    let perms = match std::fs::metadata(path) {
        Ok(m) => m.permissions(),
        Err(_) => default_permissions(tmp.as_file()).map_err(|e| FsError::io(path, e))?,
    };
    tmp.as_file()
        .set_permissions(perms)
        .map_err(|e| FsError::io(path, e))?;
    tmp.persist(path).map_err(|e| FsError::io(path, e.error))?;
    Ok(())
}

#[cfg(unix)]
fn default_permissions(_f: &std::fs::File) -> std::io::Result<std::fs::Permissions> {
    use std::os::unix::fs::PermissionsExt;
    Ok(std::fs::Permissions::from_mode(0o644))
}

#[cfg(not(unix))]
fn default_permissions(f: &std::fs::File) -> std::io::Result<std::fs::Permissions> {
    Ok(f.metadata()?.permissions())
}

/// Convenience wrapper of [`write_atomic`] for content already in memory.
pub fn write_atomic_bytes(path: &Path, bytes: &[u8]) -> Result<(), FsError> {
    write_atomic(path, |w| {
        w.write_all(bytes).map_err(|e| FsError::io(path, e))
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn failed_write_keeps_old_content_and_leaves_no_temp_file() {
        let dir = tempfile::tempdir().unwrap();
        let p = dir.path().join("fit.json");
        write_atomic_bytes(&p, b"old").unwrap();
        let r: Result<(), FsError> = write_atomic(&p, |w| {
            w.write_all(b"half").map_err(|e| FsError::io(&p, e))?;
            Err(FsError::io(&p, std::io::Error::other("boom")))
        });
        assert!(r.is_err());
        assert_eq!(std::fs::read(&p).unwrap(), b"old");
        let leftovers: Vec<_> = std::fs::read_dir(dir.path())
            .unwrap()
            .filter_map(|e| e.ok())
            .filter(|e| e.file_name().to_string_lossy().starts_with(".gaitfit-tmp"))
            .collect();
        assert!(leftovers.is_empty());
    }

    #[cfg(unix)]
    #[test]
    fn new_files_are_world_readable() {
        use std::os::unix::fs::PermissionsExt;
        let dir = tempfile::tempdir().unwrap();
        let p = dir.path().join("x.json");
        write_atomic_bytes(&p, b"x").unwrap();
        let mode = std::fs::metadata(&p).unwrap().permissions().mode() & 0o777;
        assert_eq!(mode, 0o644);
    }

    #[test]
    fn creates_parent_folders() {
        let dir = tempfile::tempdir().unwrap();
        let p = dir.path().join("a/b/c.txt");
        write_atomic_bytes(&p, b"x").unwrap();
        assert_eq!(std::fs::read(&p).unwrap(), b"x");
    }
}
