//! The one recorded frame (`gpu::LitFrame`) against the same frame put together pass by pass:
//! unshadowed and shadowed by a precomputed technique, without a split, bit for bit; its
//! lights gated on the GPU exactly as the CPU's receivers skip them; two submissions and no
//! wait; nothing made after the first frame; and its misuses as errors.

use glam::Vec3;
use gpu::{
    FrameLights, FrameShadows, GBufferPass, Gpu, LightShape, LitFrame, LitSettings, PrecomputedVisibility, Receivers,
    ReferenceReceivers, SceneGeometry, ShadeLight, ShadeParams, ShadingPass, VisibilityLayers, read_hdr,
};

/// The ground alone: nothing visible faces a light from below.
fn scene() -> scene::Scene {
    let mut s = scene::Scene::builtin("spheres_box").unwrap();
    s.objects.retain(|o| o.name == "ground");
    (s.camera.width, s.camera.height) = (48, 36);
    s
}

/// A sun, two sky lights and a light from straight below, which nothing visible faces.
fn lights() -> Vec<ShadeLight> {
    vec![
        ShadeLight::Distant {
            direction: Vec3::new(0.3, 1.0, 0.2).normalize(),
            irradiance: Vec3::new(8.0, 7.0, 6.0),
            half_angle: 0.02,
        },
        ShadeLight::Distant {
            direction: Vec3::new(-0.7, 0.5, 0.1).normalize(),
            irradiance: Vec3::splat(1.0),
            half_angle: 0.2,
        },
        ShadeLight::Distant {
            direction: Vec3::new(0.1, 0.4, -0.9).normalize(),
            irradiance: Vec3::splat(0.6),
            half_angle: 0.3,
        },
        ShadeLight::Distant { direction: Vec3::NEG_Y, irradiance: Vec3::splat(3.0), half_angle: 1e-4 },
    ]
}

fn shape(l: &ShadeLight) -> LightShape {
    match *l {
        ShadeLight::Distant { direction, half_angle, .. } => LightShape::Distant { direction, half_angle },
        ShadeLight::Point { position, .. } => LightShape::Sphere { center: position, radius: 0.0 },
    }
}

/// `shade` all EnvDirects (no split), nothing but the lights.
fn every_light_direct<'a>(shade: &'a [ShadeLight], shapes: &'a [LightShape]) -> FrameLights<'a> {
    FrameLights { lights: shade, shapes, directs: shade.len(), ambient: None, specular_ambient: None, background: None }
}

#[test]
fn the_recorded_frame_equals_its_passes_put_together() {
    let gpu = Gpu::new().unwrap_or_else(|e| panic!("{e}"));
    let s = scene();
    let size = (s.camera.width, s.camera.height);
    let geometry = SceneGeometry::upload(&gpu, &s).unwrap();
    let view = GBufferPass::camera_view(&geometry, &s.camera);
    let shade = lights();
    let shapes: Vec<LightShape> = shade.iter().map(shape).collect();
    let pixels = (size.0 * size.1) as usize;
    let layers = shapes.iter().enumerate().map(|(k, l)| (*l, vec![0.2 + 0.15 * k as f32; pixels])).collect();
    let technique = PrecomputedVisibility::new(&gpu, "graded", size, layers).unwrap();
    let frame_lights = every_light_direct(&shade, &shapes);
    // by hand: the G-buffer, the CPU's receivers, each light the CPU does not skip, shading
    let gb = GBufferPass::new(&gpu).render(&gpu, &geometry, &s.camera).unwrap();
    let points = gb.read_points(&gpu).unwrap();
    let receivers = Receivers::new(&gb, &points);
    let params = ShadeParams { lights: &shade, ..Default::default() };
    let shading = ShadingPass::new(&gpu).unwrap();
    let unlit = VisibilityLayers::new(&gpu, size.0, size.1, shade.len() as u32).unwrap();
    let plain = read_hdr(&gpu, &shading.render_texture(&gpu, &geometry, &gb, &params, &unlit).unwrap()).unwrap();
    let vis = VisibilityLayers::new(&gpu, size.0, size.1, shade.len() as u32).unwrap();
    let by_hand = gpu::render_visibility(&gpu, &technique, &receivers, &shapes, &[], &vis).unwrap();
    let shadowed = read_hdr(&gpu, &shading.render_texture(&gpu, &geometry, &gb, &params, &vis).unwrap()).unwrap();
    assert!(by_hand.iter().any(|r| r.skipped.is_some()) && by_hand.iter().any(|r| r.skipped.is_none()));

    let lit = LitFrame::new(&gpu, size).unwrap();
    let settings = LitSettings { weber: false, ..LitSettings::default() };
    let unshadowed = lit.render(&gpu, &geometry, &view, &frame_lights, None, &settings).unwrap();
    gpu.wait(None).unwrap();
    let (texture, reports) = unshadowed.finish_reports(&gpu).unwrap();
    assert!(reports.is_empty());
    assert_eq!(read_hdr(&gpu, &texture).unwrap(), plain, "unshadowed");

    let shadows = Some(FrameShadows { direct: &technique, indirect: &technique });
    for k in 0..3 {
        let before = gpu.counters();
        let frame = lit.render(&gpu, &geometry, &view, &frame_lights, shadows, &settings).unwrap();
        let d = gpu.counters() - before;
        // the reduction's few hundred bytes are asked for, not waited for
        assert_eq!((d.submits, d.waits), (2, 0), "frame {k}: {d:?}");
        assert!(d.readback_bytes <= gpu::ReceiverStats::BYTES, "frame {k}: {d:?}");
        if k > 0 {
            assert_eq!((d.buffers, d.bind_groups, d.textures, d.pipelines), (0, 0, 0, 0), "frame {k}: {d:?}");
        }
        gpu.wait(None).unwrap();
        let (texture, reports) = frame.finish_reports(&gpu).unwrap();
        let skipped = |r: &[gpu::ShadowPassReport]| r.iter().map(|r| r.skipped.clone()).collect::<Vec<_>>();
        assert_eq!(skipped(&reports), skipped(&by_hand), "frame {k}");
        assert_eq!(read_hdr(&gpu, &texture).unwrap(), shadowed, "frame {k}");
    }
    // the references agree with it
    let both = FrameShadows { direct: &technique, indirect: &technique };
    for from in [ReferenceReceivers::ReadStats, ReferenceReceivers::CpuPoints] {
        let frame = lit.render_reference(&gpu, &geometry, &view, &frame_lights, both, &settings, from).unwrap();
        gpu.wait(None).unwrap();
        assert_eq!(read_hdr(&gpu, &frame.finish_reports(&gpu).unwrap().0).unwrap(), shadowed, "{from:?}");
    }
}

