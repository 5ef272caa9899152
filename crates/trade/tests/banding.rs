//! Banding on the GPU (lavapipe in CI): a wide bright source drawn by a few hard-shadowed
//! lights shows steps across its penumbra that the truth has not; paper 001's interleaved sets
//! shrink them and add noise along the edge; wedges leave little to shrink. The truth is pinned
//! to the closed form of a long wall under a constant sky.

use envmap_sphere::EnvMap;
use glam::Vec3;
use gpu::Gpu;
use trade::{BandingCase, Interleave, Passes, Shadow, measure_banding};

/// A dim sky and a bright cap of 20° half-angle at 40° elevation.
fn cap_map() -> EnvMap {
    let centre = Vec3::new(40f32.to_radians().cos(), 40f32.to_radians().sin(), 0.0);
    let cos_cap = 20f32.to_radians().cos();
    EnvMap::from_fn(256, 128, |d| {
        if d.dot(centre) > cos_cap {
            Vec3::splat(20.0)
        } else if d.y > 0.0 {
            Vec3::new(0.2, 0.3, 0.5)
        } else {
            Vec3::splat(0.1)
        }
    })
}

fn case_of(map: &EnvMap, k: usize, size: (u32, u32)) -> BandingCase {
    let d = light_extract::extractor(light_extract::DEFAULT_METHOD, k).expect("method").extract(map).expect("lights");
    BandingCase::new(map, &d, size).expect("a light above the horizon")
}

#[test]
fn interleaving_shrinks_the_steps_of_hard_shadows_and_adds_noise() {
    let gpu = Gpu::new().unwrap_or_else(|e| panic!("{e}"));
    let passes = Passes::new(&gpu).expect("passes");
    let case = case_of(&cap_map(), 8, (96, 24));
    assert!(case.columns() > 80, "{} columns see the ground", case.columns());
    let maps = Shadow::Maps { resolution: 512, pcf: 1 };
    let row = |shadow: &Shadow, interleave| {
        let r = measure_banding(&gpu, &passes, &case, shadow, interleave, 1).expect("measured");
        assert_eq!((r.technique.as_str(), r.interleave), (shadow.name().as_str(), interleave));
        r.banding.expect("the wall's shadow has contrast")
    };
    let hard = row(&maps, Interleave::NONE);
    let paper = row(&maps, Interleave::PAPER);
    let wider = row(&maps, Interleave { sets: 8, jitter: 0.3 });
    let wedges = row(&Shadow::Wedges, Interleave::NONE);
    // the cap's few lights band: steps the smooth truth has not
    assert!(hard.visible_steps >= 1 && hard.largest_step > 2.0 * hard.truth_largest_step, "{hard:?}");
    // interleaving trades the steps for noise, more of both the wider the perturbation
    assert!(paper.largest_step < 0.8 * hard.largest_step, "{hard:?} {paper:?}");
    assert!(wider.largest_step < paper.largest_step, "{paper:?} {wider:?}");
    assert!(paper.noise > 3.0 * hard.noise && wider.noise > paper.noise, "{hard:?} {paper:?} {wider:?}");
    // soft shadows leave little banding to remove
    assert!(wedges.largest_step < 0.1 * hard.largest_step, "{hard:?} {wedges:?}");
    // what no frame can be
    for (shadow, sets) in [(maps, 0), (maps, gpu::MAX_SETS as usize + 1)] {
        assert!(measure_banding(&gpu, &passes, &case, &shadow, Interleave { sets, jitter: 0.1 }, 1).is_err());
    }
    let point_maps = Shadow::Paraboloid { resolution: 256, pcf: 0, subdivide: true };
    assert!(measure_banding(&gpu, &passes, &case, &point_maps, Interleave::NONE, 1).is_err());
}

