//! light-extract: extraction time per method at K = 32 on the 1024 x 512 default map.

use criterion::{Criterion, criterion_group, criterion_main};
use light_extract::{
    CenterSurround, EmissiveSplit, ImportanceSampled, LightExtractor, MedianCut, VarianceMinimization,
};
use std::hint::black_box;

fn extract(c: &mut Criterion) {
    let map = envshadow_benches::bench_map();
    c.bench_function("median_cut_32_1024x512", |b| b.iter(|| MedianCut::with_lights(32).extract(black_box(&map))));
    c.bench_function("variance_min_32_1024x512", |b| {
        b.iter(|| VarianceMinimization::with_lights(32).extract(black_box(&map)))
    });
    c.bench_function("emissive_split_32_1024x512", |b| b.iter(|| EmissiveSplit::default().extract(black_box(&map))));
    c.bench_function("center_surround_1024x512", |b| b.iter(|| CenterSurround::default().extract(black_box(&map))));
    c.bench_function("importance_32_1024x512", |b| {
        b.iter(|| ImportanceSampled { count: 32, seed: 0 }.extract(black_box(&map)))
    });
}

criterion_group!(benches, extract);
criterion_main!(benches);
