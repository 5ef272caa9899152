//! glTF 2.0 import (`.gltf` with external or embedded buffers, `.glb`) through the `gltf` crate,
//! into the [`Scene`] every renderer here draws: the default scene's node hierarchy (TRS and
//! matrix transforms), every triangle primitive (strips and fans converted; points and lines
//! skipped and counted), u8/u16/u32 indices, normals where the file has them (flat shading
//! otherwise), the first perspective camera (else one that frames the model) and
//! `KHR_lights_punctual` point lights; what [`Scene::write_gltf`] adds in `extras` (exact
//! Lambertian and GGX layers, the exact camera and lights) where it agrees with the standard data.
//!
//! Materials are glTF's metallic-roughness model as [`Material::metallic_roughness`] maps it
//! onto ours: the base colour, metallic and roughness factors, their textures (base colour
//! and emissive in sRGB, metallic-roughness linear; PNG or JPEG, through TEXCOORD_0, kept in
//! [`Scene::textures`] and sampled per hit as [`Material::at`] says), the emissive factor (with
//! `KHR_materials_emissive_strength`) and texture, and `doubleSided` (one-sided back faces are
//! culled for the camera).
//!
//! Every accessor is checked against its buffer view and buffer before it is read, and every
//! image's size from its header before it is decoded, so a file that lies about its sizes is an
//! error, not a panic, and nothing is allocated past [`GltfOptions::max_triangles`] or
//! [`GltfOptions::max_texture_bytes`]. What the file holds that is not modelled is listed in
//! [`GltfImport::warnings`], once per kind.

use crate::texture::{Filter, Texture, Wrap};
use crate::{Camera, Ggx, Maps, Material, Mesh, Object, PointLight, Scene};
use glam::{Affine3A, Mat4, Vec2, Vec3};
use gltf::accessor::{DataType, Dimensions};
use gltf::mesh::Mode;
use serde_json::Value;
use std::borrow::Cow;
use std::collections::{BTreeMap, BTreeSet};
use std::path::{Path, PathBuf};

/// Files larger than this are refused before they are read (4 GiB).
pub const MAX_FILE_BYTES: u64 = 4 << 30;

/// Widest and tallest texture decoded (larger are refused before decoding).
pub const MAX_TEXTURE_SIDE: u32 = 16384;

/// Texel bytes all of a file's textures may take together by default (1 GiB; see
/// [`GltfOptions::max_texture_bytes`]).
pub const MAX_TEXTURE_BYTES: u64 = 1 << 30;

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
    /// Texel bytes (4 a texel) all textures may take together, refused beyond before decoding.
    pub max_texture_bytes: u64,
}

