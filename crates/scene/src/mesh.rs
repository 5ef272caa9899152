//! Triangle meshes and the procedural shapes the built-in scenes are made of.
//!
//! Triangles wind counter-clockwise seen from outside: the geometric normal (b - a) x (c - a)
//! points out. Meshes with `normals` shade with interpolated vertex normals; the others flat.

use glam::{Affine3A, Mat3, Vec3};

/// The matrix normals transform by: the cofactor matrix of `linear` (the inverse transpose
/// times the determinant), its sign the determinant's. Unlike the inverse it exists for a
/// flattened object too (its normals then come out as they should, or zero).
#[must_use]
pub fn normal_matrix(linear: Mat3) -> Mat3 {
    if linear == Mat3::IDENTITY {
        return Mat3::IDENTITY;
    }
    let (a, b, c) = (linear.x_axis, linear.y_axis, linear.z_axis);
    let cof = Mat3::from_cols(b.cross(c), c.cross(a), a.cross(b));
    if linear.determinant() < 0.0 { -cof } else { cof }
}

/// An indexed triangle mesh in world space.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Mesh {
    /// Vertex positions.
    pub positions: Vec<Vec3>,
    /// Per-vertex shading normals (unit), or `None` for flat shading.
    pub normals: Option<Vec<Vec3>>,
    /// Triangles as vertex indices.
    pub indices: Vec<[u32; 3]>,
    /// Per-vertex texture coordinates (glTF's TEXCOORD_0), or `None` where nothing is textured.
    pub uvs: Option<Vec<glam::Vec2>>,
}

impl Mesh {
    /// Moves the mesh by `t`: positions by `t`, normals by its [`normal_matrix`] and made unit
    /// again (zero where `t` flattens the object). A mirror turns the triangles' winding back,
    /// so that they still wind counter-clockwise seen from outside.
    pub fn transform(&mut self, t: &Affine3A) {
        for p in &mut self.positions {
            *p = t.transform_point3(*p);
        }
        if t.matrix3.determinant() < 0.0 {
            for tri in &mut self.indices {
                tri.swap(1, 2);
            }
        }
        if let Some(normals) = &mut self.normals {
            let n = normal_matrix(Mat3::from(t.matrix3));
            for v in normals {
                *v = (n * *v).normalize_or_zero();
            }
        }
    }

    /// Checks the mesh: indices in range, normals (if any) one per vertex and unit length, finite
    /// positions, no degenerate triangles. Returns the first problem found.
    ///
    /// # Errors
    /// A message naming the offending triangle or vertex.
    pub fn validate(&self) -> Result<(), String> {
        let n = self.positions.len();
        if let Some(normals) = &self.normals {
            if normals.len() != n {
                return Err(format!("{} normals for {n} vertices", normals.len()));
            }
            if let Some(k) = normals.iter().position(|v| (v.length() - 1.0).abs() > 1e-4) {
                return Err(format!("normal {k} is not unit length: {}", normals[k]));
            }
        }
        if let Some(uvs) = &self.uvs
            && uvs.len() != n
        {
            return Err(format!("{} texture coordinates for {n} vertices", uvs.len()));
        }
        if let Some(k) = self.positions.iter().position(|p| !p.is_finite()) {
            return Err(format!("vertex {k} is not finite"));
        }
        for (t, tri) in self.indices.iter().enumerate() {
            if tri.iter().any(|&i| i as usize >= n) {
                return Err(format!("triangle {t} indexes past {n} vertices: {tri:?}"));
            }
            if self.geometric_normal(t).length_squared() == 0.0 {
                return Err(format!("triangle {t} is degenerate"));
            }
        }
        Ok(())
    }

    /// The three corners of triangle `t`.
    #[must_use]
    pub fn triangle(&self, t: usize) -> [Vec3; 3] {
        self.indices[t].map(|i| self.positions[i as usize])
    }

