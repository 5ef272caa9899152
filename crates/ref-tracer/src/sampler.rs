//! Deterministic sample points: every (seed, pixel, sample) has its own stream, so an image is
//! bit-identical for a seed whatever the thread count or tile order.
//!
//! Two kinds ([`SamplerKind`]):
//! - `Independent`: uniform numbers from a PCG stream per pixel sample; plain Monte Carlo, RMSE
//!   falls as 1 / sqrt(spp).
//! - `Sobol` (the default): each 2D dimension pair of a pixel's samples takes the first two
//!   dimensions of the Sobol sequence, Owen-scrambled and index-shuffled with hashes of (seed,
//!   pixel, pair) (Burley 2020, "Practical Hash-based Owen Scrambling"; a padded sampler like
//!   pbrt-v4's). Each pixel's first 2^m samples then form a (0, m, 2)-net in every pair, so
//!   sub-pixel positions, map samples and BRDF samples are stratified, and every point is still
//!   uniform: estimates stay unbiased, and renders with different seeds are independent.

use glam::Vec2;
use rand::Rng;
use rand_pcg::Pcg32;

/// SplitMix64 finalizer: decorrelates consecutive keys.
fn mix(mut z: u64) -> u64 {
    z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
    z ^ (z >> 31)
}

/// How a [`PixelSampler`] draws its numbers.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub enum SamplerKind {
    /// Independent uniform numbers (plain Monte Carlo).
    Independent,
    /// Owen-scrambled, shuffled Sobol points per 2D dimension pair (stratified).
    #[default]
    Sobol,
}

/// The numbers of one pixel sample.
pub struct PixelSampler {
    sample: u64,
    stream: Stream,
}

/// Where a [`PixelSampler`]'s numbers come from.
enum Stream {
    Independent(Pcg32),
    Sobol {
        /// hash of (seed, pixel): the scrambles derive from it per dimension pair
        key: u64,
        /// the last dimension pair drawn
        pair: u64,
    },
}

/// Laine and Karras's hash-based permutation that only lets a bit affect higher bits.
fn laine_karras(mut x: u32, seed: u32) -> u32 {
    x = x.wrapping_add(seed);
    x ^= x.wrapping_mul(0x6c50_b47c);
    x ^= x.wrapping_mul(0xb82f_1e52);
    x ^= x.wrapping_mul(0xc7af_e638);
    x ^= x.wrapping_mul(0x8d22_f6e6);
    x
}

/// Nested uniform (Owen) scramble of a 32-bit fraction: each bit flipped by a hash of the
/// bits above it.
fn owen_scramble(x: u32, seed: u32) -> u32 {
    laine_karras(x.reverse_bits(), seed).reverse_bits()
}

/// Direction numbers of the second Sobol dimension (primitive polynomial x + 1):
/// v_0 = 2^31, v_k = v_(k-1) ^ v_(k-1) >> 1.
const fn direction_numbers() -> [u32; 32] {
    let mut v = [0u32; 32];
    v[0] = 1 << 31;
    let mut k = 1;
    while k < 32 {
        v[k] = v[k - 1] ^ (v[k - 1] >> 1);
        k += 1;
    }
    v
}

/// The second dimension by bytes of the index: XOR of the direction numbers of a byte's set
/// bits, for each of the four byte positions (4 KiB; one look-up per byte instead of a loop
/// over 32 bits).
const SOBOL_1_BYTES: [[u32; 256]; 4] = {
    let v = direction_numbers();
    let mut t = [[0u32; 256]; 4];
    let mut byte = 0;
    while byte < 4 {
        let mut value = 0;
        while value < 256 {
            let (mut x, mut bit) = (0u32, 0);
            while bit < 8 {
                if value >> bit & 1 == 1 {
                    x ^= v[byte * 8 + bit];
                }
                bit += 1;
            }
            t[byte][value] = x;
            value += 1;
        }
        byte += 1;
    }
    t
};

/// The first two Sobol dimensions of index `i` as 32-bit fractions: van der Corput, and the
/// dimension of primitive polynomial x + 1.
fn sobol_pair(i: u32) -> (u32, u32) {
    let b = i.to_le_bytes();
    let y = SOBOL_1_BYTES[0][b[0] as usize]
        ^ SOBOL_1_BYTES[1][b[1] as usize]
        ^ SOBOL_1_BYTES[2][b[2] as usize]
        ^ SOBOL_1_BYTES[3][b[3] as usize];
    (i.reverse_bits(), y)
}

/// A 32-bit fraction as a float in [0, 1): its top 24 bits, exactly representable, never 1.
fn to_unit(x: u32) -> f32 {
    (x >> 8) as f32 * (1.0 / (1u32 << 24) as f32)
}

impl PixelSampler {
    /// The stream for (`seed`, `pixel`, `sample`) of the default kind.
    #[must_use]
    pub fn new(seed: u64, pixel: u64, sample: u64) -> Self {
        Self::with_kind(SamplerKind::default(), seed, pixel, sample)
    }

