//! The wedges' geometry built on the GPU for every light (`crates/penumbra-wedge/shaders/build.wgsl`):
//! the casters' welded faces and their edges with adjacency live in buffers made once per scene;
//! per light, five compute dispatches classify the faces, count each edge's lit faces, compact
//! the silhouette in edge order, append the hard volume and bound each wedge's footprint. The
//! volume and the footprints are drawn indirectly from what the GPU wrote: the CPU records a
//! light without knowing its silhouette. [`crate::Wedges::plan`] is the same construction on
//! the CPU, the reference this one is tested against.
//!
//! A mesh whose per-light buffers (volume, silhouette, footprints, their hull points, the edge
//! marks) would exceed the device's storage binding limit, or [`crate::WedgeSettings`]'
//! `chunk_bytes`, is built in chunks of consecutive faces and edges ([`plan_chunks`]): a first
//! classify of every chunk marks each face lit or not, then each chunk builds and draws in
//! turn into the same accumulator from the same scratch buffers. An edge stays whole, with
//! all its faces, in one chunk, so the silhouette, its order and every edge term are the
//! unchunked ones: more passes, the same pixels.
//!
//! Two differences from the CPU plan, neither changing a pixel's terms: each silhouette edge
//! gets a footprint of its own (the CPU groups consecutive edges of a chain), and a footprint
//! is the octagon (x, y and both diagonals) around the wedge's projected hull points, clipped
//! to the screen, which contains the CPU's convex hull. The edge term is zero outside its
//! wedge, so a larger footprint adds only zeros; the sums' order differs (float rounding).

use crate::casters::Casters;
use gpu::{Gpu, GpuError};
use std::collections::BTreeMap;

/// Edges a workgroup of `mark` and `emit` handles (build.wgsl's workgroup size).
pub(crate) const BLOCK: u32 = 256;
/// Silhouette edges a workgroup of `footprint` handles.
const FOOTPRINT_GROUP: u32 = 64;
/// Bytes of build.wgsl's `Mark`.
const MARK_BYTES: u64 = 48;
/// Bytes of footprint.wgsl's `Footprint` (corner count, first edge, edge count, a pad word, 20
/// corners).
const FOOTPRINT_BYTES: u64 = 176;
/// Bytes of coverage.wgsl's `Edge`.
const EDGE_BYTES: u64 = 64;
/// Words of the indirect arguments and counts (build.wgsl's `args`).
const ARG_WORDS: u64 = 16;
/// Lights whose counts are kept for [`GpuBuilder::read_counts`] (a ring).
const COUNT_SLOTS: u32 = 256;

/// The casters as the builder reads them (every face and edge), and its per-light scratch,
/// sized for the largest of its chunks.
pub(crate) struct MeshBuffers {
    // world positions, placed from the welded ones by the casters' transforms
    positions: wgpu::Buffer,
    placement: gpu::placement::Placement,
    faces: wgpu::Buffer,
    edges: wgpu::Buffer,
    edge_faces: wgpu::Buffer,
    pub(crate) lit: wgpu::Buffer,
    marks: wgpu::Buffer,
    blocks: wgpu::Buffer,
    pub(crate) args: wgpu::Buffer,
    pub(crate) footprint_dispatch: wgpu::Buffer,
    pub(crate) volume: wgpu::Buffer,
    pub(crate) silhouette: wgpu::Buffer,
    pub(crate) footprints: wgpu::Buffer,
    hull_points: wgpu::Buffer,
    polygon_scratch: wgpu::Buffer,
    /// The passes of one light's build, in edge order (one when the mesh fits the buffers).
    pub(crate) chunks: Vec<Chunk>,
    // per caster, its first welded vertex in `positions`
    bases: Vec<u32>,
}

/// One pass of the build over a range of the faces and a range of the edges.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) struct ChunkRange {
    /// First face, face count.
    pub(crate) faces: (u32, u32),
    /// First edge, edge count.
    pub(crate) edges: (u32, u32),
    /// The most silhouette edges its edges can give.
    pub(crate) capacity: u32,
}

