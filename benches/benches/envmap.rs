//! envmap-sphere: loading, integrals, SH projection and importance sampling on a 1024 x 512 map.

use criterion::{Criterion, criterion_group, criterion_main};
use envmap_sphere::{EnvDistribution, EnvMap, Layout, LoadOptions, Sh9};
use glam::{Vec2, Vec3};
use std::hint::black_box;

fn load(c: &mut Criterion) {
    let bytes = envmap_sphere::default_map_bytes();
    c.bench_function("load_dwab_exr_1024x512", |b| {
        b.iter(|| envshadow_benches::ok(EnvMap::load_from_bytes(black_box(bytes), "city.exr", &LoadOptions::default())))
    });
}

fn integrals(c: &mut Criterion) {
    let map = envshadow_benches::bench_map();
    c.bench_function("sh9_project_1024x512", |b| b.iter(|| Sh9::project(black_box(&map))));
    c.bench_function("power_1024x512", |b| b.iter(|| black_box(&map).power()));
    c.bench_function("irradiance_brute_force_1024x512", |b| b.iter(|| black_box(&map).irradiance(Vec3::Y)));
    c.bench_function("resample_to_cube_128", |b| b.iter(|| black_box(&map).to_layout(Layout::CubeStrip { face: 128 })));
}

fn sampling(c: &mut Criterion) {
    let map = envshadow_benches::bench_map();
    c.bench_function("distribution_build_1024x512", |b| b.iter(|| EnvDistribution::new(black_box(&map))));
    let dist = EnvDistribution::new(&map);
    let mut k = 0u32;
    c.bench_function("distribution_sample_dir", |b| {
        b.iter(|| {
            k = k.wrapping_add(1);
            // a cheap low-discrepancy sequence: R2
            let u = Vec2::new((k as f32 * 0.754_877_7).fract(), (k as f32 * 0.569_840_3).fract());
            dist.sample_dir(black_box(u))
        })
    });
}

criterion_group!(benches, load, integrals, sampling);
criterion_main!(benches);
