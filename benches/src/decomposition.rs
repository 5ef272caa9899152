//! Paper 001's frame on the GPU, whole: the G-buffer, the EnvDirects' soft shadows (wedges) at
//! full resolution, the EnvIndirects' shadows (orthographic maps, as paper 001's Unity version)
//! from a G-buffer at 1 / `scale` of the resolution, joint bilateral upsampling, shading with the
//! residual's SH9 and prefiltered specular ambient. The criterion bench `decomposition` times it
//! on `gallery` (161,794 triangles, paper 001's scale).

use envmap_sphere::EnvMap;
use gpu::{
    Background, GBufferPass, GBufferTargets, Gpu, GpuError, JointBilateral, LightShape, MappedStats, PendingStats,
    PrefilterSettings, ReceiverReduction, Receivers, SceneGeometry, ShadeLight, ShadingPass, ShadowTechnique,
    SpecularAmbient, SplitFrame, SplitPasses, SplitSettings, SplitTargets, UpsamplePass, Visibility, WEBER_FRACTION,
    WeberInput, indirect_camera, record_split, record_visibility,
};
use light_extract::Decomposition;
use penumbra_wedge::{WedgeSettings, Wedges};
use shadowmap_paraboloid::{MapTechnique, ShadowSettings, Technique};
use std::cell::RefCell;
use std::rc::Rc;
use std::time::{Duration, Instant};

/// The extraction the frame draws: the toolkit's most accurate (validate's default).
pub const METHOD: &str = "emissive-split+moment-cones+above-horizon+residual";

/// The EnvIndirects' maps: 1024², 3 x 3 PCF.
fn maps_settings() -> ShadowSettings {
    ShadowSettings { resolution: 1024, pcf_radius: 1, ..ShadowSettings::default() }
}

/// The object `cargo xtask frame --animate` moves: the scene's first object that is not its
/// ground (moving a ground plane along itself changes nothing to see), else the first.
#[must_use]
pub fn animated_object(scene: &scene::Scene) -> usize {
    scene.objects.iter().position(|o| o.name != "ground").unwrap_or(0)
}

/// Where the animated object is at frame `k`: moved along a horizontal circle through its
/// rest pose, of radius an eighth of its bounding box's diagonal, and turned about the vertical
/// through its centre by the same angle; a new pose every frame (64 poses a turn). Frame 0 is
/// the rest pose.
#[must_use]
pub fn animation_pose(scene: &scene::Scene, object: usize, k: usize) -> glam::Affine3A {
    let Some((lo, hi)) = scene.objects.get(object).and_then(|o| finite_box(&o.mesh.positions)) else {
        return glam::Affine3A::IDENTITY;
    };
    if k.is_multiple_of(64) {
        return glam::Affine3A::IDENTITY;
    }
    let r = 0.125 * (hi - lo).length();
    let a = std::f32::consts::TAU * (k % 64) as f32 / 64.0;
    let centre = 0.5 * (lo + hi);
    let offset = glam::Vec3::new(r * (a.cos() - 1.0), 0.0, r * a.sin());
    glam::Affine3A::from_translation(centre + offset)
        * glam::Affine3A::from_rotation_y(a)
        * glam::Affine3A::from_translation(-centre)
}

/// A frame's image (submitted, not waited for) and what its shadow passes did. The image is
/// the frame's own target: the next frame at the same scale renders into it.
pub struct RenderedFrame {
    /// The HDR image.
    pub texture: wgpu::Texture,
    /// Per light, EnvDirects first: its shadow pass as recorded, or why it had none. Where the
    /// GPU gated the lights, which it skipped is known once the frame has run:
    /// [`RenderedFrame::finish_reports`].
    pub reports: Vec<gpu::ShadowPassReport>,
    // the receivers' statistics being mapped (full resolution, then low), and the EnvDirects
    gated: Option<(Vec<MappedStats>, usize)>,
}

