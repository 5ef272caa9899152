//! The one interface of shadow techniques: given a frame's receivers (its G-buffer and what the
//! camera sees) and a light's shape, write the light's visibility layer. Shadow maps (hard, PCF,
//! PCSS, N samples), penumbra wedges and uploaded ray-traced visibility all implement
//! [`ShadowTechnique`]; the shading pass only reads the layers, and `validate` and the trade
//! report iterate over techniques through it.
//!
//! [`record_visibility`] is the frame loop: it records every light's passes into the caller's
//! encoder, skipping lights that no visible receiver can see (no shadow pass for a light nobody
//! sees) and those [`weber_negligible`] finds below Weber's 2 % at every visible receiver,
//! together, and reports what it skipped. [`render_visibility`] is the same loop measured: one
//! submission, waited for, each light between timestamps of its own.

use crate::context::{Gpu, GpuError};
use crate::gate::{Gate, GpuStats};
use crate::gbuffer::GBuffer;
use crate::shade::VisibilityLayers;
use crate::timer::Clock;
use glam::Vec3;
use std::time::Duration;

pub use scene::LightShape;

/// What a frame gives shadow techniques: the G-buffer on the GPU and, on the CPU, the visible
/// surface points (position, geometric normal; NaN positions for background pixels) with their
/// bounds. Techniques use the bounds to spend work only where receivers are.
pub struct Receivers<'a> {
    /// The frame's G-buffer.
    pub gbuffer: &'a GBuffer,
    /// The visible points, row-major, as [`GBuffer::read_points`] returns them.
    pub points: &'a [(Vec3, Vec3)],
    /// Axis-aligned bounds of the finite points, `None` when the camera sees nothing.
    pub bounds: Option<(Vec3, Vec3)>,
    /// Where most of what the camera sees is: the mean visible point and the 95th percentile of
    /// distances to it (a shadow map spends its texels there; the far rest stays unshadowed).
    pub focus: Option<(Vec3, f32)>,
    /// Lights known to be faced (or not) by a visible receiver without the points (from a
    /// [`crate::ReceiverStats`]); [`Receivers::any_faces`] answers from here first.
    pub facing: Vec<(LightShape, bool)>,
    /// The GPU's reduction of these receivers, left there ([`Receivers::on_gpu`]): lights are
    /// gated by it and orthographic maps take their focus from it, so the CPU never waits.
    pub on_gpu: Option<GpuStats>,
}

impl<'a> Receivers<'a> {
    /// The receivers of `gbuffer`, whose points `points` were read back from it.
    #[must_use]
    pub fn new(gbuffer: &'a GBuffer, points: &'a [(Vec3, Vec3)]) -> Self {
        let (mut lo, mut hi) = (Vec3::splat(f32::INFINITY), Vec3::splat(f32::NEG_INFINITY));
        for (p, _) in points.iter().filter(|(p, _)| p.is_finite()) {
            lo = lo.min(*p);
            hi = hi.max(*p);
        }
        Self {
            gbuffer,
            points,
            bounds: lo.is_finite().then_some((lo, hi)),
            focus: view_focus(points),
            facing: Vec::new(),
            on_gpu: None,
        }
    }

    /// The receivers of `gbuffer` as the CPU can know them without waiting: `bounds`, a box
    /// that holds every visible point (e.g. [`crate::conservative_bounds`] of the scene and
    /// the view), and the GPU's reduction of them left on the GPU (`stats`,
    /// [`crate::PendingStats::on_gpu`]), which gates each light's passes and gives maps their
    /// focus. [`Receivers::any_faces`] answers yes for every light: the GPU decides.
    #[must_use]
    pub fn on_gpu(gbuffer: &'a GBuffer, bounds: Option<(Vec3, Vec3)>, stats: GpuStats) -> Self {
        Self { gbuffer, points: &[], bounds, focus: None, facing: Vec::new(), on_gpu: Some(stats) }
    }

