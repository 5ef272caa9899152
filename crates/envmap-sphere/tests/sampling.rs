//! Importance sampling: normalization, sample/pdf agreement, chi-square, inversion, extremes.

mod common;

use envmap_sphere::distribution::ONE_MINUS_EPSILON;
use envmap_sphere::latlong::row_cos_bounds;
use envmap_sphere::{Distribution1D, EnvDistribution, EnvMap, SummedAreaTable, luminance};
use glam::{Vec2, Vec3};
use rand::Rng;
use std::f64::consts::PI;

/// A small map with a sun, a sky gradient, black texels and a pole feature.
fn test_map() -> EnvMap {
    EnvMap::from_texels(32, 16, |i, j| {
        let mut l = Vec3::splat(0.2 + 0.05 * j as f32);
        if (i, j) == (9, 4) {
            l = Vec3::splat(500.0);
        }
        if j == 0 {
            l = Vec3::new(5.0, 1.0, 0.5);
        }
        if (20..24).contains(&i) && j > 10 {
            l = Vec3::ZERO;
        }
        l
    })
}

#[test]
fn pdf_integrates_to_one() {
    for map in [test_map(), envmap_sphere::default_map()] {
        for dist in [
            EnvDistribution::new(&map),
            EnvDistribution::for_bilinear(&map),
            EnvDistribution::for_bilinear_compensated(&map),
        ] {
            // Quadrature on a grid 3x finer than the texels, independent of the texel layout.
            let (w, h) = (map.width() * 3, map.height() * 3);
            let fine = EnvMap::constant(w, h, Vec3::ZERO);
            let mut sum = 0.0;
            for j in 0..h {
                let sa = fine.texel_solid_angle(j);
                for i in 0..w {
                    sum += f64::from(dist.dir_pdf(fine.texel_dir(i, j))) * sa;
                }
            }
            assert!((sum - 1.0).abs() < 1e-4, "{}x{}: {sum}", map.width(), map.height());
        }
    }
}

#[test]
fn sample_pdf_matches_pdf() {
    let map = envmap_sphere::default_map();
    let dist = EnvDistribution::new(&map);
    // Independently of the distribution: pdf = Y(texel) / integral of Y d omega.
    let total: f64 = (0..map.height())
        .map(|j| map.row(j).iter().map(|p| f64::from(luminance(*p))).sum::<f64>() * map.texel_solid_angle(j))
        .sum();
    let mut rng = common::rng(1);
    let mut edge_cases = 0;
    let n = 200_000;
    for _ in 0..n {
        let u = Vec2::new(rng.random(), rng.random());
        let s = dist.sample_dir(u);
        assert!((s.dir.length() - 1.0).abs() < 1e-5);
        assert!((envmap_sphere::latlong::latlong_uv_to_dir(s.uv) - s.dir).length() < 1e-5, "uv is the direction's");
        let (i, j) = ((s.uv.x * 1024.0) as u32, (s.uv.y * 512.0) as u32);
        let want = (f64::from(luminance(map.pixel(i, j))) / total) as f32;
        assert!(s.pdf > 0.0 && s.pdf == dist.uv_pdf(s.uv), "u = {u}");
        assert!((s.pdf - want).abs() <= 1e-5 * want, "u = {u}: pdf {} vs Y / integral {want}", s.pdf);
        if s.pdf != dist.dir_pdf(s.dir) {
            edge_cases += 1; // the f32 direction rounded across a texel edge
        }
    }
    assert!(edge_cases * 10_000 < n, "{edge_cases} of {n} samples disagree with dir_pdf");
}

/// Upper quantile of the chi-square distribution (Wilson-Hilferty), for significance 1e-4.
fn chi_square_critical(dof: f64) -> f64 {
    let z = 3.719; // standard normal quantile of 1 - 1e-4
    let a = 2.0 / (9.0 * dof);
    dof * (1.0 - a + z * a.sqrt()).powi(3)
}

#[test]
fn chi_square_samples_match_the_pdf() {
    let map = test_map();
    let dist = EnvDistribution::new(&map);
    chi_square_test(&map, |u| dist.sample_dir(u).dir);
}

