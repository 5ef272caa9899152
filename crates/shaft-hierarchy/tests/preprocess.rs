//! Pre-processing on real scenes: transfers against Monte Carlo integration, the source set's
//! share, and the whole pipeline's conservativeness.

use glam::Vec3;
use rand::{Rng, SeedableRng};
use rand_pcg::Pcg64;
use real_scene::{Patch, Perturbation, RealScene, SolveSettings, luminance, solve};
use shaft_hierarchy::preprocess::{PreprocessSettings, Source, build, prepare};
use trade::shafts::{check, object_path};

fn patch(corners: [Vec3; 4], reflectance: f32, radiance: f32) -> Patch {
    Patch {
        corners,
        reflectance: Vec3::splat(reflectance),
        emission: Vec3::splat(radiance),
        radiance: Vec3::splat(radiance),
    }
}

/// A lamp tilted over a floor tile, nothing between: each vertex's transfer is ρ L F, F the
/// point-to-patch form factor, here integrated by Monte Carlo over the lamp's area.
#[test]
fn unoccluded_transfer_is_rho_l_times_the_form_factor() {
    let floor = patch([Vec3::ZERO, Vec3::Z, Vec3::new(1.0, 0.0, 1.0), Vec3::X], 0.5, 0.1);
    // a 0.6 m lamp at 1.2 m, tilted, facing down
    let lamp = patch(
        [Vec3::new(0.2, 1.2, 0.1), Vec3::new(0.8, 1.4, 0.1), Vec3::new(0.8, 1.4, 0.7), Vec3::new(0.2, 1.2, 0.7)],
        0.0,
        10.0,
    );
    let scene = RealScene {
        name: "lamp".into(),
        patches: vec![floor, lamp],
        camera: scene::Camera {
            eye: Vec3::new(0.5, 0.6, 3.0),
            target: Vec3::new(0.5, 0.0, 0.5),
            up: Vec3::Y,
            hfov_degrees: 60.0,
            width: 64,
            height: 48,
        },
        environment_lit: false,
    };
    assert!(lamp.normal().y < 0.0, "the lamp faces the floor");
    let bvh = ref_tracer::SceneBvh::new(&scene.to_scene());
    let p = prepare(
        &scene,
        &[],
        &bvh,
        &PreprocessSettings { source_share: 1.0, visibility_samples: 2, ..PreprocessSettings::PAPER },
    );
    assert_eq!(p.receivers, vec![0], "the camera sees the floor, not the lamp's back");
    let lamp_row = p.sources.iter().position(|&s| s == Source::Patch(1)).expect("the lamp is a source");
    let mut rng = Pcg64::seed_from_u64(3);
    for (i, &x) in p.vertices.iter().enumerate() {
        // F = ∫ cos θx cos θl / (π r²) dA over the lamp
        let n = 200_000;
        let area = lamp.area();
        let mut sum = 0.0f64;
        for _ in 0..n {
            let y = lamp.point(rng.random(), rng.random());
            let d = y - x;
            let r2 = d.length_squared();
            let d = d / r2.sqrt();
            sum += f64::from((d.y.max(0.0) * (-d).dot(lamp.normal()).max(0.0)) / (std::f32::consts::PI * r2));
        }
        let f = sum / f64::from(n) * f64::from(area);
        let expected = 0.5 * 10.0 * f;
        let got = f64::from(p.transfers.row(lamp_row)[i]);
        assert!((got - expected).abs() < 0.01 * expected, "vertex {i}: {got} vs {expected}");
    }
}

