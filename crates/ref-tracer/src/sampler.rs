//! Deterministic random numbers: every (seed, pixel, sample) has its own PCG stream, so an image
//! is bit-identical for a seed whatever the thread count or tile order.

use glam::Vec2;
use rand::Rng;
use rand_pcg::Pcg32;

/// SplitMix64 finalizer: decorrelates consecutive keys.
fn mix(mut z: u64) -> u64 {
    z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
    z ^ (z >> 31)
}

/// The random stream of one pixel sample.
pub struct PixelSampler {
    rng: Pcg32,
    sample: u64,
}

impl PixelSampler {
    /// The stream for (`seed`, `pixel`, `sample`).
    #[must_use]
    pub fn new(seed: u64, pixel: u64, sample: u64) -> Self {
        let key = mix(seed
            ^ mix(pixel.wrapping_add(0x9e37_79b9_7f4a_7c15))
            ^ mix(sample.wrapping_mul(0x2545_f491_4f6c_dd1d)));
        // state and stream straight from the key: cheaper than seed_from_u64's seeding PCG
        Self { rng: Pcg32::new(key, mix(key ^ 0xda3e_39cb_94b9_5bdb)), sample }
    }

    /// The index of the pixel sample this stream belongs to (for stratifying a discrete choice
    /// over a pixel's samples).
    #[must_use]
    pub fn sample_index(&self) -> u64 {
        self.sample
    }

    /// A number in [0, 1).
    pub fn next_1d(&mut self) -> f32 {
        // 24 random bits: exactly representable, never 1.0
        (self.rng.random::<u32>() >> 8) as f32 * (1.0 / (1u32 << 24) as f32)
    }

    /// A point in [0, 1)^2.
    pub fn next_2d(&mut self) -> Vec2 {
        Vec2::new(self.next_1d(), self.next_1d())
    }
}
