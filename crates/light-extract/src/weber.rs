//! No visible shadow dropped (ours, `<method>+weber`): every compact source whose unshadowed
//! light is a visible part of some receiver's irradiance gets a light of its own, whatever the
//! inner method's importance split decided.
//!
//! Weber's law (paper 000 stops extraction with it): a change of light below about 2 % goes
//! unseen, so a shadow that takes away more than 2 % of a receiver's irradiance is visible. A
//! method may still fold a sun into a wide cone or the ambient term (paper 001's split gives a
//! sun on the map's top row, ~4 % of its power, no EnvDirect): its shadow vanishes.
//!
//! [`compact_sources`] finds sources: connected regions of texels (8-neighbours, across the seam
//! and around each pole) brighter than [`Weber::contrast`] x the map's mean radiance; a region
//! wider than [`Weber::max_half_angle`] is searched again at 4 x the threshold for compact
//! cores. A source is visible when, for some receiver normal n (the source's own direction and
//! [`Weber::normals`] directions spread over the sphere), its irradiance exceeds
//! [`Weber::fraction`] of the whole map's irradiance at n (brute force on a 64 x 32 copy).
//!
//! [`Weber`] runs the inner method; each visible source that its lights do not stand for (lights
//! whose axes lie within the source, whose cones are not much wider than it, and which carry at
//! least half its power: [`COVERED_SHARE`]) is taken out of the map
//! and given a light (its texels' power, as the cone of equal solid angle at their centroid), and
//! the inner method runs again on the rest with the budget that is left: the books still balance
//! and the count stays within the budget.

use crate::decomposition::{Decomposition, ExtractError, ExtractedLight, LightExtractor};
use envmap_sphere::{EnvMap, luminance};
use glam::{DVec3, Vec3};
use scene::DistantLight;
use std::borrow::Cow;
use std::f64::consts::PI;
use std::time::Instant;

/// A compact source of a map: a connected bright region.
#[derive(Clone, Debug, PartialEq)]
pub struct CompactSource {
    /// Its texels (i, j).
    pub texels: Vec<(u32, u32)>,
    /// Luminance-weighted mean direction (unit).
    pub direction: Vec3,
    /// Largest angle from `direction` to a texel centre, radians.
    pub extent: f32,
    /// Solid angle of its texels, steradians.
    pub solid_angle: f64,
    /// RGB power: radiance x solid angle summed over its texels.
    pub power: DVec3,
    /// Largest share of a receiver's irradiance it gives, over the normals tried.
    pub irradiance_fraction: f64,
}

impl CompactSource {
    /// The cone light standing for it: at its direction, of its solid angle and power.
    #[must_use]
    pub fn light(&self) -> ExtractedLight {
        let solid_angle = self.solid_angle.clamp(1e-12, 4.0 * PI);
        ExtractedLight {
            light: DistantLight {
                direction: self.direction,
                solid_angle: solid_angle as f32,
                radiance: (self.power / solid_angle).as_vec3(),
            },
            extent: self.extent,
            indirect: false,
        }
    }

    /// Whether `light` is part of this source: its axis within the source (plus a texel) and its
    /// cone no wider than twice the source (plus a texel).
    #[must_use]
    pub fn is_covered_by(&self, light: &DistantLight, texel_angle: f32) -> bool {
        let angle = light.direction.dot(self.direction).clamp(-1.0, 1.0).acos();
        angle <= self.extent + texel_angle && light.half_angle() <= 2.0 * self.extent + texel_angle
    }

    /// The share of its luminous power carried by `lights` that are part of it (a method may
    /// split a bright source into several small lights; their shadows are still the source's).
    #[must_use]
    pub fn covered_share(&self, lights: &[ExtractedLight], texel_angle: f32) -> f64 {
        let own = envmap_sphere::color::luminance_f64(self.power.to_array());
        let covered: f64 = lights
            .iter()
            .filter(|l| self.is_covered_by(&l.light, texel_angle))
            .map(|l| f64::from(luminance(l.power())))
            .sum();
        if own > 0.0 { covered / own } else { 1.0 }
    }
}

