//! The lat-long convention: orientation, solid angles, round trips, seam and poles.

mod common;

use envmap_sphere::latlong::{atan2, latlong_dir_to_uv, latlong_texel_solid_angle, latlong_uv_to_dir};
use envmap_sphere::{EnvMap, Sh9};
use glam::{Vec2, Vec3};
use std::f64::consts::PI;

fn formula_dir(i: u32, j: u32, w: u32, h: u32) -> Vec3 {
    // Written out from the convention, independently of the library.
    let u = (f64::from(i) + 0.5) / f64::from(w);
    let v = (f64::from(j) + 0.5) / f64::from(h);
    let (phi, theta) = (2.0 * PI * u, PI * v);
    Vec3::new((theta.sin() * phi.sin()) as f32, theta.cos() as f32, (-theta.sin() * phi.cos()) as f32)
}

#[test]
fn solid_angles_sum_to_four_pi() {
    for (w, h) in [(1024, 512), (8, 4), (7, 3), (4096, 2048), (1, 1)] {
        let sum: f64 = (0..h).map(|j| latlong_texel_solid_angle(j, w, h) * f64::from(w)).sum();
        assert!((sum / (4.0 * PI) - 1.0).abs() < 1e-6, "{w}x{h}: {sum}");
    }
}

#[test]
fn one_bright_texel_lies_in_the_formula_direction() {
    let (w, h) = (64, 32);
    for (i, j) in [(0, 0), (16, 16), (32, 16), (48, 7), (63, 31), (5, 25)] {
        let mut map = EnvMap::constant(w, h, Vec3::ZERO);
        map.set_pixel(i, j, Vec3::ONE);
        let want = formula_dir(i, j, w, h);
        assert!((map.texel_dir(i, j) - want).length() < 1e-6, "texel ({i}, {j})");
        assert_eq!(map.texel_of_dir(want), (i, j));
        assert_eq!(map.lookup_nearest(want), Vec3::ONE);
        // Independent of the lookup code: the l = 1 SH coefficients are proportional to the
        // mean direction of the light, (c[3], c[1], c[2]) ~ (x, y, z).
        let sh = Sh9::project(&map);
        let d = Vec3::new(sh.coeffs[3].x, sh.coeffs[1].x, sh.coeffs[2].x).normalize();
        assert!(d.dot(want) > 0.9999, "({i}, {j}): SH says {d}, formula {want}");
    }
}

#[test]
fn named_directions_sit_where_the_convention_says() {
    let (w, h) = (1024, 512);
    let map = EnvMap::constant(w, h, Vec3::ZERO);
    // -Z at the seam u = 0, +X at u = 0.25, +Z at the centre, -X at u = 0.75, +Y the top row.
    assert_eq!(map.texel_of_dir(Vec3::new(-1e-4, 0.0, -1.0)), (1023, 256));
    assert_eq!(map.texel_of_dir(Vec3::new(1e-4, 0.0, -1.0)), (0, 256));
    assert_eq!(map.texel_of_dir(Vec3::new(1.0, 1e-4, 0.0)), (256, 255));
    assert_eq!(map.texel_of_dir(Vec3::new(-1e-4, -1e-4, 1.0)), (512, 256));
    assert_eq!(map.texel_of_dir(Vec3::new(-1.0, 1e-4, 1e-4)), (767, 255));
    assert_eq!(map.texel_of_dir(Vec3::Y).1, 0);
    assert_eq!(map.texel_of_dir(Vec3::NEG_Y).1, 511);
    // Right-handed with +Y up: facing -Z, the right-hand side is forward x up = +X, and the
    // panorama is not mirrored: going right from the seam (u grows) turns towards +X.
    let right = Vec3::NEG_Z.cross(Vec3::Y);
    assert!(latlong_uv_to_dir(Vec2::new(0.01, 0.5)).dot(right) > 0.0);
    assert!(latlong_uv_to_dir(Vec2::new(0.25, 0.5)).dot(right) > 0.999);
}

#[test]
fn dir_uv_dir_round_trips_for_random_directions() {
    let mut rng = common::rng(7);
    for _ in 0..100_000 {
        let d = common::random_dir(&mut rng);
        let uv = latlong_dir_to_uv(d);
        assert!((0.0..1.0).contains(&uv.x) && (0.0..=1.0).contains(&uv.y), "{d} -> {uv}");
        let back = latlong_uv_to_dir(uv);
        assert!((back - d).length() < 2e-6, "{d} -> {uv} -> {back}");
    }
}

