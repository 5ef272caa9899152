//! The real-time path: every light recorded into one encoder (no submission, wait, mapping or
//! pipeline while recording; one map texture and one accumulator reused from light to light)
//! writes exactly the layers that each light waited for in a submission of its own writes; and
//! an object moved with `MapTechnique::update_object` shadows bit for bit as maps built afresh
//! for its new pose.

use glam::Vec3;
use gpu::{
    GBufferPass, Gpu, LightShape, Receivers, SceneGeometry, VisibilityLayers, record_visibility, render_visibility,
};
use shadowmap_paraboloid::{MapTechnique, ShadowSettings, Technique};

fn scene() -> scene::Scene {
    let mut s = scene::Scene::builtin("spheres_box").unwrap();
    (s.camera.width, s.camera.height) = (96, 72);
    s
}

fn distant() -> Vec<LightShape> {
    vec![
        LightShape::Distant { direction: Vec3::new(0.3, 1.0, 0.2).normalize(), half_angle: 0.02 },
        LightShape::Distant { direction: Vec3::new(-0.6, 0.8, 0.4).normalize(), half_angle: 0.2 },
        LightShape::Distant { direction: Vec3::new(0.7, 0.4, -0.5).normalize(), half_angle: 0.1 },
    ]
}

fn local() -> Vec<LightShape> {
    vec![
        LightShape::Sphere { center: Vec3::new(0.5, 3.0, 1.0), radius: 0.0 },
        LightShape::Sphere { center: Vec3::new(-1.5, 2.0, 0.5), radius: 0.0 },
    ]
}

fn settings() -> ShadowSettings {
    ShadowSettings { resolution: 256, pcf_radius: 1, ..ShadowSettings::default() }
}

fn recorded(
    gpu: &Gpu,
    t: &MapTechnique,
    receivers: &Receivers,
    lights: &[LightShape],
) -> (Vec<Vec<f32>>, gpu::GpuCounters) {
    let (layers, during, reports) = recorded_any(gpu, t, receivers, lights);
    assert!(reports.iter().all(|r| r.skipped.is_none() && r.primitives > 0));
    (layers, during)
}

fn waited(gpu: &Gpu, t: &MapTechnique, receivers: &Receivers, lights: &[LightShape]) -> Vec<Vec<f32>> {
    let (w, h) = receivers.gbuffer.size();
    let vis = VisibilityLayers::new(gpu, w, h, lights.len() as u32).unwrap();
    render_visibility(gpu, t, receivers, lights, &[], &vis).unwrap();
    (0..lights.len() as u32).map(|k| vis.read(gpu, k).unwrap()).collect()
}

#[test]
fn all_lights_recorded_in_one_encoder_equal_each_light_waited_for() {
    let gpu = Gpu::new().unwrap_or_else(|e| panic!("{e}"));
    let scene = scene();
    let (gb, points) = seen(&gpu, &scene);
    let receivers = Receivers::new(&gb, &points);
    let ortho = MapTechnique::new(&gpu, &scene, Technique::Orthographic, settings(), 1).unwrap();
    let cases = [
        (ortho.variant(Technique::Orthographic, settings(), 1), distant()),
        // four maps a light into one accumulator
        (ortho.variant(Technique::Orthographic, settings(), 4), distant()),
        (ortho.variant(Technique::Cube, settings(), 1), local()),
        (ortho.variant(Technique::DualParaboloid, settings(), 1), local()),
    ];
    for (technique, lights) in &cases {
        let name = gpu::ShadowTechnique::name(technique);
        let (layers, during) = recorded(&gpu, technique, &receivers, lights);
        assert_eq!(
            (during.submits, during.waits, during.readback_bytes, during.pipelines),
            (0, 0, 0, 0),
            "{name}: recording submitted, waited, mapped or built"
        );
        let reference = waited(&gpu, technique, &receivers, lights);
        for (k, (a, b)) in layers.iter().zip(&reference).enumerate() {
            assert!(a == b, "{name}, light {k}: recorded and waited layers differ");
            assert!(a.iter().any(|v| *v < 0.5) && a.iter().any(|v| *v > 0.5), "{name}, light {k}: no shadow edge");
        }
    }
}

