//! Small valid files to mutate, made here so the harness needs nothing beside the repository:
//! Radiance `.hdr` (flat and run-length encoded), OpenEXR (every compression the loader meets,
//! RGB, RGBA and f16 channels), `lights.json` as `extract` writes it, and glTF models (`.gltf`
//! with an embedded buffer and `.glb`: built-in scenes as `Scene::to_gltf` writes them, and one
//! written here with u8 and u16 indices, a strip, points, a node hierarchy and a camera); and the
//! library targets that load them as the commands do.

use crate::{FUZZ_MAX_PIXELS, Format, Target};
use envmap_sphere::{EnvMap, LoadOptions, NegativePolicy};
use glam::Vec3;
use std::io::Cursor;

/// A small map with a bright spot, some zeros and a gradient: `w` x `h`.
fn pixels(w: usize, h: usize) -> Vec<Vec3> {
    (0..w * h)
        .map(|k| {
            let (i, j) = (k % w, k / w);
            if i == w / 3 && j == h / 4 {
                Vec3::new(900.0, 800.0, 700.0)
            } else if (i + j) % 7 == 0 {
                Vec3::ZERO
            } else {
                Vec3::new(i as f32 / w as f32, j as f32 / h as f32, 0.25)
            }
        })
        .collect()
}

/// Radiance RGBE of one pixel.
fn rgbe(c: Vec3) -> [u8; 4] {
    let m = c.max_element();
    if m < 1e-32 {
        return [0; 4];
    }
    let e = m.log2().floor() as i32 + 1;
    let scale = 256.0 / 2f32.powi(e);
    [(c.x * scale) as u8, (c.y * scale) as u8, (c.z * scale) as u8, (e + 128).clamp(0, 255) as u8]
}

/// `.hdr` files: flat 16 x 8, run-length encoded 16 x 8 and 64 x 32 (the encoder's), and a flat
/// one with extra header lines.
#[must_use]
pub fn hdr() -> Vec<Vec<u8>> {
    let mut out = Vec::new();
    for (w, h, header) in [
        (16, 8, "#?RADIANCE\nFORMAT=32-bit_rle_rgbe\n\n-Y 8 +X 16\n"),
        (16, 8, "#?RADIANCE\n# made by the fuzzer\nEXPOSURE=1.0\nFORMAT=32-bit_rle_rgbe\n\n-Y 8 +X 16\n"),
    ] {
        let mut bytes = header.as_bytes().to_vec();
        for p in pixels(w, h) {
            bytes.extend(rgbe(p));
        }
        out.push(bytes);
    }
    for (w, h) in [(16usize, 8usize), (64, 32)] {
        let rgb: Vec<image::Rgb<f32>> = pixels(w, h).iter().map(|p| image::Rgb(p.to_array())).collect();
        let mut bytes = Vec::new();
        if image::codecs::hdr::HdrEncoder::new(&mut bytes).encode(&rgb, w, h).is_ok() {
            out.push(bytes);
        }
    }
    out
}

/// `.exr` files: 16 x 8 RGB f32 with no, RLE, ZIP, PIZ and DWAB compression, RGBA f16, and a
/// Y-only image (no colour channels).
#[must_use]
pub fn exr() -> Vec<Vec<u8>> {
    use exr::prelude::*;
    let (w, h) = (16usize, 8usize);
    let px = pixels(w, h);
    let mut out = Vec::new();
    for compression in
        [Compression::Uncompressed, Compression::RLE, Compression::ZIP16, Compression::PIZ, Compression::DWAB(None)]
    {
        let channels = SpecificChannels::rgb(|p: Vec2<usize>| {
            let c = px[p.y() * w + p.x()];
            (c.x, c.y, c.z)
        });
        let encoding = Encoding { compression, ..Encoding::UNCOMPRESSED };
        let layer = Layer::new((w, h), LayerAttributes::named("rgb"), encoding, channels);
        let mut bytes = Vec::new();
        if Image::from_layer(layer).write().to_buffered(Cursor::new(&mut bytes)).is_ok() {
            out.push(bytes);
        }
    }
    let rgba = SpecificChannels::rgba(|p: Vec2<usize>| {
        let c = px[p.y() * w + p.x()];
        (f16::from_f32(c.x), f16::from_f32(c.y), f16::from_f32(c.z), f16::from_f32(1.0))
    });
    let layer = Layer::new((w, h), LayerAttributes::named("rgba"), Encoding::UNCOMPRESSED, rgba);
    let mut bytes = Vec::new();
    if Image::from_layer(layer).write().to_buffered(Cursor::new(&mut bytes)).is_ok() {
        out.push(bytes);
    }
    let gray = AnyChannel::new("Y", FlatSamples::F32(vec![0.5; w * h]));
    let layer = Layer::new(
        (w, h),
        LayerAttributes::named("gray"),
        Encoding::UNCOMPRESSED,
        AnyChannels::sort(SmallVec::from_vec(vec![gray])),
    );
    let mut bytes = Vec::new();
    if Image::from_layer(layer).write().to_buffered(Cursor::new(&mut bytes)).is_ok() {
        out.push(bytes);
    }
    out
}

