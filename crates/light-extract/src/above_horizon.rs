//! Modelling only what the scene requires: for a scene standing on an opaque ground, light from
//! below the horizon reaches no receiver (the ground blocks it), yet a method given the whole
//! map spends lights on it and leaves the rest in the unshadowed ambient term, where it lights
//! downward-facing surfaces that the truth leaves dark. [`AboveHorizon`] wraps any extractor and
//! hands it only the hemisphere above the ground plane.
//!
//! Some methods spend part of their budget on the empty lower half anyway (paper 001's light
//! tree splits zero-energy nodes for their extent) and return fewer than K lights; with
//! `fill_budget` the wrapper raises the inner budget until K lights come back.
//!
//! A light near the horizon whose cone reaches below it would lose that part to the ground;
//! with `narrow_at_horizon` such a cone is narrowed until it touches the horizon (same
//! direction, same power).
//!
//! This is an improvement of ours, not a paper's method: the papers' methods stay as published
//! and this is a separate, named option (`<method>+above-horizon` in `lights.json`).

use crate::decomposition::{Decomposition, ExtractError, LightExtractor};
use envmap_sphere::EnvMap;
use glam::Vec3;
use scene::DistantLight;
use std::borrow::Cow;
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
    /// Raise the inner method's budget until it returns as many lights as its budget asked for
    /// (methods with a budget only).
    pub fill_budget: bool,
    /// Narrow every cone that crosses the horizon until it touches it, keeping its direction
    /// and power.
    pub narrow_at_horizon: bool,
}

/// At most this many extra extractions when filling the budget.
const FILL_ATTEMPTS: usize = 24;

impl<E> AboveHorizon<E> {
    /// `inner` above the +Y horizon (the toolkit's up).
    pub fn new(inner: E) -> Self {
        Self { inner, up: Vec3::Y, fill_budget: true, narrow_at_horizon: true }
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

/// Narrows `light`'s cone, if it crosses the horizon of `up` while its axis is above it, to the
/// half-angle of the axis's elevation; the radiance rises so the power stays.
pub fn narrow_to_horizon(light: &mut DistantLight, up: Vec3) {
    let elevation = light.direction.dot(up).clamp(-1.0, 1.0).asin();
    if elevation > 0.0 && light.half_angle() > elevation {
        let power = light.power();
        // 2 pi (1 - cos e), without cancellation for suns on the horizon
        light.solid_angle = 4.0 * std::f32::consts::PI * (0.5 * elevation).sin().powi(2);
        light.radiance = power / light.solid_angle;
    }
}

impl<E: LightExtractor> AboveHorizon<E> {
    /// Re-spends the budget the inner method lost on the empty half: the inner budget goes up
    /// by the shortfall, and back down by one after an overshoot past K (the count is not
    /// monotonic in the budget), keeping the result with the most lights not above K.
    fn fill(&self, upper: &EnvMap, first: Decomposition, k: usize) -> Result<(Decomposition, usize), ExtractError> {
        let (mut last_budget, mut last_count) = (k, first.lights.len());
        let (mut best, mut best_budget) = (first, k);
        let mut tried = vec![k];
        for _ in 0..FILL_ATTEMPTS {
            if best.lights.len() >= k {
                break;
            }
            let budget = if last_count < k { last_budget + (k - last_count) } else { last_budget - 1 };
            if tried.contains(&budget) {
                break;
            }
            tried.push(budget);
            let Some(e) = self.inner.with_budget(budget) else { break };
            let d = e.extract(upper)?;
            (last_budget, last_count) = (budget, d.lights.len());
            if d.lights.len() <= k && d.lights.len() > best.lights.len() {
                (best, best_budget) = (d, budget);
            }
        }
        Ok((best, best_budget))
    }
}

impl<E: LightExtractor> LightExtractor for AboveHorizon<E> {
    fn extract(&self, map: &EnvMap) -> Result<Decomposition, ExtractError> {
        let start = Instant::now();
        let up =
            self.up.try_normalize().ok_or_else(|| ExtractError::Parameter("up must be a non-zero vector".into()))?;
        let upper = upper_hemisphere(map, up);
        let mut d = self.inner.extract(&upper)?;
        let mut inner_budget = self.inner.budget();
        if let (true, Some(k)) = (self.fill_budget, inner_budget) {
            let (filled, budget) = self.fill(&upper, d, k)?;
            (d, inner_budget) = (filled, Some(budget));
        }
        if self.narrow_at_horizon {
            for l in &mut d.lights {
                narrow_to_horizon(&mut l.light, up);
            }
        }
        // the inner method's books already hold the upper hemisphere's power
        let (full, kept) = (map.power(), d.map_power);
        d.params = serde_json::json!({
            "inner": d.params,
            "up": up.to_array(),
            "inner_budget": inner_budget,
            "fill_budget": self.fill_budget,
            "narrow_at_horizon": self.narrow_at_horizon,
            "dropped_power": [full[0] - kept[0], full[1] - kept[1], full[2] - kept[2]],
        });
        d.method = format!("{}+above-horizon", d.method);
        d.time_ms = start.elapsed().as_secs_f64() * 1e3;
        Ok(d)
    }

    fn budget(&self) -> Option<usize> {
        self.inner.budget()
    }

    fn with_budget(&self, lights: usize) -> Option<Box<dyn LightExtractor>> {
        let inner = self.inner.with_budget(lights)?;
        Some(Box::new(AboveHorizon {
            inner,
            up: self.up,
            fill_budget: self.fill_budget,
            narrow_at_horizon: self.narrow_at_horizon,
        }))
    }

    fn modelled_map<'m>(&self, map: &'m EnvMap) -> Cow<'m, EnvMap> {
        Cow::Owned(upper_hemisphere(map, self.up.normalize_or_zero()))
    }
}
