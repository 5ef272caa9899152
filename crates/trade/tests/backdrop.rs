//! Compositing onto an HDRI (the backdrop) at the extremes the issue names, each against the
//! local scene path traced (the truth): a sun on the horizon, a sun at the zenith, an overcast
//! sky, an object floating above the ground, an object larger than the ground disc. Synthetic
//! maps, small images, the GPU compositor as the command runs it (soft shadows, 2 x 2
//! coverage).

use std::sync::OnceLock;

use differential_composite::gpu::{GpuCompositor, GpuSettings};
use differential_composite::{Mode, ObjectPlacement, SyntheticObject};
use envmap_sphere::EnvMap;
use glam::Vec3;
use real_scene::{Backdrop, luminance};
use trade::backdrop::{BackdropSession, BackdropSettings};

const SIZE: (u32, u32) = (96, 72);

fn gpu() -> &'static gpu::Gpu {
    static GPU: OnceLock<gpu::Gpu> = OnceLock::new();
    GPU.get_or_init(|| gpu::Gpu::new().unwrap_or_else(|e| panic!("{e}")))
}

/// A sky of radiance 0.6 (bluer at the zenith) over a ground of 0.1-0.2 with a pattern, and a
/// sun of `sun` = (direction, radiance) 1.5 degrees in radius.
fn map(sun: Option<(Vec3, f32)>) -> EnvMap {
    striped_map(sun, 0.05)
}

/// [`map`] with the ground's pattern `stripe` brighter in red and blue.
fn striped_map(sun: Option<(Vec3, f32)>, stripe: f32) -> EnvMap {
    let (w, h) = (512u32, 256u32);
    let probe = EnvMap::from_texels(w, h, |_, _| Vec3::ZERO);
    EnvMap::from_texels(w, h, |i, j| {
        let d = probe.texel_dir(i, j);
        if let Some((s, l)) = sun
            && d.dot(s.normalize()) >= 1.5f32.to_radians().cos()
        {
            return Vec3::splat(l);
        }
        if d.y >= 0.0 {
            Vec3::new(0.5, 0.55, 0.6 + 0.2 * d.y)
        } else {
            let stripe = if (i / 16 + j / 16) % 2 == 0 { stripe } else { 0.0 };
            Vec3::new(0.15 + stripe, 0.13, 0.1 + stripe)
        }
    })
}

fn settings(radius: f32) -> BackdropSettings {
    BackdropSettings {
        backdrop: Backdrop { ground_radius: radius, ..BackdropSettings::default().backdrop },
        ground_texels: 512,
        ..BackdropSettings::default()
    }
}

fn camera(eye: Vec3, target: Vec3) -> scene::Camera {
    scene::Camera { eye, target, up: Vec3::Y, hfov_degrees: 70.0, width: SIZE.0, height: SIZE.1 }
}

fn sphere(at: Vec3, scale: f32) -> SyntheticObject {
    SyntheticObject::open_placed("sphere", &ObjectPlacement { scale, ..ObjectPlacement::at(at) })
        .unwrap_or_else(|e| panic!("{e}"))
        .0
}

/// The GPU composite (HDR, 50 passes, soft shadows, 2 x 2 coverage) and the truth at `spp`,
/// both in radiance.
fn run(session: &BackdropSession, object: &SyntheticObject, spp: u32) -> (Vec<Vec3>, Vec<Vec3>) {
    let ours = composite(session, object, true).1;
    let (truth, _) = session.differential(object, spp, 3);
    assert!(ours.iter().chain(&truth).all(|v| v.is_finite() && v.min_element() >= 0.0), "a NaN or a negative");
    (ours, truth)
}

/// The GPU composite as the command draws it (HDR, 50 passes, soft shadows, 2 x 2 coverage),
/// its masks culled or not: the 8-bit image and the radiance.
fn composite(session: &BackdropSession, object: &SyntheticObject, cull_masks: bool) -> (Vec<[u8; 3]>, Vec<Vec3>) {
    let c = &session.compositor;
    let gc = GpuCompositor::new(gpu(), c).unwrap_or_else(|e| panic!("{e}"));
    let settings = GpuSettings {
        pcss: Some(shadowmap_paraboloid::Pcss { blocker_samples: 8, filter_samples: 16, max_radius_texels: 64.0 }),
        coverage_samples: 2,
        cull_masks,
        ..GpuSettings::default()
    };
    let frame = c.frame(object, 50);
    let (image, _, _) = trade::composite_rows::composite(gpu(), &gc, (c, &frame, object), Mode::Hdr, &settings)
        .unwrap_or_else(|e| panic!("{e}"));
    (image, gc.read_output_hdr(gpu()).unwrap_or_else(|e| panic!("{e}")))
}

