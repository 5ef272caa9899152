//! Reading textures and buffers back to the CPU (rows padded to 256 bytes by the copy rules).

use crate::context::{Gpu, GpuError};

/// Maps `buffer` (which needs `MAP_READ`, its work submitted) and returns its bytes: a wait.
///
/// # Errors
/// [`GpuError::Failed`] when the wait or the mapping fails.
pub fn read_mapped(gpu: &Gpu, buffer: &wgpu::Buffer) -> Result<Vec<u8>, GpuError> {
    Ok(read_mapped_all(gpu, &[buffer])?.swap_remove(0))
}

/// Maps every one of `buffers` (as [`read_mapped`]) with one wait for all of them.
///
/// # Errors
/// [`GpuError::Failed`] when the wait or a mapping fails.
pub fn read_mapped_all(gpu: &Gpu, buffers: &[&wgpu::Buffer]) -> Result<Vec<Vec<u8>>, GpuError> {
    let mapping = MappingRead::start(gpu, buffers.iter().map(|b| (*b).clone()).collect());
    gpu.wait(None)?;
    mapping.finish(gpu)
}

/// Buffers whose mapping was asked for without waiting ([`MappingRead::start`]): a frame's
/// small results, read once the frame has finished (after the caller's own wait, or the next
/// frame), never a stall of the frame that made them.
pub struct MappingRead {
    buffers: Vec<wgpu::Buffer>,
    done: Vec<std::sync::mpsc::Receiver<Result<(), wgpu::BufferAsyncError>>>,
}

impl MappingRead {
    /// Asks for every one of `buffers` (which need `MAP_READ`, their work submitted) to be
    /// mapped, and returns at once. Their bytes count as read back now.
    #[must_use]
    pub fn start(gpu: &Gpu, buffers: Vec<wgpu::Buffer>) -> Self {
        for b in &buffers {
            gpu.count_readback(b.size());
        }
        let done = buffers
            .iter()
            .map(|buffer| {
                let (tx, rx) = std::sync::mpsc::channel();
                buffer.map_async(wgpu::MapMode::Read, .., move |r| {
                    let _ = tx.send(r);
                });
                rx
            })
            .collect();
        Self { buffers, done }
    }

    /// The buffers' bytes, in order, when the device has finished them; it polls without
    /// blocking and never waits.
    ///
    /// # Errors
    /// [`GpuError::Failed`] when the work has not finished yet (wait for it first) or a
    /// mapping failed.
    pub fn finish(self, gpu: &Gpu) -> Result<Vec<Vec<u8>>, GpuError> {
        gpu.device.poll(wgpu::PollType::Poll).map_err(|e| GpuError::Failed(e.to_string()))?;
        let mut out = Vec::with_capacity(self.buffers.len());
        for (buffer, rx) in self.buffers.iter().zip(self.done) {
            rx.try_recv()
                .map_err(|_| GpuError::Failed("a readback is not finished: wait for its frame first".into()))?
                .map_err(|e| GpuError::Failed(format!("mapping a readback buffer: {e}")))?;
            out.push(buffer.get_mapped_range(..).map_err(|e| GpuError::Failed(e.to_string()))?.to_vec());
            buffer.unmap();
        }
        Ok(out)
    }
}

/// Copies `buffer` (which needs `COPY_SRC`) back to the CPU.
///
/// # Errors
/// [`GpuError::Failed`] when the copy or the mapping fails.
pub fn read_buffer(gpu: &Gpu, buffer: &wgpu::Buffer) -> Result<Vec<u8>, GpuError> {
    let staging = gpu.create_buffer(&wgpu::BufferDescriptor {
        label: Some("readback"),
        size: buffer.size(),
        usage: wgpu::BufferUsages::MAP_READ | wgpu::BufferUsages::COPY_DST,
        mapped_at_creation: false,
    });
    let mut encoder = gpu.encoder("readback");
    encoder.copy_buffer_to_buffer(buffer, 0, &staging, 0, buffer.size());
    gpu.submit_and_wait(encoder)?;
    read_mapped(gpu, &staging)
}

/// A texture layer's copy recorded into an encoder, to be mapped once the encoder has run.
pub struct PendingRead {
    buffer: wgpu::Buffer,
    row: u32,
    padded: u32,
}

