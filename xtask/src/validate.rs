//! `cargo xtask validate`: the main job. Today it loads the map and prints its statistics;
//! the GPU issue extends it to the whole pipeline against the reference (and then calls
//! `lavapipe::ensure` before its GPU stages).

use crate::info::MapInfo;
use envmap_sphere::{DEFAULT_MAP_CREDIT, DEFAULT_MAP_NAME, EnvMap, LoadOptions};
use std::path::Path;
use std::time::Instant;

pub fn run(envmap: Option<&Path>) -> Result<(), String> {
    let start = Instant::now();
    println!("[1/1] load environment map");
    let (name, (map, report)) = match envmap {
        Some(path) => {
            (path.display().to_string(), EnvMap::load_with(path, &LoadOptions::default()).map_err(|e| e.to_string())?)
        }
        None => (
            format!("{DEFAULT_MAP_NAME} (embedded default; {DEFAULT_MAP_CREDIT})"),
            EnvMap::load_from_bytes(envmap_sphere::default_map_bytes(), DEFAULT_MAP_NAME, &LoadOptions::default())
                .map_err(|e| e.to_string())?,
        ),
    };
    MapInfo::new(&map, &report).print_text(&name, &map, &report);
    println!("validate: done in {:.2} s", start.elapsed().as_secs_f64());
    Ok(())
}
