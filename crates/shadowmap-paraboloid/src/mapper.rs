//! The GPU side: depth passes for paraboloid, cube and orthographic maps (with per-map chunk
//! culling), and the visibility pass that turns a map into a screen-space visibility layer.

use crate::paraboloid::{Hemisphere, ParaboloidFrame};
use crate::{MapView, Rejection, ShadowSettings, Technique};
use glam::{Mat4, Vec3};
use gpu::{Calls, Chunk, Clock, GBuffer, Gate, Gpu, GpuError, GpuStats, Indirect, ShadowGeometry};
use std::time::Duration;

/// This crate's WGSL library files (for `// requires:` lines; shaders that read its maps use
/// `lookup.wgsl`).
pub const LIBRARY: &[(&str, &str)] = &[
    ("shadowmap-paraboloid/paraboloid.wgsl", include_str!("../shaders/paraboloid.wgsl")),
    ("shadowmap-paraboloid/lookup.wgsl", include_str!("../shaders/lookup.wgsl")),
];

/// Depth format of every shadow map: 32-bit float, readable back.
pub const DEPTH_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Depth32Float;

/// One rendered view of a shadow map (one layer of its texture).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ShadowView {
    /// Paraboloid: world -> light space; otherwise world -> clip.
    pub matrix: Mat4,
    /// Near distance (paraboloid) or 0.
    pub near: f32,
    /// Far distance (paraboloid), or the map's world extent (orthographic), or far (cube).
    pub far: f32,
    /// Whether this is a paraboloid view.
    pub paraboloid: bool,
    /// Side in texels.
    pub resolution: u32,
    /// Triangles drawn into it after culling.
    pub triangles_drawn: u32,
}

#[repr(C)]
#[derive(Clone, Copy, Debug, bytemuck::Pod, bytemuck::Zeroable)]
struct ViewUniform {
    matrix: [[f32; 4]; 4],
    params: [f32; 4],
}

impl ShadowView {
    fn uniform(&self) -> ViewUniform {
        ViewUniform {
            matrix: self.matrix.to_cols_array_2d(),
            params: [self.near, self.far, if self.paraboloid { 0.0 } else { 1.0 }, self.resolution as f32],
        }
    }
}

/// A light's rendered shadow map.
pub struct ShadowMap {
    /// Depth32Float 2D array, one layer per view.
    pub texture: wgpu::Texture,
    /// The views, in layer order (paraboloid: front, back; cube: +X, -X, +Y, -Y, +Z, -Z).
    pub views: Vec<ShadowView>,
    /// The technique.
    pub technique: Technique,
    /// The view it was drawn from.
    pub light: MapView,
    /// The paraboloid frame, for paraboloid maps.
    pub frame: Option<ParaboloidFrame>,
    /// The settings it was made with (rejection as actually used).
    pub settings: ShadowSettings,
    /// Generation time of all its passes.
    pub time: Duration,
    /// The clock `time` comes from.
    pub clock: Clock,
    /// The map's first layer in `texture` (0 unless recorded into a shared array,
    /// [`ShadowMapper::record`]).
    pub first_layer: u32,
    /// An orthographic map fitted to the receivers on the GPU ([`OnGpu::stats`]): its view as
    /// the GPU made it (`views` holds the CPU's view of the whole scene instead).
    pub gpu_view: Option<wgpu::Buffer>,
}

/// What a map's passes take from the GPU instead of the CPU, so that a frame records them
/// without waiting: the light's gate and the receivers' statistics (an orthographic map's
/// focus, where its settings give none).
#[derive(Clone, Copy, Default)]
pub struct OnGpu<'a> {
    /// The light's gate: every draw indirect through it.
    pub gate: Option<Gate<'a>>,
    /// The receivers' statistics an orthographic map is fitted to.
    pub stats: Option<&'a GpuStats>,
}

#[repr(C)]
#[derive(Clone, Copy, bytemuck::Pod, bytemuck::Zeroable)]
struct FocusParams {
    s: [f32; 4],
    u: [f32; 4],
    f: [f32; 4],
    d: [f32; 4],
    scene: [f32; 4],
    info: [f32; 4],
    words: [u32; 4],
}

/// Where `MapParams` holds its first view.
const FIRST_VIEW_OFFSET: u64 = 5 * 16;

impl ShadowMap {
    /// Triangles drawn over all views.
    #[must_use]
    pub fn triangles_drawn(&self) -> u32 {
        self.views.iter().map(|v| v.triangles_drawn).sum()
    }

    /// Reads one layer's depths back, row-major from the top-left.
    ///
    /// # Errors
    /// GPU failures.
    pub fn read_layer(&self, gpu: &Gpu, layer: u32) -> Result<Vec<f32>, GpuError> {
        gpu::read_texture_f32(gpu, &self.texture, self.first_layer + layer)
    }

