// requires: gpu/brdf.wgsl gpu/sh9.wgsl gpu/fullscreen.wgsl
// Shading pass: per pixel, the G-buffer surface lit by distant cone lights (the diffuse lobe by
// the cone's exact irradiance, a GGX lobe by its representative point or, as wide as the cone,
// by quadrature over it) and point lights, each
// times its visibility layer, plus ambient: SH9 irradiance on the diffuse lobe and the
// prefiltered ambient map on the specular lobe (both signed), as `ref-tracer`'s `lights`
// integrator; misses see the map.

struct Light {
    // xyz: unit direction towards a distant light, or a point light's position; w: 0 distant, 1 point
    position_or_direction: vec4<f32>,
    // rgb: a distant light's irradiance at normal incidence (radiance x solid angle), or a point
    // light's intensity (W/sr); w: a distant light's half-angle (radians; 0 directional)
    value: vec4<f32>,
}

struct Params {
    eye: vec4<f32>,
    // camera ray generation as `scene::CameraRays`: dir = corner + right x + down y
    right: vec4<f32>,
    down: vec4<f32>,
    corner: vec4<f32>,
    // x light count, y bit 0 ambient on, bit 1 emission on, z background width, w background height (0: black)
    counts: vec4<u32>,
    // the prefiltered ambient of the specular lobe: x width, y height, z levels (0: none),
    // w side of the directional-albedo table
    ambient_info: vec4<u32>,
    // the maps' turns about +Y (`Background::set_turn`): cos and sin of the background's, then
    // of the specular ambient's
    turn: vec4<f32>,
    // SH9 irradiance coefficients premultiplied by A_l
    sh: array<vec4<f32>, 9>,
}

@group(0) @binding(0) var<uniform> params: Params;
@group(0) @binding(1) var<storage, read> lights: array<Light>;
@group(0) @binding(2) var<storage, read> materials: array<Material>;
@group(0) @binding(3) var g_position: texture_2d<f32>;
@group(0) @binding(4) var g_normal: texture_2d<f32>;
@group(0) @binding(5) var g_geometric_normal: texture_2d<f32>;
@group(0) @binding(6) var visibility: texture_2d_array<f32>;
@group(0) @binding(7) var background: texture_2d_array<f32>;
// `gpu::ambient`: the ambient map prefiltered per roughness level, and the GGX lobe's
// directional albedo as (F0 scale, bias) over (cos theta_o, roughness)
@group(0) @binding(8) var prefiltered: texture_2d_array<f32>;
@group(0) @binding(9) var dfg: texture_2d<f32>;
// `gpu::geometry`'s texel words: per texture a header (first texel, width, height, wrap u |
// wrap v << 2 | nearest << 4), then RGBA8 texels
@group(0) @binding(10) var<storage, read> texels: array<u32>;

const NO_TEXTURE: u32 = 0xffffffffu;
const MIN_ROUGHNESS: f32 = 0.0316;

fn srgb_to_linear(c: f32) -> f32 {
    return select(pow((c + 0.055) / 1.055, 2.4), c / 12.92, c <= 0.04045);
}

// `scene::Wrap::texel`: 0 repeat, 1 clamp, 2 mirrored repeat.
fn wrap_texel(i: i32, n: i32, mode: u32) -> u32 {
    if mode == 1u {
        return u32(clamp(i, 0, n - 1));
    }
    if mode == 2u {
        let k = ((i % (2 * n)) + 2 * n) % (2 * n);
        return u32(select(2 * n - 1 - k, k, k < n));
    }
    return u32(((i % n) + n) % n);
}

fn texel(first: u32, w: u32, x: u32, y: u32, srgb: bool) -> vec4<f32> {
    let c = unpack4x8unorm(texels[first + y * w + x]);
    if srgb {
        return vec4<f32>(srgb_to_linear(c.r), srgb_to_linear(c.g), srgb_to_linear(c.b), c.a);
    }
    return c;
}

