// requires: gpu/brdf.wgsl gpu/fullscreen.wgsl
// Joint bilateral upsampling (Kopf et al. 2007) of an image shaded at 1/factor resolution, added
// to a full-resolution base image: per full-resolution pixel, a window of low-resolution
// samples weighted by a spatial Gaussian (in low-resolution pixels) times Gaussians of the
// differences of shading normal, depth (relative to the pixel's own) and albedo, read from the
// two G-buffers (paper 001, section 3.4). Weights are taken relative to the best sample of the
// window, so a pixel that matches no sample takes the closest one instead of dividing 0 by 0.

struct Params {
    eye: vec4<f32>,
    // 1 / (2 sigma^2) of: normal, depth, albedo, spatial (0: that term off)
    inv_two_sigma2: vec4<f32>,
    // x factor, y window radius, z low width, w low height
    info: vec4<u32>,
}

@group(0) @binding(0) var<uniform> params: Params;
@group(0) @binding(1) var<storage, read> materials: array<Material>;
@group(0) @binding(2) var low_position: texture_2d<f32>;
@group(0) @binding(3) var low_normal: texture_2d<f32>;
@group(0) @binding(4) var low_image: texture_2d<f32>;
@group(0) @binding(5) var high_position: texture_2d<f32>;
@group(0) @binding(6) var high_normal: texture_2d<f32>;
@group(0) @binding(7) var base: texture_2d<f32>;

// The exponent of a sample's weight, or -1 for a sample that is no surface.
fn exponent(q: vec2<i32>, c: vec2<f32>, p: vec3<f32>, n: vec3<f32>, a: vec3<f32>, d: f32) -> f32 {
    let lp = textureLoad(low_position, q, 0);
    if lp.w < 0.0 {
        return -1.0;
    }
    let ln = textureLoad(low_normal, q, 0).xyz;
    let la = materials[u32(lp.w)].albedo.rgb;
    let ld = length(lp.xyz - params.eye.xyz);
    let s = vec2<f32>(q) - c;
    let dd = (ld - d) / max(d, 1e-30);
    let dn = ln - n;
    let da = la - a;
    let k = params.inv_two_sigma2;
    return k.x * dot(dn, dn) + k.y * dd * dd + k.z * dot(da, da) + k.w * dot(s, s);
}

@fragment
fn fs(@builtin(position) frag: vec4<f32>) -> @location(0) vec4<f32> {
    let pixel = vec2<i32>(frag.xy);
    let b = textureLoad(base, pixel, 0);
    let hp = textureLoad(high_position, pixel, 0);
    if hp.w < 0.0 {
        return b;
    }
    let n = textureLoad(high_normal, pixel, 0).xyz;
    let a = materials[u32(hp.w)].albedo.rgb;
    let d = length(hp.xyz - params.eye.xyz);
    let f = f32(params.info.x);
    // the pixel's centre in low-resolution pixel coordinates (sample q sits at q)
    let c = (frag.xy) / f - vec2<f32>(0.5);
    let centre = vec2<i32>(round(c));
    let r = i32(params.info.y);
    let size = vec2<i32>(i32(params.info.z), i32(params.info.w));
    // weights relative to the best sample so far (an online maximum, as in a streaming
    // softmax): the sums are rescaled when a better one comes
    var best = 3.4e38;
    var sum = vec3<f32>(0.0);
    var weight = 0.0;
    for (var y = -r; y <= r; y++) {
        for (var x = -r; x <= r; x++) {
            let q = centre + vec2<i32>(x, y);
            if any(q < vec2<i32>(0)) || any(q >= size) {
                continue;
            }
            let e = exponent(q, c, hp.xyz, n, a, d);
            if e < 0.0 {
                continue;
            }
            var w = 1.0;
            if e < best {
                let rescale = select(exp(e - best), 0.0, best > 3.0e38);
                sum *= rescale;
                weight *= rescale;
                best = e;
            } else {
                w = exp(best - e);
            }
            sum += w * textureLoad(low_image, q, 0).rgb;
            weight += w;
        }
    }
    if weight <= 0.0 {
        // no surface in the window: nothing to add
        return b;
    }
    return vec4<f32>(b.rgb + sum / weight, b.a);
}
