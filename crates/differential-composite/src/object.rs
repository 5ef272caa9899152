//! Synthetic objects, built in or a user's model: what is composited into the photograph, with
//! the simplified mesh its shadows are cast from (paper 003, Section 7.2: 100-500 triangles).

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
    /// What it is, which decides its shadow mesh.
    pub shape: Shape,
}

/// What a synthetic object is.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Shape {
    /// The built-in sphere: its shadow mesh is re-tessellated at the asked detail.
    Sphere,
    /// The built-in box.
    Box,
    /// A user's model: its shadow mesh is its own mesh.
    Model,
}

/// Where and how large [`SyntheticObject::open_placed`] puts an object.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ObjectPlacement {
    /// Where its bounding box's bottom centre goes (y = 0: standing on the ground).
    pub at: Vec3,
    /// Its size times this.
    pub scale: f32,
    /// A turn about the vertical, degrees (counter-clockwise seen from above).
    pub rotate_y_degrees: f32,
    /// Fit a model's largest side to this many metres first (`None`: the model's own size;
    /// built-ins keep theirs either way).
    pub size: Option<f32>,
}

impl ObjectPlacement {
    /// Standing at `at`, as it is.
    #[must_use]
    pub fn at(at: Vec3) -> Self {
        Self { at, scale: 1.0, rotate_y_degrees: 0.0, size: None }
    }

    fn check(&self) -> Result<(), CompositeError> {
        let size_ok = self.size.is_none_or(|s| s.is_finite() && s > 0.0);
        let finite = self.at.is_finite() && self.scale.is_finite() && self.rotate_y_degrees.is_finite();
        if !(finite && self.scale > 0.0 && size_ok) {
            return Err(CompositeError::Parameter(format!(
                "placement at {}, scale {}, rotation {} degrees, size {:?}: positions finite, scale and size positive",
                self.at, self.scale, self.rotate_y_degrees, self.size
            )));
        }
        Ok(())
    }
}

/// Radius of the built-in sphere and half the side of the built-in box, metres.
pub const SIZE: f32 = 0.3;

