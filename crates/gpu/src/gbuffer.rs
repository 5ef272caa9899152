//! The G-buffer: per pixel, the visible surface's world position and object, shading normal and
//! geometric normal. Shadow techniques read it to write visibility; the shading pass to light.

use crate::context::{Gpu, GpuError};
use crate::geometry::SceneGeometry;
use glam::{Mat4, Vec3};

/// Format of the G-buffer's colour targets.
pub const GBUFFER_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Rgba32Float;

/// The G-buffer of one view.
pub struct GBuffer {
    /// xyz world position, w object index (or -1 where camera rays miss).
    pub position: wgpu::Texture,
    /// xyz shading normal facing the camera.
    pub normal: wgpu::Texture,
    /// xyz geometric normal facing the camera.
    pub geometric_normal: wgpu::Texture,
    /// Depth (Depth32Float).
    pub depth: wgpu::Texture,
    /// The view it was rendered from: what techniques know of the camera.
    pub view: crate::View,
}

/// Projection × view of `camera` for wgpu's clip space (depth in [0, 1]); `near`/`far` in metres.
#[must_use]
pub fn view_projection(camera: &scene::Camera, near: f32, far: f32) -> Mat4 {
    let (fov_y, aspect, view) = view_and_fov(camera);
    glam::camera::rh::proj::directx::perspective(fov_y, aspect, near, far) * view
}

/// (vertical field of view, aspect ratio, view matrix) of `camera`.
pub(crate) fn view_and_fov(camera: &scene::Camera) -> (f32, f32, Mat4) {
    let aspect = camera.width as f32 / camera.height as f32;
    let tan_half_x = (camera.hfov_degrees.to_radians() * 0.5).tan();
    let (_, up, forward) = camera.basis();
    (2.0 * (tan_half_x / aspect).atan(), aspect, glam::camera::rh::view::look_to_mat4(camera.eye, forward, up))
}

/// Reversed-Z projection × view with the far plane at infinity (depth = near / distance, 1 at
/// the near plane, 0 at infinity): a float depth buffer then resolves distances to the same
/// relative precision near and far. With standard Z over a 100 m ground, a box's front face
/// lost its bottom pixel rows to the ground 5 mm behind it.
#[must_use]
pub fn view_projection_reverse(camera: &scene::Camera, near: f32) -> Mat4 {
    let (fov_y, aspect, view) = view_and_fov(camera);
    glam::camera::rh::proj::directx::perspective_infinite_reverse(fov_y, aspect, near) * view
}

/// As [`view_projection`] with the far plane at infinity: what passes that draw geometry
/// extruded far beyond the scene (shadow volumes) use, so that no far plane cuts it.
#[must_use]
pub fn view_projection_infinite(camera: &scene::Camera, near: f32) -> Mat4 {
    let (fov_y, aspect, view) = view_and_fov(camera);
    glam::camera::rh::proj::directx::perspective_infinite(fov_y, aspect, near) * view
}

#[repr(C)]
#[derive(Clone, Copy, bytemuck::Pod, bytemuck::Zeroable)]
struct CameraUniform {
    view_proj: [[f32; 4]; 4],
    eye: [f32; 4],
}

/// The G-buffer pass: its pipelines, built once, rendering a [`GBuffer`] per view.
pub struct GBufferPass {
    // one pass writing all three targets, or (within 32 colour bytes a sample) position and
    // normal first, then the geometric normal where the depth is equal
    passes: Passes,
}

enum Passes {
    One(wgpu::RenderPipeline),
    Two(wgpu::RenderPipeline, wgpu::RenderPipeline),
}

/// Colour bytes a sample the one-pass G-buffer writes (three `Rgba32Float` targets).
const ONE_PASS_BYTES: u32 = 48;

impl GBufferPass {
    /// Builds the pipelines: one pass where the device allows 48 colour bytes a sample, else
    /// two (WebGPU's default limits allow 32).
    #[must_use]
    pub fn new(gpu: &Gpu) -> Self {
        if gpu.limits.max_color_attachment_bytes_per_sample >= ONE_PASS_BYTES {
            Self::one_pass(gpu)
        } else {
            Self::two_passes(gpu)
        }
    }

    /// The G-buffer in two passes whatever the device allows (what `new` builds within
    /// WebGPU's default limits); the same G-buffer as one pass.
    #[must_use]
    pub fn two_passes(gpu: &Gpu) -> Self {
        let module = Self::module(gpu);
        let surface = Self::pipeline(gpu, &module, ("vs", "fs_surface"), 2, true);
        let geometric = Self::pipeline(gpu, &module, ("vs", "fs_geometric"), 1, false);
        Self { passes: Passes::Two(surface, geometric) }
    }

