//! The GPU stages `cargo xtask validate` measures: the extracted lights on `spheres_box` (or the
//! given scene) shadowed by every technique (shadow maps, PCSS, N-sample maps, penumbra wedges,
//! the traced truth) through `gpu::ShadowTechnique` and drawn by `gpu::LitFrame`, paper 001's
//! split and interleaved frames, and the `room` point light's paraboloid and cube maps against
//! ray-traced visibility. `validate` compares the images with the reference and prints.

use crate::TradeError;
use crate::{TechniqueBuilder, TechniqueSpec, equal_texel_variants, traced_visibility};
use envmap_sphere::EnvMap;
use glam::Vec3;
use gpu::{
    Background, FrameLights, FrameShadows, GBufferPass, Gpu, JointBilateral, LightShape, LitFrame, LitSettings,
    PrefilterSettings, Receivers, ReferenceReceivers, SceneGeometry, ShadeLight, ShadowGeometry, ShadowTechnique,
    SpecularAmbient, SplitSettings, VisibilityLayers,
};
use ref_tracer::SceneBvh;
use ref_tracer::visibility::{disagreement, light_visibility};
use shadowmap_paraboloid::{MapView, Pcss, ShadowMapper, ShadowSettings, Technique, shadow_triangles};
use std::time::Instant;

/// One GPU image: its row name, what it is (technique, lights shadowed and skipped, GPU time),
/// the image and the seconds it took end to end.
pub struct GpuImage {
    /// Row name, e.g. `gpu_wedges`.
    pub name: String,
    /// What it is: technique, lights shadowed and skipped, GPU time.
    pub what: String,
    /// The image, resolved to the plan's size.
    pub image: Vec<Vec3>,
    /// Seconds end to end.
    pub seconds: f64,
}

/// What the stages draw and how.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct StagePlan {
    /// The hard maps; PCSS and the N-sample maps derive from them.
    pub shadow: ShadowSettings,
    /// Maps per light of the N-sample technique (at half the resolution).
    pub multi_samples: u32,
    /// Ray-traced visibility of the truth row: n × n directions per pixel and light.
    pub truth_directions: u32,
    /// GPU images supersampled on a rotated grid of k² + 1 samples per pixel, box-filtered.
    pub gpu_supersample: u32,
    /// Rows of interleaved light sets too.
    pub interleaved: bool,
    /// Size of the `room` frames.
    pub room_size: (u32, u32),
    /// Renders per map variant (the median time is kept).
    pub repeats: usize,
}

/// One shadow map of the `room` comparison against ray-traced visibility.
#[derive(Clone, Debug, PartialEq)]
pub struct MaskRow {
    /// The variant's name ([`crate::MapVariant`]).
    pub name: String,
    /// Its projection.
    pub technique: Technique,
    /// Texels of all its views.
    pub texels: u64,
    /// Fraction of the pixels whose lit test disagrees with the truth.
    pub disagreement: f64,
    /// Median GPU time of the map, ms.
    pub gpu_ms: f64,
    /// Triangles drawn into it.
    pub triangles: u32,
}

/// The GPU passes, built once per run.
pub struct StagePasses {
    /// The G-buffer pass.
    pub gbuffer: GBufferPass,
    /// The shadow mapper of the `room` maps.
    pub shadows: ShadowMapper,
}

impl StagePasses {
    /// The passes on `gpu`.
    #[must_use]
    pub fn new(gpu: &Gpu) -> Self {
        Self { gbuffer: GBufferPass::new(gpu), shadows: ShadowMapper::new(gpu) }
    }
}

/// A row name and its shadow technique.
type NamedTechnique = (String, Box<dyn ShadowTechnique>);

/// The shadow techniques validate compares on the extracted lights, by row name: the plan's
/// hard maps, PCSS on them, the mean of `plan.multi_samples` maps of half the side, wedges.
fn techniques(gpu: &Gpu, scene: &scene::Scene, plan: &StagePlan) -> Result<Vec<NamedTechnique>, TradeError> {
    let hard = plan.shadow;
    let pcss = ShadowSettings { pcss: Some(Pcss::default()), pcf_radius: 0, ..hard };
    let multi = ShadowSettings { resolution: hard.resolution / 2, pcf_radius: 0, ..hard };
    let specs = [
        ("gpu_shadow_maps".to_string(), TechniqueSpec::orthographic(hard, 1)),
        ("gpu_pcss".into(), TechniqueSpec::orthographic(pcss, 1)),
        (format!("gpu_shadow_maps_x{}", plan.multi_samples), TechniqueSpec::orthographic(multi, plan.multi_samples)),
        ("gpu_wedges".into(), TechniqueSpec::wedges()),
    ];
    Ok(TechniqueBuilder::new(gpu, scene).build_all(&specs)?)
}

