//! Timing GPU work: timestamp queries around the recorded commands when the adapter has them
//! (inside encoders), else the wall time of submit + wait. Both are stated with the figure.

use crate::context::{Gpu, GpuError};
use std::time::Duration;

/// Which clock a duration came from.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Clock {
    /// GPU timestamp queries around the commands.
    GpuTimestamps,
    /// Wall time of submit and wait on the CPU.
    #[default]
    WallTime,
    /// Wall time of one submission holding several lights, an even share each: without
    /// timestamps inside encoders the lights recorded together cannot be told apart (their
    /// sum is the submission's).
    WallTimeShare,
}

impl Clock {
    /// A short name for reports.
    #[must_use]
    pub fn name(self) -> &'static str {
        match self {
            Clock::GpuTimestamps => "GPU timestamps",
            Clock::WallTime => "wall time (submit + wait)",
            Clock::WallTimeShare => "wall time (submit + wait), an even share a light",
        }
    }
}

impl Gpu {
    /// Records commands with `record`, submits them, waits, and returns how long they took on
    /// the GPU (timestamps when available) and the clock used.
    ///
    /// # Errors
    /// As [`Gpu::submit_and_wait`].
    pub fn measure(&self, record: impl FnOnce(&mut wgpu::CommandEncoder)) -> Result<(Duration, Clock), GpuError> {
        let mut encoder = self.encoder("measure");
        let Some(stamps) = StageStamps::new(self, 1)? else {
            record(&mut encoder);
            return Ok((self.submit_timed(encoder)?, Clock::WallTime));
        };
        stamps.write(&mut encoder, 0);
        record(&mut encoder);
        stamps.write(&mut encoder, 1);
        stamps.record_resolve(&mut encoder);
        self.submit_and_wait(encoder)?;
        Ok((stamps.read(self)?.first().copied().unwrap_or_default(), Clock::GpuTimestamps))
    }
}

/// A set of GPU timestamps written inside encoders, resolved and copied for mapping: what
/// [`StageStamps`] and `technique::LightStamps` are made of.
pub(crate) struct Stamps {
    set: wgpu::QuerySet,
    resolve: wgpu::Buffer,
    read: wgpu::Buffer,
    pub(crate) count: u32,
}

impl Stamps {
    /// `count` stamps; `None` without timestamps inside encoders or for none.
    ///
    /// # Errors
    /// [`GpuError::TooLarge`] past the queries one set holds (`what` names the request).
    pub(crate) fn new(gpu: &Gpu, count: u64, what: &'static str) -> Result<Option<Self>, GpuError> {
        let timestamps = wgpu::Features::TIMESTAMP_QUERY | wgpu::Features::TIMESTAMP_QUERY_INSIDE_ENCODERS;
        if !gpu.features.contains(timestamps) || count == 0 {
            return Ok(None);
        }
        let limit = u64::from(wgpu::QUERY_SET_MAX_QUERIES);
        if count > limit {
            return Err(GpuError::TooLarge { what, size: count, limit });
        }
        let set = gpu.device.create_query_set(&wgpu::QuerySetDescriptor {
            label: Some(what),
            ty: wgpu::QueryType::Timestamp,
            count: count as u32,
        });
        let buffer = |usage| {
            gpu.create_buffer(&wgpu::BufferDescriptor {
                label: Some(what),
                size: 8 * count,
                usage,
                mapped_at_creation: false,
            })
        };
        Ok(Some(Self {
            set,
            resolve: buffer(wgpu::BufferUsages::QUERY_RESOLVE | wgpu::BufferUsages::COPY_SRC),
            read: buffer(wgpu::BufferUsages::MAP_READ | wgpu::BufferUsages::COPY_DST),
            count: count as u32,
        }))
    }

    /// Writes stamp `k`; past the last, nothing.
    pub(crate) fn write(&self, encoder: &mut wgpu::CommandEncoder, k: u32) {
        if k < self.count {
            encoder.write_timestamp(&self.set, k);
        }
    }

    /// Records the stamps' resolve and copy, after the last.
    pub(crate) fn record_resolve(&self, encoder: &mut wgpu::CommandEncoder) {
        encoder.resolve_query_set(&self.set, 0..self.count, &self.resolve, 0);
        encoder.copy_buffer_to_buffer(&self.resolve, 0, &self.read, 0, 8 * u64::from(self.count));
    }

    /// The buffer the stamps are mapped from, once their submission has run.
    pub(crate) fn read_buffer(&self) -> &wgpu::Buffer {
        &self.read
    }
}

/// The time between two ticks of a mapped stamp buffer.
pub(crate) fn between(gpu: &Gpu, from: u64, to: u64) -> Duration {
    Duration::from_nanos((to.saturating_sub(from) as f64 * f64::from(gpu.queue.get_timestamp_period())) as u64)
}

/// GPU timestamps between the stages of one recorded submission: `stages + 1` stamps, stage k
/// running from stamp k to stamp k + 1. How measurement times a frame recorded as a renderer
/// records it (one encoder, no waits between stages). Made per measured frame.
pub struct StageStamps(Stamps);

impl StageStamps {
    /// Stamps around `stages` stages; `None` without timestamps inside encoders (the caller
    /// then times each stage on the wall clock) or for no stage.
    ///
    /// # Errors
    /// [`GpuError::TooLarge`] past the queries one set holds.
    pub fn new(gpu: &Gpu, stages: usize) -> Result<Option<Self>, GpuError> {
        let count = if stages == 0 { 0 } else { stages as u64 + 1 };
        Ok(Stamps::new(gpu, count, "timestamps of stages timed in one submission")?.map(Self))
    }

    /// Writes stamp `k` (0: before the first stage; k: after stage k - 1); past the last, nothing.
    pub fn write(&self, encoder: &mut wgpu::CommandEncoder, k: u32) {
        self.0.write(encoder, k);
    }

    /// Records the stamps' resolve and copy, after the last stage.
    pub fn record_resolve(&self, encoder: &mut wgpu::CommandEncoder) {
        self.0.record_resolve(encoder);
    }

    /// Each stage's time, once the submission holding the stamps has run: a wait.
    ///
    /// # Errors
    /// GPU failures.
    pub fn read(&self, gpu: &Gpu) -> Result<Vec<Duration>, GpuError> {
        let bytes = crate::readback::read_mapped(gpu, self.0.read_buffer())?;
        let ticks: Vec<u64> = bytemuck::pod_collect_to_vec(&bytes);
        Ok(ticks.windows(2).map(|t| between(gpu, t[0], t[1])).collect())
    }
}
