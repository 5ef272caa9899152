//! Cube and paraboloid parameterizations: round trips, Jacobians, extremes, and resampling.

mod common;

use envmap_sphere::cube::{CubeFace, cube_dir_to_uv, cube_jacobian, cube_rect_solid_angle, cube_uv_to_dir};
use envmap_sphere::paraboloid::{
    Hemisphere, PARABOLOID_MAX_RADIUS, paraboloid_dir_to_point, paraboloid_jacobian, paraboloid_point_to_dir,
};
use envmap_sphere::{EnvMap, Layout, RadianceSource, SphereImage};
use glam::{Vec2, Vec3};
use std::f64::consts::PI;

#[test]
fn cube_round_trips_for_random_directions() {
    let mut rng = common::rng(3);
    for _ in 0..100_000 {
        let d = common::random_dir(&mut rng);
        let (face, st) = cube_dir_to_uv(d);
        assert!((cube_uv_to_dir(face, st) - d).length() < 1e-6, "{d}");
    }
}

#[test]
fn cube_round_trips_on_edges_and_corners() {
    let s = 1.0 / 3f32.sqrt();
    let mut dirs = vec![];
    for a in [-1.0, 0.0, 1.0f32] {
        for b in [-1.0, 0.0, 1.0f32] {
            for c in [-1.0, 0.0, 1.0f32] {
                if (a, b, c) != (0.0, 0.0, 0.0) {
                    dirs.push(Vec3::new(a, b, c).normalize());
                }
            }
        }
    }
    dirs.push(Vec3::splat(s));
    for d in dirs {
        let (face, st) = cube_dir_to_uv(d);
        assert!(st.cmpge(Vec2::ZERO).all() && st.cmple(Vec2::ONE).all(), "{d}: {st}");
        assert!((cube_uv_to_dir(face, st) - d).length() < 1e-6, "{d}: {face:?} {st}");
    }
    // Face corners in (s, t) map to the cube's corners and back to the same direction.
    for face in CubeFace::ALL {
        for st in [Vec2::ZERO, Vec2::ONE, Vec2::new(0.0, 1.0), Vec2::new(1.0, 0.5)] {
            let d = cube_uv_to_dir(face, st);
            let (f2, st2) = cube_dir_to_uv(d);
            assert!((cube_uv_to_dir(f2, st2) - d).length() < 1e-6, "{face:?} {st}");
        }
    }
}

#[test]
fn cube_faces_follow_the_gpu_convention() {
    // Face centres point along their axes; (s, t) = (1, 0.5) on +Z is +X (s grows with x).
    let axes = [Vec3::X, Vec3::NEG_X, Vec3::Y, Vec3::NEG_Y, Vec3::Z, Vec3::NEG_Z];
    for (face, axis) in CubeFace::ALL.iter().zip(axes) {
        assert!((cube_uv_to_dir(*face, Vec2::splat(0.5)) - axis).length() < 1e-7);
        assert_eq!(cube_dir_to_uv(axis).0, *face);
    }
    assert!(cube_uv_to_dir(CubeFace::PosZ, Vec2::new(1.0, 0.5)).x > 0.7);
    assert!(cube_uv_to_dir(CubeFace::PosZ, Vec2::new(0.5, 0.0)).y > 0.7, "t = 0 is up on the side faces");
}

#[test]
fn cube_solid_angles_sum_to_four_pi() {
    let face = cube_rect_solid_angle(0.0, 0.0, 1.0, 1.0);
    assert!((6.0 * face / (4.0 * PI) - 1.0).abs() < 1e-12);
    // The Jacobian integrates to the same, and the exact texel solid angle agrees with it.
    let n = 256;
    let mut sum = 0.0f64;
    for y in 0..n {
        for x in 0..n {
            let st = Vec2::new((x as f32 + 0.5) / n as f32, (y as f32 + 0.5) / n as f32);
            sum += f64::from(cube_jacobian(st)) / f64::from(n * n);
        }
    }
    assert!((6.0 * sum / (4.0 * PI) - 1.0).abs() < 1e-4, "{sum}");
    let layout = Layout::CubeStrip { face: 16 };
    let total: f64 =
        (0..16).flat_map(|y| (0..96).map(move |x| (x, y))).map(|(x, y)| layout.texel_solid_angle(x, y)).sum();
    assert!((total / (4.0 * PI) - 1.0).abs() < 1e-6, "{total}");
}

