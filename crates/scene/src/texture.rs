//! Textures as glTF gives them: 8-bit RGBA images with a sampler (wrap per axis, nearest or
//! bilinear), sampled at full resolution by the reference tracer and, the same way, by the GPU
//! (`gpu`'s texel buffer): no mipmaps on either, so the two agree texel for texel.

use glam::{Vec2, Vec4};

/// How a texture coordinate outside [0, 1) comes back into the image (glTF's wrap modes).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Wrap {
    /// The image tiles (glTF's default).
    #[default]
    Repeat,
    /// The edge texel extends.
    Clamp,
    /// The image tiles, every other copy mirrored.
    Mirror,
}

impl Wrap {
    /// The shaders' code for the mode.
    #[must_use]
    pub fn code(self) -> u32 {
        match self {
            Self::Repeat => 0,
            Self::Clamp => 1,
            Self::Mirror => 2,
        }
    }

    /// Texel index `i` of an axis of `n` texels, wrapped into `0..n`.
    #[must_use]
    pub fn texel(self, i: i64, n: u32) -> u32 {
        let n = i64::from(n.max(1));
        match self {
            Self::Repeat => i.rem_euclid(n) as u32,
            Self::Clamp => i.clamp(0, n - 1) as u32,
            Self::Mirror => {
                let k = i.rem_euclid(2 * n);
                (if k < n { k } else { 2 * n - 1 - k }) as u32
            }
        }
    }
}

/// How a texture is filtered between texel centres.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Filter {
    /// The nearest texel.
    Nearest,
    /// Bilinear between the four nearest texel centres (glTF's usual).
    #[default]
    Linear,
}

/// An 8-bit RGBA image and how to sample it. Row 0 is the image's top, at v = 0 (glTF's
/// convention: uv (0, 0) is the first texel of the file).
#[derive(Clone, Debug, PartialEq)]
pub struct Texture {
    /// Width in texels.
    pub width: u32,
    /// Height in texels.
    pub height: u32,
    /// `width * height` texels, row by row.
    pub texels: Vec<[u8; 4]>,
    /// Wrap along u and along v.
    pub wrap: [Wrap; 2],
    /// Filter.
    pub filter: Filter,
}

/// The sRGB transfer function undone, exactly (IEC 61966-2-1).
#[must_use]
pub fn srgb_to_linear(c: f32) -> f32 {
    if c <= 0.04045 { c / 12.92 } else { ((c + 0.055) / 1.055).powf(2.4) }
}

/// A linear value in [0, 1] as the nearest 8-bit sRGB code (IEC 61966-2-1); values outside
/// are clamped, NaN reads 0.
#[must_use]
pub fn linear_to_srgb8(c: f32) -> u8 {
    let c = if c.is_nan() { 0.0 } else { c.clamp(0.0, 1.0) };
    let s = if c <= 0.003_130_8 { 12.92 * c } else { 1.055 * c.powf(1.0 / 2.4) - 0.055 };
    (s * 255.0).round().clamp(0.0, 255.0) as u8
}

impl Texture {
    /// Texel `(x, y)` as linear values in [0, 1]: its RGB through the sRGB curve when `srgb`
    /// (base colour and emission), as stored otherwise (metallic-roughness); alpha as stored.
    #[must_use]
    pub fn texel(&self, x: u32, y: u32, srgb: bool) -> Vec4 {
        let t = self.texels[(y * self.width + x) as usize];
        let f = |c: u8| f32::from(c) / 255.0;
        let rgb = |c: u8| if srgb { srgb_to_linear(f(c)) } else { f(c) };
        Vec4::new(rgb(t[0]), rgb(t[1]), rgb(t[2]), f(t[3]))
    }

    /// The texture at `uv`, filtered and wrapped as its sampler says; white for an empty image.
    #[must_use]
    pub fn sample(&self, uv: Vec2, srgb: bool) -> Vec4 {
        if self.width == 0 || self.height == 0 || self.texels.len() != (self.width * self.height) as usize {
            return Vec4::ONE;
        }
        // non-finite coordinates (a broken UV) read the first texel rather than poison a pixel
        let uv = if uv.is_finite() { uv } else { Vec2::ZERO };
        let (w, h) = (self.width, self.height);
        let (x, y) = (f64::from(uv.x) * f64::from(w), f64::from(uv.y) * f64::from(h));
        let at = |i: f64, j: f64| {
            let clamp = |v: f64| v.clamp(-1e15, 1e15) as i64;
            self.texel(self.wrap[0].texel(clamp(i), w), self.wrap[1].texel(clamp(j), h), srgb)
        };
        match self.filter {
            Filter::Nearest => at(x.floor(), y.floor()),
            Filter::Linear => {
                let (x, y) = (x - 0.5, y - 0.5);
                let (x0, y0) = (x.floor(), y.floor());
                let (fx, fy) = ((x - x0) as f32, (y - y0) as f32);
                let top = at(x0, y0).lerp(at(x0 + 1.0, y0), fx);
                let bottom = at(x0, y0 + 1.0).lerp(at(x0 + 1.0, y0 + 1.0), fx);
                top.lerp(bottom, fy)
            }
        }
    }

