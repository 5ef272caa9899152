//! Additive accumulation of per-pixel terms and its resolve into a visibility layer: shadow
//! techniques that sum several passes (N shadow maps averaged; a hard count and wedge terms)
//! blend into an [`Accumulator`] and a [`ResolvePass`] turns it into visibility.
//!
//! The accumulator is `Rg32Float` where the adapter can blend 32-bit floats
//! (`FLOAT32_BLENDABLE`), else `Rg16Float` (whole counts stay exact; sums of fractions carry
//! about 1e-3 error, stated by [`Accumulator::format`]).

use crate::context::{Gpu, GpuError};
use crate::gbuffer::GBuffer;

/// Blend state adding a pass's output to what the accumulator holds.
pub const ADD: wgpu::BlendState = wgpu::BlendState {
    color: wgpu::BlendComponent {
        src_factor: wgpu::BlendFactor::One,
        dst_factor: wgpu::BlendFactor::One,
        operation: wgpu::BlendOperation::Add,
    },
    alpha: wgpu::BlendComponent {
        src_factor: wgpu::BlendFactor::One,
        dst_factor: wgpu::BlendFactor::One,
        operation: wgpu::BlendOperation::Add,
    },
};

/// A screen-sized two-channel float target that passes add into.
#[derive(Clone)]
pub struct Accumulator {
    /// The texture (`format`).
    pub texture: wgpu::Texture,
    /// A view of it, to render into and to read.
    pub view: wgpu::TextureView,
}

impl Accumulator {
    /// The format on this adapter: `Rg32Float` where blendable, else `Rg16Float`.
    #[must_use]
    pub fn format(gpu: &Gpu) -> wgpu::TextureFormat {
        if gpu.features.contains(wgpu::Features::FLOAT32_BLENDABLE) {
            wgpu::TextureFormat::Rg32Float
        } else {
            wgpu::TextureFormat::Rg16Float
        }
    }

    /// A `width` × `height` accumulator (contents undefined until a pass clears it).
    ///
    /// # Errors
    /// [`GpuError::TooLarge`] beyond the adapter's limits.
    pub fn new(gpu: &Gpu, (width, height): (u32, u32)) -> Result<Self, GpuError> {
        let texture = crate::target::render_target(gpu, "accumulator", (width, height, 1), Self::format(gpu))?;
        let view = texture.create_view(&Default::default());
        Ok(Self { texture, view })
    }

    /// A colour attachment of it: cleared to 0 when `clear`, else loaded.
    #[must_use]
    pub fn attachment(&self, clear: bool) -> wgpu::RenderPassColorAttachment<'_> {
        wgpu::RenderPassColorAttachment {
            view: &self.view,
            depth_slice: None,
            resolve_target: None,
            ops: wgpu::Operations {
                load: if clear { wgpu::LoadOp::Clear(wgpu::Color::TRANSPARENT) } else { wgpu::LoadOp::Load },
                store: wgpu::StoreOp::Store,
            },
        }
    }

    /// The colour target state of a pipeline adding into it.
    #[must_use]
    pub fn target(gpu: &Gpu) -> wgpu::ColorTargetState {
        wgpu::ColorTargetState {
            format: Self::format(gpu),
            blend: Some(ADD),
            write_mask: wgpu::ColorWrites::RED | wgpu::ColorWrites::GREEN,
        }
    }
}

/// The resolve pass: a full-screen pass reading the accumulator and writing a visibility
/// layer. Its shader binds the pass's uniform at 0, the G-buffer positions at 1 and the
/// accumulator at 2 (and any extra bindings its caller passes); the default one writes the mean
/// of N lit tests, `clamp(r × scale)`. Techniques with their own resolve (penumbra wedges) bring
/// their shader.
pub struct ResolvePass {
    pipeline: wgpu::RenderPipeline,
    // each light's parameters and bind group, kept from frame to frame
    slots: crate::Slots<ResolveSlot>,
}

/// One light's resolve: its uniform and the bind group over it and the textures it reads.
struct ResolveSlot {
    params: wgpu::Buffer,
    bind: crate::Keyed<Vec<wgpu::Texture>, wgpu::BindGroup>,
}

