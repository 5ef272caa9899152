// requires: shadowmap-paraboloid/paraboloid.wgsl
// Depth pass of a matrix shadow view: a cube face (90° perspective) or an orthographic map.

@group(0) @binding(0) var<uniform> view: ShadowView;

@vertex
fn vs(@location(0) p: vec3<f32>) -> @builtin(position) vec4<f32> {
    return view.matrix * vec4<f32>(p, 1.0);
}
