//! Soft shadows of the extracted lights (distant cones) and of local spherical lights with
//! penumbra wedges (Akenine-Möller and Assarsson 2002; Assarsson and Akenine-Möller 2003), as
//! paper 000 renders them, behind [`gpu::ShadowTechnique`].
//!
//! Per light: the silhouette of every caster whose shadow can reach a visible receiver, seen
//! from the light's centre ([`casters`]); the hard shadow volume from the centre, counted
//! z-fail against the G-buffer; one conservative footprint per silhouette edge whose wedge can
//! reach a visible receiver ([`geometry`]); per pixel in a footprint, the edge's signed coverage
//! of the light's disk, computed analytically ([`coverage`], no coverage textures); then
//! `V = clamp(1 − w + Σ a_e / π)`. The counts and sums add into a [`gpu::accumulate`] target.
//!
//! ```no_run
//! use gpu::{LightShape, Receivers, ShadowTechnique};
//! let gpu = gpu::Gpu::new().expect("a GPU or lavapipe");
//! let scene = scene::Scene::builtin("three_boxes").expect("built in");
//! let geometry = gpu::SceneGeometry::upload(&gpu, &scene).expect("fits");
//! let gbuffer = gpu::GBufferPass::new(&gpu).render(&gpu, &geometry, &scene.camera).expect("renders");
//! let points = gbuffer.read_points(&gpu).expect("reads");
//! let wedges = penumbra_wedge::Wedges::new(&gpu, &scene, penumbra_wedge::WedgeSettings::default());
//! let light = LightShape::Distant { direction: glam::Vec3::new(0.3, 1.0, 0.2).normalize(), half_angle: 0.05 };
//! let vis = gpu::VisibilityLayers::new(&gpu, 640, 480, 1).expect("fits");
//! let mut encoder = gpu.encoder("frame");
//! // a renderer records every light of its frame so, then submits once
//! let report = wedges.record(&gpu, &mut encoder, &Receivers::new(&gbuffer, &points), &light, None, &vis.layer(0));
//! gpu.submit(encoder);
//! ```

pub mod casters;
pub mod coverage;
pub mod geometry;
mod gpu_build;

use casters::{Caster, Casters};
use geometry::reach_along;
use glam::{Mat4, Vec3};
use gpu::accumulate::{Accumulator, ResolvePass};
use gpu::{Calls, Gpu, GpuError, Indirect, LightShape, Receivers, ShadowPassReport, ShadowTechnique};
use gpu_build::{GpuBuilder, LightBuild};
use std::cell::RefCell;

/// How wedges reach the pixels they cover.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum WedgePath {
    /// Footprints rasterized, one fragment per pixel and footprint (paper 000's way).
    #[default]
    Raster,
    /// Footprints binned into 16 × 16 screen tiles on the CPU, every pixel of a tile summing
    /// its tile's edges in one compute invocation (`crates/penumbra-wedge/shaders/tiles.wgsl`): no
    /// blending, one write per pixel, more edge terms evaluated (the whole tile's).
    Compute,
}

/// Where a light's silhouette, volume and footprints are built.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum WedgeBuild {
    /// On the GPU, in compute passes recorded with the light (`crates/penumbra-wedge/shaders/build.wgsl`):
    /// the CPU never sees the silhouette. A footprint (an octagon around the wedges) covers
    /// [`WedgeSettings::edges_per_footprint`] consecutive silhouette edges in the casters' edge
    /// order (along a Hilbert curve) rather than along a chain. The raster path only: the
    /// compute path bins footprints on the CPU and builds there.
    #[default]
    Gpu,
    /// On the CPU ([`Wedges::plan`]), uploaded per light: the reference the GPU builder is
    /// tested against, and the compute path's builder.
    Cpu,
}

/// Knobs of the wedges.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct WedgeSettings {
    /// Draw only casters whose shadow can reach a visible receiver, and only wedges that can
    /// reach one and lie on screen (off: everything, for measuring what culling saves).
    pub cull: bool,
    /// Consecutive silhouette edges drawn under one footprint (the hull of their wedges): fewer,
    /// larger footprints, each pixel looping over the group's edges. 1 is one wedge per edge.
    pub edges_per_footprint: u32,
    /// Raster or tiled compute (the hard volume is rasterized either way).
    pub path: WedgePath,
    /// Weight the light's disk by the receiver's cosine (`coverage` module doc), as a
    /// Lambertian receiver does; off: the plain covered fraction, paper 000's.
    pub cosine_weighted: bool,
    /// Where the geometry is built (the raster path; the compute path builds on the CPU).
    pub build: WedgeBuild,
    /// The largest buffer the GPU build uses for one light, bytes (`None`: the device's storage
    /// binding limit, as the default): a mesh that needs more is built in chunks of faces and
    /// edges, one after another, the same pixels in more passes with less memory.
    pub chunk_bytes: Option<u64>,
}

impl WedgeSettings {
    fn build_sizes(&self) -> gpu_build::BuildSizes {
        gpu_build::BuildSizes { edges_per_footprint: self.edges_per_footprint, chunk_bytes: self.chunk_bytes }
    }
}

impl Default for WedgeSettings {
    /// Culling on, 8 edges per footprint (the CPU builder's), the raster path, cosine
    /// weighting, built on the GPU, chunked at the device's limit.
    fn default() -> Self {
        Self {
            cull: true,
            edges_per_footprint: 8,
            path: WedgePath::Raster,
            cosine_weighted: true,
            build: WedgeBuild::Gpu,
            chunk_bytes: None,
        }
    }
}

/// Side of the compute path's screen tiles, pixels (`tiles.wgsl`'s workgroup size).
pub const TILE: u32 = 16;

/// The compute path's bins: per tile of [`TILE`] × [`TILE`] pixels (row-major, `tiles_x` per
/// row), the range of its entries in `groups`; each entry is a footprint's edge range
/// `(first, count)`. A footprint is binned into every tile its triangles' screen bounds touch,
/// once per tile.
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct TileBins {
    /// Tiles per row.
    pub tiles_x: u32,
    /// Per tile: (first entry, entry count).
    pub ranges: Vec<[u32; 2]>,
    /// Edge ranges `(first, count)` of the binned footprints.
    pub groups: Vec<[u32; 2]>,
}

