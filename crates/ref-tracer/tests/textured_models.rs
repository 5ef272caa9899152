//! Textured glTF models written here, whose every pixel has a closed-form answer: a unit quad
//! facing the camera with a 4 x 4 texture of known texels, sampled nearest, so each pixel whose
//! footprint stays inside one texel must show that texel: as the albedo (base colour
//! texture), as metallic and roughness (their texture), as the radiance a camera sees in the
//! dark (emissive texture), and not at all from behind when the material is one-sided. The
//! expected values come from the texels and the sRGB formula here, not from the importer.

use envmap_sphere::EnvMap;
use glam::{Vec2, Vec3};
use ref_tracer::{EnvLight, Integrator, RenderSettings, SceneBvh, Strategy};
use scene::import::{GltfOptions, load_gltf, load_gltf_from_bytes};
use serde_json::{Value, json};
use std::path::Path;

const SIDE: u32 = 4;

fn texel(x: u32, y: u32) -> [u8; 4] {
    [(x * 60 + 10) as u8, (y * 60 + 10) as u8, ((x + y) * 20) as u8, 255]
}

fn png() -> Vec<u8> {
    let image = image::RgbaImage::from_fn(SIDE, SIDE, |x, y| image::Rgba(texel(x, y)));
    let mut out = std::io::Cursor::new(Vec::new());
    image.write_to(&mut out, image::ImageFormat::Png).expect("PNG");
    out.into_inner()
}

/// The sRGB curve, written out here.
fn linear(c: u8) -> f32 {
    let c = f32::from(c) / 255.0;
    if c <= 0.04045 { c / 12.92 } else { ((c + 0.055) / 1.055).powf(2.4) }
}

/// A quad over [-1, 1]^2 at z = 0 facing +z (or -z when `away`), uv (0, 0) at its top left, a
/// camera 2.5 in front looking at it, `material` as the only material; the image in the GLB's
/// buffer (`image: None`) or at the URI given.
fn quad(material: &Value, away: bool, image: Option<&str>) -> (Value, Vec<u8>) {
    let positions: [[f32; 3]; 4] = [[-1.0, -1.0, 0.0], [1.0, -1.0, 0.0], [1.0, 1.0, 0.0], [-1.0, 1.0, 0.0]];
    let uvs: [[f32; 2]; 4] = [[0.0, 1.0], [1.0, 1.0], [1.0, 0.0], [0.0, 0.0]];
    let indices: [u16; 6] = if away { [0, 2, 1, 0, 3, 2] } else { [0, 1, 2, 0, 2, 3] };
    let mut bin: Vec<u8> = positions.iter().flatten().flat_map(|f| f.to_le_bytes()).collect();
    bin.extend(uvs.iter().flatten().flat_map(|f| f.to_le_bytes()));
    bin.extend(indices.iter().flat_map(|i| i.to_le_bytes()));
    let mut views = vec![
        json!({"buffer": 0, "byteOffset": 0, "byteLength": 48}),
        json!({"buffer": 0, "byteOffset": 48, "byteLength": 32}),
        json!({"buffer": 0, "byteOffset": 80, "byteLength": 12}),
    ];
    let images = match image {
        Some(uri) => json!([{"uri": uri}]),
        None => {
            let png = png();
            views.push(json!({"buffer": 0, "byteOffset": 92, "byteLength": png.len()}));
            bin.extend(png);
            json!([{"bufferView": 3, "mimeType": "image/png"}])
        }
    };
    while !bin.len().is_multiple_of(4) {
        bin.push(0);
    }
    let doc = json!({
        "asset": {"version": "2.0"},
        "extensionsUsed": ["KHR_materials_emissive_strength"],
        "scene": 0,
        "scenes": [{"nodes": [0, 1]}],
        "nodes": [{"mesh": 0}, {"camera": 0, "translation": [0.0, 0.0, 2.5]}],
        "cameras": [{"type": "perspective", "perspective": {"yfov": 0.9, "aspectRatio": 1.0, "znear": 0.01}}],
        "meshes": [{"primitives": [{"attributes": {"POSITION": 0, "TEXCOORD_0": 1}, "indices": 2, "material": 0}]}],
        "materials": [material],
        "textures": [{"source": 0, "sampler": 0}],
        "samplers": [{"magFilter": 9728, "minFilter": 9728}],
        "images": images,
        "accessors": [
            {"bufferView": 0, "componentType": 5126, "count": 4, "type": "VEC3",
             "min": [-1.0, -1.0, 0.0], "max": [1.0, 1.0, 0.0]},
            {"bufferView": 1, "componentType": 5126, "count": 4, "type": "VEC2"},
            {"bufferView": 2, "componentType": 5123, "count": 6, "type": "SCALAR"},
        ],
        "bufferViews": views,
        "buffers": [{"byteLength": bin.len()}],
    });
    (doc, bin)
}

