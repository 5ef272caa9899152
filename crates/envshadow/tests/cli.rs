//! The user's commands as a user runs them: output shape, exit codes, one-line errors.

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

fn envshadow(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_envshadow")).args(args).output().expect("run envshadow")
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
    let out = dir.join("render.exr");
    let out = out.to_str().unwrap_or_default();
    for path in [dir.join("missing.exr"), text] {
        let p = path.to_str().unwrap_or_default();
        for args in [
            vec!["info", p],
            vec!["info", p, "--json"],
            vec!["extract", p],
            vec!["render", "--scene", "room", "--envmap", p, "--spp", "1", "--size", "8x6", "--out", out],
            vec!["compare", p, p],
        ] {
            let out = envshadow(&args);
            assert_eq!(out.status.code(), Some(1), "{args:?}");
            let err = String::from_utf8_lossy(&out.stderr);
            assert_eq!(err.trim().lines().count(), 1, "{args:?}: {err}");
            assert!(err.contains(p), "{args:?}: {err}");
            assert!(out.stdout.is_empty(), "{args:?}");
        }
    }
    // a BVH preset that is not one: refused before anything is loaded, naming the presets
    let bad = envshadow(&["render", "--scene", "room", "--bvh", "quick", "--spp", "1", "--size", "8x6", "--out", out]);
    assert_eq!(bad.status.code(), Some(1));
    let err = String::from_utf8_lossy(&bad.stderr);
    assert_eq!(err.trim().lines().count(), 1, "{err}");
    assert!(err.contains("quick") && err.contains("very-slow"), "{err}");
}

#[test]
fn info_json_has_the_documented_keys_and_values() {
    let path = shared("city.exr");
    let out = envshadow(&["info", path.to_str().unwrap_or_default(), "--json"]);
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let text = String::from_utf8_lossy(&out.stdout);
    assert_eq!(text.trim().lines().count(), 1, "one JSON object on one line: {text}");
    let v: serde_json::Value = serde_json::from_str(&text).expect("valid JSON");
    let keys: Vec<&str> = v.as_object().expect("an object").keys().map(String::as_str).collect();
    for k in [
        "width",
        "height",
        "format",
        "compression",
        "converted_from_primaries",
        "max_luminance",
        "mean_luminance",
        "power",
        "sh9",
    ] {
        assert!(keys.contains(&k), "missing key {k} in {keys:?}");
    }
    assert_eq!((v["width"].as_u64(), v["height"].as_u64()), (Some(1024), Some(512)));
    assert_eq!((v["format"].as_str(), v["compression"].as_str()), (Some("exr"), Some("dwab")));
    // city.exr declares sRGB primaries adapted to D50 (white at x 0.3457): read converted to
    // Rec.709 of the same XYZ, its maximum luminance moves (stored values: 31749.4)
    let white = &v["converted_from_primaries"][3];
    assert!((white[0].as_f64().unwrap_or(0.0) - 0.3457).abs() < 1e-4, "{white}");
    let (max, mean) = (v["max_luminance"].as_f64().unwrap_or(0.0), v["mean_luminance"].as_f64().unwrap_or(0.0));
    assert!((max - 31839.6).abs() < 1.0, "{max}");
    assert!((mean - 1.055).abs() < 0.01, "{mean}"); // XYZ is kept, so luminance barely moves
    let power = v["power"].as_array().expect("power array");
    assert_eq!(power.len(), 3);
    let sh9 = v["sh9"].as_array().expect("sh9 array");
    assert!(sh9.len() == 9 && sh9.iter().all(|c| c.as_array().is_some_and(|c| c.len() == 3)));
    // sh9[0] = integral of L * Y00 = power * 0.2820948
    let p0 = power[0].as_f64().unwrap_or(0.0);
    let c0 = sh9[0][0].as_f64().unwrap_or(0.0);
    assert!((c0 / (p0 * 0.282_094_8) - 1.0).abs() < 1e-4, "{c0} vs {p0}");
}

#[test]
fn info_text_lists_the_statistics() {
    let path = shared("venice_sunset_1k.hdr");
    let out = envshadow(&["info", path.to_str().unwrap_or_default()]);
    assert!(out.status.success());
    let text = String::from_utf8_lossy(&out.stdout);
    for needle in ["1024 x 512", "hdr (rle)", "max 2090.", "power", "sh9 l2 m2"] {
        assert!(text.contains(needle), "missing {needle:?} in:\n{text}");
    }
}

