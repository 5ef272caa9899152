//! A reconstructed real scene, as paper 003 takes it from a capture: a triangulated model of a
//! room whose every patch has a diffuse reflectance and a radiance, a calibrated camera, and the
//! lights. We have no capture rig, so the built-in scenes are procedural (`ar_room`: a room with
//! a window and a ceiling lamp; `ar_ground`: a ground with a few objects under an environment
//! map) and their radiances come from a radiosity solution ([`solve`]), checked against closed
//! forms. [`Perturbation`] makes the reconstruction imperfect on purpose.
//!
//! Visibility is asked of a [`Visibility`] (`scene`'s trait; the caller's BVH behind it, one
//! object per patch of [`RealScene::to_scene`]), so nothing here depends on how rays are traced:
//! `ref_tracer::SceneBvh` answers it.

pub mod backdrop;
mod builtin;
pub mod formfactor;
mod photo;
mod radiosity;

pub use backdrop::{Backdrop, PhotoGround};
pub use builtin::{BUILTIN_REAL_SCENES, Perturbation};
pub use photo::{CameraResponse, MAX_PHOTO_PIXELS, MAX_PHOTO_SIDE, Photograph};
pub use radiosity::{SolveReport, SolveSettings, estimate_reflectances, solve};
pub use scene::Visibility;

use glam::Vec3;

/// A flat quadrilateral patch of the reconstructed model.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Patch {
    /// Corners, counter-clockwise seen from the front: the normal is (c1 - c0) x (c3 - c0).
    pub corners: [Vec3; 4],
    /// Diffuse reflectance (RGB, in [0, 1)).
    pub reflectance: Vec3,
    /// Emitted radiance (primary sources: lamps, a window's sky).
    pub emission: Vec3,
    /// Outgoing radiance: emission plus reflected light, as the capture (or [`solve`]) gives it.
    pub radiance: Vec3,
}

impl Patch {
    /// Unit normal (front side).
    #[must_use]
    pub fn normal(&self) -> Vec3 {
        (self.corners[1] - self.corners[0]).cross(self.corners[3] - self.corners[0]).normalize_or_zero()
    }

    /// Area (both triangles).
    #[must_use]
    pub fn area(&self) -> f32 {
        let [a, b, c, d] = self.corners;
        0.5 * ((b - a).cross(c - a).length() + (c - a).cross(d - a).length())
    }

    /// Centroid of the corners.
    #[must_use]
    pub fn center(&self) -> Vec3 {
        self.corners.iter().copied().sum::<Vec3>() * 0.25
    }

    /// A point of the patch from (u, v) in [0, 1]² (bilinear in the corners).
    #[must_use]
    pub fn point(&self, u: f32, v: f32) -> Vec3 {
        let [a, b, c, d] = self.corners;
        a.lerp(b, u).lerp(d.lerp(c, u), v)
    }

    /// Power leaving the patch, luminance: π L A.
    #[must_use]
    pub fn power(&self) -> f32 {
        std::f32::consts::PI * luminance(self.radiance) * self.area()
    }
}

/// Rec. 709 luminance of linear RGB (the project's one definition).
pub use envmap_sphere::luminance;

/// The reconstructed scene: patches and the camera that took the photograph.
#[derive(Clone, Debug, PartialEq)]
pub struct RealScene {
    /// Name (`ar_room`, `ar_ground`).
    pub name: String,
    /// The model, one-sided diffuse patches.
    pub patches: Vec<Patch>,
    /// The calibrated camera.
    pub camera: scene::Camera,
    /// True when an environment map lights the scene (`ar_ground`); false when its own
    /// emitting patches do (`ar_room`).
    pub environment_lit: bool,
}

impl RealScene {
    /// The model as a `scene::Scene`: one object per patch (two triangles), so that a ray's
    /// object is its patch, each with its reflectance as a Lambertian albedo.
    #[must_use]
    pub fn to_scene(&self) -> scene::Scene {
        let objects = self
            .patches
            .iter()
            .enumerate()
            .map(|(k, p)| scene::Object {
                name: format!("patch_{k}"),
                mesh: scene::Mesh {
                    positions: p.corners.to_vec(),
                    normals: None,
                    indices: vec![[0, 1, 2], [0, 2, 3]],
                    uvs: None,
                },
                material: scene::Material::rgb(p.reflectance, None),
            })
            .collect();
        scene::Scene {
            name: self.name.clone(),
            objects,
            camera: self.camera,
            point_lights: Vec::new(),
            textures: Vec::new(),
        }
    }

    /// The point synthetic objects are placed from: the centre of the floor (the bounds' centre
    /// in x and z, their lowest y). `ar_ground`'s is the origin; `ar_room`'s is (2.5, 0, 2).
    #[must_use]
    pub fn floor_centre(&self) -> Vec3 {
        let (lo, hi) = self.bounds();
        Vec3::new(0.5 * (lo.x + hi.x), lo.y, 0.5 * (lo.z + hi.z))
    }

    /// The patches' joint bounds (min, max).
    #[must_use]
    pub fn bounds(&self) -> (Vec3, Vec3) {
        self.patches
            .iter()
            .flat_map(|p| p.corners)
            .fold((Vec3::INFINITY, Vec3::NEG_INFINITY), |(lo, hi), c| (lo.min(c), hi.max(c)))
    }

    /// Patches the camera sees: one ray through every pixel centre of its image.
    #[must_use]
    pub fn visible_patches(&self, vis: &impl Visibility) -> Vec<u32> {
        let rays = self.camera.rays();
        let mut seen = vec![false; self.patches.len()];
        for y in 0..self.camera.height {
            for x in 0..self.camera.width {
                let (o, d) = rays.ray(x as f32 + 0.5, y as f32 + 0.5);
                if let Some((p, _)) = vis.first_hit(o, d) {
                    seen[p as usize] = true;
                }
            }
        }
        (0..self.patches.len() as u32).filter(|&p| seen[p as usize]).collect()
    }
}

/// Errors of this crate.
#[derive(Debug, thiserror::Error, PartialEq, Eq)]
pub enum RealSceneError {
    /// No built-in real scene of that name.
    #[error("unknown real scene {0:?}; built-in real scenes: {list}", list = BUILTIN_REAL_SCENES.join(", "))]
    Unknown(String),
    /// An environment-lit scene was solved without a map, or a scene without one was
    /// photographed under a map.
    #[error(
        "{0}: the environment map and the scene's lighting disagree (environment-lit scenes need one, others take none)"
    )]
    NeedsEnvironment(String),
    /// A parameter out of its range (a backdrop's height or radius, a camera below the ground).
    #[error("{0}")]
    Parameter(String),
    /// An HDR photograph the maps' reader refuses: its message, which names the file.
    #[error("{0}")]
    Image(String),
    /// A photograph that cannot be read or used, and why.
    #[error("{path}: {reason}", path = path.display())]
    Photo {
        /// The file.
        path: std::path::PathBuf,
        /// Why.
        reason: String,
    },
}
