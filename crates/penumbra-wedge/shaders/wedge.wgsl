// requires: penumbra-wedge/light.wgsl penumbra-wedge/coverage.wgsl penumbra-wedge/footprint.wgsl
// Penumbra wedges: per pixel of a footprint (the conservative hull of a few consecutive
// silhouette edges' wedges), each edge's signed coverage of the light's disk seen from the
// G-buffer point, a_e / pi (coverage.wgsl), summed and added to the accumulator's g.

@group(0) @binding(0) var<uniform> light: Light;
@group(0) @binding(1) var<storage, read> edges: array<Edge>;
@group(0) @binding(2) var g_position: texture_2d<f32>;
@group(0) @binding(3) var g_geometric_normal: texture_2d<f32>;

struct VsOut {
    @builtin(position) clip: vec4<f32>,
    // the footprint's edges: first index and count
    @location(0) @interpolate(flat) first: u32,
    @location(1) @interpolate(flat) count: u32,
}

@vertex
fn vs(@location(0) ndc: vec2<f32>, @location(1) first: u32, @location(2) count: u32) -> VsOut {
    var out: VsOut;
    out.clip = vec4<f32>(ndc, 0.5, 1.0);
    out.first = first;
    out.count = count;
    return out;
}

// Footprints built on the GPU (footprint.wgsl, one instance each): a fan of up to 18
// triangles over its corners; triangles past them collapse to a point.
@group(0) @binding(4) var<storage, read> footprints: array<Footprint>;

@vertex
fn vs_polygon(@builtin(vertex_index) vertex: u32, @builtin(instance_index) instance: u32) -> VsOut {
    let f = footprints[instance];
    let t = vertex / 3u;
    let k = vertex % 3u;
    var out: VsOut;
    out.first = f.first;
    out.count = f.edges;
    if t + 2u >= f.count {
        out.clip = vec4<f32>(0.0, 0.0, 0.5, 1.0);
        return out;
    }
    out.clip = vec4<f32>(f.corners[select(t + k, 0u, k == 0u)], 0.5, 1.0);
    return out;
}

@fragment
fn fs(in: VsOut) -> @location(0) vec4<f32> {
    let g = textureLoad(g_position, vec2<i32>(in.clip.xy), 0);
    let n = textureLoad(g_geometric_normal, vec2<i32>(in.clip.xy), 0).xyz;
    if g.w < 0.0 {
        discard;
    }
    let f = light_frame(light, g.xyz);
    let weights = cosine_weights(light, n, f);
    var sum = 0.0;
    for (var k = in.first; k < in.first + in.count; k++) {
        let e = edges[k];
        sum += oriented_edge_term(g.xyz, n, f, e, weights);
    }
    return vec4<f32>(0.0, sum, 0.0, 0.0);
}
