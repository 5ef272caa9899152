//! Shadow maps on the GPU (lavapipe where there is no GPU) against the CPU paraboloid rasterizer
//! and against ray-traced visibility from `ref-tracer`, with the extremes: the singular
//! direction, the hemisphere boundary, tiny and huge scales, a light inside an occluder.

use glam::Vec3;
use gpu::{GBuffer, GBufferPass, Gpu, SceneGeometry, ShadowGeometry, VisibilityLayers, scene_triangles};
use ref_tracer::SceneBvh;
use ref_tracer::visibility::{disagreement, light_visibility};
use scene::{LightShape, Material, Mesh, Object, Scene};
use shadowmap_paraboloid::cpu::{CpuParaboloidMap, lit};
use shadowmap_paraboloid::paraboloid::Hemisphere;
use shadowmap_paraboloid::{
    MapView, OnGpu, Rejection, ShadowMap, ShadowMapper, ShadowSettings, Technique, shadow_triangles,
};

fn gpu() -> Gpu {
    Gpu::new().unwrap_or_else(|e| panic!("{e}"))
}

fn room(w: u32, h: u32) -> Scene {
    let mut s = Scene::builtin("room").unwrap();
    s.camera.width = w;
    s.camera.height = h;
    s
}

struct Setup {
    gpu: Gpu,
    scene: Scene,
    gb: GBuffer,
    /// the G-buffer's points (position, geometric normal), read back once; background as NaN
    points: Vec<(Vec3, Vec3)>,
    mapper: ShadowMapper,
}

impl Setup {
    fn new(scene: Scene) -> Self {
        let gpu = gpu();
        let geometry = SceneGeometry::upload(&gpu, &scene).unwrap();
        let gb = GBufferPass::new(&gpu).render(&gpu, &geometry, &scene.camera).unwrap();
        let points = gb.read_points(&gpu).unwrap();
        let mapper = ShadowMapper::new(&gpu);
        Self { gpu, scene, gb, points, mapper }
    }

    fn map(&self, triangles: &[[Vec3; 3]], light: &MapView, t: Technique, s: &ShadowSettings) -> ShadowMap {
        let triangles = shadow_triangles(triangles, light, t, s);
        let geometry = ShadowGeometry::upload(&self.gpu, &triangles, ShadowGeometry::CHUNK_TRIANGLES).unwrap();
        let map = self.mapper.render(&self.gpu, &geometry, light, t, s).unwrap();
        // The map reports the rejection it ran: clip distances exactly where the device has them
        // (so a test asking for them says which path it checked), a discard otherwise.
        let ran = if self.gpu.has_clip_distances() { s.rejection } else { Rejection::Discard };
        assert_eq!(map.settings.rejection, ran, "{}", self.gpu.describe());
        map
    }

    fn mask(&self, map: &ShadowMap) -> Vec<f32> {
        let (w, h) = self.gb.size();
        let vis = VisibilityLayers::new(&self.gpu, w, h, 1).unwrap();
        self.mapper.visibility(&self.gpu, map, &self.gb, &vis.layer(0)).unwrap();
        vis.read(&self.gpu, 0).unwrap()
    }

    fn truth(&self, light: LightShape) -> Vec<Option<bool>> {
        light_visibility(&SceneBvh::new(&self.scene), &self.points, light)
    }
}

/// The adapters this suite runs on, lavapipe (CI) and NVIDIA's, have `CLIP_DISTANCES`: there
/// the clip-distance tests must run the clip-distance path, not fall back to the discard.
#[test]
fn the_clip_distance_path_runs_where_the_adapter_has_it() {
    let gpu = gpu();
    let name = gpu.describe().to_lowercase();
    if name.contains("llvmpipe") || name.contains("nvidia") {
        assert!(gpu.has_clip_distances(), "{name}: CLIP_DISTANCES not enabled");
    }
    let s = Setup::new(room(8, 8));
    let tris = scene_triangles(&s.scene);
    let light = MapView::omni(s.scene.point_lights[0].position);
    for rejection in [Rejection::ClipDistance, Rejection::Discard] {
        let settings = ShadowSettings { resolution: 64, rejection, ..ShadowSettings::default() };
        // `Setup::map` asserts the rejection that ran
        let map = s.map(&tris, &light, Technique::DualParaboloid, &settings);
        assert!(map.triangles_drawn() > 0);
    }
}

