//! The BRDF: reciprocity, energy conservation, pdf normalization, chi-square of its sampling,
//! and no NaN at grazing angles or extreme roughness.

use glam::{Vec2, Vec3};
use scene::brdf::Frame;
use scene::{Ggx, Material};
use std::f32::consts::PI;

fn materials() -> Vec<Material> {
    let ggx = |roughness: f32, f0: f32| Some(Ggx { roughness, f0: Vec3::splat(f0) });
    vec![
        Material::lambert(0.8),
        Material::rgb(Vec3::new(0.3, 0.7, 0.3), ggx(0.6, 0.04)),
        Material::rgb(Vec3::new(0.25, 0.35, 0.8), ggx(0.3, 0.04)),
        Material::rgb(Vec3::splat(0.2), ggx(0.2, 0.5)),
        Material::rgb(Vec3::ONE, ggx(0.05, 1.0)),
    ]
}

fn dir(theta: f32, phi: f32) -> Vec3 {
    Vec3::new(theta.sin() * phi.cos(), theta.sin() * phi.sin(), theta.cos())
}

/// Midpoint quadrature over the upper hemisphere in (cos theta, phi), equal-area cells.
fn hemisphere_integral(n: usize, f: impl Fn(Vec3) -> f64) -> f64 {
    let mut sum = 0.0;
    for a in 0..n {
        let z = (a as f32 + 0.5) / n as f32;
        for b in 0..2 * n {
            let phi = (b as f32 + 0.5) / (2 * n) as f32 * 2.0 * PI;
            let r = (1.0 - z * z).sqrt();
            sum += f(Vec3::new(r * phi.cos(), r * phi.sin(), z));
        }
    }
    sum * 2.0 * std::f64::consts::PI / (2 * n * n) as f64
}

#[test]
fn brdf_is_reciprocal() {
    for m in materials() {
        for (t1, t2, p) in [(0.2, 1.1, 0.7), (1.4, 0.3, 2.0), (0.9, 0.9, 3.1)] {
            let (a, b) = (dir(t1, 0.0), dir(t2, p));
            let (f1, f2) = (m.eval_brdf(a, b), m.eval_brdf(b, a));
            assert!((f1 - f2).abs().max_element() <= 1e-5 * f1.max_element().max(1.0), "{m:?}: {f1} vs {f2}");
        }
    }
}

#[test]
fn lambertian_albedo_is_reflected_and_no_material_gains_energy() {
    let lambert = Material::lambert(0.8);
    let r = hemisphere_integral(256, |wi| f64::from(lambert.eval_brdf(Vec3::Z, wi).x * wi.z));
    assert!((r - 0.8).abs() < 1e-3, "{r}");
    // Directional albedo by importance sampling (the sampler is checked by the chi-square test);
    // a grid cannot resolve a glossy lobe at 89 degrees.
    for m in materials() {
        for theta in [0.0f32, 0.5, 1.0, 1.4, 1.55] {
            let wo = dir(theta, 0.3);
            let n = 100_000;
            let r: f64 = (0..n)
                .filter_map(|k| m.sample_brdf(wo, r2(k), frac(k as f32 * 0.618_034 + 0.1)))
                .map(|(wi, pdf)| f64::from((m.eval_brdf(wo, wi) * wi.z / pdf).max_element()))
                .sum::<f64>()
                / n as f64;
            // 1% covers the estimator noise; the uncoupled diffuse + specular sum reflected 1.05-1.22.
            assert!(r <= 1.01, "{m:?} at theta {theta}: reflects {r}");
        }
    }
}

#[test]
fn pdf_integrates_to_the_fraction_of_valid_samples() {
    // Roughness 0.05 is too peaked for any grid; it is covered by no_nan_at_extremes.
    for m in materials().into_iter().take(4) {
        for theta in [0.1f32, 0.8, 1.3] {
            let wo = dir(theta, 0.0);
            let integral = hemisphere_integral(400, |wi| f64::from(m.brdf_pdf(wo, wi)));
            // Samples reflected below the surface are returned as None: the pdf over the upper
            // hemisphere integrates to the fraction that is not.
            let n = 40_000;
            let valid = (0..n).filter(|&k| m.sample_brdf(wo, r2(k), frac(k as f32 * 0.618_034)).is_some()).count();
            let want = valid as f64 / n as f64;
            assert!((integral - want).abs() < 0.01, "{m:?} theta {theta}: integral {integral} vs {want}");
        }
    }
}

