//! Each crate's architecture invariant (docs/architecture.md), checked on the real dependency
//! graph from `cargo metadata`, transitive dependencies included.

use std::collections::{BTreeSet, HashMap};
use std::process::Command;

/// package name -> names of its normal (non-dev) dependencies, resolved.
fn dependency_graph() -> HashMap<String, Vec<String>> {
    let cargo = std::env::var("CARGO").unwrap_or_else(|_| "cargo".into());
    // Only the host's packages: other platforms' crates are not downloaded.
    let rustc = Command::new("rustc").arg("-vV").output().expect("run rustc -vV");
    let host = String::from_utf8_lossy(&rustc.stdout)
        .lines()
        .find_map(|l| l.strip_prefix("host: ").map(str::to_string))
        .expect("rustc -vV names the host");
    let out = Command::new(cargo)
        .args(["metadata", "--format-version", "1", "--filter-platform", &host])
        .current_dir(workspace_tests::workspace_root())
        .output()
        .expect("run cargo metadata");
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let meta: serde_json::Value = serde_json::from_slice(&out.stdout).expect("metadata JSON");
    let names: HashMap<&str, &str> = meta["packages"]
        .as_array()
        .into_iter()
        .flatten()
        .filter_map(|p| Some((p["id"].as_str()?, p["name"].as_str()?)))
        .collect();
    let mut graph = HashMap::new();
    for node in meta["resolve"]["nodes"].as_array().into_iter().flatten() {
        let Some(name) = node["id"].as_str().and_then(|id| names.get(id)) else { continue };
        let deps = node["deps"]
            .as_array()
            .into_iter()
            .flatten()
            .filter(|d| {
                d["dep_kinds"].as_array().into_iter().flatten().any(|k| k["kind"].is_null() || k["kind"] == "build")
            })
            .filter_map(|d| d["pkg"].as_str().and_then(|id| names.get(id)).map(|n| n.to_string()))
            .collect();
        graph.insert(name.to_string(), deps);
    }
    graph
}

fn transitive(graph: &HashMap<String, Vec<String>>, root: &str) -> BTreeSet<String> {
    let mut seen = BTreeSet::new();
    let mut stack = vec![root.to_string()];
    while let Some(n) = stack.pop() {
        for d in graph.get(&n).into_iter().flatten() {
            if seen.insert(d.clone()) {
                stack.push(d.clone());
            }
        }
    }
    seen
}

const OURS: [&str; 10] = [
    "envmap-sphere",
    "real-scene",
    "light-extract",
    "shaft-hierarchy",
    "shadowmap-paraboloid",
    "penumbra-wedge",
    "differential-composite",
    "ref-tracer",
    "input-fuzz",
    "trade",
];

#[test]
fn envmap_sphere_depends_on_no_crate_of_ours() {
    let graph = dependency_graph();
    // Not vacuous: the graph does see our own edges.
    assert!(transitive(&graph, "xtask").contains("envmap-sphere"), "xtask -> envmap-sphere missing");
    let deps = transitive(&graph, "envmap-sphere");
    let ours: Vec<_> = deps.iter().filter(|d| OURS.contains(&d.as_str()) || *d == "scene" || *d == "gpu").collect();
    assert!(ours.is_empty(), "envmap-sphere depends on {ours:?}");
}

#[test]
fn light_extract_and_ref_tracer_never_touch_wgpu() {
    let graph = dependency_graph();
    for krate in ["light-extract", "ref-tracer", "envmap-sphere", "scene", "input-fuzz"] {
        assert!(graph.contains_key(krate), "{krate} not in the workspace");
        let deps = transitive(&graph, krate);
        let gpu: Vec<_> = deps.iter().filter(|d| d.starts_with("wgpu") || *d == "ash" || *d == "naga").collect();
        assert!(gpu.is_empty(), "{krate} depends on {gpu:?}");
    }
}

#[test]
fn gpu_layer_and_shadow_techniques_stand_apart_from_the_reference() {
    // gpu builds only on envmap-sphere and scene; shadow techniques build on gpu, never on the
    // reference tracer or light extraction (they are measured against the reference in tests
    // and in `xtask validate`, not built on it).
    let graph = dependency_graph();
    let gpu = transitive(&graph, "gpu");
    assert!(gpu.contains("wgpu") && gpu.contains("scene"), "gpu's graph is incomplete: {gpu:?}");
    let ours: Vec<_> = gpu.iter().filter(|d| OURS.contains(&d.as_str()) && *d != "envmap-sphere").collect();
    assert!(ours.is_empty(), "gpu depends on {ours:?}");
    for technique in ["shadowmap-paraboloid", "penumbra-wedge"] {
        let shadows = transitive(&graph, technique);
        assert!(shadows.contains("gpu"), "{technique} does not build on gpu: {shadows:?}");
        for banned in ["ref-tracer", "light-extract", "obvhs"] {
            assert!(!shadows.contains(banned), "{technique} depends on {banned}");
        }
    }
}

