//! The camera that takes a real scene's photograph: a [`CameraResponse`] (exposure, a response
//! curve, clipping, 8 bits) turns the HDR image into the LDR photograph paper 003 composites
//! into. The HDR image itself is the caller's (a capture; in this project `trade::capture`
//! path traces it).

use glam::Vec3;
use rayon::prelude::*;

use crate::RealSceneError;

/// A camera's response T: code = round(255 · clamp((exposure · L / white)^(1 / gamma), 0, 1))
/// per channel, 8 bits.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct CameraResponse {
    /// Exposure: radiance scale before the curve.
    pub exposure: f32,
    /// The curve's gamma (2.2: the usual display-referred response).
    pub gamma: f32,
    /// Exposed radiance that saturates (code 255).
    pub white: f32,
}

impl CameraResponse {
    /// The response for a scene: exposure so that the 99th percentile of the HDR image's
    /// brightest channel reaches the white point (so about 1 % of pixels clip); gamma 2.2.
    #[must_use]
    pub fn auto(hdr: &[Vec3]) -> Self {
        let mut l: Vec<f32> = hdr.iter().map(|&c| c.max_element()).filter(|v| v.is_finite()).collect();
        l.sort_by(f32::total_cmp);
        let p99 = l.get(l.len() * 99 / 100).copied().unwrap_or(1.0);
        Self { exposure: if p99 > 0.0 { 1.0 / p99 } else { 1.0 }, gamma: 2.2, white: 1.0 }
    }

    /// T of one channel before quantization, in [0, 1] (non-finite and negative read as 0).
    #[must_use]
    pub fn curve(&self, radiance: f32) -> f32 {
        let x = radiance * self.exposure / self.white;
        if x.is_nan() || x <= 0.0 { 0.0 } else { x.min(1.0).powf(1.0 / self.gamma) }
    }

    /// The 8-bit code of one channel.
    #[must_use]
    pub fn code(&self, radiance: f32) -> u8 {
        (self.curve(radiance) * 255.0).round() as u8
    }

    /// The 8-bit pixel of a radiance.
    #[must_use]
    pub fn apply(&self, radiance: Vec3) -> [u8; 3] {
        radiance.to_array().map(|c| self.code(c))
    }

    /// The radiance a code stands for (the middle of its bin; 255 is the clip level, a lower
    /// bound).
    #[must_use]
    pub fn invert(&self, code: u8) -> f32 {
        (f32::from(code) / 255.0).powf(self.gamma) * self.white / self.exposure
    }

    /// True when the channel saturates.
    #[must_use]
    pub fn clips(&self, radiance: f32) -> bool {
        radiance * self.exposure >= self.white
    }
}

/// The largest side a photograph may have, pixels.
pub const MAX_PHOTO_SIDE: u32 = 16_384;

/// The most pixels a photograph may have (64 Mpx).
pub const MAX_PHOTO_PIXELS: u64 = 1 << 26;

/// A user's photograph of the real scene in linear RGB (row-major, row 0 at the top), and where
/// it saturated: an 8-bit or 16-bit PNG or a JPEG through a camera response's inverse (its
/// codes over their maximum, to the power gamma), or an OpenEXR / Radiance HDR image as it is.
#[derive(Clone, Debug, PartialEq)]
pub struct Photograph {
    /// Width in pixels.
    pub width: u32,
    /// Height in pixels.
    pub height: u32,
    /// Linear radiance in the photograph's own units.
    pub radiance: Vec<Vec3>,
    /// Per pixel, the channels that saturated (bit c for channel c).
    pub clipped: Vec<u8>,
    /// The radiance a channel saturates at, when the photograph clips: an integer image's top
    /// code (1), an HDR image's plateau at its maximum (found by [`Photograph::from_hdr`]).
    pub clip: Option<f32>,
    /// The gamma of the response it was read through (an HDR image's: 2.2, the curve its
    /// 8-bit previews are drawn with).
    pub gamma: f32,
}

