//! `cargo xtask pictures`: the README's pictures, made by the current code. A model of
//! `assets/models/` on the default map with its soft shadows, as the GPU draws it with wedges
//! and as the reference tracer renders it (`validate --quick`'s images), and the default map
//! with the lights extracted from it. `--check` makes them again in a temporary folder and
//! fails when one differs from the committed picture by more than its FLIP in
//! `docs/pictures/flip.json` (data, not code).

use clap::Parser;
use std::path::{Path, PathBuf};

/// The model shown, from the workspace root.
const MODEL: &str = "assets/models/BoxTextured.gltf";

/// Options of `cargo xtask pictures`.
#[derive(clap::Parser, Clone, Debug)]
pub struct PicturesArgs {
    /// Folder of the pictures (and of `flip.json`).
    #[arg(long, default_value = "docs/pictures")]
    pub out: PathBuf,
    /// Make the pictures in a temporary folder and compare them with those in `--out`.
    #[arg(long)]
    pub check: bool,
    /// The GPU adapter, as for validate.
    #[arg(long)]
    pub adapter: Option<String>,
}

fn root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("..")
}

/// Makes every picture in `dir`; their file names.
fn make(dir: &Path, adapter: Option<&str>) -> Result<Vec<&'static str>, String> {
    std::fs::create_dir_all(dir).map_err(|e| format!("{}: {e}", dir.display()))?;
    let work = dir.join("validate");
    let model = root().join(MODEL);
    let mut argv: Vec<String> = ["validate", "--ground", "--quick"].map(String::from).to_vec();
    argv.extend(["--scene".into(), model.display().to_string(), "--out".into(), work.display().to_string()]);
    if let Some(a) = adapter {
        argv.extend(["--adapter".into(), a.to_string()]);
    }
    crate::validate::run(&crate::validate::ValidateArgs::parse_from(argv))?;
    let copies = [("reference.png", "model_reference.png"), ("gpu_wedges.png", "model_gpu_wedges.png")];
    for (from, to) in copies {
        std::fs::copy(work.join(from), dir.join(to)).map_err(|e| format!("{}: {e}", work.join(from).display()))?;
    }
    std::fs::remove_dir_all(&work).map_err(|e| format!("{}: {e}", work.display()))?;
    let map = envmap_sphere::default_map();
    let extractor = light_extract::extractor(light_extract::DEFAULT_METHOD, 32).ok_or("the default method")?;
    let lights = extractor.extract(&map).map_err(|e| e.to_string())?.lights;
    light_extract::overlay::write_overlay(&dir.join("map_lights.png"), &map, &lights).map_err(|e| e.to_string())?;
    Ok(vec!["model_reference.png", "model_gpu_wedges.png", "map_lights.png"])
}

/// Runs the command.
///
/// # Errors
/// A failed stage; with `--check`, a picture missing, of another size, or past its FLIP.
pub fn run(args: &PicturesArgs) -> Result<(), String> {
    let out = if args.out.is_absolute() { args.out.clone() } else { root().join(&args.out) };
    if !args.check {
        let names = make(&out, args.adapter.as_deref())?;
        outln!("pictures: {} in {}", names.join(", "), out.display());
        return Ok(());
    }
    let limits_path = out.join("flip.json");
    let text = std::fs::read_to_string(&limits_path).map_err(|e| format!("{}: {e}", limits_path.display()))?;
    let limits: serde_json::Value =
        serde_json::from_str(&text).map_err(|e| format!("{}: {e}", limits_path.display()))?;
    let fresh = std::env::temp_dir().join(format!("envshadow-pictures-{}", std::process::id()));
    let names = make(&fresh, args.adapter.as_deref())?;
    let mut failures = Vec::new();
    for name in names {
        let limit =
            limits[name].as_f64().ok_or_else(|| format!("{}: no FLIP limit for {name}", limits_path.display()))?;
        let load = |p: &Path| envmap_sphere::io::load_png_srgb8(p).map_err(|e| e.to_string());
        let (committed, made) = (load(&out.join(name))?, load(&fresh.join(name))?);
        if (committed.0, committed.1) != (made.0, made.1) {
            failures.push(format!("{name}: {}x{} committed, {}x{} made", committed.0, committed.1, made.0, made.1));
            continue;
        }
        let flip = ref_tracer::metrics::flip_rgb8(&committed.2, &made.2, made.0, made.1);
        outln!("pictures: {name} mean FLIP {flip:.4} against the committed one (limit {limit})");
        if flip > limit {
            failures.push(format!("{name}: mean FLIP {flip:.4} > {limit}"));
        }
    }
    std::fs::remove_dir_all(&fresh).ok();
    if failures.is_empty() {
        Ok(())
    } else {
        Err(format!(
            "the committed pictures are not what the code makes now ({}); run `cargo xtask pictures` to make them again",
            failures.join("; ")
        ))
    }
}
