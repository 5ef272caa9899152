//! `cargo xtask validate`: the main job. On the embedded default map and `spheres_box` (or the
//! given ones): decompose the map with EmissiveSplit, render the lights on the GPU with
//! orthographic shadow maps (and without shadows), render the `ref-tracer` references, measure
//! the `room` point light's paraboloid and cube shadow maps against ray-traced visibility and
//! time them, write `target/validate/report.html` (self-contained), and fail when an error
//! exceeds its threshold in `validate/thresholds.json`.

mod readme;
mod report;

use crate::render::load_map;
use envmap_sphere::EnvMap;
use glam::Vec3;
use gpu::{
    Background, GBufferPass, Gpu, SceneGeometry, ShadeLight, ShadeParams, ShadingPass, ShadowGeometry, Visibility,
};
use light_extract::{EmissiveSplit, LightExtractor};
use ref_tracer::metrics::{FlipTonemap, flip, rmse};
use ref_tracer::visibility::{VisibilityLight, light_visibility};
use ref_tracer::{EnvLight, Integrator, LightSet, RenderSettings, SceneBvh, Strategy};
use report::Report;
use shadowmap_paraboloid::{
    ShadowLight, ShadowMapper, ShadowSettings, Technique, disagreement, equal_texel_variants, shadow_triangles,
};
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use std::time::Instant;

/// Options of `cargo xtask validate`.
#[derive(clap::Parser, Clone, Debug)]
pub struct ValidateArgs {
    /// Environment map (.exr or .hdr); the embedded default map when absent.
    #[arg(long)]
    pub envmap: Option<PathBuf>,
    /// Built-in scene lit by the map.
    #[arg(long, default_value = "spheres_box")]
    pub scene: String,
    /// Smaller images and fewer samples: about 10 s on 2 cores once built.
    #[arg(long)]
    pub quick: bool,
    /// Output directory.
    #[arg(long, default_value = "target/validate")]
    pub out: PathBuf,
    /// The GPU adapter: a case-insensitive part of its name, or `cpu` for a software one
    /// (lavapipe); the best adapter present when absent (discrete, integrated, then CPU).
    #[arg(long)]
    pub adapter: Option<String>,
    /// Error thresholds (JSON, as validate/thresholds.json); the checked-in file embedded in
    /// this binary when absent.
    #[arg(long)]
    pub thresholds: Option<PathBuf>,
    /// Rewrite the validate block of this Markdown file (the README) with this run's figures.
    #[arg(long)]
    pub readme: Option<PathBuf>,
    /// Fail when the validate block of this Markdown file differs from this run's figures (the
    /// GPU's only when the file names the same adapter).
    #[arg(long)]
    pub check_readme: Option<PathBuf>,
}

/// Settings of one run.
struct Plan {
    size: (u32, u32),
    reference_spp: u32,
    lights_spp: u32,
    lights: usize,
    shadow: ShadowSettings,
    room_size: (u32, u32),
    repeats: usize,
}

impl Plan {
    fn new(quick: bool) -> Self {
        let shadow = ShadowSettings { resolution: 2048, pcf_radius: 1, ..ShadowSettings::default() };
        if quick {
            Self {
                size: (320, 240),
                reference_spp: 128,
                lights_spp: 8,
                lights: 32,
                shadow: ShadowSettings { resolution: 1024, ..shadow },
                room_size: (320, 240),
                repeats: 3,
            }
        } else {
            Self {
                size: (640, 480),
                reference_spp: 256,
                lights_spp: 16,
                lights: 32,
                shadow,
                room_size: (640, 480),
                repeats: 7,
            }
        }
    }

    fn describe(&self) -> String {
        format!(
            "{}x{}, reference {} spp, ray-traced lights {} spp, K = {}, orthographic maps {}² with PCF {}x{}, room masks {}x{}, timings median of {}",
            self.size.0,
            self.size.1,
            self.reference_spp,
            self.lights_spp,
            self.lights,
            self.shadow.resolution,
            2 * self.shadow.pcf_radius + 1,
            2 * self.shadow.pcf_radius + 1,
            self.room_size.0,
            self.room_size.1,
            self.repeats
        )
    }
}

/// One image row of the report.
struct Row {
    name: String,
    what: String,
    image: Vec<Vec3>,
    seconds: f64,
    rmse: Option<f64>,
    flip: Option<f64>,
    rmse_vs_lights: Option<f64>,
}

