//! The ambient remainder on the specular lobe: the split-sum approximation (Karis 2013). The
//! remainder map is prefiltered on the CPU for GGX lobes at a few roughnesses (filtered
//! importance sampling, the normal and view taken along the mirror direction), and the
//! directional albedo of `scene::brdf`'s GGX lobe is tabulated as a scale and a bias of F0. The
//! shading pass multiplies the two. The map may be signed (a residual of
//! `light_extract::Residual`): nothing is clamped.
//!
//! `ref-tracer`'s `lights` integrator evaluates the same term exactly (MIS of map and BRDF
//! samples); a test measures the approximation against it.

use crate::context::{Gpu, GpuError};
use envmap_sphere::EnvMap;
use glam::{Vec2, Vec3};
use rayon::prelude::*;
use scene::brdf::{Frame, ggx_d, ggx_g2};
use std::f32::consts::{PI, TAU};
use wgpu::util::DeviceExt;

/// The smallest GGX alpha, as `scene::brdf` clamps it.
const MIN_ALPHA: f32 = 1e-3;

/// How the ambient map is prefiltered.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PrefilterSettings {
    /// Width of every prefiltered level in texels (height: half of it).
    pub width: u32,
    /// Roughness levels, spaced evenly in perceptual roughness from 0 (mirror) to 1.
    pub levels: u32,
    /// GGX samples per texel of a rough level.
    pub samples: u32,
    /// Side of the directional-albedo table (cos theta_o x roughness).
    pub table_size: u32,
}

impl Default for PrefilterSettings {
    fn default() -> Self {
        Self { width: 256, levels: 6, samples: 128, table_size: 32 }
    }
}

impl PrefilterSettings {
    /// Largest accepted `width` (a 2:1 level of 4096 x 2048 float texels is 128 MiB).
    pub const MAX_WIDTH: u32 = 4096;
    /// Largest accepted level count and table side.
    pub const MAX_LEVELS: u32 = 16;
}

/// Radical inverse in base 2: the second coordinate of the Hammersley set.
fn radical_inverse(i: u32) -> f32 {
    i.reverse_bits() as f32 * (1.0 / 4_294_967_296.0)
}

fn hammersley(i: u32, n: u32) -> Vec2 {
    Vec2::new((i as f32 + 0.5) / n as f32, radical_inverse(i))
}

/// A GGX half vector about +Z with density D(h) cos theta_h.
fn sample_ggx_d(alpha: f32, u: Vec2) -> Vec3 {
    let a2 = alpha * alpha;
    let cos2 = ((1.0 - u.x) / (1.0 + (a2 - 1.0) * u.x)).clamp(0.0, 1.0);
    let (c, s) = (cos2.sqrt(), (1.0 - cos2).sqrt());
    let (sp, cp) = (TAU * u.y).sin_cos();
    Vec3::new(s * cp, s * sp, c)
}

/// The GGX alpha of a perceptual roughness, as `scene::brdf`.
fn alpha(roughness: f32) -> f32 {
    (roughness * roughness).max(MIN_ALPHA)
}

/// The map prefiltered for GGX lobes: level k is roughness k / (levels - 1), each a lat-long map
/// of the same size.
#[derive(Clone, Debug)]
pub struct PrefilteredMap {
    /// The levels, mirror first.
    pub levels: Vec<EnvMap>,
}

/// Errors of prefiltering.
#[derive(Debug, thiserror::Error)]
pub enum PrefilterError {
    /// A setting is outside its range.
    #[error("prefilter settings: {0}")]
    Settings(String),
}

