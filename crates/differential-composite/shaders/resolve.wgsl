// requires: gpu/sh9.wgsl
// The composite: the object (G-buffer object index `object`) shaded by its SH9 irradiance, the
// rest the photograph less the darkening — in radiance then through the camera response (HDR),
// or in codes (LDR) — as 8-bit RGBA.

struct Params {
    width: u32,
    height: u32,
    // 0 HDR, 1 LDR
    mode: u32,
    object: u32,
    // x exposure, y 1 / gamma, z white
    response: vec4<f32>,
    // the object's albedo / pi
    albedo: vec4<f32>,
    irradiance: array<vec4<f32>, 9>,
}

@group(0) @binding(0) var<uniform> params: Params;
@group(0) @binding(1) var<storage, read> photo_hdr: array<vec4<f32>>;
@group(0) @binding(2) var<storage, read> photo_ldr: array<u32>;
@group(0) @binding(3) var<storage, read> darkening: array<vec4<f32>>;
@group(0) @binding(4) var g_position: texture_2d<f32>;
@group(0) @binding(5) var g_normal: texture_2d<f32>;
@group(0) @binding(6) var<storage, read_write> out: array<u32>;

// T in unrounded codes, as `CameraResponse::curve` x 255
fn codes(l: vec3<f32>) -> vec3<f32> {
    let x = max(l * params.response.x / params.response.z, vec3<f32>(0.0));
    return 255.0 * pow(min(x, vec3<f32>(1.0)), vec3<f32>(params.response.y));
}

fn pack(c: vec3<f32>) -> u32 {
    let q = vec3<u32>(clamp(round(c), vec3<f32>(0.0), vec3<f32>(255.0)));
    return q.x | (q.y << 8u) | (q.z << 16u) | (255u << 24u);
}

fn unpack(p: u32) -> vec3<f32> {
    return vec3<f32>(f32(p & 255u), f32((p >> 8u) & 255u), f32((p >> 16u) & 255u));
}

@compute @workgroup_size(8, 8)
fn main(@builtin(global_invocation_id) id: vec3<u32>) {
    if id.x >= params.width || id.y >= params.height {
        return;
    }
    let k = id.y * params.width + id.x;
    let g = textureLoad(g_position, vec2<i32>(id.xy), 0);
    if g.w >= 0.0 && u32(g.w + 0.5) == params.object {
        let n = normalize(textureLoad(g_normal, vec2<i32>(id.xy), 0).xyz);
        out[k] = pack(codes(max(params.albedo.rgb * sh9_irradiance(params.irradiance, n), vec3<f32>(0.0))));
        return;
    }
    let d = darkening[k].rgb;
    if all(d == vec3<f32>(0.0)) {
        out[k] = photo_ldr[k];
        return;
    }
    if params.mode == 0u {
        out[k] = pack(codes(max(photo_hdr[k].rgb - d, vec3<f32>(0.0))));
    } else {
        out[k] = pack(unpack(photo_ldr[k]) - d);
    }
}
