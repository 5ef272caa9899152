//! Lights for the shadows, the residual for the rest: a cone of mean radiance is not the texels
//! it stands for. A Lambertian receiver barely sees the difference, but a glossy one mirrors it:
//! the map's detail inside a cone, and the gaps and overlaps between cones, are what a K-light
//! decomposition gets most wrong on semi-glossy objects. [`Residual`] keeps any method's lights
//! and replaces its ambient remainder by the signed residual: the map its lights stand for minus
//! the lights splatted onto the map's texels. Lights + residual then give back the map exactly,
//! unshadowed, and the lights alone decide the shadows.
//!
//! A renderer lights the diffuse lobe with the residual's SH9 irradiance and the specular lobe
//! with the residual itself (prefiltered for its roughness, as engines prefilter their specular
//! maps); the residual is signed, so neither may be clamped at zero.
//!
//! This is an improvement of ours, not a paper's method: a separate, named option
//! (`<method>+residual` in `lights.json`).

use crate::decomposition::{
    Decomposition, ExtractError, INTERLEAVED_JITTER, INTERLEAVED_SETS, LightExtractor, interleaved_sets,
};
use envmap_sphere::{EnvMap, Sh9};
use glam::Vec3;
use scene::DistantLight;
use std::borrow::Cow;
use std::f32::consts::{PI, TAU};
use std::time::Instant;

/// Runs `inner`, then replaces the ambient remainder by the map `inner` models minus its
/// lights, splatted (the mean over the `sets` light sets of interleaved sampling, which a
/// renderer cycles through).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Residual<E> {
    /// The extractor whose lights are kept.
    pub inner: E,
    /// Light sets averaged into the splat: [`INTERLEAVED_SETS`] (the renderers' default), or 1
    /// for the lights alone.
    pub sets: usize,
}

impl<E> Residual<E> {
    /// `inner`'s lights with the residual of the default interleaved sets.
    pub fn new(inner: E) -> Self {
        Self { inner, sets: INTERLEAVED_SETS }
    }
}

/// The radiance `lights` add to each texel of a `width` x `height` lat-long map: each light's
/// power spread evenly over the texels whose centres lie in its cone (so the splat's power is
/// the light's power exactly), or put in the texel of its direction when its cone holds no texel
/// centre.
#[must_use]
pub fn splat_lights(lights: &[DistantLight], width: u32, height: u32) -> Vec<Vec3> {
    let mut out = vec![Vec3::ZERO; (width as usize) * (height as usize)];
    let solid = |j: u32| envmap_sphere::latlong::latlong_texel_solid_angle(j, width, height);
    let dirs = envmap_sphere::latlong::TexelDirections::new(width, height);
    for light in lights {
        let texels = cone_texels(light, &dirs, width, height);
        let omega: f64 = texels.iter().map(|&(_, j)| solid(j)).sum();
        let (texels, omega) = if omega > 0.0 {
            (texels, omega)
        } else {
            let uv = envmap_sphere::latlong::latlong_dir_to_uv(light.direction.normalize_or(Vec3::Y));
            let (i, j) = envmap_sphere::latlong::latlong_uv_to_texel(uv, width, height);
            (vec![(i, j)], solid(j))
        };
        let radiance = light.power() / omega as f32;
        for (i, j) in texels {
            out[(j * width + i) as usize] += radiance;
        }
    }
    out
}

/// The texels whose centres lie in `light`'s cone, row by row: per row only the columns within
/// the cone's azimuth span are tested.
fn cone_texels(
    light: &DistantLight,
    dirs: &envmap_sphere::latlong::TexelDirections,
    width: u32,
    height: u32,
) -> Vec<(u32, u32)> {
    let d = light.direction.normalize_or(Vec3::Y);
    let cos_max = light.cos_half_angle();
    let half = light.half_angle();
    let theta_c = d.y.clamp(-1.0, 1.0).acos();
    let phi_c = envmap_sphere::latlong::atan2(d.x, -d.z).rem_euclid(TAU);
    let row = |theta: f32| ((theta / PI * height as f32 - 0.5).floor().max(0.0) as u32).min(height - 1);
    let (j0, j1) = (row(theta_c - half), row(theta_c + half) + 1);
    let mut texels = Vec::new();
    for j in j0..=j1.min(height - 1) {
        let theta = PI * (j as f32 + 0.5) / height as f32;
        let (st, ct) = theta.sin_cos();
        let denom = st * theta_c.sin();
        // cos(angle) = cos t cos tc + sin t sin tc cos(dphi) >= cos_max
        let c = if denom > 1e-6 { (cos_max - ct * theta_c.cos()) / denom } else { -2.0 };
        let columns: Box<dyn Iterator<Item = i64>> = if c <= -1.0 {
            Box::new(0..i64::from(width))
        } else if c > 1.0 {
            continue;
        } else {
            let span = c.acos() / TAU * width as f32 + 1.0;
            let centre = phi_c / TAU * width as f32 - 0.5;
            let (lo, hi) = ((centre - span).floor() as i64, (centre + span).ceil() as i64);
            // a span as wide as the map: every column once
            if hi - lo + 1 >= i64::from(width) { Box::new(0..i64::from(width)) } else { Box::new(lo..=hi) }
        };
        for i in columns {
            let i = i.rem_euclid(i64::from(width)) as u32;
            if dirs.dir(i, j).dot(d) >= cos_max {
                texels.push((i, j));
            }
        }
    }
    texels
}

impl<E: LightExtractor> LightExtractor for Residual<E> {
    fn extract(&self, map: &EnvMap) -> Result<Decomposition, ExtractError> {
        let start = Instant::now();
        if self.sets == 0 {
            return Err(ExtractError::Parameter("residual: sets must be at least 1".into()));
        }
        let mut d = self.inner.extract(map)?;
        let modelled = self.inner.modelled_map(map);
        let (w, h) = (map.width(), map.height());
        // the splat is linear: the mean of the sets' splats is the splat of all their lights
        let all: Vec<DistantLight> =
            interleaved_sets(&d.lights, self.sets, INTERLEAVED_JITTER, 0).iter().flatten().map(|l| l.light).collect();
        let mut residual = modelled.into_owned();
        let scale = 1.0 / self.sets as f32;
        for (r, s) in residual.pixels_mut().iter_mut().zip(splat_lights(&all, w, h)) {
            *r -= s * scale;
        }
        d.ambient_sh = Sh9::project(&residual);
        d.ambient = residual;
        // lights + residual = the modelled map, whatever the inner method left aside
        d.partitions = true;
        d.params = serde_json::json!({ "inner": d.params, "sets": self.sets });
        d.method = format!("{}+residual", d.method);
        d.time_ms = start.elapsed().as_secs_f64() * 1e3;
        Ok(d)
    }

    fn budget(&self) -> Option<usize> {
        self.inner.budget()
    }

    fn with_budget(&self, lights: usize) -> Option<Box<dyn LightExtractor>> {
        Some(Box::new(Residual { inner: self.inner.with_budget(lights)?, sets: self.sets }))
    }

    fn modelled_map<'m>(&self, map: &'m EnvMap) -> Cow<'m, EnvMap> {
        self.inner.modelled_map(map)
    }
}