    /// The receivers of `gbuffer` as the GPU reduced them ([`crate::ReceiverReduction`], for
    /// `lights`), without its points: bounds, focus (the GPU's mean, in a fixed summation
    /// order, and its exact 95th percentile) and which of `lights` a receiver faces.
    #[must_use]
    pub fn from_stats(gbuffer: &'a GBuffer, stats: &crate::ReceiverStats, lights: &[LightShape]) -> Self {
        Self {
            gbuffer,
            points: &[],
            bounds: stats.bounds,
            focus: stats.mean.zip(stats.radius),
            facing: lights.iter().copied().zip(stats.faces.iter().copied()).collect(),
            on_gpu: None,
        }
    }

    /// Whether any visible receiver has part of `light` above its surface: a light no receiver
    /// faces lights nothing, so it needs no shadow pass.
    #[must_use]
    pub fn any_faces(&self, light: &LightShape) -> bool {
        if self.on_gpu.is_some() {
            return true;
        }
        if let Some((_, faces)) = self.facing.iter().find(|(l, _)| l == light) {
            return *faces;
        }
        self.points.iter().any(|(p, n)| p.is_finite() && light.reaches(*p, *n))
    }
}

/// Sphere around what the camera sees: the mean visible point and the 95th percentile of the
/// distances to it.
fn view_focus(points: &[(Vec3, Vec3)]) -> Option<(Vec3, f32)> {
    let pts: Vec<Vec3> = points.iter().map(|(p, _)| *p).filter(|p| p.is_finite()).collect();
    if pts.is_empty() {
        return None;
    }
    let c = pts.iter().copied().sum::<Vec3>() / pts.len() as f32;
    let mut d: Vec<f32> = pts.iter().map(|p| p.distance(c)).collect();
    let k = (d.len() * 95 / 100).min(d.len() - 1);
    let (_, r, _) = d.select_nth_unstable_by(k, f32::total_cmp);
    Some((c, *r))
}

/// What one technique did for one light.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct ShadowPassReport {
    /// GPU time of the light's passes (generation and visibility).
    pub time: Duration,
    /// The clock `time` comes from, `None` when nothing ran.
    pub clock: Option<Clock>,
    /// Why the light got no shadow pass (its layer stays lit), or `None`.
    pub skipped: Option<String>,
    /// Primitives drawn (triangles into maps, volume and wedge triangles).
    pub primitives: u64,
    /// Work that was left out because it could not matter (e.g. wedges of edges whose shadow
    /// cannot reach a visible receiver), as `(what, how many)`.
    pub culled: Vec<(&'static str, u64)>,
}

/// A GPU shadow technique: writes one light's visibility layer (1 lit, 0 shadowed) for a frame.
///
/// [`ShadowTechnique::record`] is the real-time path: it records the light's passes into the
/// caller's encoder and never submits, waits or maps. [`render_visibility`] wraps it for
/// measurement (every light of a frame in one submission, waited for, each light timed).
pub trait ShadowTechnique {
    /// Name, e.g. `wedge_raster` or `pcss_2048`; validate's rows prefix it with `gpu_`.
    fn name(&self) -> String;

    /// Whether it can shadow `light` (a cube map cannot shadow a distant light).
    fn supports(&self, light: &LightShape) -> bool;

    /// Records the passes writing `light`'s visibility of every G-buffer pixel of `receivers`
    /// into `target`, without submitting. Work recorded for several lights into one encoder
    /// runs in order, so a technique may reuse its scratch targets from light to light. The
    /// report's `time` is zero and its `clock` `None` (the caller times the submission).
    ///
    /// With a `gate` (the light's, from [`Receivers::on_gpu`]), every draw and dispatch is
    /// indirect through it ([`crate::Calls`]): where the GPU finds the light needs no pass,
    /// nothing is drawn and `target` is left as its passes clear it, lit. The report then says
    /// what would be drawn; what was skipped is known once the frame has run.
    ///
    /// # Errors
    /// A light the technique does not support; sizes beyond the device's limits.
    fn record(
        &self,
        gpu: &Gpu,
        encoder: &mut wgpu::CommandEncoder,
        receivers: &Receivers,
        light: &LightShape,
        gate: Option<Gate<'_>>,
        target: &wgpu::TextureView,
    ) -> Result<ShadowPassReport, GpuError>;

