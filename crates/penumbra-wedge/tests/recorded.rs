//! The real-time path: every light recorded into one encoder (no submission, wait, mapping or
//! pipeline while recording, scratch targets reused from light to light) writes exactly the
//! layers that each light waited for in a submission of its own writes; and a caster moved with
//! `Wedges::update_object` shadows bit for bit as wedges built afresh for its new pose.

use glam::Vec3;
use gpu::{
    GBufferPass, Gpu, LightShape, Receivers, SceneGeometry, VisibilityLayers, record_visibility, render_visibility,
};
use penumbra_wedge::{WedgePath, WedgeSettings, Wedges};
use scene::Scene;

fn scene() -> Scene {
    let mut s = Scene::builtin("spheres_box").unwrap();
    (s.camera.width, s.camera.height) = (96, 72);
    s
}

/// Lights of every kind and size: a small and a large cone, one at the horizon, a sphere light.
fn lights() -> Vec<LightShape> {
    vec![
        LightShape::Distant { direction: Vec3::new(0.3, 1.0, 0.2).normalize(), half_angle: 0.02 },
        LightShape::Distant { direction: Vec3::new(-0.6, 0.8, 0.4).normalize(), half_angle: 0.3 },
        LightShape::Distant { direction: Vec3::new(1.0, 0.05, -0.3).normalize(), half_angle: 0.1 },
        LightShape::Sphere { center: Vec3::new(0.5, 3.0, 1.0), radius: 0.4 },
    ]
}

/// What the camera of `scene` sees: its G-buffer and the points read back from it.
fn seen(gpu: &Gpu, scene: &Scene) -> (gpu::GBuffer, Vec<(Vec3, Vec3)>) {
    let geometry = SceneGeometry::upload(gpu, scene).unwrap();
    let gb = GBufferPass::new(gpu).render(gpu, &geometry, &scene.camera).unwrap();
    let points = gb.read_points(gpu).unwrap();
    (gb, points)
}

/// Object `object` of `scene` turned and moved by `t`, on the CPU.
fn posed(scene: &Scene, object: usize, t: glam::Affine3A) -> Scene {
    let mut moved = scene.clone();
    moved.objects[object].mesh.transform(&t);
    moved
}

/// Per light its layer, every light recorded into one encoder; the counters while recording.
fn recorded(
    gpu: &Gpu,
    wedges: &Wedges,
    receivers: &Receivers,
    lights: &[LightShape],
) -> (Vec<Vec<f32>>, gpu::GpuCounters) {
    let (w, h) = receivers.gbuffer.size();
    let vis = VisibilityLayers::allocate(gpu, w, h, lights.len() as u32).unwrap();
    let mut encoder = gpu.encoder("all lights");
    let before = gpu.counters();
    vis.record_clear(&mut encoder);
    let reports = record_visibility(gpu, &mut encoder, wedges, receivers, lights, &[], &vis).unwrap();
    let during = gpu.counters() - before;
    assert!(reports.iter().all(|r| r.skipped.is_none() && r.clock.is_none()));
    gpu.submit(encoder);
    ((0..lights.len() as u32).map(|k| vis.read(gpu, k).unwrap()).collect(), during)
}

fn waited(gpu: &Gpu, wedges: &Wedges, receivers: &Receivers, lights: &[LightShape]) -> Vec<Vec<f32>> {
    let (w, h) = receivers.gbuffer.size();
    let vis = VisibilityLayers::new(gpu, w, h, lights.len() as u32).unwrap();
    render_visibility(gpu, wedges, receivers, lights, &[], &vis).unwrap();
    (0..lights.len() as u32).map(|k| vis.read(gpu, k).unwrap()).collect()
}

#[test]
fn all_lights_recorded_in_one_encoder_equal_each_light_waited_for() {
    let gpu = Gpu::new().unwrap_or_else(|e| panic!("{e}"));
    let scene = scene();
    let (gb, points) = seen(&gpu, &scene);
    let receivers = Receivers::new(&gb, &points);
    let lights = lights();
    for path in [WedgePath::Raster, WedgePath::Compute] {
        let wedges = Wedges::new(&gpu, &scene, WedgeSettings { path, ..WedgeSettings::default() });
        let (layers, during) = recorded(&gpu, &wedges, &receivers, &lights);
        assert_eq!(
            (during.submits, during.waits, during.readback_bytes, during.pipelines),
            (0, 0, 0, 0),
            "{path:?}: recording submitted, waited, mapped or built"
        );
        let reference = waited(&gpu, &wedges, &receivers, &lights);
        for (k, (a, b)) in layers.iter().zip(&reference).enumerate() {
            assert!(a == b, "{path:?}, light {k}: recorded and waited layers differ");
            // not a vacuous comparison: every light shadows something and lights something
            assert!(a.iter().any(|v| *v < 0.5) && a.iter().any(|v| *v > 0.5), "{path:?}, light {k}: no shadow edge");
        }
    }
}

