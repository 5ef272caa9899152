//! Scene geometry on the GPU: shaded vertices for the G-buffer, and position-only triangle soup
//! in spatially coherent chunks (with bounding spheres) for shadow passes that cull per view.

use crate::context::{Gpu, GpuError};
use crate::placement::{Placement, VertexWords, transform_box};
use glam::{Affine3A, Vec3};

/// G-buffer vertex: position, shading normal, geometric normal, object index.
#[repr(C)]
#[derive(Clone, Copy, bytemuck::Pod, bytemuck::Zeroable)]
struct ShadedVertex {
    position: [f32; 3],
    normal: [f32; 3],
    geometric_normal: [f32; 3],
    object: u32,
}

/// What the G-buffer reads of a vertex beside its position and normals (a second vertex
/// buffer, so the placed one stays within a buffer's default 256 MiB at 2 M triangles):
/// texture coordinates and whether the back face is culled.
#[repr(C)]
#[derive(Clone, Copy, bytemuck::Pod, bytemuck::Zeroable)]
struct SurfaceVertex {
    uv: [f32; 2],
    /// 1: one-sided (back faces culled), 0: double-sided
    cull: u32,
}

/// "No texture" in [`GpuMaterial::maps`].
const NO_TEXTURE: u32 = u32::MAX;

/// Material as the shaders read it (`crates/gpu/shaders/brdf.wgsl`): the uniform material,
/// and where it has [`scene::Maps`] the factors and textures `material_at` resolves it from
/// (`crates/gpu/shaders/shade.wgsl`, as [`scene::Material::at`]).
#[repr(C)]
#[derive(Clone, Copy, bytemuck::Pod, bytemuck::Zeroable)]
pub(crate) struct GpuMaterial {
    albedo: [f32; 4],
    f0_roughness: [f32; 4],
    emission: [f32; 4],
    /// rgb base colour factor, a metallic factor
    base_metallic: [f32; 4],
    /// x roughness factor, y 1 where textured, z 1 where the textured material has no
    /// specular layer (Lambertian base colour)
    pbr: [f32; 4],
    /// base colour, metallic-roughness and emissive texture (`NO_TEXTURE`: none)
    maps: [u32; 4],
}

impl GpuMaterial {
    fn new(m: &scene::Material) -> Self {
        let (has, f0, r) = m.specular.map_or((0.0, Vec3::ZERO, 1.0), |g| (1.0, g.f0, g.roughness));
        let e = m.emission;
        let mut out = Self {
            albedo: [m.albedo.x, m.albedo.y, m.albedo.z, has],
            f0_roughness: [f0.x, f0.y, f0.z, r],
            emission: [e.x, e.y, e.z, 0.0],
            base_metallic: [0.0; 4],
            pbr: [0.0; 4],
            maps: [NO_TEXTURE; 4],
        };
        if let Some(maps) = m.maps {
            let b = maps.base_color;
            out.base_metallic = [b.x, b.y, b.z, maps.metallic];
            out.pbr = [maps.roughness, 1.0, if maps.specular { 0.0 } else { 1.0 }, 0.0];
            let t = |t: Option<u32>| t.unwrap_or(NO_TEXTURE);
            out.maps = [t(maps.base_color_texture), t(maps.metallic_roughness_texture), t(maps.emissive_texture), 0];
            out.emission = [maps.emissive.x, maps.emissive.y, maps.emissive.z, 0.0];
        }
        out
    }
}

/// The scene's textures as one storage buffer of words: per texture a header (first texel's
/// word, width, height, wrap u | wrap v << 2 | nearest << 4), then every texture's RGBA8
/// texels, row by row. Textures are halved until the whole fits `limit` bytes; the count of
/// halvings comes back.
fn texel_words(textures: &[scene::Texture], limit: u64) -> (Vec<u32>, u32) {
    let mut textures: Vec<std::borrow::Cow<scene::Texture>> = textures.iter().map(std::borrow::Cow::Borrowed).collect();
    let bytes = |t: &[std::borrow::Cow<scene::Texture>]| {
        4 * (4 * t.len() as u64 + t.iter().map(|t| u64::from(t.width) * u64::from(t.height)).sum::<u64>())
    };
    let mut halvings = 0;
    while bytes(&textures) > limit {
        // the largest texture gives way first
        let Some(k) = (0..textures.len()).max_by_key(|&k| u64::from(textures[k].width) * u64::from(textures[k].height))
        else {
            break;
        };
        if textures[k].width <= 1 && textures[k].height <= 1 {
            break;
        }
        textures[k] = std::borrow::Cow::Owned(textures[k].halved());
        halvings += 1;
    }
    let mut words = Vec::with_capacity((bytes(&textures) / 4) as usize + 1);
    let mut next = 4 * textures.len() as u32;
    for t in &textures {
        let nearest = u32::from(t.filter == scene::Filter::Nearest);
        words.extend([next, t.width, t.height, t.wrap[0].code() | t.wrap[1].code() << 2 | nearest << 4]);
        next += t.width * t.height;
    }
    for t in &textures {
        words.extend(t.texels.iter().map(|&c| u32::from_le_bytes(c)));
    }
    if words.is_empty() {
        // storage bindings may not be empty
        words.push(0);
    }
    (words, halvings)
}

