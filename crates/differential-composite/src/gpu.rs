//! The compositor on the GPU (paper 003, Section 7, on wgpu): per frame the G-buffer of the
//! reconstruction with the object, then per representative a hard shadow map of the object's
//! simplified mesh from its origin (one hemispherical paraboloid map for a patch, paper 004;
//! an orthographic map for a distant light), all of them layers of as few texture arrays as the
//! adapter allows and rendered in one submission; then one pass per array that, per pixel,
//! adds every representative's transfer where its map says the object blocks it into a
//! darkening buffer (the paper's blending pass per source, folded into a loop); last the
//! resolve: the object shaded by its SH9 irradiance, the rest the photograph less the darkening
//! (HDR: in radiance, then the camera response; LDR: in codes). `GpuCompositor::record` records
//! the whole frame into the caller's encoder (no submission, wait or readback);
//! `GpuCompositor::record_staged` is the same recording with a hook between stages, which
//! measurement (`trade::composite_rows::composite`) times; nothing here waits.
//!
//! Shaders: `crates/differential-composite/shaders/`.

use std::time::Duration;

use glam::Vec3;
use gpu::{GBuffer, GBufferPass, Gpu, GpuError, SceneGeometry, ShadowGeometry};
use shadowmap_paraboloid::{DEPTH_FORMAT, MapView, Pcss, ShadowMapper, ShadowSettings, Technique};
use shaft_hierarchy::preprocess::{Origin, Source};

use crate::compositor::{Compositor, FrameTransfers, RepTransfer};
use crate::{Mode, SyntheticObject};

/// Knobs of the GPU compositor.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct GpuSettings {
    /// Side of each shadow map, texels (paper: 256).
    pub map_resolution: u32,
    /// The sphere's shadow mesh detail (slices; about detail^2 triangles; paper: 100-500).
    pub shadow_detail: u32,
    /// A patch source's map: one hemispherical paraboloid (paper 004), or a cube of six faces
    /// (the baseline that does not know the source emits into a hemisphere).
    pub patch_maps: Technique,
    /// Most layers of one texture array of maps (a frame's maps share as few arrays as this
    /// allows, one mask dispatch each); `None`: the adapter's limit.
    pub layers_per_array: Option<u32>,
    /// Soft shadows of distant representatives: percentage-closer soft shadows over the cone
    /// holding the sources each stands for ([`RepTransfer::half_angle`]); `None`: the paper's
    /// hard masks.
    pub pcss: Option<Pcss>,
    /// n x n G-buffer samples a pixel for the object's coverage (its edge antialiased: the
    /// object's mean radiance blended over the darkened photograph); 1: the pixel centre alone
    /// (the paper's), at most 4.
    pub coverage_samples: u32,
    /// Test each distant representative's mask only inside the screen rectangle its shadow can
    /// reach ([`shadow_rect`]: the object's box swept away from the light over the cone of its
    /// sources, within the model's bounds); the image is the same (tested), the work less.
    pub cull_masks: bool,
}

impl Default for GpuSettings {
    /// The paper's: 256^2 maps, a 484-triangle sphere, hemispherical paraboloid maps, hard
    /// masks.
    fn default() -> Self {
        Self {
            map_resolution: 256,
            shadow_detail: 22,
            patch_maps: Technique::DualParaboloid,
            layers_per_array: None,
            pcss: None,
            coverage_samples: 1,
            cull_masks: false,
        }
    }
}

impl GpuSettings {
    /// The light and projection of representative `r`'s shadow map: a patch's hemispherical
    /// paraboloid (or a cube), an omnidirectional paraboloid from a point on a distant source, an
    /// orthographic map along a direction.
    #[must_use]
    pub fn map_light(&self, c: &Compositor, r: &RepTransfer) -> (MapView, Technique) {
        match (r.origin, c.prepared.sources[r.origin_source as usize]) {
            (Origin::Point(p), Source::Patch(_)) if self.patch_maps == Technique::Cube => {
                (MapView::omni(p), Technique::Cube)
            }
            (Origin::Point(p), Source::Patch(j)) => {
                let n = c.model.patches[j as usize].normal();
                (MapView::Point { position: p, hemisphere: Some(n) }, Technique::DualParaboloid)
            }
            (Origin::Point(p), Source::Distant(_)) => (MapView::omni(p), Technique::DualParaboloid),
            (Origin::Direction(d), _) => (MapView::Distant { direction: d }, Technique::Orthographic),
        }
    }
}

