//! Tone mapping for previews: exposure, the ACES filmic curve (Narkowicz's fit) and the sRGB
//! transfer function. Used for every `.png` the toolkit writes.

use crate::color::luminance;
use glam::Vec3;

/// Exposure followed by ACES (Narkowicz 2015) and sRGB encoding to 8 bits.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Tonemap {
    /// Linear scale applied to radiance before the curve.
    pub exposure: f32,
}

impl Tonemap {
    /// Exposure that maps the log-average luminance to middle grey 0.18 (Reinhard's key);
    /// 1 for black or empty input.
    #[must_use]
    pub fn auto(pixels: &[Vec3]) -> Self {
        let (sum, n) = pixels
            .iter()
            .map(|p| luminance(*p))
            .filter(|y| y.is_finite() && *y > 0.0)
            .fold((0.0f64, 0usize), |(s, n), y| (s + f64::from(y.max(1e-6)).ln(), n + 1));
        if n == 0 {
            return Self { exposure: 1.0 };
        }
        let log_avg = (sum / n as f64).exp();
        Self { exposure: (0.18 / log_avg) as f32 }
    }

    /// Linear radiance to display-referred linear [0, 1].
    #[must_use]
    pub fn curve(&self, rgb: Vec3) -> Vec3 {
        let x = (rgb * self.exposure).max(Vec3::ZERO);
        let (a, b, c, d, e) = (2.51, 0.03, 2.43, 0.59, 0.14);
        ((x * (a * x + b)) / (x * (c * x + d) + e)).clamp(Vec3::ZERO, Vec3::ONE)
    }

    /// Linear radiance to 8-bit sRGB.
    #[must_use]
    pub fn apply(&self, rgb: Vec3) -> [u8; 3] {
        let v = self.curve(rgb);
        let enc = |c: f32| {
            let s = if c <= 0.003_130_8 { 12.92 * c } else { 1.055 * c.powf(1.0 / 2.4) - 0.055 };
            (s * 255.0 + 0.5) as u8
        };
        [enc(v.x), enc(v.y), enc(v.z)]
    }
}
