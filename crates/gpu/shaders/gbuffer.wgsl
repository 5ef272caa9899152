// G-buffer pass: world position (w = object index, -1 where nothing was hit), shading normal
// and geometric normal, both facing the camera as `ref-tracer` orients them, their w the
// texture coordinates u and v. The back faces of one-sided materials are culled, as
// `ref-tracer`'s camera rays pass them.

struct Camera {
    view_proj: mat4x4<f32>,
    eye: vec4<f32>,
}

@group(0) @binding(0) var<uniform> camera: Camera;

struct VsIn {
    @location(0) position: vec3<f32>,
    @location(1) normal: vec3<f32>,
    @location(2) geometric_normal: vec3<f32>,
    @location(3) object: u32,
    @location(4) uv: vec2<f32>,
    @location(5) cull: u32,
}

struct VsOut {
    // invariant: the two-pass G-buffer's passes rasterize the same fragments
    @builtin(position) @invariant clip: vec4<f32>,
    @location(0) world: vec3<f32>,
    @location(1) normal: vec3<f32>,
    @location(2) @interpolate(flat) geometric_normal: vec3<f32>,
    @location(3) @interpolate(flat) object: u32,
    @location(4) uv: vec2<f32>,
    @location(5) @interpolate(flat) cull: u32,
}

@vertex
fn vs(v: VsIn) -> VsOut {
    var out: VsOut;
    out.clip = camera.view_proj * vec4<f32>(v.position, 1.0);
    out.world = v.position;
    out.normal = v.normal;
    out.geometric_normal = v.geometric_normal;
    out.object = v.object;
    out.uv = v.uv;
    out.cull = v.cull;
    return out;
}

struct GBufferOut {
    @location(0) position: vec4<f32>,
    @location(1) normal: vec4<f32>,
    @location(2) geometric_normal: vec4<f32>,
}

fn surface(world: vec3<f32>, normal: vec3<f32>, geometric_normal: vec3<f32>, object: u32, uv: vec2<f32>) -> GBufferOut {
    var ng = geometric_normal;
    // toward the viewer: to the eye, or (w = 0) along an orthographic view's axis
    if dot(ng, camera.eye.xyz - world * camera.eye.w) < 0.0 {
        ng = -ng;
    }
    var ns = normal;
    let len = length(ns);
    ns = select(ng, ns / len, len > 0.0);
    if dot(ns, ng) < 0.0 {
        ns = -ns;
    }
    var out: GBufferOut;
    out.position = vec4<f32>(world, f32(object));
    out.normal = vec4<f32>(ns, uv.x);
    out.geometric_normal = vec4<f32>(ng, uv.y);
    return out;
}

// The geometric normal, as uploaded, faces the triangle's front (counter-clockwise) side.
fn culled(in: VsOut) -> bool {
    return in.cull != 0u && dot(in.geometric_normal, camera.eye.xyz - in.world * camera.eye.w) < 0.0;
}

@fragment
fn fs(in: VsOut) -> GBufferOut {
    if culled(in) {
        discard;
    }
    return surface(in.world, in.normal, in.geometric_normal, in.object, in.uv);
}

// Within WebGPU's default limits (32 colour bytes a sample) the G-buffer takes two passes over
// the same geometry: position and shading normal, then the geometric normal where the depth is
// equal.

struct SurfaceOut {
    @location(0) position: vec4<f32>,
    @location(1) normal: vec4<f32>,
}

@fragment
fn fs_surface(in: VsOut) -> SurfaceOut {
    if culled(in) {
        discard;
    }
    let g = surface(in.world, in.normal, in.geometric_normal, in.object, in.uv);
    return SurfaceOut(g.position, g.normal);
}

@fragment
fn fs_geometric(in: VsOut) -> @location(0) vec4<f32> {
    if culled(in) {
        discard;
    }
    return surface(in.world, in.normal, in.geometric_normal, in.object, in.uv).geometric_normal;
}
