//! The compositor end to end at 80 x 60: on `ar_room` against the photograph where nothing is
//! occluded and the GPU against the CPU reference; on `ar_ground` against the path-traced truth
//! where the object shadows.

use std::sync::OnceLock;

use differential_composite::cpu::{ObjectBvh, composite, object_pixels};
use differential_composite::gpu::{GpuCompositor, GpuSettings};
use differential_composite::{Compositor, FrameTransfers, Mode, SyntheticObject};
use glam::Vec3;
use real_scene::{Perturbation, luminance};
use trade::{PhotoSettings, Session, SessionSettings};

const SIZE: (u32, u32) = (80, 60);

/// The tests' tracer for the compositor's ray queries.
fn rays(scene: &scene::Scene) -> Box<dyn real_scene::Visibility> {
    Box::new(ref_tracer::SceneBvh::new(scene))
}

fn settings(reconstruction: Perturbation, estimate: bool) -> SessionSettings {
    SessionSettings {
        size: Some(SIZE),
        photo: PhotoSettings { spp: 32, max_depth: 4, seed: 1 },
        reconstruction,
        estimate_reflectances: estimate,
        ..SessionSettings::default()
    }
}

fn room() -> &'static Session {
    static ROOM: OnceLock<Session> = OnceLock::new();
    ROOM.get_or_init(|| {
        Session::new("ar_room", None, Vec::new(), &settings(Perturbation::NONE, false))
            .unwrap_or_else(|e| panic!("{e}"))
    })
}

fn gpu() -> &'static (gpu::Gpu, GpuCompositor) {
    static GPU: OnceLock<(gpu::Gpu, GpuCompositor)> = OnceLock::new();
    GPU.get_or_init(|| {
        let g = gpu::Gpu::new().unwrap_or_else(|e| panic!("{e}"));
        let c = GpuCompositor::new(&g, &room().compositor).unwrap_or_else(|e| panic!("{e}"));
        (g, c)
    })
}

fn sphere(s: &Session, at: Vec3) -> SyntheticObject {
    s.object("sphere", at).unwrap_or_else(|e| panic!("{e}"))
}

fn cpu_composite(s: &Session, frame: &FrameTransfers, object: &SyntheticObject, mode: Mode) -> Vec<[u8; 3]> {
    let bvh = ObjectBvh::new(object, &object.mesh, s.compositor.model.camera, &rays);
    composite(&s.compositor, frame, object, &bvh, mode)
}

fn gpu_composite(frame: &FrameTransfers, object: &SyntheticObject, mode: Mode) -> Vec<[u8; 3]> {
    let (g, gc) = gpu();
    trade::composite_rows::composite(g, gc, (&room().compositor, frame, object), mode, &GpuSettings::default())
        .unwrap_or_else(|e| panic!("{e}"))
        .0
}

/// Pixels on the object or next to it (its silhouette's antialiasing reaches one pixel).
fn near_object(c: &Compositor, object: &SyntheticObject) -> Vec<bool> {
    let on = object_pixels(c, &ObjectBvh::new(object, &object.mesh, c.model.camera, &rays));
    let (w, h) = (c.size.0 as i64, c.size.1 as i64);
    (0..w * h)
        .map(|k| {
            let (x, y) = (k % w, k / w);
            (-1..=1).any(|dy| {
                (-1..=1).any(|dx| {
                    let (a, b) = (x + dx, y + dy);
                    a >= 0 && b >= 0 && a < w && b < h && on[(b * w + a) as usize]
                })
            })
        })
        .collect()
}

/// The luminance codes `image` takes away from the photograph, summed over the pixels off the
/// object.
fn darkening(c: &Compositor, image: &[[u8; 3]], skip: &[bool]) -> f64 {
    let y = |p: [u8; 3]| f64::from(luminance(Vec3::from_array(p.map(f32::from))));
    image.iter().zip(&c.photo_ldr).zip(skip).filter(|(_, s)| !**s).map(|((a, p), _)| y(*p) - y(*a)).sum()
}

#[test]
fn pixels_with_no_occluded_transfer_equal_the_photograph() {
    let s = room();
    let c = &s.compositor;
    let object = sphere(s, Vec3::new(0.0, 0.3, 0.5));
    let frame = c.frame(&object, 20);
    assert!(!frame.reps.is_empty(), "the sphere on the floor occludes sources");
    let near = near_object(c, &object);
    // a pixel's transfers: zero in every representative at all four of its vertices
    let untouched: Vec<bool> = c
        .pixels
        .iter()
        .zip(&near)
        .map(|(p, n)| {
            !n && (p.slot == u32::MAX
                || frame.reps.iter().all(|r| (0..4).all(|v| r.radiance[p.slot as usize + v] == Vec3::ZERO)))
        })
        .collect();
    let count = untouched.iter().filter(|u| **u).count();
    assert!(count > c.pixels.len() / 2, "{count} untouched pixels");
    for mode in [Mode::Hdr, Mode::Ldr] {
        for (name, image) in
            [("cpu", cpu_composite(s, &frame, &object, mode)), ("gpu", gpu_composite(&frame, &object, mode))]
        {
            let differ = (0..image.len()).filter(|&k| untouched[k] && image[k] != c.photo_ldr[k]).count();
            assert_eq!(differ, 0, "{name} {mode:?}: {differ} untouched pixels changed");
            assert!(image.iter().zip(&c.photo_ldr).any(|(a, p)| a != p), "{name} {mode:?}: nothing composited");
        }
    }
}

