//! The receivers' statistics reduced on the GPU (`crates/gpu/shaders/receivers.wgsl`): the bounds and
//! count of the visible points, their mean, and per light whether any visible receiver faces
//! it. What comes back is [`ReceiverStats::BYTES`] bytes, not the G-buffer's 32 a pixel: the
//! first part of moving `Receivers` onto the GPU (`docs/real-time.md`, step 2). The CPU version
//! (`Receivers::new`, `Receivers::any_faces`) is the reference it is tested against.

use crate::context::{Gpu, GpuError};
use crate::gate::GpuStats;
use crate::gbuffer::GBuffer;
use crate::shade::ShadeLight;
use crate::slots::{Keyed, binding_of, writable_buffer, write_grown};
use crate::technique::LightShape;
use envmap_sphere::Sh9;
use glam::Vec3;
use std::cell::RefCell;

/// What [`ReceiverReduction`] found.
#[derive(Clone, Debug, PartialEq)]
pub struct ReceiverStats {
    /// Axis-aligned bounds of the visible points (exactly the CPU's), `None` when none is.
    pub bounds: Option<(Vec3, Vec3)>,
    /// Visible points.
    pub count: u32,
    /// Their mean (a fixed-order sum: the same bits every run, not the CPU's sequential sum).
    pub mean: Option<Vec3>,
    /// The 95th percentile of their distances to `mean`, exactly (a radix select): with the
    /// mean, the focus of `Receivers`.
    pub radius: Option<f32>,
    /// Per light (in the order given): whether any visible receiver has part of it above its
    /// surface.
    pub faces: Vec<bool>,
    /// Per light of the [`WeberInput`] (empty without one): whether Weber's law finds it
    /// negligible, as [`crate::weber_negligible`].
    pub negligible: Vec<bool>,
}

impl ReceiverStats {
    /// Why light `k` got no shadow pass where a frame gated its lights by these statistics
    /// ([`crate::GpuStats::gate`]): no visible receiver faces it, or Weber's law finds it
    /// negligible; `None` when it had its pass.
    #[must_use]
    pub fn skip_reason(&self, k: usize) -> Option<String> {
        let faced = self.faces.get(k).copied().unwrap_or(false);
        crate::technique::why_skipped(faced, self.negligible.get(k).copied().unwrap_or(false))
    }

    /// Bytes mapped back per reduction.
    pub const BYTES: u64 = 8 * 4 + 16 + 4 * (ReceiverReduction::MAX_LIGHTS as u64 / 32) + 32;
}

/// The inverse of the shader's order-preserving key.
fn from_key(k: u32) -> f32 {
    f32::from_bits(if k & 0x8000_0000 != 0 { k ^ 0x8000_0000 } else { !k })
}

/// What Weber's test ([`crate::weber_negligible`]) needs beside the G-buffer.
#[derive(Clone, Copy)]
pub struct WeberInput<'a> {
    /// Every light of the frame, in the order of the result.
    pub lights: &'a [ShadeLight],
    /// The ambient's SH9 (its irradiance counts towards what a receiver gets).
    pub ambient: Option<&'a Sh9>,
    /// The fraction, e.g. [`crate::WEBER_FRACTION`].
    pub fraction: f32,
}

/// Bytes of the Weber state mapped back: its flags and the negligible lights' bits.
const WEBER_BYTES: u64 = 16 + 4 * 32;

#[repr(C)]
#[derive(Clone, Copy, bytemuck::Pod, bytemuck::Zeroable)]
struct WeberParams {
    size: [u32; 4],
    info: [f32; 4],
    sh: [[f32; 4]; 9],
}

#[repr(C)]
#[derive(Clone, Copy, bytemuck::Pod, bytemuck::Zeroable)]
struct GpuLight {
    place: [f32; 4],
    shape: [f32; 4],
}

/// Buffers for one image size.
struct Buffers {
    size: (u32, u32),
    partials: wgpu::Buffer,
    // per receiver of Weber's subset: its total and the skipped share
    totals: wgpu::Buffer,
    skipped: wgpu::Buffer,
}

