//! `cargo xtask validate`: the main job. On the embedded default map and `spheres_box` (or the
//! given ones): decompose the map with EmissiveSplit, render the lights on the GPU with
//! orthographic shadow maps (and without shadows), render the `ref-tracer` references, measure
//! the `room` point light's paraboloid and cube shadow maps against ray-traced visibility and
//! time them, write `target/validate/report.html` (self-contained), and fail when an error
//! exceeds its threshold in `validate/thresholds.json`.

use crate::render::load_map;
use envmap_sphere::{EnvMap, Tonemap};
use glam::Vec3;
use gpu::{
    Background, GBufferPass, Gpu, SceneGeometry, ShadeLight, ShadeParams, ShadingPass, ShadowGeometry, Visibility,
};
use light_extract::{EmissiveSplit, LightExtractor};
use ref_tracer::metrics::{FlipTonemap, flip, rmse};
use ref_tracer::visibility::{VisibilityLight, light_visibility};
use ref_tracer::{EnvLight, Integrator, LightSet, RenderSettings, SceneBvh, Strategy};
use shadowmap_paraboloid::{
    ShadowLight, ShadowMapper, ShadowSettings, Technique, disagreement, equal_texel_variants, shadow_triangles,
};
use std::collections::BTreeMap;
use std::fmt::Write as _;
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

    stages.next("GPU: G-buffer, orthographic shadow maps, shading (lavapipe)");
    crate::lavapipe::ensure()?;
    let gpu = Gpu::new().map_err(|e| e.to_string())?;
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
    let thresholds = load_thresholds()?;
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

