//! The procedural built-in scenes. No asset files: every scene is built from `Mesh` shapes.

use crate::{Camera, Ggx, Material, Mesh, Object, PointLight, Scene, SceneError};
use glam::Vec3;

/// Names of the built-in scenes.
pub const BUILTIN_SCENES: [&str; 6] = ["spheres_box", "three_boxes", "column", "glossy_set", "room", "gallery"];

/// Subdivision level of the `spheres_box` sphere: 20 x 4^5 = 20,480 triangles. Its largest
/// deviation from the true sphere is 0.15 mm, under 0.02 pixel at 640 x 480 (a test checks).
pub const SPHERES_BOX_SPHERE_LEVEL: u32 = 5;

fn object(name: &str, mesh: Mesh, material: Material) -> Object {
    Object { name: name.into(), mesh, material }
}

/// Ground square at y = 0, x and z in [-half, half], normal +Y.
fn ground(half: f32) -> Mesh {
    Mesh::quad(Vec3::new(-half, 0.0, half), Vec3::new(2.0 * half, 0.0, 0.0), Vec3::new(0.0, 0.0, -2.0 * half), 1, 1)
}

fn camera(eye: Vec3, target: Vec3, hfov_degrees: f32) -> Camera {
    Camera { eye, target, up: Vec3::Y, hfov_degrees, width: 640, height: 480 }
}

impl Scene {
    /// A built-in scene by name (see [`BUILTIN_SCENES`]).
    ///
    /// # Errors
    /// [`SceneError::Unknown`] for any other name.
    pub fn builtin(name: &str) -> Result<Self, SceneError> {
        let scene = match name {
            "spheres_box" => spheres_box(),
            "three_boxes" => three_boxes(),
            "column" => column(),
            "glossy_set" => glossy_set(),
            "room" => room(),
            "gallery" => gallery(),
            _ => return Err(SceneError::Unknown { name: name.into() }),
        };
        Ok(scene)
    }
}

/// The validation scene, exactly as specified: ground square, a sphere and a box, all
/// Lambertian, lit only by the environment map.
fn spheres_box() -> Scene {
    Scene {
        name: "spheres_box".into(),
        objects: vec![
            object("ground", ground(50.0), Material::lambert(0.5)),
            object(
                "sphere",
                Mesh::icosphere(Vec3::new(-1.0, 1.0, 0.0), 1.0, SPHERES_BOX_SPHERE_LEVEL),
                Material::lambert(0.8),
            ),
            object("box", Mesh::cuboid(Vec3::new(0.5, 0.0, -0.5), Vec3::new(1.5, 2.0, 0.5)), Material::lambert(0.8)),
        ],
        camera: camera(Vec3::new(0.5, 2.5, 7.0), Vec3::new(0.0, 0.9, 0.0), 40.0),
        point_lights: vec![],
        textures: Vec::new(),
    }
}

/// Paper 000's first test scene: a ground quad and three boxes, 38 triangles.
fn three_boxes() -> Scene {
    let boxes = [
        (Vec3::new(-2.2, 0.0, -0.6), Vec3::new(-1.2, 1.0, 0.4)),
        (Vec3::new(-0.5, 0.0, -1.5), Vec3::new(0.5, 2.0, -0.5)),
        (Vec3::new(1.0, 0.0, 0.2), Vec3::new(2.4, 0.6, 1.2)),
    ];
    let mut objects = vec![object("ground", ground(10.0), Material::lambert(0.5))];
    for (k, (lo, hi)) in boxes.into_iter().enumerate() {
        objects.push(object(&format!("box{}", k + 1), Mesh::cuboid(lo, hi), Material::lambert(0.7)));
    }
    Scene {
        name: "three_boxes".into(),
        objects,
        camera: camera(Vec3::new(0.0, 3.5, 7.5), Vec3::new(0.0, 0.5, 0.0), 45.0),
        point_lights: vec![],
        textures: Vec::new(),
    }
}

/// Paper 000's second scene: a ground quad and a column, 442 triangles.
fn column() -> Scene {
    Scene {
        name: "column".into(),
        objects: vec![
            object("ground", ground(10.0), Material::lambert(0.5)),
            object("column", Mesh::cylinder(Vec3::ZERO, 0.4, 3.0, 110), Material::lambert(0.75)),
        ],
        camera: camera(Vec3::new(2.5, 3.0, 6.5), Vec3::new(0.0, 1.2, 0.0), 45.0),
        point_lights: vec![],
        textures: Vec::new(),
    }
}

