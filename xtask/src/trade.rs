//! `cargo xtask trade`: every setting of a preset on scenes x maps, timed on the GPU and
//! compared with its family's truth (the `trade` crate measures): environment-lit scenes under
//! each map, scenes with point lights, real scenes composited into; DIR/trade.csv,
//! DIR/trade.json and DIR/report.html. `trade merge` joins shards' outputs.

use clap::{Args, Subcommand};
use std::path::{Path, PathBuf};
use trade::{Case, CompositeCase, Family, Passes, Plan, PointCase, Preset, Run, RunConfig, Shard};

/// Budgets (ms per frame) the report's chooser answers: real-GPU frame budgets, and budgets
/// lavapipe on 2 cores can meet.
pub const REPORT_BUDGETS: [f64; 6] = [1.0, 4.0, 16.0, 250.0, 1000.0, 4000.0];

/// The default run's scenes: validate's, the glossy one, paper 000's two (environment-lit);
/// paper 004's room (a point light); paper 003's real scenes (composites).
const SCENES: [&str; 7] = ["spheres_box", "glossy_set", "three_boxes", "column", "room", "ar_room", "ar_ground"];
/// The default run's test-set maps beside the embedded one.
const DEFAULT_MAPS: [&str; 2] = ["st_fagans_interior_1k.hdr", "kiara_1_dawn_1k.hdr"];
/// `--quick`'s scenes.
const QUICK_SCENES: [&str; 4] = ["spheres_box", "three_boxes", "room", "ar_ground"];

/// `cargo xtask trade`.
#[derive(Args)]
#[command(args_conflicts_with_subcommands = true)]
pub struct TradeArgs {
    #[command(subcommand)]
    merge: Option<TradeCommand>,
    /// The quick preset (11 settings, 160x120, the default map, spheres_box, three_boxes, room
    /// and ar_ground), for CI.
    #[arg(long)]
    quick: bool,
    /// Comma-separated built-in scenes or glTF models (`.gltf`, `.glb`). A real scene (ar_room, ar_ground) is composited into;
    /// a scene with point lights (room) is measured by its point lights; any other is lit by
    /// each map. When absent: spheres_box, glossy_set, three_boxes, column, room, ar_room and
    /// ar_ground (with --quick: spheres_box, three_boxes, room, ar_ground).
    #[arg(long, value_delimiter = ',')]
    scenes: Vec<String>,
    /// For a model: a Lambertian ground plane under it (albedo 0.5, or the value given).
    #[arg(long, num_args = 0..=1, default_missing_value = "0.5", value_parser = ::trade::args::parse_albedo)]
    ground: Option<f32>,
    /// Comma-separated maps or folders of maps (`assets/envmaps` for the whole test set); when
    /// absent the embedded default map, st_fagans_interior (indoor) and kiara_1_dawn (a low
    /// sun), or with --quick the default map alone.
    #[arg(long, value_delimiter = ',')]
    maps: Vec<PathBuf>,
    /// Image size WIDTHxHEIGHT; 160x120 when absent (sized for lavapipe on 2 cores).
    #[arg(long, value_parser = crate::common::parse_size)]
    size: Option<(u32, u32)>,
    /// Frames timed per setting (the median is kept; under 3, an untimed frame goes first).
    #[arg(long)]
    repeats: Option<u32>,
    /// Samples per pixel of the environment-lit and point-light truths (the preset's when
    /// absent: 64 quick, 128 default); more lowers the truth's own noise under the errors.
    #[arg(long)]
    truth_spp: Option<u32>,
    /// This run's share of the work, I/N (0-based): the maps (each with every environment-lit
    /// scene) and the point-light and composite scenes, sorted by name, dealt round-robin.
    #[arg(long, default_value = "0/1")]
    shard: Shard,
    /// The GPU adapter: a case-insensitive part of its name, or `cpu`.
    #[arg(long)]
    adapter: Option<String>,
    /// Output folder.
    #[arg(long, default_value = "target/trade")]
    out: PathBuf,
}

#[derive(Subcommand)]
enum TradeCommand {
    /// Join shards' outputs (their trade.json) into one run: trade.csv, trade.json, report.html.
    Merge {
        /// The shards' output folders.
        #[arg(required = true)]
        dirs: Vec<PathBuf>,
        /// Output folder.
        #[arg(long)]
        out: PathBuf,
    },
}

/// A map's name and how to load it (`None`: the embedded default map).
type MapSource = (String, Option<PathBuf>);