impl Default for GltfOptions {
    /// 640 × 480, the file's first camera, no ground, up to 50 million triangles and
    /// [`MAX_TEXTURE_BYTES`] of textures.
    fn default() -> Self {
        Self {
            size: (640, 480),
            camera_index: None,
            ground: None,
            max_triangles: 50_000_000,
            max_texture_bytes: MAX_TEXTURE_BYTES,
        }
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

/// Extensions whose data cannot be read without decoding, and that are not decoded here (Draco
/// is: [`DRACO`]).
const COMPRESSION: [&str; 1] = ["EXT_meshopt_compression"];

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
    // Draco primitives decode through `draco-gltf`; the `gltf` crate, which does not know the
    // extension, reads the rest of the file with it no longer required
    let draco_free = without_required_draco(bytes);
    let gltf_bytes = draco_free.as_deref().unwrap_or(bytes);
    // the reader refuses a required extension it does not know; say which and what to do
    let refusal = |e: gltf::Error| {
        let reason = e.to_string();
        COMPRESSION.iter().find(|c| reason.contains(*c)).map_or_else(|| invalid(e), |c| compressed(c))
    };
    let gltf::Gltf { document, blob } = if bytes.windows(DRACO.len()).any(|w| w == DRACO.as_bytes()) {
        let g = gltf::Gltf::from_slice_without_validation(gltf_bytes).map_err(refusal)?;
        validate_but_draco_views(&g.document).map_err(invalid)?;
        g
    } else {
        gltf::Gltf::from_slice(gltf_bytes).map_err(refusal)?
    };
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
    let draco = if document.extensions_used().any(|e| e == DRACO) { Some(Draco::open(bytes, path)?) } else { None };
    Importer {
        path,
        options,
        buffers: &buffers,
        warnings: BTreeSet::new(),
        degenerate: 0,
        skipped: 0,
        textures: Vec::new(),
        texture_index: BTreeMap::new(),
        texture_bytes: 0,
        // the image's fields as written: `gltf::Image::source` unwraps a missing URI or MIME
        // type (1.4.1), so the import reads them itself
        images: document.as_json().images.iter().map(|i| (i.buffer_view.map(|v| v.value()), i.uri.clone())).collect(),
        views: document.views().map(|v| (v.buffer().index(), v.offset(), v.length())).collect(),
        draco,
    }
    .run(&document)
}

/// The extension decoded through `draco-gltf`.
const DRACO: &str = "KHR_draco_mesh_compression";

/// The `gltf` crate's validation, but for accessors without a buffer view: a Draco primitive's
/// have none (its stream is their data), and any other is refused by the import's own reading.
fn validate_but_draco_views(document: &gltf::Document) -> Result<(), gltf::Error> {
    use gltf::json::validation::{Error, Validate};
    let root = document.as_json();
    let mut errors = Vec::new();
    root.validate(root, gltf::json::Path::new, &mut |path, error| {
        let path = path();
        let view = path.as_str().starts_with("accessors[") && path.as_str().ends_with("].bufferView");
        if !(view && matches!(error, Error::Missing)) {
            errors.push((path, error));
        }
    });
    if errors.is_empty() { Ok(()) } else { Err(gltf::Error::Validation(errors)) }
}

/// `bytes` (a `.gltf` or a `.glb`) with [`DRACO`] taken out of `extensionsRequired`, or `None`
/// when it is not there (or the JSON cannot be read: the `gltf` crate then says why).
fn without_required_draco(bytes: &[u8]) -> Option<Vec<u8>> {
    let glb = bytes.starts_with(b"glTF");
    let json_len = if glb { u32::from_le_bytes(bytes.get(12..16)?.try_into().ok()?) as usize } else { bytes.len() };
    let json = if glb { bytes.get(20..20usize.checked_add(json_len)?)? } else { bytes };
    let mut doc: Value = serde_json::from_slice(json).ok()?;
    let required = doc.get_mut("extensionsRequired")?.as_array_mut()?;
    let before = required.len();
    required.retain(|e| e.as_str() != Some(DRACO));
    if required.len() == before {
        return None;
    }
    let mut text = serde_json::to_vec(&doc).ok()?;
    if !glb {
        return Some(text);
    }
    // the JSON chunk padded with spaces, the chunks after it as they were
    while !text.len().is_multiple_of(4) {
        text.push(b' ');
    }
    let rest = bytes.get(20 + json_len..)?;
    let total = u32::try_from(12 + 8 + text.len() + rest.len()).ok()?;
    let mut out = Vec::with_capacity(total as usize);
    out.extend_from_slice(&bytes[..8]);
    out.extend_from_slice(&total.to_le_bytes());
    out.extend_from_slice(&u32::try_from(text.len()).ok()?.to_le_bytes());
    out.extend_from_slice(&bytes[16..20]);
    out.extend_from_slice(&text);
    out.extend_from_slice(rest);
    Some(out)
}

/// A file's Draco-compressed primitives, decoded on demand by `draco-gltf` (0.7: pure Rust, 0
/// panics in 40,000 mutated files when evaluated, see docs/gltf.md).
struct Draco {
    import: draco_gltf::Import,
    /// (mesh, primitive) of each primitive carrying the extension
    primitives: BTreeSet<(usize, usize)>,
}

/// A primitive's decoded geometry.
struct Decoded {
    positions: Vec<Vec3>,
    normals: Option<Vec<Vec3>>,
    uvs: Option<Vec<Vec2>>,
    indices: Option<Vec<u32>>,
}

impl Draco {
    fn open(bytes: &[u8], path: &Path) -> Result<Self, GltfError> {
        let options = draco_gltf::ImportOptions {
            base_path: path.parent(),
            external_file_policy: draco_gltf::ExternalFilePolicy::Allow,
            profile: draco_gltf::ValidationProfile::Gltf20,
            ..Default::default()
        };
        let import = draco_gltf::import_slice_with_options(bytes, &options).map_err(|e| GltfError::Malformed {
            path: path.to_path_buf(),
            reason: one_line(&format!("{DRACO}: {e}")),
        })?;
        let primitives = import.draco_primitives().map(|p| (p.mesh_index().0, p.primitive_index())).collect();
        Ok(Self { import, primitives })
    }

