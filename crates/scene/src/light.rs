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

    /// Whether `dir` (unit) lies in the cone.
    #[must_use]
    pub fn contains(&self, dir: Vec3) -> bool {
        dir.dot(self.direction) >= self.cos_half_angle()
    }
}
