//! Textured materials on the GPU against `ref-tracer`: a quad whose base colour, metallic-
//! roughness and emissive textures are sampled per pixel (bilinear and nearest, mirrored,
//! clamped and repeated texture coordinates past [0, 1]), shaded by one distant light without
//! shadows; and a one-sided quad seen from behind, which both renderers cull.

use glam::{Vec2, Vec3};
use gpu::{GBufferPass, Gpu, SceneGeometry, ShadeLight, ShadeParams, ShadingPass, VisibilityLayers};
use ref_tracer::{Integrator, LightSet, RenderSettings, SceneBvh, render};
use scene::{Camera, DistantLight, Filter, Maps, Material, Mesh, Object, Scene, Texture, Wrap};

fn gpu() -> Gpu {
    Gpu::new().unwrap_or_else(|e| panic!("{e}"))
}

fn texture(wrap: [Wrap; 2], filter: Filter, f: impl Fn(u32, u32) -> [u8; 4]) -> Texture {
    Texture { width: 4, height: 4, texels: (0..16).map(|k| f(k % 4, k / 4)).collect(), wrap, filter }
}

/// A 2 x 2 quad at z = `z` facing +z (or -z when `away`), its uvs running over [-0.5, 1.5].
fn quad(z: f32, half: f32, away: bool) -> Mesh {
    let positions = [(-1.0, -1.0), (1.0, -1.0), (1.0, 1.0), (-1.0, 1.0)].map(|(x, y)| Vec3::new(x * half, y * half, z));
    let uvs = [(-0.5, 1.5), (1.5, 1.5), (1.5, -0.5), (-0.5, -0.5)].map(|(u, v)| Vec2::new(u, v));
    let indices = if away { vec![[0, 2, 1], [0, 3, 2]] } else { vec![[0, 1, 2], [0, 2, 3]] };
    Mesh { positions: positions.to_vec(), normals: None, indices, uvs: Some(uvs.to_vec()) }
}

fn textured_scene(specular: bool) -> Scene {
    let maps = Maps {
        base_color: Vec3::new(0.9, 0.8, 0.7),
        metallic: 1.0,
        roughness: 1.0,
        emissive: Vec3::new(0.5, 0.3, 0.2),
        base_color_texture: Some(0),
        metallic_roughness_texture: Some(1),
        emissive_texture: Some(2),
        specular,
    };
    let material = Material { maps: Some(maps), double_sided: false, ..Material::lambert(0.5) };
    let base = texture([Wrap::Mirror, Wrap::Clamp], Filter::Linear, |x, y| {
        [(x * 70 + 20) as u8, (y * 70 + 20) as u8, (230 - x * 50) as u8, 255]
    });
    let metal_rough = texture([Wrap::Repeat; 2], Filter::Nearest, |x, y| [0, (60 + 60 * y) as u8, (x * 80) as u8, 255]);
    let emissive =
        texture([Wrap::Clamp, Wrap::Mirror], Filter::Linear, |x, y| [(255 - 60 * y) as u8, 40, (x * 80) as u8, 255]);
    Scene {
        name: "textured quad".into(),
        objects: vec![Object { name: "quad".into(), mesh: quad(0.0, 1.0, false), material }],
        camera: Camera {
            eye: Vec3::new(0.2, 0.1, 3.0),
            target: Vec3::ZERO,
            up: Vec3::Y,
            hfov_degrees: 45.0,
            width: 96,
            height: 96,
        },
        point_lights: vec![],
        textures: vec![base, metal_rough, emissive],
    }
}

#[test]
fn textured_material_shades_as_ref_tracer() {
    shades_as_ref_tracer(true);
}

/// A textured material without its specular layer (a backdrop's ground): the base colour
/// alone, Lambertian, on both renderers.
#[test]
fn lambertian_textured_material_shades_as_ref_tracer() {
    shades_as_ref_tracer(false);
}