#[test]
fn fast_atan2_matches_libm_everywhere() {
    use rand::Rng;
    let mut rng = common::rng(11);
    // error in units of the f32 spacing at the exact result (libm's own is up to about 0.5)
    let mut worst = 0.0f64;
    for k in 0..400_000 {
        // every octant and ratios from 1e-30 to 1e30
        let scale = |r: &mut rand_pcg::Pcg64Mcg| 10f32.powf(r.random_range(-30.0..30.0));
        let (y, x) = if k % 2 == 0 {
            (rng.random_range(-1.0f32..1.0), rng.random_range(-1.0f32..1.0))
        } else {
            (rng.random_range(-1.0f32..1.0) * scale(&mut rng), rng.random_range(-1.0f32..1.0) * scale(&mut rng))
        };
        let exact = f64::from(y).atan2(f64::from(x));
        let ulp = f64::from((exact as f32).abs().next_up() - (exact as f32).abs());
        worst = worst.max((f64::from(atan2(y, x)) - exact).abs() / ulp);
    }
    assert!(worst < 3.0, "largest error {worst} ulp");
    // Zeros, infinities and NaN keep libm's exact answers (signed zeros decide u at the poles).
    let special = [0.0f32, -0.0, f32::INFINITY, f32::NEG_INFINITY];
    let any = [0.0f32, -0.0, 1.0, -1.0, f32::MIN_POSITIVE, f32::MAX, f32::INFINITY, f32::NEG_INFINITY];
    for a in special {
        for b in any {
            assert_eq!(atan2(a, b).to_bits(), a.atan2(b).to_bits(), "atan2({a}, {b})");
            assert_eq!(atan2(b, a).to_bits(), b.atan2(a).to_bits(), "atan2({b}, {a})");
        }
    }
    assert!(atan2(f32::NAN, 1.0).is_nan() && atan2(1.0, f32::NAN).is_nan());
}

#[test]
fn round_trips_hold_at_the_poles_and_the_seam() {
    for d in [Vec3::Y, Vec3::NEG_Y, Vec3::new(1e-7, 1.0, 0.0).normalize(), Vec3::new(0.0, -1.0, 1e-7).normalize()] {
        let uv = latlong_dir_to_uv(d);
        assert!(uv.is_finite());
        assert!((latlong_uv_to_dir(uv) - d).length() < 1e-6, "{d} -> {uv}");
    }
    assert_eq!(latlong_dir_to_uv(Vec3::Y).y, 0.0);
    assert_eq!(latlong_dir_to_uv(Vec3::NEG_Y).y, 1.0);
    // Either side of the seam, and exactly on it.
    for x in [-1e-6f32, -f32::MIN_POSITIVE, 0.0, -0.0, f32::MIN_POSITIVE, 1e-6] {
        let d = Vec3::new(x, 0.3, -1.0).normalize();
        let uv = latlong_dir_to_uv(d);
        assert!((0.0..1.0).contains(&uv.x), "x = {x}: u = {}", uv.x);
        assert!((latlong_uv_to_dir(uv) - d).length() < 1e-6);
    }
    // u = 1 - eps and u = 1 are the seam again.
    let a = latlong_uv_to_dir(Vec2::new(1.0 - f32::EPSILON, 0.5));
    let b = latlong_uv_to_dir(Vec2::new(1.0, 0.5));
    assert!((a - Vec3::NEG_Z).length() < 1e-5 && (b - Vec3::NEG_Z).length() < 1e-5);
}

#[test]
fn bilinear_lookup_wraps_in_u_and_clamps_in_v() {
    let (w, h) = (16, 8);
    let map = EnvMap::from_texels(w, h, |i, j| match (i, j) {
        (0, _) => Vec3::new(2.0, 0.0, 0.0),
        (15, _) => Vec3::new(0.0, 4.0, 0.0),
        _ => Vec3::ZERO,
    });
    // u = 0 lies halfway between the centres of columns 15 and 0.
    let seam = map.lookup_uv(Vec2::new(0.0, 0.5));
    assert!((seam - Vec3::new(1.0, 2.0, 0.0)).length() < 1e-5, "{seam}");
    let top = map.lookup_uv(Vec2::new(0.5 / 16.0, 0.0));
    assert!((top - Vec3::new(2.0, 0.0, 0.0)).length() < 1e-5, "{top}");
}

#[test]
fn rotating_by_columns_rotates_directions_about_y() {
    let map = EnvMap::from_texels(32, 16, |i, j| Vec3::new(i as f32, j as f32, 1.0));
    let rotated = map.rotate_columns(8); // +90 degrees of phi
    // phi grows: the direction of old texel (i, j) is now found at column i + 8.
    assert_eq!(rotated.pixel(10, 3), map.pixel(2, 3));
    assert_eq!(rotated.pixel(2, 3), map.pixel(26, 3));
}

#[test]
fn luminance_uses_the_rec709_weights() {
    // Y of the Rec.709 primaries (ITU-R BT.709, the Y row of its RGB-to-XYZ matrix)
    let weights = [0.2126, 0.7152, 0.0722];
    for (k, w) in weights.iter().enumerate() {
        let mut rgb = [0.0f32; 3];
        rgb[k] = 1.0;
        assert!((envmap_sphere::luminance(Vec3::from_array(rgb)) - w).abs() < 1e-6, "channel {k}");
    }
    // white has Y = 1, and Y is linear
    assert!((envmap_sphere::luminance(Vec3::ONE) - 1.0).abs() < 1e-6);
    let (a, b) = (Vec3::new(0.3, 2.0, 7.0), Vec3::new(5.0, 0.1, 0.4));
    let lin = envmap_sphere::luminance(2.0 * a + b) - (2.0 * envmap_sphere::luminance(a) + envmap_sphere::luminance(b));
    assert!(lin.abs() < 1e-5);
}