/// Chi-square test of a sampler of `map`'s luminance x solid angle, at 2 x 2 sub-cells per
/// texel (so the placement inside a texel is tested too).
fn chi_square_test(map: &EnvMap, sample: impl Fn(Vec2) -> Vec3) {
    let (w, h) = (map.width() as usize, map.height() as usize);
    // Expected probabilities straight from the map, not from the distribution: texel
    // luminance x solid angle, split evenly into 2 x 2 sub-cells (equal in phi and cos theta).
    let total: f64 = (0..h)
        .map(|j| {
            (0..w).map(|i| f64::from(luminance(map.pixel(i as u32, j as u32)))).sum::<f64>()
                * map.texel_solid_angle(j as u32)
        })
        .sum();
    let cell = |i: usize, j: usize| {
        f64::from(luminance(map.pixel(i as u32, j as u32))) * map.texel_solid_angle(j as u32) / total / 4.0
    };
    let n = 400_000;
    let mut counts = vec![0u32; w * h * 4];
    let mut rng = common::rng(2);
    for _ in 0..n {
        let d = sample(Vec2::new(rng.random(), rng.random()));
        let (i, j) = map.texel_of_dir(d);
        let (i, j) = (i as usize, j as usize);
        let phi = f64::from(d.x.atan2(-d.z)).rem_euclid(2.0 * PI);
        let sub_i = usize::from((phi / (2.0 * PI) * w as f64 - i as f64) >= 0.5);
        let (c0, c1) = row_cos_bounds(j as u32, h as u32);
        let sub_j = usize::from((c0 - f64::from(d.y)) / (c0 - c1) >= 0.5);
        counts[(j * w + i) * 4 + sub_j * 2 + sub_i] += 1;
    }
    let (mut chi2, mut dof, mut pooled_obs, mut pooled_exp) = (0.0, -1.0, 0.0, 0.0);
    for j in 0..h {
        for i in 0..w {
            for k in 0..4 {
                let expected = cell(i, j) * f64::from(n);
                let observed = f64::from(counts[(j * w + i) * 4 + k]);
                if expected == 0.0 {
                    assert_eq!(observed, 0.0, "samples in zero-probability texel ({i}, {j})");
                } else if expected < 5.0 {
                    pooled_obs += observed;
                    pooled_exp += expected;
                } else {
                    chi2 += (observed - expected).powi(2) / expected;
                    dof += 1.0;
                }
            }
        }
    }
    if pooled_exp > 0.0 {
        chi2 += (pooled_obs - pooled_exp).powi(2) / pooled_exp;
        dof += 1.0;
    }
    let critical = chi_square_critical(dof);
    assert!(chi2 < critical, "chi2 = {chi2:.1} with {dof} dof, critical {critical:.1}");
}

#[test]
fn invert_dir_sample_round_trips() {
    let dist = EnvDistribution::new(&envmap_sphere::default_map());
    let h = dist.size().1;
    let mut rng = common::rng(4);
    let mut on_a_row_edge = 0;
    for _ in 0..100_000 {
        let u = Vec2::new(rng.random(), rng.random());
        let d = dist.sample_dir(u).dir;
        let back = dist.invert_dir_sample(d);
        // A direction within f32 resolution of the edge between two rows belongs to either, and
        // the other row's column cdf differs: no round trip there (~1 sample in 1e5).
        let row = (f64::from(d.y).clamp(-1.0, 1.0).acos() / std::f64::consts::PI * f64::from(h)).round();
        if (f64::from(d.y) - (row * std::f64::consts::PI / f64::from(h)).cos()).abs() < 2e-7 {
            on_a_row_edge += 1;
            continue;
        }
        // f32 directions resolve u to about 1e-5 in the map's steepest cdf regions.
        assert!((back - u).abs().max_element() < 2e-4, "{u} -> {d} -> {back}");
        assert!((dist.sample_dir(back).dir - d).length() < 1e-3);
    }
    assert!(on_a_row_edge < 30, "{on_a_row_edge} samples on row edges");
}

#[test]
fn no_nan_at_extremes() {
    let maps = [
        test_map(),
        envmap_sphere::default_map(),
        EnvMap::constant(8, 4, Vec3::ZERO),
        EnvMap::constant(1, 1, Vec3::ONE),
    ];
    let edges = [0.0, f32::MIN_POSITIVE, 0.5, ONE_MINUS_EPSILON, 1.0];
    for map in &maps {
        let dist = EnvDistribution::new(map);
        for &a in &edges {
            for &b in &edges {
                let s = dist.sample_dir(Vec2::new(a, b));
                assert!(s.dir.is_finite() && (s.dir.length() - 1.0).abs() < 1e-5, "u = ({a}, {b}): {s:?}");
                assert!(s.pdf.is_finite() && s.pdf > 0.0, "u = ({a}, {b}): {s:?}");
                assert!(dist.invert_dir_sample(s.dir).is_finite());
                assert_eq!(s.pdf, dist.uv_pdf(s.uv), "u = ({a}, {b}): {s:?}");
            }
        }
        for d in [Vec3::Y, Vec3::NEG_Y, Vec3::NEG_Z, Vec3::new(-1e-9, 0.0, -1.0), Vec3::new(1e-30, 1.0, 0.0)] {
            assert!(dist.dir_pdf(d).is_finite(), "{d}");
            assert!(dist.invert_dir_sample(d).is_finite(), "{d}");
        }
    }
}

