//! The one technique builder (lavapipe in CI): each spec builds the technique it names, the
//! same layer bit for bit as the technique made by hand, and map specs share one set of
//! pipelines.

use glam::Vec3;
use gpu::{GBufferPass, Gpu, LightShape, Receivers, SceneGeometry, ShadowTechnique, VisibilityLayers};
use penumbra_wedge::{WedgeSettings, Wedges};
use shadowmap_paraboloid::{MapTechnique, Pcss, ShadowSettings, Technique};
use trade::{TechniqueBuilder, TechniqueSpec};

fn layer(gpu: &Gpu, scene: &scene::Scene, technique: &dyn ShadowTechnique) -> Vec<f32> {
    let geometry = SceneGeometry::upload(gpu, scene).unwrap();
    let gb = GBufferPass::new(gpu).render(gpu, &geometry, &scene.camera).unwrap();
    let points = gb.read_points(gpu).unwrap();
    let light = LightShape::Distant { direction: Vec3::new(0.45, 1.0, 0.3).normalize(), half_angle: 0.1 };
    let vis = VisibilityLayers::new(gpu, scene.camera.width, scene.camera.height, 1).unwrap();
    gpu::render_visibility(gpu, technique, &Receivers::new(&gb, &points), &[light], &[], &vis).unwrap();
    vis.read(gpu, 0).unwrap()
}

fn scene() -> scene::Scene {
    let mut s = scene::Scene::builtin("three_boxes").unwrap();
    (s.camera.width, s.camera.height) = (64, 48);
    s
}

#[test]
fn each_spec_builds_the_technique_it_names() {
    let gpu = Gpu::new().unwrap_or_else(|e| panic!("{e}"));
    let scene = scene();
    let hard = ShadowSettings { resolution: 256, pcf_radius: 1, ..ShadowSettings::default() };
    let pcss = ShadowSettings { pcf_radius: 0, pcss: Some(Pcss::default()), ..hard };
    let wedges = WedgeSettings::default();
    let cases: [(TechniqueSpec, Box<dyn ShadowTechnique>); 3] = [
        (
            TechniqueSpec::orthographic(hard, 1),
            Box::new(MapTechnique::new(&gpu, &scene, Technique::Orthographic, hard, 1).unwrap()),
        ),
        (
            TechniqueSpec::orthographic(pcss, 4),
            Box::new(MapTechnique::new(&gpu, &scene, Technique::Orthographic, pcss, 4).unwrap()),
        ),
        (TechniqueSpec::Wedges(wedges), Box::new(Wedges::new(&gpu, &scene, wedges))),
    ];
    let mut builder = TechniqueBuilder::new(&gpu, &scene);
    let mut layers = Vec::new();
    for (spec, by_hand) in &cases {
        let built = builder.build(spec).unwrap();
        let (a, b) = (layer(&gpu, &scene, built.as_ref()), layer(&gpu, &scene, by_hand.as_ref()));
        assert_eq!(a, b, "{spec:?}: the builder's layer differs from the technique made by hand");
        assert!(a.iter().any(|v| *v < 0.5), "{spec:?}: no shadow on three_boxes");
        layers.push(a);
    }
    assert_ne!(layers[0], layers[1], "hard maps and 4 PCSS maps gave the same layer");
}

#[test]
fn map_specs_share_one_set_of_pipelines() {
    let gpu = Gpu::new().unwrap_or_else(|e| panic!("{e}"));
    let scene = scene();
    let hard = ShadowSettings { resolution: 256, ..ShadowSettings::default() };
    let mut builder = TechniqueBuilder::new(&gpu, &scene);
    let before = gpu.counters();
    let first = builder.build(&TechniqueSpec::orthographic(hard, 1)).unwrap();
    let _ = layer(&gpu, &scene, first.as_ref());
    let after_first = gpu.counters();
    let second = builder.build(&TechniqueSpec::orthographic(ShadowSettings { pcf_radius: 2, ..hard }, 8)).unwrap();
    let _ = layer(&gpu, &scene, second.as_ref());
    let after_second = gpu.counters();
    // the G-buffer pass of `layer` is made each time: count only what the second costs beyond it
    let gbuffer = {
        let c = gpu.counters();
        let geometry = SceneGeometry::upload(&gpu, &scene).unwrap();
        let _ = GBufferPass::new(&gpu).render(&gpu, &geometry, &scene.camera).unwrap();
        gpu.counters().pipelines - c.pipelines
    };
    let first_cost = after_first.pipelines - before.pipelines;
    let second_cost = after_second.pipelines - after_first.pipelines;
    assert!(
        first_cost > gbuffer,
        "the first map technique made no pipelines ({first_cost} with the G-buffer's {gbuffer})"
    );
    assert_eq!(second_cost, gbuffer, "a second map spec made pipelines of its own");
}