    /// The map as `lookup.wgsl`'s `MapParams` (its layers at `first_layer` of the texture it is
    /// bound with). `half_angle` (the light's, radians) is for PCSS on orthographic maps.
    #[must_use]
    pub fn lookup_params(&self, half_angle: f32, first_layer: u32) -> MapParams {
        let (light, kind) = match self.light {
            MapView::Point { position, .. } => (position, 0.0),
            MapView::Distant { direction } => (direction.normalize_or(Vec3::Y), 1.0),
        };
        let technique = match self.technique {
            Technique::DualParaboloid => 0.0,
            Technique::Cube => 1.0,
            Technique::Orthographic => 2.0,
        };
        let mut views = [bytemuck::Zeroable::zeroed(); 6];
        for (slot, v) in views.iter_mut().zip(&self.views) {
            *slot = v.uniform();
        }
        let forward = self.frame.map_or(Vec3::ZERO, |f| f.forward);
        let (pcss, pcss_limits) = match self.settings.pcss {
            Some(p) if self.technique == Technique::Orthographic => (
                [
                    1.0,
                    half_angle.clamp(0.0, 1.5).tan(),
                    p.blocker_samples.max(1) as f32,
                    p.filter_samples.max(1) as f32,
                ],
                [p.max_radius_texels.max(1.0), 0.0, 0.0, 0.0],
            ),
            _ => ([0.0; 4], [0.0; 4]),
        };
        MapParams {
            light: light.extend(kind).to_array(),
            forward: forward.extend(first_layer as f32).to_array(),
            config: [technique, self.views.len() as f32, self.settings.pcf_radius as f32, self.settings.bias_texels],
            pcss,
            pcss_limits,
            views,
        }
    }
}

/// A map as `crates/shadowmap-paraboloid/shaders/lookup.wgsl` reads it (`MapParams`).
#[repr(C)]
#[derive(Clone, Copy, Debug, bytemuck::Pod, bytemuck::Zeroable)]
pub struct MapParams {
    light: [f32; 4],
    forward: [f32; 4],
    config: [f32; 4],
    pcss: [f32; 4],
    pcss_limits: [f32; 4],
    views: [ViewUniform; 6],
}

/// Pipelines of the shadow passes, built once.
pub struct ShadowMapper {
    view_layout: wgpu::BindGroupLayout,
    paraboloid_clip: Option<wgpu::RenderPipeline>,
    paraboloid_discard: wgpu::RenderPipeline,
    // paraboloid without rejection, for chunks wholly inside a hemisphere
    paraboloid_plain: wgpu::RenderPipeline,
    matrix: wgpu::RenderPipeline,
    visibility: wgpu::RenderPipeline,
    // the same pass adding into a `gpu::accumulate::Accumulator` (N-sample maps)
    visibility_add: wgpu::RenderPipeline,
    // an orthographic view fitted on the GPU (`ortho_focus.wgsl`)
    focus: wgpu::ComputePipeline,
    // each map of a submission's uniforms and bind groups, kept from frame to frame: its
    // views, its fitted focus, its visibility pass (one cursor a stage, the stages run in the
    // same order for every map)
    view_slots: gpu::Slots<ViewSlot>,
    focus_slots: gpu::Slots<FocusSlot>,
    visibility_slots: gpu::Slots<VisibilitySlot>,
}

/// A map's view uniforms and their bind groups (grown to the most views a map has had).
#[derive(Default)]
struct ViewSlot {
    buffers: Vec<wgpu::Buffer>,
    binds: Vec<wgpu::BindGroup>,
}

/// A map's orthographic focus: its parameters, the view it writes, and the bind group over
/// them and the receivers' statistics.
struct FocusSlot {
    params: wgpu::Buffer,
    view: wgpu::Buffer,
    bind: gpu::Keyed<wgpu::Buffer, wgpu::BindGroup>,
}

/// A map's visibility pass: its parameters and the bind group over them, the G-buffer and the
/// map's layers.
struct VisibilitySlot {
    params: wgpu::Buffer,
    bind: gpu::Keyed<(wgpu::RenderPipeline, wgpu::Texture, wgpu::Texture, wgpu::Texture, u32, u32), wgpu::BindGroup>,
}