/// Bins `footprints` (NDC triangles with their edge range, as [`WedgePlan::footprints`]) into
/// the tiles of a `width` × `height` image.
#[must_use]
pub fn bin_footprints(footprints: &[([glam::Vec2; 3], u32, u32)], (width, height): (u32, u32)) -> TileBins {
    let tiles_x = width.div_ceil(TILE).max(1);
    let tiles_y = height.div_ceil(TILE).max(1);
    let n_tiles = (tiles_x * tiles_y) as usize;
    // per footprint, the tiles it touches (a footprint's triangles are consecutive)
    let mut per_tile: Vec<Vec<[u32; 2]>> = vec![Vec::new(); n_tiles];
    let mut last: Vec<Option<u32>> = vec![None; n_tiles];
    for (tri, first, count) in footprints {
        if !tri.iter().all(|v| v.is_finite()) {
            continue;
        }
        let px = tri.map(|v| glam::Vec2::new((v.x + 1.0) * 0.5 * width as f32, (1.0 - v.y) * 0.5 * height as f32));
        let lo = px[0].min(px[1]).min(px[2]);
        let hi = px[0].max(px[1]).max(px[2]);
        if hi.x < 0.0 || hi.y < 0.0 || lo.x >= width as f32 || lo.y >= height as f32 {
            continue;
        }
        let tile = |v: f32, n: u32| ((v.max(0.0) / TILE as f32) as u32).min(n - 1);
        let (x0, x1) = (tile(lo.x, tiles_x), tile(hi.x, tiles_x));
        let (y0, y1) = (tile(lo.y, tiles_y), tile(hi.y, tiles_y));
        for ty in y0..=y1 {
            for tx in x0..=x1 {
                let t = (ty * tiles_x + tx) as usize;
                if last[t] != Some(*first) {
                    last[t] = Some(*first);
                    per_tile[t].push([*first, *count]);
                }
            }
        }
    }
    let mut bins = TileBins { tiles_x, ranges: Vec::with_capacity(n_tiles), groups: Vec::new() };
    for list in per_tile {
        bins.ranges.push([bins.groups.len() as u32, list.len() as u32]);
        bins.groups.extend(list);
    }
    bins
}

