//! The one BRDF of the toolkit, written once here; the GPU shaders mirror it and are tested
//! against it.
//!
//! Without a specular layer, f = albedo / pi (Lambert). With one,
//! f = f_diffuse + D(h) G2(wo, wi) F(wo . h) / (4 cos_o cos_i): the GGX (Trowbridge-Reitz)
//! distribution (alpha = roughness^2), the height-correlated Smith G2 and Schlick's Fresnel, over
//! Ashikhmin and Shirley's coupled diffuse term
//! f_diffuse = 28 albedo / (23 pi) (1 - F0) (1 - (1 - cos_i / 2)^5) (1 - (1 - cos_o / 2)^5),
//! which is reciprocal and gives up at grazing angles the energy the specular layer takes (a plain
//! sum reflects more than it receives there; a test checks). Directions are unit vectors in a
//! local frame with the normal along +Z (`Frame` converts).
//!
//! Sampling comes as `sample_brdf` / `brdf_pdf` pairs: the lobe is chosen with a fixed
//! probability from the material, the diffuse lobe by cosine-weighted hemisphere sampling, the
//! specular lobe by sampling GGX visible normals (Heitz 2018).

use crate::Material;
use glam::{Vec2, Vec3};
use std::f32::consts::{FRAC_1_PI, PI, TAU};

/// An orthonormal frame around a unit normal (Duff et al. 2017, branchless).
#[derive(Clone, Copy, Debug)]
pub struct Frame {
    /// Tangent.
    pub t: Vec3,
    /// Bitangent.
    pub b: Vec3,
    /// Normal.
    pub n: Vec3,
}

impl Frame {
    /// The frame of unit normal `n`.
    #[must_use]
    pub fn new(n: Vec3) -> Self {
        let sign = 1.0f32.copysign(n.z);
        let a = -1.0 / (sign + n.z);
        let b = n.x * n.y * a;
        Self {
            t: Vec3::new(1.0 + sign * n.x * n.x * a, sign * b, -sign * n.x),
            b: Vec3::new(b, sign + n.y * n.y * a, -n.y),
            n,
        }
    }

    /// World to local.
    #[must_use]
    pub fn to_local(&self, v: Vec3) -> Vec3 {
        Vec3::new(v.dot(self.t), v.dot(self.b), v.dot(self.n))
    }

    /// Local to world.
    #[must_use]
    pub fn to_world(&self, v: Vec3) -> Vec3 {
        self.t * v.x + self.b * v.y + self.n * v.z
    }
}

/// Smallest alpha used: keeps D finite for roughness 0.
const MIN_ALPHA: f32 = 1e-3;

fn alpha(roughness: f32) -> f32 {
    (roughness * roughness).max(MIN_ALPHA)
}

/// GGX normal distribution D(h) for local half vector `h`.
#[must_use]
pub fn ggx_d(h: Vec3, alpha: f32) -> f32 {
    let a2 = alpha * alpha;
    let c2 = h.z * h.z;
    let d = c2 * (a2 - 1.0) + 1.0;
    a2 / (PI * d * d)
}

/// Smith Lambda for GGX.
fn ggx_lambda(w: Vec3, alpha: f32) -> f32 {
    let c2 = w.z * w.z;
    if c2 <= 0.0 {
        return f32::INFINITY;
    }
    let tan2 = ((1.0 - c2) / c2).max(0.0);
    0.5 * (-1.0 + (1.0 + alpha * alpha * tan2).sqrt())
}

/// Smith masking G1.
#[must_use]
pub fn ggx_g1(w: Vec3, alpha: f32) -> f32 {
    1.0 / (1.0 + ggx_lambda(w, alpha))
}

/// Height-correlated Smith masking-shadowing G2.
#[must_use]
pub fn ggx_g2(wo: Vec3, wi: Vec3, alpha: f32) -> f32 {
    1.0 / (1.0 + ggx_lambda(wo, alpha) + ggx_lambda(wi, alpha))
}

/// Schlick's Fresnel.
#[must_use]
pub fn fresnel_schlick(f0: Vec3, cos: f32) -> Vec3 {
    let m = (1.0 - cos.clamp(0.0, 1.0)).powi(5);
    f0 + (Vec3::ONE - f0) * m
}

impl Material {
    /// Approximate share of the albedo the diffuse lobe reflects: 1 without a specular layer,
    /// 1 - max(F0) with one. Used to choose lobes and to light the diffuse lobe with ambient
    /// irradiance.
    #[must_use]
    pub fn diffuse_weight(&self) -> f32 {
        self.specular.map_or(1.0, |g| 1.0 - g.f0.max_element().clamp(0.0, 1.0))
    }

    /// The diffuse lobe's value for local directions (both above the surface).
    #[must_use]
    pub fn eval_diffuse(&self, wo: Vec3, wi: Vec3) -> Vec3 {
        match self.specular {
            None => self.albedo * FRAC_1_PI,
            Some(g) => {
                let k = |c: f32| 1.0 - (1.0 - 0.5 * c).powi(5);
                self.albedo * (Vec3::ONE - g.f0) * (28.0 / (23.0 * PI) * k(wi.z) * k(wo.z))
            }
        }
    }