#[test]
fn an_object_far_from_everything_changes_nothing() {
    let s = room();
    let c = &s.compositor;
    // 20 m outside the room: no shaft reaches it, the camera does not see it
    let object = sphere(s, Vec3::new(20.0, 0.3, 0.0));
    let frame = c.frame(&object, 50);
    assert!(frame.reps.is_empty() && frame.occluded_sources == 0);
    for mode in [Mode::Hdr, Mode::Ldr] {
        assert!(cpu_composite(s, &frame, &object, mode) == c.photo_ldr, "cpu {mode:?}");
        assert!(gpu_composite(&frame, &object, mode) == c.photo_ldr, "gpu {mode:?}");
    }
}

#[test]
fn gpu_composite_matches_the_cpu_reference() {
    // the GPU's shadow maps (256^2) against rays from each pixel to each origin, off the object
    let s = room();
    let c = &s.compositor;
    for at in [Vec3::new(0.0, 0.3, 0.5), Vec3::new(-0.8, 1.2, 0.0)] {
        let object = sphere(s, at);
        let near = near_object(c, &object);
        let frame = c.frame(&object, 20);
        for mode in [Mode::Hdr, Mode::Ldr] {
            let (a, b) = (cpu_composite(s, &frame, &object, mode), gpu_composite(&frame, &object, mode));
            let far = (0..a.len()).filter(|&k| !near[k]).count();
            // shadow-map texels and bias move a hard edge by a pixel here and there
            let differ = (0..a.len()).filter(|&k| !near[k] && (0..3).any(|ch| a[k][ch].abs_diff(b[k][ch]) > 2)).count();
            let mean: f64 = (0..a.len())
                .filter(|&k| !near[k])
                .map(|k| (0..3).map(|ch| f64::from(a[k][ch].abs_diff(b[k][ch]))).sum::<f64>() / 3.0)
                .sum::<f64>()
                / far as f64;
            assert!((differ as f64) < 0.03 * far as f64, "{at} {mode:?}: {differ} of {far} pixels differ by > 2 codes");
            assert!(mean < 0.2, "{at} {mode:?}: mean difference {mean} codes");
        }
    }
}

fn ground() -> &'static Session {
    static GROUND: OnceLock<Session> = OnceLock::new();
    GROUND.get_or_init(|| {
        let map = envmap_sphere::default_map();
        let lights = light_extract::extractor("emissive-split+moment-cones+above-horizon+residual", 32)
            .and_then(|e| e.extract(&map).ok())
            .map(|d| d.distant_lights())
            .unwrap_or_default();
        assert!(!lights.is_empty(), "the map's lights");
        Session::new("ar_ground", Some(map), lights, &settings(Perturbation::NONE, false))
            .unwrap_or_else(|e| panic!("{e}"))
    })
}

#[test]
fn the_composite_follows_the_truths_shadow_as_the_object_rises() {
    // paper 003, Figure 7, on the environment-lit ground (sun and sky): at each height the
    // darkening the composite adds is the truth's within a third, the more passes the closer,
    // and its error is no more than leaving the photograph alone
    let s = ground();
    let c = &s.compositor;
    for y in [0.3, 0.8, 1.5] {
        let object = sphere(s, Vec3::new(0.0, y, 1.0));
        let near = near_object(c, &object);
        let truth = s.truth(&object).unwrap_or_else(|e| panic!("{e}"));
        let want = darkening(c, &truth, &near);
        let off: Vec<usize> = (0..truth.len()).filter(|&k| !near[k]).collect();
        let pick = |img: &[[u8; 3]]| off.iter().map(|&k| img[k]).collect::<Vec<_>>();
        let mae =
            |img: &[[u8; 3]]| differential_composite::code_error(&pick(img), &pick(&truth), &pick(&c.photo_ldr)).mae;
        let nothing = mae(&c.photo_ldr);
        let mut last = f64::INFINITY;
        for n in [1, 10, 0] {
            let frame = c.frame(&object, n);
            let image = cpu_composite(s, &frame, &object, Mode::Hdr);
            let (got, err) = (darkening(c, &image, &near), mae(&image));
            if n == 0 {
                assert!(got > 0.7 * want && got < 1.35 * want, "height {y}: darkening {got} vs the truth's {want}");
                assert!(err <= nothing + 0.01, "height {y}: error {err} vs the photograph's {nothing}");
            }
            assert!(err <= last + 0.01, "height {y}, {n} passes: error {err} after {last}");
            last = err;
        }
    }
}

