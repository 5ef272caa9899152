//! Emitting surfaces in `PathEmissive`: the closed-box furnace per bounce depth, one-sidedness,
//! and that `Path` is unchanged by them.

use glam::Vec3;
use ref_tracer::{Emitters, EnvLight, Integrator, RenderSettings, SceneBvh, render};
use scene::{Camera, Material, Mesh, Object, Scene};

/// Inside a closed unit box whose walls face inwards, all of albedo `a`, emitting `le`.
fn furnace(a: f32) -> Scene {
    Scene {
        name: "furnace".into(),
        objects: vec![Object {
            name: "box".into(),
            mesh: Mesh::tessellated_cuboid(Vec3::ZERO, Vec3::ONE, 3).flipped(),
            material: Material::lambert(a),
        }],
        camera: Camera {
            eye: Vec3::splat(0.5),
            target: Vec3::new(0.3, 0.2, 0.0),
            up: Vec3::Y,
            hfov_degrees: 90.0,
            width: 12,
            height: 8,
        },
        point_lights: Vec::new(),
        textures: Vec::new(),
    }
}

/// Inside, the radiance after up to d bounces is le (1 - a^(d+1)) / (1 - a): every direction
/// sees an emitter, and each bounce reflects a of it. Next-event estimation and the BRDF
/// samples share each bounce's emitters by MIS, so the sum holds in the mean.
#[test]
fn closed_box_furnace_sums_the_geometric_series_per_depth() {
    let (a, le) = (0.6f32, Vec3::new(1.0, 0.5, 2.0));
    let scene = furnace(a);
    let bvh = SceneBvh::new(&scene);
    let emitters = Emitters::new(&scene, &[le]);
    for depth in [0u32, 1, 2, 3, 6, 40] {
        let r = render(
            &scene,
            &bvh,
            None,
            &Integrator::PathEmissive { max_depth: depth, emitters: &emitters },
            &RenderSettings { spp: 256, seed: 1, ..RenderSettings::default() },
            &|_, _| {},
        );
        let exact = le * (1.0 - a.powi(depth as i32 + 1)) / (1.0 - a);
        let mean = r.color.iter().copied().sum::<Vec3>() / r.color.len() as f32;
        assert!(((mean - exact) / exact).abs().max_element() < 0.005, "depth {depth}: {mean} vs {exact}");
        for c in &r.color {
            assert!(((*c - exact) / exact).abs().max_element() < 0.05, "depth {depth}: a pixel {c} vs {exact}");
        }
    }
}

/// Emitters found only by BRDF samples (a one-emitter scene seen through a mirror-free box is
/// the same either way): the MIS weights sum to one, so turning next-event estimation's share
/// to nothing leaves the mean. Here: the box's floor emits alone, the rest reflects; its
/// irradiance at the ceiling's centre is the floor's form factor times le.
#[test]
fn one_emitting_face_lights_the_opposite_face_by_its_form_factor() {
    let le = Vec3::splat(2.0);
    let (a, depth) = (0.5f32, 1u32);
    let floor = Object {
        name: "floor".into(),
        mesh: Mesh::quad(Vec3::ZERO, Vec3::Z, Vec3::X, 4, 4),
        material: Material::lambert(a),
    };
    let ceiling = Object {
        name: "ceiling".into(),
        mesh: Mesh::quad(Vec3::Y, Vec3::X, Vec3::Z, 4, 4),
        material: Material::lambert(a),
    };
    let scene = Scene {
        name: "plates".into(),
        objects: vec![floor, ceiling],
        camera: Camera {
            eye: Vec3::new(0.5, 0.2, 0.5),
            target: Vec3::new(0.5, 1.0, 0.5001),
            up: Vec3::Z,
            hfov_degrees: 2.0,
            width: 2,
            height: 2,
        },
        point_lights: Vec::new(),
        textures: Vec::new(),
    };
    let emitters = Emitters::new(&scene, &[le, Vec3::ZERO]);
    let r = render(
        &scene,
        &SceneBvh::new(&scene),
        None,
        &Integrator::PathEmissive { max_depth: depth, emitters: &emitters },
        &RenderSettings { spp: 4096, seed: 5, ..RenderSettings::default() },
        &|_, _| {},
    );
    // a unit square at height 1 seen from its centre's foot: F = 4 x the corner rectangle's
    // (1/2π)[X/√(1+X²) atan(X/√(1+X²))] x 2, X = 1/2
    let x = 0.5f32;
    let g = x / (1.0 + x * x).sqrt();
    let f = 4.0 * (1.0 / (2.0 * std::f32::consts::PI)) * 2.0 * g * g.atan();
    let exact = le * a * f;
    let mean = r.color.iter().copied().sum::<Vec3>() / r.color.len() as f32;
    assert!(((mean - exact) / exact).abs().max_element() < 0.01, "{mean} vs {exact}");
}

/// A quad emits from its front face only.
#[test]
fn emitters_are_one_sided() {
    let quad = |flip: bool| {
        let m = Mesh::quad(Vec3::new(-1.0, -1.0, 0.0), Vec3::X * 2.0, Vec3::Y * 2.0, 1, 1);
        Scene {
            name: "quad".into(),
            objects: vec![Object {
                name: "lamp".into(),
                mesh: if flip { m.flipped() } else { m },
                material: Material::lambert(0.0),
            }],
            camera: Camera {
                eye: Vec3::new(0.0, 0.0, 3.0),
                target: Vec3::ZERO,
                up: Vec3::Y,
                hfov_degrees: 20.0,
                width: 4,
                height: 4,
            },
            point_lights: Vec::new(),
            textures: Vec::new(),
        }
    };
    for (flip, expected) in [(false, 3.0), (true, 0.0)] {
        let s = quad(flip);
        let emitters = Emitters::new(&s, &[Vec3::splat(3.0)]);
        let r = render(
            &s,
            &SceneBvh::new(&s),
            None,
            &Integrator::PathEmissive { max_depth: 2, emitters: &emitters },
            &RenderSettings { spp: 2, ..RenderSettings::default() },
            &|_, _| {},
        );
        assert!(r.color.iter().all(|c| (c.x - expected).abs() < 1e-6), "flipped {flip}: {:?}", r.color[5]);
    }
}

/// Without emitters, `PathEmissive` under a map is `Path`, bit for bit.
#[test]
fn no_emission_is_the_plain_path_tracer() {
    let scene = Scene::builtin("spheres_box").unwrap();
    let mut scene = scene;
    (scene.camera.width, scene.camera.height) = (32, 24);
    let map = envmap_sphere::EnvMap::from_fn(64, 32, |d| Vec3::splat(0.5 + d.y.max(0.0)));
    let bvh = SceneBvh::new(&scene);
    let env = EnvLight::new(&map);
    let settings = RenderSettings { spp: 4, seed: 3, ..RenderSettings::default() };
    let a = render(&scene, &bvh, Some(&env), &Integrator::Path { max_depth: 3 }, &settings, &|_, _| {});
    let none = Emitters::new(&scene, &[]);
    let b = render(
        &scene,
        &bvh,
        Some(&env),
        &Integrator::PathEmissive { max_depth: 3, emitters: &none },
        &settings,
        &|_, _| {},
    );
    assert_eq!(a.color, b.color);
}
