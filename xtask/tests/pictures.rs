//! The README's pictures (`docs/pictures/`) are what `cargo xtask pictures` makes from the
//! current code, within the FLIP of `docs/pictures/flip.json`, and the check finds a picture
//! that is not: one run over a copy of the folder with one picture spoiled and one of the
//! trade's errors moved (so its plot is no longer the one drawn from it either).

use std::path::Path;
use std::process::Command;

#[test]
fn committed_pictures_are_what_the_code_makes_now() {
    let committed = Path::new(env!("CARGO_MANIFEST_DIR")).join("../docs/pictures");
    let copy = std::env::temp_dir().join(format!("envshadow-pictures-test-{}", std::process::id()));
    std::fs::create_dir_all(&copy).expect("temp folder");
    let names = [
        "model_reference.png",
        "model_gpu_wedges.png",
        "map_lights.png",
        "flip.json",
        "trade_front.json",
        "trade_front.svg",
    ];
    for name in names {
        std::fs::copy(committed.join(name), copy.join(name)).unwrap_or_else(|e| panic!("docs/pictures/{name}: {e}"));
    }
    // the map's picture mirrored left to right: the same colours, in other places
    let (w, h, pixels) = envmap_sphere::io::load_png_srgb8(&copy.join("map_lights.png")).expect("a PNG");
    let mirrored: Vec<u8> = (0..h)
        .flat_map(|y| (0..w).rev().map(move |x| (x, y)))
        .flat_map(|(x, y)| pixels[(y * w + x) as usize])
        .collect();
    envmap_sphere::io::save_png_srgb8(&copy.join("map_lights.png"), w, h, &mirrored).expect("write");
    // the trade's first setting 20 % worse than measured
    let run_path = copy.join("trade_front.json");
    let mut run: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&run_path).expect("trade_front.json")).expect("JSON");
    let first = &mut run["rows"][0];
    let moved = first["setting"].as_str().expect("a setting").to_string();
    first["rmse"] = serde_json::json!(first["rmse"].as_f64().expect("an RMSE") * 1.2);
    std::fs::write(&run_path, serde_json::to_string_pretty(&run).expect("JSON")).expect("write");
    let out = Command::new(env!("CARGO_BIN_EXE_xtask"))
        .args(["pictures", "--check", "--out"])
        .arg(&copy)
        .output()
        .expect("run xtask");
    let (stdout, stderr) = (String::from_utf8_lossy(&out.stdout), String::from_utf8_lossy(&out.stderr));
    std::fs::remove_dir_all(&copy).ok();
    assert!(!out.status.success(), "the spoiled picture must fail the check:\n{stdout}\n{stderr}");
    assert!(stderr.contains("map_lights.png: mean FLIP"), "{stderr}");
    assert!(stderr.contains("trade_front.svg: not what the code draws"), "{stderr}");
    assert!(stderr.contains(&format!("trade_front.json: {moved} RMSE")), "{stderr}");
    assert_eq!(stderr.matches("trade_front.json: ").count(), 1, "only the moved setting fails:\n{stderr}\n{stdout}");
    for name in ["model_reference.png", "model_gpu_wedges.png"] {
        assert!(!stderr.contains(&format!("{name}:")), "{name} is not what the code makes now:\n{stderr}\n{stdout}");
        assert!(stdout.contains(&format!("pictures: {name} mean FLIP")), "{name} was not compared:\n{stdout}");
    }
}
