//! `cargo xtask`: the project's own jobs. `validate` is the main job, `test` runs the test
//! suite; the rest measure (trade, frame, soft-shadows, eval-lights, shafts), fuzz, or make the README's
//! pictures. The user's
//! tools are the `envshadow` binary's. One module per subcommand.

#![allow(clippy::print_stdout, clippy::print_stderr)]

/// `println!` that ignores a closed stdout (`cargo xtask validate | head -1` must not panic).
macro_rules! outln {
    ($($arg:tt)*) => {{
        use std::io::Write as _;
        let _ = writeln!(std::io::stdout(), $($arg)*);
    }};
}

mod common;
mod eval_lights;
mod frame;
mod fuzz;
mod large_model;
mod lavapipe;
mod pictures;
mod shafts;
mod soft_shadows;
mod test;
mod thresholds;
mod trade;
mod validate;

use clap::{Parser, Subcommand};
use common::parse_size;

/// The allocator with accounts: `fuzz` limits each case's memory and reports the peak.
#[global_allocator]
static ALLOCATOR: cap::Cap<std::alloc::System> = cap::Cap::new(std::alloc::System, usize::MAX);
use std::path::PathBuf;
use std::process::ExitCode;

#[derive(Parser)]
#[command(name = "cargo xtask", about = "envshadow: shadows from HDR environment maps, measured")]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand)]
enum Command {
    /// The main job: decompose the map into lights, render them on the GPU (the best adapter) with
    /// shadow maps, render the ref-tracer reference, measure point-light shadow maps on `room`,
    /// and write target/validate/report.html. Fails when an error exceeds
    /// validate/thresholds.json.
    Validate(validate::ValidateArgs),
    /// The README's pictures from the current code into docs/pictures (a model with its soft
    /// shadows on the GPU and in the reference tracer, the map with its lights, the trade's
    /// plot); `--check` compares new ones with those committed, within the FLIP (and the trade's
    /// relative error) of docs/pictures/flip.json.
    Pictures(pictures::PicturesArgs),
    /// The large model the scale figures are measured on: a grid of --triangles (2 million by
    /// default) displaced by two sines, written as .glb or .gltf.
    LargeModel(large_model::LargeModelArgs),
    /// Run the test suite, the GPU tests on the best adapter present (lavapipe is installed
    /// first only where there is no adapter at all and we are root).
    Test {
        /// The GPU adapter for the GPU tests and validate: a case-insensitive part of its name,
        /// or `cpu` for a software one.
        #[arg(long)]
        adapter: Option<String>,
        /// Extra arguments passed to `cargo test` (after `--`).
        #[arg(last = true)]
        args: Vec<String>,
    },
    /// Every extraction method against the env-direct truth over maps x scenes: Markdown, CSV
    /// and JSON tables under target/eval-lights (paper 001's Table 1). `--shard I/N` runs a
    /// share of the maps; `eval-lights merge DIR... --out DIR` joins shards.
    EvalLights(eval_lights::EvalLightsArgs),
    /// Structured fuzzing of every file a command reads (.hdr, .exr, lights.json,
    /// thresholds): mutations of small valid files; prints the findings and last
    /// `fuzz: N cases, P panics, ...`; exits 1 when anything was found.
    Fuzz {
        /// Number of cases.
        #[arg(long, default_value_t = 1_000_000)]
        cases: usize,
        /// Seed of the mutations.
        #[arg(long, default_value_t = 1)]
        seed: u64,
    },
    /// Soft shadows: every technique's visibility error against ray-traced visibility and
    /// its GPU time per light, per scene and light size (0.25 to 45 degrees), and each
    /// technique's speed at the wedges' error; OUT/soft_shadows.{csv,md}.
    SoftShadows {
        /// Comma-separated built-in scenes or glTF models (`.gltf`, `.glb`); three_boxes,
        /// column and spheres_box when absent.
        #[arg(long, value_delimiter = ',')]
        scenes: Vec<String>,
        /// For a model: a Lambertian ground plane under it (albedo 0.5, or the value given).
        #[arg(long, num_args = 0..=1, default_missing_value = "0.5", value_parser = ::trade::args::parse_albedo)]
        ground: Option<f32>,
        /// Image size WIDTHxHEIGHT.
        #[arg(long, value_parser = parse_size, default_value = "640x480")]
        size: (u32, u32),
        /// The GPU adapter: a case-insensitive part of its name, or `cpu`.
        #[arg(long)]
        adapter: Option<String>,
        /// Output folder.
        #[arg(long, default_value = "target/soft-shadows")]
        out: PathBuf,
    },
    /// Paper 001's whole frame on the GPU, timed: G-buffer, the EnvDirects' wedges, the
    /// EnvIndirects' maps at 1, 1/2 and 1/4 resolution, joint bilateral upsampling, shading; the
    /// median and fastest ms per frame (and fps) of each.
    Frame {
        /// Built-in scene (`gallery`: 161,794 triangles, paper 001's scale) or a glTF model
        /// (`.gltf`, `.glb`).
        #[arg(long, default_value = "gallery")]
        scene: String,
        /// For a model: a Lambertian ground plane under it (albedo 0.5, or the value given).
        #[arg(long, num_args = 0..=1, default_missing_value = "0.5", value_parser = ::trade::args::parse_albedo)]
        ground: Option<f32>,
        /// Image size WIDTHxHEIGHT.
        #[arg(long, value_parser = parse_size, default_value = "1600x1200")]
        size: (u32, u32),
        /// Frames timed per resolution, after an untimed one.
        #[arg(long, default_value_t = 20)]
        repeats: usize,
        /// Lights K of the decomposition.
        #[arg(long, default_value_t = 32)]
        lights: usize,
        /// Environment map (.exr or .hdr); the embedded default map when absent.
        #[arg(long)]
        envmap: Option<PathBuf>,
        /// The GPU adapter: a case-insensitive part of its name, or `cpu`.
        #[arg(long)]
        adapter: Option<String>,
        /// Move the scene's first object other than its ground along a circle, a new pose
        /// every frame.
        #[arg(long)]
        animate: bool,
        /// One JSON object: what a frame costs at `--scale` (submissions, waits, bytes read
        /// back, pipelines created after the first frame, CPU, GPU and wall ms; medians).
        #[arg(long)]
        json: bool,
        /// With `--json`: the EnvIndirects at 1 / this of the resolution (1, 2 or 4).
        #[arg(long, default_value_t = 2)]
        scale: u32,
    },
    /// Paper 003's shaft hierarchy on a built-in real scene (ar_room, ar_ground): radiosity
    /// solve, pre-processing (source set, receivers, transfers, shafts), the brute-force
    /// conservativeness check along a built-in object path, per-frame traversal time, and
    /// OUT/<scene>_overlay.png (sources red, receivers blue, the object yellow). Exits 1 on a
    /// missed occluder.
    Shafts {
        /// The built-in real scene.
        #[arg(long, default_value = "ar_room")]
        scene: String,
        /// One JSON object: patches, sources, receivers, leaf_shafts, bytes, preprocess_s,
        /// traversal_us, segments_checked, misses (and more).
        #[arg(long)]
        json: bool,
        /// Share of the total power the source set carries.
        #[arg(long, default_value_t = 0.7)]
        source_share: f32,
        /// Receiver patches per octree leaf at most.
        #[arg(long, default_value_t = 8)]
        leaf_size: usize,
        /// Prune a pair below this fraction of every reached vertex's radiance.
        #[arg(long, default_value_t = 0.02)]
        prune: f32,
        /// Output folder of the overlay image.
        #[arg(long, default_value = "target/shafts")]
        out: PathBuf,
        /// Also path trace the scene's photograph at this many spp (HDR, and 8-bit through an
        /// auto-exposed camera response).
        #[arg(long)]
        photo: Option<u32>,
        /// Instead, sweep the knobs one at a time (source share, leaf size, pruning) and print
        /// a row each: time, memory and the fraction of true occluders found.
        #[arg(long)]
        sweep: bool,
    },
    /// The speed/accuracy trade: every setting of a preset (extraction, K, shadow technique and
    /// its knobs, paper 001's split) on scenes x maps, its GPU time per frame and its error
    /// against the env-direct truth; OUT/trade.csv, trade.json and report.html (plots, Pareto
    /// fronts, the chooser's picks). `trade merge DIR... --out DIR` joins shards.
    Trade(trade::TradeArgs),
}