fn shades_as_ref_tracer(specular: bool) {
    let gpu = gpu();
    let scene = textured_scene(specular);
    let light =
        DistantLight { direction: Vec3::new(0.3, 0.4, 1.0).normalize(), solid_angle: 1e-5, radiance: Vec3::splat(2e5) };
    let lights = [light];
    let shade: Vec<ShadeLight> = lights.iter().map(ShadeLight::from).collect();
    let geometry = SceneGeometry::upload(&gpu, &scene).unwrap();
    assert_eq!(geometry.texture_halvings, 0, "three 4 x 4 textures fit");
    let gb = GBufferPass::new(&gpu).render(&gpu, &geometry, &scene.camera).unwrap();
    let vis = VisibilityLayers::new(&gpu, 96, 96, 1).unwrap();
    let params = ShadeParams { lights: &shade, ..Default::default() };
    let image = ShadingPass::new(&gpu).unwrap().render(&gpu, &geometry, &gb, &params, &vis).unwrap();
    let bvh = SceneBvh::new(&scene);
    let set = LightSet::new(&lights);
    let settings = RenderSettings { spp: 64, seed: 5, ..RenderSettings::default() };
    let reference = render(&scene, &bvh, None, &Integrator::Lights(set), &settings, &|_, _| {});
    let positions = gb.read_positions(&gpu).unwrap();
    // the nearest-filtered texel under each corner of a pixel: where they differ, the
    // reference's mean over the pixel and the GPU's centre sample part
    let nearest = |x: f32, y: f32| {
        let (o, d) = scene.camera.ray(x, y);
        bvh.intersect_camera(o, d).map(|h| (h.uv * 4.0).floor())
    };
    let one_texel = |x: usize, y: usize| {
        let (x, y) = (x as f32, y as f32);
        let c = nearest(x, y);
        [(1.0, 0.0), (0.0, 1.0), (1.0, 1.0)].iter().all(|&(dx, dy)| nearest(x + dx, y + dy) == c)
    };
    // pixels of the quad away from its edge (the mean over a pixel and its centre part there)
    let w = 96usize;
    let inside: Vec<usize> = (0..w * w)
        .filter(|&k| {
            let (x, y) = (k % w, k / w);
            x > 0
                && y > 0
                && x + 1 < w
                && y + 1 < w
                && {
                    let around = [k - 1, k + 1, k - w, k + w, k - w - 1, k + w + 1, k - w + 1, k + w - 1];
                    around.iter().chain([&k]).all(|&j| reference.object_id[j] == 0 && positions[j][3] == 0.0)
                }
                && one_texel(x, y)
        })
        .collect();
    assert!(inside.len() > 2000, "{} pixels", inside.len());
    let peak = inside.iter().map(|&k| reference.color[k].max_element()).fold(0.0, f32::max);
    let errors: Vec<f32> = inside.iter().map(|&k| (image[k] - reference.color[k]).abs().max_element() / peak).collect();
    let mean = errors.iter().sum::<f32>() / errors.len() as f32;
    let within = errors.iter().filter(|&&e| e < 0.01).count() as f32 / errors.len() as f32;
    assert!(mean < 0.005 && within > 0.98, "mean error {mean} of the peak {peak}; {within} of the pixels within 1 %");
    // the textures vary the image: not one flat colour the factors alone would give
    let spread = inside.iter().map(|&k| image[k].x).fold(0.0, f32::max)
        - inside.iter().map(|&k| image[k].x).fold(f32::MAX, f32::min);
    assert!(spread > 0.2 * peak, "spread {spread}");
}

#[test]
fn one_sided_back_faces_are_culled_as_ref_tracer_culls_them() {
    let gpu = gpu();
    let mut scene = textured_scene(true);
    // in front of the textured quad, turned away from the camera: culled, so the quad behind shows
    let blocker = Object {
        name: "blocker".into(),
        mesh: quad(0.8, 0.4, true),
        material: Material { double_sided: false, ..Material::lambert(0.5) },
    };
    scene.objects.push(blocker.clone());
    let geometry = SceneGeometry::upload(&gpu, &scene).unwrap();
    let positions =
        GBufferPass::new(&gpu).render(&gpu, &geometry, &scene.camera).unwrap().read_positions(&gpu).unwrap();
    let bvh = SceneBvh::new(&scene);
    let mut culled_pixels = 0;
    for (k, p) in positions.iter().enumerate() {
        let (o, d) = scene.camera.ray((k % 96) as f32 + 0.5, (k / 96) as f32 + 0.5);
        let seen = bvh.intersect_camera(o, d).map_or(-1.0, |h| h.object as f32);
        let any = bvh.intersect(o, d, f32::INFINITY).map_or(-1.0, |h| h.object as f32);
        culled_pixels += usize::from(any == 1.0 && seen == 0.0);
        // a pixel on an edge may go either way in either renderer
        if p[3] != seen {
            let (x, y) = (k % 96, k / 96);
            assert!(
                [(0i32, 1i32), (1, 0), (0, -1), (-1, 0)].iter().any(|(dx, dy)| {
                    let (nx, ny) = (x as i32 + dx, y as i32 + dy);
                    (0..96).contains(&nx)
                        && (0..96).contains(&ny)
                        && positions[ny as usize * 96 + nx as usize][3] == seen
                }),
                "pixel {x},{y}: the G-buffer sees object {} where the camera ray sees {seen}",
                p[3]
            );
        }
    }
    assert!(culled_pixels > 300, "the blocker covers {culled_pixels} pixels, culled in both");
    // turned double-sided, it is drawn
    scene.objects[1].material.double_sided = true;
    let geometry = SceneGeometry::upload(&gpu, &scene).unwrap();
    let positions =
        GBufferPass::new(&gpu).render(&gpu, &geometry, &scene.camera).unwrap().read_positions(&gpu).unwrap();
    let drawn = positions.iter().filter(|p| p[3] == 1.0).count();
    assert!(drawn + 40 > culled_pixels && drawn > 300, "{drawn} pixels of the double-sided blocker");
}
