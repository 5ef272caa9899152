//! Image error metrics against a reference: RMSE and relative MSE over all pixels and channels.
//! (FLIP, the perceptual metric, lives with the commands that compare images.)

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
}
