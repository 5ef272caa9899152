//! The viewer's camera: an orbit about a target (yaw, pitch, distance), as model viewers have
//! it, turned into the `scene::Camera` the frame is drawn from.

use glam::Vec3;

/// An orbit camera: the eye on a sphere about `target`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct Orbit {
    /// The point looked at.
    pub target: Vec3,
    /// Turn about the vertical, radians (0: the eye on +Z of the target).
    pub yaw: f32,
    /// Elevation of the eye, radians (positive: above the target).
    pub pitch: f32,
    /// Eye to target, metres.
    pub distance: f32,
}

/// The pitch stays this far from the poles, where the view's up is undefined.
const PITCH_LIMIT: f32 = 1.55;

impl Orbit {
    /// The orbit through `camera`'s eye about its target.
    #[must_use]
    pub(crate) fn from_camera(camera: &scene::Camera) -> Self {
        let d = camera.eye - camera.target;
        let distance = d.length();
        if !(distance.is_finite() && distance > 0.0) {
            return Self { target: camera.target, yaw: 0.0, pitch: 0.0, distance: 1.0 };
        }
        let pitch = (d.y / distance).clamp(-1.0, 1.0).asin().clamp(-PITCH_LIMIT, PITCH_LIMIT);
        Self { target: camera.target, yaw: d.x.atan2(d.z), pitch, distance }
    }

    /// The eye's position.
    #[must_use]
    pub(crate) fn eye(&self) -> Vec3 {
        let (sy, cy) = self.yaw.sin_cos();
        let (sp, cp) = self.pitch.sin_cos();
        self.target + self.distance * Vec3::new(cp * sy, sp, cp * cy)
    }

    /// `camera` looking from this orbit (its field of view and size kept, +Y up).
    #[must_use]
    pub(crate) fn apply(&self, camera: &scene::Camera) -> scene::Camera {
        scene::Camera { eye: self.eye(), target: self.target, up: Vec3::Y, ..*camera }
    }

    /// Turns by `yaw` and `pitch` radians; the pitch stays off the poles.
    pub(crate) fn rotate(&mut self, yaw: f32, pitch: f32) {
        self.yaw = (self.yaw + yaw).rem_euclid(std::f32::consts::TAU);
        self.pitch = (self.pitch + pitch).clamp(-PITCH_LIMIT, PITCH_LIMIT);
    }

    /// Moves the target (and the eye with it) by `right` and `up` fractions of the distance,
    /// along the view's axes.
    pub(crate) fn pan(&mut self, right: f32, up: f32) {
        let forward = (self.target - self.eye()).normalize_or_zero();
        let r = forward.cross(Vec3::Y).normalize_or_zero();
        let u = r.cross(forward);
        self.target += self.distance * (right * r + up * u);
    }

    /// Moves the eye toward the target by `factor` of the distance (< 1: nearer), never through
    /// it nor to infinity.
    pub(crate) fn zoom(&mut self, factor: f32) {
        if factor.is_finite() && factor > 0.0 {
            self.distance = (self.distance * factor).clamp(1e-4, 1e7);
        }
    }

    /// The ground directions (x, z) of the view's right and forward, for moving an object with
    /// the keyboard as it is seen.
    #[must_use]
    pub(crate) fn ground_axes(&self) -> (Vec3, Vec3) {
        let (sy, cy) = self.yaw.sin_cos();
        (Vec3::new(cy, 0.0, -sy), Vec3::new(-sy, 0.0, -cy))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn camera(eye: Vec3, target: Vec3) -> scene::Camera {
        scene::Camera { eye, target, up: Vec3::Y, hfov_degrees: 60.0, width: 64, height: 48 }
    }

    #[test]
    fn an_orbit_from_a_camera_gives_back_its_eye() {
        for eye in [Vec3::new(0.0, 1.6, 4.0), Vec3::new(-3.0, 0.5, -2.0), Vec3::new(2.0, -1.0, 0.1)] {
            let target = Vec3::new(0.2, 0.3, -0.4);
            let o = Orbit::from_camera(&camera(eye, target));
            assert!(o.eye().distance(eye) < 1e-4, "{eye} -> {}", o.eye());
        }
    }

    #[test]
    fn a_full_turn_comes_back_and_the_pitch_stops_short_of_the_poles() {
        let mut o = Orbit::from_camera(&camera(Vec3::new(0.0, 1.0, 5.0), Vec3::ZERO));
        let start = o.eye();
        for _ in 0..8 {
            o.rotate(std::f32::consts::FRAC_PI_4, 0.0);
        }
        assert!(o.eye().distance(start) < 1e-4);
        o.rotate(0.0, 10.0);
        assert!(o.pitch <= PITCH_LIMIT && o.eye().is_finite());
        let view = o.apply(&camera(Vec3::ZERO, Vec3::ONE));
        let (r, u, f) = view.basis();
        assert!(r.is_finite() && u.is_finite() && f.is_finite());
    }

    #[test]
    fn pan_moves_eye_and_target_together_and_zoom_keeps_the_direction() {
        let mut o = Orbit::from_camera(&camera(Vec3::new(1.0, 2.0, 3.0), Vec3::ZERO));
        let (e0, t0) = (o.eye(), o.target);
        o.pan(0.1, -0.2);
        assert!(((o.eye() - o.target) - (e0 - t0)).length() < 1e-4);
        assert!(o.target.distance(t0) > 0.0);
        let dir = (o.eye() - o.target).normalize();
        o.zoom(0.5);
        assert!(((o.eye() - o.target).normalize() - dir).length() < 1e-5);
        for bad in [0.0, -1.0, f32::NAN, f32::INFINITY] {
            let d = o.distance;
            o.zoom(bad);
            assert_eq!(o.distance, d);
        }
    }

    #[test]
    fn the_ground_axes_are_the_views_right_and_forward_on_the_ground() {
        let o = Orbit::from_camera(&camera(Vec3::new(3.0, 2.0, -1.0), Vec3::ZERO));
        let view = o.apply(&camera(Vec3::ZERO, Vec3::ONE));
        let (r, _, f) = view.basis();
        let (gr, gf) = o.ground_axes();
        assert!((gr - Vec3::new(r.x, 0.0, r.z).normalize()).length() < 1e-4, "{gr} {r}");
        assert!((gf - Vec3::new(f.x, 0.0, f.z).normalize()).length() < 1e-4, "{gf} {f}");
    }
}
