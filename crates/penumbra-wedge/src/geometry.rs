//! What the GPU draws for one light: the hard shadow volume from the light's centre and one
//! conservative footprint per wedge, both built on the CPU from a [`Silhouette`].
//!
//! The volume is closed and wound outward (a test checks its signed volume), extruded a finite
//! `extent` beyond every caster and receiver so that no far plane cuts it: z-fail counting then
//! holds with the camera inside it. A wedge (the points from which its edge overlaps the light)
//! lies in the convex hull of the two endpoint cones (a convex combination argument), each
//! bounded by a pyramid on a circumscribed octagon; its footprint is the 2-D convex hull of
//! those 18 points on the screen (all of the screen when a point is behind the eye).

use crate::casters::Silhouette;
use glam::{Mat4, Vec2, Vec3, Vec4Swizzles};
use gpu::LightShape;

/// Where `x` goes when extruded away from the light's centre by `extent`; `None` for a point
/// at the centre of a local light.
#[must_use]
pub fn extrude(x: Vec3, light: &LightShape, extent: f32) -> Option<Vec3> {
    match *light {
        LightShape::Distant { direction, .. } => Some(x - direction.normalize_or(Vec3::Y) * extent),
        LightShape::Sphere { center, .. } => {
            let d = x - center;
            let len = d.length();
            (len > 1e-12 * extent.max(1.0) && len.is_finite()).then(|| x + d / len * extent)
        }
    }
}

/// The hard shadow volume of `sil` from `light`'s centre: front cap (the lit faces), dark cap
/// (them extruded by `extent`, reversed) and a quad per silhouette edge, wound outward.
#[must_use]
pub fn shadow_volume(sil: &Silhouette, light: &LightShape, extent: f32) -> Vec<[Vec3; 3]> {
    let mut out = Vec::with_capacity(2 * sil.lit_faces.len() + 2 * sil.edges.len());
    for &[a, b, c] in &sil.lit_faces {
        let (Some(a2), Some(b2), Some(c2)) =
            (extrude(a, light, extent), extrude(b, light, extent), extrude(c, light, extent))
        else {
            continue;
        };
        out.push([a, b, c]);
        out.push([c2, b2, a2]);
    }
    for &[a, b] in &sil.edges {
        let (Some(a2), Some(b2)) = (extrude(a, light, extent), extrude(b, light, extent)) else { continue };
        out.push([a, a2, b2]);
        out.push([a, b2, b]);
    }
    out
}

/// The interval of t >= 0 where `origin + axis t` lies in the box `(lo, hi)` (slab test),
/// `None` when the ray misses it.
#[must_use]
pub fn box_interval(origin: Vec3, axis: Vec3, (lo, hi): (Vec3, Vec3)) -> Option<(f32, f32)> {
    let (mut t0, mut t1) = (0.0f32, f32::INFINITY);
    for k in 0..3 {
        if axis[k].abs() < 1e-20 {
            if origin[k] < lo[k] || origin[k] > hi[k] {
                return None;
            }
        } else {
            let (a, b) = ((lo[k] - origin[k]) / axis[k], (hi[k] - origin[k]) / axis[k]);
            t0 = t0.max(a.min(b));
            t1 = t1.min(a.max(b));
        }
    }
    (t0 <= t1).then_some((t0, t1))
}

/// Where a ray `origin + axis t` (t >= 0) leaves the box: the largest t inside it, `None` when
/// it never enters.
#[must_use]
pub fn box_exit(origin: Vec3, axis: Vec3, bounds: (Vec3, Vec3)) -> Option<f32> {
    box_interval(origin, axis, bounds).map(|(_, t1)| t1)
}

/// How far along `axis` a cone of half-angle tangent `tan` from any apex within `radius` of
/// `centre` can still meet the box `receivers`, at most `extent`: a point of the cone at axial
/// distance t lies within t tan of the axis, so its axis point lies in the box grown by that;
/// iterating the exit parameter of the grown box from `extent` down stays conservative.
/// `None` when it cannot meet the box at all.
#[must_use]
pub fn reach_along(
    centre: Vec3,
    radius: f32,
    axis: Vec3,
    tan: f32,
    receivers: (Vec3, Vec3),
    extent: f32,
) -> Option<f32> {
    let mut l = extent;
    for _ in 0..4 {
        let grow = Vec3::splat(radius + l * tan);
        let exit = box_exit(centre, axis, (receivers.0 - grow, receivers.1 + grow))?;
        if exit >= l {
            break;
        }
        l = exit;
    }
    Some(l.max(0.0))
}

