//! Image error metrics against a reference: RMSE and relative MSE over all pixels and channels,
//! and FLIP (Andersson et al. 2020), the perceptual difference, through the `nv-flip` bindings.
//!
//! FLIP here is LDR-FLIP: both images go through the same tone mapping first, stated by
//! [`FlipTonemap::describe`] and printed with every result: the reference's automatic exposure
//! (log-average luminance to 0.18), the ACES filmic fit, sRGB encoding to 8 bits, and 67 pixels
//! per degree (a 0.7 m wide 4K monitor seen from 0.7 m, FLIP's default).
//!
//! [`banding`] measures one artefact on its own: the staircase a global set of lights draws
//! across a penumbra, and the noise interleaved light sets trade it for.

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

/// The viewing distance FLIP assumes, in pixels per degree (FLIP's default).
pub const FLIP_PIXELS_PER_DEGREE: f32 = nv_flip::DEFAULT_PIXELS_PER_DEGREE;

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

/// Shadow-boundary banding across straight shadow edges that run down the image's columns: a
/// global set of K lights draws a penumbra as up to K steps where the truth is a smooth ramp
/// (paper 001, section 3.5); interleaved light sets trade the steps for noise.
///
/// The profile is the image's mean down each column, box-filtered over `scale` columns (an
/// interleaving tile's width: finer than that is the tile's pattern, which the filter that
/// completes interleaved sampling removes); a jump is the filtered profile's change over
/// `scale` columns, so a sharp step keeps its full height. Every figure but the counts is in
/// units of the truth's contrast over the columns measured.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Banding {
    /// Columns measured.
    pub columns: usize,
    /// The box filter's width in columns.
    pub scale: usize,
    /// The truth profile's largest minus smallest luminance: the unit of the figures below.
    pub contrast: f64,
    /// The largest jump of the image's profile beyond the truth's largest jump within
    /// [`BANDING_WINDOW`] columns of it.
    pub largest_step: f64,
    /// The truth's own largest jump (its ramp's resolution at this scale).
    pub truth_largest_step: f64,
    /// Jumps beyond the truth's (as in `largest_step`) by more than `weber` of the truth's
    /// darker side, neighbouring ones counted once: the steps an observer sees.
    pub visible_steps: usize,
    /// RMS of the filtered profile's error against the filtered truth (banding and any smooth
    /// bias).
    pub profile_error: f64,
    /// RMS of the image about its column means: the noise along the edge that interleaving
    /// brings (the tile's pattern across the columns is what `scale` filters out).
    pub noise: f64,
}

/// The mean luminance down each of `image`'s `width` columns (row-major): the profile across
/// edges that run down the columns, as [`banding`] takes it.
///
/// # Panics
/// When `image` is not `width` columns by whole rows.
#[must_use]
pub fn column_means(image: &[Vec3], width: usize) -> Vec<f64> {
    assert!(width > 0 && image.len().is_multiple_of(width), "image is not {width} columns wide");
    let rows = (image.len() / width).max(1) as f64;
    let mut sums = vec![0.0; width];
    for row in image.chunks_exact(width) {
        for (s, p) in sums.iter_mut().zip(row) {
            *s += f64::from(envmap_sphere::color::luminance(*p));
        }
    }
    sums.into_iter().map(|s| s / rows).collect()
}

/// Columns on either side within which a jump of the truth excuses one of the image's: an edge
/// drawn up to this far from the truth's is not counted as a band.
pub const BANDING_WINDOW: usize = 2;

