//! The one recorded frame: the G-buffers, their receivers reduced on the GPU, every light's
//! shadow pass gated by that reduction, and paper 001's split shading (EnvDirects at full
//! resolution, EnvIndirects at 1 / scale, joint-bilateral upsampled), in two submissions with no
//! wait and no readback inside. `cargo xtask frame`, the benches and the trade draw through it;
//! measurement wraps it ([`LitSettings::time_lights`], a wait after), it is not a second path.
//!
//! Everything it renders into is made once per size, scale and light count and rendered into
//! frame after frame: a frame's image is overwritten by the next. Paper 001's interleaved light
//! sets are the same frame drawn once per set, each gathered into one image
//! ([`LitFrame::render_interleaved`]).

use crate::ambient::SpecularAmbient;
use crate::context::{Gpu, GpuError};
use crate::gbuffer::{GBuffer, GBufferPass, GBufferTargets};
use crate::geometry::SceneGeometry;
use crate::interleave::{InterleavePass, MAX_SETS};
use crate::receivers::{MappedStats, PendingStats, ReceiverReduction, WeberInput};
use crate::shade::{Background, ShadeLight, ShadeParams, ShadingPass, VisibilityLayers};
use crate::slots::Keyed;
use crate::split::{SplitFrame, SplitPasses, SplitSettings, SplitTargets, indirect_size, record_split_stamped};
use crate::technique::{
    LightShape, LightStamps, Receivers, ShadowPassReport, ShadowTechnique, WEBER_FRACTION, record_visibility_stamped,
    weber_negligible,
};
use crate::upsample::UpsamplePass;
use crate::view::{View, conservative_bounds};
use envmap_sphere::Sh9;
use std::cell::RefCell;
use std::rc::Rc;

/// What a frame lights: its lights, the EnvDirects first, and what shades it beside them.
#[derive(Clone, Copy)]
pub struct FrameLights<'a> {
    /// Every light, the EnvDirects first.
    pub lights: &'a [ShadeLight],
    /// Their shapes, for the shadow techniques, in the same order.
    pub shapes: &'a [LightShape],
    /// How many of `lights` are EnvDirects, shaded at full resolution; all of them: no split
    /// (one shading pass at full resolution).
    pub directs: usize,
    /// Ambient SH9 (diffuse lobe).
    pub ambient: Option<&'a Sh9>,
    /// The ambient on the specular lobe.
    pub specular_ambient: Option<&'a SpecularAmbient>,
    /// What misses see.
    pub background: Option<&'a Background>,
}

/// The shadow techniques of a frame: one for the EnvDirects, one for the EnvIndirects (the same
/// one twice, or paper 001's wedges and maps).
#[derive(Clone, Copy)]
pub struct FrameShadows<'a> {
    /// The EnvDirects'.
    pub direct: &'a dyn ShadowTechnique,
    /// The EnvIndirects'.
    pub indirect: &'a dyn ShadowTechnique,
}

/// Where a reference frame's receivers come from ([`LitFrame::render_reference`]): the CPU
/// waits for them and plans every light from them, as no real-time frame does.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ReferenceReceivers {
    /// The GPU's reduction mapped back (a few hundred bytes).
    ReadStats,
    /// The G-buffers' points mapped back (32 bytes a pixel) and reduced on the CPU
    /// (`Receivers::new`, `weber_negligible`): the original reference.
    CpuPoints,
}

/// How a frame is drawn.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct LitSettings {
    /// The EnvIndirects' resolution and upsampling (unused without EnvIndirects).
    pub split: SplitSettings,
    /// Whether Weber's law skips lights too faint to matter ([`WEBER_FRACTION`]); lights no
    /// visible receiver faces are skipped either way.
    pub weber: bool,
    /// Measurement: each light's passes between two timestamps of its own, mapped with the
    /// frame's reports ([`RenderedFrame::finish_reports`]); without timestamps inside encoders
    /// nothing is timed. Makes a query set and two buffers a frame.
    pub time_lights: bool,
}