/// Consecutive runs of maps of `views` layers each whose layers fit in `max_layers` (at least
/// one map a run, whatever its size): (first map, layers) per run.
#[must_use]
pub fn batches(views: &[u32], max_layers: u32) -> Vec<(usize, u32)> {
    let mut out: Vec<(usize, u32)> = Vec::new();
    for (k, &n) in views.iter().enumerate() {
        match out.last_mut() {
            Some((_, layers)) if *layers + n <= max_layers => *layers += n,
            _ => out.push((k, n)),
        }
    }
    out
}

/// What a frame's shadow maps cost in views, and what was left out.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct MapWork {
    /// Views rendered: paraboloid hemispheres, cube faces, orthographic maps.
    pub views: u32,
    /// Paraboloid hemispheres not rendered: a patch emits into one hemisphere (paper 004).
    pub hemispheres_skipped: u32,
}

/// Where a GPU frame's time went: the CPU's work, then each GPU stage between timestamps of
/// its own (the frame recorded into one submission, as [`GpuCompositor::record`] records it),
/// or, without timestamps inside encoders, each stage submitted and waited for on the wall
/// clock (`trade::composite_rows::composite` measures it).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct FrameTimes {
    /// Traversal, representative set, transfers and the object's irradiance probe, and the
    /// recording of the GPU's commands (CPU).
    pub cpu: Duration,
    /// The G-buffer of the reconstruction with the object.
    pub gbuffer: Duration,
    /// The representatives' shadow maps.
    pub shadow_maps: Duration,
    /// Their masks and the darkening.
    pub masks: Duration,
    /// The resolve into the output.
    pub resolve: Duration,
    /// Which clock timed the GPU's stages.
    pub clock: gpu::Clock,
}

impl FrameTimes {
    /// The whole frame.
    #[must_use]
    pub fn total(&self) -> Duration {
        self.cpu + self.gbuffer + self.shadow_maps + self.masks + self.resolve
    }
}

#[repr(C)]
#[derive(Clone, Copy, bytemuck::Pod, bytemuck::Zeroable)]
struct GpuPixel {
    weights: [f32; 4],
    position: [f32; 4],
    normal: [f32; 4],
    slot: u32,
    pad: [u32; 3],
}

#[repr(C)]
#[derive(Clone, Copy, bytemuck::Pod, bytemuck::Zeroable)]
struct MaskParams {
    width: u32,
    height: u32,
    slots: u32,
    reps: u32,
    first_rep: u32,
    origin: [u32; 2],
    object_radius: f32,
}

#[repr(C)]
#[derive(Clone, Copy, bytemuck::Pod, bytemuck::Zeroable)]
struct ResolveParams {
    width: u32,
    height: u32,
    mode: u32,
    object: u32,
    samples: u32,
    light_count: u32,
    pad: [u32; 2],
    response: [f32; 4],
    albedo: [f32; 4],
    irradiance: [[f32; 4]; 9],
    lights: [[f32; 4]; 16],
}

/// Lights the resolve shades the object by per pixel.
pub const MAX_OBJECT_LIGHTS: usize = 8;

/// The GPU compositor of one [`Compositor`]: its static buffers and pipelines.
pub struct GpuCompositor {
    pixels: wgpu::Buffer,
    photo_hdr: wgpu::Buffer,
    photo_ldr: wgpu::Buffer,
    pixel_scale: wgpu::Buffer,
    darkening: wgpu::Buffer,
    out: wgpu::Buffer,
    out_hdr: wgpu::Buffer,
    masks: wgpu::ComputePipeline,
    resolve: wgpu::ComputePipeline,
    gbuffer: GBufferPass,
    mapper: ShadowMapper,
    size: (u32, u32),
}

