//! The lat-long (equirectangular) parameterization: the one direction convention of the toolkit.
//!
//! Pixel (i, j) has column i from the left and row j from the top (the file's first scanline).
//! Texel centre u = (i + 0.5)/W, v = (j + 0.5)/H; phi = 2 pi u, theta = pi v;
//! direction = (sin theta sin phi, cos theta, -sin theta cos phi). So -Z is the seam u = 0,
//! +X is u = 0.25, +Z the image centre and +Y the top row: Mitsuba 3's `envmap` orientation.

use glam::{Vec2, Vec3};
use std::f32::consts::{PI, TAU};
use std::f64::consts::PI as PI64;

/// Direction for lat-long coordinates `uv` in [0, 1]^2 (any `u` is accepted: it wraps).
#[inline]
#[must_use]
pub fn latlong_uv_to_dir(uv: Vec2) -> Vec3 {
    let (sin_phi, cos_phi) = (TAU * uv.x).sin_cos();
    let (sin_theta, cos_theta) = (PI * uv.y).sin_cos();
    Vec3::new(sin_theta * sin_phi, cos_theta, -sin_theta * cos_phi)
}

/// Lat-long coordinates of a direction (need not be normalized; must not be zero).
///
/// `u` is in [0, 1), `v` in [0, 1]. At the poles (x = z = 0) `u` is 0.5 by the definition of
/// `atan2(0, -0)`: any `u` describes the pole, this one is returned deterministically.
/// Theta uses `atan2`, not `acos`, so directions near the poles keep full precision.
#[inline]
#[must_use]
pub fn latlong_dir_to_uv(dir: Vec3) -> Vec2 {
    let mut u = atan2(dir.x, -dir.z) / TAU;
    if u < 0.0 {
        u += 1.0;
    }
    // -tiny + 1.0 rounds to 1.0, which is the seam again.
    if u >= 1.0 {
        u = 0.0;
    }
    let theta = atan2(dir.x.hypot(dir.z), dir.y);
    Vec2::new(u, (theta / PI).clamp(0.0, 1.0))
}

/// `y.atan2(x)` within 2 f32 ulps of the exact result, without libm's call and range reduction:
/// a minimax polynomial for atan on [0, 1] (absolute error 7e-9 in exact arithmetic) after
/// folding the octants. Zeros, infinities and NaN go to libm, so signed zeros (the poles'
/// u = 0.5) and the edge cases keep its exact values.
#[inline]
#[must_use]
pub fn atan2(y: f32, x: f32) -> f32 {
    const Q: [f32; 8] = [
        -0.333_329_87,
        0.199_904,
        -0.141_860_01,
        0.105_740_34,
        -0.073_669_27,
        0.041_124_493,
        -0.015_134_162,
        0.002_622_651_5,
    ];
    let (ax, ay) = (x.abs(), y.abs());
    let (lo, hi) = (ax.min(ay), ax.max(ay));
    if !(ax.is_finite() && ay.is_finite() && lo > 0.0) {
        return y.atan2(x);
    }
    let a = lo / hi;
    let s = a * a;
    let q = Q.iter().rev().fold(0.0f32, |acc, &c| acc * s + c);
    let mut r = a + a * s * q;
    if ay > ax {
        r = std::f32::consts::FRAC_PI_2 - r;
    }
    if x < 0.0 {
        r = PI - r;
    }
    r.copysign(y)
}

/// The texel (i, j) of a `width` x `height` lat-long map containing `uv` (u = 1 or v = 1 fall in
/// the last column or row).
#[inline]
#[must_use]
pub fn latlong_uv_to_texel(uv: Vec2, width: u32, height: u32) -> (u32, u32) {
    (((uv.x * width as f32) as u32).min(width - 1), ((uv.y * height as f32) as u32).min(height - 1))
}

/// Solid angle per unit area of (u, v): d omega = 2 pi^2 sin(pi v) du dv.
#[inline]
#[must_use]
pub fn latlong_jacobian(uv: Vec2) -> f32 {
    2.0 * PI * PI * (PI * uv.y).sin()
}

/// Exact solid angle of one texel of row `j` in a `width` x `height` map:
/// (2 pi / W)(cos theta_top - cos theta_bottom). The texels of a map sum to 4 pi.
#[inline]
#[must_use]
pub fn latlong_texel_solid_angle(j: u32, width: u32, height: u32) -> f64 {
    let (c0, c1) = row_cos_bounds(j, height);
    2.0 * PI64 / f64::from(width) * (c0 - c1)
}

/// cos theta at the top and bottom edge of row `j` (top > bottom).
#[inline]
#[must_use]
pub fn row_cos_bounds(j: u32, height: u32) -> (f64, f64) {
    let h = f64::from(height);
    ((PI64 * f64::from(j) / h).cos(), (PI64 * f64::from(j + 1) / h).cos())
}

