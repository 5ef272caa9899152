//! Each built-in scene written as glTF (`.gltf` + `.bin`, and `.glb`) and read back is the same
//! scene (object for object, the camera and the lights) and renders the same image, bit for bit.

use envmap_sphere::EnvMap;
use glam::Vec3;
use ref_tracer::{EnvLight, Integrator, RenderSettings, SceneBvh, render};
use scene::import::{GltfOptions, load_gltf};
use scene::{BUILTIN_SCENES, Scene};

fn sky_and_sun() -> EnvMap {
    let sun = Vec3::new(0.4, 0.8, 0.3).normalize();
    EnvMap::from_texels(128, 64, |i, j| {
        let d = envmap_sphere::texel_centre_dir(i, j, 128, 64);
        let sky = if d.y > 0.0 { Vec3::new(0.6, 0.8, 1.0) } else { Vec3::splat(0.3) };
        if d.dot(sun) > 4f32.to_radians().cos() { Vec3::splat(400.0) } else { sky }
    })
}

fn image_bits(scene: &Scene, map: &EnvMap) -> Vec<u32> {
    let bvh = SceneBvh::new(scene);
    let env = EnvLight::new(map);
    let settings = RenderSettings { spp: 2, seed: 7, ..RenderSettings::default() };
    let r = render(scene, &bvh, Some(&env), &Integrator::Path { max_depth: 2 }, &settings, &|_, _| {});
    r.color.iter().flat_map(|c| c.to_array()).map(f32::to_bits).collect()
}

#[test]
fn every_builtin_round_trips_through_gltf_and_renders_bit_for_bit() {
    let dir = std::env::temp_dir().join(format!("envshadow-gltf-round-trip-{}", std::process::id()));
    std::fs::create_dir_all(&dir).expect("temp dir");
    let map = sky_and_sun();
    for name in BUILTIN_SCENES {
        let mut built = Scene::builtin(name).expect("built-in");
        (built.camera.width, built.camera.height) = (40, 30);
        let expected = image_bits(&built, &map);
        for ext in ["gltf", "glb"] {
            let path = dir.join(format!("{name}.{ext}"));
            built.write_gltf(&path).expect("writes");
            let import = load_gltf(&path, &GltfOptions { size: (40, 30), ..GltfOptions::default() })
                .unwrap_or_else(|e| panic!("{e}"));
            assert!(import.warnings.is_empty(), "{name}.{ext}: {:?}", import.warnings);
            let back = import.scene;
            assert_eq!(back.name, built.name, "{ext}");
            assert_eq!(back.camera, built.camera, "{name}.{ext}");
            assert_eq!(back.point_lights, built.point_lights, "{name}.{ext}");
            assert_eq!(back.objects.len(), built.objects.len(), "{name}.{ext}");
            for (b, o) in back.objects.iter().zip(&built.objects) {
                assert_eq!(b, o, "{name}.{ext}: object {}", o.name);
            }
            assert!(image_bits(&back, &map) == expected, "{name}.{ext}: the image differs");
        }
    }
}
