//! Scene geometry on the GPU: shaded vertices for the G-buffer, and position-only triangle soup
//! in spatially coherent chunks (with bounding spheres) for shadow passes that cull per view.

use crate::context::{Gpu, GpuError};
use glam::Vec3;
use wgpu::util::DeviceExt;

/// G-buffer vertex: position, shading normal, geometric normal, object index.
#[repr(C)]
#[derive(Clone, Copy, bytemuck::Pod, bytemuck::Zeroable)]
struct ShadedVertex {
    position: [f32; 3],
    normal: [f32; 3],
    geometric_normal: [f32; 3],
    object: u32,
}

/// Material as the shaders read it (`shaders/gpu/brdf.wgsl`).
#[repr(C)]
#[derive(Clone, Copy, bytemuck::Pod, bytemuck::Zeroable)]
pub(crate) struct GpuMaterial {
    albedo: [f32; 4],
    f0_roughness: [f32; 4],
}

impl GpuMaterial {
    fn new(m: &scene::Material) -> Self {
        let (has, f0, r) = m.specular.map_or((0.0, Vec3::ZERO, 1.0), |g| (1.0, g.f0, g.roughness));
        Self { albedo: [m.albedo.x, m.albedo.y, m.albedo.z, has], f0_roughness: [f0.x, f0.y, f0.z, r] }
    }
}

/// A scene's triangles as the G-buffer pass draws them.
pub struct SceneGeometry {
    pub(crate) vertices: wgpu::Buffer,
    pub(crate) vertex_count: u32,
    pub(crate) materials: wgpu::Buffer,
    /// Axis-aligned bounds of the scene.
    pub bounds: (Vec3, Vec3),
}

/// Largest vertex count we upload (16 M triangles): refused before allocating.
const MAX_VERTICES: u64 = 48 << 20;

fn check_count(gpu: &Gpu, vertices: usize, stride: u64) -> Result<(), GpuError> {
    let size = vertices as u64 * stride;
    let limit = gpu.limits.max_buffer_size.min(MAX_VERTICES * stride);
    if size > limit {
        return Err(GpuError::TooLarge { what: "vertex buffer bytes", size, limit });
    }
    Ok(())
}

impl SceneGeometry {
    /// Uploads every object of `scene`, flat or smooth as its mesh says.
    ///
    /// # Errors
    /// [`GpuError::TooLarge`] for scenes beyond the buffer limits.
    pub fn upload(gpu: &Gpu, scene: &scene::Scene) -> Result<Self, GpuError> {
        let count: usize = scene.objects.iter().map(|o| o.mesh.indices.len() * 3).sum();
        check_count(gpu, count, std::mem::size_of::<ShadedVertex>() as u64)?;
        let mut vertices = Vec::with_capacity(count);
        let (mut lo, mut hi) = (Vec3::splat(f32::INFINITY), Vec3::splat(f32::NEG_INFINITY));
        for (k, object) in scene.objects.iter().enumerate() {
            let mesh = &object.mesh;
            for (t, tri) in mesh.indices.iter().enumerate() {
                let ng = mesh.geometric_normal(t).normalize_or_zero();
                for &i in tri {
                    let p = mesh.positions[i as usize];
                    lo = lo.min(p);
                    hi = hi.max(p);
                    let n = mesh.normals.as_ref().map_or(ng, |n| n[i as usize]);
                    vertices.push(ShadedVertex {
                        position: p.to_array(),
                        normal: n.to_array(),
                        geometric_normal: ng.to_array(),
                        object: k as u32,
                    });
                }
            }
        }
        let mut materials: Vec<GpuMaterial> = scene.objects.iter().map(|o| GpuMaterial::new(&o.material)).collect();
        if materials.is_empty() {
            // storage bindings may not be empty
            materials.push(GpuMaterial::new(&scene::Material::lambert(0.0)));
        }
        let vertices_buf = gpu.device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
            label: Some("scene vertices"),
            contents: bytemuck::cast_slice(&vertices),
            usage: wgpu::BufferUsages::VERTEX,
        });
        let materials_buf = gpu.device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
            label: Some("materials"),
            contents: bytemuck::cast_slice(&materials),
            usage: wgpu::BufferUsages::STORAGE,
        });
        Ok(Self {
            vertices: vertices_buf,
            vertex_count: vertices.len() as u32,
            materials: materials_buf,
            bounds: (lo, hi),
        })
    }

    pub(crate) const LAYOUT: wgpu::VertexBufferLayout<'static> = wgpu::VertexBufferLayout {
        array_stride: std::mem::size_of::<ShadedVertex>() as u64,
        step_mode: wgpu::VertexStepMode::Vertex,
        attributes: &wgpu::vertex_attr_array![0 => Float32x3, 1 => Float32x3, 2 => Float32x3, 3 => Uint32],
    };
}

