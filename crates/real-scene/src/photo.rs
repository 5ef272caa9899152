//! The camera that takes a real scene's photograph: a [`CameraResponse`] (exposure, a response
//! curve, clipping, 8 bits) turns the HDR image into the LDR photograph paper 003 composites
//! into. The HDR image itself is the caller's (a capture; in this project `trade::capture`
//! path traces it).

use glam::Vec3;

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
}
