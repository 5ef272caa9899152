//! Materials: a Lambertian base with an optional GGX microfacet specular layer.

use glam::Vec3;

/// A GGX (Trowbridge-Reitz) specular layer.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Ggx {
    /// Perceptual roughness in (0, 1]; alpha = roughness^2.
    pub roughness: f32,
    /// Reflectance at normal incidence (Schlick's F0), per channel.
    pub f0: Vec3,
}

/// A surface material.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Material {
    /// Diffuse albedo (RGB, in [0, 1]).
    pub albedo: Vec3,
    /// Optional specular layer.
    pub specular: Option<Ggx>,
}

impl Material {
    /// A purely Lambertian material of grey albedo `a`.
    #[must_use]
    pub fn lambert(a: f32) -> Self {
        Self { albedo: Vec3::splat(a), specular: None }
    }

    /// One line describing the material, as written in OBJ comments.
    #[must_use]
    pub fn describe(&self) -> String {
        let a = self.albedo;
        match self.specular {
            None => format!("lambert albedo {} {} {}", a.x, a.y, a.z),
            Some(g) => format!(
                "lambert albedo {} {} {} + ggx roughness {} f0 {} {} {}",
                a.x, a.y, a.z, g.roughness, g.f0.x, g.f0.y, g.f0.z
            ),
        }
    }
}
