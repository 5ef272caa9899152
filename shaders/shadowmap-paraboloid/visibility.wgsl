// requires: shadowmap-paraboloid/paraboloid.wgsl gpu/fullscreen.wgsl
// Visibility pass: per G-buffer pixel, whether the light reaches it through a shadow map —
// a dual or single paraboloid map, a cube map (6 views) or an orthographic map — with a
// normal-offset bias of `bias` texels and optional PCF over (2r + 1)^2 texels.

struct Params {
    // xyz light position (point) or unit direction towards the light (distant); w 0 point, 1 distant
    light: vec4<f32>,
    // xyz the paraboloid frame's forward axis
    forward: vec4<f32>,
    // x technique (0 paraboloid, 1 cube, 2 orthographic), y view count, z PCF radius, w bias in texels
    config: vec4<f32>,
    // PCSS (orthographic maps of distant cone lights): x 1 = on, y tan of the light's
    // half-angle, z blocker-search samples, w filter samples
    pcss: vec4<f32>,
    // x largest search / filter radius, texels
    pcss_limits: vec4<f32>,
    views: array<ShadowView, 6>,
}

@group(0) @binding(0) var<uniform> params: Params;
@group(0) @binding(1) var g_position: texture_2d<f32>;
@group(0) @binding(2) var g_geometric_normal: texture_2d<f32>;
@group(0) @binding(3) var shadow_map: texture_depth_2d_array;

// Cube face of a direction: +X, -X, +Y, -Y, +Z, -Z.
fn cube_face(d: vec3<f32>) -> u32 {
    let a = abs(d);
    if a.x >= a.y && a.x >= a.z {
        return select(1u, 0u, d.x >= 0.0);
    }
    if a.y >= a.z {
        return select(3u, 2u, d.y >= 0.0);
    }
    return select(5u, 4u, d.z >= 0.0);
}

// Fraction of the (2r + 1)^2 texels around `uv` (in [-1, 1], +v up) of layer `layer` whose
// depth is not less than `depth`. A receiver beyond the map's far plane lies behind whatever
// the map holds there (a map of a few casters over distant receivers), so its depth is taken
// as the far plane's.
fn lit_fraction(uv: vec2<f32>, depth_in: f32, layer: u32) -> f32 {
    let depth = min(depth_in, 1.0);
    let res = i32(params.views[layer].params.w);
    let x = i32(floor((uv.x * 0.5 + 0.5) * f32(res)));
    let y = i32(floor((0.5 - uv.y * 0.5) * f32(res)));
    let r = i32(params.config.z);
    var lit = 0.0;
    for (var dy = -r; dy <= r; dy++) {
        for (var dx = -r; dx <= r; dx++) {
            let t = clamp(vec2<i32>(x + dx, y + dy), vec2<i32>(0), vec2<i32>(res - 1));
            let stored = textureLoad(shadow_map, t, i32(layer), 0);
            lit += select(0.0, 1.0, depth <= stored);
        }
    }
    return lit / f32((2 * r + 1) * (2 * r + 1));
}

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
    let is_distant = params.light.w > 0.5;
    var to_light = params.light.xyz;
    var dist = 1.0;
    if !is_distant {
        to_light = params.light.xyz - g.xyz;
        dist = length(to_light);
        to_light = to_light / max(dist, 1e-30);
    }
    var ng = textureLoad(g_geometric_normal, pixel, 0).xyz;
    if dot(ng, to_light) < 0.0 {
        ng = -ng;
    }
    let technique = u32(params.config.x);
    let res = params.views[0].params.w;
    // world size of one texel at the receiver: paraboloid 4/res rad at the centre, cube 2/res
    // rad at a face centre, orthographic extent / res
    var texel = dist * 4.0 / res;
    if technique == 1u {
        texel = dist * 2.0 / res;
    } else if technique == 2u {
        texel = params.views[0].params.y / res;
    }
    let offset = params.config.w * texel;
    let p = g.xyz + ng * offset + to_light * offset;
    var lit = 1.0;
    if technique == 0u {
        var layer = 0u;
        if dot(p - params.light.xyz, params.forward.xyz) < 0.0 {
            if params.config.y < 1.5 {
                // a hemispherical light does not emit there: the shading pass sees no light
                return vec4<f32>(0.0);
            }
            layer = 1u;
        }
        let c = paraboloid_project(params.views[layer], p);
        lit = lit_fraction(c.xy, c.z, layer);
    } else {
        var layer = 0u;
        if technique == 1u {
            layer = cube_face(p - params.light.xyz);
        }
        let clip = params.views[layer].matrix * vec4<f32>(p, 1.0);
        let ndc = clip.xyz / clip.w;
        // outside the footprint, or between the light and the map's near plane: nothing can
        // shadow it; beyond the far plane it is compared at the far plane (`lit_fraction`)
        if technique == 2u && (any(abs(ndc.xy) > vec2<f32>(1.0)) || ndc.z < 0.0) {
            return vec4<f32>(1.0);
        }
        if technique == 2u && params.pcss.x > 0.5 {
            // tan of the receiver's tilt from the light, capped: the depth slope across the map
            let c = max(dot(ng, to_light), 0.1);
            let slope = sqrt(max(1.0 - c * c, 0.0)) / c;
            // a per-pixel turn of the sample pattern (interleaved gradient noise): noise instead
            // of banding, fixed per pixel
            let spin = 6.2831853 * fract(52.9829189 * fract(dot(frag.xy, vec2<f32>(0.06711056, 0.00583715))));
            return vec4<f32>(pcss(ndc.xy, min(ndc.z, 1.0), slope, spin));
        }
        lit = lit_fraction(ndc.xy, ndc.z, layer);
    }
    return vec4<f32>(lit);
}
