//! The residual option: its splat against a brute-force cone test, its books and extremes, and
//! a lone glossy sphere lit by lights + residual, rendered like the map itself.

use envmap_sphere::EnvMap;
use glam::{DVec3, Vec3};
use light_extract::{
    AboveHorizon, EmissiveSplit, LightExtractor, MedianCut, Residual, extractor, splat_lights, upper_hemisphere,
};
use ref_tracer::{AmbientMap, EnvLight, Integrator, LightSet, RenderSettings, SceneBvh, Strategy, metrics, render};
use scene::{Camera, DistantLight, Ggx, Material, Mesh, Object, Scene};
use std::f64::consts::PI;

/// Texel-centre direction from the conventions, in f64 (independent of the crate's tables).
fn centre(i: u32, j: u32, w: u32, h: u32) -> DVec3 {
    let (phi, theta) = (2.0 * PI * (f64::from(i) + 0.5) / f64::from(w), PI * (f64::from(j) + 0.5) / f64::from(h));
    DVec3::new(theta.sin() * phi.sin(), theta.cos(), -theta.sin() * phi.cos())
}

fn solid_angle(j: u32, w: u32, h: u32) -> f64 {
    let (t0, t1) = (PI * f64::from(j) / f64::from(h), PI * f64::from(j + 1) / f64::from(h));
    2.0 * PI / f64::from(w) * (t0.cos() - t1.cos())
}

fn light(dir: Vec3, half_angle_deg: f32, radiance: Vec3) -> DistantLight {
    // 4 pi sin^2(h / 2): no cancellation for cones smaller than a texel
    let s = (0.5 * half_angle_deg.to_radians()).sin();
    DistantLight { direction: dir.normalize(), solid_angle: 4.0 * std::f32::consts::PI * s * s, radiance }
}

fn cones() -> Vec<DistantLight> {
    vec![
        light(Vec3::new(0.3, 0.8, 0.2), 10.0, Vec3::new(1.0, 2.0, 3.0)),
        light(Vec3::Y, 20.0, Vec3::splat(4.0)),
        light(-Vec3::Y, 5.0, Vec3::splat(40.0)),
        light(Vec3::new(0.0, 0.3, -1.0), 8.0, Vec3::splat(7.0)), // across the seam u = 0 / 1
        light(Vec3::new(0.05, 0.99, 0.0), 15.0, Vec3::splat(2.0)), // holds the pole off-centre
        light(Vec3::new(-0.4, 0.2, 0.9), 0.01, Vec3::splat(1e6)), // smaller than a texel
        light(Vec3::new(0.6, -0.3, 0.1), 150.0, Vec3::splat(0.1)),
    ]
}

#[test]
fn splat_matches_a_brute_force_cone_test() {
    for (w, h) in [(64, 32), (256, 128), (8, 4)] {
        for l in cones() {
            let splat = splat_lights(&[l], w, h);
            let (d, cos_max) = (l.direction.as_dvec3(), f64::from(l.cos_half_angle()));
            let inside: Vec<(u32, u32)> = (0..h)
                .flat_map(|j| (0..w).map(move |i| (i, j)))
                .filter(|&(i, j)| centre(i, j, w, h).dot(d) >= cos_max)
                .collect();
            let held: f64 = (0..h)
                .flat_map(|j| (0..w).map(move |i| (i, j)))
                .map(|(i, j)| f64::from(splat[(j * w + i) as usize].x) * solid_angle(j, w, h))
                .sum();
            let power = f64::from(l.power().x);
            assert!((held / power - 1.0).abs() < 1e-4, "{w}x{h} {l:?}: splat holds {held} of {power}");
            for j in 0..h {
                for i in 0..w {
                    let (dot, s) = (centre(i, j, w, h).dot(d), splat[(j * w + i) as usize]);
                    if (dot - cos_max).abs() < 1e-5 {
                        continue; // on the cone's rim either answer is right
                    }
                    let expected = inside.contains(&(i, j)) || (inside.is_empty() && s != Vec3::ZERO);
                    assert_eq!(s != Vec3::ZERO, expected, "{w}x{h} texel ({i}, {j}) {l:?}");
                }
            }
            if inside.is_empty() {
                assert_eq!(splat.iter().filter(|s| **s != Vec3::ZERO).count(), 1, "one texel takes a tiny cone");
            }
        }
    }
}

