//! The raster renderer against independent results: `ref-tracer`'s `lights` integrator on a
//! scene without cast shadows (same BRDF, SH9 ambient and background), and the closed form of a
//! point light over a Lambertian plane. Runs on lavapipe where there is no GPU.

use envmap_sphere::{EnvMap, Sh9};
use glam::Vec3;
use gpu::{Background, GBufferPass, Gpu, SceneGeometry, ShadeLight, ShadeParams, ShadingPass, VisibilityLayers};
use ref_tracer::{EnvLight, Integrator, LightSet, RenderSettings, SceneBvh, render};
use scene::{Camera, DistantLight, Ggx, Material, Mesh, Object, PointLight, Scene};

fn gpu() -> Gpu {
    Gpu::new().unwrap_or_else(|e| panic!("{e}"))
}

fn camera(eye: Vec3, target: Vec3, w: u32, h: u32) -> Camera {
    Camera { eye, target, up: Vec3::Y, hfov_degrees: 50.0, width: w, height: h }
}

fn gpu_render(gpu: &Gpu, scene: &Scene, params: &ShadeParams) -> (Vec<Vec3>, Vec<[f32; 4]>) {
    let geometry = SceneGeometry::upload(gpu, scene).unwrap();
    let gb = GBufferPass::new(gpu).render(gpu, &geometry, &scene.camera).unwrap();
    let vis = VisibilityLayers::new(gpu, scene.camera.width, scene.camera.height, params.lights.len() as u32).unwrap();
    let image = ShadingPass::new(gpu).unwrap().render(gpu, &geometry, &gb, params, &vis).unwrap();
    (image, gb.read_positions(gpu).unwrap())
}

/// Pixels whose 3x3 neighbourhood sees one object and one face orientation in both renders: no
/// silhouette or box edge inside.
fn interior(ids: &[u32], normals: &[Vec3], gpu_pos: &[[f32; 4]], w: usize, h: usize) -> Vec<usize> {
    (0..w * h)
        .filter(|&k| {
            let (x, y) = ((k % w) as i64, (k / w) as i64);
            let id = ids[k];
            (-1..=1).all(|dy| {
                (-1..=1).all(|dx| {
                    let (nx, ny) = (x + dx, y + dy);
                    if nx < 0 || ny < 0 || nx >= w as i64 || ny >= h as i64 {
                        return false;
                    }
                    let j = (ny as usize) * w + nx as usize;
                    let gpu_id = gpu_pos[j][3];
                    ids[j] == id
                        && (id == u32::MAX || normals[j].dot(normals[k]) > 0.99)
                        && (if id == u32::MAX { gpu_id < 0.0 } else { gpu_id == id as f32 })
                })
            })
        })
        .collect()
}

