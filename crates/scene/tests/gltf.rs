//! glTF import against files written here, byte by byte, where the answer is known: a cube at a
//! known node hierarchy, strips and fans, `.glb` against `.gltf`, cameras, the ground, and every
//! kind of bad file, each an error naming the file and never a panic.

use glam::{Mat4, Quat, Vec3};
use scene::import::{GltfError, GltfOptions, load_gltf};
use std::path::{Path, PathBuf};

fn dir(name: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("envshadow-gltf-{}-{name}", std::process::id()));
    std::fs::create_dir_all(&d).expect("temp dir");
    d
}

/// Little-endian bytes of `positions` (f32 VEC3) then `indices` (u16, padded to 4).
fn bin(positions: &[Vec3], indices: &[u16]) -> Vec<u8> {
    let mut b: Vec<u8> = positions.iter().flat_map(|p| p.to_array()).flat_map(f32::to_le_bytes).collect();
    b.extend(indices.iter().flat_map(|i| i.to_le_bytes()));
    while !b.len().is_multiple_of(4) {
        b.push(0);
    }
    b
}

/// A document with one mesh of one primitive (`mode`, indexed), its buffer at `uri` (or the GLB
/// chunk when `None`), the mesh on `mesh_node`, and `nodes`/`extra` as given.
fn document(positions: &[Vec3], indices: &[u16], mode: u32, uri: Option<&str>, nodes: &str, extra: &str) -> String {
    let n = positions.len();
    let pos_bytes = n * 12;
    let idx_bytes = indices.len() * 2;
    let total = bin(positions, indices).len();
    let (lo, hi) = positions.iter().fold((Vec3::INFINITY, Vec3::NEG_INFINITY), |(l, h), p| (l.min(*p), h.max(*p)));
    let uri = uri.map_or_else(String::new, |u| format!(r#""uri": "{u}", "#));
    format!(
        r#"{{
  "asset": {{"version": "2.0"}},
  "scene": 0,
  "scenes": [{{"nodes": [0]}}],
  "nodes": {nodes},
  "meshes": [{{"name": "m", "primitives": [{{"attributes": {{"POSITION": 0}}, "indices": 1, "mode": {mode}}}]}}],
  "buffers": [{{{uri}"byteLength": {total}}}],
  "bufferViews": [
    {{"buffer": 0, "byteOffset": 0, "byteLength": {pos_bytes}}},
    {{"buffer": 0, "byteOffset": {pos_bytes}, "byteLength": {idx_bytes}}}
  ],
  "accessors": [
    {{"bufferView": 0, "componentType": 5126, "count": {n}, "type": "VEC3",
      "min": [{}, {}, {}], "max": [{}, {}, {}]}},
    {{"bufferView": 1, "componentType": 5123, "count": {}, "type": "SCALAR"}}
  ]{extra}
}}"#,
        lo.x,
        lo.y,
        lo.z,
        hi.x,
        hi.y,
        hi.z,
        indices.len()
    )
}

/// `.gltf` + `.bin` in `d`.
fn write_gltf(d: &Path, name: &str, json: &str, bin: &[u8]) -> PathBuf {
    std::fs::write(d.join(format!("{name}.bin")), bin).expect("write bin");
    let p = d.join(format!("{name}.gltf"));
    std::fs::write(&p, json).expect("write gltf");
    p
}

/// A GLB of `json` and `bin`, through the writer the export uses.
fn glb(json: &str, bin: &[u8]) -> Vec<u8> {
    scene::glb_bytes(json.as_bytes(), bin).expect("under 4 GiB")
}

fn cube() -> (Vec<Vec3>, Vec<u16>) {
    let p: Vec<Vec3> =
        (0..8).map(|i| Vec3::new((i & 1) as f32, ((i >> 1) & 1) as f32, ((i >> 2) & 1) as f32)).collect();
    // each face as two triangles, counter-clockwise seen from outside
    let faces: [[u16; 4]; 6] = [[0, 2, 3, 1], [4, 5, 7, 6], [0, 1, 5, 4], [2, 6, 7, 3], [0, 4, 6, 2], [1, 3, 7, 5]];
    let idx = faces.iter().flat_map(|f| [f[0], f[1], f[2], f[0], f[2], f[3]]).collect();
    (p, idx)
}

const TWO_NODES: &str = r#"[
    {"translation": [1, 2, 3], "children": [1]},
    {"mesh": 0, "scale": [2, 2, 2], "rotation": [0, 0.70710678, 0, 0.70710678]}
  ]"#;