/// The 18 points whose convex hull contains edge `[v0, v1]`'s wedge out to `extent`, or `None`
/// when an endpoint is within the light (a local light's edge that close is skipped). With
/// `receivers`, a distant light's wedge stops where it can no longer meet them (`None` when it
/// cannot meet them at all).
#[must_use]
pub fn wedge_hull_points(
    v0: Vec3,
    v1: Vec3,
    light: &LightShape,
    extent: f32,
    receivers: Option<(Vec3, Vec3)>,
) -> Option<Vec<Vec3>> {
    // (apex, axis away from the light, half-angle, axial length)
    let cones: [(Vec3, Vec3, f32, f32); 2] = match *light {
        LightShape::Distant { direction, half_angle } => {
            let a = -direction.normalize_or(Vec3::Y);
            let h = half_angle.clamp(0.0, LightShape::MAX_HALF_ANGLE);
            // one length for both cones, from the edge's bounding sphere (the convexity
            // argument needs equal lengths; a bound at the endpoints alone would not hold inside)
            let len = receivers.map_or(Some(extent), |rb| {
                reach_along(0.5 * (v0 + v1), 0.5 * v0.distance(v1), a, h.tan(), rb, extent)
            })?;
            [(v0, a, h, len), (v1, a, h, len)]
        }
        LightShape::Sphere { center, radius } => {
            let (d0, d1) = (v0.distance(center), v1.distance(center));
            let near = d0.min(d1) - radius;
            if near.is_nan() || near <= 1e-4 * radius.max(1e-12) {
                return None;
            }
            // the same ray parameter t for both endpoints (the convexity argument needs it):
            // t (|v - c| + r) reaches `extent` from the nearer endpoint's slowest ray
            let t = extent / near;
            let cone = |v: Vec3| {
                let d = v.distance(center);
                (v, (v - center) / d, (radius / d).min(1.0).asin(), t * (d + radius))
            };
            [cone(v0), cone(v1)]
        }
    };
    let mut pts = Vec::with_capacity(18);
    let circumscribe = 1.0 / (std::f32::consts::PI / 8.0).cos();
    for (apex, axis, half, len) in cones {
        pts.push(apex);
        let (e1, e2) = axis.any_orthonormal_pair();
        let r = len * half.min(LightShape::MAX_HALF_ANGLE).tan() * circumscribe;
        for k in 0..8 {
            let (s, c) = (k as f32 * std::f32::consts::FRAC_PI_4).sin_cos();
            pts.push(apex + axis * len + (e1 * c + e2 * s) * r);
        }
    }
    pts.iter().all(|p| p.is_finite()).then_some(pts)
}

/// Whether the boxes `(lo, hi)` and the points' bounds overlap.
#[must_use]
pub fn points_meet_box(points: &[Vec3], (lo, hi): (Vec3, Vec3)) -> bool {
    let (plo, phi) = points
        .iter()
        .fold((Vec3::splat(f32::INFINITY), Vec3::splat(f32::NEG_INFINITY)), |(a, b), p| (a.min(*p), b.max(*p)));
    plo.cmple(hi).all() && phi.cmpge(lo).all()
}

/// The screen footprint (NDC triangles) of the convex hull of `points` under `view_proj`,
/// clipped to view depths of at least `near` (no receiver is nearer) and to the screen with a
/// margin ([`SCREEN_MARGIN`]); nothing when it lies off screen or behind the eye. Clipping a
/// convex hull by a plane keeps the points in front and the crossings of every segment between
/// a point in front and one behind.
#[must_use]
pub fn footprint(points: &[Vec3], view_proj: &Mat4, near: f32) -> Vec<[Vec2; 3]> {
    let clip: Vec<glam::Vec4> = points.iter().map(|p| *view_proj * p.extend(1.0)).collect();
    let (front, back): (Vec<glam::Vec4>, Vec<glam::Vec4>) = clip.iter().partition(|c| c.w >= near);
    let mut ndc: Vec<Vec2> = front.iter().map(|c| c.xy() / c.w).collect();
    for f in &front {
        for b in &back {
            let t = (f.w - near) / (f.w - b.w);
            let c = *f + (*b - *f) * t;
            ndc.push(c.xy() / near);
        }
    }
    let hull = clip_to_screen(&convex_hull(ndc));
    if hull.len() < 3 {
        return Vec::new();
    }
    (1..hull.len() - 1).map(|k| [hull[0], hull[k], hull[k + 1]]).collect()
}

/// How far past the screen's edges ([-1, 1]² in NDC) footprints are clipped: a hull whose
/// near-plane crossings project to NDC of 1e7 and more meets the screen's edges after rounding
/// errors of that size's ulps, which lost whole rows of border pixels before (a compute-path
/// test found them); the margin keeps such rounding off screen. Pixels are not drawn twice.
pub const SCREEN_MARGIN: f32 = 0.05;