/// A scene's triangles as the G-buffer pass draws them.
pub struct SceneGeometry {
    pub(crate) vertices: wgpu::Buffer,
    pub(crate) vertex_count: u32,
    pub(crate) materials: wgpu::Buffer,
    /// texture coordinates and culling per vertex ([`SurfaceVertex`])
    pub(crate) surface: wgpu::Buffer,
    /// the textures ([`texel_words`])
    pub(crate) texels: wgpu::Buffer,
    /// How many times a texture was halved to fit the GPU's storage binding limit (0: every
    /// texture at full size, as the reference tracer samples it).
    pub texture_halvings: u32,
    /// Axis-aligned bounds of the scene, its objects where their transforms put them.
    pub bounds: (Vec3, Vec3),
    // per object: first vertex, vertex count, bounds in object space
    objects: Vec<(u32, u32, (Vec3, Vec3))>,
    placement: Placement,
}

/// Usage of vertex buffers a [`Placement`] moves: drawn, written, copied and placed.
const PLACED: wgpu::BufferUsages = wgpu::BufferUsages::VERTEX
    .union(wgpu::BufferUsages::COPY_DST)
    .union(wgpu::BufferUsages::COPY_SRC)
    .union(wgpu::BufferUsages::STORAGE);

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

/// Object `object`'s per-vertex texture coordinates and culling, three per triangle.
fn surface_vertices(object: &scene::Object) -> Vec<SurfaceVertex> {
    let mesh = &object.mesh;
    let cull = u32::from(!object.material.double_sided);
    mesh.indices
        .iter()
        .flatten()
        .map(|&i| SurfaceVertex { uv: mesh.uvs.as_ref().map_or([0.0; 2], |uv| uv[i as usize].to_array()), cull })
        .collect()
}

/// Object `k`'s G-buffer vertices (three per triangle) and their bounds.
fn object_vertices(k: usize, object: &scene::Object) -> (Vec<ShadedVertex>, (Vec3, Vec3)) {
    let mesh = &object.mesh;
    let mut vertices = Vec::with_capacity(mesh.indices.len() * 3);
    let (mut lo, mut hi) = (Vec3::splat(f32::INFINITY), Vec3::splat(f32::NEG_INFINITY));
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
    (vertices, (lo, hi))
}

