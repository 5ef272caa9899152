// One representative's share of the frame's darkening: where its mask says the object blocks
// its origin (1 - visibility), add its transfer at the pixel, the bilinear blend of its
// receiver's four vertex transfers (radiance for HDR, codes for LDR).

struct Params {
    width: u32,
    height: u32,
    // transfer columns (receiver vertices) per representative
    slots: u32,
    rep: u32,
}

struct PixelRef {
    weights: vec4<f32>,
    // first column of the pixel's receiver, 0xffffffff for none
    slot: u32,
    pad0: u32,
    pad1: u32,
    pad2: u32,
}

@group(0) @binding(0) var<uniform> params: Params;
@group(0) @binding(1) var<storage, read> pixels: array<PixelRef>;
@group(0) @binding(2) var<storage, read> transfers: array<vec4<f32>>;
@group(0) @binding(3) var visibility: texture_2d<f32>;
@group(0) @binding(4) var<storage, read_write> darkening: array<vec4<f32>>;

@compute @workgroup_size(8, 8)
fn main(@builtin(global_invocation_id) id: vec3<u32>) {
    if id.x >= params.width || id.y >= params.height {
        return;
    }
    let k = id.y * params.width + id.x;
    let px = pixels[k];
    if px.slot == 0xffffffffu {
        return;
    }
    let m = 1.0 - textureLoad(visibility, vec2<i32>(id.xy), 0).r;
    if m <= 0.0 {
        return;
    }
    let base = params.rep * params.slots + px.slot;
    let t = px.weights.x * transfers[base] + px.weights.y * transfers[base + 1u]
        + px.weights.z * transfers[base + 2u] + px.weights.w * transfers[base + 3u];
    darkening[k] += m * t;
}
