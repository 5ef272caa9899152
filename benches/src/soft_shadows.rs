//! The soft-shadow trade: every shadow technique's visibility error against ray-traced
//! visibility of the whole light, and its GPU time per light, per scene and light size; and the
//! speed of each at the wedges' error. `cargo xtask soft-shadows` prints it; the criterion
//! bench `soft_shadows` times the techniques.
//!
//! A technique bench, not a frame: it measures one light's visibility layer, which no frame
//! shows alone, through `gpu::render_visibility` (`record_visibility`, the recording
//! `gpu::LitFrame` makes of every light, submitted once and timed); its receivers are the
//! G-buffer's points, which the ray-traced truth needs anyway.

use glam::Vec3;
use gpu::{
    GBufferPass, Gpu, GpuError, LightShape, Receivers, SceneGeometry, ShadowTechnique, VisibilityLayers,
    render_visibility,
};
use penumbra_wedge::{WedgePath, WedgeSettings};
use ref_tracer::SceneBvh;
use ref_tracer::visibility::{Weighting, area_light_visibility_refined};
use shadowmap_paraboloid::{Pcss, ShadowSettings};
use trade::{TechniqueBuilder, TechniqueSpec};

/// Paper 000's scenes and the validation scene.
pub const SCENES: [&str; 3] = ["three_boxes", "column", "spheres_box"];

/// Light half-angles, degrees, from a sun to a wide sky light.
pub const HALF_ANGLES: [f32; 5] = [0.25, 1.0, 4.0, 16.0, 45.0];

/// The light's direction in every case: 57 degrees up, from the front right.
#[must_use]
pub fn light(half_angle_degrees: f32) -> LightShape {
    LightShape::Distant {
        direction: Vec3::new(0.45, 1.0, 0.3).normalize(),
        half_angle: half_angle_degrees.to_radians(),
    }
}

/// A named technique with the knob it sweeps.
pub struct Entry {
    /// Family: `wedges`, `wedges_compute`, `pcss`, `shadow_maps_xN`, `shadow_maps`.
    pub family: &'static str,
    /// The technique.
    pub technique: Box<dyn ShadowTechnique>,
}

/// Every technique and setting of the sweep for `scene`: wedges (raster and tiled compute); one
/// hard 2048² map with 3 × 3 PCF; PCSS on 2048² maps with 8, 32 and 64 filter samples; the mean
/// of 4, 16 and 64 1024² maps.
///
/// # Errors
/// GPU failures.
pub fn entries(gpu: &Gpu, scene: &scene::Scene) -> Result<Vec<Entry>, GpuError> {
    let hard = ShadowSettings { resolution: 2048, pcf_radius: 1, ..ShadowSettings::default() };
    // the covered fraction, unweighted, as the truth here is (`Weighting::Uniform`): the
    // techniques are compared on the same measure
    let wedges = WedgeSettings { cosine_weighted: false, ..WedgeSettings::default() };
    let mut specs = vec![
        ("wedges", TechniqueSpec::Wedges(wedges)),
        ("wedges_compute", TechniqueSpec::Wedges(WedgeSettings { path: WedgePath::Compute, ..wedges })),
        ("shadow_maps", TechniqueSpec::orthographic(hard, 1)),
    ];
    for filter_samples in [8, 32, 64] {
        let pcss = Pcss { filter_samples, blocker_samples: filter_samples.min(16), ..Pcss::default() };
        specs
            .push(("pcss", TechniqueSpec::orthographic(ShadowSettings { pcf_radius: 0, pcss: Some(pcss), ..hard }, 1)));
    }
    for n in [4, 16, 64] {
        let settings = ShadowSettings { resolution: 1024, pcf_radius: 0, ..hard };
        specs.push(("shadow_maps_xN", TechniqueSpec::orthographic(settings, n)));
    }
    let built = TechniqueBuilder::new(gpu, scene).build_all(&specs)?;
    Ok(built.into_iter().map(|(family, technique)| Entry { family, technique }).collect())
}

/// One measurement.
#[derive(Clone, Debug, PartialEq)]
pub struct Row {
    /// Scene.
    pub scene: String,
    /// Light half-angle, degrees.
    pub degrees: f32,
    /// Technique family and name (with its setting).
    pub family: String,
    /// Technique name.
    pub technique: String,
    /// Mean |V − truth| × the light's weight ([`light_weights`]) over pixels in or near
    /// penumbrae.
    pub mean: f32,
    /// 95th percentile of the same.
    pub p95: f32,
    /// Pixels in or near penumbrae.
    pub pixels: usize,
    /// GPU time for the light, ms.
    pub ms: f64,
    /// The clock of `ms`.
    pub clock: String,
}

