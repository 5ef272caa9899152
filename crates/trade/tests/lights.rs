//! The extraction methods' measurement without rendering: summaries against hand-worked means
//! and ranks, method selection, and merges that must refuse.

use trade::TradeError;
use trade::lights::{LightsConfig, LightsRow, LightsRun, chosen_methods, merge_lights, summary};

fn row(map: &str, method: &str, rmse: f64) -> LightsRow {
    LightsRow {
        map: map.into(),
        scene: "s".into(),
        method: method.into(),
        lights: 4,
        rmse,
        converged_rmse: rmse,
        flip: rmse,
        extract_ms: 1.0,
    }
}

#[test]
fn summary_gives_each_methods_mean_and_mean_rank() {
    // map a: x 0.1 < y 0.3; map b: y 0.2 < x 0.5 -> x mean 0.3 rank 1.5; y mean 0.25 rank 1.5
    let rows = [row("a", "x", 0.1), row("a", "y", 0.3), row("b", "x", 0.5), row("b", "y", 0.2), row("c", "x", 0.4)];
    let s = summary(&rows, |r| r.rmse);
    let x = s.iter().find(|(m, _, _)| m == "x").expect("x");
    let y = s.iter().find(|(m, _, _)| m == "y").expect("y");
    assert!((x.1 - 1.0 / 3.0).abs() < 1e-12, "{x:?}");
    assert!((y.1 - 0.25).abs() < 1e-12, "{y:?}");
    // on c, y is missing: it ranks after every method there
    assert!((x.2 - 4.0 / 3.0).abs() < 1e-12, "{x:?}");
    assert!((y.2 - 5.0 / 3.0).abs() < 1e-12, "{y:?}");
}

#[test]
fn an_unknown_method_is_refused_with_the_available_ones() {
    let e = chosen_methods(8, &["no-such-method".into()]).err().expect("refused");
    assert!(e.to_string().contains("no-such-method") && e.to_string().contains("median-cut"), "{e}");
    let some = chosen_methods(8, &["emissive-split".into()]).expect("known");
    let labels: Vec<&str> = some.iter().map(|(l, _)| l.as_str()).collect();
    assert_eq!(labels, ["emissive-split", "median-cut"], "table order, median cut always in");
}

#[test]
fn merges_refuse_a_map_twice_and_nothing() {
    let dir = std::env::temp_dir().join(format!("envshadow-lights-merge-{}", std::process::id()));
    let config = LightsConfig {
        scenes: vec!["s".into()],
        lights: 4,
        methods: vec!["x".into()],
        spp: 4,
        lights_spp: 1,
        size: (8, 8),
    };
    for (k, shard) in ["0/2", "1/2"].into_iter().enumerate() {
        let d = dir.join(k.to_string());
        std::fs::create_dir_all(&d).expect("mkdir");
        let run = LightsRun { config: config.clone(), shards: vec![shard.into()], rows: vec![row("a", "x", 0.1)] };
        std::fs::write(d.join("eval-lights.json"), serde_json::to_string(&run).expect("json")).expect("write");
    }
    let e = merge_lights(&[dir.join("0"), dir.join("1")]).expect_err("refused");
    assert!(matches!(e, TradeError::Duplicate { .. }) && e.to_string().contains("map a"), "{e}");
    let one = merge_lights(&[dir.join("0")]).expect("one shard");
    assert_eq!(one.rows.len(), 1);
    assert!(matches!(merge_lights(&[]), Err(TradeError::NothingToMerge)));
    let _ = std::fs::remove_dir_all(&dir);
}
