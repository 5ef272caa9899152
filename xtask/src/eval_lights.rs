//! `cargo xtask eval-lights`: every extraction method against the `env-direct` truth, over maps
//! x scenes, as paper 001's Table 1: mean RMSE and FLIP per method, their ratio to median cut,
//! and the mean rank; the `emissive-split/...` rows are its Table 2 ablation (masking and k-means
//! off). Writes `DIR/eval-lights.csv` (one row per map, scene and method), `DIR/eval-lights.md`
//! and `DIR/eval-lights.json` (what `eval-lights merge` joins: a map library's shards, each run
//! with `--shard I/N`).

use crate::common::load_map;
use clap::{Args, Subcommand};
use light_extract::{EmissiveSplit, LightExtractor};
use ref_tracer::metrics::{FlipTonemap, flip, rmse};
use ref_tracer::{AmbientMap, EnvLight, Integrator, LightSet, RenderSettings, SceneBvh, Strategy};
use serde::{Deserialize, Serialize};
use std::fmt::Write as _;
use std::path::{Path, PathBuf};
use trade::Shard;

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

/// How a run measured: shards must agree on it to merge.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
struct EvalConfig {
    scenes: Vec<String>,
    lights: usize,
    methods: Vec<String>,
    spp: u32,
    lights_spp: u32,
    size: (u32, u32),
}

/// `eval-lights.json`.
#[derive(Serialize, Deserialize)]
struct EvalRun {
    config: EvalConfig,
    shards: Vec<String>,
    rows: Vec<Row>,
}

/// Runs `eval-lights` or `eval-lights merge`.
pub fn command(args: &EvalLightsArgs) -> Result<(), String> {
    if let Some(EvalCommand::Merge { dirs, out }) = &args.merge {
        return merge(dirs, out);
    }
    run(args)
}

fn merge(dirs: &[PathBuf], out: &Path) -> Result<(), String> {
    let mut merged: Option<EvalRun> = None;
    for dir in dirs {
        let p = dir.join("eval-lights.json");
        let text = std::fs::read_to_string(&p).map_err(|e| format!("{}: {e}", p.display()))?;
        let run: EvalRun =
            serde_json::from_str(&text).map_err(|e| format!("{}: not an eval-lights run: {e}", p.display()))?;
        let m =
            merged.get_or_insert_with(|| EvalRun { config: run.config.clone(), shards: Vec::new(), rows: Vec::new() });
        if run.config != m.config {
            return Err(format!(
                "{}: measured differently from {}: {:?} vs {:?}",
                p.display(),
                dirs[0].display(),
                run.config,
                m.config
            ));
        }
        for s in run.shards {
            if m.shards.contains(&s) {
                return Err(format!("{}: shard {s} is already in the merge", p.display()));
            }
            m.shards.push(s);
        }
        if let Some(r) = run.rows.iter().find(|r| m.rows.iter().any(|o| o.map == r.map)) {
            return Err(format!("{}: map {} is already in the merge", p.display(), r.map));
        }
        m.rows.extend(run.rows);
    }
    let mut m = merged.ok_or("nothing to merge: give at least one folder with an eval-lights.json")?;
    m.shards.sort();
    outln!("merged {} runs ({} rows; shards {})", dirs.len(), m.rows.len(), m.shards.join(", "));
    write_tables(m.rows, &m.config, m.shards, out)
}

#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
struct Row {
    map: String,
    scene: String,
    method: String,
    lights: usize,
    rmse: f64,
    /// RMSE against the converged truth, estimated: the truth's own noise variance (half the
    /// floor's mean square) taken out of the mean square error, clamped at zero.
    converged_rmse: f64,
    flip: f64,
    extract_ms: f64,
}

/// A row of the table: its label and its extractor.
type Method = (String, Box<dyn LightExtractor>);

/// The methods labelled in `only` and median cut (all when `only` is empty), in table order.
fn chosen_methods(k: usize, only: &[String]) -> Result<Vec<Method>, String> {
    let all = methods(k);
    if let Some(unknown) = only.iter().find(|m| !all.iter().any(|(label, _)| label == *m)) {
        let labels: Vec<&str> = all.iter().map(|(label, _)| label.as_str()).collect();
        return Err(format!("unknown method {unknown:?}; available: {}", labels.join(", ")));
    }
    Ok(all.into_iter().filter(|(label, _)| only.is_empty() || label == "median-cut" || only.contains(label)).collect())
}

