//! Centre-surround extraction (paper 000, Section 3): circular filters find compact regions much
//! brighter than their surround; each becomes a cone light covering the filter's inner cap, its
//! pixels are removed, and the search repeats until the last light is dimmer than 2 % of those
//! found (Weber's law). What remains is the ambient map.
//!
//! Filter: inner radius = `inner_ratio` x outer radius, weights +1 inside and -10 in the ring,
//! response divided by the filter's angular extent (read here as the outer diameter, so sizes
//! 4.5-45 degrees are outer radii 2.25-22.5 degrees). Responses integrate luminance x solid angle
//! over spherical caps on the sphere itself, not on a flattened image.
//!
//! Speed (the paper took 0.5-1.5 hours a map): a cap's intersection with a row of the lat-long map
//! is an interval of phi, found in closed form (whole rows near a pole, wrapping at the seam), and
//! summed with per-row prefix sums, so a cap costs one step per row it crosses. Each filter size
//! is evaluated on the pyramid level (exact solid-angle box downsampling) where its inner cap spans
//! about 8 rows, at that level's brightest 10 % of texels. Extraction itself is at full
//! resolution.

use crate::decomposition::{Decomposition, ExtractError, ExtractedLight, LightExtractor};
use envmap_sphere::{EnvMap, luminance};
use glam::{DVec3, Vec3};
use scene::DistantLight;
use std::f64::consts::PI;
use std::time::Instant;

/// Centre-surround light extraction with paper 000's parameters as defaults.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct CenterSurround {
    /// Inner radius / outer radius (paper: 0.75).
    pub inner_ratio: f64,
    /// Weight of the inner disc (paper: +1).
    pub inner_weight: f64,
    /// Weight of the ring (paper: -10).
    pub ring_weight: f64,
    /// Number of filter sizes (paper: 20).
    pub sizes: usize,
    /// Smallest and largest angular extent (outer diameter), degrees (paper: 4.5 and 45).
    pub extent_degrees: (f64, f64),
    /// Fraction of brightest texels considered as filter centres (paper: 0.10).
    pub candidate_fraction: f64,
    /// Stop when a light's intensity is below this fraction of the lights found (paper: 0.02).
    pub weber: f64,
    /// Most lights, whatever the Weber test says (a budget; the paper has none).
    pub max_lights: usize,
}

impl Default for CenterSurround {
    fn default() -> Self {
        Self {
            inner_ratio: 0.75,
            inner_weight: 1.0,
            ring_weight: -10.0,
            sizes: 20,
            extent_degrees: (4.5, 45.0),
            candidate_fraction: 0.10,
            weber: 0.02,
            max_lights: 64,
        }
    }
}

/// Per-row prefix sums of luminance x solid angle, for cap integrals.
struct CapSums {
    w: usize,
    h: usize,
    /// (w + 1) per row
    prefix: Vec<f64>,
    /// per row: (sin theta, cos theta) of the centre
    rows: Vec<(f64, f64)>,
}

impl CapSums {
    fn new(map: &EnvMap) -> Self {
        let (w, h) = (map.width() as usize, map.height() as usize);
        let mut prefix = Vec::with_capacity((w + 1) * h);
        for j in 0..h {
            let sa = map.texel_solid_angle(j as u32);
            let mut acc = 0.0;
            prefix.push(0.0);
            for p in map.row(j as u32) {
                acc += f64::from(luminance(*p).max(0.0)) * sa;
                prefix.push(acc);
            }
        }
        let rows = (0..h).map(|j| (PI * (j as f64 + 0.5) / h as f64).sin_cos()).collect();
        Self { w, h, prefix, rows }
    }

    /// Sum over columns [a, b] (inclusive, a <= b, may exceed the row and wrap) of row j.
    fn row_sum(&self, j: usize, a: i64, b: i64) -> f64 {
        let w = self.w as i64;
        let row = &self.prefix[j * (self.w + 1)..(j + 1) * (self.w + 1)];
        if b - a + 1 >= w {
            return row[self.w];
        }
        let (a, b) = (a.rem_euclid(w), b.rem_euclid(w));
        if a <= b { row[b as usize + 1] - row[a as usize] } else { row[self.w] - row[a as usize] + row[b as usize + 1] }
    }
}

