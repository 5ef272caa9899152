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
    if !(args.fov > 0.0 && args.fov < 180.0) {
        return Err(format!("--fov {}: degrees in (0, 180)", args.fov));
    }
    if !(1..=256).contains(&args.lights) {
        return Err(format!("--lights {}: 1 to 256", args.lights));
    }
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
    // the inputs first: a bad map, photograph, model or camera is refused before the GPU and
    // the renders
    let view = View::new(args)?;
    let map_path = view.map_path.clone();
    let map = trade::args::load_map(Some(&map_path)).map_err(|e| e.to_string())?;
    if view.photo.is_some() && !(1.9..=2.1).contains(&(map.width() as f32 / map.height() as f32)) {
        return Err(format!(
            "{}: {} x {} is not a light probe (an equirectangular map, 2:1)",
            map_path.display(),
            map.width(),
            map.height()
        ));
    }
    let at = view.at;
    let placement = ObjectPlacement {
        at: at - view.shift,
        scale: args.scale,
        rotate_y_degrees: args.rotate_y,
        size: args.object_size,
    };
    let (object, warnings) = SyntheticObject::open_placed(&args.object, &placement).map_err(e)?;
    for w in warnings {
        eprintln!("warning: {}: {w}", args.object);
    }
    let (w, h) = view.size;
    let backdrop = view.backdrop;
    let (eye, target) = match view.eye_target {
        Some((eye, target)) => (eye - view.shift, target - view.shift),
        None => (backdrop.probe(), object.centre),
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
        lights: args.lights,
        ..BackdropSettings::default()
    };
    let t = std::time::Instant::now();
    let session = match &view.photo {
        Some(photo) => BackdropSession::with_photo(map, photo, camera, &settings)
            .map_err(|e| format!("{}: {e}", args.photo.as_deref().unwrap_or(Path::new("")).display()))?,
        None => BackdropSession::new(map, camera, &settings).map_err(e)?,
    };
    let c = &session.compositor;
    if let (Some(fit), Some(photo)) = (&session.photo, &view.photo) {
        say(&format!(
            "{}: {w} x {h}, exposure x {:.4} to the probe's units; {} pixels clipped, {} raised to the probe's radiance",
            args.photo.as_deref().unwrap_or(Path::new("")).display(),
            fit.exposure,
            photo.clipped_pixels(),
            fit.raised
        ));
    }
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
        trade::composite_rows::composite(&gpu, &gc, (c, &frame, &object), main.mode, &gpu_settings)
            .map_err(|e| e.to_string())?;
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
            "eye": (eye + view.shift).to_array(),
            "target": (target + view.shift).to_array(),
            "photo": args.photo.as_ref().map(|p| p.display().to_string()),
            "photo_exposure": session.photo.map(|p| p.exposure),
            "clipped_pixels": view.photo.as_ref().map(real_scene::Photograph::clipped_pixels),
            "clipped_raised": session.photo.map(|p| p.raised),
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
            "rows": table.iter().map(trade::composite_rows::Row::json).collect::<Vec<_>>(),
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

/// What the command's options say of the view: the map (or probe) and, with a photograph, the
/// photograph at the image's size and the shift that puts the probe's foot at the origin and
/// the ground at y = 0 (the backdrop's frame; the user's coordinates are reported).
struct View {
    map_path: PathBuf,
    photo: Option<real_scene::Photograph>,
    backdrop: Backdrop,
    shift: Vec3,
    at: Vec3,
    eye_target: Option<(Vec3, Vec3)>,
    size: (u32, u32),
}

impl View {
    fn new(args: &CompositeArgs) -> Result<Self, String> {
        let eye_target = args.eye.zip(args.target);
        let Some(photo_path) = &args.photo else {
            let map_path = args.envmap.clone().ok_or("--envmap: the map to composite onto")?;
            let at = trade::args::parse_vec3(args.at.as_deref().unwrap_or("0,0,3")).map_err(|e| format!("--at {e}"))?;
            let backdrop = Backdrop::new(args.camera_height, args.ground_radius).map_err(|e| e.to_string())?;
            return Ok(Self { map_path, photo: None, backdrop, shift: Vec3::ZERO, at, eye_target, size: args.size() });
        };
        if args.envmap.is_some() || args.scene.is_some() {
            return Err("--photo takes its light probe as --probe, without --envmap or --scene".into());
        }
        let map_path = args.probe.clone().ok_or("--photo needs --probe: the light probe taken where it was")?;
        let (eye, target) = eye_target.ok_or("--photo needs --eye and --target: the camera that took it")?;
        if !args.ground_y.is_finite() {
            return Err(format!("--ground-y {}: not a height", args.ground_y));
        }
        if eye.y <= args.ground_y {
            return Err(format!(
                "--eye {},{},{}: the camera is not above the ground (y = {})",
                eye.x, eye.y, eye.z, args.ground_y
            ));
        }
        let probe_at = args.probe_at.unwrap_or(eye);
        if probe_at.y <= args.ground_y {
            return Err(format!(
                "--probe-at {},{},{}: the probe is not above the ground (y = {})",
                probe_at.x, probe_at.y, probe_at.z, args.ground_y
            ));
        }
        let backdrop =
            Backdrop::new(probe_at.y - args.ground_y, args.ground_radius).map_err(|e| format!("--probe-at: {e}"))?;
        let photo = real_scene::Photograph::open(photo_path, args.gamma).map_err(|e| e.to_string())?;
        let (pw, ph) = (photo.width, photo.height);
        let aspect = pw as f32 / ph as f32;
        let size = match args.size {
            Some((w, h)) => {
                if ((w as f32 / h as f32) / aspect - 1.0).abs() > 0.01 {
                    return Err(format!(
                        "{}: its {pw} x {ph} does not match the camera's {w} x {h} (--size): another aspect",
                        photo_path.display()
                    ));
                }
                (w, h)
            }
            None if pw > 320 => (320, ((320.0 / aspect).round() as u32).max(1)),
            None => (pw, ph),
        };
        let shift = Vec3::new(probe_at.x, args.ground_y, probe_at.z);
        // by default on the ground under the point looked at
        let at = match &args.at {
            Some(at) => trade::args::parse_vec3(at).map_err(|e| format!("--at {e}"))?,
            None => Vec3::new(target.x, args.ground_y, target.z),
        };
        Ok(Self {
            map_path,
            photo: Some(photo.resized(size.0, size.1)),
            backdrop,
            shift,
            at,
            eye_target: Some((eye, target)),
            size,
        })
    }
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
        let (_, times, _) = trade::composite_rows::composite(gpu, gc, (c, &frame, &moved), mode, settings)
            .map_err(|e| e.to_string())?;
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
