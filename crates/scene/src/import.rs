//! glTF 2.0 import (`.gltf` with external or embedded buffers, `.glb`) through the `gltf` crate,
//! into the [`Scene`] every renderer here draws: the default scene's node hierarchy (TRS and
//! matrix transforms), every triangle primitive (strips and fans converted; points and lines
//! skipped and counted), u8/u16/u32 indices, normals where the file has them (flat shading
//! otherwise), the base colour factor as the albedo, the first perspective camera (else one that
//! frames the model) and `KHR_lights_punctual` point lights; what [`Scene::write_gltf`] adds in
//! `extras` (GGX layers, the exact camera and lights) where it agrees with the standard data.
//!
//! Every accessor is checked against its buffer view and buffer before it is read, so a file
//! that lies about its sizes is an error, not a panic, and nothing is allocated past
//! [`GltfOptions::max_triangles`]. What the file holds that is not modelled is listed in
//! [`GltfImport::warnings`], once per kind.

use crate::{Camera, Ggx, Material, Mesh, Object, PointLight, Scene};
use glam::{Affine3A, Mat4, Vec3};
use gltf::accessor::{DataType, Dimensions};
use gltf::mesh::Mode;
use serde_json::Value;
use std::collections::BTreeSet;
use std::path::{Path, PathBuf};

/// Files larger than this are refused before they are read (4 GiB).
pub const MAX_FILE_BYTES: u64 = 4 << 30;

/// Why a glTF file could not be imported; each message names the file.
#[derive(Debug, thiserror::Error)]
pub enum GltfError {
    /// The file could not be read.
    #[error("{path}: {source}")]
    Io {
        /// The file.
        path: PathBuf,
        /// Why.
        source: std::io::Error,
    },
    /// Not a glTF 2.0 file, or one the `gltf` crate rejects (truncated, invalid JSON, a missing
    /// buffer file).
    #[error("{path}: not a readable glTF 2.0 file: {reason}")]
    Invalid {
        /// The file.
        path: PathBuf,
        /// The reader's reason.
        reason: String,
    },
    /// A file whose sizes or values cannot be right.
    #[error("{path}: {reason}")]
    Malformed {
        /// The file.
        path: PathBuf,
        /// What is wrong, naming the mesh, primitive or accessor.
        reason: String,
    },
    /// A file that needs an extension this reader does not decode.
    #[error("{path}: uses {extension}, which is not supported; {hint}")]
    Unsupported {
        /// The file.
        path: PathBuf,
        /// The extension.
        extension: String,
        /// What to do instead.
        hint: &'static str,
    },
    /// A file without a triangle to draw.
    #[error("{path}: no triangles (after dropping {degenerate} degenerate ones)")]
    NoTriangles {
        /// The file.
        path: PathBuf,
        /// Degenerate triangles dropped.
        degenerate: usize,
    },
}

/// How to import.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct GltfOptions {
    /// Image size of the scene's camera.
    pub size: (u32, u32),
    /// The file's camera to use (`None`: the first perspective one, else a framing camera).
    pub camera_index: Option<usize>,
    /// A Lambertian ground plane of this albedo under the model's lowest point.
    pub ground: Option<f32>,
    /// Triangles refused beyond (before their indices are allocated).
    pub max_triangles: usize,
}

impl Default for GltfOptions {
    /// 640 × 480, the file's first camera, no ground, up to 50 million triangles.
    fn default() -> Self {
        Self { size: (640, 480), camera_index: None, ground: None, max_triangles: 50_000_000 }
    }
}

/// An imported file: its scene and what the import left out.
#[derive(Clone, Debug)]
pub struct GltfImport {
    /// The scene, one object per primitive, named after its node (else its mesh), with
    /// `/k` for primitive k of a mesh of several, made unique with ` #2`, ` #3` …
    pub scene: Scene,
    /// What the file holds that is not modelled, one line per kind.
    pub warnings: Vec<String>,
    /// Degenerate triangles dropped (zero area or repeated indices).
    pub degenerate: usize,
    /// Point and line primitives skipped.
    pub skipped_primitives: usize,
}

/// Extensions whose data cannot be read without decoding.
const COMPRESSION: [&str; 2] = ["KHR_draco_mesh_compression", "EXT_meshopt_compression"];

