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
//! about 8 rows, at that level's brightest 10 % of texels (exactly 10 %: ties, as on a flat
//! background, are broken by a hash of the position, so the cost does not depend on them). Extraction itself is at full
//! resolution.

use crate::decomposition::{Decomposition, ExtractError, ExtractedLight, LightExtractor};
use envmap_sphere::{EnvMap, luminance};
use glam::{DVec3, Vec3};
use rayon::prelude::*;
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
    /// The sums of the level that merges `f` x `f` texels of a full-resolution map whose texels
    /// hold luminance x solid angle in `energy` (`w` x `h`, both multiples of `f`).
    fn level(energy: &[f64], w: usize, h: usize, f: usize) -> Self {
        let (lw, lh) = (w / f, h / f);
        let rows = (0..lh).map(|j| (PI * (j as f64 + 0.5) / lh as f64).sin_cos()).collect();
        let mut sums = Self { w: lw, h: lh, prefix: vec![0.0; (lw + 1) * lh], rows };
        sums.update_rows(energy, w, f, 0..=lh - 1);
        sums
    }

    /// Recomputes the level's rows `rows` from the full-resolution `energy`.
    fn update_rows(&mut self, energy: &[f64], w: usize, f: usize, rows: std::ops::RangeInclusive<usize>) {
        for j in rows {
            let row = &mut self.prefix[j * (self.w + 1)..(j + 1) * (self.w + 1)];
            let mut acc = 0.0;
            row[0] = 0.0;
            if f == 1 {
                for (i, e) in energy[j * w..(j + 1) * w].iter().enumerate() {
                    acc += e;
                    row[i + 1] = acc;
                }
                continue;
            }
            for i in 0..self.w {
                for y in j * f..(j + 1) * f {
                    acc += energy[y * w + i * f..y * w + (i + 1) * f].iter().sum::<f64>();
                }
                row[i + 1] = acc;
            }
        }
    }

    /// Mean luminance of each texel of the level (energy over solid angle).
    fn luminance(&self) -> Vec<f32> {
        let mut out = Vec::with_capacity(self.w * self.h);
        for j in 0..self.h {
            let sa = envmap_sphere::latlong::latlong_texel_solid_angle(j as u32, self.w as u32, self.h as u32);
            let row = &self.prefix[j * (self.w + 1)..(j + 1) * (self.w + 1)];
            out.extend(row.windows(2).map(|p| ((p[1] - p[0]) / sa) as f32));
        }
        out
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

/// The indices of the brightest `fraction` of the positive texels of `lum`: exactly
/// ceil(fraction x count) of them, however many tie (a flat background would otherwise make every
/// texel a candidate). Ties are broken by a hash of the index, so tied candidates spread evenly
/// over the map instead of piling up in its first rows.
fn brightest(lum: &[f32], fraction: f64) -> Vec<usize> {
    let n = ((lum.len() as f64 * fraction).ceil() as usize).clamp(1, lum.len());
    let mut idx: Vec<usize> = (0..lum.len()).filter(|&k| lum[k] >= f32::MIN_POSITIVE).collect();
    if idx.len() > n {
        let spread = |k: usize| (k as u64).wrapping_mul(0x9E37_79B9_7F4A_7C15).rotate_left(29);
        idx.select_nth_unstable_by(n - 1, |&a, &b| lum[b].total_cmp(&lum[a]).then(spread(a).cmp(&spread(b))));
        idx.truncate(n);
        idx.sort_unstable();
    }
    idx
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

/// One pyramid level: its cap sums and candidate centres.
struct Level {
    /// texels merged per side
    factor: usize,
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
    /// unit direction of (theta, phi)
    dir: DVec3,
    ro: f64,
    level: usize,
}

/// Unit direction of (theta, phi) in the toolkit's convention.
fn dir_of(theta: f64, phi: f64) -> DVec3 {
    DVec3::new(theta.sin() * phi.sin(), theta.cos(), -theta.sin() * phi.cos())
}

/// Luminance x solid angle of each texel of `map` (negatives as zero).
fn texel_energy(map: &EnvMap) -> Vec<f64> {
    let mut out = Vec::with_capacity(map.pixels().len());
    for j in 0..map.height() {
        let sa = map.texel_solid_angle(j);
        out.extend(map.row(j).iter().map(|p| f64::from(luminance(*p).max(0.0)) * sa));
    }
    out
}

impl CenterSurround {
    fn response(&self, sums: &CapSums, theta: f64, phi: f64, ro: f64) -> f64 {
        let inner = sums.cap(theta, phi, ro * self.inner_ratio);
        let outer = sums.cap(theta, phi, ro);
        (self.inner_weight * inner + self.ring_weight * (outer - inner)) / (2.0 * ro)
    }

    /// The levels of `plan` over the full-resolution `energy`; candidates: each level's
    /// brightest fraction of texels.
    fn levels(&self, energy: &[f64], w: usize, h: usize, plan: &[(u32, Vec<f64>)]) -> Vec<Level> {
        plan.iter()
            .map(|(level, _)| {
                let factor = 1usize << level;
                let sums = CapSums::level(energy, w, h, factor);
                let (lw, lh) = (sums.w, sums.h);
                let candidates = brightest(&sums.luminance(), self.candidate_fraction)
                    .into_iter()
                    .map(|k| angles(k % lw, k / lw, lw, lh))
                    .collect();
                Level { factor, sums, candidates }
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
        let (w, h) = (map.width() as usize, map.height() as usize);
        let mut energy = texel_energy(&remainder);
        let mut levels = self.levels(&energy, w, h, &plan);
        // each response is computed on its own: the same values on any number of threads
        let mut responses: Vec<Response> = Vec::new();
        for (li, (level, (_, radii))) in levels.iter().zip(&plan).enumerate() {
            let found: Vec<Response> = level
                .candidates
                .par_iter()
                .flat_map_iter(|&(theta, phi)| {
                    radii.iter().map(move |&ro| {
                        let value = self.response(&level.sums, theta, phi, ro);
                        Response { value, theta, phi, dir: dir_of(theta, phi), ro, level: li }
                    })
                })
                .collect();
            responses.extend(found);
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
                energy[j as usize * w + i as usize] = 0.0;
            }
            // Only the rows the cap crossed change, and only filters overlapping it: refresh
            // those rows of each level, then those filters.
            let (j0, j1) =
                texels.iter().fold((usize::MAX, 0), |(a, b), &(_, j)| (a.min(j as usize), b.max(j as usize)));
            for level in &mut levels {
                let f = level.factor;
                level.sums.update_rows(&energy, w, f, j0 / f..=j1 / f);
            }
            let centre = dir_of(theta, phi);
            responses.par_iter_mut().for_each(|r| {
                let reach = r.ro + ri + 2.0 * PI / levels[r.level].sums.h as f64;
                if reach >= PI || r.dir.dot(centre) >= reach.cos() {
                    r.value = self.response(&levels[r.level].sums, r.theta, r.phi, r.ro);
                }
            });
            found += intensity;
            let solid_angle = 2.0 * PI * (1.0 - cos_r);
            let direction = centre.as_vec3();
            lights.push(ExtractedLight {
                light: DistantLight {
                    direction: direction.normalize(),
                    solid_angle: solid_angle as f32,
                    radiance: (power / solid_angle).as_vec3(),
                },
                extent: ri as f32,
                indirect: false,
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

#[cfg(test)]
mod tests {
    use super::brightest;

    #[test]
    fn candidates_are_the_fraction_asked_for_whatever_the_ties() {
        let flat = vec![1.0f32; 100_000];
        let c = brightest(&flat, 0.1);
        assert_eq!(c.len(), 10_000);
        // ties spread over the whole map, not piled up in its first rows
        assert!(c.iter().filter(|&&k| k < 50_000).count().abs_diff(5_000) < 500);
        // strictly brighter texels always win over ties
        let mut lum = flat.clone();
        lum[99_999] = 2.0;
        lum[12_345] = 3.0;
        let c = brightest(&lum, 0.1);
        assert!(c.contains(&99_999) && c.contains(&12_345) && c.len() == 10_000);
        // black texels are never candidates
        assert!(brightest(&vec![0.0f32; 1000], 0.1).is_empty());
        let half: Vec<f32> = (0..1000).map(|k| if k % 2 == 0 { 1.0 } else { 0.0 }).collect();
        assert!(brightest(&half, 1.0).iter().all(|k| k % 2 == 0));
    }
}
