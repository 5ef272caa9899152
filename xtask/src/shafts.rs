//! `cargo xtask shafts`: paper 003's shaft hierarchy on a built-in real scene. Solves the
//! scene's radiances (the stand-in for a capture), pre-processes (source set, receivers,
//! transfers, trees, shafts), checks the hierarchy (validate and brute-force segments along a
//! built-in object path), times a frame's traversal plus representative set, writes an overlay
//! image, and prints the figures (one JSON object with `--json`).

use std::path::Path;
use std::time::Instant;

use real_scene::{RealScene, SolveSettings, Visibility};
use shaft_hierarchy::preprocess::PreprocessSettings;
use shaft_hierarchy::{Occlusion, Traversal};
use trade::shafts::{figures, object_path, overlay, sweep};

/// Frames of the object path.
const FRAMES: usize = 240;
/// Segments drawn per frame by the conservativeness check (at least 100,000 in all).
const SEGMENTS_PER_FRAME: usize = 500;
/// Nodes of the representative set per frame.
const REPRESENTATIVES: usize = 8;

/// The command's options.
pub struct ShaftsArgs<'a> {
    pub scene: &'a str,
    pub json: bool,
    pub settings: PreprocessSettings,
    pub sweep: bool,
    pub photo: Option<u32>,
    pub out: &'a Path,
}

pub fn run(args: &ShaftsArgs) -> Result<(), String> {
    let say = |s: &str| {
        if !args.json {
            outln!("{s}");
        }
    };
    let mut scene = RealScene::builtin(args.scene).map_err(|e| e.to_string())?;
    let t = Instant::now();
    let bvh = ref_tracer::SceneBvh::new(&scene.to_scene());
    let (map, lights) = crate::common::environment(&scene)?;
    let report =
        real_scene::solve(&mut scene, &bvh, map.as_ref(), &SolveSettings::default()).map_err(|e| e.to_string())?;
    say(&format!(
        "{}: {} patches, radiosity solved in {:.2} s ({} links, {} iterations){}",
        scene.name,
        scene.patches.len(),
        t.elapsed().as_secs_f64(),
        report.links,
        report.iterations,
        if lights.is_empty() {
            String::new()
        } else {
            format!(", {} distant lights from the embedded map", lights.len())
        }
    ));
    if let Some(spp) = args.photo {
        photograph(&scene, map.as_ref(), spp, args.out)?;
    }
    if args.sweep {
        say(
            "knob sweep: setting | sources | leaf shafts | bytes (per leaf) | pre-processing | traversal | true occluders found | misses",
        );
        for (name, settings) in sweep() {
            let (f, _, _) = figures(&scene, &lights, &bvh, &settings, (FRAMES, SEGMENTS_PER_FRAME, REPRESENTATIVES))
                .map_err(|e| e.to_string())?;
            let line = format!(
                "| {name} | {} | {} | {} ({:.1}) | {:.2} s | {:.1} us | {:.1} % | {} |",
                f.sources,
                f.leaf_shafts,
                f.bytes,
                f.bytes as f64 / f.leaf_shafts.max(1) as f64,
                f.preprocess_s,
                f.traversal_us,
                100.0 * f.check.found as f64 / f.check.true_occluders.max(1) as f64,
                f.check.misses
            );
            if args.json {
                outln!(
                    "{}",
                    serde_json::json!({"setting": name, "sources": f.sources, "leaf_shafts": f.leaf_shafts, "bytes": f.bytes, "preprocess_s": f.preprocess_s, "traversal_us": f.traversal_us, "true_occluders_found": f.check.found as f64 / f.check.true_occluders.max(1) as f64, "misses": f.check.misses})
                );
            } else {
                outln!("{line}");
            }
            if f.check.misses > 0 {
                return Err(format!("{name}: {} occluded segments in no reported shaft", f.check.misses));
            }
        }
        return Ok(());
    }
    let (f, prepared, h) =
        figures(&scene, &lights, &bvh, &args.settings, (FRAMES, SEGMENTS_PER_FRAME, REPRESENTATIVES))
            .map_err(|e| e.to_string())?;
    let objects = object_path(&scene, FRAMES);
    let c = f.check;
    let (preprocess_s, traversal_us, bytes, leaf_shafts) = (f.preprocess_s, f.traversal_us, f.bytes, f.leaf_shafts);
    // the overlay at the path position nearest the middle of the view, among those in sight
    let (right, up, forward) = scene.camera.basis();
    let off_centre = |b: &shaft_hierarchy::Aabb| {
        let d = b.center() - scene.camera.eye;
        let z = d.dot(forward).max(1e-6);
        (d.dot(right) / z).hypot(d.dot(up) / z)
    };
    let in_sight = |b: &&shaft_hierarchy::Aabb| bvh.clear(scene.camera.eye, b.center());
    let nearest = |a: &&shaft_hierarchy::Aabb, b: &&shaft_hierarchy::Aabb| off_centre(a).total_cmp(&off_centre(b));
    let shown = objects
        .iter()
        .filter(in_sight)
        .min_by(nearest)
        .or_else(|| objects.iter().min_by(nearest))
        .ok_or("no object path")?;
    let mut o = Occlusion::default();
    h.traverse(shown, &mut Traversal::default(), &mut o);
    let image = overlay(&scene, &bvh, &prepared, &o, shown);
    std::fs::create_dir_all(args.out).map_err(|e| format!("{}: {e}", args.out.display()))?;
    let png = args.out.join(format!("{}_overlay.png", scene.name));
    let bytes_rgb: Vec<u8> = image.iter().flatten().copied().collect();
    envmap_sphere::io::save_png_srgb8(&png, scene.camera.width, scene.camera.height, &bytes_rgb)
        .map_err(|e| e.to_string())?;
    if args.json {
        let v = serde_json::json!({
            "scene": scene.name,
            "patches": scene.patches.len(),
            "sources": prepared.sources.len(),
            "receivers": prepared.receivers.len(),
            "leaf_shafts": leaf_shafts,
            "bytes": bytes,
            "preprocess_s": preprocess_s,
            "traversal_us": traversal_us,
            "segments_checked": c.segments,
            "misses": c.misses,
            "segments_hitting": c.hits,
            "hits_in_pruned_shafts": c.in_pruned,
            "true_occluders_found": c.found as f64 / c.true_occluders.max(1) as f64,
            "sources_reported_per_frame": c.reported as f64 / FRAMES as f64,
            "reported_unconfirmed": c.unconfirmed as f64 / c.reported.max(1) as f64,
            "shafts": h.shafts.len(),
            "transfer_bytes": h.transfer_bytes(),
            "source_power_share": prepared.power.0 / prepared.power.1.max(f64::MIN_POSITIVE),
        });
        outln!("{v}");
    } else {
        say(&format!(
            "source set: {} sources ({:.0} % of the power), {} receivers ({} vertices)",
            prepared.sources.len(),
            100.0 * prepared.power.0 / prepared.power.1.max(f64::MIN_POSITIVE),
            prepared.receivers.len(),
            prepared.vertices.len()
        ));
        say(&format!(
            "hierarchy: {} shafts, {leaf_shafts} leaf shafts, {bytes} bytes ({:.1} per leaf shaft; transfers {} bytes more), pre-processing {preprocess_s:.2} s",
            h.shafts.len(),
            bytes as f64 / leaf_shafts.max(1) as f64,
            h.transfer_bytes()
        ));
        say(&format!(
            "per frame ({FRAMES} positions of a box along a loop): traversal + {REPRESENTATIVES} representatives {traversal_us:.1} us (median), {:.1} sources reported",
            c.reported as f64 / FRAMES as f64
        ));
        say(&format!(
            "check: {} segments, {} meet the object, {} misses, {} in pruned shafts; {:.1} % of the true occluders found; {:.1} % of the reported sources unconfirmed by {} segments each (false positives at most)",
            c.segments,
            c.hits,
            c.misses,
            c.in_pruned,
            100.0 * c.found as f64 / c.true_occluders.max(1) as f64,
            100.0 * c.unconfirmed as f64 / c.reported.max(1) as f64,
            trade::shafts::CONFIRM_SEGMENTS
        ));
        say(&format!("wrote {}", png.display()));
    }
    if c.misses > 0 {
        return Err(format!("{} occluded segments in no reported shaft", c.misses));
    }
    Ok(())
}