    /// Primitive `(mesh, primitive)` decoded, when it is one of Draco's.
    fn decode(&self, mesh: usize, primitive: usize) -> Result<Option<Decoded>, String> {
        if !self.primitives.contains(&(mesh, primitive)) {
            return Ok(None);
        }
        let index = draco_gltf::PrimitiveIndex::new(draco_gltf::MeshIndex(mesh), primitive);
        let g = self.import.read_primitive(index).map_err(|e| one_line(&format!("{DRACO}: {e}")))?;
        let attribute = |name: &str| g.attributes().iter().find(|a| a.semantic() == name);
        let floats = |a: &draco_gltf::PackedAttribute, n: u8| -> Result<Vec<f32>, String> {
            if a.components() != n {
                return Err(format!("{DRACO}: {} has {} components, not {n}", a.semantic(), a.components()));
            }
            let b = a.bytes();
            Ok(match a.component_type() {
                draco_gltf::ComponentType::F32 => {
                    b.chunks_exact(4).map(|c| f32::from_le_bytes([c[0], c[1], c[2], c[3]])).collect()
                }
                draco_gltf::ComponentType::U8 if a.normalized() => b.iter().map(|&v| f32::from(v) / 255.0).collect(),
                draco_gltf::ComponentType::U16 if a.normalized() => {
                    b.chunks_exact(2).map(|c| f32::from(u16::from_le_bytes([c[0], c[1]])) / 65535.0).collect()
                }
                t => return Err(format!("{DRACO}: {} decodes as {t:?}", a.semantic())),
            })
        };
        let vec3s = |a| -> Result<Vec<Vec3>, String> {
            Ok(floats(a, 3)?.chunks_exact(3).map(|c| Vec3::new(c[0], c[1], c[2])).collect())
        };
        let positions = vec3s(attribute("POSITION").ok_or_else(|| format!("{DRACO}: no POSITION decoded"))?)?;
        let normals = attribute("NORMAL").map(vec3s).transpose()?;
        let uvs = attribute("TEXCOORD_0")
            .map(|a| Ok::<_, String>(floats(a, 2)?.chunks_exact(2).map(|c| Vec2::new(c[0], c[1])).collect()))
            .transpose()?;
        let indices = g.indices().map(|i| {
            let b = i.bytes();
            match i.component_type() {
                draco_gltf::ComponentType::U8 => b.iter().map(|&v| u32::from(v)).collect(),
                draco_gltf::ComponentType::U16 => {
                    b.chunks_exact(2).map(|c| u32::from(u16::from_le_bytes([c[0], c[1]]))).collect()
                }
                _ => b.chunks_exact(4).map(|c| u32::from_le_bytes([c[0], c[1], c[2], c[3]])).collect(),
            }
        });
        Ok(Some(Decoded { positions, normals, uvs, indices }))
    }
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
    /// decoded textures, and which glTF texture (with its colour space) each one is
    textures: Vec<Texture>,
    texture_index: BTreeMap<usize, u32>,
    texture_bytes: u64,
    /// per image: its buffer view and URI; per buffer view: buffer, offset, length
    images: Vec<(Option<usize>, Option<String>)>,
    views: Vec<(usize, usize, usize)>,
    /// the file's Draco primitives, when it has any
    draco: Option<Draco>,
}

impl Importer<'_> {
    fn malformed(&self, reason: String) -> GltfError {
        GltfError::Malformed { path: self.path.to_path_buf(), reason }
    }

    fn run(mut self, document: &gltf::Document) -> Result<GltfImport, GltfError> {
        for ext in document.extensions_used() {
            if !matches!(ext, "KHR_lights_punctual" | "KHR_materials_emissive_strength" | DRACO) {
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
            scene: Scene { name, objects, camera, point_lights, textures: self.textures },
            warnings,
            degenerate: self.degenerate,
            skipped_primitives: self.skipped,
        })
    }