/// `lights.json` files as `extract` writes them (two methods, with interleaved sets), and a
/// minimal one.
#[must_use]
pub fn lights_json() -> Vec<Vec<u8>> {
    use light_extract::LightExtractor;
    let map = EnvMap::try_new(64, 32, pixels(64, 32)).unwrap_or_else(|_| EnvMap::constant(64, 32, Vec3::ONE));
    let mut out = vec![br#"{"lights":[{"direction":[0,1,0],"solid_angle":0.01,"radiance":[1,2,3]}]}"#.to_vec()];
    for method in ["median-cut", "emissive-split"] {
        if let Some(Ok(d)) = light_extract::extractor(method, 4).map(|e| e.extract(&map)) {
            let mut sets = d.interleaved();
            sets.truncate(2);
            if let Ok(text) = serde_json::to_vec_pretty(&d.to_json(&sets)) {
                out.push(text);
            }
        }
    }
    out
}

/// A model written by hand: a cube (u16 indices) and its points under a TRS parent, through a
/// matrix node; a quad as a u8 triangle strip with texture coordinates and a base colour
/// texture (a 2 x 2 PNG in the buffer); two materials and a camera. Its document and buffer.
fn handmade() -> (serde_json::Value, Vec<u8>) {
    let f32s = |v: &[[f32; 3]]| -> Vec<u8> { v.iter().flatten().flat_map(|f| f.to_le_bytes()).collect() };
    let corners: Vec<[f32; 3]> =
        (0..8).map(|k| [(k & 1) as f32 - 0.5, ((k >> 1) & 1) as f32 - 0.5, ((k >> 2) & 1) as f32 - 0.5]).collect();
    let faces: [[u16; 4]; 6] = [[0, 2, 3, 1], [4, 5, 7, 6], [0, 1, 5, 4], [2, 6, 7, 3], [0, 4, 6, 2], [1, 3, 7, 5]];
    let cube: Vec<u16> = faces.iter().flat_map(|f| [f[0], f[1], f[2], f[0], f[2], f[3]]).collect();
    let quad = [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 0.0, 1.0], [1.0, 0.0, 1.0]];
    let mut bin = f32s(&corners);
    bin.extend(cube.iter().flat_map(|i| i.to_le_bytes()));
    bin.extend(f32s(&quad));
    bin.extend([0u8, 1, 2, 3]);
    bin.extend([[0.0f32, 0.0], [1.0, 0.0], [0.0, 1.0], [1.0, 1.0]].iter().flatten().flat_map(|f| f.to_le_bytes()));
    let mut png = std::io::Cursor::new(Vec::new());
    let texels = image::RgbaImage::from_fn(2, 2, |x, y| image::Rgba([200 * x as u8, 200 * y as u8, 90, 255]));
    // an encoder's failure leaves the view empty, which the import refuses: still a seed
    let _ = texels.write_to(&mut png, image::ImageFormat::Png);
    let png = png.into_inner();
    bin.extend(&png);
    while !bin.len().is_multiple_of(4) {
        bin.push(0);
    }
    let doc = serde_json::json!({
        "asset": {"version": "2.0", "generator": "input-fuzz"},
        "scene": 0,
        "scenes": [{"nodes": [0, 3]}],
        "nodes": [
            {"name": "parent", "translation": [0.0, 1.0, 0.0], "rotation": [0.0, 0.382_683_43, 0.0, 0.923_879_5],
             "scale": [2.0, 2.0, 2.0], "children": [1, 2]},
            {"name": "cube", "mesh": 0, "matrix": [1.0, 0.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 0.0, 1.0, 0.0,
             0.5, 0.25, 0.0, 1.0]},
            {"name": "quad", "mesh": 1},
            {"name": "camera", "camera": 0, "translation": [0.0, 1.5, 6.0]}
        ],
        "meshes": [
            {"primitives": [{"attributes": {"POSITION": 0}, "indices": 1, "material": 0, "mode": 4},
                            {"attributes": {"POSITION": 0}, "mode": 0}]},
            {"primitives": [{"attributes": {"POSITION": 2, "TEXCOORD_0": 4}, "indices": 3, "mode": 5, "material": 1}]}
        ],
        "materials": [{"pbrMetallicRoughness": {"baseColorFactor": [0.8, 0.6, 0.4, 1.0]}, "doubleSided": true},
                      {"pbrMetallicRoughness": {"baseColorTexture": {"index": 0}, "metallicFactor": 0.0}}],
        "textures": [{"source": 0, "sampler": 0}],
        "samplers": [{"magFilter": 9729, "wrapS": 33648, "wrapT": 33071}],
        "images": [{"bufferView": 5, "mimeType": "image/png"}],
        "cameras": [{"type": "perspective", "perspective": {"yfov": 0.8, "znear": 0.01, "aspectRatio": 1.333}}],
        "accessors": [
            {"bufferView": 0, "componentType": 5126, "count": 8, "type": "VEC3",
             "min": [-0.5, -0.5, -0.5], "max": [0.5, 0.5, 0.5]},
            {"bufferView": 1, "componentType": 5123, "count": 36, "type": "SCALAR"},
            {"bufferView": 2, "componentType": 5126, "count": 4, "type": "VEC3",
             "min": [0.0, 0.0, 0.0], "max": [1.0, 0.0, 1.0]},
            {"bufferView": 3, "componentType": 5121, "count": 4, "type": "SCALAR"},
            {"bufferView": 4, "componentType": 5126, "count": 4, "type": "VEC2"}
        ],
        "bufferViews": [
            {"buffer": 0, "byteOffset": 0, "byteLength": 96, "target": 34962},
            {"buffer": 0, "byteOffset": 96, "byteLength": 72, "target": 34963},
            {"buffer": 0, "byteOffset": 168, "byteLength": 48, "target": 34962},
            {"buffer": 0, "byteOffset": 216, "byteLength": 4, "target": 34963},
            {"buffer": 0, "byteOffset": 220, "byteLength": 32, "target": 34962},
            {"buffer": 0, "byteOffset": 252, "byteLength": png.len()}
        ],
        "buffers": [{"byteLength": bin.len()}]
    });
    (doc, bin)
}