/// Per ground pixel the object does not cover: its ground point and how much of the plate's
/// luminance the image takes away there.
fn darkening(session: &BackdropSession, image: &[Vec3], object: &SyntheticObject) -> Vec<(Vec3, f32)> {
    let c = &session.compositor;
    let rays = c.model.camera.rays();
    let bounds = object.bounds();
    (0..image.len())
        .filter_map(|k| {
            let (w, _) = c.size;
            let (o, d) = rays.ray((k as u32 % w) as f32 + 0.5, (k as u32 / w) as f32 + 0.5);
            let p = session.backdrop.ground_hit(o, d)?;
            // pixels whose ray meets the object's box before the ground are the object's
            let t = (p - o).length();
            let before = ray_box(o, d, bounds.min, bounds.max).is_some_and(|s| s < t);
            (!before).then(|| (p, luminance(c.photo_hdr[k]) - luminance(image[k])))
        })
        .collect()
}

fn ray_box(o: Vec3, d: Vec3, lo: Vec3, hi: Vec3) -> Option<f32> {
    let inv = d.recip();
    let (a, b) = ((lo - o) * inv, (hi - o) * inv);
    let (near, far) = (a.min(b).max_element(), a.max(b).min_element());
    (near <= far && far > 0.0).then_some(near.max(0.0))
}

/// The darkening added up (light the object adds, reflected onto the ground, is left out: the
/// compositor only darkens).
fn total(d: &[(Vec3, f32)]) -> f32 {
    d.iter().map(|x| x.1.max(0.0)).sum()
}

/// Where the darkening lies on the ground: its darkening-weighted centre.
fn centre(d: &[(Vec3, f32)]) -> Vec3 {
    let w: f32 = d.iter().map(|x| x.1.max(0.0)).sum();
    d.iter().map(|x| x.0 * x.1.max(0.0)).sum::<Vec3>() / w.max(f32::MIN_POSITIVE)
}

#[test]
fn sun_at_the_zenith_shadows_under_the_object() {
    // a clear day's sun: four times the sky's irradiance
    let map = map(Some((Vec3::Y, 3e3)));
    let at = Vec3::new(0.0, 0.0, 2.0);
    let object = sphere(at, 1.0);
    // from above: the umbra right under the sphere is hidden by it, the ring around it is not
    let s = BackdropSession::new(map, camera(Vec3::new(0.0, 5.0, 1.0), at), &settings(20.0)).unwrap();
    let (ours, truth) = run(&s, &object, 64);
    let (d_ours, d_truth) = (darkening(&s, &ours, &object), darkening(&s, &truth, &object));
    let (a, b) = (total(&d_ours), total(&d_truth));
    // the ring of sky shadow around the contact (the sun's is under the sphere, hidden): ours
    // darker by 40 % when measured (the light the sphere reflects onto the ground is not
    // composited)
    assert!(b > 0.0 && (a / b - 1.0).abs() < 0.6, "darkening {a} against the truth's {b}");
    // both centred under the sphere (radius 0.3), not beside it
    for d in [&d_ours, &d_truth] {
        let c = centre(d);
        assert!(Vec3::new(c.x - at.x, 0.0, c.z - at.z).length() < 0.3, "shadow centred at {c}");
    }
}

#[test]
fn sun_on_the_horizon_shadows_reach_the_disc_edge() {
    // the sun 2 degrees up in +x: the sphere's shadow runs 8.6 m toward -x, past a 5 m disc
    let sun = Vec3::new(1.0, 2f32.to_radians().tan(), 0.0).normalize();
    let map = map(Some((sun, 2e4)));
    let at = Vec3::new(0.0, 0.0, 0.0);
    let object = sphere(at, 1.0);
    let s =
        BackdropSession::new(map, camera(Vec3::new(0.5, 6.0, 4.0), Vec3::new(-2.5, 0.0, 0.0)), &settings(5.0)).unwrap();
    let (ours, truth) = run(&s, &object, 64);
    for (name, image) in [("ours", &ours), ("truth", &truth)] {
        let d = darkening(&s, image, &object);
        // ground points 4-5 m down the shadow, within its width, against ones as far to the side
        let mean = |f: &dyn Fn(Vec3) -> bool| {
            let v: Vec<f32> = d.iter().filter(|x| f(x.0)).map(|x| x.1).collect();
            assert!(v.len() > 3, "{name}: {} pixels", v.len());
            v.iter().sum::<f32>() / v.len() as f32
        };
        let down = mean(&|p: Vec3| (-5.0..-4.0).contains(&p.x) && p.z.abs() < 0.15);
        let side = mean(&|p: Vec3| (-5.0..-4.0).contains(&p.x) && (1.0..2.0).contains(&p.z));
        // the sun, 2 degrees up, gives the ground about half its light there
        assert!(down > 0.02 && down > 8.0 * side.max(0.0), "{name}: {down} down the shadow, {side} beside it");
    }
}