    /// Completes the reports of the lights this technique recorded last (`reports` in record
    /// order, skipped lights passed over) with what only the GPU knew when they were recorded,
    /// e.g. the primitives and culled work of geometry built on the GPU. Measurement only: it
    /// reads back and waits. The default has nothing to add.
    ///
    /// # Errors
    /// GPU failures.
    fn read_counts(&self, _gpu: &Gpu, _reports: &mut [ShadowPassReport]) -> Result<(), GpuError> {
        Ok(())
    }
}

/// Why a light got no shadow pass, or `None` when it needs one: no visible receiver faces it,
/// or `negligible` marks it (Weber's law).
fn skip_reason(receivers: &Receivers, light: &LightShape, negligible: bool) -> Option<String> {
    why_skipped(receivers.any_faces(light), negligible)
}

/// Why a light whose visible receivers `faced` it (or not) and that Weber's law finds
/// `negligible` (or not) gets no shadow pass, or `None` when it needs one.
pub(crate) fn why_skipped(faced: bool, negligible: bool) -> Option<String> {
    if !faced {
        return Some("no visible receiver faces it".into());
    }
    negligible.then(|| {
        format!(
            "under Weber's {:.0} % of every visible receiver's light, with the others skipped",
            WEBER_FRACTION * 100.0
        )
    })
}

/// The frame loop: `shadow(k, light)` for every light that needs a pass, a skip report for
/// the others.
fn each_light(
    receivers: &Receivers,
    lights: &[LightShape],
    negligible: &[bool],
    visibility: &VisibilityLayers,
    mut shadow: impl FnMut(u32, &LightShape) -> Result<ShadowPassReport, GpuError>,
) -> Result<Vec<ShadowPassReport>, GpuError> {
    if lights.len() as u64 > u64::from(visibility.layers()) {
        return Err(GpuError::TooLarge {
            what: "lights for the visibility layers",
            size: lights.len() as u64,
            limit: visibility.layers().into(),
        });
    }
    let mut out = Vec::with_capacity(lights.len());
    for (k, light) in lights.iter().enumerate() {
        match skip_reason(receivers, light, negligible.get(k).copied().unwrap_or(false)) {
            Some(why) => out.push(ShadowPassReport { skipped: Some(why), ..ShadowPassReport::default() }),
            None => out.push(shadow(k as u32, light)?),
        }
    }
    Ok(out)
}

/// Records every light's layer of `visibility` with `technique` into `encoder`, skipping
/// lights that no visible receiver faces and lights marked in `negligible` (e.g. by
/// [`weber_negligible`]; an empty slice marks none). Skipped lights' layers are left as they
/// are: clear `visibility` to lit first ([`VisibilityLayers::record_clear`]).
///
/// # Errors
/// [`GpuError::TooLarge`] when `visibility` has fewer layers than lights; the technique's
/// errors.
pub fn record_visibility(
    gpu: &Gpu,
    encoder: &mut wgpu::CommandEncoder,
    technique: &dyn ShadowTechnique,
    receivers: &Receivers,
    lights: &[LightShape],
    negligible: &[bool],
    visibility: &VisibilityLayers,
) -> Result<Vec<ShadowPassReport>, GpuError> {
    record_visibility_stamped(gpu, encoder, (technique, receivers), (lights, negligible), visibility, None)
}