#[test]
fn a_moved_caster_shadows_as_wedges_built_for_its_pose() {
    let gpu = Gpu::new().unwrap_or_else(|e| panic!("{e}"));
    let rest = scene();
    let object = rest.objects.iter().position(|o| o.name != "ground").unwrap();
    let moved = posed(&rest, object, glam::Affine3A::from_translation(Vec3::new(0.31, 0.0, -0.17)));
    let (gb, points) = seen(&gpu, &moved);
    let receivers = Receivers::new(&gb, &points);
    let lights = lights();
    let mut updated = Wedges::new(&gpu, &rest, WedgeSettings::default());
    let at_rest = recorded(&gpu, &updated, &receivers, &lights).0;
    let before = gpu.counters();
    updated.update_object(&gpu, &moved, object).unwrap();
    assert_eq!(gpu.counters() - before, gpu::GpuCounters::default(), "moving made GPU work");
    let fresh = Wedges::new(&gpu, &moved, WedgeSettings::default());
    let (a, b) = (recorded(&gpu, &updated, &receivers, &lights).0, recorded(&gpu, &fresh, &receivers, &lights).0);
    assert!(a == b, "the updated wedges differ from wedges built for the pose");
    assert!(a != at_rest, "the shadows did not move with the caster");
    assert!(updated.update_object(&gpu, &moved, moved.objects.len()).is_err());
}

#[test]
fn wedges_gated_on_the_gpu_and_planned_for_a_looser_box_equal_wedges_planned_for_the_read_receivers() {
    // planned for the receivers' exact bounds read back, or for the scene's box within the view
    // (what the CPU knows without waiting) with the lights gated on the GPU: the culling is
    // conservative, so only the volumes' and wedges' extent and near plane move
    let gpu = Gpu::new().unwrap_or_else(|e| panic!("{e}"));
    let scene = scene();
    let geometry = SceneGeometry::upload(&gpu, &scene).unwrap();
    let gb = GBufferPass::new(&gpu).render(&gpu, &geometry, &scene.camera).unwrap();
    let all = lights();
    let reduction = gpu::ReceiverReduction::new(&gpu);
    let mut encoder = gpu.encoder("reduction");
    let pending = reduction.record(&gpu, &mut encoder, &gb, &all, None).unwrap();
    gpu.submit(encoder);
    let on_gpu = pending.on_gpu().clone();
    let stats = pending.read(&gpu).unwrap();
    let read = Receivers::from_stats(&gb, &stats, &all);
    let (lo, hi) = scene
        .objects
        .iter()
        .flat_map(|o| &o.mesh.positions)
        .fold((Vec3::splat(f32::INFINITY), Vec3::splat(f32::NEG_INFINITY)), |(lo, hi), p| (lo.min(*p), hi.max(*p)));
    let bounds = gpu::conservative_bounds((lo, hi), &gb.view);
    let (exact, loose) = (read.bounds.unwrap(), bounds.unwrap());
    assert!(loose.0.cmple(exact.0).all() && loose.1.cmpge(exact.1).all(), "{loose:?} does not hold {exact:?}");
    let left = Receivers::on_gpu(&gb, bounds, on_gpu);
    for settings in [WedgeSettings::default(), WedgeSettings { path: WedgePath::Compute, ..WedgeSettings::default() }] {
        let wedges = Wedges::new(&gpu, &scene, settings);
        let (w, h) = gb.size();
        let vis = VisibilityLayers::allocate(&gpu, w, h, all.len() as u32).unwrap();
        let mut encoder = gpu.encoder("read stats");
        vis.record_clear(&mut encoder);
        record_visibility(&gpu, &mut encoder, &wedges, &read, &all, &[], &vis).unwrap();
        gpu.submit(encoder);
        let want: Vec<Vec<f32>> = (0..all.len() as u32).map(|k| vis.read(&gpu, k).unwrap()).collect();
        let vis = VisibilityLayers::allocate(&gpu, w, h, all.len() as u32).unwrap();
        let mut encoder = gpu.encoder("gated");
        let before = gpu.counters();
        vis.record_clear(&mut encoder);
        record_visibility(&gpu, &mut encoder, &wedges, &left, &all, &[], &vis).unwrap();
        let during = gpu.counters() - before;
        assert_eq!((during.submits, during.waits, during.readback_bytes, during.pipelines), (0, 0, 0, 0));
        // one gate a light: its volume, wedges (or bins) and resolve behind it
        assert_eq!(during.gate_passes, all.len() as u64);
        gpu.submit(encoder);
        for (k, a) in want.iter().enumerate() {
            let b = vis.read(&gpu, k as u32).unwrap();
            let differ = a.iter().zip(&b).filter(|(x, y)| x != y).count();
            let worst = a.iter().zip(&b).map(|(x, y)| (x - y).abs()).fold(0.0, f32::max);
            // measured on lavapipe: no pixel differs
            assert!(
                differ * 1000 <= a.len() && worst <= 2.0 / 255.0,
                "{settings:?}, light {k}: {differ} differ, worst {worst}"
            );
        }
    }
}