impl GpuCompositor {
    /// Uploads `c`'s photograph and pixel table and builds the pipelines.
    ///
    /// # Errors
    /// Sizes beyond the adapter's limits.
    pub fn new(gpu: &Gpu, c: &Compositor) -> Result<Self, GpuError> {
        let (w, h) = c.size;
        gpu.check_texture(w, h, 1)?;
        let storage = |label: &str, bytes: &[u8], extra: wgpu::BufferUsages| {
            gpu.create_buffer_init(&wgpu::util::BufferInitDescriptor {
                label: Some(label),
                contents: bytes,
                usage: wgpu::BufferUsages::STORAGE | extra,
            })
        };
        let table: Vec<GpuPixel> = c
            .pixels
            .iter()
            .map(|p| {
                // a pixel that meets nothing keeps no point (slot NONE: the masks skip it)
                let finite = |v: Vec3| if v.is_finite() { v.extend(0.0).to_array() } else { [0.0; 4] };
                GpuPixel {
                    weights: p.weights,
                    position: finite(p.position),
                    normal: finite(p.normal),
                    slot: p.slot,
                    pad: [0; 3],
                }
            })
            .collect();
        let hdr: Vec<[f32; 4]> = c.photo_hdr.iter().map(|v| v.extend(1.0).to_array()).collect();
        let ldr: Vec<u32> = c.photo_ldr.iter().map(|p| pack(*p)).collect();
        let scale: Vec<[f32; 4]> = c.pixel_scale.iter().map(|v| v.extend(1.0).to_array()).collect();
        let n = u64::from(w) * u64::from(h);
        let module =
            |label: &str, src: &str| gpu::shader::module(&gpu.device, label, src, shadowmap_paraboloid::LIBRARY);
        let pipeline = |label: &str, m: &wgpu::ShaderModule| {
            gpu.compute_pipeline(&wgpu::ComputePipelineDescriptor {
                label: Some(label),
                layout: None,
                module: m,
                entry_point: Some("main"),
                compilation_options: Default::default(),
                cache: None,
            })
        };
        let masks = pipeline("composite masks", &module("composite masks", include_str!("../shaders/masks.wgsl")));
        let resolve =
            pipeline("composite resolve", &module("composite resolve", include_str!("../shaders/resolve.wgsl")));
        Ok(Self {
            pixels: storage("composite pixels", bytemuck::cast_slice(&table), wgpu::BufferUsages::empty()),
            photo_hdr: storage("photo hdr", bytemuck::cast_slice(&hdr), wgpu::BufferUsages::empty()),
            photo_ldr: storage("photo ldr", bytemuck::cast_slice(&ldr), wgpu::BufferUsages::empty()),
            pixel_scale: storage("pixel scale", bytemuck::cast_slice(&scale), wgpu::BufferUsages::empty()),
            darkening: gpu.create_buffer(&wgpu::BufferDescriptor {
                label: Some("darkening"),
                size: n * 16,
                usage: wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_DST,
                mapped_at_creation: false,
            }),
            out: gpu.create_buffer(&wgpu::BufferDescriptor {
                label: Some("composite"),
                size: n * 4,
                usage: wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_SRC,
                mapped_at_creation: false,
            }),
            out_hdr: gpu.create_buffer(&wgpu::BufferDescriptor {
                label: Some("composite hdr"),
                size: n * 16,
                usage: wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_SRC,
                mapped_at_creation: false,
            }),
            masks,
            resolve,
            gbuffer: GBufferPass::new(gpu),
            mapper: ShadowMapper::new(gpu),
            size: (w, h),
        })
    }

    /// Records the whole composite of `frame` for `object` in `mode` into `encoder`, without
    /// submitting: the G-buffer of the reconstruction with the object, every representative's
    /// map, the masks and darkening, the resolve into [`GpuCompositor::output`] (the 8-bit
    /// image, a `u32` per pixel, RGB in its low bytes). No submission, wait or readback: what a
    /// renderer's frame calls. Returns the maps' work.
    ///
    /// # Errors
    /// GPU failures; sizes beyond the device's limits.
    #[allow(clippy::too_many_arguments)]
    pub fn record(
        &self,
        gpu: &Gpu,
        encoder: &mut wgpu::CommandEncoder,
        c: &Compositor,
        frame: &FrameTransfers,
        object: &SyntheticObject,
        mode: Mode,
        settings: &GpuSettings,
    ) -> Result<MapWork, GpuError> {
        self.record_staged(gpu, encoder, (c, frame, object), mode, settings, &mut |_, _| Ok(()))
    }

