//! Joint bilateral upsampling (Kopf et al. 2007) of an image shaded from a low-resolution
//! G-buffer to full resolution, guided by both G-buffers: how paper 001 renders its
//! low-frequency EnvIndirects (section 3.4). The result is added to a full-resolution base image
//! in the same pass.

use crate::context::{Gpu, GpuError};
use crate::gbuffer::GBuffer;
use crate::geometry::SceneGeometry;

/// The Gaussians of joint bilateral upsampling. A sigma of infinity turns its term off (all
/// range sigmas infinite: plain Gaussian upsampling).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct JointBilateral {
    /// Of the difference of unit shading normals.
    pub sigma_normal: f32,
    /// Of the difference of eye distances, relative to the full-resolution pixel's.
    pub sigma_depth: f32,
    /// Of the difference of albedos.
    pub sigma_albedo: f32,
    /// Of the distance in low-resolution pixels.
    pub sigma_spatial: f32,
    /// The window is (2 radius + 1)^2 low-resolution pixels.
    pub radius: u32,
}

impl JointBilateral {
    /// Paper 001's settings: normal, depth and albedo sigma 0.005, spatial sigma 1, a 5 x 5
    /// window.
    pub const PAPER: Self =
        Self { sigma_normal: 0.005, sigma_depth: 0.005, sigma_albedo: 0.005, sigma_spatial: 1.0, radius: 2 };
    /// No guidance: the spatial Gaussian alone, over the same window (what the G-buffer terms
    /// buy is measured against it).
    pub const GAUSSIAN: Self = Self {
        sigma_normal: f32::INFINITY,
        sigma_depth: f32::INFINITY,
        sigma_albedo: f32::INFINITY,
        sigma_spatial: 1.0,
        radius: 2,
    };
    /// Largest window radius accepted.
    pub const MAX_RADIUS: u32 = 8;
}

impl Default for JointBilateral {
    fn default() -> Self {
        Self::PAPER
    }
}

/// 1 / (2 sigma^2), 0 for an infinite or non-finite sigma; an error for a non-positive one.
fn inverse(name: &str, sigma: f32) -> Result<f32, GpuError> {
    if sigma.is_nan() || sigma <= 0.0 {
        return Err(GpuError::Failed(format!("upsampling: sigma of {name} must be positive, got {sigma}")));
    }
    let v = 1.0 / (2.0 * sigma * sigma);
    Ok(if v.is_finite() { v } else { f32::MAX })
}

#[repr(C)]
#[derive(Clone, Copy, bytemuck::Pod, bytemuck::Zeroable)]
struct Uniform {
    eye: [f32; 4],
    inv_two_sigma2: [f32; 4],
    info: [u32; 4],
}

/// The upsampling pass: pipeline built once.
pub struct UpsamplePass {
    pipeline: wgpu::RenderPipeline,
    // each upsampling of a submission's uniform and bind group, kept from frame to frame
    slots: crate::Slots<UpsampleSlot>,
}

/// One upsampling's uniform and the bind group over it, the materials and the six textures.
struct UpsampleSlot {
    uniform: wgpu::Buffer,
    bind: crate::Keyed<(wgpu::Buffer, [wgpu::Texture; 6]), wgpu::BindGroup>,
}

impl UpsamplePass {
    /// Builds the pipeline.
    #[must_use]
    pub fn new(gpu: &Gpu) -> Self {
        let module = crate::shader::module(&gpu.device, "upsample", include_str!("../shaders/upsample.wgsl"), &[]);
        Self {
            pipeline: crate::fullscreen::pipeline(gpu, "upsample", &module, crate::shade::HDR_FORMAT),
            slots: crate::Slots::new(),
        }
    }

    /// `base` + `low` upsampled: `low` was shaded from `low_gb`, whose size is `high_gb`'s
    /// divided by an integer factor. Returns a new full-resolution HDR texture, waited for.
    ///
    /// # Errors
    /// As [`UpsamplePass::record`]; GPU failures.
    pub fn render(
        &self,
        gpu: &Gpu,
        geometry: &SceneGeometry,
        low: (&GBuffer, &wgpu::Texture),
        high: (&GBuffer, &wgpu::Texture),
        settings: &JointBilateral,
    ) -> Result<wgpu::Texture, GpuError> {
        let mut encoder = gpu.encoder("upsample");
        let output = self.record(gpu, &mut encoder, geometry, low, high, settings)?;
        gpu.submit_and_wait(encoder)?;
        Ok(output)
    }