/// One point-light shadow-map measurement.
struct MaskRow {
    name: String,
    technique: Technique,
    texels: u64,
    disagreement: f64,
    gpu_ms: f64,
    triangles: u32,
}

struct Stages {
    total: usize,
    done: usize,
    start: Instant,
}

impl Stages {
    fn next(&mut self, what: &str) {
        self.done += 1;
        outln!("[{}/{}] {what} ({:.1} s)", self.done, self.total, self.start.elapsed().as_secs_f64());
    }
}

pub fn run(args: &ValidateArgs) -> Result<(), String> {
    let plan = Plan::new(args.quick);
    // before any other work: which GPU runs it (and lavapipe's install, where there is none)
    let gpu = crate::lavapipe::open_gpu(args.adapter.as_deref())?;
    outln!("GPU: {}", gpu.describe());
    let thresholds = load_thresholds(args.thresholds.as_deref())?;
    let mut stages = Stages { total: 8, done: 0, start: Instant::now() };
    stages.next("load environment map");
    let map = load_map(args.envmap.as_deref())?;
    let map_name = args.envmap.as_ref().map_or_else(
        || envmap_sphere::DEFAULT_MAP_NAME.to_string(),
        |p| p.file_name().map_or_else(|| p.display().to_string(), |n| n.to_string_lossy().to_string()),
    );
    let mut scene = scene::Scene::builtin(&args.scene).map_err(|e| e.to_string())?;
    (scene.camera.width, scene.camera.height) = plan.size;
    let (w, h) = plan.size;

    stages.next("extract lights (EmissiveSplit)");
    let decomposition = EmissiveSplit { lights: plan.lights, ..EmissiveSplit::default() }
        .extract(&map)
        .map_err(|e| format!("{map_name}: {e}"))?;
    let lights = decomposition.distant_lights();
    let sets = decomposition.interleaved_distant_lights();

    stages.next(&format!("reference: ref-tracer env-direct, {} spp", plan.reference_spp));
    let bvh = SceneBvh::new(&scene);
    let env = EnvLight::new(&map);
    let t = Instant::now();
    let settings = RenderSettings { spp: plan.reference_spp, seed: 1, aovs: false, ..RenderSettings::default() };
    let reference =
        ref_tracer::render(&scene, &bvh, Some(&env), &Integrator::EnvDirect(Strategy::Mis), &settings, &|_, _| {});
    let reference_s = t.elapsed().as_secs_f64();

    stages.next(&format!("ray-traced lights: ref-tracer lights, {} spp", plan.lights_spp));
    let t = Instant::now();
    let set = LightSet {
        lights: &lights,
        interleaved: &sets,
        ambient: Some(decomposition.ambient_sh),
        // the GPU pass shades the ambient by SH9 alone
        ambient_map: None,
        shadow_ambient: false,
        background: Some(&map),
    };
    let settings = RenderSettings { spp: plan.lights_spp, seed: 2, ..settings };
    let traced = ref_tracer::render(&scene, &bvh, None, &Integrator::Lights(set), &settings, &|_, _| {});
    let traced_s = t.elapsed().as_secs_f64();

    stages.next(&format!("GPU: G-buffer, orthographic shadow maps, shading ({})", gpu.info.name));
    let passes = Passes {
        gbuffer: GBufferPass::new(&gpu),
        shadows: ShadowMapper::new(&gpu),
        shading: ShadingPass::new(&gpu).map_err(|e| e.to_string())?,
    };
    let (gpu_image, gpu_unshadowed, gpu_s, shadow_ms) = gpu_render(&gpu, &passes, &scene, &map, &decomposition, &plan)?;

    stages.next("room: point-light shadow maps against ray-traced visibility, and their speed");
    let (mask_rows, mask_images, size_rows, clock) = room_masks(&gpu, &passes, &plan)?;

    stages.next("metrics");
    let tm = FlipTonemap::for_reference(&reference.color);
    let metric = |img: &[Vec3]| (rmse(&reference.color, img), flip(&reference.color, img, w, h, &tm));
    let mut rows = vec![Row {
        name: "reference".into(),
        what: format!("ref-tracer env-direct (MIS), {} spp", plan.reference_spp),
        image: reference.color.clone(),
        seconds: reference_s,
        rmse: None,
        flip: None,
        rmse_vs_lights: None,
    }];
    for (name, what, image, seconds) in [
        (
            "lights_ray_traced",
            format!(
                "ref-tracer lights: {} lights + SH9 ambient, 8 interleaved sets, {} spp",
                lights.len(),
                plan.lights_spp
            ),
            traced.color.clone(),
            traced_s,
        ),
        (
            "gpu_shadow_maps",
            format!(
                "GPU: {} lights with orthographic shadow maps {}², PCF {}, + SH9 ambient (shadow maps {shadow_ms:.1} ms)",
                lights.len(),
                plan.shadow.resolution,
                plan.shadow.pcf_radius
            ),
            gpu_image,
            gpu_s,
        ),
        ("gpu_unshadowed", "GPU: the same lights without shadows".to_string(), gpu_unshadowed, 0.0),
    ] {
        let (r, f) = metric(&image);
        rows.push(Row {
            name: name.into(),
            what,
            rmse_vs_lights: (name != "lights_ray_traced").then(|| rmse(&traced.color, &image)),
            image,
            seconds,
            rmse: Some(r),
            flip: Some(f),
        });
    }

    stages.next("report and thresholds");
    std::fs::create_dir_all(&args.out).map_err(|e| format!("{}: {e}", args.out.display()))?;
    let key = format!("{}@{}{}", args.scene, map_name, if args.quick { "/quick" } else { "" });
    let mut measured: BTreeMap<String, f64> = BTreeMap::new();
    for r in &rows {
        if let (Some(rm), Some(fl)) = (r.rmse, r.flip) {
            measured.insert(format!("{key}:{}.rmse", r.name), rm);
            measured.insert(format!("{key}:{}.flip", r.name), fl);
        }
    }
    let room_key = format!("room_point_light{}", if args.quick { "/quick" } else { "" });
    for m in &mask_rows {
        measured.insert(format!("{room_key}:{}.disagreement", m.name), m.disagreement);
    }
    let failures: Vec<String> = measured
        .iter()
        .filter_map(|(k, v)| thresholds.get(k).filter(|t| *v > **t).map(|t| format!("{k} = {v:.5} exceeds {t}")))
        .collect();
    let checked = measured.keys().filter(|k| thresholds.contains_key(*k)).count();
    let report = Report {
        gpu: &gpu,
        plan: &plan,
        map_name: &map_name,
        scene: &args.scene,
        rows: &rows,
        masks: &mask_rows,
        mask_images: &mask_images,
        sizes: &size_rows,
        clock,
        tm: &tm,
        size: (w, h),
        failures: &failures,
        checked,
        lights: lights.len(),
        extract_ms: decomposition.time_ms,
    };
    let path = args.out.join("report.html");
    std::fs::write(&path, report.html(&args.out)?).map_err(|e| format!("{}: {e}", path.display()))?;
    for r in &rows {
        if let (Some(rm), Some(fl)) = (r.rmse, r.flip) {
            outln!("  {:<18} RMSE {rm:.4}  FLIP {fl:.4}  {:.2} s", r.name, r.seconds);
        }
    }
    for m in &mask_rows {
        outln!("  room {:<26} {:>7.3} % of pixels disagree  {:>7.2} ms", m.name, m.disagreement * 100.0, m.gpu_ms);
    }
    for r in &size_rows {
        outln!(
            "  room paraboloid_1024, widest edge {:.3} rad ({} triangles): {:.3} % disagree",
            r.widest,
            r.triangles,
            r.disagreement * 100.0
        );
    }
    outln!("report: {}", path.display());
    let figures = readme::Figures {
        adapter: &gpu.info.name,
        adapter_detail: &format!(
            "{:?}, {:?}; driver {} {}",
            gpu.info.backend, gpu.info.device_type, gpu.info.driver, gpu.info.driver_info
        ),
        settings: &format!("{} on {map_name}, {}", args.scene, plan.describe()),
        rows: &rows,
        masks: &mask_rows,
        clock: clock.name(),
    };
    if let Some(p) = &args.readme {
        readme::write(p, &figures)?;
        outln!("wrote the validate figures into {}", p.display());
    }
    if let Some(p) = &args.check_readme {
        outln!("{}", readme::check(p, &figures)?);
    }
    if checked == 0 {
        outln!("thresholds: none recorded for {key} (validate/thresholds.json)");
    }
    if failures.is_empty() {
        outln!("validate: {checked} thresholds met, done in {:.1} s", stages.start.elapsed().as_secs_f64());
        Ok(())
    } else {
        Err(format!("validate: {} of {checked} thresholds exceeded:\n  {}", failures.len(), failures.join("\n  ")))
    }
}