/// A source is lit by lights of its own when they carry at least this share of its power.
pub const COVERED_SHARE: f64 = 0.5;

/// `<method>+weber`: `inner`'s lights, plus a light of its own for every compact source whose
/// shadow would be visible.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Weber<E> {
    /// The method whose lights are kept.
    pub inner: E,
    /// A source is visible above this fraction of a receiver's irradiance (Weber: 0.02).
    pub fraction: f64,
    /// Texels brighter than this multiple of the map's mean radiance can form a source.
    pub contrast: f64,
    /// Regions wider than this half-angle (radians) are not compact: searched again for cores.
    pub max_half_angle: f64,
    /// Receiver normals tried, spread evenly over the sphere (plus each source's direction).
    pub normals: usize,
}

impl<E> Weber<E> {
    /// `inner` with Weber's 2 %, contrast 16, sources up to 10 degrees, 256 normals.
    pub fn new(inner: E) -> Self {
        Self { inner, fraction: 0.02, contrast: 16.0, max_half_angle: 10f64.to_radians(), normals: 256 }
    }

    fn check(&self) -> Result<(), ExtractError> {
        let ok = self.fraction.is_finite()
            && self.fraction >= 0.0
            && self.contrast.is_finite()
            && self.contrast > 0.0
            && self.max_half_angle > 0.0
            && self.max_half_angle <= PI
            && self.normals <= 1 << 16;
        if ok { Ok(()) } else { Err(ExtractError::Parameter("weber parameters out of range".into())) }
    }
}

/// Connected components (8-neighbours, wrapping at the seam, joined around each pole) of the
/// texels in `mask` among `candidates`.
fn components(map: &EnvMap, candidates: &[usize], mask: &mut [bool]) -> Vec<Vec<usize>> {
    let (w, h) = (map.width() as usize, map.height() as usize);
    let mut out = Vec::new();
    let mut stack = Vec::new();
    for &start in candidates {
        if !mask[start] {
            continue;
        }
        mask[start] = false;
        stack.push(start);
        let mut comp = Vec::new();
        while let Some(k) = stack.pop() {
            comp.push(k);
            let (i, j) = ((k % w) as i64, (k / w) as i64);
            let mut visit = |ni: i64, nj: i64| {
                let (ni, nj) = if nj < 0 || nj >= h as i64 {
                    // across the pole: the same row, half a turn round
                    (ni + w as i64 / 2, nj.clamp(0, h as i64 - 1))
                } else {
                    (ni, nj)
                };
                let n = nj as usize * w + ni.rem_euclid(w as i64) as usize;
                if mask[n] {
                    mask[n] = false;
                    stack.push(n);
                }
            };
            for dj in -1..=1 {
                for di in -1..=1 {
                    if di != 0 || dj != 0 {
                        visit(i + di, j + dj);
                    }
                }
            }
        }
        out.push(comp);
    }
    out
}

/// The texels of a 64 x 32 copy of `map`: direction and luminance x solid angle, the black ones
/// left out.
fn coarse_texels(map: &EnvMap) -> Vec<(DVec3, f64)> {
    let (w, h) = (map.width().min(64), map.height().min(32));
    let small = map.resize(w, h);
    (0..h)
        .flat_map(|j| {
            let small = &small;
            (0..w).map(move |i| {
                let y = f64::from(luminance(small.pixel(i, j))).max(0.0);
                (small.texel_dir(i, j).as_dvec3(), y * small.texel_solid_angle(j))
            })
        })
        .filter(|(_, e)| *e > 0.0)
        .collect()
}

/// Irradiance (luminance) at normal `n` from `texels`, brute force.
fn irradiance(texels: &[(DVec3, f64)], n: DVec3) -> f64 {
    texels.iter().map(|(d, e)| e * n.dot(*d).max(0.0)).sum()
}

