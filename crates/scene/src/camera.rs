//! A pinhole camera: look-at, horizontal field of view, image size in pixels.

use glam::Vec3;

/// A pinhole camera.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Camera {
    /// Eye position.
    pub eye: Vec3,
    /// Point looked at.
    pub target: Vec3,
    /// Up hint.
    pub up: Vec3,
    /// Horizontal field of view in degrees.
    pub hfov_degrees: f32,
    /// Image width in pixels.
    pub width: u32,
    /// Image height in pixels.
    pub height: u32,
}

impl Camera {
    /// Orthonormal basis (right, up, forward).
    #[must_use]
    pub fn basis(&self) -> (Vec3, Vec3, Vec3) {
        let forward = (self.target - self.eye).normalize();
        let right = forward.cross(self.up).normalize();
        let up = right.cross(forward);
        (right, up, forward)
    }

    /// Ray through image position (x, y) in pixels from the top-left corner (pixel centres at
    /// half-integers): (origin, unit direction).
    #[must_use]
    pub fn ray(&self, x: f32, y: f32) -> (Vec3, Vec3) {
        let (right, up, forward) = self.basis();
        let tan_half = (self.hfov_degrees.to_radians() * 0.5).tan();
        let sx = (2.0 * x / self.width as f32 - 1.0) * tan_half;
        let sy = (1.0 - 2.0 * y / self.height as f32) * tan_half * self.height as f32 / self.width as f32;
        (self.eye, (forward + right * sx + up * sy).normalize())
    }

    /// Angle subtended by one pixel at the image centre, radians.
    #[must_use]
    pub fn pixel_angle(&self) -> f32 {
        2.0 * (self.hfov_degrees.to_radians() * 0.5).tan() / self.width as f32
    }
}