/// [`record_visibility`] with light `k`'s passes between pair `first + k` of `stamps`
/// (measurement: [`LightStamps`]; `first` places a split frame's EnvIndirects after its
/// EnvDirects).
pub(crate) fn record_visibility_stamped(
    gpu: &Gpu,
    encoder: &mut wgpu::CommandEncoder,
    (technique, receivers): (&dyn ShadowTechnique, &Receivers),
    (lights, negligible): (&[LightShape], &[bool]),
    visibility: &VisibilityLayers,
    stamps: Option<(&LightStamps, usize)>,
) -> Result<Vec<ShadowPassReport>, GpuError> {
    let reports = each_light(receivers, lights, negligible, visibility, |k, light| {
        let gate = receivers.on_gpu.as_ref().map(|s| s.gate(k));
        if let Some((s, first)) = stamps {
            s.write(encoder, first + k as usize, 0);
        }
        let report = technique.record(gpu, encoder, receivers, light, gate, &visibility.layer(k));
        if let Some((s, first)) = stamps {
            s.write(encoder, first + k as usize, 1);
        }
        report
    })?;
    // skipped lights' pairs are written too (nothing between them), so that every query resolves
    if let Some((s, first)) = stamps {
        for (k, _) in reports.iter().enumerate().filter(|(_, r)| r.skipped.is_some()) {
            s.write(encoder, first + k, 0);
            s.write(encoder, first + k, 1);
        }
    }
    Ok(reports)
}

/// Two GPU timestamps a light around its recorded passes: how measurement times each light of
/// a frame recorded into one submission. Made per measured frame (measurement only).
pub struct LightStamps {
    stamps: crate::timer::Stamps,
    lights: usize,
}

impl LightStamps {
    /// Stamps for `lights` lights, `None` without timestamps inside encoders (or for none).
    ///
    /// # Errors
    /// [`GpuError::TooLarge`] past the queries one set holds.
    pub fn new(gpu: &Gpu, lights: usize) -> Result<Option<Self>, GpuError> {
        let stamps = crate::timer::Stamps::new(gpu, 2 * lights as u64, "timestamps of lights timed in one submission")?;
        Ok(stamps.map(|stamps| Self { stamps, lights }))
    }

    fn write(&self, encoder: &mut wgpu::CommandEncoder, light: usize, end: u32) {
        if light < self.lights {
            self.stamps.write(encoder, 2 * light as u32 + end);
        }
    }

    /// Records the stamps' resolve and copy, after every light's passes.
    pub fn record_resolve(&self, encoder: &mut wgpu::CommandEncoder) {
        self.stamps.record_resolve(encoder);
    }

    /// The buffer the stamps are mapped from, once their submission has run.
    #[must_use]
    pub fn read_buffer(&self) -> &wgpu::Buffer {
        self.stamps.read_buffer()
    }

    /// Puts each drawn light's time (between its two stamps, from the mapped `bytes`) into its
    /// report, `reports[k]` being light k's.
    pub fn apply(&self, gpu: &Gpu, bytes: &[u8], reports: &mut [ShadowPassReport]) {
        let ticks: Vec<u64> = bytemuck::pod_collect_to_vec(bytes);
        for (k, r) in reports.iter_mut().enumerate().take(self.lights) {
            if r.skipped.is_some() || ticks.len() < 2 * k + 2 {
                continue;
            }
            r.time = crate::timer::between(gpu, ticks[2 * k], ticks[2 * k + 1]);
            r.clock = Some(Clock::GpuTimestamps);
        }
    }
}