/// A chunk and its uniforms (build.wgsl's `Chunk`): building, and marking its faces only.
pub(crate) struct Chunk {
    pub(crate) range: ChunkRange,
    build: wgpu::Buffer,
    mark_only: wgpu::Buffer,
}

/// The per-light buffers a chunk of `faces` faces, `edges` edges and silhouette capacity
/// `capacity` needs, bytes, with `group` edges a footprint.
fn chunk_bytes(faces: u64, edges: u64, capacity: u64, group: u64) -> [(&'static str, u64); 5] {
    let footprints = capacity.div_ceil(group);
    [
        ("wedge volume bytes", 12 * 6 * (faces + capacity)),
        ("wedge silhouette bytes", EDGE_BYTES * capacity),
        ("wedge footprint bytes", FOOTPRINT_BYTES * footprints),
        ("wedge hull point bytes", 8 * 18 * group * footprints),
        ("wedge edge marks bytes", MARK_BYTES * edges),
    ]
}

/// Splits `faces` faces and the edges of silhouette capacities `capacities` (in order) into
/// consecutive chunks whose per-light buffers each stay within `limit` bytes and whose
/// dispatches within `max_groups` workgroups: one chunk holding everything when it fits;
/// otherwise half of the volume for the caps and half for the sides, the edges cut greedily
/// and the faces into as many equal ranges (padded with empty ranges where one side needs
/// fewer).
///
/// # Errors
/// [`GpuError::TooLarge`] when one edge alone exceeds a buffer (`limit` under a few hundred
/// bytes, or an edge shared by absurdly many faces).
pub(crate) fn plan_chunks(
    faces: u32,
    capacities: &[u32],
    group: u32,
    limit: u64,
    max_groups: u64,
) -> Result<Vec<ChunkRange>, GpuError> {
    let group = u64::from(group.max(1));
    let max_items = max_groups * u64::from(BLOCK);
    let edges = capacities.len() as u64;
    let total: u64 = capacities.iter().map(|&c| u64::from(c)).sum();
    let fits = |f: u64, e: u64, c: u64| {
        f <= max_items
            && e <= max_items
            && c.div_ceil(group).div_ceil(u64::from(FOOTPRINT_GROUP)) <= max_groups
            && chunk_bytes(f, e, c, group).iter().all(|(_, b)| *b <= limit)
    };
    let count = |n: u64| u32::try_from(n).unwrap_or(u32::MAX);
    if fits(u64::from(faces), edges, total) {
        return Ok(vec![ChunkRange { faces: (0, faces), edges: (0, count(edges)), capacity: count(total) }]);
    }
    let face_max = (limit / 2 / 72).min(max_items);
    let cap_max = (limit / 2 / 72)
        .min(limit / EDGE_BYTES)
        .min(group * (limit / FOOTPRINT_BYTES))
        .min(group * (limit / (8 * 18 * group)))
        .min(group * u64::from(FOOTPRINT_GROUP) * max_groups);
    let edge_max = (limit / MARK_BYTES).min(max_items);
    let too_small = |what, size| GpuError::TooLarge { what, size, limit };
    if face_max == 0 || edge_max == 0 {
        return Err(too_small("wedge build chunk bytes", 72.max(MARK_BYTES)));
    }
    // (first, count, capacity) of each edge range
    let mut ranges: Vec<(u64, u64, u64)> = Vec::new();
    let (mut first, mut n, mut cap) = (0u64, 0u64, 0u64);
    for (e, &c) in capacities.iter().enumerate() {
        let c = u64::from(c);
        if c > cap_max {
            return Err(too_small("silhouette capacity of one edge", c));
        }
        if n + 1 > edge_max || cap + c > cap_max {
            ranges.push((first, n, cap));
            (first, n, cap) = (e as u64, 0, 0);
        }
        n += 1;
        cap += c;
    }
    if n > 0 {
        ranges.push((first, n, cap));
    }
    let chunks = u64::from(faces).div_ceil(face_max).max(ranges.len() as u64).max(1);
    let per = u64::from(faces).div_ceil(chunks);
    Ok((0..chunks)
        .map(|j| {
            let f0 = (j * per).min(u64::from(faces));
            let f1 = ((j + 1) * per).min(u64::from(faces));
            let (e0, n, cap) = ranges.get(j as usize).copied().unwrap_or((edges, 0, 0));
            ChunkRange { faces: (count(f0), count(f1 - f0)), edges: (count(e0), count(n)), capacity: count(cap) }
        })
        .collect())
}

/// Silhouette edges a footprint: the setting, within 1 ..= 64.
pub(crate) fn group_size(edges_per_footprint: u32) -> u32 {
    edges_per_footprint.clamp(1, 64)
}

/// Per caster and light: whether it can shadow a visible receiver, whether it is closed, how
/// far its volume reaches (build.wgsl's `casters`).
pub(crate) type CasterParams = [f32; 4];

/// The builder's pipelines and the casters' buffers.
pub(crate) struct GpuBuilder {
    pub(crate) classify: wgpu::ComputePipeline,
    pub(crate) mark: wgpu::ComputePipeline,
    pub(crate) scan: wgpu::ComputePipeline,
    pub(crate) emit: wgpu::ComputePipeline,
    pub(crate) footprint: wgpu::ComputePipeline,
    pub(crate) mesh: Result<MeshBuffers, GpuError>,
    pub(crate) counts: wgpu::Buffer,
    next_slot: std::cell::Cell<u32>,
}

fn storage(gpu: &Gpu, label: &str, bytes: u64, extra: wgpu::BufferUsages) -> wgpu::Buffer {
    gpu.create_buffer(&wgpu::BufferDescriptor {
        label: Some(label),
        size: bytes.max(16),
        usage: wgpu::BufferUsages::STORAGE | extra,
        mapped_at_creation: false,
    })
}

/// The index of `p` along a Hilbert curve (21 bits an axis) through the cube of half-side
/// `radius` about `centre` (Skilling 2004, "Programming the Hilbert curve"): unlike a Morton
/// curve it never jumps, so consecutive edges in its order lie next to each other.
fn hilbert(p: glam::Vec3, centre: glam::Vec3, radius: f32) -> u64 {
    const BITS: u32 = 21;
    let q = (p - centre) / (2.0 * radius.max(f32::MIN_POSITIVE)) + 0.5;
    let mut x = q.to_array().map(|v| (v.clamp(0.0, 1.0) * ((1u32 << BITS) - 1) as f32) as u32);
    let top = 1u32 << (BITS - 1);
    let mut bit = top;
    while bit > 1 {
        let low = bit - 1;
        for i in 0..3 {
            if x[i] & bit != 0 {
                x[0] ^= low;
            } else {
                let t = (x[0] ^ x[i]) & low;
                x[0] ^= t;
                x[i] ^= t;
            }
        }
        bit >>= 1;
    }
    x[1] ^= x[0];
    x[2] ^= x[1];
    let mut t = 0;
    let mut bit = top;
    while bit > 1 {
        if x[2] & bit != 0 {
            t ^= bit - 1;
        }
        bit >>= 1;
    }
    let x = x.map(|v| v ^ t);
    (0..BITS).rev().fold(0u64, |h, b| (0..3).fold(h, |h, i| (h << 1) | u64::from((x[i] >> b) & 1)))
}

/// Caster `k`'s welded positions as the builder's buffer holds them: xyz, then the caster's
/// index (a `u32`: what the placement reads; the shaders read xyz only).
fn caster_positions(k: usize, c: &crate::casters::Caster) -> Vec<[f32; 4]> {
    c.positions.iter().map(|p| p.extend(f32::from_bits(k as u32)).to_array()).collect()
}

fn positions_of(casters: &Casters) -> Vec<[f32; 4]> {
    casters.casters.iter().enumerate().flat_map(|(k, c)| caster_positions(k, c)).collect()
}

impl MeshBuffers {
    /// Records the placement of moved casters' vertices (nothing when none moved).
    pub(crate) fn record_placement(&self, gpu: &Gpu, encoder: &mut wgpu::CommandEncoder) {
        self.placement.record(gpu, encoder, &self.positions);
    }

    fn new(gpu: &Gpu, casters: &Casters, sizes: BuildSizes) -> Result<Self, GpuError> {
        let mut faces: Vec<[u32; 4]> = Vec::new();
        let mut bases = Vec::with_capacity(casters.casters.len());
        // per undirected edge (global welded indices), its faces in triangle order
        let mut adjacency: BTreeMap<(u32, u32), Vec<u32>> = BTreeMap::new();
        let mut base = 0u32;
        for (k, c) in casters.casters.iter().enumerate() {
            bases.push(base);
            for t in &c.triangles {
                let g = t.map(|i| i + base);
                let face = faces.len() as u32;
                faces.push([g[0], g[1], g[2], k as u32]);
                for j in 0..3 {
                    let (a, b) = (g[j], g[(j + 1) % 3]);
                    adjacency.entry((a.min(b), a.max(b))).or_default().push(face);
                }
            }
            base += c.positions.len() as u32;
        }
        // each caster's edges along a Hilbert curve of their midpoints in its bounds: the
        // silhouette keeps this order, so a footprint's consecutive edges lie near each other
        let positions = positions_of(casters);
        let at = |i: u32| glam::Vec4::from(positions[i as usize]).truncate();
        let mut order: Vec<(u32, u64, (u32, u32))> = adjacency
            .keys()
            .map(|&(lo, hi)| {
                let caster = faces[adjacency[&(lo, hi)][0] as usize][3];
                let (centre, radius) = casters.casters[caster as usize].bounds;
                (caster, hilbert(0.5 * (at(lo) + at(hi)), centre, radius), (lo, hi))
            })
            .collect();
        order.sort_unstable();
        let mut edges: Vec<[u32; 4]> = Vec::with_capacity(adjacency.len());
        let mut edge_faces: Vec<u32> = Vec::new();
        let mut capacities: Vec<u32> = Vec::with_capacity(adjacency.len());
        for (lo, hi, list) in order.iter().map(|(_, _, (lo, hi))| (lo, hi, &adjacency[&(*lo, *hi)])) {
            let caster = faces[list[0] as usize][3] as usize;
            let closed = casters.casters[caster].closed;
            // a closed caster's edge is on the silhouette at most once, a sheet's at most once
            // a face
            capacities.push(if closed { 1 } else { list.len() as u32 });
            edges.push([*lo, *hi, edge_faces.len() as u32, list.len() as u32]);
            edge_faces.extend(list);
        }
        let limits = &gpu.limits;
        let binding = limits.max_storage_buffer_binding_size.min(limits.max_buffer_size);
        // what every chunk reads stays whole
        for (what, bytes) in [
            ("caster position bytes", 16 * positions.len() as u64),
            ("caster face bytes", 16 * faces.len() as u64),
            ("caster edge bytes", 16 * edges.len() as u64),
            ("caster edge face bytes", 4 * edge_faces.len() as u64),
        ] {
            if bytes > binding {
                return Err(GpuError::TooLarge { what, size: bytes, limit: binding });
            }
        }
        let group = group_size(sizes.edges_per_footprint);
        let limit = sizes.chunk_bytes.map_or(binding, |c| c.min(binding));
        let groups = u64::from(limits.max_compute_workgroups_per_dimension);
        let ranges = plan_chunks(faces.len() as u32, &capacities, group, limit, groups)?;
        // the scratch: the largest chunk's
        let largest = |f: fn(&ChunkRange) -> u64| ranges.iter().map(f).max().unwrap_or(0);
        let chunk_edges = largest(|r| u64::from(r.edges.1));
        let chunk_capacity = largest(|r| u64::from(r.capacity));
        let volume_bytes = largest(|r| 12 * 6 * (u64::from(r.faces.1) + u64::from(r.capacity)));
        let footprints = chunk_capacity.div_ceil(u64::from(group));
        let hull_points = 8 * 18 * u64::from(group) * footprints;
        let init = |label, contents: &[u8], usage| {
            let contents = if contents.is_empty() { &[0u8; 16][..] } else { contents };
            gpu.create_buffer_init(&wgpu::util::BufferInitDescriptor { label: Some(label), contents, usage })
        };
        let read = wgpu::BufferUsages::STORAGE;
        let blocks = chunk_edges.div_ceil(u64::from(BLOCK));
        let chunks = ranges
            .iter()
            .map(|r| {
                let uniform = |caps: u32| {
                    let words =
                        [r.faces.0, r.edges.0, caps, 0, r.faces.1, r.edges.1, r.edges.1.div_ceil(BLOCK), r.capacity];
                    init("wedge chunk", bytemuck::cast_slice(&words), wgpu::BufferUsages::UNIFORM)
                };
                Chunk { range: *r, build: uniform(1), mark_only: uniform(0) }
            })
            .collect();
        let placed = read | wgpu::BufferUsages::COPY_DST | wgpu::BufferUsages::COPY_SRC;
        let positions_buf = init("caster positions", bytemuck::cast_slice(&positions), placed);
        let words =
            gpu::placement::VertexWords { count: positions.len() as u32, stride: 4, normals: 0, object_word: 3 };
        let mut placement = gpu::placement::Placement::new(gpu, words, casters.casters.len())?;
        // a rebuilt mesh keeps where its casters are
        for (k, c) in casters.casters.iter().enumerate() {
            placement.set(gpu, &positions_buf, k, c.transform)?;
        }
        Ok(Self {
            positions: positions_buf,
            placement,
            faces: init("caster faces", bytemuck::cast_slice(&faces), read),
            edges: init("caster edges", bytemuck::cast_slice(&edges), read),
            edge_faces: init("caster edge faces", bytemuck::cast_slice(&edge_faces), read),
            lit: storage(gpu, "lit faces", 4 * faces.len() as u64, wgpu::BufferUsages::empty()),
            marks: storage(gpu, "edge marks", MARK_BYTES * chunk_edges, wgpu::BufferUsages::empty()),
            blocks: storage(gpu, "edge blocks", 4 * blocks, wgpu::BufferUsages::empty()),
            args: storage(
                gpu,
                "wedge arguments",
                4 * ARG_WORDS,
                wgpu::BufferUsages::INDIRECT | wgpu::BufferUsages::COPY_DST | wgpu::BufferUsages::COPY_SRC,
            ),
            footprint_dispatch: storage(
                gpu,
                "wedge footprint dispatch",
                16,
                wgpu::BufferUsages::INDIRECT | wgpu::BufferUsages::COPY_DST,
            ),
            volume: storage(gpu, "shadow volume", volume_bytes, wgpu::BufferUsages::VERTEX),
            silhouette: storage(gpu, "silhouette edges", EDGE_BYTES * chunk_capacity, wgpu::BufferUsages::COPY_SRC),
            footprints: storage(gpu, "wedge footprints", FOOTPRINT_BYTES * footprints, wgpu::BufferUsages::COPY_SRC),
            hull_points: storage(gpu, "wedge hull points", hull_points, wgpu::BufferUsages::empty()),
            polygon_scratch: storage(
                gpu,
                "wedge footprint scratch",
                FOOTPRINT_BYTES * footprints,
                wgpu::BufferUsages::empty(),
            ),
            chunks,
            bases,
        })
    }
}

/// What the mesh's buffers are sized by ([`crate::WedgeSettings`]' knobs).
#[derive(Clone, Copy, Debug)]
pub(crate) struct BuildSizes {
    pub(crate) edges_per_footprint: u32,
    pub(crate) chunk_bytes: Option<u64>,
}

/// The bind groups of one light's build: per chunk, its marking classify and its four
/// dispatches; the footprints' (the same scratch for every chunk).
#[derive(Clone)]
pub(crate) struct BuildBinds {
    pub(crate) chunks: Vec<ChunkBinds>,
    pub(crate) footprint: wgpu::BindGroup,
}

/// A chunk's bind groups: classify marking its faces only, then classify, mark, scan, emit.
#[derive(Clone)]
pub(crate) struct ChunkBinds {
    pub(crate) mark_only: wgpu::BindGroup,
    pub(crate) stages: [wgpu::BindGroup; 4],
}

/// What the build bound for one light: its uniform and its casters' parameters.
pub(crate) struct LightBuild<'a> {
    pub(crate) uniform: &'a wgpu::Buffer,
    pub(crate) casters: &'a wgpu::Buffer,
}

