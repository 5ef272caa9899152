//! Image error metrics against a reference: RMSE and relative MSE over all pixels and channels,
//! and FLIP (Andersson et al. 2020), the perceptual difference, through the `nv-flip` bindings.
//!
//! FLIP here is LDR-FLIP: both images go through the same tone mapping first, stated by
//! [`FlipTonemap::describe`] and printed with every result: the reference's automatic exposure
//! (log-average luminance to 0.18), the ACES filmic fit, sRGB encoding to 8 bits, and 67 pixels
//! per degree (a 0.7 m wide 4K monitor seen from 0.7 m, FLIP's default).

use envmap_sphere::Tonemap;
use glam::{DVec3, Vec3};

/// Mean over pixels and channels of `per_pixel(reference, test)` (summed over channels).
fn channel_mean(reference: &[Vec3], test: &[Vec3], per_pixel: impl Fn(DVec3, DVec3) -> f64) -> f64 {
    assert_eq!(reference.len(), test.len(), "images differ in size");
    let sum: f64 = reference.iter().zip(test).map(|(a, b)| per_pixel(a.as_dvec3(), b.as_dvec3())).sum();
    sum / (3 * reference.len().max(1)) as f64
}

/// Root-mean-square error over pixels and channels.
///
/// # Panics
/// When the images differ in size.
#[must_use]
pub fn rmse(reference: &[Vec3], test: &[Vec3]) -> f64 {
    channel_mean(reference, test, |a, b| (b - a).length_squared()).sqrt()
}

/// Relative MSE: mean over pixels and channels of (test - ref)^2 / (ref^2 + 0.01), the
/// regularized form used in rendering papers.
///
/// # Panics
/// When the images differ in size.
#[must_use]
pub fn relative_mse(reference: &[Vec3], test: &[Vec3]) -> f64 {
    channel_mean(reference, test, |a, b| {
        let d = b - a;
        (d * d / (a * a + DVec3::splat(0.01))).element_sum()
    })
}

/// The tone mapping applied to both images before LDR-FLIP.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct FlipTonemap {
    /// Exposure + ACES + sRGB, with the reference's automatic exposure.
    pub tonemap: Tonemap,
}

impl FlipTonemap {
    /// The tone mapping for comparisons against `reference`.
    #[must_use]
    pub fn for_reference(reference: &[Vec3]) -> Self {
        Self { tonemap: Tonemap::auto(reference) }
    }

    /// One line stating the tone mapping, printed with FLIP values.
    #[must_use]
    pub fn describe(&self) -> String {
        format!(
            "LDR-FLIP after exposure {:.4} (reference log-average luminance to 0.18), ACES (Narkowicz), sRGB 8-bit; {} pixels per degree",
            self.tonemap.exposure,
            nv_flip::DEFAULT_PIXELS_PER_DEGREE
        )
    }
}

/// Mean LDR-FLIP error of the 8-bit sRGB image `test` against `reference` (both `width` x
/// `height`), in [0, 1]: for images that are 8-bit already (photographs, composites).
///
/// # Panics
/// When the images differ in size or do not match `width` x `height`.
#[must_use]
pub fn flip_rgb8(reference: &[[u8; 3]], test: &[[u8; 3]], width: u32, height: u32) -> f64 {
    assert_eq!(reference.len(), test.len(), "images differ in size");
    assert_eq!(reference.len(), (width * height) as usize, "size does not match the pixels");
    let (a, b): (Vec<u8>, Vec<u8>) = (reference.concat(), test.concat());
    let error = nv_flip::flip(
        nv_flip::FlipImageRgb8::with_data(width, height, &a),
        nv_flip::FlipImageRgb8::with_data(width, height, &b),
        nv_flip::DEFAULT_PIXELS_PER_DEGREE,
    );
    f64::from(nv_flip::FlipPool::from_image(&error).mean())
}

/// Mean FLIP error of `test` against `reference` (both `width` x `height`), in [0, 1].
///
/// # Panics
/// When the images differ in size or do not match `width` x `height`.
#[must_use]
pub fn flip(reference: &[Vec3], test: &[Vec3], width: u32, height: u32, tm: &FlipTonemap) -> f64 {
    assert_eq!(reference.len(), test.len(), "images differ in size");
    assert_eq!(reference.len(), (width * height) as usize, "size does not match the pixels");
    let ldr = |img: &[Vec3]| -> Vec<u8> { img.iter().flat_map(|p| tm.tonemap.apply(*p)).collect() };
    let (a, b) = (ldr(reference), ldr(test));
    let error = nv_flip::flip(
        nv_flip::FlipImageRgb8::with_data(width, height, &a),
        nv_flip::FlipImageRgb8::with_data(width, height, &b),
        nv_flip::DEFAULT_PIXELS_PER_DEGREE,
    );
    f64::from(nv_flip::FlipPool::from_image(&error).mean())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn metrics_of_known_differences() {
        let a = vec![Vec3::ZERO, Vec3::ONE];
        let b = vec![Vec3::splat(1.0), Vec3::ONE];
        // one pixel off by 1 in all channels: MSE = 3 / 6
        assert!((rmse(&a, &b) - 0.5f64.sqrt()).abs() < 1e-12);
        assert!((relative_mse(&a, &b) - 3.0 / 0.01 / 6.0).abs() < 1e-9);
        assert_eq!(rmse(&a, &a), 0.0);
    }

    #[test]
    fn flip_is_zero_for_equal_images_and_grows_with_the_difference() {
        let (w, h) = (32, 24);
        let img: Vec<Vec3> = (0..w * h).map(|k| Vec3::splat(0.1 + (k % 7) as f32 * 0.1)).collect();
        let tm = FlipTonemap::for_reference(&img);
        assert_eq!(flip(&img, &img, w, h, &tm), 0.0);
        let small: Vec<Vec3> = img.iter().map(|p| *p * 1.1).collect();
        let large: Vec<Vec3> = img.iter().map(|p| *p * 3.0).collect();
        let (fs, fl) = (flip(&img, &small, w, h, &tm), flip(&img, &large, w, h, &tm));
        assert!(fs > 0.0 && fl > 2.0 * fs && fl < 1.0, "{fs} {fl}");
        assert!(tm.describe().contains("ACES"));
    }

    #[test]
    fn flip_rgb8_agrees_with_flip_through_the_same_codes() {
        // an 8-bit image is what `flip` compares after its tone mapping: the same codes give
        // the same value, and a black image against a grey one the largest
        let (w, h) = (32, 24);
        let img: Vec<Vec3> = (0..w * h).map(|k| Vec3::splat(0.1 + (k % 7) as f32 * 0.1)).collect();
        let dim: Vec<Vec3> = img.iter().map(|p| *p * 0.7).collect();
        let tm = FlipTonemap::for_reference(&img);
        let codes = |i: &[Vec3]| -> Vec<[u8; 3]> { i.iter().map(|p| tm.tonemap.apply(*p)).collect() };
        let (a, b) = (codes(&img), codes(&dim));
        assert_eq!(flip_rgb8(&a, &a, w, h), 0.0);
        assert_eq!(flip_rgb8(&a, &b, w, h), flip(&img, &dim, w, h, &tm));
        let black = vec![[0u8; 3]; (w * h) as usize];
        assert!(flip_rgb8(&a, &black, w, h) > flip_rgb8(&a, &b, w, h));
    }
}
