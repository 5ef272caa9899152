//! The scene's triangles in an obvhs compressed-wide BVH: closest-hit and occlusion queries,
//! and the surface point of a hit. Traversal is obvhs's `traverse!` with our node and triangle
//! tests: no absolute epsilon anywhere, so images do not depend on the scene's scale.

use glam::{UVec2, Vec2, Vec3, Vec3A};
use obvhs::BvhBuildParams;
use obvhs::cwbvh::CwBvh;
use obvhs::cwbvh::builder::build_cwbvh_from_tris;
use obvhs::cwbvh::node::CwBvhNode;
use obvhs::ray::Ray;
use obvhs::triangle::Triangle;
use scene::{Material, Mesh, Scene, Texture};

/// A ray's closest hit, resolved to a surface point.
#[derive(Clone, Copy, Debug)]
pub struct SurfacePoint {
    /// Distance along the ray.
    pub t: f32,
    /// Position.
    pub position: Vec3,
    /// Unit geometric normal, facing the incoming ray.
    pub geometric_normal: Vec3,
    /// Unit shading normal (interpolated vertex normals where the mesh has them), on the same
    /// side as the geometric normal.
    pub shading_normal: Vec3,
    /// Index of the object in the scene.
    pub object: u32,
    /// True when the ray hit the triangle's front side (counter-clockwise as the ray sees it):
    /// one-sided emitters emit from there.
    pub front: bool,
    /// Texture coordinates, interpolated (zero where the mesh has none).
    pub uv: Vec2,
}

/// A BVH over every triangle of a scene.
pub struct SceneBvh {
    bvh: CwBvh,
    /// the triangles in the BVH's primitive order, so a leaf's triangles sit side by side in
    /// memory and need no index lookup
    triangles: Vec<RtTriangle>,
    /// per triangle, in the same order: (object, triangle within the object)
    owners: Vec<(u32, u32)>,
    materials: Vec<Material>,
    textures: Vec<Texture>,
    /// whether any material emits
    emits: bool,
    /// per object: its mesh, for interpolating vertex normals
    meshes: Vec<Mesh>,
    scale: f32,
}

/// How long the BVH build may take to make traversal faster: obvhs's named presets, fastest
/// first. The build is the tracer's start-up cost; at millions of triangles it is the largest
/// one, so a user tracing few samples of a large model picks a faster preset.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum BvhQuality {
    /// obvhs `fastest_build`.
    Fastest,
    /// obvhs `very_fast_build`.
    VeryFast,
    /// obvhs `fast_build`.
    Fast,
    /// obvhs `medium_build`.
    Medium,
    /// obvhs `slow_build`.
    Slow,
    /// obvhs `very_slow_build` (spatial pre-splits, full reinsertion): the default, ~50 ms for
    /// `spheres_box`'s 20k triangles, repaid by ~15 % faster traversal.
    #[default]
    VerySlow,
}

impl BvhQuality {
    /// Every preset, fastest build first.
    pub const ALL: [Self; 6] = [Self::Fastest, Self::VeryFast, Self::Fast, Self::Medium, Self::Slow, Self::VerySlow];

    /// The preset's name on a command line (`fastest` … `very-slow`).
    #[must_use]
    pub const fn name(self) -> &'static str {
        match self {
            Self::Fastest => "fastest",
            Self::VeryFast => "very-fast",
            Self::Fast => "fast",
            Self::Medium => "medium",
            Self::Slow => "slow",
            Self::VerySlow => "very-slow",
        }
    }

    /// The preset named `name`.
    #[must_use]
    pub fn parse(name: &str) -> Option<Self> {
        Self::ALL.into_iter().find(|q| q.name() == name)
    }

    const fn params(self) -> BvhBuildParams {
        match self {
            Self::Fastest => BvhBuildParams::fastest_build(),
            Self::VeryFast => BvhBuildParams::very_fast_build(),
            Self::Fast => BvhBuildParams::fast_build(),
            Self::Medium => BvhBuildParams::medium_build(),
            Self::Slow => BvhBuildParams::slow_build(),
            Self::VerySlow => BvhBuildParams::very_slow_build(),
        }
    }
}

