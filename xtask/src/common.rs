//! What several commands share, and nothing else: the leaf of `xtask`'s module tree (a command
//! module uses this and `lavapipe`, `thresholds` and `render`'s loaders, never another command's
//! internals; `tests/architecture.rs` checks the tree).

use envmap_sphere::EnvMap;
use glam::Vec3;
use real_scene::RealScene;
use std::path::Path;

/// Parses `WIDTHxHEIGHT`.
pub fn parse_size(s: &str) -> Result<(u32, u32), String> {
    let (w, h) = s.split_once('x').ok_or("expected WIDTHxHEIGHT, e.g. 320x240")?;
    Ok((w.parse().map_err(|e| format!("width: {e}"))?, h.parse().map_err(|e| format!("height: {e}"))?))
}

/// The map from `--envmap`, or the embedded default.
pub fn load_map(path: Option<&Path>) -> Result<EnvMap, String> {
    match path {
        Some(p) => EnvMap::load(p).map_err(|e| e.to_string()),
        None => Ok(envmap_sphere::default_map()),
    }
}

/// An environment-lit scene's map (the embedded one) and its extracted lights as distant
/// sources; nothing for a scene lit by its own patches.
pub fn environment(scene: &RealScene) -> Result<(Option<EnvMap>, Vec<scene::DistantLight>), String> {
    trade::session::environment(scene, light_extract::DEFAULT_METHOD, 32).map_err(|e| e.to_string())
}

/// Writes an image (name, size, 8-bit RGB) and returns its `<img>` element.
pub type WritePng<'a> = dyn Fn(&str, (u32, u32), &[u8]) -> Result<String, String> + 'a;

/// "X,Y,Z": three finite numbers.
pub fn parse_vec3(s: &str) -> Result<Vec3, String> {
    let v: Vec<f32> =
        s.split(',').map(|x| x.trim().parse::<f32>()).collect::<Result<_, _>>().map_err(|e| format!("{s:?}: {e}"))?;
    match v.as_slice() {
        [x, y, z] if v.iter().all(|c| c.is_finite()) => Ok(Vec3::new(*x, *y, *z)),
        _ => Err(format!("{s:?}: three finite numbers X,Y,Z")),
    }
}
