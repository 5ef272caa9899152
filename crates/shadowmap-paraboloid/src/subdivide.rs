//! Splitting triangles that span a large angle seen from a point light. A paraboloid map is a
//! non-linear projection but the rasterizer interpolates linearly between projected corners, so
//! a large triangle's interior lands in the wrong texels (paper 004's caveat). Bisecting each
//! triangle's widest edge (as seen from the light) until every edge subtends at most
//! `max_angle` bounds that error.

use glam::Vec3;

/// Most bisections of one input triangle (2^16 pieces), so a triangle touching the light
/// cannot make the output explode.
pub const MAX_SPLITS: u32 = 16;

fn angle(light: Vec3, a: Vec3, b: Vec3) -> f32 {
    let (da, db) = (a - light, b - light);
    // atan2 form: accurate for tiny and near-straight angles alike
    da.cross(db).length().atan2(da.dot(db))
}

/// The widest angle any triangle edge of `triangles` spans seen from `light`, radians.
#[must_use]
pub fn max_edge_angle(triangles: &[[Vec3; 3]], light: Vec3) -> f32 {
    triangles.iter().flat_map(|t| [0, 1, 2].map(|k| angle(light, t[k], t[(k + 1) % 3]))).fold(0.0, f32::max)
}

/// `triangles` with every triangle bisected until each edge subtends at most `max_angle`
/// radians from `light` (or [`MAX_SPLITS`] levels deep).
#[must_use]
pub fn subdivide_for_light(triangles: &[[Vec3; 3]], light: Vec3, max_angle: f32) -> Vec<[Vec3; 3]> {
    let mut out = Vec::with_capacity(triangles.len());
    let mut stack: Vec<([Vec3; 3], u32)> = Vec::new();
    for &t in triangles {
        stack.push((t, 0));
        while let Some((tri, depth)) = stack.pop() {
            let angles = [0, 1, 2].map(|k| angle(light, tri[k], tri[(k + 1) % 3]));
            let (k, widest) =
                angles.iter().copied().enumerate().fold((0, 0.0), |m, (k, a)| if a > m.1 { (k, a) } else { m });
            if widest <= max_angle || depth >= MAX_SPLITS {
                out.push(tri);
                continue;
            }
            let (a, b, c) = (tri[k], tri[(k + 1) % 3], tri[(k + 2) % 3]);
            let m = 0.5 * (a + b);
            // both halves keep the winding of the original
            stack.push(([a, m, c], depth + 1));
            stack.push(([m, b, c], depth + 1));
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn pieces_cover_the_same_area_and_respect_the_angle() {
        let light = Vec3::new(0.0, 1.0, 0.0);
        let tris = [[Vec3::new(-5.0, 0.0, -5.0), Vec3::new(5.0, 0.0, -5.0), Vec3::new(0.0, 0.0, 5.0)]];
        let area = |t: &[Vec3; 3]| 0.5 * (t[1] - t[0]).cross(t[2] - t[0]).length();
        let out = subdivide_for_light(&tris, light, 0.3);
        assert!(out.len() > 100);
        let total: f32 = out.iter().map(area).sum();
        assert!((total - area(&tris[0])).abs() < 1e-3 * total, "{total}");
        for t in &out {
            for k in 0..3 {
                assert!(angle(light, t[k], t[(k + 1) % 3]) <= 0.3 + 1e-6);
            }
            let n = (t[1] - t[0]).cross(t[2] - t[0]);
            let n0 = (tris[0][1] - tris[0][0]).cross(tris[0][2] - tris[0][0]);
            assert!(n.dot(n0) > 0.0, "winding kept");
        }
    }

    #[test]
    fn a_triangle_through_the_light_stops_at_the_split_limit() {
        let light = Vec3::ZERO;
        let tris = [[Vec3::new(-1.0, 0.0, -1.0), Vec3::new(1.0, 0.0, -1.0), Vec3::new(0.0, 0.0, 1.0)]];
        let out = subdivide_for_light(&tris, light, 0.01);
        assert!(out.len() > 1 && out.len() <= 1 << MAX_SPLITS, "{}", out.len());
        // Each bisection halves the area, so a piece made d levels deep has area A / 2^d: the
        // pieces still wider than the limit (those at the light) are exactly MAX_SPLITS deep,
        // and together the pieces cover the triangle.
        let area = |t: &[Vec3; 3]| f64::from(0.5 * (t[1] - t[0]).cross(t[2] - t[0]).length());
        let whole = area(&tris[0]);
        let deepest = whole / f64::from(1u32 << MAX_SPLITS);
        let wide: Vec<_> = out.iter().filter(|t| max_edge_angle(&[**t], light) > 0.01).collect();
        assert!(!wide.is_empty(), "the pieces at the light cannot meet the limit");
        for t in &wide {
            assert!((area(t) / deepest - 1.0).abs() < 1e-3, "a wide piece stopped early: area {}", area(t));
        }
        let total: f64 = out.iter().map(area).sum();
        assert!((total / whole - 1.0).abs() < 1e-4, "{total} vs {whole}");
    }
}