    /// [`GpuCompositor::record`] with `between(encoder, k)` called before the first stage
    /// (k = 0) and after each of the four (G-buffer, maps, masks, resolve: k = 1..=4): where
    /// measurement writes a GPU timestamp, or, without them, submits the stage recorded so far
    /// (swapping in a new encoder) and times it (`trade::composite_rows::composite`).
    ///
    /// # Errors
    /// GPU failures; sizes beyond the device's limits; `between`'s own.
    pub fn record_staged(
        &self,
        gpu: &Gpu,
        encoder: &mut wgpu::CommandEncoder,
        (c, frame, object): (&Compositor, &FrameTransfers, &SyntheticObject),
        mode: Mode,
        settings: &GpuSettings,
        between: &mut dyn FnMut(&mut wgpu::CommandEncoder, usize) -> Result<(), GpuError>,
    ) -> Result<MapWork, GpuError> {
        between(encoder, 0)?;
        let gb = self.record_gbuffer(gpu, encoder, c, object, settings)?;
        between(encoder, 1)?;
        let maps = self.record_maps(gpu, encoder, c, frame, object, settings)?;
        between(encoder, 2)?;
        self.record_masks(gpu, encoder, (c, frame, object), mode, settings, &maps);
        between(encoder, 3)?;
        self.record_resolve(gpu, encoder, c, &gb, frame, object, mode);
        between(encoder, 4)?;
        Ok(maps.work)
    }

    /// The composite's output once its encoder has run: a `u32` per pixel, row-major, RGB in
    /// its low three bytes (`STORAGE | COPY_SRC`).
    #[must_use]
    pub fn output(&self) -> &wgpu::Buffer {
        &self.out
    }

    /// Reads [`GpuCompositor::output`] back (its work submitted): a wait.
    ///
    /// # Errors
    /// GPU failures.
    pub fn read_output(&self, gpu: &Gpu) -> Result<Vec<[u8; 3]>, GpuError> {
        let bytes = gpu::read_buffer(gpu, &self.out)?;
        Ok(bytes.chunks_exact(4).map(|p| [p[0], p[1], p[2]]).collect())
    }

    /// The composite in radiance once its encoder has run (HDR mode: what the 8-bit output is
    /// the camera response of; LDR mode leaves the photograph's radiance where it subtracts
    /// codes): a `vec4<f32>` per pixel, row-major (`STORAGE | COPY_SRC`).
    #[must_use]
    pub fn output_hdr(&self) -> &wgpu::Buffer {
        &self.out_hdr
    }

    /// Reads [`GpuCompositor::output_hdr`] back (its work submitted): a wait.
    ///
    /// # Errors
    /// GPU failures.
    pub fn read_output_hdr(&self, gpu: &Gpu) -> Result<Vec<Vec3>, GpuError> {
        let bytes = gpu::read_buffer(gpu, &self.out_hdr)?;
        // the bytes need not be aligned for f32
        let f = |b: &[u8]| f32::from_le_bytes([b[0], b[1], b[2], b[3]]);
        Ok(bytes.chunks_exact(16).map(|p| Vec3::new(f(&p[0..4]), f(&p[4..8]), f(&p[8..12]))).collect())
    }

    /// The G-buffer of the reconstruction with the object (its index: after the patches).
    fn record_gbuffer(
        &self,
        gpu: &Gpu,
        encoder: &mut wgpu::CommandEncoder,
        c: &Compositor,
        object: &SyntheticObject,
        settings: &GpuSettings,
    ) -> Result<GBuffer, GpuError> {
        let mut scene = c.model.to_scene();
        scene.objects.push(object.to_object());
        let geometry = SceneGeometry::upload(gpu, &scene)?;
        // n x n samples a pixel for the object's coverage: the same camera at n times the size
        let n = settings.coverage_samples.clamp(1, 4);
        let camera = scene::Camera { width: scene.camera.width * n, height: scene.camera.height * n, ..scene.camera };
        gpu.check_texture(camera.width, camera.height, 1)?;
        self.gbuffer.record(gpu, encoder, &geometry, &camera)
    }