impl SceneBvh {
    /// Builds the BVH with the default [`BvhQuality`] (the slowest build, the fastest traversal).
    #[must_use]
    pub fn new(scene: &Scene) -> Self {
        Self::with_quality(scene, BvhQuality::default())
    }

    /// Builds the BVH with the preset `quality`: every preset finds the same closest hits.
    #[must_use]
    pub fn with_quality(scene: &Scene, quality: BvhQuality) -> Self {
        let mut triangles = Vec::with_capacity(scene.triangle_count());
        let mut owners = Vec::with_capacity(scene.triangle_count());
        let mut scale = 0.0f32;
        for (k, o) in scene.objects.iter().enumerate() {
            for t in 0..o.mesh.indices.len() {
                let [a, b, c] = o.mesh.triangle(t);
                scale = scale.max(a.abs().max_element()).max(b.abs().max_element()).max(c.abs().max_element());
                triangles.push(Triangle { v0: a.into(), v1: b.into(), v2: c.into() });
                owners.push((k as u32, t as u32));
            }
        }
        let bvh = build_cwbvh_from_tris(&triangles, quality.params(), &mut Default::default());
        let triangles = bvh.primitive_indices.iter().map(|&i| RtTriangle::new(&triangles[i as usize])).collect();
        let owners = bvh.primitive_indices.iter().map(|&i| owners[i as usize]).collect();
        Self {
            bvh,
            triangles,
            owners,
            materials: scene.objects.iter().map(|o| o.material).collect(),
            textures: scene.textures.clone(),
            emits: scene.objects.iter().any(|o| o.material.emits()),
            meshes: scene.objects.iter().map(|o| o.mesh.clone()).collect(),
            scale,
        }
    }

    /// Material of object `k`.
    #[must_use]
    pub fn material(&self, object: u32) -> &Material {
        &self.materials[object as usize]
    }

    /// The material where `sp` is: object `sp.object`'s, its textures sampled at `sp.uv`.
    #[must_use]
    pub fn material_at(&self, sp: &SurfacePoint) -> Material {
        self.materials[sp.object as usize].at(&self.textures, sp.uv)
    }

    /// Radiance the material emits toward the ray that found `sp`: its emission (textured)
    /// from the front, or from either side where it is double-sided.
    #[must_use]
    pub fn emission_at(&self, sp: &SurfacePoint) -> Vec3 {
        let m = &self.materials[sp.object as usize];
        if !m.emits() || !(sp.front || m.double_sided) {
            return Vec3::ZERO;
        }
        m.at(&self.textures, sp.uv).emission
    }

    /// Whether any material emits (so a path's last bounce ray is worth tracing).
    #[must_use]
    pub fn emits(&self) -> bool {
        self.emits
    }

    /// The closest hit a camera sees along `origin + t dir`: as [`Self::intersect`], past the
    /// back faces of one-sided materials (glTF's back-face culling; shadow and bounce rays see
    /// both sides).
    #[must_use]
    pub fn intersect_camera(&self, origin: Vec3, dir: Vec3) -> Option<SurfacePoint> {
        let mut t_min = 0.0;
        // a bounded walk: each step passes one culled face at a strictly larger distance
        for _ in 0..256 {
            let (id, t) = self.closest(origin, dir, t_min, f32::INFINITY)?;
            let sp = self.surface(id as usize, origin, dir, t);
            if sp.front || self.materials[sp.object as usize].double_sided {
                return Some(sp);
            }
            t_min = t;
        }
        None
    }

    /// Offset that moves a ray origin off a surface: relative to the scene's extent, so tiny and
    /// huge scenes both avoid self-intersection.
    #[must_use]
    pub fn epsilon(&self) -> f32 {
        1e-5 * self.scale
    }

    /// The closest hit along `origin + t dir`, t in (0, t_max).
    #[must_use]
    pub fn intersect(&self, origin: Vec3, dir: Vec3, t_max: f32) -> Option<SurfacePoint> {
        self.closest(origin, dir, 0.0, t_max).map(|(id, t)| self.surface(id as usize, origin, dir, t))
    }

