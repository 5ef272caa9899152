//! Per-object transforms placed on the GPU against the same meshes moved on the CPU: the
//! G-buffer of a turned, scaled and moved object equals the G-buffer of its vertices moved and
//! uploaded afresh (positions, normals and object ids, a rounding apart), without a pipeline,
//! a submission or a wait; back at the identity it is bit for bit the first.

use glam::{Affine3A, Quat, Vec3};
use gpu::{GBufferPass, Gpu, SceneGeometry};

fn gpu() -> Gpu {
    Gpu::new().unwrap_or_else(|e| panic!("{e}"))
}

fn scene() -> scene::Scene {
    let mut s = scene::Scene::builtin("spheres_box").unwrap();
    (s.camera.width, s.camera.height) = (96, 72);
    s
}

/// `scene` with object `object`'s vertices and normals moved by `t` on the CPU.
fn posed(scene: &scene::Scene, object: usize, t: Affine3A) -> scene::Scene {
    let mut s = scene.clone();
    s.objects[object].mesh.transform(&t);
    s
}

/// The G-buffer's positions (w: object), shading normals and geometric normals.
fn gbuffer(gpu: &Gpu, geometry: &SceneGeometry, camera: &scene::Camera) -> [Vec<[f32; 4]>; 3] {
    let gb = GBufferPass::new(gpu).render(gpu, geometry, camera).unwrap();
    [
        gb.read_positions(gpu).unwrap(),
        gpu::read_texture_rgba(gpu, &gb.normal, 0).unwrap(),
        gb.read_geometric_normals(gpu).unwrap(),
    ]
}

#[test]
fn a_placed_object_gbuffer_equals_its_mesh_moved_on_the_cpu() {
    let gpu = gpu();
    let rest = scene();
    let object = rest.objects.iter().position(|o| o.name != "ground").unwrap();
    let mut geometry = SceneGeometry::upload(&gpu, &rest).unwrap();
    let first = gbuffer(&gpu, &geometry, &rest.camera);
    let t = Affine3A::from_scale_rotation_translation(
        Vec3::new(1.3, 0.8, 1.1),
        Quat::from_euler(glam::EulerRot::YXZ, 0.7, 0.2, -0.1),
        Vec3::new(0.2, 0.1, -0.3),
    );
    let before = gpu.counters();
    geometry.set_transform(&gpu, object, t).unwrap();
    let d = gpu.counters() - before;
    assert_eq!((d.submits, d.waits, d.pipelines), (0, 0, 0), "setting a transform submitted, waited or built");
    let moved = posed(&rest, object, t);
    let fresh = SceneGeometry::upload(&gpu, &moved).unwrap();
    let (lo, hi) = fresh.bounds;
    assert!(
        geometry.bounds.0.cmple(lo).all() && geometry.bounds.1.cmpge(hi).all(),
        "moved bounds do not hold the mesh"
    );
    let [pa, na, ga] = gbuffer(&gpu, &geometry, &rest.camera);
    let [pb, nb, gb] = gbuffer(&gpu, &fresh, &rest.camera);
    // the same pixels covered by the same objects, except where a rounding moves an edge
    let ids_differ = pa.iter().zip(&pb).filter(|(a, b)| a[3] != b[3]).count();
    assert!(ids_differ * 200 <= pa.len(), "{ids_differ} of {} pixels see another object", pa.len());
    let same: Vec<usize> = (0..pa.len()).filter(|&k| pa[k][3] == pb[k][3] && pa[k][3] >= 0.0).collect();
    assert!(same.len() * 2 > pa.len(), "the object must cover the view");
    let far = |a: &[[f32; 4]], b: &[[f32; 4]], tol: f32| {
        same.iter().filter(|&&k| (0..3).any(|c| (a[k][c] - b[k][c]).abs() > tol)).count()
    };
    // positions: a rounding of the transform; normals: of the normal matrix and normalisation
    let moved_pixels = same.iter().filter(|&&k| pa[k][3] == object as f32).count();
    assert!(moved_pixels > 100, "the moved object covers {moved_pixels} pixels");
    for (what, n) in [
        ("positions", far(&pa, &pb, 1e-5)),
        ("normals", far(&na, &nb, 1e-5)),
        ("geometric normals", far(&ga, &gb, 1e-5)),
    ] {
        assert!(n * 500 <= same.len(), "{what}: {n} of {} pixels apart", same.len());
    }
    assert!(pa != first[0], "the object did not move");
    // back at rest: bit for bit
    geometry.set_transform(&gpu, object, Affine3A::IDENTITY).unwrap();
    assert!(gbuffer(&gpu, &geometry, &rest.camera) == first, "back at the identity, the G-buffer differs");
    assert!(geometry.set_transform(&gpu, rest.objects.len(), t).is_err());
    assert!(geometry.set_transform(&gpu, object, Affine3A::from_translation(Vec3::splat(f32::INFINITY))).is_err());
}

#[test]
fn a_flattened_object_places_without_nan() {
    // a scale of zero along one axis (an object animated to vanish): finite positions, normals
    // finite or zero, never NaN
    let gpu = gpu();
    let rest = scene();
    let object = rest.objects.iter().position(|o| o.name != "ground").unwrap();
    let mut geometry = SceneGeometry::upload(&gpu, &rest).unwrap();
    geometry.set_transform(&gpu, object, Affine3A::from_scale(Vec3::new(1.0, 0.0, 1.0))).unwrap();
    let [p, n, g] = gbuffer(&gpu, &geometry, &rest.camera);
    assert!(p.iter().all(|v| v.iter().all(|c| !c.is_nan())));
    assert!(n.iter().chain(&g).all(|v| v.iter().all(|c| c.is_finite())));
}
