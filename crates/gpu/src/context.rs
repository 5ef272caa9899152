//! Device creation: the adapter wgpu picks (llvmpipe on these machines), with the optional
//! features our passes use when the adapter has them.

use std::time::{Duration, Instant};

/// Errors of the GPU layer.
#[derive(Debug, thiserror::Error)]
pub enum GpuError {
    /// No adapter at all.
    #[error(
        "no GPU adapter found: install Mesa's software Vulkan driver (Debian/Ubuntu: \
         `apt-get install mesa-vulkan-drivers`) or a GPU driver ({0})"
    )]
    NoAdapter(String),
    /// The adapter refused the device.
    #[error("the GPU adapter {adapter} refused a device: {reason}")]
    Device {
        /// Adapter name.
        adapter: String,
        /// What wgpu said.
        reason: String,
    },
    /// A size the adapter cannot handle, refused before allocating.
    #[error("{what} of {size} exceeds the adapter's limit of {limit}")]
    TooLarge {
        /// What was too large.
        what: &'static str,
        /// The size asked for.
        size: u64,
        /// The limit.
        limit: u64,
    },
    /// Waiting for or mapping GPU work failed.
    #[error("GPU work failed: {0}")]
    Failed(String),
}

/// A device and queue with what we know of the adapter.
pub struct Gpu {
    /// The device.
    pub device: wgpu::Device,
    /// Its queue.
    pub queue: wgpu::Queue,
    /// Adapter name, driver, backend.
    pub info: wgpu::AdapterInfo,
    /// Features enabled on the device.
    pub features: wgpu::Features,
    /// Limits of the device (the adapter's).
    pub limits: wgpu::Limits,
}

impl Gpu {
    /// Creates a device on the default adapter, enabling `CLIP_DISTANCES` and timestamp queries
    /// when the adapter has them.
    ///
    /// # Errors
    /// [`GpuError::NoAdapter`] naming `mesa-vulkan-drivers` when there is no adapter.
    pub fn new() -> Result<Self, GpuError> {
        Self::with_backends(None)
    }

    /// As [`Gpu::new`], restricted to `backends` (`None`: wgpu's default, or `WGPU_BACKEND`).
    ///
    /// # Errors
    /// [`GpuError::NoAdapter`] when none of them has an adapter.
    pub fn with_backends(backends: Option<wgpu::Backends>) -> Result<Self, GpuError> {
        let mut descriptor = wgpu::InstanceDescriptor::new_without_display_handle_from_env();
        if let Some(b) = backends {
            descriptor.backends = b;
        }
        let instance = wgpu::Instance::new(descriptor);
        let adapter = pollster::block_on(instance.request_adapter(&wgpu::RequestAdapterOptions::default()))
            .map_err(|e| GpuError::NoAdapter(e.to_string()))?;
        let info = adapter.get_info();
        let wanted = wgpu::Features::CLIP_DISTANCES
            | wgpu::Features::TIMESTAMP_QUERY
            | wgpu::Features::TIMESTAMP_QUERY_INSIDE_ENCODERS;
        let features = adapter.features() & wanted;
        let limits = adapter.limits();
        let (device, queue) = pollster::block_on(adapter.request_device(&wgpu::DeviceDescriptor {
            label: Some("envshadow"),
            required_features: features,
            required_limits: limits.clone(),
            ..Default::default()
        }))
        .map_err(|e| GpuError::Device { adapter: info.name.clone(), reason: e.to_string() })?;
        Ok(Self { device, queue, info, features, limits })
    }

    /// One line: adapter, backend, driver and its version.
    #[must_use]
    pub fn describe(&self) -> String {
        format!(
            "{} ({:?}, {:?}; driver {} {})",
            self.info.name, self.info.backend, self.info.device_type, self.info.driver, self.info.driver_info
        )
    }

    /// Whether vertex shaders can write clip distances (`CLIP_DISTANCES`).
    #[must_use]
    pub fn has_clip_distances(&self) -> bool {
        self.features.contains(wgpu::Features::CLIP_DISTANCES)
    }

    /// Refuses a 2D texture size (or layer count) the device cannot create.
    ///
    /// # Errors
    /// [`GpuError::TooLarge`].
    pub fn check_texture(&self, width: u32, height: u32, layers: u32) -> Result<(), GpuError> {
        let max = self.limits.max_texture_dimension_2d;
        let side = width.max(height);
        if side > max || width == 0 || height == 0 {
            return Err(GpuError::TooLarge { what: "texture side", size: side.into(), limit: max.into() });
        }
        if layers > self.limits.max_texture_array_layers {
            return Err(GpuError::TooLarge {
                what: "texture array layers",
                size: layers.into(),
                limit: self.limits.max_texture_array_layers.into(),
            });
        }
        Ok(())
    }

    /// Submits `encoder` and waits for the queue to finish it.
    ///
    /// # Errors
    /// [`GpuError::Failed`] when the device is lost or the wait fails.
    pub fn submit_and_wait(&self, encoder: wgpu::CommandEncoder) -> Result<(), GpuError> {
        let index = self.queue.submit([encoder.finish()]);
        self.device
            .poll(wgpu::PollType::Wait { submission_index: Some(index), timeout: None })
            .map(|_| ())
            .map_err(|e| GpuError::Failed(e.to_string()))
    }

    /// Wall time to submit `encoder` and wait for it: the time a frame's work takes end to end.
    ///
    /// # Errors
    /// As [`Gpu::submit_and_wait`].
    pub fn submit_timed(&self, encoder: wgpu::CommandEncoder) -> Result<Duration, GpuError> {
        let start = Instant::now();
        self.submit_and_wait(encoder)?;
        Ok(start.elapsed())
    }

    /// A new command encoder.
    #[must_use]
    pub fn encoder(&self, label: &str) -> wgpu::CommandEncoder {
        self.device.create_command_encoder(&wgpu::CommandEncoderDescriptor { label: Some(label) })
    }
}
