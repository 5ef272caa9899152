//! The wedges' geometry built on the GPU for every light (`crates/penumbra-wedge/shaders/build.wgsl`):
//! the casters' welded faces and their edges with adjacency live in buffers made once per scene;
//! per light, five compute dispatches classify the faces, count each edge's lit faces, compact
//! the silhouette in edge order, append the hard volume and bound each wedge's footprint. The
//! volume and the footprints are drawn indirectly from what the GPU wrote: the CPU records a
//! light without knowing its silhouette. [`crate::Wedges::plan`] is the same construction on
//! the CPU, the reference this one is tested against.
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

/// The casters as the builder reads them, and its scratch, sized for them.
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
    pub(crate) face_count: u32,
    pub(crate) edge_count: u32,
    capacity: u32,
    // per caster, its first welded vertex in `positions`
    bases: Vec<u32>,
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

    fn new(gpu: &Gpu, casters: &Casters, edges_per_footprint: u32) -> Result<Self, GpuError> {
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
        let mut capacity = 0u64;
        for (lo, hi, list) in order.iter().map(|(_, _, (lo, hi))| (lo, hi, &adjacency[&(*lo, *hi)])) {
            let caster = faces[list[0] as usize][3] as usize;
            let closed = casters.casters[caster].closed;
            // a closed caster's edge is on the silhouette at most once, a sheet's at most once
            // a face
            capacity += if closed { 1 } else { list.len() as u64 };
            edges.push([*lo, *hi, edge_faces.len() as u32, list.len() as u32]);
            edge_faces.extend(list);
        }
        let limits = &gpu.limits;
        let groups = u64::from(limits.max_compute_workgroups_per_dimension);
        let max_items = groups * u64::from(BLOCK);
        for (what, n) in [("caster faces", faces.len() as u64), ("caster edges", edges.len() as u64)] {
            if n > max_items {
                return Err(GpuError::TooLarge { what, size: n, limit: max_items });
            }
        }
        let volume_bytes = 12 * 6 * (faces.len() as u64 + capacity);
        let group = u64::from(group_size(edges_per_footprint));
        let footprints = capacity.div_ceil(group);
        let hull_points = 8 * 18 * group * footprints;
        let binding = limits.max_storage_buffer_binding_size.min(limits.max_buffer_size);
        for (what, bytes) in [
            ("wedge volume bytes", volume_bytes),
            ("wedge silhouette bytes", EDGE_BYTES * capacity),
            ("wedge footprint bytes", FOOTPRINT_BYTES * footprints),
            ("wedge hull point bytes", hull_points),
            ("wedge edge marks bytes", MARK_BYTES * edges.len() as u64),
        ] {
            if bytes > binding {
                return Err(GpuError::TooLarge { what, size: bytes, limit: binding });
            }
        }
        if footprints.div_ceil(u64::from(FOOTPRINT_GROUP)) > groups {
            return Err(GpuError::TooLarge {
                what: "wedge footprints",
                size: footprints,
                limit: groups * u64::from(FOOTPRINT_GROUP),
            });
        }
        let init = |label, contents: &[u8], usage| {
            let contents = if contents.is_empty() { &[0u8; 16][..] } else { contents };
            gpu.create_buffer_init(&wgpu::util::BufferInitDescriptor { label: Some(label), contents, usage })
        };
        let read = wgpu::BufferUsages::STORAGE;
        let blocks = (edges.len() as u64).div_ceil(u64::from(BLOCK));
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
            marks: storage(gpu, "edge marks", MARK_BYTES * edges.len() as u64, wgpu::BufferUsages::empty()),
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
            silhouette: storage(gpu, "silhouette edges", EDGE_BYTES * capacity, wgpu::BufferUsages::COPY_SRC),
            footprints: storage(gpu, "wedge footprints", FOOTPRINT_BYTES * footprints, wgpu::BufferUsages::COPY_SRC),
            hull_points: storage(gpu, "wedge hull points", hull_points, wgpu::BufferUsages::empty()),
            polygon_scratch: storage(
                gpu,
                "wedge footprint scratch",
                FOOTPRINT_BYTES * footprints,
                wgpu::BufferUsages::empty(),
            ),
            face_count: faces.len() as u32,
            edge_count: edges.len() as u32,
            capacity: capacity as u32,
            bases,
        })
    }
}