impl RenderedFrame {
    /// The reports with the lights the GPU skipped marked (why, and nothing drawn), read once
    /// the frame has finished (after the caller's own wait, or a later frame's): no wait of
    /// its own, a few hundred bytes.
    ///
    /// # Errors
    /// The frame has not finished; GPU failures.
    pub fn finish_reports(self, gpu: &Gpu) -> Result<(wgpu::Texture, Vec<gpu::ShadowPassReport>), GpuError> {
        let mut reports = self.reports;
        if let Some((mapped, directs)) = self.gated {
            let stats = mapped.into_iter().map(|m| m.finish(gpu)).collect::<Result<Vec<_>, _>>()?;
            for (k, r) in reports.iter_mut().enumerate() {
                let s = if k < directs { stats.first() } else { stats.last() };
                if let Some(why) = s.and_then(|s| s.skip_reason(k)) {
                    *r = gpu::ShadowPassReport { skipped: Some(why), ..gpu::ShadowPassReport::default() };
                }
            }
        }
        Ok((self.texture, reports))
    }
}

/// What a frame at one scale renders into: the low-resolution G-buffer (none at scale 1)
/// and the split frame's images.
type ScaleTargets = (Option<GBufferTargets>, SplitTargets);

/// Everything a frame needs that does not change between frames.
pub struct Frame {
    /// The scene as built (objects at rest; [`Frame::set_transform`] moves them), its camera
    /// at the frame's size.
    pub scene: scene::Scene,
    /// The decomposition of the default map, EnvDirects first.
    pub decomposition: Decomposition,
    geometry: SceneGeometry,
    gbuffer: GBufferPass,
    shading: ShadingPass,
    upsample: UpsamplePass,
    background: Background,
    specular: SpecularAmbient,
    wedges: Wedges,
    maps: MapTechnique,
    // the receivers of the full- and the low-resolution G-buffer
    reductions: [ReceiverReduction; 2],
    // what the frame renders into, made once: the full-resolution G-buffer, the low one and
    // the split frame's images (for the last scale asked) and the EnvDirects' visibility
    targets: GBufferTargets,
    low_targets: RefCell<gpu::Keyed<u32, Rc<ScaleTargets>>>,
    direct_visibility: Visibility,
}

impl Frame {
    /// Sets up `scene_name` at `size`, lit by `map` decomposed into `lights` lights.
    ///
    /// # Errors
    /// An unknown scene or method; GPU failures.
    pub fn new(gpu: &Gpu, scene_name: &str, size: (u32, u32), map: &EnvMap, lights: usize) -> Result<Self, String> {
        let mut scene = scene::Scene::builtin(scene_name).map_err(|e| e.to_string())?;
        (scene.camera.width, scene.camera.height) = size;
        Self::with_scene(gpu, scene, map, lights)
    }

    /// Sets up `scene` (its camera's size is the frame's), lit by `map` decomposed into
    /// `lights` lights.
    ///
    /// # Errors
    /// An unknown method; GPU failures.
    pub fn with_scene(gpu: &Gpu, scene: scene::Scene, map: &EnvMap, lights: usize) -> Result<Self, String> {
        let e = |e: GpuError| e.to_string();
        let extractor = light_extract::extractor(METHOD, lights).ok_or("unknown method")?;
        let mut decomposition = extractor.extract(map).map_err(|e| e.to_string())?;
        decomposition.sort_directs_first();
        let size = (scene.camera.width, scene.camera.height);
        Ok(Self {
            targets: GBufferTargets::new(gpu, size).map_err(e)?,
            low_targets: RefCell::default(),
            direct_visibility: Visibility::allocate(gpu, size.0, size.1, decomposition.directs() as u32).map_err(e)?,
            geometry: SceneGeometry::upload(gpu, &scene).map_err(e)?,
            gbuffer: GBufferPass::new(gpu),
            shading: ShadingPass::new(gpu).map_err(e)?,
            upsample: UpsamplePass::new(gpu),
            background: Background::upload(gpu, map).map_err(e)?,
            specular: SpecularAmbient::new(gpu, &decomposition.ambient, &PrefilterSettings::default()).map_err(e)?,
            wedges: Wedges::new(gpu, &scene, WedgeSettings::default()),
            maps: MapTechnique::new(gpu, &scene, Technique::Orthographic, maps_settings(), 1).map_err(e)?,
            reductions: [ReceiverReduction::new(gpu), ReceiverReduction::new(gpu)],
            scene,
            decomposition,
        })
    }