fn union(boxes: impl Iterator<Item = (Vec3, Vec3)>) -> (Vec3, Vec3) {
    boxes.fold((Vec3::splat(f32::INFINITY), Vec3::splat(f32::NEG_INFINITY)), |(lo, hi), (a, b)| (lo.min(a), hi.max(b)))
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
        let mut objects = Vec::with_capacity(scene.objects.len());
        for (k, object) in scene.objects.iter().enumerate() {
            let (v, bounds) = object_vertices(k, object);
            objects.push((vertices.len() as u32, v.len() as u32, bounds));
            vertices.extend(v);
        }
        let mut surface: Vec<SurfaceVertex> = scene.objects.iter().flat_map(surface_vertices).collect();
        if surface.is_empty() {
            // as the vertices: a buffer slice may not be empty
            surface.push(SurfaceVertex { uv: [0.0; 2], cull: 0 });
        }
        let limit = gpu.limits.max_storage_buffer_binding_size.min(gpu.limits.max_buffer_size);
        let (texels, texture_halvings) = texel_words(&scene.textures, limit);
        let mut materials: Vec<GpuMaterial> = scene.objects.iter().map(|o| GpuMaterial::new(&o.material)).collect();
        if materials.is_empty() {
            // storage bindings may not be empty
            materials.push(GpuMaterial::new(&scene::Material::lambert(0.0)));
        }
        let vertices_buf = gpu.create_buffer_init(&wgpu::util::BufferInitDescriptor {
            label: Some("scene vertices"),
            contents: bytemuck::cast_slice(&vertices),
            usage: PLACED,
        });
        let materials_buf = gpu.create_buffer_init(&wgpu::util::BufferInitDescriptor {
            label: Some("materials"),
            contents: bytemuck::cast_slice(&materials),
            usage: wgpu::BufferUsages::STORAGE,
        });
        let surface_buf = gpu.create_buffer_init(&wgpu::util::BufferInitDescriptor {
            label: Some("scene vertex surfaces"),
            contents: bytemuck::cast_slice(&surface),
            usage: wgpu::BufferUsages::VERTEX | wgpu::BufferUsages::COPY_DST,
        });
        let texels_buf = gpu.create_buffer_init(&wgpu::util::BufferInitDescriptor {
            label: Some("texels"),
            contents: bytemuck::cast_slice(&texels),
            usage: wgpu::BufferUsages::STORAGE,
        });
        let words = VertexWords { count: vertices.len() as u32, stride: 10, normals: 2, object_word: 9 };
        Ok(Self {
            vertices: vertices_buf,
            vertex_count: vertices.len() as u32,
            materials: materials_buf,
            surface: surface_buf,
            texels: texels_buf,
            texture_halvings,
            bounds: union(objects.iter().map(|o| o.2)),
            placement: Placement::new(gpu, words, objects.len())?,
            objects,
        })
    }

    /// Sets object `object`'s transform (from its mesh as uploaded, object space, to the
    /// world): one `queue.write_buffer`; the G-buffer pass that next draws the geometry places
    /// its vertices on the GPU first. The bounds follow.
    ///
    /// # Errors
    /// [`GpuError::Failed`] for an object out of range or a non-finite transform.
    pub fn set_transform(&mut self, gpu: &Gpu, object: usize, transform: Affine3A) -> Result<(), GpuError> {
        self.placement.set(gpu, &self.vertices, object, transform)?;
        self.bounds = self.world_bounds();
        Ok(())
    }

    /// Object `object`'s transform (the identity until [`SceneGeometry::set_transform`]).
    #[must_use]
    pub fn transform(&self, object: usize) -> Affine3A {
        self.placement.transform(object)
    }

    fn world_bounds(&self) -> (Vec3, Vec3) {
        union(self.objects.iter().enumerate().map(|(k, o)| transform_box(&self.placement.transform(k), o.2)))
    }

    /// Records the placement of moved objects' vertices (nothing when none moved): what the
    /// G-buffer pass calls before drawing.
    pub(crate) fn record_placement(&self, gpu: &Gpu, encoder: &mut wgpu::CommandEncoder) {
        self.placement.record(gpu, encoder, &self.vertices);
    }

    /// Writes object `object`'s vertices from its mesh in `scene` (same triangles, new
    /// positions or normals: a deformation) with `queue.write_buffer`, and updates the bounds:
    /// what [`SceneGeometry::upload`] of the changed scene would hold, without a new buffer.
    /// Its transform ([`SceneGeometry::set_transform`]) still applies; a rigid motion needs only
    /// that.
    ///
    /// # Errors
    /// [`GpuError::Failed`] for an object out of range or with another triangle count.
    pub fn update_object(&mut self, gpu: &Gpu, scene: &scene::Scene, object: usize) -> Result<(), GpuError> {
        let (Some(&(first, count, _)), Some(o)) = (self.objects.get(object), scene.objects.get(object)) else {
            return Err(GpuError::Failed(format!("scene geometry: no object {object}")));
        };
        if o.mesh.indices.len() as u64 * 3 != u64::from(count) {
            return Err(GpuError::Failed(format!(
                "scene geometry: object {object} has {} triangles, uploaded with {}",
                o.mesh.indices.len(),
                count / 3
            )));
        }
        let (vertices, bounds) = object_vertices(object, o);
        if !vertices.is_empty() {
            let offset = u64::from(first) * std::mem::size_of::<ShadedVertex>() as u64;
            self.placement.write_vertices(gpu, &self.vertices, offset, bytemuck::cast_slice(&vertices));
            let offset = u64::from(first) * std::mem::size_of::<SurfaceVertex>() as u64;
            gpu.queue.write_buffer(&self.surface, offset, bytemuck::cast_slice(&surface_vertices(o)));
        }
        self.objects[object].2 = bounds;
        self.bounds = self.world_bounds();
        Ok(())
    }

    pub(crate) const LAYOUT: wgpu::VertexBufferLayout<'static> = wgpu::VertexBufferLayout {
        array_stride: std::mem::size_of::<ShadedVertex>() as u64,
        step_mode: wgpu::VertexStepMode::Vertex,
        attributes: &wgpu::vertex_attr_array![0 => Float32x3, 1 => Float32x3, 2 => Float32x3, 3 => Uint32],
    };

    /// The second vertex buffer's layout ([`SceneGeometry::surface`]).
    pub(crate) const SURFACE_LAYOUT: wgpu::VertexBufferLayout<'static> = wgpu::VertexBufferLayout {
        array_stride: std::mem::size_of::<SurfaceVertex>() as u64,
        step_mode: wgpu::VertexStepMode::Vertex,
        attributes: &wgpu::vertex_attr_array![4 => Float32x2, 5 => Uint32],
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
    /// Vertex buffer: a `[f32; 3]` position and the `u32` object index, three vertices per
    /// triangle ([`ShadowGeometry::LAYOUT`]).
    pub vertices: wgpu::Buffer,
    /// The chunks, covering every triangle once, with their bounds where the objects'
    /// transforms put them.
    pub chunks: Vec<Chunk>,
    /// Triangle count.
    pub triangles: u32,
    // triangles per chunk (the last may have fewer), and every triangle as uploaded (object
    // space), for bounds updates
    chunk_triangles: usize,
    soup: Vec<[Vec3; 3]>,
    // per object, its first triangle and count
    objects: Vec<(usize, usize)>,
    // per chunk, the bounding sphere of each object's triangles in it, object space
    parts: Vec<Vec<(u32, Vec3, f32)>>,
    placement: Placement,
}