#[test]
fn scene_writes_obj_and_gltf_and_refuses_unknown_names() {
    let dir = fresh_dir("cli-scene");
    let obj = dir.join("spheres_box.obj");
    let out = envshadow(&["scene", "spheres_box", "--obj", obj.to_str().unwrap_or_default()]);
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    assert!(String::from_utf8_lossy(&out.stdout).contains("20494 triangles"));
    let text = std::fs::read_to_string(&obj).expect("OBJ written");
    assert_eq!(text.lines().filter(|l| l.starts_with("o ")).count(), 3);
    assert_eq!(text.lines().filter(|l| l.starts_with("f ")).count(), 20_494);
    // the same scene as glTF: what `render --scene` reads back renders as the built-in does
    let glb = dir.join("spheres_box.glb");
    let out = envshadow(&["scene", "spheres_box", "--gltf", glb.to_str().unwrap_or_default()]);
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let render = |scene: &str, name: &str| {
        let exr = dir.join(name);
        let args =
            ["render", "--scene", scene, "--size", "32x24", "--spp", "1", "--out", exr.to_str().unwrap_or_default()];
        let out = envshadow(&args);
        assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
        std::fs::read(dir.join(name.replace(".exr", ".png"))).expect("png")
    };
    assert!(render(glb.to_str().unwrap_or_default(), "a.exr") == render("spheres_box", "b.exr"), "the images differ");
    let out = envshadow(&["scene", "spheres_box"]);
    assert_eq!(out.status.code(), Some(2), "clap asks for --obj or --gltf");
    let out = envshadow(&["scene", "teapot", "--obj", obj.to_str().unwrap_or_default()]);
    assert_eq!(out.status.code(), Some(1));
    assert!(String::from_utf8_lossy(&out.stderr).contains("unknown scene \"teapot\""));
}

#[test]
fn render_writes_images_and_compare_reports_rmse_and_flip() {
    let dir = fresh_dir("cli-render");
    let (a, b) = (dir.join("a.exr"), dir.join("b.exr"));
    let base = ["render", "--scene", "spheres_box", "--size", "64x48", "--spp", "4"];
    let out = envshadow(&[&base[..], &["--seed", "1", "--aovs", "--out", a.to_str().unwrap_or_default()]].concat());
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let line = String::from_utf8_lossy(&out.stdout);
    assert_eq!(line.trim().lines().count(), 1, "one summary line: {line}");
    assert!(line.contains("64 x 48, 4 spp") && line.contains("samples/s"), "{line}");
    for f in ["a.exr", "a.png", "a.albedo.exr", "a.normal.exr", "a.depth.exr", "a.object.exr"] {
        assert!(dir.join(f).exists(), "{f} missing");
    }
    let out = envshadow(
        &[&base[..], &["--seed", "2", "--env-sampling", "complete", "--out", b.to_str().unwrap_or_default()]].concat(),
    );
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let out = envshadow(&[&base[..], &["--env-sampling", "some", "--out", b.to_str().unwrap_or_default()]].concat());
    assert_eq!(out.status.code(), Some(1));
    assert!(String::from_utf8_lossy(&out.stderr).trim().lines().count() == 1);
    let out = envshadow(&["compare", a.to_str().unwrap_or_default(), b.to_str().unwrap_or_default()]);
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let text = String::from_utf8_lossy(&out.stdout);
    let lines: Vec<&str> = text.trim().lines().collect();
    assert_eq!(lines.len(), 2, "{text}");
    let value = |line: &str, key: &str| -> f64 {
        assert!(line.starts_with(key), "{line}");
        line.split_whitespace().nth(1).and_then(|v| v.parse().ok()).unwrap_or(-1.0)
    };
    assert!(value(lines[0], "RMSE") > 0.0);
    assert!(value(lines[1], "FLIP") > 0.0 && lines[1].contains("ACES"), "the tone mapping is stated");
    // identical images: zero
    let out = envshadow(&["compare", a.to_str().unwrap_or_default(), a.to_str().unwrap_or_default()]);
    assert!(String::from_utf8_lossy(&out.stdout).starts_with("RMSE 0.000000\nFLIP 0.000000"));
    // mismatched sizes and bad files: exit 1, one line
    let c = dir.join("c.exr");
    let out = envshadow(&[
        "render",
        "--scene",
        "column",
        "--size",
        "32x24",
        "--spp",
        "1",
        "--out",
        c.to_str().unwrap_or_default(),
    ]);
    assert!(out.status.success());
    for (x, y) in [(&a, &c), (&a, &dir.join("missing.exr"))] {
        let out = envshadow(&["compare", x.to_str().unwrap_or_default(), y.to_str().unwrap_or_default()]);
        assert_eq!(out.status.code(), Some(1));
        assert_eq!(String::from_utf8_lossy(&out.stderr).trim().lines().count(), 1);
    }
}