/// Imports `path` (`.gltf` or `.glb`).
///
/// # Errors
/// An unreadable, invalid or malformed file, compressed geometry, or no triangles.
pub fn load_gltf(path: &Path, options: &GltfOptions) -> Result<GltfImport, GltfError> {
    let io = |source| GltfError::Io { path: path.to_path_buf(), source };
    let len = std::fs::metadata(path).map_err(io)?.len();
    if len > MAX_FILE_BYTES {
        return Err(GltfError::Malformed {
            path: path.to_path_buf(),
            reason: format!("{len} bytes, more than the {MAX_FILE_BYTES} a model may have"),
        });
    }
    let bytes = std::fs::read(path).map_err(io)?;
    load_gltf_from_bytes(&bytes, path, options)
}

/// Imports `bytes` as the file `path` (`.gltf` or `.glb`): external buffers are looked for
/// beside `path`, and every message names it. What [`load_gltf`] does once it has read the file;
/// a fuzzer's or an embedder's way in.
///
/// # Errors
/// As [`load_gltf`].
pub fn load_gltf_from_bytes(bytes: &[u8], path: &Path, options: &GltfOptions) -> Result<GltfImport, GltfError> {
    if bytes.len() as u64 > MAX_FILE_BYTES {
        return Err(GltfError::Malformed {
            path: path.to_path_buf(),
            reason: format!("{} bytes, more than the {MAX_FILE_BYTES} a model may have", bytes.len()),
        });
    }
    let invalid = |e: gltf::Error| GltfError::Invalid { path: path.to_path_buf(), reason: e.to_string() };
    let compressed = |ext: &str| GltfError::Unsupported {
        path: path.to_path_buf(),
        extension: ext.to_string(),
        hint: "decompress it first, e.g. `gltf-transform copy in.glb out.glb` (glTF-Transform writes plain accessors)",
    };
    precheck(bytes).map_err(|reason| GltfError::Malformed { path: path.to_path_buf(), reason })?;
    // the reader refuses a required extension it does not know; say which and what to do
    let gltf::Gltf { document, blob } = gltf::Gltf::from_slice(bytes).map_err(|e| {
        let reason = e.to_string();
        COMPRESSION.iter().find(|c| reason.contains(*c)).map_or_else(|| invalid(e), |c| compressed(c))
    })?;
    if let Some(ext) = document.extensions_required().find(|e| COMPRESSION.contains(e)) {
        return Err(compressed(ext));
    }
    for buffer in document.buffers() {
        if let gltf::buffer::Source::Uri(uri) = buffer.source()
            && !uri.starts_with("data:")
        {
            let file = path.parent().unwrap_or(Path::new(".")).join(uri);
            if !file.is_file() {
                return Err(GltfError::Malformed {
                    path: path.to_path_buf(),
                    reason: format!("buffer {} is file {uri:?}, which is missing", buffer.index()),
                });
            }
        }
    }
    let buffers = gltf::import_buffers(&document, path.parent(), blob).map_err(invalid)?;
    Importer { path, options, buffers: &buffers, warnings: BTreeSet::new(), degenerate: 0, skipped: 0 }.run(&document)
}

/// What the `gltf` crate (1.4) panics on instead of refusing, found by `cargo xtask fuzz`: a GLB
/// header whose length is under its own 12 bytes (an overflowing subtraction), and a primitive
/// whose `POSITION` names an accessor past the document's (its validation indexes the array
/// before checking the index). Checked here first; anything else is left to the reader.
fn precheck(bytes: &[u8]) -> Result<(), String> {
    let json = if bytes.starts_with(b"glTF") {
        let Some(length) = bytes.get(8..12).and_then(|w| <[u8; 4]>::try_from(w).ok()).map(u32::from_le_bytes) else {
            return Err(format!("a GLB header of {} bytes, under its 12 (truncated)", bytes.len()));
        };
        if length < 12 {
            return Err(format!("the GLB header gives the file {length} bytes, under the header's own 12"));
        }
        let chunk = bytes.get(12..16).and_then(|w| <[u8; 4]>::try_from(w).ok()).map(u32::from_le_bytes);
        match chunk.and_then(|n| bytes.get(20..20usize.checked_add(n as usize)?)) {
            Some(json) => json,
            None => return Ok(()),
        }
    } else {
        bytes
    };
    // typed, ignoring the rest as the reader does: it skips a field it ignores without checking
    // its numbers or UTF-8, so a full parse would refuse files the reader takes
    let Ok(doc) = serde_json::from_slice::<Precheck>(json) else { return Ok(()) };
    let accessors = doc.accessors.len();
    for (m, mesh) in doc.meshes.iter().enumerate() {
        for (p, primitive) in mesh.primitives.iter().enumerate() {
            for (name, index) in primitive.attributes.iter().chain(primitive.targets.iter().flatten().flatten()) {
                if let Some(k) = index.as_u64().filter(|&k| k >= accessors as u64) {
                    return Err(format!("mesh {m} primitive {p}: {name} is accessor {k}, past the file's {accessors}"));
                }
            }
        }
    }
    Ok(())
}

