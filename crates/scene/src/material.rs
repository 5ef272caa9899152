//! Materials: a Lambertian base with an optional GGX microfacet specular layer, an emission,
//! and optionally glTF's metallic-roughness parameters with textures that vary them over the
//! surface ([`Material::at`] resolves them at a point).

use crate::texture::Texture;
use glam::{Vec2, Vec3};

/// A GGX (Trowbridge-Reitz) specular layer.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Ggx {
    /// Perceptual roughness in (0, 1]; alpha = roughness^2.
    pub roughness: f32,
    /// Reflectance at normal incidence (Schlick's F0), per channel.
    pub f0: Vec3,
}

/// glTF's metallic-roughness material with its textures (indices into [`crate::Scene::textures`],
/// each sampled through TEXCOORD_0): what [`Material::at`] turns into an albedo, a GGX layer and
/// an emission at a surface point.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Maps {
    /// `baseColorFactor` (RGB, linear).
    pub base_color: Vec3,
    /// `metallicFactor`.
    pub metallic: f32,
    /// `roughnessFactor` (perceptual).
    pub roughness: f32,
    /// `emissiveFactor` (times `KHR_materials_emissive_strength` where given).
    pub emissive: Vec3,
    /// `baseColorTexture` (sRGB; RGB multiplies the factor).
    pub base_color_texture: Option<u32>,
    /// `metallicRoughnessTexture` (linear; B multiplies metallic, G roughness).
    pub metallic_roughness_texture: Option<u32>,
    /// `emissiveTexture` (sRGB; RGB multiplies the factor).
    pub emissive_texture: Option<u32>,
    /// glTF's specular layer (a dielectric's 4 %, a metal's base colour); `false`: the base
    /// colour alone as a Lambertian albedo, metallic and roughness unused (a backdrop's ground,
    /// whose reflectance is estimated from a photograph as radiance over irradiance).
    pub specular: bool,
}

/// Smallest perceptual roughness a GGX layer takes (alpha 1e-3, the shaders' floor): glTF
/// allows 0, a perfect mirror neither renderer samples.
pub const MIN_ROUGHNESS: f32 = 0.0316;

/// A surface material.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Material {
    /// Diffuse albedo (RGB, in [0, 1]).
    pub albedo: Vec3,
    /// Optional specular layer.
    pub specular: Option<Ggx>,
    /// Radiance emitted from the front side (linear RGB, the map's units); zero for most.
    pub emission: Vec3,
    /// Whether the back side is drawn: false (glTF's default for a file) culls the back faces
    /// camera rays meet; shadows and bounces see both sides.
    pub double_sided: bool,
    /// Textures that vary the material over the surface (`None`: uniform, as above).
    pub maps: Option<Maps>,
}

impl Material {
    /// A purely Lambertian material of grey albedo `a`.
    #[must_use]
    pub fn lambert(a: f32) -> Self {
        Self::rgb(Vec3::splat(a), None)
    }

    /// A uniform, double-sided material of albedo `albedo` and specular layer `specular`,
    /// emitting nothing.
    #[must_use]
    pub fn rgb(albedo: Vec3, specular: Option<Ggx>) -> Self {
        Self { albedo, specular, emission: Vec3::ZERO, double_sided: true, maps: None }
    }

    /// glTF's metallic-roughness BRDF as ours: the diffuse albedo `base (1 - metallic)`, a GGX
    /// layer of F0 `lerp(0.04, base, metallic)` (glTF's dielectric 4 %) and the roughness,
    /// floored at [`MIN_ROUGHNESS`]. Inputs are clamped to their ranges.
    #[must_use]
    pub fn metallic_roughness(base: Vec3, metallic: f32, roughness: f32) -> (Vec3, Ggx) {
        let fix = |v: f32| if v.is_finite() { v.clamp(0.0, 1.0) } else { 0.0 };
        let base = base.to_array().map(fix).into();
        let (m, r) = (fix(metallic), fix(roughness));
        let albedo: Vec3 = base * (1.0 - m);
        (albedo, Ggx { roughness: r.max(MIN_ROUGHNESS), f0: Vec3::splat(0.04).lerp(base, m) })
    }

    /// The material at texture coordinate `uv`: itself where it has no [`Maps`], else its
    /// factors times its textures (a texture index past `textures` reads white), as a uniform
    /// material.
    #[must_use]
    pub fn at(&self, textures: &[Texture], uv: Vec2) -> Self {
        let Some(m) = self.maps else { return *self };
        let sample = |t: Option<u32>, srgb: bool| {
            t.and_then(|k| textures.get(k as usize)).map_or(glam::Vec4::ONE, |t| t.sample(uv, srgb))
        };
        let base = m.base_color * sample(m.base_color_texture, true).truncate();
        let emission = m.emissive * sample(m.emissive_texture, true).truncate();
        if !m.specular {
            let albedo = base.to_array().map(|v| if v.is_finite() { v.clamp(0.0, 1.0) } else { 0.0 }).into();
            return Self { albedo, specular: None, emission, double_sided: self.double_sided, maps: None };
        }
        let mr = sample(m.metallic_roughness_texture, false);
        let (albedo, ggx) = Self::metallic_roughness(base, m.metallic * mr.z, m.roughness * mr.y);
        Self { albedo, specular: Some(ggx), emission, double_sided: self.double_sided, maps: None }
    }

    /// Whether the material emits anywhere: its emission, or where it has [`Maps`] their
    /// emissive factor (which [`Material::at`] takes instead).
    #[must_use]
    pub fn emits(&self) -> bool {
        match self.maps {
            Some(m) => m.emissive != Vec3::ZERO,
            None => self.emission != Vec3::ZERO,
        }
    }

    /// One line describing the material, as written in OBJ comments.
    #[must_use]
    pub fn describe(&self) -> String {
        let a = self.albedo;
        let mut s = match self.specular {
            None => format!("lambert albedo {} {} {}", a.x, a.y, a.z),
            Some(g) => format!(
                "lambert albedo {} {} {} + ggx roughness {} f0 {} {} {}",
                a.x, a.y, a.z, g.roughness, g.f0.x, g.f0.y, g.f0.z
            ),
        };
        if self.emission != Vec3::ZERO {
            let e = self.emission;
            s += &format!(" + emission {} {} {}", e.x, e.y, e.z);
        }
        if self.maps.is_some() {
            s += " (textured: the factors shown)";
        }
        s
    }
}