fn counts_ring(gpu: &Gpu, mesh: &Result<MeshBuffers, GpuError>) -> wgpu::Buffer {
    let chunks = mesh.as_ref().map_or(1, |m| m.chunks.len().max(1)) as u64;
    gpu.create_buffer(&wgpu::BufferDescriptor {
        label: Some("wedge counts"),
        size: 4 * ARG_WORDS * u64::from(COUNT_SLOTS) * chunks,
        usage: wgpu::BufferUsages::COPY_DST | wgpu::BufferUsages::COPY_SRC,
        mapped_at_creation: false,
    })
}

impl GpuBuilder {
    pub(crate) fn new(gpu: &Gpu, casters: &Casters, sizes: BuildSizes, library: &[(&str, &str)]) -> Self {
        let module = gpu::shader::module(&gpu.device, "wedge build", include_str!("../shaders/build.wgsl"), library);
        let pipeline = |entry: &str| {
            gpu.compute_pipeline(&wgpu::ComputePipelineDescriptor {
                label: Some(entry),
                layout: None,
                module: &module,
                entry_point: Some(entry),
                compilation_options: Default::default(),
                cache: None,
            })
        };
        let mesh = MeshBuffers::new(gpu, casters, sizes);
        Self {
            classify: pipeline("classify"),
            mark: pipeline("mark"),
            scan: pipeline("scan"),
            emit: pipeline("emit"),
            footprint: pipeline("footprint"),
            counts: counts_ring(gpu, &mesh),
            mesh,
            next_slot: std::cell::Cell::new(0),
        }
    }