impl Photograph {
    /// Reads a PNG, JPEG, OpenEXR or Radiance HDR photograph; integer images through the
    /// inverse of a response of `gamma`. Sizes are checked before decoding.
    ///
    /// # Errors
    /// [`RealSceneError::Photo`] naming the file: unreadable, another format, too large,
    /// undecodable, not finite or negative.
    pub fn open(path: &std::path::Path, gamma: f32) -> Result<Self, RealSceneError> {
        let bytes = std::fs::read(path)
            .map_err(|e| RealSceneError::Photo { path: path.to_path_buf(), reason: e.to_string() })?;
        Self::from_bytes(&bytes, path, gamma, MAX_PHOTO_PIXELS)
    }

    /// [`Photograph::open`] from a file's bytes; `path` names it in errors, and at most
    /// `max_pixels` (and [`MAX_PHOTO_PIXELS`]) are decoded.
    ///
    /// # Errors
    /// As [`Photograph::open`].
    pub fn from_bytes(
        bytes: &[u8],
        path: &std::path::Path,
        gamma: f32,
        max_pixels: u64,
    ) -> Result<Self, RealSceneError> {
        let fail = |reason: String| RealSceneError::Photo { path: path.to_path_buf(), reason };
        if !(gamma.is_finite() && (0.1..=10.0).contains(&gamma)) {
            return Err(fail(format!("a response gamma of {gamma} (0.1 to 10)")));
        }
        let max_pixels = max_pixels.min(MAX_PHOTO_PIXELS);
        // an HDR image through the maps' own reader; anything it does not know as one, an
        // integer image
        let options = envmap_sphere::LoadOptions { max_pixels, ..envmap_sphere::LoadOptions::default() };
        match envmap_sphere::load_rgb_image_from_bytes(bytes, path, &options) {
            Ok(image) if image.pixels.iter().any(|p| p.min_element() < 0.0) => {
                return Err(fail("negative radiance: not a photograph".into()));
            }
            Ok(image) => return Ok(Self::from_hdr(image.width, image.height, image.pixels)),
            Err(envmap_sphere::EnvMapError::UnknownFormat { .. }) => {}
            Err(e) => return Err(RealSceneError::Image(e.to_string())),
        }
        let guess = || {
            image::ImageReader::new(std::io::Cursor::new(bytes))
                .with_guessed_format()
                .map_err(|e| fail(format!("unreadable image: {}", one_line(&e))))
        };
        let reader = guess()?;
        if !matches!(reader.format(), Some(image::ImageFormat::Png | image::ImageFormat::Jpeg)) {
            return Err(fail("not a PNG, JPEG, OpenEXR or Radiance HDR image".into()));
        }
        let (w, h) = reader.into_dimensions().map_err(|e| fail(format!("unreadable image: {}", one_line(&e))))?;
        check_size(w, h, max_pixels).map_err(fail)?;
        let mut reader = guess()?;
        let mut limits = image::Limits::default();
        // 16-bit RGBA and the decoder's own buffers
        limits.max_alloc = Some((u64::from(w) * u64::from(h) * 16).max(1 << 20));
        reader.limits(limits);
        let decoded = reader.decode().map_err(|e| fail(format!("unreadable image: {}", one_line(&e))))?;
        let rgb = decoded.into_rgb32f();
        let codes: Vec<[f32; 3]> = rgb.pixels().map(|p| p.0).collect();
        Ok(Self::from_codes(w, h, &codes, gamma))
    }

    /// A photograph from an integer image's codes over their maximum (in [0, 1]) through the
    /// inverse of a response of `gamma`; a channel at 1 is clipped.
    #[must_use]
    pub fn from_codes(width: u32, height: u32, codes: &[[f32; 3]], gamma: f32) -> Self {
        // the top code: within half an 8-bit code of 1
        let top = 1.0 - 0.5 / 255.0;
        let radiance = codes.iter().map(|c| Vec3::from_array(c.map(|v| v.clamp(0.0, 1.0).powf(gamma)))).collect();
        let clipped = codes.iter().map(|c| (0..3).fold(0u8, |m, k| m | (u8::from(c[k] >= top) << k))).collect();
        Self { width, height, radiance, clipped, clip: Some(1.0), gamma }
    }

