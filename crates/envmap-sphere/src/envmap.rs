//! [`EnvMap`]: a lat-long map of linear RGB radiance, its texels' directions and solid angles,
//! and bilinear lookups.

use crate::error::{EnvMapError, MEMORY_PATH};
use crate::latlong::{latlong_dir_to_uv, latlong_texel_solid_angle, latlong_uv_to_dir};
use glam::{Vec2, Vec3};

/// A lat-long environment map of linear Rec.709 RGB radiance (W/(m^2 sr), or any unit).
///
/// Row 0 is the top (+Y). See [`crate::latlong`] for the direction convention. In-memory maps
/// may hold any finite or non-finite values; the file loaders apply [`crate::LoadOptions`].
///
/// ```
/// use envmap_sphere::EnvMap;
/// use glam::Vec3;
/// let sky = EnvMap::constant(64, 32, Vec3::splat(1.0));
/// // A constant map of radiance L has power 4 pi L and irradiance pi L for every normal.
/// assert!((sky.power()[1] - 4.0 * std::f64::consts::PI).abs() < 1e-9);
/// assert!((sky.irradiance(Vec3::Y).y - std::f32::consts::PI).abs() < 1e-3);
/// ```
#[derive(Clone, Debug, PartialEq)]
pub struct EnvMap {
    width: u32,
    height: u32,
    pixels: Vec<Vec3>,
}

impl EnvMap {
    /// A map from row-major pixels (row 0 at the top).
    ///
    /// # Errors
    /// [`EnvMapError::InvalidSize`] when a side is zero or `pixels.len() != width * height`.
    pub fn try_new(width: u32, height: u32, pixels: Vec<Vec3>) -> Result<Self, EnvMapError> {
        if width == 0 || height == 0 || pixels.len() as u64 != u64::from(width) * u64::from(height) {
            return Err(EnvMapError::InvalidSize {
                path: MEMORY_PATH.into(),
                width: u64::from(width),
                height: u64::from(height),
            });
        }
        Ok(Self { width, height, pixels })
    }

    /// A map whose texel (i, j) holds `f(i, j)`.
    ///
    /// # Panics
    /// When a side is zero.
    #[must_use]
    pub fn from_texels(width: u32, height: u32, f: impl Fn(u32, u32) -> Vec3) -> Self {
        assert!(width > 0 && height > 0, "an EnvMap needs a non-zero size");
        let pixels = (0..height).flat_map(|j| (0..width).map(move |i| (i, j))).map(|(i, j)| f(i, j)).collect();
        Self { width, height, pixels }
    }

    /// A map whose every texel holds `f(direction of its centre)`.
    ///
    /// # Panics
    /// When a side is zero.
    #[must_use]
    pub fn from_fn(width: u32, height: u32, f: impl Fn(Vec3) -> Vec3) -> Self {
        Self::from_texels(width, height, |i, j| f(texel_centre_dir(i, j, width, height)))
    }

    /// A map of constant radiance.
    ///
    /// # Panics
    /// When a side is zero.
    #[must_use]
    pub fn constant(width: u32, height: u32, radiance: Vec3) -> Self {
        assert!(width > 0 && height > 0, "an EnvMap needs a non-zero size");
        Self { width, height, pixels: vec![radiance; width as usize * height as usize] }
    }

    /// Width W in texels.
    #[must_use]
    pub fn width(&self) -> u32 {
        self.width
    }

    /// Height H in texels.
    #[must_use]
    pub fn height(&self) -> u32 {
        self.height
    }

    /// Row-major texels, row 0 at the top.
    #[must_use]
    pub fn pixels(&self) -> &[Vec3] {
        &self.pixels
    }

    /// Mutable row-major texels.
    pub fn pixels_mut(&mut self) -> &mut [Vec3] {
        &mut self.pixels
    }

    /// Texel (i, j). Panics when out of range.
    #[must_use]
    pub fn pixel(&self, i: u32, j: u32) -> Vec3 {
        self.pixels[self.index(i, j)]
    }