/// What a reduction writes at each record, and the bind groups over it, made once and rewritten
/// with `queue.write_buffer` (one reduction holds one result at a time, so one set serves it).
struct Uploads {
    params: wgpu::Buffer,
    // grown to the largest frame's lights
    lights: wgpu::Buffer,
    weber_params: wgpu::Buffer,
    weber_lights: wgpu::Buffer,
    // reduce, finish, histogram, select: on (light bytes, [lights, partials], [position, normal])
    binds: Keyed<(u64, [wgpu::Buffer; 2], [wgpu::Texture; 2]), [wgpu::BindGroup; 4]>,
    // totals and greedy: on (light bytes, [lights, totals, skipped], [position, normal])
    weber_binds: Keyed<(u64, [wgpu::Buffer; 3], [wgpu::Texture; 2]), [wgpu::BindGroup; 2]>,
}

/// Mappable buffers whose results were read (and unmapped), handed to the next record: a
/// frame's readback makes no buffer once the frames in flight have theirs.
type ReadPool = std::sync::Arc<std::sync::Mutex<Vec<wgpu::Buffer>>>;

/// A mappable buffer of `size` bytes from `pool`, or a new one.
fn pooled_read(gpu: &Gpu, pool: &ReadPool, label: &str, size: u64) -> wgpu::Buffer {
    let mut pool = pool.lock().unwrap_or_else(std::sync::PoisonError::into_inner);
    match pool.iter().position(|b| b.size() == size) {
        Some(k) => pool.swap_remove(k),
        None => gpu.create_buffer(&wgpu::BufferDescriptor {
            label: Some(label),
            size,
            usage: wgpu::BufferUsages::MAP_READ | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        }),
    }
}

/// The distances' radix select: a byte a pass.
const DIGITS: u32 = 4;

/// The reduction's pipelines, built once, and its buffers, made per image size.
pub struct ReceiverReduction {
    reduce: wgpu::ComputePipeline,
    finish: wgpu::ComputePipeline,
    histogram_pass: wgpu::ComputePipeline,
    select_digit: wgpu::ComputePipeline,
    stats: wgpu::Buffer,
    histogram: wgpu::Buffer,
    weber_totals: wgpu::ComputePipeline,
    weber_greedy: wgpu::ComputePipeline,
    weber_state: wgpu::Buffer,
    gate: wgpu::ComputePipeline,
    // the gated lights' resources, kept from frame to frame
    gate_slots: std::sync::Arc<crate::Slots<crate::gate::GateSlot>>,
    buffers: RefCell<Option<Buffers>>,
    uploads: RefCell<Uploads>,
    reads: ReadPool,
}

/// A reduction recorded, its result to be mapped once the encoder has run.
pub struct PendingStats {
    read: wgpu::Buffer,
    lights: usize,
    // Weber's result and its light count, when asked
    weber: Option<(wgpu::Buffer, usize)>,
    on_gpu: GpuStats,
    // where `read` and Weber's go back once read
    pool: ReadPool,
}

/// A reduction's result being mapped ([`PendingStats::map`]), to be read once its frame is done.
pub struct MappedStats {
    pending: PendingStats,
    mapping: crate::readback::MappingRead,
}

impl ReceiverReduction {
    /// Lights one reduction tests at most (one bit each).
    pub const MAX_LIGHTS: usize = 1024;

    /// Builds the pipelines.
    #[must_use]
    pub fn new(gpu: &Gpu) -> Self {
        let module = crate::shader::module(&gpu.device, "receivers", include_str!("../shaders/receivers.wgsl"), &[]);
        let weber = crate::shader::module(&gpu.device, "weber", include_str!("../shaders/weber.wgsl"), &[]);
        let gate = crate::shader::module(&gpu.device, "gate", include_str!("../shaders/gate.wgsl"), &[]);
        let pipeline_of = |module: &wgpu::ShaderModule, entry| {
            gpu.compute_pipeline(&wgpu::ComputePipelineDescriptor {
                label: Some(entry),
                layout: None,
                module,
                entry_point: Some(entry),
                compilation_options: Default::default(),
                cache: None,
            })
        };
        let pipeline = |entry| pipeline_of(&module, entry);
        let weber_state = gpu.create_buffer(&wgpu::BufferDescriptor {
            label: Some("weber state"),
            size: WEBER_BYTES + 4 * 2 * Self::MAX_LIGHTS as u64,
            usage: wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_SRC | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });
        let stats = gpu.create_buffer(&wgpu::BufferDescriptor {
            label: Some("receiver stats"),
            size: ReceiverStats::BYTES,
            usage: wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_SRC | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });
        let histogram = gpu.create_buffer(&wgpu::BufferDescriptor {
            label: Some("receiver distance histogram"),
            size: 256 * 4,
            usage: wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });
        Self {
            reduce: pipeline("reduce"),
            finish: pipeline("finish"),
            histogram_pass: pipeline("histogram_pass"),
            select_digit: pipeline("select_digit"),
            stats,
            histogram,
            weber_totals: pipeline_of(&weber, "totals_pass"),
            weber_greedy: pipeline_of(&weber, "greedy"),
            weber_state,
            gate: pipeline_of(&gate, "gate"),
            gate_slots: std::sync::Arc::default(),
            buffers: RefCell::new(None),
            uploads: RefCell::new(Uploads {
                params: writable_buffer(gpu, "receiver params", wgpu::BufferUsages::UNIFORM, 16),
                lights: writable_buffer(gpu, "receiver lights", wgpu::BufferUsages::STORAGE, 256),
                weber_params: writable_buffer(
                    gpu,
                    "weber params",
                    wgpu::BufferUsages::UNIFORM,
                    std::mem::size_of::<WeberParams>() as u64,
                ),
                weber_lights: writable_buffer(gpu, "weber lights", wgpu::BufferUsages::STORAGE, 256),
                binds: Keyed::default(),
                weber_binds: Keyed::default(),
            }),
            reads: ReadPool::default(),
        }
    }