/// The scene's photograph: path traced (HDR, OUT/<scene>_photo.exr) and through an
/// auto-exposed camera response to 8 bits (OUT/<scene>_photo.png).
fn photograph(scene: &RealScene, map: Option<&envmap_sphere::EnvMap>, spp: u32, out: &Path) -> Result<(), String> {
    let t = Instant::now();
    let photo = trade::photograph(scene, map, &trade::PhotoSettings { spp, ..trade::PhotoSettings::default() })
        .map_err(|e| e.to_string())?;
    let response = real_scene::CameraResponse::auto(&photo.color);
    std::fs::create_dir_all(out).map_err(|e| format!("{}: {e}", out.display()))?;
    let exr = out.join(format!("{}_photo.exr", scene.name));
    envmap_sphere::io::save_exr_rgb(&exr, photo.width as usize, photo.height as usize, &photo.color)
        .map_err(|e| e.to_string())?;
    let png = out.join(format!("{}_photo.png", scene.name));
    let ldr: Vec<u8> = photo.color.iter().flat_map(|&c| response.apply(c)).collect();
    envmap_sphere::io::save_png_srgb8(&png, photo.width, photo.height, &ldr).map_err(|e| e.to_string())?;
    let clipped = photo.color.iter().filter(|c| c.to_array().iter().any(|&v| response.clips(v))).count();
    outln!(
        "photograph: path traced, {spp} spp, {:.1} s; exposure {:.3}, gamma {}, {clipped} pixels clip; wrote {} and {}",
        t.elapsed().as_secs_f64(),
        response.exposure,
        response.gamma,
        exr.display(),
        png.display()
    );
    Ok(())
}