/// (label, extractor): Table 1's methods, then Table 2's ablation of EmissiveSplit, then our
/// options (not the papers'): above-horizon (only the hemisphere above the ground reaches the
/// receivers), moment cones, the residual as the remainder (median cut's too, for a fair
/// comparison), and a light for every compact source of visible shadow (weber).
fn methods(k: usize) -> Vec<Method> {
    let es = EmissiveSplit { lights: k, ..EmissiveSplit::default() };
    let ablations: [(&str, Box<dyn LightExtractor>); 3] = [
        ("emissive-split/no-masking", Box::new(EmissiveSplit { masking: false, ..es })),
        ("emissive-split/no-kmeans", Box::new(EmissiveSplit { kmeans: false, ..es })),
        ("emissive-split/neither", Box::new(EmissiveSplit { masking: false, kmeans: false, ..es })),
    ];
    let named = |name: &str| light_extract::extractor(name, k).map(|e| (name.to_string(), e));
    light_extract::METHODS
        .iter()
        .filter_map(|m| named(m))
        .chain(ablations.into_iter().map(|(n, e)| (n.to_string(), e)))
        .chain(
            [
                "emissive-split+above-horizon",
                "emissive-split+moment-cones",
                "emissive-split+moment-cones+above-horizon",
                "emissive-split+moment-cones+above-horizon+residual",
                "emissive-split+weber",
                "emissive-split+moment-cones+weber+above-horizon+residual",
                "median-cut+above-horizon",
                "median-cut+above-horizon+residual",
            ]
            .into_iter()
            .filter_map(named),
        )
        .collect()
}

fn run(args: &EvalLightsArgs) -> Result<(), String> {
    let dir = args.maps.clone().unwrap_or_else(test_set::dir);
    let all = test_set::maps_in(&dir).map_err(|e| e.to_string())?;
    if all.is_empty() {
        return Err(format!("{}: no .exr or .hdr maps", dir.display()));
    }
    let maps =
        args.shard.select(&all, |p| p.file_name().map_or_else(String::new, |n| n.to_string_lossy().into_owned()));
    let methods = chosen_methods(args.lights, &args.methods)?;
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
        .map(|name| {
            let mut scene = scene::Scene::builtin(name).map_err(|e| e.to_string())?;
            (scene.camera.width, scene.camera.height) = args.size;
            let bvh = SceneBvh::new(&scene);
            Ok((name, scene, bvh))
        })
        .collect::<Result<Vec<_>, String>>()?;
    let mut rows = Vec::new();
    for map_path in &maps {
        let map = load_map(Some(map_path))?;
        let map_name = map_path.file_name().map_or_else(String::new, |n| n.to_string_lossy().to_string());
        let env = EnvLight::new(&map);
        let decompositions: Vec<_> = methods
            .iter()
            .map(|(label, m)| {
                let mut d = m.extract(&map).map_err(|e| format!("{}: {e}", map_path.display()))?;
                d.method.clone_from(label);
                // paper 001, section 3.5: 8 sets; the extra 7 as renderers take them
                let (lights, sets) = (d.distant_lights(), d.interleaved_distant_lights());
                Ok::<_, String>((d, lights, sets))
            })
            .collect::<Result<Vec<_>, _>>()?;
        let ambient_maps: Vec<_> = decompositions.iter().map(|(d, _, _)| AmbientMap::new(&d.ambient)).collect();
        for (scene_name, scene, bvh) in &scenes {
            bar.set_message(format!("{map_name} / {scene_name}"));
            // Every render goes through the same lights_spp sub-pixel positions, so a method's
            // error holds no antialiasing noise, only its lighting error and lighting noise.
            let positions = Some(args.lights_spp.max(1));
            let truth = RenderSettings {
                spp: args.spp,
                seed: 1,
                aovs: false,
                pixel_positions: positions,
                ..Default::default()
            };
            let reference =
                ref_tracer::render(scene, bvh, Some(&env), &Integrator::EnvDirect(Strategy::Mis), &truth, &|_, _| {});
            bar.inc(1);
            let tm = FlipTonemap::for_reference(&reference.color);
            // The noise floor: the same truth with another seed.
            let again = RenderSettings { seed: 3, ..truth };
            let floor =
                ref_tracer::render(scene, bvh, Some(&env), &Integrator::EnvDirect(Strategy::Mis), &again, &|_, _| {});
            bar.inc(1);
            // Two truths differ by twice the truth's noise variance.
            let floor_rmse = rmse(&reference.color, &floor.color);
            let truth_variance = floor_rmse * floor_rmse / 2.0;
            let converged = |e: f64| (e * e - truth_variance).max(0.0).sqrt();
            rows.push(Row {
                map: map_name.clone(),
                scene: scene_name.to_string(),
                method: "(reference, other seed)".into(),
                lights: 0,
                rmse: floor_rmse,
                converged_rmse: converged(floor_rmse),
                flip: flip(&reference.color, &floor.color, floor.width, floor.height, &tm),
                extract_ms: 0.0,
            });
            for ((d, lights, sets), ambient_map) in decompositions.iter().zip(&ambient_maps) {
                let set = LightSet {
                    lights,
                    interleaved: sets,
                    ambient: Some(d.ambient_sh),
                    ambient_map: ambient_map.as_ref(),
                    shadow_ambient: false,
                    background: Some(&map),
                };
                let settings = RenderSettings { spp: args.lights_spp.max(1), seed: 2, ..truth };
                let img = ref_tracer::render(scene, bvh, None, &Integrator::Lights(set), &settings, &|_, _| {});
                bar.inc(1);
                let error = rmse(&reference.color, &img.color);
                rows.push(Row {
                    map: map_name.clone(),
                    scene: scene_name.to_string(),
                    method: d.method.clone(),
                    lights: d.lights.len(),
                    rmse: error,
                    converged_rmse: converged(error),
                    flip: flip(&reference.color, &img.color, img.width, img.height, &tm),
                    extract_ms: d.time_ms,
                });
            }
        }
    }
    bar.finish_and_clear();
    let config = EvalConfig {
        scenes: args.scenes.clone(),
        lights: args.lights,
        methods: methods.iter().map(|(label, _)| label.clone()).collect(),
        spp: args.spp,
        lights_spp: args.lights_spp,
        size: args.size,
    };
    write_tables(rows, &config, vec![args.shard.to_string()], &args.out)
}

