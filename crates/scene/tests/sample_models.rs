//! The public sample models in `assets/models/` (Khronos glTF-Sample-Assets, CC0 and CC-BY 4.0;
//! see its README): each imports with its triangles, material and warnings, or is refused with
//! the reason the README states. Their triangles and depth images against an independent reader
//! are checked in `tests/tests/independent_gltf.rs` (it needs the reference tracer).

use glam::Vec3;
use scene::import::{GltfError, GltfOptions, load_gltf};
use serde_json::Value;
use std::path::PathBuf;

fn model(name: &str) -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../assets/models").join(name)
}

#[test]
fn sample_models_import_with_their_triangles_material_and_warnings() {
    // none has a material: glTF's default (metallic 1, roughness 1, one-sided) is modelled
    for (name, triangles, warnings) in [
        ("Cameras.gltf", 2, &[][..]),
        ("TriangleWithoutIndices.gltf", 1, &[][..]),
        ("AnimatedTriangle.gltf", 1, &["animations are not modelled"][..]),
    ] {
        let import = load_gltf(&model(name), &GltfOptions::default()).unwrap_or_else(|e| panic!("{e}"));
        let count: usize = import.scene.objects.iter().map(|o| o.mesh.indices.len()).sum();
        assert_eq!(count, triangles, "{name}");
        assert_eq!(import.warnings.len(), warnings.len(), "{name}: {:?}", import.warnings);
        for o in &import.scene.objects {
            let m = o.material;
            assert!(m.albedo == Vec3::ZERO && m.specular.is_some_and(|g| g.f0 == Vec3::ONE && g.roughness == 1.0));
            assert!(!m.double_sided, "{name}");
        }
        for w in warnings {
            assert!(import.warnings.iter().any(|x| x.contains(w)), "{name}: {:?}", import.warnings);
        }
    }
}

#[test]
fn the_sample_cameras_first_perspective_camera_is_used() {
    // Cameras.gltf: a perspective camera (yfov 0.7, aspect 1) and an orthographic one, both at
    // (0.5, 0.5, 3) looking down -Z
    let options = GltfOptions { size: (400, 400), ..GltfOptions::default() };
    let c = load_gltf(&model("Cameras.gltf"), &options).expect("import").scene.camera;
    assert!(c.eye.distance(Vec3::new(0.5, 0.5, 3.0)) < 1e-6, "{c:?}");
    assert!((c.target - c.eye).normalize().distance(Vec3::NEG_Z) < 1e-6, "{c:?}");
    assert!((c.hfov_degrees - 0.7f32.to_degrees()).abs() < 1e-3, "{c:?}");
}

/// SimpleSparseAccessor.gltf: a 7 x 2 grid of vertices (x 0..6, y 0 and 1) whose POSITION
/// accessor substitutes three of them sparsely: vertices 8, 10 and 12 (x 1, 3, 5 of the top
/// row) rise to y 2, 3 and 4 (the sample's README).
#[test]
fn the_sparse_sample_reads_its_substituted_vertices() {
    let import =
        load_gltf(&model("SimpleSparseAccessor.gltf"), &GltfOptions::default()).unwrap_or_else(|e| panic!("{e}"));
    let [object] = import.scene.objects.as_slice() else { panic!("{} objects", import.scene.objects.len()) };
    assert_eq!(object.mesh.indices.len(), 12);
    let key = |p: Vec3| p.to_array().map(f32::to_bits);
    let mut want: Vec<[u32; 3]> = (0..14)
        .map(|i| {
            let (x, row) = ((i % 7) as f32, i / 7);
            let y = match i {
                8 => 2.0,
                10 => 3.0,
                12 => 4.0,
                _ => row as f32,
            };
            key(Vec3::new(x, y, 0.0))
        })
        .collect();
    let mut got: Vec<[u32; 3]> = object.mesh.positions.iter().map(|&p| key(p)).collect();
    want.sort_unstable();
    got.sort_unstable();
    assert_eq!(got, want);
}

