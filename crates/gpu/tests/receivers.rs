//! The receivers' statistics reduced on the GPU against the CPU's, from the same G-buffer: the
//! bounds exactly, the count exactly, the mean within the rounding of two summation orders, and
//! per light the same answer to "does any visible receiver face it", over scenes at 1e-3, 1 and
//! 1e3 metres, lights that face everything, some and nothing, and a camera that sees nothing.

use envmap_sphere::Sh9;
use glam::Vec3;
use gpu::{
    GBufferPass, Gpu, LightShape, ReceiverReduction, ReceiverStats, Receivers, SceneGeometry, ShadeLight,
    WEBER_FRACTION, WeberInput, weber_negligible,
};

fn scene(scale: f32) -> scene::Scene {
    let mut s = scene::Scene::builtin("spheres_box").unwrap();
    (s.camera.width, s.camera.height) = (97, 71);
    for o in &mut s.objects {
        for p in &mut o.mesh.positions {
            *p *= scale;
        }
    }
    s.camera.eye *= scale;
    s.camera.target *= scale;
    s
}

fn lights(scale: f32) -> Vec<LightShape> {
    vec![
        LightShape::Distant { direction: Vec3::Y, half_angle: 0.01 },
        // from straight below, tiny: only faces turned down see it
        LightShape::Distant { direction: Vec3::NEG_Y, half_angle: 1e-4 },
        LightShape::Distant { direction: Vec3::new(1.0, -0.2, 0.1).normalize(), half_angle: 0.3 },
        // wider than the technique's largest half-angle: clamped as on the CPU
        LightShape::Distant { direction: Vec3::NEG_Y, half_angle: 1.57 },
        LightShape::Sphere { center: Vec3::new(0.3, 2.0, 0.5) * scale, radius: 0.2 * scale },
        // under the ground, a point: faces only what looks down at it
        LightShape::Sphere { center: Vec3::new(0.0, -5.0, 0.0) * scale, radius: 0.0 },
        // degenerate direction: the CPU takes +Y
        LightShape::Distant { direction: Vec3::ZERO, half_angle: 0.1 },
    ]
}

/// A sun, a sky of lights from 30 % of it down to a ten-thousandth (some under Weber's 2 %
/// alone, not all together), a point light, and an ambient.
fn shade_lights(scale: f32) -> (Vec<ShadeLight>, Sh9) {
    let mut lights = vec![ShadeLight::Distant {
        direction: Vec3::new(0.3, 1.0, 0.2).normalize(),
        irradiance: Vec3::new(10.0, 9.0, 8.0),
        half_angle: 0.01,
    }];
    for k in 0..12 {
        let a = k as f32 * 0.52;
        let power = 3.0 * 0.45f32.powi(k);
        lights.push(ShadeLight::Distant {
            direction: Vec3::new(a.cos(), 0.2 + 0.06 * k as f32, a.sin()).normalize(),
            irradiance: Vec3::new(power, power * 0.9, power * 1.1),
            half_angle: 0.05 + 0.04 * k as f32,
        });
    }
    lights.push(ShadeLight::Point {
        position: Vec3::new(0.5, 1.5, 1.0) * scale,
        intensity: Vec3::splat(0.3 * scale * scale),
    });
    let sky = Sh9 { coeffs: std::array::from_fn(|k| Vec3::splat(if k == 0 { 1.2 } else { 0.1 / k as f32 })) };
    (lights, sky)
}

fn compare(gpu: &Gpu, reduction: &ReceiverReduction, scene: &scene::Scene, lights: &[LightShape]) -> ReceiverStats {
    compare_weber(gpu, reduction, scene, lights, &shade_lights(1.0))
}