#[test]
fn overcast_sky_darkens_as_the_truth() {
    let map = map(None);
    let at = Vec3::new(0.0, 0.0, 2.5);
    let object = sphere(at, 1.0);
    let s = BackdropSession::new(map, camera(Vec3::new(0.0, 1.6, 0.0), at), &settings(20.0)).unwrap();
    assert!(s.lights.0 > 0, "the sky's lights are the sources");
    let (ours, truth) = run(&s, &object, 128);
    let (a, b) = (total(&darkening(&s, &ours, &object)), total(&darkening(&s, &truth, &object)));
    assert!(b > 0.0 && (a / b - 1.0).abs() < 0.3, "darkening {a} against the truth's {b}");
}

#[test]
fn a_floating_objects_shadow_weakens_as_the_truths() {
    // under an overcast sky a sphere on the ground darkens the ground around its contact;
    // lifted 0.8 m, it darkens it much less
    let at = Vec3::new(0.0, 0.0, 2.5);
    let s = BackdropSession::new(map(None), camera(Vec3::new(0.0, 2.0, 0.0), at), &settings(20.0)).unwrap();
    // the darkest of the shadow within 1.2 m of the axis: the mean of its 30 darkest pixels,
    // as a fraction of the plate
    let near = |image: &[Vec3], object: &SyntheticObject| {
        let d = darkening(&s, image, object);
        let mut v: Vec<f32> =
            d.iter().filter(|x| Vec3::new(x.0.x - at.x, 0.0, x.0.z - at.z).length() < 1.2).map(|x| x.1).collect();
        v.sort_by(|a, b| b.total_cmp(a));
        v.iter().take(30).sum::<f32>() / 30.0
    };
    let mut shadows = [[0.0f32; 2]; 2];
    for (k, lift) in [0.0, 0.8].into_iter().enumerate() {
        let object = sphere(at + Vec3::Y * lift, 1.0);
        let (ours, truth) = run(&s, &object, 512);
        shadows[0][k] = near(&ours, &object);
        shadows[1][k] = near(&truth, &object);
    }
    let ratios = shadows.map(|[grounded, lifted]| lifted / grounded.max(f32::MIN_POSITIVE));
    assert!(shadows.iter().all(|s| s[0] > 0.0), "{shadows:?}");
    assert!(ratios.iter().all(|&r| r < 0.8), "lifted over grounded, ours and the truth's: {ratios:?} of {shadows:?}");
    assert!((ratios[0] - ratios[1]).abs() < 0.2, "ours keeps {} of its darkening, the truth {}", ratios[0], ratios[1]);
}

#[test]
fn an_object_larger_than_the_disc_composites() {
    // a sphere 24 m across on a 5 m disc, 15 m away
    let at = Vec3::new(0.0, 0.0, 15.0);
    let object = sphere(at, 40.0);
    let sun = Vec3::new(0.2, 1.0, 0.5).normalize();
    let s = BackdropSession::new(
        map(Some((sun, 2e4))),
        camera(Vec3::new(0.0, 1.6, 0.0), at + Vec3::Y * 12.0),
        &settings(5.0),
    )
    .unwrap();
    let (ours, truth) = run(&s, &object, 32);
    let c = &s.compositor;
    let codes = |v: &[Vec3]| v.iter().map(|x| c.response.apply(*x)).collect::<Vec<_>>();
    let e = differential_composite::code_error(&codes(&ours), &codes(&truth), &c.photo_ldr);
    assert!(e.changed > (SIZE.0 * SIZE.1 / 4) as usize, "it fills the view: {} pixels changed", e.changed);
    assert!(e.rmse_changed < 20.0, "RMSE {} codes", e.rmse_changed);
}