#[test]
fn shading_matches_ref_tracer_lights_without_shadows() {
    let gpu = gpu();
    let glossy = Material::rgb(Vec3::new(0.7, 0.5, 0.3), Some(Ggx { roughness: 0.4, f0: Vec3::splat(0.04) }));
    let metal = Material::rgb(Vec3::splat(0.2), Some(Ggx { roughness: 0.55, f0: Vec3::new(0.9, 0.6, 0.3) }));
    let scene = Scene {
        name: "apart".into(),
        objects: vec![
            Object {
                name: "sphere".into(),
                mesh: Mesh::icosphere(Vec3::new(-2.0, 0.0, 0.0), 1.0, 4),
                material: glossy,
            },
            Object {
                name: "box".into(),
                mesh: Mesh::cuboid(Vec3::new(1.5, -0.5, -0.5), Vec3::new(2.5, 0.5, 0.5)),
                material: metal,
            },
        ],
        camera: camera(Vec3::new(0.0, 1.5, 6.5), Vec3::ZERO, 160, 96),
        point_lights: vec![],
        textures: Vec::new(),
    };
    // No light direction reaches one object past the other (they are 3 m apart, lights high).
    let cone =
        |d: Vec3, l: f32| DistantLight { direction: d.normalize(), solid_angle: 1e-5, radiance: Vec3::splat(l * 1e5) };
    let lights = [
        cone(Vec3::new(0.0, 1.0, 0.3), 2.0),
        cone(Vec3::new(0.3, 0.6, 1.0), 1.5),
        cone(Vec3::new(-0.8, 0.7, 0.1), 1.0),
    ];
    let sky = EnvMap::from_fn(64, 32, |d| Vec3::new(0.3, 0.4, 0.6) * (0.5 + 0.5 * d.y) + Vec3::splat(0.05));
    let ambient = Sh9::project(&sky);
    let shade_lights: Vec<ShadeLight> = lights.iter().map(ShadeLight::from).collect();
    let background = Background::upload(&gpu, &sky).unwrap();
    let (image, positions) = gpu_render(
        &gpu,
        &scene,
        &ShadeParams {
            lights: &shade_lights,
            ambient: Some(&ambient),
            background: Some(&background),
            ..Default::default()
        },
    );
    let bvh = SceneBvh::new(&scene);
    let set = LightSet {
        lights: &lights,
        interleaved: &[],
        ambient: Some(ambient),
        ambient_map: None,
        shadow_ambient: false,
        background: Some(&sky),
    };
    let env = EnvLight::new(&sky);
    let reference = render(
        &scene,
        &bvh,
        Some(&env),
        &Integrator::Lights(set),
        &RenderSettings { spp: 16, seed: 7, ..RenderSettings::default() },
        &|_, _| {},
    );
    let (w, h) = (scene.camera.width as usize, scene.camera.height as usize);
    let pixels = interior(&reference.object_id, &reference.normal, &positions, w, h);
    for object in [0u32, 1, u32::MAX] {
        let ks: Vec<usize> = pixels.iter().copied().filter(|&k| reference.object_id[k] == object).collect();
        assert!(ks.len() > 200, "object {object}: only {} interior pixels", ks.len());
        let mut rel: Vec<f32> = ks
            .iter()
            .map(|&k| ((image[k] - reference.color[k]).abs() / (reference.color[k] + Vec3::splat(0.01))).max_element())
            .collect();
        rel.sort_by(f32::total_cmp);
        let mean = rel.iter().sum::<f32>() / rel.len() as f32;
        let p99 = rel[rel.len() * 99 / 100];
        assert!(mean < 0.01 && p99 < 0.05, "object {object}: relative error mean {mean}, 99th percentile {p99}");
    }
}

#[test]
fn point_light_over_a_lambertian_plane_matches_the_closed_form() {
    let gpu = gpu();
    let albedo = 0.6;
    let scene = Scene {
        name: "plane".into(),
        objects: vec![Object {
            name: "floor".into(),
            mesh: Mesh::quad(Vec3::new(-5.0, 0.0, 5.0), Vec3::new(10.0, 0.0, 0.0), Vec3::new(0.0, 0.0, -10.0), 1, 1),
            material: Material::lambert(albedo),
        }],
        camera: camera(Vec3::new(0.0, 4.0, 4.0), Vec3::ZERO, 96, 64),
        point_lights: vec![],
        textures: Vec::new(),
    };
    let light = PointLight::point(Vec3::new(0.5, 1.5, -0.5), Vec3::new(4.0, 3.0, 2.0));
    let lights = [ShadeLight::from(&light)];
    let (image, positions) = gpu_render(&gpu, &scene, &ShadeParams { lights: &lights, ..Default::default() });
    let mut checked = 0;
    for (k, p) in positions.iter().enumerate() {
        if p[3] < 0.0 {
            assert_eq!(image[k], Vec3::ZERO, "no background: misses are black");
            continue;
        }
        let x = Vec3::new(p[0], p[1], p[2]);
        let d = light.position - x;
        let want = light.intensity * (albedo / std::f32::consts::PI) * (d.y / d.length()) / d.length_squared();
        let err = ((image[k] - want).abs() / want).max_element();
        assert!(err < 1e-3, "pixel {k} at {x}: {} vs {want}", image[k]);
        checked += 1;
    }
    assert!(checked > 1000);
}

#[test]
fn no_adapter_is_an_error_naming_the_driver_package() {
    let err = Gpu::with_backends(Some(wgpu::Backends::empty())).err().expect("no backend, no adapter");
    assert!(err.to_string().contains("mesa-vulkan-drivers"), "{err}");
}

#[test]
fn adapter_is_described_and_sizes_beyond_the_limits_are_refused() {
    let gpu = gpu();
    assert!(!gpu.describe().is_empty());
    let too_big = gpu.limits.max_texture_dimension_2d + 1;
    let err = VisibilityLayers::new(&gpu, too_big, 4, 1).err().expect("refused");
    assert!(err.to_string().contains("exceeds the adapter's limit"), "{err}");
}