/// The checked-in thresholds, embedded so that a binary copied elsewhere still has them.
pub const THRESHOLDS: &str = include_str!("../../../validate/thresholds.json");

/// The thresholds of `path`, or the embedded checked-in ones.
fn load_thresholds(path: Option<&Path>) -> Result<BTreeMap<String, f64>, String> {
    match path {
        Some(p) => {
            let text = std::fs::read_to_string(p).map_err(|e| format!("{}: {e}", p.display()))?;
            parse_thresholds(&text, &p.display().to_string())
        }
        None => parse_thresholds(THRESHOLDS, "validate/thresholds.json (embedded)"),
    }
}

/// `{"thresholds": {"key": number, ...}}`; `name` is the file's name in errors.
pub fn parse_thresholds(text: &str, name: &str) -> Result<BTreeMap<String, f64>, String> {
    let one_line = envmap_sphere::error::one_line;
    let value: serde_json::Value =
        serde_json::from_str(text).map_err(|e| format!("{name}: {}", one_line(&e.to_string())))?;
    let obj = value
        .get("thresholds")
        .and_then(|v| v.as_object())
        .ok_or_else(|| format!("{name}: no \"thresholds\" object"))?;
    let mut out = BTreeMap::new();
    for (k, v) in obj {
        let t = v
            .as_f64()
            .filter(|t| t.is_finite())
            .ok_or_else(|| format!("{name}: threshold {} is not a finite number", one_line(k)))?;
        out.insert(k.clone(), t);
    }
    Ok(out)
}