/// What [`precheck`] reads of a document.
#[derive(serde::Deserialize)]
struct Precheck {
    #[serde(default)]
    accessors: Vec<serde::de::IgnoredAny>,
    #[serde(default)]
    meshes: Vec<PrecheckMesh>,
}

#[derive(serde::Deserialize)]
struct PrecheckMesh {
    #[serde(default)]
    primitives: Vec<PrecheckPrimitive>,
}

#[derive(serde::Deserialize)]
struct PrecheckPrimitive {
    #[serde(default)]
    attributes: std::collections::BTreeMap<String, Value>,
    #[serde(default)]
    targets: Option<Vec<std::collections::BTreeMap<String, Value>>>,
}

struct Importer<'a> {
    path: &'a Path,
    options: &'a GltfOptions,
    buffers: &'a [gltf::buffer::Data],
    warnings: BTreeSet<String>,
    degenerate: usize,
    skipped: usize,
}

impl Importer<'_> {
    fn malformed(&self, reason: String) -> GltfError {
        GltfError::Malformed { path: self.path.to_path_buf(), reason }
    }

    fn run(mut self, document: &gltf::Document) -> Result<GltfImport, GltfError> {
        for ext in document.extensions_used() {
            if !matches!(ext, "KHR_lights_punctual") {
                self.warnings.insert(format!("extension {ext} is not modelled"));
            }
        }
        if document.skins().next().is_some() {
            self.warnings.insert("skins are not modelled: the rest pose is drawn".into());
        }
        if document.animations().next().is_some() {
            self.warnings.insert("animations are not modelled: the rest pose is drawn".into());
        }
        let Some(root) = document.default_scene().or_else(|| document.scenes().next()) else {
            return Err(GltfError::NoTriangles { path: self.path.to_path_buf(), degenerate: 0 });
        };
        let mut objects = Vec::new();
        let mut cameras = Vec::new();
        let mut lights = Vec::new();
        let mut triangles = 0usize;
        // depth first in the document's order (the stack pops the last pushed first), so a
        // written scene comes back with its objects in its own order
        let mut stack: Vec<(gltf::Node, Mat4)> = root.nodes().map(|n| (n, Mat4::IDENTITY)).collect();
        stack.reverse();
        let mut names = BTreeSet::new();
        let mut visited = 0usize;
        while let Some((node, parent)) = stack.pop() {
            visited += 1;
            if visited > document.nodes().len() {
                return Err(self.malformed("the node hierarchy has a cycle".into()));
            }
            let world = parent * Mat4::from_cols_array_2d(&node.transform().matrix());
            if !world.is_finite() {
                return Err(self.malformed(format!("node {} has a non-finite transform", node.index())));
            }
            if let Some(mesh) = node.mesh() {
                let base = node.name().or(mesh.name()).map_or_else(|| format!("mesh {}", mesh.index()), str::to_string);
                let several = mesh.primitives().len() > 1;
                for primitive in mesh.primitives() {
                    if let Some(mut object) = self.primitive(&mesh, &primitive, &world, &mut triangles)? {
                        let name = if several { format!("{base}/{}", primitive.index()) } else { base.clone() };
                        object.name = unique(&mut names, name);
                        objects.push(object);
                    }
                }
            }
            if let Some(camera) = node.camera() {
                cameras.push((camera, world));
            }
            if let Some(light) = node.light() {
                lights.push((light, world));
            }
            let first = stack.len();
            stack.extend(node.children().map(|c| (c, world)));
            stack[first..].reverse();
        }
        if objects.is_empty() {
            return Err(GltfError::NoTriangles { path: self.path.to_path_buf(), degenerate: self.degenerate });
        }
        let mut point_lights = Vec::new();
        for (light, world) in lights {
            match light.kind() {
                gltf::khr_lights_punctual::Kind::Point => {
                    let c = Vec3::from(light.color()) * light.intensity();
                    let mut l = PointLight::point(world.transform_point3(Vec3::ZERO), c);
                    // our own exact figures, where they say what the standard ones say
                    if let Some(x) = ours(light.extras())
                        && let Some(i) = x.get("intensity").and_then(vec3_of)
                        && close(i, c, 1e-5 * c.max_element().max(1e-30))
                    {
                        l.intensity = i;
                        l.radius = x.get("radius").and_then(Value::as_f64).map_or(0.0, |r| r as f32).max(0.0);
                    }
                    point_lights.push(l);
                }
                _ => {
                    self.warnings.insert("directional and spot lights are not modelled".into());
                }
            }
        }
        let (lo, hi) = bounds(&objects);
        if let Some(albedo) = self.options.ground {
            objects.push(ground(lo, hi, albedo));
        }
        let camera = self.camera(&cameras, lo, hi)?;
        let name = self.path.file_stem().map_or_else(|| "gltf".into(), |s| s.to_string_lossy().into_owned());
        let mut warnings: Vec<String> = self.warnings.into_iter().collect();
        if self.skipped > 0 {
            warnings.push(format!("{} point or line primitives are not drawn", self.skipped));
        }
        Ok(GltfImport {
            scene: Scene { name, objects, camera, point_lights },
            warnings,
            degenerate: self.degenerate,
            skipped_primitives: self.skipped,
        })
    }

    /// The bytes of `accessor`, checked: its last element ends inside its view, its view inside
    /// its buffer; `(data, stride, count)`.
    fn accessor(&self, accessor: &gltf::Accessor, what: &str) -> Result<(&[u8], usize, usize), GltfError> {
        let Some(view) = accessor.view() else {
            return Err(self.malformed(format!("{what}: accessor {} has no buffer view", accessor.index())));
        };
        let buffer = self
            .buffers
            .get(view.buffer().index())
            .ok_or_else(|| self.malformed(format!("{what}: buffer {} is missing", view.buffer().index())))?;
        let (start, len) = (view.offset(), view.length());
        if start.checked_add(len).is_none_or(|end| end > buffer.len()) {
            return Err(self.malformed(format!(
                "{what}: buffer view {} ({start} + {len} bytes) runs past its buffer of {} bytes",
                view.index(),
                buffer.len()
            )));
        }
        let data = &buffer[start..start + len];
        let size = accessor.size();
        let stride = view.stride().unwrap_or(size);
        let count = accessor.count();
        // an empty accessor still has to start inside its view: its data is sliced from there
        let need = if count == 0 {
            Some(accessor.offset())
        } else {
            (count - 1).checked_mul(stride).and_then(|n| n.checked_add(accessor.offset().checked_add(size)?))
        };
        if stride < size || need.is_none_or(|n| n > data.len()) {
            return Err(self.malformed(format!(
                "{what}: accessor {} ({count} elements of {size} bytes, stride {stride}, offset {}) runs past its \
                 buffer view of {} bytes",
                accessor.index(),
                accessor.offset(),
                data.len()
            )));
        }
        if accessor.sparse().is_some() {
            return Err(GltfError::Unsupported {
                path: self.path.to_path_buf(),
                extension: "sparse accessors".into(),
                hint: "write them out dense first (e.g. `gltf-transform copy`)",
            });
        }
        Ok((&data[accessor.offset()..], stride, count))
    }

    fn vec3s(&self, accessor: &gltf::Accessor, what: &str) -> Result<Vec<Vec3>, GltfError> {
        if accessor.dimensions() != Dimensions::Vec3 || accessor.data_type() != DataType::F32 {
            return Err(self.malformed(format!("{what}: accessor {} is not float VEC3", accessor.index())));
        }
        let (data, stride, count) = self.accessor(accessor, what)?;
        Ok((0..count)
            .map(|i| {
                let e = &data[i * stride..i * stride + 12];
                let f = |k: usize| f32::from_le_bytes([e[k], e[k + 1], e[k + 2], e[k + 3]]);
                Vec3::new(f(0), f(4), f(8))
            })
            .collect())
    }

    fn indices(&self, accessor: &gltf::Accessor, what: &str) -> Result<Vec<u32>, GltfError> {
        if accessor.dimensions() != Dimensions::Scalar {
            return Err(self.malformed(format!("{what}: index accessor {} is not SCALAR", accessor.index())));
        }
        let (data, stride, count) = self.accessor(accessor, what)?;
        let read = |i: usize| -> Option<u32> {
            let e = &data[i * stride..];
            match accessor.data_type() {
                DataType::U8 => Some(u32::from(e[0])),
                DataType::U16 => Some(u32::from(u16::from_le_bytes([e[0], e[1]]))),
                DataType::U32 => Some(u32::from_le_bytes([e[0], e[1], e[2], e[3]])),
                _ => None,
            }
        };
        (0..count)
            .map(|i| read(i).ok_or_else(|| self.malformed(format!("{what}: indices are not unsigned integers"))))
            .collect()
    }

    fn primitive(
        &mut self,
        mesh: &gltf::Mesh,
        primitive: &gltf::Primitive,
        world: &Mat4,
        triangles: &mut usize,
    ) -> Result<Option<Object>, GltfError> {
        let what = format!("mesh {} primitive {}", mesh.index(), primitive.index());
        let mode = primitive.mode();
        if matches!(mode, Mode::Points | Mode::Lines | Mode::LineLoop | Mode::LineStrip) {
            self.skipped += 1;
            return Ok(None);
        }
        if primitive.morph_targets().next().is_some() {
            self.warnings.insert("morph targets are not modelled: the base shape is drawn".into());
        }
        let Some(positions) = primitive.get(&gltf::Semantic::Positions) else {
            return Err(self.malformed(format!("{what}: no POSITION")));
        };
        // refuse before allocating: every index list is at most a few per vertex or index
        let count = primitive.indices().map_or(positions.count(), |a| a.count());
        let tris = match mode {
            Mode::Triangles => count / 3,
            _ => count.saturating_sub(2),
        };
        if triangles.saturating_add(tris) > self.options.max_triangles {
            return Err(self.malformed(format!(
                "more than {} triangles (the import's limit, `GltfOptions::max_triangles`)",
                self.options.max_triangles
            )));
        }
        let mut local = self.vec3s(&positions, &what)?;
        if let Some(p) = local.iter().position(|p| !p.is_finite()) {
            return Err(self.malformed(format!("{what}: position {p} is not finite")));
        }
        let normals = match primitive.get(&gltf::Semantic::Normals) {
            Some(a) => {
                Some(self.vec3s(&a, &what)?).filter(|n| n.len() == local.len() && n.iter().all(|v| v.is_finite()))
            }
            None => None,
        };
        let list: Vec<u32> = match primitive.indices() {
            Some(a) => self.indices(&a, &what)?,
            None => (0..local.len() as u32).collect(),
        };
        if let Some(i) = list.iter().find(|&&i| i as usize >= local.len()) {
            return Err(self.malformed(format!("{what}: index {i} past the {} vertices", local.len())));
        }
        let raw: Vec<[u32; 3]> =
            match mode {
                Mode::Triangles => list.chunks_exact(3).map(|t| [t[0], t[1], t[2]]).collect(),
                // every other triangle of a strip turns the other way round
                Mode::TriangleStrip => (0..list.len().saturating_sub(2))
                    .map(|k| {
                        if k % 2 == 0 {
                            [list[k], list[k + 1], list[k + 2]]
                        } else {
                            [list[k + 1], list[k], list[k + 2]]
                        }
                    })
                    .collect(),
                _ => (1..list.len().saturating_sub(1)).map(|k| [list[0], list[k], list[k + 1]]).collect(),
            };
        let affine = Affine3A::from_mat4(*world);
        for p in &mut local {
            *p = affine.transform_point3(*p);
        }
        let indices: Vec<[u32; 3]> = raw
            .into_iter()
            .filter(|t| {
                let [a, b, c] = t.map(|i| local[i as usize]);
                let keep = t[0] != t[1] && t[1] != t[2] && t[0] != t[2] && (b - a).cross(c - a).length_squared() > 0.0;
                if !keep {
                    self.degenerate += 1;
                }
                keep
            })
            .collect();
        if indices.is_empty() {
            return Ok(None);
        }
        *triangles += indices.len();
        let mut mesh_out = Mesh { positions: local, normals: None, indices };
        if let Some(n) = normals {
            let m = crate::normal_matrix(glam::Mat3::from_mat4(*world));
            // a normal already unit under an identity transform is kept as written, bit for bit
            let unit = |v: Vec3| {
                if (v.length_squared() - 1.0).abs() <= 4.0 * f32::EPSILON { v } else { v.normalize_or(Vec3::Y) }
            };
            mesh_out.normals =
                Some(n.into_iter().map(|v| unit(if m == glam::Mat3::IDENTITY { v } else { m * v })).collect());
        }
        if affine.matrix3.determinant() < 0.0 {
            // a mirroring node: keep the winding counter-clockwise seen from outside
            for t in &mut mesh_out.indices {
                t.swap(1, 2);
            }
        }
        Ok(Some(Object {
            name: format!("{}/{}", mesh.name().unwrap_or("mesh"), primitive.index()),
            mesh: mesh_out,
            material: self.material(&primitive.material()),
        }))
    }

    fn material(&mut self, m: &gltf::Material) -> Material {
        let pbr = m.pbr_metallic_roughness();
        let c = pbr.base_color_factor();
        if pbr.base_color_texture().is_some() || pbr.metallic_roughness_texture().is_some() {
            self.warnings.insert("textures are not modelled yet: their factors are used".into());
        }
        if m.normal_texture().is_some() || m.occlusion_texture().is_some() {
            self.warnings.insert("normal and occlusion maps are not modelled".into());
        }
        if m.emissive_factor() != [0.0; 3] || m.emissive_texture().is_some() {
            self.warnings.insert("emission is not modelled yet".into());
        }
        if m.alpha_mode() == gltf::material::AlphaMode::Blend {
            self.warnings.insert("alpha blending is not modelled: blended surfaces are opaque".into());
        }
        if pbr.metallic_factor() > 0.0 {
            self.warnings.insert("metallic and roughness are not modelled yet: surfaces are Lambertian".into());
        }
        // a GGX layer as envshadow writes it
        let specular = ours(m.extras()).and_then(|x| {
            let g = x.get("ggx")?;
            let roughness = g.get("roughness")?.as_f64()? as f32;
            let f0 = vec3_of(g.get("f0")?)?;
            (roughness > 0.0 && roughness <= 1.0 && f0.cmpge(Vec3::ZERO).all() && f0.cmple(Vec3::ONE).all())
                .then_some(Ggx { roughness, f0 })
        });
        Material { albedo: Vec3::new(c[0], c[1], c[2]).clamp(Vec3::ZERO, Vec3::ONE), specular }
    }

    fn camera(&mut self, cameras: &[(gltf::Camera, Mat4)], lo: Vec3, hi: Vec3) -> Result<Camera, GltfError> {
        let (width, height) = self.options.size;
        let aspect = width as f32 / height.max(1) as f32;
        let chosen = match self.options.camera_index {
            Some(k) => Some(cameras.get(k).ok_or_else(|| {
                self.malformed(format!("no camera {k}: the default scene has {} cameras", cameras.len()))
            })?),
            None => cameras.iter().find(|(c, _)| matches!(c.projection(), gltf::camera::Projection::Perspective(_))),
        };
        if let Some((camera, world)) = chosen {
            if let gltf::camera::Projection::Perspective(p) = camera.projection() {
                let eye = world.transform_point3(Vec3::ZERO);
                let forward = world.transform_vector3(Vec3::NEG_Z).normalize_or(Vec3::NEG_Z);
                let up = world.transform_vector3(Vec3::Y).normalize_or(Vec3::Y);
                let hfov = 2.0 * ((p.yfov() * 0.5).tan() * aspect).atan();
                let mut c = Camera { eye, target: eye + forward, up, hfov_degrees: hfov.to_degrees(), width, height };
                // the exact camera envshadow wrote, where it is the camera the node and the
                // projection describe (the field of view as the file's aspect gives it)
                if let Some(x) = ours(camera.extras())
                    && let (Some(e), Some(t), Some(u), Some(h)) = (
                        x.get("eye").and_then(vec3_of),
                        x.get("target").and_then(vec3_of),
                        x.get("up").and_then(vec3_of),
                        x.get("hfov_degrees").and_then(Value::as_f64).map(|h| h as f32),
                    )
                {
                    let scale = e.abs().max_element().max(1.0);
                    let file_aspect = p.aspect_ratio().unwrap_or(aspect);
                    let file_hfov = (2.0 * ((p.yfov() * 0.5).tan() * file_aspect).atan()).to_degrees();
                    if close(e, eye, 1e-5 * scale)
                        && close((t - e).normalize_or_zero(), forward, 1e-4)
                        && u.cross(forward).length() > 1e-3
                        && (h - file_hfov).abs() < 1e-3
                        && h > 0.0
                        && h < 180.0
                    {
                        (c.eye, c.target, c.up) = (e, t, u);
                        c.hfov_degrees = if (file_aspect - aspect).abs() <= 1e-6 * aspect { h } else { c.hfov_degrees };
                    }
                }
                return Ok(c);
            }
            self.warnings.insert("orthographic cameras are not modelled: a framing camera is used".into());
        }
        Ok(framing_camera(lo, hi, (width, height)))
    }
}