fn adapter(name: &str, device_type: wgpu::DeviceType, backend: wgpu::Backend) -> wgpu::AdapterInfo {
    wgpu::AdapterInfo { name: name.into(), ..wgpu::AdapterInfo::new(device_type, backend) }
}

#[test]
fn the_best_adapter_is_a_real_gpu_and_lavapipe_the_fallback() {
    use wgpu::{Backend, DeviceType};
    let lavapipe = adapter("llvmpipe (LLVM 15.0.6, 256 bits)", DeviceType::Cpu, Backend::Vulkan);
    let lavapipe_gl = adapter("llvmpipe (LLVM 15.0.6, 256 bits)", DeviceType::Cpu, Backend::Gl);
    let h200_gl = adapter("NVIDIA H200", DeviceType::DiscreteGpu, Backend::Gl);
    let h200 = adapter("NVIDIA H200", DeviceType::DiscreteGpu, Backend::Vulkan);
    let intel = adapter("Intel(R) UHD Graphics 770", DeviceType::IntegratedGpu, Backend::Vulkan);
    let infos = [lavapipe_gl, lavapipe, intel, h200_gl, h200];
    // discrete first, and on it the backend our passes are validated on
    assert_eq!(gpu::pick_adapter(&infos, None), Some(4));
    assert_eq!(gpu::pick_adapter(&infos[..3], None), Some(2), "integrated before CPU");
    assert_eq!(gpu::pick_adapter(&infos[..2], None), Some(1), "lavapipe on Vulkan before GL");
    let gl_only = [infos[3].clone(), infos[0].clone(), infos[1].clone()];
    assert_eq!(gpu::pick_adapter(&gl_only, None), Some(2), "OpenGL only when there is nothing else");
    assert_eq!(gpu::pick_adapter(&gl_only[..2], None), Some(0));
    let other_gl = adapter("llvmpipe", DeviceType::Other, Backend::Gl);
    assert_eq!(gpu::pick_adapter(&[other_gl, infos[1].clone()], None), Some(1));
    assert_eq!(gpu::pick_adapter(&infos, Some("cpu")), Some(1));
    assert_eq!(gpu::pick_adapter(&infos, Some("CPU")), Some(1), "names are case-insensitive");
    assert_eq!(gpu::pick_adapter(&infos, Some("intel")), Some(2));
    assert_eq!(gpu::pick_adapter(&infos, Some("h200")), Some(4));
    assert_eq!(gpu::pick_adapter(&infos, Some("llvmpipe")), Some(1));
    assert_eq!(gpu::pick_adapter(&infos, Some("radeon")), None);
    assert_eq!(gpu::pick_adapter(&[], None), None);
}

#[test]
fn an_unknown_adapter_name_is_one_line_listing_the_adapters_found() {
    let err = Gpu::with_adapter(Some("no-such-adapter-xyz")).err().expect("no adapter has that name");
    let text = err.to_string();
    assert!(!text.contains('\n'), "{text}");
    assert!(text.contains("no-such-adapter-xyz") && text.contains("found:"), "{text}");
    // every adapter present is listed by name
    for info in gpu::adapters(None) {
        assert!(text.contains(&info.name), "{} missing from {text}", info.name);
    }
}

#[test]
fn the_software_adapter_is_named_cpu() {
    // CI has lavapipe; elsewhere a machine may have only hardware adapters
    let has_cpu = gpu::adapters(None).iter().any(|i| i.device_type == wgpu::DeviceType::Cpu);
    match Gpu::with_adapter(Some("cpu")) {
        Ok(g) => assert_eq!(g.info.device_type, wgpu::DeviceType::Cpu, "{}", g.describe()),
        Err(e) => assert!(!has_cpu, "{e}"),
    }
}