/// What the GPU draws for one light, built on the CPU.
#[derive(Clone, Debug, Default)]
pub struct WedgePlan {
    /// Hard shadow volume triangles (world space).
    pub volume: Vec<[Vec3; 3]>,
    /// Silhouette edges with a wedge to draw.
    pub edges: Vec<[Vec3; 2]>,
    /// Per edge, its lit and unlit faces' normals ([`casters::Silhouette::normals`]).
    pub normals: Vec<[Vec3; 2]>,
    /// Footprint triangles in NDC with the range of their edges in `edges` (first, count).
    pub footprints: Vec<([glam::Vec2; 3], u32, u32)>,
    /// Work left out, as `(what, how many)`.
    pub culled: Vec<(&'static str, u64)>,
}

/// Penumbra wedges for one scene: its casters, and the pipelines.
pub struct Wedges {
    casters: Casters,
    bounds: (Vec3, Vec3),
    settings: WedgeSettings,
    volume: wgpu::RenderPipeline,
    wedge: wgpu::RenderPipeline,
    tiles: wgpu::ComputePipeline,
    resolve: ResolvePass,
    // the resolve's edge sum where the raster path leaves it in the accumulator
    no_edge_sum: wgpu::Texture,
    // the GPU builder and the pipeline drawing its footprints
    builder: GpuBuilder,
    polygons: wgpu::RenderPipeline,
    // screen-sized targets reused from light to light (passes recorded in order), per size
    scratch: RefCell<Option<Scratch>>,
    // the GPU-built lights' uniforms and bind groups, kept from frame to frame
    slots: gpu::Slots<LightSlot>,
}

/// One GPU-built light's resources ([`gpu::Slots`]): its build uniform (whose first words are
/// the wedge pass's light), per-caster parameters and view, and the bind groups of its seven
/// passes over them, the builder's buffers and the G-buffer.
struct LightSlot {
    uniform: wgpu::Buffer,
    casters: wgpu::Buffer,
    view: wgpu::Buffer,
    binds: gpu::Keyed<(wgpu::Buffer, wgpu::Texture, wgpu::Texture), LightBinds>,
}

/// A GPU-built light's bind groups: its build's, the volume pass's and the wedge pass's.
#[derive(Clone)]
struct LightBinds {
    build: gpu_build::BuildBinds,
    volume: wgpu::BindGroup,
    wedge: wgpu::BindGroup,
}

/// A light's screen-sized scratch targets.
#[derive(Clone)]
struct Scratch {
    size: (u32, u32),
    accumulator: Accumulator,
    // the compute path's edge sum (1 x 1 on the raster path)
    edge_sum: wgpu::Texture,
}

/// The WGSL library of this crate's shaders (`// requires:` names).
const LIBRARY: &[(&str, &str)] = &[
    ("penumbra-wedge/light.wgsl", include_str!("../shaders/light.wgsl")),
    ("penumbra-wedge/coverage.wgsl", include_str!("../shaders/coverage.wgsl")),
    ("penumbra-wedge/footprint.wgsl", include_str!("../shaders/footprint.wgsl")),
];

#[repr(C)]
#[derive(Clone, Copy, bytemuck::Pod, bytemuck::Zeroable)]
struct FootprintVertex {
    ndc: [f32; 2],
    first: u32,
    count: u32,
}

#[repr(C)]
#[derive(Clone, Copy, bytemuck::Pod, bytemuck::Zeroable)]
struct ViewUniform {
    view_proj: [[f32; 4]; 4],
    // w = 1: the eye of a perspective; w = 0: a point behind every receiver of an orthographic
    // view, from which depths are measured along `forward`
    eye: [f32; 4],
    // the orthographic view's axis (w unused)
    forward: [f32; 4],
}

/// The volume pass's view: `view`'s pixels, depths measured from its eye (or, orthographic,
/// from a plane behind every receiver within `bounds`).
fn view_uniform(view: &gpu::View, view_proj: &Mat4, bounds: Option<(Vec3, Vec3)>, extent: f32) -> ViewUniform {
    let forward = view.forward();
    let eye = if view.is_orthographic() {
        let (lo, hi) = bounds.unwrap_or((view.eye(), view.eye()));
        let nearest = (0..8)
            .map(|k| Vec3::select(glam::BVec3::new(k & 1 != 0, k & 2 != 0, k & 4 != 0), hi, lo))
            .map(|c| (c - view.eye()).dot(forward))
            .fold(0.0f32, f32::min);
        (view.eye() + forward * (nearest - extent)).extend(0.0)
    } else {
        view.eye().extend(1.0)
    };
    ViewUniform {
        view_proj: view_proj.to_cols_array_2d(),
        eye: eye.to_array(),
        forward: forward.extend(0.0).to_array(),
    }
}

/// The compute path's R32Float sum of edge terms (zero-initialized).
fn edge_sum_texture(gpu: &Gpu, (w, h): (u32, u32)) -> wgpu::Texture {
    gpu.create_texture(&wgpu::TextureDescriptor {
        label: Some("wedge edge sum"),
        size: wgpu::Extent3d { width: w.max(1), height: h.max(1), depth_or_array_layers: 1 },
        mip_level_count: 1,
        sample_count: 1,
        dimension: wgpu::TextureDimension::D2,
        format: wgpu::TextureFormat::R32Float,
        usage: wgpu::TextureUsages::STORAGE_BINDING | wgpu::TextureUsages::TEXTURE_BINDING,
        view_formats: &[],
    })
}

/// The box around every caster's bounding sphere.
fn casters_bounds(casters: &Casters) -> (Vec3, Vec3) {
    let (mut lo, mut hi) = (Vec3::splat(f32::INFINITY), Vec3::splat(f32::NEG_INFINITY));
    for c in &casters.casters {
        let (centre, r) = c.world_bounds();
        lo = lo.min(centre - Vec3::splat(r));
        hi = hi.max(centre + Vec3::splat(r));
    }
    (lo, hi)
}

/// Whether the segment from `a` to `b` meets the box `(lo, hi)`.
fn segment_meets_box(a: Vec3, b: Vec3, bounds: (Vec3, Vec3)) -> bool {
    geometry::box_interval(a, b - a, bounds).is_some_and(|(t0, _)| t0 <= 1.0)
}

/// Whether any shadow of `caster` from `light` can land in `receivers` within `extent`: its
/// bounding sphere swept away from the light, widened by the penumbra, against the box.
fn shadow_can_reach(caster: &Caster, light: &LightShape, receivers: (Vec3, Vec3), extent: f32) -> bool {
    let (c, r) = caster.world_bounds();
    let (dir, tan_spread) = match *light {
        LightShape::Distant { direction, half_angle } => {
            (-direction.normalize_or(Vec3::Y), half_angle.clamp(0.0, LightShape::MAX_HALF_ANGLE).tan())
        }
        LightShape::Sphere { center, radius } => {
            let d = c.distance(center);
            if d <= r + radius {
                return true;
            }
            ((c - center) / d, ((radius + r) / d).asin().tan())
        }
    };
    let widen = Vec3::splat(r + extent * tan_spread);
    segment_meets_box(c, c + dir * extent, (receivers.0 - widen, receivers.1 + widen))
}

impl Wedges {
    /// The casters of `scene` and the pipelines.
    #[must_use]
    pub fn new(gpu: &Gpu, scene: &scene::Scene, settings: WedgeSettings) -> Self {
        let casters = Casters::new(scene);
        let (lo, hi) = casters_bounds(&casters);
        let module = |label, src| gpu::shader::module(&gpu.device, label, src, LIBRARY);
        let volume_module = module("shadow volume", include_str!("../shaders/volume.wgsl"));
        let wedge_module = module("wedges", include_str!("../shaders/wedge.wgsl"));
        let pipeline = |label, m: &wgpu::ShaderModule, entry: &str, layout: Option<wgpu::VertexBufferLayout<'_>>| {
            gpu.render_pipeline(&wgpu::RenderPipelineDescriptor {
                label: Some(label),
                layout: None,
                vertex: wgpu::VertexState {
                    module: m,
                    entry_point: Some(entry),
                    compilation_options: Default::default(),
                    buffers: if layout.is_some() { std::slice::from_ref(&layout) } else { &[] },
                },
                // both windings: the volume's count needs them; footprints are screen-facing
                primitive: wgpu::PrimitiveState::default(),
                depth_stencil: None,
                multisample: Default::default(),
                fragment: Some(wgpu::FragmentState {
                    module: m,
                    entry_point: Some("fs"),
                    compilation_options: Default::default(),
                    targets: &[Some(Accumulator::target(gpu))],
                }),
                multiview_mask: None,
                cache: None,
            })
        };
        let volume = pipeline(
            "shadow volume",
            &volume_module,
            "vs",
            Some(wgpu::VertexBufferLayout {
                array_stride: 12,
                step_mode: wgpu::VertexStepMode::Vertex,
                attributes: &wgpu::vertex_attr_array![0 => Float32x3],
            }),
        );
        let wedge = pipeline(
            "wedges",
            &wedge_module,
            "vs",
            Some(wgpu::VertexBufferLayout {
                array_stride: std::mem::size_of::<FootprintVertex>() as u64,
                step_mode: wgpu::VertexStepMode::Vertex,
                attributes: &wgpu::vertex_attr_array![0 => Float32x2, 1 => Uint32, 2 => Uint32],
            }),
        );
        let polygons = pipeline("wedges built on the GPU", &wedge_module, "vs_polygon", None);
        let resolve = ResolvePass::with_shader(gpu, "wedge resolve", include_str!("../shaders/resolve.wgsl"), LIBRARY);
        let tiles_module = module("wedge tiles", include_str!("../shaders/tiles.wgsl"));
        let tiles = gpu.compute_pipeline(&wgpu::ComputePipelineDescriptor {
            label: Some("wedge tiles"),
            layout: None,
            module: &tiles_module,
            entry_point: Some("main"),
            compilation_options: Default::default(),
            cache: None,
        });
        let no_edge_sum = edge_sum_texture(gpu, (1, 1));
        let builder = GpuBuilder::new(gpu, &casters, settings.build_sizes(), LIBRARY);
        Self {
            casters,
            bounds: (lo, hi),
            settings,
            volume,
            wedge,
            tiles,
            resolve,
            no_edge_sum,
            builder,
            polygons,
            scratch: RefCell::new(None),
            slots: gpu::Slots::new(),
        }
    }

