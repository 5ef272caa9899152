//! Errors in 8-bit codes against the truth, as issue and paper state them: mean absolute and
//! RMSE over the pixels whose truth differs from the photograph (where the object changed
//! something) and over the whole image.

/// A composite's error against the truth, in 8-bit codes (per channel value).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct CodeError {
    /// Mean absolute error over the pixels whose truth differs from the photograph.
    pub mae_changed: f64,
    /// RMSE over those pixels.
    pub rmse_changed: f64,
    /// Mean absolute error over the whole image.
    pub mae: f64,
    /// RMSE over the whole image.
    pub rmse: f64,
    /// How many pixels the truth changed.
    pub changed: usize,
}

/// `image`'s error against `truth`; `photo` says which pixels the object changed.
///
/// # Panics
/// When the three images differ in size.
#[must_use]
pub fn code_error(image: &[[u8; 3]], truth: &[[u8; 3]], photo: &[[u8; 3]]) -> CodeError {
    assert!(image.len() == truth.len() && truth.len() == photo.len(), "images of different sizes");
    let (mut abs_c, mut sq_c, mut abs, mut sq, mut changed) = (0.0f64, 0.0f64, 0.0f64, 0.0f64, 0usize);
    for ((a, t), p) in image.iter().zip(truth).zip(photo) {
        let is_changed = t != p;
        changed += usize::from(is_changed);
        for c in 0..3 {
            let e = f64::from(a[c]) - f64::from(t[c]);
            abs += e.abs();
            sq += e * e;
            if is_changed {
                abs_c += e.abs();
                sq_c += e * e;
            }
        }
    }
    let (n, nc) = ((3 * image.len()).max(1) as f64, (3 * changed).max(1) as f64);
    CodeError {
        mae_changed: abs_c / nc,
        rmse_changed: (sq_c / nc).sqrt(),
        mae: abs / n,
        rmse: (sq / n).sqrt(),
        changed,
    }
}

/// |image - truth| x 8 per channel: the error map the command and the report write.
#[must_use]
pub fn error_image(image: &[[u8; 3]], truth: &[[u8; 3]]) -> Vec<[u8; 3]> {
    image
        .iter()
        .zip(truth)
        .map(|(a, t)| std::array::from_fn(|c| (u16::from(a[c].abs_diff(t[c])) * 8).min(255) as u8))
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn errors_count_codes_over_changed_pixels_and_all() {
        let photo = vec![[10, 10, 10]; 4];
        let mut truth = photo.clone();
        truth[1] = [4, 4, 4];
        let mut image = truth.clone();
        image[1] = [7, 4, 4]; // 3 codes off in one channel of the changed pixel
        image[3] = [10, 10, 12]; // 2 codes off where nothing changed
        let e = code_error(&image, &truth, &photo);
        assert_eq!(e.changed, 1);
        assert!((e.mae_changed - 1.0).abs() < 1e-12 && (e.rmse_changed - 3.0f64.sqrt()).abs() < 1e-12);
        assert!((e.mae - 5.0 / 12.0).abs() < 1e-12 && (e.rmse - (13.0f64 / 12.0).sqrt()).abs() < 1e-12);
        assert_eq!(code_error(&truth, &truth, &photo), CodeError { changed: 1, ..CodeError::default() });
        assert_eq!(error_image(&image, &truth)[3], [0, 0, 16]);
    }
}
