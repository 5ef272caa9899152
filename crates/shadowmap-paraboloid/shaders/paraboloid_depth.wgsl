enable clip_distances;
// requires: shadowmap-paraboloid/paraboloid.wgsl
// Paraboloid depth pass, other hemisphere rejected by a clip distance (needs CLIP_DISTANCES):
// clipped before rasterization, so the depth test stays early and there is no fragment stage.

@group(0) @binding(0) var<uniform> view: ShadowView;

struct VsOut {
    @builtin(position) position: vec4<f32>,
    @builtin(clip_distances) clip: array<f32, 1>,
}

@vertex
fn vs(@location(0) p: vec3<f32>) -> VsOut {
    let c = paraboloid_project(view, p);
    var out: VsOut;
    out.position = vec4<f32>(c.xy, c.z, 1.0);
    out.clip[0] = c.w;
    return out;
}