impl Default for LitSettings {
    /// Paper 001's frame: EnvIndirects at half resolution, Weber's skipping.
    fn default() -> Self {
        Self { split: SplitSettings::default(), weber: true, time_lights: false }
    }
}

/// A frame's image (submitted, not waited for) and what its shadow passes did.
pub struct RenderedFrame {
    /// The HDR image: the frame's target, which the next frame of the same size renders into.
    pub texture: wgpu::Texture,
    /// Per light, EnvDirects first: its shadow pass as recorded, or why it had none (empty for a
    /// frame without shadows). Where the GPU gated the lights, which it skipped is known once
    /// the frame has run: [`RenderedFrame::finish_reports`].
    pub reports: Vec<ShadowPassReport>,
    // the receivers' statistics being mapped (full resolution, then low), and the EnvDirects
    gated: Option<(Vec<MappedStats>, usize)>,
    // measurement: the lights' stamps being mapped
    stamps: Option<(LightStamps, crate::readback::MappingRead)>,
}

impl RenderedFrame {
    /// The image and the reports completed with what the GPU knew only once the frame ran:
    /// the lights it skipped (why, and nothing drawn) and, when timed, each light's time. Read
    /// once the frame has finished (after the caller's own wait, or a later frame's): no wait
    /// of its own, a few hundred bytes.
    ///
    /// # Errors
    /// The frame has not finished; GPU failures.
    pub fn finish_reports(self, gpu: &Gpu) -> Result<(wgpu::Texture, Vec<ShadowPassReport>), GpuError> {
        let mut reports = self.reports;
        if let Some((mapped, directs)) = self.gated {
            let stats = mapped.into_iter().map(|m| m.finish(gpu)).collect::<Result<Vec<_>, _>>()?;
            for (k, r) in reports.iter_mut().enumerate() {
                let s = if k < directs { stats.first() } else { stats.last() };
                if let Some(why) = s.and_then(|s| s.skip_reason(k)) {
                    *r = ShadowPassReport { skipped: Some(why), ..ShadowPassReport::default() };
                }
            }
        }
        if let Some((stamps, mapping)) = self.stamps {
            let bytes = mapping.finish(gpu)?;
            stamps.apply(gpu, bytes.first().map_or(&[][..], Vec::as_slice), &mut reports);
        }
        Ok((self.texture, reports))
    }
}

/// An interleaved frame's image (submitted, not waited for) and its sets' frames, in order.
pub struct InterleavedImage {
    /// The gathered HDR image, which the next interleaved frame of the same size renders into.
    pub texture: wgpu::Texture,
    /// Each set's frame, for its reports (its own image is the next set's by now).
    pub sets: Vec<RenderedFrame>,
}

impl InterleavedImage {
    /// The gathered image and every set's reports, set after set, completed as
    /// [`RenderedFrame::finish_reports`] completes one frame's. Read once the last set has run.
    ///
    /// # Errors
    /// As [`RenderedFrame::finish_reports`].
    pub fn finish_reports(self, gpu: &Gpu) -> Result<(wgpu::Texture, Vec<ShadowPassReport>), GpuError> {
        let mut reports = Vec::new();
        for set in self.sets {
            reports.extend(set.finish_reports(gpu)?.1);
        }
        Ok((self.texture, reports))
    }
}

/// Receivers and their Weber flags (per light of the frame; empty: none marked).
type Flagged<'a> = (&'a Receivers<'a>, &'a [bool]);

/// What a frame at one scale renders into: the low-resolution G-buffer (none at scale 1) and
/// the split frame's images.
type ScaleTargets = (Option<GBufferTargets>, SplitTargets);

/// The frame's passes, built once, and its targets, made once per size, scale and light count.
pub struct LitFrame {
    gbuffer: GBufferPass,
    shading: ShadingPass,
    upsample: UpsamplePass,
    // the receivers of the full- and the low-resolution G-buffer
    reductions: [ReceiverReduction; 2],
    targets: GBufferTargets,
    // per (scale, EnvIndirects): the low G-buffer and the split frame's images
    scales: RefCell<Keyed<(u32, u32), Rc<ScaleTargets>>>,
    // the EnvDirects' visibility, per layer count
    direct_visibility: RefCell<Keyed<u32, Rc<VisibilityLayers>>>,
    // a frame without EnvIndirects: its one shaded image
    whole: RefCell<Keyed<(u32, u32), wgpu::Texture>>,
    // interleaved light sets: the gathering pass and the gathered image
    gather: InterleavePass,
    interleaved: RefCell<Keyed<(u32, u32), wgpu::Texture>>,
}