/// The texels of row j (h rows, w columns) whose centres lie within angle `r` of direction
/// (theta_p, phi_p): an inclusive column range, or None.
fn cap_columns(j: usize, w: usize, h: usize, theta_p: f64, phi_p: f64, cos_r: f64) -> Option<(i64, i64)> {
    let (sin_t, cos_t) = (PI * (j as f64 + 0.5) / h as f64).sin_cos();
    cap_columns_at(sin_t, cos_t, w, theta_p.sin_cos(), phi_p, cos_r)
}

/// [`cap_columns`] with the row's and the centre's trigonometry precomputed.
fn cap_columns_at(
    sin_t: f64,
    cos_t: f64,
    w: usize,
    (sin_p, cos_p): (f64, f64),
    phi_p: f64,
    cos_r: f64,
) -> Option<(i64, i64)> {
    let denom = sin_t * sin_p;
    let num = cos_r - cos_t * cos_p;
    let half = if denom <= 1e-12 {
        // p or the row on a pole: the whole row is in or out
        if num <= 0.0 { PI } else { return None }
    } else {
        let c = num / denom;
        if c > 1.0 {
            return None;
        }
        if c <= -1.0 { PI } else { c.acos() }
    };
    let dphi = 2.0 * PI / w as f64;
    let a = ((phi_p - half) / dphi - 0.5).ceil() as i64;
    let b = ((phi_p + half) / dphi - 0.5).floor() as i64;
    (a <= b).then_some((a, b))
}

/// Rows a cap of angle `r` around theta_p can touch.
fn cap_rows(h: usize, theta_p: f64, r: f64) -> std::ops::RangeInclusive<usize> {
    let lo = (((theta_p - r) / PI * h as f64).floor().max(0.0)) as usize;
    let hi = (((theta_p + r) / PI * h as f64).ceil() as usize).min(h - 1);
    lo..=hi
}

impl CapSums {
    fn cap(&self, theta_p: f64, phi_p: f64, r: f64) -> f64 {
        let cos_r = r.cos();
        let p = theta_p.sin_cos();
        cap_rows(self.h, theta_p, r)
            .filter_map(|j| {
                let (sin_t, cos_t) = self.rows[j];
                cap_columns_at(sin_t, cos_t, self.w, p, phi_p, cos_r).map(|(a, b)| self.row_sum(j, a, b))
            })
            .sum()
    }
}

/// The texels of `map` within angle `r` of (theta, phi) at full resolution, their RGB power and
/// their luminance-weighted direction sum.
fn inner_cap(map: &EnvMap, theta: f64, phi: f64, r: f64) -> (Vec<(u32, u32)>, DVec3, DVec3) {
    let (w, h) = (map.width() as usize, map.height() as usize);
    let (mut texels, mut power, mut centroid) = (Vec::new(), DVec3::ZERO, DVec3::ZERO);
    for j in cap_rows(h, theta, r) {
        if let Some((a, b)) = cap_columns(j, w, h, theta, phi, r.cos()) {
            let sa = map.texel_solid_angle(j as u32);
            for i in a..=b.min(a + w as i64 - 1) {
                let i = i.rem_euclid(w as i64) as u32;
                let l = map.pixel(i, j as u32);
                power += l.as_dvec3() * sa;
                centroid += map.texel_dir(i, j as u32).as_dvec3() * (f64::from(luminance(l)) * sa);
                texels.push((i, j as u32));
            }
        }
    }
    (texels, power, centroid)
}

/// (theta, phi) of texel (i, j)'s centre.
fn angles(i: usize, j: usize, w: usize, h: usize) -> (f64, f64) {
    (PI * (j as f64 + 0.5) / h as f64, 2.0 * PI * (i as f64 + 0.5) / w as f64)
}

impl CenterSurround {
    fn check(&self) -> Result<(), ExtractError> {
        let (a, b) = self.extent_degrees;
        let ok = self.inner_ratio > 0.0
            && self.inner_ratio < 1.0
            && self.sizes >= 1
            && a > 0.0
            && b >= a
            && b < 360.0
            && self.candidate_fraction > 0.0
            && self.candidate_fraction <= 1.0
            && self.weber >= 0.0
            && self.max_lights <= 1 << 16;
        if ok {
            Ok(())
        } else {
            Err(ExtractError::Parameter(format!("centre-surround parameters out of range: {self:?}")))
        }
    }

