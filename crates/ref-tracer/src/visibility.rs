//! Ray-traced visibility of one light from given surface points: the exact shadow mask that
//! shadow-map techniques are measured against (same receivers, only visibility differs).

use crate::bvh::SceneBvh;
use glam::Vec3;
use rayon::prelude::*;
use scene::LightShape;

/// For each `(position, geometric normal)`, whether the centre of `light` reaches it (its hard
/// shadow; [`area_light_visibility`] traces its whole extent): `None` for points to skip
/// (`position` not finite), else a shadow ray from the point offset by the BVH's epsilon along
/// the normal turned towards the light.
#[must_use]
pub fn light_visibility(bvh: &SceneBvh, points: &[(Vec3, Vec3)], light: LightShape) -> Vec<Option<bool>> {
    let eps = bvh.epsilon();
    points
        .par_iter()
        .map(|&(p, ng)| {
            if !p.is_finite() {
                return None;
            }
            let (dir, t_max) = match light {
                LightShape::Sphere { center, .. } => {
                    let d = center - p;
                    let len = d.length();
                    (d / len.max(1e-30), len)
                }
                LightShape::Distant { direction, .. } => (direction.normalize_or(Vec3::Y), f32::INFINITY),
            };
            let n = if ng.dot(dir) < 0.0 { -ng } else { ng };
            let origin = p + n * eps;
            let t_max = if t_max.is_finite() { (t_max - eps).max(0.0) } else { t_max };
            Some(!bvh.occluded(origin, dir, t_max))
        })
        .collect()
}

/// How [`area_light_visibility`] weighs the light's directions.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Weighting {
    /// Uniform in solid angle: the covered fraction of the light.
    Uniform,
    /// By the cosine to the normal: the fraction of a Lambertian receiver's irradiance from the
    /// light that arrives (what shading by `unshadowed irradiance x visibility` needs).
    Cosine,
}

/// For each `(position, geometric normal)`, the fraction of `light`'s cone of directions above
/// the surface (as seen from the point, uniform in solid angle) that reaches it unoccluded,
/// from `n` × `n` stratified directions (cell centres in (cos θ, φ), so the same points give
/// the same answer); `None` for points to skip. The normal is the side that is shaded (the
/// G-buffer's, facing the camera): directions below it are the surface's own horizon, which the
/// shading's cosine already removes, so they count neither way. A light wholly below the
/// surface gives `None` (nothing to shadow: the shading gives it nothing there); a point inside
/// a sphere light sees all of it. `weighting` weighs each direction uniformly or by its cosine to
/// the normal.
#[must_use]
pub fn area_light_visibility(
    bvh: &SceneBvh,
    points: &[(Vec3, Vec3)],
    light: LightShape,
    n: u32,
    weighting: Weighting,
) -> Vec<Option<f32>> {
    let eps = bvh.epsilon();
    let n = n.max(1);
    points
        .par_iter()
        .map(|&(p, ng)| {
            if !p.is_finite() {
                return None;
            }
            let (axis, cos_max, center_radius) = match light {
                LightShape::Distant { direction, half_angle } => {
                    (direction.normalize_or(Vec3::Y), half_angle.clamp(0.0, std::f32::consts::PI).cos(), None)
                }
                LightShape::Sphere { center, radius } => {
                    let d = center.distance(p);
                    if d <= radius {
                        return Some(1.0);
                    }
                    ((center - p) / d, (1.0 - (radius / d).powi(2)).max(0.0).sqrt(), Some((center, radius)))
                }
            };
            let frame = scene::brdf::Frame::new(axis);
            let (mut lit, mut above) = (0f32, 0f32);
            for i in 0..n {
                for j in 0..n {
                    let cos = 1.0 - (i as f32 + 0.5) / n as f32 * (1.0 - cos_max);
                    let sin = (1.0 - cos * cos).max(0.0).sqrt();
                    let (s, c) = (std::f32::consts::TAU * (j as f32 + 0.5) / n as f32).sin_cos();
                    let dir = frame.to_world(Vec3::new(sin * c, sin * s, cos)).normalize();
                    let t_max = center_radius.map_or(f32::INFINITY, |(c, r)| {
                        // nearest hit of the sphere: occluders beyond it do not count
                        let oc = c - p;
                        let b = oc.dot(dir);
                        (b - (b * b - oc.length_squared() + r * r).max(0.0).sqrt() - eps).max(0.0)
                    });
                    let cos = ng.dot(dir);
                    if cos <= 0.0 {
                        continue;
                    }
                    let w = match weighting {
                        Weighting::Uniform => 1.0,
                        Weighting::Cosine => cos,
                    };
                    above += w;
                    if !bvh.occluded(p + ng * eps, dir, t_max) {
                        lit += w;
                    }
                }
            }
            (above > 0.0).then(|| (lit / above).min(1.0))
        })
        .collect()
}

/// [`area_light_visibility`] with `coarse` × `coarse` directions everywhere, refined to `fine` ×
/// `fine` where the coarse estimate is partial or differs from a 4-neighbour's (the points are
/// an image `width` wide): penumbrae get the fine estimate at a fraction of its cost. A
/// penumbra narrower than a pixel that all coarse directions miss stays unrefined.
#[must_use]
pub fn area_light_visibility_refined(
    bvh: &SceneBvh,
    points: &[(Vec3, Vec3)],
    light: LightShape,
    width: usize,
    (coarse, fine): (u32, u32),
    weighting: Weighting,
) -> Vec<Option<f32>> {
    let mut out = area_light_visibility(bvh, points, light, coarse, weighting);
    let w = width.max(1);
    let h = out.len() / w;
    let refine: Vec<usize> = (0..out.len())
        .filter(|&k| {
            let Some(v) = out[k] else { return false };
            if v > 0.0 && v < 1.0 {
                return true;
            }
            let (x, y) = (k % w, k / w);
            [(x.wrapping_sub(1), y), (x + 1, y), (x, y.wrapping_sub(1)), (x, y + 1)]
                .into_iter()
                .filter(|&(nx, ny)| nx < w && ny < h)
                .any(|(nx, ny)| out[ny * w + nx].is_some_and(|u| u != v))
        })
        .collect();
    let subset: Vec<(Vec3, Vec3)> = refine.iter().map(|&k| points[k]).collect();
    for (k, v) in refine.into_iter().zip(area_light_visibility(bvh, &subset, light, fine, weighting)) {
        out[k] = v;
    }
    out
}

/// Fraction of the points with a `truth` value (from [`light_visibility`]) where the
/// thresholded visibility `mask` (`mask > 0.5` = lit) disagrees with it, and the number of
/// points compared.
#[must_use]
pub fn disagreement(mask: &[f32], truth: &[Option<bool>]) -> (f64, usize) {
    let (mut wrong, mut n) = (0usize, 0usize);
    for (m, t) in mask.iter().zip(truth) {
        if let Some(t) = t {
            n += 1;
            if (*m > 0.5) != *t {
                wrong += 1;
            }
        }
    }
    (if n == 0 { 0.0 } else { wrong as f64 / n as f64 }, n)
}
