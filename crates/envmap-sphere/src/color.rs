//! Colour conventions: linear Rec.709 RGB radiance stored as [`glam::Vec3`].

use glam::{DMat3, DVec3, Vec3};

/// Rec.709 luminance weights: Y = 0.2126 R + 0.7152 G + 0.0722 B.
pub const LUMINANCE_WEIGHTS: Vec3 = Vec3::new(0.2126, 0.7152, 0.0722);

/// Luminance of a linear Rec.709 RGB value.
#[inline]
#[must_use]
pub fn luminance(rgb: Vec3) -> f32 {
    rgb.dot(LUMINANCE_WEIGHTS)
}

/// Luminance in f64, for sums over millions of texels.
#[inline]
#[must_use]
pub fn luminance_f64(rgb: [f64; 3]) -> f64 {
    0.2126 * rgb[0] + 0.7152 * rgb[1] + 0.0722 * rgb[2]
}

/// The CIE 1931 xy chromaticities of an RGB space's primaries and white point: what an OpenEXR
/// file's `chromaticities` attribute says its RGB values mean.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Chromaticities {
    /// Red primary (x, y).
    pub red: [f32; 2],
    /// Green primary (x, y).
    pub green: [f32; 2],
    /// Blue primary (x, y).
    pub blue: [f32; 2],
    /// White point (x, y): the colour of RGB (1, 1, 1).
    pub white: [f32; 2],
}

impl Chromaticities {
    /// ITU-R BT.709 primaries with a D65 white: our working space, and OpenEXR's default.
    pub const REC709: Self =
        Self { red: [0.64, 0.33], green: [0.30, 0.60], blue: [0.15, 0.06], white: [0.3127, 0.3290] };

    /// Whether these are [`Chromaticities::REC709`] up to the rounding files store them with.
    #[must_use]
    pub fn is_rec709(&self) -> bool {
        let near = |a: [f32; 2], b: [f32; 2]| (a[0] - b[0]).abs() < 1e-4 && (a[1] - b[1]).abs() < 1e-4;
        let r = Self::REC709;
        near(self.red, r.red) && near(self.green, r.green) && near(self.blue, r.blue) && near(self.white, r.white)
    }

    /// The matrix from RGB in these primaries to CIE XYZ, the white point at Y = 1 (columns:
    /// the primaries' XYZ); `None` when the chromaticities are degenerate (a y of zero, a
    /// non-finite value, collinear primaries).
    #[must_use]
    pub fn rgb_to_xyz(&self) -> Option<DMat3> {
        let xyz = |[x, y]: [f32; 2]| {
            let (x, y) = (f64::from(x), f64::from(y));
            (x.is_finite() && y.is_finite() && y.abs() > 1e-9).then(|| DVec3::new(x / y, 1.0, (1.0 - x - y) / y))
        };
        let primaries = DMat3::from_cols(xyz(self.red)?, xyz(self.green)?, xyz(self.blue)?);
        if primaries.determinant().abs() < 1e-9 {
            return None;
        }
        // scale each primary so that their sum is the white point
        let scale = primaries.inverse() * xyz(self.white)?;
        let m = primaries * DMat3::from_diagonal(scale);
        m.is_finite().then_some(m)
    }

    /// The matrix from RGB in these primaries to linear Rec.709 RGB of the same XYZ, without
    /// chromatic adaptation (so a file's white becomes its own colour under D65, not Rec.709
    /// white): OpenEXR's `RGBtoXYZ` followed by `XYZtoRGB`, as Mitsuba 3 reads EXR files.
    /// `None` when the chromaticities are degenerate.
    #[must_use]
    pub fn to_rec709(&self) -> Option<DMat3> {
        Some(Self::REC709.rgb_to_xyz()?.inverse() * self.rgb_to_xyz()?)
    }
}
