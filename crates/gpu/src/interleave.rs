//! Interleaved sampling of light sets over the pixels (Keller and Heidrich 2001; paper 001,
//! section 3.5): with `n` sets, pixel (x, y) shows set (x mod a) + a (y mod b) of an a x b
//! tile (a b = n, as square as n allows), so every tile holds each set once and a filter over a
//! tile (or supersampling) averages the sets. Each set is rendered whole and its pixels gathered
//! into one image: the shadow work is n times one set's.

use crate::context::{Gpu, GpuError};
use wgpu::util::DeviceExt;

/// The tile (a, b) of `sets` sets: b the largest divisor of `sets` not above its square root.
#[must_use]
pub fn interleave_tile(sets: u32) -> (u32, u32) {
    let sets = sets.max(1);
    let b = (1..=sets).filter(|b| sets.is_multiple_of(*b) && b * b <= sets).max().unwrap_or(1);
    (sets / b, b)
}

/// The set pixel (x, y) shows.
#[must_use]
pub fn interleave_set(x: u32, y: u32, sets: u32) -> u32 {
    let (a, b) = interleave_tile(sets);
    x % a + a * (y % b)
}

/// The gathering pass: pipeline built once.
pub struct InterleavePass {
    pipeline: wgpu::RenderPipeline,
}

impl InterleavePass {
    /// Builds the pipeline.
    #[must_use]
    pub fn new(gpu: &Gpu) -> Self {
        let module =
            crate::shader::module(&gpu.device, "interleave", include_str!("../../../shaders/gpu/interleave.wgsl"), &[]);
        Self { pipeline: crate::fullscreen::pipeline(gpu, "interleave", &module, crate::shade::HDR_FORMAT) }
    }

    /// Copies the pixels of set `index` of `sets` from `src` into `dst` (same size, both
    /// [`crate::HDR_FORMAT`]); `dst`'s other pixels are kept.
    ///
    /// # Errors
    /// [`GpuError::Failed`] for an index out of range or sizes that differ; GPU failures.
    pub fn gather(
        &self,
        gpu: &Gpu,
        src: &wgpu::Texture,
        dst: &wgpu::Texture,
        sets: u32,
        index: u32,
    ) -> Result<(), GpuError> {
        if index >= sets || src.size() != dst.size() {
            return Err(GpuError::Failed(format!(
                "interleaving: set {index} of {sets}, images {:?} and {:?}",
                src.size(),
                dst.size()
            )));
        }
        let (a, b) = interleave_tile(sets);
        let buffer = gpu.device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
            label: Some("interleave params"),
            contents: bytemuck::cast_slice(&[a, b, index, 0u32]),
            usage: wgpu::BufferUsages::UNIFORM,
        });
        let view = src.create_view(&Default::default());
        let bind = gpu.device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("interleave"),
            layout: &self.pipeline.get_bind_group_layout(0),
            entries: &[
                wgpu::BindGroupEntry { binding: 0, resource: buffer.as_entire_binding() },
                wgpu::BindGroupEntry { binding: 1, resource: wgpu::BindingResource::TextureView(&view) },
            ],
        });
        crate::fullscreen::draw_over(gpu, &self.pipeline, &bind, &dst.create_view(&Default::default()))
    }
}
