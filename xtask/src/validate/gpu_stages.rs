//! The GPU stages of `validate`: the extracted lights with orthographic shadow maps on
//! `spheres_box` (or the given scene), and the `room` point light's paraboloid and cube maps
//! against ray-traced visibility.

use super::{MaskRow, Plan};
use envmap_sphere::EnvMap;
use glam::Vec3;
use gpu::{
    Background, GBufferPass, Gpu, SceneGeometry, ShadeLight, ShadeParams, ShadingPass, ShadowGeometry, Visibility,
};
use ref_tracer::SceneBvh;
use ref_tracer::visibility::{VisibilityLight, light_visibility};
use shadowmap_paraboloid::{
    ShadowLight, ShadowMapper, ShadowSettings, Technique, disagreement, equal_texel_variants, shadow_triangles,
};
use std::time::Instant;

/// Sphere around what the camera sees: the mean visible position and the 95th percentile of
/// distances to it (the rest, far away, is left unshadowed).
fn view_focus(points: &[(Vec3, Vec3)]) -> Option<(Vec3, f32)> {
    let pts: Vec<Vec3> = points.iter().map(|(p, _)| *p).filter(|p| p.is_finite()).collect();
    if pts.is_empty() {
        return None;
    }
    let c = pts.iter().copied().sum::<Vec3>() / pts.len() as f32;
    let mut d: Vec<f32> = pts.iter().map(|p| p.distance(c)).collect();
    d.sort_by(f32::total_cmp);
    Some((c, d[(d.len() * 95 / 100).min(d.len() - 1)]))
}

pub(super) type GpuImages = (Vec<Vec3>, Vec<Vec3>, f64, f64);

/// The GPU passes, built once per run.
pub(super) struct Passes {
    pub(super) gbuffer: GBufferPass,
    pub(super) shadows: ShadowMapper,
    pub(super) shading: ShadingPass,
}

pub(super) fn gpu_render(
    gpu: &Gpu,
    passes: &Passes,
    scene: &scene::Scene,
    map: &EnvMap,
    d: &light_extract::Decomposition,
    plan: &Plan,
) -> Result<GpuImages, String> {
    let e = |e: gpu::GpuError| e.to_string();
    let start = Instant::now();
    let geometry = SceneGeometry::upload(gpu, scene).map_err(e)?;
    let gb = passes.gbuffer.render(gpu, &geometry, &scene.camera).map_err(e)?;
    let points = gb.read_points(gpu).map_err(e)?;
    let tris = gpu::scene_triangles(scene);
    let shadow_geometry = ShadowGeometry::upload(gpu, &tris, ShadowGeometry::CHUNK_TRIANGLES).map_err(e)?;
    let mapper = &passes.shadows;
    let settings = ShadowSettings { focus: view_focus(&points), ..plan.shadow };
    let lights: Vec<ShadeLight> = d.lights.iter().map(|l| ShadeLight::from(&l.light)).collect();
    let (w, h) = gb.size();
    let vis = Visibility::new(gpu, w, h, lights.len() as u32).map_err(e)?;
    let mut shadow_ms = 0.0;
    for (k, l) in d.lights.iter().enumerate() {
        // model only what the scene requires: a light that no visible surface faces lights
        // nothing (the shading pass skips it per pixel), so it needs no shadow map
        if !points.iter().any(|(p, n)| p.is_finite() && n.dot(l.light.direction) > 0.0) {
            continue;
        }
        let light = ShadowLight::Distant { direction: l.light.direction };
        let m = mapper.render(gpu, &shadow_geometry, &light, Technique::Orthographic, &settings).map_err(e)?;
        shadow_ms += m.time.as_secs_f64() * 1e3;
        mapper.visibility(gpu, &m, &gb, &vis.layer(k as u32)).map_err(e)?;
    }
    let pass = &passes.shading;
    let background = Background::upload(gpu, map).map_err(e)?;
    let params = ShadeParams { lights: &lights, ambient: Some(&d.ambient_sh), background: Some(&background) };
    let image = pass.render(gpu, &geometry, &gb, &params, &vis).map_err(e)?;
    let seconds = start.elapsed().as_secs_f64();
    let lit = Visibility::new(gpu, w, h, lights.len() as u32).map_err(e)?;
    let unshadowed = pass.render(gpu, &geometry, &gb, &params, &lit).map_err(e)?;
    Ok((image, unshadowed, seconds, shadow_ms))
}