/// A chunk's bounding sphere: the centre of its box and the farthest vertex from it.
fn chunk_sphere(tris: &[[Vec3; 3]]) -> (Vec3, f32) {
    let (mut lo, mut hi) = (Vec3::splat(f32::INFINITY), Vec3::splat(f32::NEG_INFINITY));
    for p in tris.iter().flatten() {
        lo = lo.min(*p);
        hi = hi.max(*p);
    }
    let center = 0.5 * (lo + hi);
    (center, tris.iter().flatten().map(|p| p.distance(center)).fold(0.0, f32::max))
}

/// A sphere holding every one of `spheres`.
fn sphere_of_spheres(spheres: &[(Vec3, f32)]) -> (Vec3, f32) {
    let (mut lo, mut hi) = (Vec3::splat(f32::INFINITY), Vec3::splat(f32::NEG_INFINITY));
    for &(c, r) in spheres {
        lo = lo.min(c - Vec3::splat(r));
        hi = hi.max(c + Vec3::splat(r));
    }
    let center = 0.5 * (lo + hi);
    (center, spheres.iter().map(|&(c, r)| c.distance(center) + r).fold(0.0, f32::max))
}

impl ShadowGeometry {
    /// Triangles per chunk by default: small enough to cull walls row by row, large enough that
    /// draw calls stay few.
    pub const CHUNK_TRIANGLES: usize = 16;

    /// Uploads `triangles` (world space, one object) in chunks of `chunk_triangles`
    /// consecutive triangles.
    ///
    /// # Errors
    /// [`GpuError::TooLarge`] beyond the buffer limits.
    pub fn upload(gpu: &Gpu, triangles: &[[Vec3; 3]], chunk_triangles: usize) -> Result<Self, GpuError> {
        Self::upload_objects(gpu, &[triangles], chunk_triangles)
    }

