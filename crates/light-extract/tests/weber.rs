//! `+weber`: a compact source whose shadow would be visible (over 2 % of some receiver's
//! irradiance) always gets a light of its own: a sun on a pole, across the seam, at f16's
//! largest value over black; the books still balance and the budget holds.

use envmap_sphere::{EnvMap, luminance};
use glam::Vec3;
use light_extract::{
    COVERED_SHARE, CompactSource, Decomposition, EmissiveSplit, LightExtractor, MedianCut, Weber, extractor,
};
use std::f64::consts::PI;

const K: usize = 32;

/// A dim sky over a darker ground, and a sun: the texels within `radius` of `sun`, of radiance
/// `sun_radiance`.
fn sky_with_sun(w: u32, h: u32, sun: Vec3, radius: f32, sun_radiance: f32) -> EnvMap {
    let cos_r = radius.cos();
    EnvMap::from_texels(w, h, |i, j| {
        let d = envmap_sphere::texel_centre_dir(i, j, w, h);
        if d.dot(sun) >= cos_r {
            Vec3::splat(sun_radiance)
        } else if d.y >= 0.0 {
            Vec3::new(0.3, 0.4, 0.6)
        } else {
            Vec3::splat(0.05)
        }
    })
}

/// Brute-force irradiance (luminance) at normal `n` from the texels `keep` selects.
fn irradiance(map: &EnvMap, n: Vec3, keep: impl Fn(u32, u32) -> bool) -> f64 {
    let mut e = 0.0;
    for j in 0..map.height() {
        for i in 0..map.width() {
            if keep(i, j) {
                let y = f64::from(luminance(map.pixel(i, j)));
                e += y * map.texel_solid_angle(j) * f64::from(n.dot(map.texel_dir(i, j)).max(0.0));
            }
        }
    }
    e
}

fn no_nan(d: &Decomposition) {
    for l in &d.lights {
        assert!(l.light.direction.is_finite() && (l.light.direction.length() - 1.0).abs() < 1e-4, "{l:?}");
        assert!(l.light.radiance.is_finite() && l.light.solid_angle > 0.0 && l.extent.is_finite(), "{l:?}");
    }
    assert!(d.ambient.pixels().iter().all(|p| p.is_finite()));
}

/// Whether `d` lights `source` with lights of its own (at least half its power).
fn has_own_light(d: &Decomposition, source: &CompactSource, map: &EnvMap) -> bool {
    let texel = (PI / f64::from(map.height())) as f32;
    source.covered_share(&d.lights, texel) >= COVERED_SHARE
}

/// The sun as the only visible compact source of `map`, with its share of a receiver's
/// irradiance checked against brute force at the sun's own direction.
fn the_sun(map: &EnvMap, sun: Vec3) -> CompactSource {
    let sources = Weber::new(MedianCut::default()).visible_sources(map);
    assert_eq!(
        sources.len(),
        1,
        "{:?}",
        sources.iter().map(|s| (s.direction, s.irradiance_fraction)).collect::<Vec<_>>()
    );
    let s = sources.into_iter().next().unwrap_or_else(|| unreachable!());
    assert!(s.direction.dot(sun) > 0.9999, "{} vs {sun}", s.direction);
    let in_sun: std::collections::HashSet<(u32, u32)> = s.texels.iter().copied().collect();
    let share = irradiance(map, sun, |i, j| in_sun.contains(&(i, j))) / irradiance(map, sun, |_, _| true);
    // the fraction is the largest over the normals tried, the sun's own among them
    assert!(s.irradiance_fraction >= share * 0.97, "{} vs brute force {share}", s.irradiance_fraction);
    s
}

fn check_weber(map: &EnvMap, sun: Vec3, method: &str) -> Decomposition {
    let s = the_sun(map, sun);
    let e = extractor(&format!("{method}+weber"), K).unwrap_or_else(|| panic!("{method}+weber"));
    let d = e.extract(map).unwrap_or_else(|e| panic!("{e}"));
    no_nan(&d);
    assert!(d.method.ends_with("+weber"), "{}", d.method);
    assert!(d.lights.len() <= K, "{}: {} lights", d.method, d.lights.len());
    // importance sampling's lights do not partition the map: it keeps no books
    assert!(!d.partitions || d.power_balance_error() < 1e-4, "{}: books {}", d.method, d.power_balance_error());
    assert!(has_own_light(&d, &s, map), "{}: no light for the sun", d.method);
    // when +weber made the light, one light carries exactly the sun's power
    if d.params["added"].as_array().is_some_and(|a| !a.is_empty()) {
        let p =
            d.lights.iter().map(|l| l.power().as_dvec3()).find(|p| (*p - s.power).length() < 1e-4 * s.power.length());
        assert!(p.is_some(), "no light of the sun's power {}", s.power);
    }
    d
}

