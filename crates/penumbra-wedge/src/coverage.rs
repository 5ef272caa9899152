//! The wedge term on the CPU, as `crates/penumbra-wedge/shaders/wedge.wgsl` computes it per pixel, and
//! the closed forms it is tested against.
//!
//! In a frame at the receiver `p` whose z axis points at the light's centre, an edge's clipped
//! endpoints map to `q = (x, y) / (z tan α)`: the light becomes the unit disk. With the edge's
//! line at signed distance `h` from the origin and `s` the position along it,
//! `a_e = G(h, s1) − G(h, s0)`, `G(h, s) = ½ atan(s / h) − ½ h s` over the chord
//! `|s| ≤ √(1 − h²)` (constant beyond): the part of the edge's angular sector of the disk that
//! lies beyond the edge. Summed over a closed silhouette loop oriented counter-clockwise seen
//! from the light, `Σ ½Δφ = π w` (w the winding number about the centre: the hard shadow), so
//! the visible fraction of the disk is `V = clamp(1 − w + Σ a_e / π)`.
//!
//! **Cosine weighting.** A Lambertian receiver weighs each direction of the light by its cosine
//! to the normal `n`: in the projected plane `n · d ∝ n_z (1 + k · q)` with
//! `k = tan α (n_x, n_y) / n_z`. The hard term and the edge regions decompose the occluded part of
//! the disk as signed indicator functions, so any weight integrates through them: the weighted
//! visible fraction is `clamp(1 − w + Σ (a_e + k · m_e) / π)`, `m_e` the first moment of the
//! edge's region (the full disk's moment is zero). In the edge's frame (`t` along the normal
//! from the centre to its line, `s` along it) the region from the foot of the perpendicular to
//! `s` has, for a line at distance `a = |h|`, `r = √(a² + s²)`:
//! `M_t = (s / r − a² s) / 3` and `M_s = ((1 − a / r) − a s² / 2) / 3`, the latter signed as the
//! area is. Only where the disk lies wholly above the receiver's plane (`|k| <= 1`, every
//! weight >= 0): where it straddles the plane, negative weights below it would turn the
//! double counting of overlapping casters (a point in two shadow volumes; the ground covering
//! the part below the plane besides another caster) from a lower bound into light leaking into
//! umbrae, so those pixels keep the uniform fraction. On a flat receiver a distant light is
//! weighted at every pixel or at none; on a curved one the switch is a seam where a penumbra
//! crosses the curve where the light touches the tangent plane. Unweighted, the wedges were 1.39x the
//! ray-traced lights' RMSE on `kiara_1_dawn_1k.hdr`, whose lights sit low: the open part of a
//! cone under a sphere is its low, grazing part.

use glam::{Vec2, Vec3};
use gpu::LightShape;
use std::f32::consts::PI;

/// The frame of the light as seen from `p`: (x, y, z axes, tan of the half-angle, the largest
/// z that still lies before the light, or infinity).
#[must_use]
pub fn light_frame(p: Vec3, light: &LightShape) -> (Vec3, Vec3, Vec3, f32, f32) {
    let z = light.direction_from(p);
    // right-handed (x cross y = z): counter-clockwise seen from the light stays so in (x, y)
    let x = z.any_orthonormal_vector();
    let y = z.cross(x);
    let alpha = light.half_angle_at(p).clamp(1e-7, LightShape::MAX_HALF_ANGLE);
    let z_max = match *light {
        LightShape::Distant { .. } => f32::INFINITY,
        // the disk of tangency: nothing beyond it occludes the sphere's visible cap
        LightShape::Sphere { center, .. } => center.distance(p) * alpha.cos().powi(2),
    };
    (x, y, z, alpha.tan(), z_max)
}

/// `G(h, s)` of the module doc with `s` clamped to the chord.
fn g(h: f32, s: f32) -> f32 {
    let c = (1.0 - h * h).max(0.0).sqrt();
    let s = s.clamp(-c, c);
    // atan(s / h) continued through h = 0 by its sign
    let phi = if h >= 0.0 { s.atan2(h) } else { -s.atan2(-h) };
    0.5 * phi - 0.5 * h * s
}

/// The first moment `(M_t, M_s)` of the region `G(h, s)` measures (module doc), `s` clamped to
/// the chord, signed as `G` is.
fn g_moment(h: f32, s: f32) -> Vec2 {
    let c = (1.0 - h * h).max(0.0).sqrt();
    let s = s.clamp(-c, c);
    let a = h.abs();
    let r = a.hypot(s);
    if r <= 0.0 {
        return Vec2::ZERO;
    }
    let sign = if h >= 0.0 { 1.0 } else { -1.0 };
    Vec2::new((s / r - a * a * s) / 3.0, sign * ((1.0 - a / r) - 0.5 * a * s * s) / 3.0)
}

