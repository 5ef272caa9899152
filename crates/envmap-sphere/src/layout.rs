//! Images over the sphere in any parameterization ([`Layout`]) and solid-angle-weighted
//! resampling between them.
//!
//! Image coordinates (u, v) in [0, 1]^2 span the whole image, v down. A cube map is a strip of
//! six square faces in layer order; a (dual) paraboloid map has one (two) disks inscribed in
//! square tiles, front (+Z) on the left, with disk point p = (2u' - 1, 1 - 2v) per tile.

use crate::cube::{CubeFace, cube_dir_to_uv, cube_jacobian, cube_rect_solid_angle, cube_uv_to_dir};
use crate::envmap::EnvMap;
use crate::latlong::{latlong_dir_to_uv, latlong_jacobian, latlong_texel_solid_angle, latlong_uv_to_dir};
use crate::paraboloid::{Hemisphere, paraboloid_dir_to_point, paraboloid_jacobian, paraboloid_point_to_dir};
use glam::{Vec2, Vec3};
use rayon::prelude::*;

/// A parameterization of (part of) the sphere on a texel grid.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Layout {
    /// The lat-long convention of [`crate::latlong`].
    LatLong {
        /// W
        width: u32,
        /// H
        height: u32,
    },
    /// Six `face` x `face` faces side by side in layer order +X, -X, +Y, -Y, +Z, -Z.
    CubeStrip {
        /// Face size in texels.
        face: u32,
    },
    /// One hemisphere on a `size` x `size` image.
    Paraboloid {
        /// Image size in texels.
        size: u32,
        /// The covered hemisphere.
        hemisphere: Hemisphere,
    },
    /// Front (+Z) and back (-Z) paraboloids side by side on a 2 `size` x `size` image.
    DualParaboloid {
        /// Size of each tile in texels.
        size: u32,
    },
}

impl Layout {
    /// (width, height) in texels.
    #[must_use]
    pub fn size(&self) -> (u32, u32) {
        match *self {
            Self::LatLong { width, height } => (width, height),
            Self::CubeStrip { face } => (6 * face, face),
            Self::Paraboloid { size, .. } => (size, size),
            Self::DualParaboloid { size } => (2 * size, size),
        }
    }

    /// Number of square tiles side by side (1 for lat-long, whose one tile is the image).
    fn tiles(&self) -> u32 {
        match self {
            Self::LatLong { .. } | Self::Paraboloid { .. } => 1,
            Self::CubeStrip { .. } => 6,
            Self::DualParaboloid { .. } => 2,
        }
    }

    /// Direction of image coordinates `uv`, or `None` outside the covered domain.
    #[must_use]
    pub fn uv_to_dir(&self, uv: Vec2) -> Option<Vec3> {
        match *self {
            Self::LatLong { .. } => Some(latlong_uv_to_dir(uv)),
            Self::CubeStrip { .. } => {
                let (k, st) = self.tile_uv(uv);
                Some(cube_uv_to_dir(CubeFace::from_index(k)?, st))
            }
            Self::Paraboloid { hemisphere, .. } => disk_dir(uv, hemisphere),
            Self::DualParaboloid { .. } => {
                let (k, st) = self.tile_uv(uv);
                disk_dir(st, if k == 0 { Hemisphere::Front } else { Hemisphere::Back })
            }
        }
    }

    /// Image coordinates of a direction, or `None` where the layout does not cover it.
    #[must_use]
    pub fn dir_to_uv(&self, dir: Vec3) -> Option<Vec2> {
        match *self {
            Self::LatLong { .. } => Some(latlong_dir_to_uv(dir)),
            Self::CubeStrip { .. } => {
                let (face, st) = cube_dir_to_uv(dir);
                Some(Vec2::new((face as u32 as f32 + st.x) / 6.0, st.y))
            }
            Self::Paraboloid { hemisphere, .. } => {
                let p = paraboloid_dir_to_point(dir, hemisphere);
                (p.length_squared() <= 1.0).then(|| disk_uv(p))
            }
            Self::DualParaboloid { .. } => {
                let h = Hemisphere::of(dir);
                let st = disk_uv(paraboloid_dir_to_point(dir, h));
                Some(Vec2::new((if h == Hemisphere::Front { 0.0 } else { 1.0 } + st.x) / 2.0, st.y))
            }
        }
    }