    /// Every representative's map, into layers of as few texture arrays as the adapter allows.
    fn record_maps(
        &self,
        gpu: &Gpu,
        encoder: &mut wgpu::CommandEncoder,
        c: &Compositor,
        frame: &FrameTransfers,
        object: &SyntheticObject,
        settings: &GpuSettings,
    ) -> Result<Maps, GpuError> {
        let casters: Vec<[Vec3; 3]> = {
            let m = object.shadow_mesh(settings.shadow_detail);
            (0..m.indices.len()).map(|t| m.triangle(t)).collect()
        };
        let casters = ShadowGeometry::upload(gpu, &casters, ShadowGeometry::CHUNK_TRIANGLES)?;
        let map_settings = ShadowSettings {
            resolution: settings.map_resolution,
            pcss: settings.pcss,
            // the object's few hundred triangles subtend a small angle from a source
            subdivide_angle: None,
            ..ShadowSettings::default()
        };
        let lights: Vec<(MapView, Technique)> = frame.reps.iter().map(|r| settings.map_light(c, r)).collect();
        let limit = gpu.device.limits().max_texture_array_layers;
        let views: Vec<u32> = lights.iter().map(|(l, t)| ShadowMapper::view_count(l, *t)).collect();
        let batches = batches(&views, settings.layers_per_array.map_or(limit, |n| n.min(limit)));
        let res = map_settings.resolution;
        let mut arrays = Vec::with_capacity(batches.len());
        let mut params: Vec<Vec<shadowmap_paraboloid::MapParams>> = Vec::with_capacity(batches.len());
        let mut work = MapWork::default();
        for (b, &(first, layers)) in batches.iter().enumerate() {
            let end = batches.get(b + 1).map_or(lights.len(), |next| next.0);
            let array = gpu::render_target(gpu, "composite shadow maps", (res, res, layers), DEPTH_FORMAT)?;
            let mut layer = 0;
            let mut mine = Vec::with_capacity(end - first);
            for ((light, technique), rep) in lights[first..end].iter().zip(&frame.reps[first..end]) {
                let map = self.mapper.record(
                    gpu,
                    encoder,
                    &casters,
                    light,
                    *technique,
                    &map_settings,
                    Some((&array, layer)),
                    shadowmap_paraboloid::OnGpu::default(),
                )?;
                mine.push(map.lookup_params(rep.half_angle, layer));
                layer += map.views.len() as u32;
                work.views += map.views.len() as u32;
                // a hemispherical light's paraboloid map has its front view alone
                if map.technique == Technique::DualParaboloid
                    && matches!(light, MapView::Point { hemisphere: Some(_), .. })
                {
                    work.hemispheres_skipped += 2 - map.views.len() as u32;
                }
            }
            arrays.push(array);
            params.push(mine);
        }
        Ok(Maps { arrays, params, batches, work })
    }