/// `a_e / π` for the projected segment `q0 -> q1` in unit-disk coordinates.
#[must_use]
pub fn segment_term(q0: Vec2, q1: Vec2) -> f32 {
    segment_terms(q0, q1).x
}

/// `(a_e, m_e) / π` for the projected segment `q0 -> q1`: the region's area and its first
/// moment in unit-disk coordinates.
#[must_use]
pub fn segment_terms(q0: Vec2, q1: Vec2) -> Vec3 {
    let d = q1 - q0;
    let len = d.length();
    if len.is_nan() || len <= 1e-12 || !len.is_finite() {
        return Vec3::ZERO;
    }
    let s_hat = d / len;
    // n_hat = s_hat turned -90 degrees: (n_hat, s_hat) counter-clockwise
    let n_hat = Vec2::new(s_hat.y, -s_hat.x);
    let h = q0.dot(n_hat);
    if h.abs() >= 1.0 {
        return Vec3::ZERO;
    }
    let (s0, s1) = (q0.dot(s_hat), q1.dot(s_hat));
    let m = g_moment(h, s1) - g_moment(h, s0);
    let moment = n_hat * m.x + s_hat * m.y;
    Vec3::new(g(h, s1) - g(h, s0), moment.x, moment.y) / PI
}

/// The cosine weight at a receiver with normal `n` in the light's frame (module doc): a disk
/// point `q` weighs `1 + k · q` (`∝ n · d`), returned as `(1, k.x, k.y)` where the disk lies
/// wholly above the receiver's plane (`|k| <= 1`), else `(1, 0, 0)`: uniform.
#[must_use]
pub fn cosine_weights(n: Vec3, x: Vec3, y: Vec3, z: Vec3, tan_a: f32) -> Vec3 {
    let nz = n.dot(z);
    let c = Vec2::new(n.dot(x), n.dot(y)) * tan_a;
    if nz > 0.0 && c.length() <= nz { Vec3::new(1.0, c.x / nz, c.y / nz) } else { Vec3::X }
}

/// `a_e / π` of the edge `v0 -> v1` seen from `p`: the edge is clipped to the slab between `p`
/// and the light (`z > 0`, and before the light's tangent disk for a sphere) and projected.
#[must_use]
pub fn edge_term(p: Vec3, v0: Vec3, v1: Vec3, light: &LightShape) -> f32 {
    edge_terms(p, v0, v1, light).x
}

/// [`edge_term`] with the region's first moment: `(a_e, m_e) / π` ([`segment_terms`]).
#[must_use]
pub fn edge_terms(p: Vec3, v0: Vec3, v1: Vec3, light: &LightShape) -> Vec3 {
    let (x, y, z, tan_a, z_max) = light_frame(p, light);
    let (d0, d1) = (v0 - p, v1 - p);
    let (z0, z1) = (d0.dot(z), d1.dot(z));
    // the clip plane's z a hair above p's: endpoints exactly at z = 0 project to infinity
    let z_min = 1e-6 * d0.length().max(d1.length());
    let Some((t0, t1)) = clip_interval(z0, z1, z_min, z_max) else { return Vec3::ZERO };
    let at = |t: f32| d0 + (d1 - d0) * t;
    let project = |d: Vec3| {
        let zz = d.dot(z).max(z_min);
        Vec2::new(d.dot(x), d.dot(y)) / (zz * tan_a)
    };
    segment_terms(project(at(t0)), project(at(t1)))
}

/// The parameter interval of the segment z(t) = z0 + (z1 − z0) t, t in [0, 1], where
/// `lo <= z <= hi`; `None` when empty.
fn clip_interval(z0: f32, z1: f32, lo: f32, hi: f32) -> Option<(f32, f32)> {
    let (mut t0, mut t1) = (0.0f32, 1.0f32);
    let dz = z1 - z0;
    for (bound, below) in [(lo, true), (hi, false)] {
        if !bound.is_finite() {
            continue;
        }
        // keep z >= bound (below) or z <= bound
        let inside0 = if below { z0 >= bound } else { z0 <= bound };
        let inside1 = if below { z1 >= bound } else { z1 <= bound };
        match (inside0, inside1) {
            (true, true) => {}
            (false, false) => return None,
            _ => {
                let t = ((bound - z0) / dz).clamp(0.0, 1.0);
                if inside0 { t1 = t1.min(t) } else { t0 = t0.max(t) }
            }
        }
    }
    (t0 < t1).then_some((t0, t1))
}