/// [`record_visibility`] measured: every light's passes recorded into one encoder between two
/// GPU timestamps of its own, one submission, one wait; each report's `time` is its light's.
/// Without timestamps inside encoders the same single submission is timed on the wall clock
/// and each light gets an even share of it ([`Clock::WallTimeShare`]): there is no per-light
/// submission. What validate, the trade and the benches measure a frame's lights with.
///
/// # Errors
/// As [`record_visibility`]; GPU failures.
pub fn render_visibility(
    gpu: &Gpu,
    technique: &dyn ShadowTechnique,
    receivers: &Receivers,
    lights: &[LightShape],
    negligible: &[bool],
    visibility: &VisibilityLayers,
) -> Result<Vec<ShadowPassReport>, GpuError> {
    if lights.is_empty() {
        return Ok(Vec::new());
    }
    let stamps = LightStamps::new(gpu, lights.len())?;
    let mut encoder = gpu.encoder("lights, each timed");
    let mut reports = record_visibility_stamped(
        gpu,
        &mut encoder,
        (technique, receivers),
        (lights, negligible),
        visibility,
        stamps.as_ref().map(|s| (s, 0)),
    )?;
    if let Some(s) = &stamps {
        s.record_resolve(&mut encoder);
    }
    let total = gpu.submit_timed(encoder)?;
    technique.read_counts(gpu, &mut reports)?;
    match &stamps {
        Some(s) => s.apply(gpu, &crate::readback::read_mapped(gpu, s.read_buffer())?, &mut reports),
        None => {
            // the lights recorded together cannot be told apart: an even share each
            let drawn = reports.iter().filter(|r| r.skipped.is_none()).count().max(1) as u32;
            for r in reports.iter_mut().filter(|r| r.skipped.is_none()) {
                r.time = total / drawn;
                r.clock = Some(Clock::WallTimeShare);
            }
        }
    }
    Ok(reports)
}

/// Weber's fraction: a change of luminance below 2 % of what a surface already receives is not
/// seen (as `light_extract::Weber` uses it for extraction).
pub const WEBER_FRACTION: f32 = 0.02;

/// Receivers [`weber_negligible`] looks at, at most: a regular subset of the G-buffer's points
/// (every k-th pixel in x and y), so the test costs the same whatever the image size.
pub const WEBER_MAX_RECEIVERS: usize = 1 << 16;

/// Which lights need no shadow pass by Weber's law: a set of lights whose unshadowed
/// irradiance, **summed**, stays below `fraction` of the receiver's whole unshadowed irradiance
/// (all lights and the ambient's SH9) at every visible receiver. Their shadows together change
/// no pixel by a visible amount. A per-light test alone would not do: on
/// `st_fagans_interior_1k.hdr` it skipped lights each under 2 % that together made the
/// ray-traced truth row's RMSE 9 % worse. Lights are taken greedily, faintest (by their largest
/// share anywhere) first, while the sum fits at every receiver.
///
/// Luminance; the diffuse lobe (a small light's glossy highlight can stand out more than its
/// irradiance says: pass a lower fraction for glossy scenes). Looks at most at
/// [`WEBER_MAX_RECEIVERS`] points of a regular subset of the image: a light that matters only
/// between them can be skipped. Non-finite irradiance marks nothing negligible.
#[must_use]
pub fn weber_negligible(
    receivers: &Receivers,
    lights: &[crate::shade::ShadeLight],
    ambient: Option<&envmap_sphere::Sh9>,
    fraction: f32,
) -> Vec<bool> {
    use crate::shade::ShadeLight;
    let luminance = |c: Vec3| c.dot(Vec3::new(0.2126, 0.7152, 0.0722));
    let (w, h) = receivers.gbuffer.size();
    let pixels = (w as usize * h as usize).max(1);
    let stride = ((pixels as f64 / WEBER_MAX_RECEIVERS as f64).sqrt().ceil() as usize).max(1);
    let points: Vec<(Vec3, Vec3)> = (0..h as usize)
        .step_by(stride)
        .flat_map(|y| (0..w as usize).step_by(stride).map(move |x| y * w as usize + x))
        .filter_map(|k| receivers.points.get(k).copied())
        .filter(|(p, _)| p.is_finite())
        .collect();
    let irradiance = |light: &ShadeLight, (p, n): (Vec3, Vec3)| match *light {
        ShadeLight::Distant { direction, irradiance, half_angle } => {
            let solid_angle = std::f32::consts::TAU * (1.0 - half_angle.cos());
            let cos = n.dot(direction.normalize_or_zero());
            let mean_cos = if half_angle.sin() > 1e-3 {
                scene::cone_cosine_integral(cos, half_angle) / solid_angle
            } else {
                cos.max(0.0)
            };
            luminance(irradiance) * mean_cos
        }
        ShadeLight::Point { position, intensity } => {
            let d = position - p;
            let d2 = d.length_squared().max(f32::MIN_POSITIVE);
            luminance(intensity) * (n.dot(d) / d2.sqrt()).max(0.0) / d2
        }
    };
    let totals: Vec<f32> = points
        .iter()
        .map(|&pn| {
            ambient.map_or(0.0, |a| luminance(a.irradiance(pn.1)).max(0.0))
                + lights.iter().map(|l| irradiance(l, pn)).sum::<f32>()
        })
        .collect();
    if !totals.iter().all(|t| t.is_finite()) {
        return vec![false; lights.len()];
    }
    // each light's largest share of a receiver's irradiance: the order of the greedy pass
    let share = |light: &ShadeLight, (k, &pn): (usize, &(Vec3, Vec3))| irradiance(light, pn) / totals[k].max(1e-30);
    let mut order: Vec<(usize, f32)> = lights
        .iter()
        .enumerate()
        .map(|(i, l)| (i, points.iter().enumerate().map(|r| share(l, r)).fold(0.0f32, f32::max)))
        .filter(|(_, s)| *s < fraction)
        .collect();
    order.sort_by(|a, b| a.1.total_cmp(&b.1));
    let mut negligible = vec![false; lights.len()];
    let mut skipped_share = vec![0f32; points.len()];
    for (i, _) in order {
        let add: Vec<f32> = points.iter().enumerate().map(|r| share(&lights[i], r)).collect();
        if add.iter().zip(&skipped_share).all(|(a, s)| a + s < fraction) {
            for (s, a) in skipped_share.iter_mut().zip(add) {
                *s += a;
            }
            negligible[i] = true;
        }
    }
    negligible
}

