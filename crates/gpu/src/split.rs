//! Paper 001's frame (sections 3.4-3.5): the EnvDirects (the first lights, high-frequency) shaded
//! at full resolution with the ambient, the EnvIndirects (the rest, low-frequency) shaded from a
//! G-buffer at 1 / `indirect_scale` of the resolution with their own shadow technique, and
//! joint-bilateral upsampled onto the first. What a light *is* (direct or indirect) comes from
//! the extraction; this module only draws it.

use crate::context::{Gpu, GpuError};
use crate::gbuffer::GBufferPass;
use crate::geometry::SceneGeometry;
use crate::lit_frame::FrameLights;
use crate::shade::{ShadeParams, ShadingPass, VisibilityLayers};
use crate::technique::{Receivers, ShadowPassReport, ShadowTechnique, WEBER_FRACTION, weber_negligible};
use crate::upsample::{JointBilateral, UpsamplePass};

/// How the EnvIndirects are drawn.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SplitSettings {
    /// The EnvIndirects are shaded at 1 / this of the G-buffer's resolution (1: full; the
    /// G-buffer's sides must be multiples of it).
    pub indirect_scale: u32,
    /// How they are brought back to full resolution.
    pub upsample: JointBilateral,
}

impl Default for SplitSettings {
    /// Paper 001: half resolution, its joint bilateral sigmas.
    fn default() -> Self {
        Self { indirect_scale: 2, upsample: JointBilateral::PAPER }
    }
}

/// The lights and ambient of one split frame, and what it renders into.
#[derive(Clone, Copy)]
pub struct SplitFrame<'a> {
    /// Every light, the EnvDirects first, and what shades them beside.
    pub lit: FrameLights<'a>,
    /// What the frame renders into, made once by the caller ([`SplitTargets::new`]); `None`:
    /// new textures for this frame alone.
    pub targets: Option<&'a SplitTargets>,
}

/// What a split frame renders into, made once per size: the EnvDirects' shaded image, the
/// EnvIndirects' visibility and shaded image at their resolution, and the output. A frame
/// rendered into them is overwritten by the next one.
pub struct SplitTargets {
    base: wgpu::Texture,
    indirect_visibility: VisibilityLayers,
    shaded: wgpu::Texture,
    output: wgpu::Texture,
}

impl SplitTargets {
    /// Targets for frames of `size` pixels with `indirects` EnvIndirects drawn as `settings`
    /// says.
    ///
    /// # Errors
    /// [`GpuError::Failed`] for a scale that does not divide `size`; [`GpuError::TooLarge`]
    /// beyond the adapter's limits.
    pub fn new(gpu: &Gpu, size: (u32, u32), settings: &SplitSettings, indirects: u32) -> Result<Self, GpuError> {
        let (lw, lh) = indirect_size(size, settings)?;
        let target = |label, (w, h)| crate::target::render_target(gpu, label, (w, h, 1), crate::shade::HDR_FORMAT);
        Ok(Self {
            base: target("split base", size)?,
            indirect_visibility: VisibilityLayers::allocate(gpu, lw, lh, indirects)?,
            shaded: target("split indirects", (lw, lh))?,
            output: target("split frame", size)?,
        })
    }

    /// Whether frames of `size` with `indirects` EnvIndirects at `low` pixels render into these.
    fn fits(&self, size: (u32, u32), low: (u32, u32), indirects: u32) -> bool {
        let v = &self.indirect_visibility.texture;
        (self.output.width(), self.output.height()) == size
            && (v.width(), v.height()) == low
            && self.indirect_visibility.layers() == indirects.max(1)
    }
}

/// The passes a split frame uses, built once.
pub struct SplitPasses<'a> {
    /// For the low-resolution G-buffer.
    pub gbuffer: &'a GBufferPass,
    /// Shading at both resolutions.
    pub shading: &'a ShadingPass,
    /// Joint bilateral upsampling (and, at scale 1, the sum of the two parts).
    pub upsample: &'a UpsamplePass,
}

/// A split frame's image and what its EnvIndirects cost.
pub struct SplitImage {
    /// Full-resolution HDR image.
    pub texture: wgpu::Texture,
    /// The EnvIndirects' shadow passes, one report per indirect light.
    pub indirect_reports: Vec<ShadowPassReport>,
    /// The resolution the EnvIndirects were shaded at.
    pub indirect_size: (u32, u32),
}

/// The camera the EnvIndirects are shaded from: `camera` at 1 / `settings.indirect_scale` of
/// its size.
///
/// # Errors
/// [`GpuError::Failed`] for a scale that does not divide the camera's size.
pub fn indirect_camera(camera: &scene::Camera, settings: &SplitSettings) -> Result<scene::Camera, GpuError> {
    let (width, height) = indirect_size((camera.width, camera.height), settings)?;
    Ok(scene::Camera { width, height, ..*camera })
}

/// The size the EnvIndirects are shaded at for a frame of `(w, h)` pixels.
pub(crate) fn indirect_size((w, h): (u32, u32), settings: &SplitSettings) -> Result<(u32, u32), GpuError> {
    let f = settings.indirect_scale;
    if f == 0 || !w.is_multiple_of(f) || !h.is_multiple_of(f) {
        return Err(GpuError::Failed(format!("EnvIndirects at 1/{f} of {w}x{h}: the scale must divide both sides")));
    }
    Ok((w / f, h / f))
}