#[test]
fn gpu_paraboloid_maps_match_the_cpu_rasterizer() {
    let s = Setup::new(room(8, 8));
    let tris = scene_triangles(&s.scene);
    let light = MapView::omni(s.scene.point_lights[0].position);
    for rejection in [Rejection::ClipDistance, Rejection::Discard] {
        let settings =
            ShadowSettings { resolution: 256, rejection, subdivide_angle: None, ..ShadowSettings::default() };
        let map = s.map(&tris, &light, Technique::DualParaboloid, &settings);
        let frame = map.frame.unwrap();
        for (layer, h) in [Hemisphere::Front, Hemisphere::Back].into_iter().enumerate() {
            let gpu_depth = map.read_layer(&s.gpu, layer as u32).unwrap();
            let cpu = CpuParaboloidMap::rasterize(&frame, h, 256, &tris);
            let off = gpu_depth.iter().zip(&cpu.depth).filter(|(g, c)| (*g - *c).abs() > 1e-4).count();
            let frac = off as f64 / gpu_depth.len() as f64;
            assert!(frac < 0.01, "{rejection:?} {h:?}: {:.2} % of texels differ", frac * 100.0);
        }
    }
}

#[test]
fn gpu_visibility_matches_the_cpu_shadow_test() {
    let s = Setup::new(room(160, 120));
    let tris = scene_triangles(&s.scene);
    let light = MapView::omni(s.scene.point_lights[0].position);
    let settings = ShadowSettings { resolution: 512, subdivide_angle: None, ..ShadowSettings::default() };
    let map = s.map(&tris, &light, Technique::DualParaboloid, &settings);
    let frame = map.frame.unwrap();
    let cpu_maps = [Hemisphere::Front, Hemisphere::Back].map(|h| CpuParaboloidMap::rasterize(&frame, h, 512, &tris));
    let mask = s.mask(&map);
    let truth: Vec<Option<bool>> = s
        .points
        .iter()
        .map(|&(p, n)| if p.is_finite() { lit(&cpu_maps, p, n, settings.bias_texels) } else { None })
        .collect();
    let (frac, n) = disagreement(&mask, &truth);
    assert!(n > 10_000 && frac < 0.005, "GPU and CPU shadow tests disagree on {:.3} % of {n} pixels", frac * 100.0);
}

#[test]
fn paraboloid_and_cube_agree_with_ray_traced_visibility_in_the_room() {
    let s = Setup::new(room(320, 240));
    let tris = scene_triangles(&s.scene);
    let position = s.scene.point_lights[0].position;
    let truth = s.truth(LightShape::point(position));
    for (technique, res) in [(Technique::DualParaboloid, 1024), (Technique::Cube, 592)] {
        for rejection in [Rejection::ClipDistance, Rejection::Discard] {
            let settings = ShadowSettings { resolution: res, rejection, ..ShadowSettings::default() };
            let map = s.map(&tris, &MapView::omni(position), technique, &settings);
            let (frac, n) = disagreement(&s.mask(&map), &truth);
            assert!(n > 50_000 && frac < 0.002, "{technique:?} {rejection:?}: {:.3} % disagree", frac * 100.0);
        }
    }
}