    /// Uploads the triangles of each object of `objects` (object space), one after the other,
    /// in chunks of `chunk_triangles` consecutive triangles; each object can then be moved by
    /// its transform ([`ShadowGeometry::set_transform`]).
    ///
    /// # Errors
    /// [`GpuError::TooLarge`] beyond the buffer limits.
    pub fn upload_objects(gpu: &Gpu, objects: &[&[[Vec3; 3]]], chunk_triangles: usize) -> Result<Self, GpuError> {
        let count: usize = objects.iter().map(|o| o.len()).sum();
        check_count(gpu, count * 3, 16)?;
        let n = chunk_triangles.max(1);
        let mut soup = Vec::with_capacity(count);
        let mut ranges = Vec::with_capacity(objects.len());
        let mut flat: Vec<[u32; 4]> = Vec::with_capacity(count * 3);
        for (k, tris) in objects.iter().enumerate() {
            ranges.push((soup.len(), tris.len()));
            soup.extend_from_slice(tris);
            flat.extend(tris.iter().flatten().map(|p| {
                let [x, y, z] = p.to_array().map(f32::to_bits);
                [x, y, z, k as u32]
            }));
        }
        let chunks = soup
            .chunks(n)
            .enumerate()
            .map(|(k, tris)| {
                let (center, radius) = chunk_sphere(tris);
                Chunk { first_vertex: (k * n * 3) as u32, vertex_count: (tris.len() * 3) as u32, center, radius }
            })
            .collect();
        let vertices = gpu.create_buffer_init(&wgpu::util::BufferInitDescriptor {
            label: Some("shadow vertices"),
            contents: bytemuck::cast_slice(if flat.is_empty() { &[[0u32; 4]; 3][..] } else { &flat[..] }),
            usage: PLACED,
        });
        let words = VertexWords { count: flat.len() as u32, stride: 4, normals: 0, object_word: 3 };
        let mut out = Self {
            vertices,
            chunks,
            triangles: count as u32,
            chunk_triangles: n,
            soup,
            parts: Vec::new(),
            placement: Placement::new(gpu, words, ranges.len())?,
            objects: ranges,
        };
        out.parts = (0..out.chunks.len()).map(|k| out.chunk_parts(k)).collect();
        Ok(out)
    }

    /// The object of triangle `t`.
    fn object_of(&self, t: usize) -> usize {
        self.objects.partition_point(|&(first, count)| first + count <= t)
    }

    /// Chunk `k`'s bounding sphere of each object's triangles in it (object space).
    fn chunk_parts(&self, k: usize) -> Vec<(u32, Vec3, f32)> {
        let n = self.chunk_triangles;
        let (start, end) = (k * n, ((k + 1) * n).min(self.soup.len()));
        let mut parts = Vec::new();
        let mut t = start;
        while t < end {
            let object = self.object_of(t);
            let stop = self.objects.get(object).map_or(end, |&(first, count)| (first + count).min(end)).max(t + 1);
            let (c, r) = chunk_sphere(&self.soup[t..stop]);
            parts.push((object as u32, c, r));
            t = stop;
        }
        parts
    }

    /// Chunk `k`'s bounds where the transforms put its triangles: as uploaded while they are
    /// all the identity.
    fn place_chunk(&mut self, k: usize) {
        let n = self.chunk_triangles;
        let parts = &self.parts[k];
        let moved = parts.iter().any(|p| self.placement.transform(p.0 as usize) != Affine3A::IDENTITY);
        let (center, radius) = if !moved {
            chunk_sphere(&self.soup[k * n..((k + 1) * n).min(self.soup.len())])
        } else {
            let spheres: Vec<(Vec3, f32)> = parts
                .iter()
                .map(|&(o, c, r)| crate::placement::transform_sphere(&self.placement.transform(o as usize), (c, r)))
                .collect();
            sphere_of_spheres(&spheres)
        };
        self.chunks[k].center = center;
        self.chunks[k].radius = radius;
    }