/// The extracted lights on the GPU with every technique of [`techniques`], and without shadows
/// (the last image), each frame the toolkit's recorded frame ([`gpu::LitFrame`]) with its
/// receivers read back and reduced on the CPU ([`ReferenceReceivers::CpuPoints`]): the
/// reference its GPU-gated frame is tested against, waited for and its lights timed.
/// The extracted lights of `d` on `scene` lit by `map`, one image per technique and frame
/// kind, the last without shadows.
///
/// # Errors
/// GPU failures.
pub fn gpu_render(
    gpu: &Gpu,
    passes: &StagePasses,
    scene: &scene::Scene,
    map: &EnvMap,
    d: &light_extract::Decomposition,
    plan: &StagePlan,
) -> Result<Vec<GpuImage>, TradeError> {
    let start = Instant::now();
    // supersampled as the ray tracer's pixels are (box filter): edges alias otherwise, and
    // their error would hide the shadows'. A rotated grid: an ordered one quantizes the
    // coverage of every horizontal edge (the ground's far edge) to 1/k along the whole row
    let ss = plan.gpu_supersample.max(1);
    let grid = gpu::RotatedGrid::new(&scene.camera, ss);
    let mut scene = scene.clone();
    scene.camera = *grid.camera();
    let scene = &scene;
    let geometry = SceneGeometry::upload(gpu, scene)?;
    // the ray-traced truth's receivers: its rays start from the G-buffer's points
    let gb = passes.gbuffer.render(gpu, &geometry, &scene.camera)?;
    let points = gb.read_points(gpu)?;
    let receivers = Receivers::new(&gb, &points);
    let lights: Vec<ShadeLight> = d.lights.iter().map(|l| ShadeLight::from(&l.light)).collect();
    let shapes: Vec<LightShape> = d.lights.iter().map(|l| LightShape::from(&l.light)).collect();
    let lit = LitFrame::new(gpu, gb.size())?;
    let view = GBufferPass::camera_view(&geometry, &scene.camera);
    let background = Background::upload(gpu, map)?;
    // the ambient map on the specular lobe, for scenes that have one
    let glossy = scene.objects.iter().any(|o| o.material.specular.is_some());
    let specular =
        if glossy { Some(SpecularAmbient::new(gpu, &d.ambient, &PrefilterSettings::default())?) } else { None };
    let ambient = match &specular {
        Some(_) => "SH9 + prefiltered specular ambient",
        None => "SH9 ambient (no glossy surface: no specular prefiltering)",
    };
    let whole = FrameLights {
        lights: &lights,
        shapes: &shapes,
        directs: lights.len(),
        ambient: Some(&d.ambient_sh),
        specular_ambient: specular.as_ref(),
        background: Some(&background),
    };
    // lights whose shadow no visible receiver could tell apart (Weber's law) get no pass
    let settings = LitSettings { split: SplitSettings::default(), weber: true, time_lights: true };
    let common = start.elapsed().as_secs_f64();
    let mut out = Vec::new();
    let mut all = techniques(gpu, scene, plan)?;
    all.push((
        "gpu_traced_visibility".into(),
        Box::new(traced_visibility(gpu, scene, &receivers, &shapes, plan.truth_directions)?),
    ));
    for (name, technique) in &all {
        let t = Instant::now();
        let shadows = FrameShadows { direct: technique.as_ref(), indirect: technique.as_ref() };
        let frame =
            lit.render_reference(gpu, &geometry, &view, &whole, shadows, &settings, ReferenceReceivers::CpuPoints)?;
        let (image, reports) = finished(gpu, frame, technique.as_ref())?;
        let (time, shadowed, _, _) = gpu::totals(&reports);
        let shadow_ms = time.as_secs_f64() * 1e3;
        out.push(GpuImage {
            what: format!(
                "GPU: {} lights with {} ({shadowed} shadowed{}; {shadow_ms:.1} ms), + {ambient}",
                lights.len(),
                technique.name(),
                skip_summary(&reports),
            ),
            name: name.clone(),
            image: grid.resolve(&image),
            seconds: common + t.elapsed().as_secs_f64(),
        });
    }
    let directs = d.directs();
    if let Some((_, technique)) = all.iter().find(|(n, _)| n == "gpu_wedges")
        && directs < lights.len()
    {
        // paper 001's frame: the EnvDirects' wedges at full resolution, the EnvIndirects' at
        // 1/2 or 1/4 of the output's resolution, upsampled
        let split_lights = FrameLights { directs, ..whole };
        let shadows = FrameShadows { direct: technique.as_ref(), indirect: technique.as_ref() };
        for (suffix, scale, upsample, how) in [
            ("half", 2, JointBilateral::PAPER, "joint bilateral"),
            ("quarter", 4, JointBilateral::PAPER, "joint bilateral"),
            ("half_gaussian", 2, JointBilateral::GAUSSIAN, "Gaussian"),
        ] {
            let t = Instant::now();
            let settings = LitSettings { split: SplitSettings { indirect_scale: scale * ss, upsample }, ..settings };
            let frame = lit.render_reference(
                gpu,
                &geometry,
                &view,
                &split_lights,
                shadows,
                &settings,
                ReferenceReceivers::CpuPoints,
            )?;
            let (image, reports) = finished(gpu, frame, technique.as_ref())?;
            let direct_ms = gpu::totals(&reports[..directs]).0.as_secs_f64() * 1e3;
            let indirect_ms = gpu::totals(&reports[directs..]).0.as_secs_f64() * 1e3;
            let (lw, lh) = (gb.size().0 / (scale * ss), gb.size().1 / (scale * ss));
            let pitch = f64::from(scale * ss) / f64::from(grid.samples_per_pixel()).sqrt();
            out.push(GpuImage {
                name: format!("gpu_wedges_indirects_{suffix}"),
                what: format!(
                    "GPU, paper 001's split: {directs} EnvDirects with wedges at full resolution ({direct_ms:.1} ms), {} EnvIndirects with wedges at {lw}x{lh} (a sample every {pitch:.2} pixels; {indirect_ms:.1} ms{}), {how} upsampling, + {ambient}",
                    lights.len() - directs,
                    skip_summary(&reports[directs..]),
                ),
                image: grid.resolve(&image),
                seconds: common + t.elapsed().as_secs_f64(),
            });
        }
    }
    if plan.interleaved {
        let sets: Vec<Vec<scene::DistantLight>> =
            std::iter::once(d.distant_lights()).chain(d.interleaved_distant_lights()).collect();
        let shade: Vec<Vec<ShadeLight>> = sets.iter().map(|s| s.iter().map(ShadeLight::from).collect()).collect();
        let set_shapes: Vec<Vec<LightShape>> = sets.iter().map(|s| s.iter().map(LightShape::from).collect()).collect();
        let frames: Vec<FrameLights> = shade
            .iter()
            .zip(&set_shapes)
            .map(|(l, s)| FrameLights { lights: l, shapes: s, directs: l.len(), ..whole })
            .collect();
        for (name, technique) in all.iter().filter(|(n, _)| n == "gpu_shadow_maps" || n == "gpu_wedges") {
            let t = Instant::now();
            let shadows = FrameShadows { direct: technique.as_ref(), indirect: technique.as_ref() };
            let interleaved = lit.render_interleaved(
                gpu,
                &geometry,
                &view,
                &frames,
                shadows,
                &settings,
                Some(ReferenceReceivers::CpuPoints),
            )?;
            gpu.wait(None)?;
            let (texture, reports) = interleaved.finish_reports(gpu)?;
            let ms = gpu::totals(&reports).0.as_secs_f64() * 1e3;
            let image = gpu::read_hdr(gpu, &texture)?;
            out.push(GpuImage {
                name: format!("{name}_interleaved"),
                what: format!(
                    "GPU: {} lights in {} interleaved sets (a {}x{} pixel tile) with {} ({ms:.1} ms), + {ambient}",
                    lights.len(),
                    sets.len(),
                    gpu::interleave_tile(sets.len() as u32).0,
                    gpu::interleave_tile(sets.len() as u32).1,
                    technique.name()
                ),
                image: grid.resolve(&image),
                seconds: common + t.elapsed().as_secs_f64(),
            });
        }
    }
    let frame = lit.render(gpu, &geometry, &view, &whole, None, &settings)?;
    gpu.wait(None)?;
    let (texture, _) = frame.finish_reports(gpu)?;
    out.push(GpuImage {
        name: "gpu_unshadowed".into(),
        what: "GPU: the same lights without shadows".into(),
        image: grid.resolve(&gpu::read_hdr(gpu, &texture)?),
        seconds: 0.0,
    });
    Ok(out)
}