fn glb(material: &Value, away: bool) -> scene::Scene {
    let (doc, bin) = quad(material, away, None);
    let bytes = scene::glb_bytes(&serde_json::to_vec(&doc).unwrap(), &bin).expect("a GLB");
    let options = GltfOptions { size: (48, 48), ..GltfOptions::default() };
    load_gltf_from_bytes(&bytes, Path::new("quad.glb"), &options).expect("the quad imports").scene
}

/// Per pixel, the texel every point of the pixel's footprint falls in (`None`: the footprint
/// leaves the quad or straddles texels).
fn texel_under(scene: &scene::Scene, px: u32, py: u32) -> Option<(u32, u32)> {
    let corners = [(0.0, 0.0), (1.0, 0.0), (0.0, 1.0), (1.0, 1.0)].map(|(dx, dy)| {
        let (o, d) = scene.camera.ray(px as f32 + dx, py as f32 + dy);
        let p = o + d * (-o.z / d.z);
        let uv = Vec2::new((p.x + 1.0) * 0.5, (1.0 - p.y) * 0.5) * SIDE as f32;
        (uv.x.floor(), uv.y.floor())
    });
    let (x, y) = corners[0];
    (corners.iter().all(|&c| c == (x, y)) && (0.0..SIDE as f32).contains(&x) && (0.0..SIDE as f32).contains(&y))
        .then_some((x as u32, y as u32))
}

fn render(scene: &scene::Scene, spp: u32) -> ref_tracer::Render {
    let bvh = SceneBvh::new(scene);
    let dark = EnvMap::constant(8, 4, Vec3::ZERO);
    let env = EnvLight::new(&dark);
    let settings = RenderSettings { spp, aovs: true, ..RenderSettings::default() };
    ref_tracer::render(scene, &bvh, Some(&env), &Integrator::EnvDirect(Strategy::Mis), &settings, &|_, _| {})
}

fn pixels(scene: &scene::Scene) -> Vec<(usize, (u32, u32))> {
    let w = scene.camera.width;
    let out: Vec<_> = (0..w * scene.camera.height)
        .filter_map(|k| texel_under(scene, k % w, k / w).map(|t| (k as usize, t)))
        .collect();
    assert!(out.len() > 400, "the quad fills much of the view: {} pixels inside one texel", out.len());
    out
}

#[test]
fn base_colour_texture_is_the_albedo_at_every_pixel() {
    let material = json!({"pbrMetallicRoughness": {"baseColorTexture": {"index": 0}, "metallicFactor": 0.0}});
    let scene = glb(&material, false);
    assert_eq!(scene.textures.len(), 1);
    let t = &scene.textures[0];
    assert_eq!((t.width, t.height, t.filter), (SIDE, SIDE, scene::Filter::Nearest));
    assert!((0..SIDE * SIDE).all(|k| t.texels[k as usize] == texel(k % SIDE, k / SIDE)), "texels as written");
    let r = render(&scene, 1);
    for (k, (x, y)) in pixels(&scene) {
        let c = texel(x, y);
        let want = Vec3::new(linear(c[0]), linear(c[1]), linear(c[2]));
        assert!((r.albedo[k] - want).abs().max_element() < 1e-5, "pixel {k}: {} for texel {x},{y} {want}", r.albedo[k]);
    }
}

#[test]
fn metallic_roughness_texture_scales_metal_and_roughness() {
    let base = Vec3::new(0.8, 0.6, 0.4);
    let material = json!({"pbrMetallicRoughness": {"baseColorFactor": [0.8, 0.6, 0.4, 1.0],
        "metallicRoughnessTexture": {"index": 0}, "metallicFactor": 1.0, "roughnessFactor": 1.0}});
    let scene = glb(&material, false);
    let bvh = SceneBvh::new(&scene);
    for (k, (x, y)) in pixels(&scene) {
        let (o, d) = scene.camera.ray((k as u32 % 48) as f32 + 0.5, (k as u32 / 48) as f32 + 0.5);
        let sp = bvh.intersect_camera(o, d).expect("the quad");
        let m = bvh.material_at(&sp);
        let c = texel(x, y);
        // linear data: B metallic, G roughness
        let (metal, rough) = (f32::from(c[2]) / 255.0, f32::from(c[1]) / 255.0);
        assert!((m.albedo - base * (1.0 - metal)).abs().max_element() < 1e-5, "albedo at {x},{y}");
        let g = m.specular.expect("a GGX layer");
        assert!((g.roughness - rough.max(scene::MIN_ROUGHNESS)).abs() < 1e-5, "roughness at {x},{y}");
        assert!((g.f0 - Vec3::splat(0.04).lerp(base, metal)).abs().max_element() < 1e-5, "F0 at {x},{y}");
    }
}

