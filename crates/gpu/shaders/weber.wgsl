// requires: gpu/sh9.wgsl
// Weber's 2 % test of `gpu::weber_negligible` on the GPU, over the same regular subset of the
// G-buffer (every `stride`-th pixel in x and y): per receiver its whole unshadowed luminance
// irradiance (the ambient's SH9, clamped at 0, plus every light's), per light its largest share
// anywhere (an atomic max of order-preserving keys: exact), then in one workgroup the greedy
// pass: lights under the fraction everywhere, faintest first (ties in index order, as the CPU's
// stable sort), taken while the skipped lights' summed share stays under the fraction at every
// receiver. The same arithmetic as the CPU's, in its order; `sin`, `acos` and `normalize` may
// differ from the CPU's in the last bit.

struct Params {
    // width, height, stride, light count
    size: vec4<u32>,
    // x: fraction, y: 1 with an ambient, z: subset columns
    info: vec4<f32>,
    sh: array<vec4<f32>, 9>,
}

struct Light {
    // xyz: direction towards a distant light (w 0) or a point light's position (w 1)
    place: vec4<f32>,
    // x: luminance of its irradiance (distant) or intensity (point), y: half-angle
    value: vec4<f32>,
}

struct State {
    nonfinite: atomic<u32>,
    order_len: u32,
    pad: vec2<u32>,
    // bit k % 32 of word k / 32: light k is negligible
    negligible: array<u32, 32>,
    max_share: array<atomic<u32>, 1024>,
    order: array<u32, 1024>,
}

@group(0) @binding(0) var g_position: texture_2d<f32>;
@group(0) @binding(1) var g_geometric_normal: texture_2d<f32>;
@group(0) @binding(2) var<uniform> params: Params;
@group(0) @binding(3) var<storage, read> lights: array<Light>;
@group(0) @binding(4) var<storage, read_write> state: State;
// per subset receiver: its total (negative: background), and the skipped lights' summed share
@group(0) @binding(5) var<storage, read_write> totals: array<f32>;
@group(0) @binding(6) var<storage, read_write> skipped: array<f32>;

const PI: f32 = 3.14159265358979;
const TAU: f32 = 6.28318530717959;
const HALF_PI: f32 = 1.5707963267948966;

fn key(x: f32) -> u32 {
    let b = bitcast<u32>(x);
    return select(b ^ 0x80000000u, ~b, (b >> 31u) == 1u);
}

// The largest share as the CPU folds it, from 0: keys at or below 0's (0x80000000, and the
// cleared buffer's 0 when no receiver is seen) give 0.
fn largest_share(k: u32) -> f32 {
    return select(0.0, bitcast<f32>(k ^ 0x80000000u), k > 0x80000000u);
}

// `scene::cone_cosine_integral`, its guards included.
fn cone_integral(cos_theta: f32, half_angle: f32) -> f32 {
    let s = sin(clamp(half_angle, 0.0, HALF_PI));
    let sin2 = s * s;
    let c = clamp(cos_theta, -1.0, 1.0);
    if c * c > sin2 {
        return PI * sin2 * max(c, 0.0);
    }
    if sin2 <= 0.0 {
        return 0.0;
    }
    let sin_t = sqrt(max(1.0 - c * c, 1e-12));
    let x = sqrt(max(1.0 / sin2 - 1.0, 0.0));
    let y = clamp(-x * c / sin_t, -1.0, 1.0);
    let sin_t_sqrt_y = sin_t * sqrt(max(1.0 - y * y, 0.0));
    return max((c * acos(y) - x * sin_t_sqrt_y) * sin2 + atan2(sin_t_sqrt_y, x), 0.0);
}

fn unit_or_zero(v: vec3<f32>) -> vec3<f32> {
    let l = length(v);
    return select(vec3<f32>(0.0), v * (1.0 / l), l > 0.0 && l < 3.4e38);
}

fn irradiance(l: Light, p: vec3<f32>, n: vec3<f32>) -> f32 {
    if l.place.w == 0.0 {
        let half = l.value.y;
        let solid_angle = TAU * (1.0 - cos(half));
        let c = dot(n, unit_or_zero(l.place.xyz));
        let mean_cos = select(max(c, 0.0), cone_integral(c, half) / solid_angle, sin(half) > 1e-3);
        return l.value.x * mean_cos;
    }
    let d = l.place.xyz - p;
    let d2 = max(dot(d, d), 1.17549435e-38);
    return l.value.x * max(dot(n, d) / sqrt(d2), 0.0) / d2;
}