    /// The bytes of buffer view `view`, checked to lie inside its buffer.
    fn view(&self, view: &gltf::buffer::View, what: &str) -> Result<&[u8], GltfError> {
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
        Ok(&buffer[start..start + len])
    }

    /// The bytes of `accessor`, checked: its last element ends inside its view, its view inside
    /// its buffer; `(data, stride, count)`. A sparse accessor comes back dense: its base (or
    /// zeros, without a view) with the substituted elements written in, each index checked.
    fn accessor(&self, accessor: &gltf::Accessor, what: &str) -> Result<(Cow<'_, [u8]>, usize, usize), GltfError> {
        let size = accessor.size();
        let count = accessor.count();
        let sparse = accessor.sparse();
        let Some(view) = accessor.view() else {
            if sparse.is_none() {
                return Err(self.malformed(format!("{what}: accessor {} has no buffer view", accessor.index())));
            }
            // all zeros but the substitutions: refused past what any triangle could use
            let limit = self.options.max_triangles.saturating_mul(3);
            if count > limit {
                return Err(self.malformed(format!(
                    "{what}: sparse accessor {} of {count} elements exceeds the import's limit of {limit}",
                    accessor.index()
                )));
            }
            let zeros = Cow::Owned(vec![0u8; count * size]);
            return self.substitute(accessor, what, zeros, size, count);
        };
        let data = self.view(&view, what)?;
        let stride = view.stride().unwrap_or(size);
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
        let data = &data[accessor.offset()..];
        if sparse.is_none() {
            return Ok((Cow::Borrowed(data), stride, count));
        }
        // dense copy (bounded by the view's bytes just checked), then the substitutions
        let mut dense = vec![0u8; count * size];
        for (i, e) in dense.chunks_exact_mut(size.max(1)).enumerate() {
            e.copy_from_slice(&data[i * stride..i * stride + size]);
        }
        self.substitute(accessor, what, Cow::Owned(dense), size, count)
    }