/// The wedge visibility at `p` on the CPU: `clamp(1 − w + Σ a_e / π)` over `edges`, with `w`
/// the hard count: the number of shadow volumes (one per caster's silhouette loop) holding `p`.
///
/// Each caster `c` occludes `w_c − Σ_c` of the disk (its hard term less its edge terms), so
/// `1 − w + Σ` is the visible fraction when the casters' occlusions do not overlap, and a lower
/// bound otherwise (clamped at 0). Paper 000's `w = min(count, 1)` is right for one silhouette
/// only: where a point lies in two volumes (a box's umbra inside the ground's shadow of a light
/// below the horizon), the second caster's edge terms light the first's umbra. Measured on
/// `validate` (spheres_box, default map) the wedges' RMSE is 0.0158 with the count; on two stacked
/// slabs it took the mean error in penumbrae from 0.142 to 0.107.
///
/// `n` is the receiver's normal, `faces` each edge's lit and unlit face normals (see
/// [`oriented_edge_term`]).
#[must_use]
pub fn visibility(
    p: Vec3,
    n: Vec3,
    edges: &[[Vec3; 2]],
    faces: &[[Vec3; 2]],
    hard_count: u32,
    light: &LightShape,
) -> f32 {
    weighted_visibility(p, n, (edges, faces), hard_count, light, Vec3::X)
}

/// `clamp(1 − w + Σ weights · (a_e, m_e) / π)`: [`visibility`] with `(1, 0, 0)`.
fn weighted_visibility(
    p: Vec3,
    n: Vec3,
    (edges, faces): (&[[Vec3; 2]], &[[Vec3; 2]]),
    hard_count: u32,
    light: &LightShape,
    weights: Vec3,
) -> f32 {
    let sum: f32 = edges.iter().zip(faces).map(|(&e, &f)| weights.dot(oriented_edge_terms(p, n, e, f, light))).sum();
    (1.0 - hard_count as f32 + sum).clamp(0.0, 1.0)
}

/// [`visibility`] weighted by the cosine to `n` (module doc): `clamp(1 − w + Σ (a_e + k · m_e)
/// / π)` where the light lies wholly above the receiver's plane, [`visibility`] where it
/// straddles it (divide by [`disk_above`] as there).
#[must_use]
pub fn cosine_visibility(
    p: Vec3,
    n: Vec3,
    edges: &[[Vec3; 2]],
    faces: &[[Vec3; 2]],
    hard_count: u32,
    light: &LightShape,
) -> f32 {
    let (x, y, z, tan_a, _) = light_frame(p, light);
    let weights = cosine_weights(n.normalize_or_zero(), x, y, z, tan_a);
    weighted_visibility(p, n, (edges, faces), hard_count, light, weights)
}

/// [`edge_term`] for a silhouette edge between a lit face and an unlit one, with normals
/// `[lit, unlit]` (the lit one facing the light; the unlit one zero for a sheet's edge):
/// negated where `p` lies in front of the lit face and not in front of the unlit one.
///
/// Seen from the light both faces fold to the edge's left. Seen from `p`, a face keeps that
/// side where `p` is behind it and takes the other where `p` is in front: behind the lit face
/// and in front of the unlit one (the usual penumbra) the caster stays on the left; in front of
/// the lit face and behind the unlit one both fold to the right, the outline mirrored. That
/// happens where a light straddles the lit face's plane (a light at the horizon and the
/// ground, or a face nearly edge-on to it): rays to the part of the disk behind the face hit
/// its lit side. Where `p` sees both faces or neither, the edge lies inside the caster's
/// outline seen from `p` (the single-silhouette approximation) and keeps its sign, the caster
/// still mostly to its left.
///
/// A receiver on a face's plane (the ground receiving, the ground's own edge) is on the side its
/// normal `n` points to: the tests use `p` moved along `n` by [`ON_PLANE`] of its distance to
/// the edge. The ground's top then lies in front of the ground lit from above (its edge hides
/// what lies below the receiver's tangent plane, the part `disk_above` leaves out) and behind
/// the ground lit from below. Measured on `courtyard.exr`, whose brightest
/// light sits on the horizon: without the flip the ground's edge added the part of the disk it
/// hides instead of taking it away, and every shadow of that light vanished.
#[must_use]
pub fn oriented_edge_term(p: Vec3, n: Vec3, edge: [Vec3; 2], faces: [Vec3; 2], light: &LightShape) -> f32 {
    oriented_edge_terms(p, n, edge, faces, light).x
}

/// [`oriented_edge_term`] with the region's first moment ([`edge_terms`]).
#[must_use]
pub fn oriented_edge_terms(p: Vec3, n: Vec3, [v0, v1]: [Vec3; 2], [lit, unlit]: [Vec3; 2], light: &LightShape) -> Vec3 {
    let t = edge_terms(p, v0, v1, light);
    let d = p - v0;
    let d = d + n * (ON_PLANE * d.length());
    if lit.dot(d) > 0.0 && unlit.dot(d) <= 0.0 { -t } else { t }
}

