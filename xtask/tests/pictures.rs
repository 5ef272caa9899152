//! The README's pictures (`docs/pictures/`) are what `cargo xtask pictures` makes from the
//! current code, within the FLIP of `docs/pictures/flip.json`, and the check finds a picture
//! that is not: one run over a copy of the folder with one picture spoiled.

use std::path::Path;
use std::process::Command;

#[test]
fn committed_pictures_are_what_the_code_makes_now() {
    let committed = Path::new(env!("CARGO_MANIFEST_DIR")).join("../docs/pictures");
    let copy = std::env::temp_dir().join(format!("envshadow-pictures-test-{}", std::process::id()));
    std::fs::create_dir_all(&copy).expect("temp folder");
    let names = ["model_reference.png", "model_gpu_wedges.png", "map_lights.png", "flip.json"];
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
    let out = Command::new(env!("CARGO_BIN_EXE_xtask"))
        .args(["pictures", "--check", "--out"])
        .arg(&copy)
        .output()
        .expect("run xtask");
    let (stdout, stderr) = (String::from_utf8_lossy(&out.stdout), String::from_utf8_lossy(&out.stderr));
    std::fs::remove_dir_all(&copy).ok();
    assert!(!out.status.success(), "the spoiled picture must fail the check:\n{stdout}\n{stderr}");
    assert!(stderr.contains("map_lights.png: mean FLIP"), "{stderr}");
    for name in ["model_reference.png", "model_gpu_wedges.png"] {
        assert!(!stderr.contains(&format!("{name}:")), "{name} is not what the code makes now:\n{stderr}\n{stdout}");
        assert!(stdout.contains(&format!("pictures: {name} mean FLIP")), "{name} was not compared:\n{stdout}");
    }
}