/// A convex polygon clipped to the screen square widened by [`SCREEN_MARGIN`]
/// (Sutherland-Hodgman, in f64: the crossings of huge coordinates keep their precision).
fn clip_to_screen(poly: &[Vec2]) -> Vec<Vec2> {
    let mut out: Vec<glam::DVec2> = poly.iter().map(|p| p.as_dvec2()).collect();
    let edge = 1.0 + f64::from(SCREEN_MARGIN);
    for (axis, sign) in [(0, 1.0f64), (0, -1.0), (1, 1.0), (1, -1.0)] {
        if out.is_empty() {
            break;
        }
        // keep sign * p[axis] <= edge
        let inside = |p: glam::DVec2| sign * p[axis] <= edge;
        let input = std::mem::take(&mut out);
        for k in 0..input.len() {
            let (a, b) = (input[k], input[(k + 1) % input.len()]);
            if inside(a) {
                out.push(a);
            }
            if inside(a) != inside(b) {
                let t = (sign * edge - a[axis]) / (b[axis] - a[axis]);
                out.push(a + (b - a) * t);
            }
        }
    }
    out.into_iter().map(|p| p.as_vec2()).collect()
}

/// Silhouette edges ordered into chains (each edge's end is the next one's start where the
/// silhouette continues), so that neighbouring edges can share one footprint: indices into
/// `edges`.
#[must_use]
pub fn chains(edges: &[[Vec3; 2]]) -> Vec<Vec<usize>> {
    let key = |p: Vec3| [p.x.to_bits(), p.y.to_bits(), p.z.to_bits()];
    let mut by_start: std::collections::HashMap<[u32; 3], Vec<usize>> = std::collections::HashMap::new();
    for (k, e) in edges.iter().enumerate() {
        by_start.entry(key(e[0])).or_default().push(k);
    }
    let mut used = vec![false; edges.len()];
    let mut out = Vec::new();
    for first in 0..edges.len() {
        if used[first] {
            continue;
        }
        let mut chain = Vec::new();
        let mut k = first;
        loop {
            used[k] = true;
            chain.push(k);
            let next = by_start.get(&key(edges[k][1])).and_then(|c| c.iter().copied().find(|&j| !used[j]));
            match next {
                Some(j) => k = j,
                None => break,
            }
        }
        out.push(chain);
    }
    out
}

