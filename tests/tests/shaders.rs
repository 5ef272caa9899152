//! Every WGSL file parses and validates with naga, composed with the library files its
//! `// requires:` lines name, by `gpu::shader::compose_with` as at run time. Each shader sits in
//! `crates/<crate>/shaders/` of the crate whose pass owns it, so each crate packages its own.

use std::path::{Path, PathBuf};
use workspace_tests::{collect, workspace_root};

fn shaders() -> Vec<PathBuf> {
    let mut out = Vec::new();
    collect(&workspace_root().join("crates"), "wgsl", &mut out);
    out.sort();
    out
}

/// The file composed as at run time (`gpu::shader::compose_with`), a library file `<crate>/<file>`
/// read from `crates/<crate>/shaders/<file>`.
fn compose(path: &Path) -> Result<String, String> {
    let text = std::fs::read_to_string(path).map_err(|e| format!("{}: {e}", path.display()))?;
    let read = |name: &str| {
        let (krate, file) =
            name.split_once('/').ok_or_else(|| format!("{} requires {name}: not <crate>/<file>", path.display()))?;
        let lib = workspace_root().join("crates").join(krate).join("shaders").join(file);
        std::fs::read_to_string(&lib).map_err(|e| format!("{} requires {name}: {e}", path.display()))
    };
    gpu::shader::compose_with(&text, read)
}

#[test]
fn every_shader_lives_in_its_crates_shaders_folder() {
    // A shader outside `crates/<crate>/shaders/` would not be packaged with the crate that
    // includes it; and no shader is left at the workspace root.
    let root = workspace_root();
    let files = shaders();
    assert!(!files.is_empty(), "no shader found under crates/");
    for p in files {
        let rel = p.strip_prefix(root.join("crates")).unwrap_or(&p);
        let parts: Vec<_> = rel.components().map(|c| c.as_os_str().to_string_lossy().to_string()).collect();
        assert!(parts.len() == 3 && parts[1] == "shaders", "{}: not crates/<crate>/shaders/<file>", p.display());
    }
    assert!(!root.join("shaders").exists(), "a shaders/ folder at the workspace root");
}

#[test]
fn every_shader_parses_and_validates_with_naga() {
    let files = shaders();
    assert!(files.len() >= 4, "found only {} shaders", files.len());
    let mut failures = Vec::new();
    for p in files {
        let src = match compose(&p) {
            Ok(s) => s,
            Err(e) => {
                failures.push(e);
                continue;
            }
        };
        let module = match naga::front::wgsl::parse_str(&src) {
            Ok(m) => m,
            Err(e) => {
                failures.push(format!("{}: {}", p.display(), e.emit_to_string(&src)));
                continue;
            }
        };
        let mut validator =
            naga::valid::Validator::new(naga::valid::ValidationFlags::all(), naga::valid::Capabilities::all());
        if let Err(e) = validator.validate(&module) {
            failures.push(format!("{}: {}", p.display(), e.emit_to_string(&src)));
        }
    }
    assert!(failures.is_empty(), "{}", failures.join("\n\n"));
}
