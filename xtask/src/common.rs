//! What several commands share, and nothing else: the leaf of `xtask`'s module tree (a command
//! module uses this, `lavapipe` and `thresholds`, never another command's internals;
//! `tests/architecture.rs` checks the tree).

use envmap_sphere::EnvMap;
use real_scene::RealScene;

pub use trade::args::{load_map, parse_size};

/// An environment-lit scene's map (the embedded one) and its extracted lights as distant
/// sources; nothing for a scene lit by its own patches.
pub fn environment(scene: &RealScene) -> Result<(Option<EnvMap>, Vec<scene::DistantLight>), String> {
    trade::session::environment(scene, light_extract::DEFAULT_METHOD, 32).map_err(|e| e.to_string())
}

/// Writes an image (name, size, 8-bit RGB) and returns its `<img>` element.
pub type WritePng<'a> = dyn Fn(&str, (u32, u32), &[u8]) -> Result<String, String> + 'a;
