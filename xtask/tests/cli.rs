//! The commands as a user runs them: output shape, exit codes, one-line errors.

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

fn xtask(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_xtask")).args(args).output().expect("run xtask")
}

/// An empty scratch folder for one test: cleared first, so a command that stopped writing its
/// files cannot pass on what an earlier run left there.
fn fresh_dir(name: &str) -> PathBuf {
    let dir = PathBuf::from(env!("CARGO_TARGET_TMPDIR")).join(name);
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).expect("scratch dir");
    dir
}

fn shared(name: &str) -> PathBuf {
    test_set::path(name)
}

#[test]
fn bad_input_exits_one_with_one_line_naming_the_file() {
    let dir = fresh_dir("cli-bad");
    let text = dir.join("text.hdr");
    std::fs::write(&text, "hello").expect("write");
    for path in [dir.join("missing.exr"), text] {
        let p = path.to_str().unwrap_or_default();
        for args in [vec!["validate", "--envmap", p], vec!["frame", "--envmap", p]] {
            let out = xtask(&args);
            assert_eq!(out.status.code(), Some(1), "{args:?}");
            let err = String::from_utf8_lossy(&out.stderr);
            assert_eq!(err.trim().lines().count(), 1, "{args:?}: {err}");
            assert!(err.contains(p), "{args:?}: {err}");
        }
    }
}

#[test]
fn validate_quick_runs_from_a_copied_binary_meets_its_thresholds_and_the_docs_figures() {
    // a binary copied elsewhere, run from an empty folder: the thresholds are in the binary;
    // docs/measured.md's quick block must be what this code measures (CI's validate run)
    let dir = fresh_dir("cli-validate");
    let copy = dir.join("xtask-copy");
    std::fs::copy(env!("CARGO_BIN_EXE_xtask"), &copy).expect("copy the binary");
    let docs = Path::new(env!("CARGO_MANIFEST_DIR")).join("../docs/measured.md");
    let out = Command::new(&copy)
        .args(["validate", "--quick", "--out", "out", "--check-readme"])
        .arg(&docs)
        .current_dir(&dir)
        .output()
        .expect("run");
    let dir = dir.join("out");
    let text = String::from_utf8_lossy(&out.stdout);
    assert!(out.status.success(), "{text}\n{}", String::from_utf8_lossy(&out.stderr));
    assert!(text.contains("validate --quick figures match this run"), "{text}");
    assert!(text.contains("[1/10] load environment map") && text.contains("[10/10] report"), "{text}");
    // the adapter is named before any work, and again by the GPU stage
    let first = text.lines().next().unwrap_or_default();
    let adapter = first.strip_prefix("GPU: ").unwrap_or_else(|| panic!("first line {first:?}"));
    let name = adapter.split(" (").next().unwrap_or_default();
    assert!(text.lines().any(|l| l.contains("[5/10] GPU") && l.contains(name)), "{text}");
    assert!(text.contains("thresholds met") && !text.contains(" 0 thresholds met"), "{text}");
    let html = std::fs::read_to_string(dir.join("report.html")).expect("report written");
    assert!(html.contains("data:image/png;base64,") && !html.contains("src=\"http"), "images embedded");
    for row in [
        "reference",
        "lights_ray_traced",
        "gpu_shadow_maps",
        "gpu_wedges_indirects_half",
        "env_direct_equal_time",
        "paraboloid_1024_clip",
        "cube_592",
        "GPU adapter",
        "Compositing (paper 003)",
        "composite_gpu_50_hdr",
    ] {
        assert!(html.contains(row), "report lacks {row}");
    }
}

#[test]
fn an_unknown_adapter_exits_one_with_one_line_listing_the_adapters() {
    let out = xtask(&["validate", "--quick", "--adapter", "no-such-gpu-xyz"]);
    assert_eq!(out.status.code(), Some(1));
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(err.trim().lines().count(), 1, "{err}");
    assert!(err.contains("no-such-gpu-xyz") && err.contains("found:"), "{err}");
    assert!(out.stdout.is_empty(), "no work before the adapter is settled: {}", String::from_utf8_lossy(&out.stdout));
}

