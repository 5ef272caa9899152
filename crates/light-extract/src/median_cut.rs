//! Median cut (Debevec, "A Median Cut Algorithm for Light Probe Sampling", 2005): split the map
//! into 2^n regions of equal energy, each time across the region's longer side (widths weighted
//! by cos latitude), and put a light at each region's energy centroid.
//!
//! Energy is luminance x texel solid angle, summed with a summed-area table, so a split costs
//! O(log W) and the whole extraction one pass over the texels for the centroids. Each light is a
//! cone with its region's solid angle and mean radiance: the regions partition the map, so the
//! remainder is zero and light power = map power.

use crate::decomposition::{Decomposition, ExtractError, LightExtractor};
use crate::regions::{Region, partition, subdivide};
use envmap_sphere::{EnvMap, SummedAreaTable};
use std::time::Instant;

/// Median cut with 2^`depth` regions.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct MedianCut {
    /// Number of splitting rounds n: 2^n lights (fewer when regions reach one texel).
    pub depth: u32,
}

impl Default for MedianCut {
    /// n = 5: 32 lights.
    fn default() -> Self {
        Self { depth: 5 }
    }
}

impl MedianCut {
    /// The median cut with the largest power of two of lights not above `k` (at least 1).
    #[must_use]
    pub fn with_lights(k: usize) -> Self {
        Self { depth: crate::regions::depth_for_lights(k) }
    }
}

fn energy(sat: &SummedAreaTable<1>, r: &Region) -> f64 {
    sat.sum(r.x0, r.y0, r.x1, r.y1)[0]
}

/// Splits `r` in two of equal energy across its longer angular side, or `None` for one texel.
fn split(sat: &SummedAreaTable<1>, r: Region, w: u32, h: u32) -> Option<(Region, Region)> {
    let (nx, ny) = (r.x1 - r.x0, r.y1 - r.y0);
    if nx <= 1 && ny <= 1 {
        return None;
    }
    let (width, height) = r.angular_size(w, h);
    let along_x = ny <= 1 || (nx > 1 && width >= height);
    let total = energy(sat, &r);
    // Smallest cut c in (lo, hi) whose first part holds at least half the energy; an empty
    // region is cut in the middle.
    let (lo, hi) = if along_x { (r.x0, r.x1) } else { (r.y0, r.y1) };
    let part = |c: u32| if along_x { energy(sat, &Region { x1: c, ..r }) } else { energy(sat, &Region { y1: c, ..r }) };
    let cut = if total > 0.0 {
        let (mut a, mut b) = (lo + 1, hi - 1);
        while a < b {
            let m = a + (b - a) / 2;
            if part(m) >= 0.5 * total { b = m } else { a = m + 1 }
        }
        // the neighbour below may be closer to one half
        if a > lo + 1 && (part(a - 1) - 0.5 * total).abs() < (part(a) - 0.5 * total).abs() { a - 1 } else { a }
    } else {
        lo + (hi - lo) / 2
    };
    Some(if along_x {
        (Region { x1: cut, ..r }, Region { x0: cut, ..r })
    } else {
        (Region { y1: cut, ..r }, Region { y0: cut, ..r })
    })
}

impl LightExtractor for MedianCut {
    fn budget(&self) -> Option<usize> {
        Some(1 << self.depth)
    }

    fn with_budget(&self, lights: usize) -> Option<Box<dyn LightExtractor>> {
        Some(Box::new(Self::with_lights(lights)))
    }

    fn extract(&self, map: &EnvMap) -> Result<Decomposition, ExtractError> {
        if self.depth > 24 {
            return Err(ExtractError::Parameter(format!("median cut depth {} > 24", self.depth)));
        }
        let start = Instant::now();
        let (w, h) = (map.width(), map.height());
        let sat = SummedAreaTable::luminance_power(map);
        let regions = subdivide(w, h, self.depth, |r| split(&sat, r, w, h));
        Ok(partition("median-cut", serde_json::json!({ "depth": self.depth }), map, &regions, start))
    }
}