/// A lat-long pyramid of `map` (level 0 the map), each level half the size of the last,
/// texels averaged by solid angle, down to 4 texels wide.
fn pyramid(map: &EnvMap) -> Vec<EnvMap> {
    let mut out = vec![map.clone()];
    loop {
        let last = out.last().unwrap_or(map);
        let (w, h) = (last.width(), last.height());
        if w < 8 || h < 2 {
            break;
        }
        let (nw, nh) = (w / 2, h / 2);
        let next = EnvMap::from_texels(nw, nh, |i, j| {
            let mut sum = Vec3::ZERO;
            let mut weight = 0.0;
            for dj in 0..2 {
                let sj = (2 * j + dj).min(h - 1);
                let sa = last.texel_solid_angle(sj) as f32;
                for di in 0..2 {
                    sum += last.pixel((2 * i + di).min(w - 1), sj) * sa;
                    weight += sa;
                }
            }
            if weight > 0.0 { sum / weight } else { Vec3::ZERO }
        });
        out.push(next);
    }
    out
}

/// Trilinear lookup in a pyramid at fractional level `lod`.
fn lookup_lod(pyramid: &[EnvMap], dir: Vec3, lod: f32) -> Vec3 {
    let top = (pyramid.len() - 1) as f32;
    let lod = lod.clamp(0.0, top);
    let l0 = lod.floor() as usize;
    let l1 = (l0 + 1).min(pyramid.len() - 1);
    let f = lod - l0 as f32;
    let a = pyramid[l0].lookup(dir);
    if f == 0.0 || l0 == l1 { a } else { a.lerp(pyramid[l1].lookup(dir), f) }
}

impl PrefilteredMap {
    /// Prefilters `map` (any size; may be signed).
    ///
    /// # Errors
    /// [`PrefilterError::Settings`] for a width outside 4..=[`PrefilterSettings::MAX_WIDTH`],
    /// fewer than 2 or more than [`PrefilterSettings::MAX_LEVELS`] levels, or no samples.
    pub fn new(map: &EnvMap, settings: &PrefilterSettings) -> Result<Self, PrefilterError> {
        let s = settings;
        if !(4..=PrefilterSettings::MAX_WIDTH).contains(&s.width) {
            return Err(PrefilterError::Settings(format!(
                "width {} is outside 4..={}",
                s.width,
                PrefilterSettings::MAX_WIDTH
            )));
        }
        if !(2..=PrefilterSettings::MAX_LEVELS).contains(&s.levels) || s.samples == 0 {
            return Err(PrefilterError::Settings(format!(
                "{} levels and {} samples: levels must be 2..={}, samples at least 1",
                s.levels,
                s.samples,
                PrefilterSettings::MAX_LEVELS
            )));
        }
        let pyr = pyramid(map);
        let (w, h) = (s.width, (s.width / 2).max(2));
        // solid angle of a texel of the pyramid's base, on average
        let base_texel = 4.0 * PI / (map.width() as f32 * map.height() as f32);
        // the mirror level: the pyramid level nearest the output's resolution
        let mirror_lod = (map.width() as f32 / w as f32).log2().max(0.0);
        let levels = (0..s.levels)
            .map(|k| {
                let roughness = k as f32 / (s.levels - 1) as f32;
                let a = alpha(roughness);
                let texels: Vec<Vec3> = (0..w * h)
                    .into_par_iter()
                    .map(|t| {
                        let n = envmap_sphere::texel_centre_dir(t % w, t / w, w, h);
                        if k == 0 {
                            return lookup_lod(&pyr, n, mirror_lod);
                        }
                        let frame = Frame::new(n);
                        let (mut sum, mut weight) = (Vec3::ZERO, 0.0f32);
                        for i in 0..s.samples {
                            let hl = sample_ggx_d(a, hammersley(i, s.samples));
                            // n = v: l = 2 (n.h) h - n, pdf(l) = D(h) / 4
                            let cos_l = 2.0 * hl.z * hl.z - 1.0;
                            if cos_l <= 0.0 {
                                continue;
                            }
                            let l = frame.to_world(2.0 * hl.z * hl - Vec3::Z);
                            let pdf = ggx_d(hl, a) / 4.0;
                            // filtered importance sampling: the pyramid level whose texel
                            // covers the sample's share of the sphere
                            let sample_sa = 1.0 / (s.samples as f32 * pdf.max(1e-12));
                            let lod = 0.5 * (sample_sa / base_texel).log2() + 1.0;
                            sum += lookup_lod(&pyr, l, lod.max(mirror_lod)) * cos_l;
                            weight += cos_l;
                        }
                        if weight > 0.0 { sum / weight } else { lookup_lod(&pyr, n, mirror_lod) }
                    })
                    .collect();
                EnvMap::try_new(w, h, texels).map_err(|e| PrefilterError::Settings(e.to_string()))
            })
            .collect::<Result<Vec<_>, _>>()?;
        Ok(Self { levels })
    }

