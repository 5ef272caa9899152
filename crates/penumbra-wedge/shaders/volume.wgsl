// Hard shadow volume, z-fail: each volume face behind the G-buffer surface along the view ray
// adds +1 (back face) or -1 (front face) to the accumulator's r. The volume is closed and wound
// outward, so the count is the number of volumes the surface point lies in, whether or not
// the eye is inside one. The depth test is done here against the G-buffer position (no depth
// attachment), so the volume needs no far plane: it is drawn with an infinite projection.

struct View {
    view_proj: mat4x4<f32>,
    // w = 1: the eye of a perspective; w = 0: a point behind every receiver of an
    // orthographic view, depths measured from it along `forward`
    eye: vec4<f32>,
    // an orthographic view's axis (w unused). A mirrored (left-handed) view flips which
    // faces are front faces: the counts change sign, which the resolve's |count| ignores.
    forward: vec4<f32>,
}

@group(0) @binding(0) var<uniform> view: View;
@group(0) @binding(1) var g_position: texture_2d<f32>;

struct VsOut {
    @builtin(position) clip: vec4<f32>,
    @location(0) world: vec3<f32>,
}

@vertex
fn vs(@location(0) position: vec3<f32>) -> VsOut {
    var out: VsOut;
    out.clip = view.view_proj * vec4<f32>(position, 1.0);
    out.world = position;
    return out;
}

// how far along its view ray `x` lies
fn depth(x: vec3<f32>) -> f32 {
    if view.eye.w > 0.5 {
        return distance(x, view.eye.xyz);
    }
    return dot(x - view.eye.xyz, view.forward.xyz);
}

@fragment
fn fs(in: VsOut, @builtin(front_facing) front: bool) -> @location(0) vec4<f32> {
    let g = textureLoad(g_position, vec2<i32>(in.clip.xy), 0);
    if g.w < 0.0 {
        discard;
    }
    // depth fail: the face lies at or behind the surface. The front cap lies on the casters'
    // lit faces; where the surface is such a face its cap fragment must count (as a depth test
    // LESS fails on equal depths), so a relative margin lets faces a hair in front count too.
    let t_surface = depth(g.xyz);
    if depth(in.world) < t_surface * (1.0 - 1e-5) {
        discard;
    }
    return vec4<f32>(select(1.0, -1.0, front), 0.0, 0.0, 0.0);
}
