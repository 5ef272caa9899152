//! Measuring a composite setting (paper 003): a sphere composited into a built-in real scene's
//! photograph on the GPU, against the real scene path traced with the sphere. Errors are in
//! 8-bit codes over the pixels the sphere changed in the truth (the paper's and `validate`'s
//! measure); FLIP on the 8-bit images.

use crate::TradeError;
use crate::capture::PhotoSettings;
use crate::front::Measurement;
use crate::measure::Plan;
use crate::session::{Session, SessionSettings};
use crate::setting::{PatchMaps, Setting};
use differential_composite::gpu::{GpuCompositor, GpuSettings};
use differential_composite::{Mode, SyntheticObject, code_error};
use glam::Vec3;
use gpu::Gpu;
use real_scene::RealScene;
use ref_tracer::metrics::flip_rgb8;

/// Where the sphere sits, from the scene's floor centre: `ar_ground`'s in front of the boxes
/// (`validate`'s), elsewhere 0.5 m forward (`envshadow composite`'s default).
#[must_use]
pub fn object_position(scene: &str) -> Vec3 {
    if scene == "ar_ground" { Vec3::new(0.0, 0.3, 1.0) } else { Vec3::new(0.0, 0.3, 0.5) }
}

/// A real scene with the sphere, its truth and the GPU compositor.
pub struct CompositeCase {
    /// The real scene's name.
    pub scene: String,
    /// The environment map's name, `-` for a scene lit by its own patches.
    pub map: String,
    session: Session,
    object: SyntheticObject,
    truth: Vec<[u8; 3]>,
    truth_noise: f64,
    compositor: GpuCompositor,
}

impl CompositeCase {
    /// Captures `scene_name` at the plan's size (photograph path traced at `plan.photo_spp`),
    /// reconstructs it exactly and builds its shaft hierarchy; renders the truth twice with
    /// independent seeds (the second for its noise). An environment-lit scene takes the
    /// embedded map's lights extracted by `method` (K = 32).
    ///
    /// # Errors
    /// An unknown real scene; a failing extraction; GPU failures.
    pub fn new(gpu: &Gpu, scene_name: &str, method: &str, plan: &Plan) -> Result<Self, TradeError> {
        let e = |e: differential_composite::CompositeError| TradeError::Scene(format!("{scene_name}: {e}"));
        let real = RealScene::builtin(scene_name).map_err(|e| TradeError::Scene(e.to_string()))?;
        let (map, lights) = crate::session::environment(&real, method, 32).map_err(e)?;
        let map_name = if map.is_some() { envmap_sphere::DEFAULT_MAP_NAME.to_string() } else { "-".to_string() };
        let photo = PhotoSettings { spp: plan.photo_spp.max(1), ..SessionSettings::default().photo };
        let settings = SessionSettings { size: Some(plan.size), photo, ..SessionSettings::default() };
        let session = Session::new(scene_name, map, lights, &settings).map_err(e)?;
        let object = session.object("sphere", object_position(scene_name)).map_err(e)?;
        let truth = session.truth(&object).map_err(e)?;
        let second = session.truth_with(&object, &PhotoSettings { seed: photo.seed + 7919, ..photo }).map_err(e)?;
        let truth_noise =
            code_error(&second, &truth, &session.compositor.photo_ldr).rmse_changed / std::f64::consts::SQRT_2;
        let compositor = GpuCompositor::new(gpu, &session.compositor)?;
        Ok(Self { scene: scene_name.into(), map: map_name, session, object, truth, truth_noise, compositor })
    }

    /// The truth, 8-bit.
    #[must_use]
    pub fn truth(&self) -> &[[u8; 3]] {
        &self.truth
    }
}

/// Measures every composite setting of `settings` on `case`: `plan.repeats` frames (the median
/// by total time; under 3 repeats an untimed frame first), each frame its traversal, maps,
/// masks and resolve.
///
/// # Errors
/// GPU failures.
pub fn measure_composite(
    gpu: &Gpu,
    case: &CompositeCase,
    settings: &[Setting],
    plan: &Plan,
    progress: &mut dyn FnMut(&Measurement),
) -> Result<Vec<Measurement>, TradeError> {
    let c = &case.session.compositor;
    let (w, h) = plan.size;
    let sources = c.prepared.sources.len();
    let mut out = Vec::new();
    for (knobs, setting) in settings.iter().filter_map(|s| s.as_composite().map(|k| (s, k))) {
        let gpu_settings = GpuSettings {
            map_resolution: setting.map_resolution,
            patch_maps: match setting.patch_maps {
                PatchMaps::Paraboloid => shadowmap_paraboloid::Technique::DualParaboloid,
                PatchMaps::Cube => shadowmap_paraboloid::Technique::Cube,
            },
            ..GpuSettings::default()
        };
        let mode = if setting.ldr { Mode::Ldr } else { Mode::Hdr };
        if plan.repeats < 3 {
            let frame = c.frame(&case.object, setting.passes);
            crate::composite_rows::composite(gpu, &case.compositor, (c, &frame, &case.object), mode, &gpu_settings)?;
        }
        let row = crate::composite_rows::rows(
            gpu,
            &case.compositor,
            &case.session.compositor,
            &case.object,
            &case.truth,
            &[setting.passes],
            &[mode],
            &gpu_settings,
            plan.repeats.max(1) as usize,
        )?
        .pop()
        .ok_or_else(|| TradeError::Render("no composite".into()))?;
        let t = row.times_ms();
        let mut skipped = Vec::new();
        if sources > row.occluded_sources {
            skipped.push((
                "the shaft hierarchy excluded it (the object occludes none of its light, or under the pruning fraction)"
                    .to_string(),
                sources - row.occluded_sources,
            ));
        }
        if row.occluded_sources > row.reps {
            skipped.push(("merged into a representative's pass".to_string(), row.occluded_sources - row.reps));
        }
        let mut culled = Vec::new();
        if row.work.hemispheres_skipped > 0 {
            culled.push((
                "paraboloid hemispheres not rendered (hemispherical sources)".to_string(),
                u64::from(row.work.hemispheres_skipped),
            ));
        }
        let m = Measurement {
            setting: knobs.name(),
            knobs: knobs.clone(),
            scene: case.scene.clone(),
            map: case.map.clone(),
            ms: t[0],
            clock: "wall time (frame: CPU traversal and transfers, GPU work waited for, the 8-bit image read back)"
                .into(),
            shadow_ms: t[3] + t[4],
            shadow_clock: "wall time (maps and masks, waited for)".into(),
            extract_ms: 0.0,
            rmse: row.error.rmse_changed,
            flip: flip_rgb8(&case.truth, &row.image, w, h),
            truth_noise: case.truth_noise,
            shadowed: row.reps,
            skipped,
            culled,
            pareto: false,
        };
        progress(&m);
        out.push(m);
    }
    Ok(out)
}
