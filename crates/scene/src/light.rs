//! What a light *is*, shared by the extractor that finds them, the reference tracer and the GPU
//! renderers that draw them: a distant cone ([`DistantLight`]) or a point or sphere
//! ([`PointLight`]), each with its power and colour, and the geometry both share
//! ([`LightShape`]: where a light is and how large, which is all a shadow needs). How a light is
//! drawn (a shading uniform, a shadow map's view) is derived from these where it is drawn.

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

/// A local light: a point (radius 0) or a uniformly emitting sphere around `position`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PointLight {
    /// Position (the sphere's centre), metres.
    pub position: Vec3,
    /// Radiant intensity, W/sr per channel. A uniform sphere gives a surface outside it, whose
    /// horizon it does not cross, the irradiance of a point of this intensity at its centre.
    pub intensity: Vec3,
    /// Radius of the emitting sphere, metres; 0 is a point light (hard shadows).
    pub radius: f32,
}

impl PointLight {
    /// A point light (radius 0).
    #[must_use]
    pub fn point(position: Vec3, intensity: Vec3) -> Self {
        Self { position, intensity, radius: 0.0 }
    }
}

/// A light's geometry, without its colour: where it is and how large. Shadows need only this;
/// every shadow technique and the traced truths take it.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum LightShape {
    /// A distant cone light (the extracted lights): the disk is the cone's cross-section.
    Distant {
        /// Unit direction towards the light (the cone's axis).
        direction: Vec3,
        /// Half-angle of the cone, radians; 0 is a directional light.
        half_angle: f32,
    },
    /// A local spherical light; radius 0 is a point light.
    Sphere {
        /// Centre, metres.
        center: Vec3,
        /// Radius, metres.
        radius: f32,
    },
}

impl LightShape {
    /// The largest half-angle shadow techniques accept: wider cones are clamped to it (a cone
    /// of 90 degrees or more has no disk cross-section).
    pub const MAX_HALF_ANGLE: f32 = 1.5;

    /// A point light at `center` (a sphere of radius 0).
    #[must_use]
    pub fn point(center: Vec3) -> Self {
        LightShape::Sphere { center, radius: 0.0 }
    }

    /// A directional light towards `direction` (a cone of half-angle 0).
    #[must_use]
    pub fn directional(direction: Vec3) -> Self {
        LightShape::Distant { direction, half_angle: 0.0 }
    }

    /// Half-angle the light subtends from `p` (0 for a point light; pi/2 inside a sphere light).
    #[must_use]
    pub fn half_angle_at(&self, p: Vec3) -> f32 {
        match *self {
            LightShape::Distant { half_angle, .. } => half_angle.clamp(0.0, Self::MAX_HALF_ANGLE),
            LightShape::Sphere { center, radius } => {
                let d = center.distance(p);
                if d <= radius { std::f32::consts::FRAC_PI_2 } else { (radius / d).asin() }
            }
        }
    }

    /// Unit direction from `p` to the light's centre.
    #[must_use]
    pub fn direction_from(&self, p: Vec3) -> Vec3 {
        match *self {
            LightShape::Distant { direction, .. } => direction.normalize_or(Vec3::Y),
            LightShape::Sphere { center, .. } => (center - p).normalize_or(Vec3::Y),
        }
    }

    /// Whether any part of the light is above the plane of a surface at `p` with normal `n`.
    #[must_use]
    pub fn reaches(&self, p: Vec3, n: Vec3) -> bool {
        let d = self.direction_from(p);
        n.dot(d) > -self.half_angle_at(p).sin()
    }
}

impl From<&DistantLight> for LightShape {
    fn from(l: &DistantLight) -> Self {
        LightShape::Distant { direction: l.direction.normalize_or(Vec3::Y), half_angle: l.half_angle() }
    }
}

impl From<&PointLight> for LightShape {
    fn from(l: &PointLight) -> Self {
        LightShape::Sphere { center: l.position, radius: l.radius.max(0.0) }
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
