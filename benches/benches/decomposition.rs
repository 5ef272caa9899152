//! Paper 001's whole frame on the GPU (`envshadow_benches::decomposition`): time per frame on
//! `gallery` (161,794 triangles) at 1600 x 1200 with the EnvIndirects at full, half and quarter
//! resolution. Wall time, CPU work of the frame included. Under `cargo test` (one smoke run)
//! the frame is 160 x 120.

use criterion::{Criterion, criterion_group, criterion_main};
use envshadow_benches::decomposition::Frame;
use gpu::Gpu;
use std::time::Duration;

fn decomposition(c: &mut Criterion) {
    let gpu = Gpu::new().unwrap_or_else(|e| panic!("{e}"));
    let size = if envshadow_benches::benchmarking() { (1600, 1200) } else { (160, 120) };
    let frame =
        Frame::new(&gpu, "gallery", size, &envshadow_benches::bench_map(), 32).unwrap_or_else(|e| panic!("{e}"));
    let mut group = envshadow_benches::slow_group(c, format!("decomposition_gallery_{}x{}", size.0, size.1));
    for (name, scale) in [("indirects_full", 1), ("indirects_half", 2), ("indirects_quarter", 4)] {
        group.bench_function(name, |b| {
            b.iter_custom(|iters| {
                (0..iters).map(|_| envshadow_benches::ok(frame.render_timed(&gpu, scale)).0).sum::<Duration>()
            });
        });
    }
    group.finish();
}

criterion_group!(benches, decomposition);
criterion_main!(benches);
