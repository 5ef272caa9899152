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
// depth is not less than `depth`.
fn lit_fraction(uv: vec2<f32>, depth: f32, layer: u32) -> f32 {
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
        if technique == 2u && (any(abs(ndc.xy) > vec2<f32>(1.0)) || ndc.z < 0.0 || ndc.z > 1.0) {
            return vec4<f32>(1.0);
        }
        lit = lit_fraction(ndc.xy, ndc.z, layer);
    }
    return vec4<f32>(lit);
}