impl LitFrame {
    /// The passes and the full-resolution targets for frames of `size` pixels.
    ///
    /// # Errors
    /// Sizes beyond the adapter's limits; GPU failures.
    pub fn new(gpu: &Gpu, size: (u32, u32)) -> Result<Self, GpuError> {
        Ok(Self {
            gbuffer: GBufferPass::new(gpu),
            shading: ShadingPass::new(gpu)?,
            upsample: UpsamplePass::new(gpu),
            reductions: [ReceiverReduction::new(gpu), ReceiverReduction::new(gpu)],
            targets: GBufferTargets::new(gpu, size)?,
            scales: RefCell::default(),
            direct_visibility: RefCell::default(),
            whole: RefCell::default(),
            gather: InterleavePass::new(gpu),
            interleaved: RefCell::default(),
        })
    }

    /// The frame's size.
    #[must_use]
    pub fn size(&self) -> (u32, u32) {
        self.targets.size()
    }

    /// Renders `geometry` from `view` (of the frame's size) lit by `lights`, each shadowed by
    /// `shadows` (`None`: unshadowed), and returns the image with its work submitted and not
    /// waited for: two submissions, no wait, no readback inside (the G-buffers with their
    /// receivers reduced on the GPU, then everything else recorded into one encoder). The
    /// reduction gates each light's draws and fits the orthographic maps, the wedges are planned
    /// from the scene's box within the view ([`conservative_bounds`]), and its few hundred bytes
    /// are mapped for [`RenderedFrame::finish_reports`]. A frame without shadows is one
    /// submission.
    ///
    /// # Errors
    /// A view of another size; a split frame without shadows; a scale that does not divide the
    /// size; the techniques' errors; GPU failures.
    pub fn render(
        &self,
        gpu: &Gpu,
        geometry: &SceneGeometry,
        view: &View,
        lights: &FrameLights,
        shadows: Option<FrameShadows<'_>>,
        settings: &LitSettings,
    ) -> Result<RenderedFrame, GpuError> {
        self.check(lights, shadows.is_some(), settings)?;
        let mut encoder = gpu.encoder("frame g-buffers");
        let (gb, low_gb) = self.record_gbuffers(gpu, &mut encoder, geometry, view, lights, settings)?;
        let Some(shadows) = shadows else {
            let receivers = Receivers::new(&gb, &[]);
            return self.record_lit(gpu, encoder, geometry, lights, None, (&receivers, &[]), None, settings);
        };
        let pending = self.record_reductions(gpu, &mut encoder, (&gb, low_gb.as_ref()), lights, settings)?;
        gpu.submit(encoder);
        let scene_box = {
            let (lo, hi) = geometry.bounds;
            (lo.is_finite() && hi.is_finite()).then_some((lo, hi))
        };
        let in_view = |g: &GBuffer| scene_box.and_then(|b| conservative_bounds(b, &g.view));
        let receivers = Receivers::on_gpu(&gb, in_view(&gb), pending[0].on_gpu().clone());
        // the EnvIndirects' gates are the low reduction's, from their first light on
        let low_gpu = pending[pending.len() - 1].on_gpu().starting_at(lights.directs as u32);
        let low_receivers = match &low_gb {
            Some(l) => Receivers::on_gpu(l, in_view(l), low_gpu),
            None => Receivers::on_gpu(&gb, receivers.bounds, low_gpu),
        };
        let frame = self.record_lit(
            gpu,
            gpu.encoder("frame"),
            geometry,
            lights,
            Some(shadows),
            (&receivers, &[]),
            Some((&low_receivers, &[])),
            settings,
        )?;
        let mapped = pending.into_iter().map(|p| p.map(gpu)).collect();
        Ok(RenderedFrame { gated: Some((mapped, lights.directs)), ..frame })
    }

