//! Timing GPU work: timestamp queries around the recorded commands when the adapter has them
//! (inside encoders), else the wall time of submit + wait. Both are stated with the figure.

use crate::context::{Gpu, GpuError};
use std::time::Duration;

/// Which clock a duration came from.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Clock {
    /// GPU timestamp queries around the commands.
    GpuTimestamps,
    /// Wall time of submit and wait on the CPU.
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
        let timestamps = wgpu::Features::TIMESTAMP_QUERY | wgpu::Features::TIMESTAMP_QUERY_INSIDE_ENCODERS;
        let mut encoder = self.encoder("measure");
        if !self.features.contains(timestamps) {
            record(&mut encoder);
            return Ok((self.submit_timed(encoder)?, Clock::WallTime));
        }
        let set = self.device.create_query_set(&wgpu::QuerySetDescriptor {
            label: Some("measure"),
            ty: wgpu::QueryType::Timestamp,
            count: 2,
        });
        let resolve = self.create_buffer(&wgpu::BufferDescriptor {
            label: Some("timestamps"),
            size: 16,
            usage: wgpu::BufferUsages::QUERY_RESOLVE | wgpu::BufferUsages::COPY_SRC,
            mapped_at_creation: false,
        });
        let read = self.create_buffer(&wgpu::BufferDescriptor {
            label: Some("timestamps readback"),
            size: 16,
            usage: wgpu::BufferUsages::MAP_READ | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });
        encoder.write_timestamp(&set, 0);
        record(&mut encoder);
        encoder.write_timestamp(&set, 1);
        encoder.resolve_query_set(&set, 0..2, &resolve, 0);
        encoder.copy_buffer_to_buffer(&resolve, 0, &read, 0, 16);
        self.submit_and_wait(encoder)?;
        let bytes = crate::readback::read_mapped(self, &read)?;
        let ticks: [u64; 2] = bytemuck::pod_read_unaligned(&bytes[..16]);
        let ns = ticks[1].saturating_sub(ticks[0]) as f64 * f64::from(self.queue.get_timestamp_period());
        Ok((Duration::from_nanos(ns as u64), Clock::GpuTimestamps))
    }
}