    /// Solid angle per unit image area at `uv`; 0 outside the covered domain.
    #[must_use]
    pub fn jacobian(&self, uv: Vec2) -> f32 {
        let tiles = self.tiles() as f32;
        match *self {
            Self::LatLong { .. } => latlong_jacobian(uv),
            Self::CubeStrip { .. } => tiles * cube_jacobian(self.tile_uv(uv).1),
            Self::Paraboloid { .. } | Self::DualParaboloid { .. } => {
                let p = disk_point(self.tile_uv(uv).1);
                // disk point per tile uv: dp = 4 dst
                if p.length_squared() <= 1.0 { tiles * 4.0 * paraboloid_jacobian(p) } else { 0.0 }
            }
        }
    }

    /// Solid angle of texel (x, y): exact for lat-long and cube maps; for paraboloids the
    /// Jacobian integrated on a 4 x 4 grid (texels on the rim count only their inside part).
    #[must_use]
    pub fn texel_solid_angle(&self, x: u32, y: u32) -> f64 {
        let (w, h) = self.size();
        match *self {
            Self::LatLong { width, height } => latlong_texel_solid_angle(y, width, height),
            Self::CubeStrip { face } => {
                let (fx, n) = (f64::from(x % face), f64::from(face));
                let fy = f64::from(y);
                cube_rect_solid_angle(fx / n, fy / n, (fx + 1.0) / n, (fy + 1.0) / n)
            }
            Self::Paraboloid { .. } | Self::DualParaboloid { .. } => {
                const N: u32 = 4;
                let sum: f64 = subtexel_uvs(x, y, N, (w, h)).map(|uv| f64::from(self.jacobian(uv))).sum();
                sum / f64::from(N * N) / (f64::from(w) * f64::from(h))
            }
        }
    }

    /// (tile index, coordinates within the tile in [0, 1]^2).
    fn tile_uv(&self, uv: Vec2) -> (usize, Vec2) {
        let t = self.tiles() as f32;
        let x = (uv.x * t).clamp(0.0, t - f32::EPSILON * t);
        let k = x.floor();
        (k as usize, Vec2::new(x - k, uv.y))
    }
}

/// Image coordinates of the centres of an `n` x `n` grid of sub-texels of texel (x, y).
fn subtexel_uvs(x: u32, y: u32, n: u32, (w, h): (u32, u32)) -> impl Iterator<Item = Vec2> {
    (0..n * n).map(move |k| {
        let (a, b) = (k % n, k / n);
        Vec2::new(
            (x as f32 + (a as f32 + 0.5) / n as f32) / w as f32,
            (y as f32 + (b as f32 + 0.5) / n as f32) / h as f32,
        )
    })
}

/// Disk point of tile coordinates: p = (2s - 1, 1 - 2t).
fn disk_point(st: Vec2) -> Vec2 {
    Vec2::new(2.0 * st.x - 1.0, 1.0 - 2.0 * st.y)
}

fn disk_uv(p: Vec2) -> Vec2 {
    Vec2::new((p.x + 1.0) * 0.5, (1.0 - p.y) * 0.5)
}

fn disk_dir(st: Vec2, h: Hemisphere) -> Option<Vec3> {
    let p = disk_point(st);
    (p.length_squared() <= 1.0).then(|| paraboloid_point_to_dir(p, h))
}

/// Anything radiance can be looked up in by direction.
pub trait RadianceSource: Sync {
    /// Filtered radiance towards `dir`.
    fn radiance(&self, dir: Vec3) -> Vec3;
    /// Approximate solid angle of one source texel around `dir` (decides the supersampling).
    fn texel_solid_angle_at(&self, dir: Vec3) -> f64;
}

