//! The display pass: the frame's HDR image tone mapped into the window's (or an offscreen)
//! 8-bit target, recorded into the frame's encoder, and the screenshot read back from it.

use gpu::{Gpu, GpuError, PendingRead};
use std::cell::RefCell;

/// The tone-mapping pass for one target format.
pub(crate) struct Display {
    pipeline: wgpu::RenderPipeline,
    params: wgpu::Buffer,
    format: wgpu::TextureFormat,
    // the frame's image is the same texture frame after frame: its bind group is made once
    bound: RefCell<Option<(wgpu::Texture, wgpu::BindGroup)>>,
}

/// The uniform block of `shaders/display.wgsl`.
#[repr(C)]
#[derive(Clone, Copy, bytemuck::Pod, bytemuck::Zeroable)]
struct Params {
    exposure: f32,
    encode: u32,
    pad: [u32; 2],
}

impl Display {
    /// The pass writing `format` (an 8-bit RGBA or BGRA format, sRGB or not).
    pub(crate) fn new(gpu: &Gpu, format: wgpu::TextureFormat) -> Self {
        let module = gpu::shader::module(&gpu.device, "display", include_str!("../../shaders/display.wgsl"), &[]);
        let pipeline = gpu::fullscreen::pipeline(gpu, "display", &module, format);
        let params = gpu.create_buffer(&wgpu::BufferDescriptor {
            label: Some("display params"),
            size: std::mem::size_of::<Params>() as u64,
            usage: wgpu::BufferUsages::UNIFORM | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });
        Self { pipeline, params, format, bound: RefCell::new(None) }
    }

    /// Records `frame` (an HDR image of the target's size) tone mapped at `exposure` into
    /// `target`.
    pub(crate) fn record(
        &self,
        gpu: &Gpu,
        encoder: &mut wgpu::CommandEncoder,
        frame: &wgpu::Texture,
        exposure: f32,
        target: &wgpu::TextureView,
    ) {
        let params = Params { exposure, encode: u32::from(!self.format.is_srgb()), pad: [0; 2] };
        gpu.queue.write_buffer(&self.params, 0, bytemuck::bytes_of(&params));
        let mut bound = self.bound.borrow_mut();
        if bound.as_ref().is_none_or(|(t, _)| t != frame) {
            let view = frame.create_view(&wgpu::TextureViewDescriptor::default());
            let group = gpu.create_bind_group(&wgpu::BindGroupDescriptor {
                label: Some("display"),
                layout: &self.pipeline.get_bind_group_layout(0),
                entries: &[
                    wgpu::BindGroupEntry { binding: 0, resource: self.params.as_entire_binding() },
                    wgpu::BindGroupEntry { binding: 1, resource: wgpu::BindingResource::TextureView(&view) },
                ],
            });
            *bound = Some((frame.clone(), group));
        }
        if let Some((_, group)) = bound.as_ref() {
            gpu::fullscreen::record(encoder, &self.pipeline, group, target, wgpu::LoadOp::Clear(wgpu::Color::BLACK));
        }
    }
}

/// An offscreen target for the display pass: what a window shows, without one (`--offscreen`,
/// and screenshots from a surface that cannot be copied).
pub(crate) fn offscreen_target(gpu: &Gpu, size: (u32, u32), format: wgpu::TextureFormat) -> wgpu::Texture {
    gpu.create_texture(&wgpu::TextureDescriptor {
        label: Some("display target"),
        size: wgpu::Extent3d { width: size.0, height: size.1, depth_or_array_layers: 1 },
        mip_level_count: 1,
        sample_count: 1,
        dimension: wgpu::TextureDimension::D2,
        format,
        usage: wgpu::TextureUsages::RENDER_ATTACHMENT | wgpu::TextureUsages::COPY_SRC,
        view_formats: &[],
    })
}

/// A screenshot's copy recorded into the frame's encoder: read it once the frame is submitted.
pub(crate) struct PendingShot {
    read: PendingRead,
    format: wgpu::TextureFormat,
    size: (u32, u32),
}

impl PendingShot {
    /// Records the copy of `texture` (the display pass's target: 8-bit RGBA or BGRA).
    ///
    /// # Errors
    /// A format that cannot be copied back.
    pub(crate) fn record(
        gpu: &Gpu,
        encoder: &mut wgpu::CommandEncoder,
        texture: &wgpu::Texture,
    ) -> Result<Self, GpuError> {
        let read = PendingRead::record(gpu, encoder, texture, 0, wgpu::TextureAspect::All)?;
        Ok(Self { read, format: texture.format(), size: (texture.width(), texture.height()) })
    }

    /// The image as 8-bit RGB rows (waits for the frame: a screenshot, not a frame's work).
    ///
    /// # Errors
    /// GPU failures; a format other than 8-bit RGBA or BGRA.
    pub(crate) fn finish(self, gpu: &Gpu) -> Result<((u32, u32), Vec<u8>), GpuError> {
        use wgpu::TextureFormat as F;
        let bgra = match self.format {
            F::Rgba8Unorm | F::Rgba8UnormSrgb => false,
            F::Bgra8Unorm | F::Bgra8UnormSrgb => true,
            other => return Err(GpuError::Failed(format!("cannot save a screenshot of {other:?}"))),
        };
        let bytes = PendingRead::finish_all(gpu, &[self.read])?.swap_remove(0);
        let rgb =
            bytes.chunks_exact(4).flat_map(|p| if bgra { [p[2], p[1], p[0]] } else { [p[0], p[1], p[2]] }).collect();
        Ok((self.size, rgb))
    }
}
