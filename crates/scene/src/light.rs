//! Distant lights: what a light *is*, shared by the extractor that finds them, the reference
//! tracer and the GPU renderers that draw them.

use glam::Vec3;
use std::f32::consts::TAU;

/// A distant circular area light: a cone of directions of constant radiance.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct DistantLight {
    /// Unit direction towards the light (the cone's axis).
    pub direction: Vec3,
    /// Solid angle of the cone, steradians, in (0, 4 pi].
    pub solid_angle: f32,
    /// Mean RGB radiance over the cone.
    pub radiance: Vec3,
}

impl DistantLight {
    /// cos of the cone's half-angle: 1 - solid_angle / (2 pi), in [-1, 1).
    #[must_use]
    pub fn cos_half_angle(&self) -> f32 {
        (1.0 - self.solid_angle / TAU).clamp(-1.0, 1.0)
    }

    /// The cone's half-angle, radians.
    #[must_use]
    pub fn half_angle(&self) -> f32 {
        self.cos_half_angle().acos()
    }

    /// Radiant intensity integrated over the cone: radiance x solid angle (W/m^2 per channel,
    /// the irradiance it gives a surface facing it).
    #[must_use]
    pub fn power(&self) -> Vec3 {
        self.radiance * self.solid_angle
    }

    /// A direction uniform in the cone from `u` in [0, 1)^2, and its pdf 1 / solid_angle.
    #[must_use]
    pub fn sample_direction(&self, u: glam::Vec2) -> (Vec3, f32) {
        let cos_max = self.cos_half_angle();
        let cos = 1.0 - u.x * (1.0 - cos_max);
        let sin = (1.0 - cos * cos).max(0.0).sqrt();
        let (s, c) = (TAU * u.y).sin_cos();
        let f = crate::brdf::Frame::new(self.direction.normalize());
        (f.to_world(Vec3::new(sin * c, sin * s, cos)).normalize(), 1.0 / self.solid_angle)
    }

    /// The integral of cos over the part of the cone above a surface whose normal is at
    /// `cos_theta` from the cone's axis: the irradiance per unit radiance it gives (π sin²α cos θ
    /// while the cone is wholly above the horizon; Snyder's closed form for a uniform sphere or
    /// disk light across it). The GPU shading pass evaluates the same (`crates/gpu/shaders/shade.wgsl`).
    #[must_use]
    pub fn cosine_integral(&self, cos_theta: f32) -> f32 {
        cone_cosine_integral(cos_theta, self.half_angle().min(std::f32::consts::FRAC_PI_2))
    }

    /// Whether `dir` (unit) lies in the cone.
    #[must_use]
    pub fn contains(&self, dir: Vec3) -> bool {
        dir.dot(self.direction) >= self.cos_half_angle()
    }
}

/// The integral of cos over the part of a cone of half-angle `half_angle` (at most pi/2) above
/// a surface whose normal is at `cos_theta` from the cone's axis; see
/// [`DistantLight::cosine_integral`].
#[must_use]
pub fn cone_cosine_integral(cos_theta: f32, half_angle: f32) -> f32 {
    let sin2 = half_angle.clamp(0.0, std::f32::consts::FRAC_PI_2).sin().powi(2);
    let c = cos_theta.clamp(-1.0, 1.0);
    if c * c > sin2 {
        return std::f32::consts::PI * sin2 * c.max(0.0);
    }
    if sin2 <= 0.0 {
        return 0.0;
    }
    let sin_t = (1.0 - c * c).max(1e-12).sqrt();
    let x = (1.0 / sin2 - 1.0).max(0.0).sqrt();
    let y = (-x * c / sin_t).clamp(-1.0, 1.0);
    let sin_t_sqrt_y = sin_t * (1.0 - y * y).max(0.0).sqrt();
    ((c * y.acos() - x * sin_t_sqrt_y) * sin2 + sin_t_sqrt_y.atan2(x)).max(0.0)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The integral by quadrature over the cone: (cos theta, phi) cell centres.
    fn quadrature(theta: f32, half: f32) -> f64 {
        let n = 400;
        let axis = glam::DVec3::new(f64::from(theta).sin(), 0.0, f64::from(theta).cos());
        let t = glam::DVec3::new(f64::from(theta).cos(), 0.0, -f64::from(theta).sin());
        let ch = f64::from(half).cos();
        let mut sum = 0.0;
        for i in 0..n {
            let c = 1.0 - (i as f64 + 0.5) / n as f64 * (1.0 - ch);
            let s = (1.0 - c * c).sqrt();
            for j in 0..n {
                let p = std::f64::consts::TAU * (j as f64 + 0.5) / n as f64;
                let d = axis * c + (t * p.cos() + glam::DVec3::Y * p.sin()) * s;
                sum += d.z.max(0.0);
            }
        }
        sum / f64::from(n * n) * std::f64::consts::TAU * (1.0 - ch)
    }

    #[test]
    fn cone_cosine_integral_matches_quadrature_across_the_horizon() {
        for half in [0.5f32, 5.0, 20.0, 45.0, 80.0, 90.0] {
            for theta in [0.0f32, 30.0, 60.0, 85.0, 90.0, 100.0, 130.0, 175.0] {
                let (h, t) = (half.to_radians(), theta.to_radians());
                let exact = cone_cosine_integral(t.cos(), h);
                let q = quadrature(t, h) as f32;
                assert!((exact - q).abs() < 1e-4 * (1.0 + q), "half {half}, theta {theta}: {exact} vs {q}");
                assert!(exact.is_finite() && exact >= 0.0);
            }
        }
    }
}