    /// The volume pass's bind group: the view, the G-buffer's positions.
    fn volume_bind(&self, gpu: &Gpu, view: &wgpu::Buffer, position: &wgpu::TextureView) -> wgpu::BindGroup {
        gpu.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("shadow volume"),
            layout: &self.volume.get_bind_group_layout(0),
            entries: &[
                wgpu::BindGroupEntry { binding: 0, resource: view.as_entire_binding() },
                wgpu::BindGroupEntry { binding: 1, resource: wgpu::BindingResource::TextureView(position) },
            ],
        })
    }

    /// The scratch targets for images of `size`, made when the size changes.
    fn scratch(&self, gpu: &Gpu, size: (u32, u32)) -> Result<Scratch, GpuError> {
        let mut cached = self.scratch.borrow_mut();
        if let Some(s) = cached.as_ref().filter(|s| s.size == size) {
            return Ok(s.clone());
        }
        let edge_size = if self.settings.path == WedgePath::Compute { size } else { (1, 1) };
        let s = Scratch { size, accumulator: Accumulator::new(gpu, size)?, edge_sum: edge_sum_texture(gpu, edge_size) };
        *cached = Some(s.clone());
        Ok(s)
    }

    /// Moves object `object` to its mesh in `scene` (a new pose): its caster is welded again
    /// from the moved positions, on the CPU, as [`Wedges::new`] would, and its positions are
    /// written to the GPU builder's buffer (`queue.write_buffer`; its buffers are made again
    /// only when the mesh's triangles changed). No pipeline is made.
    ///
    /// # Errors
    /// [`GpuError::Failed`] for an object out of range.
    pub fn update_object(&mut self, gpu: &Gpu, scene: &scene::Scene, object: usize) -> Result<(), GpuError> {
        let (Some(slot), Some(o)) = (self.casters.casters.get_mut(object), scene.objects.get(object)) else {
            return Err(GpuError::Failed(format!("wedges: no object {object}")));
        };
        let mut moved = Caster::new(&o.name, &o.mesh.positions, &o.mesh.indices);
        moved.transform = slot.transform;
        // the same welded triangles: the builder's buffers hold its topology already
        let same = moved.triangles == slot.triangles && moved.positions.len() == slot.positions.len();
        *slot = moved;
        self.bounds = casters_bounds(&self.casters);
        self.builder.update(gpu, &self.casters, object, same, self.settings.build_sizes());
        Ok(())
    }

    /// Sets object `object`'s transform (from its mesh as the wedges were made with, to the
    /// world): a rigid (or any affine) motion without welding or building anything. One
    /// `queue.write_buffer`; the next light recorded places the casters' vertices on the GPU
    /// first. The CPU builder ([`Wedges::plan`]) and the culling use the same transform.
    ///
    /// # Errors
    /// [`GpuError::Failed`] for an object out of range or a non-finite transform.
    pub fn set_transform(&mut self, gpu: &Gpu, object: usize, transform: glam::Affine3A) -> Result<(), GpuError> {
        let Some(slot) = self.casters.casters.get_mut(object) else {
            return Err(GpuError::Failed(format!("wedges: no object {object}")));
        };
        self.builder.set_transform(gpu, object, transform)?;
        slot.transform = transform;
        self.bounds = casters_bounds(&self.casters);
        Ok(())
    }

    /// How many chunks one light's GPU build takes: 1 while the casters fit the device's
    /// buffers (and [`WedgeSettings::chunk_bytes`]), more for larger meshes, 0 when the
    /// casters could not be built (every light then fails with the reason).
    #[must_use]
    pub fn build_chunks(&self) -> usize {
        self.builder.mesh.as_ref().map_or(0, |m| m.chunks.len())
    }

    /// The casters (which are closed, which cast as sheets).
    #[must_use]
    pub fn casters(&self) -> &Casters {
        &self.casters
    }

    /// How far volumes and wedges reach: twice the diameter of casters and receivers together.
    fn extent(&self, receivers: Option<(Vec3, Vec3)>) -> f32 {
        let (mut lo, mut hi) = self.bounds;
        if let Some((a, b)) = receivers {
            lo = lo.min(a);
            hi = hi.max(b);
        }
        let d = (hi - lo).length();
        if d.is_finite() { 2.0 * d.max(1e-6) } else { 1.0 }
    }

    /// What to draw for `light` seen with `view_proj`, given the receivers' bounds.
    #[must_use]
    pub fn plan(&self, light: &LightShape, receivers: Option<(Vec3, Vec3)>, view_proj: &Mat4) -> WedgePlan {
        let mut plan = WedgePlan::default();
        let Some(rb) = receivers else { return plan };
        let extent = self.extent(receivers);
        // nearer than this no receiver can be (the G-buffer's near plane is farther)
        let near = extent * 1e-7;
        let cull = self.settings.cull;
        let mut casters_culled = 0u64;
        let sils = self.casters.silhouettes(light, |c| {
            let keep = self.casts(c, light, rb, extent);
            casters_culled += u64::from(!keep);
            keep
        });
        let (mut at_light, mut away) = (0u64, 0u64);
        for (caster, sil) in &sils {
            let length = self.volume_length(caster, light, rb, extent);
            plan.volume.extend(geometry::shadow_volume(sil, light, length));
            for chain in geometry::chains(&sil.edges) {
                for group in chain.chunks(self.settings.edges_per_footprint.max(1) as usize) {
                    let mut points = Vec::with_capacity(18 * group.len());
                    let mut edges = Vec::with_capacity(group.len());
                    for &k in group {
                        let [a, b] = sil.edges[k];
                        match geometry::wedge_hull_points(a, b, light, extent, cull.then_some(rb)) {
                            Some(p) => {
                                points.extend(p);
                                edges.push(k);
                            }
                            // a distant light's wedge that cannot reach a receiver, or a local
                            // light's edge with an endpoint inside it
                            None if matches!(light, LightShape::Distant { .. }) => away += 1,
                            None => at_light += 1,
                        }
                    }
                    if edges.is_empty() {
                        continue;
                    }
                    let tris = if cull && !geometry::points_meet_box(&points, rb) {
                        Vec::new()
                    } else {
                        geometry::footprint(&points, view_proj, near)
                    };
                    if tris.is_empty() {
                        away += edges.len() as u64;
                        continue;
                    }
                    let first = plan.edges.len() as u32;
                    let count = edges.len() as u32;
                    plan.edges.extend(edges.iter().map(|&k| sil.edges[k]));
                    plan.normals.extend(edges.iter().map(|&k| sil.normals[k]));
                    plan.footprints.extend(tris.into_iter().map(|t| (t, first, count)));
                }
            }
        }
        plan.culled = vec![(CULLED_CASTERS, casters_culled), (CULLED_WEDGES, away), (CULLED_AT_LIGHT, at_light)];
        plan
    }
}

/// What [`ShadowPassReport::culled`] counts, as [`Wedges::plan`] and the GPU builder name it.
const CULLED_CASTERS: &str = "casters whose shadow cannot reach a visible receiver";
const CULLED_WEDGES: &str = "wedges off screen or away from visible receivers";
const CULLED_AT_LIGHT: &str = "edges with an endpoint inside the light";

