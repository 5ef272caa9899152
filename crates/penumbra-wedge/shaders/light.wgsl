// The light as penumbra wedges see it from a receiver, shared by the wedge and resolve passes
// (`penumbra_wedge::coverage::light_frame` on the CPU).

const PI: f32 = 3.14159265358979;
const MAX_HALF_ANGLE: f32 = 1.5;

struct Light {
    // xyz unit direction towards a distant light, or a sphere light's centre
    position_or_direction: vec4<f32>,
    // x 0 distant, 1 sphere; y half-angle (distant) or radius (sphere); z 1: weight the disk by
    // the receiver's cosine (coverage.wgsl's cosine_slope)
    config: vec4<f32>,
}

// The light seen from a receiver: its frame (z towards the centre), tan of its half-angle, and
// the farthest z that still occludes it.
struct LightFrame {
    x: vec3<f32>,
    y: vec3<f32>,
    z: vec3<f32>,
    tan_a: f32,
    z_max: f32,
}

fn light_frame(light: Light, p: vec3<f32>) -> LightFrame {
    var f: LightFrame;
    var alpha: f32;
    f.z_max = 3.0e38;
    if light.config.x < 0.5 {
        f.z = light.position_or_direction.xyz;
        alpha = light.config.y;
    } else {
        let to_c = light.position_or_direction.xyz - p;
        let dist = length(to_c);
        f.z = to_c / max(dist, 1e-30);
        alpha = select(asin(min(light.config.y / dist, 1.0)), PI * 0.5, dist <= light.config.y);
        f.z_max = dist * cos(alpha) * cos(alpha);
    }
    alpha = clamp(alpha, 1e-7, MAX_HALF_ANGLE);
    let helper = select(vec3<f32>(1.0, 0.0, 0.0), vec3<f32>(0.0, 1.0, 0.0), abs(f.z.x) > 0.9);
    f.x = normalize(cross(helper, f.z));
    f.y = cross(f.z, f.x);
    f.tan_a = tan(alpha);
    return f;
}

// The cosine weight at a receiver with normal n: a point q of the light's unit disk weighs
// 1 + k.q (proportional to n.d), returned as (1, k) where the disk lies wholly above the
// receiver's plane (|k| <= 1); (1, 0, 0), uniform, where it straddles the plane or when the
// light does not ask for weighting (config.z) (`coverage::cosine_weights`).
fn cosine_weights(light: Light, n: vec3<f32>, f: LightFrame) -> vec3<f32> {
    let nz = dot(n, f.z);
    let c = vec2<f32>(dot(n, f.x), dot(n, f.y)) * f.tan_a;
    if light.config.z < 0.5 || !(nz > 0.0) || length(c) > nz {
        return vec3<f32>(1.0, 0.0, 0.0);
    }
    return vec3<f32>(1.0, c / nz);
}