#[test]
fn wide_cones_shade_as_the_ray_traced_cone() {
    // one cone light at a time on a Lambertian and a glossy sphere, apart (spheres cast no
    // shadow on themselves above their horizon): the shading pass's cone integral against the
    // ray tracer's cone samples
    let gpu = gpu();
    let glossy = Material::rgb(Vec3::new(0.6, 0.5, 0.4), Some(Ggx { roughness: 0.5, f0: Vec3::splat(0.04) }));
    let rough_metal = Material::rgb(Vec3::ZERO, Some(Ggx { roughness: 1.0, f0: Vec3::ONE }));
    let scene = Scene {
        name: "cones".into(),
        objects: vec![
            Object {
                name: "lambert".into(),
                mesh: Mesh::icosphere(Vec3::new(-1.3, 0.0, 0.0), 1.0, 4),
                material: Material::lambert(0.8),
            },
            Object { name: "glossy".into(), mesh: Mesh::icosphere(Vec3::new(1.3, 0.0, 0.0), 1.0, 4), material: glossy },
            // glTF's default material: white, metallic 1, roughness 1
            Object {
                name: "rough metal".into(),
                mesh: Mesh::icosphere(Vec3::new(3.9, 0.0, 0.0), 1.0, 4),
                material: rough_metal,
            },
        ],
        camera: camera(Vec3::new(1.3, 0.5, 7.5), Vec3::new(1.3, 0.0, 0.0), 192, 64),
        point_lights: vec![],
        textures: Vec::new(),
    };
    let bvh = SceneBvh::new(&scene);
    for degrees in [5.0f32, 20.0, 45.0] {
        let half = degrees.to_radians();
        let solid_angle = std::f32::consts::TAU * (1.0 - half.cos());
        let light = DistantLight {
            direction: Vec3::new(0.5, 0.7, 0.4).normalize(),
            solid_angle,
            radiance: Vec3::splat(1.0 / solid_angle),
        };
        let lights = [light];
        let shade_lights: Vec<ShadeLight> = lights.iter().map(ShadeLight::from).collect();
        let (image, positions) = gpu_render(&gpu, &scene, &ShadeParams { lights: &shade_lights, ..Default::default() });
        let set = LightSet {
            lights: &lights,
            interleaved: &[],
            ambient: None,
            ambient_map: None,
            shadow_ambient: false,
            background: None,
        };
        let reference = render(
            &scene,
            &bvh,
            None,
            &Integrator::Lights(set),
            &RenderSettings { spp: 256, seed: 3, ..RenderSettings::default() },
            &|_, _| {},
        );
        let (w, h) = (scene.camera.width as usize, scene.camera.height as usize);
        let pixels = interior(&reference.object_id, &reference.normal, &positions, w, h);
        // (object, bound on the mean error relative to the brightest pixel). Measured on
        // lavapipe at 5 / 20 / 45 degrees: Lambert 0.014 / 0.026 / 0.91 % (exact up to the
        // tessellation; shading the cone as directional was 2.2 % at 20 degrees); glossy 0.087 /
        // 1.2 / 5.1 % (the representative point, blended with the quadrature at 20 degrees, and
        // the coupled diffuse at the mean cosine); the rough metal 0.066 / 0.29 / 0.80 % by the
        // cone quadrature (3.5 / 14 % at 5 / 20 degrees by the representative point)
        for (object, bound) in [(0u32, 0.015f32), (1, 0.08), (2, 0.02)] {
            let ks: Vec<usize> = pixels.iter().copied().filter(|&k| reference.object_id[k] == object).collect();
            assert!(ks.len() > 500, "object {object}: {} pixels", ks.len());
            let peak = ks.iter().map(|&k| reference.color[k].max_element()).fold(0.0, f32::max);
            let mean = ks.iter().map(|&k| (image[k] - reference.color[k]).abs().max_element()).sum::<f32>()
                / (ks.len() as f32 * peak);
            assert!(mean < bound, "{degrees} deg, object {object}: mean error {mean} of the peak {peak}");
        }
    }
}

