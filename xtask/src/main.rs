//! `cargo xtask`: the project's commands. `validate` is the main job, `test` runs the test
//! suite; the rest are user-facing tools. One module per subcommand.

#![allow(clippy::print_stdout, clippy::print_stderr)]

mod info;
mod lavapipe;
mod scene;
mod test;
mod validate;

use clap::{Parser, Subcommand};
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
    /// The main job: the whole pipeline on the default (or given) map, checked against the
    /// reference. For now: load the map and print its statistics.
    Validate {
        /// Environment map (.exr or .hdr); the embedded default map when absent.
        #[arg(long)]
        envmap: Option<PathBuf>,
    },
    /// Run the test suite (installs lavapipe first where it is missing and we are root).
    Test {
        /// Extra arguments passed to `cargo test` (after `--`).
        #[arg(last = true)]
        args: Vec<String>,
    },
    /// Write a built-in scene's geometry (spheres_box, three_boxes, column, glossy_set, room).
    Scene {
        /// The scene's name.
        name: String,
        /// Output Wavefront OBJ file: one `o` per object, materials in comments.
        #[arg(long)]
        obj: PathBuf,
    },
    /// Print an environment map's size, format, luminance, power and SH9 coefficients.
    Info {
        /// The map (.exr or .hdr).
        path: PathBuf,
        /// One JSON object instead of text.
        #[arg(long)]
        json: bool,
    },
}

fn main() -> ExitCode {
    let cli = Cli::parse();
    let result = match cli.command {
        Command::Validate { envmap } => validate::run(envmap.as_deref()),
        Command::Test { args } => test::run(&args),
        Command::Info { path, json } => info::run(&path, json),
        Command::Scene { name, obj } => scene::run(&name, &obj),
    };
    match result {
        Ok(()) => ExitCode::SUCCESS,
        Err(message) => {
            eprintln!("error: {message}");
            ExitCode::FAILURE
        }
    }
}
