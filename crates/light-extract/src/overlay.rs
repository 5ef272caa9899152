//! The papers' figure of found lights: the map, tone-mapped, with each light drawn as the
//! circle of its cone (and, dotted, of its cluster's extent).

use crate::decomposition::ExtractedLight;
use envmap_sphere::{EnvMap, Tonemap};
use glam::Vec3;
use scene::brdf::Frame;
use std::path::Path;

/// 8-bit sRGB pixels of the overlay (row-major RGB triples).
#[must_use]
pub fn overlay(map: &EnvMap, lights: &[ExtractedLight]) -> Vec<u8> {
    let tm = Tonemap::auto(map.pixels());
    let mut px: Vec<u8> = map.pixels().iter().flat_map(|p| tm.apply(*p)).collect();
    let mut plot = |d: Vec3, colour: [u8; 3]| {
        let (i, j) = map.texel_of_dir(d);
        let k = 3 * (j as usize * map.width() as usize + i as usize);
        px[k..k + 3].copy_from_slice(&colour);
    };
    for l in lights {
        let f = Frame::new(l.light.direction.normalize());
        for (radius, colour, step) in [(l.light.half_angle(), [255, 40, 40], 1), (l.extent, [40, 255, 80], 3)] {
            let n = 720;
            for k in (0..n).step_by(step) {
                let a = k as f32 / n as f32 * std::f32::consts::TAU;
                let (s, c) = radius.sin_cos();
                plot(f.to_world(Vec3::new(s * a.cos(), s * a.sin(), c)), colour);
            }
        }
        plot(l.light.direction, [255, 255, 0]);
    }
    px
}

/// Writes [`overlay`] as a PNG.
///
/// # Errors
/// [`EnvMapError`](envmap_sphere::EnvMapError), naming the file.
pub fn write_overlay(path: &Path, map: &EnvMap, lights: &[ExtractedLight]) -> Result<(), envmap_sphere::EnvMapError> {
    envmap_sphere::io::save_png_srgb8(path, map.width(), map.height(), &overlay(map, lights))
}