    /// Records the reduction of `gbuffer` for `lights` (and Weber's test when `weber` is given)
    /// and the copy of its result, without submitting. One reduction holds one result: record
    /// a second only after the first one's is read (a frame with two G-buffers uses two).
    ///
    /// # Errors
    /// [`GpuError::TooLarge`] for more than [`ReceiverReduction::MAX_LIGHTS`] lights.
    pub fn record(
        &self,
        gpu: &Gpu,
        encoder: &mut wgpu::CommandEncoder,
        gbuffer: &GBuffer,
        lights: &[LightShape],
        weber: Option<WeberInput<'_>>,
    ) -> Result<PendingStats, GpuError> {
        let most = lights.len().max(weber.map_or(0, |w| w.lights.len()));
        if most > Self::MAX_LIGHTS {
            return Err(GpuError::TooLarge {
                what: "lights for the receiver reduction",
                size: most as u64,
                limit: Self::MAX_LIGHTS as u64,
            });
        }
        let (w, h) = gbuffer.size();
        let groups = (w.div_ceil(16).max(1), h.div_ceil(16).max(1));
        let (stride, columns, rows) = weber_subset((w, h));
        let (partials, totals, skipped) = {
            let mut cached = self.buffers.borrow_mut();
            if cached.as_ref().is_none_or(|b| b.size != (w, h)) {
                let storage = |label, size| {
                    gpu.create_buffer(&wgpu::BufferDescriptor {
                        label: Some(label),
                        size,
                        usage: wgpu::BufferUsages::STORAGE,
                        mapped_at_creation: false,
                    })
                };
                let receivers = u64::from(columns) * u64::from(rows) * 4;
                *cached = Some(Buffers {
                    size: (w, h),
                    partials: storage("receiver partial sums", u64::from(groups.0) * u64::from(groups.1) * 16),
                    totals: storage("weber totals", receivers),
                    skipped: storage("weber skipped shares", receivers),
                });
            }
            let b = cached.as_ref().ok_or_else(|| GpuError::Failed("receiver buffers".into()))?;
            (b.partials.clone(), b.totals.clone(), b.skipped.clone())
        };
        let mut shapes: Vec<GpuLight> = lights
            .iter()
            .map(|l| match *l {
                LightShape::Distant { .. } => {
                    // the CPU's own direction and threshold (`LightShape::reaches`), bit for bit
                    let d = l.direction_from(Vec3::ZERO);
                    GpuLight {
                        place: d.extend(0.0).to_array(),
                        shape: [0.0, 0.0, -l.half_angle_at(Vec3::ZERO).sin(), 0.0],
                    }
                }
                LightShape::Sphere { center, radius } => {
                    GpuLight { place: center.extend(1.0).to_array(), shape: [1.0, radius, 0.0, 0.0] }
                }
            })
            .collect();
        if shapes.is_empty() {
            // storage bindings may not be empty
            shapes.push(bytemuck::Zeroable::zeroed());
        }
        let params = [w, h, lights.len() as u32, groups.0];
        let light_bytes: &[u8] = bytemuck::cast_slice(&shapes);
        let mut uploads = self.uploads.borrow_mut();
        let Uploads { params: params_buf, lights: lights_buf, binds, .. } = &mut *uploads;
        gpu.queue.write_buffer(params_buf, 0, bytemuck::cast_slice(&params));
        write_grown(gpu, lights_buf, "receiver lights", wgpu::BufferUsages::STORAGE, light_bytes);
        let bytes = light_bytes.len() as u64;
        let key = (
            bytes,
            [lights_buf.clone(), partials.clone()],
            [gbuffer.position.clone(), gbuffer.geometric_normal.clone()],
        );
        let [reduce, finish, histogram_pass, select_digit] = binds.get(key, || {
            let position = gbuffer.position.create_view(&Default::default());
            let normal = gbuffer.geometric_normal.create_view(&Default::default());
            let bind = |label, pipeline: &wgpu::ComputePipeline, entries: &[wgpu::BindGroupEntry<'_>]| {
                gpu.create_bind_group(&wgpu::BindGroupDescriptor {
                    label: Some(label),
                    layout: &pipeline.get_bind_group_layout(0),
                    entries,
                })
            };
            let entry = |binding, resource| wgpu::BindGroupEntry { binding, resource };
            let texture = |view| wgpu::BindingResource::TextureView(view);
            [
                bind(
                    "receiver reduce",
                    &self.reduce,
                    &[
                        entry(0, texture(&position)),
                        entry(1, texture(&normal)),
                        entry(2, params_buf.as_entire_binding()),
                        entry(3, binding_of(lights_buf, bytes)),
                        entry(4, self.stats.as_entire_binding()),
                        entry(5, partials.as_entire_binding()),
                    ],
                ),
                bind(
                    "receiver finish",
                    &self.finish,
                    &[entry(4, self.stats.as_entire_binding()), entry(5, partials.as_entire_binding())],
                ),
                bind(
                    "receiver distance histogram",
                    &self.histogram_pass,
                    &[
                        entry(0, texture(&position)),
                        entry(2, params_buf.as_entire_binding()),
                        entry(4, self.stats.as_entire_binding()),
                        entry(6, self.histogram.as_entire_binding()),
                    ],
                ),
                bind(
                    "receiver distance select",
                    &self.select_digit,
                    &[entry(4, self.stats.as_entire_binding()), entry(6, self.histogram.as_entire_binding())],
                ),
            ]
        });
        encoder.clear_buffer(&self.stats, 0, None);
        encoder.clear_buffer(&self.histogram, 0, None);
        {
            let mut pass = encoder
                .begin_compute_pass(&wgpu::ComputePassDescriptor { label: Some("receivers"), timestamp_writes: None });
            pass.set_pipeline(&self.reduce);
            pass.set_bind_group(0, reduce, &[]);
            pass.dispatch_workgroups(groups.0, groups.1, 1);
            pass.set_pipeline(&self.finish);
            pass.set_bind_group(0, finish, &[]);
            pass.dispatch_workgroups(1, 1, 1);
            for _ in 0..DIGITS {
                pass.set_pipeline(&self.histogram_pass);
                pass.set_bind_group(0, histogram_pass, &[]);
                pass.dispatch_workgroups(groups.0, groups.1, 1);
                pass.set_pipeline(&self.select_digit);
                pass.set_bind_group(0, select_digit, &[]);
                pass.dispatch_workgroups(1, 1, 1);
            }
        }
        let read = pooled_read(gpu, &self.reads, "receiver stats read", ReceiverStats::BYTES);
        encoder.copy_buffer_to_buffer(&self.stats, 0, &read, 0, ReceiverStats::BYTES);
        drop(uploads);
        let weber = weber
            .map(|input| {
                self.record_weber(gpu, encoder, gbuffer, input, (stride, columns, rows), (&totals, &skipped))
                    .map(|b| (b, input.lights.len()))
            })
            .transpose()?;
        let on_gpu = GpuStats {
            stats: self.stats.clone(),
            weber: weber.as_ref().map(|_| self.weber_state.clone()),
            gate: self.gate.clone(),
            first: 0,
            slots: self.gate_slots.clone(),
        };
        Ok(PendingStats { read, lights: lights.len(), weber, on_gpu, pool: self.reads.clone() })
    }

