//! Colour conventions: linear Rec.709 RGB radiance stored as [`glam::Vec3`].

use glam::Vec3;

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