/// Reduces `scene`'s G-buffer with `reduction` (one reused from call to call: its uploads and
/// bind groups follow the G-buffer, the image size and the lights) and checks it against the CPU.
fn compare_weber(
    gpu: &Gpu,
    reduction: &ReceiverReduction,
    scene: &scene::Scene,
    lights: &[LightShape],
    weber: &(Vec<ShadeLight>, Sh9),
) -> ReceiverStats {
    let geometry = SceneGeometry::upload(gpu, scene).unwrap();
    let gb = GBufferPass::new(gpu).render(gpu, &geometry, &scene.camera).unwrap();
    let points = gb.read_points(gpu).unwrap();
    let cpu = Receivers::new(&gb, &points);
    let mut encoder = gpu.encoder("receivers");
    let before = gpu.counters();
    let (shade, sky) = weber;
    let weber = WeberInput { lights: shade, ambient: Some(sky), fraction: WEBER_FRACTION };
    let pending = reduction.record(gpu, &mut encoder, &gb, lights, Some(weber)).unwrap();
    gpu.submit(encoder);
    let stats = pending.read(gpu).unwrap();
    let d = gpu.counters() - before;
    assert_eq!((d.submits, d.waits, d.pipelines), (1, 1, 0));
    assert!(d.readback_bytes <= 512, "{} bytes read back", d.readback_bytes);
    assert_eq!(stats.negligible, weber_negligible(&cpu, shade, Some(sky), WEBER_FRACTION), "Weber");
    let visible: Vec<Vec3> = points.iter().map(|(p, _)| *p).filter(|p| p.is_finite()).collect();
    assert_eq!(stats.count as usize, visible.len());
    assert_eq!(stats.bounds, cpu.bounds, "bounds");
    match (stats.mean, stats.radius, cpu.focus) {
        (Some(m), Some(r), Some((c, cpu_r))) => {
            let extent = cpu.bounds.map_or(1.0, |(lo, hi)| (hi - lo).length());
            assert!((m - c).length() <= 1e-5 * extent, "mean {m} against {c}");
            assert!((r - cpu_r).abs() <= 1e-5 * extent, "radius {r} against {cpu_r}");
            // the select itself: the CPU's percentile of the distances to the GPU's mean
            let mut d: Vec<f32> = visible.iter().map(|p| p.distance(m)).collect();
            let k = (d.len() * 95 / 100).min(d.len() - 1);
            let (_, want, _) = d.select_nth_unstable_by(k, f32::total_cmp);
            assert!((r - *want).abs() <= 4.0 * f32::EPSILON * *want, "radius {r}, the {k}-th distance {want}");
        }
        (None, None, None) => {}
        (m, r, c) => panic!("mean {m:?}, radius {r:?} against focus {c:?}"),
    }
    let want: Vec<bool> = lights.iter().map(|l| cpu.any_faces(l)).collect();
    assert_eq!(stats.faces, want, "faces");
    stats
}

#[test]
fn gpu_receiver_stats_equal_the_cpu_receivers() {
    let gpu = Gpu::new().unwrap_or_else(|e| panic!("{e}"));
    let reduction = ReceiverReduction::new(&gpu);
    let (mut outcomes, mut negligible) = (Vec::new(), Vec::new());
    for scale in [1e-3, 1.0, 1e3] {
        let s = scene(scale);
        let stats = compare_weber(&gpu, &reduction, &s, &lights(scale), &shade_lights(scale));
        outcomes.extend(stats.faces);
        negligible.extend(stats.negligible);
    }
    // the ground alone: the lights from below face nothing
    let mut ground = scene(1.0);
    ground.objects.retain(|o| o.name == "ground");
    outcomes.extend(compare(&gpu, &reduction, &ground, &lights(1.0)).faces);
    // another size, fewer lights and more Weber lights than before, with the same reduction
    let mut small = scene(1.0);
    (small.camera.width, small.camera.height) = (33, 129);
    let (mut shade, sky) = shade_lights(1.0);
    shade.extend(shade.clone());
    compare_weber(&gpu, &reduction, &small, &lights(1.0)[..2], &(shade, sky));
    // not vacuous: some lights face a receiver and some face none
    assert!(outcomes.contains(&true) && outcomes.contains(&false), "{outcomes:?}");
    assert!(negligible.contains(&true) && negligible.contains(&false), "{negligible:?}");
    // twice the same frame: the same bits
    let s = scene(1.0);
    assert_eq!(
        compare(&gpu, &reduction, &s, &lights(1.0)),
        compare(&gpu, &ReceiverReduction::new(&gpu), &s, &lights(1.0))
    );
}

