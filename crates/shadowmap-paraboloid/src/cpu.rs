//! A CPU paraboloid shadow map: the same mapping, the clip-distance rejection (polygon clipping
//! at z = 0 and at depths 0 and 1, attributes interpolated linearly as the rasterizer does), pixel-
//! centre coverage and linearly interpolated depth, and the same biased shadow test as
//! `visibility.wgsl`. The GPU maps are checked against it.

use crate::paraboloid::{Hemisphere, ParaboloidFrame, texel_of};
use glam::{Vec2, Vec3, Vec4};

/// One CPU-rasterized paraboloid map.
#[derive(Clone, Debug)]
pub struct CpuParaboloidMap {
    /// The light's frame.
    pub frame: ParaboloidFrame,
    /// Which map.
    pub hemisphere: Hemisphere,
    /// Side in texels.
    pub resolution: u32,
    /// Depths in [0, 1], row-major from the top-left; 1 where nothing was drawn.
    pub depth: Vec<f32>,
}

/// Clips a polygon of (x, y, depth, clip distance) vertices against `keep(v) >= 0`.
fn clip(poly: &[Vec4], keep: impl Fn(Vec4) -> f32) -> Vec<Vec4> {
    let mut out = Vec::with_capacity(poly.len() + 2);
    for (i, &a) in poly.iter().enumerate() {
        let b = poly[(i + 1) % poly.len()];
        let (da, db) = (keep(a), keep(b));
        if da >= 0.0 {
            out.push(a);
        }
        if (da >= 0.0) != (db >= 0.0) {
            out.push(a + (b - a) * (da / (da - db)));
        }
    }
    out
}

impl CpuParaboloidMap {
    /// Rasterizes `triangles` (world space) into the `hemisphere` map of `frame`.
    #[must_use]
    pub fn rasterize(
        frame: &ParaboloidFrame,
        hemisphere: Hemisphere,
        resolution: u32,
        triangles: &[[Vec3; 3]],
    ) -> Self {
        let r = resolution as usize;
        let mut depth = vec![1.0f32; r * r];
        let res = resolution as f32;
        for tri in triangles {
            let poly: Vec<Vec4> = tri
                .iter()
                .map(|&p| {
                    let (c, z) = frame.project_into(p, hemisphere);
                    Vec4::new(c.uv.x, c.uv.y, c.depth, z)
                })
                .collect();
            let poly = clip(&poly, |v| v.w);
            let poly = clip(&poly, |v| v.z);
            let poly = clip(&poly, |v| 1.0 - v.z);
            if poly.len() < 3 {
                continue;
            }
            // to pixel space: x right, y down
            let px: Vec<Vec3> =
                poly.iter().map(|v| Vec3::new((v.x * 0.5 + 0.5) * res, (0.5 - v.y * 0.5) * res, v.z)).collect();
            for k in 1..px.len() - 1 {
                raster_triangle(&mut depth, r, px[0], px[k], px[k + 1]);
            }
        }
        Self { frame: *frame, hemisphere, resolution, depth }
    }

    /// Stored depth at `uv`.
    #[must_use]
    pub fn depth_at(&self, uv: Vec2) -> f32 {
        let (x, y) = texel_of(uv, self.resolution);
        self.depth[(y * self.resolution + x) as usize]
    }
}

fn raster_triangle(depth: &mut [f32], r: usize, a: Vec3, b: Vec3, c: Vec3) {
    let area = (b.x - a.x) * (c.y - a.y) - (b.y - a.y) * (c.x - a.x);
    if area == 0.0 || !area.is_finite() {
        return;
    }
    let lo = a.min(b).min(c);
    let hi = a.max(b).max(c);
    let x0 = lo.x.floor().max(0.0) as usize;
    let y0 = lo.y.floor().max(0.0) as usize;
    let x1 = (hi.x.ceil().min(r as f32) as usize).min(r);
    let y1 = (hi.y.ceil().min(r as f32) as usize).min(r);
    for y in y0..y1 {
        for x in x0..x1 {
            let (px, py) = (x as f32 + 0.5, y as f32 + 0.5);
            let w0 = ((b.x - px) * (c.y - py) - (b.y - py) * (c.x - px)) / area;
            let w1 = ((c.x - px) * (a.y - py) - (c.y - py) * (a.x - px)) / area;
            let w2 = 1.0 - w0 - w1;
            if w0 < 0.0 || w1 < 0.0 || w2 < 0.0 {
                continue;
            }
            let z = w0 * a.z + w1 * b.z + w2 * c.z;
            let d = &mut depth[y * r + x];
            if z < *d {
                *d = z;
            }
        }
    }
}

/// The CPU dual (or single) paraboloid shadow test of `visibility.wgsl` without PCF: whether
/// the light at `maps[0].frame.position` reaches `p` (geometric normal `ng`), with the bias of
/// `bias_texels` texels. `maps` holds the front map and, for an omnidirectional light, the back
/// one. `None` behind a hemispherical light.
#[must_use]
pub fn lit(maps: &[CpuParaboloidMap], p: Vec3, ng: Vec3, bias_texels: f32) -> Option<bool> {
    let frame = maps.first()?.frame;
    let to_light = frame.position - p;
    let dist = to_light.length();
    let to_light = to_light / dist.max(1e-30);
    let ng = if ng.dot(to_light) < 0.0 { -ng } else { ng };
    let offset = bias_texels * dist * 4.0 / maps[0].resolution as f32;
    let q = p + ng * offset + to_light * offset;
    let front = (q - frame.position).dot(frame.forward) >= 0.0;
    let map = if front { &maps[0] } else { maps.get(1)? };
    let (c, _) = frame.project_into(q, map.hemisphere);
    Some(c.depth <= map.depth_at(c.uv))
}
