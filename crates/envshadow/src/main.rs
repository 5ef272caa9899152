//! `envshadow`: the user's tool. Statistics of a map (`info`), its lights (`extract`), the
//! reference render of a built-in scene or a glTF 2.0 model (`render`), image error (`compare`),
//! an object composited into a photograph (`composite`) and a built-in scene's geometry
//! (`scene`), and a window on the real-time frame (`view`). One module per command; the work is
//! the library crates'.

#![allow(clippy::print_stdout, clippy::print_stderr)]

/// `println!` that ignores a closed stdout (`envshadow compare a b | head -1` must not panic).
macro_rules! outln {
    ($($arg:tt)*) => {{
        use std::io::Write as _;
        let _ = writeln!(std::io::stdout(), $($arg)*);
    }};
}

mod backdrop;
mod composite;
mod extract;
mod info;
mod render;
mod scene;
mod view;

use clap::{Parser, Subcommand};
use std::path::PathBuf;
use std::process::ExitCode;

#[derive(Parser)]
#[command(
    name = "envshadow",
    version,
    about = "Shadows from HDR environment maps: lights, reference renders, compositing"
)]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand)]
enum Command {
    /// Write a built-in scene (spheres_box, three_boxes, column, glossy_set, room, gallery) as
    /// Wavefront OBJ or glTF 2.0, for another renderer or to start a model of one's own from.
    #[command(
        after_help = "Examples:\n  envshadow scene room --gltf room.glb --obj room.obj\n  envshadow scene spheres_box --without-ground --gltf objects.glb"
    )]
    Scene {
        /// The scene's name.
        name: String,
        /// Output Wavefront OBJ file: one `o` per object, materials in comments.
        #[arg(long, required_unless_present = "gltf")]
        obj: Option<PathBuf>,
        /// Output glTF file (`.glb`, or `.gltf` with a `.bin` beside it) that every command here
        /// reads back as the same scene: camera, lights and GGX layers included.
        #[arg(long)]
        gltf: Option<PathBuf>,
        /// Leave its ground out: its objects alone, a model to composite (`composite --object`).
        #[arg(long)]
        without_ground: bool,
    },
    /// Render a built-in scene or a glTF model with the CPU reference tracer: OUT.exr, a tone-mapped OUT.png,
    /// and with --aovs OUT.albedo.exr, OUT.normal.exr, OUT.depth.exr, OUT.object.exr.
    #[command(
        after_help = "Example: envshadow render --scene model.glb --ground --envmap map.exr --integrator env-direct --spp 64 --size 640x480 --out render.exr"
    )]
    Render(render::RenderArgs),
    /// A window on the real-time frame: a built-in scene or your glTF model lit by your map,
    /// its soft shadows drawn by the technique chosen. Mouse: orbit (left), pan (right), zoom
    /// (wheel), move the object (ctrl + left, arrows); T: next technique; +/-: lights; P:
    /// screenshot; drop a map or model on the window to load it.
    #[command(after_help = "Examples:
  envshadow view --envmap map.exr --scene model.glb --ground
  envshadow view --scene spheres_box --frames 60 --orbit 3 --screenshot shot.png --json")]
    View(view::ViewArgs),
    /// Decompose a map into shadow-casting lights + ambient: DIR/lights.json, ambient.exr,
    /// lights.gltf (KHR_lights_punctual) and overlay.png.
    #[command(after_help = "Example: envshadow extract map.exr --method emissive-split --lights 16 --out lights/")]
    Extract {
        /// The map (.exr or .hdr).
        path: PathBuf,
        /// emissive-split, center-surround (stops by Weber's law; K is a cap), median-cut,
        /// variance-min or importance; append +above-horizon to model only the hemisphere above
        /// the ground (for scenes standing on an opaque ground), to emissive-split
        /// +moment-cones (before +above-horizon) for cones matching each cluster's spread, and
        /// last +residual to make ambient.exr the signed residual, map minus lights.
        #[arg(long, default_value = "median-cut")]
        method: String,
        /// Number of lights K (median cut uses the largest power of two not above K).
        #[arg(long, default_value_t = 32)]
        lights: usize,
        /// Output folder; target/extract/<map>-<method> when absent.
        #[arg(long)]
        out: Option<PathBuf>,
        /// glTF intensity per unit of the map's luminance x sr (683 for maps in W/(m^2 sr)).
        #[arg(long, default_value_t = 1.0)]
        lux_per_unit: f32,
    },
    /// RMSE and FLIP of TEST against REF (two lines).
    #[command(after_help = "Example: envshadow compare reference.exr test.exr")]
    Compare {
        /// Reference image (.exr or .hdr).
        reference: PathBuf,
        /// Test image of the same size.
        test: PathBuf,
    },
    /// A synthetic object composited into a built-in real scene's photograph on the GPU
    /// (paper 003): shadow maps per representative source, transfers subtracted in HDR or, with
    /// --ldr, intensity transfers in 8-bit codes. Writes OUT (and OUT_photo, _truth, _debevec,
    /// _error beside it) and prints the error in codes against the path-traced truth and
    /// Debevec's offline differential rendering, and the time per frame.
    #[command(
        after_help = "Examples:\n  envshadow composite --envmap my_hdri.exr --object model.glb --out composite.png\n  envshadow composite --scene ar_ground --object model.glb --out composite.png"
    )]
    Composite(composite::CompositeArgs),
    /// Print an environment map's size, format, luminance, power and SH9 coefficients.
    #[command(after_help = "Example: envshadow info map.exr --json")]
    Info {
        /// The map (.exr or .hdr).
        path: PathBuf,
        /// One JSON object instead of text.
        #[arg(long)]
        json: bool,
    },
}

/// Set, the command line is parsed (clap's checks: subcommand, options, values) and nothing is
/// run: what the README's command-line test uses.
const PARSE_ONLY_ENV: &str = "ENVSHADOW_PARSE_ONLY";

fn main() -> ExitCode {
    let cli = Cli::parse();
    if std::env::var_os(PARSE_ONLY_ENV).is_some() {
        outln!("parsed");
        return ExitCode::SUCCESS;
    }
    let result = match cli.command {
        Command::Info { path, json } => info::run(&path, json),
        Command::Composite(args) => composite::run(&args),
        Command::Scene { name, obj, gltf, without_ground } => {
            scene::run(&name, obj.as_deref(), gltf.as_deref(), without_ground)
        }
        Command::Render(args) => render::run(&args),
        Command::View(args) => view::run(&args),
        Command::Compare { reference, test } => render::compare(&reference, &test),
        Command::Extract { path, method, lights, out, lux_per_unit } => {
            extract::run(&path, &method, lights, out.as_deref(), lux_per_unit)
        }
    };
    match result {
        Ok(()) => ExitCode::SUCCESS,
        Err(message) => {
            eprintln!("error: {message}");
            ExitCode::FAILURE
        }
    }
}
