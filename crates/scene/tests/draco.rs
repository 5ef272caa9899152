//! `KHR_draco_mesh_compression` through `draco-gltf`: a built-in scene written as GLB,
//! compressed by `draco-gltf`'s encoder (14-bit positions, 10-bit normals), imports as the
//! uncompressed file does, every triangle within the quantization step; damaged streams are
//! refused in one line naming the file, never a panic.

use draco_gltf::{CompressionOptions, MeshIndex, OutputFormat, QuantizationBits};
use glam::Vec3;
use scene::import::{GltfImport, GltfOptions, load_gltf_from_bytes};
use std::path::Path;

/// `scene` as GLB, uncompressed and with every primitive Draco-compressed (Draco only).
fn both(name: &str) -> (Vec<u8>, Vec<u8>) {
    let (doc, bin) = scene::Scene::builtin(name).expect("built-in").to_gltf(None);
    let raw = scene::glb_bytes(&serde_json::to_vec(&doc).expect("json"), &bin).expect("glb");
    let mut import = draco_gltf::import_slice(&raw, None).expect("draco-gltf reads the export");
    let meshes = import.document().meshes().len();
    let options = CompressionOptions {
        quantization: QuantizationBits {
            position: Some(14),
            normal: Some(10),
            tex_coord: Some(12),
            color: None,
            generic: None,
        },
        ..CompressionOptions::default()
    };
    for m in 0..meshes {
        let primitives = import.document().mesh(MeshIndex(m)).map_or(0, |x| x.primitive_count());
        for p in 0..primitives {
            import.compress_primitive(MeshIndex(m), p, options).expect("compress");
        }
    }
    (raw, import.to_bytes(OutputFormat::GlbV2).expect("write"))
}

fn load(bytes: &[u8], path: &str) -> GltfImport {
    load_gltf_from_bytes(bytes, Path::new(path), &GltfOptions::default()).unwrap_or_else(|e| panic!("{e}"))
}

#[test]
fn draco_primitives_import_as_the_uncompressed_file_within_the_quantization() {
    for name in ["column", "three_boxes"] {
        let (raw, draco) = both(name);
        let text = String::from_utf8_lossy(&draco);
        assert!(text.contains("\"extensionsRequired\":[\"KHR_draco_mesh_compression\"]"), "{name}: not required");
        assert!(draco.len() < raw.len(), "{name}: {} bytes compressed, {} raw", draco.len(), raw.len());
        let (a, b) = (load(&raw, "raw.glb"), load(&draco, "draco.glb"));
        assert!(b.warnings.is_empty(), "{name}: {:?}", b.warnings);
        assert_eq!(a.scene.objects.len(), b.scene.objects.len(), "{name}");
        for (x, y) in a.scene.objects.iter().zip(&b.scene.objects) {
            assert_eq!(x.mesh.indices.len(), y.mesh.indices.len(), "{name}: {}", x.name);
            assert_eq!(x.material, y.material, "{name}: {}", x.name);
            let (lo, hi) =
                x.mesh.positions.iter().fold((Vec3::INFINITY, Vec3::NEG_INFINITY), |(l, h), &p| (l.min(p), h.max(p)));
            // 14 bits over the largest side, and a little for the dequantization's rounding
            let step = (hi - lo).max_element() / f32::from(1u16 << 14) * 1.01;
            let corners = |m: &scene::Mesh, t: &[u32; 3]| t.map(|i| m.positions[i as usize]);
            let ys: Vec<[Vec3; 3]> = y.mesh.indices.iter().map(|t| corners(&y.mesh, t)).collect();
            for t in &x.mesh.indices {
                let want = corners(&x.mesh, t);
                // the same triangle up to a rotation of its corners (Draco reorders vertices)
                let found =
                    ys.iter().any(|g| (0..3).any(|r| (0..3).all(|k| want[k].distance(g[(k + r) % 3]) <= step * 1.8)));
                assert!(found, "{name}: {}: triangle {want:?} not decoded", x.name);
            }
            assert_eq!(x.mesh.normals.is_some(), y.mesh.normals.is_some(), "{name}: {}: normals", x.name);
            for n in y.mesh.normals.iter().flatten() {
                assert!((n.length() - 1.0).abs() < 1e-3, "{name}: {}: normal {n}", x.name);
            }
        }
    }
}

#[test]
fn damaged_draco_streams_are_refused_in_one_line() {
    let (_, draco) = both("column");
    // the BIN chunk (after the 12-byte header, the JSON chunk's 8 + length, its own 8)
    let json_len = u32::from_le_bytes(draco[12..16].try_into().expect("glb")) as usize;
    let bin = 20 + json_len + 8;
    let mut state = 0x243f_6a88_85a3_08d3u64;
    let mut next = |n: usize| {
        state ^= state << 13;
        state ^= state >> 7;
        state ^= state << 17;
        (state % n as u64) as usize
    };
    let mut refused = 0;
    for _ in 0..300 {
        let mut m = draco.clone();
        for _ in 0..1 + next(6) {
            let k = bin + next(m.len() - bin);
            m[k] = next(256) as u8;
        }
        if let Err(e) = load_gltf_from_bytes(&m, Path::new("damaged.glb"), &GltfOptions::default()) {
            let msg = e.to_string();
            assert!(msg.contains("damaged.glb") && !msg.contains('\n'), "{msg}");
            refused += 1;
        }
    }
    assert!(refused > 30, "only {refused} of 300 damaged streams refused");
}
