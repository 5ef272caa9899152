//! Additive accumulation of per-pixel terms and its resolve into a visibility layer: shadow
//! techniques that sum several passes (N shadow maps averaged; a hard count and wedge terms)
//! blend into an [`Accumulator`] and [`ResolvePass`] turns it into visibility.
//!
//! The accumulator is `Rg32Float` where the adapter can blend 32-bit floats
//! (`FLOAT32_BLENDABLE`), else `Rg16Float` (whole counts stay exact; sums of fractions carry
//! about 1e-3 error, stated by [`Accumulator::format`]).

use crate::context::{Gpu, GpuError};
use crate::gbuffer::GBuffer;
use wgpu::util::DeviceExt;

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

/// How [`ResolvePass`] turns the accumulated channels into visibility.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Resolve {
    /// `clamp(r × scale)`: e.g. the mean of N lit tests with scale 1/N.
    Scale(f32),
    /// `clamp(1 − w + g)` with `w = 1` where the hard count `r` is not 0 (penumbra wedges) for
    /// this light, divided by the fraction of its disk above the surface's own plane (the
    /// shading's cone integral already leaves that part out; casters the point lies on hide
    /// it from the wedge sum).
    Wedges(crate::LightShape),
}

/// The resolve pass: pipeline built once.
pub struct ResolvePass {
    pipeline: wgpu::RenderPipeline,
}

impl ResolvePass {
    /// Builds the pipeline.
    #[must_use]
    pub fn new(gpu: &Gpu) -> Self {
        let module =
            crate::shader::module(&gpu.device, "resolve", include_str!("../../../shaders/gpu/resolve.wgsl"), &[]);
        Self { pipeline: crate::fullscreen::pipeline(gpu, "resolve", &module, crate::shade::Visibility::FORMAT) }
    }

    /// Records the resolve of `acc` into `target` (a visibility layer) into `encoder`.
    pub fn record(
        &self,
        gpu: &Gpu,
        encoder: &mut wgpu::CommandEncoder,
        gbuffer: &GBuffer,
        acc: &Accumulator,
        how: Resolve,
        target: &wgpu::TextureView,
    ) {
        let config: [[f32; 4]; 3] = match how {
            Resolve::Scale(s) => [[0.0, s, 0.0, 0.0], [0.0; 4], [0.0; 4]],
            Resolve::Wedges(crate::LightShape::Distant { direction, half_angle }) => [
                [1.0, 1.0, 0.0, 0.0],
                direction.normalize_or(glam::Vec3::Y).extend(0.0).to_array(),
                [0.0, half_angle, 0.0, 0.0],
            ],
            Resolve::Wedges(crate::LightShape::Sphere { center, radius }) => {
                [[1.0, 1.0, 0.0, 0.0], center.extend(1.0).to_array(), [1.0, radius, 0.0, 0.0]]
            }
        };
        let buffer = gpu.device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
            label: Some("resolve"),
            contents: bytemuck::cast_slice(&config),
            usage: wgpu::BufferUsages::UNIFORM,
        });
        let position = gbuffer.position.create_view(&Default::default());
        let normal = gbuffer.geometric_normal.create_view(&Default::default());
        let bind = gpu.device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("resolve"),
            layout: &self.pipeline.get_bind_group_layout(0),
            entries: &[
                wgpu::BindGroupEntry { binding: 0, resource: buffer.as_entire_binding() },
                wgpu::BindGroupEntry { binding: 1, resource: wgpu::BindingResource::TextureView(&position) },
                wgpu::BindGroupEntry { binding: 2, resource: wgpu::BindingResource::TextureView(&normal) },
                wgpu::BindGroupEntry { binding: 3, resource: wgpu::BindingResource::TextureView(&acc.view) },
            ],
        });
        let mut pass = encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
            label: Some("resolve"),
            color_attachments: &[Some(wgpu::RenderPassColorAttachment {
                view: target,
                depth_slice: None,
                resolve_target: None,
                ops: wgpu::Operations { load: wgpu::LoadOp::Clear(wgpu::Color::WHITE), store: wgpu::StoreOp::Store },
            })],
            ..Default::default()
        });
        pass.set_pipeline(&self.pipeline);
        pass.set_bind_group(0, &bind, &[]);
        pass.draw(0..3, 0..1);
    }
}