/// Andrew's monotone chain: the convex hull of `pts`, counter-clockwise, without collinear
/// points.
#[must_use]
pub fn convex_hull(mut pts: Vec<Vec2>) -> Vec<Vec2> {
    pts.retain(|p| p.is_finite());
    pts.sort_by(|a, b| a.x.total_cmp(&b.x).then(a.y.total_cmp(&b.y)));
    pts.dedup();
    if pts.len() < 3 {
        return pts;
    }
    let cross = |o: Vec2, a: Vec2, b: Vec2| (a - o).perp_dot(b - o);
    let mut hull: Vec<Vec2> = Vec::with_capacity(2 * pts.len());
    for pass in 0..2 {
        let start = hull.len();
        let iter: Box<dyn Iterator<Item = &Vec2>> =
            if pass == 0 { Box::new(pts.iter()) } else { Box::new(pts.iter().rev()) };
        for &p in iter {
            while hull.len() >= start + 2 && cross(hull[hull.len() - 2], hull[hull.len() - 1], p) <= 0.0 {
                hull.pop();
            }
            hull.push(p);
        }
        hull.pop();
    }
    hull
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::casters::{Caster, Casters};

    fn signed_volume(tris: &[[Vec3; 3]]) -> f32 {
        tris.iter().map(|[a, b, c]| a.dot(b.cross(*c)) / 6.0).sum()
    }

    #[test]
    fn volume_is_closed_and_wound_outward() {
        let m = scene::Mesh::cuboid(Vec3::ZERO, Vec3::ONE);
        let casters = Casters { casters: vec![Caster::new("box", &m.positions, &m.indices)] };
        let d = Vec3::new(0.3, 1.0, 0.2).normalize();
        let light = LightShape::Distant { direction: d, half_angle: 0.05 };
        let sil = casters.silhouette(&light, |_| true);
        let extent = 10.0;
        let v = signed_volume(&shadow_volume(&sil, &light, extent));
        // a prism: the box's cross-section seen along d times the extent, plus part of the box
        let section: f32 = sil.edges.iter().map(|[a, b]| a.cross(*b).dot(d) / 2.0).sum();
        assert!(section > 0.0);
        assert!((v - section * extent).abs() <= 1.0 + 1e-3, "volume {v}, prism {}", section * extent);
    }

    #[test]
    fn cube_silhouette_is_one_closed_chain() {
        let m = scene::Mesh::cuboid(Vec3::ZERO, Vec3::ONE);
        let casters = Casters { casters: vec![Caster::new("box", &m.positions, &m.indices)] };
        let light = LightShape::Distant { direction: Vec3::new(0.3, 1.0, 0.2).normalize(), half_angle: 0.05 };
        let sil = casters.silhouette(&light, |_| true);
        let c = chains(&sil.edges);
        assert_eq!(c.len(), 1);
        assert_eq!(c[0].len(), sil.edges.len());
        for k in 0..c[0].len() {
            let (e, next) = (sil.edges[c[0][k]], sil.edges[c[0][(k + 1) % c[0].len()]]);
            assert_eq!(e[1], next[0], "edge {k} ends where the next starts");
        }
    }

    #[test]
    fn footprint_behind_the_eye_is_clipped_not_the_whole_screen() {
        let camera = scene::Camera {
            eye: Vec3::new(0.0, 1.0, 5.0),
            target: Vec3::ZERO,
            up: Vec3::Y,
            hfov_degrees: 60.0,
            width: 64,
            height: 48,
        };
        let vp = gpu::view_projection_infinite(&camera, 0.01);
        // a thin slab from in front of the eye to behind it, off to the left
        let pts = [
            Vec3::new(-1.5, 0.0, 0.0),
            Vec3::new(-1.5, 0.2, 0.0),
            Vec3::new(-1.5, 0.0, 10.0),
            Vec3::new(-1.5, 0.2, 10.0),
        ];
        let tris = footprint(&pts, &vp, 0.01);
        let area: f32 = tris.iter().map(|t| 0.5 * (t[1] - t[0]).perp_dot(t[2] - t[0]).abs()).sum();
        assert!(area > 0.0 && area < 2.0, "area {area} of the screen's 4");
        for t in &tris {
            for v in t {
                assert!(v.x <= -0.0 && v.abs().max_element() <= 1.0 + SCREEN_MARGIN + 1e-5, "{v}");
            }
        }
        // wholly behind the eye: nothing
        let behind: Vec<Vec3> = pts.iter().map(|p| *p + Vec3::Z * 20.0).collect();
        assert!(footprint(&behind, &vp, 0.01).is_empty());
    }

    #[test]
    fn hull_is_counter_clockwise_and_convex() {
        let pts = vec![Vec2::ZERO, Vec2::X, Vec2::Y, Vec2::ONE, Vec2::splat(0.5), Vec2::new(0.5, 0.0)];
        let h = convex_hull(pts);
        assert_eq!(h.len(), 4);
        let area: f32 = (0..h.len()).map(|k| h[k].perp_dot(h[(k + 1) % h.len()])).sum::<f32>() / 2.0;
        assert!((area - 1.0).abs() < 1e-6);
    }

    #[test]
    fn wedge_hull_contains_every_point_whose_view_of_the_edge_meets_the_light() {
        let (v0, v1) = (Vec3::new(-0.5, 1.0, 0.0), Vec3::new(0.7, 1.2, 0.3));
        let lights = [
            LightShape::Distant { direction: Vec3::new(0.2, 1.0, -0.1).normalize(), half_angle: 0.3 },
            LightShape::Sphere { center: Vec3::new(0.5, 4.0, 0.5), radius: 0.8 },
        ];
        for light in lights {
            let pts = wedge_hull_points(v0, v1, &light, 20.0, None).expect("outside the light");
            // random points p: where an edge point x seen from p lies within the light, p must
            // be inside the hull (checked against its faces by a 3-D support test per
            // direction: p's projection on any direction does not exceed the hull's)
            let mut state = 7u32;
            let mut rnd = || {
                state = state.wrapping_mul(747_796_405).wrapping_add(2_891_336_453);
                (state >> 8) as f32 / (1u32 << 24) as f32
            };
            let mut checked = 0;
            for _ in 0..4000 {
                let p = Vec3::new(rnd() * 8.0 - 4.0, rnd() * 3.0 - 2.0, rnd() * 8.0 - 4.0);
                let x = v0 + (v1 - v0) * rnd();
                let dir = (x - p).normalize();
                let inside = dir.dot(light.direction_from(p)) >= light.half_angle_at(p).cos();
                if !inside || (x - p).length() > 10.0 {
                    continue;
                }
                checked += 1;
                for k in 0..64 {
                    let (s, c) = (k as f32 * 0.7).sin_cos();
                    let n = Vec3::new(c * (k as f32 * 0.3).cos(), (k as f32 * 0.3).sin(), s).normalize();
                    let support = pts.iter().map(|q| q.dot(n)).fold(f32::NEG_INFINITY, f32::max);
                    assert!(p.dot(n) <= support + 1e-4, "{light:?}: {p} outside the hull along {n}");
                }
            }
            assert!(checked > 50, "{checked}");
        }
    }
}