    /// Caster `object` moved: with `same_triangles` (its welded triangles and vertex count are
    /// the ones the buffers were made with) its positions are written; otherwise the buffers
    /// are made again.
    pub(crate) fn update(
        &mut self,
        gpu: &Gpu,
        casters: &Casters,
        object: usize,
        same_triangles: bool,
        sizes: BuildSizes,
    ) {
        if same_triangles
            && let Ok(mesh) = &self.mesh
            && let Some(&base) = mesh.bases.get(object)
        {
            let data = caster_positions(object, &casters.casters[object]);
            if !data.is_empty() {
                mesh.placement.write_vertices(gpu, &mesh.positions, u64::from(base) * 16, bytemuck::cast_slice(&data));
            }
            return;
        }
        self.mesh = MeshBuffers::new(gpu, casters, sizes);
        // the ring holds a row per chunk and light
        self.counts = counts_ring(gpu, &self.mesh);
        self.next_slot.set(0);
    }

    /// Caster `object`'s transform: written for the placement (a mesh that could not be
    /// built has nothing to place).
    pub(crate) fn set_transform(
        &mut self,
        gpu: &Gpu,
        object: usize,
        transform: glam::Affine3A,
    ) -> Result<(), GpuError> {
        match &mut self.mesh {
            Ok(mesh) => mesh.placement.set(gpu, &mesh.positions, object, transform),
            Err(_) => Ok(()),
        }
    }