/// How far along its normal, relative to its distance from the edge, [`oriented_edge_term`]
/// moves a receiver before its side tests: G-buffer positions round by about 1e-6 of their
/// distance. `coverage.wgsl` has the same constant (a test checks).
pub const ON_PLANE: f32 = 1e-4;

/// The visible fraction of the light's disk (in the projected plane the wedges use) when a
/// convex planar polygon `poly` (counter-clockwise seen from the light, wholly between `p` and
/// the light) occludes it: 1 − area(projection ∩ disk) / π. Independent of the edge terms: it
/// integrates the polygon ∩ disk area in polar coordinates.
#[must_use]
pub fn polygon_visible_fraction(p: Vec3, poly: &[Vec3], light: &LightShape) -> f32 {
    polygon_weighted_visible_fraction(p, poly, light, Vec2::ZERO)
}

/// [`polygon_visible_fraction`] with the disk weighted by `1 + k · q`: 1 − ∫ (1 + k · q) over
/// projection ∩ disk / π (the same polar integration, with the exact radial moment).
#[must_use]
pub fn polygon_weighted_visible_fraction(p: Vec3, poly: &[Vec3], light: &LightShape, k: Vec2) -> f32 {
    let (x, y, z, tan_a, _) = light_frame(p, light);
    let q: Vec<Vec2> = poly
        .iter()
        .map(|v| {
            let d = *v - p;
            Vec2::new(d.dot(x), d.dot(y)) / (d.dot(z) * tan_a)
        })
        .collect();
    let (area, moment) = polygon_disk_area_moment(&q);
    1.0 - (area + k.dot(moment)) / PI
}

/// Area of a convex polygon (counter-clockwise) intersected with the unit disk, by integrating
/// the polygon's indicator over the disk in polar coordinates: for each direction the covered
/// radial interval is clipped to [0, 1]. 4096 angular steps with the exact radial integral
/// (the error is below 1e-5 for the polygons the tests use).
#[must_use]
pub fn polygon_disk_area(q: &[Vec2]) -> f32 {
    polygon_disk_area_moment(q).0
}

/// [`polygon_disk_area`] and the first moment of the same region (the radial integral of
/// r² dr is exact too).
#[must_use]
pub fn polygon_disk_area_moment(q: &[Vec2]) -> (f32, Vec2) {
    const STEPS: usize = 4096;
    let mut area = 0.0f64;
    let mut moment = glam::DVec2::ZERO;
    for k in 0..STEPS {
        let phi = (k as f64 + 0.5) / STEPS as f64 * std::f64::consts::TAU;
        let dir = glam::DVec2::new(phi.cos(), phi.sin());
        // the ray r * dir, r in [0, 1], against the convex polygon: the interval inside it
        let (mut lo, mut hi) = (0.0f64, 1.0f64);
        for i in 0..q.len() {
            let a = q[i].as_dvec2();
            let b = q[(i + 1) % q.len()].as_dvec2();
            let e = b - a;
            // inside is left of a -> b: cross(e, x - a) >= 0
            let c0 = e.perp_dot(-a);
            let c1 = e.perp_dot(dir);
            if c1.abs() < 1e-15 {
                if c0 < 0.0 {
                    hi = -1.0;
                }
            } else {
                let t = -c0 / c1;
                if c1 > 0.0 { lo = lo.max(t) } else { hi = hi.min(t) }
            }
        }
        if hi > lo {
            area += 0.5 * (hi * hi - lo * lo);
            moment += dir * ((hi * hi * hi - lo * lo * lo) / 3.0);
        }
    }
    let step = std::f64::consts::TAU / STEPS as f64;
    ((area * step) as f32, (moment * step).as_vec2())
}

/// Fraction of the light's disk (in the projected plane) above the plane through `p` with
/// normal `n` (the side that is shaded): what the wedge resolve divides by.
#[must_use]
pub fn disk_above(p: Vec3, n: Vec3, light: &LightShape) -> f32 {
    let (x, y, z, tan_a, _) = light_frame(p, light);
    let n = n.normalize_or_zero();
    let (nx, ny, nz) = (n.dot(x), n.dot(y), n.dot(z));
    let nxy = nx.hypot(ny);
    if nxy < 1e-7 {
        return if nz > 0.0 { 1.0 } else { 0.0 };
    }
    let t = (-nz / (tan_a * nxy)).clamp(-1.0, 1.0);
    circular_segment(t)
}

/// The fraction of the unit disk beyond a chord at signed distance `t` from its centre:
/// `(acos t − t √(1 − t²)) / π` (1 at t = −1, ½ at 0, 0 at 1).
#[must_use]
pub fn circular_segment(t: f32) -> f32 {
    let t = t.clamp(-1.0, 1.0);
    (t.acos() - t * (1.0 - t * t).max(0.0).sqrt()) / PI
}

