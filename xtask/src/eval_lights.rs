//! `cargo xtask eval-lights`: every extraction method against the `env-direct` truth, over maps
//! x scenes, as paper 001's Table 1: mean RMSE and FLIP per method, their ratio to median cut,
//! and the mean rank; the `emissive-split/...` rows are its Table 2 ablation (masking and k-means
//! off). Writes `DIR/eval-lights.csv` (one row per map, scene and method), `DIR/eval-lights.md`
//! and `DIR/eval-lights.json` (what `eval-lights merge` joins: a map library's shards, each run
//! with `--shard I/N`).

use crate::common::load_map;
use clap::{Args, Subcommand};
use std::fmt::Write as _;
use std::path::{Path, PathBuf};
use trade::Shard;
use trade::lights::{LightsConfig, LightsRow, LightsRun, LightsScene, chosen_methods, measure_lights, summary};

/// `cargo xtask eval-lights`.
#[derive(Args)]
#[command(args_conflicts_with_subcommands = true)]
pub struct EvalLightsArgs {
    #[command(subcommand)]
    merge: Option<EvalCommand>,
    /// Folder of maps; the repository's test set (assets/envmaps) when absent.
    #[arg(long)]
    maps: Option<PathBuf>,
    /// Comma-separated built-in scenes.
    #[arg(long, default_value = "spheres_box,glossy_set", value_delimiter = ',')]
    scenes: Vec<String>,
    /// Lights per method K.
    #[arg(long, default_value_t = 32)]
    lights: usize,
    /// Comma-separated method labels of the table to run (median cut, the reference of the
    /// ratios, always runs); every method when absent.
    #[arg(long, value_delimiter = ',')]
    methods: Vec<String>,
    /// Samples per pixel of the env-direct truth (its noise floor is reported).
    #[arg(long, default_value_t = 1024)]
    spp: u32,
    /// Samples per pixel of the lights renders (each traces one shadow ray per light).
    #[arg(long, default_value_t = 32)]
    lights_spp: u32,
    /// Image size WIDTHxHEIGHT.
    #[arg(long, value_parser = crate::common::parse_size, default_value = "160x120")]
    size: (u32, u32),
    /// This run's share of the maps, I/N (0-based): maps sorted by name, dealt round-robin.
    #[arg(long, default_value = "0/1")]
    shard: Shard,
    /// Output folder.
    #[arg(long, default_value = "target/eval-lights")]
    out: PathBuf,
}

#[derive(Subcommand)]
enum EvalCommand {
    /// Join shards' outputs (their eval-lights.json) into one table: the unsharded run's.
    Merge {
        /// The shards' output folders.
        #[arg(required = true)]
        dirs: Vec<PathBuf>,
        /// Output folder.
        #[arg(long)]
        out: PathBuf,
    },
}

/// Runs `eval-lights` or `eval-lights merge`.
pub fn command(args: &EvalLightsArgs) -> Result<(), String> {
    if let Some(EvalCommand::Merge { dirs, out }) = &args.merge {
        return merge(dirs, out);
    }
    run(args)
}

fn merge(dirs: &[PathBuf], out: &Path) -> Result<(), String> {
    let m = trade::lights::merge_lights(dirs).map_err(|e| e.to_string())?;
    outln!("merged {} runs ({} rows; shards {})", dirs.len(), m.rows.len(), m.shards.join(", "));
    write_tables(m.rows, &m.config, m.shards, out)
}

fn run(args: &EvalLightsArgs) -> Result<(), String> {
    let dir = args.maps.clone().unwrap_or_else(test_set::dir);
    let all = test_set::maps_in(&dir).map_err(|e| e.to_string())?;
    if all.is_empty() {
        return Err(format!("{}: no .exr or .hdr maps", dir.display()));
    }
    let maps =
        args.shard.select(&all, |p| p.file_name().map_or_else(String::new, |n| n.to_string_lossy().into_owned()));
    let methods = chosen_methods(args.lights, &args.methods).map_err(|e| e.to_string())?;
    let n_methods = methods.len();
    let bar = indicatif::ProgressBar::new((maps.len() * args.scenes.len() * (2 + n_methods)) as u64);
    bar.set_style(
        indicatif::ProgressStyle::with_template(
            "eval-lights [{bar:40}] {pos}/{len} renders, {elapsed} (eta {eta}) {msg}",
        )
        .map_err(|e| e.to_string())?,
    );
    // the scenes and their BVHs, built once for every map
    let scenes = args
        .scenes
        .iter()
        .map(|name| LightsScene::builtin(name, args.size).map_err(|e| e.to_string()))
        .collect::<Result<Vec<_>, String>>()?;
    let mut rows = Vec::new();
    for map_path in &maps {
        let map = load_map(Some(map_path)).map_err(|e| e.to_string())?;
        let map_name = map_path.file_name().map_or_else(String::new, |n| n.to_string_lossy().to_string());
        bar.set_message(map_name.clone());
        let mut progress = |what: &str| {
            bar.set_message(what.to_string());
            bar.inc(1);
        };
        rows.extend(
            measure_lights(&map_name, &map, &methods, &scenes, (args.spp, args.lights_spp), &mut progress)
                .map_err(|e| format!("{}: {e}", map_path.display()))?,
        );
    }
    bar.finish_and_clear();
    let config = LightsConfig {
        scenes: args.scenes.clone(),
        lights: args.lights,
        methods: methods.iter().map(|(label, _)| label.clone()).collect(),
        spp: args.spp,
        lights_spp: args.lights_spp,
        size: args.size,
    };
    write_tables(rows, &config, vec![args.shard.to_string()], &args.out)
}

