//! Built-in synthetic objects: what is composited into the photograph, with the simplified mesh
//! its shadows are cast from (paper 003, Section 7.2: 100-500 triangles).

use glam::Vec3;
use scene::Mesh;
use shaft_hierarchy::Aabb;

use crate::CompositeError;

/// Names accepted by [`SyntheticObject::builtin`].
pub const BUILTIN_OBJECTS: &[&str] = &["sphere", "box"];

/// A synthetic object placed in the scene: a Lambertian mesh.
#[derive(Clone, Debug)]
pub struct SyntheticObject {
    /// Its name.
    pub name: String,
    /// The mesh it is shaded and ray traced with, in world coordinates.
    pub mesh: Mesh,
    /// Its Lambertian albedo.
    pub albedo: Vec3,
    /// Its centre.
    pub centre: Vec3,
}

/// Radius of the built-in sphere and half the side of the built-in box, metres.
pub const SIZE: f32 = 0.3;

impl SyntheticObject {
    /// A built-in object centred at `centre` (world coordinates): `sphere` (radius 0.3 m, 484
    /// triangles, as paper 003's Figure 9) or `box` (a 0.6 m cube).
    ///
    /// # Errors
    /// [`CompositeError::UnknownObject`] for another name; [`CompositeError::Parameter`] for a
    /// centre that is not finite.
    pub fn builtin(name: &str, centre: Vec3) -> Result<Self, CompositeError> {
        if !centre.is_finite() {
            return Err(CompositeError::Parameter(format!("object centre {centre} is not finite")));
        }
        let mesh = match name {
            "sphere" => uv_sphere(centre, SIZE, 22, 12),
            "box" => Mesh::cuboid(centre - Vec3::splat(SIZE), centre + Vec3::splat(SIZE)),
            _ => return Err(CompositeError::UnknownObject(name.to_string())),
        };
        Ok(Self { name: name.to_string(), mesh, albedo: Vec3::new(0.7, 0.7, 0.65), centre })
    }

    /// The mesh its shadows are cast from: the sphere at `detail` (slices; stacks half that,
    /// about detail^2 triangles), the box as it is. The knob of paper 003's simplified objects.
    #[must_use]
    pub fn shadow_mesh(&self, detail: u32) -> Mesh {
        if self.name == "sphere" {
            let slices = detail.max(3);
            uv_sphere(self.centre, SIZE, slices, (slices / 2).max(2))
        } else {
            self.mesh.clone()
        }
    }

    /// The mesh's bounds.
    #[must_use]
    pub fn bounds(&self) -> Aabb {
        self.mesh.positions.iter().fold(Aabb::EMPTY, |b, &p| b.union(&Aabb::new(p, p)))
    }

    /// The object as a scene object (for the path tracer and the G-buffer).
    #[must_use]
    pub fn to_object(&self) -> scene::Object {
        scene::Object {
            name: self.name.clone(),
            mesh: self.mesh.clone(),
            material: scene::Material { albedo: self.albedo, specular: None },
        }
    }
}

/// A latitude-longitude sphere: `slices` around, `stacks` from pole to pole, smooth normals;
/// 2 slices (stacks - 1) triangles.
#[must_use]
pub fn uv_sphere(centre: Vec3, radius: f32, slices: u32, stacks: u32) -> Mesh {
    let (slices, stacks) = (slices.max(3), stacks.max(2));
    let mut dirs = vec![Vec3::Y];
    for i in 1..stacks {
        let theta = std::f32::consts::PI * i as f32 / stacks as f32;
        for j in 0..slices {
            let phi = std::f32::consts::TAU * j as f32 / slices as f32;
            dirs.push(Vec3::new(theta.sin() * phi.cos(), theta.cos(), theta.sin() * phi.sin()));
        }
    }
    dirs.push(Vec3::NEG_Y);
    let bottom = dirs.len() as u32 - 1;
    let ring = |i: u32, j: u32| 1 + (i - 1) * slices + j % slices;
    let mut indices = Vec::new();
    for j in 0..slices {
        // outward winding (counter-clockwise seen from outside)
        indices.push([0, ring(1, j + 1), ring(1, j)]);
        indices.push([bottom, ring(stacks - 1, j), ring(stacks - 1, j + 1)]);
    }
    for i in 1..stacks - 1 {
        for j in 0..slices {
            let (a, b, c, d) = (ring(i, j), ring(i, j + 1), ring(i + 1, j + 1), ring(i + 1, j));
            indices.push([a, b, c]);
            indices.push([a, c, d]);
        }
    }
    Mesh { positions: dirs.iter().map(|d| centre + *d * radius).collect(), normals: Some(dirs), indices }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn builtins_are_closed_outward_and_the_papers_size() {
        for name in BUILTIN_OBJECTS {
            let o = SyntheticObject::builtin(name, Vec3::new(1.0, 0.3, -2.0)).unwrap_or_else(|e| panic!("{e}"));
            o.mesh.validate().unwrap_or_else(|e| panic!("{name}: {e}"));
            // outward: every face normal points away from the centre
            for t in 0..o.mesh.indices.len() {
                let [a, b, c] = o.mesh.triangle(t);
                let n = (b - a).cross(c - a);
                assert!(n.dot((a + b + c) / 3.0 - o.centre) > 0.0, "{name}: face {t} inward");
            }
            // closed: the divergence theorem gives the volume
            let volume: f32 = (0..o.mesh.indices.len())
                .map(|t| {
                    let [a, b, c] = o.mesh.triangle(t).map(|p| p - o.centre);
                    a.dot(b.cross(c)) / 6.0
                })
                .sum();
            let exact =
                if *name == "sphere" { 4.0 / 3.0 * std::f32::consts::PI * SIZE.powi(3) } else { (2.0 * SIZE).powi(3) };
            assert!((volume / exact - 1.0).abs() < 0.05, "{name}: volume {volume} vs {exact}");
        }
        let sphere = SyntheticObject::builtin("sphere", Vec3::ZERO).unwrap_or_else(|e| panic!("{e}"));
        assert_eq!(sphere.mesh.indices.len(), 484, "paper 003's 100-500 triangles");
        assert_eq!(sphere.shadow_mesh(10).indices.len(), 2 * 10 * 4);
        assert!(matches!(SyntheticObject::builtin("teapot", Vec3::ZERO), Err(CompositeError::UnknownObject(_))));
        assert!(matches!(SyntheticObject::builtin("box", Vec3::NAN), Err(CompositeError::Parameter(_))));
    }
}
