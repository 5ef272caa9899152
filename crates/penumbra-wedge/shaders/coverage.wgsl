// requires: penumbra-wedge/light.wgsl
// The analytic edge term of penumbra wedges, shared by the raster path (wedge.wgsl) and the
// tiled compute path (tiles.wgsl): an edge's signed coverage of the light's disk seen from a
// point, a_e / pi, weighted by the receiver's cosine with the region's first moment m_e
// (`penumbra_wedge::coverage` is the same computation on the CPU; its doc derives it). Zero
// wherever the edge's projection misses the disk: outside its wedge.

struct Edge {
    v0: vec4<f32>,
    v1: vec4<f32>,
    // the normals of the lit face (facing the light) and the unlit one (zero for a sheet)
    lit: vec4<f32>,
    unlit: vec4<f32>,
}

// G(h, s) = atan(s / h) / 2 - h s / 2 over the chord |s| <= sqrt(1 - h^2), constant beyond.
fn g_term(h: f32, s_in: f32) -> f32 {
    let c = sqrt(max(1.0 - h * h, 0.0));
    let s = clamp(s_in, -c, c);
    var phi = atan2(s, h);
    if h < 0.0 {
        phi = -atan2(s, -h);
    }
    return 0.5 * phi - 0.5 * h * s;
}

// The first moment (M_t, M_s) of the region g_term measures, signed as it is
// (`coverage::g_moment`).
fn g_moment(h: f32, s_in: f32) -> vec2<f32> {
    let c = sqrt(max(1.0 - h * h, 0.0));
    let s = clamp(s_in, -c, c);
    let a = abs(h);
    let r = sqrt(a * a + s * s);
    if !(r > 0.0) {
        return vec2<f32>(0.0);
    }
    let sign = select(-1.0, 1.0, h >= 0.0);
    return vec2<f32>((s / r - a * a * s) / 3.0, sign * ((1.0 - a / r) - 0.5 * a * s * s) / 3.0);
}

// (a_e, m_e) / pi of the projected segment q0 -> q1 (unit-disk coordinates): the region's area
// and first moment.
fn segment_terms(q0: vec2<f32>, q1: vec2<f32>) -> vec3<f32> {
    let d = q1 - q0;
    let len = length(d);
    if !(len > 1e-12) || len > 3.0e38 {
        return vec3<f32>(0.0);
    }
    let s_hat = d / len;
    let n_hat = vec2<f32>(s_hat.y, -s_hat.x);
    let h = dot(q0, n_hat);
    if abs(h) >= 1.0 {
        return vec3<f32>(0.0);
    }
    let s0 = dot(q0, s_hat);
    let s1 = dot(q1, s_hat);
    let m = g_moment(h, s1) - g_moment(h, s0);
    let moment = n_hat * m.x + s_hat * m.y;
    return vec3<f32>(g_term(h, s1) - g_term(h, s0), moment) / PI;
}

fn edge_terms(p: vec3<f32>, f: LightFrame, v0: vec3<f32>, v1: vec3<f32>) -> vec3<f32> {
    let d0 = v0 - p;
    let d1 = v1 - p;
    let z0 = dot(d0, f.z);
    let z1 = dot(d1, f.z);
    let z_min = 1e-6 * max(length(d0), length(d1));
    if (z0 < z_min && z1 < z_min) || (z0 > f.z_max && z1 > f.z_max) {
        return vec3<f32>(0.0);
    }
    // clip to z_min <= z <= z_max
    var t0 = 0.0;
    var t1 = 1.0;
    let dz = z1 - z0;
    if z0 < z_min {
        t0 = clamp((z_min - z0) / dz, 0.0, 1.0);
    } else if z1 < z_min {
        t1 = clamp((z_min - z0) / dz, 0.0, 1.0);
    }
    if z0 > f.z_max {
        t0 = max(t0, clamp((f.z_max - z0) / dz, 0.0, 1.0));
    } else if z1 > f.z_max {
        t1 = min(t1, clamp((f.z_max - z0) / dz, 0.0, 1.0));
    }
    if t0 >= t1 {
        return vec3<f32>(0.0);
    }
    let a = d0 + (d1 - d0) * t0;
    let b = d0 + (d1 - d0) * t1;
    let qa = vec2<f32>(dot(a, f.x), dot(a, f.y)) / (max(dot(a, f.z), z_min) * f.tan_a);
    let qb = vec2<f32>(dot(b, f.x), dot(b, f.y)) / (max(dot(b, f.z), z_min) * f.tan_a);
    return segment_terms(qa, qb);
}

// edge_term, negated where p lies in front of the edge's lit face and not in front of its
// unlit one: a light straddling the lit face's plane is partly hidden by the face's lit side
// there, and the outline is seen mirrored (`coverage::oriented_edge_term`).
// A receiver on a face's plane is on the side its normal n points to (coverage::ON_PLANE).
const ON_PLANE: f32 = 1e-4;

// weighted by c0 + c.q (light.wgsl's cosine_weights; (1, 0, 0): the plain a_e / pi)
fn oriented_edge_term(p: vec3<f32>, n: vec3<f32>, f: LightFrame, e: Edge, weights: vec3<f32>) -> f32 {
    let t = dot(weights, edge_terms(p, f, e.v0.xyz, e.v1.xyz));
    let d0 = p - e.v0.xyz;
    let d = d0 + n * (ON_PLANE * length(d0));
    return select(t, -t, dot(e.lit.xyz, d) > 0.0 && dot(e.unlit.xyz, d) <= 0.0);
}