#[test]
fn validate_reads_thresholds_from_a_file_and_refuses_a_broken_one() {
    let dir = fresh_dir("cli-thresholds");
    for (name, text, want) in [
        ("missing.json", None, "missing.json"),
        ("broken.json", Some("{\"thresholds\": {\"a\": \"x\"}}"), "threshold a is not a finite number"),
        ("empty.json", Some("[]"), "no \"thresholds\" object"),
    ] {
        let path = dir.join(name);
        match text {
            Some(t) => std::fs::write(&path, t).expect("write"),
            None => {
                let _ = std::fs::remove_file(&path);
            }
        }
        let out = xtask(&["validate", "--quick", "--thresholds", path.to_str().unwrap_or_default()]);
        assert_eq!(out.status.code(), Some(1), "{name}");
        let err = String::from_utf8_lossy(&out.stderr);
        assert_eq!(err.trim().lines().count(), 1, "{err}");
        assert!(err.contains(name) && err.contains(want), "{err}");
    }
}

#[test]
fn fuzz_short_run_finds_nothing() {
    let out = xtask(&["fuzz", "--cases", "5000", "--seed", "7"]);
    let text = String::from_utf8_lossy(&out.stdout);
    assert!(out.status.success(), "{text}\n{}", String::from_utf8_lossy(&out.stderr));
    let last = text.trim().lines().last().unwrap_or_default();
    assert!(last.starts_with("fuzz: 5000 cases, 0 panics, 0 errors not one line naming the file"), "{last}");
    // every target ran, and some cases were refused and some loaded
    assert!(text.contains("thresholds.json") && text.contains("lights.json") && text.contains("map.exr"), "{text}");
    assert!(text.contains("model.gltf") && text.contains("model.glb"), "{text}");
}

#[test]
fn validate_refuses_an_unknown_scene_in_one_line() {
    let out = xtask(&["validate", "--quick", "--scene", "nowhere"]);
    assert_eq!(out.status.code(), Some(1));
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(err.trim().lines().count(), 1, "{err}");
    assert!(err.contains("nowhere") && err.contains("spheres_box"), "{err}");
}

