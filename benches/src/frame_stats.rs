//! What a frame costs, counted over many frames: queue submissions, CPU waits, bytes mapped
//! back, pipelines created after the first frame, gate passes, buffers, bind groups and textures
//! created (from `gpu::GpuCounters`), the CPU's time
//! outside waits, GPU time between two timestamps around the frame, and wall time.
//!
//! The measurement wraps the frame: the timestamps go in submissions of their own before and
//! after it, and their submissions, waits and readback are not counted as the frame's. The one
//! wait it adds, for the frame's work to finish, is counted (a frame that already waited finds
//! nothing left to wait for).

use gpu::{Gpu, GpuCounters, GpuError};
use std::time::{Duration, Instant};

/// Medians per frame over the measured frames (the first, where pipelines compile and buffers
/// grow, is rendered but not measured).
#[derive(Clone, Debug, PartialEq)]
pub struct FrameStats {
    /// Frames measured.
    pub frames: usize,
    /// Queue submissions.
    pub submits_per_frame: f64,
    /// Times the CPU blocked on the GPU.
    pub waits_per_frame: f64,
    /// Bytes mapped back to the CPU.
    pub readback_bytes_per_frame: f64,
    /// Pipelines created over all measured frames.
    pub pipelines_created_after_first_frame: u64,
    /// Gate passes recorded (one a gated light and technique).
    pub gate_passes_per_frame: f64,
    /// Buffers, bind groups and textures the toolkit created ([`gpu::Gpu::create_buffer`] and
    /// its siblings): what a frame still makes instead of reusing.
    pub created_per_frame: Created,
    /// CPU time outside waits: recording, planning, uploads.
    pub cpu_record_ms: f64,
    /// GPU time from the frame's first command to its last (timestamps), `None` without
    /// timestamp queries.
    pub gpu_ms: Option<f64>,
    /// Wall time until the frame's work is done.
    pub wall_ms: f64,
    /// The first, unmeasured frame's wall time: pipelines compile and buffers grow on it, so
    /// it is what a viewer waits for before its first picture.
    pub first_frame_wall_ms: f64,
    /// The first frame's GPU time (timestamps), `None` without timestamp queries.
    pub first_frame_gpu_ms: Option<f64>,
}

/// Resources created in a frame (medians).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Created {
    /// Buffers.
    pub buffers: f64,
    /// Bind groups.
    pub bind_groups: f64,
    /// Textures.
    pub textures: f64,
}

fn median(mut v: Vec<f64>) -> f64 {
    if v.is_empty() {
        return f64::NAN;
    }
    v.sort_by(f64::total_cmp);
    v[v.len() / 2]
}

/// Two timestamps around a frame, when the device has them.
struct Stamps {
    set: wgpu::QuerySet,
    resolve: wgpu::Buffer,
    read: wgpu::Buffer,
}

impl Stamps {
    fn new(gpu: &Gpu) -> Option<Self> {
        let needed = wgpu::Features::TIMESTAMP_QUERY | wgpu::Features::TIMESTAMP_QUERY_INSIDE_ENCODERS;
        if !gpu.features.contains(needed) {
            return None;
        }
        let set = gpu.device.create_query_set(&wgpu::QuerySetDescriptor {
            label: Some("frame stamps"),
            ty: wgpu::QueryType::Timestamp,
            count: 2,
        });
        let buffer = |label, usage| {
            gpu.create_buffer(&wgpu::BufferDescriptor {
                label: Some(label),
                size: 16,
                usage,
                mapped_at_creation: false,
            })
        };
        Some(Self {
            set,
            resolve: buffer("frame stamps", wgpu::BufferUsages::QUERY_RESOLVE | wgpu::BufferUsages::COPY_SRC),
            read: buffer("frame stamps read", wgpu::BufferUsages::MAP_READ | wgpu::BufferUsages::COPY_DST),
        })
    }

    fn stamp(&self, gpu: &Gpu, k: u32) {
        let mut encoder = gpu.encoder("frame stamp");
        encoder.write_timestamp(&self.set, k);
        if k == 1 {
            encoder.resolve_query_set(&self.set, 0..2, &self.resolve, 0);
            encoder.copy_buffer_to_buffer(&self.resolve, 0, &self.read, 0, 16);
        }
        gpu.submit(encoder);
    }

    fn read(&self, gpu: &Gpu) -> Result<f64, GpuError> {
        let bytes = gpu::read_mapped(gpu, &self.read)?;
        let tick = |k: usize| bytes.get(8 * k..8 * k + 8).and_then(|b| b.try_into().ok()).map_or(0, u64::from_le_bytes);
        Ok(tick(1).saturating_sub(tick(0)) as f64 * f64::from(gpu.queue.get_timestamp_period()) * 1e-6)
    }
}

/// Renders `frames + 1` frames with `frame` (given the frame's index; the first is not
/// measured) and returns the medians.
///
/// # Errors
/// The frame's errors; GPU failures.
pub fn measure_frames<E: From<GpuError>>(
    gpu: &Gpu,
    frames: usize,
    mut frame: impl FnMut(usize) -> Result<(), E>,
) -> Result<FrameStats, E> {
    let stamps = Stamps::new(gpu);
    let (mut submits, mut waits, mut bytes, mut cpu, mut gpu_ms, mut wall) =
        (Vec::new(), Vec::new(), Vec::new(), Vec::new(), Vec::new(), Vec::new());
    let mut gates = Vec::new();
    let (mut buffers, mut binds, mut textures) = (Vec::new(), Vec::new(), Vec::new());
    let mut pipelines_after_first = 0;
    let (mut first_wall, mut first_gpu) = (0.0, None);
    for k in 0..=frames {
        if let Some(s) = &stamps {
            s.stamp(gpu, 0);
        }
        let before: GpuCounters = gpu.counters();
        let start = Instant::now();
        frame(k)?;
        gpu.wait(None)?;
        let elapsed = start.elapsed();
        let d = gpu.counters() - before;
        if let Some(s) = &stamps {
            s.stamp(gpu, 1);
        }
        let ms = stamps.as_ref().map(|s| s.read(gpu)).transpose()?;
        if k == 0 {
            (first_wall, first_gpu) = (elapsed.as_secs_f64() * 1e3, ms);
            continue;
        }
        pipelines_after_first += d.pipelines;
        submits.push(d.submits as f64);
        waits.push(d.waits as f64);
        bytes.push(d.readback_bytes as f64);
        gates.push(d.gate_passes as f64);
        buffers.push(d.buffers as f64);
        binds.push(d.bind_groups as f64);
        textures.push(d.textures as f64);
        cpu.push(elapsed.saturating_sub(Duration::from_nanos(d.wait_ns)).as_secs_f64() * 1e3);
        wall.push(elapsed.as_secs_f64() * 1e3);
        gpu_ms.extend(ms);
    }
    Ok(FrameStats {
        frames,
        submits_per_frame: median(submits),
        waits_per_frame: median(waits),
        readback_bytes_per_frame: median(bytes),
        pipelines_created_after_first_frame: pipelines_after_first,
        gate_passes_per_frame: median(gates),
        created_per_frame: Created { buffers: median(buffers), bind_groups: median(binds), textures: median(textures) },
        cpu_record_ms: median(cpu),
        gpu_ms: (!gpu_ms.is_empty()).then(|| median(gpu_ms)),
        wall_ms: median(wall),
        first_frame_wall_ms: first_wall,
        first_frame_gpu_ms: first_gpu,
    })
}
