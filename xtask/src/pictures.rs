//! `cargo xtask pictures`: the README's pictures, made by the current code. A model of
//! `assets/models/` on the default map with its soft shadows, as the GPU draws it with wedges
//! and as the reference tracer renders it (`validate --quick`'s images), and the default map
//! with the lights extracted from it, and the trade's plot for that model (the quick preset's
//! environment-lit settings: error against ms per frame, the Pareto front drawn; the run behind
//! it kept as `trade_front.json`). `--check` makes them again in a temporary folder and fails when
//! an image differs from the committed picture by more than its FLIP in `docs/pictures/flip.json`
//! (data, not code), when the committed plot is not what the code draws from the committed run,
//! or, on the committed run's adapter, when a setting's error moved by more than the relative
//! tolerance given there (times are one run's, never checked).

use clap::Parser;
use std::path::{Path, PathBuf};

/// The model shown, from the workspace root.
const MODEL: &str = "assets/models/BoxTextured.gltf";
/// The trade's plot and the run it is drawn from.
const TRADE_SVG: &str = "trade_front.svg";
const TRADE_JSON: &str = "trade_front.json";
/// The truth's samples per pixel for the plot: its own noise well under the errors plotted.
const TRADE_TRUTH_SPP: &str = "1024";

/// Options of `cargo xtask pictures`.
#[derive(clap::Parser, Clone, Debug)]
pub struct PicturesArgs {
    /// Folder of the pictures (and of `flip.json`).
    #[arg(long, default_value = "docs/pictures")]
    pub out: PathBuf,
    /// Make the pictures in a temporary folder and compare them with those in `--out`.
    #[arg(long)]
    pub check: bool,
    /// The GPU adapter, as for validate.
    #[arg(long)]
    pub adapter: Option<String>,
}

fn root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("..")
}

/// Makes every picture in `dir`; their file names.
fn make(dir: &Path, adapter: Option<&str>) -> Result<Vec<&'static str>, String> {
    std::fs::create_dir_all(dir).map_err(|e| format!("{}: {e}", dir.display()))?;
    let work = dir.join("validate");
    let model = root().join(MODEL);
    let mut argv: Vec<String> = ["validate", "--ground", "--quick"].map(String::from).to_vec();
    argv.extend(["--scene".into(), model.display().to_string(), "--out".into(), work.display().to_string()]);
    if let Some(a) = adapter {
        argv.extend(["--adapter".into(), a.to_string()]);
    }
    crate::validate::run(&crate::validate::ValidateArgs::parse_from(argv))?;
    let copies = [("reference.png", "model_reference.png"), ("gpu_wedges.png", "model_gpu_wedges.png")];
    for (from, to) in copies {
        std::fs::copy(work.join(from), dir.join(to)).map_err(|e| format!("{}: {e}", work.join(from).display()))?;
    }
    std::fs::remove_dir_all(&work).map_err(|e| format!("{}: {e}", work.display()))?;
    let map = envmap_sphere::default_map();
    let extractor = light_extract::extractor(light_extract::DEFAULT_METHOD, 32).ok_or("the default method")?;
    let lights = extractor.extract(&map).map_err(|e| e.to_string())?.lights;
    light_extract::overlay::write_overlay(&dir.join("map_lights.png"), &map, &lights).map_err(|e| e.to_string())?;
    trade_run(dir, &model, adapter)?;
    let svg = trade_svg(&read_run(dir)?)?;
    std::fs::write(dir.join(TRADE_SVG), svg).map_err(|e| format!("{}: {e}", dir.join(TRADE_SVG).display()))?;
    Ok(vec!["model_reference.png", "model_gpu_wedges.png", "map_lights.png"])
}

/// The quick trade on the model with its ground, its run kept as [`TRADE_JSON`].
fn trade_run(dir: &Path, model: &Path, adapter: Option<&str>) -> Result<(), String> {
    let work = dir.join("trade");
    let mut argv: Vec<String> =
        ["xtask", "trade", "--quick", "--ground", "--truth-spp", TRADE_TRUTH_SPP].map(String::from).to_vec();
    argv.extend(["--scenes".into(), model.display().to_string(), "--out".into(), work.display().to_string()]);
    if let Some(a) = adapter {
        argv.extend(["--adapter".into(), a.to_string()]);
    }
    let crate::Command::Trade(args) = crate::Cli::parse_from(argv).command else {
        return Err("pictures: the trade's command line parsed as another command".into());
    };
    crate::trade::run(&args)?;
    let from = work.join("trade.json");
    std::fs::copy(&from, dir.join(TRADE_JSON)).map_err(|e| format!("{}: {e}", from.display()))?;
    std::fs::remove_dir_all(&work).map_err(|e| format!("{}: {e}", work.display()))
}

fn read_run(dir: &Path) -> Result<trade::Run, String> {
    let p = dir.join(TRADE_JSON);
    let text = std::fs::read_to_string(&p).map_err(|e| format!("{}: {e}", p.display()))?;
    serde_json::from_str(&text).map_err(|e| format!("{}: not a trade run: {e}", p.display()))
}