#[test]
fn frame_json_counts_what_a_moving_frame_costs() {
    let out = xtask(&[
        "frame",
        "--scene",
        "spheres_box",
        "--size",
        "64x48",
        "--repeats",
        "3",
        "--lights",
        "4",
        "--animate",
        "--json",
    ]);
    let text = String::from_utf8_lossy(&out.stdout);
    assert!(out.status.success(), "{text}{}", String::from_utf8_lossy(&out.stderr));
    let v: serde_json::Value = serde_json::from_str(text.trim()).unwrap_or_else(|e| panic!("{e}: {text}"));
    assert_eq!(v["frames"], 3, "{v}");
    assert_eq!(v["animated_object"], "sphere", "{v}");
    for k in ["submits_per_frame", "waits_per_frame", "readback_bytes_per_frame", "cpu_record_ms", "wall_ms"] {
        assert!(v[k].as_f64().is_some_and(|x| x.is_finite() && x >= 0.0), "{k}: {v}");
    }
    // the first frame does everything a measured frame does and compiles the pipelines too
    for k in ["first_frame_wall_ms", "setup_ms"] {
        assert!(v[k].as_f64().is_some_and(|x| x.is_finite() && x > 0.0), "{k}: {v}");
    }
    // the recorded frame: the G-buffers' submission (with their receivers reduced) and the
    // frame's; no wait inside it, the harness's at the frame's end alone; nothing built after
    // the first frame
    assert_eq!(v["submits_per_frame"].as_f64(), Some(2.0), "{v}");
    assert_eq!(v["waits_per_frame"].as_f64(), Some(1.0), "{v}");
    assert_eq!(v["pipelines_created_after_first_frame"].as_u64(), Some(0), "{v}");
    // the receivers' statistics, not their points: at most the 4 KiB
    assert!(v["readback_bytes_per_frame"].as_f64().is_some_and(|b| b > 0.0 && b <= 4096.0), "{v}");
    assert!(v["gpu_ms"].is_null() || v["gpu_ms"].as_f64().is_some_and(|g| g >= 0.0), "{v}");
    // a gate pass a gated light, not one a pass of its
    let lights = v["lights"].as_f64().unwrap();
    assert!(v["gate_passes_per_frame"].as_f64().is_some_and(|g| g > 0.0 && g <= lights), "{v}");
    // per-light resources come from slots kept from frame to frame: what a frame makes is its
    // own few passes' (the benches' test holds it equal for 4 and 32 lights)
    for k in ["buffers_created_per_frame", "bind_groups_created_per_frame", "textures_created_per_frame"] {
        assert!(v[k].as_f64().is_some_and(|n| (0.0..=24.0).contains(&n)), "{k}: {v}");
    }
    assert!(v["adapter"].as_str().is_some_and(|a| !a.is_empty()), "{v}");
    // every light is shadowed or skipped with a reason
    let skipped: u64 =
        v["lights_skipped"].as_array().map_or(0, |a| a.iter().filter_map(|s| s["lights"].as_u64()).sum());
    assert_eq!(v["lights_shadowed"].as_u64().map(|n| n + skipped), v["lights"].as_u64(), "{v}");
    // a model's path in place of a built-in name, on its own ground
    let dir = fresh_dir("cli-frame-model");
    let model = dir.join("mine.glb");
    scene::Scene::builtin("three_boxes").expect("built-in").write_gltf(&model).expect("writes");
    let path = model.to_str().unwrap_or_default();
    let out = xtask(&["frame", "--scene", path, "--ground", "0.3", "--size", "64x48", "--repeats", "1", "--json"]);
    let text = String::from_utf8_lossy(&out.stdout);
    assert!(out.status.success(), "{text}{}", String::from_utf8_lossy(&out.stderr));
    let v: serde_json::Value = serde_json::from_str(text.trim()).unwrap_or_else(|e| panic!("{e}: {text}"));
    assert_eq!((v["scene"].as_str(), v["triangles"].as_u64()), (Some(path), Some(38 + 2)), "{v}");
    let out = xtask(&["frame", "--scene", path, "--ground", "2", "--size", "64x48"]);
    assert_eq!(out.status.code(), Some(2), "clap refuses an albedo past 1");
    let out = xtask(&["frame", "--json", "--scale", "3", "--size", "64x48"]);
    assert_eq!(out.status.code(), Some(1));
    assert!(String::from_utf8_lossy(&out.stderr).contains("--scale 3"));
}

#[test]
fn frame_times_each_resolution_and_refuses_bad_arguments_in_one_line() {
    let out = xtask(&["frame", "--scene", "three_boxes", "--size", "64x48", "--repeats", "2", "--lights", "4"]);
    let text = String::from_utf8_lossy(&out.stdout);
    assert!(out.status.success(), "{text}{}", String::from_utf8_lossy(&out.stderr));
    assert!(text.contains("three_boxes: 38 triangles, 64x48; 4 lights"), "{text}");
    for name in ["full", "half", "quarter"] {
        let line = text.lines().find(|l| l.contains(&format!("EnvIndirects at {name} resolution"))).expect(name);
        assert!(line.contains(" fps)") && line.contains("over 2 frames"), "{line}");
    }
    for (args, says) in [
        (&["frame", "--repeats", "0"][..], "--repeats 0"),
        (&["frame", "--scene", "nowhere", "--size", "64x48"][..], "nowhere"),
        (&["frame", "--envmap", "missing.exr", "--size", "64x48"][..], "missing.exr"),
    ] {
        let out = xtask(args);
        let err = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(1), "{args:?}: {err}");
        assert!(err.trim().lines().count() == 1 && err.contains(says), "{args:?}: {err}");
    }
}

