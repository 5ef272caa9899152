//! glTF 2.0 export: the scene as a `.gltf` (with its `.bin` beside it) or a `.glb` any glTF
//! viewer opens, and that [`crate::import`] reads back into an equal scene.
//!
//! One node and one mesh per object, in the scene's order, positions in world space (no node
//! transforms), vertex normals where the object shades with them; the albedo as the base colour
//! (metallic 0), the emission, `doubleSided` (textures are not written: a textured object
//! goes out with its factors); the camera as a perspective camera on its own node; point lights as
//! `KHR_lights_punctual` point lights. What glTF cannot say exactly rides in `extras.envshadow`,
//! read back only where it agrees with the standard data (so a file edited elsewhere is read
//! by its standard fields): a GGX layer's roughness and F0, the camera's exact eye, target, up
//! and horizontal field of view, a light's per-channel intensity and radius.

use crate::{Scene, SceneError};
use glam::Vec3;
use serde_json::{Value, json};
use std::path::Path;

/// The key under `extras` holding what glTF cannot say exactly.
pub(crate) const EXTRAS_KEY: &str = "envshadow";

/// `f` as a JSON number, written as its shortest exact decimal (`0.7`, not `0.699999988…`).
fn num(f: f32) -> Value {
    Value::from(f.to_string().parse::<f64>().unwrap_or(0.0))
}

fn vec3(v: Vec3) -> Value {
    Value::Array(vec![num(v.x), num(v.y), num(v.z)])
}

impl Scene {
    /// The scene as a glTF document and its binary buffer, the buffer referred to as `bin_uri`
    /// (`None`: the GLB's own chunk).
    #[must_use]
    pub fn to_gltf(&self, bin_uri: Option<&str>) -> (Value, Vec<u8>) {
        let mut bin: Vec<u8> = Vec::new();
        let (mut views, mut accessors, mut meshes, mut materials, mut nodes) =
            (Vec::new(), Vec::new(), Vec::new(), Vec::new(), Vec::new());
        let mut view = |bin: &mut Vec<u8>, bytes: &[u8], target: u32| {
            views.push(json!({"buffer": 0, "byteOffset": bin.len(), "byteLength": bytes.len(), "target": target}));
            bin.extend_from_slice(bytes);
            views.len() - 1
        };
        for (k, o) in self.objects.iter().enumerate() {
            let m = &o.mesh;
            let (mut lo, mut hi) = (Vec3::splat(f32::INFINITY), Vec3::splat(f32::NEG_INFINITY));
            for p in &m.positions {
                lo = lo.min(*p);
                hi = hi.max(*p);
            }
            let floats =
                |v: &[Vec3]| -> Vec<u8> { v.iter().flat_map(|p| p.to_array()).flat_map(f32::to_le_bytes).collect() };
            let pv = view(&mut bin, &floats(&m.positions), 34962);
            accessors.push(json!({"bufferView": pv, "componentType": 5126, "count": m.positions.len(), "type": "VEC3",
                "min": vec3(lo), "max": vec3(hi)}));
            let mut attributes = json!({"POSITION": accessors.len() - 1});
            if let Some(normals) = &m.normals {
                let nv = view(&mut bin, &floats(normals), 34962);
                accessors
                    .push(json!({"bufferView": nv, "componentType": 5126, "count": normals.len(), "type": "VEC3"}));
                attributes["NORMAL"] = json!(accessors.len() - 1);
            }
            let indices: Vec<u8> = m.indices.iter().flatten().flat_map(|i| i.to_le_bytes()).collect();
            let iv = view(&mut bin, &indices, 34963);
            accessors
                .push(json!({"bufferView": iv, "componentType": 5125, "count": m.indices.len() * 3, "type": "SCALAR"}));
            let a = o.material.albedo;
            let mut material = json!({"name": o.name, "pbrMetallicRoughness": {
                "baseColorFactor": [num(a.x), num(a.y), num(a.z), 1.0], "metallicFactor": 0.0,
                "roughnessFactor": num(o.material.specular.map_or(1.0, |g| g.roughness))},
                "doubleSided": o.material.double_sided});
            material["extras"] = match o.material.specular {
                Some(g) => json!({EXTRAS_KEY: {"ggx": {"roughness": num(g.roughness), "f0": vec3(g.f0)}}}),
                None => json!({EXTRAS_KEY: {"lambert": true}}),
            };
            let e = o.material.emission;
            if e != Vec3::ZERO {
                // glTF's factor stops at 1; the strength extension carries the rest
                let peak = e.max_element();
                material["emissiveFactor"] = vec3(e / peak.max(1.0));
                if peak > 1.0 {
                    material["extensions"] =
                        json!({"KHR_materials_emissive_strength": {"emissiveStrength": num(peak)}});
                }
            }
            materials.push(material);
            meshes
                .push(json!({"name": o.name, "primitives": [{"attributes": attributes, "indices": accessors.len() - 1,
                "material": k, "mode": 4}]}));
            nodes.push(json!({"name": o.name, "mesh": k}));
        }
        let c = &self.camera;
        let (right, up, forward) = c.basis();
        let aspect = c.width as f32 / c.height.max(1) as f32;
        let yfov = 2.0 * ((c.hfov_degrees.to_radians() * 0.5).tan() / aspect).atan();
        let back = -forward;
        nodes.push(json!({"name": "camera", "camera": 0, "matrix": [
            num(right.x), num(right.y), num(right.z), 0.0, num(up.x), num(up.y), num(up.z), 0.0,
            num(back.x), num(back.y), num(back.z), 0.0, num(c.eye.x), num(c.eye.y), num(c.eye.z), 1.0]}));
        let cameras = json!([{"type": "perspective", "perspective": {"yfov": num(yfov), "aspectRatio": num(aspect),
            "znear": 0.001}, "extras": {EXTRAS_KEY: {"eye": vec3(c.eye), "target": vec3(c.target), "up": vec3(c.up),
            "hfov_degrees": num(c.hfov_degrees)}}}]);
        let mut lights = Vec::new();
        for (k, l) in self.point_lights.iter().enumerate() {
            let peak = l.intensity.max_element();
            let colour = if peak > 0.0 { l.intensity / peak } else { Vec3::ONE };
            lights.push(json!({"type": "point", "color": vec3(colour), "intensity": num(peak.max(0.0)),
                "extras": {EXTRAS_KEY: {"intensity": vec3(l.intensity), "radius": num(l.radius)}}}));
            nodes.push(json!({"name": format!("light {k}"), "translation": vec3(l.position),
                "extensions": {"KHR_lights_punctual": {"light": k}}}));
        }
        let mut buffer = json!({"byteLength": bin.len()});
        if let Some(uri) = bin_uri {
            buffer["uri"] = json!(uri);
        }
        let mut doc = json!({
            "asset": {"version": "2.0", "generator": "envshadow"},
            "scene": 0,
            "scenes": [{"name": self.name, "nodes": (0..nodes.len()).collect::<Vec<_>>()}],
            "nodes": nodes, "meshes": meshes, "materials": materials, "cameras": cameras,
            "accessors": accessors, "bufferViews": views, "buffers": [buffer],
        });
        let mut used = Vec::new();
        if self.objects.iter().any(|o| o.material.emission.max_element() > 1.0) {
            used.push("KHR_materials_emissive_strength");
        }
        if !lights.is_empty() {
            used.push("KHR_lights_punctual");
            doc["extensions"] = json!({"KHR_lights_punctual": {"lights": lights}});
        }
        if !used.is_empty() {
            doc["extensionsUsed"] = json!(used);
        }
        (doc, bin)
    }