pub(super) type MaskImages = (Vec<f32>, Vec<f32>, Vec<Option<bool>>, (u32, u32));

pub(super) fn room_masks(
    gpu: &Gpu,
    passes: &Passes,
    plan: &Plan,
) -> Result<(Vec<MaskRow>, MaskImages, Vec<SizeRow>, gpu::Clock), String> {
    let e = |e: gpu::GpuError| e.to_string();
    let mut scene = scene::Scene::builtin("room").map_err(|e| e.to_string())?;
    (scene.camera.width, scene.camera.height) = plan.room_size;
    let geometry = SceneGeometry::upload(gpu, &scene).map_err(e)?;
    let gb = passes.gbuffer.render(gpu, &geometry, &scene.camera).map_err(e)?;
    let points = gb.read_points(gpu).map_err(e)?;
    let position = scene.point_lights[0].position;
    let truth = light_visibility(&SceneBvh::new(&scene), &points, VisibilityLight::Point(position));
    let tris = gpu::scene_triangles(&scene);
    let light = ShadowLight::omni(position);
    let mapper = &passes.shadows;
    let (w, h) = plan.room_size;
    let vis = Visibility::new(gpu, w, h, 1).map_err(e)?;
    let mut rows = Vec::new();
    let (mut paraboloid_mask, mut cube_mask) = (Vec::new(), Vec::new());
    let mut clock = gpu::Clock::WallTime;
    for v in equal_texel_variants() {
        let (technique, settings) = (v.technique, v.settings);
        let t = shadow_triangles(&tris, &light, technique, &settings);
        let g = ShadowGeometry::upload(gpu, &t, ShadowGeometry::CHUNK_TRIANGLES).map_err(e)?;
        let mut times = Vec::new();
        let mut last = None;
        for _ in 0..plan.repeats.max(1) {
            let m = mapper.render(gpu, &g, &light, technique, &settings).map_err(e)?;
            times.push(m.time.as_secs_f64() * 1e3);
            clock = m.clock;
            last = Some(m);
        }
        times.sort_by(f64::total_cmp);
        let m = last.ok_or("no shadow map")?;
        mapper.visibility(gpu, &m, &gb, &vis.layer(0)).map_err(e)?;
        let mask = vis.read(gpu, 0).map_err(e)?;
        let (frac, _) = disagreement(&mask, &truth);
        if v.name == "paraboloid_1024_clip_subdivided" {
            paraboloid_mask = mask;
        } else if v.name == "cube_592" {
            cube_mask = mask;
        }
        rows.push(MaskRow {
            name: v.name,
            technique,
            texels: u64::from(settings.resolution) * u64::from(settings.resolution) * m.views.len() as u64,
            disagreement: frac,
            gpu_ms: times[times.len() / 2],
            triangles: m.triangles_drawn(),
        });
    }
    // the paper's caveat: error against the angle triangles span from the light
    let mut sizes = Vec::new();
    for angle in [None, Some(0.8), Some(0.4), Some(0.2), Some(0.1), Some(0.05)] {
        let settings = ShadowSettings { subdivide_angle: angle, ..ShadowSettings::default() };
        let t = shadow_triangles(&tris, &light, Technique::DualParaboloid, &settings);
        let widest = shadowmap_paraboloid::subdivide::max_edge_angle(&t, position);
        let g = ShadowGeometry::upload(gpu, &t, ShadowGeometry::CHUNK_TRIANGLES).map_err(e)?;
        let m = mapper.render(gpu, &g, &light, Technique::DualParaboloid, &settings).map_err(e)?;
        mapper.visibility(gpu, &m, &gb, &vis.layer(0)).map_err(e)?;
        let (frac, _) = disagreement(&vis.read(gpu, 0).map_err(e)?, &truth);
        sizes.push(SizeRow { widest, triangles: t.len(), disagreement: frac });
    }
    Ok((rows, (paraboloid_mask, cube_mask, truth, plan.room_size), sizes, clock))
}

/// One row of the error-against-triangle-size sweep.
pub(super) struct SizeRow {
    pub(super) widest: f32,
    pub(super) triangles: usize,
    pub(super) disagreement: f64,
}
