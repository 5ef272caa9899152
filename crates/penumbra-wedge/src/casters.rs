//! Casters with edge adjacency, and their silhouettes from a light's centre.
//!
//! Each object's mesh is welded by exact vertex position (flat-shaded meshes repeat corners per
//! face). A mesh whose every edge joins exactly two faces wound oppositely is **closed**: only
//! its faces that face the light cast, and its silhouette is where lit faces meet unlit ones.
//! Any other mesh (the ground quad, a non-manifold or inconsistently wound mesh) casts as a
//! **two-sided sheet**: every face casts with the winding of its side that faces the light. That
//! is exact for open surfaces and never garbage for broken ones; where such a surface folds, two
//! layers cover the light and the wedge sum counts them twice (clamped; the overlap artefact).
//!
//! Silhouette edges are oriented as their lit face winds, so that seen from the light the lit
//! region lies to their left; the hard volume and the wedges use that one orientation. Each edge
//! keeps the normals of its lit and unlit face: a receiver in front of the lit face and behind
//! the unlit one (a light straddling the lit face's plane, e.g. the ground and a light at the
//! horizon) sees the edge's outline mirrored, and the wedge term flips its sign there
//! (`coverage::oriented_edge_term`).

use glam::{Affine3A, Vec3};
use gpu::LightShape;
use std::borrow::Cow;
use std::collections::HashMap;

/// One object's welded mesh.
#[derive(Clone, Debug)]
pub struct Caster {
    /// The object's name.
    pub name: String,
    /// Welded positions, object space (as the mesh was given).
    pub positions: Vec<Vec3>,
    /// Non-degenerate triangles over `positions`.
    pub triangles: Vec<[u32; 3]>,
    /// Closed and consistently wound (see the module doc); else it casts as a two-sided sheet.
    pub closed: bool,
    /// Bounding sphere (centre, radius), object space.
    pub bounds: (Vec3, f32),
    /// Object space to world: where the caster is ([`crate::Wedges::set_transform`]).
    pub transform: Affine3A,
}

impl Caster {
    /// Welds `positions` / `indices` and classifies the result.
    #[must_use]
    pub fn new(name: &str, positions: &[Vec3], indices: &[[u32; 3]]) -> Self {
        let mut welded: Vec<Vec3> = Vec::new();
        let mut index: HashMap<[u32; 3], u32> = HashMap::new();
        // +0.0 makes -0.0 and 0.0 one key
        let key = |p: Vec3| [(p.x + 0.0).to_bits(), (p.y + 0.0).to_bits(), (p.z + 0.0).to_bits()];
        let remap: Vec<u32> = positions
            .iter()
            .map(|&p| {
                *index.entry(key(p)).or_insert_with(|| {
                    welded.push(p);
                    (welded.len() - 1) as u32
                })
            })
            .collect();
        let triangles: Vec<[u32; 3]> = indices
            .iter()
            .filter(|t| t.iter().all(|&i| (i as usize) < remap.len()))
            .map(|t| t.map(|i| remap[i as usize]))
            .filter(|&[a, b, c]| {
                let [pa, pb, pc] = [a, b, c].map(|i| welded[i as usize]);
                a != b && b != c && a != c && (pb - pa).cross(pc - pa).length_squared() > 0.0
            })
            .collect();
        // per undirected edge: (faces winding it low -> high, faces winding it high -> low)
        let mut edges: HashMap<(u32, u32), (u32, u32)> = HashMap::new();
        for t in &triangles {
            for k in 0..3 {
                let (a, b) = (t[k], t[(k + 1) % 3]);
                let e = edges.entry((a.min(b), a.max(b))).or_default();
                if a < b {
                    e.0 += 1;
                } else {
                    e.1 += 1;
                }
            }
        }
        let closed = !triangles.is_empty() && edges.values().all(|&c| c == (1, 1));
        let (lo, hi) = welded
            .iter()
            .fold((Vec3::splat(f32::INFINITY), Vec3::splat(f32::NEG_INFINITY)), |(lo, hi), p| (lo.min(*p), hi.max(*p)));
        let center = if lo.is_finite() { 0.5 * (lo + hi) } else { Vec3::ZERO };
        let radius = welded.iter().map(|p| p.distance(center)).fold(0.0, f32::max);
        Self {
            name: name.into(),
            positions: welded,
            triangles,
            closed,
            bounds: (center, radius),
            transform: Affine3A::IDENTITY,
        }
    }

