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
    /// half-integers): (origin, unit direction). For many rays, [`Camera::rays`] precomputes.
    #[must_use]
    pub fn ray(&self, x: f32, y: f32) -> (Vec3, Vec3) {
        self.rays().ray(x, y)
    }

    /// The camera's basis and scales, precomputed for generating many rays.
    #[must_use]
    pub fn rays(&self) -> CameraRays {
        let (right, up, forward) = self.basis();
        let tan_half = (self.hfov_degrees.to_radians() * 0.5).tan();
        let (w, h) = (self.width as f32, self.height as f32);
        CameraRays {
            eye: self.eye,
            right: right * (2.0 * tan_half / w),
            down: up * (-2.0 * tan_half / w),
            corner: forward - right * tan_half + up * (tan_half * h / w),
        }
    }

    /// Where point `p` falls in the image, in pixels from the top-left corner (the inverse of
    /// [`Camera::ray`]); `None` behind the camera or not finite. Points outside the image
    /// give coordinates outside [0, width] x [0, height].
    #[must_use]
    pub fn project(&self, p: Vec3) -> Option<glam::Vec2> {
        let (right, up, forward) = self.basis();
        let v = p - self.eye;
        let z = v.dot(forward);
        if z.is_nan() || z <= 0.0 {
            return None;
        }
        let tan_half = (self.hfov_degrees.to_radians() * 0.5).tan();
        let (w, h) = (self.width as f32, self.height as f32);
        // the image plane at distance 1: x spans 2 tan_half over w pixels, square pixels
        let scale = w / (2.0 * tan_half);
        let xy = glam::Vec2::new(0.5 * w + v.dot(right) / z * scale, 0.5 * h - v.dot(up) / z * scale);
        xy.is_finite().then_some(xy)
    }

    /// Angle subtended by one pixel at the image centre, radians.
    #[must_use]
    pub fn pixel_angle(&self) -> f32 {
        2.0 * (self.hfov_degrees.to_radians() * 0.5).tan() / self.width as f32
    }
}

/// Precomputed ray generation of a [`Camera`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct CameraRays {
    /// ray origin
    pub eye: Vec3,
    /// image-plane step per pixel to the right
    pub right: Vec3,
    /// image-plane step per pixel down
    pub down: Vec3,
    /// image-plane point of pixel coordinate (0, 0), the top-left corner
    pub corner: Vec3,
}

impl CameraRays {
    /// As [`Camera::ray`].
    #[must_use]
    pub fn ray(&self, x: f32, y: f32) -> (Vec3, Vec3) {
        (self.eye, (self.corner + self.right * x + self.down * y).normalize())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn project_inverts_ray() {
        let camera = Camera {
            eye: Vec3::new(1.0, 2.0, -3.0),
            target: Vec3::new(0.5, 0.3, 2.0),
            up: Vec3::Y,
            hfov_degrees: 75.0,
            width: 160,
            height: 90,
        };
        let rays = camera.rays();
        for (x, y) in [(0.0, 0.0), (80.0, 45.0), (159.5, 0.5), (3.25, 88.0), (-20.0, 130.0)] {
            let (o, d) = rays.ray(x, y);
            for t in [0.01, 1.0, 250.0] {
                let xy = camera.project(o + d * t).unwrap();
                // f32 eye coordinates: a point 1 cm away is placed to a few thousandths of a pixel
                assert!((xy - glam::Vec2::new(x, y)).length() < 1e-2, "({x}, {y}) at {t}: {xy}");
            }
            assert!(camera.project(o - d).is_none(), "behind the camera");
        }
        assert!(camera.project(Vec3::NAN).is_none() && camera.project(camera.eye).is_none());
    }
}
