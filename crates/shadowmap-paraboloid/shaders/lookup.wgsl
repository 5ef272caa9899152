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

// Fraction of the (2r + 1)^2 texels around `uv` (in [-1, 1], +v up) of the texture's layer
// `layer` (a view of `view`'s resolution) whose depth is not less than `depth`. A receiver
// beyond the map's far plane lies behind whatever the map holds there (a map of a few casters
// over distant receivers), so its depth is taken as the far plane's.
fn lit_fraction(view: ShadowView, maps: texture_depth_2d_array, layer: i32, r: i32, uv: vec2<f32>, depth_in: f32) -> f32 {
    let depth = min(depth_in, 1.0);
    let res = i32(view.params.w);
    let x = i32(floor((uv.x * 0.5 + 0.5) * f32(res)));
    let y = i32(floor((0.5 - uv.y * 0.5) * f32(res)));
    var lit = 0.0;
    for (var dy = -r; dy <= r; dy++) {
        for (var dx = -r; dx <= r; dx++) {
            let t = clamp(vec2<i32>(x + dx, y + dy), vec2<i32>(0), vec2<i32>(res - 1));
            let stored = textureLoad(maps, t, layer, 0);
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

// The functions below take a map's fields rather than a whole `MapParams`: a pass that loops
// over many maps in a storage buffer then loads only the fields and the one view it needs.

// `light`, `config`: the map's; `view0`: its first view's `params` (resolution, extent).
fn map_receiver(light: vec4<f32>, config: vec4<f32>, view0: vec4<f32>, g: vec3<f32>, ng_in: vec3<f32>) -> MapReceiver {
    let is_distant = light.w > 0.5;
    var to_light = light.xyz;
    var dist = 1.0;
    if !is_distant {
        to_light = light.xyz - g;
        dist = length(to_light);
        to_light = to_light / max(dist, 1e-30);
    }
    var ng = ng_in;
    if dot(ng, to_light) < 0.0 {
        ng = -ng;
    }
    let technique = u32(config.x);
    let res = view0.w;
    // world size of one texel at the receiver: paraboloid 4/res rad at the centre, cube 2/res
    // rad at a face centre, orthographic extent / res
    var texel = dist * 4.0 / res;
    if technique == 1u {
        texel = dist * 2.0 / res;
    } else if technique == 2u {
        texel = view0.y / res;
    }
    let offset = config.w * texel;
    return MapReceiver(g + ng * offset + to_light * offset, ng, to_light);
}

// No layer: the receiver lies behind a hemispherical light, which does not emit there.
const NO_LAYER: u32 = 0xffffffffu;

// The map's layer that sees `p`: the paraboloid hemisphere, the cube face, the one
// orthographic view; `NO_LAYER` behind a hemispherical light.
fn map_layer(light: vec4<f32>, forward: vec4<f32>, config: vec4<f32>, p: vec3<f32>) -> u32 {
    let technique = u32(config.x);
    if technique == 0u {
        if dot(p - light.xyz, forward.xyz) < 0.0 {
            return select(1u, NO_LAYER, config.y < 1.5);
        }
        return 0u;
    }
    if technique == 1u {
        return cube_face(p - light.xyz);
    }
    return 0u;
}

// `p`'s visibility through `view` (texture layer `layer`): 1 lit, 0 shadowed, fractions with
// a PCF radius `pcf`; 1 outside an orthographic view's footprint or between the light and its
// near plane (nothing there can shadow it).
fn view_lit(view: ShadowView, technique: u32, pcf: i32, maps: texture_depth_2d_array, layer: i32, p: vec3<f32>) -> f32 {
    if technique == 0u {
        let c = paraboloid_project(view, p);
        return lit_fraction(view, maps, layer, pcf, c.xy, c.z);
    }
    let clip = view.matrix * vec4<f32>(p, 1.0);
    let ndc = clip.xyz / clip.w;
    if technique == 2u && (any(abs(ndc.xy) > vec2<f32>(1.0)) || ndc.z < 0.0) {
        return 1.0;
    }
    return lit_fraction(view, maps, layer, pcf, ndc.xy, ndc.z);
}