    /// Every triangle, in the order of the vertex buffer, in world space (where the objects'
    /// transforms put them).
    #[must_use]
    pub fn triangle_soup(&self) -> std::borrow::Cow<'_, [[Vec3; 3]]> {
        if !self.placement.in_use() {
            return std::borrow::Cow::Borrowed(&self.soup);
        }
        let mut out = Vec::with_capacity(self.soup.len());
        for (k, &(first, count)) in self.objects.iter().enumerate() {
            let t = self.placement.transform(k);
            out.extend(self.soup[first..first + count].iter().map(|tri| tri.map(|p| t.transform_point3(p))));
        }
        std::borrow::Cow::Owned(out)
    }

    /// Sets object `object`'s transform (from its triangles as uploaded to the world): one
    /// `queue.write_buffer`; the depth passes that next draw the geometry place its vertices on
    /// the GPU first ([`ShadowGeometry::record_placement`]). Its chunks' bounds follow.
    ///
    /// # Errors
    /// [`GpuError::Failed`] for an object out of range or a non-finite transform.
    pub fn set_transform(&mut self, gpu: &Gpu, object: usize, transform: Affine3A) -> Result<(), GpuError> {
        self.placement.set(gpu, &self.vertices, object, transform)?;
        let (first, count) = self.objects[object];
        if count > 0 {
            let n = self.chunk_triangles;
            for k in first / n..(first + count).div_ceil(n) {
                self.place_chunk(k);
            }
        }
        Ok(())
    }

    /// Object `object`'s transform (the identity until [`ShadowGeometry::set_transform`]).
    #[must_use]
    pub fn transform(&self, object: usize) -> Affine3A {
        self.placement.transform(object)
    }

    /// Records the placement of moved objects' vertices into `encoder` (nothing when none
    /// moved since the last): before any pass that draws [`ShadowGeometry::vertices`].
    pub fn record_placement(&self, gpu: &Gpu, encoder: &mut wgpu::CommandEncoder) {
        self.placement.record(gpu, encoder, &self.vertices);
    }

    /// Replaces triangles `first..first + triangles.len()` (as uploaded: a deformed object's)
    /// with `queue.write_buffer` and recomputes the bounds of the chunks they fall in: what
    /// [`ShadowGeometry::upload_objects`] of the changed triangles would give, without a new
    /// buffer. The objects' transforms still apply.
    ///
    /// # Errors
    /// [`GpuError::Failed`] for a range past the end.
    pub fn update(&mut self, gpu: &Gpu, first: usize, triangles: &[[Vec3; 3]]) -> Result<(), GpuError> {
        let end = first.checked_add(triangles.len()).filter(|&e| e <= self.soup.len()).ok_or_else(|| {
            GpuError::Failed(format!(
                "shadow geometry: triangles {first}.. ({}) past its {}",
                triangles.len(),
                self.soup.len()
            ))
        })?;
        if triangles.is_empty() {
            return Ok(());
        }
        self.soup[first..end].copy_from_slice(triangles);
        let flat: Vec<[u32; 4]> = (first..end)
            .flat_map(|t| {
                let object = self.object_of(t) as u32;
                self.soup[t].map(|p| {
                    let [x, y, z] = p.to_array().map(f32::to_bits);
                    [x, y, z, object]
                })
            })
            .collect();
        self.placement.write_vertices(gpu, &self.vertices, first as u64 * 48, bytemuck::cast_slice(&flat));
        let n = self.chunk_triangles;
        for k in first / n..end.div_ceil(n) {
            self.parts[k] = self.chunk_parts(k);
            self.place_chunk(k);
        }
        Ok(())
    }

    /// Vertex layout: one `vec3<f32>` position at location 0 (16 bytes a vertex: the object
    /// index follows it).
    pub const LAYOUT: wgpu::VertexBufferLayout<'static> = wgpu::VertexBufferLayout {
        array_stride: 16,
        step_mode: wgpu::VertexStepMode::Vertex,
        attributes: &wgpu::vertex_attr_array![0 => Float32x3],
    };

    /// Draws the chunks whose index `visible` accepts, merging neighbours into one draw call.
    /// Returns the number of triangles drawn.
    pub fn draw(&self, pass: &mut wgpu::RenderPass<'_>, visible: impl Fn(usize) -> bool) -> u32 {
        self.set_vertices(pass);
        let (runs, drawn) = self.runs(visible);
        for r in runs {
            pass.draw(r, 0..1);
        }
        drawn
    }

    /// Binds the vertices at slot 0 for drawing [`ShadowGeometry::runs`].
    pub fn set_vertices(&self, pass: &mut wgpu::RenderPass<'_>) {
        pass.set_vertex_buffer(0, self.vertices.slice(..));
    }

    /// The vertex ranges of the chunks whose index `visible` accepts, neighbours merged (one
    /// draw call each), and their triangles.
    #[must_use]
    pub fn runs(&self, visible: impl Fn(usize) -> bool) -> (Vec<std::ops::Range<u32>>, u32) {
        let mut runs: Vec<std::ops::Range<u32>> = Vec::new();
        let mut drawn = 0;
        for c in self.chunks.iter().enumerate().filter(|(k, _)| visible(*k)).map(|(_, c)| c) {
            drawn += c.vertex_count / 3;
            match runs.last_mut() {
                Some(r) if r.end == c.first_vertex => r.end += c.vertex_count,
                _ => runs.push(c.first_vertex..c.first_vertex + c.vertex_count),
            }
        }
        (runs, drawn)
    }
}

/// Every triangle of `scene` in world space, object by object.
#[must_use]
pub fn scene_triangles(scene: &scene::Scene) -> Vec<[Vec3; 3]> {
    scene.objects.iter().flat_map(|o| (0..o.mesh.indices.len()).map(|t| o.mesh.triangle(t))).collect()
}
