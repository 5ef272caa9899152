//! Paper 001's frame on the GPU, whole: the G-buffer, the EnvDirects' soft shadows (wedges) at
//! full resolution, the EnvIndirects' shadows (orthographic maps, as paper 001's Unity version)
//! from a G-buffer at 1 / `scale` of the resolution, joint bilateral upsampling, shading with the
//! residual's SH9 and prefiltered specular ambient. The criterion bench `decomposition` times it
//! on `gallery` (161,794 triangles, paper 001's scale).

use envmap_sphere::EnvMap;
use gpu::{
    Background, FrameLights, FrameShadows, GBufferPass, Gpu, GpuError, JointBilateral, LightShape, LitFrame,
    LitSettings, PrefilterSettings, ReferenceReceivers, SceneGeometry, ShadeLight, SpecularAmbient, SplitSettings,
};
use light_extract::Decomposition;
use penumbra_wedge::{WedgeSettings, Wedges};
use shadowmap_paraboloid::{MapTechnique, ShadowSettings, Technique};
use std::time::{Duration, Instant};

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

pub use gpu::RenderedFrame;

/// Everything a frame needs that does not change between frames: the scene, its lights, its
/// techniques, and the toolkit's one recorded frame ([`gpu::LitFrame`]) they draw through.
pub struct Frame {
    /// The scene as built (objects at rest; [`Frame::set_transform`] moves them), its camera
    /// at the frame's size.
    pub scene: scene::Scene,
    /// The decomposition of the default map, EnvDirects first.
    pub decomposition: Decomposition,
    geometry: SceneGeometry,
    background: Background,
    specular: SpecularAmbient,
    wedges: Wedges,
    maps: MapTechnique,
    lit: LitFrame,
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
        let extractor = light_extract::extractor(light_extract::DEFAULT_METHOD, lights).ok_or("unknown method")?;
        let mut decomposition = extractor.extract(map).map_err(|e| e.to_string())?;
        decomposition.sort_directs_first();
        let size = (scene.camera.width, scene.camera.height);
        Ok(Self {
            lit: LitFrame::new(gpu, size).map_err(e)?,
            geometry: SceneGeometry::upload(gpu, &scene).map_err(e)?,
            background: Background::upload(gpu, map).map_err(e)?,
            specular: SpecularAmbient::new(gpu, &decomposition.ambient, &PrefilterSettings::default()).map_err(e)?,
            wedges: Wedges::new(gpu, &scene, WedgeSettings::default()),
            maps: MapTechnique::new(gpu, &scene, Technique::Orthographic, maps_settings(), 1).map_err(e)?,
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

    /// Renders one frame with the EnvIndirects at 1 / `scale` and returns the image, its work
    /// submitted and not waited for: [`gpu::LitFrame::render`] with the GPU's receivers, two
    /// submissions, no wait, no readback inside. Its few hundred bytes of statistics are mapped
    /// for [`RenderedFrame::finish_reports`].
    ///
    /// # Errors
    /// GPU failures; a scale that does not divide the size.
    pub fn render(&self, gpu: &Gpu, scale: u32) -> Result<RenderedFrame, GpuError> {
        self.render_with(gpu, scale, None)
    }

    /// The same frame with the CPU waiting for the GPU's reduction (a few hundred bytes) and
    /// planning every light from it ([`ReferenceReceivers::ReadStats`]): a reference for
    /// [`Frame::render`].
    ///
    /// # Errors
    /// As [`Frame::render`].
    pub fn render_from_read_stats(&self, gpu: &Gpu, scale: u32) -> Result<RenderedFrame, GpuError> {
        self.render_with(gpu, scale, Some(ReferenceReceivers::ReadStats))
    }

    /// The same frame with its receivers made on the CPU from the G-buffers' points mapped back
    /// ([`ReferenceReceivers::CpuPoints`]), waited for: the reference the GPU reduction of
    /// [`Frame::render`] is tested against, not a real-time path.
    ///
    /// # Errors
    /// As [`Frame::render`].
    pub fn render_from_cpu_receivers(&self, gpu: &Gpu, scale: u32) -> Result<wgpu::Texture, GpuError> {
        let frame = self.render_with(gpu, scale, Some(ReferenceReceivers::CpuPoints))?;
        gpu.wait(None)?;
        Ok(frame.texture)
    }

    fn render_with(&self, gpu: &Gpu, scale: u32, from: Option<ReferenceReceivers>) -> Result<RenderedFrame, GpuError> {
        let d = &self.decomposition;
        let lights: Vec<ShadeLight> = d.lights.iter().map(|l| ShadeLight::from(&l.light)).collect();
        let shapes: Vec<LightShape> = d.lights.iter().map(|l| LightShape::from(&l.light)).collect();
        let view = GBufferPass::camera_view(&self.geometry, &self.scene.camera);
        let frame_lights = FrameLights {
            lights: &lights,
            shapes: &shapes,
            directs: d.directs(),
            ambient: Some(&d.ambient_sh),
            specular_ambient: Some(&self.specular),
            background: Some(&self.background),
        };
        let shadows = FrameShadows { direct: &self.wedges, indirect: &self.maps };
        let settings = LitSettings {
            split: SplitSettings { indirect_scale: scale, upsample: JointBilateral::PAPER },
            ..LitSettings::default()
        };
        match from {
            None => self.lit.render(gpu, &self.geometry, &view, &frame_lights, Some(shadows), &settings),
            Some(from) => {
                self.lit.render_reference(gpu, &self.geometry, &view, &frame_lights, shadows, &settings, from)
            }
        }
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
