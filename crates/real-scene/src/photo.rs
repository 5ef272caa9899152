//! The photograph of a real scene, and the camera that takes it: `ref-tracer`'s path tracer
//! (with the scene's emitting patches) renders the HDR image from the scene's camera; a [`CameraResponse`] (exposure, a response
//! curve, clipping, 8 bits) turns it into the LDR photograph paper 003 composites into.

use envmap_sphere::EnvMap;
use glam::Vec3;

use crate::{RealScene, RealSceneError};

/// A camera's response T: code = round(255 · clamp((exposure · L / white)^(1 / gamma), 0, 1))
/// per channel, 8 bits.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct CameraResponse {
    /// Exposure: radiance scale before the curve.
    pub exposure: f32,
    /// The curve's gamma (2.2: the usual display-referred response).
    pub gamma: f32,
    /// Exposed radiance that saturates (code 255).
    pub white: f32,
}

impl CameraResponse {
    /// The response for a scene: exposure so that the 99th percentile of the HDR image's
    /// brightest channel reaches the white point (so about 1 % of pixels clip); gamma 2.2.
    #[must_use]
    pub fn auto(hdr: &[Vec3]) -> Self {
        let mut l: Vec<f32> = hdr.iter().map(|&c| c.max_element()).filter(|v| v.is_finite()).collect();
        l.sort_by(f32::total_cmp);
        let p99 = l.get(l.len() * 99 / 100).copied().unwrap_or(1.0);
        Self { exposure: if p99 > 0.0 { 1.0 / p99 } else { 1.0 }, gamma: 2.2, white: 1.0 }
    }

    /// T of one channel before quantization, in [0, 1] (non-finite and negative read as 0).
    #[must_use]
    pub fn curve(&self, radiance: f32) -> f32 {
        let x = radiance * self.exposure / self.white;
        if x.is_nan() || x <= 0.0 { 0.0 } else { x.min(1.0).powf(1.0 / self.gamma) }
    }

    /// The 8-bit code of one channel.
    #[must_use]
    pub fn code(&self, radiance: f32) -> u8 {
        (self.curve(radiance) * 255.0).round() as u8
    }

    /// The 8-bit pixel of a radiance.
    #[must_use]
    pub fn apply(&self, radiance: Vec3) -> [u8; 3] {
        radiance.to_array().map(|c| self.code(c))
    }

    /// The radiance a code stands for (the middle of its bin; 255 is the clip level, a lower
    /// bound).
    #[must_use]
    pub fn invert(&self, code: u8) -> f32 {
        (f32::from(code) / 255.0).powf(self.gamma) * self.white / self.exposure
    }

    /// True when the channel saturates.
    #[must_use]
    pub fn clips(&self, radiance: f32) -> bool {
        radiance * self.exposure >= self.white
    }
}

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

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn response_is_monotonic_clips_and_inverts_within_half_a_code() {
        let t = CameraResponse { exposure: 0.5, gamma: 2.2, white: 1.0 };
        let mut last = 0;
        for k in 0..=4000 {
            let l = k as f32 * 0.001;
            let c = t.code(l);
            assert!(c >= last);
            last = c;
            if !t.clips(l) && c > 0 && c < 255 {
                // the code's bin, half a code either side, holds the radiance
                let back = |x: f32| x.powf(t.gamma) * t.white / t.exposure;
                let (lo, hi) = (back((f32::from(c) - 0.5) / 255.0), back((f32::from(c) + 0.5) / 255.0));
                assert!(l >= lo * (1.0 - 1e-5) && l <= hi * (1.0 + 1e-5), "{l}: code {c}, bin {lo}..{hi}");
                assert!(t.invert(c) >= lo && t.invert(c) <= hi);
            }
        }
        assert_eq!(t.code(2.0), 255);
        assert!(t.clips(2.0) && !t.clips(1.9));
        assert_eq!(t.apply(Vec3::new(f32::NAN, -1.0, f32::INFINITY)), [0, 0, 255]);
        assert_eq!(t.code(0.0), 0);
    }

    #[test]
    fn auto_exposure_puts_the_99th_percentile_at_white() {
        let hdr: Vec<Vec3> = (0..1000).map(|k| Vec3::splat(k as f32 * 0.01)).collect();
        let t = CameraResponse::auto(&hdr);
        assert!((t.curve(9.9) - 1.0).abs() < 1e-3 && t.curve(5.0) < 1.0);
        let black = CameraResponse::auto(&[Vec3::ZERO; 4]);
        assert!(black.exposure.is_finite());
    }
}
