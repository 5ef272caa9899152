// requires: gpu/fullscreen.wgsl
// Resolve of an accumulated visibility (`gpu::accumulate`) into a visibility layer: the mean of
// N lit tests, V = clamp(r * scale, 0, 1). Background pixels (G-buffer w < 0) stay lit.

struct Params {
    // x scale
    config: vec4<f32>,
}

@group(0) @binding(0) var<uniform> params: Params;
@group(0) @binding(1) var g_position: texture_2d<f32>;
@group(0) @binding(2) var accumulated: texture_2d<f32>;

@fragment
fn fs(@builtin(position) frag: vec4<f32>) -> @location(0) vec4<f32> {
    let pixel = vec2<i32>(frag.xy);
    if textureLoad(g_position, pixel, 0).w < 0.0 {
        return vec4<f32>(1.0);
    }
    return vec4<f32>(clamp(textureLoad(accumulated, pixel, 0).r * params.config.x, 0.0, 1.0));
}
