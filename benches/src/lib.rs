//! The criterion suite lives in `benches/benches/`: one file per crate, each bench named after
//! the knob it measures. `cargo bench -p envshadow-benches` runs it; `cargo xtask test` runs
//! every bench once so none rots. This library holds the inputs benches share.

pub mod decomposition;
pub mod soft_shadows;

use envmap_sphere::EnvMap;

/// The embedded default map (1024 x 512), the input of most benches.
#[must_use]
pub fn bench_map() -> EnvMap {
    envmap_sphere::default_map()
}