/// A grid of 2 x 7 vertices whose positions substitute three sparsely (u16 indices, as
/// SimpleSparseAccessor does), and a second primitive whose sparse positions have no view (a
/// base of zeros). Its document and buffer.
fn sparse() -> (serde_json::Value, Vec<u8>) {
    let grid: Vec<[f32; 3]> = (0..14).map(|i| [(i % 7) as f32, (i / 7) as f32, 0.0]).collect();
    let indices: Vec<u16> = (0..6u16).flat_map(|x| [x, x + 8, x + 7, x, x + 1, x + 8]).collect();
    let mut bin: Vec<u8> = grid.iter().flatten().flat_map(|f| f.to_le_bytes()).collect();
    bin.extend(indices.iter().flat_map(|i| i.to_le_bytes()));
    bin.extend([8u16, 10, 12].iter().flat_map(|i| i.to_le_bytes()));
    bin.extend([0u8; 2]);
    bin.extend([[1.0f32, 2.0, 0.0], [3.0, 3.0, 0.0], [5.0, 4.0, 0.0]].iter().flatten().flat_map(|f| f.to_le_bytes()));
    let sparse = serde_json::json!({"count": 3, "indices": {"bufferView": 2, "componentType": 5123},
        "values": {"bufferView": 3}});
    let doc = serde_json::json!({
        "asset": {"version": "2.0", "generator": "input-fuzz"},
        "scene": 0,
        "scenes": [{"nodes": [0]}],
        "nodes": [{"mesh": 0}],
        "meshes": [{"primitives": [{"attributes": {"POSITION": 1}, "indices": 0},
                                   {"attributes": {"POSITION": 2}, "indices": 0}]}],
        "accessors": [
            {"bufferView": 0, "componentType": 5123, "count": 36, "type": "SCALAR"},
            {"bufferView": 1, "componentType": 5126, "count": 14, "type": "VEC3",
             "min": [0.0, 0.0, 0.0], "max": [6.0, 4.0, 0.0], "sparse": sparse},
            {"componentType": 5126, "count": 14, "type": "VEC3",
             "min": [0.0, 0.0, 0.0], "max": [5.0, 4.0, 0.0], "sparse": sparse}
        ],
        "bufferViews": [
            {"buffer": 0, "byteOffset": 168, "byteLength": 72, "target": 34963},
            {"buffer": 0, "byteOffset": 0, "byteLength": 168, "target": 34962},
            {"buffer": 0, "byteOffset": 240, "byteLength": 6},
            {"buffer": 0, "byteOffset": 248, "byteLength": 36}
        ],
        "buffers": [{"byteLength": bin.len()}]
    });
    (doc, bin)
}