/// [`Banding`] of `image` (`width` columns, row-major) against `truth`, the truth's luminance
/// per column (`None`: the column is not measured, e.g. it sees the occluder), at `scale`
/// columns (1: no filter). Only runs of measured columns enter a filter or a jump. `None` when
/// no jump can be measured or the truth has no contrast.
///
/// # Panics
/// When `image` is not `width` columns by whole rows or `truth` has not `width` entries.
#[must_use]
pub fn banding(image: &[Vec3], width: usize, truth: &[Option<f64>], weber: f64, scale: usize) -> Option<Banding> {
    assert!(width > 0 && image.len().is_multiple_of(width) && truth.len() == width, "image and truth sizes differ");
    let scale = scale.max(1);
    let rows = image.len() / width;
    let luminance = |x: usize, y: usize| f64::from(envmap_sphere::color::luminance(image[y * width + x]));
    let means = column_means(image, width);
    let columns: Vec<Option<(f64, f64)>> =
        (0..width).map(|x| truth[x].filter(|t| t.is_finite()).map(|t| (means[x], t))).collect();
    // (image, truth) box-filtered over columns x..x + scale, where all are measured
    let filtered: Vec<Option<(f64, f64)>> = (0..width)
        .map(|x| {
            let run = columns.get(x..x + scale)?;
            let sum = run.iter().try_fold((0.0, 0.0), |(p, t), c| c.map(|c| (p + c.0, t + c.1)))?;
            Some((sum.0 / scale as f64, sum.1 / scale as f64))
        })
        .collect();
    let measured = columns.iter().flatten().count();
    let (lo, hi) =
        columns.iter().flatten().fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), c| (lo.min(c.1), hi.max(c.1)));
    let contrast = hi - lo;
    // (image's jump, truth's jump, truth's darker side) over scale columns from x
    let jumps: Vec<Option<(f64, f64, f64)>> = (0..width)
        .map(|x| match (filtered[x], filtered.get(x + scale).copied().flatten()) {
            (Some((p0, t0)), Some((p1, t1))) => Some(((p1 - p0).abs(), (t1 - t0).abs(), t0.min(t1))),
            _ => None,
        })
        .collect();
    if jumps.iter().flatten().next().is_none() || contrast.is_nan() || contrast <= 0.0 {
        return None;
    }
    let (mut largest, mut truth_largest, mut visible) = (0.0f64, 0.0f64, 0);
    // a step smeared over neighbouring jumps is one step
    let mut in_step = false;
    for x in 0..width {
        let Some((dp, dt, darker)) = jumps[x] else {
            in_step = false;
            continue;
        };
        let near = jumps[x.saturating_sub(BANDING_WINDOW)..(x + BANDING_WINDOW + 1).min(width)]
            .iter()
            .flatten()
            .fold(0.0f64, |m, j| m.max(j.1));
        let excess = (dp - near).max(0.0);
        largest = largest.max(excess);
        truth_largest = truth_largest.max(dt);
        let seen = excess > weber * darker.max(0.0) && excess > 1e-9 * contrast;
        if seen && !in_step {
            visible += 1;
        }
        in_step = seen;
    }
    let kept: Vec<(f64, f64)> = filtered.iter().flatten().copied().collect();
    let n = kept.len().max(1) as f64;
    let profile_error = (kept.iter().map(|k| (k.0 - k.1).powi(2)).sum::<f64>() / n).sqrt();
    // each pixel against its column's mean: the variation along the edge
    let noise = (columns
        .iter()
        .enumerate()
        .filter_map(|(x, c)| c.map(|(p, _)| (0..rows).map(|y| (luminance(x, y) - p).powi(2)).sum::<f64>()))
        .sum::<f64>()
        / (measured.max(1) * rows.max(1)) as f64)
        .sqrt();
    Some(Banding {
        columns: measured,
        scale,
        contrast,
        largest_step: largest / contrast,
        truth_largest_step: truth_largest / contrast,
        visible_steps: visible,
        profile_error: profile_error / contrast,
        noise: noise / contrast,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A ramp over columns 10..50 of 0..1 (luminance of grey), flat either side.
    fn ramp(x: usize) -> f64 {
        ((x as f64 - 10.0) / 40.0).clamp(0.0, 1.0)
    }

    fn image_of(width: usize, rows: usize, f: impl Fn(usize, usize) -> f64) -> Vec<Vec3> {
        (0..rows).flat_map(|y| (0..width).map(move |x| (x, y))).map(|(x, y)| Vec3::splat(f(x, y) as f32)).collect()
    }

    #[test]
    fn banding_counts_a_staircase_and_not_its_smooth_truth() {
        let (w, rows) = (60, 8);
        let truth: Vec<Option<f64>> = (0..w).map(|x| Some(ramp(x))).collect();
        let smooth = banding(&image_of(w, rows, |x, _| ramp(x)), w, &truth, 0.02, 1).unwrap();
        assert!(smooth.largest_step < 1e-6 && smooth.visible_steps == 0, "{smooth:?}");
        assert!(smooth.noise < 1e-6 && smooth.profile_error < 1e-6);
        assert!((smooth.truth_largest_step - 1.0 / 40.0).abs() < 1e-6);
        // four lights: four steps of a quarter, at the ramp's quarter points
        let stairs = |x: usize| (ramp(x) * 4.0).floor() / 4.0;
        let b = banding(&image_of(w, rows, |x, _| stairs(x)), w, &truth, 0.02, 1).unwrap();
        assert_eq!(b.visible_steps, 4, "{b:?}");
        assert!((b.largest_step - (0.25 - 1.0 / 40.0)).abs() < 1e-6, "{b:?}");
        assert!(b.noise < 1e-6 && b.profile_error > 0.05);
        // the same steps, each split over two neighbouring columns: still four steps, half as tall
        let smeared = |x: usize| (stairs(x) + stairs(x + 1)) / 2.0;
        let b = banding(&image_of(w, rows, |x, _| smeared(x)), w, &truth, 0.02, 1).unwrap();
        assert_eq!(b.visible_steps, 4, "{b:?}");
        assert!((b.largest_step - (0.125 - 1.0 / 40.0)).abs() < 1e-6, "{b:?}");
    }

    #[test]
    fn interleaving_trades_banding_for_noise() {
        let (w, rows) = (60, 8);
        let truth: Vec<Option<f64>> = (0..w).map(|x| Some(ramp(x))).collect();
        let stairs = |x: usize, offset: f64| ((ramp(x) * 4.0 + offset).floor() / 4.0).min(1.0);
        let one = banding(&image_of(w, rows, |x, _| stairs(x, 0.0)), w, &truth, 0.02, 1).unwrap();
        // 8 sets, each with its steps shifted by an eighth of a step, one set per row
        let eight = banding(&image_of(w, rows, |x, y| stairs(x, y as f64 / 8.0)), w, &truth, 0.02, 1).unwrap();
        assert!(eight.largest_step < one.largest_step / 3.0, "{one:?} {eight:?}");
        assert!(eight.noise > 0.05 && one.noise < 1e-6, "{one:?} {eight:?}");
        // the sets in a 4-column pattern instead: each column's mean alternates, bands at
        // scale 1; the filter over the tile's 4 columns sees what the rows' version saw
        let tiled = image_of(w, rows, |x, _| stairs(x, (x % 4) as f64 / 4.0));
        let raw = banding(&tiled, w, &truth, 0.02, 1).unwrap();
        let filtered = banding(&tiled, w, &truth, 0.02, 4).unwrap();
        let one_at_4 = banding(&image_of(w, rows, |x, _| stairs(x, 0.0)), w, &truth, 0.02, 4).unwrap();
        assert!(raw.visible_steps > one.visible_steps, "{raw:?}");
        assert!(filtered.largest_step < 0.6 * one_at_4.largest_step, "{filtered:?} {one_at_4:?}");
        // a sharp step keeps its full height through the filter (less the truth's ramp over 4
        // columns, shorter where the ramp ends)
        assert!((0.15..0.16).contains(&one_at_4.largest_step), "{one_at_4:?}");
        assert!(one_at_4.noise < 1e-6 && filtered.noise < 1e-6, "a pattern across, none along");
    }

    #[test]
    fn banding_excuses_an_edge_drawn_a_pixel_off() {
        let (w, rows) = (40, 4);
        let edge = |x: usize, at: usize| if x < at { 0.2 } else { 1.0 };
        let truth: Vec<Option<f64>> = (0..w).map(|x| Some(edge(x, 20))).collect();
        let b = banding(&image_of(w, rows, |x, _| edge(x, 21)), w, &truth, 0.02, 1).unwrap();
        assert_eq!((b.largest_step, b.visible_steps), (0.0, 0), "{b:?}");
        assert!((b.truth_largest_step - 1.0).abs() < 1e-6);
        // drawn far off, it is a step the truth does not have
        let far = banding(&image_of(w, rows, |x, _| edge(x, 30)), w, &truth, 0.02, 1).unwrap();
        assert!(far.largest_step > 0.99 && far.visible_steps == 1, "{far:?}");
    }

    #[test]
    fn banding_skips_unmeasured_columns_and_refuses_no_contrast() {
        let (w, rows) = (20, 2);
        let image = image_of(w, rows, |x, _| if x == 10 { 1e30 } else { x as f64 });
        // the spike's column is not measured, so no pair touches it
        let truth: Vec<Option<f64>> = (0..w).map(|x| (x != 10).then_some(x as f64)).collect();
        let b = banding(&image, w, &truth, 0.02, 1).unwrap();
        assert_eq!(b.columns, 19);
        assert!(b.largest_step < 1e-6 && b.visible_steps == 0 && b.profile_error < 1e-6, "{b:?}");
        let flat: Vec<Option<f64>> = vec![Some(1.0); w];
        assert!(banding(&image, w, &flat, 0.02, 1).is_none());
        assert!(banding(&image, w, &[None; 20], 0.02, 1).is_none());
        let nan: Vec<Option<f64>> = vec![Some(f64::NAN); w];
        assert!(banding(&image, w, &nan, 0.02, 1).is_none());
    }

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
