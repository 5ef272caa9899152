//! Order-2 (9-coefficient) real spherical harmonics: projection of a map and the
//! Ramamoorthy-Hanrahan irradiance ("An Efficient Representation for Irradiance Environment
//! Maps", SIGGRAPH 2001).
//!
//! The basis is the usual real SH polynomials evaluated on world (x, y, z), in the order
//! l=0; l=1 m=-1,0,1; l=2 m=-2..2 — the same basis as three.js's `SphericalHarmonics3`.

use crate::envmap::EnvMap;
use glam::{DVec3, Vec3};

/// 9 RGB coefficients of a function on the sphere.
#[derive(Clone, Copy, Debug, PartialEq, Default)]
pub struct Sh9 {
    /// Coefficients in the order l=0; l=1 m=-1,0,1; l=2 m=-2..2.
    pub coeffs: [Vec3; 9],
}

/// Convolution of the clamped cosine with each band, A_l: pi, 2 pi / 3, pi / 4.
pub const IRRADIANCE_BAND_FACTORS: [f32; 3] =
    [std::f32::consts::PI, 2.0 * std::f32::consts::PI / 3.0, std::f32::consts::PI / 4.0];

/// The 9 real SH basis functions at unit direction `d`.
#[must_use]
pub fn sh9_basis(d: Vec3) -> [f32; 9] {
    let (x, y, z) = (d.x, d.y, d.z);
    [
        0.282_094_8,
        0.488_602_5 * y,
        0.488_602_5 * z,
        0.488_602_5 * x,
        1.092_548_4 * x * y,
        1.092_548_4 * y * z,
        0.315_391_57 * (3.0 * z * z - 1.0),
        1.092_548_4 * x * z,
        0.546_274_2 * (x * x - y * y),
    ]
}

/// Band l of coefficient index k.
const BAND: [usize; 9] = [0, 1, 1, 1, 2, 2, 2, 2, 2];

impl Sh9 {
    /// Projects a map onto the basis: c_k = sum over texels of L Y_k(w_centre) d omega.
    #[must_use]
    pub fn project(map: &EnvMap) -> Self {
        let mut acc = [DVec3::ZERO; 9];
        if map.pixels().iter().all(|p| *p == Vec3::ZERO) {
            return Self::default();
        }
        let dirs = crate::latlong::TexelDirections::new(map.width(), map.height());
        for j in 0..map.height() {
            let sa = map.texel_solid_angle(j);
            for (i, l) in map.row(j).iter().enumerate() {
                if *l == Vec3::ZERO {
                    continue;
                }
                let basis = sh9_basis(dirs.dir(i as u32, j));
                let l = l.as_dvec3() * sa;
                for (a, b) in acc.iter_mut().zip(basis) {
                    *a += l * f64::from(b);
                }
            }
        }
        Self { coeffs: acc.map(|c| c.as_vec3()) }
    }

    /// The function value sum c_k Y_k(d).
    #[must_use]
    pub fn eval(&self, d: Vec3) -> Vec3 {
        sh9_basis(d).iter().zip(&self.coeffs).map(|(b, c)| *c * *b).sum()
    }

    /// Irradiance for unit normal `n`: sum A_l c_k Y_k(n) (Ramamoorthy and Hanrahan).
    #[must_use]
    pub fn irradiance(&self, n: Vec3) -> Vec3 {
        sh9_basis(n).iter().zip(self.irradiance_coefficients()).map(|(b, c)| c * *b).sum()
    }

    /// The coefficients of the irradiance function, A_l c_k: irradiance(n) = sum of these times
    /// Y_k(n). Renderers upload these (the GPU shading pass does).
    #[must_use]
    pub fn irradiance_coefficients(&self) -> [Vec3; 9] {
        std::array::from_fn(|k| self.coeffs[k] * IRRADIANCE_BAND_FACTORS[BAND[k]])
    }

    /// The function turned by `rotation`: g(d) = f(rotation⁻¹ d), as a map turned by it projects
    /// to. Exact: a band-limited function's rotation stays in its bands, and its projection is
    /// integrated by the icosahedron's 12 vertices, a spherical 5-design (exact for the degree-4
    /// products of two order-2 polynomials).
    #[must_use]
    pub fn rotated(&self, rotation: glam::Quat) -> Self {
        let inverse = rotation.inverse();
        let weight = 4.0 * std::f64::consts::PI / 12.0;
        let mut acc = [DVec3::ZERO; 9];
        for v in icosahedron() {
            let g = self.eval(inverse * v).as_dvec3();
            for (a, b) in acc.iter_mut().zip(sh9_basis(v)) {
                *a += g * f64::from(b) * weight;
            }
        }
        Self { coeffs: acc.map(|c| c.as_vec3()) }
    }

