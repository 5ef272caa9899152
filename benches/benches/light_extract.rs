//! light-extract: extraction time per method at K = 32 on the 1024 x 512 default map, and
//! centre-surround on the maps that cost it most: a flat background (every texel ties for the
//! brightest 10 %) and many wide lights (each one refreshes the filters it overlaps).

use criterion::{Criterion, criterion_group, criterion_main};
use envmap_sphere::EnvMap;
use envshadow_benches::ok;
use glam::Vec3;
use light_extract::{
    CenterSurround, EmissiveSplit, ImportanceSampled, LightExtractor, MedianCut, VarianceMinimization,
};
use std::hint::black_box;

/// `n` discs of half-angle acos(`cos_r`) spread evenly over a dim background, each a little
/// dimmer than the last, so that every one passes Weber's test.
fn discs(n: usize, cos_r: f32) -> EnvMap {
    let centres: Vec<Vec3> = (0..n)
        .map(|k| {
            let z = 1.0 - (k as f32 + 0.5) / (n as f32 / 2.0);
            let r = (1.0 - z * z).max(0.0).sqrt();
            let p = k as f32 * 2.399_963;
            Vec3::new(r * p.cos(), z, r * p.sin())
        })
        .collect();
    EnvMap::from_fn(1024, 512, |d| {
        centres
            .iter()
            .position(|c| d.dot(*c) > cos_r)
            .map_or(Vec3::splat(0.2), |k| Vec3::splat(50.0 * (1.0 - k as f32 / 200.0)))
    })
}

fn extract(c: &mut Criterion) {
    let map = envshadow_benches::bench_map();
    c.bench_function("median_cut_32_1024x512", |b| {
        b.iter(|| ok(MedianCut::with_lights(32).extract(black_box(&map)).map(|d| d.lights.len())))
    });
    c.bench_function("variance_min_32_1024x512", |b| {
        b.iter(|| ok(VarianceMinimization::with_lights(32).extract(black_box(&map)).map(|d| d.lights.len())))
    });
    c.bench_function("emissive_split_32_1024x512", |b| {
        b.iter(|| ok(EmissiveSplit::default().extract(black_box(&map)).map(|d| d.lights.len())))
    });
    c.bench_function("center_surround_1024x512", |b| {
        b.iter(|| ok(CenterSurround::default().extract(black_box(&map)).map(|d| d.lights.len())))
    });
    let flat_with_pole_sun = EnvMap::from_texels(1024, 512, |_, j| Vec3::splat(if j < 2 { 300.0 } else { 0.5 }));
    c.bench_function("center_surround_flat_pole_sun_1024x512", |b| {
        b.iter(|| ok(CenterSurround::default().extract(black_box(&flat_with_pole_sun)).map(|d| d.lights.len())))
    });
    let wide = discs(64, 0.99);
    c.bench_function("center_surround_64_wide_discs_1024x512", |b| {
        b.iter(|| ok(CenterSurround::default().extract(black_box(&wide)).map(|d| d.lights.len())))
    });
    c.bench_function("importance_32_1024x512", |b| {
        b.iter(|| ok(ImportanceSampled { count: 32, seed: 0 }.extract(black_box(&map)).map(|d| d.lights.len())))
    });
}

criterion_group!(benches, extract);
criterion_main!(benches);
