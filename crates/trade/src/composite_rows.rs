//! Measuring the compositor: for each setting (passes, HDR or LDR) the GPU composite's error
//! against the truth in 8-bit codes and its time per frame, beside Debevec's offline error; and
//! Figure 3's datasets from a frame's vertices.

use std::time::{Duration, Instant};

use gpu::{Gpu, GpuError};

use differential_composite::compositor::FrameTransfers;
use differential_composite::gpu::{FrameTimes, GpuCompositor, GpuSettings, MapWork};
use differential_composite::ldr::Dataset;
use differential_composite::{CodeError, Compositor, Mode, SyntheticObject, code_error};

use crate::session::Session;

/// One setting's figures.
#[derive(Clone, Debug)]
pub struct Row {
    /// Passes asked for (0: one per occluded source).
    pub passes: usize,
    /// Representatives drawn.
    pub reps: usize,
    /// Sources the traversal reported.
    pub occluded_sources: usize,
    /// HDR or LDR.
    pub mode: Mode,
    /// Error against the truth.
    pub error: CodeError,
    /// The median frame's times over the repeats.
    pub times: FrameTimes,
    /// Its shadow maps' views.
    pub work: MapWork,
    /// The composite.
    pub image: Vec<[u8; 3]>,
}

impl Row {
    /// The passes as printed: a number, or "all".
    #[must_use]
    pub fn passes_label(&self) -> String {
        if self.passes == 0 { "all".to_string() } else { self.passes.to_string() }
    }

    /// "HDR" or "LDR".
    #[must_use]
    pub fn mode_label(&self) -> &'static str {
        if self.mode == Mode::Ldr { "LDR" } else { "HDR" }
    }

    /// The frame's times as the commands' JSON gives them: `ms_per_frame`, each stage's
    /// `ms_*`, and the `clock` that timed the GPU's stages.
    #[must_use]
    pub fn times_json(&self) -> serde_json::Map<String, serde_json::Value> {
        let [total, cpu, gbuffer, maps, masks, resolve] = self.times_ms();
        let mut out: serde_json::Map<String, serde_json::Value> = [
            ("ms_per_frame", total),
            ("ms_cpu", cpu),
            ("ms_gbuffer", gbuffer),
            ("ms_shadow_maps", maps),
            ("ms_masks", masks),
            ("ms_resolve", resolve),
        ]
        .into_iter()
        .map(|(k, v)| (k.to_string(), serde_json::json!(v)))
        .collect();
        out.insert("clock".into(), self.times.clock.name().into());
        out
    }

    /// The setting as the commands' JSON lists it under `rows`: its passes, mode,
    /// representatives, errors and [`Row::times_json`].
    #[must_use]
    pub fn json(&self) -> serde_json::Value {
        let mut o = self.times_json();
        o.extend([
            ("passes".to_string(), serde_json::json!(self.passes)),
            ("mode".to_string(), serde_json::json!(self.mode_label().to_lowercase())),
            ("representatives".to_string(), serde_json::json!(self.reps)),
            ("error_mae_codes".to_string(), serde_json::json!(self.error.mae_changed)),
            ("error_rmse_codes".to_string(), serde_json::json!(self.error.rmse_changed)),
        ]);
        o.into()
    }

    /// The frame's times in milliseconds: total, CPU, G-buffer, maps, masks, resolve.
    #[must_use]
    pub fn times_ms(&self) -> [f64; 6] {
        let t = &self.times;
        [t.total(), t.cpu, t.gbuffer, t.shadow_maps, t.masks, t.resolve].map(ms)
    }
}