#[test]
fn a_hemispherical_light_gets_one_map_and_lights_only_its_hemisphere() {
    let s = Setup::new(room(160, 120));
    let tris = scene_triangles(&s.scene);
    let position = s.scene.point_lights[0].position;
    let light = MapView::Point { position, hemisphere: Some(Vec3::NEG_Y) };
    let map = s.map(&tris, &light, Technique::DualParaboloid, &ShadowSettings::default());
    assert_eq!(map.views.len(), 1);
    let mask = s.mask(&map);
    let points = &s.points;
    let truth = s.truth(LightShape::point(position));
    let (mut above, mut wrong_below) = (0, 0);
    for ((m, (p, _)), t) in mask.iter().zip(points).zip(&truth) {
        if p.is_finite() && p.y > position.y + 0.05 {
            above += 1;
            assert_eq!(*m, 0.0, "{p} is behind the light's hemisphere");
        } else if let Some(t) = t {
            wrong_below += usize::from((*m > 0.5) != *t);
        }
    }
    assert!(above > 1000, "the view sees the ceiling");
    assert!((wrong_below as f64) < 0.01 * mask.len() as f64, "{wrong_below} pixels wrong below the light");
}

#[test]
fn the_singular_direction_leaves_the_front_map_clean() {
    // An occluder straight behind the front map's axis (z -> -1) lands at the back map's centre
    // and nowhere in the front map, with both rejection modes.
    let s = Setup::new(room(8, 8));
    let position = Vec3::new(0.0, 2.0, 0.0);
    let occluder = Mesh::cuboid(Vec3::new(-0.05, 2.5, -0.05), Vec3::new(0.05, 2.6, 0.05));
    let tris: Vec<[Vec3; 3]> = (0..occluder.indices.len()).map(|t| occluder.triangle(t)).collect();
    for rejection in [Rejection::ClipDistance, Rejection::Discard] {
        let settings = ShadowSettings { resolution: 128, rejection, cull: false, ..ShadowSettings::default() };
        // front axis -Y: the occluder above is at z = -1 of the front map
        let map = s.map(&tris, &MapView::Point { position, hemisphere: None }, Technique::DualParaboloid, &settings);
        let front = map.read_layer(&s.gpu, 0).unwrap();
        assert!(front.iter().all(|d| *d == 1.0), "{rejection:?}: front map drew the occluder behind it");
        let back = map.read_layer(&s.gpu, 1).unwrap();
        assert!(
            back[64 * 128 + 64] < 1.0 && back.iter().all(|d| d.is_finite()),
            "{rejection:?}: back map centre empty"
        );
    }
}

#[test]
fn an_occluder_across_the_hemisphere_boundary_shadows_both_sides() {
    // A wall standing in the rim plane y = 2 of a light facing down: half in each map.
    let mut scene = room(160, 120);
    scene.objects.push(Object {
        name: "screen".into(),
        mesh: Mesh::cuboid(Vec3::new(0.8, 1.2, -1.0), Vec3::new(1.0, 2.8, 1.0)),
        material: Material::lambert(0.5),
    });
    let s = Setup::new(scene);
    let tris = scene_triangles(&s.scene);
    let position = s.scene.point_lights[0].position;
    let truth = s.truth(LightShape::point(position));
    let plain = ShadowSettings { subdivide_angle: None, ..ShadowSettings::default() };
    let map = s.map(&tris, &MapView::omni(position), Technique::DualParaboloid, &plain);
    let (frac, _) = disagreement(&s.mask(&map), &truth);
    // the boundary is where linear interpolation of the non-linear mapping is worst
    let map = s.map(&tris, &MapView::omni(position), Technique::DualParaboloid, &ShadowSettings::default());
    let (frac_sub, _) = disagreement(&s.mask(&map), &truth);
    assert!(frac_sub < 0.002 && frac_sub * 4.0 < frac, "disagreement {frac} plain, {frac_sub} subdivided");
}

