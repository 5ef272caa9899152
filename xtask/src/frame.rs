//! `cargo xtask frame`: paper 001's whole frame on the GPU, timed (the `decomposition` bench's
//! frame, `envshadow_benches::decomposition`, as one command a machine without Rust can run
//! from a copied binary): G-buffer, the EnvDirects' wedges at full resolution, the
//! EnvIndirects' 1024² orthographic maps at 1, 1/2 and 1/4 of it, joint bilateral upsampling,
//! shading with the residual's SH9 and split-sum ambient.

use envshadow_benches::decomposition::Frame;
use std::path::Path;

/// The most frames timed per scale: a typo should not hold a GPU machine for hours.
const MAX_REPEATS: usize = 10_000;

/// What to time.
pub struct FrameArgs<'a> {
    pub scene: &'a str,
    pub size: (u32, u32),
    pub repeats: usize,
    pub lights: usize,
    pub envmap: Option<&'a Path>,
    pub adapter: Option<&'a str>,
}

/// Times `repeats` frames per scale after one untimed frame (pipelines compile and buffers grow
/// on it) and prints the median and the fastest, in ms and frames per second.
pub fn run(args: &FrameArgs) -> Result<(), String> {
    if args.repeats == 0 || args.repeats > MAX_REPEATS {
        return Err(format!("--repeats {}: give 1 to {MAX_REPEATS}", args.repeats));
    }
    let gpu = crate::lavapipe::open_gpu(args.adapter)?;
    outln!("GPU: {}", gpu.describe());
    let map = crate::render::load_map(args.envmap)?;
    let frame = Frame::new(&gpu, args.scene, args.size, &map, args.lights)?;
    let d = &frame.decomposition;
    outln!(
        "{}: {} triangles, {}x{}; {} lights ({}): {} EnvDirects with wedges, {} EnvIndirects with 1024² maps",
        args.scene,
        frame.scene.triangle_count(),
        args.size.0,
        args.size.1,
        d.lights.len(),
        envshadow_benches::decomposition::METHOD,
        d.directs(),
        d.lights.len() - d.directs()
    );
    for (name, scale) in [("full", 1), ("half", 2), ("quarter", 4)] {
        frame.render(&gpu, scale).map_err(|e| e.to_string())?;
        let mut ms = (0..args.repeats)
            .map(|_| frame.render(&gpu, scale).map(|(t, _)| t.as_secs_f64() * 1e3))
            .collect::<Result<Vec<f64>, _>>()
            .map_err(|e| e.to_string())?;
        ms.sort_by(f64::total_cmp);
        let median = ms[ms.len() / 2];
        outln!(
            "  EnvIndirects at {name} resolution: median {median:.2} ms ({:.1} fps), fastest {:.2} ms, over {} frames (wall time, the frame's CPU work and waits included)",
            1e3 / median,
            ms[0],
            ms.len()
        );
    }
    Ok(())
}
