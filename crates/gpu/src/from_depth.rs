//! A G-buffer from what a renderer already has: its depth texture and its view. Positions are
//! unprojected at each pixel's centre; geometric normals come from the neighbours on the same
//! surface; shading normals are the renderer's own when it has them.

use crate::context::{Gpu, GpuError};
use crate::gbuffer::{GBUFFER_FORMAT, GBuffer};
use crate::view::View;

#[repr(C)]
#[derive(Clone, Copy, bytemuck::Pod, bytemuck::Zeroable)]
struct Params {
    inverse_view_proj: [[f32; 4]; 4],
    toward_viewer: [f32; 4],
    info: [f32; 4],
}

/// The pass that turns a depth texture and a [`View`] into a [`GBuffer`]; its pipeline is built
/// once.
pub struct DepthGBufferPass {
    pipeline: wgpu::RenderPipeline,
}

impl DepthGBufferPass {
    /// Builds the pipeline (two `Rgba32Float` targets: 32 colour bytes a sample, within
    /// WebGPU's default limits).
    #[must_use]
    pub fn new(gpu: &Gpu) -> Self {
        let module =
            crate::shader::module(&gpu.device, "gbuffer from depth", include_str!("../shaders/from_depth.wgsl"), &[]);
        let targets = [Some(GBUFFER_FORMAT.into()), Some(GBUFFER_FORMAT.into())];
        let pipeline = crate::fullscreen::pipeline_with_targets(gpu, "gbuffer from depth", &module, &targets);
        Self { pipeline }
    }

    /// Records the G-buffer of `depth` (a depth or depth-stencil texture of `view`'s size,
    /// cleared to [`View::far_depth`] where nothing was drawn) seen from `view` into
    /// `encoder`. `normal` is the renderer's shading normal (`Rgba32Float`, xyz facing the
    /// viewer); without one the geometric normal serves. Pixel (x, y) is unprojected at its
    /// centre, as the rasterizer samples it: a jittered view's jitter belongs in its
    /// projection. Every pixel's object index is 0.
    ///
    /// # Errors
    /// [`GpuError::Failed`] for a texture without depth or of another size than the view's, a
    /// normal texture of another size or format; [`GpuError::TooLarge`] beyond the adapter's
    /// limits.
    pub fn record(
        &self,
        gpu: &Gpu,
        encoder: &mut wgpu::CommandEncoder,
        depth: &wgpu::Texture,
        view: &View,
        normal: Option<&wgpu::Texture>,
    ) -> Result<GBuffer, GpuError> {
        let (w, h) = view.size();
        if !depth.format().has_depth_aspect() {
            return Err(GpuError::Failed(format!("G-buffer from depth: {:?} has no depth", depth.format())));
        }
        if (depth.width(), depth.height()) != (w, h) {
            return Err(GpuError::Failed(format!(
                "G-buffer from depth: a {}x{} depth texture for a {w}x{h} view",
                depth.width(),
                depth.height()
            )));
        }
        if let Some(n) = normal
            && ((n.width(), n.height()) != (w, h) || n.format() != GBUFFER_FORMAT)
        {
            return Err(GpuError::Failed(format!(
                "G-buffer from depth: normals of {}x{} {:?} for a {w}x{h} view ({GBUFFER_FORMAT:?} needed)",
                n.width(),
                n.height(),
                n.format()
            )));
        }
        let target = |label| crate::target::render_target(gpu, label, (w, h, 1), GBUFFER_FORMAT);
        let position = target("gbuffer position from depth")?;
        let geometric = target("gbuffer geometric normal from depth")?;
        let params = Params {
            inverse_view_proj: view.view_projection().inverse().to_cols_array_2d(),
            toward_viewer: view.toward_viewer().to_array(),
            info: [view.far_depth(), w as f32, h as f32, 0.0],
        };
        let buffer = gpu.create_buffer_init(&wgpu::util::BufferInitDescriptor {
            label: Some("gbuffer from depth"),
            contents: bytemuck::bytes_of(&params),
            usage: wgpu::BufferUsages::UNIFORM,
        });
        let depth_view = depth
            .create_view(&wgpu::TextureViewDescriptor { aspect: wgpu::TextureAspect::DepthOnly, ..Default::default() });
        let bind = gpu.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("gbuffer from depth"),
            layout: &self.pipeline.get_bind_group_layout(0),
            entries: &[
                wgpu::BindGroupEntry { binding: 0, resource: buffer.as_entire_binding() },
                wgpu::BindGroupEntry { binding: 1, resource: wgpu::BindingResource::TextureView(&depth_view) },
            ],
        });
        let views = [&position, &geometric].map(|t| t.create_view(&Default::default()));
        let attachments = views.each_ref().map(|v| {
            Some(wgpu::RenderPassColorAttachment {
                view: v,
                depth_slice: None,
                resolve_target: None,
                ops: wgpu::Operations {
                    load: wgpu::LoadOp::Clear(wgpu::Color::TRANSPARENT),
                    store: wgpu::StoreOp::Store,
                },
            })
        });
        {
            let mut pass = encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
                label: Some("gbuffer from depth"),
                color_attachments: &attachments,
                depth_stencil_attachment: None,
                timestamp_writes: None,
                occlusion_query_set: None,
                multiview_mask: None,
            });
            pass.set_pipeline(&self.pipeline);
            pass.set_bind_group(0, &bind, &[]);
            pass.draw(0..3, 0..1);
        }
        Ok(GBuffer {
            position,
            normal: normal.cloned().unwrap_or_else(|| geometric.clone()),
            geometric_normal: geometric,
            depth: depth.clone(),
            view: *view,
        })
    }
}
