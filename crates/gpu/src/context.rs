//! Device creation on the best adapter present (a discrete GPU, then an integrated one, then a
//! virtual one, then a CPU implementation such as Mesa's lavapipe), or on one named by the
//! caller or by `ENVSHADOW_ADAPTER`, with the optional features our passes use when the adapter
//! has them.

use std::sync::Arc;
use std::sync::atomic::{AtomicU64, Ordering};
use std::time::{Duration, Instant};

/// Errors of the GPU layer.
#[derive(Debug, thiserror::Error)]
pub enum GpuError {
    /// No adapter matches the name asked for.
    #[error("no GPU adapter matches {wanted:?}; found: {}", if found.is_empty() { "none".to_string() } else { found.join("; ") })]
    UnknownAdapter {
        /// The name asked for (a substring of an adapter's name, or `cpu`).
        wanted: String,
        /// The adapters found, described.
        found: Vec<String>,
    },
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
    /// Limits of the device (the adapter's, or what the caller's device was created with).
    pub limits: wgpu::Limits,
    counters: Arc<Counters>,
    // the placement pass's pipeline, made once per device (`placement::Placement`)
    pub(crate) place: std::sync::OnceLock<wgpu::ComputePipeline>,
}

/// What the toolkit asked of the device since it was wrapped: submissions, CPU waits, bytes
/// mapped back and pipelines created. A real-time frame is judged by these (`cargo xtask frame
/// --json`): differences of two snapshots count one frame's.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct GpuCounters {
    /// Command buffers submitted to the queue (one per `queue.submit` call).
    pub submits: u64,
    /// Times the CPU blocked on the device (a poll that waits).
    pub waits: u64,
    /// Bytes of buffers mapped for reading on the CPU.
    pub readback_bytes: u64,
    /// Render and compute pipelines created.
    pub pipelines: u64,
    /// Nanoseconds the CPU spent in those waits.
    pub wait_ns: u64,
    /// Gate passes recorded ([`crate::Gate`]): one a gated light per technique call.
    pub gate_passes: u64,
    /// Buffers created through [`Gpu::create_buffer`] and [`Gpu::create_buffer_init`] (every
    /// buffer the toolkit's library crates make).
    pub buffers: u64,
    /// Bind groups created through [`Gpu::create_bind_group`].
    pub bind_groups: u64,
    /// Textures created through [`Gpu::create_texture`].
    pub textures: u64,
}

/// What happened between two snapshots, `later - earlier` (saturating: never negative).
impl std::ops::Sub for GpuCounters {
    type Output = GpuCounters;
    fn sub(self, o: GpuCounters) -> GpuCounters {
        GpuCounters {
            submits: self.submits.saturating_sub(o.submits),
            waits: self.waits.saturating_sub(o.waits),
            readback_bytes: self.readback_bytes.saturating_sub(o.readback_bytes),
            pipelines: self.pipelines.saturating_sub(o.pipelines),
            wait_ns: self.wait_ns.saturating_sub(o.wait_ns),
            gate_passes: self.gate_passes.saturating_sub(o.gate_passes),
            buffers: self.buffers.saturating_sub(o.buffers),
            bind_groups: self.bind_groups.saturating_sub(o.bind_groups),
            textures: self.textures.saturating_sub(o.textures),
        }
    }
}

#[derive(Debug, Default)]
struct Counters {
    submits: AtomicU64,
    waits: AtomicU64,
    readback_bytes: AtomicU64,
    pipelines: AtomicU64,
    wait_ns: AtomicU64,
    gate_passes: AtomicU64,
    buffers: AtomicU64,
    bind_groups: AtomicU64,
    textures: AtomicU64,
    // submissions made or marked ([`Gpu::mark_submitted`]): where per-light slots start over
    epoch: AtomicU64,
}

/// The environment variable [`Gpu::new`] reads an adapter name from (as `--adapter`).
pub const ADAPTER_ENV: &str = "ENVSHADOW_ADAPTER";