#[test]
fn a_moved_object_shadows_as_maps_built_for_its_pose() {
    let gpu = Gpu::new().unwrap_or_else(|e| panic!("{e}"));
    let rest = scene();
    let object = rest.objects.iter().position(|o| o.name != "ground").unwrap();
    let moved = posed(&rest, object, glam::Affine3A::from_translation(Vec3::new(0.31, 0.0, -0.17)));
    let (gb, points) = seen(&gpu, &moved);
    let receivers = Receivers::new(&gb, &points);
    let updated = MapTechnique::new(&gpu, &rest, Technique::Orthographic, settings(), 1).unwrap();
    // a variant shares the geometry: it sees the move too
    let cube = updated.variant(Technique::Cube, settings(), 1);
    let at_rest = recorded(&gpu, &updated, &receivers, &distant()).0;
    let before = gpu.counters();
    updated.update_object(&gpu, &moved, object).unwrap();
    let d = gpu.counters() - before;
    assert_eq!((d.submits, d.waits, d.pipelines), (0, 0, 0), "moving submitted, waited or built");
    let fresh = MapTechnique::new(&gpu, &moved, Technique::Orthographic, settings(), 1).unwrap();
    let a = recorded(&gpu, &updated, &receivers, &distant()).0;
    assert!(a == recorded(&gpu, &fresh, &receivers, &distant()).0, "updated maps differ from maps built for the pose");
    assert!(a != at_rest, "the shadows did not move with the object");
    let fresh_cube = fresh.variant(Technique::Cube, settings(), 1);
    assert!(recorded(&gpu, &cube, &receivers, &local()).0 == recorded(&gpu, &fresh_cube, &receivers, &local()).0);
    // another mesh, or no such object: refused
    let mut other = moved.clone();
    other.objects[object].mesh.indices.pop();
    assert!(updated.update_object(&gpu, &other, object).is_err());
    assert!(updated.update_object(&gpu, &moved, moved.objects.len()).is_err());
}

#[test]
fn maps_fitted_and_gated_on_the_gpu_equal_maps_fitted_on_the_cpu() {
    // the same reduction read back (`from_stats`: the CPU fits the orthographic maps, and skips)
    // and left on the GPU (`on_gpu`: `ortho_focus.wgsl` fits them, the gate skips): the
    // arithmetic is the CPU's operation for operation
    let gpu = Gpu::new().unwrap_or_else(|e| panic!("{e}"));
    let scene = scene();
    let geometry = SceneGeometry::upload(&gpu, &scene).unwrap();
    let gb = GBufferPass::new(&gpu).render(&gpu, &geometry, &scene.camera).unwrap();
    let reduction = gpu::ReceiverReduction::new(&gpu);
    let mut lights = distant();
    // nothing the camera sees faces a light from below: skipped either way
    lights.push(LightShape::Distant { direction: Vec3::NEG_Y, half_angle: 1e-4 });
    let all: Vec<LightShape> = lights.iter().chain(&local()).copied().collect();
    let mut encoder = gpu.encoder("reduction");
    let pending = reduction.record(&gpu, &mut encoder, &gb, &all, None).unwrap();
    gpu.submit(encoder);
    let on_gpu = pending.on_gpu().clone();
    let stats = pending.read(&gpu).unwrap();
    let read = Receivers::from_stats(&gb, &stats, &all);
    let left = Receivers::on_gpu(&gb, read.bounds, on_gpu.clone());
    let local_left = Receivers::on_gpu(&gb, read.bounds, on_gpu.starting_at(lights.len() as u32));
    let ortho = MapTechnique::new(&gpu, &scene, Technique::Orthographic, settings(), 1).unwrap();
    let cases = [
        (ortho.variant(Technique::Orthographic, settings(), 1), &lights[..], &left),
        (ortho.variant(Technique::Orthographic, settings(), 4), &lights[..], &left),
        (ortho.variant(Technique::Cube, settings(), 1), &all[lights.len()..], &local_left),
        (ortho.variant(Technique::DualParaboloid, settings(), 1), &all[lights.len()..], &local_left),
    ];
    for (technique, lights, left) in cases {
        let name = gpu::ShadowTechnique::name(&technique);
        let (want, _, reports) = recorded_any(&gpu, &technique, &read, lights);
        let (got, during, _) = recorded_any(&gpu, &technique, left, lights);
        assert_eq!((during.submits, during.waits, during.readback_bytes), (0, 0, 0), "{name}");
        // one gate a light, whatever its samples' depth and visibility passes and the resolve
        assert_eq!(during.gate_passes, lights.len() as u64, "{name}");
        for (k, (a, b)) in want.iter().zip(&got).enumerate() {
            let differ = a.iter().zip(b).filter(|(x, y)| x != y).count();
            assert_eq!(differ, 0, "{name}, light {k} (skipped on the CPU: {:?})", reports[k].skipped);
        }
    }
}