    /// Records [`UpsamplePass::render`] into `encoder` without submitting, into a new texture.
    ///
    /// # Errors
    /// As [`UpsamplePass::record_into`]; an image beyond the limits.
    pub fn record(
        &self,
        gpu: &Gpu,
        encoder: &mut wgpu::CommandEncoder,
        geometry: &SceneGeometry,
        low: (&GBuffer, &wgpu::Texture),
        high: (&GBuffer, &wgpu::Texture),
        settings: &JointBilateral,
    ) -> Result<wgpu::Texture, GpuError> {
        let (hw, hh) = high.0.size();
        let output = crate::target::render_target(gpu, "upsampled", (hw, hh, 1), crate::shade::HDR_FORMAT)?;
        self.record_into(gpu, encoder, geometry, low, high, settings, &output)?;
        Ok(output)
    }

    /// Records [`UpsamplePass::render`] into `encoder` without submitting, into `output` (an
    /// [`crate::HDR_FORMAT`] render target of the high G-buffer's size, made once by the
    /// caller). Its uniform and bind group are made once and rewritten frame after frame.
    ///
    /// # Errors
    /// [`GpuError::Failed`] for sizes that are not an integer factor apart, an `output` of
    /// another size or format, a non-positive sigma or a radius over
    /// [`JointBilateral::MAX_RADIUS`].
    #[allow(clippy::too_many_arguments)]
    pub fn record_into(
        &self,
        gpu: &Gpu,
        encoder: &mut wgpu::CommandEncoder,
        geometry: &SceneGeometry,
        (low_gb, low): (&GBuffer, &wgpu::Texture),
        (high_gb, base): (&GBuffer, &wgpu::Texture),
        settings: &JointBilateral,
        output: &wgpu::Texture,
    ) -> Result<(), GpuError> {
        let (lw, lh) = low_gb.size();
        let (hw, hh) = high_gb.size();
        let factor = hw / lw.max(1);
        if lw == 0 || factor == 0 || lw * factor != hw || lh * factor != hh || low.width() != lw || base.width() != hw {
            return Err(GpuError::Failed(format!(
                "upsampling: {lw}x{lh} to {hw}x{hh} is not a whole factor (images {}x{} and {}x{})",
                low.width(),
                low.height(),
                base.width(),
                base.height()
            )));
        }
        if settings.radius > JointBilateral::MAX_RADIUS {
            return Err(GpuError::Failed(format!(
                "upsampling: radius {} is over {}",
                settings.radius,
                JointBilateral::MAX_RADIUS
            )));
        }
        let s = settings;
        let uniform = Uniform {
            eye: high_gb.view.eye().extend(1.0).to_array(),
            inv_two_sigma2: [
                inverse("normal", s.sigma_normal)?,
                inverse("depth", s.sigma_depth)?,
                inverse("albedo", s.sigma_albedo)?,
                inverse("spatial", s.sigma_spatial)?,
            ]
            .map(|v| if v == f32::MAX { 0.0 } else { v }),
            info: [factor, s.radius, lw, lh],
        };
        if (output.width(), output.height()) != (hw, hh) || output.format() != crate::shade::HDR_FORMAT {
            return Err(GpuError::Failed(format!(
                "upsampling into a {}x{} {:?} target: wants {hw}x{hh} {:?}",
                output.width(),
                output.height(),
                output.format(),
                crate::shade::HDR_FORMAT
            )));
        }
        let textures =
            [&low_gb.position, &low_gb.normal, low, &high_gb.position, &high_gb.normal, base].map(Clone::clone);
        let make = || UpsampleSlot {
            uniform: crate::slots::writable_buffer(
                gpu,
                "upsample params",
                wgpu::BufferUsages::UNIFORM,
                std::mem::size_of::<Uniform>() as u64,
            ),
            bind: crate::Keyed::default(),
        };
        let bind = self.slots.next_or_own(gpu, make, |slot| {
            gpu.queue.write_buffer(&slot.uniform, 0, bytemuck::bytes_of(&uniform));
            let uniform = &slot.uniform;
            slot.bind
                .get((geometry.materials.clone(), textures.clone()), || {
                    let views = textures.each_ref().map(|t| t.create_view(&Default::default()));
                    let mut entries = vec![
                        wgpu::BindGroupEntry { binding: 0, resource: uniform.as_entire_binding() },
                        wgpu::BindGroupEntry { binding: 1, resource: geometry.materials.as_entire_binding() },
                    ];
                    for (k, v) in views.iter().enumerate() {
                        entries.push(wgpu::BindGroupEntry {
                            binding: 2 + k as u32,
                            resource: wgpu::BindingResource::TextureView(v),
                        });
                    }
                    gpu.create_bind_group(&wgpu::BindGroupDescriptor {
                        label: Some("upsample"),
                        layout: &self.pipeline.get_bind_group_layout(0),
                        entries: &entries,
                    })
                })
                .clone()
        });
        crate::fullscreen::record(
            encoder,
            &self.pipeline,
            &bind,
            &output.create_view(&Default::default()),
            wgpu::LoadOp::Clear(wgpu::Color::BLACK),
        );
        Ok(())
    }
}
