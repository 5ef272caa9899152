//! Lights gated on the GPU (`gpu::Gate`): a light whose receivers the reduction finds facing
//! it and that Weber's law keeps draws its passes; the others draw nothing and their layers
//! stay as their passes clear them, lit — decided without the CPU waiting for the reduction,
//! and the same lights as the CPU's skipping (`ReceiverStats::skip_reason`) once read back.

use glam::Vec3;
use gpu::{
    GBufferPass, Gpu, LightShape, PrecomputedVisibility, ReceiverReduction, Receivers, SceneGeometry, ShadeLight,
    VisibilityLayers, WEBER_FRACTION, WeberInput,
};

/// A sun from above, a sky of faint lights (the faintest under Weber's 2 %), one light from
/// straight below and a point light under the ground, which the ground does not face.
fn lights() -> Vec<ShadeLight> {
    let mut lights = vec![ShadeLight::Distant {
        direction: Vec3::new(0.3, 1.0, 0.2).normalize(),
        irradiance: Vec3::new(10.0, 9.0, 8.0),
        half_angle: 0.01,
    }];
    for k in 0..8 {
        let a = k as f32 * 0.7;
        let power = 2.0 * 0.3f32.powi(k);
        lights.push(ShadeLight::Distant {
            direction: Vec3::new(a.cos(), 0.3 + 0.05 * k as f32, a.sin()).normalize(),
            irradiance: Vec3::splat(power),
            half_angle: 0.05,
        });
    }
    lights.push(ShadeLight::Distant { direction: Vec3::NEG_Y, irradiance: Vec3::splat(5.0), half_angle: 1e-4 });
    lights.push(ShadeLight::Point { position: Vec3::new(0.0, -5.0, 0.0), intensity: Vec3::splat(50.0) });
    lights
}

fn shape(l: &ShadeLight) -> LightShape {
    match *l {
        ShadeLight::Distant { direction, half_angle, .. } => LightShape::Distant { direction, half_angle },
        ShadeLight::Point { position, .. } => LightShape::Sphere { center: position, radius: 0.0 },
    }
}

#[test]
fn gated_lights_draw_exactly_where_the_reduction_says_they_need_a_pass() {
    let gpu = Gpu::new().unwrap_or_else(|e| panic!("{e}"));
    // the ground alone: nothing visible faces a light from below
    let mut scene = scene::Scene::builtin("spheres_box").unwrap();
    scene.objects.retain(|o| o.name == "ground");
    (scene.camera.width, scene.camera.height) = (64, 48);
    let geometry = SceneGeometry::upload(&gpu, &scene).unwrap();
    let gb = GBufferPass::new(&gpu).render(&gpu, &geometry, &scene.camera).unwrap();
    let shade = lights();
    let shapes: Vec<LightShape> = shade.iter().map(shape).collect();
    // every light's layer would be a quarter lit, where its passes run
    let pixels = 64 * 48;
    let layers = shapes.iter().map(|l| (*l, vec![0.25; pixels])).collect();
    let technique = PrecomputedVisibility::new(&gpu, "quarter", (64, 48), layers).unwrap();
    let reduction = ReceiverReduction::new(&gpu);
    let vis = VisibilityLayers::allocate(&gpu, 64, 48, shapes.len() as u32).unwrap();

    let before = gpu.counters();
    let mut encoder = gpu.encoder("gated");
    let weber = WeberInput { lights: &shade, ambient: None, fraction: WEBER_FRACTION };
    let pending = reduction.record(&gpu, &mut encoder, &gb, &shapes, Some(weber)).unwrap();
    let receivers = Receivers::on_gpu(&gb, None, pending.on_gpu().clone());
    vis.record_clear(&mut encoder);
    let reports = gpu::record_visibility(&gpu, &mut encoder, &technique, &receivers, &shapes, &[], &vis).unwrap();
    gpu.submit(encoder);
    let mapped = pending.map(&gpu);
    let d = gpu.counters() - before;
    // recorded and submitted without a wait; the CPU records every light
    assert_eq!((d.submits, d.waits, d.pipelines), (1, 0, 0), "{d:?}");
    assert!(reports.iter().all(|r| r.skipped.is_none()));

    gpu.wait(None).unwrap();
    let stats = mapped.finish(&gpu).unwrap();
    let (mut drawn, mut unfaced, mut negligible) = (0, 0, 0);
    for (k, light) in shapes.iter().enumerate() {
        let layer = vis.read(&gpu, k as u32).unwrap();
        let why = stats.skip_reason(k);
        let want = if why.is_some() { 1.0 } else { 64.0 / 255.0 };
        assert!(layer.iter().all(|v| (v - want).abs() < 1e-6), "light {k} ({light:?}, skipped: {why:?}): {}", layer[0]);
        match (stats.faces[k], stats.negligible[k]) {
            (false, _) => unfaced += 1,
            (true, true) => negligible += 1,
            (true, false) => drawn += 1,
        }
    }
    // each case happens: drawn, faced by nothing visible, under Weber's 2 %
    assert!(drawn > 0 && unfaced > 0 && negligible > 0, "{drawn} drawn, {unfaced} unfaced, {negligible} negligible");
}