    /// (b - a) x (c - a) of triangle `t`: outward, with length twice the area.
    #[must_use]
    pub fn geometric_normal(&self, t: usize) -> Vec3 {
        let [a, b, c] = self.triangle(t);
        (b - a).cross(c - a)
    }

    /// Total surface area.
    #[must_use]
    pub fn area(&self) -> f32 {
        (0..self.indices.len()).map(|t| 0.5 * self.geometric_normal(t).length()).sum()
    }

    /// Appends `other`, re-indexing it. Shading normals survive only if both meshes have them.
    pub fn append(&mut self, other: &Mesh) {
        let base = self.positions.len() as u32;
        self.normals = if self.positions.is_empty() {
            other.normals.clone()
        } else {
            match (self.normals.take(), &other.normals) {
                (Some(mut a), Some(b)) => {
                    a.extend_from_slice(b);
                    Some(a)
                }
                _ => None,
            }
        };
        self.positions.extend_from_slice(&other.positions);
        self.indices.extend(other.indices.iter().map(|t| t.map(|i| i + base)));
    }

    /// The same surface facing the other way: winding reversed, shading normals negated.
    #[must_use]
    pub fn flipped(mut self) -> Self {
        self.indices.iter_mut().for_each(|t| t.swap(1, 2));
        if let Some(n) = &mut self.normals {
            n.iter_mut().for_each(|v| *v = -*v);
        }
        self
    }

    /// A flat parallelogram from `corner` spanned by `u` and `v` (normal u x v), split into
    /// `nu` x `nv` cells of two triangles each.
    #[must_use]
    pub fn quad(corner: Vec3, u: Vec3, v: Vec3, nu: u32, nv: u32) -> Self {
        let (nu, nv) = (nu.max(1), nv.max(1));
        let mut positions = Vec::with_capacity(((nu + 1) * (nv + 1)) as usize);
        for j in 0..=nv {
            for i in 0..=nu {
                positions.push(corner + u * (i as f32 / nu as f32) + v * (j as f32 / nv as f32));
            }
        }
        let idx = |i: u32, j: u32| j * (nu + 1) + i;
        let mut indices = Vec::with_capacity((2 * nu * nv) as usize);
        for j in 0..nv {
            for i in 0..nu {
                let (a, b, c, d) = (idx(i, j), idx(i + 1, j), idx(i + 1, j + 1), idx(i, j + 1));
                indices.push([a, b, c]);
                indices.push([a, c, d]);
            }
        }
        Self { positions, normals: None, indices, uvs: None }
    }

    /// An axis-aligned box, 12 triangles, flat shaded, faces pointing out.
    #[must_use]
    pub fn cuboid(min: Vec3, max: Vec3) -> Self {
        Self::tessellated_cuboid(min, max, 1)
    }

    /// An axis-aligned box whose faces are split into `n` x `n` cells (2 n^2 triangles a face).
    #[must_use]
    pub fn tessellated_cuboid(min: Vec3, max: Vec3, n: u32) -> Self {
        let d = max - min;
        let (x, y, z) = (Vec3::new(d.x, 0.0, 0.0), Vec3::new(0.0, d.y, 0.0), Vec3::new(0.0, 0.0, d.z));
        let faces = [
            (min, z, y),     // -X: z x y = -x
            (min + x, y, z), // +X
            (min, x, z),     // -Y: x x z = -y
            (min + y, z, x), // +Y
            (min, y, x),     // -Z: y x x = -z
            (min + z, x, y), // +Z
        ];
        let mut mesh = Mesh::default();
        for (corner, u, v) in faces {
            mesh.append(&Self::quad(corner, u, v, n, n));
        }
        mesh
    }

