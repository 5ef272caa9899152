//! Per-object transforms, applied on the GPU: geometry is uploaded in object space and a moved
//! object changes one transform (`queue.write_buffer`, 128 bytes), not its vertices. A compute
//! pass (`crates/gpu/shaders/place.wgsl`), recorded into the frame's encoder before the geometry is
//! drawn, writes every vertex's world position (and normals) from a copy of the uploaded ones.
//!
//! Only a scene that moves pays for it: the copy and the transform table are made at the first
//! transform that is not the identity, and the pass runs only in frames after a change.
//! [`SceneGeometry`](crate::SceneGeometry), [`ShadowGeometry`](crate::ShadowGeometry) and the
//! wedges' casters (`penumbra-wedge`) place their vertices through it.

use crate::context::{Gpu, GpuError};
use glam::{Affine3A, Mat3, Vec3};
use std::cell::Cell;

/// An object's transform as `place.wgsl` reads it.
#[repr(C)]
#[derive(Clone, Copy, bytemuck::Pod, bytemuck::Zeroable)]
struct GpuTransform {
    model: [[f32; 4]; 4],
    normal: [[f32; 4]; 3],
    flags: [u32; 4],
}

impl GpuTransform {
    fn new(t: &Affine3A) -> Self {
        let linear = Mat3::from(t.matrix3);
        let n = scene::normal_matrix(linear);
        Self {
            model: glam::Mat4::from(*t).to_cols_array_2d(),
            normal: [n.x_axis, n.y_axis, n.z_axis].map(|c| c.extend(0.0).to_array()),
            flags: [u32::from(linear != Mat3::IDENTITY), 0, 0, 0],
        }
    }
}

/// Why `transform` cannot place an object: a non-finite entry.
fn check(transform: &Affine3A, object: usize) -> Result<(), GpuError> {
    if transform.is_finite() {
        Ok(())
    } else {
        Err(GpuError::Failed(format!("transform of object {object} is not finite: {transform:?}")))
    }
}

/// The largest factor by which `linear` stretches a vector, bounded from above: the square root
/// of Gershgorin's bound on the largest eigenvalue of `linearᵀ·linear`, exact for rotations and
/// uniform scales, a little more for shears.
#[must_use]
pub fn stretch_bound(linear: Mat3) -> f32 {
    if linear == Mat3::IDENTITY {
        return 1.0;
    }
    let g = linear.transpose() * linear;
    let rows = [g.row(0), g.row(1), g.row(2)].map(|r| r.abs().element_sum());
    // a relative margin for the rounding of the products above
    rows.into_iter().fold(0.0, f32::max).sqrt() * (1.0 + 1e-6)
}

/// A bounding sphere of `sphere` (centre, radius) moved by `t`: exactly `sphere` for the
/// identity.
#[must_use]
pub fn transform_sphere(t: &Affine3A, sphere: (Vec3, f32)) -> (Vec3, f32) {
    if *t == Affine3A::IDENTITY {
        return sphere;
    }
    let linear = Mat3::from(t.matrix3);
    let c = t.transform_point3(sphere.0);
    (c, sphere.1 * stretch_bound(linear) + 1e-6 * c.abs().max_element())
}

/// An axis-aligned box holding the box `(lo, hi)` moved by `t` (its centre moved, its half
/// extent by the absolute matrix): exactly the box for the identity; an empty box stays empty.
#[must_use]
pub fn transform_box(t: &Affine3A, (lo, hi): (Vec3, Vec3)) -> (Vec3, Vec3) {
    if *t == Affine3A::IDENTITY || !lo.is_finite() || !hi.is_finite() {
        return (lo, hi);
    }
    let m = Mat3::from(t.matrix3);
    let c = t.transform_point3(0.5 * (lo + hi));
    let abs = Mat3::from_cols(m.x_axis.abs(), m.y_axis.abs(), m.z_axis.abs());
    let e = abs * (0.5 * (hi - lo));
    // a relative margin for the rounding of the centre and extent
    let slack = Vec3::splat(1e-6 * (c.abs() + e).max_element());
    (c - e - slack, c + e + slack)
}

/// What `place.wgsl` reads beside the transforms.
#[repr(C)]
#[derive(Clone, Copy, bytemuck::Pod, bytemuck::Zeroable)]
struct Params {
    count: u32,
    stride: u32,
    normals: u32,
    object_word: u32,
    row: u32,
    objects: u32,
    pad: [u32; 2],
}

/// The buffers of a placement that is used: the uploaded vertices' copy and the transforms.
struct Buffers {
    local: wgpu::Buffer,
    table: wgpu::Buffer,
    bind: wgpu::BindGroup,
    // whether the copy of the uploaded vertices has been recorded
    copied: Cell<bool>,
}

