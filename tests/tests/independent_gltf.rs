//! The glTF import against an independent reading of the same files: the JSON through
//! `serde_json`, buffers from data URIs (`base64`) or beside the file, the default scene's node
//! tree with its matrices and TRS applied here, u8/u16/u32 or no indices, sparse accessors, and a ray caster of its
//! own (every triangle against every pixel's centre ray, back faces of one-sided materials
//! culled). Each public sample model in `assets/models/` gives the same
//! world-space triangles, and the depth image the reference tracer renders of the import
//! (`render --aovs`'s `OUT.depth.exr`) is the one cast here through the same camera, pixel for
//! pixel.

use glam::{Mat4, Quat, Vec3};
use serde_json::Value;
use std::path::{Path, PathBuf};

fn model(name: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../assets/models").join(name)
}

/// A triangle in world space and whether its material is double-sided.
#[derive(Clone, Copy, Debug)]
struct Triangle {
    p: [Vec3; 3],
    double_sided: bool,
}

/// The triangles of the file's default scene, read without the `gltf` crate.
fn independent_triangles(path: &Path) -> Vec<Triangle> {
    let doc: Value = serde_json::from_slice(&std::fs::read(path).expect("read")).expect("json");
    let buffers: Vec<Vec<u8>> = doc["buffers"]
        .as_array()
        .expect("buffers")
        .iter()
        .map(|b| {
            let uri = b["uri"].as_str().expect("uri");
            if uri.starts_with("data:") {
                base64::decode(&uri[uri.find(',').expect("data uri") + 1..]).expect("base64")
            } else {
                std::fs::read(path.with_file_name(uri)).expect("buffer file")
            }
        })
        .collect();
    let component = |accessor: &Value, k: usize| -> f64 {
        let view = &doc["bufferViews"][accessor["bufferView"].as_u64().expect("view") as usize];
        let bytes = &buffers[view["buffer"].as_u64().expect("buffer") as usize];
        let start = view["byteOffset"].as_u64().unwrap_or(0) + accessor["byteOffset"].as_u64().unwrap_or(0);
        let width = match accessor["componentType"].as_u64().expect("type") {
            5121 => 1,
            5123 => 2,
            5125 | 5126 => 4,
            t => panic!("component type {t}"),
        };
        let n = match accessor["type"].as_str().expect("type") {
            "SCALAR" => 1,
            "VEC3" => 3,
            t => panic!("accessor type {t}"),
        };
        let stride = view["byteStride"].as_u64().map_or(width * n, |s| s as usize);
        let at = start as usize + (k / n) * stride + (k % n) * width;
        let b = &bytes[at..at + width];
        match accessor["componentType"].as_u64().expect("type") {
            5121 => f64::from(b[0]),
            5123 => f64::from(u16::from_le_bytes([b[0], b[1]])),
            5125 => f64::from(u32::from_le_bytes([b[0], b[1], b[2], b[3]])),
            _ => f64::from(f32::from_le_bytes([b[0], b[1], b[2], b[3]])),
        }
    };
    let mut out = Vec::new();
    let mut stack: Vec<(u64, Mat4)> = doc["scenes"][doc["scene"].as_u64().unwrap_or(0) as usize]["nodes"]
        .as_array()
        .expect("nodes")
        .iter()
        .map(|n| (n.as_u64().expect("node"), Mat4::IDENTITY))
        .collect();
    while let Some((index, parent)) = stack.pop() {
        let node = &doc["nodes"][index as usize];
        let floats = |key: &str, default: &[f32]| -> Vec<f32> {
            node[key].as_array().map_or(default.to_vec(), |v| v.iter().map(|x| x.as_f64().expect("f") as f32).collect())
        };
        let local = if node["matrix"].is_array() {
            Mat4::from_cols_slice(&floats("matrix", &[]))
        } else {
            let (t, r, s) = (
                floats("translation", &[0.0; 3]),
                floats("rotation", &[0.0, 0.0, 0.0, 1.0]),
                floats("scale", &[1.0; 3]),
            );
            // files round their quaternions (-0.383, 0.92375): a reader normalizes them
            Mat4::from_scale_rotation_translation(
                Vec3::from_slice(&s),
                Quat::from_xyzw(r[0], r[1], r[2], r[3]).normalize(),
                Vec3::from_slice(&t),
            )
        };
        let world = parent * local;
        for child in node["children"].as_array().into_iter().flatten() {
            stack.push((child.as_u64().expect("child"), world));
        }
        let Some(mesh) = node["mesh"].as_u64() else { continue };
        // a mirroring transform turns counter-clockwise faces clockwise: glTF flips them back
        let mirrored = world.determinant() < 0.0;
        for primitive in doc["meshes"][mesh as usize]["primitives"].as_array().expect("primitives") {
            assert_eq!(primitive["mode"].as_u64().unwrap_or(4), 4, "triangle lists in these files");
            let positions = &doc["accessors"][primitive["attributes"]["POSITION"].as_u64().expect("pos") as usize];
            let count = positions["count"].as_u64().expect("count") as usize;
            let element = |a: &Value, v: usize| Vec3::from_array([0, 1, 2].map(|k| component(a, 3 * v + k) as f32));
            // a sparse accessor: its base (zeros without a view) with elements substituted
            let mut local: Vec<Vec3> = (0..count)
                .map(|v| if positions["bufferView"].is_null() { Vec3::ZERO } else { element(positions, v) })
                .collect();
            if let Some(sparse) = positions.get("sparse") {
                let part = |key: &str, component_type: &Value, kind: &str| {
                    let s = &sparse[key];
                    serde_json::json!({ "bufferView": s["bufferView"], "byteOffset": s["byteOffset"],
                        "componentType": component_type, "type": kind })
                };
                let indices = part("indices", &sparse["indices"]["componentType"], "SCALAR");
                let values = part("values", &positions["componentType"], "VEC3");
                for k in 0..sparse["count"].as_u64().expect("count") as usize {
                    local[component(&indices, k) as usize] = element(&values, k);
                }
            }
            let p: Vec<Vec3> = local.into_iter().map(|x| world.transform_point3(x)).collect();
            let indices: Vec<usize> = match primitive["indices"].as_u64() {
                Some(k) => {
                    let a = &doc["accessors"][k as usize];
                    (0..a["count"].as_u64().expect("count") as usize).map(|i| component(a, i) as usize).collect()
                }
                None => (0..count).collect(),
            };
            let double_sided = primitive["material"]
                .as_u64()
                .is_some_and(|m| doc["materials"][m as usize]["doubleSided"].as_bool().unwrap_or(false));
            for t in indices.chunks_exact(3) {
                let (a, b, c) = (p[t[0]], p[t[1]], p[t[2]]);
                out.push(Triangle { p: if mirrored { [a, c, b] } else { [a, b, c] }, double_sided });
            }
        }
    }
    out
}