    /// The prefiltered radiance along `dir` for a lobe of perceptual `roughness` (linear
    /// between levels, bilinear within one): what the shader computes.
    #[must_use]
    pub fn lookup(&self, dir: Vec3, roughness: f32) -> Vec3 {
        let top = (self.levels.len() - 1) as f32;
        let x = roughness.clamp(0.0, 1.0) * top;
        let k0 = x.floor() as usize;
        let k1 = (k0 + 1).min(self.levels.len() - 1);
        self.levels[k0].lookup(dir).lerp(self.levels[k1].lookup(dir), x - k0 as f32)
    }
}

/// The directional albedo of `scene::brdf`'s GGX lobe with Schlick's Fresnel, as F0 x scale +
/// bias, tabulated over cos theta_o (columns) and perceptual roughness (rows) at texel centres.
#[derive(Clone, Debug)]
pub struct DfgTable {
    /// Side of the table.
    pub size: u32,
    /// (scale, bias), row-major.
    pub values: Vec<[f32; 2]>,
}

impl DfgTable {
    /// Samples per entry that keep every entry within 1 % of brute force (1024 did not at
    /// grazing angles).
    pub const SAMPLES: u32 = 4096;

    /// Integrates the lobe with `samples` GGX samples per entry.
    ///
    /// # Errors
    /// [`PrefilterError::Settings`] for a size outside 2..=64 or no samples.
    pub fn new(size: u32, samples: u32) -> Result<Self, PrefilterError> {
        if !(2..=64).contains(&size) || samples == 0 {
            return Err(PrefilterError::Settings(format!(
                "table of {size} x {size}, {samples} samples: the side must be 2..=64, samples at least 1"
            )));
        }
        let values = (0..size * size)
            .into_par_iter()
            .map(|t| {
                let cos_o = ((t % size) as f32 + 0.5) / size as f32;
                let roughness = ((t / size) as f32 + 0.5) / size as f32;
                Self::integrate(cos_o, roughness, samples)
            })
            .collect();
        Ok(Self { size, values })
    }

    /// (scale, bias) at one point: the integral over the hemisphere of the lobe times cos
    /// theta_i, split by Schlick's (1 - v.h)^5.
    fn integrate(cos_o: f32, roughness: f32, samples: u32) -> [f32; 2] {
        let a = alpha(roughness);
        let wo = Vec3::new((1.0 - cos_o * cos_o).max(0.0).sqrt(), 0.0, cos_o);
        let (mut scale, mut bias) = (0.0f64, 0.0f64);
        for i in 0..samples {
            let h = sample_ggx_d(a, hammersley(i, samples));
            let voh = wo.dot(h);
            let wi = 2.0 * voh * h - wo;
            if wi.z <= 0.0 || voh <= 0.0 {
                continue;
            }
            // f cos / pdf with pdf = D(h) h.z / (4 v.h): G2 v.h / (cos_o h.z)
            let g = f64::from(ggx_g2(wo, wi, a) * voh / (cos_o * h.z));
            let fc = f64::from((1.0 - voh).powi(5));
            scale += (1.0 - fc) * g;
            bias += fc * g;
        }
        let n = f64::from(samples);
        [(scale / n) as f32, (bias / n) as f32]
    }