// `scene::Texture::sample`: full resolution, nearest or bilinear, wrapped; white for none.
fn sample_texture(t: u32, uv_in: vec2<f32>, srgb: bool) -> vec4<f32> {
    if t == NO_TEXTURE || 4u * t + 3u >= arrayLength(&texels) {
        return vec4<f32>(1.0);
    }
    let first = texels[4u * t];
    let size = vec2<u32>(texels[4u * t + 1u], texels[4u * t + 2u]);
    let mode = texels[4u * t + 3u];
    if size.x == 0u || size.y == 0u {
        return vec4<f32>(1.0);
    }
    let n = vec2<i32>(size);
    let wu = mode & 3u;
    let wv = (mode >> 2u) & 3u;
    // clamped where a float no longer tells texels apart, so the conversion to i32 is exact
    let p = clamp(uv_in * vec2<f32>(size), vec2<f32>(-1e9), vec2<f32>(1e9));
    if (mode & 16u) != 0u {
        let q = vec2<i32>(floor(p));
        return texel(first, size.x, wrap_texel(q.x, n.x, wu), wrap_texel(q.y, n.y, wv), srgb);
    }
    let c = p - vec2<f32>(0.5);
    let c0 = floor(c);
    let f = c - c0;
    let q = vec2<i32>(c0);
    let x0 = wrap_texel(q.x, n.x, wu);
    let x1 = wrap_texel(q.x + 1, n.x, wu);
    let y0 = wrap_texel(q.y, n.y, wv);
    let y1 = wrap_texel(q.y + 1, n.y, wv);
    let top = mix(texel(first, size.x, x0, y0, srgb), texel(first, size.x, x1, y0, srgb), f.x);
    let bottom = mix(texel(first, size.x, x0, y1, srgb), texel(first, size.x, x1, y1, srgb), f.x);
    return mix(top, bottom, f.y);
}

// `scene::Material::at`: a textured material resolved at `uv` into a uniform one.
fn material_at(m: Material, uv: vec2<f32>) -> Material {
    if m.pbr.y < 0.5 {
        return m;
    }
    var out = m;
    let base = clamp(m.base_metallic.rgb * sample_texture(m.maps.x, uv, true).rgb, vec3<f32>(0.0), vec3<f32>(1.0));
    out.emission = vec4<f32>(m.emission.rgb * sample_texture(m.maps.z, uv, true).rgb, 0.0);
    // `Maps::specular` false: the base colour alone, Lambertian
    if m.pbr.z > 0.5 {
        out.albedo = vec4<f32>(base, 0.0);
        out.f0_roughness = vec4<f32>(0.0, 0.0, 0.0, 1.0);
        return out;
    }
    let mr = sample_texture(m.maps.y, uv, false);
    let metallic = clamp(m.base_metallic.a * mr.b, 0.0, 1.0);
    let roughness = max(clamp(m.pbr.x * mr.g, 0.0, 1.0), MIN_ROUGHNESS);
    out.albedo = vec4<f32>(base * (1.0 - metallic), 1.0);
    out.f0_roughness = vec4<f32>(mix(vec3<f32>(0.04), base, metallic), roughness);
    return out;
}

// Bilinear lat-long lookup in layer `layer` of `t` (`size` texels), wrapping in u and
// clamping in v (`EnvMap::lookup`).
fn latlong_bilinear(t: texture_2d_array<f32>, layer: i32, size: vec2<u32>, dir: vec3<f32>) -> vec3<f32> {
    var u = atan2(dir.x, -dir.z) / (2.0 * PI);
    if u < 0.0 {
        u += 1.0;
    }
    let v = clamp(atan2(length(dir.xz), dir.y) / PI, 0.0, 1.0);
    let x = u * f32(size.x) - 0.5;
    let y = clamp(v * f32(size.y) - 0.5, 0.0, f32(size.y - 1u));
    let x0 = floor(x);
    let y0 = floor(y);
    let fx = x - x0;
    let fy = y - y0;
    let wi = i32(size.x);
    let xi0 = ((i32(x0) % wi) + wi) % wi;
    let xi1 = (xi0 + 1) % wi;
    let yi0 = i32(y0);
    let yi1 = min(yi0 + 1, i32(size.y) - 1);
    let top = mix(textureLoad(t, vec2<i32>(xi0, yi0), layer, 0).rgb, textureLoad(t, vec2<i32>(xi1, yi0), layer, 0).rgb, fx);
    let bottom = mix(textureLoad(t, vec2<i32>(xi0, yi1), layer, 0).rgb, textureLoad(t, vec2<i32>(xi1, yi1), layer, 0).rgb, fx);
    return mix(top, bottom, fy);
}