/// Composites `frame` (made by `c.frame`) for `object` in `mode`, measured: the 8-bit image,
/// where the time went and the shadow maps' views. The frame is [`GpuCompositor::record`]'s
/// recording: with timestamps inside encoders, one submission with a GPU timestamp between its
/// stages; without, each stage submitted and waited for on the wall clock. Then the image is
/// read back (not timed). `cpu` is `frame`'s own and the recording's.
///
/// # Errors
/// GPU failures.
pub fn composite(
    gpu: &Gpu,
    gc: &GpuCompositor,
    (c, frame, object): (&Compositor, &FrameTransfers, &SyntheticObject),
    mode: Mode,
    settings: &GpuSettings,
) -> Result<(Vec<[u8; 3]>, FrameTimes, MapWork), GpuError> {
    let mut times = FrameTimes { cpu: frame.cpu(), ..FrameTimes::default() };
    let mut encoder = gpu.encoder("composite, measured");
    let work = if let Some(stamps) = gpu::StageStamps::new(gpu, 4)? {
        let t = Instant::now();
        let mut stamp = |e: &mut wgpu::CommandEncoder, k: usize| {
            stamps.write(e, k as u32);
            Ok(())
        };
        let work = gc.record_staged(gpu, &mut encoder, (c, frame, object), mode, settings, &mut stamp)?;
        stamps.record_resolve(&mut encoder);
        times.cpu += t.elapsed();
        gpu.submit_and_wait(encoder)?;
        if let [g, m, k, r] = stamps.read(gpu)?[..] {
            (times.gbuffer, times.shadow_maps, times.masks, times.resolve) = (g, m, k, r);
        }
        times.clock = gpu::Clock::GpuTimestamps;
        work
    } else {
        // each stage recorded so far submitted and waited for, a new encoder in its place
        let mut stages = [Duration::ZERO; 4];
        let mut t = Instant::now();
        let mut submit = |e: &mut wgpu::CommandEncoder, k: usize| {
            if k > 0 {
                gpu.submit_and_wait(std::mem::replace(e, gpu.encoder("composite, measured")))?;
                stages[k - 1] = t.elapsed();
            }
            t = Instant::now();
            Ok(())
        };
        let work = gc.record_staged(gpu, &mut encoder, (c, frame, object), mode, settings, &mut submit)?;
        [times.gbuffer, times.shadow_maps, times.masks, times.resolve] = stages;
        times.clock = gpu::Clock::WallTime;
        work
    };
    Ok((gc.read_output(gpu)?, times, work))
}

/// Composites `object` with each of `passes` in each of `modes`, `repeats` times each (the
/// median frame by total time is kept), against `truth`.
///
/// # Errors
/// GPU failures.
#[allow(clippy::too_many_arguments)]
pub fn rows(
    gpu: &Gpu,
    gc: &GpuCompositor,
    c: &Compositor,
    object: &SyntheticObject,
    truth: &[[u8; 3]],
    passes: &[usize],
    modes: &[Mode],
    settings: &GpuSettings,
    repeats: usize,
) -> Result<Vec<Row>, GpuError> {
    let mut out = Vec::new();
    for &n in passes {
        for &mode in modes {
            let mut runs: Vec<(FrameTransfers, Vec<[u8; 3]>, FrameTimes, MapWork)> = Vec::new();
            for _ in 0..repeats.max(1) {
                let frame = c.frame(object, n);
                let (image, times, work) = composite(gpu, gc, (c, &frame, object), mode, settings)?;
                runs.push((frame, image, times, work));
            }
            runs.sort_by_key(|r| r.2.total());
            let (frame, image, times, work) = runs.swap_remove(runs.len() / 2);
            out.push(Row {
                passes: n,
                reps: frame.reps.len(),
                occluded_sources: frame.occluded_sources,
                mode,
                error: code_error(&image, truth, &c.photo_ldr),
                times,
                work,
                image,
            });
        }
    }
    Ok(out)
}

/// Milliseconds of a duration.
#[must_use]
pub fn ms(d: Duration) -> f64 {
    d.as_secs_f64() * 1e3
}

/// Figure 3's datasets from `frame`: up to `count` receiver vertices with at least `sources`
/// non-zero transfers from the frame's occluded sources (one representative a source), those
/// with the most radiance first, each with its `sources` largest transfers.
#[must_use]
pub fn figure3_datasets(session: &Session, frame: &FrameTransfers, count: usize, sources: usize) -> Vec<Dataset> {
    let c = &session.compositor;
    let mut vertices: Vec<Dataset> = (0..c.prepared.transfers.slots)
        .filter_map(|s| {
            let mut t: Vec<glam::Vec3> =
                frame.reps.iter().map(|r| r.radiance[s] * r.keep).filter(|v| v.max_element() > 0.0).collect();
            if t.len() < sources {
                return None;
            }
            t.sort_by(|a, b| real_scene::luminance(*b).total_cmp(&real_scene::luminance(*a)));
            t.truncate(sources);
            Some(Dataset { radiance: c.vertex_radiance[s], transfers: t })
        })
        .collect();
    vertices.sort_by(|a, b| real_scene::luminance(b.radiance).total_cmp(&real_scene::luminance(a.radiance)));
    vertices.truncate(count);
    vertices
}
