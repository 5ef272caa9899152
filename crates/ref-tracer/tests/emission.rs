//! Emitting surfaces in `PathEmissive`: the closed-box furnace per bounce depth, one-sidedness,
//! and that `Path` is unchanged by them.

use glam::Vec3;
use ref_tracer::{EnvLight, Integrator, RenderSettings, SceneBvh, render};
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
    }
}

/// Every path sees emission at every vertex and Lambertian sampling weighs each bounce by
/// exactly a, so up to depth d the radiance is le (1 - a^(d+1)) / (1 - a) with no variance
/// (until Russian roulette starts, at the fifth vertex).
#[test]
fn closed_box_furnace_sums_the_geometric_series_per_depth() {
    let (a, le) = (0.6f32, Vec3::new(1.0, 0.5, 2.0));
    let scene = furnace(a);
    let bvh = SceneBvh::new(&scene);
    let emission = [le];
    for depth in [0u32, 1, 2, 3, 4] {
        let r = render(
            &scene,
            &bvh,
            None,
            &Integrator::PathEmissive { max_depth: depth, emission: &emission },
            &RenderSettings { spp: 4, seed: 1, ..RenderSettings::default() },
            &|_, _| {},
        );
        let exact = le * (1.0 - a.powi(depth as i32 + 1)) / (1.0 - a);
        for c in &r.color {
            assert!(((*c - exact) / exact).abs().max_element() < 1e-4, "depth {depth}: {c} vs {exact}");
        }
    }
    // deep paths: Russian roulette keeps the mean
    let r = render(
        &scene,
        &bvh,
        None,
        &Integrator::PathEmissive { max_depth: 40, emission: &emission },
        &RenderSettings { spp: 256, seed: 2, ..RenderSettings::default() },
        &|_, _| {},
    );
    let mean = r.color.iter().copied().sum::<Vec3>() / r.color.len() as f32;
    let exact = le / (1.0 - a);
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
        }
    };
    let emission = [Vec3::splat(3.0)];
    for (flip, expected) in [(false, 3.0), (true, 0.0)] {
        let s = quad(flip);
        let r = render(
            &s,
            &SceneBvh::new(&s),
            None,
            &Integrator::PathEmissive { max_depth: 2, emission: &emission },
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
    let b = render(
        &scene,
        &bvh,
        Some(&env),
        &Integrator::PathEmissive { max_depth: 3, emission: &[] },
        &settings,
        &|_, _| {},
    );
    assert_eq!(a.color, b.color);
}
