//! A G-buffer made from a renderer's depth texture and view (`DepthGBufferPass`) against the
//! G-buffer the same view rasterizes: the same background, positions within rounding of the
//! unprojection, geometric normals equal on flat faces away from their edges; for a camera's,
//! a jittered and an orthographic view. Malformed inputs are refused.

use glam::{Mat4, Vec3, Vec4};
use gpu::{DepthGBufferPass, GBuffer, GBufferPass, Gpu, SceneGeometry, View};

fn reversed(p: Mat4) -> Mat4 {
    Mat4::from_cols(Vec4::X, Vec4::Y, Vec4::new(0.0, 0.0, -1.0, 0.0), Vec4::new(0.0, 0.0, 1.0, 1.0)) * p
}

fn points(gpu: &Gpu, gb: &GBuffer) -> Vec<(Vec3, Vec3)> {
    gb.read_points(gpu).unwrap()
}

#[test]
fn a_gbuffer_from_depth_has_the_rasterized_positions_and_normals() {
    let gpu = Gpu::new().unwrap_or_else(|e| panic!("{e}"));
    let mut scene = scene::Scene::builtin("three_boxes").unwrap();
    (scene.camera.width, scene.camera.height) = (160, 120);
    let c = scene.camera;
    let geometry = SceneGeometry::upload(&gpu, &scene).unwrap();
    let passes = (GBufferPass::new(&gpu), DepthGBufferPass::new(&gpu));
    let reach = c.eye.distance(c.target);
    let half = reach * (c.hfov_degrees.to_radians() * 0.5).tan();
    let ortho = View::new(
        glam::camera::rh::view::look_at_mat4(
            c.target + Vec3::new(0.3, 1.0, 0.6).normalize() * reach,
            c.target,
            Vec3::Y,
        ),
        reversed(glam::camera::rh::proj::directx::orthographic(
            -half,
            half,
            -0.75 * half,
            0.75 * half,
            0.0,
            4.0 * reach,
        )),
        (160, 120),
    )
    .unwrap();
    let camera = {
        let mut encoder = gpu.encoder("camera");
        let gb = passes.0.record(&gpu, &mut encoder, &geometry, &c).unwrap();
        gpu.submit_and_wait(encoder).unwrap();
        gb.view
    };
    for (name, view) in [("camera", camera), ("jittered", camera.jittered(0.3, 0.45)), ("orthographic", ortho)] {
        let mut encoder = gpu.encoder("gbuffers");
        let rasterized = passes.0.record_view(&gpu, &mut encoder, &geometry, &view).unwrap();
        let made = passes.1.record(&gpu, &mut encoder, &rasterized.depth, &view, None).unwrap();
        gpu.submit_and_wait(encoder).unwrap();
        let (a, b) = (points(&gpu, &rasterized), points(&gpu, &made));
        let (mut seen, mut flat, mut bent) = (0, 0, 0);
        let (w, h) = view.size();
        for (k, ((pa, na), (pb, nb))) in a.iter().zip(&b).enumerate() {
            assert_eq!(pa.is_finite(), pb.is_finite(), "{name}: pixel {k} background in one only");
            if !pa.is_finite() {
                continue;
            }
            seen += 1;
            let scale = if view.is_orthographic() { reach } else { pa.distance(view.eye()) };
            assert!(pa.distance(*pb) <= 1e-4 * scale, "{name}: pixel {k}: {pa} vs {pb}");
            // normals of pixels whose 3 x 3 neighbourhood shows one face are the face's
            let (x, y) = ((k as u32 % w) as i64, (k as u32 / w) as i64);
            let one_face = (-1..=1).all(|dy| {
                (-1..=1).all(|dx| {
                    let (u, v) = (x + dx, y + dy);
                    u >= 0 && v >= 0 && u < w as i64 && v < h as i64 && {
                        let (q, nq) = a[(v * w as i64 + u) as usize];
                        q.is_finite() && nq.dot(*na) > 1.0 - 1e-6
                    }
                })
            });
            if one_face {
                flat += 1;
                bent += usize::from(na.dot(*nb) < 1.0 - 1e-4);
            }
        }
        assert!(seen > 5000 && flat > seen / 2, "{name}: {seen} pixels see the scene, {flat} inside faces");
        assert!(bent * 1000 <= flat, "{name}: {bent} of {flat} face pixels' normals differ by more than 1e-4");
    }
}

#[test]
fn malformed_depth_inputs_are_refused() {
    let gpu = Gpu::new().unwrap_or_else(|e| panic!("{e}"));
    let pass = DepthGBufferPass::new(&gpu);
    let c = scene::Camera { eye: Vec3::Z, target: Vec3::ZERO, up: Vec3::Y, hfov_degrees: 60.0, width: 8, height: 8 };
    let view = View::from_camera(&c, 1e-3);
    let depth = gpu::render_target(&gpu, "depth", (8, 8, 1), wgpu::TextureFormat::Depth32Float).unwrap();
    let small = gpu::render_target(&gpu, "depth", (4, 8, 1), wgpu::TextureFormat::Depth32Float).unwrap();
    let colour = gpu::render_target(&gpu, "colour", (8, 8, 1), gpu::GBUFFER_FORMAT).unwrap();
    let half = gpu::render_target(&gpu, "normals", (8, 8, 1), wgpu::TextureFormat::Rgba16Float).unwrap();
    let mut encoder = gpu.encoder("refused");
    let e = pass.record(&gpu, &mut encoder, &small, &view, None).err().unwrap().to_string();
    assert!(e.contains("4x8") && e.contains("8x8"), "{e}");
    let e = pass.record(&gpu, &mut encoder, &colour, &view, None).err().unwrap().to_string();
    assert!(e.contains("no depth"), "{e}");
    let e = pass.record(&gpu, &mut encoder, &depth, &view, Some(&half)).err().unwrap().to_string();
    assert!(e.contains("Rgba16Float"), "{e}");
    assert!(pass.record(&gpu, &mut encoder, &depth, &view, Some(&colour)).is_ok());
}