    /// A map whose texels hold this function at their centres (a band-limited test map).
    #[must_use]
    pub fn to_map(&self, width: u32, height: u32) -> EnvMap {
        EnvMap::from_fn(width, height, |d| self.eval(d))
    }
}

/// The icosahedron's 12 unit vertices: (0, ±1, ±φ) and their cyclic permutations, normalized.
fn icosahedron() -> [Vec3; 12] {
    let phi = (1.0 + 5.0f32.sqrt()) / 2.0;
    let mut out = [Vec3::ZERO; 12];
    let mut k = 0;
    for a in [-1.0, 1.0] {
        for b in [-phi, phi] {
            for v in [Vec3::new(0.0, a, b), Vec3::new(a, b, 0.0), Vec3::new(b, 0.0, a)] {
                out[k] = v.normalize();
                k += 1;
            }
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn rotation_matches_the_projection_of_the_turned_map() {
        // a band-limited function with every coefficient set, turned by whole texel columns:
        // the turned map is exact, its projection the rotated coefficients
        let sh =
            Sh9 { coeffs: std::array::from_fn(|k| Vec3::new(1.0 + k as f32, 0.5 - 0.3 * k as f32, (k as f32).sin())) };
        let (w, h) = (256, 128);
        let map = sh.to_map(w, h);
        for columns in [1u32, 37, 128] {
            let turned = EnvMap::from_texels(w, h, |i, j| map.pixel((i + w - columns) % w, j));
            // lat-long u grows with atan2(x, -z): a column is a turn of -2 pi / w about +Y
            let angle = -std::f32::consts::TAU * columns as f32 / w as f32;
            let want = Sh9::project(&turned);
            let got = Sh9::project(&map).rotated(glam::Quat::from_rotation_y(angle));
            for (g, t) in got.coeffs.iter().zip(want.coeffs) {
                assert!((*g - t).abs().max_element() < 2e-3 * (1.0 + t.abs().max_element()), "{columns}: {g} vs {t}");
            }
        }
    }

    #[test]
    fn rotations_compose_and_keep_the_function() {
        let sh =
            Sh9 { coeffs: std::array::from_fn(|k| Vec3::splat(1.0 / (1.0 + k as f32)) * Vec3::new(1.0, -2.0, 0.5)) };
        let (a, b) = (
            glam::Quat::from_rotation_y(0.7),
            glam::Quat::from_axis_angle(Vec3::new(1.0, 2.0, -0.5).normalize(), -1.3),
        );
        let twice = sh.rotated(a).rotated(b);
        let once = sh.rotated(b * a);
        for d in [Vec3::X, Vec3::Y, Vec3::new(0.3, -0.4, 0.866).normalize()] {
            assert!((twice.eval(d) - once.eval(d)).abs().max_element() < 1e-4);
            // g(d) = f(R⁻¹ d)
            assert!((sh.rotated(a).eval(d) - sh.eval(a.inverse() * d)).abs().max_element() < 1e-4);
        }
        let same = sh.rotated(glam::Quat::IDENTITY);
        for (s, t) in same.coeffs.iter().zip(sh.coeffs) {
            assert!((*s - t).abs().max_element() < 1e-5);
        }
    }

    #[test]
    fn basis_is_orthonormal_under_the_texel_quadrature() {
        let (w, h) = (256, 128);
        let map = EnvMap::constant(w, h, Vec3::ONE);
        let mut gram = [[0.0f64; 9]; 9];
        for j in 0..h {
            let sa = map.texel_solid_angle(j);
            for i in 0..w {
                let b = sh9_basis(map.texel_dir(i, j));
                for a in 0..9 {
                    for c in 0..9 {
                        gram[a][c] += f64::from(b[a]) * f64::from(b[c]) * sa;
                    }
                }
            }
        }
        for (a, row) in gram.iter().enumerate() {
            for (c, g) in row.iter().enumerate() {
                let want = if a == c { 1.0 } else { 0.0 };
                assert!((g - want).abs() < 2e-4, "<Y{a}, Y{c}> = {g}");
            }
        }
    }
}
