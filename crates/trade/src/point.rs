//! Measuring a point-light setting: a scene's point lights shadowed by paraboloid or cube maps
//! (paper 004) on the GPU, against the same frame with ray-traced visibility. The truth shares
//! the frame's G-buffer and shading, so its error is the shadows' alone, and it has no noise: a
//! ray from every G-buffer point to every light (`ref_tracer::visibility`).

use crate::TradeError;
use crate::front::Measurement;
use crate::measure::{FRAME_CLOCK, Passes, Plan, Shadows, finished, technique, timed};
use crate::setting::Setting;
use glam::Vec3;
use gpu::{
    FrameLights, FrameShadows, GBufferPass, Gpu, LightShape, LitFrame, LitSettings, PrecomputedVisibility, RotatedGrid,
    SceneGeometry, ShadeLight, ShadowPassReport, ShadowTechnique,
};
use ref_tracer::SceneBvh;
use ref_tracer::metrics::{FlipTonemap, flip, rmse};
use ref_tracer::visibility::light_visibility;

/// A built-in scene with point lights, and its truth.
pub struct PointCase {
    /// The scene at the plan's size.
    pub scene: scene::Scene,
    grid: RotatedGrid,
    geometry: SceneGeometry,
    lit: LitFrame,
    lights: Vec<ShadeLight>,
    shapes: Vec<LightShape>,
    truth: Vec<Vec3>,
    tonemap: FlipTonemap,
}

impl PointCase {
    /// The frame of `scene_name`'s point lights with ray-traced visibility, on the plan's
    /// rotated grid.
    ///
    /// # Errors
    /// An unknown scene or one without point lights; GPU failures.
    pub fn new(gpu: &Gpu, passes: &Passes, scene_name: &str, plan: &Plan) -> Result<Self, TradeError> {
        let scene = scene::Scene::builtin(scene_name).map_err(|e| TradeError::Scene(e.to_string()))?;
        Self::with_scene(gpu, passes, scene, plan)
    }

    /// As [`PointCase::new`] for any scene with point lights (a model's `KHR_lights_punctual`
    /// ones, say), its camera set to the plan's size.
    ///
    /// # Errors
    /// A scene without point lights; GPU failures.
    pub fn with_scene(gpu: &Gpu, passes: &Passes, mut scene: scene::Scene, plan: &Plan) -> Result<Self, TradeError> {
        if scene.point_lights.is_empty() {
            return Err(TradeError::Scene(format!("{} has no point lights", scene.name)));
        }
        (scene.camera.width, scene.camera.height) = plan.size;
        let grid = RotatedGrid::new(&scene.camera, plan.supersample.max(1));
        let geometry = SceneGeometry::upload(gpu, &scene)?;
        let lights: Vec<ShadeLight> = scene.point_lights.iter().map(ShadeLight::from).collect();
        let shapes: Vec<LightShape> = scene.point_lights.iter().map(LightShape::from).collect();
        let camera = grid.camera();
        let lit = LitFrame::new(gpu, (camera.width, camera.height))?;
        let mut case = Self {
            scene,
            grid,
            geometry,
            lit,
            lights,
            shapes,
            truth: Vec::new(),
            tonemap: FlipTonemap::for_reference(&[]),
        };
        let gb = passes.gbuffer.render(gpu, &case.geometry, case.grid.camera())?;
        let points = gb.read_points(gpu)?;
        let bvh = SceneBvh::new(&case.scene);
        let layers = case
            .shapes
            .iter()
            .map(|shape| {
                let v = light_visibility(&bvh, &points, *shape);
                (*shape, v.into_iter().map(|v| if v == Some(false) { 0.0 } else { 1.0 }).collect())
            })
            .collect();
        let traced = PrecomputedVisibility::new(gpu, "ray_traced", gb.size(), layers)?;
        let (image, _) = case.frame(gpu, &traced)?;
        case.truth = case.grid.resolve(&gpu::read_hdr(gpu, &image)?);
        case.tonemap = FlipTonemap::for_reference(&case.truth);
        Ok(case)
    }

    /// The truth image.
    #[must_use]
    pub fn truth(&self) -> &[Vec3] {
        &self.truth
    }

    /// One frame, the toolkit's recorded frame ([`gpu::LitFrame`]) waited for and its lights
    /// timed, every light shadowed by `technique` at full resolution (no Weber skipping: the
    /// truth skips none).
    fn frame(
        &self,
        gpu: &Gpu,
        technique: &dyn ShadowTechnique,
    ) -> Result<(wgpu::Texture, Vec<ShadowPassReport>), TradeError> {
        let view = GBufferPass::camera_view(&self.geometry, self.grid.camera());
        let lights = FrameLights {
            lights: &self.lights,
            shapes: &self.shapes,
            directs: self.lights.len(),
            ambient: None,
            specular_ambient: None,
            background: None,
        };
        let shadows = FrameShadows { direct: technique, indirect: technique };
        let settings = LitSettings { weber: false, time_lights: true, ..LitSettings::default() };
        let rendered = self.lit.render(gpu, &self.geometry, &view, &lights, Some(shadows), &settings)?;
        finished(gpu, rendered, Some(technique))
    }
}

/// Measures every point-light setting of `settings` on `case` as [`crate::measure`] does the
/// environment-lit ones.
///
/// # Errors
/// A technique that cannot shadow point lights; GPU failures.
pub fn measure_point(
    gpu: &Gpu,
    case: &PointCase,
    settings: &[Setting],
    plan: &Plan,
    progress: &mut dyn FnMut(&Measurement),
) -> Result<Vec<Measurement>, TradeError> {
    let (w, h) = plan.size;
    let mut out = Vec::new();
    for (knobs, setting) in settings.iter().filter_map(|s| s.as_point().map(|k| (s, k))) {
        let technique = technique(gpu, &case.scene, &setting.shadow)?
            .filter(|_| setting.shadow.for_point_lights())
            .ok_or_else(|| TradeError::Render(format!("{}: not a point-light technique", knobs.name())))?;
        let ((image, reports), ms) = timed(plan, || case.frame(gpu, technique.as_ref()))?;
        let image = case.grid.resolve(&gpu::read_hdr(gpu, &image)?);
        let shadows = Shadows::of(&reports);
        let m = Measurement {
            setting: knobs.name(),
            knobs: knobs.clone(),
            scene: case.scene.name.clone(),
            map: "-".into(),
            ms,
            clock: FRAME_CLOCK.into(),
            shadow_ms: shadows.ms,
            shadow_clock: shadows.clock,
            extract_ms: 0.0,
            rmse: rmse(&case.truth, &image),
            flip: flip(&case.truth, &image, w, h, &case.tonemap),
            truth_noise: 0.0,
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
