//! Median cut (Debevec, "A Median Cut Algorithm for Light Probe Sampling", 2005): split the map
//! into 2^n regions of equal energy, each time across the region's longer side (widths weighted
//! by cos latitude), and put a light at each region's energy centroid.
//!
//! Energy is luminance x texel solid angle, summed with a summed-area table, so a split costs
//! O(log W) and the whole extraction one pass over the texels for the centroids. Each light is a
//! cone with its region's solid angle and mean radiance: the regions partition the map, so the
//! remainder is zero and light power = map power.

use crate::decomposition::{Decomposition, ExtractError, ExtractedLight, LightExtractor};
use envmap_sphere::latlong::{TexelDirections, latlong_uv_to_dir};
use envmap_sphere::{EnvMap, SummedAreaTable, luminance};
use glam::{DVec3, Vec2, Vec3};
use scene::DistantLight;
use std::f64::consts::PI;
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
        Self { depth: usize::BITS - 1 - k.max(1).leading_zeros() }
    }
}

/// A half-open texel rectangle.
#[derive(Clone, Copy, Debug)]
struct Region {
    x0: u32,
    y0: u32,
    x1: u32,
    y1: u32,
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
    let theta_c = PI * f64::from(r.y0 + r.y1) * 0.5 / f64::from(h);
    let width = f64::from(nx) * 2.0 * PI / f64::from(w) * theta_c.sin();
    let height = f64::from(ny) * PI / f64::from(h);
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

/// The light standing for region `r`: energy centroid, region solid angle, mean radiance.
fn region_light(map: &EnvMap, row_sa: &[f64], dirs: &TexelDirections, r: &Region) -> ExtractedLight {
    let (mut centroid, mut power, mut solid_angle) = (DVec3::ZERO, DVec3::ZERO, 0.0);
    for j in r.y0..r.y1 {
        let sa = row_sa[j as usize];
        solid_angle += sa * f64::from(r.x1 - r.x0);
        let (mut row_power, mut row_centroid) = (Vec3::ZERO, Vec3::ZERO);
        for (i, l) in (r.x0..r.x1).zip(&map.row(j)[r.x0 as usize..r.x1 as usize]) {
            row_power += *l;
            row_centroid += dirs.dir(i, j) * luminance(*l).max(0.0);
        }
        power += row_power.as_dvec3() * sa;
        centroid += row_centroid.as_dvec3() * sa;
    }
    let (w, h) = (map.width() as f32, map.height() as f32);
    let uv = |x: u32, y: u32| Vec2::new(x as f32 / w, y as f32 / h);
    let centre = latlong_uv_to_dir((uv(r.x0, r.y0) + uv(r.x1, r.y1)) * 0.5);
    let direction = centroid.as_vec3().try_normalize().unwrap_or(centre);
    let (xm, ym) = ((r.x0 + r.x1) / 2, (r.y0 + r.y1) / 2);
    let extent =
        [(r.x0, r.y0), (r.x1, r.y0), (r.x0, r.y1), (r.x1, r.y1), (xm, r.y0), (xm, r.y1), (r.x0, ym), (r.x1, ym)]
            .iter()
            .map(|&(x, y)| direction.angle_between(latlong_uv_to_dir(uv(x, y))))
            .fold(0.0f32, f32::max);
    ExtractedLight {
        light: DistantLight {
            direction,
            solid_angle: solid_angle as f32,
            radiance: (power / solid_angle.max(1e-300)).as_vec3(),
        },
        extent,
    }
}

impl LightExtractor for MedianCut {
    fn extract(&self, map: &EnvMap) -> Result<Decomposition, ExtractError> {
        if self.depth > 24 {
            return Err(ExtractError::Parameter(format!("median cut depth {} > 24", self.depth)));
        }
        let start = Instant::now();
        let (w, h) = (map.width(), map.height());
        let sat = SummedAreaTable::luminance_power(map);
        let mut regions = vec![Region { x0: 0, y0: 0, x1: w, y1: h }];
        for _ in 0..self.depth {
            let mut next = Vec::with_capacity(regions.len() * 2);
            for r in regions {
                match split(&sat, r, w, h) {
                    Some((a, b)) => next.extend([a, b]),
                    None => next.push(r),
                }
            }
            regions = next;
        }
        let row_sa = map.row_solid_angles();
        let dirs = TexelDirections::new(w, h);
        let lights: Vec<ExtractedLight> = regions
            .iter()
            .map(|r| region_light(map, &row_sa, &dirs, r))
            .filter(|l| l.power().max_element() > 0.0)
            .collect();
        let ambient = EnvMap::constant(w, h, Vec3::ZERO);
        let params = serde_json::json!({ "depth": self.depth });
        let mut d = Decomposition::new("median-cut", params, map, lights, ambient, true);
        d.time_ms = start.elapsed().as_secs_f64() * 1e3;
        Ok(d)
    }
}
