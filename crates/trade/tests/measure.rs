//! The measurement on the GPU (lavapipe in CI): every setting gets a row, shadows lower the
//! error, and shards measured on their own give the unsharded run's errors value for value.

use envmap_sphere::EnvMap;
use gpu::Gpu;
use trade::{
    Case, CompositeCase, CompositeSetting, Passes, PatchMaps, Plan, PointCase, PointSetting, Run, RunConfig, Setting,
    Shadow, Shard, measure, measure_composite, measure_point, merge,
};

const PLAN: Plan = Plan { size: (64, 48), truth_spp: 32, repeats: 1, supersample: 1, photo_spp: 4 };

fn settings() -> Vec<Setting> {
    let m = light_extract::DEFAULT_METHOD;
    vec![
        Setting::new(m, 4, Shadow::None),
        Setting::new(m, 4, Shadow::Maps { resolution: 256, pcf: 1 }),
        Setting::new(m, 4, Shadow::Wedges),
    ]
}

/// Two small maps: the default one halved, and the same turned half a revolution.
fn maps() -> Vec<(String, EnvMap)> {
    let d = envmap_sphere::default_map();
    let (w, h) = (d.width() / 4, d.height() / 4);
    let small = EnvMap::from_texels(w, h, |i, j| d.pixel(i * 4, j * 4));
    let turned = EnvMap::from_texels(w, h, |i, j| small.pixel((i + w / 2) % w, j));
    vec![("small.exr".into(), small), ("turned.exr".into(), turned)]
}

fn run(gpu: &Gpu, shard: Shard) -> Run {
    let mut rows = Vec::new();
    for (name, map) in shard.select(&maps(), |m| m.0.clone()) {
        let case = Case::new("three_boxes", &name, map, &PLAN).expect("case");
        rows.extend(measure(gpu, &case, &settings(), &PLAN, &mut |_| {}).expect("measured"));
    }
    let config = RunConfig {
        size: PLAN.size,
        truth_spp: PLAN.truth_spp,
        repeats: PLAN.repeats,
        supersample: PLAN.supersample,
        photo_spp: PLAN.photo_spp,
        adapter: gpu.describe(),
        preset: "test".into(),
    };
    let mut r = Run { config, shards: vec![shard.to_string()], rows };
    r.finish();
    r
}

#[test]
fn shadows_lower_the_error_and_shards_merge_to_the_whole_run() {
    let gpu = Gpu::new().unwrap_or_else(|e| panic!("{e}"));
    let whole = run(&gpu, Shard::ALL);
    assert_eq!(whole.rows.len(), 2 * settings().len());
    for map in ["small.exr", "turned.exr"] {
        let rmse =
            |s: &str| whole.rows.iter().find(|r| r.map == map && r.setting.ends_with(s)).map(|r| r.rmse).expect(s);
        // unshadowed lights are far off on three_boxes; either shadow technique is much closer
        assert!(rmse("/wedges") < 0.7 * rmse("/none"), "{map}: wedges {} none {}", rmse("/wedges"), rmse("/none"));
        assert!(rmse("/maps_256_pcf1") < 0.85 * rmse("/none"), "{map}");
        for r in whole.rows.iter().filter(|r| r.map == map) {
            assert!(r.ms.is_finite() && r.ms > 0.0 && r.rmse.is_finite() && r.flip.is_finite(), "{r:?}");
            assert!(r.truth_noise > 0.0 && r.truth_noise < r.rmse, "{r:?}");
        }
        assert!(whole.rows.iter().any(|r| r.map == map && r.pareto), "{map}: no front");
    }
    let shards: Vec<_> =
        (0..2).map(|i| (format!("shard{i}").into(), run(&gpu, Shard { index: i, count: 2 }))).collect();
    let mut merged = merge(&shards).expect("merge");
    // times are measured anew in every run; everything else must agree exactly
    let times = |r: &mut Run| {
        r.rows.iter_mut().for_each(|m| (m.ms, m.extract_ms, m.shadow_ms) = (0.0, 0.0, 0.0));
    };
    let mut whole = whole;
    times(&mut whole);
    times(&mut merged);
    // fronts depend on the times: compare them apart
    let fronts = |r: &mut Run| r.rows.iter_mut().for_each(|m| m.pareto = false);
    fronts(&mut whole);
    fronts(&mut merged);
    assert_eq!(merged.rows, whole.rows);
}