    /// The closest triangle (in BVH order) and its distance, t in (t_min, t_max).
    fn closest(&self, origin: Vec3, dir: Vec3, t_min: f32, t_max: f32) -> Option<(u32, f32)> {
        let mut ray = Ray::new(origin.into(), dir.into(), t_min, t_max);
        let mut hit = None;
        let mut state = self.bvh.new_traversal(ray.direction);
        let mut node: &CwBvhNode;
        obvhs::traverse!(self.bvh, node, state, node_hits(node, &ray, state.oct_inv4), {
            let t = self.triangles[state.primitive_id as usize].intersect(&ray);
            if t < ray.tmax {
                hit = Some(state.primitive_id);
                ray.tmax = t;
            }
        });
        hit.map(|id| (id, ray.tmax))
    }

    /// Whether anything blocks `origin + t dir` for t in (0, t_max).
    #[must_use]
    pub fn occluded(&self, origin: Vec3, dir: Vec3, t_max: f32) -> bool {
        let ray = Ray::new(origin.into(), dir.into(), 0.0, t_max);
        let mut state = self.bvh.new_traversal(ray.direction);
        let mut node: &CwBvhNode;
        let mut blocked = false;
        obvhs::traverse!(self.bvh, node, state, node_hits(node, &ray, state.oct_inv4), {
            if self.triangles[state.primitive_id as usize].intersect(&ray) < ray.tmax {
                blocked = true;
                break;
            }
        });
        blocked
    }

    fn surface(&self, tri_index: usize, origin: Vec3, dir: Vec3, t: f32) -> SurfacePoint {
        let tri = &self.triangles[tri_index];
        let position = origin + dir * t;
        let mut ng = tri.n.normalize_or(Vec3::Y);
        let (object, local) = self.owners[tri_index];
        let mesh = &self.meshes[object as usize];
        let b = barycentric(position, tri);
        let corners = mesh.indices[local as usize];
        let mut ns = match &mesh.normals {
            Some(normals) => {
                let [i0, i1, i2] = corners.map(|i| normals[i as usize]);
                (i0 * b.x + i1 * b.y + i2 * b.z).normalize_or(ng)
            }
            None => ng,
        };
        let uv = mesh.uvs.as_ref().map_or(Vec2::ZERO, |uvs| {
            let [a, b1, c] = corners.map(|i| uvs[i as usize]);
            a * b.x + b1 * b.y + c * b.z
        });
        let front = ng.dot(dir) < 0.0;
        if !front {
            ng = -ng;
        }
        if ns.dot(ng) < 0.0 {
            ns = -ns;
        }
        SurfacePoint { t, position, geometric_normal: ng, shading_normal: ns, object, front, uv }
    }
}

/// The tracer answers the ray queries of the crates that must not depend on it (the radiosity
/// solver, the shaft hierarchy, the compositor): one object per patch gives patch ids.
impl scene::Visibility for SceneBvh {
    fn occluded(&self, origin: Vec3, dir: Vec3, t_max: f32) -> bool {
        SceneBvh::occluded(self, origin, dir, t_max)
    }

    fn first_hit(&self, origin: Vec3, dir: Vec3) -> Option<(u32, f32)> {
        self.intersect(origin, dir, f32::INFINITY).map(|h| (h.object, h.t))
    }

    fn first_hit_normal(&self, origin: Vec3, dir: Vec3) -> Option<(f32, Vec3)> {
        self.intersect(origin, dir, f32::INFINITY).map(|h| (h.t, h.shading_normal))
    }

    fn epsilon(&self) -> f32 {
        SceneBvh::epsilon(self)
    }
}

/// Barycentric coordinates (w0, w1, w2) of a point in the triangle's plane.
fn barycentric(p: Vec3, tri: &RtTriangle) -> Vec3 {
    let (e1, e2, n, d) = (tri.e1, tri.e2, tri.n, p - tri.v0);
    let inv = 1.0 / n.length_squared();
    let b1 = d.cross(e2).dot(n) * inv;
    let b2 = e1.cross(d).dot(n) * inv;
    Vec3::new(1.0 - b1 - b2, b1, b2)
}