/// Where a visibility pass writes.
#[derive(Clone, Copy)]
pub enum VisibilityTarget<'a> {
    /// A visibility layer (R8Unorm), overwritten.
    Layer(&'a wgpu::TextureView),
    /// Added into an accumulator's r (cleared first when the flag says so).
    Add(&'a gpu::accumulate::Accumulator, bool),
}

fn depth_pipeline(
    gpu: &Gpu,
    layout: &wgpu::PipelineLayout,
    label: &str,
    source: &str,
    fragment: bool,
) -> wgpu::RenderPipeline {
    let module = gpu::shader::module(&gpu.device, label, source, LIBRARY);
    gpu.render_pipeline(&wgpu::RenderPipelineDescriptor {
        label: Some(label),
        layout: Some(layout),
        vertex: wgpu::VertexState {
            module: &module,
            entry_point: Some("vs"),
            compilation_options: Default::default(),
            buffers: &[Some(ShadowGeometry::LAYOUT)],
        },
        // no culling: closed and open meshes alike cast shadows from either side
        primitive: wgpu::PrimitiveState::default(),
        depth_stencil: Some(wgpu::DepthStencilState {
            format: DEPTH_FORMAT,
            depth_write_enabled: Some(true),
            depth_compare: Some(wgpu::CompareFunction::Less),
            stencil: Default::default(),
            bias: Default::default(),
        }),
        multisample: Default::default(),
        fragment: fragment.then(|| wgpu::FragmentState {
            module: &module,
            entry_point: Some("fs"),
            compilation_options: Default::default(),
            targets: &[],
        }),
        multiview_mask: None,
        cache: None,
    })
}

/// What a view does with a chunk.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Class {
    /// Culled: the view cannot see it.
    Skip,
    /// Wholly inside the view: drawn without rejection.
    Inside,
    /// Across a paraboloid map's band edge: drawn with the rejection (clip distance or discard).
    Straddle,
}

/// How a view classifies chunks.
type Classifier = Box<dyn Fn(&Chunk) -> Class>;

/// A map's texture, views and passes, made before its passes are recorded.
pub(crate) struct Prepared<'a> {
    map: ShadowMap,
    layer_views: Vec<wgpu::TextureView>,
    view_buffers: Vec<wgpu::Buffer>,
    binds: Vec<wgpu::BindGroup>,
    /// Each chunk's class per view.
    classes: Vec<Vec<Class>>,
    /// Pipelines for chunks inside a view and across its edge.
    inside: &'a wgpu::RenderPipeline,
    straddle: &'a wgpu::RenderPipeline,
}

/// A prepared map's depth draws: per view, how many runs of chunks inside it, then across its
/// edge, are drawn, and the triangles it draws.
pub(crate) struct DepthCalls {
    runs: Vec<(usize, usize)>,
    drawn: Vec<u32>,
}

impl DepthCalls {
    /// The depth draws of `p` and their calls, in the order its passes issue them.
    pub(crate) fn of(geometry: &ShadowGeometry, p: &Prepared) -> (Self, Vec<Indirect>) {
        let mut calls = Self { runs: Vec::new(), drawn: Vec::new() };
        let mut args = Vec::new();
        for class in &p.classes {
            let (inside, a) = geometry.runs(|c| class[c] == Class::Inside);
            let (straddle, b) = geometry.runs(|c| class[c] == Class::Straddle);
            calls.drawn.push(a + b);
            calls.runs.push((inside.len(), straddle.len()));
            args.extend(inside.into_iter().chain(straddle).map(Indirect::draw));
        }
        (calls, args)
    }
}

impl Prepared<'_> {
    /// The map, with the triangles each view drew.
    fn finish(self, drawn: Vec<u32>) -> ShadowMap {
        let mut map = self.map;
        for (v, n) in map.views.iter_mut().zip(drawn) {
            v.triangles_drawn = n;
        }
        map
    }
}

/// Range of z / |d| over a sphere (centre `q` relative to the light, radius `r`) for unit
/// `axis`: the cosines of the nearest and farthest angles from the axis.
fn cos_range(q: Vec3, r: f32, axis: Vec3) -> (f32, f32) {
    let len = q.length();
    if len <= r {
        return (-1.0, 1.0);
    }
    let theta = (q.dot(axis) / len).clamp(-1.0, 1.0).acos();
    let spread = (r / len).asin();
    ((theta + spread).min(std::f32::consts::PI).cos(), (theta - spread).max(0.0).cos())
}

/// A paraboloid view's class of a chunk: outside its band, inside its hemisphere, or across.
fn paraboloid_class(c: &Chunk, light: Vec3, axis: Vec3) -> Class {
    let (lo, hi) = cos_range(c.center - light, c.radius, axis);
    if hi < -crate::paraboloid::RIM_MARGIN {
        Class::Skip
    } else if lo >= 0.0 {
        Class::Inside
    } else {
        Class::Straddle
    }
}

/// Bounding sphere of all chunks (centre, radius).
fn bounds(geometry: &ShadowGeometry) -> (Vec3, f32) {
    let (mut lo, mut hi) = (Vec3::splat(f32::INFINITY), Vec3::splat(f32::NEG_INFINITY));
    for c in &geometry.chunks {
        lo = lo.min(c.center - Vec3::splat(c.radius));
        hi = hi.max(c.center + Vec3::splat(c.radius));
    }
    if !lo.is_finite() {
        return (Vec3::ZERO, 1.0);
    }
    let center = 0.5 * (lo + hi);
    let radius = geometry.chunks.iter().map(|c| c.center.distance(center) + c.radius).fold(0.0, f32::max);
    (center, radius.max(1e-6))
}

/// Farthest distance from `p` to any chunk.
fn reach(geometry: &ShadowGeometry, p: Vec3) -> f32 {
    geometry.chunks.iter().map(|c| c.center.distance(p) + c.radius).fold(0.0, f32::max)
}