/// `name`, or `name #2`, `name #3` … where it is taken.
fn unique(names: &mut BTreeSet<String>, name: String) -> String {
    let mut out = name.clone();
    let mut k = 1;
    while !names.insert(out.clone()) {
        k += 1;
        out = format!("{name} #{k}");
    }
    out
}

/// What `extras.envshadow` holds, if anything.
fn ours(extras: &gltf::json::Extras) -> Option<Value> {
    let raw = extras.as_ref()?;
    let mut v: Value = serde_json::from_str(raw.get()).ok()?;
    v.get_mut(crate::export::EXTRAS_KEY).map(Value::take)
}

/// Three finite numbers.
fn vec3_of(v: &Value) -> Option<Vec3> {
    let a = v.as_array()?;
    let f = |k: usize| a.get(k).and_then(Value::as_f64).map(|x| x as f32);
    let out = Vec3::new(f(0)?, f(1)?, f(2)?);
    (a.len() == 3 && out.is_finite()).then_some(out)
}

fn close(a: Vec3, b: Vec3, tolerance: f32) -> bool {
    (a - b).abs().max_element() <= tolerance
}

/// Bounds of every vertex of `objects`.
fn bounds(objects: &[Object]) -> (Vec3, Vec3) {
    let mut lo = Vec3::splat(f32::INFINITY);
    let mut hi = Vec3::splat(f32::NEG_INFINITY);
    for p in objects.iter().flat_map(|o| &o.mesh.positions) {
        lo = lo.min(*p);
        hi = hi.max(*p);
    }
    (lo, hi)
}

