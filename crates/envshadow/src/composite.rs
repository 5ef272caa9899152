//! `envshadow composite`: a synthetic object composited on the GPU (paper 003) into a built-in
//! real scene's photograph (`--scene`), against the path-traced truth and Debevec's offline
//! differential rendering, or onto a user's HDRI (`--envmap` alone: the backdrop, see
//! [`crate::backdrop`]): errors in 8-bit codes, time per frame, the images; `--sweep` for
//! every passes x HDR/LDR setting, `--path` for a moving object.

use std::path::{Path, PathBuf};

use differential_composite::gpu::{GpuCompositor, GpuSettings};
use differential_composite::{MODEL_SIZE, Mode, SyntheticObject, code_error};
use glam::Vec3;
use real_scene::{Perturbation, RealScene};
use shaft_hierarchy::preprocess::PreprocessSettings;
use trade::composite_rows::{figure3_datasets, ms, rows};
use trade::{PhotoSettings, Session, SessionSettings};

use trade::args::parse_size;

/// The command's options.
#[derive(clap::Args)]
pub struct CompositeArgs {
    /// The built-in real scene (ar_room, ar_ground); the default without --envmap: ar_room.
    #[arg(long)]
    pub scene: Option<String>,
    /// A user's HDR map (.exr, .hdr): without --scene, the object is composited onto it, its
    /// lower hemisphere projected onto a ground disc (the backdrop).
    #[arg(long)]
    pub envmap: Option<PathBuf>,
    /// A user's photograph (PNG or JPEG through a response of --gamma, or an HDR EXR) to
    /// composite into, with --probe, --eye, --target and --fov: the ground plane is at
    /// --ground-y.
    #[arg(long, requires_all = ["probe", "eye", "target"])]
    pub photo: Option<PathBuf>,
    /// The light probe taken where the photograph was (an HDR lat-long map, .exr or .hdr).
    #[arg(long, requires = "photo")]
    pub probe: Option<PathBuf>,
    /// Photograph: the ground plane's height.
    #[arg(long, default_value_t = 0.0, allow_hyphen_values = true)]
    pub ground_y: f32,
    /// Photograph: where the probe was captured (its ground projection's centre); by default
    /// where the camera stood.
    #[arg(long, value_parser = trade::args::parse_vec3, requires = "photo", allow_hyphen_values = true)]
    pub probe_at: Option<Vec3>,
    /// Photograph: the gamma of the camera's response (8-bit and 16-bit images are read
    /// through its inverse; the composite is written through it).
    #[arg(long, default_value_t = 2.2)]
    pub gamma: f32,
    /// The object: a built-in (sphere, box) or a glTF model's path (.gltf, .glb). In a built-in
    /// scene a model is fitted into a cube of --object-size; on a backdrop it keeps its own
    /// size (glTF's metres) unless --object-size is given.
    #[arg(long, default_value = "sphere")]
    pub object: String,
    /// A model's size: the largest side of its bounding box, metres (built-ins keep theirs;
    /// in a built-in scene 0.6 m when absent).
    #[arg(long)]
    pub object_size: Option<f32>,
    /// Built-in scene: the object's centre X,Y,Z from the floor's centre (default 0,0.3,0.5).
    /// Backdrop: where the bottom of its bounding box stands (default 0,0,3: on the ground
    /// 3 m ahead, toward the middle of the map).
    #[arg(long, allow_hyphen_values = true)]
    pub at: Option<String>,
    /// Backdrop: the object's size times this.
    #[arg(long, default_value_t = 1.0)]
    pub scale: f32,
    /// Backdrop: turn the object about the vertical by this many degrees.
    #[arg(long, default_value_t = 0.0, allow_hyphen_values = true)]
    pub rotate_y: f32,
    /// Backdrop: the camera's position X,Y,Z (with --target); by default at the map's centre of
    /// projection, --camera-height above the ground.
    #[arg(long, value_parser = trade::args::parse_vec3, requires = "target", allow_hyphen_values = true)]
    pub eye: Option<Vec3>,
    /// Backdrop: the point looked at (with --eye); by default the object's centre.
    #[arg(long, value_parser = trade::args::parse_vec3, requires = "eye", allow_hyphen_values = true)]
    pub target: Option<Vec3>,
    /// Backdrop: horizontal field of view, degrees.
    #[arg(long, default_value_t = 60.0)]
    pub fov: f32,
    /// Backdrop: the map's centre of projection above the ground, metres.
    #[arg(long, default_value_t = real_scene::Backdrop::DEFAULT_CAMERA_HEIGHT)]
    pub camera_height: f32,
    /// Backdrop: the radius of the ground disc the map's lower half is projected onto, metres.
    #[arg(long, default_value_t = real_scene::Backdrop::DEFAULT_GROUND_RADIUS)]
    pub ground_radius: f32,
    /// Backdrop and photograph: lights extracted from the map, the shadow sources (more:
    /// narrower cones, truer soft and contact shadows, more shadow maps).
    #[arg(long, default_value_t = 32)]
    pub lights: usize,
    /// Backdrop: samples a pixel of the path-traced truth (it is two renders of half as many,
    /// whose difference gives its own noise).
    #[arg(long, default_value_t = 1024)]
    pub truth_spp: u32,
    /// Backdrop: samples a pixel of the path-traced shadow catcher (the offline baseline).
    #[arg(long, default_value_t = 64)]
    pub catcher_spp: u32,
    /// Backdrop: the paper's hard shadow per representative instead of soft shadows over the
    /// cone of the sources it stands for (PCSS).
    #[arg(long)]
    pub hard_shadows: bool,
    /// Backdrop: the soft shadows' filter samples (the blocker search takes half as many).
    #[arg(long, default_value_t = 16)]
    pub pcss_samples: u32,
    /// Shadow passes (representative sources); 0: one per occluded source.
    #[arg(long, default_value_t = 50)]
    pub passes: usize,
    /// Subtract intensity transfers from the 8-bit photograph (paper 003's LDR path).
    #[arg(long)]
    pub ldr: bool,
    /// The composite image (PNG; on a backdrop in HDR mode an EXR beside it too).
    #[arg(long, default_value = "target/composite/composite.png")]
    pub out: PathBuf,
    /// One JSON object: ms_per_frame, error_rmse_codes, changed_pixels, adapter and more
    /// (on a backdrop: pathtraced_error_rmse_codes, pathtraced_ms, sources_excluded).
    #[arg(long)]
    pub json: bool,
    /// Move the object across the ground, 1 m left of --at to 1 m right, in this many frames
    /// (or --frames when no number is given): each frame's time (and in a built-in scene its
    /// error against its own truth).
    #[arg(long, num_args = 0..=1)]
    pub path: Option<Option<usize>>,
    /// Frames of --path.
    #[arg(long, default_value_t = 10)]
    pub frames: usize,
    /// Every setting: passes 1, 10, 20, 50 and all, HDR and LDR (and Figure 3 in a built-in
    /// scene).
    #[arg(long)]
    pub sweep: bool,
    /// Image size WIDTHxHEIGHT (default 320x240; with --photo the photograph's aspect, 320
    /// wide at most).
    #[arg(long, value_parser = parse_size)]
    pub size: Option<(u32, u32)>,
    /// Built-in scene: samples per pixel of the photograph, the truth and Debevec's renders.
    #[arg(long, default_value_t = 32)]
    pub spp: u32,
    /// The reconstruction's reflectances times this (1: exact).
    #[arg(long, default_value_t = 1.0)]
    pub reflectance_scale: f32,
    /// Estimate the reconstruction's reflectances from the capture's radiances (radiance over
    /// computed irradiance) instead of solving it with its own.
    #[arg(long)]
    pub estimate_reflectances: bool,
    /// The shaft hierarchy's pruning: a pair below this fraction of every reached vertex's
    /// radiance is dropped (built-in scenes: the paper's 0.02; backdrop: 0.002).
    #[arg(long)]
    pub prune: Option<f32>,
    /// Shadow-map side in texels.
    #[arg(long, default_value_t = 256)]
    pub map_resolution: u32,
    /// The sphere's shadow-mesh detail (slices; about detail^2 triangles).
    #[arg(long, default_value_t = 22)]
    pub shadow_detail: u32,
    /// A patch source's shadow map: `paraboloid` (one hemispherical map, paper 004) or `cube`.
    #[arg(long, default_value = "paraboloid")]
    pub patch_maps: String,
    /// The GPU adapter: a case-insensitive part of its name, or `cpu`.
    #[arg(long)]
    pub adapter: Option<String>,
}