    /// Writes the scene as glTF: a `.glb` when `path` ends so, else a `.gltf` with its buffer
    /// in a `.bin` of the same stem beside it.
    ///
    /// # Errors
    /// [`SceneError::Io`] naming the file.
    pub fn write_gltf(&self, path: &Path) -> Result<(), SceneError> {
        let io = |path: &Path| {
            let path = path.to_path_buf();
            move |source| SceneError::Io { path, source }
        };
        let glb = path.extension().is_some_and(|e| e.eq_ignore_ascii_case("glb"));
        if glb {
            let (doc, bin) = self.to_gltf(None);
            let bytes = glb_bytes(&serde_json::to_vec(&doc).unwrap_or_default(), &bin)
                .ok_or_else(|| io(path)(std::io::Error::other("more than the 4 GiB a .glb can hold; write a .gltf")))?;
            return std::fs::write(path, bytes).map_err(io(path));
        }
        let stem = path.file_stem().map_or_else(|| "scene".into(), |s| s.to_string_lossy().into_owned());
        let bin_path = path.with_file_name(format!("{stem}.bin"));
        let (doc, bin) = self.to_gltf(Some(&format!("{stem}.bin")));
        std::fs::write(&bin_path, bin).map_err(io(&bin_path))?;
        let text = serde_json::to_string_pretty(&doc).unwrap_or_default();
        std::fs::write(path, text).map_err(io(path))
    }
}

/// A GLB container around `json` and `bin`: the 12-byte header, the JSON chunk padded with
/// spaces, the BIN chunk padded with zeros (both to 4 bytes, as the format asks); `None` past the
/// format's 4 GiB. The bytes need not be valid (a fuzzer wraps damaged JSON in a sound container).
#[must_use]
pub fn glb_bytes(json: &[u8], bin: &[u8]) -> Option<Vec<u8>> {
    let (json_len, bin_len) = (json.len().next_multiple_of(4), bin.len().next_multiple_of(4));
    let total = 12 + 8 + json_len + 8 + bin_len;
    u32::try_from(total).ok()?;
    let u32le = |n: usize| u32::try_from(n).unwrap_or(u32::MAX).to_le_bytes();
    let mut out = Vec::with_capacity(total);
    out.extend_from_slice(b"glTF");
    out.extend_from_slice(&2u32.to_le_bytes());
    out.extend_from_slice(&u32le(total));
    out.extend_from_slice(&u32le(json_len));
    out.extend_from_slice(b"JSON");
    out.extend_from_slice(json);
    out.resize(20 + json_len, b' ');
    out.extend_from_slice(&u32le(bin_len));
    out.extend_from_slice(b"BIN\0");
    out.extend_from_slice(bin);
    out.resize(total, 0);
    Some(out)
}