#[test]
fn a_transfers_share_of_its_pixel_does_not_depend_on_reflectance_estimated_from_the_photo() {
    // reconstructions 30 % too dark: solved with their reflectances, the shadows' transfers
    // change; with reflectances estimated from the capture's radiances, they do not
    let make = |scale: f32, estimate: bool| {
        let p = Perturbation { reflectance_scale: scale, ..Perturbation::NONE };
        Session::new("ar_room", None, Vec::new(), &settings(p, estimate)).unwrap_or_else(|e| panic!("{e}"))
    };
    // every pair's transfer, summed
    let total = |s: &Session| {
        let c = &s.compositor;
        (0..c.prepared.sources.len())
            .flat_map(|j| (0..c.prepared.transfers.slots).map(move |k| (j, k)))
            .map(|(j, k)| f64::from(luminance(c.transfer_rgb(j, k))))
            .sum::<f64>()
    };
    let (exact, dark) = (total(&make(1.0, true)), total(&make(0.7, true)));
    assert!(exact > 0.0 && ((dark - exact) / exact).abs() < 1e-3, "estimated: {dark} vs {exact}");
    let (exact, dark) = (total(&make(1.0, false)), total(&make(0.7, false)));
    assert!(dark < 0.8 * exact, "solved with the wrong reflectances: {dark} vs {exact}");
}

#[test]
fn the_composite_stays_between_the_photograph_and_its_residual_light() {
    // never brighter than the photograph; in HDR never darker than the photograph less every
    // source's transfer (what an object occluding everything leaves: the residual light)
    let s = room();
    let c = &s.compositor;
    let object = sphere(s, Vec3::new(0.0, 0.3, 0.5));
    let near = near_object(c, &object);
    let frame = c.frame(&object, 0);
    let residual: Vec<[u8; 3]> = c
        .pixels
        .iter()
        .zip(&c.photo_hdr)
        .map(|(p, l)| {
            if p.slot == u32::MAX {
                return c.response.apply(*l);
            }
            let all: Vec3 = (0..c.prepared.sources.len())
                .map(|j| (0..4).map(|v| p.weights[v] * c.transfer_rgb(j, p.slot as usize + v)).sum::<Vec3>())
                .sum();
            c.response.apply((*l - all).max(Vec3::ZERO))
        })
        .collect();
    for mode in [Mode::Hdr, Mode::Ldr] {
        let image = cpu_composite(s, &frame, &object, mode);
        for k in (0..image.len()).filter(|&k| !near[k]) {
            for ch in 0..3 {
                assert!(image[k][ch] <= c.photo_ldr[k][ch], "{mode:?} pixel {k} brighter than the photograph");
                if mode == Mode::Hdr {
                    assert!(image[k][ch] >= residual[k][ch], "pixel {k} below its residual light");
                }
            }
        }
    }
    // the vertices' transfers mostly sum below their radiance (the source set holds 70 % of
    // the power); a vertex near an edge can exceed its patch's centre radiance
    let mut ratios: Vec<f32> = (0..c.prepared.transfers.slots)
        .filter(|&k| c.vertex_radiance[k].max_element() > 0.0)
        .map(|k| {
            let sum: Vec3 = (0..c.prepared.sources.len()).map(|j| c.transfer_rgb(j, k)).sum();
            luminance(sum) / luminance(c.vertex_radiance[k])
        })
        .collect();
    ratios.sort_by(f32::total_cmp);
    let median = ratios[ratios.len() / 2];
    assert!(median > 0.5 && median < 0.9, "median transfer share {median}");
}

#[test]
fn extremes_black_receivers_and_an_object_in_a_shaft_only() {
    // black receivers: a reconstruction with no reflectance transfers nothing
    let black = Session::new(
        "ar_room",
        None,
        Vec::new(),
        &settings(Perturbation { reflectance_scale: 0.0, ..Perturbation::NONE }, false),
    )
    .unwrap_or_else(|e| panic!("{e}"));
    let object = sphere(&black, Vec3::new(0.0, 0.3, 0.5));
    let near = near_object(&black.compositor, &object);
    let frame = black.compositor.frame(&object, 20);
    for mode in [Mode::Hdr, Mode::Ldr] {
        let image = cpu_composite(&black, &frame, &object, mode);
        assert!((0..image.len()).all(|k| near[k] || image[k] == black.compositor.photo_ldr[k]), "{mode:?}");
    }
    // in mid-air under the lamp, touching nothing: its shaft's sources still shadow the floor
    let s = room();
    let object = sphere(s, Vec3::new(0.0, 2.0, 0.0));
    let frame = s.compositor.frame(&object, 20);
    assert!(!frame.reps.is_empty());
    let near = near_object(&s.compositor, &object);
    assert!(darkening(&s.compositor, &cpu_composite(s, &frame, &object, Mode::Hdr), &near) > 0.0);
}