impl CompositeArgs {
    /// The image size asked for, or the default.
    pub(crate) fn size(&self) -> (u32, u32) {
        self.size.unwrap_or((320, 240))
    }

    /// The frames of `--path`, if asked for.
    pub(crate) fn path_frames(&self) -> Option<usize> {
        self.path.map(|n| n.unwrap_or(self.frames).max(1))
    }

    /// The GPU settings asked for.
    pub(crate) fn gpu_settings(&self) -> Result<GpuSettings, String> {
        let patch_maps = match self.patch_maps.as_str() {
            "paraboloid" => shadowmap_paraboloid::Technique::DualParaboloid,
            "cube" => shadowmap_paraboloid::Technique::Cube,
            other => return Err(format!("--patch-maps {other:?}: paraboloid or cube")),
        };
        Ok(GpuSettings {
            map_resolution: self.map_resolution,
            shadow_detail: self.shadow_detail,
            patch_maps,
            layers_per_array: None,
            pcss: None,
            coverage_samples: 1,
            cull_masks: false,
        })
    }
}

pub(crate) fn run(args: &CompositeArgs) -> Result<(), String> {
    if args.photo.is_some() || (args.scene.is_none() && args.envmap.is_some()) {
        return crate::backdrop::run(args);
    }
    let say = |s: &str| {
        if !args.json {
            outln!("{s}");
        }
    };
    let scene_name = args.scene.as_deref().unwrap_or("ar_room");
    let e = |e: differential_composite::CompositeError| e.to_string();
    let at = trade::args::parse_vec3(args.at.as_deref().unwrap_or("0,0.3,0.5")).map_err(|e| format!("--at {e}"))?;
    let gpu_settings = args.gpu_settings()?;
    let gpu = open_gpu(args.adapter.as_deref())?;
    say(&format!("GPU: {}", gpu.describe()));
    let probe = RealScene::builtin(scene_name).map_err(|e| e.to_string())?;
    // the object first: a bad model is refused before the capture's minutes
    let (object, warnings) =
        SyntheticObject::open(&args.object, probe.floor_centre() + at, args.object_size.unwrap_or(MODEL_SIZE))
            .map_err(e)?;
    for w in warnings {
        eprintln!("warning: {}: {w}", args.object);
    }
    let (map, lights) =
        trade::session::environment(&probe, light_extract::DEFAULT_METHOD, 32).map_err(|e| e.to_string())?;
    let settings = SessionSettings {
        size: Some(args.size()),
        photo: PhotoSettings { spp: args.spp, ..SessionSettings::default().photo },
        reconstruction: Perturbation { reflectance_scale: args.reflectance_scale, ..Perturbation::NONE },
        estimate_reflectances: args.estimate_reflectances,
        preprocess: PreprocessSettings {
            hierarchy: shaft_hierarchy::Settings {
                prune_fraction: args.prune.unwrap_or(0.02),
                ..shaft_hierarchy::Settings::PAPER
            },
            ..PreprocessSettings::PAPER
        },
    };
    let t = std::time::Instant::now();
    let session = Session::new(scene_name, map, lights, &settings).map_err(e)?;
    let c = &session.compositor;
    say(&format!(
        "{}: {} x {}, photograph {} spp, {} sources, {} receivers; reconstruction with reflectances x {}{}, pruning {} ({:.1} s)",
        scene_name,
        args.size().0,
        args.size().1,
        args.spp,
        c.prepared.sources.len(),
        c.prepared.receivers.len(),
        args.reflectance_scale,
        if args.estimate_reflectances { ", then estimated from the capture" } else { "" },
        args.prune.unwrap_or(0.02),
        t.elapsed().as_secs_f64()
    ));
    let gc = GpuCompositor::new(&gpu, c).map_err(|e| e.to_string())?;
    let mode = if args.ldr { Mode::Ldr } else { Mode::Hdr };
    if let Some(frames) = args.path_frames() {
        return moving(args, (&gpu, &gc, &gpu_settings), &session, (&object, at, frames), mode);
    }
    let t = std::time::Instant::now();
    let truth = session.truth(&object).map_err(e)?;
    let debevec = session.debevec(&object).map_err(e)?;
    say(&format!("truth and Debevec's differential rendering path traced ({:.1} s)", t.elapsed().as_secs_f64()));
    let deb = code_error(&debevec, &truth, &c.photo_ldr);
    let passes: Vec<usize> = if args.sweep { vec![1, 10, 20, 50, 0] } else { vec![args.passes] };
    let modes: Vec<Mode> = if args.sweep { vec![Mode::Hdr, Mode::Ldr] } else { vec![mode] };
    let table = rows(&gpu, &gc, c, &object, &truth, &passes, &modes, &gpu_settings, 5).map_err(|e| e.to_string())?;
    let (w, h) = args.size();
    let save = |path: &Path, img: &[[u8; 3]]| save_png(path, (w, h), img);
    let beside = |suffix: &str| -> PathBuf {
        let stem = args.out.file_stem().map_or_else(|| "composite".into(), |s| s.to_string_lossy().to_string());
        args.out.with_file_name(format!("{stem}_{suffix}.png"))
    };
    let main = table.last().ok_or("no composite")?;
    save(&args.out, &main.image)?;
    save(&beside("photo"), &c.photo_ldr)?;
    save(&beside("truth"), &truth)?;
    save(&beside("debevec"), &debevec)?;
    save(&beside("error"), &differential_composite::metrics::error_image(&main.image, &truth))?;
    if args.json {
        let v = serde_json::json!({
            "scene": scene_name,
            "object": args.object,
            "at": at.to_array(),
            "passes": main.passes,
            "representatives": main.reps,
            "occluded_sources": main.occluded_sources,
            "mode": main.mode_label().to_lowercase(),
            "error_mae_codes": main.error.mae_changed,
            "error_rmse_codes": main.error.rmse_changed,
            "error_mae_codes_image": main.error.mae,
            "error_rmse_codes_image": main.error.rmse,
            "debevec_error_mae_codes": deb.mae_changed,
            "debevec_error_rmse_codes": deb.rmse_changed,
            "changed_pixels": main.error.changed,
            "size": [w, h],
            "spp": args.spp,
            "reflectance_scale": args.reflectance_scale,
            "estimate_reflectances": args.estimate_reflectances,
            "prune": args.prune.unwrap_or(0.02),
            "adapter": gpu.info.name,
            "rows": table.iter().map(trade::composite_rows::Row::json).collect::<Vec<_>>(),
        });
        print_json(v, main);
        return Ok(());
    }
    outln!(
        "Debevec (offline, same model): MAE {:.2} codes, RMSE {:.2} over the {} pixels the object changed",
        deb.mae_changed,
        deb.rmse_changed,
        deb.changed
    );
    outln!(
        "passes | reps | mode | MAE codes | RMSE codes | / Debevec | ms per frame (cpu + gbuffer + maps + masks + resolve)"
    );
    for r in &table {
        let [total, cpu, gbuffer, maps, masks, resolve] = r.times_ms();
        outln!(
            "{:>6} | {:>4} | {} | {:>9.2} | {:>10.2} | {:>9.2} | {total:.2} ({cpu:.2} + {gbuffer:.2} + {maps:.2} + {masks:.2} + {resolve:.2})",
            r.passes_label(),
            r.reps,
            r.mode_label(),
            r.error.mae_changed,
            r.error.rmse_changed,
            r.error.mae_changed / deb.mae_changed.max(1e-9),
        );
    }
    if args.sweep {
        let frame = c.frame(&object, 0);
        // the paper's 50 sources a vertex where the scene has them
        let (data, n) = [50, 32, 16, 8]
            .iter()
            .map(|&n| (figure3_datasets(&session, &frame, 4, n), n))
            .find(|(d, _)| !d.is_empty())
            .unwrap_or_default();
        outln!(
            "Figure 3 ({} vertices with {n} occluded sources; RMS error in codes for P occluded, 10000 trials):",
            data.len()
        );
        for share in [0.5, 0.25, 0.1] {
            let curve = differential_composite::ldr::figure3(&data, &c.response, share, 10_000, 1);
            let row: Vec<String> = curve.iter().step_by(5).map(|(p, e)| format!("{p}:{e:.2}")).collect();
            outln!("  split {:.0}/{:.0}: {}", share * 100.0, (1.0 - share) * 100.0, row.join(" "));
        }
    }
    outln!("wrote {} (and _photo, _truth, _debevec, _error)", args.out.display());
    Ok(())
}