#[test]
fn the_residual_keeps_the_lights_and_the_books() {
    let map = envmap_sphere::default_map();
    for name in ["median-cut", "emissive-split+moment-cones+above-horizon", "center-surround", "importance"] {
        let inner = extractor(name, 16).unwrap().extract(&map).unwrap();
        let d = extractor(&format!("{name}+residual"), 16).unwrap().extract(&map).unwrap();
        assert_eq!(d.method, format!("{name}+residual"));
        assert_eq!(d.lights, inner.lights, "{name}: the option keeps the lights");
        assert!(d.ambient.pixels().iter().all(|p| p.is_finite()), "{name}");
        assert!(d.power_balance_error() < 1e-4, "{name}: {}", d.power_balance_error());
    }
    // the residual stands for the map the inner method models: above the horizon, only the
    // cones' rims can reach below it
    let d = Residual::new(AboveHorizon::new(MedianCut::with_lights(16))).extract(&map).unwrap();
    let upper = upper_hemisphere(&map, Vec3::Y);
    let low: f64 = (0..map.height())
        .flat_map(|j| (0..map.width()).map(move |i| (i, j)))
        .filter(|&(i, j)| map.texel_dir(i, j).y < -0.2)
        .map(|(i, j)| f64::from(d.ambient.pixel(i, j).abs().max_element()))
        .sum();
    assert_eq!(low, 0.0, "nothing well below the horizon");
    assert_eq!(d.map_power, upper.power());
}

#[test]
fn a_light_covering_a_constant_map_leaves_no_residual() {
    let map = EnvMap::constant(128, 64, Vec3::new(0.5, 1.0, 2.0));
    let d = Residual { inner: MedianCut::with_lights(1), sets: 1 }.extract(&map).unwrap();
    assert_eq!(d.lights.len(), 1);
    let worst = d.ambient.pixels().iter().map(|p| p.abs().max_element()).fold(0.0, f32::max);
    assert!(worst < 1e-4, "residual {worst}");
}

#[test]
fn no_nan_at_extremes() {
    let black = EnvMap::constant(64, 32, Vec3::ZERO);
    let d = Residual::new(EmissiveSplit::default()).extract(&black).unwrap();
    assert!(d.lights.is_empty() && d.ambient.pixels().iter().all(|p| *p == Vec3::ZERO));
    let mut sun = EnvMap::constant(1024, 512, Vec3::splat(1e-4));
    sun.set_pixel(300, 0, Vec3::splat(65504.0)); // the half-float maximum, on the pole
    let tiny = EnvMap::from_texels(8, 4, |i, j| Vec3::splat(1.0 + (i * 4 + j) as f32));
    for map in [&sun, &tiny] {
        for k in [1, 32, 1024] {
            for name in ["median-cut+residual", "emissive-split+moment-cones+above-horizon+residual"] {
                let d = extractor(name, k).unwrap().extract(map).unwrap();
                assert!(d.ambient.pixels().iter().all(|p| p.is_finite()), "{name} K = {k}");
                assert!(d.ambient_sh.coeffs.iter().all(|c| c.is_finite()), "{name} K = {k}");
                assert!(d.power_balance_error() < 1e-3, "{name} K = {k}: {}", d.power_balance_error());
            }
        }
    }
    assert!(Residual { inner: MedianCut::default(), sets: 0 }.extract(&tiny).is_err());
}