#[test]
fn misused_frames_are_errors() {
    let gpu = Gpu::new().unwrap_or_else(|e| panic!("{e}"));
    let s = scene();
    let geometry = SceneGeometry::upload(&gpu, &s).unwrap();
    let view = GBufferPass::camera_view(&geometry, &s.camera);
    let shade = lights();
    let shapes: Vec<LightShape> = shade.iter().map(shape).collect();
    let lit = LitFrame::new(&gpu, (s.camera.width, s.camera.height)).unwrap();
    let all = every_light_direct(&shade, &shapes);
    let settings = LitSettings::default();
    // more directs than lights; shapes that do not match the lights
    let too_many = FrameLights { directs: shade.len() + 1, ..all };
    assert!(lit.render(&gpu, &geometry, &view, &too_many, None, &settings).is_err());
    let fewer_shapes = FrameLights { shapes: &shapes[..1], ..all };
    assert!(lit.render(&gpu, &geometry, &view, &fewer_shapes, None, &settings).is_err());
    // a split without shadow techniques; a scale that does not divide the size
    let split = FrameLights { directs: 1, ..all };
    assert!(lit.render(&gpu, &geometry, &view, &split, None, &settings).is_err());
    let layers = shapes.iter().map(|l| (*l, vec![1.0; 48 * 36])).collect();
    let technique = PrecomputedVisibility::new(&gpu, "lit", (48, 36), layers).unwrap();
    let shadows = Some(FrameShadows { direct: &technique, indirect: &technique });
    let mut odd = settings;
    odd.split.indirect_scale = 5;
    assert!(lit.render(&gpu, &geometry, &view, &split, shadows, &odd).is_err());
    // a view of another size than the frame's
    let small = view.resized(24, 18);
    assert!(lit.render(&gpu, &geometry, &small, &all, None, &settings).is_err());
}