    /// Bind groups of one light's dispatches, chunk by chunk.
    pub(crate) fn bind_groups(&self, gpu: &Gpu, mesh: &MeshBuffers, light: &LightBuild<'_>) -> BuildBinds {
        let shared: [(u32, &wgpu::Buffer); 16] = [
            (0, light.uniform),
            (1, light.casters),
            (2, &mesh.positions),
            (3, &mesh.faces),
            (4, &mesh.edges),
            (5, &mesh.edge_faces),
            (6, &mesh.lit),
            (7, &mesh.marks),
            (8, &mesh.blocks),
            (9, &mesh.args),
            (10, &mesh.volume),
            (11, &mesh.silhouette),
            (12, &mesh.footprints),
            (13, &mesh.footprint_dispatch),
            (14, &mesh.hull_points),
            (15, &mesh.polygon_scratch),
        ];
        // the bindings each entry point uses (auto layouts hold only those)
        let group = |pipeline: &wgpu::ComputePipeline, used: &[u32], chunk: Option<&wgpu::Buffer>| {
            let entries: Vec<wgpu::BindGroupEntry<'_>> = shared
                .iter()
                .copied()
                .chain(chunk.map(|c| (16, c)))
                .filter(|(b, _)| used.contains(b))
                .map(|(b, buf)| wgpu::BindGroupEntry { binding: b, resource: buf.as_entire_binding() })
                .collect();
            gpu.create_bind_group(&wgpu::BindGroupDescriptor {
                label: Some("wedge build"),
                layout: &pipeline.get_bind_group_layout(0),
                entries: &entries,
            })
        };
        const CLASSIFY: &[u32] = &[0, 1, 2, 3, 6, 9, 10, 16];
        let chunks = mesh
            .chunks
            .iter()
            .map(|c| ChunkBinds {
                mark_only: group(&self.classify, CLASSIFY, Some(&c.mark_only)),
                stages: [
                    group(&self.classify, CLASSIFY, Some(&c.build)),
                    group(&self.mark, &[2, 3, 4, 5, 6, 7, 8, 16], Some(&c.build)),
                    group(&self.scan, &[0, 8, 9, 13, 16], Some(&c.build)),
                    group(&self.emit, &[0, 1, 2, 7, 8, 9, 10, 11, 16], Some(&c.build)),
                ],
            })
            .collect();
        BuildBinds { chunks, footprint: group(&self.footprint, &[0, 9, 11, 12, 14, 15], None) }
    }