fn frac(x: f32) -> f32 {
    x - x.floor()
}

/// R2 low-discrepancy points.
fn r2(k: usize) -> Vec2 {
    Vec2::new(frac(0.5 + k as f32 * 0.754_877_7), frac(0.5 + k as f32 * 0.569_840_3))
}

#[test]
fn samples_follow_the_pdf_chi_square() {
    let (nz, nphi) = (12usize, 24usize);
    for m in materials().into_iter().take(4) {
        let wo = dir(0.7, 0.0);
        let n = 300_000usize;
        let mut counts = vec![0u32; nz * nphi];
        // A fixed-seed xorshift, independent of the sampler's own structure.
        let mut state = 0x9E37_79B9_7F4A_7C15u64;
        let mut next = || {
            state ^= state << 13;
            state ^= state >> 7;
            state ^= state << 17;
            (state >> 40) as f32 / (1u64 << 24) as f32
        };
        for _ in 0..n {
            if let Some((wi, _)) = m.sample_brdf(wo, Vec2::new(next(), next()), next()) {
                let a = ((wi.z * nz as f32) as usize).min(nz - 1);
                let phi = wi.y.atan2(wi.x).rem_euclid(2.0 * PI);
                let b = ((phi / (2.0 * PI) * nphi as f32) as usize).min(nphi - 1);
                counts[a * nphi + b] += 1;
            }
        }
        let (mut chi2, mut dof) = (0.0, -1.0);
        for a in 0..nz {
            for b in 0..nphi {
                // expected: the pdf integrated over the cell, 8 x 8 midpoint sub-cells
                let mut p = 0.0f64;
                for i in 0..8 {
                    for j in 0..8 {
                        let z = (a as f32 + (i as f32 + 0.5) / 8.0) / nz as f32;
                        let phi = (b as f32 + (j as f32 + 0.5) / 8.0) / nphi as f32 * 2.0 * PI;
                        let r = (1.0 - z * z).sqrt();
                        p += f64::from(m.brdf_pdf(wo, Vec3::new(r * phi.cos(), r * phi.sin(), z)));
                    }
                }
                let cell = 2.0 * std::f64::consts::PI / (nz * nphi) as f64;
                let expected = p / 64.0 * cell * n as f64;
                if expected > 20.0 {
                    let o = f64::from(counts[a * nphi + b]);
                    chi2 += (o - expected).powi(2) / expected;
                    dof += 1.0;
                }
            }
        }
        // The expected counts carry quadrature error; bound chi2 / dof loosely but far below
        // what a wrong pdf gives (tens to thousands).
        assert!(chi2 / dof < 1.6, "{m:?}: chi2 {chi2:.0} over {dof} cells");
    }
}

#[test]
fn no_nan_at_extremes() {
    let ggx = |roughness: f32| Material::rgb(Vec3::splat(0.5), Some(Ggx { roughness, f0: Vec3::splat(0.04) }));
    for m in [ggx(0.0), ggx(1e-4), ggx(1.0), Material::lambert(1.0)] {
        for wo in [Vec3::Z, dir(std::f32::consts::FRAC_PI_2, 0.0), Vec3::new(1.0, 0.0, 1e-7).normalize(), dir(0.3, 1.0)]
        {
            for u in [Vec2::ZERO, Vec2::splat(0.999_999_9), Vec2::new(0.0, 0.999_999_9), Vec2::splat(0.5)] {
                for lobe in [0.0, 0.5, 0.999_999_9] {
                    if let Some((wi, pdf)) = m.sample_brdf(wo, u, lobe) {
                        assert!(wi.is_finite() && pdf.is_finite() && pdf > 0.0, "{m:?} {wo} {u}: {wi} {pdf}");
                        assert!(m.eval_brdf(wo, wi).is_finite());
                    }
                }
            }
        }
    }
    for n in [Vec3::Z, Vec3::NEG_Z, Vec3::X, Vec3::new(0.0, -0.6, -0.8), Vec3::new(1e-8, 0.0, -1.0).normalize()] {
        let f = Frame::new(n);
        assert!((f.t.dot(f.b)).abs() < 1e-6 && (f.t.dot(n)).abs() < 1e-6 && (f.b.dot(n)).abs() < 1e-6, "{n}");
        assert!((f.t.cross(f.b) - n).length() < 1e-5, "{n}: right-handed");
        let v = Vec3::new(0.3, -0.4, 0.5);
        assert!((f.to_world(f.to_local(v)) - v).length() < 1e-6);
    }
}
