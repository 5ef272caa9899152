//! `envshadow composite --envmap MAP --object MODEL`: the object composited onto the user's
//! HDRI, its lower hemisphere projected onto a ground disc (`real_scene::Backdrop`), with its
//! shadows from the map's lights and the rest of its sky; against the local scene path traced
//! differentially (the truth, converged, with its own noise) and a path-traced shadow catcher
//! (the offline baseline, `--catcher-spp`).

use std::path::{Path, PathBuf};

use differential_composite::gpu::GpuCompositor;
use differential_composite::{Mode, ObjectPlacement, SyntheticObject, code_error};
use glam::Vec3;
use real_scene::Backdrop;
use trade::backdrop::{BackdropSession, BackdropSettings};
use trade::composite_rows::{ms, rows};

use crate::composite::{CompositeArgs, open_gpu, print_json};

pub(crate) fn run(args: &CompositeArgs) -> Result<(), String> {
    let say = |s: &str| {
        if !args.json {
            outln!("{s}");
        }
    };
    let e = |e: differential_composite::CompositeError| e.to_string();
    let map_path = args.envmap.as_deref().ok_or("--envmap: the map to composite onto")?;
    let at = trade::args::parse_vec3(args.at.as_deref().unwrap_or("0,0,3")).map_err(|e| format!("--at {e}"))?;
    if !(args.fov > 0.0 && args.fov < 180.0) {
        return Err(format!("--fov {}: degrees in (0, 180)", args.fov));
    }
    let backdrop = Backdrop::new(args.camera_height, args.ground_radius).map_err(|e| e.to_string())?;
    let gpu_settings = differential_composite::gpu::GpuSettings {
        pcss: (!args.hard_shadows).then_some(shadowmap_paraboloid::Pcss {
            blocker_samples: args.pcss_samples.div_ceil(2).max(1),
            filter_samples: args.pcss_samples.max(1),
            max_radius_texels: 64.0,
        }),
        coverage_samples: 2,
        cull_masks: true,
        ..args.gpu_settings()?
    };
    // the inputs first: a bad map, model or camera is refused before the GPU and the renders
    let map = trade::args::load_map(Some(map_path)).map_err(|e| e.to_string())?;
    let placement = ObjectPlacement { at, scale: args.scale, rotate_y_degrees: args.rotate_y, size: args.object_size };
    let (object, warnings) = SyntheticObject::open_placed(&args.object, &placement).map_err(e)?;
    for w in warnings {
        eprintln!("warning: {}: {w}", args.object);
    }
    let (w, h) = args.size;
    let (eye, target) = match (args.eye, args.target) {
        (Some(eye), Some(target)) => (eye, target),
        _ => (backdrop.probe(), object.centre),
    };
    let camera = scene::Camera { eye, target, up: Vec3::Y, hfov_degrees: args.fov, width: w, height: h };
    Backdrop::check_camera(&camera).map_err(|e| format!("--eye/--target: {e}"))?;
    let gpu = open_gpu(args.adapter.as_deref())?;
    say(&format!("GPU: {}", gpu.describe()));
    let settings = BackdropSettings {
        backdrop,
        preprocess: shaft_hierarchy::preprocess::PreprocessSettings {
            hierarchy: shaft_hierarchy::Settings {
                prune_fraction: args.prune.unwrap_or(trade::backdrop::BACKDROP_PRUNE),
                ..shaft_hierarchy::Settings::PAPER
            },
            ..BackdropSettings::default().preprocess
        },
        ..BackdropSettings::default()
    };
    let t = std::time::Instant::now();
    let session = BackdropSession::new(map, camera, &settings).map_err(e)?;
    let c = &session.compositor;
    say(&format!(
        "{}: {w} x {h}, {} ground patches ({} seen), {} sources ({} lights, {} cones of the rest of the sky) ({:.1} s)",
        map_path.display(),
        c.model.patches.len(),
        c.prepared.receivers.len(),
        c.prepared.sources.len(),
        session.lights.0,
        session.lights.1,
        t.elapsed().as_secs_f64()
    ));
    let gc = GpuCompositor::new(&gpu, c).map_err(|e| e.to_string())?;
    let mode = if args.ldr { Mode::Ldr } else { Mode::Hdr };
    if let Some(frames) = args.path_frames() {
        return moving(args, &gpu, &gc, &session, (&object, frames), mode, &gpu_settings);
    }
    // the truth as two halves of different seeds: their difference is its own noise
    let half = (args.truth_spp / 2).max(1);
    let (a, ta) = session.differential(&object, half, 11);
    let (b, tb) = session.differential(&object, half, 12);
    let truth_hdr: Vec<Vec3> = a.iter().zip(&b).map(|(a, b)| 0.5 * (a + b)).collect();
    let truth = session.codes(&truth_hdr);
    let halves = code_error(&session.codes(&a), &session.codes(&b), &c.photo_ldr);
    say(&format!(
        "truth: {} spp, path traced with and without the object ({:.1} s)",
        2 * half,
        (ta + tb).as_secs_f64()
    ));
    let (catcher_hdr, catcher_time) = session.differential(&object, args.catcher_spp, 1);
    let catcher = session.codes(&catcher_hdr);
    let catcher_error = code_error(&catcher, &truth, &c.photo_ldr);
    let passes: Vec<usize> = if args.sweep { vec![1, 10, 20, 50, 0] } else { vec![args.passes] };
    let modes: Vec<Mode> = if args.sweep { vec![Mode::Hdr, Mode::Ldr] } else { vec![mode] };
    let table = rows(&gpu, &gc, c, &object, &truth, &passes, &modes, &gpu_settings, 5).map_err(|e| e.to_string())?;
    let main = table.iter().rev().find(|r| r.mode == mode && r.passes == args.passes).or(table.last());
    let main = main.ok_or("no composite")?;
    // the HDR image of the main setting, recomposited once more (the rows keep 8-bit images)
    let hdr = if main.mode == Mode::Hdr {
        let frame = c.frame(&object, main.passes);
        gc.composite(&gpu, c, &frame, &object, main.mode, &gpu_settings).map_err(|e| e.to_string())?;
        Some(gc.read_output_hdr(&gpu).map_err(|e| e.to_string())?)
    } else {
        None
    };
    let save = |path: &Path, img: &[[u8; 3]]| crate::composite::save_png(path, (w, h), img);
    let beside = |suffix: &str, ext: &str| -> PathBuf {
        let stem = args.out.file_stem().map_or_else(|| "composite".into(), |s| s.to_string_lossy().to_string());
        args.out.with_file_name(format!("{stem}{suffix}.{ext}"))
    };
    save(&args.out, &main.image)?;
    save(&beside("_plate", "png"), &c.photo_ldr)?;
    save(&beside("_truth", "png"), &truth)?;
    save(&beside("_catcher", "png"), &catcher)?;
    save(&beside("_error", "png"), &differential_composite::metrics::error_image(&main.image, &truth))?;
    let exr = |path: PathBuf, img: &[Vec3]| {
        envmap_sphere::io::save_exr_rgb(&path, w as usize, h as usize, img).map_err(|e| e.to_string())
    };
    exr(beside("_truth", "exr"), &truth_hdr)?;
    if let Some(hdr) = &hdr {
        exr(beside("", "exr"), hdr)?;
    }
    let sources = c.prepared.sources.len();
    if args.json {
        let v = serde_json::json!({
            "envmap": map_path.display().to_string(),
            "object": args.object,
            "at": at.to_array(),
            "eye": eye.to_array(),
            "target": target.to_array(),
            "passes": main.passes,
            "representatives": main.reps,
            "mode": main.mode_label().to_lowercase(),
            "error_rmse_codes": main.error.rmse_changed,
            "error_mae_codes": main.error.mae_changed,
            "pathtraced_error_rmse_codes": catcher_error.rmse_changed,
            "pathtraced_error_mae_codes": catcher_error.mae_changed,
            "pathtraced_ms": ms(catcher_time),
            "pathtraced_spp": args.catcher_spp,
            "truth_spp": 2 * half,
            "truth_noise_rmse_codes": halves.rmse_changed / 2.0,
            "changed_pixels": main.error.changed,
            "sources": sources,
            "occluded_sources": main.occluded_sources,
            "sources_excluded": sources - main.occluded_sources.min(sources),
            "lights": session.lights.0,
            "sky_cones": session.lights.1,
            "size": [w, h],
            "adapter": gpu.info.name,
            "rows": table.iter().map(|r| serde_json::json!({
                "passes": r.passes,
                "mode": r.mode_label().to_lowercase(),
                "representatives": r.reps,
                "ms_per_frame": ms(r.times.total()),
                "error_rmse_codes": r.error.rmse_changed,
                "error_mae_codes": r.error.mae_changed,
            })).collect::<Vec<_>>(),
        });
        print_json(v, main);
        return Ok(());
    }
    outln!(
        "path-traced catcher ({} spp, {:.0} ms): RMSE {:.2} codes, MAE {:.2} over the {} pixels the object changes; the truth's own noise {:.2}",
        args.catcher_spp,
        ms(catcher_time),
        catcher_error.rmse_changed,
        catcher_error.mae_changed,
        catcher_error.changed,
        halves.rmse_changed / 2.0
    );
    outln!(
        "sources: {sources}; the object can block {} of them, {} excluded by the shaft hierarchy",
        main.occluded_sources,
        sources - main.occluded_sources.min(sources)
    );
    outln!(
        "passes | reps | mode | RMSE codes | MAE codes | / catcher | ms per frame (cpu + gbuffer + maps + masks + resolve)"
    );
    for r in &table {
        let [total, cpu, gbuffer, maps, masks, resolve] = r.times_ms();
        outln!(
            "{:>6} | {:>4} | {} | {:>10.2} | {:>9.2} | {:>9.2} | {total:.2} ({cpu:.2} + {gbuffer:.2} + {maps:.2} + {masks:.2} + {resolve:.2})",
            r.passes_label(),
            r.reps,
            r.mode_label(),
            r.error.rmse_changed,
            r.error.mae_changed,
            r.error.rmse_changed / catcher_error.rmse_changed.max(1e-9),
        );
    }
    outln!("wrote {} (and _plate, _truth, _catcher, _error; EXR beside)", args.out.display());
    Ok(())
}

