//! Texel-rectangle regions shared by the region-splitting methods (median cut, variance
//! minimization): subdividing, and the light that stands for a region.

use crate::decomposition::{Decomposition, ExtractedLight};
use envmap_sphere::latlong::{TexelDirections, latlong_uv_to_dir};
use envmap_sphere::{EnvMap, luminance};
use glam::{DVec3, Vec2, Vec3};
use scene::DistantLight;
use std::time::Instant;

/// A half-open texel rectangle.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Region {
    pub x0: u32,
    pub y0: u32,
    pub x1: u32,
    pub y1: u32,
}

impl Region {
    /// Angular (width, height) of the region: width along the parallel through its centre.
    pub fn angular_size(&self, w: u32, h: u32) -> (f64, f64) {
        use std::f64::consts::PI;
        let theta_c = PI * f64::from(self.y0 + self.y1) * 0.5 / f64::from(h);
        (
            f64::from(self.x1 - self.x0) * 2.0 * PI / f64::from(w) * theta_c.sin(),
            f64::from(self.y1 - self.y0) * PI / f64::from(h),
        )
    }
}

/// Rounds of splitting for at most `k` lights: the largest n with 2^n <= max(k, 1).
pub(crate) fn depth_for_lights(k: usize) -> u32 {
    usize::BITS - 1 - k.max(1).leading_zeros()
}

/// `depth` rounds of splitting every region with `split` (a region it cannot split stays).
pub(crate) fn subdivide(w: u32, h: u32, depth: u32, split: impl Fn(Region) -> Option<(Region, Region)>) -> Vec<Region> {
    let mut regions = vec![Region { x0: 0, y0: 0, x1: w, y1: h }];
    for _ in 0..depth {
        let mut next = Vec::with_capacity(regions.len() * 2);
        for r in regions {
            match split(r) {
                Some((a, b)) => next.extend([a, b]),
                None => next.push(r),
            }
        }
        regions = next;
    }
    regions
}

/// The light standing for region `r`: energy centroid, region solid angle, mean radiance.
pub(crate) fn region_light(map: &EnvMap, row_sa: &[f64], dirs: &TexelDirections, r: &Region) -> ExtractedLight {
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
        indirect: false,
    }
}

/// The decomposition of a partition into regions: a light per region with power, no remainder.
pub(crate) fn partition(
    method: &str,
    params: serde_json::Value,
    map: &EnvMap,
    regions: &[Region],
    start: Instant,
) -> Decomposition {
    let row_sa = map.row_solid_angles();
    let dirs = TexelDirections::new(map.width(), map.height());
    let lights: Vec<ExtractedLight> = regions
        .iter()
        .map(|r| region_light(map, &row_sa, &dirs, r))
        .filter(|l| l.power().max_element() > 0.0)
        .collect();
    let ambient = EnvMap::constant(map.width(), map.height(), Vec3::ZERO);
    let mut d = Decomposition::new(method, params, map, lights, ambient, true);
    d.time_ms = start.elapsed().as_secs_f64() * 1e3;
    d
}