/// Set, the command line is parsed (clap's checks: subcommand, options, values) and nothing is
/// run: what the README's command-line test uses.
const PARSE_ONLY_ENV: &str = "XTASK_PARSE_ONLY";

fn main() -> ExitCode {
    let cli = Cli::parse();
    if std::env::var_os(PARSE_ONLY_ENV).is_some() {
        outln!("parsed");
        return ExitCode::SUCCESS;
    }
    let result = match cli.command {
        Command::Fuzz { cases, seed } => return fuzz::run(cases, seed),
        Command::Validate(args) => validate::run(&args),
        Command::Pictures(args) => pictures::run(&args),
        Command::LargeModel(args) => large_model::run(&args),
        Command::Test { adapter, args } => test::run(adapter.as_deref(), &args),
        Command::Shafts { scene, json, source_share, leaf_size, prune, out, sweep, photo } => {
            let hierarchy = shaft_hierarchy::Settings { leaf_size, prune_fraction: prune, distant_reach: None };
            let settings = shaft_hierarchy::preprocess::PreprocessSettings {
                source_share,
                hierarchy,
                ..shaft_hierarchy::preprocess::PreprocessSettings::PAPER
            };
            shafts::run(&shafts::ShaftsArgs { scene: &scene, json, settings, sweep, photo, out: &out })
        }
        Command::Trade(args) => trade::run(&args),
        Command::SoftShadows { scenes, ground, size, adapter, out } => {
            soft_shadows::run(&scenes, ground, size, adapter.as_deref(), &out)
        }
        Command::Frame { scene, ground, size, repeats, lights, envmap, adapter, animate, json, scale } => {
            frame::run(&frame::FrameArgs {
                scene: &scene,
                ground,
                size,
                repeats,
                lights,
                envmap: envmap.as_deref(),
                adapter: adapter.as_deref(),
                animate,
                json,
                scale,
            })
        }
        Command::EvalLights(args) => eval_lights::command(&args),
    };
    match result {
        Ok(()) => ExitCode::SUCCESS,
        Err(message) => {
            eprintln!("error: {message}");
            ExitCode::FAILURE
        }
    }
}
