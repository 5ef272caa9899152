//! Full-screen passes: one triangle covering the target (`crates/gpu/shaders/fullscreen.wgsl`'s `vs`),
//! a fragment shader per pixel. The shading pass and every shadow technique's visibility pass
//! are such passes.

use crate::context::{Gpu, GpuError};

/// A full-screen pipeline of `module` (entry points `vs` and `fs`) writing one `format` target.
#[must_use]
pub fn pipeline(
    gpu: &Gpu,
    label: &str,
    module: &wgpu::ShaderModule,
    format: wgpu::TextureFormat,
) -> wgpu::RenderPipeline {
    pipeline_with_target(gpu, label, module, format.into())
}

/// As [`pipeline`] with a full colour target state (blending, e.g. into an accumulator).
#[must_use]
pub fn pipeline_with_target(
    gpu: &Gpu,
    label: &str,
    module: &wgpu::ShaderModule,
    target: wgpu::ColorTargetState,
) -> wgpu::RenderPipeline {
    pipeline_with_targets(gpu, label, module, &[Some(target)])
}

/// As [`pipeline_with_target`] writing several targets (`@location(k)` to `targets[k]`).
#[must_use]
pub fn pipeline_with_targets(
    gpu: &Gpu,
    label: &str,
    module: &wgpu::ShaderModule,
    targets: &[Option<wgpu::ColorTargetState>],
) -> wgpu::RenderPipeline {
    gpu.render_pipeline(&wgpu::RenderPipelineDescriptor {
        label: Some(label),
        layout: None,
        vertex: wgpu::VertexState {
            module,
            entry_point: Some("vs"),
            compilation_options: Default::default(),
            buffers: &[],
        },
        primitive: wgpu::PrimitiveState::default(),
        depth_stencil: None,
        multisample: Default::default(),
        fragment: Some(wgpu::FragmentState {
            module,
            entry_point: Some("fs"),
            compilation_options: Default::default(),
            targets,
        }),
        multiview_mask: None,
        cache: None,
    })
}

/// Runs `pipeline` with `bind` over `target` (cleared to `clear` first) and waits.
///
/// # Errors
/// GPU failures.
pub fn draw(
    gpu: &Gpu,
    pipeline: &wgpu::RenderPipeline,
    bind: &wgpu::BindGroup,
    target: &wgpu::TextureView,
    clear: wgpu::Color,
) -> Result<(), GpuError> {
    run(gpu, pipeline, bind, target, wgpu::LoadOp::Clear(clear))
}

/// As [`draw`] over what `target` holds: pixels the shader discards keep their value.
///
/// # Errors
/// GPU failures.
pub fn draw_over(
    gpu: &Gpu,
    pipeline: &wgpu::RenderPipeline,
    bind: &wgpu::BindGroup,
    target: &wgpu::TextureView,
) -> Result<(), GpuError> {
    run(gpu, pipeline, bind, target, wgpu::LoadOp::Load)
}

fn run(
    gpu: &Gpu,
    pipeline: &wgpu::RenderPipeline,
    bind: &wgpu::BindGroup,
    target: &wgpu::TextureView,
    load: wgpu::LoadOp<wgpu::Color>,
) -> Result<(), GpuError> {
    let mut encoder = gpu.encoder("full-screen pass");
    record(&mut encoder, pipeline, bind, target, load);
    gpu.submit_and_wait(encoder)
}

/// Records `pipeline` with `bind` over `target` into `encoder` (`load`: clear it first, or keep
/// what pixels the shader discards), without submitting.
pub fn record(
    encoder: &mut wgpu::CommandEncoder,
    pipeline: &wgpu::RenderPipeline,
    bind: &wgpu::BindGroup,
    target: &wgpu::TextureView,
    load: wgpu::LoadOp<wgpu::Color>,
) {
    let calls = crate::Calls::direct(vec![crate::Indirect::draw(0..3)]);
    record_calls(encoder, pipeline, bind, target, load, (&calls, 0));
}

/// As [`record`], the triangle drawn as call `k` of `calls` (`Indirect::draw(0..3)`), gated or
/// not: a gated-off light's pass only applies `load`.
pub fn record_calls(
    encoder: &mut wgpu::CommandEncoder,
    pipeline: &wgpu::RenderPipeline,
    bind: &wgpu::BindGroup,
    target: &wgpu::TextureView,
    load: wgpu::LoadOp<wgpu::Color>,
    (calls, k): (&crate::Calls, usize),
) {
    let mut pass = encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
        label: Some("full-screen pass"),
        color_attachments: &[Some(wgpu::RenderPassColorAttachment {
            view: target,
            depth_slice: None,
            resolve_target: None,
            ops: wgpu::Operations { load, store: wgpu::StoreOp::Store },
        })],
        ..Default::default()
    });
    pass.set_pipeline(pipeline);
    pass.set_bind_group(0, bind, &[]);
    calls.draw(&mut pass, k);
}