/// The G-buffer sees what primary rays through the pixel centres hit: a box standing on a 100 m
/// ground (depth spans 1e4), the camera at a 2 × 2 supersampled validate size. With standard Z
/// and a near plane at 1e-5 of the scene's reach, the ground 5 mm behind the box's front face
/// won the depth test along the face's bottom rows; reversed Z resolves it, and scaled scenes
/// rasterize the same.
#[test]
fn gbuffer_objects_are_the_primary_rays_hits_at_every_scale() {
    let gpu = gpu();
    for scale in [1e-3f32, 1.0, 1e3] {
        let scene = Scene {
            name: "box on a wide ground".into(),
            objects: vec![
                Object {
                    name: "ground".into(),
                    mesh: Mesh::quad(
                        Vec3::new(-50.0, 0.0, 50.0) * scale,
                        Vec3::new(100.0, 0.0, 0.0) * scale,
                        Vec3::new(0.0, 0.0, -100.0) * scale,
                        1,
                        1,
                    ),
                    material: Material::lambert(0.5),
                },
                Object {
                    name: "box".into(),
                    mesh: Mesh::cuboid(Vec3::new(0.5, 0.0, -0.5) * scale, Vec3::new(1.5, 2.0, 0.5) * scale),
                    material: Material::lambert(0.8),
                },
            ],
            camera: Camera {
                eye: Vec3::new(0.5, 2.5, 7.0) * scale,
                target: Vec3::new(0.0, 0.9, 0.0) * scale,
                up: Vec3::Y,
                hfov_degrees: 40.0,
                width: 1280,
                height: 960,
            },
            point_lights: vec![],
            textures: Vec::new(),
        };
        let geometry = SceneGeometry::upload(&gpu, &scene).unwrap();
        let gb = GBufferPass::new(&gpu).render(&gpu, &geometry, &scene.camera).unwrap();
        let positions = gb.read_positions(&gpu).unwrap();
        let bvh = SceneBvh::new(&scene);
        let rays = scene.camera.rays();
        let (w, h) = (scene.camera.width as usize, scene.camera.height as usize);
        let mut box_pixels = 0;
        let mismatched: Vec<(usize, usize)> = (0..w * h)
            .filter(|&k| {
                let (x, y) = (k % w, k / w);
                let (o, d) = rays.ray(x as f32 + 0.5, y as f32 + 0.5);
                let hit = bvh.intersect(o, d, f32::INFINITY).map_or(-1.0, |s| s.object as f32);
                box_pixels += usize::from(hit == 1.0);
                positions[k][3] != hit
            })
            .map(|k| (k % w, k / w))
            .collect();
        assert!(box_pixels > 50_000, "scale {scale}: the box covers {box_pixels} pixels");
        // a pixel centre within rounding of a silhouette may go either way: a few, not a row
        assert!(
            mismatched.len() <= 8,
            "scale {scale}: {} pixels differ, e.g. {:?}",
            mismatched.len(),
            &mismatched[..8.min(mismatched.len())]
        );
    }
}

/// Weber's law on a floor and a wall: a light 1 % of the sun is negligible where the sun lights
/// every receiver, but a dim light that alone lights the wall's far side is not; the ambient
/// counts towards what receivers already get; skipped lights share the 2 % (ten lights of
/// 1.5 % each: one is skipped); a light no receiver faces gives 0 everywhere, so
/// it is negligible too (render_visibility names the other reason first).
#[test]
fn weber_negligible_lights_are_below_two_percent_at_every_receiver() {
    let gpu = gpu();
    let scene = Scene {
        name: "floor and wall".into(),
        objects: vec![
            Object {
                name: "floor".into(),
                mesh: Mesh::quad(Vec3::new(-4.0, 0.0, 4.0), Vec3::new(8.0, 0.0, 0.0), Vec3::new(0.0, 0.0, -8.0), 1, 1),
                material: Material::lambert(0.5),
            },
            Object {
                name: "wall".into(),
                mesh: Mesh::cuboid(Vec3::new(-0.1, 0.0, -1.0), Vec3::new(0.1, 2.0, 1.0)),
                material: Material::lambert(0.5),
            },
        ],
        camera: camera(Vec3::new(3.0, 4.0, 6.0), Vec3::new(0.0, 0.5, 0.0), 128, 96),
        point_lights: vec![],
        textures: Vec::new(),
    };
    let geometry = SceneGeometry::upload(&gpu, &scene).unwrap();
    let gb = GBufferPass::new(&gpu).render(&gpu, &geometry, &scene.camera).unwrap();
    let points = gb.read_points(&gpu).unwrap();
    let receivers = gpu::Receivers::new(&gb, &points);
    let cone = |d: Vec3, e: f32, half: f32| ShadeLight::Distant {
        direction: d.normalize(),
        irradiance: Vec3::splat(e),
        half_angle: half,
    };
    // the sun overhead, slightly to -x: it lights the floor and the wall's top and -x side
    let lights = [
        cone(Vec3::new(-0.3, 1.0, 0.1), 100.0, 0.01),
        cone(Vec3::new(-0.3, 1.0, 0.1), 1.0, 0.2), // 1 % of the sun, where the sun shines
        cone(Vec3::new(1.0, 0.05, 0.0), 1.0, 0.05), // alone on the wall's +x side
        cone(Vec3::new(-0.3, -1.0, -0.3), 1e6, 0.05), // from below: no visible receiver faces it
    ];
    let negligible = gpu::weber_negligible(&receivers, &lights, None, gpu::WEBER_FRACTION);
    assert!(points.iter().filter(|(p, n)| p.is_finite() && n.x > 0.9).count() > 100, "the wall's +x side is seen");
    assert_eq!(negligible, [false, true, false, true]);
    // with a bright ambient, the lone light on the wall is under 2 % there too
    let bright = Sh9::project(&EnvMap::from_fn(32, 16, |_| Vec3::splat(100.0)));
    let negligible = gpu::weber_negligible(&receivers, &lights, Some(&bright), gpu::WEBER_FRACTION);
    assert_eq!(negligible, [false, true, true, true]);
    // ten lights of 1.5 % each where the sun shines: one fits under 2 %, not all ten
    let mut many = vec![cone(Vec3::new(-0.3, 1.0, 0.1), 100.0, 0.01)];
    many.extend((0..10).map(|_| cone(Vec3::new(-0.3, 1.0, 0.1), 1.5 * 100.0 / 85.0, 0.01)));
    let negligible = gpu::weber_negligible(&receivers, &many, None, gpu::WEBER_FRACTION);
    assert_eq!(negligible.iter().filter(|n| **n).count(), 1, "{negligible:?}");
    // non-finite light marks nothing negligible
    let mut huge = lights;
    huge[0] = cone(Vec3::Y, f32::INFINITY, 0.01);
    assert!(gpu::weber_negligible(&receivers, &huge, None, gpu::WEBER_FRACTION).iter().all(|n| !n));
}