/// Why lights got no shadow pass, each reason with its count, in the order first met.
#[must_use]
pub fn skip_reasons(reports: &[ShadowPassReport]) -> Vec<(String, usize)> {
    let mut out: Vec<(String, usize)> = Vec::new();
    for why in reports.iter().filter_map(|r| r.skipped.as_deref()) {
        match out.iter_mut().find(|(w, _)| w == why) {
            Some((_, n)) => *n += 1,
            None => out.push((why.to_string(), 1)),
        }
    }
    out
}

/// The work the reports left out ([`ShadowPassReport::culled`]), summed per kind.
#[must_use]
pub fn culled_totals(reports: &[ShadowPassReport]) -> Vec<(&'static str, u64)> {
    let mut out: Vec<(&'static str, u64)> = Vec::new();
    for &(what, n) in reports.iter().flat_map(|r| r.culled.iter()) {
        match out.iter_mut().find(|(w, _)| *w == what) {
            Some((_, total)) => *total += n,
            None => out.push((what, n)),
        }
    }
    out
}

/// Totals over a frame's reports: (GPU time, lights shadowed, lights skipped, primitives).
#[must_use]
pub fn totals(reports: &[ShadowPassReport]) -> (Duration, usize, usize, u64) {
    let time = reports.iter().map(|r| r.time).sum();
    let skipped = reports.iter().filter(|r| r.skipped.is_some()).count();
    let primitives = reports.iter().map(|r| r.primitives).sum();
    (time, reports.len() - skipped, skipped, primitives)
}

/// Visibility computed elsewhere (e.g. ray traced on the CPU) written into the layers: the
/// technique whose shadows are the truth, so that a frame's remaining error is the shading's.
pub struct PrecomputedVisibility {
    name: String,
    size: (u32, u32),
    // per light, its values uploaded once and the bind group over them
    layers: Vec<(LightShape, wgpu::BindGroup)>,
    pipeline: wgpu::RenderPipeline,
}

impl PrecomputedVisibility {
    /// `layers`: per light its per-pixel visibility, row-major, `size.0 × size.1` values.
    ///
    /// # Errors
    /// [`GpuError::TooLarge`] when a layer's length is not the image's.
    pub fn new(gpu: &Gpu, name: &str, size: (u32, u32), layers: Vec<(LightShape, Vec<f32>)>) -> Result<Self, GpuError> {
        let pixels = u64::from(size.0) * u64::from(size.1);
        if let Some((_, l)) = layers.iter().find(|(_, l)| l.len() as u64 != pixels) {
            return Err(GpuError::TooLarge {
                what: "visibility values for the image",
                size: l.len() as u64,
                limit: pixels,
            });
        }
        let module = crate::shader::module(&gpu.device, "upload", include_str!("../shaders/upload.wgsl"), &[]);
        let pipeline = crate::fullscreen::pipeline(gpu, "upload", &module, VisibilityLayers::FORMAT);
        let buffer = |label, contents: &[u8], usage| {
            gpu.create_buffer_init(&wgpu::util::BufferInitDescriptor { label: Some(label), contents, usage })
        };
        let params = [size.0, size.1, 0, 0];
        let params = buffer("upload params", bytemuck::cast_slice(&params), wgpu::BufferUsages::UNIFORM);
        let layers = layers
            .into_iter()
            .map(|(light, values)| {
                let values = buffer("upload values", bytemuck::cast_slice(&values), wgpu::BufferUsages::STORAGE);
                let bind = gpu.create_bind_group(&wgpu::BindGroupDescriptor {
                    label: Some("upload"),
                    layout: &pipeline.get_bind_group_layout(0),
                    entries: &[
                        wgpu::BindGroupEntry { binding: 0, resource: params.as_entire_binding() },
                        wgpu::BindGroupEntry { binding: 1, resource: values.as_entire_binding() },
                    ],
                });
                (light, bind)
            })
            .collect();
        Ok(Self { name: name.into(), size, layers, pipeline })
    }
}

impl ShadowTechnique for PrecomputedVisibility {
    fn name(&self) -> String {
        self.name.clone()
    }

    fn supports(&self, light: &LightShape) -> bool {
        self.layers.iter().any(|(l, _)| l == light)
    }

    fn record(
        &self,
        gpu: &Gpu,
        encoder: &mut wgpu::CommandEncoder,
        receivers: &Receivers,
        light: &LightShape,
        gate: Option<Gate<'_>>,
        target: &wgpu::TextureView,
    ) -> Result<ShadowPassReport, GpuError> {
        let Some((_, bind)) = self.layers.iter().find(|(l, _)| l == light) else {
            return Err(GpuError::Failed(format!("{}: no visibility for {light:?}", self.name)));
        };
        if receivers.gbuffer.size() != self.size {
            return Err(GpuError::Failed(format!(
                "{}: computed for {:?}, not {:?}",
                self.name,
                self.size,
                receivers.gbuffer.size()
            )));
        }
        let calls = crate::Calls::new(gpu, encoder, gate, vec![crate::Indirect::draw(0..3)]);
        let clear = wgpu::LoadOp::Clear(wgpu::Color::WHITE);
        crate::fullscreen::record_calls(encoder, &self.pipeline, bind, target, clear, (&calls, 0));
        Ok(ShadowPassReport::default())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn skip_reasons_and_culled_work_add_up_per_kind() {
        let r = |skipped: Option<&str>, culled: Vec<(&'static str, u64)>| ShadowPassReport {
            skipped: skipped.map(String::from),
            culled,
            ..ShadowPassReport::default()
        };
        let reports = [
            r(Some("b"), vec![]),
            r(None, vec![("wedges", 3), ("casters", 1)]),
            r(Some("a"), vec![("wedges", 2)]),
            r(Some("b"), vec![]),
        ];
        assert_eq!(skip_reasons(&reports), vec![("b".to_string(), 2), ("a".to_string(), 1)]);
        assert_eq!(culled_totals(&reports), vec![("wedges", 5), ("casters", 1)]);
        assert!(skip_reasons(&[]).is_empty() && culled_totals(&[]).is_empty());
    }
}
