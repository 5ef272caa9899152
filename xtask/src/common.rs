//! What several commands share, and nothing else: the leaf of `xtask`'s module tree (a command
//! module uses this, `lavapipe` and `thresholds`, never another command's internals;
//! `tests/architecture.rs` checks the tree).

use envmap_sphere::EnvMap;
use real_scene::RealScene;

pub use trade::args::{load_map, parse_size};

/// The scene `spec` names (built-in or glTF model) at `size`, a model on a ground of albedo
/// `ground`; the import's warnings go to stderr (stdout may be a `--json` object).
pub fn open_scene(spec: &str, size: (u32, u32), ground: Option<f32>) -> Result<scene::Scene, String> {
    let (scene, warnings) = trade::args::open_scene(spec, size, ground).map_err(|e| e.to_string())?;
    for w in warnings {
        eprintln!("warning: {spec}: {w}");
    }
    Ok(scene)
}

/// An environment-lit scene's map (the embedded one) and its extracted lights as distant
/// sources; nothing for a scene lit by its own patches.
pub fn environment(scene: &RealScene) -> Result<(Option<EnvMap>, Vec<scene::DistantLight>), String> {
    trade::session::environment(scene, light_extract::DEFAULT_METHOD, 32).map_err(|e| e.to_string())
}

/// Writes an image (name, size, 8-bit RGB) and returns its `<img>` element.
pub type WritePng<'a> = dyn Fn(&str, (u32, u32), &[u8]) -> Result<String, String> + 'a;
