//! Integrals over the sphere: radiant power, irradiance, and luminance statistics.
//!
//! Sums run in f64: a 1024 x 512 map has half a million terms spanning ten orders of magnitude.

use crate::color::luminance;
use crate::envmap::EnvMap;
use crate::latlong::latlong_row_factors;
#[cfg(test)]
use crate::latlong::latlong_texel_vector;
use glam::{DVec3, Vec3};
use rayon::prelude::*;

impl EnvMap {
    /// Radiant power per channel: the integral of radiance over the sphere,
    /// the sum of texel radiance x texel solid angle.
    #[must_use]
    pub fn power(&self) -> [f64; 3] {
        let p = (0..self.height())
            .map(|j| {
                let row: DVec3 = self.row(j).iter().map(|p| p.as_dvec3()).sum();
                row * self.texel_solid_angle(j)
            })
            .sum::<DVec3>();
        p.to_array()
    }

    /// One row of texels.
    #[must_use]
    pub fn row(&self, j: u32) -> &[Vec3] {
        let w = self.width() as usize;
        &self.pixels()[j as usize * w..(j as usize + 1) * w]
    }

    /// Irradiance at a surface with unit normal `normal`: the integral of L max(0, n . w) dw,
    /// by brute force over every texel.
    ///
    /// Each texel contributes L max(0, n . V) with V its exact vector solid angle
    /// ([`latlong_texel_vector`]): exact for texels wholly above the horizon of `normal`.
    #[must_use]
    pub fn irradiance(&self, normal: Vec3) -> Vec3 {
        self.irradiance_many(&[normal])[0]
    }

    /// [`EnvMap::irradiance`] for many normals, in parallel.
    #[must_use]
    pub fn irradiance_many(&self, normals: &[Vec3]) -> Vec<Vec3> {
        let vectors = TexelVectors::new(self.width(), self.height());
        normals
            .par_iter()
            .map(|n| {
                let n = n.as_dvec3();
                let mut sum = DVec3::ZERO;
                for j in 0..self.height() {
                    let row = self.row(j);
                    for (i, l) in row.iter().enumerate() {
                        let c = n.dot(vectors.get(i, j));
                        if c > 0.0 {
                            sum += l.as_dvec3() * c;
                        }
                    }
                }
                sum.as_vec3()
            })
            .collect()
    }

    /// Luminance statistics over the texels.
    #[must_use]
    pub fn luminance_stats(&self) -> LuminanceStats {
        let lum: Vec<f32> = self.pixels().iter().map(|p| luminance(*p)).collect();
        let max = lum.iter().copied().fold(f32::NEG_INFINITY, f32::max);
        let min = lum.iter().copied().fold(f32::INFINITY, f32::min);
        let mean_per_pixel = lum.iter().map(|&y| f64::from(y)).sum::<f64>() / lum.len() as f64;
        let per_sr: f64 = (0..self.height())
            .map(|j| {
                let w = self.width() as usize;
                let row_sum: f64 = lum[j as usize * w..(j as usize + 1) * w].iter().map(|&y| f64::from(y)).sum();
                row_sum * self.texel_solid_angle(j)
            })
            .sum();
        let mut sorted = lum;
        sorted.sort_unstable_by(f32::total_cmp);
        LuminanceStats { max, min, mean_per_pixel, mean_per_sr: per_sr / (4.0 * std::f64::consts::PI), sorted }
    }
}

/// Per-texel vector solid angles of a lat-long grid, factored into a row and a column part.
struct TexelVectors {
    /// per row: (integral of sin^2 theta, integral of cos theta sin theta)
    rows: Vec<(f64, f64)>,
    /// per column: (cos phi0 - cos phi1, sin phi1 - sin phi0, delta phi)
    cols: Vec<(f64, f64, f64)>,
}

impl TexelVectors {
    fn new(width: u32, height: u32) -> Self {
        // latlong_texel_vector factored: x = s2 * cx, y = cs * dphi, z = -s2 * sz.
        let rows = (0..height).map(|j| latlong_row_factors(j, height)).collect();
        let cols = (0..width)
            .map(|i| {
                let w = f64::from(width);
                let tau = 2.0 * std::f64::consts::PI;
                let (p0, p1) = (tau * f64::from(i) / w, tau * f64::from(i + 1) / w);
                (p0.cos() - p1.cos(), p1.sin() - p0.sin(), p1 - p0)
            })
            .collect();
        Self { rows, cols }
    }

    #[inline]
    fn get(&self, i: usize, j: u32) -> DVec3 {
        let (s2, cs) = self.rows[j as usize];
        let (cx, sz, dphi) = self.cols[i];
        DVec3::new(s2 * cx, cs * dphi, -s2 * sz)
    }
}

/// Luminance statistics of a map's texels (per pixel, not solid-angle weighted, except
/// [`LuminanceStats::mean_per_sr`]).
#[derive(Clone, Debug)]
pub struct LuminanceStats {
    /// Largest texel luminance.
    pub max: f32,
    /// Smallest texel luminance.
    pub min: f32,
    /// Mean over texels, each counted once.
    pub mean_per_pixel: f64,
    /// Mean over the sphere: integral of Y d omega / 4 pi.
    pub mean_per_sr: f64,
    sorted: Vec<f32>,
}

impl LuminanceStats {
    /// The `p`-th percentile (0..=100) of texel luminance, nearest rank.
    #[must_use]
    pub fn percentile(&self, p: f64) -> f32 {
        let n = self.sorted.len();
        let rank = ((p.clamp(0.0, 100.0) / 100.0) * n as f64).ceil() as usize;
        self.sorted[rank.clamp(1, n) - 1]
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn factored_texel_vectors_equal_the_direct_formula() {
        let (w, h) = (24, 12);
        let tv = TexelVectors::new(w, h);
        for j in 0..h {
            for i in 0..w {
                let a = DVec3::from_array(latlong_texel_vector(i, j, w, h));
                assert!((tv.get(i as usize, j) - a).length() < 1e-12, "{i} {j}");
            }
        }
    }

    #[test]
    fn percentiles_use_nearest_rank() {
        let map = EnvMap::from_texels(10, 1, |i, _| Vec3::splat(i as f32 + 1.0));
        let s = map.luminance_stats();
        assert!((s.percentile(50.0) - 5.0).abs() < 1e-4);
        assert!((s.percentile(100.0) - 10.0).abs() < 1e-4);
        assert!((s.percentile(0.0) - 1.0).abs() < 1e-4);
        assert!((s.max - 10.0).abs() < 1e-4 && (s.min - 1.0).abs() < 1e-4);
    }
}