    /// The bounding sphere where the transform puts the caster.
    #[must_use]
    pub fn world_bounds(&self) -> (Vec3, f32) {
        gpu::placement::transform_sphere(&self.transform, self.bounds)
    }

    /// The welded positions where the transform puts them (borrowed for the identity).
    #[must_use]
    pub fn world_positions(&self) -> Cow<'_, [Vec3]> {
        if self.transform == Affine3A::IDENTITY {
            Cow::Borrowed(&self.positions)
        } else {
            Cow::Owned(self.positions.iter().map(|&p| self.transform.transform_point3(p)).collect())
        }
    }
}

/// Every object of a scene as a caster.
#[derive(Clone, Debug)]
pub struct Casters {
    /// One per object, in the scene's order.
    pub casters: Vec<Caster>,
}

/// A light's silhouette and lit faces for a set of casters.
#[derive(Clone, Debug, Default)]
pub struct Silhouette {
    /// Oriented silhouette edges (lit region to the left seen from the light).
    pub edges: Vec<[Vec3; 2]>,
    /// Per edge (the same order), the unit normals of the lit face it bounds (on the side
    /// facing the light) and of the unlit face beyond it (zero for a sheet's edge); sums
    /// normalised where several faces wind it.
    pub normals: Vec<[Vec3; 2]>,
    /// The faces that cast, wound to face the light: the hard volume's front cap.
    pub lit_faces: Vec<[Vec3; 3]>,
}

impl Casters {
    /// The casters of `scene`, one per object.
    #[must_use]
    pub fn new(scene: &scene::Scene) -> Self {
        Self {
            casters: scene.objects.iter().map(|o| Caster::new(&o.name, &o.mesh.positions, &o.mesh.indices)).collect(),
        }
    }

    /// Names of the objects that cast as two-sided sheets (not closed).
    #[must_use]
    pub fn open(&self) -> Vec<&str> {
        self.casters.iter().filter(|c| !c.closed).map(|c| c.name.as_str()).collect()
    }

    /// The silhouette of the casters `keep` accepts, from `light`'s centre.
    #[must_use]
    pub fn silhouette(&self, light: &LightShape, keep: impl FnMut(&Caster) -> bool) -> Silhouette {
        let mut out = Silhouette::default();
        for (_, s) in self.silhouettes(light, keep) {
            out.edges.extend(s.edges);
            out.normals.extend(s.normals);
            out.lit_faces.extend(s.lit_faces);
        }
        out
    }

    /// The silhouette of each caster `keep` accepts, with the caster.
    #[must_use]
    pub fn silhouettes(&self, light: &LightShape, mut keep: impl FnMut(&Caster) -> bool) -> Vec<(&Caster, Silhouette)> {
        self.casters.iter().filter(|c| keep(c)).map(|c| (c, silhouette_of(c, light))).collect()
    }
}

/// Whether a face with unit-free normal `n` through `a` faces the light's centre: > 0 faces,
/// < 0 faces away, 0 edge-on.
fn facing(n: Vec3, a: Vec3, light: &LightShape) -> f32 {
    match *light {
        LightShape::Distant { direction, .. } => n.dot(direction),
        LightShape::Sphere { center, .. } => n.dot(center - a),
    }
}