fn map_list(paths: &[PathBuf], quick: bool) -> Result<Vec<MapSource>, String> {
    if paths.is_empty() {
        if quick {
            return Ok(vec![(envmap_sphere::DEFAULT_MAP_NAME.to_string(), None)]);
        }
        let mut maps = vec![(envmap_sphere::DEFAULT_MAP_NAME.to_string(), None)];
        for name in DEFAULT_MAPS {
            let p = test_set::path(name);
            maps.push((name.to_string(), Some(p)));
        }
        return Ok(maps);
    }
    let mut out = Vec::new();
    for p in paths {
        if p.is_dir() {
            let maps = test_set::maps_in(p).map_err(|e| e.to_string())?;
            out.extend(maps.into_iter().map(|m| (file_name(&m), Some(m))));
        } else {
            out.push((file_name(p), Some(p.clone())));
        }
    }
    Ok(out)
}

/// A share of the work a shard takes whole: a map with every environment-lit scene, or one
/// point-light or composite scene.
#[derive(Clone)]
enum Unit {
    Map(MapSource),
    Point(String),
    Composite(String),
}

impl Unit {
    fn key(&self) -> String {
        match self {
            Unit::Map((name, _)) => format!("map:{name}"),
            Unit::Point(s) => format!("point:{s}"),
            Unit::Composite(s) => format!("composite:{s}"),
        }
    }
}

/// The family a scene is measured in: composites for real scenes, point for scenes with point
/// lights, env for the rest; with the scene opened at `size` (none for a real scene).
fn family_of(spec: &str, size: (u32, u32), ground: Option<f32>) -> Result<(Family, Option<scene::Scene>), String> {
    if real_scene::BUILTIN_REAL_SCENES.contains(&spec) {
        return Ok((Family::Composite, None));
    }
    let s = crate::common::open_scene(spec, size, ground).map_err(|e| format!("--scenes: {e}"))?;
    Ok((if s.point_lights.is_empty() { Family::Env } else { Family::Point }, Some(s)))
}

fn file_name(p: &Path) -> String {
    p.file_name().map_or_else(|| p.display().to_string(), |n| n.to_string_lossy().into_owned())
}

fn write_all(run: &Run, out: &Path) -> Result<(), String> {
    run.write(out).map_err(|e| e.to_string())?;
    let html = trade::report::html(run, &REPORT_BUDGETS).map_err(|e| e.to_string())?;
    let p = out.join("report.html");
    std::fs::write(&p, html).map_err(|e| format!("{}: {e}", p.display()))?;
    outln!("wrote {} (trade.csv, trade.json, report.html)", out.display());
    Ok(())
}

fn print_front(run: &Run) {
    for family in Family::ALL {
        let all = trade::overall(&run.rows, family);
        if all.is_empty() {
            continue;
        }
        outln!(
            "{}: Pareto front over its scenes and maps (mean ms, mean {}, mean FLIP):",
            family.name(),
            family.error_axis()
        );
        for p in trade::pareto_front(&all) {
            outln!("  {:<64} {:>9.3} ms  RMSE {:.5}  FLIP {:.4}", p.setting, p.ms, p.rmse, p.flip);
        }
        for b in REPORT_BUDGETS {
            match trade::choose(&all, b) {
                Ok(p) => outln!("budget: {b} ms -> {} (ms {:.3}, rmse {:.5})", p.setting, p.ms, p.rmse),
                Err(e) => outln!("budget: {b} ms -> {}: {e}", family.name()),
            }
        }
    }
}