    /// The darkening cleared, then every mask and its share of it, one dispatch per array.
    #[allow(clippy::too_many_arguments)]
    fn record_masks(
        &self,
        gpu: &Gpu,
        encoder: &mut wgpu::CommandEncoder,
        (c, frame, object): (&Compositor, &FrameTransfers, &SyntheticObject),
        mode: Mode,
        settings: &GpuSettings,
        maps: &Maps,
    ) {
        let (w, h) = self.size;
        let bounds = object.bounds();
        let rects: Vec<[u32; 4]> = frame
            .reps
            .iter()
            .map(|r| if settings.cull_masks { shadow_rect(c, &bounds, r) } else { [0, 0, w, h] })
            .collect();
        // the representatives' transfers, rep-major
        let slots = c.prepared.transfers.slots;
        let mut transfers: Vec<[f32; 4]> = Vec::with_capacity(frame.reps.len().max(1) * slots);
        for r in &frame.reps {
            let v = match mode {
                Mode::Hdr => &r.radiance,
                Mode::Ldr => &r.intensity,
            };
            transfers.extend(v.iter().map(|x| x.extend(0.0).to_array()));
        }
        if transfers.is_empty() {
            transfers.push([0.0; 4]);
        }
        let buffer = |label, contents: &[u8], usage| {
            gpu.create_buffer_init(&wgpu::util::BufferInitDescriptor { label: Some(label), contents, usage })
        };
        let transfer_buffer = buffer("transfers", bytemuck::cast_slice(&transfers), wgpu::BufferUsages::STORAGE);
        // per representative what a blocked receiver keeps of its transfer (LDR: its
        // intensities hold it already)
        let mut keeps: Vec<[f32; 4]> = frame
            .reps
            .iter()
            .map(|r| if mode == Mode::Hdr { r.keep.extend(1.0).to_array() } else { [1.0; 4] })
            .collect();
        if keeps.is_empty() {
            keeps.push([1.0; 4]);
        }
        let keep_buffer = buffer("keeps", bytemuck::cast_slice(&keeps), wgpu::BufferUsages::STORAGE);
        // the object's bounding radius: a blocker within it of the receiver is at the contact
        let object_radius = 0.5 * (bounds.max - bounds.min).length();
        encoder.clear_buffer(&self.darkening, 0, None);
        for ((array, mine), &(first, _)) in maps.arrays.iter().zip(&maps.params).zip(&maps.batches) {
            // the dispatch covers the union of the batch's rectangles, no more
            let mut union = [w, h, 0, 0];
            for r in &rects[first..first + mine.len()] {
                if r[2] > r[0] && r[3] > r[1] {
                    union = [union[0].min(r[0]), union[1].min(r[1]), union[2].max(r[2]), union[3].max(r[3])];
                }
            }
            if union[2] <= union[0] || union[3] <= union[1] {
                continue;
            }
            let uniform = MaskParams {
                width: w,
                height: h,
                slots: slots as u32,
                reps: mine.len() as u32,
                first_rep: first as u32,
                origin: [union[0], union[1]],
                object_radius,
            };
            let uniform = buffer("mask params", bytemuck::bytes_of(&uniform), wgpu::BufferUsages::UNIFORM);
            let params = buffer("mask maps", bytemuck::cast_slice(mine), wgpu::BufferUsages::STORAGE);
            let batch_rects = buffer(
                "mask rectangles",
                bytemuck::cast_slice(&rects[first..first + mine.len()]),
                wgpu::BufferUsages::STORAGE,
            );
            let depth = array.create_view(&wgpu::TextureViewDescriptor {
                dimension: Some(wgpu::TextureViewDimension::D2Array),
                aspect: wgpu::TextureAspect::DepthOnly,
                ..Default::default()
            });
            let bind = gpu.create_bind_group(&wgpu::BindGroupDescriptor {
                label: Some("composite masks"),
                layout: &self.masks.get_bind_group_layout(0),
                entries: &[
                    wgpu::BindGroupEntry { binding: 0, resource: uniform.as_entire_binding() },
                    wgpu::BindGroupEntry { binding: 1, resource: self.pixels.as_entire_binding() },
                    wgpu::BindGroupEntry { binding: 2, resource: transfer_buffer.as_entire_binding() },
                    wgpu::BindGroupEntry { binding: 3, resource: params.as_entire_binding() },
                    wgpu::BindGroupEntry { binding: 4, resource: wgpu::BindingResource::TextureView(&depth) },
                    wgpu::BindGroupEntry { binding: 5, resource: self.darkening.as_entire_binding() },
                    wgpu::BindGroupEntry { binding: 6, resource: batch_rects.as_entire_binding() },
                    wgpu::BindGroupEntry { binding: 7, resource: keep_buffer.as_entire_binding() },
                ],
            });
            let mut pass = encoder.begin_compute_pass(&wgpu::ComputePassDescriptor::default());
            pass.set_pipeline(&self.masks);
            pass.set_bind_group(0, &bind, &[]);
            pass.dispatch_workgroups((union[2] - union[0]).div_ceil(8), (union[3] - union[1]).div_ceil(8), 1);
        }
    }