fn silhouette_of(c: &Caster, light: &LightShape) -> Silhouette {
    let mut out = Silhouette::default();
    let positions = c.world_positions();
    // net directed count per undirected edge: +1 per lit face winding it low -> high, and the
    // sums of its lit faces' unit normals (facing the light) and its unlit ones'
    let mut net: HashMap<(u32, u32), (i32, Vec3, Vec3)> = HashMap::new();
    for &[a, b, cc] in &c.triangles {
        let [pa, pb, pc] = [a, b, cc].map(|i| positions[i as usize]);
        let f = facing((pb - pa).cross(pc - pa), pa, light);
        let tri = if f > 0.0 {
            [a, b, cc]
        } else if f < 0.0 && !c.closed {
            [a, cc, b]
        } else {
            // a closed mesh's unlit (or edge-on) face; a sheet has none
            if c.closed {
                let normal = (pb - pa).cross(pc - pa).normalize_or_zero();
                for (u, v) in [(a, b), (b, cc), (cc, a)] {
                    net.entry((u.min(v), u.max(v))).or_insert((0, Vec3::ZERO, Vec3::ZERO)).2 += normal;
                }
            }
            continue;
        };
        let face = tri.map(|i| positions[i as usize]);
        let normal = (face[1] - face[0]).cross(face[2] - face[0]).normalize_or_zero();
        out.lit_faces.push(face);
        for k in 0..3 {
            let (u, v) = (tri[k], tri[(k + 1) % 3]);
            let e = net.entry((u.min(v), u.max(v))).or_insert((0, Vec3::ZERO, Vec3::ZERO));
            e.0 += if u < v { 1 } else { -1 };
            e.1 += normal;
        }
    }
    let mut keys: Vec<_> = net.into_iter().filter(|&(_, (n, _, _))| n != 0).collect();
    // a fixed order: the GPU sums edge terms in draw order
    keys.sort_unstable_by_key(|&(k, _)| k);
    for ((lo, hi), (n, lit, unlit)) in keys {
        let (a, b) = if n > 0 { (lo, hi) } else { (hi, lo) };
        for _ in 0..n.unsigned_abs() {
            out.edges.push([positions[a as usize], positions[b as usize]]);
            out.normals.push([lit.normalize_or_zero(), unlit.normalize_or_zero()]);
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    fn cube() -> scene::Mesh {
        scene::Mesh::cuboid(Vec3::ZERO, Vec3::ONE)
    }

    #[test]
    fn cuboid_welds_closed_and_ground_quad_is_open() {
        let c = cube();
        let caster = Caster::new("box", &c.positions, &c.indices);
        assert!(caster.closed);
        assert_eq!(caster.positions.len(), 8);
        let q = scene::Mesh::quad(Vec3::ZERO, Vec3::X, Vec3::Z, 2, 2);
        assert!(!Caster::new("ground", &q.positions, &q.indices).closed);
    }

    #[test]
    fn cube_silhouette_from_above_is_its_top_square_counter_clockwise() {
        let c = cube();
        let casters = Casters { casters: vec![Caster::new("box", &c.positions, &c.indices)] };
        let light = LightShape::Distant { direction: Vec3::Y, half_angle: 0.01 };
        let s = casters.silhouette(&light, |_| true);
        assert_eq!(s.edges.len(), 4);
        assert_eq!(s.lit_faces.len(), 2);
        // seen from above (+y), counter-clockwise in (x, -z) = (x, y') coordinates: the signed
        // area of the loop about its centre is positive
        let centre = Vec3::new(0.5, 1.0, 0.5);
        let area: f32 = s.edges.iter().map(|[a, b]| (*a - centre).cross(*b - centre).y).sum();
        assert!(area > 0.0, "{area}");
        for [a, b] in &s.edges {
            assert!((a.y - 1.0).abs() < 1e-6 && (b.y - 1.0).abs() < 1e-6);
        }
        // lit: the top; unlit: the side face below the edge, facing away from the edge's middle
        assert_eq!(s.normals.len(), s.edges.len());
        for ([a, b], [lit, unlit]) in s.edges.iter().zip(&s.normals) {
            assert!(lit.distance(Vec3::Y) < 1e-6, "{lit}");
            let out = (0.5 * (*a + *b) - centre).normalize();
            assert!(unlit.distance(out) < 1e-6, "{unlit} for the edge {a} -> {b}");
        }
    }

    #[test]
    fn open_sheet_casts_from_either_side_with_the_same_outline() {
        let q = scene::Mesh::quad(Vec3::ZERO, Vec3::X, Vec3::Z, 3, 3);
        let casters = Casters { casters: vec![Caster::new("ground", &q.positions, &q.indices)] };
        for d in [Vec3::Y, Vec3::NEG_Y] {
            let s = casters.silhouette(&LightShape::Distant { direction: d, half_angle: 0.1 }, |_| true);
            assert_eq!(s.edges.len(), 12, "the 3 x 3 grid's boundary");
            assert_eq!(s.lit_faces.len(), 18);
            let area: f32 = s.edges.iter().map(|[a, b]| a.cross(*b).dot(d)).sum();
            assert!(area > 0.0, "counter-clockwise seen from the light at {d}: {area}");
            assert!(s.normals.iter().all(|[lit, unlit]| lit.distance(d) < 1e-6 && *unlit == Vec3::ZERO));
        }
    }
}