#[test]
fn black_map_samples_the_sphere_uniformly() {
    let dist = EnvDistribution::new(&EnvMap::constant(64, 32, Vec3::ZERO));
    let uniform = (1.0 / (4.0 * PI)) as f32;
    let mut rng = common::rng(6);
    let mut mean = Vec3::ZERO;
    let n = 100_000;
    for _ in 0..n {
        let s = dist.sample_dir(Vec2::new(rng.random(), rng.random()));
        assert!((s.pdf / uniform - 1.0).abs() < 1e-5, "{s:?}");
        mean += s.dir / n as f32;
    }
    assert!(mean.length() < 0.01, "uniform samples average to zero, got {mean}");
}

/// Spiky weights with zero runs, as real maps have.
fn spiky_weights(len: usize, rng: &mut impl Rng) -> Vec<f64> {
    (0..len)
        .map(|k| {
            if k % 5 == 1 {
                0.0
            } else if k % 97 == 3 {
                1e6
            } else {
                rng.random::<f64>().powi(8)
            }
        })
        .collect()
}

#[test]
fn guided_sampling_finds_the_binary_search_cell() {
    let mut rng = common::rng(13);
    for len in [1usize, 2, 7, 100, 1000] {
        let weights = spiky_weights(len, &mut rng);
        let d = Distribution1D::new(weights.iter().copied());
        let total: f64 = weights.iter().sum();
        for _ in 0..2000 {
            let u: f32 = rng.random();
            let (cell, _) = d.sample(u);
            // independent: walk the normalized prefix sums (summed in another order than the
            // distribution's, so the two may differ in the last bits)
            let (mut acc, mut want, mut starts) = (0.0, 0, Vec::with_capacity(len));
            for (k, w) in weights.iter().enumerate() {
                starts.push(acc);
                if *w > 0.0 && f64::from(u) >= acc {
                    want = k;
                }
                acc += w / total;
            }
            // Only a u on the edge between the two cells, to rounding, may pick the other one.
            let edge = starts[cell.max(want)];
            assert!(cell == want || (f64::from(u) - edge).abs() < 1e-12, "len {len} u {u}: {cell} vs {want}");
            assert!(d.cell_probability(cell) > 0.0);
        }
    }
}

#[test]
fn zero_cells_are_never_sampled() {
    let d = Distribution1D::new([0.0, 1.0, 0.0, 0.0, 3.0, 0.0]);
    for k in 0..=1000 {
        let u = (k as f32 / 1000.0).min(ONE_MINUS_EPSILON);
        let (cell, frac) = d.sample(u);
        assert!(cell == 1 || cell == 4, "u = {u}: cell {cell}");
        assert!((0.0..1.0).contains(&frac));
        assert!((d.invert(cell, frac) - u).abs() < 1e-6);
    }
    assert!((d.cell_probability(4) - 0.75).abs() < 1e-12);
}

#[test]
fn summed_area_table_matches_brute_force_sums() {
    let map = test_map();
    let sat = SummedAreaTable::luminance_power(&map);
    let brute = |x0: u32, y0: u32, x1: u32, y1: u32| -> f64 {
        (y0..y1)
            .map(|j| (x0..x1).map(|i| f64::from(luminance(map.pixel(i, j)))).sum::<f64>() * map.texel_solid_angle(j))
            .sum()
    };
    let mut rng = common::rng(8);
    for _ in 0..2000 {
        let (a, b) = (rng.random_range(0..=32u32), rng.random_range(0..=32u32));
        let (c, d) = (rng.random_range(0..=16u32), rng.random_range(0..=16u32));
        let (x0, x1, y0, y1) = (a.min(b), a.max(b), c.min(d), c.max(d));
        let want = brute(x0, y0, x1, y1);
        assert!((sat.sum(x0, y0, x1, y1)[0] - want).abs() <= 1e-9 * want.max(1.0));
        if x0 < x1 {
            // wrapped: columns x1..32 and 0..x0
            let want = brute(x1, y0, 32, y1) + brute(0, y0, x0, y1);
            assert!((sat.sum_wrapped(x1, y0, x0, y1)[0] - want).abs() <= 1e-9 * want.max(1.0));
        }
    }
    let total = sat.sum(0, 0, 32, 16)[0];
    let rgb = SummedAreaTable::rgb_power(&map).sum(0, 0, 32, 16);
    assert!((total - luminance(Vec3::new(rgb[0] as f32, rgb[1] as f32, rgb[2] as f32)) as f64).abs() < 1e-4 * total);
}