/// How a geometry's vertices lie in its buffer, for [`Placement::new`].
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct VertexWords {
    /// Vertices in the buffer.
    pub count: u32,
    /// 32-bit words a vertex.
    pub stride: u32,
    /// vec3 normals after the position (words 3..6, 6..9, ...).
    pub normals: u32,
    /// The word holding the vertex's object index (a `u32`).
    pub object_word: u32,
}

/// Per-object transforms of one geometry's vertex buffer (its *world* buffer, made with
/// `STORAGE | COPY_SRC` usage and the object-space vertices).
pub struct Placement {
    words: VertexWords,
    transforms: Vec<Affine3A>,
    buffers: Option<Buffers>,
    pending: Cell<bool>,
}

impl Placement {
    /// The placement of `objects` objects' vertices laid out as `words`, every transform the
    /// identity. The pass's pipeline is made with the device's first placement (once per
    /// device, when geometry is uploaded: never inside a frame); its buffers wait for the first
    /// transform that is not the identity.
    ///
    /// # Errors
    /// [`GpuError::TooLarge`] for a layout whose words do not fit its stride.
    pub fn new(gpu: &Gpu, words: VertexWords, objects: usize) -> Result<Self, GpuError> {
        let needed = (3 + 3 * words.normals).max(words.object_word + 1);
        if words.stride < needed {
            return Err(GpuError::TooLarge {
                what: "vertex words placed",
                size: needed.into(),
                limit: words.stride.into(),
            });
        }
        Self::pipeline(gpu);
        Ok(Self { words, transforms: vec![Affine3A::IDENTITY; objects], buffers: None, pending: Cell::new(false) })
    }

    /// The pass's pipeline, made once per device.
    fn pipeline(gpu: &Gpu) -> &wgpu::ComputePipeline {
        gpu.place.get_or_init(|| {
            let module = crate::shader::module(&gpu.device, "place", include_str!("../shaders/place.wgsl"), &[]);
            gpu.compute_pipeline(&wgpu::ComputePipelineDescriptor {
                label: Some("place"),
                layout: None,
                module: &module,
                entry_point: Some("main"),
                compilation_options: Default::default(),
                cache: None,
            })
        })
    }

    /// Object `object`'s transform (object space to world).
    #[must_use]
    pub fn transform(&self, object: usize) -> Affine3A {
        self.transforms.get(object).copied().unwrap_or(Affine3A::IDENTITY)
    }

    /// Whether any object has been given a transform other than the identity.
    #[must_use]
    pub fn in_use(&self) -> bool {
        self.buffers.is_some()
    }

    /// Sets object `object`'s transform: written with `queue.write_buffer`; the vertices move
    /// when [`Placement::record`] runs in the next encoder that draws them. `world` is the
    /// geometry's vertex buffer (its copy is made the first time).
    ///
    /// # Errors
    /// [`GpuError::Failed`] for an object out of range or a non-finite transform;
    /// [`GpuError::TooLarge`] for a buffer past the device's storage binding size.
    pub fn set(&mut self, gpu: &Gpu, world: &wgpu::Buffer, object: usize, transform: Affine3A) -> Result<(), GpuError> {
        check(&transform, object)?;
        let Some(slot) = self.transforms.get_mut(object) else {
            return Err(GpuError::Failed(format!("placement: no object {object} of {}", self.transforms.len())));
        };
        if *slot == transform {
            return Ok(());
        }
        *slot = transform;
        if self.buffers.is_none() {
            if transform == Affine3A::IDENTITY {
                return Ok(());
            }
            self.buffers = Some(self.make_buffers(gpu, world)?);
        }
        if let Some(b) = &self.buffers {
            let row = GpuTransform::new(&transform);
            gpu.queue.write_buffer(&b.table, object as u64 * 128, bytemuck::bytes_of(&row));
        }
        self.pending.set(true);
        Ok(())
    }

