// requires: gpu/fullscreen.wgsl
// A G-buffer from a renderer's depth and view: each pixel's world position unprojected at its
// centre, and a geometric normal from the neighbours on its own surface (per axis the nearer of
// the two, so an edge's far side does not bend it), facing the viewer.

struct Params {
    inverse_view_proj: mat4x4<f32>,
    // toward the viewer from x: xyz - x * w (the eye, w = 1; an orthographic axis, w = 0)
    toward_viewer: vec4<f32>,
    // x the depth of nothing (what the depth buffer was cleared to), y width, z height
    info: vec4<f32>,
}

@group(0) @binding(0) var<uniform> params: Params;
@group(0) @binding(1) var depth: texture_depth_2d;

struct Out {
    @location(0) position: vec4<f32>,
    @location(1) geometric_normal: vec4<f32>,
}

fn world(p: vec2<i32>, z: f32) -> vec3<f32> {
    let size = params.info.yz;
    let ndc = vec2<f32>((f32(p.x) + 0.5) / size.x * 2.0 - 1.0, 1.0 - (f32(p.y) + 0.5) / size.y * 2.0);
    let h = params.inverse_view_proj * vec4<f32>(ndc, z, 1.0);
    return h.xyz / h.w;
}

// the surface's tangent along `step` at `x` (pixel `p`), from whichever neighbour lies nearer;
// zero where neither is a surface
fn tangent(p: vec2<i32>, x: vec3<f32>, step: vec2<i32>) -> vec3<f32> {
    let size = vec2<i32>(params.info.yz);
    var best = vec3<f32>(0.0);
    var best_len = -1.0;
    for (var s = -1; s <= 1; s += 2) {
        let q = p + step * s;
        if any(q < vec2<i32>(0)) || any(q >= size) {
            continue;
        }
        let z = textureLoad(depth, q, 0);
        if z == params.info.x {
            continue;
        }
        let d = (world(q, z) - x) * f32(s);
        let len = length(d);
        if best_len < 0.0 || len < best_len {
            best = d;
            best_len = len;
        }
    }
    return best;
}

@fragment
fn fs(@builtin(position) frag: vec4<f32>) -> Out {
    let p = vec2<i32>(frag.xy);
    let z = textureLoad(depth, p, 0);
    var out: Out;
    if z == params.info.x {
        out.position = vec4<f32>(0.0, 0.0, 0.0, -1.0);
        out.geometric_normal = vec4<f32>(0.0);
        return out;
    }
    let x = world(p, z);
    let toward = normalize(params.toward_viewer.xyz - x * params.toward_viewer.w);
    var n = cross(tangent(p, x, vec2<i32>(1, 0)), tangent(p, x, vec2<i32>(0, 1)));
    let len = length(n);
    n = select(toward, n / len, len > 0.0);
    if dot(n, toward) < 0.0 {
        n = -n;
    }
    // object 0: a depth buffer does not say which object a pixel shows
    out.position = vec4<f32>(x, 0.0);
    out.geometric_normal = vec4<f32>(n, 0.0);
    return out;
}