#[test]
fn shafts_and_the_compositor_ask_a_visibility_trait_and_reach_no_tracer() {
    // the radiosity solver, the shaft hierarchy and the compositor ask `scene::Visibility` for
    // rays (re-exported by real-scene); the caller fills it with ref-tracer's BVH. No path of
    // their dependency graphs reaches the tracer or its BVH crate, and the first two know no GPU.
    let graph = dependency_graph();
    for krate in ["real-scene", "shaft-hierarchy", "differential-composite"] {
        let deps = transitive(&graph, krate);
        assert!(deps.contains("scene"), "{krate}'s graph is incomplete: {deps:?}");
        for banned in ["ref-tracer", "obvhs", "trade", "light-extract"] {
            assert!(!deps.contains(banned), "{krate} reaches {banned}: {deps:?}");
        }
    }
    for krate in ["shaft-hierarchy", "real-scene"] {
        let deps = transitive(&graph, krate);
        let gpu: Vec<_> = deps.iter().filter(|d| d.starts_with("wgpu") || *d == "gpu" || *d == "naga").collect();
        assert!(gpu.is_empty(), "{krate} depends on {gpu:?}");
    }
    // not vacuous: the tracer is in the graph, and the harness reaches it
    assert!(transitive(&graph, "trade").contains("ref-tracer"), "trade -> ref-tracer missing");
}

#[test]
fn library_crates_reach_no_harness() {
    // harnesses (trade, benches, input-fuzz, test-set, xtask) use the libraries, never the
    // other way round, through any path
    let graph = dependency_graph();
    let libraries = [
        "envmap-sphere",
        "scene",
        "light-extract",
        "ref-tracer",
        "gpu",
        "shadowmap-paraboloid",
        "penumbra-wedge",
        "real-scene",
        "shaft-hierarchy",
        "differential-composite",
    ];
    for krate in libraries {
        assert!(graph.contains_key(krate), "{krate} not in the workspace");
        let deps = transitive(&graph, krate);
        for harness in ["trade", "envshadow-benches", "input-fuzz", "test-set", "xtask", "envshadow", "workspace-tests"]
        {
            assert!(!deps.contains(harness), "{krate} reaches the harness {harness}");
        }
    }
}

#[test]
fn the_trade_meets_techniques_only_through_the_trait() {
    // One technique builder (`trade::TechniqueBuilder`) makes every technique the trade,
    // validate and the benches measure; otherwise they see only `gpu::ShadowTechnique`, and
    // nothing of the techniques leaks into the fronts, the chooser, shards, tables or the report
    let graph = dependency_graph();
    let deps = transitive(&graph, "trade");
    assert!(deps.contains("gpu") && deps.contains("penumbra-wedge"), "trade's graph is incomplete: {deps:?}");
    assert!(!deps.contains("xtask"), "trade depends on xtask");
    let root = workspace_tests::workspace_root();
    let mut files = Vec::new();
    for dir in ["crates/trade/src", "xtask/src", "crates/envshadow/src", "benches/src"] {
        workspace_tests::collect(&root.join(dir), "rs", &mut files);
    }
    assert!(files.len() > 20, "found only {} harness files", files.len());
    let mut builders = Vec::new();
    for path in &files {
        let text = std::fs::read_to_string(path).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
        let rel = path.strip_prefix(&root).unwrap_or(path).to_string_lossy().replace('\\', "/");
        let named = ["Wedges::new", "MapTechnique::new"].iter().filter(|t| text.contains(*t)).count();
        if named > 0 {
            builders.push((rel.clone(), named));
        }
        let knobs = ["crates/trade/src/techniques.rs", "crates/trade/src/setting.rs"];
        if rel.starts_with("crates/trade/") && !knobs.contains(&rel.as_str()) {
            assert!(!text.contains("penumbra_wedge"), "{rel} names penumbra_wedge");
        }
    }
    // the builder; the animated frame, which moves its own maps and wedges (`set_transform`
    // needs the concrete types); and the viewer, which embeds the libraries as a renderer
    // would, the harness left out, and moves its object too
    let want = vec![
        ("benches/src/decomposition.rs".to_string(), 2),
        ("crates/envshadow/src/view/stage.rs".to_string(), 2),
        ("crates/trade/src/techniques.rs".to_string(), 2),
    ];
    builders.sort();
    assert_eq!(builders, want, "techniques built outside the one builder");
}