#[test]
fn paraboloid_round_trips_on_both_hemispheres() {
    let mut rng = common::rng(5);
    for _ in 0..100_000 {
        let d = common::random_dir(&mut rng);
        let h = Hemisphere::of(d);
        let p = paraboloid_dir_to_point(d, h);
        assert!(p.length() <= 1.0 + 1e-6, "{d} -> {p}");
        assert!((paraboloid_point_to_dir(p, h) - d).length() < 1e-6, "{d}");
    }
}

#[test]
fn paraboloid_maps_the_hemisphere_boundary_to_the_unit_circle() {
    for k in 0..64 {
        let a = k as f32 / 64.0 * std::f32::consts::TAU;
        let d = Vec3::new(a.cos(), a.sin(), 0.0);
        for h in [Hemisphere::Front, Hemisphere::Back] {
            let p = paraboloid_dir_to_point(d, h);
            assert!((p.length() - 1.0).abs() < 1e-6, "{d}: {p}");
            assert!((paraboloid_point_to_dir(p, h) - d).length() < 1e-6);
        }
        assert_eq!(Hemisphere::of(d), Hemisphere::Front, "z = 0 belongs to the front map");
    }
}

#[test]
fn paraboloid_singular_direction_gives_no_nan() {
    // Approaching z -> -1 on the front map: the radius grows like 2 / angle, stays finite,
    // never NaN, and stops at PARABOLOID_MAX_RADIUS.
    let mut last = 0.0;
    for k in 1..40 {
        let angle = 10f32.powf(-(k as f32) / 4.0); // angle from -Z, 0.56 rad down to 1e-10
        let d = Vec3::new(angle.sin(), 0.0, -angle.cos());
        let p = paraboloid_dir_to_point(d, Hemisphere::Front);
        assert!(p.is_finite(), "angle {angle}: {p}");
        let r = p.length();
        assert!(r >= last * (1.0 - 1e-6) && r <= PARABOLOID_MAX_RADIUS * (1.0 + 1e-6), "angle {angle}: r = {r}");
        if r < 0.5 * PARABOLOID_MAX_RADIUS {
            // accurate before the clamp: r = (1 - z)/sin(angle) = cot(angle / 2)
            let want = 1.0 / (angle / 2.0).tan();
            assert!((r / want - 1.0).abs() < 1e-4, "angle {angle}: r = {r}, want {want}");
            assert!((paraboloid_point_to_dir(p, Hemisphere::Front) - d).length() < 1e-4);
        }
        last = r;
    }
    let exact = paraboloid_dir_to_point(Vec3::NEG_Z, Hemisphere::Front);
    assert_eq!(exact, Vec2::new(PARABOLOID_MAX_RADIUS, 0.0));
    // The far point maps back to (nearly) -Z.
    assert!(paraboloid_point_to_dir(exact, Hemisphere::Front).z < -0.999_999);
    // The same direction is the centre of the back map.
    assert!(paraboloid_dir_to_point(Vec3::NEG_Z, Hemisphere::Back).length() < 1e-7);
}

#[test]
fn paraboloid_jacobian_integrates_to_two_pi() {
    let n = 1024;
    let mut sum = 0.0f64;
    for y in 0..n {
        for x in 0..n {
            let p = Vec2::new((x as f32 + 0.5) / n as f32 * 2.0 - 1.0, (y as f32 + 0.5) / n as f32 * 2.0 - 1.0);
            if p.length_squared() <= 1.0 {
                sum += f64::from(paraboloid_jacobian(p)) * 4.0 / f64::from(n * n);
            }
        }
    }
    assert!((sum / (2.0 * PI) - 1.0).abs() < 1e-3, "{sum}");
}