    /// Probability of sampling the specular lobe.
    #[must_use]
    pub fn specular_probability(&self) -> f32 {
        match self.specular {
            None => 0.0,
            Some(g) => {
                let s = g.f0.max_element();
                let d = self.diffuse_weight() * self.albedo.max_element();
                (s / (s + d).max(1e-6)).clamp(0.1, 0.9)
            }
        }
    }

    /// BRDF value for local unit directions (normal +Z); zero below the surface.
    #[must_use]
    pub fn eval_brdf(&self, wo: Vec3, wi: Vec3) -> Vec3 {
        if wo.z <= 0.0 || wi.z <= 0.0 {
            return Vec3::ZERO;
        }
        self.eval_diffuse(wo, wi) + self.eval_specular(wo, wi)
    }

    /// The specular (GGX) lobe's value for local directions (both above the surface); zero
    /// without a specular layer.
    #[must_use]
    pub fn eval_specular(&self, wo: Vec3, wi: Vec3) -> Vec3 {
        let Some(g) = self.specular else { return Vec3::ZERO };
        let a = alpha(g.roughness);
        let h = (wo + wi).normalize_or_zero();
        if h == Vec3::ZERO {
            return Vec3::ZERO;
        }
        fresnel_schlick(g.f0, wo.dot(h)) * (ggx_d(h, a) * ggx_g2(wo, wi, a) / (4.0 * wo.z * wi.z))
    }

    /// Density (solid angle) with which [`Material::sample_brdf`] returns `wi`.
    #[must_use]
    pub fn brdf_pdf(&self, wo: Vec3, wi: Vec3) -> f32 {
        if wo.z <= 0.0 || wi.z <= 0.0 {
            return 0.0;
        }
        let ps = self.specular_probability();
        let mut pdf = (1.0 - ps) * wi.z * FRAC_1_PI;
        if let Some(g) = self.specular {
            let a = alpha(g.roughness);
            let h = (wo + wi).normalize_or_zero();
            if h != Vec3::ZERO {
                // visible-normal pdf D_wo(h) / (4 wo.h) = G1(wo) D(h) / (4 wo.z)
                pdf += ps * ggx_g1(wo, a) * ggx_d(h, a) / (4.0 * wo.z);
            }
        }
        pdf
    }

    /// Samples an incident direction for outgoing `wo` (local) from `u` in [0, 1)^2 and `u_lobe`
    /// in [0, 1). Returns the direction and its pdf, or `None` when it falls below the surface.
    #[must_use]
    pub fn sample_brdf(&self, wo: Vec3, u: Vec2, u_lobe: f32) -> Option<(Vec3, f32)> {
        if wo.z <= 0.0 {
            return None;
        }
        let wi = match self.specular {
            Some(g) if u_lobe < self.specular_probability() => {
                let h = sample_ggx_vndf(wo, alpha(g.roughness), u);
                2.0 * wo.dot(h) * h - wo
            }
            _ => sample_cosine_hemisphere(u),
        };
        if wi.z <= 0.0 {
            return None;
        }
        let pdf = self.brdf_pdf(wo, wi);
        (pdf > 0.0).then_some((wi, pdf))
    }
}

/// Cosine-weighted direction on the +Z hemisphere (pdf cos theta / pi).
#[must_use]
pub fn sample_cosine_hemisphere(u: Vec2) -> Vec3 {
    let r = u.x.sqrt();
    let (s, c) = (TAU * u.y).sin_cos();
    Vec3::new(r * c, r * s, (1.0 - u.x).max(0.0).sqrt())
}

/// A GGX visible normal for local `wo` (Heitz 2018, "Sampling the GGX Distribution of Visible
/// Normals").
#[must_use]
pub fn sample_ggx_vndf(wo: Vec3, alpha: f32, u: Vec2) -> Vec3 {
    let vh = Vec3::new(alpha * wo.x, alpha * wo.y, wo.z).normalize();
    let lensq = vh.x * vh.x + vh.y * vh.y;
    let t1 = if lensq > 0.0 { Vec3::new(-vh.y, vh.x, 0.0) / lensq.sqrt() } else { Vec3::X };
    let t2 = vh.cross(t1);
    let r = u.x.sqrt();
    let (s, c) = (TAU * u.y).sin_cos();
    let p1 = r * c;
    let blend = 0.5 * (1.0 + vh.z);
    let p2 = (1.0 - blend) * (1.0 - p1 * p1).max(0.0).sqrt() + blend * r * s;
    let nh = t1 * p1 + t2 * p2 + vh * (1.0 - p1 * p1 - p2 * p2).max(0.0).sqrt();
    Vec3::new(alpha * nh.x, alpha * nh.y, nh.z.max(1e-6)).normalize()
}