/// The source set is the largest-power prefix that reaches the share.
#[test]
fn source_set_is_the_powerful_prefix() {
    let mut scene = RealScene::builtin_with("ar_room", &Perturbation { coarsen: 2, ..Perturbation::NONE }).unwrap();
    let bvh = ref_tracer::SceneBvh::new(&scene.to_scene());
    solve(&mut scene, &bvh, None, &SolveSettings::default()).unwrap();
    for share in [0.3f32, 0.7, 1.0] {
        let p = prepare(&scene, &[], &bvh, &PreprocessSettings { source_share: share, ..PreprocessSettings::PAPER });
        let power = |s: &Source| match *s {
            Source::Patch(j) => f64::from(scene.patches[j as usize].power()),
            Source::Distant(_) => unreachable!(),
        };
        assert!(p.power.0 >= f64::from(share) * p.power.1 * 0.999_999, "{share}: {:?}", p.power);
        // without its weakest source the set would fall short
        let weakest = p.sources.iter().map(power).fold(f64::INFINITY, f64::min);
        assert!(p.power.0 - weakest < f64::from(share) * p.power.1 || share >= 1.0);
        // every source outside the set is weaker than every one in it
        let strongest_out = (0..scene.patches.len() as u32)
            .filter(|j| !p.sources.contains(&Source::Patch(*j)))
            .map(|j| power(&Source::Patch(j)))
            .fold(0.0, f64::max);
        assert!(strongest_out <= weakest, "{share}");
        // the lamp and the window are in even the smallest set
        assert!(
            p.sources
                .iter()
                .any(|s| matches!(*s, Source::Patch(j) if luminance(scene.patches[j as usize].emission) > 20.0))
        );
    }
}

/// The whole pipeline on a coarse room and on the ground under the embedded map's lights: the
/// hierarchy validates and misses no occluded segment along the object path.
#[test]
fn pipeline_misses_nothing_on_real_scenes() {
    let map = envmap_sphere::default_map();
    let lights: Vec<scene::DistantLight> = (0..6)
        .map(|k| {
            let a = k as f32;
            scene::DistantLight {
                direction: Vec3::new(a.cos(), 0.3 + 0.1 * a, a.sin()).normalize(),
                solid_angle: 0.01 + 0.05 * a,
                radiance: Vec3::splat(5.0 + a),
            }
        })
        .collect();
    for (name, lights) in [("ar_room", Vec::new()), ("ar_ground", lights)] {
        let mut scene = RealScene::builtin_with(name, &Perturbation { coarsen: 2, ..Perturbation::NONE }).unwrap();
        let bvh = ref_tracer::SceneBvh::new(&scene.to_scene());
        let env = scene.environment_lit.then_some(&map);
        solve(&mut scene, &bvh, env, &SolveSettings::default()).unwrap();
        let (prepared, h) = build(&scene, &lights, &bvh, &PreprocessSettings::PAPER).unwrap();
        h.validate().unwrap();
        assert!(prepared.transfers.values.iter().all(|v| v.is_finite() && *v >= 0.0));
        let objects = object_path(&scene, 60);
        let c = check(&h, &prepared, &scene, &lights, &objects, 500, 7);
        assert_eq!(c.segments, 30_000);
        assert!(c.hits > 100, "{name}: {c:?}");
        assert_eq!(c.misses, 0, "{name}: {c:?}");
    }
}

/// Pre-processing runs on rayon and gives the same hierarchy every time.
#[test]
fn preprocessing_is_deterministic() {
    let mut scene = RealScene::builtin_with("ar_room", &Perturbation { coarsen: 2, ..Perturbation::NONE }).unwrap();
    let bvh = ref_tracer::SceneBvh::new(&scene.to_scene());
    solve(&mut scene, &bvh, None, &SolveSettings::default()).unwrap();
    let (p1, h1) = build(&scene, &[], &bvh, &PreprocessSettings::PAPER).unwrap();
    let (p2, h2) = build(&scene, &[], &bvh, &PreprocessSettings::PAPER).unwrap();
    assert_eq!(p1.transfers, p2.transfers);
    assert_eq!(p1.sources, p2.sources);
    assert_eq!((h1.shafts, h1.leaf_transfer), (h2.shafts, h2.leaf_transfer));
}