/// `column` with every primitive Draco-compressed (`draco-gltf`'s encoder, 14-bit positions),
/// its document and buffer; `None` if the encoder refuses.
fn draco() -> Option<(serde_json::Value, Vec<u8>)> {
    use draco_gltf::{CompressionOptions, MeshIndex, OutputFormat, QuantizationBits};
    let (doc, bin) = scene::Scene::builtin("column").ok()?.to_gltf(None);
    let raw = scene::glb_bytes(&serde_json::to_vec(&doc).ok()?, &bin)?;
    let mut import = draco_gltf::import_slice(&raw, None).ok()?;
    let quantization = QuantizationBits { position: Some(14), normal: Some(10), ..QuantizationBits::default() };
    let options = CompressionOptions { quantization, ..CompressionOptions::default() };
    for m in 0..import.document().meshes().len() {
        for p in 0..import.document().mesh(MeshIndex(m)).map_or(0, |x| x.primitive_count()) {
            import.compress_primitive(MeshIndex(m), p, options).ok()?;
        }
    }
    let glb = import.to_bytes(OutputFormat::GlbV2).ok()?;
    // the container's JSON and BIN chunks
    let json_len = u32::from_le_bytes(glb.get(12..16)?.try_into().ok()?) as usize;
    let doc = serde_json::from_slice(glb.get(20..20 + json_len)?).ok()?;
    Some((doc, glb.get(20 + json_len + 8..)?.to_vec()))
}

/// The glTF seeds' documents and buffers: `three_boxes` and `column` as the export writes them,
/// [`handmade`], [`sparse`] and [`draco`].
fn models() -> Vec<(serde_json::Value, Vec<u8>)> {
    let mut out: Vec<_> = ["three_boxes", "column"]
        .iter()
        .filter_map(|n| scene::Scene::builtin(n).ok())
        .map(|s| s.to_gltf(None))
        .collect();
    out.push(handmade());
    out.push(sparse());
    out.extend(draco());
    out
}

/// `.gltf` files with their buffer embedded as a base64 data URI.
#[must_use]
pub fn gltf() -> Vec<Vec<u8>> {
    models()
        .into_iter()
        .filter_map(|(mut doc, bin)| {
            doc["buffers"][0]["uri"] = format!("{}{}", crate::model::DATA_URI, base64::encode(&bin)).into();
            serde_json::to_vec(&doc).ok()
        })
        .collect()
}

/// `.glb` files: the same models in a binary container.
#[must_use]
pub fn glb() -> Vec<Vec<u8>> {
    models()
        .into_iter()
        .filter_map(|(doc, bin)| Some(crate::model::glb(&serde_json::to_vec(&doc).ok()?, &bin)))
        .collect()
}

/// Photographs as `--photo` reads them: an 8-bit and a 16-bit PNG (a channel at its top code,
/// clipped) and a JPEG.
#[must_use]
pub fn photos() -> (Vec<Vec<u8>>, Vec<Vec<u8>>) {
    let encode = |image: image::DynamicImage, format| {
        let mut out = std::io::Cursor::new(Vec::new());
        image.write_to(&mut out, format).map(|()| out.into_inner()).ok()
    };
    let rgb8 = image::RgbImage::from_fn(24, 16, |x, y| image::Rgb([(x * 10) as u8, (y * 16) as u8, 255]));
    let rgb16 = image::ImageBuffer::<image::Rgb<u16>, _>::from_fn(12, 8, |x, y| {
        image::Rgb([(x * 5000) as u16, (y * 8000) as u16, u16::MAX])
    });
    let png = [
        encode(image::DynamicImage::ImageRgb8(rgb8.clone()), image::ImageFormat::Png),
        encode(image::DynamicImage::ImageRgb16(rgb16), image::ImageFormat::Png),
    ];
    let jpeg = [encode(image::DynamicImage::ImageRgb8(rgb8), image::ImageFormat::Jpeg)];
    (png.into_iter().flatten().collect(), jpeg.into_iter().flatten().collect())
}

