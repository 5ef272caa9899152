//! `cargo xtask frame`: paper 001's whole frame on the GPU, timed (the `decomposition` bench's
//! frame, `envshadow_benches::decomposition`, as one command a machine without Rust can run
//! from a copied binary): G-buffer, the EnvDirects' wedges at full resolution, the
//! EnvIndirects' 1024² orthographic maps at 1, 1/2 and 1/4 of it, joint bilateral upsampling,
//! shading with the residual's SH9 and split-sum ambient. `--json` measures one scale and
//! prints what each frame cost (`envshadow_benches::frame_stats`); `--animate` moves an object
//! every frame.

use envshadow_benches::decomposition::{Frame, RenderedFrame, animated_object, animation_pose};
use envshadow_benches::frame_stats::{FrameStats, measure_frames};
use std::path::Path;

/// The most frames timed per scale: a typo should not hold a GPU machine for hours.
const MAX_REPEATS: usize = 10_000;

/// What to time.
pub struct FrameArgs<'a> {
    pub scene: &'a str,
    /// For a model: the ground's albedo.
    pub ground: Option<f32>,
    pub size: (u32, u32),
    pub repeats: usize,
    pub lights: usize,
    pub envmap: Option<&'a Path>,
    pub adapter: Option<&'a str>,
    pub animate: bool,
    pub json: bool,
    /// The EnvIndirects' scale `--json` measures.
    pub scale: u32,
}

/// Measures `repeats` frames per scale after one unmeasured frame (pipelines compile and
/// buffers grow on it) and prints medians: per scale as text, or one scale as JSON.
pub fn run(args: &FrameArgs) -> Result<(), String> {
    if args.repeats == 0 || args.repeats > MAX_REPEATS {
        return Err(format!("--repeats {}: give 1 to {MAX_REPEATS}", args.repeats));
    }
    if !matches!(args.scale, 1 | 2 | 4) {
        return Err(format!("--scale {}: give 1, 2 or 4", args.scale));
    }
    let gpu = crate::lavapipe::open_gpu(args.adapter)?;
    if !args.json {
        outln!("GPU: {}", gpu.describe());
    }
    let map = crate::common::load_map(args.envmap).map_err(|e| e.to_string())?;
    let scene = crate::common::open_scene(args.scene, args.size, args.ground)?;
    let setup = std::time::Instant::now();
    let mut frame = Frame::with_scene(&gpu, scene, &map, args.lights)?;
    let setup_ms = setup.elapsed().as_secs_f64() * 1e3;
    let moving = args.animate.then(|| animated_object(&frame.scene));
    let d = &frame.decomposition;
    let (lights, directs) = (d.lights.len(), d.directs());
    if !args.json {
        outln!(
            "{}: {} triangles, {}x{}; {lights} lights ({}): {directs} EnvDirects with wedges, {} EnvIndirects with 1024² maps{}",
            args.scene,
            frame.scene.triangle_count(),
            args.size.0,
            args.size.1,
            light_extract::DEFAULT_METHOD,
            lights - directs,
            moving.map_or(String::new(), |k| format!("; {} moving", frame.scene.objects[k].name))
        );
    }
    let scales: &[(&str, u32)] =
        if args.json { &[("", args.scale)] } else { &[("full", 1), ("half", 2), ("quarter", 4)] };
    for &(name, scale) in scales {
        let mut last: Option<RenderedFrame> = None;
        let stats = measure_frames(&gpu, args.repeats, |k| -> Result<(), gpu::GpuError> {
            // what the previous frame skipped, read a frame late as a renderer would: its
            // work has finished, so this neither waits nor makes a buffer
            if let Some(previous) = last.take() {
                previous.finish_reports(&gpu)?;
            }
            if let Some(object) = moving {
                frame.set_transform(&gpu, object, animation_pose(&frame.scene, object, k))?;
            }
            last = Some(frame.render(&gpu, scale)?);
            Ok(())
        })
        .map_err(|e| e.to_string())?;
        // the last frame's, once the measured frames have finished
        let reports = match last {
            Some(r) => r.finish_reports(&gpu).map_err(|e| e.to_string())?.1,
            None => Vec::new(),
        };
        // what the last frame skipped and why
        let skipped = gpu::skip_reasons(&reports);
        if args.json {
            let mut v = json(args, &gpu, &stats, moving.map(|k| frame.scene.objects[k].name.as_str()), lights);
            v["triangles"] = frame.scene.triangle_count().into();
            v["setup_ms"] = setup_ms.into();
            v["lights_shadowed"] = (reports.len() - skipped.iter().map(|(_, n)| n).sum::<usize>()).into();
            v["lights_skipped"] = skipped.iter().map(|(why, n)| serde_json::json!({"why": why, "lights": n})).collect();
            outln!("{v}");
        } else {
            for (why, n) in &skipped {
                outln!("  EnvIndirects at {name} resolution: {n} lights without a shadow pass: {why}");
            }
            outln!(
                "  EnvIndirects at {name} resolution: median {:.2} ms ({:.1} fps) over {} frames; per frame {} submissions, {} waits, {} bytes read back, {:.2} ms CPU outside waits{}; {} pipelines created after the first frame",
                stats.wall_ms,
                1e3 / stats.wall_ms,
                stats.frames,
                stats.submits_per_frame,
                stats.waits_per_frame,
                stats.readback_bytes_per_frame,
                stats.cpu_record_ms,
                stats.gpu_ms.map_or(String::new(), |g| format!(", {g:.2} ms GPU (timestamps)")),
                stats.pipelines_created_after_first_frame,
            );
            outln!(
                "  EnvIndirects at {name} resolution: first frame {:.2} ms{} (pipelines compile, buffers grow){}",
                stats.first_frame_wall_ms,
                stats.first_frame_gpu_ms.map_or(String::new(), |g| format!(", {g:.2} ms GPU")),
                if name == "full" {
                    format!("; setup {setup_ms:.0} ms (decomposition, BVH and buffers)")
                } else {
                    String::new()
                },
            );
        }
    }
    Ok(())
}

fn json(args: &FrameArgs, gpu: &gpu::Gpu, s: &FrameStats, moving: Option<&str>, lights: usize) -> serde_json::Value {
    serde_json::json!({
        "scene": args.scene,
        "size": [args.size.0, args.size.1],
        "lights": lights,
        "indirect_scale": args.scale,
        "animated_object": moving,
        "frames": s.frames,
        "submits_per_frame": s.submits_per_frame,
        "waits_per_frame": s.waits_per_frame,
        "readback_bytes_per_frame": s.readback_bytes_per_frame,
        "pipelines_created_after_first_frame": s.pipelines_created_after_first_frame,
        "gate_passes_per_frame": s.gate_passes_per_frame,
        "buffers_created_per_frame": s.created_per_frame.buffers,
        "bind_groups_created_per_frame": s.created_per_frame.bind_groups,
        "textures_created_per_frame": s.created_per_frame.textures,
        "cpu_record_ms": s.cpu_record_ms,
        "gpu_ms": s.gpu_ms,
        "wall_ms": s.wall_ms,
        "first_frame_wall_ms": s.first_frame_wall_ms,
        "first_frame_gpu_ms": s.first_frame_gpu_ms,
        "adapter": gpu.describe(),
    })
}