/// What the camera of `scene` sees: its G-buffer and the points read back from it.
fn seen(gpu: &Gpu, scene: &scene::Scene) -> (gpu::GBuffer, Vec<(Vec3, Vec3)>) {
    let geometry = SceneGeometry::upload(gpu, scene).unwrap();
    let gb = GBufferPass::new(gpu).render(gpu, &geometry, &scene.camera).unwrap();
    let points = gb.read_points(gpu).unwrap();
    (gb, points)
}

/// Object `object` of `scene` turned and moved by `t`, on the CPU.
fn posed(scene: &scene::Scene, object: usize, t: glam::Affine3A) -> scene::Scene {
    let mut moved = scene.clone();
    moved.objects[object].mesh.transform(&t);
    moved
}

/// Per light its layer, every light recorded into one encoder (some may be skipped); the
/// counters while recording; the reports.
fn recorded_any(
    gpu: &Gpu,
    t: &MapTechnique,
    receivers: &Receivers,
    lights: &[LightShape],
) -> (Vec<Vec<f32>>, gpu::GpuCounters, Vec<gpu::ShadowPassReport>) {
    let (w, h) = receivers.gbuffer.size();
    let vis = VisibilityLayers::allocate(gpu, w, h, lights.len() as u32).unwrap();
    let mut encoder = gpu.encoder("all lights");
    let before = gpu.counters();
    vis.record_clear(&mut encoder);
    let reports = record_visibility(gpu, &mut encoder, t, receivers, lights, &[], &vis).unwrap();
    let during = gpu.counters() - before;
    gpu.submit(encoder);
    ((0..lights.len() as u32).map(|k| vis.read(gpu, k).unwrap()).collect(), during, reports)
}

#[test]
fn a_transformed_object_shadows_as_its_mesh_moved_on_the_cpu() {
    // placed on the GPU against maps of the moved triangles: depths a rounding apart, the
    // chunks' bounds moved rather than measured (the orthographic fit moves a hair)
    let gpu = Gpu::new().unwrap_or_else(|e| panic!("{e}"));
    let rest = scene();
    let object = rest.objects.iter().position(|o| o.name != "ground").unwrap();
    let t = glam::Affine3A::from_translation(Vec3::new(0.31, 0.05, -0.17)) * glam::Affine3A::from_rotation_y(0.6);
    let moved = posed(&rest, object, t);
    let (gb, points) = seen(&gpu, &moved);
    let receivers = Receivers::new(&gb, &points);
    let placed = MapTechnique::new(&gpu, &rest, Technique::Orthographic, settings(), 1).unwrap();
    let cube = placed.variant(Technique::Cube, settings(), 1);
    let at_rest = recorded(&gpu, &placed, &receivers, &distant()).0;
    let before = gpu.counters();
    placed.set_transform(&gpu, object, t).unwrap();
    let d = gpu.counters() - before;
    assert_eq!((d.submits, d.waits, d.pipelines), (0, 0, 0), "moving submitted, waited or built");
    let fresh = MapTechnique::new(&gpu, &moved, Technique::Orthographic, settings(), 1).unwrap();
    let fresh_cube = fresh.variant(Technique::Cube, settings(), 1);
    let apart = |a: &[Vec<f32>], b: &[Vec<f32>]| {
        let d = a.iter().flatten().zip(b.iter().flatten()).map(|(x, y)| (x - y).abs());
        d.fold((0usize, 0usize), |(n, all), d| (n + usize::from(d > 0.02), all + 1))
    };
    for (name, (a, b)) in [
        (
            "orthographic",
            (recorded(&gpu, &placed, &receivers, &distant()).0, recorded(&gpu, &fresh, &receivers, &distant()).0),
        ),
        ("cube", (recorded(&gpu, &cube, &receivers, &local()).0, recorded(&gpu, &fresh_cube, &receivers, &local()).0)),
    ] {
        let (n, all) = apart(&a, &b);
        assert!(n * 200 <= all, "{name}: {n} of {all} texels apart from maps of the moved mesh");
    }
    let a = recorded(&gpu, &placed, &receivers, &distant()).0;
    let (n, all) = apart(&a, &at_rest);
    assert!(n * 50 > all, "the shadows did not move with the object: {n} of {all}");
    placed.set_transform(&gpu, object, glam::Affine3A::IDENTITY).unwrap();
    assert!(recorded(&gpu, &placed, &receivers, &distant()).0 == at_rest, "back at rest, the maps differ");
    assert!(placed.set_transform(&gpu, rest.objects.len(), t).is_err());
}