/// `n` unit vectors spread evenly over the sphere (a Fibonacci lattice).
fn fibonacci(n: usize) -> Vec<DVec3> {
    let golden = PI * (3.0 - 5f64.sqrt());
    (0..n)
        .map(|k| {
            let y = 1.0 - (k as f64 + 0.5) / n as f64 * 2.0;
            let r = (1.0 - y * y).max(0.0).sqrt();
            let phi = golden * k as f64;
            DVec3::new(r * phi.cos(), y, r * phi.sin())
        })
        .collect()
}

impl<E> Weber<E> {
    /// The compact sources of `map` whose light exceeds [`Weber::fraction`] of some receiver's
    /// irradiance, brightest share first.
    #[must_use]
    pub fn visible_sources(&self, map: &EnvMap) -> Vec<CompactSource> {
        let mut sources = compact_sources(map, self.contrast, self.max_half_angle);
        if sources.is_empty() {
            return sources;
        }
        let normals = fibonacci(self.normals);
        let coarse = coarse_texels(map);
        let total: Vec<f64> = normals.iter().map(|n| irradiance(&coarse, *n)).collect();
        for s in &mut sources {
            let own = s.direction.as_dvec3();
            let own_total = irradiance(&coarse, own);
            let texels: Vec<(DVec3, f64)> = s
                .texels
                .iter()
                .map(|&(i, j)| {
                    let y = f64::from(luminance(map.pixel(i, j))).max(0.0);
                    (map.texel_dir(i, j).as_dvec3(), y * map.texel_solid_angle(j))
                })
                .collect();
            let share = |n: DVec3, e_all: f64| {
                let e = irradiance(&texels, n);
                if e_all > 0.0 { (e / e_all).min(1.0) } else { 0.0 }
            };
            s.irradiance_fraction = normals
                .iter()
                .zip(&total)
                .map(|(n, t)| share(*n, *t))
                .chain(std::iter::once(share(own, own_total)))
                .fold(0.0, f64::max);
        }
        sources.retain(|s| s.irradiance_fraction > self.fraction);
        sources.sort_by(|a, b| b.irradiance_fraction.total_cmp(&a.irradiance_fraction));
        sources
    }
}

/// The compact sources of `map`: connected regions brighter than `contrast` x its mean
/// radiance (luminance, solid-angle weighted); regions wider than `max_half_angle` are searched
/// again at 4 x the threshold. Their irradiance fraction is left at 0.
#[must_use]
pub fn compact_sources(map: &EnvMap, contrast: f64, max_half_angle: f64) -> Vec<CompactSource> {
    let (w, h) = (map.width() as usize, map.height() as usize);
    let lum: Vec<f32> = map.pixels().iter().map(|p| luminance(*p).max(0.0)).collect();
    let mean = envmap_sphere::color::luminance_f64(map.power()) / (4.0 * PI);
    if !(mean > 0.0 && mean.is_finite()) {
        return Vec::new();
    }
    let mut mask = vec![false; w * h];
    let mut out = Vec::new();
    let mut threshold = contrast * mean;
    // the first round looks at every texel, each later one only inside the regions that were
    // too wide the round before
    let mut candidates: Vec<usize> = (0..w * h).filter(|&k| f64::from(lum[k]) > threshold).collect();
    while !candidates.is_empty() && threshold.is_finite() {
        for &k in &candidates {
            mask[k] = true;
        }
        let mut wide = Vec::new();
        for comp in components(map, &candidates, &mut mask) {
            let source = describe(map, &comp);
            if f64::from(source.extent) <= max_half_angle {
                out.push(source);
            } else {
                wide.extend(comp);
            }
        }
        threshold *= 4.0;
        candidates = wide.into_iter().filter(|&k| f64::from(lum[k]) > threshold).collect();
    }
    out
}

