// requires: shadowmap-paraboloid/paraboloid.wgsl shadowmap-paraboloid/lookup.wgsl
// Every representative's share of the frame's darkening in one pass: per pixel, for each
// representative whose shadow map (all of a batch's maps are layers of one texture array)
// says the object blocks its origin (1 - visibility: hard, or PCSS over a distant
// representative's cone), its transfer at the pixel, the bilinear blend of its receiver's
// four vertex transfers (radiance for HDR, codes for LDR), added up. The receiver point is
// the reconstruction's (static, from the pixel table), not the G-buffer's.

struct Params {
    width: u32,
    height: u32,
    // transfer columns (receiver vertices) per representative
    slots: u32,
    // representatives in this batch, and the first one's index in the frame
    reps: u32,
    first_rep: u32,
    // the pixel the dispatch starts at: the corner of the batch's rectangles' union
    origin_x: u32,
    origin_y: u32,
    // the object's bounding radius: within it of the object, a receiver is at its contact
    object_radius: f32,
}

struct PixelRef {
    weights: vec4<f32>,
    // the reconstruction's surface point the pixel's centre ray meets (w unused)
    position: vec4<f32>,
    // its unit normal, facing the camera (w unused)
    normal: vec4<f32>,
    // first column of the pixel's receiver, 0xffffffff for none
    slot: u32,
    pad0: u32,
    pad1: u32,
    pad2: u32,
}

@group(0) @binding(0) var<uniform> params: Params;
@group(0) @binding(1) var<storage, read> pixels: array<PixelRef>;
@group(0) @binding(2) var<storage, read> transfers: array<vec4<f32>>;
@group(0) @binding(3) var<storage, read> maps: array<MapParams>;
@group(0) @binding(4) var shadow_maps: texture_depth_2d_array;
@group(0) @binding(5) var<storage, read_write> darkening: array<vec4<f32>>;
// per representative of the batch, the pixels (x0, y0, x1, y1; ends excluded) its shadow can
// reach (`gpu::shadow_rect`; the whole image where not culled)
@group(0) @binding(6) var<storage, read> rects: array<vec4<u32>>;
// per representative of the frame, what a blocked receiver keeps of its transfer
// (`RepTransfer::keep`: the object's own radiance in its sources' place)
@group(0) @binding(7) var<storage, read> keeps: array<vec4<f32>>;

// Vogel-disk sample k of n at radius 1, turned by `spin` radians.
fn vogel(k: u32, n: u32, spin: f32) -> vec2<f32> {
    let radius = sqrt((f32(k) + 0.5) / f32(n));
    let a = f32(k) * 2.39996323 + spin;
    return radius * vec2<f32>(cos(a), sin(a));
}

// Whether texel `t` of representative `r`'s orthographic map holds a blocker nearer than
// `depth` (texels off the map hold none: its footprint is the object's, a penumbra reaches
// past it).
fn blocked(r: u32, t: vec2<f32>, depth: f32) -> vec2<f32> {
    let res = maps[r].views[0].params.w;
    if any(t < vec2<f32>(0.0)) || any(t >= vec2<f32>(res)) {
        return vec2<f32>(0.0, 1.0);
    }
    let stored = textureLoad(shadow_maps, vec2<i32>(t), i32(maps[r].forward.w), 0);
    return vec2<f32>(select(0.0, 1.0, stored < depth), stored);
}