    /// The object shaded by its SH9 irradiance, the rest the photograph less the darkening,
    /// into [`GpuCompositor::output`].
    #[allow(clippy::too_many_arguments)]
    fn record_resolve(
        &self,
        gpu: &Gpu,
        encoder: &mut wgpu::CommandEncoder,
        c: &Compositor,
        gb: &GBuffer,
        frame: &FrameTransfers,
        object: &SyntheticObject,
        mode: Mode,
    ) {
        let (w, h) = self.size;
        let irradiance = frame.object_irradiance.irradiance_coefficients().map(|v| v.extend(0.0).to_array());
        let lights: Vec<[f32; 4]> = frame
            .object_lights
            .iter()
            .take(MAX_OBJECT_LIGHTS)
            .flat_map(|l| [l.direction.extend(0.0).to_array(), l.power().extend(0.0).to_array()])
            .collect();
        let params = ResolveParams {
            width: w,
            height: h,
            mode: u32::from(mode == Mode::Ldr),
            object: c.model.patches.len() as u32,
            samples: gb.position.width() / w.max(1),
            light_count: lights.len() as u32 / 2,
            pad: [0; 2],
            response: [c.response.exposure, 1.0 / c.response.gamma, c.response.white, c.clip.unwrap_or(0.0)],
            albedo: (object.albedo / std::f32::consts::PI).extend(0.0).to_array(),
            irradiance,
            lights: std::array::from_fn(|k| lights.get(k).copied().unwrap_or([0.0; 4])),
        };
        let uniform = gpu.create_buffer_init(&wgpu::util::BufferInitDescriptor {
            label: Some("resolve params"),
            contents: bytemuck::bytes_of(&params),
            usage: wgpu::BufferUsages::UNIFORM,
        });
        let position = gb.position.create_view(&wgpu::TextureViewDescriptor::default());
        let normal = gb.normal.create_view(&wgpu::TextureViewDescriptor::default());
        let bind = gpu.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("resolve"),
            layout: &self.resolve.get_bind_group_layout(0),
            entries: &[
                wgpu::BindGroupEntry { binding: 0, resource: uniform.as_entire_binding() },
                wgpu::BindGroupEntry { binding: 1, resource: self.photo_hdr.as_entire_binding() },
                wgpu::BindGroupEntry { binding: 2, resource: self.photo_ldr.as_entire_binding() },
                wgpu::BindGroupEntry { binding: 3, resource: self.darkening.as_entire_binding() },
                wgpu::BindGroupEntry { binding: 4, resource: wgpu::BindingResource::TextureView(&position) },
                wgpu::BindGroupEntry { binding: 5, resource: wgpu::BindingResource::TextureView(&normal) },
                wgpu::BindGroupEntry { binding: 6, resource: self.out.as_entire_binding() },
                wgpu::BindGroupEntry { binding: 7, resource: self.pixel_scale.as_entire_binding() },
                wgpu::BindGroupEntry { binding: 8, resource: self.out_hdr.as_entire_binding() },
            ],
        });
        let mut pass = encoder.begin_compute_pass(&wgpu::ComputePassDescriptor::default());
        pass.set_pipeline(&self.resolve);
        pass.set_bind_group(0, &bind, &[]);
        pass.dispatch_workgroups(w.div_ceil(8), h.div_ceil(8), 1);
    }
}