/// Texels of `a` and `b` further apart than 0.02, and the largest difference.
fn apart(a: &[Vec<f32>], b: &[Vec<f32>]) -> (usize, f32) {
    let d = a.iter().flatten().zip(b.iter().flatten()).map(|(x, y)| (x - y).abs());
    d.fold((0, 0.0f32), |(n, m), d| (n + usize::from(d > 0.02), m.max(d)))
}

#[test]
fn a_transformed_caster_shadows_as_its_mesh_moved_on_the_cpu() {
    // the transform placed on the GPU (GPU builder) and applied to the welded positions on the
    // CPU (CPU builder), against wedges built for the moved mesh: the same edges a rounding
    // apart, the bounds moved rather than measured (a hair wider: the extent moves)
    let gpu = Gpu::new().unwrap_or_else(|e| panic!("{e}"));
    let rest = scene();
    let object = rest.objects.iter().position(|o| o.name != "ground").unwrap();
    let t = glam::Affine3A::from_translation(Vec3::new(0.31, 0.05, -0.17)) * glam::Affine3A::from_rotation_y(0.6);
    let moved = posed(&rest, object, t);
    let (gb, points) = seen(&gpu, &moved);
    let receivers = Receivers::new(&gb, &points);
    let lights = lights();
    let texels = lights.len() * points.len();
    for build in [penumbra_wedge::WedgeBuild::Gpu, penumbra_wedge::WedgeBuild::Cpu] {
        let settings = WedgeSettings { build, ..WedgeSettings::default() };
        let mut placed = Wedges::new(&gpu, &rest, settings);
        let at_rest = recorded(&gpu, &placed, &receivers, &lights).0;
        let before = gpu.counters();
        placed.set_transform(&gpu, object, t).unwrap();
        let d = gpu.counters() - before;
        assert_eq!((d.submits, d.waits, d.pipelines), (0, 0, 0), "{build:?}: moving submitted, waited or built");
        let (a, during) = recorded(&gpu, &placed, &receivers, &lights);
        assert_eq!((during.submits, during.waits, during.pipelines), (0, 0, 0), "{build:?}: recording");
        let fresh = recorded(&gpu, &Wedges::new(&gpu, &moved, settings), &receivers, &lights).0;
        let (n, max) = apart(&a, &fresh);
        assert!(n * 2000 <= texels, "{build:?}: {n} of {texels} texels apart (largest {max})");
        assert!(apart(&a, &at_rest).0 * 50 > texels, "{build:?}: the shadows did not move with the caster");
        // back at rest: bit for bit
        placed.set_transform(&gpu, object, glam::Affine3A::IDENTITY).unwrap();
        assert!(recorded(&gpu, &placed, &receivers, &lights).0 == at_rest, "{build:?}: back at rest");
    }
    let mut wedges = Wedges::new(&gpu, &rest, WedgeSettings::default());
    assert!(wedges.set_transform(&gpu, rest.objects.len(), t).is_err());
    assert!(wedges.set_transform(&gpu, object, glam::Affine3A::from_scale(Vec3::splat(f32::NAN))).is_err());
}
