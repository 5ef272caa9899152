//! `envshadow render`: the reference tracer on a built-in scene or a glTF model, with a progress bar and one
//! summary line; and `envshadow compare REF TEST`: RMSE and FLIP.

use envmap_sphere::{EnvMap, LoadOptions, NegativePolicy, Sh9, Tonemap};
use glam::Vec3;
use light_extract::output::{LightsFile, read_lights_json};
use ref_tracer::metrics::{FlipTonemap, flip, rmse};
use ref_tracer::{AmbientMap, EnvLight, Integrator, LightSet, RenderSettings, SamplerKind, SceneBvh, Strategy};
use scene::{DistantLight, Scene};
use std::path::{Path, PathBuf};
use std::time::Duration;
use trade::args::parse_size;

/// What `render` was asked for (parsed by clap).
#[derive(clap::Args)]
pub struct RenderArgs {
    /// Built-in scene, or a glTF 2.0 model (`.gltf`, `.glb`).
    #[arg(long)]
    pub scene: String,
    /// For a model: a Lambertian ground plane under it (albedo 0.5, or the value given).
    #[arg(long, num_args = 0..=1, default_missing_value = "0.5", value_parser = trade::args::parse_albedo)]
    pub ground: Option<f32>,
    /// For a model: its N-th camera (0-based) instead of the first perspective one.
    #[arg(long)]
    pub camera_index: Option<usize>,
    /// Camera position X,Y,Z (with --target), overriding the scene's camera.
    #[arg(long, value_parser = trade::args::parse_vec3, requires = "target")]
    pub eye: Option<glam::Vec3>,
    /// Point looked at X,Y,Z (with --eye).
    #[arg(long, value_parser = trade::args::parse_vec3, requires = "eye")]
    pub target: Option<glam::Vec3>,
    /// Horizontal field of view in degrees (+Y up), overriding the scene's camera.
    #[arg(long)]
    pub fov: Option<f32>,
    /// Environment map; the embedded default when absent.
    #[arg(long)]
    pub envmap: Option<PathBuf>,
    /// env-direct (the truth for direct light), lights (extracted lights + ambient) or path.
    #[arg(long, default_value = "env-direct")]
    pub integrator: String,
    /// lights.json for --integrator lights (an ambient.exr beside it adds SH9 ambient).
    #[arg(long)]
    pub lights: Option<PathBuf>,
    /// Shadow the ambient term by sampling its visibility.
    #[arg(long)]
    pub shadow_ambient: bool,
    /// Bounces for --integrator path.
    #[arg(long, default_value_t = 5)]
    pub max_depth: u32,
    /// Samples per pixel.
    #[arg(long, default_value_t = 64)]
    pub spp: u32,
    /// Seed: equal seeds give equal images on any number of threads.
    #[arg(long, default_value_t = 0)]
    pub seed: u64,
    /// Stop after the pass that ends past this many seconds.
    #[arg(long)]
    pub time_budget: Option<f64>,
    /// BVH build preset, fastest build first: fastest, very-fast, fast, medium, slow, very-slow
    /// (the fastest traversal; at millions of triangles the build is the longest start-up step).
    #[arg(long, default_value = "very-slow")]
    pub bvh: String,
    /// Image size WIDTHxHEIGHT instead of the scene's camera.
    #[arg(long, value_parser = parse_size)]
    pub size: Option<(u32, u32)>,
    /// Output .exr (linear float RGB).
    #[arg(long)]
    pub out: PathBuf,
    /// Also write the AOVs.
    #[arg(long)]
    pub aovs: bool,
    /// Trace through N fixed sub-pixel positions (sample k through position k mod N, the same
    /// for every seed), so that renders compared with `compare` differ only in their lighting.
    #[arg(long)]
    pub pixel_positions: Option<u32>,
    /// Sample points: sobol (Owen-scrambled Sobol, stratified) or independent (plain Monte Carlo).
    #[arg(long, default_value = "sobol")]
    pub sampler: String,
    /// Map samples of env-direct and path: compensated (MIS compensation: only what stands out
    /// of the map's mean, the rest left to the BRDF sample) or complete (the whole map).
    #[arg(long, default_value = "compensated")]
    pub env_sampling: String,
}

