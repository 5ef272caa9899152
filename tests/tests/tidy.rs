//! Repository rules that can be tests (rust-analyzer's tidy): each failure names the file.

use workspace_tests::{rust_sources, workspace_root};

#[test]
fn sources_are_found() {
    let sources = rust_sources();
    assert!(sources.len() > 10, "found only {} .rs files under {}", sources.len(), workspace_root().display());
}

#[test]
fn every_module_starts_with_a_doc_comment() {
    let missing: Vec<String> = rust_sources()
        .into_iter()
        .filter(|p| {
            let text = std::fs::read_to_string(p).unwrap_or_default();
            !text.trim_start().starts_with("//!")
        })
        .map(|p| p.display().to_string())
        .collect();
    assert!(missing.is_empty(), "modules without a `//!` summary:\n{}", missing.join("\n"));
}

#[test]
fn no_ignored_tests_and_no_stubs() {
    // Built from parts so this file does not trip its own check.
    let banned = [concat!("#[", "ignore"), concat!("todo", "!("), concat!("unimplemented", "!(")];
    let mut hits = Vec::new();
    for p in rust_sources() {
        let text = std::fs::read_to_string(&p).unwrap_or_default();
        for (n, line) in text.lines().enumerate() {
            for b in banned {
                if line.contains(b) {
                    hits.push(format!("{}:{}: {}", p.display(), n + 1, line.trim()));
                }
            }
        }
    }
    assert!(hits.is_empty(), "ignored tests or stubs:\n{}", hits.join("\n"));
}

#[test]
fn every_crate_shares_the_workspace_lints() {
    let root = workspace_root();
    let mut manifests = Vec::new();
    workspace_tests::collect(&root.join("crates"), "toml", &mut manifests);
    manifests.extend([root.join("xtask/Cargo.toml"), root.join("tests/Cargo.toml"), root.join("benches/Cargo.toml")]);
    for m in manifests.iter().filter(|m| m.ends_with("Cargo.toml")) {
        let text = std::fs::read_to_string(m).unwrap_or_default();
        assert!(text.contains("[lints]\nworkspace = true"), "{} does not use [workspace.lints]", m.display());
    }
}

#[test]
fn nothing_reads_beside_the_repository() {
    // A user's clone has nothing beside it: data lives in the repository (assets/). Built from
    // parts so this file does not trip its own check.
    let beside = concat!("..", "/shared");
    let root = workspace_root();
    let mut files = rust_sources();
    for (dir, ext) in [(".", "toml"), ("crates", "toml"), ("xtask", "toml"), (".ci", "run"), ("crates", "wgsl")] {
        workspace_tests::collect(&root.join(dir), ext, &mut files);
    }
    files.push(root.join(".ci/run"));
    files.push(root.join(".cargo/config.toml"));
    let hits: Vec<String> = files
        .iter()
        .filter(|p| std::fs::read_to_string(p).is_ok_and(|t| t.contains(beside)))
        .map(|p| p.display().to_string())
        .collect();
    assert!(hits.is_empty(), "files that read {beside}:\n{}", hits.join("\n"));
}

#[test]
fn library_errors_are_typed() {
    // docs/architecture.md, "Errors": a public function of a library crate returns a thiserror
    // enum, not a String, except the `validate()` consistency checks. Signatures are read from
    // the `pub fn` line through its opening brace.
    let root = workspace_root();
    let mut sources = Vec::new();
    workspace_tests::collect(&root.join("crates"), "rs", &mut sources);
    let mut hits = Vec::new();
    for p in sources.iter().filter(|p| p.components().any(|c| c.as_os_str() == "src")) {
        let text = std::fs::read_to_string(p).unwrap_or_default();
        let lines: Vec<&str> = text.lines().collect();
        for (n, line) in lines.iter().enumerate() {
            let t = line.trim_start();
            if !t.starts_with("pub fn ") || t.starts_with("pub fn validate(") {
                continue;
            }
            let end = lines[n..].iter().position(|l| l.trim_end().ends_with('{') || l.trim_end().ends_with(';'));
            let signature = lines[n..=n + end.unwrap_or(0)].concat();
            if signature.contains(", String>") {
                hits.push(format!("{}:{}: {}", p.display(), n + 1, t));
            }
        }
    }
    assert!(hits.is_empty(), "String errors from library functions:\n{}", hits.join("\n"));
}