impl ResolvePass {
    /// The mean of N lit tests: `clamp(r × scale)` (`crates/gpu/shaders/resolve.wgsl`).
    #[must_use]
    pub fn new(gpu: &Gpu) -> Self {
        Self::with_shader(gpu, "resolve", include_str!("../shaders/resolve.wgsl"), &[])
    }

    /// A resolve pass with its own fragment shader (`library`: WGSL files its `// requires:`
    /// lines name outside this crate).
    #[must_use]
    pub fn with_shader(gpu: &Gpu, label: &str, source: &str, library: &[(&str, &str)]) -> Self {
        let module = crate::shader::module(&gpu.device, label, source, library);
        Self {
            pipeline: crate::fullscreen::pipeline(gpu, label, &module, crate::shade::VisibilityLayers::FORMAT),
            slots: crate::Slots::new(),
        }
    }

    /// Records the resolve of `acc` into `target` (a visibility layer): `params` is the
    /// uniform at binding 0 (at most 256 bytes), `extra` the textures of further bindings the
    /// shader reads (whole, as their default views); `call`: the triangle as call `k` of a
    /// light's [`crate::Calls`] (gated), or `None` to draw it. Each light of a submission keeps
    /// its uniform and bind group from frame to frame ([`crate::Slots`]).
    ///
    /// # Errors
    /// [`GpuError::TooLarge`] for parameters over 256 bytes.
    #[allow(clippy::too_many_arguments)]
    pub fn record(
        &self,
        gpu: &Gpu,
        encoder: &mut wgpu::CommandEncoder,
        gbuffer: &GBuffer,
        acc: &Accumulator,
        params: &[u8],
        extra: &[(u32, &wgpu::Texture)],
        call: Option<(&crate::Calls, usize)>,
        target: &wgpu::TextureView,
    ) -> Result<(), GpuError> {
        const PARAMS: u64 = 256;
        if params.len() as u64 > PARAMS || !params.len().is_multiple_of(4) {
            return Err(GpuError::TooLarge {
                what: "resolve parameter bytes",
                size: params.len() as u64,
                limit: PARAMS,
            });
        }
        let make = || ResolveSlot {
            params: gpu.create_buffer(&wgpu::BufferDescriptor {
                label: Some("resolve"),
                size: PARAMS,
                usage: wgpu::BufferUsages::UNIFORM | wgpu::BufferUsages::COPY_DST,
                mapped_at_creation: false,
            }),
            bind: crate::Keyed::default(),
        };
        let bind = self.slots.next_or_own(gpu, make, |slot| {
            gpu.queue.write_buffer(&slot.params, 0, params);
            let key: Vec<wgpu::Texture> =
                [&gbuffer.position, &acc.texture].into_iter().chain(extra.iter().map(|(_, t)| *t)).cloned().collect();
            let buffer = slot.params.clone();
            let bind = slot.bind.get(key, || {
                let views: Vec<wgpu::TextureView> =
                    extra.iter().map(|(_, t)| t.create_view(&Default::default())).collect();
                let position = gbuffer.position.create_view(&Default::default());
                let mut entries = vec![
                    wgpu::BindGroupEntry { binding: 0, resource: buffer.as_entire_binding() },
                    wgpu::BindGroupEntry { binding: 1, resource: wgpu::BindingResource::TextureView(&position) },
                    wgpu::BindGroupEntry { binding: 2, resource: wgpu::BindingResource::TextureView(&acc.view) },
                ];
                entries.extend(extra.iter().zip(&views).map(|((binding, _), view)| wgpu::BindGroupEntry {
                    binding: *binding,
                    resource: wgpu::BindingResource::TextureView(view),
                }));
                gpu.create_bind_group(&wgpu::BindGroupDescriptor {
                    label: Some("resolve"),
                    layout: &self.pipeline.get_bind_group_layout(0),
                    entries: &entries,
                })
            });
            bind.clone()
        });
        let clear = wgpu::LoadOp::Clear(wgpu::Color::WHITE);
        match call {
            Some(call) => crate::fullscreen::record_calls(encoder, &self.pipeline, &bind, target, clear, call),
            None => crate::fullscreen::record(encoder, &self.pipeline, &bind, target, clear),
        }
        Ok(())
    }
}