/// The side of the cube a model is fitted into by default: the built-ins' size (0.6 m).
pub const MODEL_SIZE: f32 = 2.0 * SIZE;

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
        let (mesh, shape) = match name {
            "sphere" => (uv_sphere(centre, SIZE, 22, 12), Shape::Sphere),
            "box" => (Mesh::cuboid(centre - Vec3::splat(SIZE), centre + Vec3::splat(SIZE)), Shape::Box),
            _ => return Err(CompositeError::UnknownObject(name.to_string())),
        };
        Ok(Self { name: name.to_string(), mesh, albedo: Vec3::new(0.7, 0.7, 0.65), centre, shape })
    }

    /// A built-in object's name or a glTF model's path (see [`scene::is_model`]): the built-in
    /// centred at `centre`, the model fitted by [`SyntheticObject::from_scene`] into a cube of
    /// side `model_size` centred there. What the compositor does not model comes back as
    /// warnings, with the import's own.
    ///
    /// # Errors
    /// As [`SyntheticObject::builtin`] and [`SyntheticObject::from_scene`]; a model that
    /// cannot be imported ([`CompositeError::Model`], naming the file).
    pub fn open(spec: &str, centre: Vec3, model_size: f32) -> Result<(Self, Vec<String>), CompositeError> {
        if !scene::is_model(spec) {
            return Ok((Self::builtin(spec, centre)?, Vec::new()));
        }
        let (model, mut all) = scene::Scene::open(spec, &scene::import::GltfOptions::default())?;
        let name =
            std::path::Path::new(spec).file_stem().map_or_else(|| spec.to_string(), |s| s.to_string_lossy().into());
        let (object, mut warnings) = Self::from_scene(&name, &model, centre, model_size)?;
        all.append(&mut warnings);
        Ok((object, all))
    }

    /// A scene's objects as one synthetic object: uniformly scaled so that the largest side of
    /// its bounding box is `size`, centred at `centre` across (x, z) and resting on the bottom
    /// of the `size` cube centred there (at `centre.y - size / 2`, where the built-ins rest),
    /// so that the default position sets it on the floor. The compositor shades one Lambertian
    /// material: the albedo is the objects' area-weighted mean, and what that leaves out
    /// (specular layers, the scene's point lights) is returned as warnings.
    ///
    /// # Errors
    /// [`CompositeError::Parameter`] for a centre or size that is not finite and positive, or
    /// a scene without triangles or without extent.
    pub fn from_scene(
        name: &str,
        scene: &scene::Scene,
        centre: Vec3,
        size: f32,
    ) -> Result<(Self, Vec<String>), CompositeError> {
        if !centre.is_finite() {
            return Err(CompositeError::Parameter(format!("object centre {centre} is not finite")));
        }
        if !(size.is_finite() && size > 0.0) {
            return Err(CompositeError::Parameter(format!("object size {size} is not finite and positive")));
        }
        let mut mesh = Mesh::default();
        let (mut weighted, mut area) = (Vec3::ZERO, 0.0f64);
        for o in &scene.objects {
            mesh.append(&o.mesh);
            let a = f64::from(o.mesh.area());
            if a.is_finite() {
                weighted += o.material.albedo * a as f32;
                area += a;
            }
        }
        if mesh.indices.is_empty() {
            return Err(CompositeError::Parameter(format!("{name}: no triangles to composite")));
        }
        let (lo, hi) =
            mesh.positions.iter().fold((Vec3::INFINITY, Vec3::NEG_INFINITY), |(lo, hi), &p| (lo.min(p), hi.max(p)));
        let extent = (hi - lo).max_element();
        if !(extent.is_finite() && extent > 0.0) {
            return Err(CompositeError::Parameter(format!("{name}: extent {extent} cannot be fitted")));
        }
        let scale = size / extent;
        // the bounding box's bottom centre goes to the bottom centre of the cube
        let anchor = Vec3::new(0.5 * (lo.x + hi.x), lo.y, 0.5 * (lo.z + hi.z));
        let target = centre - Vec3::new(0.0, 0.5 * size, 0.0);
        mesh.transform(&glam::Affine3A::from_scale_rotation_translation(
            Vec3::splat(scale),
            glam::Quat::IDENTITY,
            target - anchor * scale,
        ));
        let albedo = if area > 0.0 { weighted / area as f32 } else { Vec3::splat(0.5) };
        let mut warnings = Vec::new();
        let glossy = scene.objects.iter().filter(|o| o.material.specular.is_some()).count();
        if glossy > 0 {
            warnings.push(format!("{glossy} objects' specular layers are not composited (Lambertian only)"));
        }
        if !scene.point_lights.is_empty() {
            warnings.push(format!("its {} point lights are not composited", scene.point_lights.len()));
        }
        // the fitted bounding box's centre: half its height above the cube's floor
        let centre = target + Vec3::new(0.0, 0.5 * scale * (hi.y - lo.y), 0.0);
        Ok((
            Self {
                name: name.to_string(),
                mesh,
                albedo: albedo.clamp(Vec3::ZERO, Vec3::ONE),
                centre,
                shape: Shape::Model,
            },
            warnings,
        ))
    }

    /// A built-in object's name or a glTF model's path, placed as `placement` says: a model
    /// at its own size (glTF's metres) or fitted into `placement.size`, times
    /// `placement.scale`, turned about the vertical, its bounding box's bottom centre at
    /// `placement.at` (on the ground when its y is 0). What the compositor does not model comes
    /// back as warnings, with the import's own.
    ///
    /// # Errors
    /// As [`SyntheticObject::open`]; a placement that is not finite, or a scale or size that
    /// is not positive.
    pub fn open_placed(spec: &str, placement: &ObjectPlacement) -> Result<(Self, Vec<String>), CompositeError> {
        placement.check()?;
        let (object, warnings) = if scene::is_model(spec) {
            let (model, mut all) = scene::Scene::open(spec, &scene::import::GltfOptions::default())?;
            let name =
                std::path::Path::new(spec).file_stem().map_or_else(|| spec.to_string(), |s| s.to_string_lossy().into());
            let (lo, hi) = model
                .objects
                .iter()
                .flat_map(|o| &o.mesh.positions)
                .fold((Vec3::INFINITY, Vec3::NEG_INFINITY), |(lo, hi), &p| (lo.min(p), hi.max(p)));
            let extent = (hi - lo).max_element();
            let extent = if extent.is_finite() && extent > 0.0 { extent } else { 1.0 };
            let (object, mut warnings) = Self::from_scene(&name, &model, Vec3::new(0.0, 0.5 * extent, 0.0), extent)?;
            all.append(&mut warnings);
            (object, all)
        } else {
            (Self::builtin(spec, Vec3::new(0.0, SIZE, 0.0))?, Vec::new())
        };
        let (lo, hi) = object.extent();
        let fit = placement.size.map_or(1.0, |size| size / (hi - lo).max_element().max(f32::MIN_POSITIVE));
        Ok((object.transformed(fit * placement.scale, placement.rotate_y_degrees, placement.at)?, warnings))
    }

    /// The object scaled by `scale` and turned by `rotate_y_degrees` about the vertical through
    /// its bounding box's bottom centre, which then goes to `bottom`.
    ///
    /// # Errors
    /// [`CompositeError::Parameter`] for a scale that is not finite and positive, or an angle
    /// or position that is not finite.
    pub fn transformed(&self, scale: f32, rotate_y_degrees: f32, bottom: Vec3) -> Result<Self, CompositeError> {
        if !(scale.is_finite() && scale > 0.0 && rotate_y_degrees.is_finite() && bottom.is_finite()) {
            return Err(CompositeError::Parameter(format!(
                "object scale {scale}, rotation {rotate_y_degrees} degrees, position {bottom}: not finite and positive"
            )));
        }
        let (lo, hi) = self.extent();
        let anchor = Vec3::new(0.5 * (lo.x + hi.x), lo.y, 0.5 * (lo.z + hi.z));
        let t = glam::Affine3A::from_translation(bottom)
            * glam::Affine3A::from_rotation_y(rotate_y_degrees.to_radians())
            * glam::Affine3A::from_scale(Vec3::splat(scale))
            * glam::Affine3A::from_translation(-anchor);
        let mut out = self.clone();
        out.mesh.transform(&t);
        out.centre = t.transform_point3(self.centre);
        if !out.mesh.positions.iter().all(|p| p.is_finite()) {
            return Err(CompositeError::Parameter(format!("object scale {scale}: its positions overflow")));
        }
        Ok(out)
    }

    /// The mesh's bounding box (min, max).
    #[must_use]
    pub fn extent(&self) -> (Vec3, Vec3) {
        self.mesh.positions.iter().fold((Vec3::INFINITY, Vec3::NEG_INFINITY), |(lo, hi), &p| (lo.min(p), hi.max(p)))
    }

    /// The same object moved by `offset` (mesh and centre).
    #[must_use]
    pub fn moved(&self, offset: Vec3) -> Self {
        let mut moved = self.clone();
        moved.mesh.positions.iter_mut().for_each(|p| *p += offset);
        moved.centre += offset;
        moved
    }

    /// The mesh its shadows are cast from: the sphere at `detail` (slices; stacks half that,
    /// about detail^2 triangles), the box and a model as they are. The knob of paper 003's simplified objects.
    #[must_use]
    pub fn shadow_mesh(&self, detail: u32) -> Mesh {
        if self.shape == Shape::Sphere {
            let slices = detail.max(3);
            // its radius as placed (the built-in's, times any scale)
            let (lo, hi) = self.extent();
            uv_sphere(self.centre, 0.5 * (hi.x - lo.x), slices, (slices / 2).max(2))
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
            material: scene::Material::rgb(self.albedo, None),
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
    Mesh { positions: dirs.iter().map(|d| centre + *d * radius).collect(), normals: Some(dirs), indices, uvs: None }
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

    fn cube_object(name: &str, lo: Vec3, hi: Vec3, albedo: f32) -> scene::Object {
        scene::Object { name: name.into(), mesh: Mesh::cuboid(lo, hi), material: scene::Material::lambert(albedo) }
    }

    fn two_cubes(scale: f32) -> scene::Scene {
        let mut s = scene::Scene::builtin("three_boxes").unwrap_or_else(|e| panic!("{e}"));
        s.objects = vec![
            cube_object("small", Vec3::ZERO * scale, Vec3::ONE * scale, 0.2),
            cube_object("large", Vec3::new(3.0, 0.0, 0.0) * scale, Vec3::new(5.0, 2.0, 2.0) * scale, 0.8),
        ];
        s.point_lights.clear();
        s
    }

    fn bounds_of(m: &Mesh) -> (Vec3, Vec3) {
        m.positions.iter().fold((Vec3::INFINITY, Vec3::NEG_INFINITY), |(lo, hi), &p| (lo.min(p), hi.max(p)))
    }

    #[test]
    fn a_model_is_fitted_into_the_cube_on_its_floor_at_every_scale() {
        let centre = Vec3::new(2.5, 0.3, 2.0);
        for scale in [1e-4, 1.0, 1e6] {
            let (o, warnings) = SyntheticObject::from_scene("cubes", &two_cubes(scale), centre, MODEL_SIZE)
                .unwrap_or_else(|e| panic!("{e}"));
            assert!(warnings.is_empty(), "{warnings:?}");
            o.mesh.validate().unwrap_or_else(|e| panic!("scale {scale}: {e}"));
            assert_eq!(o.mesh.indices.len(), 24);
            let (lo, hi) = bounds_of(&o.mesh);
            let close = |a: f32, b: f32| (a - b).abs() < 1e-5;
            // the largest side (x: 5 units) is the size; the others keep their proportions
            assert!(close(hi.x - lo.x, MODEL_SIZE) && close(hi.y - lo.y, 0.4 * MODEL_SIZE), "scale {scale}: {lo} {hi}");
            // on the cube's floor, centred across it
            assert!(close(lo.y, centre.y - 0.5 * MODEL_SIZE), "scale {scale}: bottom {}", lo.y);
            assert!(close(0.5 * (lo.x + hi.x), centre.x) && close(0.5 * (lo.z + hi.z), centre.z), "{lo} {hi}");
            assert!((o.centre - 0.5 * (lo + hi)).length() < 1e-5);
            // area-weighted albedo: (0.2 * 6 + 0.8 * 24) / 30
            assert!((o.albedo - Vec3::splat(0.68)).abs().max_element() < 1e-5, "{}", o.albedo);
            assert_eq!(o.shape, Shape::Model);
            assert_eq!(o.shadow_mesh(4), o.mesh, "a model casts with its own mesh");
        }
    }

    #[test]
    fn a_model_fitted_at_the_builtins_size_is_the_builtin_box() {
        let centre = Vec3::new(-1.0, 0.3, 0.5);
        let builtin = SyntheticObject::builtin("box", centre).unwrap_or_else(|e| panic!("{e}"));
        let mut s = two_cubes(1.0);
        s.objects = vec![cube_object("box", Vec3::splat(-7.0), Vec3::splat(-4.0), 0.5)];
        let (o, _) = SyntheticObject::from_scene("box", &s, centre, MODEL_SIZE).unwrap_or_else(|e| panic!("{e}"));
        assert_eq!(o.mesh.indices, builtin.mesh.indices);
        for (a, b) in o.mesh.positions.iter().zip(&builtin.mesh.positions) {
            assert!((*a - *b).length() < 1e-6, "{a} vs {b}");
        }
        assert!((o.centre - builtin.centre).length() < 1e-6);
    }

    #[test]
    fn what_a_model_cannot_be_is_refused_and_what_is_left_out_is_said() {
        let good = two_cubes(1.0);
        for (centre, size) in [(Vec3::NAN, 0.6), (Vec3::ZERO, 0.0), (Vec3::ZERO, -1.0), (Vec3::ZERO, f32::INFINITY)] {
            assert!(matches!(SyntheticObject::from_scene("m", &good, centre, size), Err(CompositeError::Parameter(_))));
        }
        let mut empty = good.clone();
        empty.objects.clear();
        assert!(matches!(SyntheticObject::from_scene("m", &empty, Vec3::ZERO, 0.6), Err(CompositeError::Parameter(_))));
        let mut point = good.clone();
        point.objects[0].mesh.positions.iter_mut().for_each(|p| *p = Vec3::ONE);
        point.objects.truncate(1);
        assert!(matches!(SyntheticObject::from_scene("m", &point, Vec3::ZERO, 0.6), Err(CompositeError::Parameter(_))));
        let glossy = scene::Scene::builtin("glossy_set").unwrap_or_else(|e| panic!("{e}"));
        let (_, warnings) =
            SyntheticObject::from_scene("g", &glossy, Vec3::ZERO, 0.6).unwrap_or_else(|e| panic!("{e}"));
        assert!(warnings.iter().any(|w| w.contains("specular")), "{warnings:?}");
        let mut lit = good;
        lit.point_lights = vec![scene::PointLight::point(Vec3::Y, Vec3::ONE)];
        let (_, warnings) = SyntheticObject::from_scene("l", &lit, Vec3::ZERO, 0.6).unwrap_or_else(|e| panic!("{e}"));
        assert!(warnings.iter().any(|w| w.contains("1 point lights")), "{warnings:?}");
        // a moved object keeps its shape
        let b = SyntheticObject::builtin("box", Vec3::ZERO).unwrap_or_else(|e| panic!("{e}"));
        let m = b.moved(Vec3::X);
        assert_eq!(m.centre, Vec3::X);
        assert!(m.mesh.positions.iter().zip(&b.mesh.positions).all(|(p, q)| *p == *q + Vec3::X));
    }
}