#[test]
fn eval_lights_writes_both_tables_with_a_noise_floor() {
    let dir = PathBuf::from(env!("CARGO_TARGET_TMPDIR")).join("cli-eval");
    let maps = dir.join("maps");
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&maps).expect("scratch dir");
    std::fs::copy(shared("venice_sunset_1k.hdr"), maps.join("venice.hdr")).expect("copy map");
    let out_dir = dir.join("out");
    let eval = |extra: &[&str]| {
        let base =
            ["eval-lights", "--maps", maps.to_str().unwrap_or_default(), "--scenes", "spheres_box", "--lights", "4"];
        xtask(&[&base[..], extra, &["--out", out_dir.to_str().unwrap_or_default()]].concat())
    };
    let out = eval(&["--spp", "4", "--lights-spp", "2", "--size", "16x12"]);
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let csv = std::fs::read_to_string(out_dir.join("eval-lights.csv")).expect("csv");
    let lines: Vec<&str> = csv.lines().collect();
    assert_eq!(lines[0], "map,scene,method,lights,rmse,converged_rmse,flip,extract_ms");
    assert_eq!(lines.len(), 1 + 17, "floor + five methods + three ablations + eight of our options: {csv}");
    for ablation in ["emissive-split/no-masking", "emissive-split/no-kmeans", "emissive-split/neither"] {
        assert!(csv.contains(&format!(",{ablation},")), "{ablation} missing:\n{csv}");
    }
    for method in [
        "emissive-split",
        "center-surround",
        "median-cut",
        "variance-min",
        "importance",
        "\"(reference, other seed)\"",
        "emissive-split+above-horizon",
        "emissive-split+moment-cones",
        "emissive-split+moment-cones+above-horizon",
        "emissive-split+moment-cones+above-horizon+residual",
        "emissive-split+weber",
        "emissive-split+moment-cones+weber+above-horizon+residual",
        "median-cut+above-horizon",
        "median-cut+above-horizon+residual",
    ] {
        assert!(csv.contains(&format!(",{method},")), "{method} missing:\n{csv}");
    }
    // every row has the header's 8 fields (commas inside quotes do not separate)
    for line in &lines {
        let mut quoted = false;
        let fields = 1 + line
            .chars()
            .filter(|&c| {
                quoted ^= c == '"';
                c == ',' && !quoted
            })
            .count();
        assert_eq!(fields, 8, "{line}");
    }
    let md = std::fs::read_to_string(out_dir.join("eval-lights.md")).expect("md");
    assert!(md.contains("| median-cut |") && md.contains("RMSE / median cut"), "{md}");
    // --methods: those rows, the floor and median cut; an unknown label: exit 1, one line
    let run = |methods: &str| eval(&["--spp", "2", "--lights-spp", "1", "--size", "8x6", "--methods", methods]);
    let out = run("importance,emissive-split/neither");
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let csv = std::fs::read_to_string(out_dir.join("eval-lights.csv")).expect("csv");
    let mut methods: Vec<&str> =
        csv.lines().skip(1).filter_map(|l| l.splitn(3, ',').nth(2)?.rsplitn(6, ',').last()).collect();
    methods.sort_unstable();
    assert_eq!(methods, ["\"(reference, other seed)\"", "emissive-split/neither", "importance", "median-cut"], "{csv}");
    let out = run("median-cut,no-such-method");
    assert_eq!(out.status.code(), Some(1));
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(err.trim().lines().count() == 1 && err.contains("no-such-method"), "{err}");
}