#[test]
fn every_workspace_dependency_is_used() {
    // `[workspace.dependencies]` declares each dependency once; one no member names is dead
    // weight in the lock file and in every reader's head.
    let root = workspace_root();
    let top = std::fs::read_to_string(root.join("Cargo.toml")).expect("read Cargo.toml");
    let table = top.split("[workspace.dependencies]").nth(1).expect("a [workspace.dependencies] table");
    let table = table.split("\n[").next().unwrap_or_default();
    let declared: Vec<&str> = table
        .lines()
        .filter(|l| !l.trim_start().starts_with('#'))
        .filter_map(|l| l.split_once('=').map(|(k, _)| k.trim()))
        .filter(|k| !k.is_empty())
        .collect();
    assert!(declared.len() > 10, "read only {} workspace dependencies", declared.len());
    let mut manifests = Vec::new();
    workspace_tests::collect(&root.join("crates"), "toml", &mut manifests);
    manifests.extend([root.join("xtask/Cargo.toml"), root.join("tests/Cargo.toml"), root.join("benches/Cargo.toml")]);
    let members: String = manifests
        .iter()
        .filter(|m| m.ends_with("Cargo.toml"))
        .map(|m| std::fs::read_to_string(m).unwrap_or_else(|e| panic!("{}: {e}", m.display())))
        .collect();
    let unused: Vec<&&str> =
        declared.iter().filter(|d| !members.contains(&format!("\n{d}.workspace = true"))).collect();
    assert!(unused.is_empty(), "workspace dependencies no member uses: {unused:?}");
}

#[test]
fn no_library_crate_reads_the_repositorys_folders() {
    // A library's API works from a published copy of the crate: it never reaches above its own
    // folder (`../..` from its manifest) for data. The harness `test-set` is the one crate
    // meant to (it is the repository's test data), and tests may.
    let root = workspace_root();
    let mut hits = Vec::new();
    for entry in std::fs::read_dir(root.join("crates")).expect("read crates/").flatten() {
        let krate = entry.path();
        if krate.file_name().is_some_and(|n| n == "test-set") {
            continue;
        }
        let mut sources = Vec::new();
        workspace_tests::collect(&krate.join("src"), "rs", &mut sources);
        for p in sources {
            let text = std::fs::read_to_string(&p).unwrap_or_default();
            if text.contains(concat!("CARGO_MANIFEST_DIR\")).join(\"../", "..")) || text.contains("\"../../../") {
                hits.push(p.display().to_string());
            }
        }
    }
    assert!(hits.is_empty(), "library sources that read the repository's folders:\n{}", hits.join("\n"));
}

/// `pub struct|enum|trait|type NAME` in each library crate's `src`, as (crate, name, file).
fn public_types() -> Vec<(String, String, String)> {
    let root = workspace_root();
    let mut out = Vec::new();
    for entry in std::fs::read_dir(root.join("crates")).expect("read crates/").flatten() {
        let krate = entry.file_name().to_string_lossy().into_owned();
        let mut files = Vec::new();
        workspace_tests::collect(&entry.path().join("src"), "rs", &mut files);
        for f in files {
            let text = std::fs::read_to_string(&f).unwrap_or_default();
            for line in text.lines() {
                for kind in ["pub struct ", "pub enum ", "pub trait ", "pub type "] {
                    if let Some(rest) = line.strip_prefix(kind) {
                        let name: String = rest.chars().take_while(|c| c.is_alphanumeric() || *c == '_').collect();
                        out.push((krate.clone(), name, f.display().to_string()));
                    }
                }
            }
        }
    }
    out
}

#[test]
fn no_public_type_name_is_defined_twice() {
    // One type per concept, and distinct names for distinct things: two library types of one
    // name are either one concept written twice or two concepts a reader will confuse.
    let types = public_types();
    assert!(types.len() > 50, "found only {} public types", types.len());
    let mut seen: std::collections::BTreeMap<&str, Vec<&str>> = std::collections::BTreeMap::new();
    for (_, name, file) in &types {
        seen.entry(name).or_default().push(file);
    }
    let twice: Vec<String> =
        seen.iter().filter(|(_, f)| f.len() > 1).map(|(n, f)| format!("{n}: {}", f.join(", "))).collect();
    assert!(twice.is_empty(), "public types defined more than once:\n{}", twice.join("\n"));
}

#[test]
fn what_a_light_is_lives_in_scene_and_one_paraboloid_mapping_in_envmap_sphere() {
    // A light's shape, power and colour are `scene`'s (`DistantLight`, `PointLight`,
    // `LightShape`); other crates derive how they draw it. Named after a light, but not one:
    // the shading pass's drawing data, an extraction result that holds a `scene::DistantLight`
    // with what the extractor knows of it, and the environment map as the tracer's emitter.
    let allowed = [("gpu", "ShadeLight"), ("light-extract", "ExtractedLight"), ("ref-tracer", "EnvLight")];
    let types = public_types();
    let lights: Vec<String> = types
        .iter()
        .filter(|(k, n, _)| n.ends_with("Light") && k != "scene" && !allowed.contains(&(k.as_str(), n.as_str())))
        .map(|(_, n, f)| format!("{n} in {f}"))
        .collect();
    assert!(lights.is_empty(), "light types outside `scene`:\n{}", lights.join("\n"));
    for name in ["DistantLight", "PointLight", "LightShape"] {
        assert!(types.iter().any(|(k, n, _)| k == "scene" && n == name), "`scene` lost {name}");
    }
    let hemispheres: Vec<&String> = types.iter().filter(|(_, n, _)| n == "Hemisphere").map(|(_, _, f)| f).collect();
    assert!(
        hemispheres.len() == 1 && hemispheres[0].ends_with("envmap-sphere/src/paraboloid.rs"),
        "the paraboloid mapping's Hemisphere is defined in {hemispheres:?}"
    );
}