/// Independently of the distributions: the largest luminance in texel (i, j)'s 3 x 3
/// neighbourhood, wrapping in u and clamped in v.
fn neighbourhood_max(map: &EnvMap, i: i64, j: i64) -> f64 {
    let (w, h) = (i64::from(map.width()), i64::from(map.height()));
    let mut m = 0.0f64;
    for dj in -1..=1 {
        for di in -1..=1 {
            let p = map.pixel((i + di).rem_euclid(w) as u32, (j + dj).clamp(0, h - 1) as u32);
            m = m.max(f64::from(luminance(p)));
        }
    }
    m
}

#[test]
fn bilinear_distribution_bounds_radiance_over_pdf() {
    let map = envmap_sphere::default_map();
    let plain = EnvDistribution::new(&map);
    let safe = EnvDistribution::for_bilinear(&map);
    let (w, h) = (map.width() as i64, map.height() as i64);
    let weight = |i: i64, j: i64| neighbourhood_max(&map, i, j);
    let total: f64 = (0..h).map(|j| (0..w).map(|i| weight(i, j)).sum::<f64>() * map.texel_solid_angle(j as u32)).sum();
    let mut rng = common::rng(12);
    let (mut worst_plain, mut worst_safe) = (0.0f64, 0.0f64);
    for _ in 0..200_000 {
        let s = safe.sample_dir(Vec2::new(rng.random(), rng.random()));
        assert_eq!(s.pdf, safe.uv_pdf(s.uv));
        let (i, j) = ((s.uv.x * 1024.0) as u32, (s.uv.y * 512.0) as u32);
        let want = (weight(i64::from(i), i64::from(j)) / total) as f32;
        assert!((s.pdf - want).abs() <= 1e-5 * want, "{} vs {want}", s.pdf);
        // Directions everywhere (uniform), where BRDF sampling would land.
        let d = common::random_dir(&mut rng);
        let y = f64::from(luminance(map.lookup(d)));
        worst_safe = worst_safe.max(y / f64::from(safe.dir_pdf(d)).max(1e-30));
        worst_plain = worst_plain.max(y / f64::from(plain.dir_pdf(d)).max(1e-30));
    }
    // bilinear Y / pdf never exceeds the normalization of the 3 x 3 weights
    assert!(worst_safe <= total * (1.0 + 1e-4), "{worst_safe} > {total}");
    assert!(worst_plain > 10.0 * worst_safe, "the plain distribution has the spikes this one removes");
}

#[test]
fn compensated_pdf_is_the_weight_above_its_mean() {
    for map in [test_map(), envmap_sphere::default_map()] {
        let dist = EnvDistribution::for_bilinear_compensated(&map);
        let (w, h) = (i64::from(map.width()), i64::from(map.height()));
        let sa = |j: i64| map.texel_solid_angle(j as u32);
        let mean = (0..h).map(|j| (0..w).map(|i| neighbourhood_max(&map, i, j)).sum::<f64>() * sa(j)).sum::<f64>()
            / (4.0 * PI);
        let weight = |i: i64, j: i64| (neighbourhood_max(&map, i, j) - mean).max(0.0);
        let total: f64 = (0..h).map(|j| (0..w).map(|i| weight(i, j)).sum::<f64>() * sa(j)).sum();
        let mut zero = 0;
        for j in 0..h {
            for i in 0..w {
                let want = (weight(i, j) / total) as f32;
                let pdf = dist.texel_pdf(i as usize, j as usize);
                assert!((pdf - want).abs() <= 1e-5 * want, "({i}, {j}): {pdf} vs {want}");
                zero += usize::from(pdf == 0.0);
            }
        }
        assert!(zero > 0, "texels below the mean get no map samples");
        assert!(!dist.is_complete(), "the pdf says it is incomplete");
        let mut rng = common::rng(17);
        for _ in 0..100_000 {
            let s = dist.sample_dir(Vec2::new(rng.random(), rng.random()));
            assert!(s.pdf > 0.0 && s.pdf == dist.uv_pdf(s.uv), "sample in a zero-pdf texel at {}", s.uv);
        }
    }
}

#[test]
fn compensating_a_constant_map_keeps_it_uniform() {
    for map in [EnvMap::constant(64, 32, Vec3::splat(3.0)), EnvMap::constant(8, 4, Vec3::ZERO)] {
        let dist = EnvDistribution::for_bilinear_compensated(&map);
        assert!(dist.is_complete());
        let uniform = (1.0 / (4.0 * PI)) as f32;
        for j in 0..map.height() as usize {
            for i in 0..map.width() as usize {
                assert!((dist.texel_pdf(i, j) - uniform).abs() < 1e-5 * uniform, "({i}, {j})");
            }
        }
    }
}