/// Mean of `value` per method, the ratio of means to median cut's, and the mean rank.
fn summary(rows: &[Row], value: impl Fn(&Row) -> f64) -> Vec<(String, f64, f64)> {
    let mut names: Vec<String> = rows.iter().map(|r| r.method.clone()).collect();
    names.sort();
    names.dedup();
    let cases: Vec<(String, String)> = {
        let mut c: Vec<_> = rows.iter().map(|r| (r.map.clone(), r.scene.clone())).collect();
        c.dedup();
        c
    };
    names
        .iter()
        .map(|m| {
            let mine: Vec<&Row> = rows.iter().filter(|r| &r.method == m).collect();
            let mean = mine.iter().map(|r| value(r)).sum::<f64>() / mine.len().max(1) as f64;
            let rank = cases
                .iter()
                .map(|(map, scene)| {
                    let case: Vec<&Row> = rows.iter().filter(|r| &r.map == map && &r.scene == scene).collect();
                    let mine = case.iter().find(|r| &r.method == m).map_or(f64::INFINITY, |r| value(r));
                    1.0 + case.iter().filter(|r| value(r) < mine).count() as f64
                })
                .sum::<f64>()
                / cases.len().max(1) as f64;
            (m.clone(), mean, rank)
        })
        .collect()
}

/// A CSV field, quoted (RFC 4180) when it holds a comma, quote or line break.
fn csv_field(s: &str) -> String {
    if s.contains([',', '"', '\n', '\r']) { format!("\"{}\"", s.replace('"', "\"\"")) } else { s.to_string() }
}

/// Writes the CSV, the Markdown table and the JSON of `rows`, sorted by map (a stable sort:
/// within a map, the run's scene and method order), so shards merged give the unsharded run's
/// files.
fn write_tables(mut rows: Vec<Row>, config: &EvalConfig, shards: Vec<String>, out: &Path) -> Result<(), String> {
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
    let run = EvalRun { config: config.clone(), shards, rows: rows.to_vec() };
    let json = serde_json::to_string_pretty(&run).map_err(|e| format!("{}: {e}", json_path.display()))?;
    std::fs::write(&csv_path, csv).map_err(|e| format!("{}: {e}", csv_path.display()))?;
    std::fs::write(&md_path, &md).map_err(|e| format!("{}: {e}", md_path.display()))?;
    std::fs::write(&json_path, json).map_err(|e| format!("{}: {e}", json_path.display()))?;
    outln!("{md}");
    outln!("\nwrote {}, {} and {}", csv_path.display(), md_path.display(), json_path.display());
    Ok(())
}