/// What the build bound for one light: its uniform and its casters' parameters.
pub(crate) struct LightBuild<'a> {
    pub(crate) uniform: &'a wgpu::Buffer,
    pub(crate) casters: &'a wgpu::Buffer,
}

impl GpuBuilder {
    pub(crate) fn new(gpu: &Gpu, casters: &Casters, edges_per_footprint: u32, library: &[(&str, &str)]) -> Self {
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
        Self {
            classify: pipeline("classify"),
            mark: pipeline("mark"),
            scan: pipeline("scan"),
            emit: pipeline("emit"),
            footprint: pipeline("footprint"),
            mesh: MeshBuffers::new(gpu, casters, edges_per_footprint),
            counts: gpu.create_buffer(&wgpu::BufferDescriptor {
                label: Some("wedge counts"),
                size: 4 * ARG_WORDS * u64::from(COUNT_SLOTS),
                usage: wgpu::BufferUsages::COPY_DST | wgpu::BufferUsages::COPY_SRC,
                mapped_at_creation: false,
            }),
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
        edges_per_footprint: u32,
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
        self.mesh = MeshBuffers::new(gpu, casters, edges_per_footprint);
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

    /// Bind groups of the five dispatches for one light.
    pub(crate) fn bind_groups(&self, gpu: &Gpu, mesh: &MeshBuffers, light: &LightBuild<'_>) -> [wgpu::BindGroup; 5] {
        let all: [(u32, &wgpu::Buffer); 16] = [
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
        let group = |pipeline: &wgpu::ComputePipeline, used: &[u32]| {
            let entries: Vec<wgpu::BindGroupEntry<'_>> = all
                .iter()
                .filter(|(b, _)| used.contains(b))
                .map(|(b, buf)| wgpu::BindGroupEntry { binding: *b, resource: buf.as_entire_binding() })
                .collect();
            gpu.create_bind_group(&wgpu::BindGroupDescriptor {
                label: Some("wedge build"),
                layout: &pipeline.get_bind_group_layout(0),
                entries: &entries,
            })
        };
        [
            group(&self.classify, &[0, 1, 2, 3, 6, 9, 10]),
            group(&self.mark, &[0, 2, 3, 4, 5, 6, 7, 8]),
            group(&self.scan, &[0, 8, 9, 13]),
            group(&self.emit, &[0, 1, 2, 7, 8, 9, 10, 11]),
            group(&self.footprint, &[0, 9, 11, 12, 14, 15]),
        ]
    }

    /// The uniform's counts row: faces, edges, edge blocks, silhouette capacity.
    pub(crate) fn counts_row(mesh: &MeshBuffers) -> [u32; 4] {
        [mesh.face_count, mesh.edge_count, mesh.edge_count.div_ceil(BLOCK), mesh.capacity]
    }

    /// Keeps this light's counts (a copy into the next slot of the ring).
    pub(crate) fn keep_counts(&self, encoder: &mut wgpu::CommandEncoder, mesh: &MeshBuffers) {
        let slot = self.next_slot.get();
        encoder.copy_buffer_to_buffer(
            &mesh.args,
            0,
            &self.counts,
            u64::from(slot % COUNT_SLOTS) * 4 * ARG_WORDS,
            4 * ARG_WORDS,
        );
        self.next_slot.set(slot.wrapping_add(1));
    }

    /// The counts of the last `lights` lights recorded, oldest first, each build.wgsl's `args`
    /// words (measurement: a copy and a wait). Starts the ring anew.
    pub(crate) fn read_counts(&self, gpu: &Gpu, lights: usize) -> Result<Vec<[u32; 16]>, GpuError> {
        let bytes = gpu::read_buffer(gpu, &self.counts)?;
        let words: Vec<u32> = bytemuck::pod_collect_to_vec(&bytes);
        let end = self.next_slot.get();
        let n = (lights as u32).min(end).min(COUNT_SLOTS);
        self.next_slot.set(0);
        Ok((end - n..end)
            .map(|s| {
                let at = (s % COUNT_SLOTS) as usize * ARG_WORDS as usize;
                let mut w = [0u32; 16];
                w.copy_from_slice(&words[at..at + ARG_WORDS as usize]);
                w
            })
            .collect())
    }
}

#[cfg(test)]
mod tests {
    use super::hilbert;
    use glam::Vec3;

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
