//! `Path` (the map-lit path tracer, the truth for compositing) beyond one bounce, against the
//! closed form of an integrating sphere: a hollow sphere with a port, lit through the port by a
//! constant map. Every point of a sphere's inner wall sees any region of the wall with the same
//! form factor, area / (4 pi R^2), so with a port of area fraction f, albedo rho and map
//! radiance L the wall's radiance is uniform and after d scattering events is
//! rho f L (1 + q + ... + q^(d-1)), q = rho (1 - f): the integrating-sphere equation's
//! geometric series. GGX walls have no such closed form, but a passive enclosure under a
//! constant sky can never outshine it, and more bounces only add light.

use envmap_sphere::EnvMap;
use glam::Vec3;
use ref_tracer::{EnvLight, Integrator, Render, RenderSettings, SceneBvh, render};
use scene::{Camera, Ggx, Material, Mesh, Object, Scene};

/// The unit icosphere (20 x 4^5 triangles) facing inwards, without the triangles whose centroid
/// lies above y = `port_y`; returns the scene and the port's area fraction f.
fn integrating_sphere(material: Material, port_y: f32) -> (Scene, f64) {
    let full = Mesh::icosphere(Vec3::ZERO, 1.0, 5);
    let area = |t: &[Vec3; 3]| f64::from(0.5 * (t[1] - t[0]).cross(t[2] - t[0]).length());
    let total: f64 = (0..full.indices.len()).map(|t| area(&full.triangle(t))).sum();
    let mut wall = full.clone();
    wall.indices.retain(|&[a, b, c]| {
        (full.positions[a as usize] + full.positions[b as usize] + full.positions[c as usize]).y / 3.0 <= port_y
    });
    let kept: f64 = (0..wall.indices.len()).map(|t| area(&wall.triangle(t))).sum();
    let scene = Scene {
        name: "integrating_sphere".into(),
        objects: vec![Object { name: "wall".into(), mesh: wall.flipped(), material }],
        // from the centre, looking away from the port: every pixel sees the wall
        camera: Camera {
            eye: Vec3::new(0.0, 0.1, 0.0),
            target: Vec3::new(0.2, -1.0, 0.1),
            up: Vec3::Z,
            hfov_degrees: 70.0,
            width: 48,
            height: 32,
        },
        point_lights: Vec::new(),
        textures: Vec::new(),
    };
    (scene, 1.0 - kept / total)
}

fn path(scene: &Scene, map: &EnvMap, depth: u32, spp: u32) -> Render {
    let bvh = SceneBvh::new(scene);
    let env = EnvLight::new(map);
    let settings = RenderSettings { spp, seed: 3, ..RenderSettings::default() };
    render(scene, &bvh, Some(&env), &Integrator::Path { max_depth: depth }, &settings, &|_, _| {})
}

/// Image mean and its standard error, from the pixels' spread (each pixel an independent
/// estimate of the same uniform radiance).
fn mean_and_error(r: &Render) -> (Vec3, Vec3) {
    let n = r.color.len() as f32;
    let mean = r.color.iter().copied().sum::<Vec3>() / n;
    let var = r.color.iter().map(|c| (*c - mean) * (*c - mean)).sum::<Vec3>() / (n - 1.0);
    (mean, (var / n).powf(0.5))
}

#[test]
fn integrating_sphere_sums_the_geometric_series_per_depth() {
    let rho = Vec3::new(0.8, 0.6, 0.4);
    let l = Vec3::new(1.0, 2.0, 0.5);
    let (scene, f) = integrating_sphere(Material::rgb(rho, None), 0.8);
    // a cap above y = 0.8 has f = 0.1 on the exact sphere
    assert!((f - 0.1).abs() < 0.01, "port fraction {f}");
    let f = f as f32;
    let map = EnvMap::constant(64, 32, l);
    let q = rho * (1.0 - f);
    for depth in [1u32, 2, 3, 5, 30] {
        let r = path(&scene, &map, depth, 64);
        let (mean, err) = mean_and_error(&r);
        let series = (Vec3::ONE - q.powf(depth as f32)) / (Vec3::ONE - q);
        let exact = rho * f * l * series;
        // 4 standard errors, and a 0.5 % allowance for the tessellated wall
        let allowed = 4.0 * err + 0.005 * exact;
        assert!(
            (mean - exact).abs().cmple(allowed).all(),
            "depth {depth}: {mean} vs closed form {exact} (allowed {allowed})"
        );
        // and the bounces count: depth 30 is within 1e-3 of the infinite sum
        if depth == 30 {
            let infinite = rho * f * l / (Vec3::ONE - q);
            assert!(((exact - infinite) / infinite).abs().max_element() < 1e-3);
        }
    }
}

#[test]
fn ggx_walls_never_outshine_the_sky_and_bounces_only_add_light() {
    let l = Vec3::splat(1.5);
    let map = EnvMap::constant(64, 32, l);
    for roughness in [0.2f32, 0.6] {
        let material = Material::rgb(Vec3::ZERO, Some(Ggx { roughness, f0: Vec3::ONE }));
        let (scene, _) = integrating_sphere(material, 0.6);
        let mut last = Vec3::ZERO;
        for depth in [1u32, 2, 4, 8, 24] {
            let (mean, err) = mean_and_error(&path(&scene, &map, depth, 32));
            assert!(mean.is_finite() && mean.cmpgt(Vec3::ZERO).all(), "roughness {roughness} depth {depth}: {mean}");
            // energy: a passive enclosure stays below the sky's radiance
            assert!((mean - 3.0 * err).cmplt(l).all(), "roughness {roughness} depth {depth}: {mean} above the sky {l}");
            // each further bounce adds light (the same seed: the paths share their first vertices)
            assert!((mean + 3.0 * err).cmpge(last).all(), "roughness {roughness} depth {depth}: {mean} below {last}");
            last = mean;
        }
    }
}