fn luminance(c: vec3<f32>) -> f32 {
    return dot(c, vec3<f32>(0.2126, 0.7152, 0.0722));
}

fn subset_pixel(index: u32) -> vec2<i32> {
    let columns = u32(params.info.z);
    return vec2<i32>(vec2<u32>(index % columns, index / columns) * params.size.z);
}

@compute @workgroup_size(64)
fn totals_pass(@builtin(global_invocation_id) id: vec3<u32>) {
    let index = id.x;
    if index >= arrayLength(&totals) {
        return;
    }
    skipped[index] = 0.0;
    let pixel = subset_pixel(index);
    let g = textureLoad(g_position, pixel, 0);
    if g.w < 0.0 {
        totals[index] = -1.0;
        return;
    }
    let n = textureLoad(g_geometric_normal, pixel, 0).xyz;
    var sum = 0.0;
    for (var k = 0u; k < params.size.w; k++) {
        sum += irradiance(lights[k], g.xyz, n);
    }
    var ambient = 0.0;
    if params.info.y > 0.5 {
        var c: array<vec4<f32>, 9>;
        for (var k = 0u; k < 9u; k++) {
            c[k] = params.sh[k];
        }
        ambient = max(luminance(sh9_irradiance(c, n)), 0.0);
    }
    let total = ambient + sum;
    // a NaN fails both tests
    if !(abs(total) <= 3.4028235e38) {
        atomicOr(&state.nonfinite, 1u);
        totals[index] = 0.0;
        return;
    }
    totals[index] = total;
    for (var k = 0u; k < params.size.w; k++) {
        let share = irradiance(lights[k], g.xyz, n) / max(total, 1e-30);
        atomicMax(&state.max_share[k], key(share));
    }
}

var<workgroup> count: u32;
var<workgroup> bad: atomic<u32>;
var<workgroup> rejected_shared: u32;
var<workgroup> current: u32;

@compute @workgroup_size(256)
fn greedy(@builtin(local_invocation_index) t: u32) {
    let fraction = params.info.x;
    if t == 0u {
        for (var w = 0u; w < 32u; w++) {
            state.negligible[w] = 0u;
        }
        var len = 0u;
        if atomicLoad(&state.nonfinite) == 0u {
            // insertion by share, after equal shares: the order of a stable sort
            for (var k = 0u; k < params.size.w; k++) {
                let s = largest_share(atomicLoad(&state.max_share[k]));
                if !(s < fraction) {
                    continue;
                }
                var at = len;
                while at > 0u && largest_share(atomicLoad(&state.max_share[state.order[at - 1u]])) > s {
                    state.order[at] = state.order[at - 1u];
                    at -= 1u;
                }
                state.order[at] = k;
                len += 1u;
            }
        }
        state.order_len = len;
        count = len;
    }
    let len = workgroupUniformLoad(&count);
    let points = arrayLength(&totals);
    for (var o = 0u; o < len; o++) {
        if t == 0u {
            current = state.order[o];
            atomicStore(&bad, 0u);
        }
        let i = workgroupUniformLoad(&current);
        for (var index = t; index < points; index += 256u) {
            let total = totals[index];
            if total < 0.0 {
                continue;
            }
            let pixel = subset_pixel(index);
            let add = irradiance(lights[i], textureLoad(g_position, pixel, 0).xyz, textureLoad(g_geometric_normal, pixel, 0).xyz) / max(total, 1e-30);
            if !(add + skipped[index] < fraction) {
                atomicStore(&bad, 1u);
            }
        }
        workgroupBarrier();
        if t == 0u {
            rejected_shared = atomicLoad(&bad);
        }
        let rejected = workgroupUniformLoad(&rejected_shared);
        if rejected == 0u {
            for (var index = t; index < points; index += 256u) {
                let total = totals[index];
                if total < 0.0 {
                    continue;
                }
                let pixel = subset_pixel(index);
                skipped[index] += irradiance(lights[i], textureLoad(g_position, pixel, 0).xyz, textureLoad(g_geometric_normal, pixel, 0).xyz) / max(total, 1e-30);
            }
            if t == 0u {
                state.negligible[i / 32u] |= 1u << (i % 32u);
            }
        }
        workgroupBarrier();
    }
}
