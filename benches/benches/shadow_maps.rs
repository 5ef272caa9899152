//! shadowmap-paraboloid: shadow-map generation time on the GPU (lavapipe here) for the `room`
//! scene's point light, dual paraboloid (2 passes) against cube (6 passes) at equal texel
//! counts, with the rejection and subdivision knobs. Times are GPU timestamps where the adapter
//! has them (lavapipe does), else wall time of submit + wait.

use criterion::{Criterion, criterion_group, criterion_main};
use gpu::{Gpu, ShadowGeometry, scene_triangles};
use shadowmap_paraboloid::{MapView, ShadowMapper, shadow_triangles};
use trade::equal_texel_variants;

fn shadow_maps(c: &mut Criterion) {
    let gpu = Gpu::new().unwrap_or_else(|e| panic!("{e}"));
    let scene = scene::Scene::builtin("room").unwrap_or_else(|e| panic!("{e}"));
    let triangles = scene_triangles(&scene);
    let light = MapView::omni(scene.point_lights[0].position);
    let mapper = ShadowMapper::new(&gpu);
    let mut group = c.benchmark_group("shadow_maps_room");
    for v in equal_texel_variants() {
        let tris = shadow_triangles(&triangles, &light, v.technique, &v.settings);
        let geometry =
            ShadowGeometry::upload(&gpu, &tris, ShadowGeometry::CHUNK_TRIANGLES).unwrap_or_else(|e| panic!("{e}"));
        group.bench_function(&v.name, |b| {
            b.iter_custom(|iters| {
                (0..iters)
                    .map(|_| {
                        envshadow_benches::ok(mapper.render(&gpu, &geometry, &light, v.technique, &v.settings)).time
                    })
                    .sum()
            });
        });
    }
    group.finish();
}

criterion_group!(benches, shadow_maps);
criterion_main!(benches);
