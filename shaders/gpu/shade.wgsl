// requires: gpu/brdf.wgsl gpu/sh9.wgsl gpu/fullscreen.wgsl
// Shading pass: per pixel, the G-buffer surface lit by distant cone lights (as directional
// lights carrying the cone's irradiance) and point lights, each times its visibility layer, plus
// SH9 ambient on the diffuse lobe, as `ref-tracer`'s `lights` integrator; misses see the map.

struct Light {
    // xyz: unit direction towards a distant light, or a point light's position; w: 0 distant, 1 point
    position_or_direction: vec4<f32>,
    // rgb: a distant light's irradiance at normal incidence (radiance x solid angle), or a point
    // light's intensity (W/sr)
    value: vec4<f32>,
}

struct Params {
    eye: vec4<f32>,
    // camera ray generation as `scene::CameraRays`: dir = corner + right x + down y
    right: vec4<f32>,
    down: vec4<f32>,
    corner: vec4<f32>,
    // x light count, y 1 = ambient on, z background width, w background height (0: black)
    counts: vec4<u32>,
    // SH9 irradiance coefficients premultiplied by A_l
    sh: array<vec4<f32>, 9>,
}

@group(0) @binding(0) var<uniform> params: Params;
@group(0) @binding(1) var<storage, read> lights: array<Light>;
@group(0) @binding(2) var<storage, read> materials: array<Material>;
@group(0) @binding(3) var g_position: texture_2d<f32>;
@group(0) @binding(4) var g_normal: texture_2d<f32>;
@group(0) @binding(5) var g_geometric_normal: texture_2d<f32>;
@group(0) @binding(6) var visibility: texture_2d_array<f32>;
@group(0) @binding(7) var background: texture_2d<f32>;

// Bilinear lat-long lookup, wrapping in u and clamping in v (`EnvMap::lookup`).
fn background_radiance(dir: vec3<f32>) -> vec3<f32> {
    let w = params.counts.z;
    let h = params.counts.w;
    if w == 0u || h == 0u {
        return vec3<f32>(0.0);
    }
    var u = atan2(dir.x, -dir.z) / (2.0 * PI);
    if u < 0.0 {
        u += 1.0;
    }
    if u >= 1.0 {
        u = 0.0;
    }
    let v = clamp(atan2(length(dir.xz), dir.y) / PI, 0.0, 1.0);
    let x = u * f32(w) - 0.5;
    let y = clamp(v * f32(h) - 0.5, 0.0, f32(h - 1u));
    let x0 = floor(x);
    let y0 = floor(y);
    let fx = x - x0;
    let fy = y - y0;
    let wi = i32(w);
    let xi0 = ((i32(x0) % wi) + wi) % wi;
    let xi1 = (xi0 + 1) % wi;
    let yi0 = i32(y0);
    let yi1 = min(yi0 + 1, i32(h) - 1);
    let top = mix(textureLoad(background, vec2<i32>(xi0, yi0), 0).rgb, textureLoad(background, vec2<i32>(xi1, yi0), 0).rgb, fx);
    let bottom = mix(textureLoad(background, vec2<i32>(xi0, yi1), 0).rgb, textureLoad(background, vec2<i32>(xi1, yi1), 0).rgb, fx);
    return mix(top, bottom, fy);
}

@fragment
fn fs(@builtin(position) frag: vec4<f32>) -> @location(0) vec4<f32> {
    let pixel = vec2<i32>(frag.xy);
    let p = textureLoad(g_position, pixel, 0);
    if p.w < 0.0 {
        let dir = normalize(params.corner.xyz + params.right.xyz * frag.x + params.down.xyz * frag.y);
        return vec4<f32>(background_radiance(dir), 1.0);
    }
    let m = materials[u32(p.w)];
    let n = textureLoad(g_normal, pixel, 0).xyz;
    let ng = textureLoad(g_geometric_normal, pixel, 0).xyz;
    let wo = normalize(params.eye.xyz - p.xyz);
    var l = vec3<f32>(0.0);
    for (var k = 0u; k < params.counts.x; k++) {
        let light = lights[k];
        var wi = light.position_or_direction.xyz;
        var e = light.value.rgb;
        if light.position_or_direction.w > 0.5 {
            let d = wi - p.xyz;
            let d2 = max(dot(d, d), 1e-12);
            wi = d * inverseSqrt(d2);
            e = e / d2;
        }
        if dot(wi, ng) <= 0.0 {
            continue;
        }
        let v = textureLoad(visibility, pixel, k, 0).r;
        l += eval_brdf(m, n, wo, wi) * max(dot(n, wi), 0.0) * e * v;
    }
    if params.counts.y == 1u {
        l += m.albedo.rgb * diffuse_weight(m) * max(sh9_irradiance(params.sh, n), vec3<f32>(0.0)) / PI;
    }
    return vec4<f32>(l, 1.0);
}