    /// A sphere made by subdividing an icosahedron `level` times (20 x 4^level triangles), with
    /// exact unit vertex normals for smooth shading.
    #[must_use]
    pub fn icosphere(center: Vec3, radius: f32, level: u32) -> Self {
        let t = (1.0 + 5f32.sqrt()) / 2.0;
        let mut dirs: Vec<Vec3> = [
            (-1.0, t, 0.0),
            (1.0, t, 0.0),
            (-1.0, -t, 0.0),
            (1.0, -t, 0.0),
            (0.0, -1.0, t),
            (0.0, 1.0, t),
            (0.0, -1.0, -t),
            (0.0, 1.0, -t),
            (t, 0.0, -1.0),
            (t, 0.0, 1.0),
            (-t, 0.0, -1.0),
            (-t, 0.0, 1.0),
        ]
        .iter()
        .map(|&(a, b, c)| Vec3::new(a, b, c).normalize())
        .collect();
        let mut tris: Vec<[u32; 3]> = vec![
            [0, 11, 5],
            [0, 5, 1],
            [0, 1, 7],
            [0, 7, 10],
            [0, 10, 11],
            [1, 5, 9],
            [5, 11, 4],
            [11, 10, 2],
            [10, 7, 6],
            [7, 1, 8],
            [3, 9, 4],
            [3, 4, 2],
            [3, 2, 6],
            [3, 6, 8],
            [3, 8, 9],
            [4, 9, 5],
            [2, 4, 11],
            [6, 2, 10],
            [8, 6, 7],
            [9, 8, 1],
        ];
        for _ in 0..level {
            let mut midpoints = std::collections::HashMap::new();
            let mut mid = |a: u32, b: u32, dirs: &mut Vec<Vec3>| -> u32 {
                *midpoints.entry((a.min(b), a.max(b))).or_insert_with(|| {
                    dirs.push((dirs[a as usize] + dirs[b as usize]).normalize());
                    dirs.len() as u32 - 1
                })
            };
            let mut next = Vec::with_capacity(tris.len() * 4);
            for [a, b, c] in tris {
                let (ab, bc, ca) = (mid(a, b, &mut dirs), mid(b, c, &mut dirs), mid(c, a, &mut dirs));
                next.extend([[a, ab, ca], [b, bc, ab], [c, ca, bc], [ab, bc, ca]]);
            }
            tris = next;
        }
        Self {
            positions: dirs.iter().map(|d| center + *d * radius).collect(),
            normals: Some(dirs),
            indices: tris,
            uvs: None,
        }
    }

    /// A closed cylinder standing on `base` along +Y: `segments` side quads with smooth normals
    /// and two fan caps with flat normals (4 x `segments` triangles).
    #[must_use]
    pub fn cylinder(base: Vec3, radius: f32, height: f32, segments: u32) -> Self {
        let n = segments.max(3);
        let ring = |k: u32| {
            let a = std::f32::consts::TAU * k as f32 / n as f32;
            Vec3::new(a.sin(), 0.0, a.cos())
        };
        let up = Vec3::Y * height;
        let (mut positions, mut normals, mut indices) = (Vec::new(), Vec::new(), Vec::new());
        for k in 0..n {
            let d = ring(k);
            positions.extend([base + d * radius, base + d * radius + up]);
            normals.extend([d, d]);
        }
        for k in 0..n {
            let (a, b) = (2 * k, 2 * ((k + 1) % n));
            indices.push([a, b, b + 1]);
            indices.push([a, b + 1, a + 1]);
        }
        for (y, normal) in [(Vec3::ZERO, Vec3::NEG_Y), (up, Vec3::Y)] {
            let centre = positions.len() as u32;
            positions.push(base + y);
            normals.push(normal);
            for k in 0..n {
                positions.push(base + y + ring(k) * radius);
                normals.push(normal);
            }
            for k in 0..n {
                let (a, b) = (centre + 1 + k, centre + 1 + (k + 1) % n);
                indices.push(if normal.y > 0.0 { [centre, a, b] } else { [centre, b, a] });
            }
        }
        Self { positions, normals: Some(normals), indices, uvs: None }
    }
}
