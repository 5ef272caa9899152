//! Paper 003's shaft hierarchy (`shaft-hierarchy`) on `ar_room` (1,712 patches): the
//! pre-processing (source set, receivers, transfers, trees, shafts) and a frame's traversal plus
//! representative set along the built-in object path. The radiosity solve that stands in for the
//! capture is not timed. Under `cargo test` (one smoke run) the room is built twice as coarse.

use criterion::{Criterion, criterion_group, criterion_main};
use real_scene::{Perturbation, RealScene, SolveSettings, solve};
use shaft_hierarchy::preprocess::{PreprocessSettings, build};
use shaft_hierarchy::{Occlusion, Traversal};
use trade::shafts::object_path;

fn shafts(c: &mut Criterion) {
    let full = envshadow_benches::benchmarking();
    let perturbation = Perturbation { coarsen: if full { 1 } else { 2 }, ..Perturbation::NONE };
    let mut scene = RealScene::builtin_with("ar_room", &perturbation).unwrap_or_else(|e| panic!("{e}"));
    let bvh = ref_tracer::SceneBvh::new(&scene.to_scene());
    solve(&mut scene, &bvh, None, &SolveSettings::default()).unwrap_or_else(|e| panic!("{e}"));
    let settings = PreprocessSettings::PAPER;
    let mut group = envshadow_benches::slow_group(c, format!("shafts_{}_patches", scene.patches.len()));
    group.bench_function("preprocess", |b| {
        b.iter(|| envshadow_benches::ok(build(&scene, &[], &bvh, &settings)).1.leaf_shafts())
    });
    let (_, h) = build(&scene, &[], &bvh, &settings).unwrap_or_else(|e| panic!("{e}"));
    let objects = object_path(&scene, 240);
    let mut scratch = Traversal::default();
    let mut o = Occlusion::default();
    let mut k = 0;
    group.sample_size(50);
    group.bench_function("frame_traversal_and_8_representatives", |b| {
        b.iter(|| {
            k = (k + 1) % objects.len();
            h.traverse(&objects[k], &mut scratch, &mut o);
            h.representatives(&o, 8).len()
        });
    });
    group.finish();
}

criterion_group!(benches, shafts);
criterion_main!(benches);