/// Sphere around what the camera sees: the mean visible position and the 95th percentile of
/// distances to it (the rest, far away, is left unshadowed).
fn view_focus(points: &[(Vec3, Vec3)]) -> Option<(Vec3, f32)> {
    let pts: Vec<Vec3> = points.iter().map(|(p, _)| *p).filter(|p| p.is_finite()).collect();
    if pts.is_empty() {
        return None;
    }
    let c = pts.iter().copied().sum::<Vec3>() / pts.len() as f32;
    let mut d: Vec<f32> = pts.iter().map(|p| p.distance(c)).collect();
    d.sort_by(f32::total_cmp);
    Some((c, d[(d.len() * 95 / 100).min(d.len() - 1)]))
}

type GpuImages = (Vec<Vec3>, Vec<Vec3>, f64, f64);

/// The GPU passes, built once per run.
struct Passes {
    gbuffer: GBufferPass,
    shadows: ShadowMapper,
    shading: ShadingPass,
}

fn gpu_render(
    gpu: &Gpu,
    passes: &Passes,
    scene: &scene::Scene,
    map: &EnvMap,
    d: &light_extract::Decomposition,
    plan: &Plan,
) -> Result<GpuImages, String> {
    let e = |e: gpu::GpuError| e.to_string();
    let start = Instant::now();
    let geometry = SceneGeometry::upload(gpu, scene).map_err(e)?;
    let gb = passes.gbuffer.render(gpu, &geometry, &scene.camera).map_err(e)?;
    let points = gb.read_points(gpu).map_err(e)?;
    let tris = gpu::scene_triangles(scene);
    let shadow_geometry = ShadowGeometry::upload(gpu, &tris, ShadowGeometry::CHUNK_TRIANGLES).map_err(e)?;
    let mapper = &passes.shadows;
    let settings = ShadowSettings { focus: view_focus(&points), ..plan.shadow };
    let lights: Vec<ShadeLight> = d.lights.iter().map(|l| ShadeLight::from(&l.light)).collect();
    let (w, h) = gb.size();
    let vis = Visibility::new(gpu, w, h, lights.len() as u32).map_err(e)?;
    let mut shadow_ms = 0.0;
    for (k, l) in d.lights.iter().enumerate() {
        // model only what the scene requires: a light that no visible surface faces lights
        // nothing (the shading pass skips it per pixel), so it needs no shadow map
        if !points.iter().any(|(p, n)| p.is_finite() && n.dot(l.light.direction) > 0.0) {
            continue;
        }
        let light = ShadowLight::Distant { direction: l.light.direction };
        let m = mapper.render(gpu, &shadow_geometry, &light, Technique::Orthographic, &settings).map_err(e)?;
        shadow_ms += m.time.as_secs_f64() * 1e3;
        mapper.visibility(gpu, &m, &gb, &vis.layer(k as u32)).map_err(e)?;
    }
    let pass = &passes.shading;
    let background = Background::upload(gpu, map).map_err(e)?;
    let params = ShadeParams { lights: &lights, ambient: Some(&d.ambient_sh), background: Some(&background) };
    let image = pass.render(gpu, &geometry, &gb, &params, &vis).map_err(e)?;
    let seconds = start.elapsed().as_secs_f64();
    let lit = Visibility::new(gpu, w, h, lights.len() as u32).map_err(e)?;
    let unshadowed = pass.render(gpu, &geometry, &gb, &params, &lit).map_err(e)?;
    Ok((image, unshadowed, seconds, shadow_ms))
}

