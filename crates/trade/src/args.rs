//! The values both command lines (`xtask`'s jobs and the `envshadow` tool) parse the same way:
//! image sizes, points, albedos, the scene a command is given (built-in or model) and its map
//! (or the embedded default).

use envmap_sphere::EnvMap;
use glam::Vec3;
use std::path::Path;

/// A command-line value that does not parse; the message quotes it.
#[derive(Debug, thiserror::Error, PartialEq, Eq)]
pub enum ArgError {
    /// Not `WIDTHxHEIGHT` of two whole numbers.
    #[error("{0:?}: expected WIDTHxHEIGHT, e.g. 320x240")]
    Size(String),
    /// Not three finite numbers `X,Y,Z`.
    #[error("{0:?}: expected three finite numbers X,Y,Z")]
    Vec3(String),
    /// Not a number in [0, 1].
    #[error("{0:?}: expected an albedo in [0, 1]")]
    Albedo(String),
}

/// Parses `WIDTHxHEIGHT`.
///
/// # Errors
/// No `x`, or a side that is not a number.
pub fn parse_size(s: &str) -> Result<(u32, u32), ArgError> {
    let bad = || ArgError::Size(s.to_string());
    let (w, h) = s.split_once('x').ok_or_else(bad)?;
    Ok((w.parse().map_err(|_| bad())?, h.parse().map_err(|_| bad())?))
}

/// Parses "X,Y,Z": three finite numbers.
///
/// # Errors
/// Not three numbers, or one not finite.
pub fn parse_vec3(s: &str) -> Result<Vec3, ArgError> {
    let bad = || ArgError::Vec3(s.to_string());
    let v: Vec<f32> = s.split(',').map(|x| x.trim().parse::<f32>()).collect::<Result<_, _>>().map_err(|_| bad())?;
    match v.as_slice() {
        [x, y, z] if v.iter().all(|c| c.is_finite()) => Ok(Vec3::new(*x, *y, *z)),
        _ => Err(bad()),
    }
}

/// Parses an albedo: a number in [0, 1] (`--ground`'s).
///
/// # Errors
/// Not a number, or one outside [0, 1].
pub fn parse_albedo(s: &str) -> Result<f32, ArgError> {
    match s.trim().parse::<f32>() {
        Ok(a) if (0.0..=1.0).contains(&a) => Ok(a),
        _ => Err(ArgError::Albedo(s.to_string())),
    }
}

/// The scene `spec` names (a built-in or a glTF model, [`scene::Scene::open`]) with its camera
/// at `size`, a model standing on a ground of albedo `ground` when given; with the import's
/// warnings, for the command to show.
///
/// # Errors
/// An unknown name; a model that cannot be imported (the message names the file).
pub fn open_scene(
    spec: &str,
    size: (u32, u32),
    ground: Option<f32>,
) -> Result<(scene::Scene, Vec<String>), scene::SceneError> {
    scene::Scene::open(spec, &scene::import::GltfOptions { size, ground, ..Default::default() })
}

/// The map at `path` (`--envmap`), or the embedded default.
///
/// # Errors
/// The map's load error, naming the file.
pub fn load_map(path: Option<&Path>) -> Result<EnvMap, envmap_sphere::EnvMapError> {
    match path {
        Some(p) => EnvMap::load(p),
        None => Ok(envmap_sphere::default_map()),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn sizes_and_points_parse_and_bad_ones_are_refused() {
        assert_eq!(parse_size("320x240"), Ok((320, 240)));
        assert_eq!(parse_size("32x"), Err(ArgError::Size("32x".into())));
        assert!(parse_size("320").is_err() && parse_size("ax2").is_err());
        assert_eq!(parse_vec3("1, 2,-3.5"), Ok(Vec3::new(1.0, 2.0, -3.5)));
        for bad in ["1,2", "1,2,3,4", "1,nan,2", "1,inf,2", "a,b,c"] {
            assert!(parse_vec3(bad).is_err(), "{bad}");
        }
        assert_eq!(parse_albedo("0.25"), Ok(0.25));
        for bad in ["-0.1", "1.5", "nan", "x", "inf"] {
            assert_eq!(parse_albedo(bad), Err(ArgError::Albedo(bad.into())), "{bad}");
        }
    }
}