#[test]
fn point_maps_are_measured_against_ray_traced_visibility() {
    let gpu = Gpu::new().unwrap_or_else(|e| panic!("{e}"));
    let passes = Passes::new(&gpu).expect("passes");
    let plan = Plan { size: (96, 72), supersample: 2, ..PLAN };
    let case = PointCase::new(&gpu, &passes, "room", &plan).expect("room");
    let point = |shadow| Setting::Point(PointSetting { shadow });
    let settings = [
        point(Shadow::Paraboloid { resolution: 1024, pcf: 0, subdivide: true }),
        point(Shadow::Paraboloid { resolution: 1024, pcf: 0, subdivide: false }),
        point(Shadow::Cube { resolution: 592, pcf: 0 }),
        // other families' settings are left to their own cases
        Setting::new(light_extract::DEFAULT_METHOD, 4, Shadow::Wedges),
    ];
    let rows = measure_point(&gpu, &case, &settings, &plan, &mut |_| {}).expect("measured");
    assert_eq!(rows.len(), 3);
    let truth = case.truth();
    let rms = (truth.iter().map(|p| f64::from(p.length_squared())).sum::<f64>() / (3 * truth.len()) as f64).sqrt();
    assert!(rms > 0.0, "a lit room");
    for r in &rows {
        assert_eq!((r.shadowed, r.truth_noise, r.map.as_str()), (1, 0.0, "-"), "{r:?}");
        // a map that missed the room's shadows, or shadowed everything, would be far off
        assert!(r.rmse < 0.1 * rms, "{}: RMSE {} against the truth's RMS {rms}", r.setting, r.rmse);
    }
    // paper 004's caveat: a paraboloid bends straight edges, long triangles need subdividing
    assert!(rows[0].rmse < rows[1].rmse, "subdivided {} unsubdivided {}", rows[0].rmse, rows[1].rmse);
    let e = measure_point(&gpu, &case, &[point(Shadow::Wedges)], &plan, &mut |_| {})
        .expect_err("wedges do not shadow point lights here");
    assert!(e.to_string().contains("not a point-light technique"), "{e}");
    assert!(PointCase::new(&gpu, &passes, "three_boxes", &plan).is_err(), "no point lights");
}

#[test]
fn composites_count_what_the_hierarchy_and_the_maps_left_out() {
    let gpu = Gpu::new().unwrap_or_else(|e| panic!("{e}"));
    let plan = Plan { size: (64, 48), ..PLAN };
    let case = CompositeCase::new(&gpu, "ar_room", light_extract::DEFAULT_METHOD, &plan).expect("ar_room");
    let at = |passes, patch_maps| {
        Setting::Composite(CompositeSetting { patch_maps, ..CompositeSetting::new(passes, false) })
    };
    let settings = [at(1, PatchMaps::Paraboloid), at(0, PatchMaps::Paraboloid), at(0, PatchMaps::Cube)];
    let rows = measure_composite(&gpu, &case, &settings, &plan, &mut |_| {}).expect("measured");
    assert_eq!(rows.len(), 3);
    let count = |r: &trade::Measurement, what: &str| -> u64 {
        r.skipped.iter().filter(|(w, _)| w.contains(what)).map(|(_, n)| *n as u64).sum::<u64>()
            + r.culled.iter().filter(|(w, _)| w.contains(what)).map(|(_, n)| *n).sum::<u64>()
    };
    for r in &rows {
        assert!(r.rmse.is_finite() && r.flip.is_finite() && r.truth_noise > 0.0, "{r:?}");
        assert!(count(r, "shaft hierarchy excluded") > 0, "the sphere occludes few of the room's sources: {r:?}");
    }
    // one pass: every other occluded source merged into it; all passes: none merged
    assert_eq!(rows[0].shadowed, 1);
    assert_eq!(count(&rows[0], "merged") as usize + 1, rows[1].shadowed, "{:?} {:?}", rows[0], rows[1]);
    assert_eq!(count(&rows[1], "merged"), 0);
    // ar_room's sources are patches: each paraboloid map leaves a hemisphere out, a cube none
    assert_eq!(count(&rows[1], "hemispheres not rendered") as usize, rows[1].shadowed);
    assert_eq!(count(&rows[2], "hemispheres not rendered"), 0);
    // more passes: no worse (the representatives' shadows approach the sources')
    assert!(rows[1].rmse <= rows[0].rmse + 0.05, "{} {}", rows[1].rmse, rows[0].rmse);
}