/// Preference of a device type: discrete first, CPU implementations last.
fn type_rank(t: wgpu::DeviceType) -> u8 {
    match t {
        wgpu::DeviceType::DiscreteGpu => 0,
        wgpu::DeviceType::IntegratedGpu => 1,
        wgpu::DeviceType::VirtualGpu => 2,
        wgpu::DeviceType::Other => 3,
        wgpu::DeviceType::Cpu => 4,
    }
}

/// Preference of a backend: the one our passes are validated on first.
fn backend_rank(b: wgpu::Backend) -> u8 {
    match b {
        wgpu::Backend::Vulkan => 0,
        wgpu::Backend::Metal => 1,
        wgpu::Backend::Dx12 => 2,
        wgpu::Backend::Gl => 3,
        _ => 4,
    }
}

/// One line for an adapter: name, backend, type, driver.
#[must_use]
pub fn describe_adapter(info: &wgpu::AdapterInfo) -> String {
    let driver = format!("{} {}", info.driver, info.driver_info);
    let driver = driver.trim();
    if driver.is_empty() {
        format!("{} ({:?}, {:?})", info.name, info.backend, info.device_type)
    } else {
        format!("{} ({:?}, {:?}; driver {driver})", info.name, info.backend, info.device_type)
    }
}

/// Index of the adapter `wanted` picks among `infos`: the best by type, then backend, when
/// `wanted` is `None`; else the best whose name contains `wanted` (case-insensitive), or the
/// best CPU implementation for `cpu`. OpenGL adapters come last either way: our passes need
/// more than GLSL offers.
#[must_use]
pub fn pick_adapter(infos: &[wgpu::AdapterInfo], wanted: Option<&str>) -> Option<usize> {
    let wanted = wanted.map(str::to_lowercase);
    infos
        .iter()
        .enumerate()
        .filter(|(_, i)| match wanted.as_deref() {
            None => true,
            Some("cpu") => i.device_type == wgpu::DeviceType::Cpu,
            Some(w) => i.name.to_lowercase().contains(w),
        })
        // OpenGL lacks what our passes need (depth textureLoad): any other backend first
        .min_by_key(|(k, i)| (i.backend == wgpu::Backend::Gl, type_rank(i.device_type), backend_rank(i.backend), *k))
        .map(|(k, _)| k)
}

/// Every adapter on `backends` (`None`: `WGPU_BACKEND`, else the primary backends — Vulkan,
/// Metal, DX12 — since our passes need more than OpenGL offers), and those backends.
fn enumerate(backends: Option<wgpu::Backends>) -> (Vec<wgpu::Adapter>, wgpu::Backends) {
    let mut descriptor = wgpu::InstanceDescriptor::new_without_display_handle_from_env();
    descriptor.backends = backends.or_else(wgpu::Backends::from_env).unwrap_or(wgpu::Backends::PRIMARY);
    let backends = descriptor.backends;
    let instance = wgpu::Instance::new(descriptor);
    (pollster::block_on(instance.enumerate_adapters(backends)), backends)
}

/// Every adapter present on `backends` (`None`: `WGPU_BACKEND`, else Vulkan, Metal and DX12).
#[must_use]
pub fn adapters(backends: Option<wgpu::Backends>) -> Vec<wgpu::AdapterInfo> {
    enumerate(backends).0.iter().map(wgpu::Adapter::get_info).collect()
}

impl Gpu {
    /// Creates a device on the adapter named by `ENVSHADOW_ADAPTER` when it is set (see
    /// [`Gpu::with_adapter`]), else on the best adapter present, enabling `CLIP_DISTANCES` and
    /// timestamp queries when the adapter has them.
    ///
    /// # Errors
    /// [`GpuError::NoAdapter`] naming `mesa-vulkan-drivers` when there is no adapter,
    /// [`GpuError::UnknownAdapter`] when none matches `ENVSHADOW_ADAPTER`.
    pub fn new() -> Result<Self, GpuError> {
        let named = std::env::var(ADAPTER_ENV).ok().filter(|n| !n.is_empty());
        Self::open(None, named.as_deref())
    }