    /// Outer radii of the filter bank, radians, evenly spaced.
    fn radii(&self) -> Vec<f64> {
        let (a, b) = self.extent_degrees;
        (0..self.sizes)
            .map(|k| {
                let t = if self.sizes == 1 { 0.0 } else { k as f64 / (self.sizes - 1) as f64 };
                (a + t * (b - a)).to_radians() * 0.5
            })
            .collect()
    }

    /// The pyramid: for each level, the map and the outer radii evaluated on it (each radius on
    /// the coarsest level where its inner cap still spans 3 rows).
    fn plan(&self, map: &EnvMap) -> Vec<(u32, Vec<f64>)> {
        let mut radii = self.radii();
        radii.sort_by(|a, b| a.total_cmp(b));
        let coarser = |w: u32, h: u32, r: f64| {
            2.0 * PI / f64::from(h) <= r * self.inner_ratio / 3.0 && h > 8 && h.is_multiple_of(2) && w.is_multiple_of(2)
        };
        let (mut w, mut h, mut level) = (map.width(), map.height(), 0u32);
        let mut plan: Vec<(u32, Vec<f64>)> = Vec::new();
        for r in radii {
            while coarser(w, h, r) {
                (w, h, level) = (w / 2, h / 2, level + 1);
            }
            match plan.last_mut() {
                Some((l, rs)) if *l == level => rs.push(r),
                _ => plan.push((level, vec![r])),
            }
        }
        plan
    }
}

/// One pyramid level: its map, cap sums and candidate centres.
struct Level {
    sums: CapSums,
    /// candidate texel centres (theta, phi), fixed at the first iteration
    candidates: Vec<(f64, f64)>,
}

/// A cached filter response.
#[derive(Clone, Copy)]
struct Response {
    value: f64,
    theta: f64,
    phi: f64,
    ro: f64,
    level: usize,
}

fn angle_between(a: (f64, f64), b: (f64, f64)) -> f64 {
    let dir = |(t, p): (f64, f64)| DVec3::new(t.sin() * p.sin(), t.cos(), -t.sin() * p.cos());
    dir(a).dot(dir(b)).clamp(-1.0, 1.0).acos()
}

impl CenterSurround {
    fn response(&self, sums: &CapSums, theta: f64, phi: f64, ro: f64) -> f64 {
        let inner = sums.cap(theta, phi, ro * self.inner_ratio);
        let outer = sums.cap(theta, phi, ro);
        (self.inner_weight * inner + self.ring_weight * (outer - inner)) / (2.0 * ro)
    }

    /// The pyramid of `map` for `plan`: one downsampled map per level.
    fn pyramid(map: &EnvMap, plan: &[(u32, Vec<f64>)]) -> Vec<EnvMap> {
        let mut out = Vec::with_capacity(plan.len());
        let (mut current, mut at) = (map.clone(), 0);
        for (level, _) in plan {
            while at < *level {
                current = current.resize(current.width() / 2, current.height() / 2);
                at += 1;
            }
            out.push(current.clone());
        }
        out
    }

    /// The levels of `map` for `plan`; candidates: each level's brightest fraction of texels.
    fn levels(&self, map: &EnvMap, plan: &[(u32, Vec<f64>)]) -> Vec<Level> {
        Self::pyramid(map, plan)
            .into_iter()
            .map(|current| {
                let (w, h) = (current.width() as usize, current.height() as usize);
                let lum: Vec<f32> = current.pixels().iter().map(|p| luminance(*p)).collect();
                let n = ((lum.len() as f64 * self.candidate_fraction).ceil() as usize).clamp(1, lum.len());
                let mut sorted = lum.clone();
                sorted.select_nth_unstable_by(lum.len() - n, f32::total_cmp);
                let threshold = sorted[lum.len() - n].max(f32::MIN_POSITIVE);
                let candidates = lum
                    .iter()
                    .enumerate()
                    .filter(|(_, y)| **y >= threshold)
                    .map(|(k, _)| angles(k % w, k / w, w, h))
                    .collect();
                Level { sums: CapSums::new(&current), candidates }
            })
            .collect()
    }
}