    /// Keeps the counts of the chunk just built (a copy into the next row of the ring).
    pub(crate) fn keep_counts(&self, encoder: &mut wgpu::CommandEncoder, mesh: &MeshBuffers) {
        let slot = self.next_slot.get();
        let rows = COUNT_SLOTS * mesh.chunks.len().max(1) as u32;
        encoder.copy_buffer_to_buffer(
            &mesh.args,
            0,
            &self.counts,
            u64::from(slot % rows) * 4 * ARG_WORDS,
            4 * ARG_WORDS,
        );
        self.next_slot.set(slot.wrapping_add(1));
    }

    /// The counts of the last `lights` lights recorded, oldest first, each build.wgsl's `args`
    /// words summed over the light's chunks (the draws' constant words are the last chunk's;
    /// measurement: a copy and a wait). Starts the ring anew.
    pub(crate) fn read_counts(&self, gpu: &Gpu, lights: usize) -> Result<Vec<[u32; 16]>, GpuError> {
        let chunks = self.mesh.as_ref().map_or(1, |m| m.chunks.len().max(1)) as u32;
        let bytes = gpu::read_buffer(gpu, &self.counts)?;
        let words: Vec<u32> = bytemuck::pod_collect_to_vec(&bytes);
        let end = self.next_slot.get();
        let n = (lights as u32).min(end / chunks).min(COUNT_SLOTS);
        let rows = COUNT_SLOTS * chunks;
        self.next_slot.set(0);
        Ok((0..n)
            .map(|l| {
                let mut w = [0u32; 16];
                for c in 0..chunks {
                    let s = end - (n - l) * chunks + c;
                    let at = (s % rows) as usize * ARG_WORDS as usize;
                    for (k, v) in words[at..at + ARG_WORDS as usize].iter().enumerate() {
                        // counts add up; the draws' vertex counts and first words do not
                        w[k] = if matches!(k, 0 | 5 | 12..=15) { w[k] + v } else { *v };
                    }
                }
                w
            })
            .collect())
    }
}

