//! The trade's pure parts: Pareto fronts, the chooser, shards and their merge, the CSV and the
//! report, on measurements made up here (the GPU measurement is tested in `measure.rs`).

use trade::{
    ChooseError, CompositeSetting, Family, Measurement, Point, PointSetting, Run, RunConfig, Setting, Shadow, Shard,
    choose, merge, overall, pareto,
};

fn point(name: &str, ms: f64, rmse: f64) -> Point {
    Point { setting: name.into(), ms, rmse, flip: rmse / 2.0 }
}

fn row(shadow: Shadow, k: usize, scene: &str, map: &str, ms: f64, rmse: f64) -> Measurement {
    row_of(Setting::new(light_extract::DEFAULT_METHOD, k, shadow), scene, map, ms, rmse)
}

fn row_of(knobs: Setting, scene: &str, map: &str, ms: f64, rmse: f64) -> Measurement {
    let k = 8;
    Measurement {
        setting: knobs.name(),
        knobs,
        scene: scene.into(),
        map: map.into(),
        ms,
        clock: "test".into(),
        shadow_ms: ms / 2.0,
        shadow_clock: "test".into(),
        extract_ms: 1.0,
        rmse,
        flip: rmse / 2.0,
        truth_noise: 0.001,
        shadowed: k,
        skipped: vec![("why, with a comma".into(), 1)],
        culled: vec![("wedges".into(), 3)],
        pareto: false,
    }
}

fn config() -> RunConfig {
    RunConfig {
        size: (8, 6),
        truth_spp: 4,
        repeats: 1,
        supersample: 1,
        photo_spp: 2,
        adapter: "none".into(),
        preset: "test".into(),
    }
}

#[test]
fn pareto_keeps_exactly_the_undominated_points() {
    let pts = [(1.0, 5.0), (2.0, 3.0), (3.0, 4.0), (4.0, 1.0), (2.0, 3.0), (5.0, 1.0), (f64::NAN, 0.0)];
    // (3, 4) is beaten by (2, 3); (5, 1) by (4, 1); equal points stay; NaN is never on it
    assert_eq!(pareto(&pts), vec![true, true, false, true, true, false, false]);
    // brute force over random points: on the front iff nobody dominates
    let mut state = 12345u64;
    let mut next = || {
        state = state.wrapping_mul(6_364_136_223_846_793_005).wrapping_add(1_442_695_040_888_963_407);
        (state >> 40) as f64 / f64::from(1u32 << 24)
    };
    let pts: Vec<(f64, f64)> = (0..200).map(|_| (next(), next())).collect();
    let on = pareto(&pts);
    for (i, p) in pts.iter().enumerate() {
        let dominated = pts.iter().any(|q| q.0 <= p.0 && q.1 <= p.1 && q != p);
        assert_eq!(on[i], !dominated, "{p:?}");
    }
    assert!(on.iter().any(|&o| o));
}

#[test]
fn the_choice_is_on_the_front_and_within_the_budget() {
    let pts = vec![
        point("none", 0.5, 0.2),
        point("maps", 1.5, 0.05),
        point("pcss", 2.5, 0.06),
        point("wedges", 3.5, 0.03),
        point("multi", 9.0, 0.031),
    ];
    let front = trade::pareto_front(&pts);
    for budget in [0.5, 1.0, 2.0, 3.0, 4.0, 16.0, 1e9] {
        let c = choose(&pts, budget).expect("a setting fits");
        assert!(c.ms <= budget, "{budget}: {c:?}");
        assert!(front.iter().any(|f| f.setting == c.setting), "{budget}: {} is not on the front", c.setting);
        // nothing within the budget is more accurate
        assert!(pts.iter().filter(|p| p.ms <= budget).all(|p| p.rmse >= c.rmse));
    }
    assert_eq!(choose(&pts, 4.0).map(|p| p.setting), Ok("wedges".to_string()));
    assert_eq!(choose(&pts, 2.0).map(|p| p.setting), Ok("maps".to_string()));
}

#[test]
fn a_budget_below_every_setting_names_the_cheapest() {
    let pts = vec![point("maps", 1.5, 0.05), point("none", 0.5, 0.2)];
    let e = choose(&pts, 0.1).expect_err("nothing fits 0.1 ms");
    assert_eq!(e, ChooseError::OverBudget { budget: 0.1, cheapest: "none".into(), ms: 0.5 });
    assert!(e.to_string().contains("none") && e.to_string().contains("0.500 ms"), "{e}");
    assert_eq!(choose(&[], 4.0), Err(ChooseError::Empty));
    for bad in [0.0, -1.0, f64::NAN, f64::INFINITY] {
        assert!(matches!(choose(&pts, bad), Err(ChooseError::BadBudget(_))), "{bad}");
    }
}

#[test]
fn shards_partition_the_inputs_whatever_their_order() {
    let maps: Vec<String> = (0..11).map(|k| format!("map{k:02}.hdr")).collect();
    let mut reversed = maps.clone();
    reversed.reverse();
    for n in 1..=5 {
        let mut all = Vec::new();
        for i in 0..n {
            let s = Shard { index: i, count: n };
            let mine = s.select(&maps, Clone::clone);
            assert_eq!(mine, s.select(&reversed, Clone::clone), "the order of the input matters");
            assert!(mine.len() == maps.len() / n || mine.len() == maps.len().div_ceil(n));
            all.extend(mine);
        }
        all.sort();
        assert_eq!(all, maps, "{n} shards");
    }
}

