//! Interleaved sampling of light sets over the pixels (Keller and Heidrich 2001; paper 001,
//! section 3.5): with `n` sets, pixel (x, y) shows set (x mod a) + a (y mod b) of an a x b
//! tile (a b = n, as square as n allows), so every tile holds each set once and a filter over a
//! tile (or supersampling) averages the sets. Each set is drawn as a whole recorded frame
//! ([`crate::LitFrame::render_interleaved`]) and its pixels gathered into one image: the shadow
//! work is n times one set's.

use crate::context::{Gpu, GpuError};
use crate::slots::Keyed;
use std::cell::RefCell;

/// The most light sets [`crate::LitFrame::render_interleaved`] takes (each is a whole frame's
/// shadow work).
pub const MAX_SETS: u32 = 256;

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

/// The gathering pass: pipeline built once, each set count's parameters once.
pub struct InterleavePass {
    pipeline: wgpu::RenderPipeline,
    // per set count: set k's (a, b, k) at k times the uniform offset alignment, never rewritten
    // (two gathers recorded into one submission each keep their own)
    table: RefCell<Keyed<u32, wgpu::Buffer>>,
}

impl InterleavePass {
    /// Builds the pipeline.
    #[must_use]
    pub fn new(gpu: &Gpu) -> Self {
        let module = crate::shader::module(&gpu.device, "interleave", include_str!("../shaders/interleave.wgsl"), &[]);
        Self {
            pipeline: crate::fullscreen::pipeline(gpu, "interleave", &module, crate::shade::HDR_FORMAT),
            table: RefCell::default(),
        }
    }

    /// Records the copy of the pixels of set `index` of `sets` from `src` into `dst` (same
    /// size, both [`crate::HDR_FORMAT`]) into `encoder`, without submitting; `dst`'s other
    /// pixels are kept.
    ///
    /// # Errors
    /// [`GpuError::Failed`] for an index out of range or sizes that differ; more than
    /// [`MAX_SETS`]; GPU failures.
    pub fn record_gather(
        &self,
        gpu: &Gpu,
        encoder: &mut wgpu::CommandEncoder,
        (src, dst): (&wgpu::Texture, &wgpu::Texture),
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
        if sets > MAX_SETS {
            return Err(GpuError::TooLarge {
                what: "interleaved light sets",
                size: sets.into(),
                limit: MAX_SETS.into(),
            });
        }
        let stride = u64::from(gpu.device.limits().min_uniform_buffer_offset_alignment).max(16);
        let mut table = self.table.borrow_mut();
        let table = table.get(sets, || {
            let (a, b) = interleave_tile(sets);
            let mut bytes = vec![0u8; (stride * u64::from(sets)) as usize];
            for k in 0..sets {
                let at = (stride * u64::from(k)) as usize;
                bytes[at..at + 16].copy_from_slice(bytemuck::cast_slice(&[a, b, k, 0u32]));
            }
            gpu.create_buffer_init(&wgpu::util::BufferInitDescriptor {
                label: Some("interleave params"),
                contents: &bytes,
                usage: wgpu::BufferUsages::UNIFORM,
            })
        });
        let view = src.create_view(&Default::default());
        let bind = gpu.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("interleave"),
            layout: &self.pipeline.get_bind_group_layout(0),
            entries: &[
                wgpu::BindGroupEntry {
                    binding: 0,
                    resource: wgpu::BindingResource::Buffer(wgpu::BufferBinding {
                        buffer: table,
                        offset: stride * u64::from(index),
                        size: wgpu::BufferSize::new(16),
                    }),
                },
                wgpu::BindGroupEntry { binding: 1, resource: wgpu::BindingResource::TextureView(&view) },
            ],
        });
        let target = dst.create_view(&Default::default());
        crate::fullscreen::record(encoder, &self.pipeline, &bind, &target, wgpu::LoadOp::Load);
        Ok(())
    }
}
