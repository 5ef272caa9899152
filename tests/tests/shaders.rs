//! Every WGSL file under `shaders/` parses and validates with naga, composed with the library
//! files its `// requires:` lines name (as `gpu::shader::compose` does at run time). Each shader
//! sits in `shaders/<crate>/` of the crate whose pass owns it.

use std::path::{Path, PathBuf};
use workspace_tests::{collect, workspace_root};

fn shaders() -> Vec<PathBuf> {
    let mut out = Vec::new();
    collect(&workspace_root().join("shaders"), "wgsl", &mut out);
    out.sort();
    out
}

fn compose(path: &Path) -> Result<String, String> {
    let text = std::fs::read_to_string(path).map_err(|e| format!("{}: {e}", path.display()))?;
    let requires: Vec<String> = text
        .lines()
        .filter(|l| !l.trim_start().starts_with("enable "))
        .map_while(|l| l.trim().strip_prefix("//").map(str::trim))
        .filter_map(|l| l.strip_prefix("requires:"))
        .flat_map(str::split_whitespace)
        .map(String::from)
        .collect();
    let (enables, body): (Vec<&str>, Vec<&str>) = text.lines().partition(|l| l.trim_start().starts_with("enable "));
    let mut out = enables.join("\n") + "\n";
    for r in requires {
        let lib = workspace_root().join("shaders").join(&r);
        out += &std::fs::read_to_string(&lib).map_err(|e| format!("{} requires {r}: {e}", path.display()))?;
        out.push('\n');
    }
    Ok(out + &body.join("\n"))
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