fn load_thresholds() -> Result<BTreeMap<String, f64>, String> {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("../validate/thresholds.json");
    let text = std::fs::read_to_string(&path).map_err(|e| format!("{}: {e}", path.display()))?;
    let value: serde_json::Value = serde_json::from_str(&text).map_err(|e| format!("{}: {e}", path.display()))?;
    let mut out = BTreeMap::new();
    if let Some(obj) = value.get("thresholds").and_then(|v| v.as_object()) {
        for (k, v) in obj {
            let t = v.as_f64().ok_or_else(|| format!("{}: threshold {k} is not a number", path.display()))?;
            out.insert(k.clone(), t);
        }
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

struct Report<'a> {
    gpu: &'a Gpu,
    plan: &'a Plan,
    map_name: &'a str,
    scene: &'a str,
    rows: &'a [Row],
    masks: &'a [MaskRow],
    mask_images: &'a MaskImages,
    sizes: &'a [SizeRow],
    clock: gpu::Clock,
    tm: &'a FlipTonemap,
    size: (u32, u32),
    failures: &'a [String],
    checked: usize,
    lights: usize,
    extract_ms: f64,
}

/// Relative luminance error as an 8-bit heat map (black 0, red 25 %, yellow 50 %, white ≥ 75 %).
fn error_map(reference: &[Vec3], test: &[Vec3]) -> Vec<u8> {
    let y = envmap_sphere::luminance;
    let mean = reference.iter().map(|c| y(*c)).sum::<f32>() / reference.len().max(1) as f32;
    reference
        .iter()
        .zip(test)
        .flat_map(|(r, t)| {
            let e = (y(*t) - y(*r)).abs() / (y(*r) + 0.05 * mean).max(1e-12);
            let c = |x: f32| (x.clamp(0.0, 1.0) * 255.0) as u8;
            [c(e * 4.0), c(e * 4.0 - 1.0), c(e * 4.0 - 2.0)]
        })
        .collect()
}

fn mask_bytes(mask: &[f32]) -> Vec<u8> {
    mask.iter().flat_map(|m| [(m.clamp(0.0, 1.0) * 255.0) as u8; 3]).collect()
}

fn truth_diff_bytes(mask: &[f32], truth: &[Option<bool>]) -> Vec<u8> {
    mask.iter()
        .zip(truth)
        .flat_map(|(m, t)| match t {
            None => [40, 40, 60],
            Some(t) if (*m > 0.5) == *t => {
                if *t {
                    [200, 200, 200]
                } else {
                    [30, 30, 30]
                }
            }
            Some(true) => [230, 40, 40],
            Some(false) => [40, 120, 255],
        })
        .collect()
}

impl Report<'_> {
    /// Writes `name.png` into `dir` and returns an `<img>` embedding the same bytes.
    fn png(&self, dir: &Path, name: &str, (w, h): (u32, u32), bytes: &[u8]) -> Result<String, String> {
        let png = envmap_sphere::io::encode_png_srgb8(w, h, bytes).map_err(|e| format!("{name}.png: {e}"))?;
        let path = dir.join(format!("{name}.png"));
        std::fs::write(&path, &png).map_err(|e| format!("{}: {e}", path.display()))?;
        Ok(format!("<img alt=\"{name}\" src=\"data:image/png;base64,{}\">", base64(&png)))
    }

    fn html(&self, dir: &Path) -> Result<String, String> {
        let mut s = String::new();
        let tonemap: Tonemap = self.tm.tonemap;
        let _ = write!(
            s,
            "<!doctype html><html><head><meta charset=\"utf-8\"><title>envshadow validate</title><style>\
             body{{font-family:sans-serif;margin:2em;max-width:1400px}} table{{border-collapse:collapse}} \
             td,th{{border:1px solid #bbb;padding:4px 8px;text-align:right}} th{{background:#eee}} \
             td:first-child,th:first-child{{text-align:left}} img{{max-width:100%}} .fail{{color:#b00;font-weight:bold}} \
             .grid{{display:grid;grid-template-columns:repeat(3,1fr);gap:8px}} figure{{margin:0}}</style></head><body>"
        );
        let _ = write!(
            s,
            "<h1>envshadow validate</h1><p>Map <b>{}</b>, scene <b>{}</b>. {}.</p>",
            self.map_name,
            self.scene,
            self.plan.describe()
        );
        let _ = write!(
            s,
            "<p>GPU adapter: <b>{}</b>. Timings of shadow maps: {}.</p>",
            html_escape(&self.gpu.describe()),
            self.clock.name()
        );
        let _ = write!(
            s,
            "<p>EmissiveSplit found {} lights in {:.1} ms. {}</p>",
            self.lights,
            self.extract_ms,
            html_escape(&self.tm.describe())
        );
        if self.failures.is_empty() {
            let _ = write!(s, "<p>Thresholds (validate/thresholds.json): {} checked, all met.</p>", self.checked);
        } else {
            let _ = write!(
                s,
                "<p class=\"fail\">Thresholds exceeded:<br>{}</p>",
                self.failures.iter().map(|f| html_escape(f)).collect::<Vec<_>>().join("<br>")
            );
        }
        let _ = write!(
            s,
            "<h2>Environment lighting: techniques against the reference</h2><table><tr><th>technique</th><th>what</th><th>RMSE</th><th>FLIP</th><th>RMSE vs ray-traced lights</th><th>time (s)</th></tr>"
        );
        let fmt = |v: Option<f64>| v.map_or_else(|| "—".to_string(), |v| format!("{v:.4}"));
        for r in self.rows {
            let _ = write!(
                s,
                "<tr><td>{}</td><td>{}</td><td>{}</td><td>{}</td><td>{}</td><td>{}</td></tr>",
                r.name,
                html_escape(&r.what),
                fmt(r.rmse),
                fmt(r.flip),
                fmt(r.rmse_vs_lights),
                if r.seconds > 0.0 { format!("{:.2}", r.seconds) } else { "—".into() }
            );
        }
        s.push_str("</table><p>Images (same tone mapping as FLIP) and relative luminance error against the reference (black 0, red 25 %, yellow 50 %, white ≥ 75 %).</p><div class=\"grid\">");
        let reference = &self.rows[0].image;
        for r in self.rows {
            let bytes: Vec<u8> = r.image.iter().flat_map(|p| tonemap.apply(*p)).collect();
            let img = self.png(dir, &r.name, self.size, &bytes)?;
            let err = if r.rmse.is_some() {
                self.png(dir, &format!("{}_error", r.name), self.size, &error_map(reference, &r.image))?
            } else {
                String::new()
            };
            let _ = write!(
                s,
                "<figure>{img}<figcaption>{}</figcaption></figure><figure>{err}</figure><figure></figure>",
                r.name
            );
        }
        s.push_str("</div>");
        let _ = write!(
            s,
            "<h2>Point light in <code>room</code>: shadow maps against ray-traced visibility</h2><p>The fraction of visible pixels whose shadow-map test (1-texel bias, no PCF) disagrees with a ray traced from the same G-buffer point to the light; generation time of all passes of the map. Pairs of rows have equal texel counts (2 p² = 6 c²).</p><table><tr><th>map</th><th>texels</th><th>triangles drawn</th><th>pixels that disagree</th><th>generation (ms)</th><th>time / cube</th></tr>"
        );
        for m in self.masks {
            let cube = self
                .masks
                .iter()
                .find(|c| c.technique == Technique::Cube && c.texels.abs_diff(m.texels) * 50 < m.texels);
            let ratio = cube.map_or_else(|| "—".to_string(), |c| format!("{:.2}×", m.gpu_ms / c.gpu_ms));
            let _ = write!(
                s,
                "<tr><td>{}</td><td>{}</td><td>{}</td><td>{:.3} %</td><td>{:.2}</td><td>{ratio}</td></tr>",
                m.name,
                m.texels,
                m.triangles,
                m.disagreement * 100.0,
                m.gpu_ms
            );
        }
        s.push_str("</table><h3>Error against triangle size</h3><p>Dual paraboloid 1024², clip distances: triangles bisected until no edge spans more than the angle from the light (the paper's caveat: rasterization interpolates the non-linear mapping linearly).</p><table><tr><th>widest edge from the light</th><th>triangles</th><th>pixels that disagree</th></tr>");
        for r in self.sizes {
            let _ = write!(
                s,
                "<tr><td>{:.3} rad</td><td>{}</td><td>{:.3} %</td></tr>",
                r.widest,
                r.triangles,
                r.disagreement * 100.0
            );
        }
        s.push_str("</table><p>Masks: dual paraboloid 1024² (clip distances, subdivided), cube 592², and where each disagrees with the ray-traced truth (red: lit but should be shadowed, blue: shadowed but lit).</p><div class=\"grid\">");
        let (para, cube, truth, size) = self.mask_images;
        for (name, bytes) in [
            ("room_paraboloid_1024", mask_bytes(para)),
            ("room_cube_592", mask_bytes(cube)),
            ("room_paraboloid_1024_vs_ray_traced", truth_diff_bytes(para, truth)),
        ] {
            let img = self.png(dir, name, *size, &bytes)?;
            let _ = write!(s, "<figure>{img}<figcaption>{name}</figcaption></figure>");
        }
        s.push_str("</div></body></html>\n");
        Ok(s)
    }
}

fn html_escape(s: &str) -> String {
    s.replace('&', "&amp;").replace('<', "&lt;").replace('>', "&gt;")
}

/// Standard base64 with padding (RFC 4648), for images embedded in the report.
fn base64(data: &[u8]) -> String {
    const ALPHABET: &[u8; 64] = b"ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
    let mut out = String::with_capacity(data.len().div_ceil(3) * 4);
    for chunk in data.chunks(3) {
        let b = [chunk[0], *chunk.get(1).unwrap_or(&0), *chunk.get(2).unwrap_or(&0)];
        let n = (u32::from(b[0]) << 16) | (u32::from(b[1]) << 8) | u32::from(b[2]);
        for k in 0..4 {
            if k <= chunk.len() {
                out.push(ALPHABET[((n >> (18 - 6 * k)) & 63) as usize] as char);
            } else {
                out.push('=');
            }
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::base64;

    #[test]
    fn base64_matches_rfc_4648_vectors() {
        for (input, want) in [("", ""), ("f", "Zg=="), ("fo", "Zm8="), ("foo", "Zm9v"), ("foobar", "Zm9vYmFy")] {
            assert_eq!(base64(input.as_bytes()), want);
        }
    }
}