// Where world direction `d` falls in a map turned about +Y by an angle of cosine `c` and sine
// `s`: R(-angle) d.
fn in_turned_map(d: vec3<f32>, c: f32, s: f32) -> vec3<f32> {
    return vec3<f32>(c * d.x - s * d.z, d.y, s * d.x + c * d.z);
}

// What a camera ray that misses sees: the map, or black without one.
fn background_radiance(dir: vec3<f32>) -> vec3<f32> {
    if params.counts.z == 0u || params.counts.w == 0u {
        return vec3<f32>(0.0);
    }
    return latlong_bilinear(background, 0, params.counts.zw, in_turned_map(dir, params.turn.x, params.turn.y));
}

// The ambient map on a GGX lobe by the split-sum approximation (`gpu::ambient`): the map
// prefiltered for the lobe's roughness along the mirror direction, times the lobe's directional
// albedo F0 x scale + bias. Signed maps stay signed.
fn specular_ambient(m: Material, n: vec3<f32>, wo: vec3<f32>) -> vec3<f32> {
    let cos_o = dot(n, wo);
    if params.ambient_info.z == 0u || m.albedo.a < 0.5 || cos_o <= 0.0 {
        return vec3<f32>(0.0);
    }
    let roughness = clamp(m.f0_roughness.a, 0.0, 1.0);
    let x = roughness * f32(params.ambient_info.z - 1u);
    let k0 = i32(floor(x));
    let k1 = min(k0 + 1, i32(params.ambient_info.z) - 1);
    // a rough lobe's mass leans from the mirror direction towards the normal (Frostbite's
    // dominant direction, Lagarde and de Rousiers 2014)
    let alpha = roughness * roughness;
    let smooth_ = 1.0 - alpha;
    let r = in_turned_map(normalize(mix(n, reflect(-wo, n), smooth_ * (sqrt(smooth_) + alpha))), params.turn.z, params.turn.w);
    let size = params.ambient_info.xy;
    let radiance = mix(latlong_bilinear(prefiltered, k0, size, r), latlong_bilinear(prefiltered, k1, size, r), x - f32(k0));
    // bilinear in the table, clamped at its edges (`DfgTable::lookup`)
    let t = f32(params.ambient_info.w);
    let tx = clamp(cos_o * t - 0.5, 0.0, t - 1.0);
    let ty = clamp(roughness * t - 0.5, 0.0, t - 1.0);
    let x0 = i32(floor(tx));
    let y0 = i32(floor(ty));
    let x1 = min(x0 + 1, i32(params.ambient_info.w) - 1);
    let y1 = min(y0 + 1, i32(params.ambient_info.w) - 1);
    let fx = tx - f32(x0);
    let fy = ty - f32(y0);
    let top = mix(textureLoad(dfg, vec2<i32>(x0, y0), 0).rg, textureLoad(dfg, vec2<i32>(x1, y0), 0).rg, fx);
    let bottom = mix(textureLoad(dfg, vec2<i32>(x0, y1), 0).rg, textureLoad(dfg, vec2<i32>(x1, y1), 0).rg, fx);
    let sb = mix(top, bottom, fy);
    return radiance * (m.f0_roughness.rgb * sb.x + vec3<f32>(sb.y));
}