#[cfg(test)]
mod tests {
    use super::*;

    fn distant(direction: Vec3, half_angle: f32) -> LightShape {
        LightShape::Distant { direction: direction.normalize(), half_angle }
    }

    /// The polygon's normal (counter-clockwise seen from the light: it faces the light) as each
    /// edge's lit face, no unlit face (a sheet).
    fn normals(poly: &[Vec3]) -> Vec<[Vec3; 2]> {
        vec![[(poly[1] - poly[0]).cross(poly[2] - poly[0]).normalize(), Vec3::ZERO]; poly.len()]
    }

    /// Whether the ray from `p` along `d` passes through the convex polygon.
    fn ray_hits_polygon(p: Vec3, d: Vec3, poly: &[Vec3]) -> bool {
        let n = (poly[1] - poly[0]).cross(poly[2] - poly[0]);
        let t = (poly[0] - p).dot(n) / d.dot(n);
        if t.is_nan() || t <= 0.0 {
            return false;
        }
        let x = p + d * t;
        (0..poly.len()).all(|k| (poly[(k + 1) % poly.len()] - poly[k]).cross(x - poly[k]).dot(n) >= 0.0)
    }

    #[test]
    fn chord_through_the_whole_disk_is_a_circular_segment() {
        // a long edge crossing the disk at signed distance t, from far left to far right
        // going +x, the covered side (left of the edge) is y > t: with the centre uncovered
        // (t > 0) the term is minus the segment beyond the chord; covered (t < 0), the term is
        // the visible part y < t itself (w = 1 there)
        for t in [-0.9f32, -0.5, -0.01, 0.01, 0.3, 0.8] {
            let term = segment_term(Vec2::new(-50.0, t), Vec2::new(50.0, t));
            let want = if t > 0.0 { -circular_segment(t) } else { circular_segment(-t) };
            assert!((term - want).abs() < 1e-5, "t {t}: term {term}, closed form {want}");
        }
    }

    #[test]
    fn wedge_sum_matches_the_exact_polygon_coverage() {
        // convex quads between the receiver and a distant light, many placements: the wedge
        // visibility (edge terms + hard term from the centre ray) equals 1 - area / pi
        let mut state = 11u32;
        let mut rnd = || {
            state = state.wrapping_mul(747_796_405).wrapping_add(2_891_336_453);
            (state >> 8) as f32 / (1u32 << 24) as f32
        };
        let mut worst = 0.0f32;
        let mut partial = 0;
        for case in 0..400 {
            let light = distant(Vec3::new(rnd() - 0.5, 1.0, rnd() - 0.5), 0.02 + rnd() * 0.5);
            let LightShape::Distant { direction, .. } = light else { unreachable!() };
            // a quad at height 1 .. 2 above p, tilted, centred near the light's ray
            let h = 1.0 + rnd();
            let c = direction * h / direction.y + Vec3::new(rnd() - 0.5, 0.0, rnd() - 0.5) * 0.6;
            let (u, v) =
                (Vec3::new(0.3 + rnd() * 0.4, 0.1 * rnd(), 0.0), Vec3::new(0.0, 0.1 * rnd(), 0.3 + rnd() * 0.4));
            let mut poly = vec![c - u - v, c + u - v, c + u + v, c - u + v];
            // counter-clockwise seen from the light
            if (poly[1] - poly[0]).cross(poly[2] - poly[0]).dot(direction) < 0.0 {
                poly.reverse();
            }
            let p = Vec3::ZERO;
            let edges: Vec<[Vec3; 2]> = (0..4).map(|k| [poly[k], poly[(k + 1) % 4]]).collect();
            let hard = ray_hits_polygon(p, direction, &poly);
            let wedge = visibility(p, Vec3::ZERO, &edges, &normals(&poly), u32::from(hard), &light);
            let exact = polygon_visible_fraction(p, &poly, &light);
            worst = worst.max((wedge - exact).abs());
            partial += usize::from(exact > 0.01 && exact < 0.99);
            assert!((wedge - exact).abs() < 2e-4, "case {case}: wedge {wedge}, exact {exact}");
        }
        assert!(partial > 100, "only {partial} cases in a penumbra");
        assert!(worst < 2e-4);
    }