/// A frame of one scene: its G-buffer and points.
pub struct Frame {
    /// The scene at the frame's size.
    pub scene: scene::Scene,
    /// The G-buffer.
    pub gbuffer: gpu::GBuffer,
    /// Its points.
    pub points: Vec<(Vec3, Vec3)>,
}

impl Frame {
    /// Renders `name`'s G-buffer at `size`.
    ///
    /// # Errors
    /// Unknown scene, GPU failures.
    pub fn new(gpu: &Gpu, name: &str, size: (u32, u32)) -> Result<Self, String> {
        let mut scene = scene::Scene::builtin(name).map_err(|e| e.to_string())?;
        (scene.camera.width, scene.camera.height) = size;
        Self::with_scene(gpu, scene)
    }

    /// Renders `scene`'s G-buffer at its camera's size.
    ///
    /// # Errors
    /// GPU failures.
    pub fn with_scene(gpu: &Gpu, scene: scene::Scene) -> Result<Self, String> {
        let geometry = SceneGeometry::upload(gpu, &scene).map_err(|e| e.to_string())?;
        let gbuffer = GBufferPass::new(gpu).render(gpu, &geometry, &scene.camera).map_err(|e| e.to_string())?;
        let points = gbuffer.read_points(gpu).map_err(|e| e.to_string())?;
        Ok(Self { scene, gbuffer, points })
    }

    /// Ray-traced visibility of `light` per pixel: 6 × 6 stratified directions, refined to
    /// 32 × 32 where they disagree or a neighbour differs (noise below 1e-3 there).
    #[must_use]
    pub fn truth(&self, light: &LightShape) -> Vec<Option<f32>> {
        let bvh = SceneBvh::new(&self.scene);
        area_light_visibility_refined(
            &bvh,
            &self.points,
            *light,
            self.scene.camera.width as usize,
            (6, 32),
            Weighting::Uniform,
        )
    }

    /// `technique`'s visibility of `light` and its report.
    ///
    /// # Errors
    /// GPU failures.
    pub fn visibility(
        &self,
        gpu: &Gpu,
        technique: &dyn ShadowTechnique,
        light: &LightShape,
    ) -> Result<(Vec<f32>, gpu::ShadowPassReport), GpuError> {
        let (w, h) = self.gbuffer.size();
        let vis = VisibilityLayers::new(gpu, w, h, 1)?;
        let receivers = Receivers::new(&self.gbuffer, &self.points);
        let report = render_visibility(gpu, technique, &receivers, std::slice::from_ref(light), &[], &vis)?.remove(0);
        Ok((vis.read(gpu, 0)?, report))
    }
}

/// Per pixel, the light's unshadowed irradiance relative to a surface facing it (the cone's
/// cosine integral over π sin²α): what a visibility error there costs the image. 0 where the
/// light is below the surface or the pixel is background.
#[must_use]
pub fn light_weights(points: &[(Vec3, Vec3)], light: &LightShape) -> Vec<f32> {
    points
        .iter()
        .map(|&(p, n)| {
            if !p.is_finite() {
                return 0.0;
            }
            let half = light.half_angle_at(p).min(std::f32::consts::FRAC_PI_2);
            let full = std::f32::consts::PI * half.sin().powi(2);
            if full <= 0.0 {
                return f32::from(u8::from(n.dot(light.direction_from(p)) > 0.0));
            }
            scene::cone_cosine_integral(n.dot(light.direction_from(p)), half) / full
        })
        .collect()
}