    /// Bilinear lookup, clamped at the table's edges: what the shader computes.
    #[must_use]
    pub fn lookup(&self, cos_o: f32, roughness: f32) -> [f32; 2] {
        let n = self.size as f32;
        let x = (cos_o.clamp(0.0, 1.0) * n - 0.5).clamp(0.0, n - 1.0);
        let y = (roughness.clamp(0.0, 1.0) * n - 0.5).clamp(0.0, n - 1.0);
        let (x0, y0) = (x.floor() as u32, y.floor() as u32);
        let (x1, y1) = ((x0 + 1).min(self.size - 1), (y0 + 1).min(self.size - 1));
        let (fx, fy) = (x - x0 as f32, y - y0 as f32);
        let at = |i: u32, j: u32| Vec2::from(self.values[(j * self.size + i) as usize]);
        let v = at(x0, y0).lerp(at(x1, y0), fx).lerp(at(x0, y1).lerp(at(x1, y1), fx), fy);
        v.to_array()
    }
}

/// The prefiltered levels and the table on the GPU, for [`crate::ShadeParams::specular_ambient`].
pub struct SpecularAmbient {
    pub(crate) levels: wgpu::Texture,
    pub(crate) table: wgpu::Texture,
    pub(crate) size: (u32, u32, u32),
    pub(crate) table_size: u32,
    turn: f32,
}

impl SpecularAmbient {
    /// Prefilters `map` and uploads it with the table.
    ///
    /// # Errors
    /// [`GpuError::Failed`] for settings out of range; [`GpuError::TooLarge`] beyond the
    /// adapter's limits.
    pub fn new(gpu: &Gpu, map: &EnvMap, settings: &PrefilterSettings) -> Result<Self, GpuError> {
        let e = |e: PrefilterError| GpuError::Failed(e.to_string());
        let levels = PrefilteredMap::new(map, settings).map_err(e)?;
        let table = DfgTable::new(settings.table_size, DfgTable::SAMPLES).map_err(e)?;
        Self::upload(gpu, &levels, &table)
    }

    /// Uploads prefiltered levels and a table.
    ///
    /// # Errors
    /// [`GpuError::TooLarge`] beyond the adapter's limits.
    pub fn upload(gpu: &Gpu, map: &PrefilteredMap, table: &DfgTable) -> Result<Self, GpuError> {
        let (w, h, n) = (map.levels[0].width(), map.levels[0].height(), map.levels.len() as u32);
        gpu.check_texture(w, h, n)?;
        let texels: Vec<[f32; 4]> =
            map.levels.iter().flat_map(|l| l.pixels().iter().map(|p| p.extend(0.0).to_array())).collect();
        let texture = |label, (w, h, n), format, data: &[u8]| {
            gpu.device.create_texture_with_data(
                &gpu.queue,
                &wgpu::TextureDescriptor {
                    label: Some(label),
                    size: wgpu::Extent3d { width: w, height: h, depth_or_array_layers: n },
                    mip_level_count: 1,
                    sample_count: 1,
                    dimension: wgpu::TextureDimension::D2,
                    format,
                    usage: wgpu::TextureUsages::TEXTURE_BINDING,
                    view_formats: &[],
                },
                wgpu::util::TextureDataOrder::LayerMajor,
                data,
            )
        };
        let levels =
            texture("prefiltered ambient", (w, h, n), wgpu::TextureFormat::Rgba32Float, bytemuck::cast_slice(&texels));
        let t = table.size;
        let table_tex =
            texture("ambient dfg", (t, t, 1), wgpu::TextureFormat::Rg32Float, bytemuck::cast_slice(&table.values));
        Ok(Self { levels, table: table_tex, size: (w, h, n), table_size: t, turn: 0.0 })
    }

    /// Turns the prefiltered map about +Y by `radians`, as `Background::set_turn` turns the
    /// background (the same map turns as one).
    pub fn set_turn(&mut self, radians: f32) {
        self.turn = if radians.is_finite() { radians.rem_euclid(TAU) } else { 0.0 };
    }

    /// The map's turn about +Y, radians in [0, 2 pi).
    #[must_use]
    pub fn turn(&self) -> f32 {
        self.turn
    }
}