/// Pixels a fuzzed photograph may have: its decoding buffers (16 bytes a pixel) and the
/// photograph's own stay within [`crate::CASE_ALLOCATION_LIMIT`].
pub const PHOTO_MAX_PIXELS: u64 = 1 << 20;

/// The glTF import's options when fuzzed: a small camera and a million triangles at most, so a
/// case that claims the most allowed stays within [`crate::CASE_ALLOCATION_LIMIT`].
#[must_use]
pub fn gltf_options() -> scene::import::GltfOptions {
    scene::import::GltfOptions {
        size: (64, 48),
        max_triangles: 1 << 20,
        max_texture_bytes: 16 << 20,
        ..scene::import::GltfOptions::default()
    }
}

/// The loaders the commands use, on the seeds above: maps (`info`, `extract`, `--envmap`, the
/// `ambient.exr` beside a `lights.json`, read signed), images (`compare`) and `lights.json`
/// (`render --lights`), models (every command's scene or `--object` path), photographs
/// (`composite --photo`).
#[must_use]
pub fn library_targets() -> Vec<Target> {
    let options = LoadOptions { max_pixels: FUZZ_MAX_PIXELS, ..LoadOptions::default() };
    let signed = LoadOptions { negative: NegativePolicy::Keep, ..options };
    let map = move |o: LoadOptions| {
        move |bytes: &[u8], path: &std::path::Path| {
            EnvMap::load_from_bytes(bytes, path, &o).map(|_| ()).map_err(|e| e.to_string())
        }
    };
    let image = move |bytes: &[u8], path: &std::path::Path| {
        envmap_sphere::load_rgb_image_from_bytes(bytes, path, &options).map(|_| ()).map_err(|e| e.to_string())
    };
    let model = |bytes: &[u8], path: &std::path::Path| {
        scene::import::load_gltf_from_bytes(bytes, path, &gltf_options()).map(|_| ()).map_err(|e| e.to_string())
    };
    let photo = |bytes: &[u8], path: &std::path::Path| {
        real_scene::Photograph::from_bytes(bytes, path, 2.2, PHOTO_MAX_PIXELS).map(|_| ()).map_err(|e| e.to_string())
    };
    let (hdr, exr) = (hdr(), exr());
    let (png, jpeg) = photos();
    vec![
        Target {
            name: "map.hdr",
            extension: "hdr",
            format: Format::Hdr,
            seeds: hdr.clone(),
            run: Box::new(map(options)),
        },
        Target {
            name: "map.exr",
            extension: "exr",
            format: Format::Exr,
            seeds: exr.clone(),
            run: Box::new(map(options)),
        },
        Target {
            name: "ambient.exr",
            extension: "exr",
            format: Format::Exr,
            seeds: exr.clone(),
            run: Box::new(map(signed)),
        },
        Target { name: "image.hdr", extension: "hdr", format: Format::Hdr, seeds: hdr.clone(), run: Box::new(image) },
        Target { name: "image.exr", extension: "exr", format: Format::Exr, seeds: exr.clone(), run: Box::new(image) },
        Target {
            name: "lights.json",
            extension: "json",
            format: Format::Json,
            seeds: lights_json(),
            run: Box::new(|bytes, path| {
                light_extract::output::parse_lights_json(bytes, path).map(|_| ()).map_err(|e| e.to_string())
            }),
        },
        Target { name: "model.gltf", extension: "gltf", format: Format::Gltf, seeds: gltf(), run: Box::new(model) },
        Target { name: "model.glb", extension: "glb", format: Format::Glb, seeds: glb(), run: Box::new(model) },
        Target { name: "photo.png", extension: "png", format: Format::Png, seeds: png, run: Box::new(photo) },
        Target { name: "photo.jpg", extension: "jpg", format: Format::Png, seeds: jpeg, run: Box::new(photo) },
        Target {
            name: "photo.exr",
            extension: "exr",
            format: Format::Exr,
            // the maps' seeds but the signed one (a photograph has no negative radiance)
            seeds: exr.into_iter().filter(|s| photo(s, std::path::Path::new("seed")).is_ok()).collect(),
            run: Box::new(photo),
        },
    ]
}