/// `frames` positions along a line across the floor: per frame the traversal, the GPU
/// composite, its time and its error against that frame's truth.
fn moving(
    args: &CompositeArgs,
    (gpu, gc, settings): (&gpu::Gpu, &GpuCompositor, &GpuSettings),
    session: &Session,
    (object, start, frames): (&SyntheticObject, Vec3, usize),
    mode: Mode,
) -> Result<(), String> {
    let e = |e: differential_composite::CompositeError| e.to_string();
    let c = &session.compositor;
    let mut out = Vec::new();
    for k in 0..frames {
        let s = if frames > 1 { k as f32 / (frames - 1) as f32 } else { 0.0 };
        let offset = Vec3::new(-1.0 + 2.0 * s, 0.0, 0.0);
        let at = start + offset;
        let object = object.moved(offset);
        let frame = c.frame(&object, args.passes);
        let (image, times, _) = trade::composite_rows::composite(gpu, gc, (c, &frame, &object), mode, settings)
            .map_err(|e| e.to_string())?;
        let truth = session.truth(&object).map_err(e)?;
        let err = code_error(&image, &truth, &c.photo_ldr);
        if args.json {
            out.push(serde_json::json!({"frame": k, "at": at.to_array(), "ms_per_frame": ms(times.total()), "error_mae_codes": err.mae_changed, "error_rmse_codes": err.rmse_changed, "representatives": frame.reps.len()}));
        } else {
            outln!(
                "frame {k:>3} at [{:+.2}, {:+.2}, {:+.2}]: {} reps, {:.2} ms, MAE {:.2} codes, RMSE {:.2}",
                at.x,
                at.y,
                at.z,
                frame.reps.len(),
                ms(times.total()),
                err.mae_changed,
                err.rmse_changed
            );
        }
    }
    if args.json {
        outln!("{}", serde_json::json!({"frames": out, "adapter": gpu.info.name}));
    }
    Ok(())
}

