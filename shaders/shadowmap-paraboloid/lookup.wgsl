// requires: shadowmap-paraboloid/paraboloid.wgsl
// A receiver looked up in a shadow map: the map as its readers see it, the receiver offset by
// the bias, and its hard or PCF visibility (a file that requires this one lists
// paraboloid.wgsl before it: library files' own requirements are not followed).
// Used by the visibility pass (one map) and by passes that read many maps of one texture
// array (each map's layers start at `forward.w`).

struct MapParams {
    // xyz light position (point) or unit direction towards the light (distant); w 0 point, 1 distant
    light: vec4<f32>,
    // xyz the paraboloid frame's forward axis; w the map's first layer in the texture array
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

// Fraction of the (2r + 1)^2 texels around `uv` (in [-1, 1], +v up) of the map's layer `layer`
// whose depth is not less than `depth`. A receiver beyond the map's far plane lies behind
// whatever the map holds there (a map of a few casters over distant receivers), so its depth is
// taken as the far plane's.
fn lit_fraction(m: MapParams, maps: texture_depth_2d_array, uv: vec2<f32>, depth_in: f32, layer: u32) -> f32 {
    let depth = min(depth_in, 1.0);
    let res = i32(m.views[layer].params.w);
    let x = i32(floor((uv.x * 0.5 + 0.5) * f32(res)));
    let y = i32(floor((0.5 - uv.y * 0.5) * f32(res)));
    let r = i32(m.config.z);
    let base = layer + u32(m.forward.w);
    var lit = 0.0;
    for (var dy = -r; dy <= r; dy++) {
        for (var dx = -r; dx <= r; dx++) {
            let t = clamp(vec2<i32>(x + dx, y + dy), vec2<i32>(0), vec2<i32>(res - 1));
            let stored = textureLoad(maps, t, i32(base), 0);
            lit += select(0.0, 1.0, depth <= stored);
        }
    }
    return lit / f32((2 * r + 1) * (2 * r + 1));
}

// A receiver as the map compares it: the point moved `bias` texels (of the map, at the
// receiver) along its geometric normal (turned towards the light) and towards the light.
struct MapReceiver {
    p: vec3<f32>,
    ng: vec3<f32>,
    to_light: vec3<f32>,
}

fn map_receiver(m: MapParams, g: vec3<f32>, ng_in: vec3<f32>) -> MapReceiver {
    let is_distant = m.light.w > 0.5;
    var to_light = m.light.xyz;
    var dist = 1.0;
    if !is_distant {
        to_light = m.light.xyz - g;
        dist = length(to_light);
        to_light = to_light / max(dist, 1e-30);
    }
    var ng = ng_in;
    if dot(ng, to_light) < 0.0 {
        ng = -ng;
    }
    let technique = u32(m.config.x);
    let res = m.views[0].params.w;
    // world size of one texel at the receiver: paraboloid 4/res rad at the centre, cube 2/res
    // rad at a face centre, orthographic extent / res
    var texel = dist * 4.0 / res;
    if technique == 1u {
        texel = dist * 2.0 / res;
    } else if technique == 2u {
        texel = m.views[0].params.y / res;
    }
    let offset = m.config.w * texel;
    return MapReceiver(g + ng * offset + to_light * offset, ng, to_light);
}

// The receiver's visibility through the map: 1 lit, 0 shadowed, fractions with PCF; 0 behind a
// hemispherical light (it does not emit there); 1 outside an orthographic map's footprint or
// between the light and its near plane (nothing there can shadow it).
fn map_lit(m: MapParams, maps: texture_depth_2d_array, r: MapReceiver) -> f32 {
    let technique = u32(m.config.x);
    if technique == 0u {
        var layer = 0u;
        if dot(r.p - m.light.xyz, m.forward.xyz) < 0.0 {
            if m.config.y < 1.5 {
                return 0.0;
            }
            layer = 1u;
        }
        let c = paraboloid_project(m.views[layer], r.p);
        return lit_fraction(m, maps, c.xy, c.z, layer);
    }
    var layer = 0u;
    if technique == 1u {
        layer = cube_face(r.p - m.light.xyz);
    }
    let clip = m.views[layer].matrix * vec4<f32>(r.p, 1.0);
    let ndc = clip.xyz / clip.w;
    if technique == 2u && (any(abs(ndc.xy) > vec2<f32>(1.0)) || ndc.z < 0.0) {
        return 1.0;
    }
    return lit_fraction(m, maps, ndc.xy, ndc.z, layer);
}
