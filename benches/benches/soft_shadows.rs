//! Soft shadows: GPU time per light of every technique and setting of
//! `envshadow_benches::soft_shadows` (wedges, hard maps, PCSS, N maps) on `three_boxes` with a
//! 4-degree light, at 640 x 480 and 1920 x 1080. Times are the techniques' own (GPU timestamps
//! where the adapter has them, as lavapipe does). Errors are in `cargo xtask soft-shadows`.

use criterion::{Criterion, criterion_group, criterion_main};
use envshadow_benches::soft_shadows::{Frame, entries, light};
use gpu::Gpu;

fn soft_shadows(c: &mut Criterion) {
    let gpu = Gpu::new().unwrap_or_else(|e| panic!("{e}"));
    let l = light(4.0);
    for size in [(640, 480), (1920, 1080)] {
        let frame = Frame::new(&gpu, "three_boxes", size).unwrap_or_else(|e| panic!("{e}"));
        let mut group = envshadow_benches::slow_group(c, format!("soft_shadows_three_boxes_{}x{}", size.0, size.1));
        for e in entries(&gpu, &frame.scene).unwrap_or_else(|e| panic!("{e}")) {
            group.bench_function(e.technique.name(), |b| {
                b.iter_custom(|iters| {
                    (0..iters)
                        .map(|_| envshadow_benches::ok(frame.visibility(&gpu, e.technique.as_ref(), &l)).1.time)
                        .sum()
                });
            });
        }
        group.finish();
    }
}

criterion_group!(benches, soft_shadows);
criterion_main!(benches);