    fn one_pass(gpu: &Gpu) -> Self {
        let module = Self::module(gpu);
        Self { passes: Passes::One(Self::pipeline(gpu, &module, ("vs", "fs"), 3, true)) }
    }

    fn module(gpu: &Gpu) -> wgpu::ShaderModule {
        crate::shader::module(&gpu.device, "gbuffer", include_str!("../shaders/gbuffer.wgsl"), &[])
    }

    /// A pipeline writing `targets` G-buffer targets; the first pass writes depth (reversed Z,
    /// see `view_projection_reverse`), a second one draws where it is equal.
    fn pipeline(
        gpu: &Gpu,
        module: &wgpu::ShaderModule,
        (vs, fs): (&str, &str),
        targets: usize,
        first: bool,
    ) -> wgpu::RenderPipeline {
        let targets: Vec<Option<wgpu::ColorTargetState>> = (0..targets).map(|_| Some(GBUFFER_FORMAT.into())).collect();
        gpu.render_pipeline(&wgpu::RenderPipelineDescriptor {
            label: Some("gbuffer"),
            layout: None,
            vertex: wgpu::VertexState {
                module,
                entry_point: Some(vs),
                compilation_options: Default::default(),
                buffers: &[Some(SceneGeometry::LAYOUT), Some(SceneGeometry::SURFACE_LAYOUT)],
            },
            primitive: wgpu::PrimitiveState::default(),
            depth_stencil: Some(wgpu::DepthStencilState {
                format: wgpu::TextureFormat::Depth32Float,
                depth_write_enabled: Some(first),
                depth_compare: Some(if first { wgpu::CompareFunction::Greater } else { wgpu::CompareFunction::Equal }),
                stencil: Default::default(),
                bias: Default::default(),
            }),
            multisample: Default::default(),
            fragment: Some(wgpu::FragmentState {
                module,
                entry_point: Some(fs),
                compilation_options: Default::default(),
                targets: &targets,
            }),
            multiview_mask: None,
            cache: None,
        })
    }

    /// Renders the G-buffer of `geometry` seen by `camera` and waits for it.
    ///
    /// # Errors
    /// [`GpuError::TooLarge`] for an image beyond the adapter's limits; GPU failures.
    pub fn render(&self, gpu: &Gpu, geometry: &SceneGeometry, camera: &scene::Camera) -> Result<GBuffer, GpuError> {
        let mut encoder = gpu.encoder("gbuffer");
        let gb = self.record(gpu, &mut encoder, geometry, camera)?;
        gpu.submit_and_wait(encoder)?;
        Ok(gb)
    }

    /// Records the G-buffer pass of `geometry` seen by `camera` into `encoder`, without
    /// submitting: the returned targets hold the G-buffer once the caller's submission runs.
    /// The camera's view is projected with an infinite reversed depth whose near plane scales
    /// with the scene's reach from the eye: no absolute distance, so a scene scaled by 1e-3 or
    /// 1e3 rasterizes the same.
    ///
    /// # Errors
    /// [`GpuError::TooLarge`] for an image beyond the adapter's limits.
    pub fn record(
        &self,
        gpu: &Gpu,
        encoder: &mut wgpu::CommandEncoder,
        geometry: &SceneGeometry,
        camera: &scene::Camera,
    ) -> Result<GBuffer, GpuError> {
        self.record_view(gpu, encoder, geometry, &Self::camera_view(geometry, camera))
    }

    /// The view [`GBufferPass::record`] renders `camera` from: an infinite reversed depth whose
    /// near plane scales with the scene's reach from the eye.
    #[must_use]
    pub fn camera_view(geometry: &SceneGeometry, camera: &scene::Camera) -> crate::View {
        let (lo, hi) = geometry.bounds;
        let reach = if lo.is_finite() { (hi - lo).length() + camera.eye.distance(0.5 * (lo + hi)) } else { 1.0 };
        let near = (reach * 1e-6).max(f32::MIN_POSITIVE * 1e6);
        crate::View::from_camera(camera, near)
    }

    /// Records the G-buffer pass of `geometry` seen from `view` (any projection in wgpu's clip
    /// space whose nearer depths are larger, as reversed depth has them) into `encoder`.
    ///
    /// # Errors
    /// [`GpuError::TooLarge`] for an image beyond the adapter's limits.
    pub fn record_view(
        &self,
        gpu: &Gpu,
        encoder: &mut wgpu::CommandEncoder,
        geometry: &SceneGeometry,
        view: &crate::View,
    ) -> Result<GBuffer, GpuError> {
        let targets = GBufferTargets::new(gpu, view.size())?;
        self.record_into(gpu, encoder, geometry, view, &targets)
    }