/// What a `lights.json` holds for rendering.
pub struct LightsData {
    pub lights: Vec<DistantLight>,
    pub interleaved: Vec<Vec<DistantLight>>,
    pub ambient: Option<Sh9>,
    /// The `ambient.exr` itself, for the specular lobe.
    pub ambient_map: Option<EnvMap>,
}

/// Lights from a `lights.json` (the light-extract schema; `lights[]` and `interleaved[][]` with
/// their `direction`, `solid_angle` and `radiance` are read) and, when an `ambient.exr` sits
/// beside it, that map and its SH9.
pub(crate) fn load_lights(path: &Path) -> Result<LightsData, String> {
    let LightsFile { lights, interleaved, .. } = read_lights_json(path).map_err(|e| e.to_string())?;
    let ambient_path = path.with_file_name("ambient.exr");
    // signed when it is a residual (`+residual`): negative values are data, not ringing
    let signed = LoadOptions { negative: NegativePolicy::Keep, ..LoadOptions::default() };
    let ambient_map = if ambient_path.exists() {
        Some(EnvMap::load_with(&ambient_path, &signed).map_err(|e| e.to_string())?.0)
    } else {
        None
    };
    let ambient = ambient_map.as_ref().map(Sh9::project);
    Ok(LightsData { lights, interleaved, ambient, ambient_map })
}

pub(crate) fn run(args: &RenderArgs) -> Result<(), String> {
    if let Some((w, h)) = args.size
        && (w == 0 || h == 0 || u64::from(w) * u64::from(h) > 1 << 26)
    {
        return Err(format!("--size {w}x{h}: each side at least 1 and at most 2^26 pixels in all"));
    }
    if args.fov.is_some_and(|f| !(f > 0.0 && f < 180.0)) {
        return Err("--fov: degrees in (0, 180)".into());
    }
    let options = scene::import::GltfOptions {
        size: args.size.unwrap_or((640, 480)),
        camera_index: args.camera_index,
        ground: args.ground,
        ..scene::import::GltfOptions::default()
    };
    let quality = ref_tracer::BvhQuality::parse(&args.bvh).ok_or_else(|| {
        let names: Vec<&str> = ref_tracer::BvhQuality::ALL.iter().map(|q| q.name()).collect();
        format!("--bvh {}: one of {}", args.bvh, names.join(", "))
    })?;
    let t = std::time::Instant::now();
    let (mut scene, warnings) = Scene::open(&args.scene, &options).map_err(|e| e.to_string())?;
    for w in warnings {
        eprintln!("warning: {}: {w}", args.scene);
    }
    let load_s = t.elapsed().as_secs_f64();
    if let Some((w, h)) = args.size {
        scene.camera.width = w;
        scene.camera.height = h;
    }
    if let (Some(eye), Some(target)) = (args.eye, args.target) {
        if (target - eye).length_squared() == 0.0 {
            return Err("--eye and --target: two different points".into());
        }
        (scene.camera.eye, scene.camera.target, scene.camera.up) = (eye, target, glam::Vec3::Y);
    }
    if let Some(fov) = args.fov {
        scene.camera.hfov_degrees = fov;
    }
    if args.spp == 0 {
        return Err("--spp must be at least 1".into());
    }
    let map = trade::args::load_map(args.envmap.as_deref()).map_err(|e| e.to_string())?;
    let light_data = match &args.lights {
        Some(p) => Some(load_lights(p)?),
        None => None,
    };
    let ambient_map = light_data.as_ref().and_then(|d| d.ambient_map.as_ref()).and_then(AmbientMap::new);
    let integrator = match args.integrator.as_str() {
        "env-direct" => Integrator::EnvDirect(Strategy::Mis),
        "path" => Integrator::Path { max_depth: args.max_depth.max(1) },
        "lights" => {
            let data = light_data.as_ref().ok_or("--integrator lights needs --lights LIGHTS.json")?;
            Integrator::Lights(LightSet {
                lights: &data.lights,
                interleaved: &data.interleaved,
                ambient: data.ambient,
                ambient_map: ambient_map.as_ref(),
                shadow_ambient: args.shadow_ambient,
                background: Some(&map),
            })
        }
        other => return Err(format!("unknown integrator {other:?}: env-direct, lights or path")),
    };
    let complete = match args.env_sampling.as_str() {
        "compensated" => false,
        "complete" => true,
        other => return Err(format!("unknown env sampling {other:?}; available: compensated, complete")),
    };
    // the lights integrator samples its lights, not the map
    let env = match integrator {
        Integrator::Lights(_) => None,
        _ if complete => Some(EnvLight::complete(&map)),
        _ => Some(EnvLight::new(&map)),
    };
    // progress only once every argument is known good: a refusal stays one line
    let triangles: usize = scene.objects.iter().map(|o| o.mesh.indices.len()).sum();
    eprintln!("{}: {} objects, {triangles} triangles, loaded in {load_s:.2} s", args.scene, scene.objects.len());
    let t = std::time::Instant::now();
    let bvh = SceneBvh::with_quality(&scene, quality);
    eprintln!("BVH ({}) built in {:.2} s", quality.name(), t.elapsed().as_secs_f64());
    let bar = indicatif::ProgressBar::new(u64::from(args.spp));
    bar.set_style(
        indicatif::ProgressStyle::with_template("{msg} [{bar:40}] {pos}/{len} spp, {elapsed} (eta {eta})")
            .map_err(|e| e.to_string())?,
    );
    bar.set_message(format!("{} {}", scene.name, args.integrator));
    let settings = RenderSettings {
        spp: args.spp,
        seed: args.seed,
        time_budget: args.time_budget.map(Duration::from_secs_f64),
        aovs: args.aovs,
        pixel_positions: args.pixel_positions,
        sampler: match args.sampler.as_str() {
            "sobol" => SamplerKind::Sobol,
            "independent" => SamplerKind::Independent,
            other => return Err(format!("unknown sampler {other:?}; available: sobol, independent")),
        },
    };
    let img = ref_tracer::render(&scene, &bvh, env.as_ref(), &integrator, &settings, &|done, _| {
        bar.set_position(u64::from(done))
    });
    bar.finish_and_clear();
    write_outputs(&img, args)?;
    let samples = f64::from(img.width) * f64::from(img.height) * f64::from(img.spp);
    outln!(
        "{} {} x {}, {} spp, {}, {:.2} s, {:.2} M samples/s -> {}",
        scene.name,
        img.width,
        img.height,
        img.spp,
        args.integrator,
        img.seconds,
        samples / img.seconds.max(1e-9) / 1e6,
        args.out.display()
    );
    Ok(())
}