#[test]
fn a_sun_on_the_pole_gets_its_own_light() {
    let (w, h) = (512, 256);
    // the sun: the two top rows, a disc round the pole
    let radius = 2.0 * std::f32::consts::PI / h as f32 * 0.99;
    let probe = sky_with_sun(w, h, Vec3::Y, radius, 1.0);
    let sun_sa: f64 = (0..2).map(|j| probe.texel_solid_angle(j) * f64::from(w)).sum();
    // ~4 % of the map's power
    let sky_power = envmap_sphere::color::luminance_f64(probe.power()) - sun_sa;
    let radiance = (0.04 / 0.96 * sky_power / sun_sa) as f32;
    let map = sky_with_sun(w, h, Vec3::Y, radius, radiance);
    let s = the_sun(&map, Vec3::Y);
    let power_share =
        envmap_sphere::color::luminance_f64(s.power.to_array()) / envmap_sphere::color::luminance_f64(map.power());
    assert!((power_share - 0.04).abs() < 0.002, "{power_share}");
    assert!(s.irradiance_fraction > 0.05, "{}", s.irradiance_fraction);
    // the paper's method gives it no light of its own: its shadow would vanish
    let paper = EmissiveSplit { lights: K, ..EmissiveSplit::default() }.extract(&map).unwrap_or_else(|e| panic!("{e}"));
    assert!(!has_own_light(&paper, &s, &map), "emissive split now lights the pole sun by itself");
    let d = check_weber(&map, Vec3::Y, "emissive-split");
    assert_eq!(d.params["added"].as_array().map(Vec::len), Some(1));
    for m in ["median-cut", "center-surround", "variance-min", "importance", "emissive-split+moment-cones"] {
        check_weber(&map, Vec3::Y, m);
    }
}

#[test]
fn a_sun_across_the_seam_gets_one_light() {
    let (w, h) = (512, 256);
    // phi = 0 is the seam (columns 0 and w - 1): dir (0, sin e, -cos e)
    let e = 0.5f32;
    let sun = Vec3::new(0.0, e.sin(), -e.cos());
    let map = sky_with_sun(w, h, sun, 0.03, 400.0);
    let s = the_sun(&map, sun);
    let (min_i, max_i) = s.texels.iter().fold((u32::MAX, 0), |(a, b), &(i, _)| (a.min(i), b.max(i)));
    assert!(min_i == 0 && max_i == w - 1, "the sun straddles the seam: columns {min_i}..{max_i}");
    for m in ["emissive-split", "median-cut", "center-surround"] {
        check_weber(&map, sun, m);
    }
}

#[test]
fn an_f16_max_sun_over_black_is_one_finite_light() {
    let (w, h) = (256, 128);
    let sun = Vec3::new(0.6, 0.64, 0.48).normalize();
    let map = sky_with_sun(w, h, sun, 0.02, 65504.0).clone();
    let map = EnvMap::from_texels(w, h, |i, j| {
        let p = map.pixel(i, j);
        if p.x > 1.0 { p } else { Vec3::ZERO }
    });
    let s = the_sun(&map, sun);
    assert!((s.irradiance_fraction - 1.0).abs() < 1e-9, "{}", s.irradiance_fraction);
    for m in ["emissive-split", "median-cut", "center-surround", "importance"] {
        check_weber(&map, sun, m);
    }
}

#[test]
fn maps_without_compact_sources_are_left_to_the_inner_method() {
    for map in [
        EnvMap::constant(256, 128, Vec3::new(1.0, 0.9, 0.8)),
        EnvMap::constant(256, 128, Vec3::ZERO),
        EnvMap::from_fn(256, 128, |d| Vec3::splat(1.0 + d.y.max(0.0))),
    ] {
        let weber = Weber::new(MedianCut::default());
        assert!(weber.visible_sources(&map).is_empty());
        let d = weber.extract(&map).unwrap_or_else(|e| panic!("{e}"));
        let plain = MedianCut::default().extract(&map).unwrap_or_else(|e| panic!("{e}"));
        no_nan(&d);
        assert_eq!(d.lights, plain.lights);
        assert_eq!(d.params["added"].as_array().map(Vec::len), Some(0));
    }
}

#[test]
fn more_visible_sources_than_the_budget_keep_the_budget() {
    // eight equal suns round the horizon, budget four: the four most visible get lights, the
    // rest of the map is ambient, and the books balance
    let (w, h) = (256, 128);
    let suns: Vec<Vec3> = (0..8)
        .map(|k| {
            let a = k as f32 * std::f32::consts::TAU / 8.0 + 0.1;
            Vec3::new(a.cos(), 0.3, a.sin()).normalize()
        })
        .collect();
    let map = EnvMap::from_texels(w, h, |i, j| {
        let d = envmap_sphere::texel_centre_dir(i, j, w, h);
        if suns.iter().any(|s| d.dot(*s) > 0.05f32.cos()) { Vec3::splat(500.0) } else { Vec3::splat(0.2) }
    });
    let weber = Weber::new(MedianCut::with_lights(4));
    assert_eq!(weber.visible_sources(&map).len(), 8);
    let d = weber.extract(&map).unwrap_or_else(|e| panic!("{e}"));
    no_nan(&d);
    assert!(d.lights.len() <= 4, "{}", d.lights.len());
    assert!(d.power_balance_error() < 1e-4);
    let four = Weber::new(MedianCut::with_lights(1)).extract(&map).unwrap_or_else(|e| panic!("{e}"));
    assert_eq!(four.lights.len(), 1);
    assert!(four.power_balance_error() < 1e-4);
}

#[test]
fn weber_composes_with_the_other_options() {
    let sun = Vec3::new(0.3, 0.5, -0.8).normalize();
    let map = sky_with_sun(256, 128, sun, 0.03, 300.0);
    for name in [
        "emissive-split+moment-cones+weber+above-horizon+residual",
        "median-cut+weber+above-horizon",
        "center-surround+weber+residual",
    ] {
        let d = extractor(name, K).unwrap_or_else(|| panic!("{name}")).extract(&map).unwrap_or_else(|e| panic!("{e}"));
        no_nan(&d);
        assert_eq!(d.method, name);
        assert!(d.lights.len() <= K);
    }
    assert!(extractor("median-cut+above-horizon+weber", K).is_none(), "+weber comes before +above-horizon");
}