    /// The image at half its size in each direction (2 x 2 box filter; an odd last row or
    /// column kept on its own), the sampler kept: how a renderer with less memory than the
    /// textures need fits them.
    #[must_use]
    pub fn halved(&self) -> Self {
        let (w, h) = (self.width.div_ceil(2).max(1), self.height.div_ceil(2).max(1));
        let mut texels = Vec::with_capacity((w * h) as usize);
        for y in 0..h {
            for x in 0..w {
                let mut sum = [0u32; 4];
                let mut n = 0;
                for (dx, dy) in [(0, 0), (1, 0), (0, 1), (1, 1)] {
                    let (sx, sy) = (2 * x + dx, 2 * y + dy);
                    if sx < self.width && sy < self.height {
                        let t = self.texels[(sy * self.width + sx) as usize];
                        for c in 0..4 {
                            sum[c] += u32::from(t[c]);
                        }
                        n += 1;
                    }
                }
                texels.push(sum.map(|s| ((s + n / 2) / n.max(1)) as u8));
            }
        }
        Self { width: w, height: h, texels, wrap: self.wrap, filter: self.filter }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn srgb8_round_trips_every_code() {
        for code in 0..=255u8 {
            assert_eq!(linear_to_srgb8(srgb_to_linear(f32::from(code) / 255.0)), code);
        }
        assert_eq!((linear_to_srgb8(-1.0), linear_to_srgb8(2.0), linear_to_srgb8(f32::NAN)), (0, 255, 0));
    }

    #[test]
    fn lambertian_maps_give_the_base_colour_alone() {
        let t = checker();
        let maps = crate::Maps {
            base_color: glam::Vec3::new(0.5, 1.0, 1.0),
            metallic: 1.0,
            roughness: 0.2,
            emissive: glam::Vec3::ZERO,
            base_color_texture: Some(0),
            metallic_roughness_texture: None,
            emissive_texture: None,
            specular: false,
        };
        let m = crate::Material { maps: Some(maps), ..crate::Material::lambert(0.3) };
        let uv = Vec2::new(0.1, 0.1);
        let at = m.at(std::slice::from_ref(&t), uv);
        let texel = t.sample(uv, true).truncate();
        assert!(at.specular.is_none() && (at.albedo - texel * maps.base_color).abs().max_element() < 1e-6);
        // with the layer, a metal of that colour
        let layered = crate::Material { maps: Some(crate::Maps { specular: true, ..maps }), ..m };
        let at = layered.at(std::slice::from_ref(&t), uv);
        assert!(at.specular.is_some() && at.albedo.max_element() < 1e-6);
    }

    fn checker() -> Texture {
        // 2 x 2: black, white / white, black
        let texels = vec![[0, 0, 0, 255], [255, 255, 255, 255], [255, 255, 255, 255], [0, 0, 0, 255]];
        Texture { width: 2, height: 2, texels, wrap: [Wrap::Repeat; 2], filter: Filter::Nearest }
    }

    #[test]
    fn nearest_reads_the_texel_under_the_coordinate() {
        let t = checker();
        assert_eq!(t.sample(Vec2::new(0.25, 0.25), false).x, 0.0);
        assert_eq!(t.sample(Vec2::new(0.75, 0.25), false).x, 1.0);
        assert_eq!(t.sample(Vec2::new(0.25, 0.75), false).x, 1.0);
        // one tile over reads the same
        assert_eq!(t.sample(Vec2::new(1.25, -0.75), false).x, 0.0);
    }

    #[test]
    fn bilinear_is_the_mean_between_texel_centres() {
        let t = Texture { filter: Filter::Linear, ..checker() };
        // halfway between the four centres: two black, two white
        assert!((t.sample(Vec2::new(0.5, 0.5), false).x - 0.5).abs() < 1e-6);
        // on a centre: the texel itself
        assert!(t.sample(Vec2::new(0.25, 0.25), false).x.abs() < 1e-6);
    }

    #[test]
    fn wrap_modes_fold_as_gltf_says() {
        assert_eq!(Wrap::Repeat.texel(-1, 4), 3);
        assert_eq!(Wrap::Clamp.texel(-1, 4), 0);
        assert_eq!(Wrap::Clamp.texel(9, 4), 3);
        assert_eq!(Wrap::Mirror.texel(4, 4), 3);
        assert_eq!(Wrap::Mirror.texel(-1, 4), 0);
        assert_eq!(Wrap::Mirror.texel(8, 4), 0);
    }

    #[test]
    fn srgb_curve_meets_its_ends_and_mid_grey() {
        assert_eq!(srgb_to_linear(0.0), 0.0);
        assert!((srgb_to_linear(1.0) - 1.0).abs() < 1e-6);
        // the published value of sRGB 188/255
        assert!((srgb_to_linear(188.0 / 255.0) - 0.5029).abs() < 1e-3);
    }

    #[test]
    fn no_nan_at_extremes() {
        let t = Texture { filter: Filter::Linear, ..checker() };
        for uv in [Vec2::splat(f32::MAX), Vec2::splat(-f32::MAX), Vec2::splat(f32::NAN), Vec2::splat(1e-30)] {
            assert!(t.sample(uv, true).is_finite(), "{uv}");
        }
    }

    #[test]
    fn halving_keeps_the_mean() {
        let t = checker().halved();
        assert_eq!((t.width, t.height), (1, 1));
        assert_eq!(t.texels[0], [128, 128, 128, 255]);
    }
}