/// The GPU: `--adapter`, else `ENVSHADOW_ADAPTER`, else the best adapter present. Without any
/// adapter, says how to get a software one (`cargo xtask test` installs it; a user tool
/// installs nothing).
pub(crate) fn open_gpu(adapter: Option<&str>) -> Result<gpu::Gpu, String> {
    let opened = match adapter {
        Some(name) => gpu::Gpu::with_adapter(Some(name)),
        None => gpu::Gpu::new(),
    };
    opened.map_err(|e| match e {
        gpu::GpuError::NoAdapter(_) => format!(
            "{e}; for a software GPU install Mesa's lavapipe (Debian/Ubuntu: `apt install mesa-vulkan-drivers`)"
        ),
        other => other.to_string(),
    })
}

/// Writes an 8-bit image (row-major RGB), creating its folder; the error names the file.
pub(crate) fn save_png(path: &Path, (w, h): (u32, u32), img: &[[u8; 3]]) -> Result<(), String> {
    if let Some(dir) = path.parent().filter(|d| !d.as_os_str().is_empty()) {
        std::fs::create_dir_all(dir).map_err(|e| format!("{}: {e}", dir.display()))?;
    }
    envmap_sphere::io::save_png_srgb8(path, w, h, &img.iter().flatten().copied().collect::<Vec<u8>>())
        .map_err(|e| e.to_string())
}

/// Prints one command's JSON object with `row`'s times added.
pub(crate) fn print_json(mut v: serde_json::Value, row: &trade::composite_rows::Row) {
    if let Some(o) = v.as_object_mut() {
        o.extend(row.times_json());
    }
    outln!("{v}");
}
