//! Measuring an environment-lit setting: its frame on the GPU (time) against the `env-direct`
//! truth (error). Techniques come through `gpu::ShadowTechnique` and extraction through
//! `light_extract::extractor`; nothing here knows one technique from another beyond building it
//! from its [`Shadow`] value.

use crate::TradeError;
use crate::front::Measurement;
use crate::setting::{EnvSetting, Setting, Shadow};
use envmap_sphere::EnvMap;
use glam::Vec3;
use gpu::{
    Background, FrameLights, FrameShadows, GBufferPass, Gpu, JointBilateral, Keyed, LightShape, LitFrame, LitSettings,
    PrefilterSettings, RotatedGrid, SceneGeometry, ShadeLight, ShadowPassReport, ShadowTechnique, SpecularAmbient,
    SplitSettings,
};
use light_extract::Decomposition;
use ref_tracer::metrics::{FlipTonemap, flip, rmse};
use ref_tracer::{EnvLight, Integrator, RenderSettings, SceneBvh, Strategy};
use std::cell::RefCell;
use std::collections::HashMap;
use std::rc::Rc;
use std::time::Instant;

/// How a run measures.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Plan {
    /// Output image size.
    pub size: (u32, u32),
    /// Samples per pixel of the truth.
    pub truth_spp: u32,
    /// Frames timed per setting (the median is kept).
    pub repeats: u32,
    /// GPU frames on a rotated grid of k² + 1 samples per pixel (`gpu::RotatedGrid`), as
    /// `validate`'s: the ground's far edge aliases otherwise and its error hides the shadows'.
    pub supersample: u32,
    /// Samples per pixel of a composite's photograph and truth (path traced).
    pub photo_spp: u32,
}

impl Plan {
    /// `--quick`: 160 x 120, 64 spp (composites: 8), one frame timed after an untimed one (its
    /// times are for CI, not for reading).
    pub const QUICK: Plan = Plan { size: (160, 120), truth_spp: 64, repeats: 1, supersample: 2, photo_spp: 8 };
    /// The default run: 160 x 120 (lavapipe on 2 cores; pass a size for real GPUs), 128 spp
    /// (composites: 16), one frame timed after an untimed one (about 15 minutes on 2 cores;
    /// `--repeats` for medians).
    pub const DEFAULT: Plan = Plan { size: (160, 120), truth_spp: 128, repeats: 1, supersample: 2, photo_spp: 16 };
}

/// One scene under one map, with its truth.
pub struct Case {
    /// The scene at the plan's size.
    pub scene: scene::Scene,
    /// Map name for the tables.
    pub map_name: String,
    /// The map.
    pub map: EnvMap,
    truth: Vec<Vec3>,
    truth_noise: f64,
    tonemap: FlipTonemap,
}

impl Case {
    /// Renders the truth of `scene_name` under `map` twice with independent seeds: the first
    /// is the truth, their difference its noise.
    ///
    /// # Errors
    /// An unknown scene.
    pub fn new(scene_name: &str, map_name: &str, map: EnvMap, plan: &Plan) -> Result<Self, TradeError> {
        let scene = scene::Scene::builtin(scene_name).map_err(|e| TradeError::Scene(e.to_string()))?;
        Ok(Self::with_scene(scene, map_name, map, plan))
    }

    /// As [`Case::new`] for any scene (a model, say), its camera set to the plan's size.
    #[must_use]
    pub fn with_scene(mut scene: scene::Scene, map_name: &str, map: EnvMap, plan: &Plan) -> Self {
        (scene.camera.width, scene.camera.height) = plan.size;
        let bvh = SceneBvh::new(&scene);
        let env = EnvLight::new(&map);
        let render = |seed| {
            let settings = RenderSettings { spp: plan.truth_spp, seed, aovs: false, ..RenderSettings::default() };
            ref_tracer::render(&scene, &bvh, Some(&env), &Integrator::EnvDirect(Strategy::Mis), &settings, &|_, _| {})
                .color
        };
        let (truth, second) = (render(1), render(2));
        let truth_noise = rmse(&truth, &second) / std::f64::consts::SQRT_2;
        let tonemap = FlipTonemap::for_reference(&truth);
        Self { scene, map_name: map_name.into(), map, truth, truth_noise, tonemap }
    }

    /// The truth image.
    #[must_use]
    pub fn truth(&self) -> &[Vec3] {
        &self.truth
    }
}

/// GPU passes built once and shared by every setting: the truths' G-buffer pass and the
/// recorded frame of the last size asked for.
pub struct Passes {
    pub(crate) gbuffer: GBufferPass,
    lit: RefCell<Keyed<(u32, u32), Rc<LitFrame>>>,
}

impl Passes {
    /// Builds the passes.
    ///
    /// # Errors
    /// GPU failures.
    pub fn new(gpu: &Gpu) -> Result<Self, TradeError> {
        Ok(Self { gbuffer: GBufferPass::new(gpu), lit: RefCell::default() })
    }