#[test]
fn shafts_json_has_the_interface_keys_and_misses_nothing() {
    let dir = PathBuf::from(env!("CARGO_TARGET_TMPDIR")).join("cli-shafts");
    let _ = std::fs::remove_dir_all(&dir);
    let out = xtask(&["shafts", "--scene", "ar_ground", "--json", "--out", dir.to_str().unwrap_or_default()]);
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let text = String::from_utf8_lossy(&out.stdout);
    assert_eq!(text.trim().lines().count(), 1, "one JSON object on one line: {text}");
    let v: serde_json::Value = serde_json::from_str(&text).expect("valid JSON");
    for k in [
        "patches",
        "sources",
        "receivers",
        "leaf_shafts",
        "bytes",
        "preprocess_s",
        "traversal_us",
        "segments_checked",
        "misses",
    ] {
        assert!(v.get(k).is_some_and(serde_json::Value::is_number), "missing number {k} in {v}");
    }
    assert_eq!(v["patches"].as_u64(), Some(1_108));
    assert_eq!(v["misses"].as_u64(), Some(0));
    assert!(v["segments_checked"].as_u64().unwrap_or(0) >= 100_000);
    assert!(v["leaf_shafts"].as_u64().unwrap_or(0) > 0 && v["bytes"].as_u64().unwrap_or(0) > 0);
    assert!(dir.join("ar_ground_overlay.png").is_file(), "the overlay image");
    let bad = xtask(&["shafts", "--scene", "nope"]);
    assert_eq!(bad.status.code(), Some(1));
    assert_eq!(String::from_utf8_lossy(&bad.stderr).trim().lines().count(), 1);
}

/// The CSV without its timing column (extraction ms is measured anew in every run).
fn without_timing(csv: &str) -> Vec<String> {
    csv.lines().map(|l| l.rsplit_once(',').map_or(l, |(rest, _)| rest).to_string()).collect()
}

#[test]
fn eval_lights_shards_merge_into_the_unsharded_run() {
    let dir = fresh_dir("cli-eval-shards");
    let maps = dir.join("maps");
    std::fs::create_dir_all(&maps).expect("maps dir");
    for (from, to) in [("venice_sunset_1k.hdr", "a.hdr"), ("lebombo_1k.hdr", "b.hdr"), ("studio.exr", "c.exr")] {
        std::fs::copy(shared(from), maps.join(to)).expect("copy map");
    }
    let eval = |extra: &[&str], out: &Path| {
        let base = [
            "eval-lights",
            "--maps",
            maps.to_str().unwrap_or_default(),
            "--scenes",
            "spheres_box",
            "--lights",
            "4",
            "--methods",
            "importance",
            "--spp",
            "2",
            "--lights-spp",
            "1",
            "--size",
            "8x6",
        ];
        let o = xtask(&[&base[..], extra, &["--out", out.to_str().unwrap_or_default()]].concat());
        assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    };
    let whole = dir.join("whole");
    eval(&[], &whole);
    let shards: Vec<PathBuf> = (0..2).map(|i| dir.join(format!("shard{i}"))).collect();
    for (i, s) in shards.iter().enumerate() {
        eval(&["--shard", &format!("{i}/2")], s);
    }
    let rows = |d: &Path| std::fs::read_to_string(d.join("eval-lights.csv")).expect("csv");
    // each shard has its own maps: 2 and 1 of 3, 3 rows per map (floor, median cut, importance)
    assert_eq!(rows(&shards[0]).lines().count(), 1 + 2 * 3);
    assert_eq!(rows(&shards[1]).lines().count(), 1 + 3);
    let merged = dir.join("merged");
    let dirs: Vec<&str> = shards.iter().map(|s| s.to_str().unwrap_or_default()).collect();
    let o = xtask(&[&["eval-lights", "merge"][..], &dirs, &["--out", merged.to_str().unwrap_or_default()]].concat());
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    assert_eq!(without_timing(&rows(&merged)), without_timing(&rows(&whole)));
    // a shard twice, or a folder without a run: exit 1 and say which
    let again = [dirs[0], dirs[0]];
    let o = xtask(&[&["eval-lights", "merge"][..], &again, &["--out", merged.to_str().unwrap_or_default()]].concat());
    assert_eq!(o.status.code(), Some(1));
    assert!(String::from_utf8_lossy(&o.stderr).contains("already in the merge"));
    let o = xtask(&["eval-lights", "merge", maps.to_str().unwrap_or_default(), "--out", "x"]);
    assert_eq!(o.status.code(), Some(1));
    assert!(String::from_utf8_lossy(&o.stderr).contains("eval-lights.json"));
}

