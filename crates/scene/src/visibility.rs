//! Ray queries against a scene's objects: what a solver, a hierarchy or a compositor asks, and
//! the caller answers with a ray tracer of its choice (`ref_tracer::SceneBvh` implements it).
//! A trait here, so that the crates that ask never depend on the tracer.

use glam::Vec3;

/// Ray queries against a set of objects (for a real scene, one object per patch).
pub trait Visibility: Send + Sync {
    /// True when something lies along the ray from `origin` along unit `dir` before `t_max`.
    fn occluded(&self, origin: Vec3, dir: Vec3, t_max: f32) -> bool;
    /// The object a ray from `origin` along unit `dir` hits first, and the distance.
    fn first_hit(&self, origin: Vec3, dir: Vec3) -> Option<(u32, f32)>;
    /// The distance to the first hit of a ray from `origin` along unit `dir` and the surface's
    /// shading normal there (what shading an object's own pixels needs).
    fn first_hit_normal(&self, origin: Vec3, dir: Vec3) -> Option<(f32, Vec3)>;
    /// A distance that moves a point off its surface (relative to the scene's size).
    fn epsilon(&self) -> f32;

    /// True when nothing blocks the segment between `a` and `b` (ends excluded, by
    /// [`Visibility::epsilon`] at each).
    fn clear(&self, a: Vec3, b: Vec3) -> bool {
        let d = b - a;
        let len = d.length();
        let eps = self.epsilon();
        if len <= 2.0 * eps {
            return true;
        }
        let dir = d / len;
        !self.occluded(a + dir * eps, dir, len - 2.0 * eps)
    }

    /// True when the ray from `origin` along unit `dir` leaves the scene.
    fn escapes(&self, origin: Vec3, dir: Vec3) -> bool {
        !self.occluded(origin, dir, f32::INFINITY)
    }
}