impl LightExtractor for CenterSurround {
    fn budget(&self) -> Option<usize> {
        Some(self.max_lights)
    }

    fn with_budget(&self, lights: usize) -> Option<Box<dyn LightExtractor>> {
        Some(Box::new(Self { max_lights: lights, ..*self }))
    }

    fn extract(&self, map: &EnvMap) -> Result<Decomposition, ExtractError> {
        self.check()?;
        let start = Instant::now();
        let mut remainder = map.clone();
        remainder.pixels_mut().iter_mut().for_each(|p| *p = p.max(Vec3::ZERO));
        let mut lights: Vec<ExtractedLight> = Vec::new();
        let mut found = 0.0f64;
        let plan = self.plan(map);
        let mut levels = self.levels(&remainder, &plan);
        let mut responses: Vec<Response> = Vec::new();
        for (li, (level, (_, radii))) in levels.iter().zip(&plan).enumerate() {
            for &(theta, phi) in &level.candidates {
                for &ro in radii {
                    let value = self.response(&level.sums, theta, phi, ro);
                    responses.push(Response { value, theta, phi, ro, level: li });
                }
            }
        }
        while lights.len() < self.max_lights {
            let Some(best) =
                responses.iter().filter(|r| r.value > 0.0).max_by(|a, b| a.value.total_cmp(&b.value)).copied()
            else {
                break;
            };
            let (theta, phi, ro) = (best.theta, best.phi, best.ro);
            let ri = ro * self.inner_ratio;
            // Every centre within the inner radius of a point-like source responds the same:
            // re-centre the cap once on its energy centroid (a mean-shift step), then take it.
            let (_, _, centroid) = inner_cap(&remainder, theta, phi, ri);
            let (theta, phi) = match centroid.try_normalize() {
                Some(c) => (c.x.hypot(c.z).atan2(c.y), c.x.atan2(-c.z).rem_euclid(2.0 * PI)),
                None => (theta, phi),
            };
            let (texels, power, _) = inner_cap(&remainder, theta, phi, ri);
            let cos_r = ri.cos();
            let intensity = envmap_sphere::color::luminance_f64(power.to_array());
            if texels.is_empty() || intensity <= 0.0 || (!lights.is_empty() && intensity < self.weber * found) {
                break; // Weber: this light would cast no visible shadow; it stays ambient
            }
            for &(i, j) in &texels {
                remainder.set_pixel(i, j, Vec3::ZERO);
            }
            // Only filters overlapping the removed cap change: refresh those, on updated levels.
            for (level, map) in levels.iter_mut().zip(Self::pyramid(&remainder, &plan)) {
                level.sums = CapSums::new(&map);
            }
            for r in responses.iter_mut() {
                if angle_between((r.theta, r.phi), (theta, phi)) <= r.ro + ri + 2.0 * PI / levels[r.level].sums.h as f64
                {
                    r.value = self.response(&levels[r.level].sums, r.theta, r.phi, r.ro);
                }
            }
            found += intensity;
            let solid_angle = 2.0 * PI * (1.0 - cos_r);
            let direction = DVec3::new(theta.sin() * phi.sin(), theta.cos(), -theta.sin() * phi.cos()).as_vec3();
            lights.push(ExtractedLight {
                light: DistantLight {
                    direction: direction.normalize(),
                    solid_angle: solid_angle as f32,
                    radiance: (power / solid_angle).as_vec3(),
                },
                extent: ri as f32,
            });
        }
        // The books: the remainder plus the lights is the map with negatives clamped (loaded maps
        // have none), exactly, since each light's power is the sum over the texels it removed.
        let params = serde_json::json!({
            "inner_ratio": self.inner_ratio, "inner_weight": self.inner_weight, "ring_weight": self.ring_weight,
            "sizes": self.sizes, "extent_degrees": [self.extent_degrees.0, self.extent_degrees.1],
            "candidate_fraction": self.candidate_fraction, "weber": self.weber, "max_lights": self.max_lights,
        });
        let mut d = Decomposition::new("center-surround", params, map, lights, remainder, true);
        d.time_ms = start.elapsed().as_secs_f64() * 1e3;
        Ok(d)
    }
}
