//! The public sample models in `assets/models/` (Khronos glTF-Sample-Assets, CC0 and CC-BY 4.0;
//! see its README): each imports with the triangles an independent reading of the file gives —
//! the JSON through `serde_json`, the buffers' data URIs through `base64`, the node's TRS applied
//! here — or is refused with the reason the README states, and what it holds that is not modelled
//! is reported.

use glam::{Quat, Vec3};
use scene::import::{GltfError, GltfOptions, load_gltf};
use serde_json::Value;
use std::path::PathBuf;

fn model(name: &str) -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../assets/models").join(name)
}

/// World-space triangles of a file of single-primitive meshes on root nodes with TRS, read
/// without the `gltf` crate.
fn independent_triangles(name: &str) -> Vec<[Vec3; 3]> {
    let doc: Value = serde_json::from_slice(&std::fs::read(model(name)).expect("read")).expect("json");
    let buffers: Vec<Vec<u8>> = doc["buffers"]
        .as_array()
        .expect("buffers")
        .iter()
        .map(|b| {
            let uri = b["uri"].as_str().expect("uri");
            base64::decode(&uri[uri.find(',').expect("data uri") + 1..]).expect("base64")
        })
        .collect();
    let view_bytes = |accessor: &Value| -> &[u8] {
        let view = &doc["bufferViews"][accessor["bufferView"].as_u64().expect("view") as usize];
        let start = view["byteOffset"].as_u64().unwrap_or(0) + accessor["byteOffset"].as_u64().unwrap_or(0);
        &buffers[view["buffer"].as_u64().expect("buffer") as usize][start as usize..]
    };
    let mut out = Vec::new();
    for node in doc["scenes"][0]["nodes"].as_array().expect("nodes") {
        let node = &doc["nodes"][node.as_u64().expect("node") as usize];
        let Some(mesh) = node["mesh"].as_u64() else { continue };
        let r: Vec<f32> = node["rotation"]
            .as_array()
            .map_or(vec![0.0, 0.0, 0.0, 1.0], |r| r.iter().map(|v| v.as_f64().expect("f") as f32).collect());
        // the file's quaternion is unit to 3 digits (-0.383, 0.92375): a reader normalizes it
        let rotation = Quat::from_xyzw(r[0], r[1], r[2], r[3]).normalize();
        let primitive = &doc["meshes"][mesh as usize]["primitives"][0];
        let positions = &doc["accessors"][primitive["attributes"]["POSITION"].as_u64().expect("pos") as usize];
        let bytes = view_bytes(positions);
        let f = |k: usize| f32::from_le_bytes(bytes[4 * k..4 * k + 4].try_into().expect("4 bytes"));
        let count = positions["count"].as_u64().expect("count") as usize;
        let p: Vec<Vec3> = (0..count).map(|v| rotation * Vec3::new(f(3 * v), f(3 * v + 1), f(3 * v + 2))).collect();
        let indices: Vec<usize> = match primitive["indices"].as_u64() {
            Some(k) => {
                let a = &doc["accessors"][k as usize];
                assert_eq!(a["componentType"], 5123, "u16 indices in these files");
                let b = view_bytes(a);
                (0..a["count"].as_u64().expect("count") as usize)
                    .map(|i| u16::from_le_bytes([b[2 * i], b[2 * i + 1]]) as usize)
                    .collect()
            }
            None => (0..count).collect(),
        };
        out.extend(indices.chunks_exact(3).map(|t| [p[t[0]], p[t[1]], p[t[2]]]));
    }
    out
}

fn imported_triangles(import: &scene::import::GltfImport) -> Vec<[Vec3; 3]> {
    let mut out = Vec::new();
    for o in &import.scene.objects {
        out.extend(o.mesh.indices.iter().map(|t| t.map(|i| o.mesh.positions[i as usize])));
    }
    out
}

/// Whether two triangle lists are the same triangles, each up to a rotation of its corners (to
/// 1e-5: a rotation through a quaternion or through a matrix rounds differently in f32).
fn same_triangles(a: &[[Vec3; 3]], b: &[[Vec3; 3]]) -> bool {
    let same = |x: &[Vec3; 3], y: &[Vec3; 3]| (0..3).any(|s| (0..3).all(|k| x[k].distance(y[(k + s) % 3]) < 1e-5));
    a.len() == b.len() && a.iter().all(|t| b.iter().any(|u| same(t, u)))
}

#[test]
fn sample_models_import_as_an_independent_reading_of_them_gives() {
    // none has a material: glTF's default (metallic 1, roughness 1, one-sided) is modelled
    for (name, triangles, warnings) in [
        ("Cameras.gltf", 2, &[][..]),
        ("TriangleWithoutIndices.gltf", 1, &[][..]),
        ("AnimatedTriangle.gltf", 1, &["animations are not modelled"][..]),
    ] {
        let import = load_gltf(&model(name), &GltfOptions::default()).unwrap_or_else(|e| panic!("{e}"));
        let (ours, theirs) = (imported_triangles(&import), independent_triangles(name));
        assert_eq!(ours.len(), triangles, "{name}");
        assert!(same_triangles(&ours, &theirs), "{name}: {ours:?} != {theirs:?}");
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

#[test]
fn the_sparse_sample_is_refused_naming_what_to_do() {
    let path = model("SimpleSparseAccessor.gltf");
    let e = load_gltf(&path, &GltfOptions::default()).expect_err("sparse accessors are not read");
    assert!(matches!(&e, GltfError::Unsupported { extension, .. } if extension == "sparse accessors"), "{e}");
    let msg = e.to_string();
    assert!(
        msg.contains("SimpleSparseAccessor.gltf") && msg.contains("gltf-transform") && !msg.contains('\n'),
        "{msg}"
    );
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