/// A run of consecutive triangles with its bounding sphere.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Chunk {
    /// First vertex (3 per triangle).
    pub first_vertex: u32,
    /// Vertex count.
    pub vertex_count: u32,
    /// Bounding sphere centre.
    pub center: Vec3,
    /// Bounding sphere radius.
    pub radius: f32,
}

/// Position-only triangle soup for depth passes, in chunks that can be culled per view.
pub struct ShadowGeometry {
    /// Vertex buffer: `[f32; 3]` positions, three per triangle.
    pub vertices: wgpu::Buffer,
    /// The chunks, covering every triangle once.
    pub chunks: Vec<Chunk>,
    /// Triangle count.
    pub triangles: u32,
}

impl ShadowGeometry {
    /// Triangles per chunk by default: small enough to cull walls row by row, large enough that
    /// draw calls stay few.
    pub const CHUNK_TRIANGLES: usize = 16;

    /// Uploads `triangles` (world space) in chunks of `chunk_triangles` consecutive triangles.
    ///
    /// # Errors
    /// [`GpuError::TooLarge`] beyond the buffer limits.
    pub fn upload(gpu: &Gpu, triangles: &[[Vec3; 3]], chunk_triangles: usize) -> Result<Self, GpuError> {
        check_count(gpu, triangles.len() * 3, 12)?;
        let chunks = triangles
            .chunks(chunk_triangles.max(1))
            .enumerate()
            .map(|(k, tris)| {
                let (mut lo, mut hi) = (Vec3::splat(f32::INFINITY), Vec3::splat(f32::NEG_INFINITY));
                for p in tris.iter().flatten() {
                    lo = lo.min(*p);
                    hi = hi.max(*p);
                }
                let center = 0.5 * (lo + hi);
                let radius = tris.iter().flatten().map(|p| p.distance(center)).fold(0.0, f32::max);
                let first = (k * chunk_triangles.max(1) * 3) as u32;
                Chunk { first_vertex: first, vertex_count: (tris.len() * 3) as u32, center, radius }
            })
            .collect();
        let flat: Vec<[f32; 3]> = triangles.iter().flatten().map(|p| p.to_array()).collect();
        let vertices = gpu.device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
            label: Some("shadow vertices"),
            contents: bytemuck::cast_slice(if flat.is_empty() { &[[0.0f32; 3]; 3][..] } else { &flat[..] }),
            usage: wgpu::BufferUsages::VERTEX,
        });
        Ok(Self { vertices, chunks, triangles: triangles.len() as u32 })
    }

    /// Vertex layout: one `vec3<f32>` position at location 0.
    pub const LAYOUT: wgpu::VertexBufferLayout<'static> = wgpu::VertexBufferLayout {
        array_stride: 12,
        step_mode: wgpu::VertexStepMode::Vertex,
        attributes: &wgpu::vertex_attr_array![0 => Float32x3],
    };

    /// Draws the chunks whose index `visible` accepts, merging neighbours into one draw call.
    /// Returns the number of triangles drawn.
    pub fn draw(&self, pass: &mut wgpu::RenderPass<'_>, visible: impl Fn(usize) -> bool) -> u32 {
        pass.set_vertex_buffer(0, self.vertices.slice(..));
        let mut run: Option<(u32, u32)> = None;
        let mut drawn = 0;
        for c in self.chunks.iter().enumerate().filter(|(k, _)| visible(*k)).map(|(_, c)| c) {
            drawn += c.vertex_count / 3;
            run = match run {
                Some((start, end)) if end == c.first_vertex => Some((start, end + c.vertex_count)),
                Some((start, end)) => {
                    pass.draw(start..end, 0..1);
                    Some((c.first_vertex, c.first_vertex + c.vertex_count))
                }
                None => Some((c.first_vertex, c.first_vertex + c.vertex_count)),
            };
        }
        if let Some((start, end)) = run {
            pass.draw(start..end, 0..1);
        }
        drawn
    }
}

/// Every triangle of `scene` in world space, object by object.
#[must_use]
pub fn scene_triangles(scene: &scene::Scene) -> Vec<[Vec3; 3]> {
    scene.objects.iter().flat_map(|o| (0..o.mesh.indices.len()).map(|t| o.mesh.triangle(t))).collect()
}
