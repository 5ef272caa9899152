//! Every WGSL file under `shaders/` parses and validates with naga, composed with the library
//! files its `// requires:` lines name, by `gpu::shader::compose_with` as at run time. Each shader
//! sits in `shaders/<crate>/` of the crate whose pass owns it.

use std::path::{Path, PathBuf};
use workspace_tests::{collect, workspace_root};

fn shaders() -> Vec<PathBuf> {
    let mut out = Vec::new();
    collect(&workspace_root().join("shaders"), "wgsl", &mut out);
    out.sort();
    out
}

/// The file composed as at run time (`gpu::shader::compose_with`), its library files read from
/// `shaders/`.
fn compose(path: &Path) -> Result<String, String> {
    let text = std::fs::read_to_string(path).map_err(|e| format!("{}: {e}", path.display()))?;
    let read = |name: &str| {
        let lib = workspace_root().join("shaders").join(name);
        std::fs::read_to_string(&lib).map_err(|e| format!("{} requires {name}: {e}", path.display()))
    };
    gpu::shader::compose_with(&text, read)
}

#[test]
fn every_shader_lives_in_a_crate_folder() {
    let root = workspace_root();
    for p in shaders() {
        let rel = p.strip_prefix(root.join("shaders")).unwrap_or(&p);
        let krate = rel.components().next().map(|c| c.as_os_str().to_string_lossy().to_string()).unwrap_or_default();
        assert!(root.join("crates").join(&krate).is_dir(), "{}: shaders/{krate}/ names no crate", p.display());
    }
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