    /// Moves object `object` by `transform` from its rest pose. Nothing is built and no
    /// vertex is written: the transform goes to the G-buffer's, the maps' and the wedges'
    /// geometry (a `queue.write_buffer` each), whose vertices the next frame places on the GPU.
    ///
    /// # Errors
    /// An object index out of range; a non-finite transform.
    pub fn set_transform(&mut self, gpu: &Gpu, object: usize, transform: glam::Affine3A) -> Result<(), GpuError> {
        self.geometry.set_transform(gpu, object, transform)?;
        self.wedges.set_transform(gpu, object, transform)?;
        self.maps.set_transform(gpu, object, transform)
    }

    /// The scene with every object's vertices where its transform puts them: what a frame
    /// built afresh for the current poses would be given.
    #[must_use]
    pub fn posed_scene(&self) -> scene::Scene {
        let mut posed = self.scene.clone();
        for (k, o) in posed.objects.iter_mut().enumerate() {
            o.mesh.transform(&self.geometry.transform(k));
        }
        posed
    }

    /// The frame's lights as the shading pass and the techniques see them, EnvDirects first.
    fn lights(&self) -> (Vec<ShadeLight>, Vec<LightShape>) {
        let lights = &self.decomposition.lights;
        (
            lights.iter().map(|l| ShadeLight::from(&l.light)).collect(),
            lights.iter().map(|l| LightShape::from(&l.light)).collect(),
        )
    }

    /// Renders one frame with the EnvIndirects at 1 / `scale` and returns the image, its work
    /// submitted and not waited for: no wait, no readback inside it. Two submissions: the
    /// G-buffers with their receivers reduced on the GPU (bounds, focus, the lights they face,
    /// Weber's test), then everything else recorded into one encoder, which the CPU records
    /// meanwhile. The reduction stays on the GPU: it gates each light's draws (lights no
    /// receiver faces and those Weber's law finds negligible draw nothing) and fits the
    /// orthographic maps; the wedges are planned from what the CPU knows, the scene's box
    /// within the view ([`gpu::conservative_bounds`]). Its few hundred bytes are mapped for
    /// [`RenderedFrame::finish_reports`].
    ///
    /// # Errors
    /// GPU failures; a scale that does not divide the size.
    pub fn render(&self, gpu: &Gpu, scale: u32) -> Result<RenderedFrame, GpuError> {
        let d = &self.decomposition;
        let (lights, shapes) = self.lights();
        let settings = SplitSettings { indirect_scale: scale, upsample: JointBilateral::PAPER };
        let low_camera = indirect_camera(&self.scene.camera, &settings)?;
        let (gb, low_gb, pending) = self.submit_reduced(gpu, &lights, &shapes, &low_camera, scale)?;
        // the drawn geometry's box, its objects where their transforms put them
        let (lo, hi) = self.geometry.bounds;
        let scene_box = (lo.is_finite() && hi.is_finite()).then_some((lo, hi));
        let directs = d.directs() as u32;
        let bounds = scene_box.and_then(|b| gpu::conservative_bounds(b, &gb.view));
        let receivers = Receivers::on_gpu(&gb, bounds, pending[0].on_gpu().clone());
        let low_gpu = pending[pending.len() - 1].on_gpu().starting_at(directs);
        let low = match &low_gb {
            Some(l) => Receivers::on_gpu(l, scene_box.and_then(|b| gpu::conservative_bounds(b, &l.view)), low_gpu),
            None => Receivers::on_gpu(&gb, bounds, low_gpu),
        };
        let mut encoder = gpu.encoder("frame");
        let frame =
            self.record_lit(gpu, &mut encoder, (&lights, &shapes), (&receivers, &[]), (&low, Some(&[])), &settings)?;
        gpu.submit(encoder);
        let mapped = pending.into_iter().map(|p| p.map(gpu)).collect();
        Ok(RenderedFrame { gated: Some((mapped, directs as usize)), ..frame })
    }