/// The module names `text` uses through `prefix` (`crate::` or `super::`), among `names`.
fn used_modules(text: &str, prefix: &str, names: &BTreeSet<String>) -> BTreeSet<String> {
    let mut used = BTreeSet::new();
    let mut rest = text;
    while let Some(i) = rest.find(prefix) {
        rest = &rest[i + prefix.len()..];
        let word: String = rest.chars().take_while(|c| c.is_ascii_alphanumeric() || *c == '_').collect();
        if names.contains(&word) {
            used.insert(word);
        }
        // `use crate::{a, b}` and `use super::{a::X, b}`
        if rest.starts_with('{') {
            let group = &rest[1..rest.find('}').unwrap_or(rest.len())];
            for part in group.split(',') {
                let word: String = part.trim().chars().take_while(|c| c.is_ascii_alphanumeric() || *c == '_').collect();
                if names.contains(&word) {
                    used.insert(word);
                }
            }
        }
    }
    used
}

/// The first cycle of a graph, if any, as the path that closes it.
fn cycle(graph: &HashMap<String, BTreeSet<String>>) -> Option<Vec<String>> {
    fn visit(
        n: &str,
        graph: &HashMap<String, BTreeSet<String>>,
        path: &mut Vec<String>,
        done: &mut BTreeSet<String>,
    ) -> Option<Vec<String>> {
        if let Some(i) = path.iter().position(|p| p == n) {
            let mut c = path[i..].to_vec();
            c.push(n.to_string());
            return Some(c);
        }
        if done.contains(n) {
            return None;
        }
        path.push(n.to_string());
        for d in graph.get(n).into_iter().flatten() {
            if let Some(c) = visit(d, graph, path, done) {
                return Some(c);
            }
        }
        path.pop();
        done.insert(n.to_string());
        None
    }
    let mut done = BTreeSet::new();
    let mut keys: Vec<_> = graph.keys().collect();
    keys.sort();
    keys.into_iter().find_map(|k| visit(k, graph, &mut Vec::new(), &mut done))
}

#[test]
fn cycle_finds_a_circle_and_passes_a_tree() {
    let g = |edges: &[(&str, &str)]| {
        let mut m: HashMap<String, BTreeSet<String>> = HashMap::new();
        for (a, b) in edges {
            m.entry(a.to_string()).or_default().insert(b.to_string());
        }
        m
    };
    assert_eq!(cycle(&g(&[("a", "b"), ("b", "c"), ("a", "c")])), None);
    assert_eq!(
        cycle(&g(&[("a", "b"), ("b", "c"), ("c", "a")])),
        Some(vec!["a".into(), "b".into(), "c".into(), "a".into()])
    );
    let names: BTreeSet<String> = ["shafts", "validate"].into_iter().map(String::from).collect();
    let used = used_modules("use crate::{shafts::x, validate};\nlet y = crate::shafts::z;", "crate::", &names);
    assert_eq!(used, names);
}

#[test]
fn xtask_modules_form_a_tree_not_a_circle() {
    // A command module may use the leaves (`common`, `lavapipe`, `thresholds`) and run another
    // command, but no two modules reach each other: `xtask/src`'s top-level modules through
    // `crate::`, and the sibling modules of each folder through `super::`.
    let root = workspace_tests::workspace_root().join("xtask/src");
    let mut dirs = vec![(root.clone(), "crate::")];
    for entry in std::fs::read_dir(&root).expect("read xtask/src").flatten() {
        if entry.path().is_dir() {
            dirs.push((entry.path(), "super::"));
        }
    }
    let mut edges = 0;
    for (dir, prefix) in dirs {
        let mut files: HashMap<String, String> = HashMap::new();
        for entry in std::fs::read_dir(&dir).unwrap_or_else(|e| panic!("{}: {e}", dir.display())).flatten() {
            let p = entry.path();
            let name = p.file_stem().map(|s| s.to_string_lossy().to_string()).unwrap_or_default();
            if name == "main" || name == "mod" {
                continue;
            }
            let text = if p.is_dir() {
                let mut all = String::new();
                let mut sources = Vec::new();
                workspace_tests::collect(&p, "rs", &mut sources);
                for s in sources {
                    all.push_str(&std::fs::read_to_string(&s).unwrap_or_default());
                }
                all
            } else if p.extension().is_some_and(|x| x == "rs") {
                std::fs::read_to_string(&p).unwrap_or_default()
            } else {
                continue;
            };
            files.insert(name, text);
        }
        let names: BTreeSet<String> = files.keys().cloned().collect();
        let graph: HashMap<String, BTreeSet<String>> = files
            .iter()
            .map(|(n, text)| {
                let mut used = used_modules(text, prefix, &names);
                used.remove(n);
                (n.clone(), used)
            })
            .collect();
        edges += graph.values().map(BTreeSet::len).sum::<usize>();
        assert_eq!(cycle(&graph), None, "{}: modules that reach each other", dir.display());
    }
    assert!(edges > 5, "read only {edges} edges between xtask's modules");
}