#[test]
fn culled_masks_draw_the_same_image() {
    // a sun low in the side, its shadow long across the view, and an overcast sky: every
    // representative tested only inside its rectangle gives the image testing all of them does
    let at = Vec3::new(0.3, 0.0, 2.5);
    for sun in [Some((Vec3::new(-1.0, 0.4, 0.3).normalize(), 3e3)), None] {
        let s = BackdropSession::new(map(sun), camera(Vec3::new(0.0, 1.6, 0.0), at), &settings(20.0)).unwrap();
        for object in [sphere(at, 1.0), sphere(at + Vec3::Y * 0.5, 2.0)] {
            let frame = s.compositor.frame(&object, 50);
            let bounds = object.bounds();
            let culled: usize = frame
                .reps
                .iter()
                .map(|r| {
                    let [x0, y0, x1, y1] = differential_composite::gpu::shadow_rect(&s.compositor, &bounds, r);
                    (SIZE.0 * SIZE.1) as usize - (x1.saturating_sub(x0) * y1.saturating_sub(y0)) as usize
                })
                .sum();
            assert!(culled > 0, "{sun:?}: nothing culled");
            let (a, b) = (composite(&s, &object, true), composite(&s, &object, false));
            assert!(a.0 == b.0 && a.1 == b.1, "{sun:?}: the culled masks changed the image");
        }
    }
}

/// A sun behind the camera and to its left, 30 degrees up: the sphere's shadow falls ahead,
/// in view.
fn sun_behind() -> Option<(Vec3, f32)> {
    Some((Vec3::new(-0.4, 0.6, -1.0).normalize(), 3e3))
}

#[test]
fn a_photograph_of_the_backdrop_composites_as_the_backdrop() {
    // the backdrop's own plate as the user's photograph (at a quarter of the probe's exposure),
    // the map as its probe, the camera where the probe was: the same composite
    let at = Vec3::new(0.0, 0.0, 2.5);
    let object = sphere(at, 1.0);
    let cam = camera(Vec3::new(0.0, 1.6, 0.0), at + Vec3::Y * 0.3);
    let s = BackdropSession::new(map(sun_behind()), cam, &settings(20.0)).unwrap();
    let photo = real_scene::Photograph::from_hdr(SIZE.0, SIZE.1, s.compositor.photo_hdr.clone()).scaled(0.25);
    assert_eq!(photo.clip, None, "a rendered plate does not clip");
    let p = BackdropSession::with_photo(map(sun_behind()), &photo, cam, &settings(20.0)).unwrap();
    let scale = p.photo.unwrap().exposure;
    assert!((scale - 4.0).abs() < 4e-3, "exposure x {scale}, not 4");
    let (a, b) = (composite(&s, &object, true).1, composite(&p, &object, true).1);
    let c = &s.compositor;
    let (codes_a, codes_b): (Vec<_>, Vec<_>) =
        a.iter().zip(&b).map(|(x, y)| (c.response.apply(*x), c.response.apply(*y))).unzip();
    let e = differential_composite::code_error(&codes_b, &codes_a, &c.photo_ldr);
    assert!(e.changed > 300, "the shadow is in view: {} pixels", e.changed);
    assert!(e.rmse_changed < 1.0, "photograph against backdrop: RMSE {} codes", e.rmse_changed);
}