// Integral of cos over the part of a cone (half-angle with sin^2 = `sin2`) above the surface,
// the cone's axis at cos theta = `cos_t` from the normal: pi sin^2 cos theta while the cone is
// wholly above the horizon, else the closed form for a uniform sphere or disk light (Snyder
// 1996, as Frostbite writes it).
fn cone_cosine_integral(cos_t: f32, sin2: f32) -> f32 {
    if cos_t * cos_t > sin2 {
        return PI * sin2 * max(cos_t, 0.0);
    }
    let sin_t = sqrt(max(1.0 - cos_t * cos_t, 1e-12));
    let x = sqrt(max(1.0 / sin2 - 1.0, 0.0));
    let y = clamp(-x * cos_t / sin_t, -1.0, 1.0);
    let sin_t_sqrt_y = sin_t * sqrt(max(1.0 - y * y, 0.0));
    return max((cos_t * acos(y) - x * sin_t_sqrt_y) * sin2 + atan2(sin_t_sqrt_y, x), 0.0);
}

// A cone light (unit axis `axis`, half-angle `half`, radiance x solid angle `e`) on material `m`.
fn cone_light(m: Material, n: vec3<f32>, ng: vec3<f32>, wo: vec3<f32>, axis: vec3<f32>, half: f32, e: vec3<f32>) -> vec3<f32> {
    let cos_o = dot(n, wo);
    if cos_o <= 0.0 {
        return vec3<f32>(0.0);
    }
    let sin_h = sin(half);
    let cos_h = cos(half);
    let solid_angle = 2.0 * PI * (1.0 - cos_h);
    let radiance = e / max(solid_angle, 1e-30);
    let integral = cone_cosine_integral(dot(n, axis), sin_h * sin_h);
    if integral <= 0.0 {
        return vec3<f32>(0.0);
    }
    if m.albedo.a < 0.5 {
        return m.albedo.rgb / PI * radiance * integral;
    }
    // coupled diffuse at the cone's mean cosine over the surface
    let mean_cos = clamp(integral / max(solid_angle, 1e-30), 0.0, 1.0);
    let f0 = m.f0_roughness.rgb;
    var l = m.albedo.rgb * (vec3<f32>(1.0) - f0) * (28.0 / (23.0 * PI) * as_k(mean_cos) * as_k(cos_o)) * radiance * integral;
    let alpha = max(m.f0_roughness.a * m.f0_roughness.a, MIN_ALPHA);
    // A lobe as wide as the cone varies across it and meets the horizon inside it, which one
    // representative point cannot follow (a fully rough metal was 14 % off at 20 degrees): such lobes
    // integrate the cone by quadrature, sharper ones keep the point, a blend between.
    let quad = select(clamp(2.0 * alpha / half - 1.0, 0.0, 1.0), 0.0, half < 0.05);
    if quad > 0.0 {
        l += cone_specular_quadrature(m, n, ng, wo, axis, cos_h, e) * quad;
        if quad >= 1.0 {
            return l;
        }
    }
    let point = 1.0 - quad;
    // specular: the cone's direction closest to the mirror direction
    let r = reflect(-wo, n);
    var d = r;
    let c = dot(r, axis);
    if c < cos_h {
        let t = r - axis * c;
        let tl = length(t);
        d = select(axis, normalize(axis * cos_h + (t / max(tl, 1e-30)) * sin_h), tl > 1e-6);
    }
    let cos_i = dot(n, d);
    if cos_i <= 0.0 || dot(ng, d) <= 0.0 {
        return l;
    }
    // the lobe widened by the cone keeps its energy (Karis 2013's sphere-light normalization)
    let widened = min(alpha + 0.5 * tan(min(half, 1.5)), 1.0);
    let norm = (alpha / widened) * (alpha / widened);
    let hs = wo + d;
    let h = hs / max(length(hs), 1e-30);
    let g2 = 1.0 / (1.0 + ggx_lambda(cos_o, alpha) + ggx_lambda(cos_i, alpha));
    let spec = ggx_d(dot(n, h), alpha) * g2 / (4.0 * cos_o * cos_i);
    l += fresnel_schlick(f0, dot(wo, h)) * spec * cos_i * e * (norm * point);
    return l;
}