/// The light as light.wgsl's `Light` reads it.
fn light_uniform(light: &LightShape, cosine_weighted: bool) -> [[f32; 4]; 2] {
    let cosine = if cosine_weighted { 1.0 } else { 0.0 };
    match *light {
        LightShape::Distant { direction, half_angle } => {
            [direction.normalize_or(Vec3::Y).extend(0.0).to_array(), [0.0, half_angle, cosine, 0.0]]
        }
        LightShape::Sphere { center, radius } => [center.extend(1.0).to_array(), [1.0, radius, cosine, 0.0]],
    }
}

/// build.wgsl's `Build`.
#[repr(C)]
#[derive(Clone, Copy, bytemuck::Pod, bytemuck::Zeroable)]
struct BuildUniform {
    light: [[f32; 4]; 2],
    view_proj: [[f32; 4]; 4],
    receivers_lo: [f32; 4],
    receivers_hi: [f32; 4],
    reach: [f32; 4],
}

impl Wedges {
    /// Whether `caster` casts for `light` with these settings: always unculled, else when its
    /// shadow can reach the receivers' box `rb`.
    fn casts(&self, caster: &Caster, light: &LightShape, rb: (Vec3, Vec3), extent: f32) -> bool {
        !self.settings.cull || shadow_can_reach(caster, light, rb, extent)
    }

    /// How far `caster`'s volume reaches: a distant light's, culled, ends where no receiver can
    /// be (from the caster's bounding sphere); otherwise the scene's extent.
    fn volume_length(&self, caster: &Caster, light: &LightShape, rb: (Vec3, Vec3), extent: f32) -> f32 {
        match *light {
            LightShape::Distant { direction, .. } if self.settings.cull => {
                let (c, r) = caster.world_bounds();
                reach_along(c, r, -direction.normalize_or(Vec3::Y), 0.0, rb, extent).unwrap_or(0.0).max(r * 1e-3) + r
            }
            _ => extent,
        }
    }

    /// Per caster, for `light` and the receivers' box, what the GPU builder reads (as
    /// [`Wedges::plan`] decides it), and how many casters were culled.
    fn caster_params(&self, light: &LightShape, rb: (Vec3, Vec3), extent: f32) -> (Vec<gpu_build::CasterParams>, u64) {
        let mut culled = 0u64;
        let params = self
            .casters
            .casters
            .iter()
            .map(|c| {
                let keep = self.casts(c, light, rb, extent);
                culled += u64::from(!keep);
                let length = self.volume_length(c, light, rb, extent);
                [f32::from(u8::from(keep)), f32::from(u8::from(c.closed)), length, 0.0]
            })
            .collect();
        (params, culled)
    }

    /// The silhouette the GPU builder finds for `light` and `receivers` (with these settings'
    /// culling): its edges and their faces' normals, in the builder's order (by caster, then
    /// along its edges' curve), without lit faces. Measurement and tests: the light recorded
    /// ungated and submitted, waited for, then its silhouette read back.
    ///
    /// # Errors
    /// Wedges not built on the GPU (the compute path or [`WedgeBuild::Cpu`]); casters beyond
    /// the device's limits; GPU failures.
    pub fn silhouette_on_gpu(
        &self,
        gpu: &Gpu,
        receivers: &Receivers,
        light: &LightShape,
    ) -> Result<casters::Silhouette, GpuError> {
        if !self.built_on_gpu() {
            return Err(GpuError::Failed(format!("{}: not built on the GPU", self.name())));
        }
        let (w, h) = receivers.gbuffer.size();
        let vis = gpu::VisibilityLayers::new(gpu, w, h, 1)?;
        let mut encoder = gpu.encoder("silhouette");
        let mut kept = Vec::new();
        self.record_built(gpu, &mut encoder, receivers, light, None, &vis.layer(0), Some(&mut kept))?;
        gpu.submit_and_wait(encoder)?;
        let v = |a: [f32; 4]| Vec3::new(a[0], a[1], a[2]);
        let mut silhouette = casters::Silhouette { edges: Vec::new(), normals: Vec::new(), lit_faces: Vec::new() };
        // chunk by chunk, in edge order
        for (args, edges) in &kept {
            let args: Vec<u32> = bytemuck::pod_collect_to_vec(&gpu::read_buffer(gpu, args)?);
            let edges: Vec<[[f32; 4]; 4]> = bytemuck::pod_collect_to_vec(&gpu::read_buffer(gpu, edges)?);
            let n = (args[12] as usize).min(edges.len());
            silhouette.edges.extend(edges[..n].iter().map(|e| [v(e[0]), v(e[1])]));
            silhouette.normals.extend(edges[..n].iter().map(|e| [v(e[2]), v(e[3])]));
        }
        Ok(silhouette)
    }

    /// Whether lights are built on the GPU: [`WedgeBuild::Gpu`] on the raster path.
    fn built_on_gpu(&self) -> bool {
        self.settings.build == WedgeBuild::Gpu && self.settings.path == WedgePath::Raster
    }