/// A frame waited for: its image read back and its reports completed with the technique's
/// counts and what the GPU knew.
fn finished(
    gpu: &Gpu,
    mut frame: gpu::RenderedFrame,
    technique: &dyn ShadowTechnique,
) -> Result<(Vec<Vec3>, Vec<gpu::ShadowPassReport>), TradeError> {
    gpu.wait(None)?;
    technique.read_counts(gpu, &mut frame.reports)?;
    let (texture, reports) = frame.finish_reports(gpu)?;
    Ok((gpu::read_hdr(gpu, &texture)?, reports))
}

/// ", N skipped: why" per reason, or nothing.
fn skip_summary(reports: &[gpu::ShadowPassReport]) -> String {
    gpu::skip_reasons(reports).iter().map(|(why, n)| format!(", {n} skipped: {why}")).collect()
}

/// The paraboloid and cube masks the report shows, the truth and their size.
pub type MaskImages = (Vec<f32>, Vec<f32>, Vec<Option<bool>>, (u32, u32));

/// The `room` point light's maps of equal texel counts ([`crate::equal_texel_variants`])
/// against ray-traced visibility, the error against the angle triangles span (the paper's
/// caveat), and the clock the times come from.
///
/// # Errors
/// GPU failures.
pub fn room_masks(
    gpu: &Gpu,
    passes: &StagePasses,
    plan: &StagePlan,
) -> Result<(Vec<MaskRow>, MaskImages, Vec<SizeRow>, gpu::Clock), TradeError> {
    let mut scene = scene::Scene::builtin("room").map_err(|e| TradeError::Scene(e.to_string()))?;
    (scene.camera.width, scene.camera.height) = plan.room_size;
    let geometry = SceneGeometry::upload(gpu, &scene)?;
    let gb = passes.gbuffer.render(gpu, &geometry, &scene.camera)?;
    let points = gb.read_points(gpu)?;
    let position = scene.point_lights[0].position;
    let truth = light_visibility(&SceneBvh::new(&scene), &points, LightShape::point(position));
    let tris = gpu::scene_triangles(&scene);
    let light = MapView::omni(position);
    let mapper = &passes.shadows;
    let (w, h) = plan.room_size;
    let vis = VisibilityLayers::new(gpu, w, h, 1)?;
    let mut rows = Vec::new();
    let (mut paraboloid_mask, mut cube_mask) = (Vec::new(), Vec::new());
    let mut clock = gpu::Clock::WallTime;
    for v in equal_texel_variants() {
        let (technique, settings) = (v.technique, v.settings);
        let t = shadow_triangles(&tris, &light, technique, &settings);
        let g = ShadowGeometry::upload(gpu, &t, ShadowGeometry::CHUNK_TRIANGLES)?;
        let mut times = Vec::new();
        let mut last = None;
        for _ in 0..plan.repeats.max(1) {
            let m = mapper.render(gpu, &g, &light, technique, &settings)?;
            times.push(m.time.as_secs_f64() * 1e3);
            clock = m.clock;
            last = Some(m);
        }
        times.sort_by(f64::total_cmp);
        let m = last.ok_or_else(|| TradeError::Render("no shadow map".into()))?;
        mapper.visibility(gpu, &m, &gb, &vis.layer(0))?;
        let mask = vis.read(gpu, 0)?;
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
        let g = ShadowGeometry::upload(gpu, &t, ShadowGeometry::CHUNK_TRIANGLES)?;
        let m = mapper.render(gpu, &g, &light, Technique::DualParaboloid, &settings)?;
        mapper.visibility(gpu, &m, &gb, &vis.layer(0))?;
        let (frac, _) = disagreement(&vis.read(gpu, 0)?, &truth);
        sizes.push(SizeRow { widest, triangles: t.len(), disagreement: frac });
    }
    Ok((rows, (paraboloid_mask, cube_mask, truth, plan.room_size), sizes, clock))
}

/// One row of the error-against-triangle-size sweep.
pub struct SizeRow {
    /// The widest angle an edge spans from the light, radians.
    pub widest: f32,
    /// Triangles drawn.
    pub triangles: usize,
    /// Fraction of the pixels that disagree with the truth.
    pub disagreement: f64,
}