#[test]
fn tiny_and_huge_scenes_shadow_alike() {
    let mut fracs = Vec::new();
    for scale in [1e-3f32, 1.0, 1e3] {
        let mut scene = room(160, 120);
        for o in &mut scene.objects {
            for p in &mut o.mesh.positions {
                *p *= scale;
            }
        }
        scene.camera.eye *= scale;
        scene.camera.target *= scale;
        scene.point_lights[0].position *= scale;
        let s = Setup::new(scene);
        let position = s.scene.point_lights[0].position;
        let settings = ShadowSettings { near: 0.01 * scale, ..ShadowSettings::default() };
        let map = s.map(&scene_triangles(&s.scene), &MapView::omni(position), Technique::DualParaboloid, &settings);
        let (frac, n) = disagreement(&s.mask(&map), &s.truth(LightShape::point(position)));
        assert!(n > 10_000);
        fracs.push(frac);
    }
    assert!(fracs.iter().all(|f| *f < 0.002), "disagreement at scales 1e-3, 1, 1e3: {fracs:?}");
}

#[test]
fn a_light_inside_an_occluder_shadows_everything_outside() {
    let mut scene = room(160, 120);
    let position = scene.point_lights[0].position;
    scene.objects.push(Object {
        name: "lamp shade".into(),
        mesh: Mesh::cuboid(position - Vec3::splat(0.2), position + Vec3::splat(0.2)),
        material: Material::lambert(0.5),
    });
    let s = Setup::new(scene);
    let tris = scene_triangles(&s.scene);
    for technique in [Technique::DualParaboloid, Technique::Cube] {
        let map = s.map(&tris, &MapView::omni(position), technique, &ShadowSettings::fast());
        let mask = s.mask(&map);
        let points = &s.points;
        let outside: Vec<f32> = mask
            .iter()
            .zip(points)
            .filter(|(_, (p, _))| p.is_finite() && (*p - position).abs().max_element() > 0.25)
            .map(|(m, _)| *m)
            .collect();
        assert!(outside.len() > 10_000 && outside.iter().all(|m| *m == 0.0), "{technique:?}: light leaks out");
    }
}

#[test]
fn orthographic_map_of_a_distant_light_agrees_with_ray_tracing() {
    let mut scene = Scene::builtin("spheres_box").unwrap();
    scene.camera.width = 320;
    scene.camera.height = 240;
    // the ground is 100 m wide: shadow only what is near the objects, where the view looks
    scene.objects[0].mesh =
        Mesh::quad(Vec3::new(-6.0, 0.0, 6.0), Vec3::new(12.0, 0.0, 0.0), Vec3::new(0.0, 0.0, -12.0), 1, 1);
    let s = Setup::new(scene);
    let tris = scene_triangles(&s.scene);
    let dir = Vec3::new(0.4, 0.8, 0.3).normalize();
    let map = s.map(&tris, &MapView::Distant { direction: dir }, Technique::Orthographic, &ShadowSettings::quality());
    let (frac, n) = disagreement(&s.mask(&map), &s.truth(LightShape::directional(dir)));
    assert!(n > 30_000 && frac < 0.01, "{:.3} % disagree", frac * 100.0);
}

#[test]
fn mismatched_technique_and_light_is_an_error() {
    let s = Setup::new(room(8, 8));
    let tris = scene_triangles(&s.scene);
    let geometry = ShadowGeometry::upload(&s.gpu, &tris, 64).unwrap();
    let err = s
        .mapper
        .render(&s.gpu, &geometry, &MapView::Distant { direction: Vec3::Y }, Technique::Cube, &ShadowSettings::fast())
        .err()
        .expect("refused");
    assert!(err.to_string().contains("does not fit"), "{err}");
}