#[cfg(test)]
mod tests {
    use super::{ChunkRange, chunk_bytes, hilbert, plan_chunks};
    use glam::Vec3;

    /// Chunks cover every face and every edge once, in order, each within the byte limit and
    /// the dispatch limit, for random sheets and closed meshes and limits from a few edges to
    /// everything; a mesh that fits is one chunk.
    #[test]
    fn chunks_partition_faces_and_edges_within_the_limits() {
        let mut state = 0x2545_f491_4f6c_dd1du64;
        let mut next = |n: u64| {
            state ^= state << 13;
            state ^= state >> 7;
            state ^= state << 17;
            state % n
        };
        for _ in 0..200 {
            let edges = next(5000) as usize;
            let faces = next(4000) as u32;
            let capacities: Vec<u32> = (0..edges).map(|_| 1 + next(3) as u32).collect();
            let group = 1 + next(64) as u32;
            let limit = 8 * 18 * 64 * (1 + next(40));
            let max_groups = 1 + next(100);
            let chunks = match plan_chunks(faces, &capacities, group, limit, max_groups) {
                Ok(c) => c,
                Err(e) => panic!("{faces} faces, {edges} edges, limit {limit}: {e}"),
            };
            let (mut face, mut edge) = (0u32, 0u32);
            for c in &chunks {
                assert_eq!(c.faces.0, face, "faces in order");
                assert_eq!(c.edges.0, edge.min(edges as u32), "edges in order");
                face += c.faces.1;
                edge += c.edges.1;
                let cap: u32 = capacities[c.edges.0 as usize..(c.edges.0 + c.edges.1) as usize].iter().sum();
                assert_eq!(c.capacity, cap);
                let bytes = chunk_bytes(c.faces.1.into(), c.edges.1.into(), c.capacity.into(), group.into());
                for (what, b) in bytes {
                    assert!(b <= limit, "{what}: {b} > {limit}");
                }
                let items = max_groups * 256;
                assert!(u64::from(c.faces.1) <= items && u64::from(c.edges.1) <= items);
            }
            assert_eq!((face, edge), (faces, edges as u32), "everything once");
            let everything = plan_chunks(faces, &capacities, group, u64::MAX / 1024, 1 << 20).unwrap();
            let total = capacities.iter().sum();
            assert_eq!(everything, vec![ChunkRange { faces: (0, faces), edges: (0, edges as u32), capacity: total }]);
        }
        // one edge larger than a buffer: refused, not looped on
        assert!(plan_chunks(10, &[100_000], 8, 8 * 18 * 64, 100).is_err());
    }

    /// On a 2^k grid, consecutive cells along the curve are face neighbours: every index
    /// once, each step one cell along one axis.
    #[test]
    fn hilbert_order_visits_every_cell_by_unit_steps() {
        let n = 8u32;
        let cell = |i: u32| (i as f32 + 0.5) / n as f32 * 2.0 - 1.0;
        let mut cells: Vec<(u64, [i32; 3])> = Vec::new();
        for x in 0..n {
            for y in 0..n {
                for z in 0..n {
                    let p = Vec3::new(cell(x), cell(y), cell(z));
                    cells.push((hilbert(p, Vec3::ZERO, 1.0), [x as i32, y as i32, z as i32]));
                }
            }
        }
        cells.sort_unstable();
        cells.dedup_by_key(|c| c.0);
        assert_eq!(cells.len(), (n * n * n) as usize, "distinct indices");
        for w in cells.windows(2) {
            let d: i32 = (0..3).map(|k| (w[0].1[k] - w[1].1[k]).abs()).sum();
            assert_eq!(d, 1, "{:?} to {:?}", w[0].1, w[1].1);
        }
    }
}