/// Runs `trade` or `trade merge`.
pub fn run(args: &TradeArgs) -> Result<(), String> {
    if let Some(TradeCommand::Merge { dirs, out }) = &args.merge {
        let runs = dirs
            .iter()
            .map(|d| Run::read(d).map(|r| (d.clone(), r)))
            .collect::<Result<Vec<_>, _>>()
            .map_err(|e| e.to_string())?;
        let merged = trade::merge(&runs).map_err(|e| e.to_string())?;
        outln!("merged {} runs ({} measurements; shards {})", runs.len(), merged.rows.len(), merged.shards.join(", "));
        print_front(&merged);
        return write_all(&merged, out);
    }
    let (preset, mut plan) = if args.quick { (Preset::Quick, Plan::QUICK) } else { (Preset::Default, Plan::DEFAULT) };
    if let Some(size) = args.size {
        plan.size = size;
    }
    if let Some(r) = args.repeats {
        plan.repeats = r.max(1);
    }
    if let Some(spp) = args.truth_spp {
        plan.truth_spp = spp.max(1);
    }
    let settings = preset.settings();
    let scenes: Vec<String> = match (args.scenes.is_empty(), args.quick) {
        (false, _) => args.scenes.clone(),
        (true, true) => QUICK_SCENES.iter().map(|s| (*s).to_string()).collect(),
        (true, false) => SCENES.iter().map(|s| (*s).to_string()).collect(),
    };
    let mut env_scenes = Vec::new();
    let mut units = Vec::new();
    let mut opened = std::collections::HashMap::new();
    for s in &scenes {
        let (family, scene) = family_of(s, plan.size, args.ground)?;
        match family {
            Family::Env => env_scenes.push(s.clone()),
            Family::Point => units.push(Unit::Point(s.clone())),
            Family::Composite => units.push(Unit::Composite(s.clone())),
        }
        if let Some(scene) = scene {
            opened.insert(s.clone(), scene);
        }
    }
    let opened_scene = |s: &str| opened.get(s).cloned().ok_or_else(|| format!("{s}: not opened"));
    if !env_scenes.is_empty() {
        units.extend(map_list(&args.maps, args.quick)?.into_iter().map(Unit::Map));
    }
    let units = args.shard.select(&units, Unit::key);
    let gpu = crate::lavapipe::open_gpu(args.adapter.as_deref())?;
    outln!("GPU: {}", gpu.describe());
    let count = |f: Family| settings.iter().filter(|s| s.family() == f).count();
    outln!(
        "trade: {} environment-lit settings x {} scenes x {} maps, {} point-light settings, {} composite settings (shard {}: {} units), {}x{}, truth {} spp, photographs {} spp, median of {} frames",
        count(Family::Env),
        env_scenes.len(),
        units.iter().filter(|u| matches!(u, Unit::Map(_))).count(),
        count(Family::Point),
        count(Family::Composite),
        args.shard,
        units.len(),
        plan.size.0,
        plan.size.1,
        plan.truth_spp,
        plan.photo_spp,
        plan.repeats
    );
    let passes = Passes::new(&gpu).map_err(|e| e.to_string())?;
    let mut run = Run {
        config: RunConfig {
            size: plan.size,
            truth_spp: plan.truth_spp,
            repeats: plan.repeats,
            supersample: plan.supersample,
            photo_spp: plan.photo_spp,
            adapter: gpu.describe(),
            preset: if args.quick { "quick" } else { "default" }.into(),
        },
        shards: vec![args.shard.to_string()],
        rows: Vec::new(),
    };
    let start = std::time::Instant::now();
    let mut show = |m: &trade::Measurement| {
        outln!("    {:<64} {:>9.3} ms  RMSE {:.5}  FLIP {:.4}", m.setting, m.ms, m.rmse, m.flip);
    };
    let e = |e: trade::TradeError| e.to_string();
    for unit in &units {
        let elapsed = start.elapsed().as_secs_f64();
        match unit {
            Unit::Map((name, path)) => {
                let map = match path {
                    Some(p) => envmap_sphere::EnvMap::load(p).map_err(|e| e.to_string())?,
                    None => envmap_sphere::default_map(),
                };
                for scene in &env_scenes {
                    outln!("[{:>6.1} s] {scene} under {name}: truth", start.elapsed().as_secs_f64());
                    let case = Case::with_scene(opened_scene(scene)?, name, map.clone(), &plan);
                    run.rows.extend(trade::measure(&gpu, &case, &settings, &plan, &mut show).map_err(e)?);
                }
            }
            Unit::Point(scene) => {
                outln!("[{elapsed:>6.1} s] {scene}'s point lights: truth (ray-traced visibility)");
                let case = PointCase::with_scene(&gpu, &passes, opened_scene(scene)?, &plan).map_err(e)?;
                run.rows.extend(trade::measure_point(&gpu, &case, &settings, &plan, &mut show).map_err(e)?);
            }
            Unit::Composite(scene) => {
                outln!("[{elapsed:>6.1} s] a sphere composited into {scene}: capture, hierarchy, truth");
                let case = CompositeCase::new(&gpu, scene, light_extract::DEFAULT_METHOD, &plan).map_err(e)?;
                run.rows.extend(trade::measure_composite(&gpu, &case, &settings, &plan, &mut show).map_err(e)?);
            }
        }
    }
    run.finish();
    outln!("measured {} settings in {:.1} s", run.rows.len(), start.elapsed().as_secs_f64());
    print_front(&run);
    write_all(&run, &args.out)
}
