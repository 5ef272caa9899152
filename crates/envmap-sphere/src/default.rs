//! The embedded default map, used by commands given no map.

use crate::envmap::EnvMap;
use crate::io::LoadOptions;

/// File name of the embedded map.
pub const DEFAULT_MAP_NAME: &str = "city.exr";

/// Its licence line.
pub const DEFAULT_MAP_CREDIT: &str =
    "city.exr by Greg Zaal, HDRI Haven / Poly Haven, CC0 (public domain), as bundled with Blender";

static BYTES: &[u8] = include_bytes!("../assets/city.exr");

/// The bytes of the embedded OpenEXR (DWAB) file.
#[must_use]
pub fn default_map_bytes() -> &'static [u8] {
    BYTES
}

/// The embedded default map: a real outdoor probe, 1024 x 512, with a small sun 48 degrees
/// above the horizon, 30,000 times the mean luminance, that casts crisp shadows. Its 506 slightly
/// negative DWAB values are clamped as [`LoadOptions::default`] does for any file.
///
/// # Panics
/// Never in practice: a test loads the embedded bytes.
#[must_use]
pub fn default_map() -> EnvMap {
    EnvMap::load_from_bytes(BYTES, DEFAULT_MAP_NAME, &LoadOptions::default())
        .map(|(map, _)| map)
        .expect("the embedded default map decodes")
}