#[test]
fn a_cube_lands_where_its_node_hierarchy_puts_it() {
    let d = dir("cube");
    let (p, idx) = cube();
    let path = write_gltf(&d, "cube", &document(&p, &idx, 4, Some("cube.bin"), TWO_NODES, ""), &bin(&p, &idx));
    let import = load_gltf(&path, &GltfOptions::default()).expect("imports");
    let s = &import.scene;
    assert_eq!(s.objects.len(), 1);
    assert_eq!(s.objects[0].mesh.indices.len(), 12);
    assert_eq!(import.degenerate, 0);
    let world = Mat4::from_translation(Vec3::new(1.0, 2.0, 3.0))
        * Mat4::from_scale_rotation_translation(
            Vec3::splat(2.0),
            Quat::from_rotation_y(90f32.to_radians()),
            Vec3::ZERO,
        );
    for (got, local) in s.objects[0].mesh.positions.iter().zip(&p) {
        let want = world.transform_point3(*local);
        assert!((*got - want).length() < 1e-5, "{local} -> {got}, want {want}");
    }
    // outward winding kept: every face normal points away from the cube's centre
    let centre = world.transform_point3(Vec3::splat(0.5));
    let m = &s.objects[0].mesh;
    for t in &m.indices {
        let [a, b, c] = t.map(|i| m.positions[i as usize]);
        assert!((b - a).cross(c - a).dot((a + b + c) / 3.0 - centre) > 0.0, "{t:?} winds inwards");
    }
    m.validate().expect("a valid mesh");
    // glTF's default material: base colour 1, metallic 1, roughness 1 (a rough white metal)
    let m = s.objects[0].material;
    assert_eq!(m.albedo, Vec3::ZERO, "a metal has no diffuse lobe");
    assert_eq!(m.specular, Some(scene::Ggx { roughness: 1.0, f0: Vec3::ONE }), "glTF's default material");
    assert!(!m.double_sided, "glTF's default: one-sided");
}

#[test]
fn glb_and_gltf_of_one_document_import_alike() {
    let d = dir("glb");
    let (p, idx) = cube();
    let b = bin(&p, &idx);
    let a = load_gltf(
        &write_gltf(&d, "c", &document(&p, &idx, 4, Some("c.bin"), TWO_NODES, ""), &b),
        &GltfOptions::default(),
    )
    .expect("gltf");
    let glb_path = d.join("c.glb");
    std::fs::write(&glb_path, glb(&document(&p, &idx, 4, None, TWO_NODES, ""), &b)).expect("write glb");
    let g = load_gltf(&glb_path, &GltfOptions::default()).expect("glb");
    assert_eq!(a.scene.objects, g.scene.objects);
    assert_eq!(a.scene.camera, g.scene.camera);
}

#[test]
fn strips_and_fans_become_outward_triangles_and_degenerates_are_dropped() {
    let d = dir("strip");
    let quad = [Vec3::ZERO, Vec3::X, Vec3::Y, Vec3::new(1.0, 1.0, 0.0)];
    let nodes = r#"[{"mesh": 0}]"#;
    // strip 0 1 2 3: triangles (0 1 2), (2 1 3) -> both facing +z
    let strip = load_gltf(
        &write_gltf(&d, "s", &document(&quad, &[0, 1, 2, 3], 5, Some("s.bin"), nodes, ""), &bin(&quad, &[0, 1, 2, 3])),
        &GltfOptions::default(),
    )
    .expect("strip");
    // fan 0 1 3 2: (0 1 3), (0 3 2)
    let fan = load_gltf(
        &write_gltf(&d, "f", &document(&quad, &[0, 1, 3, 2], 6, Some("f.bin"), nodes, ""), &bin(&quad, &[0, 1, 3, 2])),
        &GltfOptions::default(),
    )
    .expect("fan");
    for s in [&strip.scene, &fan.scene] {
        let m = &s.objects[0].mesh;
        assert_eq!(m.indices.len(), 2);
        for t in &m.indices {
            let [a, b, c] = t.map(|i| m.positions[i as usize]);
            assert!((b - a).cross(c - a).z > 0.0, "{t:?} faces -z");
        }
    }
    // a triangle list with one repeated index and one of zero area: both dropped, counted
    let idx = [0, 1, 2, 0, 0, 1, 0, 1, 4, 1, 3, 2];
    let mut line = quad.to_vec();
    line.push(Vec3::new(2.0, 0.0, 0.0));
    let deg = load_gltf(
        &write_gltf(&d, "d", &document(&line, &idx, 4, Some("d.bin"), nodes, ""), &bin(&line, &idx)),
        &GltfOptions::default(),
    )
    .expect("degenerates");
    assert_eq!((deg.scene.objects[0].mesh.indices.len(), deg.degenerate), (2, 2));
}