#[test]
fn emissive_texture_is_what_the_camera_sees_in_the_dark() {
    let material = json!({"pbrMetallicRoughness": {"baseColorFactor": [0.0, 0.0, 0.0, 1.0], "metallicFactor": 0.0},
        "emissiveFactor": [1.0, 0.5, 0.25], "emissiveTexture": {"index": 0},
        "extensions": {"KHR_materials_emissive_strength": {"emissiveStrength": 4.0}}});
    let scene = glb(&material, false);
    let r = render(&scene, 4);
    let factor = Vec3::new(4.0, 2.0, 1.0);
    for (k, (x, y)) in pixels(&scene) {
        let c = texel(x, y);
        let want = factor * Vec3::new(linear(c[0]), linear(c[1]), linear(c[2]));
        assert!((r.color[k] - want).abs().max_element() < 1e-4 * want.max_element(), "pixel {k}: {}", r.color[k]);
    }
    // the dark map lights nothing: the background stays black
    let w = scene.camera.width as usize;
    assert_eq!(r.color[0], Vec3::ZERO);
    assert_eq!(r.color[w - 1], Vec3::ZERO);
}

#[test]
fn one_sided_back_faces_are_culled_for_the_camera() {
    let one_sided = json!({"pbrMetallicRoughness": {"baseColorTexture": {"index": 0}}});
    let two_sided = json!({"pbrMetallicRoughness": {"baseColorTexture": {"index": 0}}, "doubleSided": true});
    let seen = |m: &Value, away: bool| render(&glb(m, away), 1).depth.iter().filter(|d| d.is_finite()).count();
    let front = seen(&one_sided, false);
    assert!(front > 400, "the front is seen: {front} pixels");
    assert_eq!(seen(&one_sided, true), 0, "the back of a one-sided quad is not seen");
    assert_eq!(seen(&two_sided, true), front, "a double-sided quad is seen from behind as from the front");
}

#[test]
fn gltf_with_an_image_file_reads_as_the_glb() {
    let dir = std::env::temp_dir().join(format!("envshadow-textured-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let material = json!({"pbrMetallicRoughness": {"baseColorTexture": {"index": 0}}});
    let (mut doc, bin) = quad(&material, false, Some("texels.png"));
    doc["buffers"][0]["uri"] = json!("quad.bin");
    std::fs::write(dir.join("quad.bin"), &bin).unwrap();
    std::fs::write(dir.join("quad.gltf"), serde_json::to_vec(&doc).unwrap()).unwrap();
    let options = GltfOptions { size: (48, 48), ..GltfOptions::default() };
    // the image file is missing: one line naming the model and the image
    let err = load_gltf(&dir.join("quad.gltf"), &options).expect_err("no texels.png yet").to_string();
    assert!(err.contains("quad.gltf") && err.contains("texels.png") && !err.contains('\n'), "{err}");
    std::fs::write(dir.join("texels.png"), png()).unwrap();
    let from_file = load_gltf(&dir.join("quad.gltf"), &options).expect("imports").scene;
    let mut from_glb = glb(&material, false);
    from_glb.name = from_file.name.clone();
    assert_eq!(from_file, from_glb);
    // not an image glTF allows
    std::fs::write(dir.join("texels.png"), b"GIF89a\x01\x00\x01\x00\x00\x00\x00;").unwrap();
    let err = load_gltf(&dir.join("quad.gltf"), &options).expect_err("a GIF").to_string();
    assert!(err.contains("quad.gltf") && err.contains("image 0") && !err.contains('\n'), "{err}");
    // wider than a texture may be: refused from its header, before decoding
    let wide = image::RgbaImage::new(scene::import::MAX_TEXTURE_SIDE + 1, 1);
    wide.save_with_format(dir.join("texels.png"), image::ImageFormat::Png).unwrap();
    let err = load_gltf(&dir.join("quad.gltf"), &options).expect_err("too wide").to_string();
    assert!(err.contains("more than the 16384 a side"), "{err}");
    std::fs::remove_dir_all(&dir).ok();
}

/// What `gltf::Image::source` (1.4.1) panics on, found by `cargo xtask fuzz`: an image with
/// neither a URI nor a buffer view, and one in a buffer view without a MIME type.
#[test]
fn images_the_gltf_crate_would_panic_on_are_read_or_refused() {
    let material = json!({"pbrMetallicRoughness": {"baseColorTexture": {"index": 0}}});
    let options = GltfOptions { size: (48, 48), ..GltfOptions::default() };
    let (mut doc, bin) = quad(&material, false, None);
    doc["images"][0].as_object_mut().unwrap().remove("mimeType");
    let bytes = scene::glb_bytes(&serde_json::to_vec(&doc).unwrap(), &bin).unwrap();
    let scene = load_gltf_from_bytes(&bytes, Path::new("quad.glb"), &options).expect("no MIME type: the bytes say PNG");
    assert_eq!(scene.scene.textures[0].width, SIDE);
    doc["images"] = json!([{}]);
    let bytes = scene::glb_bytes(&serde_json::to_vec(&doc).unwrap(), &bin).unwrap();
    let err = load_gltf_from_bytes(&bytes, Path::new("quad.glb"), &options).expect_err("no image").to_string();
    assert!(err.contains("quad.glb") && err.contains("neither a URI nor a buffer view"), "{err}");
}