fn describe(map: &EnvMap, comp: &[usize]) -> CompactSource {
    let w = map.width() as usize;
    let texels: Vec<(u32, u32)> = comp.iter().map(|&k| ((k % w) as u32, (k / w) as u32)).collect();
    let (mut power, mut centroid, mut solid_angle) = (DVec3::ZERO, DVec3::ZERO, 0.0);
    for &(i, j) in &texels {
        let sa = map.texel_solid_angle(j);
        let l = map.pixel(i, j).as_dvec3().max(DVec3::ZERO);
        power += l * sa;
        solid_angle += sa;
        centroid += map.texel_dir(i, j).as_dvec3() * (f64::from(luminance(l.as_vec3())) * sa);
    }
    let direction = centroid.try_normalize().unwrap_or_else(|| {
        let (i, j) = texels[0];
        map.texel_dir(i, j).as_dvec3()
    });
    let extent = texels
        .iter()
        .map(|&(i, j)| map.texel_dir(i, j).as_dvec3().dot(direction).clamp(-1.0, 1.0).acos())
        .fold(0.0, f64::max);
    CompactSource {
        texels,
        direction: direction.as_vec3(),
        extent: extent as f32,
        solid_angle,
        power,
        irradiance_fraction: 0.0,
    }
}

impl<E: LightExtractor> LightExtractor for Weber<E> {
    fn extract(&self, map: &EnvMap) -> Result<Decomposition, ExtractError> {
        self.check()?;
        let start = Instant::now();
        let first = self.inner.extract(map)?;
        let texel_angle = (PI / f64::from(map.height())) as f32;
        let mut missing: Vec<CompactSource> = self
            .visible_sources(map)
            .into_iter()
            .filter(|s| s.covered_share(&first.lights, texel_angle) < COVERED_SHARE)
            .collect();
        let budget = self.inner.budget();
        if let Some(k) = budget {
            missing.truncate(k);
        }
        let mut d = if missing.is_empty() {
            first
        } else {
            let mut rest = map.clone();
            for s in &missing {
                for &(i, j) in &s.texels {
                    rest.set_pixel(i, j, Vec3::ZERO);
                }
            }
            let left = budget.map(|k| k - missing.len());
            let mut d = match left {
                // the sources take the whole budget: the rest of the map is ambient
                Some(0) => {
                    Decomposition::new(&first.method, first.params.clone(), &rest, Vec::new(), rest.clone(), true)
                }
                Some(left) => match self.inner.with_budget(left) {
                    Some(e) => e.extract(&rest)?,
                    None => self.inner.extract(&rest)?,
                },
                None => self.inner.extract(&rest)?,
            };
            d.lights.extend(missing.iter().map(CompactSource::light));
            d.map_power = map.power();
            d
        };
        let added: Vec<serde_json::Value> = missing
            .iter()
            .map(|s| {
                serde_json::json!({
                    "direction": s.direction.to_array(), "solid_angle": s.solid_angle,
                    "irradiance_fraction": s.irradiance_fraction,
                })
            })
            .collect();
        d.params = serde_json::json!({
            "inner": d.params, "fraction": self.fraction, "contrast": self.contrast,
            "max_half_angle": self.max_half_angle, "normals": self.normals, "added": added,
        });
        d.method = format!("{}+weber", d.method);
        d.time_ms = start.elapsed().as_secs_f64() * 1e3;
        Ok(d)
    }

    fn budget(&self) -> Option<usize> {
        self.inner.budget()
    }

    fn with_budget(&self, lights: usize) -> Option<Box<dyn LightExtractor>> {
        let inner = self.inner.with_budget(lights)?;
        Some(Box::new(Weber {
            inner,
            fraction: self.fraction,
            contrast: self.contrast,
            max_half_angle: self.max_half_angle,
            normals: self.normals,
        }))
    }

    fn modelled_map<'m>(&self, map: &'m EnvMap) -> Cow<'m, EnvMap> {
        self.inner.modelled_map(map)
    }
}