/// The nine functions in the documented order, each its documented polynomial with the
/// normalization derived here ((2l + 1) / 4 pi (l - m)! / (l + m)!, real form), and together
/// orthonormal over the sphere (by quadrature, not from the code's constants).
#[test]
fn sh_basis_is_the_documented_order_and_orthonormal() {
    let pi = PI;
    let c0 = (1.0 / (4.0 * pi)).sqrt();
    let c1 = (3.0 / (4.0 * pi)).sqrt();
    let c2 = (15.0 / (4.0 * pi)).sqrt();
    let c20 = (5.0 / (16.0 * pi)).sqrt();
    let c22 = (15.0 / (16.0 * pi)).sqrt();
    let documented = |d: Vec3| {
        let (x, y, z) = (f64::from(d.x), f64::from(d.y), f64::from(d.z));
        [
            c0,
            c1 * y,
            c1 * z,
            c1 * x,
            c2 * x * y,
            c2 * y * z,
            c20 * (3.0 * z * z - 1.0),
            c2 * x * z,
            c22 * (x * x - y * y),
        ]
    };
    let mut rng = common::rng(5);
    for _ in 0..200 {
        let d = common::random_dir(&mut rng);
        let got = envmap_sphere::sh::sh9_basis(d);
        for (k, (g, want)) in got.iter().zip(documented(d)).enumerate() {
            assert!((f64::from(*g) - want).abs() < 1e-5, "Y_{k} at {d}: {g} vs {want}");
        }
    }
    // orthonormality: midpoint quadrature in (cos theta, phi)
    let n = 200;
    let mut gram = [[0.0f64; 9]; 9];
    for a in 0..n {
        for b in 0..2 * n {
            let z = -1.0 + 2.0 * (a as f64 + 0.5) / n as f64;
            let phi = (b as f64 + 0.5) / (2 * n) as f64 * 2.0 * pi;
            let r = (1.0 - z * z).sqrt();
            let y = envmap_sphere::sh::sh9_basis(Vec3::new((r * phi.cos()) as f32, (r * phi.sin()) as f32, z as f32));
            let w = 4.0 * pi / (2 * n * n) as f64;
            for i in 0..9 {
                for j in 0..9 {
                    gram[i][j] += f64::from(y[i]) * f64::from(y[j]) * w;
                }
            }
        }
    }
    for (i, row) in gram.iter().enumerate() {
        for (j, g) in row.iter().enumerate() {
            let want = if i == j { 1.0 } else { 0.0 };
            assert!((g - want).abs() < 1e-3, "<Y_{i}, Y_{j}> = {g}");
        }
    }
}

/// docs/conventions.md says each of its rules is checked by a test named in brackets: every
/// list item and paragraph under a heading names at least one, and each named test exists here.
#[test]
fn conventions_doc_names_an_existing_test_for_every_rule() {
    let root = std::path::Path::new(env!("CARGO_MANIFEST_DIR"));
    let doc = std::fs::read_to_string(root.join("../../docs/conventions.md")).expect("docs/conventions.md");
    let mut tests = String::new();
    for entry in std::fs::read_dir(root.join("tests")).expect("tests/") {
        let path = entry.expect("entry").path();
        if path.extension().is_some_and(|x| x == "rs") {
            tests.push_str(&std::fs::read_to_string(&path).expect("read test"));
        }
    }
    // rules: list items and paragraphs after the first heading
    let mut rules: Vec<String> = Vec::new();
    let mut open = false;
    for line in doc.lines().skip_while(|l| !l.starts_with("## ")) {
        if line.trim().is_empty() || line.starts_with('#') {
            open = false;
        } else if line.starts_with("- ") || !open {
            rules.push(line.to_string());
            open = true;
        } else if let Some(last) = rules.last_mut() {
            last.push(' ');
            last.push_str(line.trim());
        }
    }
    assert!(rules.len() >= 20, "{} rules found", rules.len());
    for rule in &rules {
        let names: Vec<&str> = rule
            .split('[')
            .skip(1)
            .filter_map(|b| b.split(']').next())
            .filter(|b| b.starts_with('`'))
            .flat_map(|b| b.split(',').map(|n| n.trim().trim_matches('`')))
            .collect();
        assert!(!names.is_empty(), "a rule names no test: {rule}");
        for n in names {
            assert!(tests.contains(&format!("fn {n}(")), "{n} is not a test in crates/envmap-sphere/tests/ ({rule})");
        }
    }
}
