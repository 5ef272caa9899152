// An orthographic map's view fitted to the receivers on the GPU: the focus (the visible points'
// mean and the 95th percentile of their distances to it) comes from the receiver reduction's
// statistics where they are, so the CPU records the map without waiting for them. The
// arithmetic is `ShadowMapper`'s on the CPU, operation for operation: the view's rotation comes
// from the CPU (it depends on the light only); the product with the orthographic projection,
// whose other entries are zeros, is one multiplication per entry.

struct Params {
    // the view's axes as glam's `look_to_mat4` makes them: s, u, f
    s: vec4<f32>,
    u: vec4<f32>,
    f: vec4<f32>,
    // unit direction towards the light
    d: vec4<f32>,
    // xyz: the centre of the scene's bounding sphere, w: its radius
    scene: vec4<f32>,
    // x: the map's resolution in texels; y, z, w: the statistics' count, mean and radius words
    info: vec4<f32>,
    words: vec4<u32>,
}

// `lookup.wgsl`'s `ViewUniform`: world to clip, then (near, far, 1 for a matrix view, resolution)
struct View {
    matrix: mat4x4<f32>,
    params: vec4<f32>,
}

@group(0) @binding(0) var<uniform> params: Params;
@group(0) @binding(1) var<storage, read> stats: array<u32>;
@group(0) @binding(2) var<storage, read_write> view: View;

fn length3(v: vec3<f32>) -> f32 {
    return sqrt((v.x * v.x + v.y * v.y) + v.z * v.z);
}

fn dot3(a: vec3<f32>, b: vec3<f32>) -> f32 {
    return (a.x * b.x + a.y * b.y) + a.z * b.z;
}

@compute @workgroup_size(1)
fn focus() {
    let center = params.scene.xyz;
    let radius = params.scene.w;
    var fc = center;
    var fr = radius;
    if stats[params.words.x] > 0u {
        let m = params.words.y;
        fc = vec3<f32>(bitcast<f32>(stats[m]), bitcast<f32>(stats[m + 1u]), bitcast<f32>(stats[m + 2u]));
        fr = max(min(bitcast<f32>(stats[params.words.z]), radius), 1e-6);
    }
    let reach = length3(fc - center) + radius;
    let margin = reach * 0.01;
    let ext = reach + margin;
    let eye = fc + params.d.xyz * ext;
    let far = 2.0 * ext;
    let width_inv = 1.0 / (fr + fr);
    let xx = width_inv + width_inv;
    let zz = -(1.0 / far);
    let s = params.s.xyz;
    let u = params.u.xyz;
    let f = params.f.xyz;
    view.matrix = mat4x4<f32>(
        vec4<f32>(xx * s.x, xx * u.x, zz * -f.x, 0.0),
        vec4<f32>(xx * s.y, xx * u.y, zz * -f.y, 0.0),
        vec4<f32>(xx * s.z, xx * u.z, zz * -f.z, 0.0),
        vec4<f32>(xx * -dot3(eye, s), xx * -dot3(eye, u), zz * dot3(eye, f), 1.0),
    );
    view.params = vec4<f32>(0.0, 2.0 * fr, 1.0, params.info.x);
}