    /// [`ShadowTechnique::record`] with the geometry built on the GPU (`gpu_build`), chunk by
    /// chunk; `keep` gets a copy of each chunk's arguments and silhouette (measurement).
    #[allow(clippy::too_many_arguments)]
    fn record_built(
        &self,
        gpu: &Gpu,
        encoder: &mut wgpu::CommandEncoder,
        receivers: &Receivers,
        light: &LightShape,
        gate: Option<gpu::Gate<'_>>,
        target: &wgpu::TextureView,
        mut keep: Option<&mut Vec<(wgpu::Buffer, wgpu::Buffer)>>,
    ) -> Result<ShadowPassReport, GpuError> {
        let mesh = self.builder.mesh.as_ref().map_err(|e| GpuError::Failed(format!("wedges: {e}")))?;
        let gb = receivers.gbuffer;
        let extent = self.extent(receivers.bounds);
        let view_proj = gb.view.unclipped_projection(extent * 1e-6);
        let (params, culled) = match receivers.bounds {
            Some(rb) => self.caster_params(light, rb, extent),
            // nothing visible: nothing to build
            None => (Vec::new(), 0),
        };
        let (lo, hi) = receivers.bounds.unwrap_or((Vec3::ZERO, Vec3::ZERO));
        let light_params = light_uniform(light, self.settings.cosine_weighted);
        let uniform = BuildUniform {
            light: light_params,
            view_proj: view_proj.to_cols_array_2d(),
            receivers_lo: lo.extend(0.0).to_array(),
            receivers_hi: hi.extend(0.0).to_array(),
            reach: [
                extent,
                extent * 1e-7,
                f32::from(u8::from(self.settings.cull)),
                gpu_build::group_size(self.settings.edges_per_footprint) as f32,
            ],
        };
        let mut caster_words = params;
        // one row a caster whatever the light (culled rows stay zero), at least one
        caster_words.resize(self.casters.casters.len().max(1), [0.0; 4]);
        let view = view_uniform(&gb.view, &view_proj, receivers.bounds, extent);
        let caster_bytes = std::mem::size_of_val(caster_words.as_slice()) as u64;
        let make = || {
            let buffer = |label, size, usage: wgpu::BufferUsages| {
                gpu.create_buffer(&wgpu::BufferDescriptor {
                    label: Some(label),
                    size,
                    usage: usage | wgpu::BufferUsages::COPY_DST,
                    mapped_at_creation: false,
                })
            };
            LightSlot {
                uniform: buffer("wedge build", std::mem::size_of::<BuildUniform>() as u64, wgpu::BufferUsages::UNIFORM),
                casters: buffer("wedge casters", caster_bytes, wgpu::BufferUsages::STORAGE),
                view: buffer("wedge view", std::mem::size_of::<ViewUniform>() as u64, wgpu::BufferUsages::UNIFORM),
                binds: gpu::Keyed::default(),
            }
        };
        // the casters' count never changes (`update_object` keeps it): every slot fits
        let binds = self.slots.next_or_own(gpu, make, |slot| {
            gpu.queue.write_buffer(&slot.uniform, 0, bytemuck::bytes_of(&uniform));
            gpu.queue.write_buffer(&slot.casters, 0, bytemuck::cast_slice(&caster_words));
            gpu.queue.write_buffer(&slot.view, 0, bytemuck::bytes_of(&view));
            let key = (mesh.silhouette.clone(), gb.position.clone(), gb.geometric_normal.clone());
            let (uniform_buf, casters_buf, view_buf) = (slot.uniform.clone(), slot.casters.clone(), slot.view.clone());
            let binds = slot.binds.get(key, || {
                // the wedge pass's light: the build uniform's first words (`Build.light`)
                let light_binding = wgpu::BindingResource::Buffer(wgpu::BufferBinding {
                    buffer: &uniform_buf,
                    offset: 0,
                    size: wgpu::BufferSize::new(std::mem::size_of_val(&light_params) as u64),
                });
                let build = LightBuild { uniform: &uniform_buf, casters: &casters_buf };
                let build = self.builder.bind_groups(gpu, mesh, &build);
                let position = gb.position.create_view(&Default::default());
                let normal = gb.geometric_normal.create_view(&Default::default());
                let volume = self.volume_bind(gpu, &view_buf, &position);
                let wedge = gpu.create_bind_group(&wgpu::BindGroupDescriptor {
                    label: Some("wedges"),
                    layout: &self.polygons.get_bind_group_layout(0),
                    entries: &[
                        wgpu::BindGroupEntry { binding: 0, resource: light_binding },
                        wgpu::BindGroupEntry { binding: 1, resource: mesh.silhouette.as_entire_binding() },
                        wgpu::BindGroupEntry { binding: 2, resource: wgpu::BindingResource::TextureView(&position) },
                        wgpu::BindGroupEntry { binding: 3, resource: wgpu::BindingResource::TextureView(&normal) },
                        wgpu::BindGroupEntry { binding: 4, resource: mesh.footprints.as_entire_binding() },
                    ],
                });
                LightBinds { build, volume, wedge }
            });
            binds.clone()
        });
        let scratch = self.scratch(gpu, gb.size())?;
        let acc = &scratch.accumulator;
        // moved casters' vertices first (nothing when none moved)
        mesh.record_placement(gpu, encoder);
        // per chunk, its workgroups of faces and its edge blocks (zero when nothing is visible)
        let visible = receivers.bounds.is_some();
        let sizes: Vec<(u32, u32)> = mesh
            .chunks
            .iter()
            .map(|c| {
                if visible {
                    (c.range.faces.1.div_ceil(gpu_build::BLOCK), c.range.edges.1.div_ceil(gpu_build::BLOCK))
                } else {
                    (0, 0)
                }
            })
            .collect();
        // chunks read faces of other chunks: every face is marked first
        let chunked = sizes.len() > 1;
        let mut args = Vec::new();
        if chunked {
            args.extend(sizes.iter().map(|&(f, _)| Indirect::Dispatch([f, 1, 1])));
        }
        for &(f, e) in &sizes {
            args.extend([
                Indirect::Dispatch([f, 1, 1]),
                Indirect::Dispatch([e, 1, 1]),
                Indirect::Dispatch([u32::from(e > 0), 1, 1]),
                Indirect::Dispatch([e, 1, 1]),
            ]);
        }
        args.push(Indirect::draw(0..3));
        let resolve_call = args.len() - 1;
        let calls = Calls::new(gpu, encoder, gate, args);
        let mut call = 0;
        if chunked {
            let mut pass = encoder.begin_compute_pass(&wgpu::ComputePassDescriptor {
                label: Some("wedge faces"),
                timestamp_writes: None,
            });
            pass.set_pipeline(&self.builder.classify);
            for chunk in &binds.build.chunks {
                pass.set_bind_group(0, &chunk.mark_only, &[]);
                calls.dispatch(&mut pass, call);
                call += 1;
            }
        }
        for (k, chunk) in binds.build.chunks.iter().enumerate() {
            // what the GPU does not write stays zero: no draw, no dispatch
            encoder.clear_buffer(&mesh.args, 0, None);
            encoder.clear_buffer(&mesh.footprint_dispatch, 0, None);
            {
                let mut pass = encoder.begin_compute_pass(&wgpu::ComputePassDescriptor {
                    label: Some("wedge build"),
                    timestamp_writes: None,
                });
                let stages = [&self.builder.classify, &self.builder.mark, &self.builder.scan, &self.builder.emit];
                for (pipeline, bind) in stages.into_iter().zip(&chunk.stages) {
                    pass.set_pipeline(pipeline);
                    pass.set_bind_group(0, bind, &[]);
                    calls.dispatch(&mut pass, call);
                    call += 1;
                }
                pass.set_pipeline(&self.builder.footprint);
                pass.set_bind_group(0, &binds.build.footprint, &[]);
                pass.dispatch_workgroups_indirect(&mesh.footprint_dispatch, 0);
            }
            if let Some(keep) = keep.as_deref_mut() {
                let copy = |encoder: &mut wgpu::CommandEncoder, from: &wgpu::Buffer| {
                    let to = gpu.create_buffer(&wgpu::BufferDescriptor {
                        label: Some("kept wedge build"),
                        size: from.size(),
                        usage: wgpu::BufferUsages::COPY_DST | wgpu::BufferUsages::COPY_SRC,
                        mapped_at_creation: false,
                    });
                    encoder.copy_buffer_to_buffer(from, 0, &to, 0, from.size());
                    to
                };
                let kept = (copy(encoder, &mesh.args), copy(encoder, &mesh.silhouette));
                keep.push(kept);
            }
            {
                let mut pass = encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
                    label: Some("wedges"),
                    color_attachments: &[Some(acc.attachment(k == 0))],
                    ..Default::default()
                });
                pass.set_pipeline(&self.volume);
                pass.set_bind_group(0, &binds.volume, &[]);
                pass.set_vertex_buffer(0, mesh.volume.slice(..));
                pass.draw_indirect(&mesh.args, 0);
                pass.set_pipeline(&self.polygons);
                pass.set_bind_group(0, &binds.wedge, &[]);
                pass.draw_indirect(&mesh.args, 16);
            }
            self.builder.keep_counts(encoder, mesh);
        }
        let extra = [(3, &gb.geometric_normal), (4, &self.no_edge_sum)];
        self.resolve.record(
            gpu,
            encoder,
            gb,
            acc,
            bytemuck::cast_slice(&light_params),
            &extra,
            Some((&calls, resolve_call)),
            target,
        )?;
        Ok(ShadowPassReport {
            time: std::time::Duration::ZERO,
            clock: None,
            skipped: None,
            // known once the frame has run (`read_counts`)
            primitives: 0,
            culled: if receivers.bounds.is_some() { vec![(CULLED_CASTERS, culled)] } else { Vec::new() },
        })
    }
}