// Percentage-closer soft shadows of a distant representative (its map orthographic, `pcss.y`
// the tangent of the cone holding its sources): the mean blocker depth over the cone's
// footprint, the penumbra it implies, that much filtering; depths compared with a
// receiver-plane bias, as `shadowmap-paraboloid`'s visibility pass does (a constant bias gave
// darker contact shadows than the truth's, which the object's light reflected onto the ground
// brightens: the zenith-sun test 1.7x its darkening). Returns the lit fraction and how far the
// blockers are (world units along the light; 1e30 for none).
fn soft_lit(r: u32, rec: MapReceiver, pixel: vec2<u32>) -> vec2<f32> {
    let view = maps[r].views[0];
    let clip = view.matrix * vec4<f32>(rec.p, 1.0);
    let ndc = clip.xyz / clip.w;
    // between the light and the map's near plane nothing can shadow it
    if ndc.z < 0.0 {
        return vec2<f32>(1.0, 1e30);
    }
    let depth = min(ndc.z, 1.0);
    let res = view.params.w;
    let depth_row = vec3<f32>(view.matrix[0][2], view.matrix[1][2], view.matrix[2][2]);
    let depth_span = 1.0 / max(length(depth_row), 1e-30);
    let texel = view.params.y / res;
    let tan_a = maps[r].pcss.y;
    let max_r = maps[r].pcss_limits.x;
    let centre = vec2<f32>((ndc.x * 0.5 + 0.5) * res, (0.5 - ndc.y * 0.5) * res);
    let c = max(dot(rec.ng, rec.to_light), 0.1);
    let slope = sqrt(max(1.0 - c * c, 0.0)) / c;
    // a per-pixel turn of the pattern (interleaved gradient noise): noise, not banding
    let spin = 6.2831853 * fract(52.9829189 * fract(dot(vec2<f32>(pixel), vec2<f32>(0.06711056, 0.00583715))));
    let search = clamp(depth * depth_span * tan_a / texel, 1.0, max_r);
    let nb = u32(maps[r].pcss.z);
    var blockers = 0.0;
    var sum = 0.0;
    for (var k = 0u; k < nb; k++) {
        let o = vogel(k, nb, spin) * search;
        let bias = (length(o) + 1.5) * texel * slope / depth_span;
        let b = blocked(r, floor(centre + o), depth - bias);
        blockers += b.x;
        sum += b.x * b.y;
    }
    if blockers == 0.0 {
        return vec2<f32>(1.0, 1e30);
    }
    let blocker = sum / blockers;
    let radius = clamp((depth - blocker) * depth_span * tan_a / texel, 0.5, max_r);
    let nf = u32(maps[r].pcss.w);
    var shadowed = 0.0;
    for (var k = 0u; k < nf; k++) {
        let o = vogel(k, nf, spin) * radius;
        let bias = (length(o) + 1.5) * texel * slope / depth_span;
        shadowed += blocked(r, floor(centre + o), depth - bias).x;
    }
    return vec2<f32>(1.0 - shadowed / f32(nf), max(depth - blocker, 0.0) * depth_span);
}

@compute @workgroup_size(8, 8)
fn main(@builtin(global_invocation_id) id: vec3<u32>) {
    let xy = id.xy + vec2<u32>(params.origin_x, params.origin_y);
    if xy.x >= params.width || xy.y >= params.height {
        return;
    }
    let k = xy.y * params.width + xy.x;
    let px = pixels[k];
    if px.slot == 0xffffffffu {
        return;
    }
    // the receiver behind whatever the object covers: the darkening of the photograph there,
    // which a pixel the object covers only in part shows too
    let g = px.position;
    let ng = px.normal.xyz;
    var sum = vec4<f32>(0.0);
    for (var r = 0u; r < params.reps; r++) {
        let rect = rects[r];
        if xy.x < rect.x || xy.y < rect.y || xy.x >= rect.z || xy.y >= rect.w {
            continue;
        }
        let base = (params.first_rep + r) * params.slots + px.slot;
        let t = px.weights.x * transfers[base] + px.weights.y * transfers[base + 1u]
            + px.weights.z * transfers[base + 2u] + px.weights.w * transfers[base + 3u];
        // a receiver this representative sends nothing to (most, far from the object): no map
        // to read
        if all(t == vec4<f32>(0.0)) {
            continue;
        }
        // the map's fields and the one view the receiver needs, not the whole record
        let light = maps[r].light;
        let forward = maps[r].forward;
        let config = maps[r].config;
        let rec = map_receiver(light, config, maps[r].views[0].params, g.xyz, ng);
        let technique = u32(config.x);
        var lit = 0.0;
        // how far the blocker is: at the object's contact, the receiver sees its underside,
        // not the side its sources face, and keeps none of the object's radiance
        var apart = 1e30;
        if technique == 2u && maps[r].pcss.x > 0.5 {
            let soft = soft_lit(r, rec, xy);
            lit = soft.x;
            apart = soft.y;
        } else {
            let layer = map_layer(light, forward, config, rec.p);
            if layer != NO_LAYER {
                lit = view_lit(maps[r].views[layer], technique, i32(config.z), shadow_maps, i32(layer + u32(forward.w)), rec.p);
            }
        }
        let keep = mix(vec3<f32>(1.0), keeps[params.first_rep + r].rgb, clamp(apart / max(params.object_radius, 1e-30), 0.0, 1.0));
        sum += (1.0 - lit) * t * vec4<f32>(keep, 1.0);
    }
    darkening[k] += sum;
}
