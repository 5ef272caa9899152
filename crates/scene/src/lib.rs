//! Scenes shared by the CPU reference (`ref-tracer`) and the GPU renderers: triangle meshes with
//! one material per object, a pinhole camera, and the procedural built-in scenes (no asset
//! files), exportable as Wavefront OBJ so another renderer can render exactly the same geometry.
//!
//! ```
//! let scene = scene::Scene::builtin("spheres_box").expect("a built-in scene");
//! assert_eq!(scene.objects.len(), 3);
//! let (origin, dir) = scene.camera.ray(320.0, 240.0);
//! assert!((dir.length() - 1.0).abs() < 1e-6 && origin == scene.camera.eye);
//! ```

pub mod brdf;
mod builtin;
mod camera;
mod export;
pub mod import;
mod light;
mod material;
mod mesh;
mod obj;
pub mod texture;
mod visibility;

pub use builtin::BUILTIN_SCENES;
pub use camera::{Camera, CameraRays};
pub use export::glb_bytes;
pub use light::{DistantLight, LightShape, PointLight, cone_cosine_integral};
pub use material::{Ggx, MIN_ROUGHNESS, Maps, Material};
pub use mesh::{Mesh, normal_matrix};
pub use texture::{Filter, Texture, Wrap};
pub use visibility::Visibility;

/// One object: a mesh and its material.
#[derive(Clone, Debug, PartialEq)]
pub struct Object {
    /// Name, unique within the scene (the OBJ `o` name).
    pub name: String,
    /// Geometry in world space.
    pub mesh: Mesh,
    /// Surface material.
    pub material: Material,
}

/// A scene: objects, a camera, and optional point lights. Environment lighting comes from the map.
#[derive(Clone, Debug, PartialEq)]
pub struct Scene {
    /// Name of the scene.
    pub name: String,
    /// The objects.
    pub objects: Vec<Object>,
    /// The view.
    pub camera: Camera,
    /// Point lights, if the scene has any.
    pub point_lights: Vec<PointLight>,
    /// The textures the objects' [`Maps`] index (empty for the built-in scenes).
    pub textures: Vec<Texture>,
}

/// Errors of this crate.
#[derive(Debug, thiserror::Error)]
pub enum SceneError {
    /// No built-in scene of that name.
    #[error("unknown scene {name:?}; built-in scenes: {}", BUILTIN_SCENES.join(", "))]
    Unknown {
        /// The name asked for.
        name: String,
    },
    /// A model file that could not be imported.
    #[error(transparent)]
    Gltf(#[from] import::GltfError),
    /// Writing a file failed.
    #[error("{path}: {source}")]
    Io {
        /// The file.
        path: std::path::PathBuf,
        /// What the operating system said.
        source: std::io::Error,
    },
}

/// Whether `spec` names a model file rather than a built-in scene: a `.gltf` or `.glb` path,
/// or any existing file that is not a built-in's name (the one rule [`Scene::open`] follows).
#[must_use]
pub fn is_model(spec: &str) -> bool {
    let path = std::path::Path::new(spec);
    path.extension().is_some_and(|e| e.eq_ignore_ascii_case("gltf") || e.eq_ignore_ascii_case("glb"))
        || (!BUILTIN_SCENES.contains(&spec) && path.is_file())
}

impl Scene {
    /// A built-in scene by name, or a glTF model by path (see [`is_model`]) imported with
    /// `options`; either way its camera is `options.size`. The import's warnings come back
    /// with it (none for a built-in).
    ///
    /// # Errors
    /// An unknown name; a model that cannot be imported.
    pub fn open(spec: &str, options: &import::GltfOptions) -> Result<(Self, Vec<String>), SceneError> {
        if is_model(spec) {
            let import = import::load_gltf(std::path::Path::new(spec), options)?;
            return Ok((import.scene, import.warnings));
        }
        let mut scene = Self::builtin(spec)?;
        (scene.camera.width, scene.camera.height) = options.size;
        Ok((scene, Vec::new()))
    }

    /// Total number of triangles.
    #[must_use]
    pub fn triangle_count(&self) -> usize {
        self.objects.iter().map(|o| o.mesh.indices.len()).sum()
    }

    /// The object called `name`.
    #[must_use]
    pub fn object(&self, name: &str) -> Option<&Object> {
        self.objects.iter().find(|o| o.name == name)
    }
}