    /// The same frame with the CPU waiting for its receivers (`from`) and planning every light
    /// from them: the references [`LitFrame::render`] is tested against. A measuring wrapper,
    /// not a real-time path: it waits for the G-buffers (and the reduction) before recording
    /// the shadows; the rest is submitted and not waited for.
    ///
    /// # Errors
    /// As [`LitFrame::render`].
    #[allow(clippy::too_many_arguments)]
    pub fn render_reference(
        &self,
        gpu: &Gpu,
        geometry: &SceneGeometry,
        view: &View,
        lights: &FrameLights,
        shadows: FrameShadows<'_>,
        settings: &LitSettings,
        from: ReferenceReceivers,
    ) -> Result<RenderedFrame, GpuError> {
        self.check(lights, true, settings)?;
        let mut encoder = gpu.encoder("reference g-buffers");
        let (gb, low_gb) = self.record_gbuffers(gpu, &mut encoder, geometry, view, lights, settings)?;
        // one submission: the G-buffers, and the reduction where it is what is read back
        let pending = match from {
            ReferenceReceivers::ReadStats => {
                self.record_reductions(gpu, &mut encoder, (&gb, low_gb.as_ref()), lights, settings)?
            }
            ReferenceReceivers::CpuPoints => Vec::new(),
        };
        gpu.submit(encoder);
        let points;
        // the receivers with their Weber flags, full resolution and low
        let (receivers, low) = match from {
            ReferenceReceivers::CpuPoints => {
                points = (gb.read_points(gpu)?, low_gb.as_ref().map(|l| l.read_points(gpu)).transpose()?);
                let weber = |r: &Receivers| {
                    if settings.weber {
                        weber_negligible(r, lights.lights, lights.ambient, WEBER_FRACTION)
                    } else {
                        Vec::new()
                    }
                };
                let full = Receivers::new(&gb, &points.0);
                let low = low_gb.as_ref().zip(points.1.as_deref()).map(|(l, p)| Receivers::new(l, p));
                let (full_flags, low_flags) = (weber(&full), low.as_ref().map(weber));
                ((full, full_flags), low.zip(low_flags))
            }
            ReferenceReceivers::ReadStats => {
                let mut stats = PendingStats::read_all(gpu, pending)?;
                // the low G-buffer's statistics last (the full-resolution ones when there is none)
                let last = stats.len() - 1;
                let full = Receivers::from_stats(&gb, &stats[0], lights.shapes);
                let low = low_gb.as_ref().map(|l| Receivers::from_stats(l, &stats[last], lights.shapes));
                let low_flags = low.as_ref().map(|_| std::mem::take(&mut stats[last].negligible));
                ((full, std::mem::take(&mut stats[0].negligible)), low.zip(low_flags))
            }
        };
        let low = low.as_ref().map(|(r, n)| (r, n.as_slice()));
        let receivers = (&receivers.0, receivers.1.as_slice());
        self.record_lit(gpu, gpu.encoder("reference frame"), geometry, lights, Some(shadows), receivers, low, settings)
    }