    /// A photograph from an HDR image. It clips where several pixels share its maximum exactly
    /// (a sensor's or a tone curve's plateau: at least 3 channel values and one in 2,000 of the
    /// pixels); a lone brightest pixel is light, not a clip.
    #[must_use]
    pub fn from_hdr(width: u32, height: u32, radiance: Vec<Vec3>) -> Self {
        let top = radiance.iter().map(|p| p.max_element()).filter(|v| v.is_finite()).fold(0.0f32, f32::max);
        let at_top = radiance.iter().map(|p| p.to_array().iter().filter(|&&v| v >= top).count()).sum::<usize>();
        let clip = (top > 0.0 && at_top >= 3.max(radiance.len() / 2000)).then_some(top);
        let clipped = radiance
            .iter()
            .map(|p| clip.map_or(0, |c| (0..3).fold(0u8, |m, k| m | (u8::from(p[k] >= c) << k))))
            .collect();
        Self { width, height, radiance, clipped, clip, gamma: 2.2 }
    }

    /// Pixels with a clipped channel.
    #[must_use]
    pub fn clipped_pixels(&self) -> usize {
        self.clipped.iter().filter(|&&m| m != 0).count()
    }

    /// The photograph with its radiance (and clip level) times `s`.
    #[must_use]
    pub fn scaled(mut self, s: f32) -> Self {
        self.radiance.iter_mut().for_each(|p| *p *= s);
        self.clip = self.clip.map(|c| c * s);
        self
    }

    /// The photograph at `width` x `height` (the box filter over the pixels whose centres fall
    /// in each new pixel, the nearest one where none does); a pixel is clipped where any it
    /// takes is.
    #[must_use]
    pub fn resized(&self, width: u32, height: u32) -> Self {
        if (width, height) == (self.width, self.height) || width == 0 || height == 0 {
            return self.clone();
        }
        let (sw, sh) = (self.width as usize, self.height as usize);
        let span = |i: usize, n: usize, s: usize| {
            let lo = ((i as f64 * s as f64 / n as f64) - 0.5).ceil().max(0.0) as usize;
            let hi = (((i + 1) as f64 * s as f64 / n as f64) - 0.5).ceil().min(s as f64) as usize;
            let nearest = (((i as f64 + 0.5) * s as f64 / n as f64) as usize).min(s - 1);
            if hi > lo { lo..hi } else { nearest..nearest + 1 }
        };
        let (w, h) = (width as usize, height as usize);
        let (radiance, clipped) = (0..w * h)
            .into_par_iter()
            .map(|k| {
                let (xs, ys) = (span(k % w, w, sw), span(k / w, h, sh));
                let (mut sum, mut mask, mut n) = (Vec3::ZERO, 0u8, 0.0f32);
                for y in ys {
                    for x in xs.clone() {
                        sum += self.radiance[y * sw + x];
                        mask |= self.clipped[y * sw + x];
                        n += 1.0;
                    }
                }
                (sum / n, mask)
            })
            .unzip();
        Self { width, height, radiance, clipped, clip: self.clip, gamma: self.gamma }
    }

    /// The scale that brings this photograph to `reference`'s units (the same view as the
    /// reference sees it, pixel for pixel): the median of their luminance ratios over the
    /// pixels neither clipped nor near black. `None` with fewer than 16 such pixels.
    #[must_use]
    pub fn exposure_against(&self, reference: &[Vec3]) -> Option<f32> {
        let floor = |v: &[f32]| v.iter().copied().fold(0.0f32, f32::max) * 1e-4;
        let ours: Vec<f32> = self.radiance.iter().map(|&p| crate::luminance(p)).collect();
        let theirs: Vec<f32> = reference.iter().map(|&p| crate::luminance(p)).collect();
        let (a, b) = (floor(&ours), floor(&theirs));
        let mut ratios: Vec<f32> = (0..ours.len().min(theirs.len()))
            .filter(|&k| self.clipped[k] == 0 && ours[k] > a && theirs[k] > b)
            .map(|k| theirs[k] / ours[k])
            .filter(|r| r.is_finite() && *r > 0.0)
            .collect();
        if ratios.len() < 16 {
            return None;
        }
        let mid = ratios.len() / 2;
        Some(*ratios.select_nth_unstable_by(mid, f32::total_cmp).1)
    }
}

