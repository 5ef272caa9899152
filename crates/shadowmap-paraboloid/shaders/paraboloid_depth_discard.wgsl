// requires: shadowmap-paraboloid/paraboloid.wgsl
// Paraboloid depth pass, other hemisphere rejected per fragment (the paper's alpha test): works
// without CLIP_DISTANCES, but the discard moves the depth test after the fragment shader.

@group(0) @binding(0) var<uniform> view: ShadowView;

struct VsOut {
    @builtin(position) position: vec4<f32>,
    @location(0) z: f32,
}

@vertex
fn vs(@location(0) p: vec3<f32>) -> VsOut {
    let c = paraboloid_project(view, p);
    var out: VsOut;
    out.position = vec4<f32>(c.xy, c.z, 1.0);
    out.z = c.w;
    return out;
}

@fragment
fn fs(in: VsOut) {
    if in.z < 0.0 {
        discard;
    }
}
