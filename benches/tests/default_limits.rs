//! Every technique within WebGPU's default limits (`wgpu::Limits::default()`, no optional
//! feature), as a browser or a cautious engine creates its device: the G-buffer takes two passes
//! there (32 colour bytes a sample) and equals the one-pass G-buffer bit for bit; each
//! technique's layers and paper 001's whole frame come out as on the adapter's own limits,
//! within what the 16-bit accumulator (no `FLOAT32_BLENDABLE`) changes.

use envmap_sphere::EnvMap;
use envshadow_benches::decomposition::Frame;
use glam::Vec3;
use gpu::{
    GBufferPass, Gpu, LightShape, Receivers, SceneGeometry, ShadowTechnique, VisibilityLayers, render_visibility,
};
use penumbra_wedge::{WedgePath, WedgeSettings, Wedges};
use shadowmap_paraboloid::{MapTechnique, ShadowSettings, Technique};

/// A device on the toolkit's adapter with WebGPU's default limits and no optional feature.
fn default_limits(ours: &Gpu) -> Gpu {
    let instance = wgpu::Instance::new(wgpu::InstanceDescriptor::new_without_display_handle_from_env());
    let adapters = pollster::block_on(instance.enumerate_adapters(wgpu::Backends::PRIMARY));
    let adapter = adapters.into_iter().find(|a| a.get_info() == ours.info).expect("the same adapter");
    let descriptor = wgpu::DeviceDescriptor { required_limits: wgpu::Limits::default(), ..Default::default() };
    let (device, queue) = pollster::block_on(adapter.request_device(&descriptor)).expect("a device");
    Gpu::from_device(device, queue, adapter.get_info())
}

fn scene() -> scene::Scene {
    let mut s = scene::Scene::builtin("spheres_box").unwrap();
    (s.camera.width, s.camera.height) = (96, 72);
    s
}

/// Per technique (name, its layers) over `gpu`'s own G-buffer of the scene.
fn layers(gpu: &Gpu) -> Vec<(String, Vec<Vec<f32>>)> {
    let scene = scene();
    let geometry = SceneGeometry::upload(gpu, &scene).unwrap();
    let gb = GBufferPass::new(gpu).render(gpu, &geometry, &scene.camera).unwrap();
    let points = gb.read_points(gpu).unwrap();
    let receivers = Receivers::new(&gb, &points);
    let distant = vec![
        LightShape::Distant { direction: Vec3::new(0.3, 1.0, 0.2).normalize(), half_angle: 0.05 },
        LightShape::Distant { direction: Vec3::new(-0.6, 0.8, 0.4).normalize(), half_angle: 0.25 },
    ];
    let local = vec![LightShape::Sphere { center: Vec3::new(0.5, 3.0, 1.0), radius: 0.0 }];
    let maps = |t, samples| {
        MapTechnique::new(gpu, &scene, t, ShadowSettings { resolution: 512, ..ShadowSettings::default() }, samples)
            .unwrap()
    };
    let techniques: Vec<(Box<dyn ShadowTechnique>, &[LightShape])> = vec![
        (Box::new(Wedges::new(gpu, &scene, WedgeSettings::default())), &distant),
        (
            Box::new(Wedges::new(gpu, &scene, WedgeSettings { path: WedgePath::Compute, ..WedgeSettings::default() })),
            &distant,
        ),
        (Box::new(maps(Technique::Orthographic, 1)), &distant),
        (Box::new(maps(Technique::Orthographic, 4)), &distant),
        (Box::new(maps(Technique::Cube, 1)), &local),
        (Box::new(maps(Technique::DualParaboloid, 1)), &local),
    ];
    techniques
        .into_iter()
        .map(|(t, lights)| {
            let vis = VisibilityLayers::new(gpu, 96, 72, lights.len() as u32).unwrap();
            render_visibility(gpu, t.as_ref(), &receivers, lights, &[], &vis).unwrap();
            (t.name(), (0..lights.len() as u32).map(|k| vis.read(gpu, k).unwrap()).collect())
        })
        .collect()
}

#[test]
fn every_technique_renders_within_webgpus_default_limits() {
    let ours = Gpu::new().unwrap_or_else(|e| panic!("{e}"));
    let theirs = default_limits(&ours);
    assert!(theirs.limits.max_color_attachment_bytes_per_sample < 48 && theirs.features.is_empty());
    // the G-buffer: two passes there, one here (or two on both where the adapter has only 32)
    let s = scene();
    let g = |gpu: &Gpu, pass: GBufferPass| {
        let gb = pass.render(gpu, &SceneGeometry::upload(gpu, &s).unwrap(), &s.camera).unwrap();
        [&gb.position, &gb.normal, &gb.geometric_normal].map(|t| gpu::read_texture_rgba(gpu, t, 0).unwrap())
    };
    let one = g(&ours, GBufferPass::new(&ours));
    assert!(one == g(&theirs, GBufferPass::new(&theirs)), "the default-limits G-buffer differs");
    assert!(one == g(&ours, GBufferPass::two_passes(&ours)), "two passes differ from one");
    // every technique, against the same on the adapter's limits
    for ((name, a), (_, b)) in layers(&ours).iter().zip(layers(&theirs)) {
        for (k, (a, b)) in a.iter().zip(&b).enumerate() {
            let worst = a.iter().zip(b).map(|(x, y)| (x - y).abs()).fold(0.0f32, f32::max);
            let mean = a.iter().zip(b).map(|(x, y)| (x - y).abs()).sum::<f32>() / a.len() as f32;
            assert!(mean < 2e-3 && worst <= 0.1, "{name}, light {k}: mean {mean}, worst {worst}");
            assert!(b.iter().any(|v| *v < 0.5), "{name}, light {k}: no shadow");
        }
    }
    // paper 001's whole frame
    let mut map = EnvMap::constant(128, 64, Vec3::splat(0.3));
    map.set_pixel(20, 14, Vec3::splat(4000.0));
    let image = |gpu: &Gpu| {
        let frame = Frame::new(gpu, "spheres_box", (96, 72), &map, 8).unwrap_or_else(|e| panic!("{e}"));
        gpu::read_hdr(gpu, &frame.render_timed(gpu, 2).unwrap().1).unwrap()
    };
    let (a, b) = (image(&ours), image(&theirs));
    let diff = a.iter().zip(&b).map(|(x, y)| (*x - *y).abs().max_element()).sum::<f32>();
    let total = a.iter().map(|x| x.max_element()).sum::<f32>();
    assert!(b.iter().all(|c| c.is_finite()) && diff <= 1e-3 * total, "frame: {diff} of {total}");
}
