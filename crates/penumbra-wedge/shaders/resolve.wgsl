// requires: penumbra-wedge/light.wgsl gpu/fullscreen.wgsl
// Resolve of the wedges' accumulator into a visibility layer: V = clamp(1 - w + g, 0, 1), w the
// hard count r (the number of shadow volumes the point lies in), g the edge terms' sum (the accumulator's g, or `edge_sum`),
// divided by the fraction of the light's disk above the surface's own plane (casters the point
// lies on hide the part below it, which the shading's cone integral already leaves out).
// Background pixels (G-buffer w < 0) stay lit.

@group(0) @binding(0) var<uniform> light: Light;
@group(0) @binding(1) var g_position: texture_2d<f32>;
@group(0) @binding(2) var accumulated: texture_2d<f32>;
@group(0) @binding(3) var g_geometric_normal: texture_2d<f32>;
// the edge terms' sum of the compute path (tiles.wgsl); a 1 x 1 zero texture for the raster
// path, whose sum is in the accumulator's g
@group(0) @binding(4) var edge_sum: texture_2d<f32>;

// Fraction of the light's disk (in the plane the wedges project onto) above the plane through
// p with normal n.
fn disk_above(p: vec3<f32>, n: vec3<f32>) -> f32 {
    let f = light_frame(light, p);
    let nz = dot(n, f.z);
    let nxy = sqrt(max(1.0 - nz * nz, 0.0));
    if nxy < 1e-7 {
        return select(0.0, 1.0, nz > 0.0);
    }
    // above: tan_a (n_xy . q) + n_z > 0, a half-plane at signed distance t from the centre
    let t = clamp(-nz / (f.tan_a * nxy), -1.0, 1.0);
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
    // counts are whole numbers: exact in f32 and f16
    // every volume the point lies in hides the light's centre once: where casters overlap, their
    // occlusions add (clamped below) instead of the second caster's edges lighting the first's
    // umbra (`coverage::visibility` says why)
    let w = abs(round(a.r));
    let sum_texel = min(vec2<u32>(pixel), textureDimensions(edge_sum) - vec2<u32>(1u));
    // cosine-weighted edge terms (light.wgsl's cosine_weights) resolve alike: their weight is 1
    // at the disk's centre and the disk lies wholly above the plane (disk_above = 1)
    let v = clamp(1.0 - w + a.g + textureLoad(edge_sum, sum_texel, 0).r, 0.0, 1.0);
    let n = textureLoad(g_geometric_normal, pixel, 0).xyz;
    return vec4<f32>(clamp(v / max(disk_above(g.xyz, n), 1e-4), 0.0, 1.0));
}