/// (mean, 95th percentile, count) of |v − truth| × weight over pixels in or near penumbrae
/// (either value strictly between 0.01 and 0.99, grown by 2 pixels) whose weight is not 0: a
/// visibility error where the light gives little costs little.
#[must_use]
pub fn penumbra_error(v: &[f32], truth: &[Option<f32>], weights: &[f32], width: usize) -> (f32, f32, usize) {
    let soft = |x: f32| x > 0.01 && x < 0.99;
    let seed: Vec<bool> = v.iter().zip(truth).map(|(a, b)| b.is_some_and(|b| soft(*a) || soft(b))).collect();
    let h = v.len() / width.max(1);
    let mut errors = Vec::new();
    for k in 0..v.len() {
        let Some(t) = truth[k] else { continue };
        if weights[k] <= 1e-3 {
            continue;
        }
        let (x, y) = ((k % width) as i64, (k / width) as i64);
        let near = (-2..=2).any(|dy: i64| {
            (-2..=2).any(|dx: i64| {
                let (nx, ny) = (x + dx, y + dy);
                nx >= 0
                    && ny >= 0
                    && (nx as usize) < width
                    && (ny as usize) < h
                    && seed[ny as usize * width + nx as usize]
            })
        });
        if near {
            errors.push((v[k] - t).abs() * weights[k]);
        }
    }
    if errors.is_empty() {
        return (0.0, 0.0, 0);
    }
    let mean = errors.iter().sum::<f32>() / errors.len() as f32;
    errors.sort_by(f32::total_cmp);
    (mean, errors[(errors.len() * 95 / 100).min(errors.len() - 1)], errors.len())
}

/// Measures every entry on `frame` for each half-angle; `progress` hears each row.
///
/// # Errors
/// GPU failures.
pub fn measure(
    gpu: &Gpu,
    frame: &Frame,
    entries: &[Entry],
    half_angles: &[f32],
    progress: &mut dyn FnMut(&Row),
) -> Result<Vec<Row>, String> {
    let mut rows = Vec::new();
    let width = frame.scene.camera.width as usize;
    for &degrees in half_angles {
        let l = light(degrees);
        let truth = frame.truth(&l);
        let weights = light_weights(&frame.points, &l);
        for e in entries {
            let (v, report) = frame.visibility(gpu, e.technique.as_ref(), &l).map_err(|e| e.to_string())?;
            // the median of three timings (one when a run takes over 2 s)
            let mut times = vec![report.time.as_secs_f64() * 1e3];
            while times.len() < 3 && times[0] < 2000.0 {
                let (_, r) = frame.visibility(gpu, e.technique.as_ref(), &l).map_err(|e| e.to_string())?;
                times.push(r.time.as_secs_f64() * 1e3);
            }
            times.sort_by(f64::total_cmp);
            let (mean, p95, pixels) = penumbra_error(&v, &truth, &weights, width);
            let row = Row {
                scene: frame.scene.name.clone(),
                degrees,
                family: e.family.into(),
                technique: e.technique.name(),
                mean,
                p95,
                pixels,
                ms: times[times.len() / 2],
                clock: report.clock.map_or("none", gpu::Clock::name).into(),
            };
            progress(&row);
            rows.push(row);
        }
    }
    Ok(rows)
}

/// The speed of each technique family at the wedges' error, for one scene and light size.
#[derive(Clone, Debug, PartialEq)]
pub struct EqualError {
    /// Scene.
    pub scene: String,
    /// Half-angle, degrees.
    pub degrees: f32,
    /// The wedges' mean error and time per light (ms).
    pub wedges: (f32, f64),
    /// Per other family: its fastest setting whose mean error is at most the wedges', with its
    /// time per light, or `None` when no setting reaches it.
    pub others: Vec<(String, Option<(String, f64)>)>,
}

/// Speed at equal error for every (scene, half-angle) of `rows`.
#[must_use]
pub fn equal_error(rows: &[Row]) -> Vec<EqualError> {
    let mut out = Vec::new();
    let mut keys: Vec<(String, f32)> = rows.iter().map(|r| (r.scene.clone(), r.degrees)).collect();
    keys.dedup();
    for (scene, degrees) in keys {
        let here: Vec<&Row> = rows.iter().filter(|r| r.scene == scene && r.degrees == degrees).collect();
        let Some(w) = here.iter().find(|r| r.family == "wedges") else { continue };
        let mut families: Vec<&str> = here.iter().map(|r| r.family.as_str()).filter(|f| *f != "wedges").collect();
        families.dedup();
        let best = families
            .into_iter()
            .map(|f| {
                let fastest = here
                    .iter()
                    .filter(|r| r.family == f && r.mean <= w.mean)
                    .min_by(|a, b| a.ms.total_cmp(&b.ms))
                    .map(|r| (r.technique.clone(), r.ms));
                (f.to_string(), fastest)
            })
            .collect();
        out.push(EqualError { scene, degrees, wedges: (w.mean, w.ms), others: best });
    }
    out
}
