// One shadow view: a paraboloid map (world -> light rigid transform) or a matrix map (cube face,
// orthographic: world -> clip). The paraboloid arithmetic is `envmap_sphere::paraboloid`'s front
// mapping in the view's frame, as `shadowmap_paraboloid::paraboloid` places it (tests compare the
// two). In the band a map covers (z >= -RIM_MARGIN) the formulas agree; beyond it, where nothing
// is drawn, this clamp only keeps the result finite.
const MIN_DENOMINATOR: f32 = 1e-4;
// Each map covers z >= -RIM_MARGIN, its (u, v) scaled by 1 / UV_SCALE = (1 - m) / sqrt(1 - m^2)
// to fit: clipping exactly at the rim would leave the clipped triangles' chords inside it.
const RIM_MARGIN: f32 = 0.05;
const UV_SCALE: f32 = 1.051315;

struct ShadowView {
    // paraboloid: world -> light space; matrix kinds: world -> clip
    matrix: mat4x4<f32>,
    // x near, y far, z kind (0 paraboloid, 1 matrix), w resolution
    params: vec4<f32>,
}

// (u, v, depth, clip distance) of world point `p` in a paraboloid view; the clip distance
// z / |d| + RIM_MARGIN is negative outside the map's band.
fn paraboloid_project(view: ShadowView, p: vec3<f32>) -> vec4<f32> {
    let l = (view.matrix * vec4<f32>(p, 1.0)).xyz;
    let dist = length(l);
    if dist == 0.0 {
        return vec4<f32>(0.0, 0.0, (0.0 - view.params.x) / (view.params.y - view.params.x), 1.0);
    }
    let n = l / dist;
    let uv = n.xy / (max(1.0 + n.z, MIN_DENOMINATOR) * UV_SCALE);
    let depth = (dist - view.params.x) / (view.params.y - view.params.x);
    return vec4<f32>(uv, depth, n.z + RIM_MARGIN);
}