    /// The same frame with the CPU waiting for the GPU's reduction (a few hundred bytes) and
    /// planning every light from it: lights skipped on the CPU, the wedges planned for the
    /// receivers' exact bounds, the maps fitted on the CPU. What the frame did before its
    /// lights were gated on the GPU, kept as a second reference for [`Frame::render`].
    ///
    /// # Errors
    /// As [`Frame::render`].
    pub fn render_from_read_stats(&self, gpu: &Gpu, scale: u32) -> Result<RenderedFrame, GpuError> {
        let (lights, shapes) = self.lights();
        let settings = SplitSettings { indirect_scale: scale, upsample: JointBilateral::PAPER };
        let low_camera = indirect_camera(&self.scene.camera, &settings)?;
        let (gb, low_gb, pending) = self.submit_reduced(gpu, &lights, &shapes, &low_camera, scale)?;
        let stats = PendingStats::read_all(gpu, pending)?;
        let receivers = Receivers::from_stats(&gb, &stats[0], &shapes);
        let low_receivers = low_gb.as_ref().map(|l| Receivers::from_stats(l, &stats[1], &shapes));
        let low = low_receivers.as_ref().unwrap_or(&receivers);
        let mut encoder = gpu.encoder("frame");
        let (negligible, low_negligible) = (&stats[0].negligible, &stats[stats.len() - 1].negligible);
        let frame = self.record_lit(
            gpu,
            &mut encoder,
            (&lights, &shapes),
            (&receivers, negligible),
            (low, Some(low_negligible)),
            &settings,
        )?;
        gpu.submit(encoder);
        Ok(frame)
    }

    /// The low-resolution G-buffer's (none at scale 1) and the split frame's targets at
    /// `scale`, made when the scale differs from the last one asked.
    fn scale_targets(&self, gpu: &Gpu, scale: u32) -> Result<Rc<ScaleTargets>, GpuError> {
        let settings = SplitSettings { indirect_scale: scale, upsample: JointBilateral::PAPER };
        let size = (self.scene.camera.width, self.scene.camera.height);
        let indirects = (self.decomposition.lights.len() - self.decomposition.directs()) as u32;
        let make = || {
            let low = indirect_camera(&self.scene.camera, &settings)?;
            // at scale 1 the EnvIndirects are shaded from the full-resolution G-buffer
            let gbuffer = (scale != 1).then(|| GBufferTargets::new(gpu, (low.width, low.height))).transpose()?;
            Ok(Rc::new((gbuffer, SplitTargets::new(gpu, size, &settings, indirects)?)))
        };
        Ok(self.low_targets.borrow_mut().try_get(scale, make)?.clone())
    }

    /// Submits both G-buffers (the low one at `low_camera` when `scale` is not 1) with their
    /// receivers reduced on the GPU: the frame's first submission.
    fn submit_reduced(
        &self,
        gpu: &Gpu,
        lights: &[ShadeLight],
        shapes: &[LightShape],
        low_camera: &scene::Camera,
        scale: u32,
    ) -> Result<(gpu::GBuffer, Option<gpu::GBuffer>, Vec<PendingStats>), GpuError> {
        let ambient = Some(&self.decomposition.ambient_sh);
        let weber = WeberInput { lights, ambient, fraction: WEBER_FRACTION };
        let mut encoder = gpu.encoder("frame g-buffers");
        let view = GBufferPass::camera_view(&self.geometry, &self.scene.camera);
        let gb = self.gbuffer.record_into(gpu, &mut encoder, &self.geometry, &view, &self.targets)?;
        let low_gb = if scale == 1 {
            None
        } else {
            let low = self.scale_targets(gpu, scale)?;
            let view = GBufferPass::camera_view(&self.geometry, low_camera);
            let targets = low.0.as_ref().ok_or_else(|| GpuError::Failed("no low G-buffer at scale 1".into()))?;
            Some(self.gbuffer.record_into(gpu, &mut encoder, &self.geometry, &view, targets)?)
        };
        let mut pending = vec![self.reductions[0].record(gpu, &mut encoder, &gb, shapes, Some(weber))?];
        if let Some(l) = &low_gb {
            pending.push(self.reductions[1].record(gpu, &mut encoder, l, shapes, Some(weber))?);
        }
        gpu.submit(encoder);
        Ok((gb, low_gb, pending))
    }