/// Sparse substitutions that point past the accessor, or whose indices or values run past
/// their view, are refused in one line naming the file; a sparse accessor without a view
/// starts from zeros.
#[test]
fn bad_sparse_accessors_are_refused_in_one_line() {
    let text = std::fs::read_to_string(model("SimpleSparseAccessor.gltf")).expect("read");
    let d = std::env::temp_dir().join(format!("envshadow-sparse-{}", std::process::id()));
    std::fs::create_dir_all(&d).expect("temp dir");
    let edit = |name: &str, change: &dyn Fn(&mut Value)| {
        let mut doc: Value = serde_json::from_str(&text).expect("json");
        change(&mut doc["accessors"][1]);
        let path = d.join(name);
        std::fs::write(&path, serde_json::to_vec(&doc).expect("json")).expect("write");
        (path.clone(), load_gltf(&path, &GltfOptions::default()))
    };
    for (name, change, reason) in [
        ("past.gltf", &(|a: &mut Value| a["count"] = 12.into()) as &dyn Fn(&mut Value), "substitutes element 12 of 12"),
        ("many.gltf", &|a: &mut Value| a["sparse"]["count"] = 100.into(), "run past buffer view"),
        ("offset.gltf", &|a: &mut Value| a["sparse"]["values"]["byteOffset"] = 8.into(), "values (offset 8) run past"),
    ] {
        let (path, result) = edit(name, change);
        let e = result.err().unwrap_or_else(|| panic!("{name}: imported"));
        let msg = e.to_string();
        assert!(matches!(e, GltfError::Malformed { .. }), "{name}: {msg}");
        assert!(msg.contains(path.to_str().expect("utf-8")) && msg.contains(reason) && !msg.contains('\n'), "{msg}");
    }
    // without its view the base is zeros: every triangle keeps two vertices at the origin (each
    // has one of the substituted three at most), so all twelve are dropped as degenerate
    let (_, zeros) = edit("zeros.gltf", &|a: &mut Value| {
        a.as_object_mut().expect("accessor").remove("bufferView");
    });
    let Err(e) = zeros else { panic!("zeros.gltf imported: all its triangles are degenerate") };
    let msg = e.to_string();
    assert!(msg.contains("no triangles (after dropping 12 degenerate ones)"), "{msg}");
    std::fs::remove_dir_all(&d).ok();
}

#[test]
fn the_textured_sample_imports_its_texture_and_coordinates_as_read_here() {
    // BoxTextured.gltf: a cube (24 vertices, u16 indices) under a matrix node that turns +Y to
    // -Z, its base colour a 256 x 256 PNG in a data URI, sampled linear and repeated
    let import = load_gltf(&model("BoxTextured.gltf"), &GltfOptions::default()).unwrap_or_else(|e| panic!("{e}"));
    assert!(import.warnings.is_empty(), "{:?}", import.warnings);
    let scene = &import.scene;
    let doc: Value = serde_json::from_slice(&std::fs::read(model("BoxTextured.gltf")).expect("read")).expect("json");
    let data = |uri: &str| base64::decode(&uri[uri.find(',').expect("data uri") + 1..]).expect("base64");
    let bin = data(doc["buffers"][0]["uri"].as_str().expect("uri"));
    let png = image::load_from_memory(&data(doc["images"][0]["uri"].as_str().expect("uri"))).expect("png").into_rgba8();
    let t = &scene.textures[0];
    assert_eq!((scene.textures.len(), t.width, t.height), (1, png.width(), png.height()));
    assert!(t.texels.iter().zip(png.pixels()).all(|(a, b)| *a == b.0), "texels as the PNG holds them");
    assert_eq!((t.wrap, t.filter), ([scene::Wrap::Repeat; 2], scene::Filter::Linear));
    // positions at byte 288 of view 1 (offset 0), uvs in view 2 (offset 576), u16 indices at 768
    let f = |at: usize| f32::from_le_bytes(bin[at..at + 4].try_into().expect("4 bytes"));
    let position = |v: usize| {
        let p = Vec3::new(f(288 + 12 * v), f(292 + 12 * v), f(296 + 12 * v));
        Vec3::new(p.x, p.z, -p.y)
    };
    let uv = |v: usize| glam::Vec2::new(f(576 + 8 * v), f(580 + 8 * v));
    let corners: Vec<Vec<(Vec3, glam::Vec2)>> = (0..12)
        .map(|t| {
            (0..3)
                .map(|k| {
                    let i = 768 + 2 * (3 * t + k);
                    let v = u16::from_le_bytes([bin[i], bin[i + 1]]) as usize;
                    (position(v), uv(v))
                })
                .collect()
        })
        .collect();
    let o = &scene.objects[0];
    let uvs = o.mesh.uvs.as_ref().expect("texture coordinates");
    assert_eq!((scene.objects.len(), o.mesh.indices.len()), (1, 12));
    for (tri, want) in o.mesh.indices.iter().zip(&corners) {
        for (k, &i) in tri.iter().enumerate() {
            let (p, c) = want[k];
            assert!(o.mesh.positions[i as usize].distance(p) < 1e-6 && uvs[i as usize] == c, "{tri:?}: {want:?}");
        }
    }
    let maps = o.material.maps.expect("a textured material");
    assert_eq!((maps.base_color_texture, maps.metallic, maps.base_color), (Some(0), 0.0, Vec3::ONE));
    assert!(!o.material.double_sided);
}
