//! Power, irradiance and SH irradiance against closed forms and brute-force integration.

mod common;

use envmap_sphere::{EnvMap, Sh9, luminance};
use glam::Vec3;
use std::f64::consts::PI;

#[test]
fn constant_map_has_power_four_pi_l_and_irradiance_pi_l() {
    let l = Vec3::new(0.5, 1.0, 2.0);
    for (w, h) in [(1024, 512), (64, 32)] {
        let map = EnvMap::constant(w, h, l);
        let p = map.power();
        for c in 0..3 {
            let want = 4.0 * PI * f64::from(l[c]);
            assert!((p[c] / want - 1.0).abs() < 1e-6, "{w}x{h} power {p:?}");
        }
        let normals = common::fibonacci_dirs(64);
        for (n, e) in normals.iter().zip(map.irradiance_many(&normals)) {
            let rel = (e / (l * std::f32::consts::PI) - 1.0).abs().max_element();
            // The only error is texels straddling the horizon of n.
            let tol = if w == 1024 { 2e-4 } else { 5e-3 };
            assert!(rel < tol, "{w}x{h} n = {n}: {e}, relative error {rel}");
        }
    }
}

#[test]
fn sh_irradiance_of_a_constant_map_is_pi_l() {
    let l = Vec3::new(0.25, 1.0, 3.0);
    let sh = Sh9::project(&EnvMap::constant(256, 128, l));
    for n in common::fibonacci_dirs(50) {
        let e = sh.irradiance(n);
        assert!((e / (l * std::f32::consts::PI) - 1.0).abs().max_element() < 1e-4, "{n}: {e}");
    }
}

#[test]
fn sh_irradiance_equals_brute_force_for_band_limited_maps() {
    let mut rng = common::rng(11);
    for _ in 0..3 {
        let mut sh = Sh9::default();
        sh.coeffs[0] = Vec3::splat(8.0); // keeps radiance positive
        for c in sh.coeffs.iter_mut().skip(1) {
            *c = Vec3::new(
                rand::Rng::random_range(&mut rng, -1.0..1.0),
                rand::Rng::random_range(&mut rng, -1.0..1.0),
                rand::Rng::random_range(&mut rng, -1.0..1.0),
            );
        }
        let map = sh.to_map(512, 256);
        let projected = Sh9::project(&map);
        let normals = common::fibonacci_dirs(100);
        for (n, brute) in normals.iter().zip(map.irradiance_many(&normals)) {
            let fast = projected.irradiance(*n);
            let rel = ((fast - brute).abs() / brute.abs()).max_element();
            assert!(rel < 1e-3, "n = {n}: SH {fast} vs brute force {brute} ({rel})");
        }
    }
}

/// Measured error of order-2 SH irradiance against brute-force integration on each shared map:
/// (file, mean error, max error), both relative to the mean irradiance, luminance, over 400
/// normals spread evenly over the sphere. Regressions show as a change of these values.
const PINNED_SH_ERROR: [(&str, f64, f64); 11] = [
    ("adams_place_bridge_1k.hdr", 0.0313, 0.2282),
    ("city.exr", 0.0387, 0.1095),
    ("courtyard.exr", 0.0348, 0.0942),
    ("empty_warehouse_01_1k.hdr", 0.0205, 0.0832),
    ("forest_slope_1k.hdr", 0.0102, 0.0311),
    ("kiara_1_dawn_1k.hdr", 0.0237, 0.0878),
    ("lebombo_1k.hdr", 0.0137, 0.0468),
    ("potsdamer_platz_1k.hdr", 0.0097, 0.0262),
    ("st_fagans_interior_1k.hdr", 0.0144, 0.0489),
    ("studio.exr", 0.0675, 0.2198),
    ("venice_sunset_1k.hdr", 0.0108, 0.0349),
];

/// (mean, max) |Y(E_sh) - Y(E_brute)| over the normals, divided by the mean Y(E_brute).
fn sh_irradiance_error(map: &EnvMap, normals: &[Vec3]) -> (f64, f64) {
    let sh = Sh9::project(map);
    let brute = map.irradiance_many(normals);
    let mean_e: f64 = brute.iter().map(|e| f64::from(luminance(*e))).sum::<f64>() / normals.len() as f64;
    let errs: Vec<f64> = normals
        .iter()
        .zip(&brute)
        .map(|(n, e)| f64::from((luminance(sh.irradiance(*n)) - luminance(*e)).abs()))
        .collect();
    let mean = errs.iter().sum::<f64>() / errs.len() as f64;
    let max = errs.iter().copied().fold(0.0, f64::max);
    (mean / mean_e, max / mean_e)
}

#[test]
fn sh_irradiance_error_on_real_maps_is_as_measured() {
    let normals = common::fibonacci_dirs(400);
    let mut report = String::new();
    let mut failures = Vec::new();
    for path in common::shared_maps() {
        let map = EnvMap::load(&path).expect("shared map loads");
        let (mean, max) = sh_irradiance_error(&map, &normals);
        let name = path.file_name().unwrap_or_default().to_string_lossy().to_string();
        report.push_str(&format!("    (\"{name}\", {mean:.4}, {max:.4}),\n"));
        let Some(&(_, want_mean, want_max)) = PINNED_SH_ERROR.iter().find(|(n, _, _)| *n == name) else {
            failures.push(format!("{name}: not pinned"));
            continue;
        };
        // 2% relative slack: the values are deterministic up to float summation order.
        if (mean - want_mean).abs() > 0.02 * want_mean + 1e-4 || (max - want_max).abs() > 0.02 * want_max + 1e-4 {
            failures.push(format!("{name}: mean {mean:.4} (pinned {want_mean}), max {max:.4} (pinned {want_max})"));
        }
    }
    assert!(failures.is_empty(), "{}\nmeasured:\n{report}", failures.join("\n"));
}