/// Objects from diffuse to semi-glossy on a diffuse ground (like paper 001's test scenes).
fn glossy_set() -> Scene {
    let ggx = |roughness: f32, f0: f32| Some(Ggx { roughness, f0: Vec3::splat(f0) });
    Scene {
        name: "glossy_set".into(),
        objects: vec![
            object("ground", ground(20.0), Material::lambert(0.5)),
            object(
                "diffuse_sphere",
                Mesh::icosphere(Vec3::new(-2.4, 0.7, 0.0), 0.7, 4),
                Material::rgb(Vec3::new(0.8, 0.3, 0.25), None),
            ),
            object(
                "rough_sphere",
                Mesh::icosphere(Vec3::new(-0.8, 0.7, 0.0), 0.7, 4),
                Material::rgb(Vec3::new(0.3, 0.7, 0.3), ggx(0.6, 0.04)),
            ),
            object(
                "semi_glossy_sphere",
                Mesh::icosphere(Vec3::new(0.8, 0.7, 0.0), 0.7, 4),
                Material::rgb(Vec3::new(0.25, 0.35, 0.8), ggx(0.3, 0.04)),
            ),
            object(
                "glossy_box",
                Mesh::cuboid(Vec3::new(1.9, 0.0, -0.6), Vec3::new(3.1, 1.2, 0.6)),
                Material::rgb(Vec3::splat(0.2), ggx(0.2, 0.5)),
            ),
        ],
        camera: camera(Vec3::new(0.0, 2.6, 7.5), Vec3::new(0.0, 0.6, 0.0), 45.0),
        point_lights: vec![],
        textures: Vec::new(),
    }
}

/// Paper 001's scale for timing (its Unity scene has 161.8k triangles): 161,794 triangles of
/// diffuse to glossy, dielectric and metal objects on a diffuse ground. Six level-5 spheres
/// (20,480 triangles each) from Lambertian to polished metal, two 4096-segment columns and two
/// finely tessellated boxes.
fn gallery() -> Scene {
    let ggx = |roughness: f32, f0: Vec3| Some(Ggx { roughness, f0 });
    let dielectric = Vec3::splat(0.04);
    let gold = Vec3::new(1.0, 0.78, 0.34);
    let silver = Vec3::new(0.97, 0.96, 0.91);
    let spheres = [
        ("diffuse_sphere", Material::rgb(Vec3::new(0.8, 0.35, 0.3), None)),
        ("rough_sphere", Material::rgb(Vec3::new(0.3, 0.7, 0.35), ggx(0.7, dielectric))),
        ("semi_glossy_sphere", Material::rgb(Vec3::new(0.3, 0.4, 0.8), ggx(0.35, dielectric))),
        ("glossy_sphere", Material::rgb(Vec3::splat(0.7), ggx(0.15, dielectric))),
        ("rough_gold_sphere", Material::rgb(Vec3::ZERO, ggx(0.5, gold))),
        ("polished_silver_sphere", Material::rgb(Vec3::ZERO, ggx(0.2, silver))),
    ];
    let mut objects = vec![object("ground", ground(20.0), Material::lambert(0.5))];
    for (k, (name, material)) in spheres.into_iter().enumerate() {
        let (x, z) = (-3.75 + 1.5 * k as f32, if k % 2 == 0 { 0.6 } else { -0.6 });
        objects.push(object(name, Mesh::icosphere(Vec3::new(x, 0.6, z), 0.6, 5), material));
    }
    for (k, x) in [-4.3f32, 4.3].into_iter().enumerate() {
        let column = Mesh::cylinder(Vec3::new(x, 0.0, -2.0), 0.35, 3.0, 4096);
        objects.push(object(&format!("column{}", k + 1), column, Material::lambert(0.75)));
    }
    let boxes = [
        (Vec3::new(-2.5, 0.0, -3.0), Vec3::new(-1.0, 1.2, -2.0), Material::lambert(0.6)),
        (
            Vec3::new(1.0, 0.0, -3.2),
            Vec3::new(2.6, 0.8, -2.2),
            Material::rgb(Vec3::splat(0.25), ggx(0.3, Vec3::splat(0.5))),
        ),
    ];
    for (k, (lo, hi, material)) in boxes.into_iter().enumerate() {
        objects.push(object(&format!("box{}", k + 1), Mesh::tessellated_cuboid(lo, hi, 16), material));
    }
    Scene {
        name: "gallery".into(),
        objects,
        camera: camera(Vec3::new(0.0, 2.8, 8.5), Vec3::new(0.0, 0.6, -0.5), 55.0),
        point_lights: vec![],
        textures: Vec::new(),
    }
}

/// A closed 8 x 4 x 8 m room with finely tessellated inward-facing walls (16 x 16 cells each),
/// a few objects, and a point light at its centre (paper 004).
fn room() -> Scene {
    let walls = Mesh::tessellated_cuboid(Vec3::new(-4.0, 0.0, -4.0), Vec3::new(4.0, 4.0, 4.0), 16).flipped();
    Scene {
        name: "room".into(),
        objects: vec![
            object("walls", walls, Material::lambert(0.7)),
            object(
                "table",
                Mesh::cuboid(Vec3::new(-2.5, 0.0, -1.0), Vec3::new(-0.5, 0.8, 0.5)),
                Material::lambert(0.6),
            ),
            object("ball", Mesh::icosphere(Vec3::new(1.5, 0.6, 1.0), 0.6, 3), Material::lambert(0.8)),
            object("pillar", Mesh::cylinder(Vec3::new(2.0, 0.0, -2.5), 0.3, 3.2, 32), Material::lambert(0.8)),
        ],
        camera: camera(Vec3::new(3.6, 3.2, 3.6), Vec3::new(-0.5, 1.0, -0.5), 70.0),
        point_lights: vec![PointLight::point(Vec3::new(0.0, 2.0, 0.0), Vec3::splat(10.0))],
        textures: Vec::new(),
    }
}