    /// Records the G-buffer pass of `geometry` seen from `view` into `targets` (made once for
    /// the view's size and rendered into frame after frame: no texture, buffer or bind group
    /// is made): the returned G-buffer shares their textures. The view goes to their camera
    /// uniform with `queue.write_buffer`, so targets hold one view a submission.
    ///
    /// # Errors
    /// [`GpuError::Failed`] for targets of another size than the view.
    pub fn record_into(
        &self,
        gpu: &Gpu,
        encoder: &mut wgpu::CommandEncoder,
        geometry: &SceneGeometry,
        view: &crate::View,
        targets: &GBufferTargets,
    ) -> Result<GBuffer, GpuError> {
        if targets.size != view.size() {
            return Err(GpuError::Failed(format!(
                "G-buffer targets of {:?} for a view of {:?}",
                targets.size,
                view.size()
            )));
        }
        geometry.record_placement(gpu, encoder);
        let gb = GBuffer {
            position: targets.position.clone(),
            normal: targets.normal.clone(),
            geometric_normal: targets.geometric_normal.clone(),
            depth: targets.depth.clone(),
            view: *view,
        };
        let uniform = CameraUniform {
            view_proj: view.view_projection().to_cols_array_2d(),
            eye: view.toward_viewer().to_array(),
        };
        gpu.queue.write_buffer(&targets.camera, 0, bytemuck::bytes_of(&uniform));
        let views = [&gb.position, &gb.normal, &gb.geometric_normal].map(|t| t.create_view(&Default::default()));
        let clear =
            [wgpu::Color { r: 0.0, g: 0.0, b: 0.0, a: -1.0 }, wgpu::Color::TRANSPARENT, wgpu::Color::TRANSPARENT];
        let attachment = |k: usize| {
            Some(wgpu::RenderPassColorAttachment {
                view: &views[k],
                depth_slice: None,
                resolve_target: None,
                ops: wgpu::Operations { load: wgpu::LoadOp::Clear(clear[k]), store: wgpu::StoreOp::Store },
            })
        };
        let depth_view = gb.depth.create_view(&Default::default());
        let (first, second) = match &self.passes {
            Passes::One(p) => (p, None),
            Passes::Two(a, b) => (a, Some(b)),
        };
        let mut draw = |pipeline: &wgpu::RenderPipeline, outputs: &[usize], depth_load: wgpu::LoadOp<f32>| {
            let bind = targets.bind_group(gpu, pipeline);
            let attachments: Vec<_> = outputs.iter().map(|&k| attachment(k)).collect();
            let mut pass = encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
                label: Some("gbuffer"),
                color_attachments: &attachments,
                depth_stencil_attachment: Some(wgpu::RenderPassDepthStencilAttachment {
                    view: &depth_view,
                    depth_ops: Some(wgpu::Operations { load: depth_load, store: wgpu::StoreOp::Store }),
                    stencil_ops: None,
                }),
                timestamp_writes: None,
                occlusion_query_set: None,
                multiview_mask: None,
            });
            pass.set_pipeline(pipeline);
            pass.set_bind_group(0, &bind, &[]);
            pass.set_vertex_buffer(0, geometry.vertices.slice(..));
            pass.set_vertex_buffer(1, geometry.surface.slice(..));
            pass.draw(0..geometry.vertex_count, 0..1);
        };
        match second {
            None => draw(first, &[0, 1, 2], wgpu::LoadOp::Clear(0.0)),
            Some(second) => {
                draw(first, &[0, 1], wgpu::LoadOp::Clear(0.0));
                draw(second, &[2], wgpu::LoadOp::Load);
            }
        }
        Ok(gb)
    }
}

/// A G-buffer's textures and camera uniform for one size, made once: what a frame renders its
/// G-buffer into every frame ([`GBufferPass::record_into`]).
pub struct GBufferTargets {
    size: (u32, u32),
    position: wgpu::Texture,
    normal: wgpu::Texture,
    geometric_normal: wgpu::Texture,
    depth: wgpu::Texture,
    camera: wgpu::Buffer,
    // the camera's bind group for each pipeline that rendered into them
    binds: std::sync::Mutex<Vec<(wgpu::RenderPipeline, wgpu::BindGroup)>>,
}

impl GBufferTargets {
    /// Targets of `width` × `height` pixels.
    ///
    /// # Errors
    /// [`GpuError::TooLarge`] for an image beyond the adapter's limits.
    pub fn new(gpu: &Gpu, (w, h): (u32, u32)) -> Result<Self, GpuError> {
        let size = (w, h, 1);
        let target = |label, format| crate::target::render_target(gpu, label, size, format);
        Ok(Self {
            size: (w, h),
            position: target("gbuffer position", GBUFFER_FORMAT)?,
            normal: target("gbuffer normal", GBUFFER_FORMAT)?,
            geometric_normal: target("gbuffer geometric normal", GBUFFER_FORMAT)?,
            depth: target("gbuffer depth", wgpu::TextureFormat::Depth32Float)?,
            camera: gpu.create_buffer(&wgpu::BufferDescriptor {
                label: Some("camera"),
                size: std::mem::size_of::<CameraUniform>() as u64,
                usage: wgpu::BufferUsages::UNIFORM | wgpu::BufferUsages::COPY_DST,
                mapped_at_creation: false,
            }),
            binds: std::sync::Mutex::default(),
        })
    }