    /// Paper 001's interleaved sampling: each light set of `sets` drawn as a whole frame
    /// ([`LitFrame::render`], or with `reference` [`LitFrame::render_reference`]) and its pixels
    /// of the interleaving tile gathered into one image, one submission after each set's, no
    /// wait. Each set is gated and flagged by Weber's law on its own lights. The techniques'
    /// own counts ([`ShadowTechnique::read_counts`]) are the last set's once it has run.
    ///
    /// # Errors
    /// No set; more than [`MAX_SETS`]; as [`LitFrame::render`].
    #[allow(clippy::too_many_arguments)]
    pub fn render_interleaved(
        &self,
        gpu: &Gpu,
        geometry: &SceneGeometry,
        view: &View,
        sets: &[FrameLights],
        shadows: FrameShadows<'_>,
        settings: &LitSettings,
        reference: Option<ReferenceReceivers>,
    ) -> Result<InterleavedImage, GpuError> {
        if sets.is_empty() {
            return Err(GpuError::Failed("interleaving: no light set".into()));
        }
        if sets.len() > MAX_SETS as usize {
            return Err(GpuError::TooLarge {
                what: "interleaved light sets",
                size: sets.len() as u64,
                limit: MAX_SETS.into(),
            });
        }
        let size = self.size();
        let texture = self
            .interleaved
            .borrow_mut()
            .try_get(size, || {
                crate::target::render_target(gpu, "interleaved frame", (size.0, size.1, 1), crate::shade::HDR_FORMAT)
            })?
            .clone();
        let n = sets.len() as u32;
        let mut frames = Vec::with_capacity(sets.len());
        for (k, lights) in (0..n).zip(sets) {
            let frame = match reference {
                None => self.render(gpu, geometry, view, lights, Some(shadows), settings)?,
                Some(from) => self.render_reference(gpu, geometry, view, lights, shadows, settings, from)?,
            };
            // the set's image is the frame's target, which the next set renders into: gathered
            // in a submission between the two
            let mut encoder = gpu.encoder("interleave gather");
            self.gather.record_gather(gpu, &mut encoder, (&frame.texture, &texture), n, k)?;
            gpu.submit(encoder);
            frames.push(frame);
        }
        Ok(InterleavedImage { texture, sets: frames })
    }

    /// What a frame asks of its lights and settings, checked before anything is recorded.
    fn check(&self, lights: &FrameLights, shadowed: bool, settings: &LitSettings) -> Result<(), GpuError> {
        if lights.directs > lights.lights.len() || lights.shapes.len() != lights.lights.len() {
            return Err(GpuError::Failed(format!(
                "{} directs of {} lights ({} shapes)",
                lights.directs,
                lights.lights.len(),
                lights.shapes.len()
            )));
        }
        if lights.directs < lights.lights.len() {
            if !shadowed {
                return Err(GpuError::Failed("a split frame needs its shadow techniques".into()));
            }
            indirect_size(self.size(), &settings.split)?;
        }
        Ok(())
    }

    /// Records the full-resolution G-buffer and, for a split frame below full resolution, the
    /// EnvIndirects' into `encoder`.
    fn record_gbuffers(
        &self,
        gpu: &Gpu,
        encoder: &mut wgpu::CommandEncoder,
        geometry: &SceneGeometry,
        view: &View,
        lights: &FrameLights,
        settings: &LitSettings,
    ) -> Result<(GBuffer, Option<GBuffer>), GpuError> {
        let gb = self.gbuffer.record_into(gpu, encoder, geometry, view, &self.targets)?;
        let low = if lights.directs < lights.lights.len() {
            match (&self.scale_targets(gpu, settings, lights)?.0, indirect_size(view.size(), &settings.split)?) {
                (Some(t), (w, h)) => Some(self.gbuffer.record_into(gpu, encoder, geometry, &view.resized(w, h), t)?),
                (None, _) => None,
            }
        } else {
            None
        };
        Ok((gb, low))
    }

    /// Records the reduction of the full-resolution receivers and of the low ones, if any.
    fn record_reductions(
        &self,
        gpu: &Gpu,
        encoder: &mut wgpu::CommandEncoder,
        (gb, low_gb): (&GBuffer, Option<&GBuffer>),
        lights: &FrameLights,
        settings: &LitSettings,
    ) -> Result<Vec<PendingStats>, GpuError> {
        let weber = settings.weber.then_some(WeberInput {
            lights: lights.lights,
            ambient: lights.ambient,
            fraction: WEBER_FRACTION,
        });
        let mut pending = vec![self.reductions[0].record(gpu, encoder, gb, lights.shapes, weber)?];
        if let Some(l) = low_gb {
            pending.push(self.reductions[1].record(gpu, encoder, l, lights.shapes, weber)?);
        }
        Ok(pending)
    }