/// Whether a chunk can appear in a 90° cube face looking along `a` with side axes `u`, `v`.
fn in_cube_face(c: &Chunk, light: Vec3, a: Vec3, u: Vec3, v: Vec3) -> bool {
    let q = c.center - light;
    let r = c.radius * std::f32::consts::SQRT_2;
    let (qa, qu, qv) = (q.dot(a), q.dot(u), q.dot(v));
    qa - qu >= -r && qa + qu >= -r && qa - qv >= -r && qa + qv >= -r
}

/// The six cube faces: (forward, up) in the order +X, -X, +Y, -Y, +Z, -Z.
pub const CUBE_FACES: [(Vec3, Vec3); 6] = [
    (Vec3::X, Vec3::Y),
    (Vec3::NEG_X, Vec3::Y),
    (Vec3::Y, Vec3::Z),
    (Vec3::NEG_Y, Vec3::Z),
    (Vec3::Z, Vec3::Y),
    (Vec3::NEG_Z, Vec3::Y),
];

impl ShadowMapper {
    /// Builds the pipelines (the clip-distance one only where the adapter has the feature).
    #[must_use]
    pub fn new(gpu: &Gpu) -> Self {
        let src = |name| match name {
            "clip" => include_str!("../shaders/paraboloid_depth.wgsl"),
            "discard" => include_str!("../shaders/paraboloid_depth_discard.wgsl"),
            "matrix" => include_str!("../shaders/matrix_depth.wgsl"),
            _ => include_str!("../shaders/visibility.wgsl"),
        };
        let module = gpu::shader::module(&gpu.device, "shadow visibility", src("visibility"), LIBRARY);
        let visibility = gpu::fullscreen::pipeline(gpu, "shadow visibility", &module, gpu::VisibilityLayers::FORMAT);
        let visibility_add = gpu::fullscreen::pipeline_with_target(
            gpu,
            "shadow visibility (add)",
            &module,
            gpu::accumulate::Accumulator::target(gpu),
        );
        let view_layout = gpu.device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("shadow view"),
            entries: &[wgpu::BindGroupLayoutEntry {
                binding: 0,
                visibility: wgpu::ShaderStages::VERTEX,
                ty: wgpu::BindingType::Buffer {
                    ty: wgpu::BufferBindingType::Uniform,
                    has_dynamic_offset: false,
                    min_binding_size: None,
                },
                count: None,
            }],
        });
        let layout = gpu.device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
            label: Some("shadow depth"),
            bind_group_layouts: &[Some(&view_layout)],
            immediate_size: 0,
        });
        let focus_module =
            gpu::shader::module(&gpu.device, "orthographic focus", include_str!("../shaders/ortho_focus.wgsl"), &[]);
        let focus = gpu.compute_pipeline(&wgpu::ComputePipelineDescriptor {
            label: Some("orthographic focus"),
            layout: None,
            module: &focus_module,
            entry_point: Some("focus"),
            compilation_options: Default::default(),
            cache: None,
        });
        Self {
            focus,
            paraboloid_clip: gpu
                .has_clip_distances()
                .then(|| depth_pipeline(gpu, &layout, "paraboloid clip", src("clip"), false)),
            paraboloid_discard: depth_pipeline(gpu, &layout, "paraboloid discard", src("discard"), true),
            paraboloid_plain: depth_pipeline(gpu, &layout, "paraboloid plain", src("discard"), false),
            matrix: depth_pipeline(gpu, &layout, "matrix depth", src("matrix"), false),
            view_layout,
            visibility,
            visibility_add,
            view_slots: gpu::Slots::new(),
            focus_slots: gpu::Slots::new(),
            visibility_slots: gpu::Slots::new(),
        }
    }

    /// Renders the shadow map of `light` with `technique`. A hemispherical point light gets one
    /// paraboloid map, an omnidirectional one two.
    ///
    /// # Errors
    /// [`GpuError::Failed`] for a technique that does not fit the light (a paraboloid or cube
    /// map for a distant light, an orthographic map for a point light); sizes beyond the
    /// adapter's limits; GPU failures.
    pub fn render(
        &self,
        gpu: &Gpu,
        geometry: &ShadowGeometry,
        light: &MapView,
        technique: Technique,
        settings: &ShadowSettings,
    ) -> Result<ShadowMap, GpuError> {
        let mut p = self.prepare(gpu, geometry, light, technique, settings, None)?;
        let (depth, args) = DepthCalls::of(geometry, &p);
        let calls = Calls::direct(args);
        let (time, clock) = gpu.measure(|encoder| {
            geometry.record_placement(gpu, encoder);
            self.record_passes(encoder, geometry, &p, &depth, (&calls, 0));
        })?;
        p.map.time = time;
        p.map.clock = clock;
        Ok(p.finish(depth.drawn))
    }

    /// Records the shadow map of `light` into `encoder` without submitting it, so that many
    /// maps (and the passes that read them) go to the GPU in one submission; its `time` is zero
    /// (the caller times the submission). `target`: layers `first..` of a `DEPTH_FORMAT` array of
    /// `settings.resolution`² layers (e.g. one for all of a frame's maps, so that one pass can
    /// read them all), or `None` for a texture of its own.
    ///
    /// `on_gpu`: the light's gate and the receivers' statistics where the frame takes them
    /// from the GPU ([`OnGpu`]; its default for neither).
    ///
    /// # Errors
    /// As [`ShadowMapper::render`]; a target of another format or size, or without the layers.
    #[allow(clippy::too_many_arguments)]
    pub fn record(
        &self,
        gpu: &Gpu,
        encoder: &mut wgpu::CommandEncoder,
        geometry: &ShadowGeometry,
        light: &MapView,
        technique: Technique,
        settings: &ShadowSettings,
        target: Option<(&wgpu::Texture, u32)>,
        on_gpu: OnGpu<'_>,
    ) -> Result<ShadowMap, GpuError> {
        let p = self.prepare(gpu, geometry, light, technique, settings, target)?;
        let (depth, args) = DepthCalls::of(geometry, &p);
        let calls = Calls::new(gpu, encoder, on_gpu.gate, args);
        Ok(self.record_prepared(gpu, encoder, geometry, p, (light, settings, on_gpu.stats), (depth, &calls, 0)))
    }

    /// Records a prepared map: its focus fitted on the GPU (an orthographic map without a
    /// focus of its own, where the receivers' `stats` are given), then its depth passes
    /// (`depth`'s calls, the first being call `first` of `calls`).
    pub(crate) fn record_prepared(
        &self,
        gpu: &Gpu,
        encoder: &mut wgpu::CommandEncoder,
        geometry: &ShadowGeometry,
        mut p: Prepared<'_>,
        (light, settings, stats): (&MapView, &ShadowSettings, Option<&GpuStats>),
        (depth, calls, first): (DepthCalls, &Calls, usize),
    ) -> ShadowMap {
        // moved objects' vertices first (nothing when none moved)
        geometry.record_placement(gpu, encoder);
        let fit = match (p.map.technique, light, stats) {
            (Technique::Orthographic, MapView::Distant { direction }, Some(stats)) if settings.focus.is_none() => {
                Some(self.record_focus(gpu, encoder, geometry, *direction, settings.resolution, stats))
            }
            _ => None,
        };
        if let (Some(fit), Some(view)) = (&fit, p.view_buffers.first()) {
            encoder.copy_buffer_to_buffer(fit, 0, view, 0, std::mem::size_of::<ViewUniform>() as u64);
        }
        p.map.gpu_view = fit;
        self.record_passes(encoder, geometry, &p, &depth, (calls, first));
        p.finish(depth.drawn)
    }

    /// Records the orthographic view of a map towards `direction` fitted to the receivers'
    /// statistics on the GPU (`ortho_focus.wgsl`: the CPU's arithmetic in `prepare`).
    fn record_focus(
        &self,
        gpu: &Gpu,
        encoder: &mut wgpu::CommandEncoder,
        geometry: &ShadowGeometry,
        direction: Vec3,
        resolution: u32,
        stats: &GpuStats,
    ) -> wgpu::Buffer {
        let (center, radius) = bounds(geometry);
        let d = direction.normalize_or(Vec3::Y);
        let up = if d.y.abs() < 0.9 { Vec3::Y } else { Vec3::X };
        // `look_to_mat4(eye, -d, up)`'s axes, which do not depend on the eye
        let f = -d;
        let s = f.cross(up).normalize();
        let u = s.cross(f);
        let params = FocusParams {
            s: s.extend(0.0).to_array(),
            u: u.extend(0.0).to_array(),
            f: f.extend(0.0).to_array(),
            d: d.extend(0.0).to_array(),
            scene: center.extend(radius).to_array(),
            info: [resolution as f32, 0.0, 0.0, 0.0],
            words: [GpuStats::COUNT_WORD, GpuStats::MEAN_WORD, GpuStats::RADIUS_WORD, 0],
        };
        let make = || FocusSlot {
            params: gpu.create_buffer(&wgpu::BufferDescriptor {
                label: Some("orthographic focus"),
                size: std::mem::size_of::<FocusParams>() as u64,
                usage: wgpu::BufferUsages::UNIFORM | wgpu::BufferUsages::COPY_DST,
                mapped_at_creation: false,
            }),
            view: gpu.create_buffer(&wgpu::BufferDescriptor {
                label: Some("orthographic view"),
                size: std::mem::size_of::<ViewUniform>() as u64,
                usage: wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_SRC,
                mapped_at_creation: false,
            }),
            bind: gpu::Keyed::default(),
        };
        let (view, bind) = self.focus_slots.next_or_own(gpu, make, |slot| {
            gpu.queue.write_buffer(&slot.params, 0, bytemuck::bytes_of(&params));
            let (buffer, view) = (slot.params.clone(), slot.view.clone());
            let bind = slot.bind.get(stats.buffer().clone(), || {
                gpu.create_bind_group(&wgpu::BindGroupDescriptor {
                    label: Some("orthographic focus"),
                    layout: &self.focus.get_bind_group_layout(0),
                    entries: &[
                        wgpu::BindGroupEntry { binding: 0, resource: buffer.as_entire_binding() },
                        wgpu::BindGroupEntry { binding: 1, resource: stats.buffer().as_entire_binding() },
                        wgpu::BindGroupEntry { binding: 2, resource: view.as_entire_binding() },
                    ],
                })
            });
            (view, bind.clone())
        });
        let mut pass = encoder.begin_compute_pass(&wgpu::ComputePassDescriptor {
            label: Some("orthographic focus"),
            timestamp_writes: None,
        });
        pass.set_pipeline(&self.focus);
        pass.set_bind_group(0, &bind, &[]);
        pass.dispatch_workgroups(1, 1, 1);
        drop(pass);
        view
    }

    /// The views (texture layers) a map of `light` by `technique` has: a hemispherical
    /// paraboloid 1, an omnidirectional one 2, a cube 6, an orthographic map 1.
    #[must_use]
    pub fn view_count(light: &MapView, technique: Technique) -> u32 {
        match (technique, light) {
            (Technique::DualParaboloid, MapView::Point { hemisphere: Some(_), .. }) => 1,
            (Technique::DualParaboloid, _) => 2,
            (Technique::Cube, _) => 6,
            (Technique::Orthographic, _) => 1,
        }
    }

    /// Everything a map's passes need, made before recording them.
    pub(crate) fn prepare(
        &self,
        gpu: &Gpu,
        geometry: &ShadowGeometry,
        light: &MapView,
        technique: Technique,
        settings: &ShadowSettings,
        target: Option<(&wgpu::Texture, u32)>,
    ) -> Result<Prepared<'_>, GpuError> {
        let mut settings = *settings;
        if self.paraboloid_clip.is_none() {
            settings.rejection = Rejection::Discard;
        }
        let res = settings.resolution;
        // a point light's maps reach the farthest geometry
        let far_from = |p: Vec3| (reach(geometry, p) * 1.01).max(settings.near * 2.0);
        let mut frame = None;
        // (view, culling test) per layer
        let mut views: Vec<(ShadowView, Classifier)> = Vec::new();
        let cull = settings.cull;
        match (technique, *light) {
            (Technique::DualParaboloid, MapView::Point { position, hemisphere }) => {
                let f = ParaboloidFrame::new(
                    position,
                    hemisphere.unwrap_or(Vec3::NEG_Y),
                    settings.near,
                    far_from(position),
                );
                frame = Some(f);
                let maps: &[Hemisphere] =
                    if hemisphere.is_some() { &[Hemisphere::Front] } else { &[Hemisphere::Front, Hemisphere::Back] };
                for &h in maps {
                    let axis = if h == Hemisphere::Front { f.forward } else { -f.forward };
                    let view = ShadowView {
                        matrix: f.world_to_light(h),
                        near: f.near,
                        far: f.far,
                        paraboloid: true,
                        resolution: res,
                        triangles_drawn: 0,
                    };
                    // without culling every chunk goes through the rejection, as in the paper
                    views.push((
                        view,
                        Box::new(
                            move |c: &Chunk| if cull { paraboloid_class(c, position, axis) } else { Class::Straddle },
                        ),
                    ));
                }
            }
            (Technique::Cube, MapView::Point { position, .. }) => {
                let far = far_from(position);
                let proj =
                    glam::camera::rh::proj::directx::perspective(std::f32::consts::FRAC_PI_2, 1.0, settings.near, far);
                for (a, up) in CUBE_FACES {
                    let matrix = proj * glam::camera::rh::view::look_to_mat4(position, a, up);
                    let u = a.cross(up);
                    let view = ShadowView {
                        matrix,
                        near: settings.near,
                        far,
                        paraboloid: false,
                        resolution: res,
                        triangles_drawn: 0,
                    };
                    views.push((
                        view,
                        Box::new(move |c: &Chunk| {
                            if !cull || in_cube_face(c, position, a, u, up) { Class::Inside } else { Class::Skip }
                        }),
                    ));
                }
            }
            (Technique::Orthographic, MapView::Distant { direction }) => {
                let (center, radius) = bounds(geometry);
                let d = direction.normalize_or(Vec3::Y);
                let up = if d.y.abs() < 0.9 { Vec3::Y } else { Vec3::X };
                // the map's footprint: the focus (or the whole scene); its depth range: the
                // whole scene, so casters outside the footprint's box still shadow it
                let (fc, fr) = settings.focus.map_or((center, radius), |(c, r)| (c, r.min(radius).max(1e-6)));
                let reach = (fc - center).length() + radius;
                let margin = reach * 0.01;
                let eye = fc + d * (reach + margin);
                let matrix =
                    glam::camera::rh::proj::directx::orthographic(-fr, fr, -fr, fr, 0.0, 2.0 * (reach + margin))
                        * glam::camera::rh::view::look_to_mat4(eye, -d, up);
                let view = ShadowView {
                    matrix,
                    near: 0.0,
                    far: 2.0 * fr,
                    paraboloid: false,
                    resolution: res,
                    triangles_drawn: 0,
                };
                views.push((view, Box::new(|_: &Chunk| Class::Inside)));
            }
            (t, l) => return Err(GpuError::Failed(format!("a {t:?} shadow map does not fit a {l:?}"))),
        }
        let layers = views.len() as u32;
        let (texture, first_layer) = match target {
            Some((t, first)) => {
                let fits = t.format() == DEPTH_FORMAT
                    && t.width() == res
                    && t.height() == res
                    && u64::from(first) + u64::from(layers) <= u64::from(t.depth_or_array_layers());
                if !fits {
                    return Err(GpuError::Failed(format!(
                        "a {res}² map of {layers} layers does not fit layers {first}.. of a {:?} {} x {} x {} target",
                        t.format(),
                        t.width(),
                        t.height(),
                        t.depth_or_array_layers()
                    )));
                }
                (t.clone(), first)
            }
            None => (gpu::render_target(gpu, "shadow map", (res, res, layers), DEPTH_FORMAT)?, 0),
        };
        // (pipeline for chunks inside the view, pipeline for chunks across its edge)
        let (inside, straddle) = match (technique, settings.rejection, &self.paraboloid_clip) {
            (Technique::DualParaboloid, Rejection::ClipDistance, Some(p)) => (&self.paraboloid_plain, p),
            (Technique::DualParaboloid, _, _) => (&self.paraboloid_plain, &self.paraboloid_discard),
            _ => (&self.matrix, &self.matrix),
        };
        let layer_views: Vec<wgpu::TextureView> =
            (0..layers).map(|l| gpu::layer_view(&texture, first_layer + l)).collect();
        let uniforms: Vec<ViewUniform> = views.iter().map(|(v, _)| v.uniform()).collect();
        let (view_buffers, binds) = self.view_slots.next_or_own(gpu, ViewSlot::default, |slot| {
            while slot.buffers.len() < uniforms.len() {
                let buffer = gpu.create_buffer(&wgpu::BufferDescriptor {
                    label: Some("shadow view"),
                    size: std::mem::size_of::<ViewUniform>() as u64,
                    usage: wgpu::BufferUsages::UNIFORM | wgpu::BufferUsages::COPY_DST,
                    mapped_at_creation: false,
                });
                slot.binds.push(gpu.create_bind_group(&wgpu::BindGroupDescriptor {
                    label: Some("shadow view"),
                    layout: &self.view_layout,
                    entries: &[wgpu::BindGroupEntry { binding: 0, resource: buffer.as_entire_binding() }],
                }));
                slot.buffers.push(buffer);
            }
            for (buffer, u) in slot.buffers.iter().zip(&uniforms) {
                gpu.queue.write_buffer(buffer, 0, bytemuck::bytes_of(u));
            }
            (slot.buffers[..uniforms.len()].to_vec(), slot.binds[..uniforms.len()].to_vec())
        });
        // each chunk classified once per view, before recording
        let classes: Vec<Vec<Class>> =
            views.iter().map(|(_, classify)| geometry.chunks.iter().map(classify).collect()).collect();
        let views = views.into_iter().map(|(v, _)| v).collect();
        let map = ShadowMap {
            texture,
            views,
            technique,
            light: *light,
            frame,
            settings,
            time: std::time::Duration::ZERO,
            clock: gpu::Clock::WallTime,
            first_layer,
            gpu_view: None,
        };
        Ok(Prepared { map, layer_views, view_buffers, binds, classes, inside, straddle })
    }

    /// Records a prepared map's depth passes, issuing `depth`'s calls from call `first` of
    /// `calls` on.
    fn record_passes(
        &self,
        encoder: &mut wgpu::CommandEncoder,
        geometry: &ShadowGeometry,
        p: &Prepared,
        depth: &DepthCalls,
        (calls, first): (&Calls, usize),
    ) {
        let mut call = first;
        for (k, bind) in p.binds.iter().enumerate() {
            let mut pass = encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
                label: Some("shadow depth"),
                color_attachments: &[],
                depth_stencil_attachment: Some(wgpu::RenderPassDepthStencilAttachment {
                    view: &p.layer_views[k],
                    depth_ops: Some(wgpu::Operations { load: wgpu::LoadOp::Clear(1.0), store: wgpu::StoreOp::Store }),
                    stencil_ops: None,
                }),
                ..Default::default()
            });
            pass.set_bind_group(0, bind, &[]);
            geometry.set_vertices(&mut pass);
            let (inside, straddle) = depth.runs[k];
            pass.set_pipeline(p.inside);
            for _ in 0..inside {
                calls.draw(&mut pass, call);
                call += 1;
            }
            pass.set_pipeline(p.straddle);
            for _ in 0..straddle {
                calls.draw(&mut pass, call);
                call += 1;
            }
        }
    }

    /// Writes `map`'s visibility of each G-buffer pixel into `target` (a visibility layer):
    /// 1 lit, 0 shadowed, fractions with PCF; 0 behind a hemispherical light.
    ///
    /// # Errors
    /// GPU failures.
    pub fn visibility(
        &self,
        gpu: &Gpu,
        map: &ShadowMap,
        gbuffer: &GBuffer,
        target: &wgpu::TextureView,
    ) -> Result<(), GpuError> {
        let mut encoder = gpu.encoder("shadow visibility");
        let calls = Calls::direct(vec![Indirect::draw(0..3)]);
        let target = VisibilityTarget::Layer(target);
        self.record_visibility(gpu, &mut encoder, map, gbuffer, target, 0.0, (&calls, 0));
        gpu.submit_and_wait(encoder)
    }

    /// Records `map`'s visibility pass into `encoder`, writing a visibility layer or adding into
    /// an accumulator (cleared first when asked). `half_angle` is the light's (radians), used by
    /// PCSS (`settings.pcss`) on orthographic maps; its full-screen triangle is call `k` of
    /// `calls` (`Indirect::draw(0..3)`; gated when the frame gates the light).
    #[allow(clippy::too_many_arguments)]
    pub fn record_visibility(
        &self,
        gpu: &Gpu,
        encoder: &mut wgpu::CommandEncoder,
        map: &ShadowMap,
        gbuffer: &GBuffer,
        target: VisibilityTarget<'_>,
        half_angle: f32,
        (calls, k): (&Calls, usize),
    ) {
        // the view below starts at the map's first layer
        let params = map.lookup_params(half_angle, 0);
        let pipeline = match target {
            VisibilityTarget::Layer(_) => &self.visibility,
            VisibilityTarget::Add(..) => &self.visibility_add,
        };
        let make = || VisibilitySlot {
            params: gpu.create_buffer(&wgpu::BufferDescriptor {
                label: Some("visibility params"),
                size: std::mem::size_of_val(&params) as u64,
                usage: wgpu::BufferUsages::UNIFORM | wgpu::BufferUsages::COPY_DST,
                mapped_at_creation: false,
            }),
            bind: gpu::Keyed::default(),
        };
        let layers = map.views.len() as u32;
        let bind = self.visibility_slots.next_or_own(gpu, make, |slot| {
            gpu.queue.write_buffer(&slot.params, 0, bytemuck::bytes_of(&params));
            if let Some(view) = &map.gpu_view {
                let size = std::mem::size_of::<ViewUniform>() as u64;
                encoder.copy_buffer_to_buffer(view, 0, &slot.params, FIRST_VIEW_OFFSET, size);
            }
            let key = (
                pipeline.clone(),
                gbuffer.position.clone(),
                gbuffer.geometric_normal.clone(),
                map.texture.clone(),
                map.first_layer,
                layers,
            );
            let buffer = slot.params.clone();
            slot.bind
                .get(key, || {
                    let position = gbuffer.position.create_view(&Default::default());
                    let normal = gbuffer.geometric_normal.create_view(&Default::default());
                    let shadow = map.texture.create_view(&wgpu::TextureViewDescriptor {
                        dimension: Some(wgpu::TextureViewDimension::D2Array),
                        aspect: wgpu::TextureAspect::DepthOnly,
                        base_array_layer: map.first_layer,
                        array_layer_count: Some(layers),
                        ..Default::default()
                    });
                    gpu.create_bind_group(&wgpu::BindGroupDescriptor {
                        label: Some("visibility"),
                        layout: &pipeline.get_bind_group_layout(0),
                        entries: &[
                            wgpu::BindGroupEntry { binding: 0, resource: buffer.as_entire_binding() },
                            wgpu::BindGroupEntry {
                                binding: 1,
                                resource: wgpu::BindingResource::TextureView(&position),
                            },
                            wgpu::BindGroupEntry { binding: 2, resource: wgpu::BindingResource::TextureView(&normal) },
                            wgpu::BindGroupEntry { binding: 3, resource: wgpu::BindingResource::TextureView(&shadow) },
                        ],
                    })
                })
                .clone()
        });
        let attachment = match target {
            VisibilityTarget::Layer(view) => wgpu::RenderPassColorAttachment {
                view,
                depth_slice: None,
                resolve_target: None,
                ops: wgpu::Operations { load: wgpu::LoadOp::Clear(wgpu::Color::WHITE), store: wgpu::StoreOp::Store },
            },
            VisibilityTarget::Add(acc, clear) => acc.attachment(clear),
        };
        let mut pass = encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
            label: Some("shadow visibility"),
            color_attachments: &[Some(attachment)],
            ..Default::default()
        });
        pass.set_pipeline(pipeline);
        pass.set_bind_group(0, &bind, &[]);
        calls.draw(&mut pass, k);
    }
}