#[test]
fn shard_arguments_parse_or_name_the_problem() {
    assert_eq!("2/4".parse::<Shard>(), Ok(Shard { index: 2, count: 4 }));
    assert_eq!("0/1".parse::<Shard>(), Ok(Shard::ALL));
    for bad in ["4/4", "1/0", "x/2", "3", "-1/2", ""] {
        let e = bad.parse::<Shard>().expect_err(bad);
        assert!(e.to_string().contains("I/N"), "{e}");
    }
}

/// A run over three maps, and the same measurements dealt into shards as `--shard` deals maps.
fn run_and_shards(n: usize) -> (Run, Vec<(std::path::PathBuf, Run)>) {
    let maps = ["a.hdr", "b.exr", "c.hdr"];
    let mut rows = Vec::new();
    for (m, map) in maps.iter().enumerate() {
        for scene in ["spheres_box", "column"] {
            rows.push(row(Shadow::None, 8, scene, map, 0.5, 0.2 + m as f64 * 0.01));
            rows.push(row(Shadow::Maps { resolution: 512, pcf: 1 }, 8, scene, map, 1.5, 0.05));
            rows.push(row(Shadow::Wedges, 32, scene, map, 3.5 + m as f64, 0.03));
        }
    }
    let mut run = Run { config: config(), shards: vec![Shard::ALL.to_string()], rows: rows.clone() };
    run.finish();
    let shards = (0..n)
        .map(|i| {
            let s = Shard { index: i, count: n };
            let mine: Vec<String> = s.select(&maps.map(String::from), Clone::clone);
            let mut r = Run {
                config: config(),
                shards: vec![s.to_string()],
                rows: rows.iter().filter(|r| mine.contains(&r.map)).cloned().collect(),
            };
            r.finish();
            (std::path::PathBuf::from(format!("shard{i}")), r)
        })
        .collect();
    (run, shards)
}

#[test]
fn the_merge_of_shards_equals_the_unsharded_run() {
    for n in [1, 2, 3] {
        let (run, shards) = run_and_shards(n);
        // through the files, as `trade merge` reads them
        let base = std::env::temp_dir().join(format!("trade-merge-{}-{n}", std::process::id()));
        let shards: Vec<(std::path::PathBuf, Run)> = shards
            .iter()
            .map(|(name, r)| {
                let dir = base.join(name);
                r.write(&dir).expect("shard written");
                (dir.clone(), Run::read(&dir).expect("shard read"))
            })
            .collect();
        let _ = std::fs::remove_dir_all(&base);
        let merged = merge(&shards).expect("shards merge");
        assert_eq!(merged.rows, run.rows, "{n} shards");
        assert_eq!(merged.csv(), run.csv());
        assert_eq!(merged.shards.len(), n);
    }
}

#[test]
fn merging_refuses_mixed_configurations_and_repeats() {
    let (_, mut shards) = run_and_shards(2);
    let twice = vec![shards[0].clone(), shards[0].clone()];
    assert!(matches!(merge(&twice), Err(trade::TradeError::Duplicate { .. })));
    shards[1].1.config.truth_spp = 8;
    let e = merge(&shards).expect_err("different truths");
    assert!(matches!(e, trade::TradeError::Mismatch { .. }));
    assert!(e.to_string().contains("shard1"), "{e}");
    assert!(matches!(merge(&[]), Err(trade::TradeError::NothingToMerge)));
}