#[test]
fn every_layout_round_trips_texel_centres() {
    let layouts = [
        Layout::LatLong { width: 64, height: 32 },
        Layout::CubeStrip { face: 16 },
        Layout::Paraboloid { size: 32, hemisphere: Hemisphere::Front },
        Layout::Paraboloid { size: 32, hemisphere: Hemisphere::Back },
        Layout::DualParaboloid { size: 32 },
    ];
    for layout in layouts {
        let (w, h) = layout.size();
        let mut covered = 0.0;
        for y in 0..h {
            for x in 0..w {
                let uv = Vec2::new((x as f32 + 0.5) / w as f32, (y as f32 + 0.5) / h as f32);
                let Some(d) = layout.uv_to_dir(uv) else { continue };
                covered += layout.texel_solid_angle(x, y);
                assert!((d.length() - 1.0).abs() < 1e-5);
                let back = layout.dir_to_uv(d).unwrap_or_else(|| panic!("{layout:?}: {d} not covered"));
                assert!((layout.uv_to_dir(back).unwrap_or(Vec3::ZERO) - d).length() < 1e-5, "{layout:?} {uv}");
            }
        }
        let want = if matches!(layout, Layout::Paraboloid { .. }) { 2.0 * PI } else { 4.0 * PI };
        assert!((covered / want - 1.0).abs() < 0.02, "{layout:?}: covers {covered} sr");
    }
}

#[test]
fn resampling_a_constant_map_stays_constant_and_keeps_its_power() {
    let l = Vec3::new(1.0, 2.0, 3.0);
    let map = EnvMap::constant(128, 64, l);
    for layout in
        [Layout::CubeStrip { face: 32 }, Layout::DualParaboloid { size: 64 }, Layout::LatLong { width: 48, height: 24 }]
    {
        let img = map.to_layout(layout);
        assert!(img.pixels().iter().all(|p| (*p - l).abs().max_element() < 1e-5), "{layout:?}");
        let p = img.power();
        let tol = if matches!(layout, Layout::DualParaboloid { .. }) { 2e-3 } else { 1e-6 };
        assert!((p[2] / (4.0 * PI * 3.0) - 1.0).abs() < tol, "{layout:?}: {p:?}");
    }
}

#[test]
fn downsampling_preserves_power() {
    let map = envmap_sphere::default_map();
    let p0 = map.power();
    // Integer factors: exact solid-angle-weighted box filter.
    for (w, h) in [(512, 256), (128, 64), (8, 4)] {
        let p = map.resize(w, h).power();
        for c in 0..3 {
            assert!((p[c] / p0[c] - 1.0).abs() < 1e-6, "{w}x{h}: {p:?} vs {p0:?}");
        }
    }
    // Other layouts: supersampled, so power is kept to the resampling error.
    let cube = map.to_layout(Layout::CubeStrip { face: 128 });
    let back = EnvMap::resample_from(&cube, 256, 128);
    for p in [cube.power(), back.power()] {
        assert!((p[1] / p0[1] - 1.0).abs() < 0.03, "{p:?} vs {p0:?}");
    }
}

#[test]
fn sphere_image_lookup_finds_what_was_resampled() {
    // A smooth map survives latlong -> cube -> lookup to within the bilinear error.
    let map = EnvMap::from_fn(256, 128, |d| Vec3::new(1.0 + d.x, 2.0 + d.y, 1.5 + d.z));
    for layout in [Layout::CubeStrip { face: 64 }, Layout::DualParaboloid { size: 128 }] {
        let img = SphereImage::resample(&map, layout);
        let mut rng = common::rng(9);
        for _ in 0..2000 {
            let d = common::random_dir(&mut rng);
            let want = Vec3::new(1.0 + d.x, 2.0 + d.y, 1.5 + d.z);
            let got = img.radiance(d);
            assert!((got - want).abs().max_element() < 0.03, "{layout:?} {d}: {got} vs {want}");
        }
    }
}

#[test]
fn back_map_is_the_front_turned_half_a_turn_about_y() {
    // p = (-x, y) / (1 - z) on the back map: a rotation of the front's frame, so triangles keep
    // their winding when a rasterizer draws into it (a shadow map's back map is this one).
    for k in 0..200 {
        let a = k as f32 * 2.399_963;
        let z = -(k as f32 + 0.5) / 200.0;
        let s = (1.0 - z * z).sqrt();
        let d = Vec3::new(s * a.cos(), s * a.sin(), z);
        let want = Vec2::new(-d.x, d.y) / (1.0 - d.z);
        let p = paraboloid_dir_to_point(d, Hemisphere::Back);
        assert!((p - want).length() < 1e-6, "{d}: {p} vs {want}");
        let front = paraboloid_dir_to_point(Vec3::new(-d.x, d.y, -d.z), Hemisphere::Front);
        assert!((p - front).length() < 1e-6);
    }
}