/// The nearest hit of a ray with a front face (or either face of a double-sided triangle), by
/// Möller-Trumbore over every triangle; infinity for none.
fn cast(triangles: &[Triangle], o: Vec3, d: Vec3) -> f32 {
    let mut nearest = f32::INFINITY;
    for t in triangles {
        let (e1, e2) = (t.p[1] - t.p[0], t.p[2] - t.p[0]);
        let normal = e1.cross(e2);
        if !t.double_sided && normal.dot(d) >= 0.0 {
            continue;
        }
        let q = d.cross(e2);
        let det = e1.dot(q);
        if det.abs() < 1e-20 {
            continue;
        }
        let s = o - t.p[0];
        let u = s.dot(q) / det;
        let r = s.cross(e1);
        let v = d.dot(r) / det;
        let dist = e2.dot(r) / det;
        if u >= 0.0 && v >= 0.0 && u + v <= 1.0 && dist > 0.0 && dist < nearest {
            nearest = dist;
        }
    }
    nearest
}

fn imported_triangles(scene: &scene::Scene) -> Vec<[Vec3; 3]> {
    scene.objects.iter().flat_map(|o| o.mesh.indices.iter().map(|t| t.map(|i| o.mesh.positions[i as usize]))).collect()
}

/// Whether two triangle lists are the same triangles, each up to a rotation of its corners (to
/// 1e-5: a rotation through a quaternion or through a matrix rounds differently in f32).
fn same_triangles(a: &[[Vec3; 3]], b: &[Triangle]) -> bool {
    let same = |x: &[Vec3; 3], y: &[Vec3; 3]| (0..3).any(|s| (0..3).all(|k| x[k].distance(y[(k + s) % 3]) < 1e-5));
    a.len() == b.len() && a.iter().all(|t| b.iter().any(|u| same(t, &u.p)))
}