#[test]
fn render_with_lights_reads_the_light_extract_schema() {
    let dir = fresh_dir("cli-lights");
    let json = dir.join("lights.json");
    std::fs::write(
        &json,
        r#"{"method": "hand", "lights": [{"direction": [0.3, 0.8, 0.5], "solid_angle": 0.001, "radiance": [2000, 1900, 1800], "power": [2, 1.9, 1.8], "extent": 0.02}]}"#,
    )
    .expect("write json");
    let out_path = dir.join("l.exr");
    let args = ["render", "--scene", "spheres_box", "--size", "32x24", "--spp", "2", "--integrator", "lights"];
    let out = envshadow(
        &[&args[..], &["--lights", json.to_str().unwrap_or_default(), "--out", out_path.to_str().unwrap_or_default()]]
            .concat(),
    );
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let img = envmap_sphere::EnvMap::load(&out_path).expect("the render is written");
    assert!(img.pixels().iter().any(|p| p.max_element() > 0.0), "the light lit the scene");
    std::fs::remove_file(&out_path).expect("remove");
    std::fs::write(&json, r#"{"lights": [{"direction": [0, 0, 0], "solid_angle": 0.1, "radiance": [1, 1, 1]}]}"#)
        .expect("write");
    let out = envshadow(
        &[&args[..], &["--lights", json.to_str().unwrap_or_default(), "--out", out_path.to_str().unwrap_or_default()]]
            .concat(),
    );
    assert_eq!(out.status.code(), Some(1));
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(err.contains("lights.json") && err.contains("light 0"), "{err}");
    assert!(!out_path.exists(), "nothing written after an error");
}

#[test]
fn extract_writes_the_four_files_and_a_line_per_light() {
    let dir = PathBuf::from(env!("CARGO_TARGET_TMPDIR")).join("cli-extract");
    let _ = std::fs::remove_dir_all(&dir);
    let map = shared("venice_sunset_1k.hdr");
    let out = envshadow(&[
        "extract",
        map.to_str().unwrap_or_default(),
        "--lights",
        "16",
        "--out",
        dir.to_str().unwrap_or_default(),
    ]);
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let text = String::from_utf8_lossy(&out.stdout);
    assert_eq!(text.lines().filter(|l| l.starts_with("light ")).count(), 16, "{text}");
    assert!(text.contains("median-cut: 16 lights in") && text.contains("light power / map power = 1.0000"), "{text}");
    for f in ["lights.json", "ambient.exr", "lights.gltf", "overlay.png"] {
        assert!(dir.join(f).exists(), "{f} missing");
    }
    // the lights feed the reference tracer's lights integrator
    let img = dir.join("r.exr");
    let render = |scene: &str, json: &Path| {
        let out = envshadow(&[
            "render",
            "--scene",
            scene,
            "--size",
            "32x24",
            "--spp",
            "2",
            "--integrator",
            "lights",
            "--lights",
            json.to_str().unwrap_or_default(),
            "--out",
            img.to_str().unwrap_or_default(),
        ]);
        assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    };
    render("spheres_box", &dir.join("lights.json"));
    // +residual: a signed ambient.exr, which render reads with its signs
    let residual = dir.join("residual");
    let out = envshadow(&[
        "extract",
        map.to_str().unwrap_or_default(),
        "--method",
        "median-cut+above-horizon+residual",
        "--lights",
        "16",
        "--out",
        residual.to_str().unwrap_or_default(),
    ]);
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let keep = envmap_sphere::LoadOptions { negative: envmap_sphere::NegativePolicy::Keep, ..Default::default() };
    let (ambient, _) = envmap_sphere::EnvMap::load_with(residual.join("ambient.exr"), &keep).expect("ambient.exr");
    assert!(ambient.pixels().iter().any(|p| p.min_element() < 0.0), "the residual is signed");
    render("glossy_set", &residual.join("lights.json"));
    let out = envshadow(&["extract", map.to_str().unwrap_or_default(), "--method", "nope"]);
    assert_eq!(out.status.code(), Some(1));
    assert!(
        String::from_utf8_lossy(&out.stderr)
            .contains("emissive-split, center-surround, median-cut, variance-min, importance")
    );
}

#[test]
fn composite_json_has_the_interface_keys_and_writes_the_images() {
    let dir = fresh_dir("cli-composite");
    let out = dir.join("c.png");
    let args = ["composite", "--scene", "ar_ground", "--object", "sphere", "--at", "0,0.3,1", "--passes", "10"];
    let size = ["--size", "64x48", "--spp", "8"];
    let run = envshadow(&[&args[..], &size, &["--out", out.to_str().unwrap_or_default(), "--json"]].concat());
    assert!(run.status.success(), "{}", String::from_utf8_lossy(&run.stderr));
    let text = String::from_utf8_lossy(&run.stdout);
    assert_eq!(text.trim().lines().count(), 1, "one JSON object on one line: {text}");
    let v: serde_json::Value = serde_json::from_str(&text).expect("valid JSON");
    for k in ["passes", "ms_per_frame", "error_mae_codes", "debevec_error_mae_codes", "error_rmse_codes"] {
        assert!(v.get(k).is_some_and(serde_json::Value::is_number), "missing number {k} in {v}");
    }
    assert!(v["adapter"].as_str().is_some_and(|a| !a.is_empty()), "{v}");
    assert_eq!(v["passes"].as_u64(), Some(10));
    assert!(v["ms_per_frame"].as_f64().unwrap_or(0.0) > 0.0);
    for f in ["c.png", "c_photo.png", "c_truth.png", "c_debevec.png", "c_error.png"] {
        assert!(dir.join(f).is_file(), "{f} missing");
    }
    // bad input: one line naming what is wrong, exit 1
    for (bad, want) in [(["--object", "teapot"], "teapot"), (["--at", "1,2"], "--at")] {
        let run =
            envshadow(&[&["composite", "--scene", "ar_ground", "--size", "16x12", "--spp", "1"][..], &bad].concat());
        assert_eq!(run.status.code(), Some(1), "{bad:?}");
        let err = String::from_utf8_lossy(&run.stderr);
        assert!(err.trim().lines().count() == 1 && err.contains(want), "{err}");
    }
}

#[test]
fn composite_takes_a_model_fitted_where_the_builtin_would_stand() {
    // a box of another size, elsewhere, with the built-in box's albedo, as a .glb: fitted into
    // the 0.6 m cube at --at, it is the built-in box, so the composite and its error agree
    let dir = fresh_dir("cli-composite-model");
    let mut model = scene::Scene::builtin("three_boxes").expect("three_boxes");
    model.objects = vec![scene::Object {
        name: "crate".into(),
        mesh: scene::Mesh::cuboid(glam::Vec3::splat(-7.0), glam::Vec3::splat(-4.0)),
        material: scene::Material::rgb(glam::Vec3::new(0.7, 0.7, 0.65), None),
    }];
    let glb = dir.join("crate.glb");
    model.write_gltf(&glb).expect("write crate.glb");
    let glb = glb.to_str().unwrap_or_default();
    let composite = |object: &str, extra: &[&str]| {
        let args = ["composite", "--scene", "ar_ground", "--at", "0,0.3,1", "--passes", "10", "--size", "64x48"];
        let out = dir.join(format!("{}.png", extra.len()));
        let run = envshadow(
            &[
                &args[..],
                &["--spp", "8", "--json", "--object", object, "--out", out.to_str().unwrap_or_default()],
                extra,
            ]
            .concat(),
        );
        assert!(run.status.success(), "{object}: {}", String::from_utf8_lossy(&run.stderr));
        serde_json::from_slice::<serde_json::Value>(&run.stdout).expect("JSON")
    };
    let (builtin, fitted, larger) =
        (composite("box", &[]), composite(glb, &[]), composite(glb, &["--object-size", "1.2"]));
    for k in ["error_mae_codes", "error_rmse_codes", "debevec_error_mae_codes"] {
        let (a, b) = (builtin[k].as_f64().unwrap_or(f64::NAN), fitted[k].as_f64().unwrap_or(f64::NAN));
        assert!((a - b).abs() < 0.02 * a.max(0.1), "{k}: built-in box {a}, fitted model {b}");
    }
    assert_ne!(builtin["debevec_error_mae_codes"], larger["debevec_error_mae_codes"], "--object-size changed nothing");
    // a model that cannot be read is refused before the capture, naming the file
    let missing = dir.join("missing.glb");
    for (object, want) in [(missing.to_str().unwrap_or_default(), "missing.glb"), (glb, "size")] {
        let size = if object == glb { "0" } else { "0.6" };
        let run = envshadow(&["composite", "--scene", "ar_ground", "--object", object, "--object-size", size]);
        assert_eq!(run.status.code(), Some(1), "{object}");
        let err = String::from_utf8_lossy(&run.stderr);
        assert!(err.trim().lines().count() == 1 && err.contains(want), "{err}");
    }
}

/// A unit cube [0, 1]³ as `cube.gltf` + `cube.bin` in `dir`.
fn write_cube_gltf(dir: &Path) -> PathBuf {
    let mut bin: Vec<u8> = (0..8)
        .flat_map(|i| [(i & 1) as f32, ((i >> 1) & 1) as f32, ((i >> 2) & 1) as f32])
        .flat_map(f32::to_le_bytes)
        .collect();
    let faces: [[u16; 4]; 6] = [[0, 2, 3, 1], [4, 5, 7, 6], [0, 1, 5, 4], [2, 6, 7, 3], [0, 4, 6, 2], [1, 3, 7, 5]];
    bin.extend(faces.iter().flat_map(|f| [f[0], f[1], f[2], f[0], f[2], f[3]]).flat_map(u16::to_le_bytes));
    std::fs::write(dir.join("cube.bin"), &bin).expect("write bin");
    let json = r#"{"asset": {"version": "2.0"}, "scene": 0, "scenes": [{"nodes": [0]}], "nodes": [{"mesh": 0}],
      "meshes": [{"primitives": [{"attributes": {"POSITION": 0}, "indices": 1}]}],
      "buffers": [{"uri": "cube.bin", "byteLength": 168}],
      "bufferViews": [{"buffer": 0, "byteLength": 96}, {"buffer": 0, "byteOffset": 96, "byteLength": 72}],
      "accessors": [{"bufferView": 0, "componentType": 5126, "count": 8, "type": "VEC3", "min": [0, 0, 0], "max": [1, 1, 1]},
                    {"bufferView": 1, "componentType": 5123, "count": 36, "type": "SCALAR"}]}"#;
    let path = dir.join("cube.gltf");
    std::fs::write(&path, json).expect("write gltf");
    path
}

