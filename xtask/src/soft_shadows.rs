//! `cargo xtask soft-shadows`: every shadow technique's visibility error against ray-traced
//! visibility and its GPU time per light, per scene and light size, and the speed of each at
//! the wedges' error (`envshadow_benches::soft_shadows` does the measuring). Writes
//! OUT/soft_shadows.csv and OUT/soft_shadows.md.

use envshadow_benches::soft_shadows::{Frame, HALF_ANGLES, Row, SCENES, entries, equal_error, measure};
use std::fmt::Write as _;
use std::path::Path;

/// Runs the sweep over `scenes` (built-in or models, on a ground of albedo `ground`) at `size` on `adapter` (or the best one).
pub fn run(
    scenes: &[String],
    ground: Option<f32>,
    size: (u32, u32),
    adapter: Option<&str>,
    out: &Path,
) -> Result<(), String> {
    let gpu = crate::lavapipe::open_gpu(adapter)?;
    outln!("GPU: {}", gpu.describe());
    let scenes: Vec<String> =
        if scenes.is_empty() { SCENES.iter().map(|s| (*s).to_string()).collect() } else { scenes.to_vec() };
    let mut rows: Vec<Row> = Vec::new();
    for name in &scenes {
        outln!("{name} at {}x{}", size.0, size.1);
        let frame = Frame::with_scene(&gpu, crate::common::open_scene(name, size, ground)?)?;
        let list = entries(&gpu, &frame.scene).map_err(|e| e.to_string())?;
        rows.extend(measure(&gpu, &frame, &list, &HALF_ANGLES, &mut |r| {
            outln!(
                "  {:>5} deg  {:<22} mean {:.4}  p95 {:.4}  ({} px)  {:>8.2} ms",
                r.degrees,
                r.technique,
                r.mean,
                r.p95,
                r.pixels,
                r.ms
            );
        })?);
    }
    std::fs::create_dir_all(out).map_err(|e| format!("{}: {e}", out.display()))?;
    let mut csv =
        String::from("scene,half_angle_deg,family,technique,mean_error,p95_error,pixels,ms_per_light,clock\n");
    for r in &rows {
        let _ = writeln!(
            csv,
            "{},{},{},{},{:.5},{:.5},{},{:.3},{}",
            r.scene, r.degrees, r.family, r.technique, r.mean, r.p95, r.pixels, r.ms, r.clock
        );
    }
    let mut md = format!(
        "VisibilityLayers error against ray-traced visibility, weighted by the light's unshadowed irradiance there relative to a surface facing it (mean and 95th percentile over pixels in or near penumbrae), and GPU time per light (median of 3), {}x{}, {}.\n\n| scene | half-angle | technique | mean | p95 | ms/light |\n|---|---|---|---|---|---|\n",
        size.0,
        size.1,
        gpu.describe()
    );
    for r in &rows {
        let _ = writeln!(
            md,
            "| {} | {}° | {} | {:.4} | {:.4} | {:.2} |",
            r.scene, r.degrees, r.technique, r.mean, r.p95, r.ms
        );
    }
    md.push_str("\nSpeed at the wedges' error: the fastest setting of each family whose mean error is at most the wedges'.\n\n| scene | half-angle | wedges (error, ms) | pcss | shadow_maps_xN | shadow_maps |\n|---|---|---|---|---|---|\n");
    outln!("speed at the wedges' error:");
    for e in equal_error(&rows) {
        let cell = |family: &str| {
            e.others.iter().find(|(f, _)| f == family).map_or("-".to_string(), |(_, b)| {
                b.as_ref().map_or("not reached".to_string(), |(t, ms)| format!("{t} {ms:.2} ms"))
            })
        };
        let line = format!(
            "| {} | {}° | {:.4}, {:.2} ms | {} | {} | {} |",
            e.scene,
            e.degrees,
            e.wedges.0,
            e.wedges.1,
            cell("pcss"),
            cell("shadow_maps_xN"),
            cell("shadow_maps")
        );
        outln!("  {line}");
        let _ = writeln!(md, "{line}");
    }
    for (name, text) in [("soft_shadows.csv", csv), ("soft_shadows.md", md)] {
        let p = out.join(name);
        std::fs::write(&p, text).map_err(|e| format!("{}: {e}", p.display()))?;
        outln!("wrote {}", p.display());
    }
    Ok(())
}