    fn make_buffers(&self, gpu: &Gpu, world: &wgpu::Buffer) -> Result<Buffers, GpuError> {
        let limit = gpu.limits.max_storage_buffer_binding_size;
        if world.size() > limit {
            return Err(GpuError::TooLarge { what: "vertex bytes placed on the GPU", size: world.size(), limit });
        }
        let local = gpu.create_buffer(&wgpu::BufferDescriptor {
            label: Some("placed vertices, object space"),
            size: world.size(),
            usage: wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });
        let rows: Vec<GpuTransform> = self.transforms.iter().map(GpuTransform::new).collect();
        let rows = if rows.is_empty() { vec![GpuTransform::new(&Affine3A::IDENTITY)] } else { rows };
        let table = gpu.create_buffer_init(&wgpu::util::BufferInitDescriptor {
            label: Some("object transforms"),
            contents: bytemuck::cast_slice(&rows),
            usage: wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_DST,
        });
        let (x, _) = self.grid();
        let w = self.words;
        let params = Params {
            count: w.count,
            stride: w.stride,
            normals: w.normals,
            object_word: w.object_word,
            row: x * 64,
            objects: self.transforms.len() as u32,
            pad: [0; 2],
        };
        let params = gpu.create_buffer_init(&wgpu::util::BufferInitDescriptor {
            label: Some("place params"),
            contents: bytemuck::bytes_of(&params),
            usage: wgpu::BufferUsages::UNIFORM,
        });
        let bind = gpu.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("place"),
            layout: &Self::pipeline(gpu).get_bind_group_layout(0),
            entries: &[
                wgpu::BindGroupEntry { binding: 0, resource: params.as_entire_binding() },
                wgpu::BindGroupEntry { binding: 1, resource: table.as_entire_binding() },
                wgpu::BindGroupEntry { binding: 2, resource: local.as_entire_binding() },
                wgpu::BindGroupEntry { binding: 3, resource: world.as_entire_binding() },
            ],
        });
        Ok(Buffers { local, table, bind, copied: Cell::new(false) })
    }

    /// Workgroups (x, y) covering every vertex, 64 a workgroup.
    fn grid(&self) -> (u32, u32) {
        let groups = self.words.count.div_ceil(64).max(1);
        let x = groups.min(65_535);
        (x, groups.div_ceil(x))
    }

    /// Writes `bytes` at `offset` of the uploaded vertices (a deformed object, same layout):
    /// into `world`, and into the copy the transforms apply to once there is one.
    pub fn write_vertices(&self, gpu: &Gpu, world: &wgpu::Buffer, offset: u64, bytes: &[u8]) {
        gpu.queue.write_buffer(world, offset, bytes);
        if let Some(b) = &self.buffers {
            // before the copy is recorded it copies `world`, written above in the same order
            gpu.queue.write_buffer(&b.local, offset, bytes);
            self.pending.set(true);
        }
    }

    /// Records the placement of every vertex of `world` into `encoder` when a transform (or a
    /// vertex) changed since the last one recorded; nothing otherwise. Call it before the
    /// passes that read `world`, and submit the encoder.
    pub fn record(&self, gpu: &Gpu, encoder: &mut wgpu::CommandEncoder, world: &wgpu::Buffer) {
        let Some(b) = self.buffers.as_ref().filter(|_| self.pending.get()) else { return };
        if !b.copied.get() {
            encoder.copy_buffer_to_buffer(world, 0, &b.local, 0, world.size());
            b.copied.set(true);
        }
        let mut pass =
            encoder.begin_compute_pass(&wgpu::ComputePassDescriptor { label: Some("place"), timestamp_writes: None });
        pass.set_pipeline(Self::pipeline(gpu));
        pass.set_bind_group(0, &b.bind, &[]);
        let (x, y) = self.grid();
        pass.dispatch_workgroups(x, y, 1);
        self.pending.set(false);
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::Quat;

    #[test]
    fn moved_bounds_hold_every_moved_point() {
        let t = Affine3A::from_scale_rotation_translation(
            Vec3::new(2.0, 0.5, 1.5),
            Quat::from_euler(glam::EulerRot::XYZ, 0.3, -1.1, 2.0),
            Vec3::new(1e3, -4.0, 0.25),
        );
        let shear = Affine3A::from_mat3(Mat3::from_cols(Vec3::X, Vec3::new(3.0, 1.0, 0.0), Vec3::Z));
        let (lo, hi) = (Vec3::new(-1.0, 0.0, 2.0), Vec3::new(3.0, 0.5, 2.5));
        let (c, r) = (0.5 * (lo + hi), 0.5 * (hi - lo).length());
        for t in [t, shear, Affine3A::IDENTITY] {
            let (blo, bhi) = transform_box(&t, (lo, hi));
            let (sc, sr) = transform_sphere(&t, (c, r));
            for k in 0..512 {
                let f = Vec3::new((k % 8) as f32 / 7.0, ((k / 8) % 8) as f32 / 7.0, (k / 64) as f32 / 7.0);
                let p = t.transform_point3(lo + f * (hi - lo));
                assert!(p.cmpge(blo).all() && p.cmple(bhi).all(), "{p} outside {blo}..{bhi}");
                let q = t.transform_point3(c + (lo + f * (hi - lo) - c).clamp_length_max(r));
                assert!(q.distance(sc) <= sr, "{q} outside the sphere {sc}, {sr}");
            }
        }
        assert_eq!(transform_box(&Affine3A::IDENTITY, (lo, hi)), (lo, hi));
        assert_eq!(transform_sphere(&Affine3A::IDENTITY, (c, r)), (c, r));
        let rot = Affine3A::from_quat(Quat::from_rotation_y(0.7));
        assert!((stretch_bound(Mat3::from(rot.matrix3)) - 1.0).abs() < 1e-5, "a rotation stretches nothing");
    }
}