#[test]
fn interleaved_sets_take_each_pixel_from_their_own_frame() {
    let gpu = Gpu::new().unwrap_or_else(|e| panic!("{e}"));
    let s = scene();
    let size = (s.camera.width, s.camera.height);
    let geometry = SceneGeometry::upload(&gpu, &s).unwrap();
    let view = GBufferPass::camera_view(&geometry, &s.camera);
    let base = lights();
    let shapes: Vec<LightShape> = base.iter().map(shape).collect();
    let pixels = (size.0 * size.1) as usize;
    let layers = shapes.iter().enumerate().map(|(k, l)| (*l, vec![0.3 + 0.2 * k as f32; pixels])).collect();
    let technique = PrecomputedVisibility::new(&gpu, "graded", size, layers).unwrap();
    let shadows = FrameShadows { direct: &technique, indirect: &technique };
    // three sets of the same shapes in other colours: each pixel tells its set apart
    let sets: Vec<Vec<ShadeLight>> = (0..3)
        .map(|k| {
            let tint = [Vec3::new(1.0, 0.2, 0.2), Vec3::new(0.2, 1.0, 0.2), Vec3::new(0.2, 0.2, 1.0)][k];
            base.iter()
                .map(|l| match *l {
                    ShadeLight::Distant { direction, irradiance, half_angle } => {
                        ShadeLight::Distant { direction, irradiance: irradiance * tint, half_angle }
                    }
                    other => other,
                })
                .collect()
        })
        .collect();
    let frames: Vec<FrameLights> = sets.iter().map(|l| every_light_direct(l, &shapes)).collect();
    let lit = LitFrame::new(&gpu, size).unwrap();
    let settings = LitSettings { weber: false, ..LitSettings::default() };
    // each set alone, read back before the next overwrites the frame's target
    let alone: Vec<Vec<Vec3>> = frames
        .iter()
        .map(|f| {
            let frame = lit.render(&gpu, &geometry, &view, f, Some(shadows), &settings).unwrap();
            gpu.wait(None).unwrap();
            read_hdr(&gpu, &frame.finish_reports(&gpu).unwrap().0).unwrap()
        })
        .collect();
    assert_ne!(alone[0], alone[1]);
    for reference in [None, Some(ReferenceReceivers::CpuPoints)] {
        let before = gpu.counters();
        let image = lit.render_interleaved(&gpu, &geometry, &view, &frames, shadows, &settings, reference).unwrap();
        let d = gpu.counters() - before;
        if reference.is_none() {
            // each set's two submissions and its gathering; no wait
            assert_eq!((d.submits, d.waits), (3 * 3, 0), "{d:?}");
        }
        gpu.wait(None).unwrap();
        let (texture, reports) = image.finish_reports(&gpu).unwrap();
        assert_eq!(reports.len(), 3 * base.len());
        let got = read_hdr(&gpu, &texture).unwrap();
        for y in 0..size.1 {
            for x in 0..size.0 {
                let k = (y * size.0 + x) as usize;
                let set = gpu::interleave_set(x, y, 3) as usize;
                assert_eq!(got[k], alone[set][k], "pixel ({x}, {y}), {reference:?}");
            }
        }
    }
    assert!(lit.render_interleaved(&gpu, &geometry, &view, &[], shadows, &settings, None).is_err());
}

#[test]
fn a_turned_map_draws_as_the_map_turned_by_whole_columns() {
    // the background and the specular ambient of a map turned about +Y by k columns' angle, as
    // the map whose columns were moved by k (an exact turn of its texels)
    let gpu = Gpu::new().unwrap_or_else(|e| panic!("{e}"));
    let mut s = scene::Scene::builtin("glossy_set").unwrap();
    (s.camera.width, s.camera.height) = (64, 48);
    let geometry = SceneGeometry::upload(&gpu, &s).unwrap();
    let view = GBufferPass::camera_view(&geometry, &s.camera);
    let lit = LitFrame::new(&gpu, (64, 48)).unwrap();
    let map = envmap_sphere::default_map();
    let (w, h) = (map.width(), map.height());
    let settings = gpu::PrefilterSettings::default();
    // whole texels of the prefiltered map too
    let columns = w / 8 * 3;
    let moved = envmap_sphere::EnvMap::from_texels(w, h, |i, j| map.pixel((i + w - columns) % w, j));
    let angle = -std::f32::consts::TAU * columns as f32 / w as f32;
    let draw = |background: &gpu::Background, specular: &gpu::SpecularAmbient| {
        let lights = FrameLights {
            lights: &[],
            shapes: &[],
            directs: 0,
            ambient: None,
            specular_ambient: Some(specular),
            background: Some(background),
        };
        let frame = lit.render(&gpu, &geometry, &view, &lights, None, &LitSettings::default()).unwrap();
        gpu.wait(None).unwrap();
        read_hdr(&gpu, &frame.texture).unwrap()
    };
    let mut background = gpu::Background::upload(&gpu, &map).unwrap();
    let mut specular = gpu::SpecularAmbient::new(&gpu, &map, &settings).unwrap();
    let still = draw(&background, &specular);
    background.set_turn(angle);
    specular.set_turn(angle);
    let turned = draw(&background, &specular);
    let want = draw(
        &gpu::Background::upload(&gpu, &moved).unwrap(),
        &gpu::SpecularAmbient::new(&gpu, &moved, &settings).unwrap(),
    );
    let differ = |a: &[Vec3], b: &[Vec3], tol: f32| {
        a.iter()
            .zip(b)
            .filter(|(x, y)| (**x - **y).abs().max_element() > tol * x.max(**y).max_element().max(1e-3))
            .count()
    };
    // the turn shows: the background and the reflections changed
    assert!(differ(&still, &turned, 0.05) > still.len() / 4, "the turn changed little");
    // and is the moved map's, within the prefilter's
    // own sampling, which a moved map's lobes meet at other points (measured: 90 of 3072
    // pixels 2-6 % apart, none more)
    let off = differ(&turned, &want, 0.02);
    assert!(off <= turned.len() / 20, "{off} of {} pixels differ from the moved map's", turned.len());
    assert_eq!(differ(&turned, &want, 0.1), 0, "a pixel 10 % from the moved map's");
    // a turn of a whole circle is none
    background.set_turn(std::f32::consts::TAU);
    assert_eq!(background.turn(), 0.0);
    background.set_turn(f32::NAN);
    assert_eq!(background.turn(), 0.0);
}