impl ShadowTechnique for Wedges {
    fn name(&self) -> String {
        let path = match self.settings.path {
            WedgePath::Raster => "",
            WedgePath::Compute => "_compute",
        };
        format!(
            "wedges{path}{}{}",
            if self.settings.cull { "" } else { "_unculled" },
            if self.settings.cosine_weighted { "" } else { "_unweighted" }
        ) + if self.settings.path == WedgePath::Raster && !self.built_on_gpu() { "_cpu_built" } else { "" }
    }

    fn supports(&self, _light: &LightShape) -> bool {
        true
    }

    /// The GPU builder's counts: primitives drawn (volume and footprint triangles), wedges off
    /// screen or away from receivers, edges with an endpoint inside the light.
    fn read_counts(&self, gpu: &Gpu, reports: &mut [ShadowPassReport]) -> Result<(), GpuError> {
        if !self.built_on_gpu() {
            return Ok(());
        }
        let shadowed: Vec<&mut ShadowPassReport> = reports.iter_mut().filter(|r| r.skipped.is_none()).collect();
        let counts = self.builder.read_counts(gpu, shadowed.len())?;
        // the last lights recorded are the last reports
        for (r, c) in shadowed.into_iter().rev().zip(counts.into_iter().rev()) {
            r.primitives = u64::from(c[0] / 3) + u64::from(c[15]);
            if !r.culled.is_empty() {
                r.culled.push((CULLED_WEDGES, c[13].into()));
                r.culled.push((CULLED_AT_LIGHT, c[14].into()));
            }
        }
        Ok(())
    }

