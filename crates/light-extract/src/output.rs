//! Files a decomposition is written as: `lights.json`, `ambient.exr` and `lights.gltf`.
//!
//! `lights.json` (units: radiance in the map's units, W/(m^2 sr) for a calibrated map; solid
//! angles in steradians; angles in radians; directions are unit vectors towards the light in
//! the toolkit's world, right-handed, +Y up):
//!
//! ```text
//! { "method": "median-cut", "params": {...}, "time_ms": 1.2,
//!   "map_power": [r, g, b],          // integral of the map's radiance over the sphere
//!   "ambient_power": [r, g, b],      // the same for the remainder (ambient.exr)
//!   "lights": [ { "direction": [x, y, z], "solid_angle": sr, "half_angle": rad,
//!                 "radiance": [r, g, b], "power": [r, g, b], "extent": rad,
//!                 "indirect": bool }, ... ],  // one of paper 001's EnvIndirects
//!   "interleaved": [ [ light, ... ], ... ] }   // the extra sets of interleaved sampling
//! ```
//!
//! `ambient.exr` is the remainder: non-negative, except for `+residual` methods, whose remainder
//! is the signed residual map - lights (read it without clamping negatives, e.g.
//! `NegativePolicy::Keep`).
//!
//! `power` is radiance x solid angle: the irradiance the light gives a surface facing it. In
//! `lights.gltf` each light is a `KHR_lights_punctual` directional light whose node's -Z axis
//! points the way the light travels (away from `direction`); `intensity` is the luminance
//! 0.2126 R + 0.7152 G + 0.0722 B of `power` times `lux_per_unit` (683 lm/W for a map calibrated
//! in W/(m^2 sr); 1 keeps the map's own units), and `color` is `power` divided by its largest
//! component.

use crate::decomposition::{Decomposition, ExtractedLight, WriteError};
use envmap_sphere::error::one_line;
use glam::{Quat, Vec3};
use scene::DistantLight;
use serde::Deserialize;
use serde_json::{Value, json};
use std::path::{Path, PathBuf};

/// A `lights.json` that cannot be read: names the file and the reason, on one line.
#[derive(Debug, thiserror::Error)]
pub enum LightsFileError {
    /// The file cannot be read.
    #[error("{path}: {source}")]
    Io {
        /// The file.
        path: PathBuf,
        /// What the system said.
        source: std::io::Error,
    },
    /// Not JSON of the schema (the position is serde_json's line and column).
    #[error("{path}: not a lights.json: {reason}")]
    Parse {
        /// The file.
        path: PathBuf,
        /// What the parser said.
        reason: String,
    },
    /// A light whose values are out of range.
    #[error(
        "{path}: light {index}{set} is invalid: direction must be finite and non-zero, solid_angle in (0, 4 pi], \
         radiance finite and non-negative"
    )]
    InvalidLight {
        /// The file.
        path: PathBuf,
        /// Index of the light in its set.
        index: usize,
        /// " of interleaved set N", or empty for the lights themselves.
        set: String,
    },
}

/// The lights a `lights.json` holds for rendering: the lights and the extra interleaved sets.
#[derive(Clone, Debug, PartialEq)]
pub struct LightsFile {
    /// `lights[]`.
    pub lights: Vec<DistantLight>,
    /// `interleaved[][]` (may be empty).
    pub interleaved: Vec<Vec<DistantLight>>,
    /// Per light of `lights`, whether it is one of paper 001's EnvIndirects (`indirect`; false
    /// when absent).
    pub indirect: Vec<bool>,
}

#[derive(Deserialize)]
struct RawFile {
    lights: Vec<RawLight>,
    #[serde(default)]
    interleaved: Vec<Vec<RawLight>>,
}

#[derive(Deserialize)]
struct RawLight {
    direction: [f32; 3],
    solid_angle: f32,
    radiance: [f32; 3],
    #[serde(default)]
    indirect: bool,
}

fn check_lights(path: &Path, raw: &[RawLight], set: Option<usize>) -> Result<Vec<DistantLight>, LightsFileError> {
    raw.iter()
        .enumerate()
        .map(|(index, l)| {
            let d = Vec3::from_array(l.direction);
            let r = Vec3::from_array(l.radiance);
            let ok = d.is_finite()
                && d.length() > 0.0
                && d.length().is_finite()
                && l.solid_angle > 0.0
                && l.solid_angle <= 4.0 * std::f32::consts::PI
                && r.is_finite()
                && r.min_element() >= 0.0;
            if !ok {
                return Err(LightsFileError::InvalidLight {
                    path: path.to_path_buf(),
                    index,
                    set: set.map(|s| format!(" of interleaved set {s}")).unwrap_or_default(),
                });
            }
            Ok(DistantLight { direction: d.normalize(), solid_angle: l.solid_angle, radiance: r })
        })
        .collect()
}

