//! The glTF mutations reach every refusal the issue names, and nothing panics. (Its own test
//! binary: a run's panic hook is process-wide.)

use input_fuzz::{Target, seeds};
use std::sync::{Arc, Mutex};

#[test]
fn model_mutations_reach_every_kind_of_bad_model_and_none_panics() {
    let messages: Arc<Mutex<Vec<String>>> = Arc::default();
    let targets: Vec<Target> = seeds::library_targets()
        .into_iter()
        .filter(|t| t.name.starts_with("model."))
        .map(|t| {
            let (log, run) = (Arc::clone(&messages), t.run);
            Target {
                run: Box::new(move |bytes, path| {
                    let r = run(bytes, path);
                    if let (Err(e), Ok(mut l)) = (&r, log.lock()) {
                        l.push(e.clone());
                    }
                    r
                }),
                ..t
            }
        })
        .collect();
    assert_eq!(targets.len(), 2);
    let report = input_fuzz::run(&targets, 20_000, 11, None, &mut |_| {});
    let found: Vec<String> = report.findings.iter().map(|f| format!("{} {}: {}", f.target, f.name, f.what)).collect();
    assert!(report.is_clean(), "{}\n{found:#?}", report.summary());
    let messages = messages.lock().map(|m| m.clone()).unwrap_or_default();
    // the list of bad models, each reached: not glTF at all, a truncated or lying
    // container, a missing buffer file, accessors past their views, absurd counts, NaN
    // positions, indices past the vertices, nothing to draw; and compression and cycles
    for kind in [
        "not a readable glTF 2.0 file",
        "GLB header",
        "which is missing",
        "runs past",
        "POSITION is accessor",
        "more than",
        "is not finite",
        "vertices",
        "no triangles",
        "which is not supported",
        "has a cycle",
    ] {
        let n = messages.iter().filter(|m| m.contains(kind)).count();
        assert!(n > 0, "no case was refused with {kind:?}");
    }
    assert!(report.accepted > 0, "some mutations leave a model that loads");
}

#[test]
fn model_seeds_import_with_the_triangles_their_writers_put_in() {
    let count = |bytes: &[u8], name: &str| {
        let import = scene::import::load_gltf_from_bytes(bytes, std::path::Path::new(name), &seeds::gltf_options())
            .unwrap_or_else(|e| panic!("{e}"));
        let triangles: usize = import.scene.objects.iter().map(|o| o.mesh.indices.len()).sum();
        (triangles, import.skipped_primitives)
    };
    // three_boxes, column, the hand-made cube (12) and strip quad (2) with a points primitive,
    // the sparse grid (12; its copy over zeros is all degenerate) and column Draco-compressed
    let want = [(38, 0), (442, 0), (14, 1), (12, 0), (442, 0)];
    let (gltf, glb) = (seeds::gltf(), seeds::glb());
    assert_eq!((gltf.len(), glb.len()), (5, 5));
    for (k, w) in want.iter().enumerate() {
        assert_eq!(count(&gltf[k], "seed.gltf"), *w, "seed {k} as .gltf");
        assert_eq!(count(&glb[k], "seed.glb"), *w, "seed {k} as .glb");
    }
}