#[test]
fn trade_writes_its_three_files_and_merges_them_back() {
    let dir = fresh_dir("cli-trade");
    let out = dir.join("run");
    // a model of one's own beside the built-ins: three_boxes written as glTF and read back
    let model = dir.join("mine.glb");
    scene::Scene::builtin("three_boxes").expect("built-in").write_gltf(&model).expect("writes");
    let scenes = format!("three_boxes,room,ar_ground,{}", model.display());
    let o = xtask(&[
        "trade",
        "--quick",
        "--scenes",
        &scenes,
        "--size",
        "48x36",
        "--shard",
        "0/1",
        "--out",
        out.to_str().unwrap_or_default(),
    ]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let stdout = String::from_utf8_lossy(&o.stdout);
    assert!(stdout.lines().any(|l| l.starts_with("budget: 4 ms -> ")), "{stdout}");
    let csv = std::fs::read_to_string(out.join("trade.csv")).expect("trade.csv");
    let header: Vec<&str> = csv.lines().next().unwrap_or_default().split(',').collect();
    for column in ["setting", "scene", "map", "ms", "rmse", "flip", "pareto"] {
        assert!(header.contains(&column), "no {column} column: {header:?}");
    }
    assert_eq!(csv.lines().count(), 1 + 18, "one row per quick setting of each scene's family: {csv}");
    for family in [",env,three_boxes,", ",point,room,-,", ",composite,ar_ground,", ",env,mine,"] {
        assert_eq!(csv.lines().filter(|l| l.contains(family)).count(), if family.starts_with(",env,") { 7 } else { 2 });
        assert!(
            csv.lines().any(|l| l.contains(family) && l.contains(",true,")),
            "no {family} setting on its front: {csv}"
        );
    }
    let html = std::fs::read_to_string(out.join("report.html")).expect("report.html");
    assert_eq!(html.matches("<svg").count(), 7, "per family a plot over all and one for each scene");
    let merged = dir.join("merged");
    let o = xtask(&["trade", "merge", out.to_str().unwrap_or_default(), "--out", merged.to_str().unwrap_or_default()]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    assert_eq!(std::fs::read_to_string(merged.join("trade.csv")).expect("merged csv"), csv);
    assert!(merged.join("trade.json").is_file() && merged.join("report.html").is_file());
    let o = xtask(&["trade", "--quick", "--shard", "2/2", "--out", dir.to_str().unwrap_or_default()]);
    assert_eq!(o.status.code(), Some(2), "clap refuses a bad shard");
    assert!(String::from_utf8_lossy(&o.stderr).contains("I/N"));
}

#[test]
fn large_model_writes_the_grid_it_names_and_refuses_past_its_limit() {
    let dir = fresh_dir("cli-large-model");
    let out = dir.join("terrain.glb");
    let run = xtask(&["large-model", "--triangles", "20000", "--out", out.to_str().unwrap_or_default()]);
    assert!(run.status.success(), "{}", String::from_utf8_lossy(&run.stderr));
    // read back through the importer every command uses: a 100 x 100 grid, all of it under
    // the 10 m square and within the displacement's amplitude (0.6 + 0.15)
    let options = scene::import::GltfOptions::default();
    let (model, warnings) = scene::Scene::open(out.to_str().unwrap_or_default(), &options).expect("import");
    assert!(warnings.is_empty(), "{warnings:?}");
    assert_eq!(model.triangle_count(), 20_000);
    for o in &model.objects {
        assert_eq!(o.mesh.positions.len(), 101 * 101);
        for p in &o.mesh.positions {
            assert!(p.x.abs() <= 5.0 + 1e-5 && p.z.abs() <= 5.0 + 1e-5 && p.y.abs() <= 0.75 + 1e-5, "{p}");
        }
    }
    let refused = xtask(&["large-model", "--triangles", "300000000", "--out", out.to_str().unwrap_or_default()]);
    assert_eq!(refused.status.code(), Some(1));
    let err = String::from_utf8_lossy(&refused.stderr);
    assert_eq!(err.trim().lines().count(), 1, "{err}");
    assert!(err.contains("--triangles 300000000"), "{err}");
}