fn write_outputs(img: &ref_tracer::Render, args: &RenderArgs) -> Result<(), String> {
    let (w, h) = (img.width as usize, img.height as usize);
    let save = |suffix: &str, px: &[Vec3]| -> Result<(), String> {
        let path = if suffix.is_empty() { args.out.clone() } else { args.out.with_extension(format!("{suffix}.exr")) };
        envmap_sphere::io::save_exr_rgb(&path, w, h, px).map_err(|e| e.to_string())
    };
    save("", &img.color)?;
    let png = args.out.with_extension("png");
    envmap_sphere::io::save_png_rgb(&png, img.width, img.height, &img.color, &Tonemap::auto(&img.color))
        .map_err(|e| e.to_string())?;
    if args.aovs {
        save("albedo", &img.albedo)?;
        save("normal", &img.normal)?;
        // background: depth 0 and object id 0; objects are numbered from 1
        let depth: Vec<Vec3> = img.depth.iter().map(|d| Vec3::splat(if d.is_finite() { *d } else { 0.0 })).collect();
        save("depth", &depth)?;
        let ids: Vec<Vec3> =
            img.object_id.iter().map(|o| Vec3::splat(if *o == u32::MAX { 0.0 } else { (*o + 1) as f32 })).collect();
        save("object", &ids)?;
    }
    Ok(())
}

/// `compare`: RMSE and FLIP of TEST against REF, one per line.
pub(crate) fn compare(reference: &Path, test: &Path) -> Result<(), String> {
    let a = envmap_sphere::load_rgb_image(reference).map_err(|e| e.to_string())?;
    let b = envmap_sphere::load_rgb_image(test).map_err(|e| e.to_string())?;
    if (a.width, a.height) != (b.width, b.height) {
        return Err(format!(
            "{}: {} x {} does not match {} ({} x {})",
            test.display(),
            b.width,
            b.height,
            reference.display(),
            a.width,
            a.height
        ));
    }
    let tm = FlipTonemap::for_reference(&a.pixels);
    outln!("RMSE {:.6}", rmse(&a.pixels, &b.pixels));
    outln!("FLIP {:.6} ({})", flip(&a.pixels, &b.pixels, a.width, a.height, &tm), tm.describe());
    Ok(())
}
