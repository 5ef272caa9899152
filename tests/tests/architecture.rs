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
fn shafts_ask_a_visibility_trait_and_never_touch_wgpu() {
    // the shaft hierarchy asks `real_scene::Visibility` for rays, never ref-tracer itself
    // (real-scene's `PatchBvh` answers with ref-tracer's BVH); neither knows the GPU
    let graph = dependency_graph();
    for krate in ["shaft-hierarchy", "real-scene"] {
        let deps = transitive(&graph, krate);
        assert!(deps.contains("scene"), "{krate}'s graph is incomplete: {deps:?}");
        let gpu: Vec<_> = deps.iter().filter(|d| d.starts_with("wgpu") || *d == "gpu" || *d == "naga").collect();
        assert!(gpu.is_empty(), "{krate} depends on {gpu:?}");
    }
    let direct = &graph["shaft-hierarchy"];
    assert!(direct.iter().any(|d| d == "real-scene"), "{direct:?}");
    assert!(
        !direct.iter().any(|d| d == "ref-tracer" || d == "obvhs"),
        "shaft-hierarchy traces rays itself: {direct:?}"
    );
}

#[test]
fn the_interactive_compositor_never_path_traces() {
    // differential-composite: the path tracer makes the capture and the references (`offline`,
    // `setup`); the compositor itself works from transfers, masks and the photograph
    let dir = workspace_tests::workspace_root().join("crates/differential-composite/src");
    for module in ["compositor.rs", "cpu.rs", "gpu.rs", "ldr.rs"] {
        let text = std::fs::read_to_string(dir.join(module)).unwrap_or_else(|e| panic!("{module}: {e}"));
        for traced in ["photograph(", "photograph_with(", "Integrator", "ref_tracer::render", "offline::"] {
            assert!(!text.contains(traced), "{module} path traces ({traced})");
        }
    }
}

#[test]
fn the_trade_meets_techniques_only_through_the_trait() {
    // `trade` builds each technique from its `Shadow` value in one function and otherwise sees
    // only `gpu::ShadowTechnique`; nothing of the techniques leaks into the fronts, the
    // chooser, shards, tables or the report
    let graph = dependency_graph();
    let deps = transitive(&graph, "trade");
    assert!(deps.contains("gpu") && deps.contains("penumbra-wedge"), "trade's graph is incomplete: {deps:?}");
    assert!(!deps.contains("xtask"), "trade depends on xtask");
    let dir = workspace_tests::workspace_root().join("crates/trade/src");
    let mut builders = 0;
    for entry in std::fs::read_dir(&dir).unwrap_or_else(|e| panic!("{}: {e}", dir.display())) {
        let path = entry.expect("dir entry").path();
        let text = std::fs::read_to_string(&path).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
        let name = path.file_name().map(|n| n.to_string_lossy().to_string()).unwrap_or_default();
        let named = ["Wedges::new", "MapTechnique::new"].iter().filter(|t| text.contains(*t)).count();
        if name == "measure.rs" {
            builders += named;
        } else {
            assert_eq!(named, 0, "{name} builds a technique");
            assert!(!text.contains("penumbra_wedge"), "{name} names penumbra_wedge");
        }
    }
    assert_eq!(builders, 2, "measure.rs builds wedges and maps in `technique`");
}