/// A device the caller made (as a winit surface or Bevy hands one over) renders as the
/// toolkit's own, and the counters see every submission, wait, readback and pipeline.
#[test]
fn a_callers_device_renders_the_same_and_is_counted() {
    let scene = Scene {
        name: "plane".into(),
        objects: vec![Object {
            name: "plane".into(),
            mesh: Mesh::quad(Vec3::new(-2.0, 0.0, -2.0), Vec3::X * 4.0, Vec3::Z * 4.0, 1, 1),
            material: Material::lambert(0.5),
        }],
        camera: camera(Vec3::new(0.0, 2.0, 3.0), Vec3::ZERO, 32, 24),
        point_lights: vec![],
        textures: Vec::new(),
    };
    let light = [ShadeLight::Distant { direction: Vec3::Y, irradiance: Vec3::ONE, half_angle: 0.0 }];
    let params = ShadeParams { lights: &light, ..ShadeParams::default() };
    let ours = gpu();
    let (want, _) = gpu_render(&ours, &scene, &params);
    // the caller's own instance, adapter and device, on the adapter ours chose
    let instance = wgpu::Instance::new(wgpu::InstanceDescriptor::new_without_display_handle_from_env());
    let adapters = pollster::block_on(instance.enumerate_adapters(wgpu::Backends::PRIMARY));
    let adapter = adapters.into_iter().find(|a| a.get_info() == ours.info).expect("the same adapter");
    // the adapter's limits (WebGPU's defaults: benches/tests/default_limits.rs)
    let descriptor = wgpu::DeviceDescriptor { required_limits: adapter.limits(), ..Default::default() };
    let (device, queue) = pollster::block_on(adapter.request_device(&descriptor)).expect("a device");
    let theirs = Gpu::from_device(device, queue, adapter.get_info());
    assert_eq!(theirs.limits, adapter.limits(), "the caller's limits are kept");
    assert!(!theirs.features.contains(wgpu::Features::CLIP_DISTANCES), "only the features the caller enabled");
    assert_eq!(theirs.counters(), gpu::GpuCounters::default());
    let (got, _) = gpu_render(&theirs, &scene, &params);
    assert_eq!(got, want, "the same image on the caller's device");
    let c = theirs.counters();
    // G-buffer, visibility clear, shading, readbacks (image, positions): each submitted and waited
    assert!(c.submits >= 4 && c.waits >= c.submits, "{c:?}");
    assert!(c.pipelines >= 2, "G-buffer and shading: {c:?}");
    assert_eq!(c.readback_bytes % 256, 0, "whole padded rows: {c:?}");
    assert!(c.readback_bytes >= 2 * 32 * 24 * 16, "the image and the positions: {c:?}");
}
