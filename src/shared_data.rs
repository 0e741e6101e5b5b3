//! Locating the shared real-data folder (`../shared/data`, or `$GAITFIT_SHARED_DATA`).
//!
//! gaitfit never ships copies of those files; it reads them from here at run time. Tests that
//! need them are `#[ignore = "needs ../shared/data"]` and call [`require`], which fails loudly
//! (never skips) when the folder is missing.
use std::path::{Path, PathBuf};

/// The environment variable that overrides where the shared data folder is.
pub const ENV_VAR: &str = "GAITFIT_SHARED_DATA";

/// Finds the shared data folder: `$GAITFIT_SHARED_DATA` if set, else the first `shared/data`
/// found next to the current directory or one of its ancestors, else next to the crate's
/// manifest directory (so `cargo test` works from anywhere in the checkout).
pub fn locate() -> Option<PathBuf> {
    if let Some(p) = std::env::var_os(ENV_VAR) {
        let p = PathBuf::from(p);
        return p.is_dir().then_some(p);
    }
    let mut starts: Vec<PathBuf> = Vec::new();
    if let Ok(cwd) = std::env::current_dir() {
        starts.push(cwd);
    }
    starts.push(PathBuf::from(env!("CARGO_MANIFEST_DIR")));
    for start in starts {
        for dir in start.ancestors() {
            let cand = dir.join("shared").join("data");
            if cand.is_dir() {
                return Some(cand);
            }
        }
    }
    None
}

/// A human-readable explanation of where gaitfit looked, for error messages.
pub fn where_looked() -> String {
    format!(
        "set {ENV_VAR} to the folder, or place it at ../shared/data relative to the checkout \
         (looked from the current directory and from {})",
        env!("CARGO_MANIFEST_DIR")
    )
}

/// The path of `rel` inside the shared data folder, or an error message saying what is missing.
pub fn path(rel: impl AsRef<Path>) -> Result<PathBuf, String> {
    let root =
        locate().ok_or_else(|| format!("shared data folder not found: {}", where_looked()))?;
    let p = root.join(rel.as_ref());
    if p.exists() {
        Ok(p)
    } else {
        Err(format!(
            "{} is missing from the shared data folder {}",
            rel.as_ref().display(),
            root.display()
        ))
    }
}

/// For tests marked `#[ignore = "needs ../shared/data"]`: the path of `rel`, or a panic with a
/// clear message. A missing folder is a test failure, never a silent skip.
pub fn require(rel: impl AsRef<Path>) -> PathBuf {
    match path(rel) {
        Ok(p) => p,
        Err(msg) => panic!("needs ../shared/data: {msg}"),
    }
}
