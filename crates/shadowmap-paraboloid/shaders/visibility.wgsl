// requires: shadowmap-paraboloid/paraboloid.wgsl shadowmap-paraboloid/lookup.wgsl gpu/fullscreen.wgsl
// Visibility pass: per G-buffer pixel, whether the light reaches it through a shadow map —
// a dual or single paraboloid map, a cube map (6 views) or an orthographic map — with a
// normal-offset bias of `bias` texels and optional PCF over (2r + 1)^2 texels, or PCSS.

@group(0) @binding(0) var<uniform> params: MapParams;
@group(0) @binding(1) var g_position: texture_2d<f32>;
@group(0) @binding(2) var g_geometric_normal: texture_2d<f32>;
@group(0) @binding(3) var shadow_map: texture_depth_2d_array;

// Vogel-disk sample k of n at radius 1, turned by `spin` radians.
fn vogel(k: u32, n: u32, spin: f32) -> vec2<f32> {
    let r = sqrt((f32(k) + 0.5) / f32(n));
    let a = f32(k) * 2.39996323 + spin;
    return r * vec2<f32>(cos(a), sin(a));
}

// Percentage-closer soft shadows on an orthographic map: the mean blocker depth over the region
// through which the light's cone from the receiver passes, the penumbra radius it implies
// ((receiver - blocker) tan alpha), then that much filtering. Depths are compared with a
// receiver-plane bias (`slope`: depth change per world unit across the map, over the sample's
// offset plus 1.5 texels from the texel centre) so that wide filters do not shadow the receiver
// by its own tilt.
fn pcss(uv: vec2<f32>, depth: f32, slope: f32, spin: f32) -> f32 {
    let view = params.views[0];
    let res = view.params.w;
    // world units per unit of stored depth (1 / the length of the depth row of the rotation
    // and projection), and per texel
    let depth_row = vec3<f32>(view.matrix[0][2], view.matrix[1][2], view.matrix[2][2]);
    let depth_span = 1.0 / max(length(depth_row), 1e-30);
    let texel = view.params.y / res;
    let tan_a = params.pcss.y;
    let max_r = params.pcss_limits.x;
    let centre = vec2<f32>((uv.x * 0.5 + 0.5) * res, (0.5 - uv.y * 0.5) * res);
    let ri = i32(res) - 1;
    // blockers can sit anywhere between the map's plane and the receiver
    let search = clamp(depth * depth_span * tan_a / texel, 1.0, max_r);
    let nb = u32(params.pcss.z);
    var blockers = 0.0;
    var sum = 0.0;
    for (var k = 0u; k < nb; k++) {
        let o = vogel(k, nb, spin) * search;
        let t = clamp(vec2<i32>(floor(centre + o)), vec2<i32>(0), vec2<i32>(ri));
        let stored = textureLoad(shadow_map, t, 0, 0);
        let bias = (length(o) + 1.5) * texel * slope / depth_span;
        if stored < depth - bias {
            blockers += 1.0;
            sum += stored;
        }
    }
    if blockers == 0.0 {
        return 1.0;
    }
    let blocker = sum / blockers;
    let radius = clamp((depth - blocker) * depth_span * tan_a / texel, 0.5, max_r);
    let nf = u32(params.pcss.w);
    var lit = 0.0;
    for (var k = 0u; k < nf; k++) {
        let o = vogel(k, nf, spin) * radius;
        let t = clamp(vec2<i32>(floor(centre + o)), vec2<i32>(0), vec2<i32>(ri));
        let stored = textureLoad(shadow_map, t, 0, 0);
        let bias = (length(o) + 1.5) * texel * slope / depth_span;
        lit += select(0.0, 1.0, depth - bias <= stored);
    }
    return lit / f32(nf);
}

@fragment
fn fs(@builtin(position) frag: vec4<f32>) -> @location(0) vec4<f32> {
    let pixel = vec2<i32>(frag.xy);
    let g = textureLoad(g_position, pixel, 0);
    if g.w < 0.0 {
        return vec4<f32>(1.0);
    }
    let r = map_receiver(params.light, params.config, params.views[0].params, g.xyz, textureLoad(g_geometric_normal, pixel, 0).xyz);
    let technique = u32(params.config.x);
    if technique == 2u && params.pcss.x > 0.5 {
        let clip = params.views[0].matrix * vec4<f32>(r.p, 1.0);
        let ndc = clip.xyz / clip.w;
        if any(abs(ndc.xy) > vec2<f32>(1.0)) || ndc.z < 0.0 {
            return vec4<f32>(1.0);
        }
        // tan of the receiver's tilt from the light, capped: the depth slope across the map
        let c = max(dot(r.ng, r.to_light), 0.1);
        let slope = sqrt(max(1.0 - c * c, 0.0)) / c;
        // a per-pixel turn of the sample pattern (interleaved gradient noise): noise instead
        // of banding, fixed per pixel
        let spin = 6.2831853 * fract(52.9829189 * fract(dot(frag.xy, vec2<f32>(0.06711056, 0.00583715))));
        return vec4<f32>(pcss(ndc.xy, min(ndc.z, 1.0), slope, spin));
    }
    let layer = map_layer(params.light, params.forward, params.config, r.p);
    if layer == NO_LAYER {
        return vec4<f32>(0.0);
    }
    // the bound view starts at the map's first layer
    return vec4<f32>(view_lit(params.views[layer], technique, i32(params.config.z), shadow_map, i32(layer), r.p));
}