    /// Records Weber's passes and the copy of their result.
    fn record_weber(
        &self,
        gpu: &Gpu,
        encoder: &mut wgpu::CommandEncoder,
        gbuffer: &GBuffer,
        input: WeberInput<'_>,
        (stride, columns, rows): (u32, u32, u32),
        (totals, skipped): (&wgpu::Buffer, &wgpu::Buffer),
    ) -> Result<wgpu::Buffer, GpuError> {
        // as `weber_negligible` computes them, so that the shader starts from the same bits
        let luminance = |c: Vec3| c.dot(Vec3::new(0.2126, 0.7152, 0.0722));
        let mut lights: Vec<GpuLight> = input
            .lights
            .iter()
            .map(|l| match *l {
                ShadeLight::Distant { direction, irradiance, half_angle } => GpuLight {
                    place: direction.extend(0.0).to_array(),
                    shape: [luminance(irradiance), half_angle, 0.0, 0.0],
                },
                ShadeLight::Point { position, intensity } => {
                    GpuLight { place: position.extend(1.0).to_array(), shape: [luminance(intensity), 0.0, 0.0, 0.0] }
                }
            })
            .collect();
        if lights.is_empty() {
            lights.push(bytemuck::Zeroable::zeroed());
        }
        let params = WeberParams {
            size: [gbuffer.size().0, gbuffer.size().1, stride, input.lights.len() as u32],
            info: [input.fraction, if input.ambient.is_some() { 1.0 } else { 0.0 }, columns as f32, 0.0],
            sh: input.ambient.map_or([[0.0; 4]; 9], |a| a.irradiance_coefficients().map(|c| c.extend(0.0).to_array())),
        };
        let light_bytes: &[u8] = bytemuck::cast_slice(&lights);
        let mut uploads = self.uploads.borrow_mut();
        let Uploads { weber_params, weber_lights, weber_binds, .. } = &mut *uploads;
        gpu.queue.write_buffer(weber_params, 0, bytemuck::bytes_of(&params));
        write_grown(gpu, weber_lights, "weber lights", wgpu::BufferUsages::STORAGE, light_bytes);
        let bytes = light_bytes.len() as u64;
        let key = (
            bytes,
            [weber_lights.clone(), totals.clone(), skipped.clone()],
            [gbuffer.position.clone(), gbuffer.geometric_normal.clone()],
        );
        let [totals_bind, greedy_bind] = weber_binds.get(key, || {
            let position = gbuffer.position.create_view(&Default::default());
            let normal = gbuffer.geometric_normal.create_view(&Default::default());
            let bind = |pipeline: &wgpu::ComputePipeline| {
                gpu.create_bind_group(&wgpu::BindGroupDescriptor {
                    label: Some("weber"),
                    layout: &pipeline.get_bind_group_layout(0),
                    entries: &[
                        wgpu::BindGroupEntry { binding: 0, resource: wgpu::BindingResource::TextureView(&position) },
                        wgpu::BindGroupEntry { binding: 1, resource: wgpu::BindingResource::TextureView(&normal) },
                        wgpu::BindGroupEntry { binding: 2, resource: weber_params.as_entire_binding() },
                        wgpu::BindGroupEntry { binding: 3, resource: binding_of(weber_lights, bytes) },
                        wgpu::BindGroupEntry { binding: 4, resource: self.weber_state.as_entire_binding() },
                        wgpu::BindGroupEntry { binding: 5, resource: totals.as_entire_binding() },
                        wgpu::BindGroupEntry { binding: 6, resource: skipped.as_entire_binding() },
                    ],
                })
            };
            [bind(&self.weber_totals), bind(&self.weber_greedy)]
        });
        encoder.clear_buffer(&self.weber_state, 0, None);
        {
            let mut pass = encoder
                .begin_compute_pass(&wgpu::ComputePassDescriptor { label: Some("weber"), timestamp_writes: None });
            pass.set_pipeline(&self.weber_totals);
            pass.set_bind_group(0, totals_bind, &[]);
            pass.dispatch_workgroups((columns * rows).div_ceil(64).max(1), 1, 1);
            pass.set_pipeline(&self.weber_greedy);
            pass.set_bind_group(0, greedy_bind, &[]);
            pass.dispatch_workgroups(1, 1, 1);
        }
        let read = pooled_read(gpu, &self.reads, "weber read", WEBER_BYTES);
        encoder.copy_buffer_to_buffer(&self.weber_state, 0, &read, 0, WEBER_BYTES);
        Ok(read)
    }
}

