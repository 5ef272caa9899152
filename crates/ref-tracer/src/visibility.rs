//! Ray-traced visibility of one light from given surface points: the exact shadow mask that
//! shadow-map techniques are measured against (same receivers, only visibility differs).

use crate::bvh::SceneBvh;
use glam::Vec3;
use rayon::prelude::*;

/// The light whose visibility is traced.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum VisibilityLight {
    /// A point light at this position.
    Point(Vec3),
    /// A distant light in this direction (towards the light).
    Distant(Vec3),
}

/// For each `(position, geometric normal)`, whether the light reaches it: `None` for points to
/// skip (`position` not finite), else a shadow ray from the point offset by the BVH's epsilon
/// along the normal turned towards the light.
#[must_use]
pub fn light_visibility(bvh: &SceneBvh, points: &[(Vec3, Vec3)], light: VisibilityLight) -> Vec<Option<bool>> {
    let eps = bvh.epsilon();
    points
        .par_iter()
        .map(|&(p, ng)| {
            if !p.is_finite() {
                return None;
            }
            let (dir, t_max) = match light {
                VisibilityLight::Point(l) => {
                    let d = l - p;
                    let len = d.length();
                    (d / len.max(1e-30), len)
                }
                VisibilityLight::Distant(d) => (d.normalize_or(Vec3::Y), f32::INFINITY),
            };
            let n = if ng.dot(dir) < 0.0 { -ng } else { ng };
            let origin = p + n * eps;
            let t_max = if t_max.is_finite() { (t_max - eps).max(0.0) } else { t_max };
            Some(!bvh.occluded(origin, dir, t_max))
        })
        .collect()
}
