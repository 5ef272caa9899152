//! Interleaved sampling's pixel pattern and the pass that gathers each set's pixels.

use glam::Vec3;
use gpu::{Gpu, HDR_FORMAT, InterleavePass, interleave_set, interleave_tile, read_hdr, render_target};
use wgpu::util::DeviceExt;

#[test]
fn every_tile_holds_each_set_once() {
    for sets in 1..=64u32 {
        let (a, b) = interleave_tile(sets);
        assert_eq!(a * b, sets);
        assert!(b <= a, "{sets}: {a} x {b}");
        // any a x b window, wherever it starts, holds every set once
        for (x0, y0) in [(0, 0), (3, 5), (a + 1, b + 2)] {
            let mut seen = vec![0u32; sets as usize];
            for y in y0..y0 + b {
                for x in x0..x0 + a {
                    seen[interleave_set(x, y, sets) as usize] += 1;
                }
            }
            assert!(seen.iter().all(|&n| n == 1), "{sets} sets from ({x0}, {y0}): {seen:?}");
        }
    }
    assert_eq!(interleave_tile(8), (4, 2));
    assert_eq!(interleave_tile(9), (3, 3));
    assert_eq!(interleave_tile(7), (7, 1));
}

#[test]
fn gathering_takes_each_pixel_from_its_set() {
    let gpu = Gpu::new().unwrap_or_else(|e| panic!("{e}"));
    let (w, h, sets) = (37u32, 11u32, 8u32);
    let colour = |s: u32| Vec3::new(s as f32, 1.0 + s as f32 * 0.5, -(s as f32));
    let dst = render_target(&gpu, "gathered", (w, h, 1), HDR_FORMAT).unwrap();
    let pass = InterleavePass::new(&gpu);
    // every set's gathering in one submission: each keeps its own parameters
    let mut encoder = gpu.encoder("gather");
    let mut sources = Vec::new();
    for s in 0..sets {
        let texels: Vec<[f32; 4]> = vec![colour(s).extend(1.0).to_array(); (w * h) as usize];
        let src = gpu.device.create_texture_with_data(
            &gpu.queue,
            &wgpu::TextureDescriptor {
                label: Some("set"),
                size: wgpu::Extent3d { width: w, height: h, depth_or_array_layers: 1 },
                mip_level_count: 1,
                sample_count: 1,
                dimension: wgpu::TextureDimension::D2,
                format: HDR_FORMAT,
                usage: wgpu::TextureUsages::TEXTURE_BINDING,
                view_formats: &[],
            },
            wgpu::util::TextureDataOrder::LayerMajor,
            bytemuck::cast_slice(&texels),
        );
        pass.record_gather(&gpu, &mut encoder, (&src, &dst), sets, s).unwrap();
        assert!(pass.record_gather(&gpu, &mut encoder, (&src, &dst), sets, sets).is_err());
        sources.push(src);
    }
    gpu.submit(encoder);
    let image = read_hdr(&gpu, &dst).unwrap();
    for y in 0..h {
        for x in 0..w {
            assert_eq!(image[(y * w + x) as usize], colour(interleave_set(x, y, sets)), "pixel ({x}, {y})");
        }
    }
}
