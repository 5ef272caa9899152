//! `envshadow extract PATH [--method M] [--lights K] [--out DIR]`: decompose a map into
//! lights + ambient and write lights.json, ambient.exr, lights.gltf and overlay.png.

use light_extract::{METHODS, OPTIONS};
use std::path::Path;

pub(crate) fn run(path: &Path, method: &str, k: usize, out: Option<&Path>, lux_per_unit: f32) -> Result<(), String> {
    let map = envmap_sphere::EnvMap::load(path).map_err(|e| e.to_string())?;
    // a method + our options, e.g. "+above-horizon": only the hemisphere above the ground
    let extractor = light_extract::extractor(method, k).ok_or_else(|| {
        format!(
            "unknown method {method:?}; available: {}, with options +{} (in that order; moment-cones for emissive-split only)",
            METHODS.join(", "),
            OPTIONS.join(", +")
        )
    })?;
    let d = extractor.extract(&map).map_err(|e| format!("{}: {e}", path.display()))?;
    let stem = path.file_stem().map_or_else(|| "map".into(), |s| s.to_string_lossy().to_string());
    let dir = out.map_or_else(|| Path::new("target/extract").join(format!("{stem}-{method}")), Path::to_path_buf);
    // paper 001, section 3.5: 8 sets, directions perturbed within 0.1 x the cluster extent
    d.write(&dir, &d.interleaved(), lux_per_unit).map_err(|e| e.to_string())?;
    light_extract::overlay::write_overlay(&dir.join("overlay.png"), &map, &d.lights).map_err(|e| e.to_string())?;
    for (k, l) in d.lights.iter().enumerate() {
        let (dir_, p) = (l.light.direction, l.power());
        outln!(
            "light {k:>4}  dir [{:+.4}, {:+.4}, {:+.4}]  half-angle {:.3} deg  power [{:.4e}, {:.4e}, {:.4e}]  extent {:.2} deg",
            dir_.x,
            dir_.y,
            dir_.z,
            l.light.half_angle().to_degrees(),
            p.x,
            p.y,
            p.z,
            l.extent.to_degrees()
        );
    }
    let lp = d.light_power();
    outln!(
        "{}: {} lights in {:.2} ms; light power / map power = {:.4} (G); wrote {}",
        d.method,
        d.lights.len(),
        d.time_ms,
        lp[1] / d.map_power[1].max(f64::MIN_POSITIVE),
        dir.display()
    );
    Ok(())
}