impl RadianceSource for EnvMap {
    fn radiance(&self, dir: Vec3) -> Vec3 {
        self.lookup(dir)
    }

    fn texel_solid_angle_at(&self, dir: Vec3) -> f64 {
        self.texel_solid_angle(self.texel_of_dir(dir).1)
    }
}

/// A sphere image in any [`Layout`], linear RGB radiance.
#[derive(Clone, Debug, PartialEq)]
pub struct SphereImage {
    layout: Layout,
    pixels: Vec<Vec3>,
}

impl SphereImage {
    /// The layout.
    #[must_use]
    pub fn layout(&self) -> Layout {
        self.layout
    }

    /// Row-major texels. Paraboloid texels outside the disk hold the rim's radiance so that
    /// bilinear lookups near the rim are not darkened.
    #[must_use]
    pub fn pixels(&self) -> &[Vec3] {
        &self.pixels
    }

    /// Resamples `src` into `layout`, weighting by solid angle: each target texel is the
    /// solid-angle-weighted mean of `n x n` bilinear source lookups, with `n` chosen so that
    /// sub-samples are no larger than source texels (box-filtered downsampling, plain bilinear
    /// upsampling).
    #[must_use]
    pub fn resample(src: &impl RadianceSource, layout: Layout) -> Self {
        let (w, h) = layout.size();
        let pixels = (0..h)
            .into_par_iter()
            .flat_map_iter(|y| (0..w).map(move |x| (x, y)))
            .map(|(x, y)| resample_texel(src, &layout, x, y))
            .collect();
        Self { layout, pixels }
    }

    /// Radiant power per channel (texel radiance x [`Layout::texel_solid_angle`]).
    #[must_use]
    pub fn power(&self) -> [f64; 3] {
        let (w, _) = self.layout.size();
        let mut p = glam::DVec3::ZERO;
        for (k, l) in self.pixels.iter().enumerate() {
            let sa = self.layout.texel_solid_angle(k as u32 % w, k as u32 / w);
            p += l.as_dvec3() * sa;
        }
        p.to_array()
    }

    fn texel(&self, x: i64, y: i64) -> Vec3 {
        let (w, _) = self.layout.size();
        self.pixels[y as usize * w as usize + x as usize]
    }
}

impl RadianceSource for SphereImage {
    /// Bilinear within the tile that contains `dir` (clamped at tile edges; lat-long wraps u).
    fn radiance(&self, dir: Vec3) -> Vec3 {
        let (w, h) = self.layout.size();
        let Some(uv) = self.layout.dir_to_uv(dir).or_else(|| {
            // outside a single paraboloid's hemisphere: use the nearest rim direction
            let rim = Vec3::new(dir.x, dir.y, 0.0).try_normalize().unwrap_or(Vec3::X);
            self.layout.dir_to_uv(rim)
        }) else {
            return Vec3::ZERO;
        };
        let tiles = i64::from(self.layout.tiles());
        let tile_w = i64::from(w) / tiles;
        let x = uv.x * w as f32 - 0.5;
        let y = (uv.y * h as f32 - 0.5).clamp(0.0, (h - 1) as f32);
        let wrap = matches!(self.layout, Layout::LatLong { .. });
        let tile = ((uv.x * tiles as f32) as i64).clamp(0, tiles - 1);
        let (lo, hi) = (tile * tile_w, tile * tile_w + tile_w - 1);
        let fix = |xi: i64| if wrap { xi.rem_euclid(i64::from(w)) } else { xi.clamp(lo, hi) };
        let (x0, y0) = (x.floor(), y.floor());
        let (fx, fy) = (x - x0, y - y0);
        let (xa, xb) = (fix(x0 as i64), fix(x0 as i64 + 1));
        let (ya, yb) = (y0 as i64, (y0 as i64 + 1).min(i64::from(h) - 1));
        let top = self.texel(xa, ya).lerp(self.texel(xb, ya), fx);
        let bottom = self.texel(xa, yb).lerp(self.texel(xb, yb), fx);
        top.lerp(bottom, fy)
    }

