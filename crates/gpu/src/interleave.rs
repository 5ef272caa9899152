//! Interleaved sampling of light sets over the pixels (Keller and Heidrich 2001; paper 001,
//! section 3.5): with `n` sets, pixel (x, y) shows set (x mod a) + a (y mod b) of an a x b
//! tile (a b = n, as square as n allows), so every tile holds each set once and a filter over a
//! tile (or supersampling) averages the sets. Each set is rendered whole and its pixels gathered
//! into one image: the shadow work is n times one set's.

use crate::context::{Gpu, GpuError};
use crate::geometry::SceneGeometry;
use crate::shade::{ShadeLight, ShadeParams, ShadingPass, Visibility};
use crate::technique::{LightShape, Receivers, ShadowPassReport, ShadowTechnique, render_visibility};
use scene::DistantLight;

/// The most light sets [`render_interleaved`] takes (each is a whole frame's shadow work).
pub const MAX_SETS: u32 = 256;

/// The tile (a, b) of `sets` sets: b the largest divisor of `sets` not above its square root.
#[must_use]
pub fn interleave_tile(sets: u32) -> (u32, u32) {
    let sets = sets.max(1);
    let b = (1..=sets).filter(|b| sets.is_multiple_of(*b) && b * b <= sets).max().unwrap_or(1);
    (sets / b, b)
}

/// The set pixel (x, y) shows.
#[must_use]
pub fn interleave_set(x: u32, y: u32, sets: u32) -> u32 {
    let (a, b) = interleave_tile(sets);
    x % a + a * (y % b)
}

/// The gathering pass: pipeline built once.
pub struct InterleavePass {
    pipeline: wgpu::RenderPipeline,
}

impl InterleavePass {
    /// Builds the pipeline.
    #[must_use]
    pub fn new(gpu: &Gpu) -> Self {
        let module =
            crate::shader::module(&gpu.device, "interleave", include_str!("../../../shaders/gpu/interleave.wgsl"), &[]);
        Self { pipeline: crate::fullscreen::pipeline(gpu, "interleave", &module, crate::shade::HDR_FORMAT) }
    }

    /// Copies the pixels of set `index` of `sets` from `src` into `dst` (same size, both
    /// [`crate::HDR_FORMAT`]); `dst`'s other pixels are kept.
    ///
    /// # Errors
    /// [`GpuError::Failed`] for an index out of range or sizes that differ; GPU failures.
    pub fn gather(
        &self,
        gpu: &Gpu,
        src: &wgpu::Texture,
        dst: &wgpu::Texture,
        sets: u32,
        index: u32,
    ) -> Result<(), GpuError> {
        if index >= sets || src.size() != dst.size() {
            return Err(GpuError::Failed(format!(
                "interleaving: set {index} of {sets}, images {:?} and {:?}",
                src.size(),
                dst.size()
            )));
        }
        let (a, b) = interleave_tile(sets);
        let buffer = gpu.create_buffer_init(&wgpu::util::BufferInitDescriptor {
            label: Some("interleave params"),
            contents: bytemuck::cast_slice(&[a, b, index, 0u32]),
            usage: wgpu::BufferUsages::UNIFORM,
        });
        let view = src.create_view(&Default::default());
        let bind = gpu.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("interleave"),
            layout: &self.pipeline.get_bind_group_layout(0),
            entries: &[
                wgpu::BindGroupEntry { binding: 0, resource: buffer.as_entire_binding() },
                wgpu::BindGroupEntry { binding: 1, resource: wgpu::BindingResource::TextureView(&view) },
            ],
        });
        crate::fullscreen::draw_over(gpu, &self.pipeline, &bind, &dst.create_view(&Default::default()))
    }
}

/// What every set of an interleaved frame shares: the G-buffer's receivers, the shading
/// parameters (their `lights` are replaced by each set's) and the lights skipped by Weber's law
/// (by index, the same in every set: a set perturbs the lights, it does not reorder them).
pub struct InterleavedFrame<'a> {
    /// The scene on the GPU.
    pub geometry: &'a SceneGeometry,
    /// The frame's G-buffer and its points.
    pub receivers: &'a Receivers<'a>,
    /// Ambient, background and specular ambient; `lights` is ignored.
    pub params: &'a ShadeParams<'a>,
    /// Lights whose shadows are skipped, by index (may be empty).
    pub negligible: &'a [bool],
}

/// Paper 001's interleaved sampling on the GPU: each light set of `sets` shadowed by
/// `technique` and shaded whole, its pixels of the interleaving tile gathered into one image.
/// Returns the image (on the GPU, [`crate::HDR_FORMAT`]) and every set's shadow reports, set
/// after set.
///
/// # Errors
/// [`GpuError::Failed`] for no set; [`GpuError::TooLarge`] for more than [`MAX_SETS`]; GPU
/// failures.
pub fn render_interleaved(
    gpu: &Gpu,
    pass: &ShadingPass,
    frame: &InterleavedFrame,
    technique: &dyn ShadowTechnique,
    sets: &[Vec<DistantLight>],
) -> Result<(wgpu::Texture, Vec<ShadowPassReport>), GpuError> {
    if sets.is_empty() {
        return Err(GpuError::Failed("interleaving: no light set".into()));
    }
    let gb = frame.receivers.gbuffer;
    let (w, h) = gb.size();
    if sets.len() > MAX_SETS as usize {
        return Err(GpuError::TooLarge {
            what: "interleaved light sets",
            size: sets.len() as u64,
            limit: MAX_SETS.into(),
        });
    }
    let n = sets.len() as u32;
    let gathered = crate::render_target(gpu, "interleaved", (w, h, 1), crate::HDR_FORMAT)?;
    let gather = InterleavePass::new(gpu);
    let mut reports = Vec::new();
    for (k, set) in (0..n).zip(sets) {
        let lights: Vec<ShadeLight> = set.iter().map(ShadeLight::from).collect();
        let shapes: Vec<LightShape> = set.iter().map(LightShape::from).collect();
        let vis = Visibility::new(gpu, w, h, lights.len().max(1) as u32)?;
        reports.extend(render_visibility(gpu, technique, frame.receivers, &shapes, frame.negligible, &vis)?);
        let params = ShadeParams { lights: &lights, ..*frame.params };
        let image = pass.render_texture(gpu, frame.geometry, gb, &params, &vis)?;
        gather.gather(gpu, &image, &gathered, n, k)?;
    }
    Ok((gathered, reports))
}