    /// Writes sparse `accessor`'s substituted elements into its dense `data`.
    fn substitute<'b>(
        &self,
        accessor: &gltf::Accessor,
        what: &str,
        data: Cow<'b, [u8]>,
        size: usize,
        count: usize,
    ) -> Result<(Cow<'b, [u8]>, usize, usize), GltfError> {
        let Some(sparse) = accessor.sparse() else { return Ok((data, size, count)) };
        let mut data = data.into_owned();
        let n = sparse.count();
        let (indices, values) = (sparse.indices(), sparse.values());
        let index_size = match indices.index_type() {
            gltf::accessor::sparse::IndexType::U8 => 1,
            gltf::accessor::sparse::IndexType::U16 => 2,
            gltf::accessor::sparse::IndexType::U32 => 4,
        };
        let part = |view: &gltf::buffer::View, offset: usize, bytes: Option<usize>, name: &str| {
            let d = self.view(view, what)?;
            match bytes.and_then(|b| b.checked_add(offset)) {
                Some(end) if end <= d.len() => Ok(&d[offset..end]),
                _ => Err(self.malformed(format!(
                    "{what}: sparse accessor {}'s {n} {name} (offset {offset}) run past buffer view {} of {} bytes",
                    accessor.index(),
                    view.index(),
                    d.len()
                ))),
            }
        };
        let index_bytes = part(&indices.view(), indices.offset(), n.checked_mul(index_size), "indices")?;
        let value_bytes = part(&values.view(), values.offset(), n.checked_mul(size), "values")?;
        for (k, v) in value_bytes.chunks_exact(size.max(1)).enumerate() {
            let e = &index_bytes[k * index_size..];
            let i = match index_size {
                1 => usize::from(e[0]),
                2 => usize::from(u16::from_le_bytes([e[0], e[1]])),
                _ => u32::from_le_bytes([e[0], e[1], e[2], e[3]]) as usize,
            };
            if i >= count {
                return Err(self.malformed(format!(
                    "{what}: sparse accessor {} substitutes element {i} of {count}",
                    accessor.index()
                )));
            }
            data[i * size..(i + 1) * size].copy_from_slice(v);
        }
        Ok((Cow::Owned(data), size, count))
    }

    /// TEXCOORD values: floats, or unsigned bytes or shorts normalized to [0, 1].
    fn vec2s(&self, accessor: &gltf::Accessor, what: &str) -> Result<Vec<Vec2>, GltfError> {
        let kind = accessor.data_type();
        if accessor.dimensions() != Dimensions::Vec2 || !matches!(kind, DataType::F32 | DataType::U8 | DataType::U16) {
            return Err(self.malformed(format!("{what}: TEXCOORD_0 accessor {} is not VEC2", accessor.index())));
        }
        let (data, stride, count) = self.accessor(accessor, what)?;
        Ok((0..count)
            .map(|i| {
                let e = &data[i * stride..];
                let c = |k: usize| match kind {
                    DataType::U8 => f32::from(e[k]) / 255.0,
                    DataType::U16 => f32::from(u16::from_le_bytes([e[2 * k], e[2 * k + 1]])) / 65535.0,
                    _ => f32::from_le_bytes([e[4 * k], e[4 * k + 1], e[4 * k + 2], e[4 * k + 3]]),
                };
                Vec2::new(c(0), c(1))
            })
            .collect())
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
        let decoded = match &self.draco {
            Some(d) => d
                .decode(mesh.index(), primitive.index())
                .map_err(|reason| self.malformed(format!("{what}: {reason}")))?,
            None => None,
        };
        // the decoded stream's attributes, or the accessors'
        let (mut local, normals, uvs, list) = match decoded {
            Some(d) => (d.positions, d.normals, d.uvs, d.indices),
            None => {
                let local = self.vec3s(&positions, &what)?;
                let normals = primitive.get(&gltf::Semantic::Normals).map(|a| self.vec3s(&a, &what)).transpose()?;
                let uvs = primitive.get(&gltf::Semantic::TexCoords(0)).map(|a| self.vec2s(&a, &what)).transpose()?;
                let list = primitive.indices().map(|a| self.indices(&a, &what)).transpose()?;
                (local, normals, uvs, list)
            }
        };
        if let Some(p) = local.iter().position(|p| !p.is_finite()) {
            return Err(self.malformed(format!("{what}: position {p} is not finite")));
        }
        let normals = normals.filter(|n| n.len() == local.len() && n.iter().all(|v| v.is_finite()));
        let uvs = match uvs {
            Some(uvs) => {
                if uvs.len() != local.len() {
                    return Err(self.malformed(format!(
                        "{what}: {} texture coordinates for {} positions",
                        uvs.len(),
                        local.len()
                    )));
                }
                // a broken coordinate reads the texture's first texel, not a NaN
                Some(uvs.into_iter().map(|v| if v.is_finite() { v } else { Vec2::ZERO }).collect::<Vec<_>>())
            }
            None => None,
        };
        let list: Vec<u32> = list.unwrap_or_else(|| (0..local.len() as u32).collect());
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
        let material = self.material(&primitive.material())?;
        let textured = material.maps.is_some_and(|m| {
            m.base_color_texture.is_some() || m.metallic_roughness_texture.is_some() || m.emissive_texture.is_some()
        });
        if textured && uvs.is_none() {
            self.warnings.insert("textured primitives without TEXCOORD_0 read their textures at uv (0, 0)".into());
        }
        // coordinates only where a texture reads them
        let uvs = uvs.filter(|_| textured);
        let mut mesh_out = Mesh { positions: local, normals: None, indices, uvs };
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
            material,
        }))
    }

    fn material(&mut self, m: &gltf::Material) -> Result<Material, GltfError> {
        let pbr = m.pbr_metallic_roughness();
        let c = pbr.base_color_factor();
        if m.normal_texture().is_some() || m.occlusion_texture().is_some() {
            self.warnings.insert("normal and occlusion maps are not modelled".into());
        }
        match m.alpha_mode() {
            gltf::material::AlphaMode::Blend => {
                self.warnings.insert("alpha blending is not modelled: blended surfaces are opaque".into());
            }
            gltf::material::AlphaMode::Mask => {
                self.warnings.insert("alpha masks are not modelled: masked surfaces are opaque".into());
            }
            gltf::material::AlphaMode::Opaque => {}
        }
        let base = Vec3::new(c[0], c[1], c[2]).clamp(Vec3::ZERO, Vec3::ONE);
        let emissive = Vec3::from(m.emissive_factor()) * m.emissive_strength().unwrap_or(1.0);
        let emissive = if emissive.is_finite() { emissive.max(Vec3::ZERO) } else { Vec3::ZERO };
        // what envshadow wrote, where it agrees with the standard fields (metallic 0)
        let exact = ours(m.extras()).filter(|_| pbr.metallic_factor() == 0.0).and_then(|x| {
            if x.get("lambert").and_then(Value::as_bool) == Some(true) {
                return Some(None);
            }
            let g = x.get("ggx")?;
            let roughness = g.get("roughness")?.as_f64()? as f32;
            let f0 = vec3_of(g.get("f0")?)?;
            (roughness > 0.0 && roughness <= 1.0 && f0.cmpge(Vec3::ZERO).all() && f0.cmple(Vec3::ONE).all())
                .then_some(Some(Ggx { roughness, f0 }))
        });
        let base_tex = pbr.base_color_texture().map(|t| (t.texture(), t.tex_coord()));
        let mr_tex = pbr.metallic_roughness_texture().map(|t| (t.texture(), t.tex_coord()));
        let emissive_tex = m.emissive_texture().map(|t| (t.texture(), t.tex_coord()));
        let mut material = match exact {
            Some(specular) => Material::rgb(base, specular),
            None => {
                let (albedo, ggx) = Material::metallic_roughness(base, pbr.metallic_factor(), pbr.roughness_factor());
                Material::rgb(albedo, Some(ggx))
            }
        };
        material.emission = emissive;
        material.double_sided = m.double_sided();
        if base_tex.is_some() || mr_tex.is_some() || emissive_tex.is_some() {
            let mut load = |t: Option<(gltf::Texture, u32)>| -> Result<Option<u32>, GltfError> {
                let Some((texture, set)) = t else { return Ok(None) };
                if set != 0 {
                    self.warnings
                        .insert("texture coordinate sets past TEXCOORD_0 are not modelled: TEXCOORD_0 is used".into());
                }
                self.texture(&texture).map(Some)
            };
            let maps = Maps {
                base_color: base,
                metallic: pbr.metallic_factor(),
                roughness: pbr.roughness_factor(),
                emissive,
                base_color_texture: load(base_tex)?,
                metallic_roughness_texture: load(mr_tex)?,
                emissive_texture: load(emissive_tex)?,
                specular: true,
            };
            material.maps = Some(maps);
        }
        Ok(material)
    }

    /// glTF texture `texture`, decoded once (8-bit RGBA) and kept in the scene; its index there.
    fn texture(&mut self, texture: &gltf::Texture) -> Result<u32, GltfError> {
        if let Some(&k) = self.texture_index.get(&texture.index()) {
            return Ok(k);
        }
        let image = texture.source();
        let what = format!("texture {} (image {})", texture.index(), image.index());
        let (view, uri) = self.images.get(image.index()).cloned().unwrap_or_default();
        let bytes: std::borrow::Cow<[u8]> = match (view, uri) {
            (Some(v), _) => {
                let Some(&(b, start, len)) = self.views.get(v) else {
                    return Err(
                        self.malformed(format!("{what}: buffer view {v} is past the file's {}", self.views.len()))
                    );
                };
                let buffer = self.buffers.get(b).map_or(&[][..], |b| &b[..]);
                let Some(bytes) = start.checked_add(len).and_then(|end| buffer.get(start..end)) else {
                    return Err(self.malformed(format!(
                        "{what}: buffer view {v} ({start} + {len} bytes) runs past its buffer of {} bytes",
                        buffer.len()
                    )));
                };
                bytes.into()
            }
            (None, None) => return Err(self.malformed(format!("{what}: neither a URI nor a buffer view"))),
            (None, Some(uri)) => {
                if let Some(data) = uri.strip_prefix("data:") {
                    let Some((_, encoded)) = data.split_once(";base64,") else {
                        return Err(self.malformed(format!("{what}: a data URI that is not base64")));
                    };
                    base64::decode(encoded)
                        .map_err(|e| self.malformed(format!("{what}: its data URI is not base64: {e}")))?
                        .into()
                } else {
                    let file = self.path.parent().unwrap_or(Path::new(".")).join(&uri);
                    let io = |e: std::io::Error| self.malformed(format!("{what}: file {uri:?}: {e}"));
                    let len = std::fs::metadata(&file).map_err(io)?.len();
                    if len > MAX_FILE_BYTES {
                        return Err(
                            self.malformed(format!("{what}: file {uri:?} has {len} bytes, more than {MAX_FILE_BYTES}"))
                        );
                    }
                    std::fs::read(&file).map_err(io)?.into()
                }
            }
        };
        let limit = self.options.max_texture_bytes;
        let decoded = decode_image(&bytes, limit.saturating_sub(self.texture_bytes), limit)
            .map_err(|reason| self.malformed(format!("{what}: {reason}")))?;
        self.texture_bytes += u64::from(decoded.width()) * u64::from(decoded.height()) * 4;
        let sampler = texture.sampler();
        let wrap = |w: gltf::texture::WrappingMode| match w {
            gltf::texture::WrappingMode::ClampToEdge => Wrap::Clamp,
            gltf::texture::WrappingMode::MirroredRepeat => Wrap::Mirror,
            gltf::texture::WrappingMode::Repeat => Wrap::Repeat,
        };
        let filter = match sampler.mag_filter() {
            Some(gltf::texture::MagFilter::Nearest) => Filter::Nearest,
            _ => Filter::Linear,
        };
        let (width, height) = decoded.dimensions();
        let texels = decoded.pixels().map(|p| p.0).collect();
        self.textures.push(Texture {
            width,
            height,
            texels,
            wrap: [wrap(sampler.wrap_s()), wrap(sampler.wrap_t())],
            filter,
        });
        let k = self.textures.len() as u32 - 1;
        self.texture_index.insert(texture.index(), k);
        Ok(k)
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

/// A PNG or JPEG as 8-bit RGBA, its size checked before decoding: at most
/// [`MAX_TEXTURE_SIDE`] a side and `budget` bytes of texels (what is left of `limit`).
fn decode_image(bytes: &[u8], budget: u64, limit: u64) -> Result<image::RgbaImage, String> {
    let reader = image::ImageReader::new(std::io::Cursor::new(bytes))
        .with_guessed_format()
        .map_err(|e| format!("unreadable image: {e}"))?;
    if !matches!(reader.format(), Some(image::ImageFormat::Png | image::ImageFormat::Jpeg)) {
        return Err("not a PNG or JPEG image (the formats glTF 2.0 allows)".into());
    }
    let (w, h) = reader.into_dimensions().map_err(|e| format!("unreadable image: {}", one_line(&e)))?;
    if w > MAX_TEXTURE_SIDE || h > MAX_TEXTURE_SIDE {
        return Err(format!("{w} x {h} texels, more than the {MAX_TEXTURE_SIDE} a side a texture may have"));
    }
    let need = u64::from(w) * u64::from(h) * 4;
    if need > budget {
        return Err(format!("{w} x {h} texels would pass the {limit} bytes the textures may take"));
    }
    let mut reader = image::ImageReader::new(std::io::Cursor::new(bytes))
        .with_guessed_format()
        .map_err(|e| format!("unreadable image: {e}"))?;
    let mut limits = image::Limits::default();
    // the decoder's own buffers beside the texels
    limits.max_alloc = Some(need.saturating_mul(3).max(1 << 20));
    reader.limits(limits);
    let image = reader.decode().map_err(|e| format!("unreadable image: {}", one_line(&e)))?;
    Ok(image.into_rgba8())
}

/// A decoder's message on one line: control characters (from the file) become spaces.
fn one_line(e: &impl std::fmt::Display) -> String {
    e.to_string().chars().map(|c| if c.is_control() { ' ' } else { c }).collect()
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
        mesh: Mesh { positions, normals: None, indices: vec![[0, 1, 2], [0, 2, 3]], uvs: None },
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