    fn texel_solid_angle_at(&self, dir: Vec3) -> f64 {
        let (w, h) = self.layout.size();
        let uv = self.layout.dir_to_uv(dir).unwrap_or(Vec2::splat(0.5));
        f64::from(self.layout.jacobian(uv).max(1e-6)) / (f64::from(w) * f64::from(h))
    }
}

fn resample_texel(src: &impl RadianceSource, layout: &Layout, x: u32, y: u32) -> Vec3 {
    let (w, h) = layout.size();
    let centre = Vec2::new((x as f32 + 0.5) / w as f32, (y as f32 + 0.5) / h as f32);
    let Some(dir) = layout.uv_to_dir(centre) else {
        // outside a paraboloid disk: extend the rim
        let (_, st) = layout.tile_uv(centre);
        let p = disk_point(st).normalize_or(Vec2::X);
        let tile = (centre.x * layout.tiles() as f32) as u32;
        let h = if tile == 0 && !matches!(layout, Layout::Paraboloid { hemisphere: Hemisphere::Back, .. }) {
            Hemisphere::Front
        } else {
            Hemisphere::Back
        };
        return src.radiance(paraboloid_point_to_dir(p, h));
    };
    let target_sa = layout.texel_solid_angle(x, y);
    let ratio = target_sa / src.texel_solid_angle_at(dir).max(1e-12);
    let n = (ratio.sqrt().ceil() as u32).clamp(1, 32);
    if n == 1 {
        return src.radiance(dir);
    }
    let mut sum = Vec3::ZERO;
    let mut weight = 0.0;
    for uv in subtexel_uvs(x, y, n, (w, h)) {
        if let Some(d) = layout.uv_to_dir(uv) {
            let wgt = layout.jacobian(uv);
            sum += src.radiance(d) * wgt;
            weight += wgt;
        }
    }
    if weight > 0.0 { sum / weight } else { src.radiance(dir) }
}

impl EnvMap {
    /// This map in another layout (see [`SphereImage::resample`]).
    #[must_use]
    pub fn to_layout(&self, layout: Layout) -> SphereImage {
        SphereImage::resample(self, layout)
    }

    /// A lat-long map resampled from any source.
    ///
    /// # Panics
    /// When a side is zero.
    #[must_use]
    pub fn resample_from(src: &impl RadianceSource, width: u32, height: u32) -> Self {
        let img = SphereImage::resample(src, Layout::LatLong { width, height });
        Self::try_new(width, height, img.pixels).expect("size is non-zero")
    }

    /// Resized to `width` x `height`. Integer downsampling factors are exact box filters
    /// weighted by texel solid angle, so radiant power is preserved to rounding; other sizes
    /// use [`EnvMap::resample_from`].
    ///
    /// # Panics
    /// When a side is zero.
    #[must_use]
    pub fn resize(&self, width: u32, height: u32) -> Self {
        assert!(width > 0 && height > 0, "an EnvMap needs a non-zero size");
        if !self.width().is_multiple_of(width) || !self.height().is_multiple_of(height) {
            return Self::resample_from(self, width, height);
        }
        let (fx, fy) = (self.width() / width, self.height() / height);
        let sa = self.row_solid_angles();
        Self::from_texels(width, height, |i, j| {
            let mut sum = glam::DVec3::ZERO;
            let mut weight = 0.0;
            for y in j * fy..(j + 1) * fy {
                let row: glam::DVec3 = (i * fx..(i + 1) * fx).map(|x| self.pixel(x, y).as_dvec3()).sum();
                sum += row * sa[y as usize];
                weight += sa[y as usize] * f64::from(fx);
            }
            (sum / weight).as_vec3()
        })
    }
}