/// Records a split frame into `encoder`, without submitting. The EnvDirects' visibility comes
/// in `direct_visibility` (layer k for light k < `directs`, made by the caller with any
/// technique); the EnvIndirects' is made here with `indirect` over `low` (the receivers of the
/// G-buffer `passes.gbuffer` renders from [`indirect_camera`]; `receivers` themselves at scale
/// 1), skipping lights no receiver faces and those Weber's law finds negligible there: the
/// flags given with `low` (per light of the frame, e.g. a [`crate::ReceiverStats`]'s), else
/// [`weber_negligible`] over its points.
///
/// # Errors
/// [`GpuError::Failed`] for a scale that does not divide the G-buffer's size, low receivers of
/// another size, or more directs than lights; the technique's errors.
#[allow(clippy::too_many_arguments)]
pub fn record_split(
    gpu: &Gpu,
    encoder: &mut wgpu::CommandEncoder,
    passes: &SplitPasses,
    geometry: &SceneGeometry,
    (receivers, direct_visibility): (&Receivers, &VisibilityLayers),
    (low, low_negligible): (&Receivers, Option<&[bool]>),
    frame: &SplitFrame,
    indirect: &dyn ShadowTechnique,
    settings: &SplitSettings,
) -> Result<SplitImage, GpuError> {
    let visibility = (receivers, direct_visibility);
    record_split_stamped(
        gpu,
        encoder,
        passes,
        geometry,
        visibility,
        (low, low_negligible),
        frame,
        indirect,
        settings,
        None,
    )
}

/// [`record_split`] with EnvIndirect k timed between pair `directs + k` of `stamps`
/// (measurement: [`LitSettings::time_lights`](crate::LitSettings::time_lights)).
#[allow(clippy::too_many_arguments)]
pub(crate) fn record_split_stamped(
    gpu: &Gpu,
    encoder: &mut wgpu::CommandEncoder,
    passes: &SplitPasses,
    geometry: &SceneGeometry,
    (receivers, direct_visibility): (&Receivers, &VisibilityLayers),
    (low, low_negligible): (&Receivers, Option<&[bool]>),
    frame: &SplitFrame,
    indirect: &dyn ShadowTechnique,
    settings: &SplitSettings,
    stamps: Option<&crate::technique::LightStamps>,
) -> Result<SplitImage, GpuError> {
    let gb = receivers.gbuffer;
    if low.gbuffer.size() != indirect_size(gb.size(), settings)? {
        return Err(GpuError::Failed(format!(
            "EnvIndirects at 1/{} of {:?}: low receivers of {:?}",
            settings.indirect_scale,
            gb.size(),
            low.gbuffer.size()
        )));
    }
    if frame.lit.directs > frame.lit.lights.len() || frame.lit.shapes.len() != frame.lit.lights.len() {
        return Err(GpuError::Failed(format!(
            "{} directs of {} lights ({} shapes)",
            frame.lit.directs,
            frame.lit.lights.len(),
            frame.lit.shapes.len()
        )));
    }
    let (directs, indirects) = frame.lit.lights.split_at(frame.lit.directs);
    let indirect_shapes = &frame.lit.shapes[frame.lit.directs..];
    let (lw, lh) = low.gbuffer.size();
    let own;
    let targets = match frame.targets {
        Some(t) if t.fits(gb.size(), (lw, lh), indirects.len() as u32) => t,
        Some(_) => {
            return Err(GpuError::Failed(format!(
                "split targets made for another size or light count than {:?} with {} EnvIndirects at {lw}x{lh}",
                gb.size(),
                indirects.len()
            )));
        }
        None => {
            own = SplitTargets::new(gpu, gb.size(), settings, indirects.len() as u32)?;
            &own
        }
    };
    passes.shading.record_into(
        gpu,
        encoder,
        geometry,
        gb,
        &ShadeParams {
            lights: directs,
            ambient: frame.lit.ambient,
            background: frame.lit.background,
            specular_ambient: frame.lit.specular_ambient,
            lights_only: false,
        },
        direct_visibility,
        &targets.base,
    )?;
    let visibility = &targets.indirect_visibility;
    visibility.record_clear(encoder);
    // the directs count towards what a receiver already gets
    let mut negligible = match low_negligible {
        Some(n) => n.to_vec(),
        None => weber_negligible(low, frame.lit.lights, frame.lit.ambient, WEBER_FRACTION),
    };
    let negligible =
        if negligible.len() >= frame.lit.directs { negligible.split_off(frame.lit.directs) } else { Vec::new() };
    let indirect_reports = crate::technique::record_visibility_stamped(
        gpu,
        encoder,
        (indirect, low),
        (indirect_shapes, &negligible),
        visibility,
        stamps.map(|s| (s, frame.lit.directs)),
    )?;
    passes.shading.record_into(
        gpu,
        encoder,
        geometry,
        low.gbuffer,
        &ShadeParams { lights: indirects, lights_only: true, ..Default::default() },
        visibility,
        &targets.shaded,
    )?;
    // at scale 1 the pass with a 1 x 1 window is the plain sum
    let upsample = if settings.indirect_scale == 1 {
        JointBilateral { radius: 0, ..JointBilateral::GAUSSIAN }
    } else {
        settings.upsample
    };
    passes.upsample.record_into(
        gpu,
        encoder,
        geometry,
        (low.gbuffer, &targets.shaded),
        (gb, &targets.base),
        &upsample,
        &targets.output,
    )?;
    let texture = targets.output.clone();
    Ok(SplitImage { texture, indirect_reports, indirect_size: (lw, lh) })
}