/// A CSV field, quoted (RFC 4180) when it holds a comma, quote or line break.
fn csv_field(s: &str) -> String {
    if s.contains([',', '"', '\n', '\r']) { format!("\"{}\"", s.replace('"', "\"\"")) } else { s.to_string() }
}

/// Writes the CSV, the Markdown table and the JSON of `rows`, sorted by map (a stable sort:
/// within a map, the run's scene and method order), so shards merged give the unsharded run's
/// files.
fn write_tables(
    mut rows: Vec<LightsRow>,
    config: &LightsConfig,
    shards: Vec<String>,
    out: &Path,
) -> Result<(), String> {
    rows.sort_by(|a, b| a.map.cmp(&b.map));
    let rows = &rows[..];
    std::fs::create_dir_all(out).map_err(|e| format!("{}: {e}", out.display()))?;
    let mut csv = String::from("map,scene,method,lights,rmse,converged_rmse,flip,extract_ms\n");
    for r in rows {
        let _ = writeln!(
            csv,
            "{},{},{},{},{:.6},{:.6},{:.6},{:.3}",
            csv_field(&r.map),
            csv_field(&r.scene),
            csv_field(&r.method),
            r.lights,
            r.rmse,
            r.converged_rmse,
            r.flip,
            r.extract_ms
        );
    }
    let (rm, cv, fl) = (summary(rows, |r| r.rmse), summary(rows, |r| r.converged_rmse), summary(rows, |r| r.flip));
    let base = |s: &[(String, f64, f64)]| s.iter().find(|(m, _, _)| m == "median-cut").map_or(f64::NAN, |x| x.1);
    let (brm, bcv, bfl) = (base(&rm), base(&cv), base(&fl));
    let mut md = String::new();
    let _ = writeln!(
        md,
        "# Light extraction against the env-direct truth\n\n{} maps x scenes {}, K = {}, {} x {}, reference {} spp, \
         lights renders {} spp with 8 interleaved sets (stratified over each pixel's samples); every render \
         goes through the same sub-pixel positions, so no antialiasing noise enters the errors. \
         \"(reference, other seed)\" is the noise floor: the truth rendered again with another seed. \
         \"converged RMSE\" estimates the RMSE against the converged truth: the truth's noise variance \
         (half the floor's mean square) is taken out of each mean square error.\n",
        rows.iter().map(|r| &r.map).collect::<std::collections::BTreeSet<_>>().len(),
        config.scenes.join(", "),
        config.lights,
        config.size.0,
        config.size.1,
        config.spp,
        config.lights_spp
    );
    let _ = writeln!(
        md,
        "| method | mean RMSE | RMSE / median cut | mean rank (RMSE) | converged RMSE | / median cut | mean FLIP | \
         FLIP / median cut | mean rank (FLIP) |"
    );
    let _ = writeln!(md, "|---|---|---|---|---|---|---|---|---|");
    for (((m, r, rr), (_, c, _)), (_, f, fr)) in rm.iter().zip(&cv).zip(&fl) {
        let _ = writeln!(
            md,
            "| {m} | {r:.4} | {:.2} | {rr:.2} | {c:.4} | {:.2} | {f:.4} | {:.2} | {fr:.2} |",
            r / brm,
            c / bcv,
            f / bfl
        );
    }
    let csv_path = out.join("eval-lights.csv");
    let md_path = out.join("eval-lights.md");
    let json_path = out.join("eval-lights.json");
    let run = LightsRun { config: config.clone(), shards, rows: rows.to_vec() };
    let json = serde_json::to_string_pretty(&run).map_err(|e| format!("{}: {e}", json_path.display()))?;
    std::fs::write(&csv_path, csv).map_err(|e| format!("{}: {e}", csv_path.display()))?;
    std::fs::write(&md_path, &md).map_err(|e| format!("{}: {e}", md_path.display()))?;
    std::fs::write(&json_path, json).map_err(|e| format!("{}: {e}", json_path.display()))?;
    outln!("{md}");
    outln!("\nwrote {}, {} and {}", csv_path.display(), md_path.display(), json_path.display());
    Ok(())
}