/// The exact vector solid angle of texel (i, j): the integral of the direction over the texel.
///
/// For a texel entirely above the plane with normal `n`, `n . V` is exactly the integral of
/// cos over it, which makes brute-force irradiance exact away from the horizon.
#[must_use]
pub fn latlong_texel_vector(i: u32, j: u32, width: u32, height: u32) -> [f64; 3] {
    let w = f64::from(width);
    let (p0, p1) = (2.0 * PI64 * f64::from(i) / w, 2.0 * PI64 * f64::from(i + 1) / w);
    let (sin2_theta, cos_sin_theta) = latlong_row_factors(j, height);
    [sin2_theta * (p0.cos() - p1.cos()), cos_sin_theta * (p1 - p0), -sin2_theta * (p1.sin() - p0.sin())]
}

/// The row part of [`latlong_texel_vector`] for row `j`: the integrals over the row's theta
/// range of sin^2 theta and of cos theta sin theta.
#[must_use]
pub fn latlong_row_factors(j: u32, height: u32) -> (f64, f64) {
    let h = f64::from(height);
    let (t0, t1) = (PI64 * f64::from(j) / h, PI64 * f64::from(j + 1) / h);
    let a = |t: f64| (t - t.sin() * t.cos()) * 0.5;
    (a(t1) - a(t0), 0.5 * (t1.sin().powi(2) - t0.sin().powi(2)))
}

/// Texel-centre directions of a `width` x `height` map without per-texel trigonometry: the
/// direction is separable into a row part (sin theta, cos theta) and a column part
/// (sin phi, cos phi).
#[derive(Clone, Debug)]
pub struct TexelDirections {
    rows: Vec<(f32, f32)>,
    cols: Vec<(f32, f32)>,
}

impl TexelDirections {
    /// Tables for a `width` x `height` map.
    #[must_use]
    pub fn new(width: u32, height: u32) -> Self {
        let rows = (0..height).map(|j| (PI * (j as f32 + 0.5) / height as f32).sin_cos()).collect();
        let cols = (0..width).map(|i| (TAU * (i as f32 + 0.5) / width as f32).sin_cos()).collect();
        Self { rows, cols }
    }

    /// Direction of the centre of texel (i, j); equals `latlong_uv_to_dir` at the centre.
    #[inline]
    #[must_use]
    pub fn dir(&self, i: u32, j: u32) -> Vec3 {
        let (st, ct) = self.rows[j as usize];
        let (sp, cp) = self.cols[i as usize];
        Vec3::new(st * sp, ct, -st * cp)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn named_directions_match_the_convention() {
        let close = |a: Vec3, b: Vec3| (a - b).length() < 1e-6;
        assert!(close(latlong_uv_to_dir(Vec2::new(0.0, 0.5)), Vec3::NEG_Z));
        assert!(close(latlong_uv_to_dir(Vec2::new(0.25, 0.5)), Vec3::X));
        assert!(close(latlong_uv_to_dir(Vec2::new(0.5, 0.5)), Vec3::Z));
        assert!(close(latlong_uv_to_dir(Vec2::new(0.75, 0.5)), Vec3::NEG_X));
        assert!(close(latlong_uv_to_dir(Vec2::new(0.3, 0.0)), Vec3::Y));
        assert!(close(latlong_uv_to_dir(Vec2::new(0.3, 1.0)), Vec3::NEG_Y));
    }

    #[test]
    fn texel_direction_tables_match_the_formula() {
        let t = TexelDirections::new(64, 32);
        for (i, j) in [(0, 0), (63, 31), (17, 9), (32, 16)] {
            let d = latlong_uv_to_dir(Vec2::new((i as f32 + 0.5) / 64.0, (j as f32 + 0.5) / 32.0));
            assert!((t.dir(i, j) - d).length() < 1e-6);
        }
    }

    #[test]
    fn texel_vector_length_is_below_solid_angle_and_points_at_centre() {
        let (w, h) = (64, 32);
        for j in [0, 5, 15, 16, 31] {
            for i in [0, 17, 63] {
                let v = latlong_texel_vector(i, j, w, h);
                let len = (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt();
                let sa = latlong_texel_solid_angle(j, w, h);
                assert!(len <= sa * (1.0 + 1e-12) && len > 0.99 * sa, "{len} {sa}");
                let c = latlong_uv_to_dir(Vec2::new((i as f32 + 0.5) / 64.0, (j as f32 + 0.5) / 32.0));
                let d = Vec3::new(v[0] as f32, v[1] as f32, v[2] as f32).normalize();
                // a pole texel's centroid sits at 2/3 of its row, not at its centre
                assert!(c.dot(d) > 0.9995, "{c} {d}");
            }
        }
    }
}