impl PendingRead {
    /// Records the copy of one layer of `texture` (`aspect` of it) into a buffer of its own.
    ///
    /// # Errors
    /// [`GpuError::Failed`] for a format that cannot be copied back.
    pub fn record(
        gpu: &Gpu,
        encoder: &mut wgpu::CommandEncoder,
        texture: &wgpu::Texture,
        layer: u32,
        aspect: wgpu::TextureAspect,
    ) -> Result<Self, GpuError> {
        let (w, h) = (texture.width(), texture.height());
        let bpp = texture
            .format()
            .block_copy_size(Some(aspect))
            .ok_or_else(|| GpuError::Failed(format!("cannot read back {:?}", texture.format())))?;
        let row = w * bpp;
        let padded = row.div_ceil(wgpu::COPY_BYTES_PER_ROW_ALIGNMENT) * wgpu::COPY_BYTES_PER_ROW_ALIGNMENT;
        let buffer = gpu.create_buffer(&wgpu::BufferDescriptor {
            label: Some("readback"),
            size: u64::from(padded) * u64::from(h),
            usage: wgpu::BufferUsages::MAP_READ | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });
        encoder.copy_texture_to_buffer(
            wgpu::TexelCopyTextureInfo {
                texture,
                mip_level: 0,
                origin: wgpu::Origin3d { x: 0, y: 0, z: layer },
                aspect,
            },
            wgpu::TexelCopyBufferInfo {
                buffer: &buffer,
                layout: wgpu::TexelCopyBufferLayout { offset: 0, bytes_per_row: Some(padded), rows_per_image: Some(h) },
            },
            wgpu::Extent3d { width: w, height: h, depth_or_array_layers: 1 },
        );
        Ok(Self { buffer, row, padded })
    }

    /// Maps every read (their encoders submitted) with one wait; per read its tightly packed
    /// bytes, row by row.
    ///
    /// # Errors
    /// [`GpuError::Failed`] when the wait or a mapping fails.
    pub fn finish_all(gpu: &Gpu, reads: &[PendingRead]) -> Result<Vec<Vec<u8>>, GpuError> {
        let buffers: Vec<&wgpu::Buffer> = reads.iter().map(|r| &r.buffer).collect();
        let mapped = read_mapped_all(gpu, &buffers)?;
        Ok(reads
            .iter()
            .zip(mapped)
            .map(|(r, bytes)| {
                bytes.chunks_exact(r.padded as usize).flat_map(|b| b[..r.row as usize].to_vec()).collect()
            })
            .collect())
    }
}

/// Copies one layer of a texture with 4-byte texels per channel group into tightly packed
/// bytes, row by row.
fn read_layer_bytes(
    gpu: &Gpu,
    texture: &wgpu::Texture,
    layer: u32,
    aspect: wgpu::TextureAspect,
) -> Result<Vec<u8>, GpuError> {
    let mut encoder = gpu.encoder("readback");
    let read = PendingRead::record(gpu, &mut encoder, texture, layer, aspect)?;
    gpu.submit(encoder);
    Ok(PendingRead::finish_all(gpu, &[read])?.swap_remove(0))
}

/// Reads one layer of a single-channel texture as floats, row-major from the top-left: R32Float
/// or the depth aspect of Depth32Float / Depth32FloatStencil8 as stored, R8Unorm in [0, 1].
///
/// # Errors
/// [`GpuError::Failed`] when the format cannot be read back or the copy fails.
pub fn read_texture_f32(gpu: &Gpu, texture: &wgpu::Texture, layer: u32) -> Result<Vec<f32>, GpuError> {
    let format = texture.format();
    let aspect =
        if format.is_depth_stencil_format() { wgpu::TextureAspect::DepthOnly } else { wgpu::TextureAspect::All };
    let bytes = read_layer_bytes(gpu, texture, layer, aspect)?;
    match format.block_copy_size(Some(aspect)) {
        Some(1) => Ok(bytes.iter().map(|&b| f32::from(b) / 255.0).collect()),
        Some(4) => Ok(bytemuck::pod_collect_to_vec(&bytes)),
        _ => Err(GpuError::Failed(format!("read_texture_f32: {format:?} is not a single-channel format"))),
    }
}

/// Reads one layer of an Rgba32Float texture as RGBA quadruples, row-major from the top-left.
///
/// # Errors
/// As [`read_texture_f32`].
pub fn read_texture_rgba(gpu: &Gpu, texture: &wgpu::Texture, layer: u32) -> Result<Vec<[f32; 4]>, GpuError> {
    if texture.format() != wgpu::TextureFormat::Rgba32Float {
        return Err(GpuError::Failed(format!("read_texture_rgba: {:?} is not Rgba32Float", texture.format())));
    }
    let bytes = read_layer_bytes(gpu, texture, layer, wgpu::TextureAspect::All)?;
    Ok(bytemuck::pod_collect_to_vec(&bytes))
}