#[test]
fn hemispherical_sources_render_one_paraboloid_view_and_cubes_six() {
    // ar_room is lit by its patches: every representative's source emits into a hemisphere
    let s = room();
    let c = &s.compositor;
    let object = sphere(s, Vec3::new(0.0, 0.3, 0.5));
    let frame = c.frame(&object, 0);
    let patches = frame
        .reps
        .iter()
        .filter(|r| {
            matches!(c.prepared.sources[r.origin_source as usize], shaft_hierarchy::preprocess::Source::Patch(_))
        })
        .count() as u32;
    assert!(patches > 0 && patches as usize == frame.reps.len(), "{patches} of {}", frame.reps.len());
    let (g, gc) = gpu();
    let run = |patch_maps, layers_per_array| {
        let settings = GpuSettings { patch_maps, layers_per_array, ..GpuSettings::default() };
        trade::composite_rows::composite(g, gc, (c, &frame, &object), Mode::Hdr, &settings)
            .unwrap_or_else(|e| panic!("{e}"))
    };
    let (paraboloid, _, work) = run(shadowmap_paraboloid::Technique::DualParaboloid, None);
    assert_eq!((work.views, work.hemispheres_skipped), (patches, patches));
    let (cube, _, work) = run(shadowmap_paraboloid::Technique::Cube, None);
    assert_eq!((work.views, work.hemispheres_skipped), (6 * patches, 0));
    // the maps spread over arrays of 16 layers (a dispatch each) darken as one array does
    let (split, _, work) = run(shadowmap_paraboloid::Technique::Cube, Some(16));
    assert_eq!(work.views, 6 * patches);
    assert!(split.iter().zip(&cube).all(|(a, b)| (0..3).all(|ch| a[ch].abs_diff(b[ch]) <= 1)), "batches differ");
    // the hemisphere left out holds nothing the source lights: the composites agree
    let differ = paraboloid.iter().zip(&cube).filter(|(a, b)| (0..3).any(|ch| a[ch].abs_diff(b[ch]) > 2)).count();
    assert!((differ as f64) < 0.01 * paraboloid.len() as f64, "{differ} pixels differ");
}

#[test]
fn the_composite_recorded_into_one_encoder_equals_the_measured_one() {
    // the real-time path: every stage recorded into the caller's encoder, nothing submitted,
    // waited for or read back while recording; the measured path is the same recording timed
    let s = room();
    let c = &s.compositor;
    let (g, gc) = gpu();
    for at in [Vec3::new(0.0, 0.3, 0.5), Vec3::new(0.4, 0.3, 0.2)] {
        let object = sphere(s, at);
        let frame = c.frame(&object, 20);
        for mode in [Mode::Hdr, Mode::Ldr] {
            let settings = GpuSettings::default();
            let before = g.counters();
            let wall = std::time::Instant::now();
            let (measured, times, work) =
                trade::composite_rows::composite(g, gc, (c, &frame, &object), mode, &settings).unwrap();
            let (wall, measuring) = (wall.elapsed(), g.counters() - before);
            // with timestamps inside encoders the measured frame is the recorded one: one
            // submission (and the image's readback), its stages between timestamps within the
            // call's wall time; without them each of the four stages is a submission waited for
            let stamped =
                g.features.contains(wgpu::Features::TIMESTAMP_QUERY | wgpu::Features::TIMESTAMP_QUERY_INSIDE_ENCODERS);
            let want = if stamped { (gpu::Clock::GpuTimestamps, 2) } else { (gpu::Clock::WallTime, 5) };
            assert_eq!((times.clock, measuring.submits), want, "{at} {mode:?}");
            assert!(
                times.total() - times.cpu <= wall && times.masks > std::time::Duration::ZERO,
                "{times:?} in {wall:?}"
            );
            let mut encoder = g.encoder("composite");
            let before = g.counters();
            let recorded_work = gc.record(g, &mut encoder, c, &frame, &object, mode, &settings).unwrap();
            let during = g.counters() - before;
            assert_eq!((during.submits, during.waits, during.readback_bytes, during.pipelines), (0, 0, 0, 0));
            g.submit(encoder);
            assert_eq!(recorded_work, work);
            assert!(gc.read_output(g).unwrap() == measured, "{at} {mode:?}: the recorded composite differs");
        }
    }
}