    /// Random convex quads between the receiver at the origin and a distant light: (light,
    /// quad counter-clockwise seen from the light, whether the centre ray hits it).
    fn random_quads(n: usize) -> Vec<(LightShape, Vec<Vec3>, bool)> {
        let mut state = 29u32;
        let mut rnd = || {
            state = state.wrapping_mul(747_796_405).wrapping_add(2_891_336_453);
            (state >> 8) as f32 / (1u32 << 24) as f32
        };
        (0..n)
            .map(|_| {
                let light = distant(Vec3::new(rnd() - 0.5, 1.0, rnd() - 0.5), 0.02 + rnd() * 0.5);
                let LightShape::Distant { direction, .. } = light else { unreachable!() };
                let h = 1.0 + rnd();
                let c = direction * h / direction.y + Vec3::new(rnd() - 0.5, 0.0, rnd() - 0.5) * 0.6;
                let (u, v) =
                    (Vec3::new(0.3 + rnd() * 0.4, 0.1 * rnd(), 0.0), Vec3::new(0.0, 0.1 * rnd(), 0.3 + rnd() * 0.4));
                let mut poly = vec![c - u - v, c + u - v, c + u + v, c - u + v];
                if (poly[1] - poly[0]).cross(poly[2] - poly[0]).dot(direction) < 0.0 {
                    poly.reverse();
                }
                let hard = ray_hits_polygon(Vec3::ZERO, direction, &poly);
                (light, poly, hard)
            })
            .collect()
    }

    #[test]
    fn cosine_weighted_wedge_sum_matches_the_exact_polygon_moment() {
        // the same decomposition weighted by 1 + k.q: hard term and edge regions' areas and
        // first moments against the polygon's, integrated independently; receivers tilted so
        // that k spans its range (|k| up to 1)
        let mut worst = 0.0f32;
        let (mut weighted_apart, mut checked) = (0, 0);
        for (case, (light, poly, hard)) in random_quads(400).into_iter().enumerate() {
            let p = Vec3::ZERO;
            let tilt = case as f32 / 400.0 * 1.4;
            let n = Vec3::new(tilt.sin() * (case as f32).cos(), tilt.cos(), tilt.sin() * (case as f32).sin());
            let (x, y, z, tan_a, _) = light_frame(p, &light);
            let wts = cosine_weights(n, x, y, z, tan_a);
            let k = Vec2::new(wts.y, wts.z);
            // weighted where the light lies wholly above the receiver's plane
            checked += usize::from(k != Vec2::ZERO);
            let edges: Vec<[Vec3; 2]> = (0..4).map(|i| [poly[i], poly[(i + 1) % 4]]).collect();
            let wedge = cosine_visibility(p, n, &edges, &normals(&poly), u32::from(hard), &light);
            let exact = polygon_weighted_visible_fraction(p, &poly, &light, k).clamp(0.0, 1.0);
            let plain = polygon_visible_fraction(p, &poly, &light);
            worst = worst.max((wedge - exact).abs());
            weighted_apart += usize::from((exact - plain).abs() > 0.01);
            assert!((wedge - exact).abs() < 3e-4, "case {case}: wedge {wedge}, exact {exact}, k {k}");
        }
        assert!(checked > 200, "only {checked} weighted cases");
        assert!(weighted_apart > 50, "only {weighted_apart} cases where weighting matters");
        assert!(worst < 3e-4);
    }

    #[test]
    fn cosine_visibility_is_the_ray_traced_cosine_weighted_fraction_of_a_small_light() {
        // against rays: a 5-degree cone 6 degrees over the ground, its upper half hidden by a
        // sheet whose edge passes through the centre ray; the planar projection errs by about
        // tan^2 of the half-angle
        let light = distant(Vec3::new(0.0, 6f32.to_radians().tan(), 1.0), 5f32.to_radians());
        let LightShape::Distant { direction, half_angle } = light else { unreachable!() };
        let n = Vec3::Y;
        let mut poly = vec![
            Vec3::new(-5.0, 2.0 * 6f32.to_radians().tan(), 2.0),
            Vec3::new(5.0, 2.0 * 6f32.to_radians().tan(), 2.0),
            Vec3::new(5.0, 5.0, 2.0),
            Vec3::new(-5.0, 5.0, 2.0),
        ];
        if (poly[1] - poly[0]).cross(poly[2] - poly[0]).dot(direction) < 0.0 {
            poly.reverse();
        }
        let edges: Vec<[Vec3; 2]> = (0..4).map(|i| [poly[i], poly[(i + 1) % 4]]).collect();
        let hard = ray_hits_polygon(Vec3::ZERO, direction, &poly);
        let (mut open, mut all, mut count, mut seen) = (0.0f64, 0.0f64, 0, 0);
        let frame = scene::brdf::Frame::new(direction);
        let m = 400;
        for i in 0..m {
            for j in 0..m {
                let cos_t = 1.0 - (i as f32 + 0.5) / m as f32 * (1.0 - half_angle.cos());
                let phi = (j as f32 + 0.5) / m as f32 * std::f32::consts::TAU;
                let sin_t = (1.0 - cos_t * cos_t).sqrt();
                let d = frame.to_world(Vec3::new(sin_t * phi.cos(), sin_t * phi.sin(), cos_t));
                let w = f64::from(n.dot(d).max(0.0));
                let visible = !ray_hits_polygon(Vec3::ZERO, d, &poly);
                all += w;
                count += 1;
                if visible {
                    open += w;
                    seen += 1;
                }
            }
        }
        let traced = (open / all) as f32;
        let unweighted = seen as f32 / count as f32;
        let wedge = cosine_visibility(Vec3::ZERO, n, &edges, &normals(&poly), u32::from(hard), &light);
        let plain = visibility(Vec3::ZERO, n, &edges, &normals(&poly), u32::from(hard), &light);
        assert!((plain - unweighted).abs() < 0.01, "unweighted: wedge {plain}, rays {unweighted}");
        assert!((traced - unweighted).abs() > 0.1, "weighting must matter here: {traced} vs {unweighted}");
        assert!((wedge - traced).abs() < 0.01, "weighted: wedge {wedge}, rays {traced}");
    }

