//! The measurement on the GPU (lavapipe in CI): every setting gets a row, shadows lower the
//! error, and shards measured on their own give the unsharded run's errors value for value.

use envmap_sphere::EnvMap;
use gpu::Gpu;
use trade::{Case, Passes, Plan, Run, RunConfig, Setting, Shadow, Shard, measure, merge};

const PLAN: Plan = Plan { size: (64, 48), truth_spp: 32, repeats: 1, supersample: 1 };

fn settings() -> Vec<Setting> {
    let m = trade::BEST_METHOD;
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

fn run(gpu: &Gpu, passes: &Passes, shard: Shard) -> Run {
    let mut rows = Vec::new();
    for (name, map) in shard.select(&maps(), |m| m.0.clone()) {
        let case = Case::new("three_boxes", &name, map, &PLAN).expect("case");
        rows.extend(measure(gpu, passes, &case, &settings(), &PLAN, &mut |_| {}).expect("measured"));
    }
    let config = RunConfig {
        size: PLAN.size,
        truth_spp: PLAN.truth_spp,
        repeats: PLAN.repeats,
        supersample: PLAN.supersample,
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
    let passes = Passes::new(&gpu).expect("passes");
    let whole = run(&gpu, &passes, Shard::ALL);
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
        (0..2).map(|i| (format!("shard{i}").into(), run(&gpu, &passes, Shard { index: i, count: 2 }))).collect();
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