#[test]
fn the_files_camera_or_one_that_frames_the_model_and_a_ground_under_it() {
    let d = dir("camera");
    let (p, idx) = cube();
    let nodes = r#"[{"mesh": 0, "children": [1]}, {"camera": 0, "translation": [0.5, 0.5, 5]}]"#;
    let extra = r#",
  "cameras": [{"type": "perspective", "perspective": {"yfov": 0.5, "znear": 0.1}}]"#;
    let opts = GltfOptions { size: (200, 100), ground: Some(0.5), ..GltfOptions::default() };
    let s = load_gltf(&write_gltf(&d, "c", &document(&p, &idx, 4, Some("c.bin"), nodes, extra), &bin(&p, &idx)), &opts)
        .expect("camera")
        .scene;
    assert!((s.camera.eye - Vec3::new(0.5, 0.5, 5.0)).length() < 1e-6);
    assert!((s.camera.target - s.camera.eye).normalize().abs_diff_eq(Vec3::NEG_Z, 1e-6));
    let want_hfov = 2.0 * ((0.25f32).tan() * 2.0).atan();
    assert!((s.camera.hfov_degrees - want_hfov.to_degrees()).abs() < 1e-4, "{}", s.camera.hfov_degrees);
    let ground = s.object("ground").expect("a ground");
    assert!(ground.mesh.positions.iter().all(|q| q.y == 0.0), "the ground lies at the lowest point");
    assert_eq!(ground.material.albedo, Vec3::splat(0.5));
    // without a camera: every vertex of the model inside the frame
    let s = load_gltf(
        &write_gltf(&d, "n", &document(&p, &idx, 4, Some("n.bin"), r#"[{"mesh": 0}]"#, ""), &bin(&p, &idx)),
        &opts,
    )
    .expect("no camera")
    .scene;
    let (right, up, forward) = s.camera.basis();
    let half_w = (s.camera.hfov_degrees.to_radians() * 0.5).tan();
    let half_h = half_w * 100.0 / 200.0;
    for q in &p {
        let v = *q - s.camera.eye;
        let z = v.dot(forward);
        assert!(z > 0.0 && (v.dot(right) / z).abs() < half_w && (v.dot(up) / z).abs() < half_h, "{q} outside");
    }
}

/// Asserts `path` fails with a one-line message naming it.
fn refused(path: &Path) -> GltfError {
    let e = load_gltf(path, &GltfOptions::default()).expect_err("refused");
    let msg = e.to_string();
    assert!(msg.contains(&path.display().to_string()) && !msg.contains('\n'), "{msg}");
    e
}

#[test]
fn bad_files_are_errors_naming_the_file() {
    let d = dir("bad");
    let (p, idx) = cube();
    let b = bin(&p, &idx);
    std::fs::write(d.join("x.bin"), &b).expect("write x.bin");
    let doc = |extra: &str| document(&p, &idx, 4, Some("x.bin"), r#"[{"mesh": 0}]"#, extra);
    let html = d.join("page.glb");
    std::fs::write(&html, "<!DOCTYPE html><html><body>Not found</body></html>").expect("write");
    assert!(matches!(refused(&html), GltfError::Invalid { .. }));
    let full = glb(&document(&p, &idx, 4, None, r#"[{"mesh": 0}]"#, ""), &b);
    let truncated = d.join("truncated.glb");
    std::fs::write(&truncated, &full[..full.len() - 40]).expect("write");
    refused(&truncated);
    let missing = d.join("missing.gltf");
    std::fs::write(&missing, doc("").replace("x.bin", "nowhere.bin")).expect("write");
    assert!(refused(&missing).to_string().contains("nowhere.bin"));
    // an accessor that claims more vertices than its view holds
    let long = write_gltf(&d, "long", &doc("").replacen(r#""count": 8"#, r#""count": 4000000000"#, 1), &b);
    assert!(matches!(refused(&long), GltfError::Malformed { .. }));
    // an index past the vertex count
    let mut bad_idx = idx.clone();
    bad_idx[5] = 99;
    let past = write_gltf(
        &d,
        "past",
        &document(&p, &bad_idx, 4, Some("past.bin"), r#"[{"mesh": 0}]"#, ""),
        &bin(&p, &bad_idx),
    );
    assert!(refused(&past).to_string().contains("index 99"));
    // a non-finite position
    let mut nan = p.clone();
    nan[3].y = f32::NAN;
    let nan_path = write_gltf(
        &d,
        "nan",
        &document(&nan, &idx, 4, Some("nan.bin"), r#"[{"mesh": 0}]"#, "").replace("NaN", "0"),
        &bin(&nan, &idx),
    );
    assert!(refused(&nan_path).to_string().contains("not finite"));
    // points only: nothing to draw
    let points = write_gltf(&d, "points", &document(&p, &idx, 0, Some("points.bin"), r#"[{"mesh": 0}]"#, ""), &b);
    assert!(matches!(refused(&points), GltfError::NoTriangles { .. }));
    // compressed geometry: meshopt is refused; Draco is decoded (`tests/draco.rs`), and a file
    // that requires it without a Draco primitive reads as it is
    let requiring = |name: &str, ext: &str| {
        let extra = format!(r#", "extensionsUsed": ["{ext}"], "extensionsRequired": ["{ext}"]"#);
        write_gltf(&d, name, &doc(&extra).replace("x.bin", &format!("{name}.bin")), &b)
    };
    let meshopt = requiring("meshopt", "EXT_meshopt_compression");
    assert!(
        matches!(refused(&meshopt), GltfError::Unsupported { extension, .. } if extension == "EXT_meshopt_compression")
    );
    let draco = requiring("draco", "KHR_draco_mesh_compression");
    let plain = load_gltf(&draco, &GltfOptions::default()).unwrap_or_else(|e| panic!("{e}"));
    assert!(plain.warnings.is_empty() && !plain.scene.objects.is_empty(), "{:?}", plain.warnings);
    // what the gltf crate itself panics on (found by `cargo xtask fuzz`): a GLB header whose
    // length is under its own 12 bytes, a POSITION past the accessors
    let mut short = full.clone();
    short[8..12].copy_from_slice(&8u32.to_le_bytes());
    let short_path = d.join("short.glb");
    std::fs::write(&short_path, &short).expect("write");
    assert!(refused(&short_path).to_string().contains("under the header's own 12"));
    let position = write_gltf(&d, "position", &doc("").replace(r#""POSITION": 0"#, r#""POSITION": 99"#), &b);
    assert!(refused(&position).to_string().contains("POSITION is accessor 99"));
    // the same behind a field the reader ignores without parsing its number (nor its UTF-8)
    let hidden = doc(r#", "unknown": [1e309, "\u00ff"]"#).replace(r#""POSITION": 0"#, r#""POSITION": 99"#);
    let hidden = write_gltf(&d, "hidden", &hidden.replace("x.bin", "hidden.bin"), &b);
    assert!(refused(&hidden).to_string().contains("POSITION is accessor 99"));
    // an empty accessor that starts past its view
    let empty = doc("").replace(
        &format!(r#""componentType": 5123, "count": {}"#, idx.len()),
        r#""componentType": 5123, "count": 0, "byteOffset": 4000"#,
    );
    assert!(empty.contains("\"byteOffset\": 4000"));
    let empty = write_gltf(&d, "empty", &empty.replace("x.bin", "empty.bin"), &b);
    assert!(refused(&empty).to_string().contains("runs past"));
    // more triangles than the limit: refused before the indices are read
    let path = write_gltf(&d, "x", &doc(""), &b);
    let e = load_gltf(&path, &GltfOptions { max_triangles: 11, ..GltfOptions::default() }).expect_err("over the limit");
    assert!(e.to_string().contains("more than 11 triangles"), "{e}");
}

#[test]
fn is_model_tells_model_paths_from_builtin_names() {
    assert!(!scene::is_model("spheres_box") && !scene::is_model("nowhere"));
    assert!(scene::is_model("nowhere.glb") && scene::is_model("a/b.GLTF"));
    let d = dir("is-model");
    let file = d.join("model");
    std::fs::write(&file, "{}").expect("write");
    assert!(scene::is_model(file.to_str().unwrap_or_default()), "an existing file is a model, whatever its name");
}