    #[test]
    fn the_cosine_weights_are_uniform_unless_the_light_is_wholly_above() {
        let (x, y, z) = (Vec3::X, Vec3::Y, Vec3::Z);
        assert_eq!(cosine_weights(z, x, y, z, 0.3), Vec3::X);
        // tilted by theta: k = tan(alpha) tan(theta), the disk's far rim weighing 1 - |k| >= 0
        let th = 0.5f32;
        let w = cosine_weights(Vec3::new(th.sin(), 0.0, th.cos()), x, y, z, 0.2);
        assert!((w.y - 0.2 * th.tan()).abs() < 1e-6 && w.x == 1.0 && w.z == 0.0, "{w}");
        // straddling, edge-on, from behind, no normal: uniform
        for n in [Vec3::new(1.0, 0.0, 0.05).normalize(), Vec3::X, -Vec3::Z, Vec3::ZERO] {
            assert_eq!(cosine_weights(n, x, y, z, 0.5), Vec3::X, "{n}");
        }
    }

    #[test]
    fn half_plane_through_the_centre_hides_half_the_light() {
        // a huge square whose edge passes right below the light's centre
        let light = distant(Vec3::Y, 0.1);
        let poly = [
            Vec3::new(0.0, 1.0, -50.0),
            Vec3::new(0.0, 1.0, 50.0),
            Vec3::new(50.0, 1.0, 50.0),
            Vec3::new(50.0, 1.0, -50.0),
        ];
        let mut poly = poly.to_vec();
        if (poly[1] - poly[0]).cross(poly[2] - poly[0]).y < 0.0 {
            poly.reverse();
        }
        let edges: Vec<[Vec3; 2]> = (0..4).map(|k| [poly[k], poly[(k + 1) % 4]]).collect();
        for (x, hard) in [(-1e-3f32, false), (1e-3, true)] {
            let v = visibility(Vec3::new(x, 0.0, 0.0), Vec3::ZERO, &edges, &normals(&poly), u32::from(hard), &light);
            assert!((v - 0.5).abs() < 0.01, "x {x}: {v}");
        }
    }

    #[test]
    fn no_nan_at_extremes() {
        let p = Vec3::ZERO;
        let lights = [
            distant(Vec3::Y, 0.01f32.to_radians()),
            distant(Vec3::Y, 1e-9),
            distant(Vec3::Y, 45f32.to_radians()),
            distant(Vec3::Y, 3.0),
            distant(Vec3::new(1.0, 1e-6, 0.0), 0.1),
            LightShape::Sphere { center: Vec3::Y, radius: 0.5 },
            LightShape::Sphere { center: Vec3::Y * 1e-3, radius: 1e-3 },
            LightShape::Sphere { center: Vec3::Y, radius: 0.0 },
        ];
        let edges = [
            [Vec3::new(-1.0, 0.5, 0.0), Vec3::new(1.0, 0.5, 0.0)],
            // pointing at the light
            [Vec3::new(0.0, 0.2, 0.0), Vec3::new(0.0, 0.8, 0.0)],
            // an endpoint at the receiver, one at the light
            [Vec3::ZERO, Vec3::Y],
            // behind the receiver, crossing its plane
            [Vec3::new(-1.0, -0.5, 0.1), Vec3::new(1.0, 0.5, 0.1)],
            // degenerate
            [Vec3::new(0.3, 0.5, 0.0), Vec3::new(0.3, 0.5, 0.0)],
            // huge and tiny scales
            [Vec3::new(-1e6, 1e3, 0.0), Vec3::new(1e6, 1e3, 0.0)],
            [Vec3::new(-1e-6, 1e-6, 0.0), Vec3::new(1e-6, 1e-6, 0.0)],
        ];
        for light in &lights {
            for [a, b] in &edges {
                let t = edge_term(p, *a, *b, light);
                assert!(t.is_finite() && t.abs() <= 1.0 + 1e-5, "{light:?} {a} {b}: {t}");
                for hard in [0, 1, 2] {
                    for n in [[Vec3::Y, Vec3::ZERO], [Vec3::NEG_Y, Vec3::X], [Vec3::ZERO; 2]] {
                        let v = visibility(p, Vec3::Y, &[[*a, *b]], &[n], hard, light);
                        assert!((0.0..=1.0).contains(&v), "{v}");
                    }
                }
            }
            let f = disk_above(p, Vec3::new(0.3, 0.9, 0.1), light);
            assert!(f.is_finite() && (0.0..=1.0).contains(&f));
        }
    }

