// requires: gpu/fullscreen.wgsl
// Resolve of an accumulated visibility (`gpu::accumulate`) into a visibility layer.
// mode 0 (an average): V = clamp(r * scale, 0, 1);
// mode 1 (penumbra wedges): V = clamp(1 - w + g, 0, 1), w = 1 where the hard count r is not 0,
// divided by the fraction of the light's disk above the surface's own plane: casters that the
// point lies on hide the part below it, which the shading's cone integral already leaves out.
// Background pixels (G-buffer w < 0) stay lit.

struct Params {
    // x mode, y scale
    config: vec4<f32>,
    // xyz unit direction towards a distant light, or a sphere light's centre
    light: vec4<f32>,
    // x 0 distant, 1 sphere; y half-angle (distant) or radius (sphere)
    light_config: vec4<f32>,
}

const PI: f32 = 3.14159265358979;

@group(0) @binding(0) var<uniform> params: Params;
@group(0) @binding(1) var g_position: texture_2d<f32>;
@group(0) @binding(2) var g_geometric_normal: texture_2d<f32>;
@group(0) @binding(3) var accumulated: texture_2d<f32>;

// Fraction of the light's disk (in the plane the wedges project onto) above the plane through
// p with normal n.
fn disk_above(p: vec3<f32>, n: vec3<f32>) -> f32 {
    var z = params.light.xyz;
    var alpha = params.light_config.y;
    if params.light_config.x > 0.5 {
        let to_c = params.light.xyz - p;
        let dist = length(to_c);
        z = to_c / max(dist, 1e-30);
        alpha = select(asin(min(params.light_config.y / dist, 1.0)), 0.5 * PI, dist <= params.light_config.y);
    }
    let tan_a = tan(clamp(alpha, 1e-7, 1.5));
    let nz = dot(n, z);
    let nxy = sqrt(max(1.0 - nz * nz, 0.0));
    if nxy < 1e-7 {
        return select(0.0, 1.0, nz > 0.0);
    }
    // above: tan_a (n_xy . q) + n_z > 0, a half-plane at signed distance t from the centre
    let t = clamp(-nz / (tan_a * nxy), -1.0, 1.0);
    return (acos(t) - t * sqrt(1.0 - t * t)) / PI;
}

@fragment
fn fs(@builtin(position) frag: vec4<f32>) -> @location(0) vec4<f32> {
    let pixel = vec2<i32>(frag.xy);
    let g = textureLoad(g_position, pixel, 0);
    if g.w < 0.0 {
        return vec4<f32>(1.0);
    }
    let a = textureLoad(accumulated, pixel, 0);
    if params.config.x < 0.5 {
        return vec4<f32>(clamp(a.r * params.config.y, 0.0, 1.0));
    }
    // counts are whole numbers: exact in f32 and f16
    let w = select(0.0, 1.0, abs(a.r) > 0.5);
    let v = clamp(1.0 - w + a.g, 0.0, 1.0);
    let n = textureLoad(g_geometric_normal, pixel, 0).xyz;
    return vec4<f32>(clamp(v / max(disk_above(g.xyz, n), 1e-4), 0.0, 1.0));
}