/// A device on `ours`'s adapter without timestamps inside encoders (no optional feature).
fn without_timestamps(ours: &Gpu) -> Gpu {
    let instance = wgpu::Instance::new(wgpu::InstanceDescriptor::new_without_display_handle_from_env());
    let adapters = pollster::block_on(instance.enumerate_adapters(wgpu::Backends::PRIMARY));
    let adapter = adapters.into_iter().find(|a| a.get_info() == ours.info).expect("the same adapter");
    let descriptor = wgpu::DeviceDescriptor { required_limits: adapter.limits(), ..Default::default() };
    let (device, queue) = pollster::block_on(adapter.request_device(&descriptor)).expect("a device");
    Gpu::from_device(device, queue, adapter.get_info())
}

#[test]
fn measured_lights_share_one_submission_each_with_its_own_time() {
    // `render_visibility` wraps the recorded loop: one submission and one wait for every
    // light, each timed between two timestamps of its own, or, on a device without timestamps
    // inside encoders, an even share of the submission's wall time: no light goes alone
    let ours = Gpu::new().unwrap_or_else(|e| panic!("{e}"));
    let timestamps = wgpu::Features::TIMESTAMP_QUERY | wgpu::Features::TIMESTAMP_QUERY_INSIDE_ENCODERS;
    let bare = without_timestamps(&ours);
    assert!(!bare.features.contains(timestamps));
    for gpu in [ours, bare] {
        let mut scene = scene::Scene::builtin("spheres_box").unwrap();
        (scene.camera.width, scene.camera.height) = (32, 24);
        let geometry = SceneGeometry::upload(&gpu, &scene).unwrap();
        let gb = GBufferPass::new(&gpu).render(&gpu, &geometry, &scene.camera).unwrap();
        let points = gb.read_points(&gpu).unwrap();
        let receivers = Receivers::new(&gb, &points);
        let shapes: Vec<LightShape> = lights().iter().map(shape).take(3).collect();
        let layers = shapes.iter().map(|l| (*l, vec![0.5; 32 * 24])).collect();
        let technique = PrecomputedVisibility::new(&gpu, "half", (32, 24), layers).unwrap();
        let vis = VisibilityLayers::allocate(&gpu, 32, 24, shapes.len() as u32).unwrap();
        let before = gpu.counters();
        let reports = gpu::render_visibility(&gpu, &technique, &receivers, &shapes, &[], &vis).unwrap();
        let d = gpu.counters() - before;
        let drawn: Vec<_> = reports.iter().filter(|r| r.skipped.is_none()).collect();
        assert!(!drawn.is_empty());
        assert_eq!(d.submits, 1, "{d:?}");
        if gpu.features.contains(timestamps) {
            assert!(drawn.iter().all(|r| r.clock == Some(gpu::Clock::GpuTimestamps)));
        } else {
            assert!(drawn.iter().all(|r| r.clock == Some(gpu::Clock::WallTimeShare) && r.time == drawn[0].time));
            assert!(drawn[0].time > std::time::Duration::ZERO);
        }
        for (k, r) in reports.iter().enumerate() {
            let want = if r.skipped.is_some() { 1.0 } else { 128.0 / 255.0 };
            assert!(vis.read(&gpu, k as u32).unwrap().iter().all(|v| (v - want).abs() < 1e-6), "light {k}");
        }
    }
}
