//! The criterion suite lives in `benches/benches/`: one file per crate, each bench named after
//! the knob it measures. `cargo bench -p envshadow-benches` runs it; `cargo xtask test` runs
//! every bench once so none rots. This library holds the inputs benches share.

pub mod decomposition;
pub mod frame_stats;
pub mod soft_shadows;

use criterion::measurement::WallTime;
use criterion::{BenchmarkGroup, Criterion};
use envmap_sphere::EnvMap;

/// The embedded default map (1024 x 512), the input of most benches.
#[must_use]
pub fn bench_map() -> EnvMap {
    envmap_sphere::default_map()
}

/// The value of a benchmarked call that must not fail: an error panics, so a bench whose work
/// errors fails its smoke run in `cargo xtask test` instead of timing the error path.
///
/// # Panics
/// When `r` is an error, with its message.
#[track_caller]
pub fn ok<T, E: std::fmt::Display>(r: Result<T, E>) -> T {
    r.unwrap_or_else(|e| panic!("bench input failed: {e}"))
}

/// A group of slow benchmarks (a whole frame, a render, a build): criterion's least sample
/// count, 10, so the suite finishes on a 2-core machine.
pub fn slow_group<'a>(c: &'a mut Criterion, name: impl Into<String>) -> BenchmarkGroup<'a, WallTime> {
    let mut group = c.benchmark_group(name);
    group.sample_size(10);
    group
}

/// Whether criterion is benchmarking (it passes `--bench`); otherwise this is `cargo test`'s one
/// smoke run, and a bench may shrink its input.
#[must_use]
pub fn benchmarking() -> bool {
    std::env::args().any(|a| a == "--bench")
}