/// Under a constant sky L a point on the ground s from the foot of a long wall of height H
/// sees all but the wall's view factor (1 - s / sqrt(s² + H²)) / 2: its radiance is
/// albedo L (1 + s / sqrt(s² + H²)) / 2.
#[test]
fn truth_is_the_long_wall_view_factor_under_a_constant_sky() {
    let map = EnvMap::constant(512, 256, Vec3::splat(2.0));
    let case = case_of(&map, 8, (64, 8));
    let wall = case.scene.object("wall").expect("a wall");
    let height = wall.mesh.positions.iter().map(|p| p.y).fold(0.0f32, f32::max);
    let h = Vec3::new(case.facing.direction.x, 0.0, case.facing.direction.z).normalize();
    let cam = case.scene.camera;
    let mut checked = 0;
    for (x, truth) in case.truth().iter().enumerate() {
        let Some(truth) = truth else { continue };
        let (o, d) = cam.ray(x as f32 + 0.5, (cam.height / 2) as f32 + 0.5);
        let p = o + d * (-o.y / d.y);
        let s = f64::from(-p.dot(h));
        let hh = f64::from(height);
        let expected = f64::from(trade::banding::GROUND_ALBEDO) * 2.0 * (1.0 + s / s.hypot(hh)) / 2.0;
        assert!((truth - expected).abs() < 0.01 * expected, "column {x}, s {s}: {truth} against {expected}");
        checked += 1;
    }
    assert!(checked > 50, "{checked} columns");
}

#[test]
fn black_and_below_horizon_maps_refuse_with_a_reason() {
    let black = EnvMap::constant(64, 32, Vec3::ZERO);
    let below = EnvMap::from_fn(64, 32, |d| if d.y < -0.2 { Vec3::splat(65504.0) } else { Vec3::ZERO });
    for map in [black, below] {
        let d =
            light_extract::extractor(light_extract::DEFAULT_METHOD, 4).expect("method").extract(&map).expect("lights");
        let e = BandingCase::new(&map, &d, (32, 8)).err().expect("no light above the horizon");
        assert!(e.to_string().contains("above"), "{e}");
    }
    let cap = cap_map();
    let d = light_extract::extractor(light_extract::DEFAULT_METHOD, 4).expect("method").extract(&cap).expect("lights");
    assert!(BandingCase::new(&cap, &d, (4, 1)).is_err(), "too small an image");
    assert!(BandingCase::new(&cap, &d, (16, 2)).is_ok());
}

/// A small sun of `radiance` at `elevation` degrees over a dim sky.
fn sun_map(elevation: f32, radiance: f32) -> EnvMap {
    let (s, c) = elevation.to_radians().sin_cos();
    let sun = Vec3::new(c, s, 0.0);
    EnvMap::from_fn(128, 64, move |d| {
        if d.dot(sun) > 3f32.to_radians().cos() {
            Vec3::splat(radiance)
        } else if d.y > 0.0 {
            Vec3::splat(0.3)
        } else {
            Vec3::ZERO
        }
    })
}

#[test]
fn extreme_suns_give_finite_cases_and_figures() {
    let gpu = Gpu::new().unwrap_or_else(|e| panic!("{e}"));
    let passes = Passes::new(&gpu).expect("passes");
    // an f16-max sun, a sun at the zenith (the wall's height clamps), a sun grazing the horizon
    for (elevation, radiance) in [(40.0, 65504.0), (90.0, 100.0), (5.0, 100.0)] {
        let case = case_of(&sun_map(elevation, radiance), 4, (48, 8));
        let what = format!("sun at {elevation}° of {radiance}");
        assert!(case.columns() > 30, "{what}: {} columns", case.columns());
        assert!(case.truth().iter().flatten().all(|t| t.is_finite() && *t >= 0.0), "{what}");
        let r = measure_banding(&gpu, &passes, &case, &Shadow::Maps { resolution: 256, pcf: 1 }, Interleave::PAPER, 1)
            .expect("a frame");
        assert!(r.image.iter().all(|p| p.is_finite()), "{what}: a non-finite pixel");
        if let Some(b) = r.banding {
            let figures = [b.contrast, b.largest_step, b.truth_largest_step, b.profile_error, b.noise];
            assert!(figures.iter().all(|f| f.is_finite() && *f >= 0.0), "{what}: {b:?}");
        }
    }
}
