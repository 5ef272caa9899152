// requires: penumbra-wedge/light.wgsl penumbra-wedge/coverage.wgsl
// Penumbra wedges, tiled compute path: one workgroup per 16 x 16 screen tile, one invocation
// per pixel. The CPU bins each footprint (a group of consecutive silhouette edges) into the
// tiles its screen bounds touch; every pixel of a tile sums the edge terms of its tile's groups
// into `edge_sum` (coverage.wgsl: the term is 0 outside an edge's wedge, so pixels of the tile
// outside a footprint add nothing). The wedges' resolve adds `edge_sum` to the hard count the
// raster volume pass left in the accumulator.

struct Tiles {
    // x width, y height in pixels, z tiles per row
    size: vec4<u32>,
}

@group(0) @binding(0) var<uniform> light: Light;
@group(0) @binding(1) var<storage, read> edges: array<Edge>;
@group(0) @binding(2) var g_position: texture_2d<f32>;
@group(0) @binding(3) var<uniform> tiles: Tiles;
// per tile: (first group, group count) in `groups`
@group(0) @binding(4) var<storage, read> tile_ranges: array<vec2<u32>>;
// per binned group: (first edge, edge count) in `edges`
@group(0) @binding(5) var<storage, read> groups: array<vec2<u32>>;
@group(0) @binding(6) var edge_sum: texture_storage_2d<r32float, write>;
@group(0) @binding(7) var g_geometric_normal: texture_2d<f32>;

@compute @workgroup_size(16, 16)
fn main(@builtin(global_invocation_id) id: vec3<u32>, @builtin(workgroup_id) tile: vec3<u32>) {
    if id.x >= tiles.size.x || id.y >= tiles.size.y {
        return;
    }
    let pixel = vec2<i32>(id.xy);
    let g = textureLoad(g_position, pixel, 0);
    var sum = 0.0;
    if g.w >= 0.0 {
        let f = light_frame(light, g.xyz);
        let n = textureLoad(g_geometric_normal, pixel, 0).xyz;
        let weights = cosine_weights(light, n, f);
        let range = tile_ranges[tile.y * tiles.size.z + tile.x];
        for (var i = range.x; i < range.x + range.y; i++) {
            let group = groups[i];
            for (var k = group.x; k < group.x + group.y; k++) {
                let e = edges[k];
                sum += oriented_edge_term(g.xyz, n, f, e, weights);
            }
        }
    }
    textureStore(edge_sum, pixel, vec4<f32>(sum, 0.0, 0.0, 0.0));
}