fn check_size(w: u32, h: u32, max_pixels: u64) -> Result<(), String> {
    if w == 0 || h == 0 || w > MAX_PHOTO_SIDE || h > MAX_PHOTO_SIDE || u64::from(w) * u64::from(h) > max_pixels {
        return Err(format!(
            "{w} x {h} pixels: a photograph is 1 to {MAX_PHOTO_SIDE} pixels a side, at most {max_pixels} in all"
        ));
    }
    Ok(())
}

/// A decoder's message on one line (control characters from the file escaped).
fn one_line(e: &impl std::fmt::Display) -> String {
    envmap_sphere::error::one_line(&e.to_string())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn response_is_monotonic_clips_and_inverts_within_half_a_code() {
        let t = CameraResponse { exposure: 0.5, gamma: 2.2, white: 1.0 };
        let mut last = 0;
        for k in 0..=4000 {
            let l = k as f32 * 0.001;
            let c = t.code(l);
            assert!(c >= last);
            last = c;
            if !t.clips(l) && c > 0 && c < 255 {
                // the code's bin, half a code either side, holds the radiance
                let back = |x: f32| x.powf(t.gamma) * t.white / t.exposure;
                let (lo, hi) = (back((f32::from(c) - 0.5) / 255.0), back((f32::from(c) + 0.5) / 255.0));
                assert!(l >= lo * (1.0 - 1e-5) && l <= hi * (1.0 + 1e-5), "{l}: code {c}, bin {lo}..{hi}");
                assert!(t.invert(c) >= lo && t.invert(c) <= hi);
            }
        }
        assert_eq!(t.code(2.0), 255);
        assert!(t.clips(2.0) && !t.clips(1.9));
        assert_eq!(t.apply(Vec3::new(f32::NAN, -1.0, f32::INFINITY)), [0, 0, 255]);
        assert_eq!(t.code(0.0), 0);
    }

    #[test]
    fn auto_exposure_puts_the_99th_percentile_at_white() {
        let hdr: Vec<Vec3> = (0..1000).map(|k| Vec3::splat(k as f32 * 0.01)).collect();
        let t = CameraResponse::auto(&hdr);
        assert!((t.curve(9.9) - 1.0).abs() < 1e-3 && t.curve(5.0) < 1.0);
        let black = CameraResponse::auto(&[Vec3::ZERO; 4]);
        assert!(black.exposure.is_finite());
    }

    fn temp(name: &str) -> std::path::PathBuf {
        let dir = std::env::temp_dir().join(format!("envshadow-photo-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        dir.join(name)
    }

    #[test]
    fn an_hdr_plateau_is_a_clip_and_a_lone_maximum_is_not() {
        let ramp: Vec<Vec3> = (0..4000).map(|k| Vec3::new(k as f32 * 1e-3, 0.5, 0.25)).collect();
        let lone = Photograph::from_hdr(80, 50, ramp.clone());
        assert_eq!((lone.clip, lone.clipped_pixels()), (None, 0));
        let clipped: Vec<Vec3> = ramp.iter().map(|v| v.min(Vec3::splat(3.0))).collect();
        let p = Photograph::from_hdr(80, 50, clipped);
        assert_eq!(p.clip, Some(3.0));
        // red reaches 3 from pixel 3000 on; only red clips
        assert_eq!(p.clipped_pixels(), 1000);
        assert!(p.clipped[3500] == 1 && p.clipped[10] == 0);
        let black = Photograph::from_hdr(4, 4, vec![Vec3::ZERO; 16]);
        assert_eq!(black.clip, None);
    }

    #[test]
    fn codes_read_through_the_inverse_response_and_the_top_code_clips() {
        let p = Photograph::from_codes(3, 1, &[[0.0, 0.5, 1.0], [1.0, 1.0, 1.0], [0.25, 0.0, 0.0]], 2.2);
        let t = CameraResponse { exposure: 1.0, gamma: 2.2, white: 1.0 };
        // what the response writes back is the code read
        assert_eq!(t.apply(p.radiance[0]), [0, 128, 255]);
        assert_eq!(p.clipped, vec![4, 7, 0]);
        assert_eq!(p.clip, Some(1.0));
    }

    #[test]
    fn resizing_keeps_the_mean_and_the_clipped_pixels() {
        let pixels: Vec<Vec3> = (0..64 * 48).map(|k| Vec3::splat((k % 7) as f32)).collect();
        let mut p = Photograph::from_hdr(64, 48, pixels);
        // (its many pixels of 6 read as a plateau)
        p.clipped = vec![0; 64 * 48];
        p.clipped[64 * 10 + 5] = 2;
        let half = p.resized(32, 24);
        let mean = |v: &[Vec3]| v.iter().sum::<Vec3>() / v.len() as f32;
        assert!((mean(&half.radiance) - mean(&p.radiance)).abs().max_element() < 1e-4);
        assert_eq!(half.clipped_pixels(), 1);
        assert_eq!(half.clipped[32 * 5 + 2], 2);
        // up, and to a size of another ratio: every pixel from the nearest
        let up = p.resized(100, 75);
        assert_eq!(up.radiance.len(), 7500);
        assert!(up.radiance.iter().all(|v| v.x <= 6.0 && v.is_finite()));
    }

    #[test]
    fn exposure_is_recovered_from_the_unclipped_pixels() {
        let reference: Vec<Vec3> = (0..400).map(|k| Vec3::new(0.1 + k as f32 * 0.01, 0.2, 0.3)).collect();
        // a quarter of the exposure, the brightest fifth clipped
        let shot: Vec<Vec3> = reference.iter().map(|v| (*v * 0.25).min(Vec3::splat(0.8))).collect();
        let p = Photograph::from_hdr(20, 20, shot);
        assert!(p.clip.is_some());
        let s = p.exposure_against(&reference).unwrap();
        assert!((s - 4.0).abs() < 1e-3, "{s}");
        assert_eq!(Photograph::from_hdr(2, 2, vec![Vec3::ONE; 4]).exposure_against(&[Vec3::ONE; 4]), None);
    }

    #[test]
    fn photographs_open_and_bad_files_are_refused_naming_them() {
        // an 8-bit PNG round trip
        let path = temp("shot.png");
        let img = image::RgbImage::from_fn(8, 6, |x, y| image::Rgb([(x * 30) as u8, (y * 40) as u8, 255]));
        img.save(&path).unwrap();
        let p = Photograph::open(&path, 2.2).unwrap();
        assert_eq!((p.width, p.height, p.clipped_pixels()), (8, 6, 48));
        let t = CameraResponse { exposure: 1.0, gamma: 2.2, white: 1.0 };
        assert_eq!(t.apply(p.radiance[8 * 5 + 7]), [210, 200, 255]);
        // not an image, empty, missing, a bad gamma
        let text = temp("notes.png");
        std::fs::write(&text, "not a picture").unwrap();
        let empty = temp("empty.jpg");
        std::fs::write(&empty, b"").unwrap();
        for (bad, gamma) in [(&text, 2.2), (&empty, 2.2), (&temp("missing.png"), 2.2), (&path, f32::NAN), (&path, 0.0)]
        {
            let e = Photograph::open(bad, gamma).unwrap_err().to_string();
            assert!(e.contains(&bad.display().to_string()) && !e.contains('\n'), "{e}");
        }
        // a PNG header claiming 100000 x 100000 pixels: refused before decoding
        let huge = temp("huge.png");
        let mut bytes = Vec::new();
        image::RgbImage::new(1, 1).write_to(&mut std::io::Cursor::new(&mut bytes), image::ImageFormat::Png).unwrap();
        bytes[16..20].copy_from_slice(&100_000u32.to_be_bytes());
        bytes[20..24].copy_from_slice(&100_000u32.to_be_bytes());
        std::fs::write(&huge, &bytes).unwrap();
        let e = Photograph::open(&huge, 2.2).unwrap_err().to_string();
        assert!(e.contains("huge.png") && (e.contains("pixels") || e.contains("unreadable")), "{e}");
    }
}