/// Weber's regular subset of a `w` × `h` image, as `weber_negligible` takes it: (stride,
/// columns, rows).
fn weber_subset((w, h): (u32, u32)) -> (u32, u32, u32) {
    let pixels = (w as usize * h as usize).max(1);
    let stride = ((pixels as f64 / crate::WEBER_MAX_RECEIVERS as f64).sqrt().ceil() as u32).max(1);
    (stride, w.div_ceil(stride).max(1), h.div_ceil(stride).max(1))
}

impl PendingStats {
    /// The result where it is, on the GPU: what gates the frame's lights
    /// ([`GpuStats::gate`]) and what orthographic maps take their focus from, with no wait.
    #[must_use]
    pub fn on_gpu(&self) -> &GpuStats {
        &self.on_gpu
    }

    /// Asks for the result to be mapped (its encoder submitted) and returns at once: read it
    /// with [`MappedStats::finish`] once the frame has finished, without a wait of its own.
    #[must_use]
    pub fn map(self, gpu: &Gpu) -> MappedStats {
        let buffers = std::iter::once(self.read.clone()).chain(self.weber.as_ref().map(|w| w.0.clone())).collect();
        MappedStats { mapping: crate::readback::MappingRead::start(gpu, buffers), pending: self }
    }

    /// Maps the result (its encoder submitted): a wait.
    ///
    /// # Errors
    /// GPU failures.
    pub fn read(self, gpu: &Gpu) -> Result<ReceiverStats, GpuError> {
        Ok(Self::read_all(gpu, vec![self])?.swap_remove(0))
    }