/// A square Lambertian ground of `albedo` at the model's lowest point, 10 times the model's
/// widest horizontal extent across, centred under it (shadows of lights down to 10° above the
/// horizon fall on it).
fn ground(lo: Vec3, hi: Vec3, albedo: f32) -> Object {
    let c = (lo + hi) * 0.5;
    let r = 5.0 * (hi - lo).x.max((hi - lo).z).max((hi - lo).y).max(1e-3);
    let y = lo.y;
    let positions = vec![
        Vec3::new(c.x - r, y, c.z - r),
        Vec3::new(c.x - r, y, c.z + r),
        Vec3::new(c.x + r, y, c.z + r),
        Vec3::new(c.x + r, y, c.z - r),
    ];
    Object {
        name: "ground".into(),
        mesh: Mesh { positions, normals: None, indices: vec![[0, 1, 2], [0, 2, 3]] },
        material: Material::lambert(albedo.clamp(0.0, 1.0)),
    }
}

/// A camera looking at the bounding sphere of `lo`..`hi` from the front (+Z) and a little
/// above, at 45° horizontal field of view, the sphere filling the narrower side.
#[must_use]
pub fn framing_camera(lo: Vec3, hi: Vec3, (width, height): (u32, u32)) -> Camera {
    let centre = (lo + hi) * 0.5;
    let radius = ((hi - lo).length() * 0.5).max(1e-6);
    let hfov = 45f32;
    let aspect = width as f32 / height.max(1) as f32;
    let half = (hfov.to_radians() * 0.5).tan();
    let narrow = if aspect >= 1.0 { half / aspect } else { half };
    let distance = radius / narrow.atan().sin();
    let eye = centre + Vec3::new(0.0, 0.35, 1.0).normalize() * distance;
    Camera { eye, target: centre, up: Vec3::Y, hfov_degrees: hfov, width, height }
}