/// The pixels (x0, y0, x1, y1; the ends excluded) where representative `rep`'s mask can be
/// other than lit, for an object within `object`: for a distant origin, the object's box swept
/// away from the light (along every direction of the representative's cone) and kept within the
/// model's bounds, where every receiver lies, projected by the model's camera, a pixel added
/// around; the whole image for a point origin or where that region reaches behind the camera;
/// an empty rectangle where it misses the model.
#[must_use]
pub fn shadow_rect(c: &Compositor, object: &shaft_hierarchy::Aabb, rep: &RepTransfer) -> [u32; 4] {
    let cam = &c.model.camera;
    let (w, h) = (cam.width, cam.height);
    let whole = [0, 0, w, h];
    let Origin::Direction(d) = rep.origin else { return whole };
    let (lo, hi) = c.model.bounds();
    if !(lo.is_finite() && hi.is_finite() && object.min.is_finite() && object.max.is_finite()) {
        return whole;
    }
    // the object's box (a margin added for the maps' texels and biases) swept away from the
    // light, widening by tan(half-angle) a unit: box(t) = [min - t d - t k, max - t d + t k]
    let margin = 0.05 * (object.max - object.min).length() + 1e-3;
    let (o_lo, o_hi) = (object.min - Vec3::splat(margin), object.max + Vec3::splat(margin));
    let k = rep.half_angle.clamp(0.0, 1.5).tan();
    let eps = Vec3::splat(1e-3 * (hi - lo).length().max(1e-6));
    let (lo, hi) = (lo - eps, hi + eps);
    // the sweep's t where it overlaps the model's bounds on every axis, within a reach that
    // crosses them
    let (mut t0, mut t1) = (0.0f32, (hi - lo).length() + (o_hi - o_lo).length());
    for i in 0..3 {
        // box(t).min_i <= hi_i: t (d_i + k) >= o_lo_i - hi_i; box(t).max_i >= lo_i: t (d_i - k) <= o_hi_i - lo_i
        for (a, rhs, at_least) in [(d[i] + k, o_lo[i] - hi[i], true), (d[i] - k, o_hi[i] - lo[i], false)] {
            if a.abs() < 1e-9 {
                let holds = if at_least { rhs <= 0.0 } else { rhs >= 0.0 };
                if !holds {
                    return [0, 0, 0, 0];
                }
                continue;
            }
            let t = rhs / a;
            // dividing by a negative a turns the inequality round
            if at_least == (a > 0.0) {
                t0 = t0.max(t);
            } else {
                t1 = t1.min(t);
            }
        }
    }
    if t0 > t1 {
        return [0, 0, 0, 0];
    }
    let at = |t: f32| (o_lo - d * t - Vec3::splat(k * t), o_hi - d * t + Vec3::splat(k * t));
    let ((a_lo, a_hi), (b_lo, b_hi)) = (at(t0), at(t1));
    let (r_lo, r_hi) = (a_lo.min(b_lo).max(lo), a_hi.max(b_hi).min(hi));
    if r_lo.cmpgt(r_hi).any() {
        return [0, 0, 0, 0];
    }
    let (right, up, forward) = cam.basis();
    let scale = 0.5 * w as f32 / (cam.hfov_degrees.to_radians() * 0.5).tan();
    let (mut px_lo, mut px_hi) = (glam::Vec2::INFINITY, glam::Vec2::NEG_INFINITY);
    for k in 0..8 {
        let q = Vec3::new(
            if k & 1 == 0 { r_lo.x } else { r_hi.x },
            if k & 2 == 0 { r_lo.y } else { r_hi.y },
            if k & 4 == 0 { r_lo.z } else { r_hi.z },
        );
        let v = q - cam.eye;
        let z = v.dot(forward);
        if z <= 1e-6 * v.length().max(1e-6) {
            return whole;
        }
        let p = glam::Vec2::new(0.5 * w as f32 + v.dot(right) / z * scale, 0.5 * h as f32 - v.dot(up) / z * scale);
        px_lo = px_lo.min(p);
        px_hi = px_hi.max(p);
    }
    let clamp = |v: f32, n: u32| v.clamp(0.0, n as f32) as u32;
    [
        clamp(px_lo.x.floor() - 1.0, w),
        clamp(px_lo.y.floor() - 1.0, h),
        clamp(px_hi.x.ceil() + 1.0, w),
        clamp(px_hi.y.ceil() + 1.0, h),
    ]
}

/// A frame's maps as recorded: the texture arrays, each array's maps' lookup parameters, the
/// batches (first representative, layers) and the work.
struct Maps {
    arrays: Vec<wgpu::Texture>,
    params: Vec<Vec<shadowmap_paraboloid::MapParams>>,
    batches: Vec<(usize, u32)>,
    work: MapWork,
}

fn pack(p: [u8; 3]) -> u32 {
    u32::from(p[0]) | (u32::from(p[1]) << 8) | (u32::from(p[2]) << 16) | (255 << 24)
}

#[cfg(test)]
mod tests {
    use super::batches;

    #[test]
    fn batches_cover_every_map_in_order_within_the_limit() {
        let views = [1, 6, 6, 2, 1, 6, 1];
        for limit in [1, 6, 7, 12, 13, 100] {
            let b = batches(&views, limit);
            assert_eq!(b[0].0, 0);
            for (k, &(first, layers)) in b.iter().enumerate() {
                let end = b.get(k + 1).map_or(views.len(), |n| n.0);
                assert!(end > first, "{limit}: an empty run");
                assert_eq!(layers, views[first..end].iter().sum::<u32>(), "{limit}");
                // within the limit, unless one map alone exceeds it
                assert!(layers <= limit || end == first + 1, "{limit}: {b:?}");
                // greedy: the next map would not have fitted
                if end < views.len() {
                    assert!(layers + views[end] > limit, "{limit}: {b:?}");
                }
            }
        }
        assert_eq!(batches(&views, 100), vec![(0, 23)]);
        assert!(batches(&[], 8).is_empty());
    }
}
