//! The repository's test set of real maps: eleven CC0 light probes in `assets/envmaps/` at the
//! workspace root (licence and provenance in its README), read by tests, benches, `eval-lights`
//! and `validate --envmap`. `ENVSHADOW_ENVMAPS` names another folder.
//!
//! The folder is found through this crate's source location, so it is there in a clone of the
//! repository, not beside a binary copied elsewhere: commands that take maps also take a path.
//! That is why this is a crate of its own and not part of `envmap-sphere`'s API: no library
//! crate reads the repository's folders.

use std::path::{Path, PathBuf};

/// The environment variable that overrides [`dir`].
pub const ENV_VAR: &str = "ENVSHADOW_ENVMAPS";

/// Number of maps in the repository's test set.
pub const COUNT: usize = 11;

/// The folder of test maps: `ENVSHADOW_ENVMAPS`, else `assets/envmaps` in the repository.
#[must_use]
pub fn dir() -> PathBuf {
    match std::env::var_os(ENV_VAR) {
        Some(d) if !d.is_empty() => d.into(),
        _ => Path::new(env!("CARGO_MANIFEST_DIR")).join("../../assets/envmaps"),
    }
}

/// The path of one map of the test set, e.g. `path("city.exr")`.
#[must_use]
pub fn path(name: &str) -> PathBuf {
    dir().join(name)
}

/// Why the test set's maps could not be listed; the message names the folder.
#[derive(Debug, thiserror::Error)]
pub enum TestSetError {
    /// The folder cannot be read.
    #[error("{}: {source}", path.display())]
    Read {
        /// The folder.
        path: PathBuf,
        /// The reason.
        source: std::io::Error,
    },
    /// The folder holds fewer maps than the test set has.
    #[error("{}: {found} maps, expected at least {wanted}", path.display())]
    TooFew {
        /// The folder.
        path: PathBuf,
        /// Maps found.
        found: usize,
        /// Maps wanted.
        wanted: usize,
    },
}

/// Every `.exr` and `.hdr` file in `dir`, sorted by name.
///
/// # Errors
/// [`TestSetError::Read`] when the folder cannot be read.
pub fn maps_in(dir: &Path) -> Result<Vec<PathBuf>, TestSetError> {
    let entries = std::fs::read_dir(dir).map_err(|source| TestSetError::Read { path: dir.to_path_buf(), source })?;
    let mut maps: Vec<PathBuf> = entries
        .flatten()
        .map(|e| e.path())
        .filter(|p| p.extension().is_some_and(|x| x.eq_ignore_ascii_case("exr") || x.eq_ignore_ascii_case("hdr")))
        .collect();
    maps.sort();
    Ok(maps)
}

/// The test set's maps, sorted by name.
///
/// # Errors
/// [`TestSetError`] when the folder cannot be read or holds fewer than [`COUNT`] maps (tests
/// that use them must fail, not pass vacuously; with `ENVSHADOW_ENVMAPS` any non-empty folder
/// will do).
pub fn maps() -> Result<Vec<PathBuf>, TestSetError> {
    let d = dir();
    let maps = maps_in(&d)?;
    let wanted = if std::env::var_os(ENV_VAR).is_some_and(|v| !v.is_empty()) { 1 } else { COUNT };
    if maps.len() < wanted {
        return Err(TestSetError::TooFew { path: d, found: maps.len(), wanted });
    }
    Ok(maps)
}