#[test]
fn pcf_softens_only_the_shadow_edges() {
    let s = Setup::new(room(320, 240));
    let tris = scene_triangles(&s.scene);
    let light = MapView::omni(s.scene.point_lights[0].position);
    let hard = s.mask(&s.map(&tris, &light, Technique::DualParaboloid, &ShadowSettings::default()));
    let pcf = ShadowSettings { pcf_radius: 2, ..ShadowSettings::default() };
    let soft = s.mask(&s.map(&tris, &light, Technique::DualParaboloid, &pcf));
    let partial = soft.iter().filter(|v| **v > 0.02 && **v < 0.98).count();
    assert!(partial > 100, "{partial} fractional pixels: PCF did not filter");
    // away from edges PCF agrees with the hard test; the two differ on few pixels
    let flipped = hard.iter().zip(&soft).filter(|(h, v)| (**h > 0.5) != (**v > 0.5)).count();
    assert!(flipped * 100 < hard.len(), "{flipped} pixels changed side");
    assert!(partial * 10 < hard.len(), "{partial} fractional pixels: more than the edges");
}

#[test]
fn maps_recorded_into_one_submission_equal_maps_rendered_one_by_one() {
    // a frame batches many maps (the compositor's representatives); each must hold exactly the
    // depths it holds when rendered and waited for alone
    let s = Setup::new(room(8, 8));
    let tris = scene_triangles(&s.scene);
    let geometry = ShadowGeometry::upload(&s.gpu, &tris, ShadowGeometry::CHUNK_TRIANGLES).unwrap();
    let settings = ShadowSettings { resolution: 64, subdivide_angle: None, ..ShadowSettings::default() };
    let p = s.scene.point_lights[0].position;
    let lights = [
        (MapView::omni(p), Technique::DualParaboloid),
        (MapView::Point { position: p + Vec3::X, hemisphere: Some(Vec3::NEG_Y) }, Technique::DualParaboloid),
        (MapView::omni(p - Vec3::X), Technique::Cube),
        (MapView::Distant { direction: Vec3::new(0.3, 1.0, 0.2) }, Technique::Orthographic),
    ];
    // the first two into one shared array (its layers 1.. : layer 0 stays unused), the others
    // into textures of their own
    let shared = gpu::render_target(&s.gpu, "shared", (64, 64, 4), shadowmap_paraboloid::DEPTH_FORMAT).unwrap();
    let mut encoder = s.gpu.encoder("batch");
    let mut batched: Vec<ShadowMap> = Vec::new();
    for (k, (l, t)) in lights.iter().enumerate() {
        let target = (k < 2).then(|| (&shared, 1 + batched.iter().map(|m| m.views.len() as u32).sum::<u32>()));
        batched.push(
            s.mapper.record(&s.gpu, &mut encoder, &geometry, l, *t, &settings, target, OnGpu::default()).unwrap(),
        );
    }
    s.gpu.submit_and_wait(encoder).unwrap();
    assert_eq!((batched[0].first_layer, batched[1].first_layer), (1, 3));
    // a target without room for the map is refused, not overrun
    let mut encoder = s.gpu.encoder("too small");
    let e = s.mapper.record(
        &s.gpu,
        &mut encoder,
        &geometry,
        &lights[2].0,
        Technique::Cube,
        &settings,
        Some((&shared, 0)),
        OnGpu::default(),
    );
    assert!(e.is_err(), "six cube faces in a four-layer array");
    for ((l, t), b) in lights.iter().zip(&batched) {
        let alone = s.mapper.render(&s.gpu, &geometry, l, *t, &settings).unwrap();
        assert_eq!(b.views.len(), alone.views.len(), "{t:?}");
        // what a batch sizes its array by before recording
        assert_eq!(ShadowMapper::view_count(l, *t) as usize, alone.views.len(), "{t:?}");
        for layer in 0..alone.views.len() as u32 {
            let (x, y) = (b.read_layer(&s.gpu, layer).unwrap(), alone.read_layer(&s.gpu, layer).unwrap());
            assert!(x.iter().any(|d| *d < 1.0), "{t:?} layer {layer}: nothing drawn");
            assert_eq!(x, y, "{t:?} layer {layer}");
            assert_eq!(b.views[layer as usize].triangles_drawn, alone.views[layer as usize].triangles_drawn);
        }
    }
}