/// The `"..."` arguments of `macro!("...")` calls in `text`.
fn included_paths<'a>(text: &'a str, macro_name: &str) -> Vec<&'a str> {
    let open = format!("{macro_name}!(\"");
    text.match_indices(&open)
        .filter_map(|(i, _)| {
            let rest = &text[i + open.len()..];
            rest.find('"').map(|end| &rest[..end])
        })
        .collect()
}

#[test]
fn every_library_crate_packages_the_files_it_includes() {
    // A crate stands alone when its package holds what its sources include: shaders, tables,
    // the embedded map. `cargo package --list` is what a published copy would hold.
    let root = workspace_tests::workspace_root();
    let cargo = std::env::var("CARGO").unwrap_or_else(|_| "cargo".into());
    let mut checked = 0;
    for entry in std::fs::read_dir(root.join("crates")).expect("read crates/").flatten() {
        let dir = entry.path();
        let manifest = std::fs::read_to_string(dir.join("Cargo.toml")).unwrap_or_default();
        let Some(name) = manifest.lines().find_map(|l| l.strip_prefix("name = \"")).and_then(|l| l.strip_suffix('"'))
        else {
            continue;
        };
        let out = Command::new(&cargo)
            .args(["package", "--list", "--allow-dirty", "-p", name])
            .current_dir(&root)
            .output()
            .expect("run cargo package --list");
        assert!(out.status.success(), "{name}: {}", String::from_utf8_lossy(&out.stderr));
        let listed: BTreeSet<String> = String::from_utf8_lossy(&out.stdout).lines().map(str::to_string).collect();
        let mut sources = Vec::new();
        workspace_tests::collect(&dir.join("src"), "rs", &mut sources);
        for source in sources {
            let text = std::fs::read_to_string(&source).unwrap_or_default();
            for included in
                included_paths(&text, "include_str").into_iter().chain(included_paths(&text, "include_bytes"))
            {
                let path = source.parent().expect("a source's folder").join(included);
                let path =
                    std::fs::canonicalize(&path).unwrap_or_else(|e| panic!("{}: {included}: {e}", source.display()));
                let dir = std::fs::canonicalize(&dir).expect("the crate's folder");
                let rel = path
                    .strip_prefix(&dir)
                    .unwrap_or_else(|_| panic!("{}: includes {included}, outside crate {name}", source.display()));
                let rel = rel.to_string_lossy().replace('\\', "/");
                assert!(listed.contains(&rel), "{name}'s package lacks {rel} ({} includes it)", source.display());
                checked += 1;
            }
        }
    }
    assert!(checked > 20, "checked only {checked} included files");
}

#[test]
fn the_code_map_names_every_crate_with_its_invariant() {
    // docs/architecture.md, the rust-analyzer way: an entry per crate, a few lines each, its
    // invariant, and whether it is an API boundary
    let root = workspace_tests::workspace_root();
    let doc = std::fs::read_to_string(root.join("docs/architecture.md")).expect("read docs/architecture.md");
    let mut members: Vec<String> = std::fs::read_dir(root.join("crates"))
        .expect("read crates/")
        .flatten()
        .filter(|e| e.path().join("Cargo.toml").is_file())
        .map(|e| format!("crates/{}", e.file_name().to_string_lossy()))
        .collect();
    members.extend(["benches", "xtask", "tests"].map(String::from));
    assert!(members.len() >= 15, "found only {members:?}");
    for member in members {
        let heading = format!("### `{member}`");
        let start = doc.find(&heading).unwrap_or_else(|| panic!("docs/architecture.md has no `{heading}`"));
        let body = &doc[start + heading.len()..];
        let body = &body[..body.find("\n#").unwrap_or(body.len())];
        let (what, rule) = body
            .split_once("**Architecture invariant:**")
            .unwrap_or_else(|| panic!("{member}: no **Architecture invariant:**"));
        let lines = what.trim().lines().count();
        assert!((2..=6).contains(&lines), "{member}: {lines} lines before its invariant (3-6 wanted)");
        assert!(
            rule.contains("**API boundary") || rule.contains("Internal"),
            "{member}: neither **API boundary** nor Internal"
        );
    }
}
