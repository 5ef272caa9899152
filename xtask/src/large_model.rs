//! `cargo xtask large-model`: the large model the scale figures are measured on, written by code
//! so that anyone can make it again: a square grid of `--triangles` (rounded to 2 n²) displaced
//! by two sines, 10 m across, one Lambertian material, a camera that sees it all, as `.glb` or
//! `.gltf`.

use glam::Vec3;
use std::path::PathBuf;

/// Options of `cargo xtask large-model`.
#[derive(clap::Args, Clone, Debug)]
pub struct LargeModelArgs {
    /// Triangles wanted (the grid has 2 n² of them, n the nearest whole side).
    #[arg(long, default_value_t = 2_000_000)]
    pub triangles: u64,
    /// Output file (`.glb` or `.gltf`).
    #[arg(long, default_value = "target/terrain2m.glb")]
    pub out: PathBuf,
}

/// The largest grid side: 2 n² triangles and (n + 1)² vertices stay within u32 indices and a
/// `.glb`'s 4 GiB.
const MAX_SIDE: u64 = 10_000;

/// Writes the model.
///
/// # Errors
/// A triangle count past the limit, or the file's write error.
pub fn run(args: &LargeModelArgs) -> Result<(), String> {
    let n = ((args.triangles as f64 / 2.0).sqrt().round() as u64).max(1);
    if n > MAX_SIDE {
        return Err(format!(
            "--triangles {}: at most {} (a grid side of {MAX_SIDE})",
            args.triangles,
            2 * MAX_SIDE * MAX_SIDE
        ));
    }
    let n = n as u32;
    let side = 10.0f32;
    let height = |x: f32, z: f32| 0.6 * (1.3 * x).sin() * (0.9 * z).sin() + 0.15 * (3.0 * x + z).sin();
    let mut positions = Vec::with_capacity(((n + 1) * (n + 1)) as usize);
    for j in 0..=n {
        for i in 0..=n {
            let (x, z) = ((i as f32 / n as f32 - 0.5) * side, (j as f32 / n as f32 - 0.5) * side);
            positions.push(Vec3::new(x, height(x, z), z));
        }
    }
    let mut indices = Vec::with_capacity(2 * (n * n) as usize);
    for j in 0..n {
        for i in 0..n {
            let a = j * (n + 1) + i;
            let (b, c, d) = (a + 1, a + n + 1, a + n + 2);
            // counter-clockwise seen from above (+Y)
            indices.push([a, c, b]);
            indices.push([b, c, d]);
        }
    }
    let mesh = scene::Mesh { positions, normals: None, indices, uvs: None };
    let mut model = scene::Scene::builtin("spheres_box").map_err(|e| e.to_string())?;
    model.name = "terrain".into();
    model.point_lights.clear();
    model.textures.clear();
    model.objects = vec![scene::Object { name: "terrain".into(), mesh, material: scene::Material::lambert(0.6) }];
    model.camera.eye = Vec3::new(0.0, 6.0, 11.0);
    model.camera.target = Vec3::ZERO;
    model.camera.up = Vec3::Y;
    model.camera.hfov_degrees = 60.0;
    if let Some(dir) = args.out.parent().filter(|d| !d.as_os_str().is_empty()) {
        std::fs::create_dir_all(dir).map_err(|e| format!("{}: {e}", dir.display()))?;
    }
    model.write_gltf(&args.out).map_err(|e| e.to_string())?;
    outln!("large-model: {} triangles ({n} x {n} grid) in {}", 2 * u64::from(n) * u64::from(n), args.out.display());
    Ok(())
}
