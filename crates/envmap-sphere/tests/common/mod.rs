//! Helpers for the integration tests: the repository's test maps and fixed-seed randomness.

#![allow(dead_code)]

use glam::Vec3;
use rand::{Rng, SeedableRng};
use rand_pcg::Pcg64Mcg;
use std::path::PathBuf;

/// The repository's test maps (`assets/envmaps`, or `ENVSHADOW_ENVMAPS`).
pub fn envmaps_dir() -> PathBuf {
    test_set::dir()
}

/// Every map of the test set, sorted. Panics when they are missing: the tests that use them must
/// not pass vacuously.
pub fn shared_maps() -> Vec<PathBuf> {
    test_set::maps().unwrap_or_else(|e| panic!("{e}"))
}

pub fn rng(seed: u64) -> Pcg64Mcg {
    Pcg64Mcg::seed_from_u64(seed)
}

/// A uniformly distributed unit vector.
pub fn random_dir(rng: &mut impl Rng) -> Vec3 {
    let z: f32 = rng.random_range(-1.0..1.0);
    let phi: f32 = rng.random_range(0.0..std::f32::consts::TAU);
    let r = (1.0 - z * z).max(0.0).sqrt();
    Vec3::new(r * phi.cos(), r * phi.sin(), z)
}

/// `n` unit vectors spread evenly over the sphere (Fibonacci lattice): equal-area weights.
pub fn fibonacci_dirs(n: usize) -> Vec<Vec3> {
    let golden = std::f64::consts::PI * (3.0 - 5f64.sqrt());
    (0..n)
        .map(|k| {
            let y = 1.0 - (k as f64 + 0.5) / n as f64 * 2.0;
            let r = (1.0 - y * y).sqrt();
            let phi = golden * k as f64;
            Vec3::new((r * phi.cos()) as f32, y as f32, (r * phi.sin()) as f32)
        })
        .collect()
}

/// A scratch directory under the target dir, fresh for each name.
pub fn scratch_dir(name: &str) -> PathBuf {
    let dir = PathBuf::from(env!("CARGO_TARGET_TMPDIR")).join(name);
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).expect("create scratch dir");
    dir
}