    #[test]
    fn disk_above_a_tilted_plane_is_a_segment() {
        let light = distant(Vec3::Y, 0.2);
        assert!((disk_above(Vec3::ZERO, Vec3::Y, &light) - 1.0).abs() < 1e-6);
        assert!((disk_above(Vec3::ZERO, Vec3::X, &light) - 0.5).abs() < 1e-6);
        assert!(disk_above(Vec3::ZERO, Vec3::NEG_Y, &light) < 1e-6);
        // tilted so that the horizon passes 0.5 disk radii below the centre
        let tilt = (1.0 / (0.5f32 * 0.2f32.tan())).atan();
        let n = Vec3::new(tilt.sin(), tilt.cos(), 0.0);
        assert!((disk_above(Vec3::ZERO, n, &light) - circular_segment(-0.5)).abs() < 1e-4);
    }

    /// The visible fraction of the disk (the projected plane's measure, as the wedges use) by
    /// brute force: a 400 x 400 grid over the unit disk, each point's ray against the ground
    /// square `|x|, |z| <= half` at y = 0.
    fn ground_visible_fraction(p: Vec3, half: f32, light: &LightShape) -> f32 {
        let (x, y, z, tan_a, _) = light_frame(p, light);
        let n = 400;
        let (mut inside, mut seen) = (0u32, 0u32);
        for i in 0..n {
            for j in 0..n {
                let q = Vec2::new((i as f32 + 0.5) / n as f32 * 2.0 - 1.0, (j as f32 + 0.5) / n as f32 * 2.0 - 1.0);
                if q.length_squared() > 1.0 {
                    continue;
                }
                inside += 1;
                let d = z + (x * q.x + y * q.y) * tan_a;
                let t = -p.y / d.y;
                let hit = t > 0.0 && {
                    let h = p + d * t;
                    h.x.abs() <= half && h.z.abs() <= half
                };
                seen += u32::from(!hit);
            }
        }
        seen as f32 / inside as f32
    }

    #[test]
    fn shader_moves_receivers_off_planes_as_the_cpu_does() {
        let wgsl = include_str!("../shaders/coverage.wgsl");
        assert!(wgsl.contains(&format!("const ON_PLANE: f32 = {ON_PLANE:e};")), "coverage.wgsl's ON_PLANE differs");
    }

    #[test]
    fn ground_hides_the_part_of_a_horizon_light_below_it_from_either_side() {
        // the ground square's silhouette from a light straddling its plane, seen from above and
        // below it, with the light's centre above and below the horizon
        let half = 50.0;
        let q = scene::Mesh::quad(Vec3::new(-half, 0.0, -half), Vec3::X * 2.0 * half, Vec3::Z * 2.0 * half, 1, 1);
        let casters =
            crate::casters::Casters { casters: vec![crate::casters::Caster::new("ground", &q.positions, &q.indices)] };
        let mut partial = 0;
        for elevation in [-4.0f32, -1.0, 0.5, 3.0] {
            for (azimuth, height) in [(0.3f32, 1.0f32), (1.2, 0.2), (2.5, -0.7), (-2.0, 3.0)] {
                let (e, a) = (elevation.to_radians(), azimuth);
                let light = distant(Vec3::new(e.cos() * a.sin(), e.sin(), e.cos() * a.cos()), 6f32.to_radians());
                let sil = casters.silhouette(&light, |_| true);
                let p = Vec3::new(0.4, height, -0.3);
                let LightShape::Distant { direction, .. } = light else { unreachable!() };
                // the centre ray crosses the square
                let hard =
                    ray_hits_polygon(p, direction, &[q.positions[0], q.positions[1], q.positions[3], q.positions[2]]);
                let wedge = visibility(p, Vec3::ZERO, &sil.edges, &sil.normals, u32::from(hard), &light);
                let exact = ground_visible_fraction(p, half, &light);
                partial += usize::from(exact > 0.05 && exact < 0.95);
                assert!(
                    (wedge - exact).abs() < 0.01,
                    "elevation {elevation}, height {height}: wedge {wedge}, brute force {exact}"
                );
            }
        }
        assert!(partial >= 8, "{partial} cases in a penumbra");
    }
}