    /// Creates a device on the adapter `wanted` names (a case-insensitive substring of its
    /// name, or `cpu` for a CPU implementation such as lavapipe), or on the best adapter present
    /// when `None`: discrete, integrated, virtual, other, CPU, in that order, Vulkan first and
    /// OpenGL (only through `WGPU_BACKEND`) only when there is nothing else.
    ///
    /// # Errors
    /// [`GpuError::NoAdapter`] when there is none at all, [`GpuError::UnknownAdapter`] (listing
    /// those found) when none matches.
    pub fn with_adapter(wanted: Option<&str>) -> Result<Self, GpuError> {
        Self::open(None, wanted)
    }

    /// The best adapter on `backends` (`None`: `WGPU_BACKEND`, else Vulkan, Metal and DX12).
    ///
    /// # Errors
    /// [`GpuError::NoAdapter`] when none of them has an adapter.
    pub fn with_backends(backends: Option<wgpu::Backends>) -> Result<Self, GpuError> {
        Self::open(backends, None)
    }

    fn open(backends: Option<wgpu::Backends>, wanted: Option<&str>) -> Result<Self, GpuError> {
        let (all, backends) = enumerate(backends);
        let infos: Vec<wgpu::AdapterInfo> = all.iter().map(wgpu::Adapter::get_info).collect();
        if infos.is_empty() {
            return Err(GpuError::NoAdapter(format!("no adapter on backends {backends:?}")));
        }
        let k = pick_adapter(&infos, wanted).ok_or_else(|| GpuError::UnknownAdapter {
            wanted: wanted.unwrap_or_default().to_string(),
            found: infos.iter().map(describe_adapter).collect(),
        })?;
        let adapter = &all[k];
        let info = adapter.get_info();
        let wanted = wgpu::Features::CLIP_DISTANCES
            | wgpu::Features::FLOAT32_BLENDABLE
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
        Ok(Self { device, queue, info, features, limits, counters: Arc::default(), place: Default::default() })
    }

    /// Wraps a device and queue the caller already has (a winit surface's, Bevy's
    /// `RenderDevice`), with its adapter's `info`. The toolkit uses the features and limits the
    /// device was created with: `CLIP_DISTANCES`, `FLOAT32_BLENDABLE` and timestamp queries are
    /// used when enabled and done without otherwise. Every technique runs within
    /// `wgpu::Limits::default()` (WebGPU's): there the G-buffer takes two passes.
    #[must_use]
    pub fn from_device(device: wgpu::Device, queue: wgpu::Queue, info: wgpu::AdapterInfo) -> Self {
        let features = device.features();
        let limits = device.limits();
        Self { device, queue, info, features, limits, counters: Arc::default(), place: Default::default() }
    }

    /// What the toolkit has asked of the device so far (see [`GpuCounters`]).
    #[must_use]
    pub fn counters(&self) -> GpuCounters {
        let c = &self.counters;
        GpuCounters {
            submits: c.submits.load(Ordering::Relaxed),
            waits: c.waits.load(Ordering::Relaxed),
            readback_bytes: c.readback_bytes.load(Ordering::Relaxed),
            pipelines: c.pipelines.load(Ordering::Relaxed),
            wait_ns: c.wait_ns.load(Ordering::Relaxed),
            gate_passes: c.gate_passes.load(Ordering::Relaxed),
            buffers: c.buffers.load(Ordering::Relaxed),
            bind_groups: c.bind_groups.load(Ordering::Relaxed),
            textures: c.textures.load(Ordering::Relaxed),
        }
    }

    /// Submissions made through [`Gpu::submit`] or marked by [`Gpu::mark_submitted`]: per-light
    /// resources ([`crate::Slots`]) start over when it changes.
    #[must_use]
    pub fn epoch(&self) -> u64 {
        self.counters.epoch.load(Ordering::Relaxed)
    }

    /// Tells the toolkit that what was recorded so far has been submitted, for callers that
    /// submit through their own `queue.submit` (with other command buffers of theirs): the
    /// techniques' per-light uniforms ([`crate::Slots`]) are then reused by the next frame
    /// instead of new ones being made. [`Gpu::submit`] does this itself.
    pub fn mark_submitted(&self) {
        self.counters.epoch.fetch_add(1, Ordering::Relaxed);
    }