/// `frames` positions along a line across the ground: per frame the traversal and the GPU
/// composite, its time, its representatives and the sources excluded.
fn moving(
    args: &CompositeArgs,
    gpu: &gpu::Gpu,
    gc: &GpuCompositor,
    session: &BackdropSession,
    (object, frames): (&SyntheticObject, usize),
    mode: Mode,
    settings: &differential_composite::gpu::GpuSettings,
) -> Result<(), String> {
    let c = &session.compositor;
    let sources = c.prepared.sources.len();
    let mut out = Vec::new();
    for k in 0..frames {
        let s = if frames > 1 { k as f32 / (frames - 1) as f32 } else { 0.5 };
        let offset = Vec3::new(-1.0 + 2.0 * s, 0.0, 0.0);
        let moved = object.moved(offset);
        let frame = c.frame(&moved, args.passes);
        let (_, times, _) = gc.composite(gpu, c, &frame, &moved, mode, settings).map_err(|e| e.to_string())?;
        let excluded = sources - frame.occluded_sources.min(sources);
        if args.json {
            out.push(serde_json::json!({"frame": k, "offset": offset.to_array(), "ms_per_frame": ms(times.total()), "representatives": frame.reps.len(), "sources_excluded": excluded}));
        } else {
            outln!(
                "frame {k:>3} at {:+.2} m: {} reps, {excluded} of {sources} sources excluded, {:.2} ms",
                offset.x,
                frame.reps.len(),
                ms(times.total())
            );
        }
    }
    if args.json {
        outln!("{}", serde_json::json!({"frames": out, "adapter": gpu.info.name}));
    }
    Ok(())
}