/// A triangle as the intersection test reads it: one vertex, the two edges from it and their
/// cross product, precomputed once instead of per test.
#[derive(Clone, Copy, Debug)]
struct RtTriangle {
    v0: Vec3,
    e1: Vec3,
    e2: Vec3,
    /// e1 x e2, unnormalized
    n: Vec3,
}

impl RtTriangle {
    fn new(t: &Triangle) -> Self {
        let (v0, e1, e2) = (Vec3::from(t.v0), Vec3::from(t.v1 - t.v0), Vec3::from(t.v2 - t.v0));
        Self { v0, e1, e2, n: e1.cross(e2) }
    }

    /// Distance to the hit within (ray.tmin, ray.tmax], infinity for none: Moller-Trumbore
    /// with the edges and normal precomputed. A hit exactly on an edge (u, v or w = 0) counts.
    #[inline(always)]
    fn intersect(&self, ray: &Ray) -> f32 {
        let (o, d) = (Vec3::from(ray.origin), Vec3::from(ray.direction));
        let c = self.v0 - o;
        let r = d.cross(c);
        let det = -self.n.dot(d);
        let inv_det = 1.0 / det;
        let u = r.dot(self.e2) * inv_det;
        let v = -r.dot(self.e1) * inv_det;
        let t = -self.n.dot(c) * inv_det;
        let inside = u >= 0.0 && v >= 0.0 && u + v <= 1.0;
        if inside && det != 0.0 && t > ray.tmin && t <= ray.tmax { t } else { f32::INFINITY }
    }
}

/// `a.max(b)` as one vector instruction: `f32::max`'s NaN rule costs extra ones, and a NaN
/// here (a zero extent times an infinite inverse) rightly reads as a miss either way.
#[inline(always)]
fn fast_max(a: f32, b: f32) -> f32 {
    if a > b { a } else { b }
}

#[inline(always)]
fn fast_min(a: f32, b: f32) -> f32 {
    if a < b { a } else { b }
}

/// Which children of a compressed wide node the ray enters, as the hit mask obvhs's `traverse!`
/// expects: all eight slabs in one pass over arrays, which LLVM turns into one AVX2 (or two
/// SSE) vector pass, where obvhs's own test assembles each lane from scalars. The slab test
/// starts at the ray's `tmin` (obvhs's clamps at a fixed 1e-4, which drops boxes closer than
/// that in tiny scenes).
#[inline(always)]
fn node_hits(node: &CwBvhNode, ray: &Ray, oct_inv4: u32) -> u32 {
    let scale = node.compute_extent() * ray.inv_direction;
    let offset = (Vec3A::from(node.p) - ray.origin) * ray.inv_direction;
    // near and far planes per axis: the ray's sign picks which quantized bound is which
    let planes = |lo: &[u8; 8], hi: &[u8; 8], negative: bool| if negative { (*hi, *lo) } else { (*lo, *hi) };
    let (nx, fx) = planes(&node.child_min_x, &node.child_max_x, ray.direction.x < 0.0);
    let (ny, fy) = planes(&node.child_min_y, &node.child_max_y, ray.direction.y < 0.0);
    let (nz, fz) = planes(&node.child_min_z, &node.child_max_z, ray.direction.z < 0.0);
    let (child_bits8, bit_index8) = node.get_child_and_index_bits(oct_inv4);
    let (child_bits8, bit_index8) = (child_bits8.to_le_bytes(), bit_index8.to_le_bytes());
    let mut hits = [0u32; 8];
    for i in 0..8 {
        let t_near = fast_max(
            fast_max(f32::from(nx[i]) * scale.x + offset.x, f32::from(ny[i]) * scale.y + offset.y),
            fast_max(f32::from(nz[i]) * scale.z + offset.z, ray.tmin),
        );
        let t_far = fast_min(
            fast_min(f32::from(fx[i]) * scale.x + offset.x, f32::from(fy[i]) * scale.y + offset.y),
            fast_min(f32::from(fz[i]) * scale.z + offset.z, ray.tmax),
        );
        let child = u32::from(child_bits8[i]) << bit_index8[i];
        hits[i] = if t_near <= t_far { child } else { 0 };
    }
    hits.iter().fold(0, |a, b| a | b)
}