/// A lone near-mirror sphere (no diffuse lobe) under a cloudy sky with a sun: nothing occludes it, so
/// lights + residual must render what the map renders, where the lights alone cannot.
#[test]
fn lights_and_residual_render_a_lone_glossy_sphere_like_the_map() {
    let sun = Vec3::new(0.4, 0.7, 0.6).normalize();
    let map = EnvMap::from_fn(512, 256, |d| {
        // clouds: detail no cone holds
        let clouds = 1.0 + 0.8 * (9.0 * d.x).sin() * (7.0 * d.z + 3.0 * d.y).sin();
        let sky =
            Vec3::new(0.3, 0.5, 1.0) * (0.5 + d.y.max(0.0)) * clouds + Vec3::new(0.2, 0.15, 0.1) * (-d.y).max(0.0);
        if d.dot(sun) > 4.0f32.to_radians().cos() { Vec3::new(40.0, 35.0, 30.0) } else { sky }
    });
    let scene = Scene {
        name: "glossy".into(),
        objects: vec![Object {
            name: "sphere".into(),
            mesh: Mesh::icosphere(Vec3::ZERO, 1.0, 4),
            material: Material::rgb(Vec3::ZERO, Some(Ggx { roughness: 0.2, f0: Vec3::splat(0.9) })),
        }],
        camera: Camera {
            eye: Vec3::new(1.0, 1.0, 4.0),
            target: Vec3::ZERO,
            up: Vec3::Y,
            hfov_degrees: 35.0,
            width: 40,
            height: 30,
        },
        point_lights: vec![],
        textures: Vec::new(),
    };
    let bvh = SceneBvh::new(&scene);
    let settings = RenderSettings { spp: 256, seed: 1, aovs: true, pixel_positions: Some(8), ..Default::default() };
    let env = EnvLight::new(&map);
    let truth = render(&scene, &bvh, Some(&env), &Integrator::EnvDirect(Strategy::Mis), &settings, &|_, _| {});
    let d = Residual::new(EmissiveSplit { lights: 8, moment_cones: true, ..EmissiveSplit::default() })
        .extract(&map)
        .unwrap();
    let (lights, sets) = (d.distant_lights(), d.interleaved_distant_lights());
    let ambient = AmbientMap::new(&d.ambient).expect("a residual that is not black");
    // (RMSE, ratio of means) against the truth over the sphere's pixels
    let sphere: Vec<usize> = (0..truth.color.len()).filter(|&k| truth.object_id[k] == 0).collect();
    let compare = |img: &[Vec3]| {
        let (a, b): (Vec<Vec3>, Vec<Vec3>) = sphere.iter().map(|&k| (truth.color[k], img[k])).unzip();
        let mean = |v: &[Vec3]| v.iter().map(|p| f64::from(p.element_sum())).sum::<f64>();
        (metrics::rmse(&a, &b), mean(&b) / mean(&a))
    };
    let lit = |ambient_map, shadow_ambient| {
        let set = LightSet {
            lights: &lights,
            interleaved: &sets,
            ambient: Some(d.ambient_sh),
            ambient_map,
            shadow_ambient,
            background: Some(&map),
        };
        let seed = RenderSettings { seed: 2, ..settings };
        compare(&render(&scene, &bvh, None, &Integrator::Lights(set), &seed, &|_, _| {}).color)
    };
    let (with, with_ratio) = lit(Some(&ambient), false);
    let (without, _) = lit(None, false);
    // nothing occludes a lone convex sphere: shadowing the ambient changes nothing but noise
    let (shadowed, shadowed_ratio) = lit(Some(&ambient), true);
    let seed = RenderSettings { seed: 3, ..settings };
    let (floor, _) =
        compare(&render(&scene, &bvh, Some(&env), &Integrator::EnvDirect(Strategy::Mis), &seed, &|_, _| {}).color);
    assert!((with_ratio - 1.0).abs() < 0.02, "mean ratio {with_ratio}");
    assert!(with < 2.0 * floor, "with the residual {with}, noise floor {floor}");
    assert!(without > 4.0 * with, "without the residual {without}, with {with}");
    assert!((shadowed_ratio - 1.0).abs() < 0.02 && shadowed < 2.0 * floor, "shadowed: {shadowed} {shadowed_ratio}");
}