    /// Image size.
    #[must_use]
    pub fn size(&self) -> (u32, u32) {
        self.size
    }

    /// The camera's bind group for `pipeline`, made the first time.
    fn bind_group(&self, gpu: &Gpu, pipeline: &wgpu::RenderPipeline) -> wgpu::BindGroup {
        let mut binds = self.binds.lock().unwrap_or_else(std::sync::PoisonError::into_inner);
        if let Some((_, b)) = binds.iter().find(|(p, _)| p == pipeline) {
            return b.clone();
        }
        let bind = gpu.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("gbuffer"),
            layout: &pipeline.get_bind_group_layout(0),
            entries: &[wgpu::BindGroupEntry { binding: 0, resource: self.camera.as_entire_binding() }],
        });
        binds.push((pipeline.clone(), bind.clone()));
        bind
    }
}

impl GBuffer {
    /// Image size.
    #[must_use]
    pub fn size(&self) -> (u32, u32) {
        self.view.size()
    }

    /// Reads the positions back: xyz and object index (-1 for background), row-major.
    ///
    /// # Errors
    /// GPU failures.
    pub fn read_positions(&self, gpu: &Gpu) -> Result<Vec<[f32; 4]>, GpuError> {
        crate::readback::read_texture_rgba(gpu, &self.position, 0)
    }

    /// Reads the visible surface points back as (position, geometric normal facing the camera),
    /// row-major; background pixels have a NaN position.
    ///
    /// # Errors
    /// GPU failures.
    pub fn read_points(&self, gpu: &Gpu) -> Result<Vec<(Vec3, Vec3)>, GpuError> {
        let mut encoder = gpu.encoder("gbuffer points");
        let read = self.record_points(gpu, &mut encoder)?;
        gpu.submit(encoder);
        Ok(PointsRead::finish_all(gpu, vec![read])?.swap_remove(0))
    }

    /// Records the copies [`GBuffer::read_points`] maps, so that they travel in the caller's
    /// submission; [`PointsRead::finish_all`] maps them after it.
    ///
    /// # Errors
    /// GPU failures.
    pub fn record_points(&self, gpu: &Gpu, encoder: &mut wgpu::CommandEncoder) -> Result<PointsRead, GpuError> {
        let all = wgpu::TextureAspect::All;
        Ok(PointsRead {
            position: crate::readback::PendingRead::record(gpu, encoder, &self.position, 0, all)?,
            normal: crate::readback::PendingRead::record(gpu, encoder, &self.geometric_normal, 0, all)?,
        })
    }

    /// Reads the geometric normals back, row-major.
    ///
    /// # Errors
    /// GPU failures.
    pub fn read_geometric_normals(&self, gpu: &Gpu) -> Result<Vec<[f32; 4]>, GpuError> {
        crate::readback::read_texture_rgba(gpu, &self.geometric_normal, 0)
    }
}

/// A G-buffer's points on their way back ([`GBuffer::record_points`]).
pub struct PointsRead {
    position: crate::readback::PendingRead,
    normal: crate::readback::PendingRead,
}

impl PointsRead {
    /// Maps every read (their encoders submitted) with one wait: per G-buffer its points, as
    /// [`GBuffer::read_points`].
    ///
    /// # Errors
    /// GPU failures.
    pub fn finish_all(gpu: &Gpu, reads: Vec<PointsRead>) -> Result<Vec<Vec<(Vec3, Vec3)>>, GpuError> {
        let pending: Vec<crate::readback::PendingRead> =
            reads.into_iter().flat_map(|r| [r.position, r.normal]).collect();
        let bytes = crate::readback::PendingRead::finish_all(gpu, &pending)?;
        Ok(bytes
            .chunks_exact(2)
            .map(|pair| {
                let p: Vec<[f32; 4]> = bytemuck::pod_collect_to_vec(&pair[0]);
                let n: Vec<[f32; 4]> = bytemuck::pod_collect_to_vec(&pair[1]);
                p.iter()
                    .zip(&n)
                    .map(|(p, n)| {
                        if p[3] < 0.0 {
                            (Vec3::NAN, Vec3::ZERO)
                        } else {
                            (Vec3::new(p[0], p[1], p[2]), Vec3::new(n[0], n[1], n[2]))
                        }
                    })
                    .collect()
            })
            .collect())
    }
}
