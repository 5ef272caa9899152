//! Modelling only what the scene requires: for a scene standing on an opaque ground, light from
//! below the horizon reaches no receiver (the ground blocks it), yet a method given the whole
//! map spends lights on it and leaves the rest in the unshadowed ambient term, where it lights
//! downward-facing surfaces that the truth leaves dark. [`AboveHorizon`] wraps any extractor and
//! hands it only the hemisphere above the ground plane.
//!
//! This is an improvement of ours, not a paper's method: the papers' methods stay as published
//! and this is a separate, named option (`<method>+above-horizon` in `lights.json`).

use crate::decomposition::{Decomposition, ExtractError, LightExtractor};
use envmap_sphere::EnvMap;
use glam::Vec3;
use std::time::Instant;

/// Runs `inner` on the map with every texel whose centre lies below the horizon set to zero.
/// The decomposition's books then cover the upper hemisphere; `params.dropped_power` records
/// the power left out.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct AboveHorizon<E> {
    /// The extractor given the upper hemisphere.
    pub inner: E,
    /// The ground's normal (the scene's up).
    pub up: Vec3,
}

impl<E> AboveHorizon<E> {
    /// `inner` above the +Y horizon (the toolkit's up).
    pub fn new(inner: E) -> Self {
        Self { inner, up: Vec3::Y }
    }
}

/// `map` with the texels below the plane of normal `up` set to zero.
#[must_use]
pub fn upper_hemisphere(map: &EnvMap, up: Vec3) -> EnvMap {
    let mut out = map.clone();
    let (w, h) = (map.width(), map.height());
    for j in 0..h {
        for i in 0..w {
            if map.texel_dir(i, j).dot(up) < 0.0 {
                out.pixels_mut()[(j * w + i) as usize] = Vec3::ZERO;
            }
        }
    }
    out
}

impl<E: LightExtractor> LightExtractor for AboveHorizon<E> {
    fn extract(&self, map: &EnvMap) -> Result<Decomposition, ExtractError> {
        let start = Instant::now();
        let up =
            self.up.try_normalize().ok_or_else(|| ExtractError::Parameter("up must be a non-zero vector".into()))?;
        let upper = upper_hemisphere(map, up);
        let mut d = self.inner.extract(&upper)?;
        // the inner method's books already hold the upper hemisphere's power
        let (full, kept) = (map.power(), d.map_power);
        d.params = serde_json::json!({
            "inner": d.params,
            "up": up.to_array(),
            "dropped_power": [full[0] - kept[0], full[1] - kept[1], full[2] - kept[2]],
        });
        d.method = format!("{}+above-horizon", d.method);
        d.time_ms = start.elapsed().as_secs_f64() * 1e3;
        Ok(d)
    }
}