// The specular lobe over a cone (unit axis, cos of its half-angle, radiance x solid angle `e`)
// by a Fibonacci spiral of equal solid angles: deterministic, so frames do not flicker, and
// zero below the shading and the geometric horizon.
const CONE_QUADRATURE: u32 = 16u;
fn cone_specular_quadrature(m: Material, n: vec3<f32>, ng: vec3<f32>, wo: vec3<f32>, axis: vec3<f32>, cos_h: f32, e: vec3<f32>) -> vec3<f32> {
    let cos_o = dot(n, wo);
    let f0 = m.f0_roughness.rgb;
    let alpha = max(m.f0_roughness.a * m.f0_roughness.a, MIN_ALPHA);
    let helper = select(vec3<f32>(1.0, 0.0, 0.0), vec3<f32>(0.0, 1.0, 0.0), abs(axis.x) > 0.9);
    let t = normalize(cross(helper, axis));
    let b = cross(axis, t);
    var sum = vec3<f32>(0.0);
    for (var k = 0u; k < CONE_QUADRATURE; k++) {
        let c = 1.0 - (1.0 - cos_h) * (f32(k) + 0.5) / f32(CONE_QUADRATURE);
        let s = sqrt(max(1.0 - c * c, 0.0));
        let phi = f32(k) * 2.39996323;
        let d = axis * c + (t * cos(phi) + b * sin(phi)) * s;
        let cos_i = dot(n, d);
        if cos_i <= 0.0 || dot(ng, d) <= 0.0 {
            continue;
        }
        let hs = wo + d;
        let h = hs / max(length(hs), 1e-30);
        let g2 = 1.0 / (1.0 + ggx_lambda(cos_o, alpha) + ggx_lambda(cos_i, alpha));
        let spec = ggx_d(dot(n, h), alpha) * g2 / (4.0 * cos_o * cos_i);
        sum += fresnel_schlick(f0, dot(wo, h)) * (spec * cos_i);
    }
    return sum * e / f32(CONE_QUADRATURE);
}

@fragment
fn fs(@builtin(position) frag: vec4<f32>) -> @location(0) vec4<f32> {
    let pixel = vec2<i32>(frag.xy);
    let p = textureLoad(g_position, pixel, 0);
    if p.w < 0.0 {
        let dir = normalize(params.corner.xyz + params.right.xyz * frag.x + params.down.xyz * frag.y);
        return vec4<f32>(background_radiance(dir), 1.0);
    }
    let n4 = textureLoad(g_normal, pixel, 0);
    let ng4 = textureLoad(g_geometric_normal, pixel, 0);
    let m = material_at(materials[u32(p.w)], vec2<f32>(n4.w, ng4.w));
    let n = n4.xyz;
    let ng = ng4.xyz;
    // toward the viewer: to the eye, or (w = 0) along an orthographic view's axis
    let wo = normalize(params.eye.xyz - p.xyz * params.eye.w);
    // the G-buffer holds the sides a camera sees: a one-sided material's front, either side
    // of a double-sided one
    var l = select(vec3<f32>(0.0), m.emission.rgb, (params.counts.y & 2u) != 0u);
    for (var k = 0u; k < params.counts.x; k++) {
        let light = lights[k];
        var wi = light.position_or_direction.xyz;
        var e = light.value.rgb;
        let half = light.value.w;
        if light.position_or_direction.w < 0.5 && half > 1e-3 {
            // any part of the cone above the geometric surface lights it
            if dot(wi, ng) <= -sin(half) {
                continue;
            }
            let v = textureLoad(visibility, pixel, k, 0).r;
            l += cone_light(m, n, ng, wo, wi, half, e) * v;
            continue;
        }
        if light.position_or_direction.w > 0.5 {
            let d = wi - p.xyz;
            let d2 = max(dot(d, d), 1e-12);
            wi = d * inverseSqrt(d2);
            e = e / d2;
        }
        if dot(wi, ng) <= 0.0 {
            continue;
        }
        let v = textureLoad(visibility, pixel, k, 0).r;
        l += eval_brdf(m, n, wo, wi) * max(dot(n, wi), 0.0) * e * v;
    }
    if (params.counts.y & 1u) != 0u {
        // unclamped, as `ref-tracer`: a residual's irradiance is signed
        l += m.albedo.rgb * diffuse_weight(m) * sh9_irradiance(params.sh, n) / PI;
    }
    l += specular_ambient(m, n, wo);
    return vec4<f32>(l, 1.0);
}
