// The BRDF of `scene::brdf`, mirrored: Lambert, or GGX (height-correlated Smith, Schlick
// Fresnel) over the Ashikhmin-Shirley coupled diffuse. Isotropic, so it works on world vectors
// with the shading normal instead of a local frame. A test renders both and compares.

const PI: f32 = 3.14159265358979;
const MIN_ALPHA: f32 = 1e-3;

struct Material {
    // rgb albedo; a = 1 when there is a specular layer
    albedo: vec4<f32>,
    // rgb F0; a = roughness
    f0_roughness: vec4<f32>,
    // rgb emitted radiance
    emission: vec4<f32>,
    // glTF's factors where the material is textured (`scene::Maps`): rgb base colour, a metallic
    base_metallic: vec4<f32>,
    // x roughness factor, y 1 where textured
    pbr: vec4<f32>,
    // base colour, metallic-roughness and emissive texture (0xffffffff: none)
    maps: vec4<u32>,
}

fn ggx_d(noh: f32, alpha: f32) -> f32 {
    let a2 = alpha * alpha;
    let d = noh * noh * (a2 - 1.0) + 1.0;
    return a2 / (PI * d * d);
}

fn ggx_lambda(c: f32, alpha: f32) -> f32 {
    let c2 = c * c;
    let tan2 = max((1.0 - c2) / c2, 0.0);
    return 0.5 * (-1.0 + sqrt(1.0 + alpha * alpha * tan2));
}

fn fresnel_schlick(f0: vec3<f32>, c: f32) -> vec3<f32> {
    let m = pow(1.0 - clamp(c, 0.0, 1.0), 5.0);
    return f0 + (vec3<f32>(1.0) - f0) * m;
}

fn as_k(c: f32) -> f32 {
    return 1.0 - pow(1.0 - 0.5 * c, 5.0);
}

// Share of the albedo the diffuse lobe reflects (`Material::diffuse_weight`).
fn diffuse_weight(m: Material) -> f32 {
    if m.albedo.a > 0.5 {
        return 1.0 - clamp(max(m.f0_roughness.r, max(m.f0_roughness.g, m.f0_roughness.b)), 0.0, 1.0);
    }
    return 1.0;
}

// BRDF value; zero below the surface. `n`, `wo`, `wi` unit, world space.
fn eval_brdf(m: Material, n: vec3<f32>, wo: vec3<f32>, wi: vec3<f32>) -> vec3<f32> {
    let cos_o = dot(n, wo);
    let cos_i = dot(n, wi);
    if cos_o <= 0.0 || cos_i <= 0.0 {
        return vec3<f32>(0.0);
    }
    if m.albedo.a < 0.5 {
        return m.albedo.rgb / PI;
    }
    let f0 = m.f0_roughness.rgb;
    let r = m.f0_roughness.a;
    let alpha = max(r * r, MIN_ALPHA);
    var f = m.albedo.rgb * (vec3<f32>(1.0) - f0) * (28.0 / (23.0 * PI) * as_k(cos_i) * as_k(cos_o));
    let hs = wo + wi;
    let hl = length(hs);
    if hl > 0.0 {
        let h = hs / hl;
        let g2 = 1.0 / (1.0 + ggx_lambda(cos_o, alpha) + ggx_lambda(cos_i, alpha));
        let spec = ggx_d(dot(n, h), alpha) * g2 / (4.0 * cos_o * cos_i);
        f += fresnel_schlick(f0, dot(wo, h)) * spec;
    }
    return f;
}
