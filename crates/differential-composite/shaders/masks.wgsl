// requires: shadowmap-paraboloid/paraboloid.wgsl shadowmap-paraboloid/lookup.wgsl
// Every representative's share of the frame's darkening in one pass: per pixel, for each
// representative whose hard shadow map (all of a batch's maps are layers of one texture array)
// says the object blocks its origin (1 - visibility), its transfer at the pixel, the bilinear
// blend of its receiver's four vertex transfers (radiance for HDR, codes for LDR), added up.

struct Params {
    width: u32,
    height: u32,
    // transfer columns (receiver vertices) per representative
    slots: u32,
    // representatives in this batch, and the first one's index in the frame
    reps: u32,
    first_rep: u32,
    pad0: u32,
    pad1: u32,
    pad2: u32,
}

struct PixelRef {
    weights: vec4<f32>,
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
@group(0) @binding(5) var g_position: texture_2d<f32>;
@group(0) @binding(6) var g_geometric_normal: texture_2d<f32>;
@group(0) @binding(7) var<storage, read_write> darkening: array<vec4<f32>>;

@compute @workgroup_size(8, 8)
fn main(@builtin(global_invocation_id) id: vec3<u32>) {
    if id.x >= params.width || id.y >= params.height {
        return;
    }
    let k = id.y * params.width + id.x;
    let px = pixels[k];
    if px.slot == 0xffffffffu {
        return;
    }
    let g = textureLoad(g_position, vec2<i32>(id.xy), 0);
    if g.w < 0.0 {
        return;
    }
    let ng = textureLoad(g_geometric_normal, vec2<i32>(id.xy), 0).xyz;
    var sum = vec4<f32>(0.0);
    for (var r = 0u; r < params.reps; r++) {
        // the map's fields and the one view the receiver needs, not the whole record
        let light = maps[r].light;
        let forward = maps[r].forward;
        let config = maps[r].config;
        let rec = map_receiver(light, config, maps[r].views[0].params, g.xyz, ng);
        let layer = map_layer(light, forward, config, rec.p);
        var lit = 0.0;
        if layer != NO_LAYER {
            let technique = u32(config.x);
            lit = view_lit(maps[r].views[layer], technique, i32(config.z), shadow_maps, i32(layer + u32(forward.w)), rec.p);
        }
        if lit < 1.0 {
            let base = (params.first_rep + r) * params.slots + px.slot;
            let t = px.weights.x * transfers[base] + px.weights.y * transfers[base + 1u]
                + px.weights.z * transfers[base + 2u] + px.weights.w * transfers[base + 3u];
            sum += (1.0 - lit) * t;
        }
    }
    darkening[k] += sum;
}
