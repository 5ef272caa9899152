//! Workspace-wide checks live in `tests/`: the repository's rules written as tests (every
//! module documents itself, no ignored tests, no stubs). This library only locates the
//! workspace root for them.

use std::path::{Path, PathBuf};

/// The workspace root (the parent of this package).
#[must_use]
pub fn workspace_root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).parent().map(Path::to_path_buf).unwrap_or_default()
}

/// Every `.rs` file of the workspace's own code (crates, xtask, tests, benches).
#[must_use]
pub fn rust_sources() -> Vec<PathBuf> {
    let root = workspace_root();
    let mut out = Vec::new();
    for top in ["crates", "xtask", "tests", "benches"] {
        collect(&root.join(top), "rs", &mut out);
    }
    out.sort();
    out
}

/// Files with extension `ext` below `dir`, skipping `target`.
pub fn collect(dir: &Path, ext: &str, out: &mut Vec<PathBuf>) {
    let Ok(entries) = std::fs::read_dir(dir) else { return };
    for e in entries.flatten() {
        let p = e.path();
        if p.is_dir() {
            if p.file_name().is_some_and(|n| n != "target") {
                collect(&p, ext, out);
            }
        } else if p.extension().is_some_and(|x| x == ext) {
            out.push(p);
        }
    }
}