    /// The low-resolution G-buffer's (none at scale 1) and the split frame's targets.
    fn scale_targets(
        &self,
        gpu: &Gpu,
        settings: &LitSettings,
        lights: &FrameLights,
    ) -> Result<Rc<ScaleTargets>, GpuError> {
        let scale = settings.split.indirect_scale;
        let indirects = (lights.lights.len() - lights.directs) as u32;
        let size = self.size();
        let make = || {
            let low_size = indirect_size(size, &settings.split)?;
            // at scale 1 the EnvIndirects are shaded from the full-resolution G-buffer
            let low = (scale != 1).then(|| GBufferTargets::new(gpu, low_size)).transpose()?;
            Ok(Rc::new((low, SplitTargets::new(gpu, size, &settings.split, indirects)?)))
        };
        Ok(self.scales.borrow_mut().try_get((scale, indirects), make)?.clone())
    }

    /// Records the lights' shadows and the shading over `receivers` and `low` (each with its
    /// Weber flags, per light of the frame; `low` `None`: the full-resolution ones) into
    /// `encoder`, submits it and returns the frame. A split frame has its `shadows`
    /// ([`LitFrame::check`]).
    #[allow(clippy::too_many_arguments)]
    fn record_lit(
        &self,
        gpu: &Gpu,
        mut encoder: wgpu::CommandEncoder,
        geometry: &SceneGeometry,
        lights: &FrameLights,
        shadows: Option<FrameShadows<'_>>,
        (receivers, negligible): Flagged<'_>,
        low: Option<Flagged<'_>>,
        settings: &LitSettings,
    ) -> Result<RenderedFrame, GpuError> {
        let directs = lights.directs;
        let size = self.size();
        let vis = {
            let layers = (directs as u32).max(1);
            let mut cache = self.direct_visibility.borrow_mut();
            cache.try_get(layers, || VisibilityLayers::allocate(gpu, size.0, size.1, layers).map(Rc::new))?.clone()
        };
        vis.record_clear(&mut encoder);
        let stamps =
            if settings.time_lights && shadows.is_some() { LightStamps::new(gpu, lights.lights.len())? } else { None };
        let mut reports = match shadows {
            Some(s) => record_visibility_stamped(
                gpu,
                &mut encoder,
                (s.direct, receivers),
                (&lights.shapes[..directs], negligible.get(..directs).unwrap_or(&[])),
                &vis,
                stamps.as_ref().map(|s| (s, 0)),
            )?,
            None => Vec::new(),
        };
        let texture = match shadows {
            Some(shadows) if directs < lights.lights.len() => {
                let targets = self.scale_targets(gpu, settings, lights)?;
                let (low, low_negligible) = low.unwrap_or((receivers, negligible));
                let split = record_split_stamped(
                    gpu,
                    &mut encoder,
                    &SplitPasses { gbuffer: &self.gbuffer, shading: &self.shading, upsample: &self.upsample },
                    geometry,
                    (receivers, &vis),
                    (low, Some(low_negligible)),
                    &SplitFrame { lit: *lights, targets: Some(&targets.1) },
                    shadows.indirect,
                    &settings.split,
                    stamps.as_ref(),
                )?;
                reports.extend(split.indirect_reports);
                split.texture
            }
            _ => {
                let target = self
                    .whole
                    .borrow_mut()
                    .try_get(size, || {
                        crate::target::render_target(gpu, "lit frame", (size.0, size.1, 1), crate::shade::HDR_FORMAT)
                    })?
                    .clone();
                let params = ShadeParams {
                    lights: lights.lights,
                    ambient: lights.ambient,
                    background: lights.background,
                    specular_ambient: lights.specular_ambient,
                    lights_only: false,
                };
                self.shading.record_into(gpu, &mut encoder, geometry, receivers.gbuffer, &params, &vis, &target)?;
                target
            }
        };
        if let Some(s) = &stamps {
            s.record_resolve(&mut encoder);
        }
        gpu.submit(encoder);
        let stamps = stamps.map(|s| {
            let mapping = crate::readback::MappingRead::start(gpu, vec![s.read_buffer().clone()]);
            (s, mapping)
        });
        Ok(RenderedFrame { texture, reports, gated: None, stamps })
    }
}
