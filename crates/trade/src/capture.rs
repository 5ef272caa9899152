//! The stand-in for a capture: a real scene's photograph path traced from its camera
//! (`ref-tracer`'s `PathEmissive`, with the scene's emitting patches), with or without extra
//! objects in it. A harness: `real-scene` and the compositor never trace rays themselves.

use envmap_sphere::EnvMap;
use glam::Vec3;
use real_scene::{RealScene, RealSceneError};

/// Knobs of [`photograph`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PhotoSettings {
    /// Samples per pixel.
    pub spp: u32,
    /// Path length (1: direct light only).
    pub max_depth: u32,
    /// Seed.
    pub seed: u64,
}

impl Default for PhotoSettings {
    fn default() -> Self {
        Self { spp: 256, max_depth: 8, seed: 1 }
    }
}

/// The HDR photograph: the scene's model path traced from its camera (`ref-tracer`'s
/// `PathEmissive`: the emitting patches, and the map when the scene is environment-lit), with
/// AOVs (`object_id` is the patch a pixel sees).
///
/// # Errors
/// [`RealSceneError::NeedsEnvironment`] when `map` is missing for an environment-lit scene, or
/// given for one lit by its own patches.
pub fn photograph(
    scene: &RealScene,
    map: Option<&EnvMap>,
    settings: &PhotoSettings,
) -> Result<ref_tracer::Render, RealSceneError> {
    photograph_with(scene, &[], map, settings)
}

/// [`photograph`] of the scene with `extra` objects in it (which do not emit): what a camera
/// would see with a real object there. Their `object_id`s follow the patches'.
///
/// # Errors
/// As [`photograph`].
pub fn photograph_with(
    scene: &RealScene,
    extra: &[scene::Object],
    map: Option<&EnvMap>,
    settings: &PhotoSettings,
) -> Result<ref_tracer::Render, RealSceneError> {
    if scene.environment_lit != map.is_some() {
        return Err(RealSceneError::NeedsEnvironment(scene.name.clone()));
    }
    let mut s = scene.to_scene();
    s.objects.extend_from_slice(extra);
    let bvh = ref_tracer::SceneBvh::new(&s);
    let env = map.map(ref_tracer::EnvLight::new);
    let emission: Vec<Vec3> =
        scene.patches.iter().map(|p| p.emission).chain(extra.iter().map(|_| Vec3::ZERO)).collect();
    let rs =
        ref_tracer::RenderSettings { spp: settings.spp, seed: settings.seed, ..ref_tracer::RenderSettings::default() };
    let emitters = ref_tracer::Emitters::new(&s, &emission);
    let integrator = ref_tracer::Integrator::PathEmissive { max_depth: settings.max_depth, emitters: &emitters };
    Ok(ref_tracer::render(&s, &bvh, env.as_ref(), &integrator, &rs, &|_, _| {}))
}