    /// Maps every result (their encoders submitted) with one wait.
    ///
    /// # Errors
    /// GPU failures.
    pub fn read_all(gpu: &Gpu, pending: Vec<PendingStats>) -> Result<Vec<ReceiverStats>, GpuError> {
        let buffers: Vec<&wgpu::Buffer> =
            pending.iter().flat_map(|p| std::iter::once(&p.read).chain(p.weber.as_ref().map(|w| &w.0))).collect();
        let mut mapped = crate::readback::read_mapped_all(gpu, &buffers)?.into_iter();
        let mut out = Vec::with_capacity(pending.len());
        for p in pending {
            let bytes = mapped.next().unwrap_or_default();
            let weber = p.weber.as_ref().map(|_| mapped.next().unwrap_or_default());
            out.push(p.decode(&bytes, weber.as_deref())?);
            p.recycle();
        }
        Ok(out)
    }

    /// Hands the read (and unmapped) buffers back to their reduction's pool.
    fn recycle(self) {
        let mut pool = self.pool.lock().unwrap_or_else(std::sync::PoisonError::into_inner);
        pool.push(self.read);
        pool.extend(self.weber.map(|w| w.0));
    }

    fn decode(&self, bytes: &[u8], weber: Option<&[u8]>) -> Result<ReceiverStats, GpuError> {
        if (bytes.len() as u64) < ReceiverStats::BYTES || weber.is_some_and(|w| (w.len() as u64) < WEBER_BYTES) {
            return Err(GpuError::Failed("receiver stats: a short read".into()));
        }
        let words: Vec<u32> = bytemuck::pod_collect_to_vec(bytes);
        let count = words[6];
        let lo = Vec3::new(from_key(!words[0]), from_key(!words[1]), from_key(!words[2]));
        let hi = Vec3::new(from_key(words[3]), from_key(words[4]), from_key(words[5]));
        let mean: [f32; 4] = bytemuck::pod_read_unaligned(&bytes[176..192]);
        let bit = |words: &[u32], k: usize| words[k / 32] & (1 << (k % 32)) != 0;
        let faces = (0..self.lights).map(|k| bit(&words[12..], k)).collect();
        let negligible = match (weber, &self.weber) {
            (Some(w), Some((_, n))) => {
                let w: Vec<u32> = bytemuck::pod_collect_to_vec(w);
                (0..*n).map(|k| bit(&w[4..], k)).collect()
            }
            _ => Vec::new(),
        };
        Ok(ReceiverStats {
            bounds: (count > 0).then_some((lo, hi)),
            count,
            mean: (count > 0).then(|| Vec3::new(mean[0], mean[1], mean[2])),
            radius: (count > 0).then(|| f32::from_bits(words[48])),
            faces,
            negligible,
        })
    }
}

impl MappedStats {
    /// The statistics, once the work that made them has finished (the caller waited for its
    /// frame, or a later one): it never waits.
    ///
    /// # Errors
    /// [`GpuError::Failed`] when the work has not finished or the mapping failed.
    pub fn finish(self, gpu: &Gpu) -> Result<ReceiverStats, GpuError> {
        let mut bytes = self.mapping.finish(gpu)?.into_iter();
        let stats = bytes.next().unwrap_or_default();
        let weber = bytes.next();
        let stats = self.pending.decode(&stats, weber.as_deref());
        self.pending.recycle();
        stats
    }
}
