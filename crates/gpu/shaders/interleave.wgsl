// requires: gpu/fullscreen.wgsl
// Interleaved sampling (Keller and Heidrich 2001; paper 001, section 3.5): each pixel takes
// the image of one light set, set = (x mod a) + a (y mod b) over an a x b tile with a b = sets.
// This pass copies set `index`'s pixels from `src` and leaves the others as they are.

struct Params {
    // x tile width a, y tile height b, z this set's index
    info: vec4<u32>,
}

@group(0) @binding(0) var<uniform> params: Params;
@group(0) @binding(1) var src: texture_2d<f32>;

@fragment
fn fs(@builtin(position) frag: vec4<f32>) -> @location(0) vec4<f32> {
    let p = vec2<u32>(frag.xy);
    let which = p.x % params.info.x + params.info.x * (p.y % params.info.y);
    if which != params.info.z {
        discard;
    }
    return textureLoad(src, vec2<i32>(p), 0);
}