/// The sample models.
const READ: [&str; 5] = [
    "Cameras.gltf",
    "TriangleWithoutIndices.gltf",
    "AnimatedTriangle.gltf",
    "BoxTextured.gltf",
    "SimpleSparseAccessor.gltf",
];

#[test]
fn sample_models_import_as_an_independent_reading_of_them_gives() {
    for (name, triangles) in READ.into_iter().zip([2, 1, 1, 12, 12]) {
        let (scene, _) = scene::Scene::open(&model(name).display().to_string(), &Default::default())
            .unwrap_or_else(|e| panic!("{e}"));
        let (ours, theirs) = (imported_triangles(&scene), independent_triangles(&model(name)));
        assert_eq!(ours.len(), triangles, "{name}");
        assert!(same_triangles(&ours, &theirs), "{name}: {ours:?} != {theirs:?}");
    }
}

#[test]
fn depth_images_agree_with_an_independent_reader_and_caster() {
    let (w, h) = (160, 120);
    for name in READ {
        let options = scene::import::GltfOptions { size: (w, h), ..Default::default() };
        let (scene, _) =
            scene::Scene::open(&model(name).display().to_string(), &options).unwrap_or_else(|e| panic!("{e}"));
        let bvh = ref_tracer::SceneBvh::new(&scene);
        let settings = ref_tracer::RenderSettings { spp: 1, aovs: true, ..Default::default() };
        let black = envmap_sphere::EnvMap::constant(8, 4, Vec3::ZERO);
        let dark = ref_tracer::EnvLight::new(&black);
        let direct = ref_tracer::Integrator::EnvDirect(ref_tracer::Strategy::Mis);
        let ours = ref_tracer::render(&scene, &bvh, Some(&dark), &direct, &settings, &|_, _| {});
        let triangles = independent_triangles(&model(name));
        let (mut hits, mut disagree) = (0, 0);
        for (pixel, &depth) in ours.depth.iter().enumerate() {
            let (x, y) = ((pixel as u32 % w) as f32 + 0.5, (pixel as u32 / w) as f32 + 0.5);
            let (o, d) = scene.camera.ray(x, y);
            let theirs = cast(&triangles, o, d);
            hits += usize::from(theirs.is_finite());
            let agree = match (depth.is_finite(), theirs.is_finite()) {
                (true, true) => (depth - theirs).abs() <= 1e-4 * theirs.max(1.0),
                (a, b) => a == b,
            };
            disagree += usize::from(!agree);
        }
        // every model covers part of the image: an empty image would agree vacuously
        assert!(hits > (w * h) as usize / 100, "{name}: {hits} pixels hit");
        // a centre ray through a shared edge may find either triangle (same depth) or, where
        // rounding opens a crack of one ulp, neither: at most a few pixels of an edge
        assert!(disagree <= 2, "{name}: {disagree} of {} pixels disagree ({hits} hit)", w * h);
    }
}