/// The plot of a run's environment-lit settings, as the README shows it.
fn trade_svg(run: &trade::Run) -> Result<String, String> {
    let points = trade::overall(&run.rows, trade::Family::Env);
    let scene = run.rows.first().map_or("no scene", |r| r.scene.as_str());
    let map = run.rows.first().map_or("no map", |r| r.map.as_str());
    let adapter = run.config.adapter.split(" (").next().unwrap_or_default();
    let (w, h) = run.config.size;
    let title = format!("{scene} on {map}, {w}x{h}, {adapter}");
    trade::report::plot_svg(&title, &points, trade::Family::Env.error_axis()).map_err(|e| e.to_string())
}

/// What `--check` finds wrong with the committed plot: not what the code draws from the
/// committed run, or (same adapter) a setting missing or its error off by more than `relative`.
fn check_trade(committed: &Path, fresh: &Path, relative: f64) -> Result<Vec<String>, String> {
    let mut failures = Vec::new();
    let old = read_run(committed)?;
    let drawn = std::fs::read_to_string(committed.join(TRADE_SVG))
        .map_err(|e| format!("{}: {e}", committed.join(TRADE_SVG).display()))?;
    if drawn != trade_svg(&old)? {
        failures.push(format!("{TRADE_SVG}: not what the code draws from {TRADE_JSON}"));
    }
    let new = read_run(fresh)?;
    if old.config.adapter != new.config.adapter {
        outln!("pictures: {TRADE_JSON} was measured on {}, not compared on {}", old.config.adapter, new.config.adapter);
        return Ok(failures);
    }
    for r in &old.rows {
        match new.rows.iter().find(|n| n.setting == r.setting && n.scene == r.scene && n.map == r.map) {
            None => failures.push(format!("{TRADE_JSON}: {} is no longer measured", r.setting)),
            Some(n) => {
                let off = (n.rmse - r.rmse).abs() / r.rmse.max(1e-12);
                outln!("pictures: {} RMSE {:.5}, committed {:.5}", r.setting, n.rmse, r.rmse);
                if off > relative {
                    failures.push(format!(
                        "{TRADE_JSON}: {} RMSE {:.5}, committed {:.5} (off by {:.1} % > {:.1} %)",
                        r.setting,
                        n.rmse,
                        r.rmse,
                        off * 100.0,
                        relative * 100.0
                    ));
                }
            }
        }
    }
    if new.rows.len() != old.rows.len() {
        failures.push(format!("{TRADE_JSON}: {} settings committed, {} measured now", old.rows.len(), new.rows.len()));
    }
    Ok(failures)
}

/// Runs the command.
///
/// # Errors
/// A failed stage; with `--check`, a picture missing, of another size, or past its FLIP.
pub fn run(args: &PicturesArgs) -> Result<(), String> {
    let out = if args.out.is_absolute() { args.out.clone() } else { root().join(&args.out) };
    if !args.check {
        let names = make(&out, args.adapter.as_deref())?;
        outln!("pictures: {} in {}", names.join(", "), out.display());
        return Ok(());
    }
    let limits_path = out.join("flip.json");
    let text = std::fs::read_to_string(&limits_path).map_err(|e| format!("{}: {e}", limits_path.display()))?;
    let limits: serde_json::Value =
        serde_json::from_str(&text).map_err(|e| format!("{}: {e}", limits_path.display()))?;
    let fresh = std::env::temp_dir().join(format!("envshadow-pictures-{}", std::process::id()));
    let names = make(&fresh, args.adapter.as_deref())?;
    let mut failures = Vec::new();
    for name in names {
        let limit =
            limits[name].as_f64().ok_or_else(|| format!("{}: no FLIP limit for {name}", limits_path.display()))?;
        let load = |p: &Path| envmap_sphere::io::load_png_srgb8(p).map_err(|e| e.to_string());
        let (committed, made) = (load(&out.join(name))?, load(&fresh.join(name))?);
        if (committed.0, committed.1) != (made.0, made.1) {
            failures.push(format!("{name}: {}x{} committed, {}x{} made", committed.0, committed.1, made.0, made.1));
            continue;
        }
        let flip = ref_tracer::metrics::flip_rgb8(&committed.2, &made.2, made.0, made.1);
        outln!("pictures: {name} mean FLIP {flip:.4} against the committed one (limit {limit})");
        if flip > limit {
            failures.push(format!("{name}: mean FLIP {flip:.4} > {limit}"));
        }
    }
    let relative = limits[TRADE_JSON]["relative_rmse"]
        .as_f64()
        .ok_or_else(|| format!("{}: no relative_rmse for {TRADE_JSON}", limits_path.display()))?;
    failures.extend(check_trade(&out, &fresh, relative)?);
    std::fs::remove_dir_all(&fresh).ok();
    if failures.is_empty() {
        Ok(())
    } else {
        Err(format!(
            "the committed pictures are not what the code makes now ({}); run `cargo xtask pictures` to make them again",
            failures.join("; ")
        ))
    }
}
