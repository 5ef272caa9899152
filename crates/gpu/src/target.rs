//! Offscreen render targets: 2D (array) textures that passes draw into, later passes read, and
//! tests read back; and single-layer views of them.

use crate::context::{Gpu, GpuError};

/// A `width` × `height` × `layers` render target of `format`, readable by shaders and back on
/// the CPU. Sizes beyond the adapter's limits are refused before allocating.
///
/// # Errors
/// [`GpuError::TooLarge`].
pub fn render_target(
    gpu: &Gpu,
    label: &str,
    (width, height, layers): (u32, u32, u32),
    format: wgpu::TextureFormat,
) -> Result<wgpu::Texture, GpuError> {
    gpu.check_texture(width, height, layers)?;
    Ok(gpu.create_texture(&wgpu::TextureDescriptor {
        label: Some(label),
        size: wgpu::Extent3d { width, height, depth_or_array_layers: layers },
        mip_level_count: 1,
        sample_count: 1,
        dimension: wgpu::TextureDimension::D2,
        format,
        usage: wgpu::TextureUsages::RENDER_ATTACHMENT
            | wgpu::TextureUsages::TEXTURE_BINDING
            | wgpu::TextureUsages::COPY_SRC,
        view_formats: &[],
    }))
}

/// A 2D view of one layer of an array texture: what a pass renders into.
#[must_use]
pub fn layer_view(texture: &wgpu::Texture, layer: u32) -> wgpu::TextureView {
    texture.create_view(&wgpu::TextureViewDescriptor {
        dimension: Some(wgpu::TextureViewDimension::D2),
        base_array_layer: layer,
        array_layer_count: Some(1),
        ..Default::default()
    })
}