    /// The recorded frame for frames of `size` pixels, made when the size differs from the
    /// last one's.
    pub(crate) fn lit_frame(&self, gpu: &Gpu, size: (u32, u32)) -> Result<Rc<LitFrame>, TradeError> {
        Ok(self.lit.borrow_mut().try_get(size, || LitFrame::new(gpu, size).map(Rc::new))?.clone())
    }
}

/// The technique of `shadow` for `scene`, `None` for [`Shadow::None`], from the one builder
/// ([`crate::TechniqueBuilder`]).
///
/// # Errors
/// GPU failures.
pub fn technique(
    gpu: &Gpu,
    scene: &scene::Scene,
    shadow: &Shadow,
) -> Result<Option<Box<dyn ShadowTechnique>>, TradeError> {
    Ok(match shadow.spec() {
        Some(spec) => Some(crate::TechniqueBuilder::new(gpu, scene).build(&spec)?),
        None => None,
    })
}

/// A decomposition and its CPU time, per (method, K).
type Extractions = HashMap<(String, usize), (Decomposition, f64)>;

fn extract(cache: &mut Extractions, map: &EnvMap, method: &str, k: usize) -> Result<(Decomposition, f64), TradeError> {
    if let Some(d) = cache.get(&(method.to_string(), k)) {
        return Ok(d.clone());
    }
    let extractor = light_extract::extractor(method, k).ok_or_else(|| TradeError::Method(method.to_string()))?;
    let t = Instant::now();
    let mut d = extractor.extract(map).map_err(|e| TradeError::Method(format!("{method}: {e}")))?;
    let ms = t.elapsed().as_secs_f64() * 1e3;
    d.sort_directs_first();
    cache.insert((method.to_string(), k), (d.clone(), ms));
    Ok((d, ms))
}

/// What a frame needs that does not depend on the setting's shadows.
struct FrameInput<'a> {
    lit: &'a LitFrame,
    geometry: &'a SceneGeometry,
    camera: &'a scene::Camera,
    decomposition: &'a Decomposition,
    background: &'a Background,
    specular: Option<&'a SpecularAmbient>,
    /// The rotated grid's k: the split's scale is in output pixels, as `validate`'s.
    supersample: u32,
}

/// One frame, the toolkit's recorded frame ([`gpu::LitFrame`]) waited for and its lights timed
/// between timestamps of their own: the image left on the GPU (the frame's target, overwritten
/// by the next) and the shadow reports. Without a technique every light is shaded unshadowed at
/// full resolution; with one and an EnvIndirect scale above 1, paper 001's split.
fn frame(
    gpu: &Gpu,
    input: &FrameInput,
    setting: &EnvSetting,
    technique: Option<&dyn ShadowTechnique>,
) -> Result<(wgpu::Texture, Vec<ShadowPassReport>), TradeError> {
    let d = input.decomposition;
    let lights: Vec<ShadeLight> = d.lights.iter().map(|l| ShadeLight::from(&l.light)).collect();
    let shapes: Vec<LightShape> = d.lights.iter().map(|l| LightShape::from(&l.light)).collect();
    let directs = if technique.is_some() && setting.indirect_scale > 1 { d.directs() } else { lights.len() };
    let view = GBufferPass::camera_view(input.geometry, input.camera);
    let rendered = input.lit.render(
        gpu,
        input.geometry,
        &view,
        &FrameLights {
            lights: &lights,
            shapes: &shapes,
            directs,
            ambient: Some(&d.ambient_sh),
            specular_ambient: input.specular,
            background: Some(input.background),
        },
        technique.map(|t| FrameShadows { direct: t, indirect: t }),
        &LitSettings {
            split: SplitSettings {
                indirect_scale: setting.indirect_scale * input.supersample,
                upsample: JointBilateral::PAPER,
            },
            weber: setting.weber,
            time_lights: true,
        },
    )?;
    finished(gpu, rendered, technique)
}

/// A recorded frame waited for, its image and its reports completed with what the GPU knew.
pub(crate) fn finished(
    gpu: &Gpu,
    mut rendered: gpu::RenderedFrame,
    technique: Option<&dyn ShadowTechnique>,
) -> Result<(wgpu::Texture, Vec<ShadowPassReport>), TradeError> {
    gpu.wait(None)?;
    if let Some(t) = technique {
        // what only the GPU knew (its wedges' counts), in record order, before the lights the
        // GPU skipped are marked
        t.read_counts(gpu, &mut rendered.reports)?;
    }
    Ok(rendered.finish_reports(gpu)?)
}