    /// The stream for (`seed`, `pixel`, `sample`) of `kind`.
    #[must_use]
    pub fn with_kind(kind: SamplerKind, seed: u64, pixel: u64, sample: u64) -> Self {
        let pixel_key = mix(seed ^ mix(pixel.wrapping_add(0x9e37_79b9_7f4a_7c15)));
        let stream = match kind {
            SamplerKind::Independent => {
                let key = pixel_key ^ mix(sample.wrapping_mul(0x2545_f491_4f6c_dd1d));
                // state and stream straight from the key: cheaper than seed_from_u64's seeding PCG
                Stream::Independent(Pcg32::new(key, mix(key ^ 0xda3e_39cb_94b9_5bdb)))
            }
            SamplerKind::Sobol => Stream::Sobol { key: pixel_key, pair: 0 },
        };
        Self { sample, stream }
    }

    /// The index of the pixel sample this stream belongs to (for stratifying a discrete choice
    /// over a pixel's samples).
    #[must_use]
    pub fn sample_index(&self) -> u64 {
        self.sample
    }

    /// The next dimension pair's scrambled Sobol point (as 32-bit fractions) of sample
    /// `sample`.
    fn sobol_2d(sample: u64, key: u64, pair: &mut u64) -> (u32, u32) {
        *pair += 1;
        let h = mix(key ^ mix(pair.wrapping_mul(0x9e37_79b9_7f4a_7c15)));
        let h2 = mix(h);
        // shuffling the index by an Owen scramble keeps every aligned block of 2^m samples a
        // block of the sequence, so a pixel's first 2^m samples stay a net
        let index = owen_scramble(sample as u32, h as u32);
        let (x, y) = sobol_pair(index);
        (owen_scramble(x, (h >> 32) as u32), owen_scramble(y, h2 as u32))
    }

    /// A number in [0, 1).
    pub fn next_1d(&mut self) -> f32 {
        match &mut self.stream {
            // 24 random bits: exactly representable, never 1.0
            Stream::Independent(rng) => to_unit(rng.random::<u32>()),
            Stream::Sobol { key, pair } => to_unit(Self::sobol_2d(self.sample, *key, pair).0),
        }
    }

    /// A point in [0, 1)^2.
    pub fn next_2d(&mut self) -> Vec2 {
        match &mut self.stream {
            Stream::Independent(rng) => Vec2::new(to_unit(rng.random::<u32>()), to_unit(rng.random::<u32>())),
            Stream::Sobol { key, pair } => {
                let (x, y) = Self::sobol_2d(self.sample, *key, pair);
                Vec2::new(to_unit(x), to_unit(y))
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn sobol_pair_is_the_sobol_sequence() {
        let first: Vec<(f32, f32)> = (0..8).map(sobol_pair).map(|(x, y)| (to_unit(x), to_unit(y))).collect();
        let want = [
            (0.0, 0.0),
            (0.5, 0.5),
            (0.25, 0.75),
            (0.75, 0.25),
            (0.125, 0.625),
            (0.625, 0.125),
            (0.375, 0.375),
            (0.875, 0.875),
        ];
        assert_eq!(first, want);
    }

    #[test]
    fn a_pixels_first_power_of_two_samples_form_a_net_in_every_pair() {
        // 256 samples: every elementary box 2^-a x 2^-b with a + b = 8 holds exactly one point,
        // in each of four dimension pairs, for several seeds and pixels
        for (seed, pixel) in [(0, 0), (1, 17), (99, 123_456)] {
            let points: Vec<Vec<Vec2>> = (0..256)
                .map(|k| {
                    let mut s = PixelSampler::with_kind(SamplerKind::Sobol, seed, pixel, k);
                    (0..4).map(|_| s.next_2d()).collect()
                })
                .collect();
            for pair in 0..4 {
                for a in 0..=8 {
                    let mut count = vec![0u32; 256];
                    for p in &points {
                        let (x, y) =
                            ((p[pair].x * (1 << a) as f32) as usize, (p[pair].y * (1 << (8 - a)) as f32) as usize);
                        count[(x << (8 - a)) | y] += 1;
                    }
                    assert!(count.iter().all(|&c| c == 1), "seed {seed} pixel {pixel} pair {pair} boxes {a}/{}", 8 - a);
                }
            }
        }
    }

    #[test]
    fn scrambled_points_are_uniform_over_pixels() {
        // chi-square over 16 x 16 cells of one sample's point in 16384 pixels (255 dof: the
        // 99.9 % quantile is ~330)
        for kind in [SamplerKind::Sobol, SamplerKind::Independent] {
            let mut cells = vec![0u32; 256];
            for pixel in 0..16_384 {
                let p = PixelSampler::with_kind(kind, 5, pixel, 3).next_2d();
                cells[(p.x * 16.0) as usize * 16 + (p.y * 16.0) as usize] += 1;
            }
            let expected = 16_384.0 / 256.0;
            let chi2: f64 = cells.iter().map(|&c| (f64::from(c) - expected).powi(2) / expected).sum();
            assert!(chi2 < 330.0, "{kind:?}: chi-square {chi2}");
        }
    }
}