#[test]
fn an_hdr_photo_with_clipped_pixels_keeps_its_shadow() {
    // the plate clipped at a level between the ground's sunlit stripes (radiance 0.4 in red)
    // and the rest (0.15): where the sphere's shadow falls on a clipped stripe, the truth shows
    // the stripe's own darkened radiance, which only the probe (unclipped) knows
    let at = Vec3::new(0.0, 0.0, 2.5);
    let object = sphere(at, 1.0);
    let cam = camera(Vec3::new(0.0, 1.6, 0.0), at + Vec3::Y * 0.3);
    let s = BackdropSession::new(striped_map(sun_behind(), 0.25), cam, &settings(20.0)).unwrap();
    let (truth, _) = s.differential(&object, 128, 5);
    let clip = 0.25;
    let clipped: Vec<Vec3> = s.compositor.photo_hdr.iter().map(|v| v.min(Vec3::splat(clip))).collect();
    let photo = real_scene::Photograph::from_hdr(SIZE.0, SIZE.1, clipped.clone());
    assert_eq!(photo.clip, Some(clip), "the plateau is found");
    assert!(photo.clipped_pixels() > 200, "{} pixels clipped", photo.clipped_pixels());
    // the camera's 8 bits: white at the clip
    let response = real_scene::CameraResponse { exposure: 1.0 / clip, gamma: 2.2, white: 1.0 };
    let codes = |v: &[Vec3]| v.iter().map(|x| response.apply(*x)).collect::<Vec<_>>();
    let truth_codes = codes(&truth.iter().map(|v| v.min(Vec3::splat(clip))).collect::<Vec<_>>());
    let photo_codes = codes(&clipped);
    // over the clipped pixels the truth darkens, off the object: the RMSE in codes
    let bounds = object.bounds();
    let rays = cam.rays();
    let off_object = |k: usize| {
        let (o, d) = rays.ray((k as u32 % SIZE.0) as f32 + 0.5, (k as u32 / SIZE.0) as f32 + 0.5);
        s.backdrop.ground_hit(o, d).is_some() && ray_box(o, d, bounds.min, bounds.max).is_none()
    };
    let shadowed: Vec<usize> = (0..truth.len())
        .filter(|&k| photo.clipped[k] != 0 && truth_codes[k] != photo_codes[k] && off_object(k))
        .collect();
    assert!(shadowed.len() > 30, "{} clipped pixels in the shadow", shadowed.len());
    let rmse = |hdr: &[Vec3]| {
        let c = codes(hdr);
        let (c, t) = (&c, &truth_codes);
        let sum: f64 =
            shadowed.iter().flat_map(|&k| (0..3).map(move |i| (f64::from(c[k][i]) - f64::from(t[k][i])).powi(2))).sum();
        (sum / (3 * shadowed.len()) as f64).sqrt()
    };
    let error = |session: &BackdropSession| {
        let (_, hdr) = composite(session, &object, true);
        assert!(hdr.iter().all(|v| v.is_finite() && v.min_element() >= 0.0), "a NaN or a negative");
        (rmse(&hdr), hdr)
    };
    let p = BackdropSession::with_photo(striped_map(sun_behind(), 0.25), &photo, cam, &settings(20.0)).unwrap();
    assert!(p.photo.unwrap().raised > 100, "the probe raised the clipped ground");
    let (ours, hdr) = error(&p);
    // the ground only darkens: no raised pixel shows through brighter than the photograph
    assert!(hdr.iter().all(|v| v.max_element() <= clip), "the composite clips where the camera did");
    let ground = (0..hdr.len()).filter(|&k| off_object(k)).count();
    let brighter = (0..hdr.len()).filter(|&k| off_object(k) && (hdr[k] - clipped[k]).max_element() > 1e-5).count();
    assert!(ground > 1000 && brighter == 0, "{brighter} ground pixels brighter than the photograph");
    // the same photograph read as unclipped: its clipped stripes' reflectance underestimated
    let naive_photo = real_scene::Photograph { clip: None, clipped: vec![0; clipped.len()], ..photo.clone() };
    let naive = error(
        &BackdropSession::with_photo(striped_map(sun_behind(), 0.25), &naive_photo, cam, &settings(20.0)).unwrap(),
    )
    .0;
    // and the unclipped photograph, for scale
    let full = rmse(&composite(&s, &object, true).1);
    assert!(ours < 0.7 * naive, "{ours} against {naive} read as unclipped");
    assert!(ours < 1.3 * full + 0.5, "{ours} against {full} unclipped");
}

#[test]
fn the_objects_underside_sees_its_own_shadow() {
    // a sun at the zenith: the ground under the sphere is in its shadow, so the light the
    // sphere's underside gets back from the ground is less than the captured ground would give;
    // its top, which sees the sky, is unchanged
    let at = Vec3::new(0.0, 0.0, 2.5);
    let object = sphere(at, 1.0);
    let s =
        BackdropSession::new(map(Some((Vec3::Y, 3e3))), camera(Vec3::new(0.0, 1.6, 0.0), at), &settings(20.0)).unwrap();
    let c = &s.compositor;
    assert!(c.object_shadows_probe, "the backdrop's probe sees the object's shadow");
    let frame = c.frame(&object, 50);
    let captured =
        differential_composite::FrameTransfers { object_irradiance: c.irradiance_at(object.centre), ..frame.clone() };
    let (down, down_captured) = (frame.object_irradiance_at(Vec3::NEG_Y), captured.object_irradiance_at(Vec3::NEG_Y));
    let (up, up_captured) = (frame.object_irradiance_at(Vec3::Y), captured.object_irradiance_at(Vec3::Y));
    assert!(
        luminance(down) < 0.8 * luminance(down_captured) && luminance(down) > 0.0,
        "underside: {down} against {down_captured} captured"
    );
    assert!((luminance(up) / luminance(up_captured) - 1.0).abs() < 0.05, "top: {up} against {up_captured}");
}