    /// Creates a buffer (counted in [`GpuCounters::buffers`]).
    #[must_use]
    pub fn create_buffer(&self, descriptor: &wgpu::BufferDescriptor) -> wgpu::Buffer {
        self.counters.buffers.fetch_add(1, Ordering::Relaxed);
        self.device.create_buffer(descriptor)
    }

    /// Creates a buffer holding `descriptor.contents` (counted in [`GpuCounters::buffers`]).
    #[must_use]
    pub fn create_buffer_init(&self, descriptor: &wgpu::util::BufferInitDescriptor) -> wgpu::Buffer {
        use wgpu::util::DeviceExt;
        self.counters.buffers.fetch_add(1, Ordering::Relaxed);
        self.device.create_buffer_init(descriptor)
    }

    /// Creates a bind group (counted in [`GpuCounters::bind_groups`]).
    #[must_use]
    pub fn create_bind_group(&self, descriptor: &wgpu::BindGroupDescriptor) -> wgpu::BindGroup {
        self.counters.bind_groups.fetch_add(1, Ordering::Relaxed);
        self.device.create_bind_group(descriptor)
    }

    /// Creates a texture (counted in [`GpuCounters::textures`]).
    #[must_use]
    pub fn create_texture(&self, descriptor: &wgpu::TextureDescriptor) -> wgpu::Texture {
        self.counters.textures.fetch_add(1, Ordering::Relaxed);
        self.device.create_texture(descriptor)
    }

    /// Counts a gate pass recorded.
    pub(crate) fn count_gate_pass(&self) {
        self.counters.gate_passes.fetch_add(1, Ordering::Relaxed);
    }

    /// Submits `encoder` without waiting.
    pub fn submit(&self, encoder: wgpu::CommandEncoder) -> wgpu::SubmissionIndex {
        self.counters.submits.fetch_add(1, Ordering::Relaxed);
        let index = self.queue.submit([encoder.finish()]);
        self.mark_submitted();
        index
    }

    /// Blocks until the queue has finished `index` (or everything submitted, for `None`).
    ///
    /// # Errors
    /// [`GpuError::Failed`] when the device is lost or the wait fails.
    pub fn wait(&self, index: Option<wgpu::SubmissionIndex>) -> Result<(), GpuError> {
        self.counters.waits.fetch_add(1, Ordering::Relaxed);
        let start = Instant::now();
        let r = self
            .device
            .poll(wgpu::PollType::Wait { submission_index: index, timeout: None })
            .map(|_| ())
            .map_err(|e| GpuError::Failed(e.to_string()));
        self.counters.wait_ns.fetch_add(start.elapsed().as_nanos() as u64, Ordering::Relaxed);
        r
    }

    /// Counts `bytes` mapped back to the CPU.
    pub(crate) fn count_readback(&self, bytes: u64) {
        self.counters.readback_bytes.fetch_add(bytes, Ordering::Relaxed);
    }

    /// Creates a render pipeline (counted in [`GpuCounters::pipelines`]).
    #[must_use]
    pub fn render_pipeline(&self, descriptor: &wgpu::RenderPipelineDescriptor) -> wgpu::RenderPipeline {
        self.counters.pipelines.fetch_add(1, Ordering::Relaxed);
        self.device.create_render_pipeline(descriptor)
    }

    /// Creates a compute pipeline (counted in [`GpuCounters::pipelines`]).
    #[must_use]
    pub fn compute_pipeline(&self, descriptor: &wgpu::ComputePipelineDescriptor) -> wgpu::ComputePipeline {
        self.counters.pipelines.fetch_add(1, Ordering::Relaxed);
        self.device.create_compute_pipeline(descriptor)
    }

    /// One line: adapter, backend, driver and its version.
    #[must_use]
    pub fn describe(&self) -> String {
        describe_adapter(&self.info)
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
        let index = self.submit(encoder);
        self.wait(Some(index))
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