    fn record(
        &self,
        gpu: &Gpu,
        encoder: &mut wgpu::CommandEncoder,
        receivers: &Receivers,
        light: &LightShape,
        gate: Option<gpu::Gate<'_>>,
        target: &wgpu::TextureView,
    ) -> Result<ShadowPassReport, GpuError> {
        if self.built_on_gpu() {
            return self.record_built(gpu, encoder, receivers, light, gate, target, None);
        }
        let gb = receivers.gbuffer;
        let extent = self.extent(receivers.bounds);
        let view_proj = gb.view.unclipped_projection(extent * 1e-6);
        let plan = self.plan(light, receivers.bounds, &view_proj);
        let volume: Vec<[f32; 3]> = plan.volume.iter().flatten().map(|v| v.to_array()).collect();
        let footprints: Vec<FootprintVertex> = plan
            .footprints
            .iter()
            .flat_map(|(t, first, count)| {
                t.map(|v| FootprintVertex { ndc: v.to_array(), first: *first, count: *count })
            })
            .collect();
        // `Edge` in coverage.wgsl: the ends and the lit and unlit faces' normals
        let mut edges: Vec<[[f32; 4]; 4]> = plan
            .edges
            .iter()
            .zip(&plan.normals)
            .map(|([a, b], [n, m])| [a.extend(1.0), b.extend(1.0), n.extend(0.0), m.extend(0.0)].map(|v| v.to_array()))
            .collect();
        if edges.is_empty() {
            edges.push([[0.0; 4]; 4]);
        }
        let buffer = |label, contents: &[u8], usage| {
            gpu.create_buffer_init(&wgpu::util::BufferInitDescriptor { label: Some(label), contents, usage })
        };
        let light_params = light_uniform(light, self.settings.cosine_weighted);
        let view = view_uniform(&gb.view, &view_proj, receivers.bounds, extent);
        let view_buf = buffer("wedge view", bytemuck::bytes_of(&view), wgpu::BufferUsages::UNIFORM);
        let light_buf = buffer("wedge light", bytemuck::cast_slice(&light_params), wgpu::BufferUsages::UNIFORM);
        let edge_buf = buffer("wedge edges", bytemuck::cast_slice(&edges), wgpu::BufferUsages::STORAGE);
        // wgpu refuses empty buffers: a dummy element when there is nothing to draw
        let volume_buf = (!volume.is_empty())
            .then(|| buffer("shadow volume", bytemuck::cast_slice(&volume), wgpu::BufferUsages::VERTEX));
        // the compute path bins the footprints instead of drawing them
        let footprint_buf = (!footprints.is_empty() && self.settings.path == WedgePath::Raster)
            .then(|| buffer("wedge footprints", bytemuck::cast_slice(&footprints), wgpu::BufferUsages::VERTEX));
        let position = gb.position.create_view(&Default::default());
        let normal = gb.geometric_normal.create_view(&Default::default());
        let volume_bind = self.volume_bind(gpu, &view_buf, &position);
        let wedge_bind = gpu.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("wedges"),
            layout: &self.wedge.get_bind_group_layout(0),
            entries: &[
                wgpu::BindGroupEntry { binding: 0, resource: light_buf.as_entire_binding() },
                wgpu::BindGroupEntry { binding: 1, resource: edge_buf.as_entire_binding() },
                wgpu::BindGroupEntry { binding: 2, resource: wgpu::BindingResource::TextureView(&position) },
                wgpu::BindGroupEntry { binding: 3, resource: wgpu::BindingResource::TextureView(&normal) },
            ],
        });
        let scratch = self.scratch(gpu, gb.size())?;
        let acc = &scratch.accumulator;
        let compute = (self.settings.path == WedgePath::Compute).then(|| {
            let (w, h) = gb.size();
            let bins = bin_footprints(&plan.footprints, (w, h));
            let tiles = [w, h, bins.tiles_x, 0];
            let mut groups = bins.groups;
            if groups.is_empty() {
                groups.push([0, 0]);
            }
            let sum = scratch.edge_sum.clone();
            let sum_view = sum.create_view(&Default::default());
            let tiles_buf = buffer("wedge tiles", bytemuck::cast_slice(&tiles), wgpu::BufferUsages::UNIFORM);
            let ranges_buf =
                buffer("wedge tile ranges", bytemuck::cast_slice(&bins.ranges), wgpu::BufferUsages::STORAGE);
            let groups_buf = buffer("wedge tile groups", bytemuck::cast_slice(&groups), wgpu::BufferUsages::STORAGE);
            let bind = gpu.create_bind_group(&wgpu::BindGroupDescriptor {
                label: Some("wedge tiles"),
                layout: &self.tiles.get_bind_group_layout(0),
                entries: &[
                    wgpu::BindGroupEntry { binding: 0, resource: light_buf.as_entire_binding() },
                    wgpu::BindGroupEntry { binding: 1, resource: edge_buf.as_entire_binding() },
                    wgpu::BindGroupEntry { binding: 2, resource: wgpu::BindingResource::TextureView(&position) },
                    wgpu::BindGroupEntry { binding: 3, resource: tiles_buf.as_entire_binding() },
                    wgpu::BindGroupEntry { binding: 4, resource: ranges_buf.as_entire_binding() },
                    wgpu::BindGroupEntry { binding: 5, resource: groups_buf.as_entire_binding() },
                    wgpu::BindGroupEntry { binding: 6, resource: wgpu::BindingResource::TextureView(&sum_view) },
                    wgpu::BindGroupEntry { binding: 7, resource: wgpu::BindingResource::TextureView(&normal) },
                ],
            });
            (sum, bind, (bins.tiles_x, h.div_ceil(TILE).max(1)))
        });
        // volume, footprints, tiles, resolve: gated on the GPU when the frame's lights are
        let tiles = compute.as_ref().map_or([0, 0, 0], |(_, _, (tx, ty))| [*tx, *ty, 1]);
        let calls = Calls::new(
            gpu,
            encoder,
            gate,
            vec![
                Indirect::draw(0..volume.len() as u32),
                Indirect::draw(0..footprints.len() as u32),
                Indirect::Dispatch(tiles),
                Indirect::draw(0..3),
            ],
        );
        {
            {
                let mut pass = encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
                    label: Some("wedges"),
                    color_attachments: &[Some(acc.attachment(true))],
                    ..Default::default()
                });
                if let Some(vb) = &volume_buf {
                    pass.set_pipeline(&self.volume);
                    pass.set_bind_group(0, &volume_bind, &[]);
                    pass.set_vertex_buffer(0, vb.slice(..));
                    calls.draw(&mut pass, 0);
                }
                if let Some(fb) = &footprint_buf {
                    pass.set_pipeline(&self.wedge);
                    pass.set_bind_group(0, &wedge_bind, &[]);
                    pass.set_vertex_buffer(0, fb.slice(..));
                    calls.draw(&mut pass, 1);
                }
            }
            if let Some((_, bind, _)) = &compute {
                let mut pass = encoder.begin_compute_pass(&wgpu::ComputePassDescriptor {
                    label: Some("wedge tiles"),
                    timestamp_writes: None,
                });
                pass.set_pipeline(&self.tiles);
                pass.set_bind_group(0, bind, &[]);
                calls.dispatch(&mut pass, 2);
            }
            let sum = compute.as_ref().map_or(&self.no_edge_sum, |(t, _, _)| t);
            let extra = [(3, &gb.geometric_normal), (4, sum)];
            let params = bytemuck::cast_slice(&light_params);
            self.resolve.record(gpu, encoder, gb, acc, params, &extra, Some((&calls, 3)), target)?;
        }
        Ok(ShadowPassReport {
            time: std::time::Duration::ZERO,
            clock: None,
            skipped: None,
            primitives: (plan.volume.len() + plan.footprints.len()) as u64,
            culled: plan.culled,
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::Vec2;

    /// Every pixel a footprint triangle covers lies in a tile that lists the footprint, once;
    /// tiles it cannot touch do not; off-screen and non-finite triangles bin nowhere.
    #[test]
    fn footprints_bin_into_the_tiles_they_touch_once() {
        let (w, h) = (100u32, 70u32);
        let ndc = |x: f32, y: f32| Vec2::new(x / w as f32 * 2.0 - 1.0, 1.0 - y / h as f32 * 2.0);
        let footprints = vec![
            // group (0, 3): two triangles of one quad over pixels 20..40 x 5..30
            ([ndc(20.0, 5.0), ndc(40.0, 5.0), ndc(40.0, 30.0)], 0, 3),
            ([ndc(20.0, 5.0), ndc(40.0, 30.0), ndc(20.0, 30.0)], 0, 3),
            // group (3, 1): a sliver in the last tiles, partly off screen
            ([ndc(95.0, 65.0), ndc(130.0, 66.0), ndc(96.0, 90.0)], 3, 1),
            // off screen and non-finite: nowhere
            ([ndc(-50.0, -50.0), ndc(-10.0, -50.0), ndc(-10.0, -5.0)], 4, 2),
            ([Vec2::NAN, ndc(1.0, 1.0), ndc(2.0, 2.0)], 6, 1),
        ];
        let bins = bin_footprints(&footprints, (w, h));
        assert_eq!((bins.tiles_x, bins.ranges.len()), (7, 7 * 5));
        let listed = |tx: u32, ty: u32| {
            let [first, count] = bins.ranges[(ty * bins.tiles_x + tx) as usize];
            bins.groups[first as usize..(first + count) as usize].to_vec()
        };
        for ty in 0..5 {
            for tx in 0..7 {
                let quad = (1..=2).contains(&tx) && ty <= 1;
                let sliver = (5..=6).contains(&tx) && ty == 4;
                let mut want = Vec::new();
                if quad {
                    want.push([0, 3]);
                }
                if sliver {
                    want.push([3, 1]);
                }
                assert_eq!(listed(tx, ty), want, "tile ({tx}, {ty})");
            }
        }
        assert!(bin_footprints(&[], (w, h)).groups.is_empty());
    }
}