#[test]
fn a_camera_that_sees_nothing_has_no_receivers() {
    let gpu = Gpu::new().unwrap_or_else(|e| panic!("{e}"));
    let mut s = scene(1.0);
    // looking up, away from everything
    s.camera.target = s.camera.eye + Vec3::new(0.0, 1.0, 0.01);
    let stats = compare(&gpu, &ReceiverReduction::new(&gpu), &s, &lights(1.0));
    assert_eq!((stats.count, stats.bounds, stats.mean, stats.radius), (0, None, None, None));
    assert!(stats.faces.iter().all(|f| !f));
    let too_many = vec![LightShape::Distant { direction: Vec3::Y, half_angle: 0.0 }; ReceiverReduction::MAX_LIGHTS + 1];
    let geometry = SceneGeometry::upload(&gpu, &s).unwrap();
    let gb = GBufferPass::new(&gpu).render(&gpu, &geometry, &s.camera).unwrap();
    let mut encoder = gpu.encoder("too many");
    assert!(ReceiverReduction::new(&gpu).record(&gpu, &mut encoder, &gb, &too_many, None).is_err());
}

#[test]
fn weber_on_the_gpu_marks_nothing_under_non_finite_light() {
    let gpu = Gpu::new().unwrap_or_else(|e| panic!("{e}"));
    let s = scene(1.0);
    let (mut shade, sky) = shade_lights(1.0);
    if let ShadeLight::Distant { irradiance, .. } = &mut shade[0] {
        *irradiance = Vec3::splat(f32::INFINITY);
    }
    let stats = compare_weber(&gpu, &ReceiverReduction::new(&gpu), &s, &lights(1.0), &(shade, sky));
    assert!(stats.negligible.iter().all(|n| !n) && !stats.negligible.is_empty());
    // an f16-max sun is finite: the faint lights under it are negligible
    let (mut shade, sky) = shade_lights(1.0);
    if let ShadeLight::Distant { irradiance, .. } = &mut shade[0] {
        *irradiance = Vec3::splat(65504.0);
    }
    assert!(
        compare_weber(&gpu, &ReceiverReduction::new(&gpu), &s, &lights(1.0), &(shade, sky)).negligible.contains(&true)
    );
}

#[test]
fn a_reused_reduction_makes_nothing_after_its_first_record() {
    // its uploads and bind groups are kept for the G-buffer they bind, its mapped results go
    // back to a pool once read: a second frame's reduction creates no buffer and no bind group
    let gpu = Gpu::new().unwrap_or_else(|e| panic!("{e}"));
    let s = scene(1.0);
    let geometry = SceneGeometry::upload(&gpu, &s).unwrap();
    let gb = GBufferPass::new(&gpu).render(&gpu, &geometry, &s.camera).unwrap();
    let reduction = ReceiverReduction::new(&gpu);
    let (shade, sky) = shade_lights(1.0);
    let weber = WeberInput { lights: &shade, ambient: Some(&sky), fraction: WEBER_FRACTION };
    let mut results = Vec::new();
    let mut made = Vec::new();
    for _ in 0..3 {
        let before = gpu.counters();
        let mut encoder = gpu.encoder("receivers");
        let pending = reduction.record(&gpu, &mut encoder, &gb, &lights(1.0), Some(weber)).unwrap();
        gpu.submit(encoder);
        let mapped = pending.map(&gpu);
        gpu.wait(None).unwrap();
        results.push(mapped.finish(&gpu).unwrap());
        let d = gpu.counters() - before;
        made.push((d.buffers, d.bind_groups));
    }
    assert!(made[0].0 > 0 && made[0].1 > 0, "the first record makes its resources: {made:?}");
    assert_eq!(&made[1..], &[(0, 0), (0, 0)], "{made:?}");
    assert!(results.windows(2).all(|w| w[0] == w[1]), "{results:?}");
}