type MaskImages = (Vec<f32>, Vec<f32>, Vec<Option<bool>>, (u32, u32));

fn room_masks(
    gpu: &Gpu,
    passes: &Passes,
    plan: &Plan,
) -> Result<(Vec<MaskRow>, MaskImages, Vec<SizeRow>, gpu::Clock), String> {
    let e = |e: gpu::GpuError| e.to_string();
    let mut scene = scene::Scene::builtin("room").map_err(|e| e.to_string())?;
    (scene.camera.width, scene.camera.height) = plan.room_size;
    let geometry = SceneGeometry::upload(gpu, &scene).map_err(e)?;
    let gb = passes.gbuffer.render(gpu, &geometry, &scene.camera).map_err(e)?;
    let points = gb.read_points(gpu).map_err(e)?;
    let position = scene.point_lights[0].position;
    let truth = light_visibility(&SceneBvh::new(&scene), &points, VisibilityLight::Point(position));
    let tris = gpu::scene_triangles(&scene);
    let light = ShadowLight::omni(position);
    let mapper = &passes.shadows;
    let (w, h) = plan.room_size;
    let vis = Visibility::new(gpu, w, h, 1).map_err(e)?;
    let mut rows = Vec::new();
    let (mut paraboloid_mask, mut cube_mask) = (Vec::new(), Vec::new());
    let mut clock = gpu::Clock::WallTime;
    for v in equal_texel_variants() {
        let (technique, settings) = (v.technique, v.settings);
        let t = shadow_triangles(&tris, &light, technique, &settings);
        let g = ShadowGeometry::upload(gpu, &t, ShadowGeometry::CHUNK_TRIANGLES).map_err(e)?;
        let mut times = Vec::new();
        let mut last = None;
        for _ in 0..plan.repeats.max(1) {
            let m = mapper.render(gpu, &g, &light, technique, &settings).map_err(e)?;
            times.push(m.time.as_secs_f64() * 1e3);
            clock = m.clock;
            last = Some(m);
        }
        times.sort_by(f64::total_cmp);
        let m = last.ok_or("no shadow map")?;
        mapper.visibility(gpu, &m, &gb, &vis.layer(0)).map_err(e)?;
        let mask = vis.read(gpu, 0).map_err(e)?;
        let (frac, _) = disagreement(&mask, &truth);
        if v.name == "paraboloid_1024_clip_subdivided" {
            paraboloid_mask = mask;
        } else if v.name == "cube_592" {
            cube_mask = mask;
        }
        rows.push(MaskRow {
            name: v.name,
            technique,
            texels: u64::from(settings.resolution) * u64::from(settings.resolution) * m.views.len() as u64,
            disagreement: frac,
            gpu_ms: times[times.len() / 2],
            triangles: m.triangles_drawn(),
        });
    }
    // the paper's caveat: error against the angle triangles span from the light
    let mut sizes = Vec::new();
    for angle in [None, Some(0.8), Some(0.4), Some(0.2), Some(0.1), Some(0.05)] {
        let settings = ShadowSettings { subdivide_angle: angle, ..ShadowSettings::default() };
        let t = shadow_triangles(&tris, &light, Technique::DualParaboloid, &settings);
        let widest = shadowmap_paraboloid::subdivide::max_edge_angle(&t, position);
        let g = ShadowGeometry::upload(gpu, &t, ShadowGeometry::CHUNK_TRIANGLES).map_err(e)?;
        let m = mapper.render(gpu, &g, &light, Technique::DualParaboloid, &settings).map_err(e)?;
        mapper.visibility(gpu, &m, &gb, &vis.layer(0)).map_err(e)?;
        let (frac, _) = disagreement(&vis.read(gpu, 0).map_err(e)?, &truth);
        sizes.push(SizeRow { widest, triangles: t.len(), disagreement: frac });
    }
    Ok((rows, (paraboloid_mask, cube_mask, truth, plan.room_size), sizes, clock))
}

/// One row of the error-against-triangle-size sweep.
struct SizeRow {
    widest: f32,
    triangles: usize,
    disagreement: f64,
}
