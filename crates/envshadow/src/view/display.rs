//! The display pass: the frame's HDR image tone mapped into the window's (or an offscreen)
//! 8-bit target, recorded into the frame's encoder, and the screenshot read back from it. It
//! shows the frame, the reference of the same view, or their difference.

use gpu::{Gpu, GpuError, PendingRead};
use std::cell::RefCell;

/// The tone-mapping pass for one target format.
pub(crate) struct Display {
    pipeline: wgpu::RenderPipeline,
    params: wgpu::Buffer,
    format: wgpu::TextureFormat,
    // the frame's image is the same texture frame after frame: its bind group is made once
    // (and again for another reference)
    bound: RefCell<Option<(wgpu::Texture, wgpu::Texture, wgpu::BindGroup)>>,
    /// Bound where no reference is shown.
    no_reference: wgpu::Texture,
}

/// What the display shows.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub(crate) enum Shown {
    /// The frame.
    #[default]
    Frame,
    /// The reference of the same view.
    Reference,
    /// The frame's luminance minus the reference's, after the display's curve: red where the
    /// frame is brighter, blue where darker, full at [`DIFFERENCE_SCALE`].
    Difference,
}

impl Shown {
    pub(crate) const ALL: [Self; 3] = [Self::Frame, Self::Reference, Self::Difference];

    pub(crate) fn name(self) -> &'static str {
        match self {
            Self::Frame => "frame",
            Self::Reference => "reference",
            Self::Difference => "difference",
        }
    }

    /// The view named `name`.
    ///
    /// # Errors
    /// An unknown name, listing the known ones.
    pub(crate) fn parse(name: &str) -> Result<Self, String> {
        super::named(&Self::ALL, Self::name, "view", name)
    }

    /// The next one in [`Shown::ALL`].
    pub(crate) fn next(self) -> Self {
        super::after(&Self::ALL, self)
    }

    fn mode(self) -> u32 {
        match self {
            Self::Frame => 0,
            Self::Reference => 1,
            Self::Difference => 2,
        }
    }
}

/// The difference view's full colour, in display values (the tone curve's 0 to 1).
pub(crate) const DIFFERENCE_SCALE: f32 = 0.25;

/// An HDR image (the reference) as a texture the display pass reads.
///
/// # Errors
/// A size beyond the adapter's limits, or pixels that are not `size`'s.
pub(crate) fn upload_hdr(gpu: &Gpu, size: (u32, u32), pixels: &[glam::Vec3]) -> Result<wgpu::Texture, GpuError> {
    if pixels.len() != size.0 as usize * size.1 as usize {
        return Err(GpuError::Failed(format!("{} pixels for a {}x{} image", pixels.len(), size.0, size.1)));
    }
    let texture = hdr_texture(gpu, size);
    let texels: Vec<[f32; 4]> = pixels.iter().map(|p| p.extend(1.0).to_array()).collect();
    gpu.queue.write_texture(
        texture.as_image_copy(),
        bytemuck::cast_slice(&texels),
        wgpu::TexelCopyBufferLayout { offset: 0, bytes_per_row: Some(16 * size.0), rows_per_image: Some(size.1) },
        wgpu::Extent3d { width: size.0, height: size.1, depth_or_array_layers: 1 },
    );
    Ok(texture)
}

fn hdr_texture(gpu: &Gpu, size: (u32, u32)) -> wgpu::Texture {
    let usage = wgpu::TextureUsages::TEXTURE_BINDING | wgpu::TextureUsages::COPY_DST;
    texture_2d(gpu, "reference", size, wgpu::TextureFormat::Rgba32Float, usage)
}

fn texture_2d(
    gpu: &Gpu,
    label: &str,
    size: (u32, u32),
    format: wgpu::TextureFormat,
    usage: wgpu::TextureUsages,
) -> wgpu::Texture {
    gpu.create_texture(&wgpu::TextureDescriptor {
        label: Some(label),
        size: wgpu::Extent3d { width: size.0, height: size.1, depth_or_array_layers: 1 },
        mip_level_count: 1,
        sample_count: 1,
        dimension: wgpu::TextureDimension::D2,
        format,
        usage,
        view_formats: &[],
    })
}

/// The uniform block of `shaders/display.wgsl`.
#[repr(C)]
#[derive(Clone, Copy, bytemuck::Pod, bytemuck::Zeroable)]
struct Params {
    exposure: f32,
    encode: u32,
    mode: u32,
    scale: f32,
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
        let no_reference = hdr_texture(gpu, (1, 1));
        Self { pipeline, params, format, bound: RefCell::new(None), no_reference }
    }

    /// Records `frame` (an HDR image of the target's size) tone mapped at `exposure` into
    /// `target`: the frame, or with `reference` (of the same size) `shown`.
    pub(crate) fn record(
        &self,
        gpu: &Gpu,
        encoder: &mut wgpu::CommandEncoder,
        frame: &wgpu::Texture,
        exposure: f32,
        target: &wgpu::TextureView,
        (shown, reference): (Shown, Option<&wgpu::Texture>),
    ) {
        let reference = reference.filter(|r| r.size() == frame.size());
        let mode = if reference.is_some() { shown.mode() } else { 0 };
        let reference = reference.unwrap_or(&self.no_reference);
        let params = Params { exposure, encode: u32::from(!self.format.is_srgb()), mode, scale: DIFFERENCE_SCALE };
        gpu.queue.write_buffer(&self.params, 0, bytemuck::bytes_of(&params));
        let mut bound = self.bound.borrow_mut();
        if bound.as_ref().is_none_or(|(t, r, _)| t != frame || r != reference) {
            let view = frame.create_view(&wgpu::TextureViewDescriptor::default());
            let reference_view = reference.create_view(&wgpu::TextureViewDescriptor::default());
            let group = gpu.create_bind_group(&wgpu::BindGroupDescriptor {
                label: Some("display"),
                layout: &self.pipeline.get_bind_group_layout(0),
                entries: &[
                    wgpu::BindGroupEntry { binding: 0, resource: self.params.as_entire_binding() },
                    wgpu::BindGroupEntry { binding: 1, resource: wgpu::BindingResource::TextureView(&view) },
                    wgpu::BindGroupEntry { binding: 2, resource: wgpu::BindingResource::TextureView(&reference_view) },
                ],
            });
            *bound = Some((frame.clone(), reference.clone(), group));
        }
        if let Some((_, _, group)) = bound.as_ref() {
            gpu::fullscreen::record(encoder, &self.pipeline, group, target, wgpu::LoadOp::Clear(wgpu::Color::BLACK));
        }
    }
}

/// An offscreen target for the display pass: what a window shows, without one (`--offscreen`,
/// and screenshots from a surface that cannot be copied).
pub(crate) fn offscreen_target(gpu: &Gpu, size: (u32, u32), format: wgpu::TextureFormat) -> wgpu::Texture {
    let usage = wgpu::TextureUsages::RENDER_ATTACHMENT | wgpu::TextureUsages::COPY_SRC;
    texture_2d(gpu, "display target", size, format, usage)
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
