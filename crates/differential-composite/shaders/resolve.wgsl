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
    // the G-buffer's samples a pixel a side (1, or 2 for 2 x 2 coverage)
    samples: u32,
    // lights shaded per pixel (at most 8)
    light_count: u32,
    pad1: u32,
    pad2: u32,
    // x exposure, y 1 / gamma, z white, w the photograph's clip level (0: none)
    response: vec4<f32>,
    // the object's albedo / pi
    albedo: vec4<f32>,
    irradiance: array<vec4<f32>, 9>,
    // per light: unit direction towards it, then its power (radiance x solid angle)
    lights: array<vec4<f32>, 16>,
}

// The object's irradiance for unit normal `n`: the probe's SH9 and the lights
// (`FrameTransfers::object_irradiance_at`).
fn object_irradiance(n: vec3<f32>) -> vec3<f32> {
    var e = sh9_irradiance(params.irradiance, n);
    for (var l = 0u; l < min(params.light_count, 8u); l++) {
        e += params.lights[2u * l + 1u].rgb * max(dot(n, params.lights[2u * l].xyz), 0.0);
    }
    return e;
}

@group(0) @binding(0) var<uniform> params: Params;
@group(0) @binding(1) var<storage, read> photo_hdr: array<vec4<f32>>;
@group(0) @binding(2) var<storage, read> photo_ldr: array<u32>;
@group(0) @binding(3) var<storage, read> darkening: array<vec4<f32>>;
@group(0) @binding(4) var g_position: texture_2d<f32>;
@group(0) @binding(5) var g_normal: texture_2d<f32>;
@group(0) @binding(6) var<storage, read_write> out: array<u32>;
// per pixel, the darkening's factor (`Compositor::pixel_scale`)
@group(0) @binding(7) var<storage, read> pixel_scale: array<vec4<f32>>;
// the composite in radiance (HDR mode; the photograph where LDR mode leaves it)
@group(0) @binding(8) var<storage, read_write> out_hdr: array<vec4<f32>>;

// T in unrounded codes, as `CameraResponse::curve` x 255
fn codes(l: vec3<f32>) -> vec3<f32> {
    let x = max(l * params.response.x / params.response.z, vec3<f32>(0.0));
    return 255.0 * pow(min(x, vec3<f32>(1.0)), vec3<f32>(params.response.y));
}

// the camera's clip where the photograph has one (`Compositor::clip`)
fn clipped(l: vec4<f32>) -> vec4<f32> {
    if params.response.w > 0.0 {
        return vec4<f32>(min(l.rgb, vec3<f32>(params.response.w)), l.a);
    }
    return l;
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
    // the object's coverage of the pixel and its mean radiance over the samples it covers
    let n_side = max(params.samples, 1u);
    var covered = 0u;
    var object = vec3<f32>(0.0);
    for (var j = 0u; j < n_side; j++) {
        for (var i = 0u; i < n_side; i++) {
            let at = vec2<i32>(id.xy * n_side + vec2<u32>(i, j));
            let g = textureLoad(g_position, at, 0);
            if g.w >= 0.0 && u32(g.w + 0.5) == params.object {
                let n = normalize(textureLoad(g_normal, at, 0).xyz);
                object += max(params.albedo.rgb * object_irradiance(n), vec3<f32>(0.0));
                covered += 1u;
            }
        }
    }
    let alpha = f32(covered) / f32(n_side * n_side);
    if covered > 0u {
        object /= f32(covered);
    }
    if alpha == 1.0 {
        out_hdr[k] = clipped(vec4<f32>(object, 1.0));
        out[k] = pack(codes(object));
        return;
    }
    let d = darkening[k].rgb * pixel_scale[k].rgb;
    if all(d == vec3<f32>(0.0)) && covered == 0u {
        out_hdr[k] = clipped(photo_hdr[k]);
        out[k] = photo_ldr[k];
        return;
    }
    if params.mode == 0u {
        let l = mix(max(photo_hdr[k].rgb - d, vec3<f32>(0.0)), object, alpha);
        out_hdr[k] = clipped(vec4<f32>(l, 1.0));
        out[k] = pack(codes(l));
    } else {
        out_hdr[k] = clipped(photo_hdr[k]);
        out[k] = pack(mix(clamp(unpack(photo_ldr[k]) - d, vec3<f32>(0.0), vec3<f32>(255.0)), codes(object), alpha));
    }
}
