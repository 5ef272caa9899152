// The viewer's display pass: the frame's HDR image tone mapped for the screen, the curve of
// `envmap_sphere::Tonemap` (ACES fitted, after an exposure), sRGB-encoded here only where the
// target does not encode it itself. The target is the frame's size (a resized window gets a
// frame of its new size). Beside the frame it shows the reference, or the two's difference.

struct Params {
    exposure: f32,
    // 1: encode sRGB here (a linear target)
    encode: u32,
    // 0: the frame; 1: the reference; 2: their difference
    mode: u32,
    // the difference's full colour, in display values (the curve's [0, 1])
    scale: f32,
}

@group(0) @binding(0) var<uniform> params: Params;
@group(0) @binding(1) var frame: texture_2d<f32>;
@group(0) @binding(2) var reference: texture_2d<f32>;

@vertex
fn vs(@builtin(vertex_index) i: u32) -> @builtin(position) vec4<f32> {
    let uv = vec2<f32>(f32((i << 1u) & 2u), f32(i & 2u));
    return vec4<f32>(uv * 2.0 - 1.0, 0.0, 1.0);
}

fn encode(c: f32) -> f32 {
    return select(1.055 * pow(c, 1.0 / 2.4) - 0.055, 12.92 * c, c <= 0.0031308);
}

fn curve(rgb: vec3<f32>) -> vec3<f32> {
    // a non-finite pixel shows black, as the CPU curve's clamp gives
    let finite = all(rgb == rgb) && all(abs(rgb) < vec3<f32>(3.0e38));
    let x = select(vec3<f32>(0.0), max(rgb * params.exposure, vec3<f32>(0.0)), finite);
    return clamp((x * (2.51 * x + 0.03)) / (x * (2.43 * x + 0.59) + 0.14), vec3<f32>(0.0), vec3<f32>(1.0));
}

fn luminance(c: vec3<f32>) -> f32 {
    return dot(c, vec3<f32>(0.2126, 0.7152, 0.0722));
}

@fragment
fn fs(@builtin(position) frag: vec4<f32>) -> @location(0) vec4<f32> {
    let p = vec2<i32>(frag.xy);
    var v = curve(textureLoad(frame, p, 0).rgb);
    if params.mode != 0u {
        let r = curve(textureLoad(reference, p, 0).rgb);
        if params.mode == 1u {
            v = r;
        } else {
            // red where the frame is brighter than the reference, blue where darker, over the
            // reference's luminance dimmed
            let d = (luminance(v) - luminance(r)) / params.scale;
            v = clamp(vec3<f32>(0.25 * luminance(r)) + vec3<f32>(max(d, 0.0), 0.0, max(-d, 0.0)), vec3<f32>(0.0), vec3<f32>(1.0));
        }
    }
    if params.encode == 1u {
        v = vec3<f32>(encode(v.x), encode(v.y), encode(v.z));
    }
    return vec4<f32>(v, 1.0);
}