/// Measures every environment-lit setting of `settings` on `case` (the other families are
/// left to their own cases): `plan.repeats` frames timed (median; under 3 repeats an untimed
/// warm-up frame first), the last one read back and compared with the truth. `progress` is
/// told each measurement as it is made.
///
/// # Errors
/// An unknown method; a technique that cannot shadow distant lights; GPU failures.
pub fn measure(
    gpu: &Gpu,
    case: &Case,
    settings: &[Setting],
    plan: &Plan,
    progress: &mut dyn FnMut(&Measurement),
) -> Result<Vec<Measurement>, TradeError> {
    let grid = RotatedGrid::new(&case.scene.camera, plan.supersample.max(1));
    let mut scene = case.scene.clone();
    scene.camera = *grid.camera();
    let geometry = SceneGeometry::upload(gpu, &scene)?;
    let background = Background::upload(gpu, &case.map)?;
    // the recorded frame at the grid's size, its targets made once for every setting
    let lit = LitFrame::new(gpu, (scene.camera.width, scene.camera.height))?;
    let glossy = scene.objects.iter().any(|o| o.material.specular.is_some());
    let (w, h) = (case.scene.camera.width, case.scene.camera.height);
    let mut cache = Extractions::new();
    let mut specular_cache: HashMap<(String, usize), Option<SpecularAmbient>> = HashMap::new();
    let mut out = Vec::new();
    for (knobs, setting) in settings.iter().filter_map(|s| s.as_env().map(|k| (s, k))) {
        if setting.shadow.for_point_lights() {
            return Err(TradeError::Render(format!("{}: point-light maps cannot shadow distant lights", knobs.name())));
        }
        let (d, extract_ms) = extract(&mut cache, &case.map, &setting.method, setting.lights)?;
        let key = (setting.method.clone(), setting.lights);
        if !specular_cache.contains_key(&key) {
            let s =
                if glossy { Some(SpecularAmbient::new(gpu, &d.ambient, &PrefilterSettings::default())?) } else { None };
            specular_cache.insert(key.clone(), s);
        }
        let specular = specular_cache.get(&key).and_then(Option::as_ref);
        let technique = technique(gpu, &scene, &setting.shadow)?;
        let input = FrameInput {
            lit: &lit,
            geometry: &geometry,
            camera: &scene.camera,
            decomposition: &d,
            background: &background,
            specular,
            supersample: plan.supersample.max(1),
        };
        let ((image, reports), ms) = timed(plan, || frame(gpu, &input, setting, technique.as_deref()))?;
        let image = grid.resolve(&gpu::read_hdr(gpu, &image)?);
        let shadows = Shadows::of(&reports);
        let m = Measurement {
            setting: knobs.name(),
            knobs: knobs.clone(),
            scene: case.scene.name.clone(),
            map: case.map_name.clone(),
            ms,
            clock: FRAME_CLOCK.into(),
            shadow_ms: shadows.ms,
            shadow_clock: shadows.clock,
            extract_ms,
            rmse: rmse(&case.truth, &image),
            flip: flip(&case.truth, &image, w, h, &case.tonemap),
            truth_noise: case.truth_noise,
            shadowed: shadows.shadowed,
            skipped: shadows.skipped,
            culled: shadows.culled,
            pareto: false,
        };
        progress(&m);
        out.push(m);
    }
    Ok(out)
}

/// What an env or point frame's `ms` measures.
pub(crate) const FRAME_CLOCK: &str = "wall time (the recorded frame: its submissions and one wait)";

/// `plan.repeats` frames of `frame` timed: the last frame and the median milliseconds.
/// Pipelines compile and buffers grow on the first frame: a median of 3 or more drops it,
/// fewer repeats get an untimed frame first.
pub(crate) fn timed<T>(plan: &Plan, mut frame: impl FnMut() -> Result<T, TradeError>) -> Result<(T, f64), TradeError> {
    let mut last = if plan.repeats < 3 { Some(frame()?) } else { None };
    let mut times = Vec::new();
    for _ in 0..plan.repeats.max(1) {
        let t = Instant::now();
        last = Some(frame()?);
        times.push(t.elapsed());
    }
    times.sort();
    let ms = times.get(times.len() / 2).map_or(f64::NAN, |t| t.as_secs_f64() * 1e3);
    Ok((last.ok_or_else(|| TradeError::Render("no frame".into()))?, ms))
}

/// A frame's shadow reports as a measurement states them.
pub(crate) struct Shadows {
    pub(crate) ms: f64,
    pub(crate) clock: String,
    pub(crate) shadowed: usize,
    pub(crate) skipped: Vec<(String, usize)>,
    pub(crate) culled: Vec<(String, u64)>,
}

impl Shadows {
    pub(crate) fn of(reports: &[ShadowPassReport]) -> Self {
        let (time, shadowed, _, _) = gpu::totals(reports);
        Self {
            ms: time.as_secs_f64() * 1e3,
            clock: reports.iter().find_map(|r| r.clock).map_or("none (no shadow pass)", gpu::Clock::name).into(),
            shadowed,
            skipped: gpu::skip_reasons(reports),
            culled: gpu::culled_totals(reports).into_iter().map(|(w, n)| (w.to_string(), n)).collect(),
        }
    }
}
