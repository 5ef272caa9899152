//! The importance-sampling baseline: K samples of the map's luminance distribution, each an
//! equal-luminous-power light.
//!
//! Sample k is at Hammersley point ((k + 0.5)/K, radical inverse of k), rotated by a seeded
//! offset (Cranley-Patterson). Its power is L(texel) / (K pdf): luminous power is the map's / K
//! exactly, colour follows the texel. It stands for a solid angle 1 / (K pdf); its cone is its
//! texel. Not a partition: the remainder is empty and RGB power matches the map's only in
//! expectation.

use crate::decomposition::{Decomposition, ExtractError, ExtractedLight, LightExtractor};
use envmap_sphere::{EnvDistribution, EnvMap};
use glam::{Vec2, Vec3};
use rand::{Rng, SeedableRng};
use rand_pcg::Pcg32;
use scene::DistantLight;
use std::time::Instant;

/// K importance samples of the map as lights.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct ImportanceSampled {
    /// Number of lights K.
    pub count: usize,
    /// Seed of the point set's rotation.
    pub seed: u64,
}

impl Default for ImportanceSampled {
    /// K = 32, seed 0.
    fn default() -> Self {
        Self { count: 32, seed: 0 }
    }
}

fn radical_inverse_base2(k: u32) -> f32 {
    (k.reverse_bits() as f64 / 4_294_967_296.0) as f32
}

impl LightExtractor for ImportanceSampled {
    fn budget(&self) -> Option<usize> {
        Some(self.count)
    }

    fn with_budget(&self, lights: usize) -> Option<Box<dyn LightExtractor>> {
        Some(Box::new(Self { count: lights, ..*self }))
    }

    fn extract(&self, map: &EnvMap) -> Result<Decomposition, ExtractError> {
        if self.count == 0 || self.count > 1 << 20 {
            return Err(ExtractError::Parameter(format!(
                "importance sampling needs 1..=2^20 lights, got {}",
                self.count
            )));
        }
        let start = Instant::now();
        let dist = EnvDistribution::new(map);
        let mut rng = Pcg32::seed_from_u64(self.seed);
        let shift = Vec2::new(rng.random(), rng.random());
        let k_total = self.count as f32;
        let lights: Vec<ExtractedLight> = (0..self.count)
            .filter_map(|k| {
                let u = Vec2::new((k as f32 + 0.5) / k_total, radical_inverse_base2(k as u32)) + shift;
                let u = Vec2::new(u.x.fract(), u.y.fract());
                let s = dist.sample_dir(u);
                let (i, j) = ((s.uv.x * map.width() as f32) as u32, (s.uv.y * map.height() as f32) as u32);
                let l = map.pixel(i.min(map.width() - 1), j.min(map.height() - 1));
                let power = l / (s.pdf * k_total);
                if !(power.max_element() > 0.0 && power.is_finite()) {
                    return None;
                }
                let texel_sa = map.texel_solid_angle(j.min(map.height() - 1)) as f32;
                let represented = (1.0 / (s.pdf * k_total)).min(4.0 * std::f32::consts::PI);
                Some(ExtractedLight {
                    light: DistantLight { direction: s.dir, solid_angle: texel_sa, radiance: power / texel_sa },
                    extent: (1.0 - represented / std::f32::consts::TAU).clamp(-1.0, 1.0).acos(),
                    indirect: false,
                })
            })
            .collect();
        let ambient = EnvMap::constant(map.width(), map.height(), Vec3::ZERO);
        let params = serde_json::json!({ "count": self.count, "seed": self.seed });
        let mut d = Decomposition::new("importance", params, map, lights, ambient, false);
        d.time_ms = start.elapsed().as_secs_f64() * 1e3;
        Ok(d)
    }
}