#[test]
fn render_takes_a_gltf_model_with_a_ground_and_a_camera_of_ones_own() {
    let dir = fresh_dir("cli-render-gltf");
    let cube = write_cube_gltf(&dir);
    let out_path = dir.join("cube.exr");
    let args = [
        "render",
        "--scene",
        cube.to_str().unwrap_or_default(),
        "--ground",
        "--size",
        "64x32",
        "--spp",
        "2",
        "--eye",
        "0.5,0.5,5",
        "--target",
        "0.5,0.5,0",
        "--fov",
        "30",
        "--aovs",
        "--out",
        out_path.to_str().unwrap_or_default(),
    ];
    let out = envshadow(&args);
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    // the centre pixel's ray meets the cube's front face z = 1 at distance 4
    let depth = envmap_sphere::EnvMap::load(dir.join("cube.depth.exr")).expect("depth");
    let centre = depth.pixel(32, 16).x;
    assert!((centre - 4.0).abs() < 0.05, "depth at the centre {centre}");
    // the ground lies at the cube's lowest point, y = 0: the bottom row sees it, nearer than the sky
    let bottom = depth.pixel(32, 31).x;
    assert!(bottom > 0.0, "the bottom row misses the ground");
}

#[test]
fn bad_models_exit_one_with_one_line_naming_the_file() {
    let dir = fresh_dir("cli-bad-models");
    let cube = write_cube_gltf(&dir);
    let json = std::fs::read_to_string(&cube).expect("read cube.gltf");
    let bin = std::fs::read(dir.join("cube.bin")).expect("read cube.bin");
    let out_path = dir.join("out.exr");
    let write = |name: &str, json: &str, bin: &[u8]| {
        let b = format!("{name}.bin");
        std::fs::write(dir.join(&b), bin).expect("write bin");
        let p = dir.join(format!("{name}.gltf"));
        std::fs::write(&p, json.replace("cube.bin", &b)).expect("write gltf");
        p
    };
    let html = dir.join("page.glb");
    std::fs::write(&html, "<!DOCTYPE html><html><body>404</body></html>").expect("write");
    // a GLB header promising more than the file holds
    let truncated = dir.join("truncated.glb");
    let mut t = b"glTF".to_vec();
    t.extend(2u32.to_le_bytes());
    t.extend(4000u32.to_le_bytes());
    t.extend(100u32.to_le_bytes());
    t.extend(b"JSON{\"asset\"");
    std::fs::write(&truncated, t).expect("write");
    let missing = dir.join("missing.gltf");
    std::fs::write(&missing, json.replace("cube.bin", "nowhere.bin")).expect("write");
    let long = write("long", &json.replacen(r#""count": 8"#, r#""count": 4000000000"#, 1), &bin);
    let mut past = bin.clone();
    past[96..98].copy_from_slice(&900u16.to_le_bytes());
    let past = write("past", &json, &past);
    let mut nan = bin.clone();
    nan[12..16].copy_from_slice(&f32::NAN.to_le_bytes());
    let nan = write("nan", &json, &nan);
    let points = write("points", &json.replace(r#""indices": 1}"#, r#""indices": 1, "mode": 0}"#), &bin);
    let cases = [
        (&html, "not a readable glTF"),
        (&truncated, "not a readable glTF"),
        (&missing, "nowhere.bin"),
        (&long, "runs past"),
        (&past, "index 900"),
        (&nan, "not finite"),
        (&points, "no triangles"),
    ];
    for (path, why) in cases {
        let p = path.to_str().unwrap_or_default();
        let out = envshadow(&["render", "--scene", p, "--spp", "1", "--out", out_path.to_str().unwrap_or_default()]);
        assert_eq!(out.status.code(), Some(1), "{p}");
        let err = String::from_utf8_lossy(&out.stderr);
        assert_eq!(err.trim().lines().count(), 1, "{p}: {err}");
        assert!(err.contains(p) && err.contains(why), "{p}: wanted {why:?} in {err}");
    }
}

#[test]
fn composite_onto_a_map_has_the_interface_keys_and_refuses_bad_input() {
    let dir = fresh_dir("cli-backdrop");
    let cube = write_cube_gltf(&dir);
    let cube = cube.to_str().unwrap_or_default();
    let map = shared("courtyard.exr");
    let map = map.to_str().unwrap_or_default();
    let out = dir.join("b.png");
    let small = ["--size", "48x36", "--truth-spp", "16", "--catcher-spp", "4", "--passes", "10"];
    let run = envshadow(
        &[
            &["composite", "--envmap", map, "--object", cube, "--at", "0.2,0,3"][..],
            &small,
            &["--out", out.to_str().unwrap_or_default(), "--json"],
        ]
        .concat(),
    );
    assert!(run.status.success(), "{}", String::from_utf8_lossy(&run.stderr));
    let text = String::from_utf8_lossy(&run.stdout);
    assert_eq!(text.trim().lines().count(), 1, "one JSON object on one line: {text}");
    let v: serde_json::Value = serde_json::from_str(&text).expect("valid JSON");
    for k in ["ms_per_frame", "error_rmse_codes", "pathtraced_error_rmse_codes", "pathtraced_ms", "changed_pixels"] {
        assert!(v.get(k).is_some_and(serde_json::Value::is_number), "missing number {k} in {v}");
    }
    assert!(v["sources_excluded"].is_u64() && v["adapter"].as_str().is_some_and(|a| !a.is_empty()), "{v}");
    assert!(v["changed_pixels"].as_u64().unwrap_or(0) > 20, "the cube changes the image: {v}");
    assert!(v["sources_excluded"].as_u64() <= v["sources"].as_u64(), "{v}");
    // the GPU's stages timed as the issue asks where the adapter can (lavapipe can)
    assert!(["GPU timestamps", "wall time (submit + wait)"].contains(&v["clock"].as_str().unwrap_or_default()), "{v}");
    // the camera looks at the cube from the map's centre of projection, 1.6 m up
    let eye: Vec<f64> =
        v["eye"].as_array().map(|a| a.iter().filter_map(serde_json::Value::as_f64).collect()).unwrap_or_default();
    assert!(eye.len() == 3 && eye[0] == 0.0 && (eye[1] - 1.6).abs() < 1e-6 && eye[2] == 0.0, "{v}");
    for f in ["b.png", "b.exr", "b_plate.png", "b_truth.png", "b_truth.exr", "b_catcher.png", "b_error.png"] {
        assert!(dir.join(f).is_file(), "{f} missing");
    }
    // a missing map, a camera under the ground, a bad model, a bad height: one line, exit 1
    let missing = dir.join("missing.exr");
    let cases: [(&[&str], &str); 4] = [
        (&["--envmap", missing.to_str().unwrap_or_default()], "missing.exr"),
        (&["--envmap", map, "--eye", "0,-1,0", "--target", "0,0,3"], "not above the ground"),
        (&["--envmap", map, "--object", "teapot"], "teapot"),
        (&["--envmap", map, "--camera-height", "0"], "camera height"),
    ];
    for (bad, want) in cases {
        let run = envshadow(&[&["composite"][..], bad, &small].concat());
        assert_eq!(run.status.code(), Some(1), "{bad:?}");
        let err = String::from_utf8_lossy(&run.stderr);
        let lines: Vec<&str> = err.lines().filter(|l| !l.contains("XDG_RUNTIME_DIR")).collect();
        assert!(lines.len() == 1 && lines[0].contains(want), "{bad:?}: {err}");
    }
    // the plate as the user's photograph, the map as its probe, the same camera: the same
    // composite, near enough
    let plate = dir.join("b_plate.png");
    let target: Vec<String> = v["target"]
        .as_array()
        .map(|a| a.iter().filter_map(serde_json::Value::as_f64).map(|x| x.to_string()).collect())
        .unwrap_or_default();
    let target = target.join(",");
    let photo_out = dir.join("p.png");
    let photo_args = ["--photo", plate.to_str().unwrap_or_default(), "--probe", map, "--eye", "0,1.6,0"];
    let run = envshadow(
        &[
            &["composite"][..],
            &photo_args,
            &["--target", &target, "--object", cube, "--at", "0.2,0,3"],
            &small,
            &["--out", photo_out.to_str().unwrap_or_default(), "--json"],
        ]
        .concat(),
    );
    assert!(run.status.success(), "{}", String::from_utf8_lossy(&run.stderr));
    let p: serde_json::Value = serde_json::from_str(&String::from_utf8_lossy(&run.stdout)).expect("valid JSON");
    for k in ["ms_per_frame", "error_rmse_codes", "pathtraced_error_rmse_codes", "pathtraced_ms", "changed_pixels"] {
        assert!(p.get(k).is_some_and(serde_json::Value::is_number), "missing number {k} in {p}");
    }
    assert!(p["photo_exposure"].as_f64().is_some_and(|x| x > 0.0) && p["clipped_pixels"].is_u64(), "{p}");
    let (ours, backdrop) =
        (p["error_rmse_codes"].as_f64().unwrap_or(f64::NAN), v["error_rmse_codes"].as_f64().unwrap_or(0.0));
    assert!(ours < 1.5 * backdrop + 1.0, "photograph {ours} codes against the backdrop's {backdrop}");
    assert!(dir.join("p_truth.png").is_file() && dir.join("p_error.png").is_file());
    // a probe that is not a map (a PNG; a 4:3 EXR), a photograph of another aspect, a camera
    // under the ground, a missing photograph: one line, exit 1
    let not_probe = dir.join("b_truth.exr");
    let missing_photo = dir.join("missing.png");
    let photo = plate.to_str().unwrap_or_default();
    let cases: [(&[&str], &str); 5] = [
        (&["--photo", photo, "--probe", photo, "--eye", "0,1.6,0", "--target", "0,0,3"], "b_plate.png"),
        (
            &[
                "--photo",
                photo,
                "--probe",
                not_probe.to_str().unwrap_or_default(),
                "--eye",
                "0,1.6,0",
                "--target",
                "0,0,3",
            ],
            "not a light probe",
        ),
        (&["--photo", photo, "--probe", map, "--eye", "0,1.6,0", "--target", "0,0,3", "--size", "48x48"], "aspect"),
        (&["--photo", photo, "--probe", map, "--eye", "0,-1,0", "--target", "0,0,3"], "not above the ground"),
        (
            &[
                "--photo",
                missing_photo.to_str().unwrap_or_default(),
                "--probe",
                map,
                "--eye",
                "0,1.6,0",
                "--target",
                "0,0,3",
            ],
            "missing.png",
        ),
    ];
    for (bad, want) in cases {
        let run = envshadow(&[&["composite"][..], bad, &["--truth-spp", "2", "--catcher-spp", "1"]].concat());
        assert_eq!(run.status.code(), Some(1), "{bad:?}");
        let err = String::from_utf8_lossy(&run.stderr);
        let lines: Vec<&str> = err.lines().filter(|l| !l.contains("XDG_RUNTIME_DIR")).collect();
        assert!(lines.len() == 1 && lines[0].contains(want), "{bad:?}: {err}");
    }
}

/// `envshadow view ARGS` under `xvfb-run -a` (a display of its own; `cargo xtask test` installs
/// Xvfb where it installs lavapipe).
fn view_in_xvfb(args: &[&str]) -> Output {
    Command::new("xvfb-run")
        .arg("-a")
        .arg(env!("CARGO_BIN_EXE_envshadow"))
        .arg("view")
        .args(args)
        .output()
        .expect("run xvfb-run (Xvfb is installed by `cargo xtask test`, or apt-get install xvfb xauth)")
}

fn view_json(out: &Output) -> serde_json::Value {
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let text = String::from_utf8_lossy(&out.stdout);
    let line = text.lines().last().unwrap_or_default();
    serde_json::from_str(line).unwrap_or_else(|e| panic!("not one JSON object ({e}): {text}"))
}

fn png_rgb(path: &Path) -> ((u32, u32), Vec<[u8; 3]>) {
    let img = image::open(path).unwrap_or_else(|e| panic!("{}: {e}", path.display())).to_rgb8();
    (img.dimensions(), img.pixels().map(|p| p.0).collect())
}

#[test]
fn view_in_a_window_shows_the_offscreen_frame_and_a_bad_dropped_file_leaves_it_running() {
    let dir = fresh_dir("cli-view");
    let cube = write_cube_gltf(&dir);
    let bad = dir.join("broken.hdr");
    std::fs::write(&bad, "#?RADIANCE\nnot a map").expect("write");
    let map = shared("city.exr");
    let (win, off) = (dir.join("window.png"), dir.join("offscreen.png"));
    let common = |shot: &Path| -> Vec<String> {
        [
            "--scene",
            cube.to_str().unwrap_or_default(),
            "--ground",
            "--envmap",
            map.to_str().unwrap_or_default(),
            "--technique",
            "wedges",
            "--lights",
            "8",
            "--frames",
            "3",
            "--orbit",
            "10",
            "--size",
            "96x64",
            "--screenshot",
            shot.to_str().unwrap_or_default(),
            "--json",
            "--no-panel",
        ]
        .map(String::from)
        .to_vec()
    };
    // the window, with a broken map dropped after the first frame
    let mut args = common(&win);
    args.extend(["--drop".to_string(), bad.to_string_lossy().into_owned()]);
    let args: Vec<&str> = args.iter().map(String::as_str).collect();
    let shown = view_json(&view_in_xvfb(&args));
    for key in ["frames", "median_ms", "technique", "adapter"] {
        assert!(!shown[key].is_null(), "no {key}: {shown}");
    }
    assert_eq!(shown["frames"], 3, "{shown}");
    assert_eq!(shown["technique"], "wedges");
    assert!(shown["median_ms"].as_f64().is_some_and(|ms| ms > 0.0), "{shown}");
    assert!(!shown["adapter"].as_str().unwrap_or_default().is_empty());
    // what was shown, copied from the window's own image
    assert_eq!(shown["screenshot_from"], "window", "{shown}");
    let messages = shown["messages"].as_array().cloned().unwrap_or_default();
    assert_eq!(messages.len(), 1, "{shown}");
    assert!(messages[0].as_str().unwrap_or_default().contains("broken.hdr"), "{shown}");
    // the same frames with no window and nothing dropped
    let args = common(&off);
    let mut args: Vec<&str> = args.iter().map(String::as_str).collect();
    args.insert(0, "--offscreen");
    let mut all = vec!["view"];
    all.extend(args);
    let drawn = view_json(&envshadow(&all));
    assert_eq!(drawn["screenshot_from"], "offscreen");
    assert_eq!(drawn["lights_shadowed"], shown["lights_shadowed"]);
    let ((w, h), a) = png_rgb(&win);
    let (size, b) = png_rgb(&off);
    assert_eq!(((w, h), size), ((96, 64), (96, 64)));
    // the frame shows the cube and its ground, not one flat colour
    assert!(a.iter().any(|p| *p != a[0]), "a flat image");
    // measured: bit-identical on lavapipe under Xvfb (FLIP 0); the bound leaves a surface's
    // own conversion room
    let flip = ref_tracer::metrics::flip_rgb8(&b, &a, w, h);
    assert!(flip <= 0.01, "FLIP {flip} between the window and the offscreen frame");
    // with its panel, and the difference from a reference: the window as shown, panel included
    let panel = dir.join("panel.png");
    let mut args = common(&panel);
    args.retain(|a| a != "--no-panel");
    if let Some(k) = args.iter().position(|a| a == "96x64") {
        args[k] = "320x240".into();
    }
    args.extend(["--reference", "8", "--show", "difference"].map(String::from));
    let args: Vec<&str> = args.iter().map(String::as_str).collect();
    let shown = view_json(&view_in_xvfb(&args));
    assert_eq!(shown["reference"]["spp"], 8, "{shown}");
    let ((w, h), c) = png_rgb(&panel);
    assert_eq!((w, h), (320, 240));
    // the panel's text: many pixels near white, which the frame under a white-grey exposure
    // does not reach in a difference view (dimmed to a quarter)
    let bright = c.iter().filter(|p| p.iter().all(|v| *v > 180)).count();
    assert!(bright > 200, "{bright} bright pixels: no panel drawn?");
}

#[test]
fn view_held_still_refines_its_reference_in_the_background_and_measures_the_frame() {
    let dir = fresh_dir("cli-view-hold");
    let (held, plain) = (dir.join("held.png"), dir.join("plain.png"));
    let run = |shot: &Path, hold: &[&str]| {
        let mut args = vec!["--size", "64x48", "--lights", "8", "--frames", "2", "--no-panel", "--json"];
        args.extend(["--screenshot", shot.to_str().unwrap_or_default()]);
        args.extend(hold);
        view_json(&view_in_xvfb(&args))
    };
    // the window's own path: the frames done, the view still, the thread refining, the frame
    // read back and measured, the difference shown
    let j = run(&held, &["--hold", "6", "--show", "difference"]);
    let live = &j["live_reference"];
    assert_eq!(j["frames"], 2, "{j}");
    assert!(live["spp"].as_u64().is_some_and(|n| n >= 4), "{j}");
    let f = |k: &str| live[k].as_f64().unwrap_or(f64::NAN);
    assert!(f("rmse") > 0.0 && f("rmse_without_noise") <= f("rmse"), "{j}");
    assert!(f("flip") > 0.0 && f("flip") < 1.0, "{j}");
    assert!(f("noise_rmse") > 0.0 && f("noise_rmse") < f("rmse"), "{j}");
    let plain_json = run(&plain, &[]);
    assert!(plain_json["live_reference"].is_null());
    let ((w, h), a) = png_rgb(&held);
    let (_, b) = png_rgb(&plain);
    assert_eq!((w, h), (64, 48));
    assert!(a != b, "the held window does not show the difference");
}

#[test]
fn view_measures_its_frame_against_a_reference_and_shadows_bring_it_closer() {
    let dir = fresh_dir("cli-view-reference");
    let run = |technique: &str, diff: &Path| {
        let out = envshadow(&[
            "view",
            "--offscreen",
            "--frames",
            "2",
            "--size",
            "64x48",
            "--lights",
            "16",
            "--technique",
            technique,
            "--reference",
            "64",
            "--difference",
            diff.to_str().unwrap_or_default(),
            "--json",
        ]);
        view_json(&out)
    };
    let (shadowed, flat) = (run("paper001", &dir.join("a.png")), run("none", &dir.join("b.png")));
    let r = &shadowed["reference"];
    for key in ["spp", "seconds", "noise_rmse", "rmse", "rmse_without_noise", "flip", "reached_rmse", "reached_flip"] {
        assert!(r.get(key).is_some(), "no reference.{key}: {shadowed}");
    }
    assert_eq!(r["spp"], 64);
    let e = |j: &serde_json::Value, k: &str| j["reference"][k].as_f64().unwrap_or(f64::NAN);
    assert!(e(&shadowed, "rmse_without_noise") <= e(&shadowed, "rmse"));
    // the same lights unshadowed are farther from the truth, in RMSE and FLIP
    assert!(e(&shadowed, "rmse_without_noise") < e(&flat, "rmse_without_noise"), "{shadowed}\n{flat}");
    assert!(e(&shadowed, "flip") < e(&flat, "flip"), "{shadowed}\n{flat}");
    // the unshadowed frame is reached sooner than the shadowed one, if at all
    let reached = |j: &serde_json::Value| j["reference"]["reached_rmse"]["spp"].as_u64().unwrap_or(u64::MAX);
    assert!(reached(&flat) <= reached(&shadowed), "{shadowed}\n{flat}");
    let (size, a) = png_rgb(&dir.join("a.png"));
    let (_, b) = png_rgb(&dir.join("b.png"));
    assert_eq!(size, (64, 48));
    assert!(a != b, "the two differences are one image");
}

#[test]
fn view_refuses_bad_arguments_and_files_in_one_line() {
    let dir = fresh_dir("cli-view-bad");
    let missing = dir.join("missing.exr");
    let m = missing.to_str().unwrap_or_default();
    for args in [
        vec!["view", "--offscreen", "--frames", "1", "--technique", "raytraced"],
        vec!["view", "--offscreen", "--frames", "0"],
        vec!["view", "--offscreen", "--frames", "1", "--lights", "0"],
        vec!["view", "--offscreen", "--frames", "1", "--envmap", m],
        vec!["view", "--offscreen", "--frames", "1", "--scene", "nowhere.glb"],
        vec!["view", "--offscreen", "--frames", "1", "--reference", "1"],
        vec!["view", "--offscreen", "--frames", "1", "--show", "truth"],
        vec!["view", "--offscreen", "--frames", "1", "--hold", "2"],
        vec!["view", "--frames", "1", "--hold", "nan"],
    ] {
        let out = envshadow(&args);
        assert_eq!(out.status.code(), Some(1), "{args:?}");
        let err = String::from_utf8_lossy(&out.stderr);
        assert_eq!(err.trim().lines().count(), 1, "{args:?}: {err}");
        assert!(out.stdout.is_empty(), "{args:?}");
    }
    let err = String::from_utf8_lossy(&envshadow(&["view", "--offscreen", "--frames", "1", "--envmap", m]).stderr)
        .into_owned();
    assert!(err.contains("missing.exr"), "{err}");
}