    /// The same frame with its receivers made on the CPU from the G-buffers' points mapped back
    /// (32 bytes a pixel; `Receivers::new`, `weber_negligible`), waited for: the reference the
    /// GPU reduction of [`Frame::render`] is tested against, not a real-time path.
    ///
    /// # Errors
    /// As [`Frame::render`].
    pub fn render_from_cpu_receivers(&self, gpu: &Gpu, scale: u32) -> Result<wgpu::Texture, GpuError> {
        let (lights, shapes) = self.lights();
        let settings = SplitSettings { indirect_scale: scale, upsample: JointBilateral::PAPER };
        let low_camera = indirect_camera(&self.scene.camera, &settings)?;
        let gb = self.gbuffer.render(gpu, &self.geometry, &self.scene.camera)?;
        let low_gb = (scale != 1).then(|| self.gbuffer.render(gpu, &self.geometry, &low_camera)).transpose()?;
        let points = gb.read_points(gpu)?;
        let low_points = low_gb.as_ref().map(|l| l.read_points(gpu)).transpose()?;
        let receivers = Receivers::new(&gb, &points);
        let low_receivers = low_gb.as_ref().zip(low_points.as_deref()).map(|(l, p)| Receivers::new(l, p));
        let low = low_receivers.as_ref().unwrap_or(&receivers);
        let ambient = Some(&self.decomposition.ambient_sh);
        let negligible = gpu::weber_negligible(&receivers, &lights, ambient, WEBER_FRACTION);
        let mut encoder = gpu.encoder("frame");
        let frame =
            self.record_lit(gpu, &mut encoder, (&lights, &shapes), (&receivers, &negligible), (low, None), &settings)?;
        gpu.submit_and_wait(encoder)?;
        Ok(frame.texture)
    }

    /// Records the EnvDirects' wedges over `receivers` and the split frame over them and `low`
    /// (each with its Weber flags; `None`: from the low receivers' points).
    fn record_lit(
        &self,
        gpu: &Gpu,
        encoder: &mut wgpu::CommandEncoder,
        (lights, shapes): (&[ShadeLight], &[LightShape]),
        (receivers, negligible): (&Receivers, &[bool]),
        low: (&Receivers, Option<&[bool]>),
        settings: &SplitSettings,
    ) -> Result<RenderedFrame, GpuError> {
        let d = &self.decomposition;
        let directs = d.directs();
        let targets = self.scale_targets(gpu, settings.indirect_scale)?;
        let vis = &self.direct_visibility;
        vis.record_clear(encoder);
        let wedges: &dyn ShadowTechnique = &self.wedges;
        let direct_negligible = negligible.get(..directs).unwrap_or(&[]);
        let mut reports =
            record_visibility(gpu, encoder, wedges, receivers, &shapes[..directs], direct_negligible, vis)?;
        let split = record_split(
            gpu,
            encoder,
            &SplitPasses { gbuffer: &self.gbuffer, shading: &self.shading, upsample: &self.upsample },
            &self.geometry,
            (receivers, vis),
            low,
            &SplitFrame {
                lights,
                shapes,
                directs,
                ambient: Some(&d.ambient_sh),
                specular_ambient: Some(&self.specular),
                background: Some(&self.background),
                targets: Some(&targets.1),
            },
            &self.maps,
            settings,
        )?;
        reports.extend(split.indirect_reports);
        Ok(RenderedFrame { texture: split.texture, reports, gated: None })
    }

    /// [`Frame::render`] waited for: the wall time of the whole frame (CPU work included) and
    /// the image.
    ///
    /// # Errors
    /// As [`Frame::render`].
    pub fn render_timed(&self, gpu: &Gpu, scale: u32) -> Result<(Duration, wgpu::Texture), GpuError> {
        let start = Instant::now();
        let texture = self.render(gpu, scale)?.texture;
        gpu.wait(None)?;
        Ok((start.elapsed(), texture))
    }
}

/// The box around the finite points of `points`, `None` for none.
fn finite_box<'a>(points: impl IntoIterator<Item = &'a glam::Vec3>) -> Option<(glam::Vec3, glam::Vec3)> {
    let (lo, hi) = points
        .into_iter()
        .filter(|p| p.is_finite())
        .fold((glam::Vec3::splat(f32::INFINITY), glam::Vec3::splat(f32::NEG_INFINITY)), |(lo, hi), p| {
            (lo.min(*p), hi.max(*p))
        });
    (lo.is_finite() && hi.is_finite()).then_some((lo, hi))
}