/// Reads the lights of a `lights.json` from its bytes (`lights[]` and `interleaved[][]`, each
/// light's `direction`, `solid_angle` and `radiance`; other keys are ignored); `path` names the
/// file in errors.
///
/// # Errors
/// [`LightsFileError::Parse`] for anything but JSON of the schema (serde_json limits nesting,
/// so deep input is an error too), [`LightsFileError::InvalidLight`] for values out of range.
pub fn parse_lights_json(bytes: &[u8], path: &Path) -> Result<LightsFile, LightsFileError> {
    let raw: RawFile = serde_json::from_slice(bytes)
        .map_err(|e| LightsFileError::Parse { path: path.to_path_buf(), reason: one_line(&e.to_string()) })?;
    let lights = check_lights(path, &raw.lights, None)?;
    let interleaved = raw
        .interleaved
        .iter()
        .enumerate()
        .map(|(k, set)| check_lights(path, set, Some(k)))
        .collect::<Result<_, _>>()?;
    Ok(LightsFile { lights, interleaved, indirect: raw.lights.iter().map(|l| l.indirect).collect() })
}

/// [`parse_lights_json`] of the file at `path`.
///
/// # Errors
/// [`LightsFileError::Io`] when it cannot be read, else as [`parse_lights_json`].
pub fn read_lights_json(path: &Path) -> Result<LightsFile, LightsFileError> {
    let bytes = std::fs::read(path).map_err(|source| LightsFileError::Io { path: path.to_path_buf(), source })?;
    parse_lights_json(&bytes, path)
}

fn light_json(l: &ExtractedLight) -> Value {
    let p = l.power();
    json!({
        "direction": l.light.direction.to_array(),
        "solid_angle": l.light.solid_angle,
        "half_angle": l.light.half_angle(),
        "radiance": l.light.radiance.to_array(),
        "power": p.to_array(),
        "extent": l.extent,
        "indirect": l.indirect,
    })
}

impl Decomposition {
    /// The `lights.json` document; `interleaved` are the extra sets (without the first).
    #[must_use]
    pub fn to_json(&self, interleaved: &[Vec<ExtractedLight>]) -> Value {
        json!({
            "method": self.method,
            "params": self.params,
            "time_ms": self.time_ms,
            "map_power": self.map_power,
            "ambient_power": self.ambient.power(),
            "lights": self.lights.iter().map(light_json).collect::<Vec<_>>(),
            "interleaved": interleaved.iter().map(|set| set.iter().map(light_json).collect::<Vec<_>>()).collect::<Vec<_>>(),
        })
    }

    /// A glTF 2.0 document with one `KHR_lights_punctual` directional light per light.
    #[must_use]
    pub fn to_gltf(&self, lux_per_unit: f32) -> Value {
        let mut lights = Vec::new();
        let mut nodes = Vec::new();
        for (k, l) in self.lights.iter().enumerate() {
            let p = l.power();
            let max = p.max_element().max(f32::MIN_POSITIVE);
            lights.push(json!({
                "type": "directional",
                "name": format!("{}-{k}", self.method),
                "color": (p / max).to_array(),
                "intensity": envmap_sphere::luminance(p) * lux_per_unit,
            }));
            let rotation = Quat::from_rotation_arc(Vec3::NEG_Z, -l.light.direction.normalize());
            nodes.push(json!({
                "name": format!("light-{k}"),
                "rotation": rotation.to_array(),
                "extensions": { "KHR_lights_punctual": { "light": k } },
            }));
        }
        json!({
            "asset": { "version": "2.0", "generator": "envshadow light-extract" },
            "extensionsUsed": ["KHR_lights_punctual"],
            "extensions": { "KHR_lights_punctual": { "lights": lights } },
            "nodes": nodes,
            "scenes": [{ "nodes": (0..self.lights.len()).collect::<Vec<_>>() }],
            "scene": 0,
        })
    }

    /// Writes `lights.json`, `ambient.exr` and `lights.gltf` into `dir` (created if missing).
    ///
    /// # Errors
    /// [`WriteError`], naming the folder or file that could not be written.
    pub fn write(&self, dir: &Path, interleaved: &[Vec<ExtractedLight>], lux_per_unit: f32) -> Result<(), WriteError> {
        std::fs::create_dir_all(dir).map_err(|source| WriteError::Io { path: dir.to_path_buf(), source })?;
        let write_json = |name: &str, v: &Value| -> Result<(), WriteError> {
            let path = dir.join(name);
            let text =
                serde_json::to_string_pretty(v).map_err(|source| WriteError::Json { path: path.clone(), source })?;
            std::fs::write(&path, text).map_err(|source| WriteError::Io { path, source })
        };
        write_json("lights.json", &self.to_json(interleaved))?;
        write_json("lights.gltf", &self.to_gltf(lux_per_unit))?;
        Ok(self.ambient.save_exr(dir.join("ambient.exr"))?)
    }
}