    /// Sets texel (i, j). Panics when out of range.
    pub fn set_pixel(&mut self, i: u32, j: u32, value: Vec3) {
        let k = self.index(i, j);
        self.pixels[k] = value;
    }

    #[inline]
    fn index(&self, i: u32, j: u32) -> usize {
        assert!(i < self.width && j < self.height, "texel ({i}, {j}) outside {}x{}", self.width, self.height);
        j as usize * self.width as usize + i as usize
    }

    /// Direction of the centre of texel (i, j).
    #[must_use]
    pub fn texel_dir(&self, i: u32, j: u32) -> Vec3 {
        texel_centre_dir(i, j, self.width, self.height)
    }

    /// Exact solid angle of a texel of row `j`.
    #[must_use]
    pub fn texel_solid_angle(&self, j: u32) -> f64 {
        latlong_texel_solid_angle(j, self.width, self.height)
    }

    /// Solid angle of one texel of each row.
    #[must_use]
    pub fn row_solid_angles(&self) -> Vec<f64> {
        (0..self.height).map(|j| self.texel_solid_angle(j)).collect()
    }

    /// The texel containing `dir` (its nearest texel centre in u and v).
    #[must_use]
    pub fn texel_of_dir(&self, dir: Vec3) -> (u32, u32) {
        crate::latlong::latlong_uv_to_texel(latlong_dir_to_uv(dir), self.width, self.height)
    }

    /// Radiance of the texel containing `dir`.
    #[must_use]
    pub fn lookup_nearest(&self, dir: Vec3) -> Vec3 {
        let (i, j) = self.texel_of_dir(dir);
        self.pixel(i, j)
    }

    /// Bilinear radiance lookup: wraps in u, clamps in v.
    #[must_use]
    pub fn lookup(&self, dir: Vec3) -> Vec3 {
        self.lookup_uv(latlong_dir_to_uv(dir))
    }

    /// Bilinear lookup at lat-long coordinates: wraps in u, clamps in v.
    #[must_use]
    pub fn lookup_uv(&self, uv: Vec2) -> Vec3 {
        let (w, h) = (self.width as usize, self.height as usize);
        let x = uv.x * self.width as f32 - 0.5;
        let y = (uv.y * self.height as f32 - 0.5).clamp(0.0, (h - 1) as f32);
        let (x0, y0) = (x.floor(), y.floor());
        let (fx, fy) = (x - x0, y - y0);
        // u in [0, 1] needs no division to wrap; anything else takes rem_euclid
        let wrap = |k: i64| if (0..w as i64).contains(&k) { k as usize } else { k.rem_euclid(w as i64) as usize };
        let (xi0, xi1) = (wrap(x0 as i64), wrap(x0 as i64 + 1));
        let yi0 = y0 as usize;
        let yi1 = (yi0 + 1).min(h - 1);
        let (r0, r1) = (&self.pixels[yi0 * w..(yi0 + 1) * w], &self.pixels[yi1 * w..(yi1 + 1) * w]);
        let top = r0[xi0].lerp(r0[xi1], fx);
        let bottom = r1[xi0].lerp(r1[xi1], fx);
        top.lerp(bottom, fy)
    }

    /// Rotates the map about +Y by whole columns: texel i moves to column (i + columns) mod W,
    /// i.e. every direction's azimuth phi grows by 2 pi columns / W.
    #[must_use]
    pub fn rotate_columns(&self, columns: i64) -> Self {
        let w = i64::from(self.width);
        Self::from_texels(self.width, self.height, |i, j| self.pixel((i64::from(i) - columns).rem_euclid(w) as u32, j))
    }
}

/// Direction of the centre of texel (i, j) of a `width` x `height` lat-long map.
#[inline]
#[must_use]
pub fn texel_centre_dir(i: u32, j: u32, width: u32, height: u32) -> Vec3 {
    latlong_uv_to_dir(Vec2::new((i as f32 + 0.5) / width as f32, (j as f32 + 0.5) / height as f32))
}
