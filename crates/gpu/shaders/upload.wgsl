// requires: gpu/fullscreen.wgsl
// Writes a visibility layer from per-pixel values computed elsewhere (row-major, one f32 per
// pixel): `gpu::PrecomputedVisibility`, e.g. ray-traced visibility as the truth row.

struct Params {
    // x image width
    size: vec4<u32>,
}

@group(0) @binding(0) var<uniform> params: Params;
@group(0) @binding(1) var<storage, read> values: array<f32>;

@fragment
fn fs(@builtin(position) frag: vec4<f32>) -> @location(0) vec4<f32> {
    let pixel = vec2<u32>(frag.xy);
    return vec4<f32>(clamp(values[pixel.y * params.size.x + pixel.x], 0.0, 1.0));
}
