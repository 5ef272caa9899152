//! ref-tracer: samples per second of `env-direct` on the validation scene (one sample = one
//! camera ray with its map sample and BRDF sample, each with a shadow ray).

use criterion::{Criterion, Throughput, criterion_group, criterion_main};
use ref_tracer::{EnvLight, Integrator, RenderSettings, SceneBvh, Strategy, render};
use std::hint::black_box;

fn env_direct(c: &mut Criterion) {
    let scene = scene::Scene::builtin("spheres_box").expect("built-in scene");
    let map = envshadow_benches::bench_map();
    let env = EnvLight::new(&map);
    let bvh = SceneBvh::new(&scene);
    let pixels = u64::from(scene.camera.width * scene.camera.height);
    let mut group = envshadow_benches::slow_group(c, "ref_tracer");
    group.throughput(Throughput::Elements(pixels));
    let mut seed = 0;
    group.bench_function("spheres_box_env_direct_640x480_1spp", |b| {
        b.iter(|| {
            seed += 1;
            let settings = RenderSettings { spp: 1, seed, aovs: false, ..RenderSettings::default() };
            render(&scene, &bvh, Some(&env), &Integrator::EnvDirect(Strategy::Mis), &settings, &|_, _| {}).color.len()
        })
    });
    group.finish();
    c.bench_function("bvh_build_spheres_box", |b| b.iter(|| SceneBvh::new(black_box(&scene))));
}

criterion_group!(benches, env_direct);
criterion_main!(benches);