#[test]
fn runs_round_trip_through_their_files() {
    let (run, _) = run_and_shards(1);
    let dir = std::env::temp_dir().join(format!("trade-round-trip-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    run.write(&dir).expect("written");
    assert_eq!(Run::read(&dir).expect("read back"), run);
    let csv = std::fs::read_to_string(dir.join("trade.csv")).expect("csv");
    let header: Vec<&str> = csv.lines().next().expect("header").split(',').collect();
    for column in ["setting", "scene", "map", "ms", "rmse", "flip", "pareto"] {
        assert!(header.contains(&column), "no {column} column");
    }
    assert_eq!(csv.lines().count(), run.rows.len() + 1);
    // the field with a comma is quoted: every row has the header's columns
    assert!(csv.contains("\"1 why, with a comma\""));
    std::fs::write(dir.join("trade.json"), "{\"rows\": 3}").expect("spoiled");
    let e = Run::read(&dir).expect_err("not a run");
    assert!(e.to_string().contains("trade.json") && e.to_string().contains("not a trade run"), "{e}");
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn overall_means_only_settings_measured_everywhere() {
    let (mut run, _) = run_and_shards(1);
    run.rows.retain(|r| !(r.setting.ends_with("/none") && r.map == "c.hdr"));
    let all = overall(&run.rows, Family::Env);
    assert_eq!(all.len(), 2, "{all:?}");
    let wedges = all.iter().find(|p| p.setting.ends_with("/wedges")).expect("wedges");
    assert!((wedges.ms - 4.5).abs() < 1e-12 && (wedges.rmse - 0.03).abs() < 1e-12);
}

#[test]
fn the_report_draws_one_plot_per_case_and_one_over_all() {
    let (run, _) = run_and_shards(1);
    let html = trade::report::html(&run, &[0.1, 4.0]).expect("report");
    assert_eq!(html.matches("<svg").count(), 1 + 6, "one plot over all and one per scene and map");
    assert!(html.contains("Pareto front"));
    assert!(html.contains("K32/wedges"), "front labels");
    assert!(html.contains("no setting fits in 0.1 ms"), "the chooser's answer for 0.1 ms");
    let e = trade::report::plot_svg("empty", &[point("nan", f64::NAN, 0.1)], "RMSE").expect_err("nothing to plot");
    assert!(e.to_string().contains("empty"), "{e}");
}

#[test]
fn setting_names_are_distinct_in_every_preset() {
    for preset in [trade::Preset::Quick, trade::Preset::Default] {
        let mut names: Vec<String> = preset.settings().iter().map(Setting::name).collect();
        let n = names.len();
        names.sort();
        names.dedup();
        assert_eq!(names.len(), n, "{preset:?}");
    }
}

#[test]
fn families_keep_their_own_fronts_choices_and_report_sections() {
    let (mut run, _) = run_and_shards(1);
    // point and composite settings cheaper than every environment-lit one, their errors in
    // other units: none of them may enter the env front or choice
    let point = |shadow, ms, rmse| row_of(Setting::Point(PointSetting { shadow }), "room", "-", ms, rmse);
    run.rows.push(point(Shadow::Paraboloid { resolution: 1024, pcf: 0, subdivide: true }, 0.2, 0.001));
    run.rows.push(point(Shadow::Cube { resolution: 592, pcf: 0 }, 0.3, 0.0012));
    let composite = |passes, ms, rmse| {
        row_of(Setting::Composite(CompositeSetting::new(passes, false)), "ar_ground", "city.hdr", ms, rmse)
    };
    run.rows.push(composite(1, 0.1, 2.5));
    run.rows.push(composite(50, 0.4, 1.8));
    run.finish();
    let env = overall(&run.rows, Family::Env);
    assert_eq!(env.len(), 3, "{env:?}");
    assert_eq!(
        choose(&env, 0.3),
        Err(ChooseError::OverBudget {
            budget: 0.3,
            cheapest: format!("{}/K8/none", light_extract::DEFAULT_METHOD),
            ms: 0.5
        })
    );
    let points = overall(&run.rows, Family::Point);
    assert_eq!(trade::pareto_front(&points).len(), 1, "the paraboloid is faster and better: {points:?}");
    assert_eq!(choose(&points, 1.0).map(|p| p.setting), Ok("point/paraboloid_1024".to_string()));
    let composites = overall(&run.rows, Family::Composite);
    assert_eq!(choose(&composites, 0.45).map(|p| p.setting), Ok("composite/50/hdr/paraboloid_256".to_string()));
    assert!(run.rows.iter().filter(|r| r.scene == "room").any(|r| r.pareto), "fronts are per case");
    // through the files with their families, one CSV column naming each
    let dir = std::env::temp_dir().join(format!("trade-families-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    run.write(&dir).expect("written");
    assert_eq!(Run::read(&dir).expect("read back"), run);
    let csv = std::fs::read_to_string(dir.join("trade.csv")).expect("csv");
    let _ = std::fs::remove_dir_all(&dir);
    let family = csv.lines().next().unwrap_or_default().split(',').position(|c| c == "family").expect("family column");
    for (name, n) in [("env", 18), ("point", 2), ("composite", 2)] {
        assert_eq!(csv.lines().filter(|l| l.split(',').nth(family) == Some(name)).count(), n, "{name}");
    }
    let html = trade::report::html(&run, &[0.1, 4.0]).expect("report");
    assert_eq!(html.matches("<h2 id=").count(), 3, "a section per family");
    // per family one plot over all and one per case: env 1 + 6, point 1 + 1, composite 1 + 1
    assert_eq!(html.matches("<svg").count(), 11);
    assert!(html.contains(Family::Composite.error_axis()));
}

#[test]
fn profile_plots_draw_every_series_and_refuse_nothing_to_draw() {
    let ramp: Vec<(f64, f64)> = (0..40).map(|x| (f64::from(x), f64::from(x) / 40.0)).collect();
    let stairs: Vec<(f64, f64)> = ramp.iter().map(|&(x, y)| (x, (y * 4.0).floor() / 4.0)).collect();
    let svg = trade::report::profile_svg("steps", &[("truth".into(), ramp), ("one set".into(), stairs)], "luminance")
        .expect("a plot");
    assert!(svg.starts_with("<svg") && svg.contains("truth") && svg.contains("one set"), "{svg}");
    let nothing = [("truth".to_string(), vec![(f64::NAN, 1.0)])];
    assert!(trade::report::profile_svg("empty", &nothing, "luminance").is_err());
}
