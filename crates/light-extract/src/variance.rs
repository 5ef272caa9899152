//! Variance minimization (Viriyothai and Debevec, "Variance Minimization Light Probe Sampling",
//! 2009): like median cut, 2^n regions and a light at each energy centroid, but each region is
//! cut, along either axis and at any position, where the two parts' summed energy-weighted
//! variance is smallest — so regions follow the light instead of halving the energy.
//!
//! A region's variance is measured on the sphere: with w = luminance x solid angle per texel and
//! unit texel directions d, sum w |d - c|^2 about the centroid c = S / W equals W - |S|^2 / W
//! (W = sum w, S = sum w d). A 4-channel summed-area table of (w, w d) makes every candidate cut
//! O(1), a split O(width + height).

use crate::decomposition::{Decomposition, ExtractError, LightExtractor};
use crate::regions::{Region, partition, subdivide};
use envmap_sphere::latlong::TexelDirections;
use envmap_sphere::{EnvMap, SummedAreaTable, luminance};
use std::time::Instant;

/// Variance minimization with 2^`depth` regions.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct VarianceMinimization {
    /// Number of splitting rounds n: 2^n lights (fewer when regions reach one texel).
    pub depth: u32,
}

impl Default for VarianceMinimization {
    /// n = 5: 32 lights.
    fn default() -> Self {
        Self { depth: 5 }
    }
}

impl VarianceMinimization {
    /// The largest power of two of lights not above `k` (at least 1).
    #[must_use]
    pub fn with_lights(k: usize) -> Self {
        Self { depth: crate::regions::depth_for_lights(k) }
    }
}

fn variance(sat: &SummedAreaTable<4>, r: &Region) -> f64 {
    let [w, x, y, z] = sat.sum(r.x0, r.y0, r.x1, r.y1);
    if w <= 0.0 { 0.0 } else { (w - (x * x + y * y + z * z) / w).max(0.0) }
}

/// The cut of `r` (either axis, any position) that minimizes the parts' summed variance.
fn split(sat: &SummedAreaTable<4>, r: Region) -> Option<(Region, Region)> {
    let mut best: Option<(f64, Region, Region)> = None;
    let mut consider = |a: Region, b: Region| {
        let v = variance(sat, &a) + variance(sat, &b);
        if best.as_ref().is_none_or(|(bv, _, _)| v < *bv) {
            best = Some((v, a, b));
        }
    };
    for c in r.x0 + 1..r.x1 {
        consider(Region { x1: c, ..r }, Region { x0: c, ..r });
    }
    for c in r.y0 + 1..r.y1 {
        consider(Region { y1: c, ..r }, Region { y0: c, ..r });
    }
    best.map(|(_, a, b)| (a, b))
}

impl LightExtractor for VarianceMinimization {
    fn budget(&self) -> Option<usize> {
        Some(1 << self.depth)
    }

    fn with_budget(&self, lights: usize) -> Option<Box<dyn LightExtractor>> {
        Some(Box::new(Self::with_lights(lights)))
    }

    fn extract(&self, map: &EnvMap) -> Result<Decomposition, ExtractError> {
        if self.depth > 24 {
            return Err(ExtractError::Parameter(format!("variance minimization depth {} > 24", self.depth)));
        }
        let start = Instant::now();
        let (w, h) = (map.width(), map.height());
        let row_sa = map.row_solid_angles();
        let dirs = TexelDirections::new(w, h);
        let sat = SummedAreaTable::<4>::from_fn(w, h, |i, j| {
            let wt = f64::from(luminance(map.pixel(i, j)).max(0.0)) * row_sa[j as usize];
            let d = dirs.dir(i, j).as_dvec3() * wt;
            [wt, d.x, d.y, d.z]
        });
        let regions = subdivide(w, h, self.depth, |r| split(&sat, r));
        Ok(partition("variance-min", serde_json::json!({ "depth": self.depth }), map, &regions, start))
    }
}
