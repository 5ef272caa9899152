//! The form factor from a differential area (a point and its normal) to a polygon: Lambert's
//! contour integral, exact for an unoccluded polygon, with the polygon first clipped to the
//! point's upper half-space (a polygon crossing the tangent plane is the usual failure of the
//! bare formula).

use glam::Vec3;

/// F(point → polygon): the fraction of the point's cosine-weighted hemisphere the polygon
/// covers, in [0, 1]. The polygon's winding does not matter. 0 for a point on the polygon's
/// plane or a polygon wholly below the horizon.
#[must_use]
pub fn point_to_polygon(p: Vec3, n: Vec3, polygon: &[Vec3]) -> f32 {
    // clip against n·(x - p) >= 0 (Sutherland-Hodgman), relative to p for precision
    let mut clipped: Vec<Vec3> = Vec::with_capacity(polygon.len() + 2);
    for (k, &a) in polygon.iter().enumerate() {
        let b = polygon[(k + 1) % polygon.len()];
        let (a, b) = (a - p, b - p);
        let (da, db) = (n.dot(a), n.dot(b));
        if da >= 0.0 {
            clipped.push(a);
        }
        if (da >= 0.0) != (db >= 0.0) {
            let t = da / (da - db);
            clipped.push(a + (b - a) * t);
        }
    }
    if clipped.len() < 3 {
        return 0.0;
    }
    let mut sum = 0.0f64;
    for (k, &a) in clipped.iter().enumerate() {
        let b = clipped[(k + 1) % clipped.len()];
        let (la, lb) = (a.length(), b.length());
        if la <= 0.0 || lb <= 0.0 {
            continue;
        }
        let (ua, ub) = (a / la, b / lb);
        let c = ua.cross(ub);
        let s = c.length();
        if s <= 0.0 {
            continue;
        }
        let gamma = f64::from(s).atan2(f64::from(ua.dot(ub)));
        sum += gamma * f64::from(n.dot(c / s));
    }
    ((sum / (2.0 * std::f64::consts::PI)).abs() as f32).min(1.0)
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::{Rng, SeedableRng};
    use rand_pcg::Pcg64;

    /// A disk of radius r at height h, parallel and centred: F = r² / (h² + r²).
    #[test]
    fn disk_matches_its_closed_form() {
        for (r, h) in [(1.0f32, 1.0f32), (0.1, 2.0), (3.0, 0.5), (1e-3, 1e-3), (1e3, 2e3)] {
            let disk: Vec<Vec3> = (0..512)
                .map(|k| {
                    let a = k as f32 / 512.0 * std::f32::consts::TAU;
                    Vec3::new(r * a.cos(), h, r * a.sin())
                })
                .collect();
            let exact = r * r / (h * h + r * r);
            let got = point_to_polygon(Vec3::ZERO, Vec3::Y, &disk);
            // a 512-gon has 1 - sin(2π/512)/(2π/512) ≈ 2.5e-5 less area than the disk
            assert!((got - exact).abs() < 1e-4 * exact.max(1e-3), "r {r} h {h}: {got} vs {exact}");
        }
    }

    /// Polygons tilted and crossing the horizon, against Monte Carlo integration of
    /// cos θ / π over the hemisphere directions that hit the polygon.
    #[test]
    fn clipped_polygons_match_monte_carlo() {
        let mut rng = Pcg64::seed_from_u64(5);
        let quads = [
            // straddles the horizon
            [
                Vec3::new(-1.0, -0.5, 1.0),
                Vec3::new(1.0, -0.5, 1.0),
                Vec3::new(1.0, 1.0, 1.0),
                Vec3::new(-1.0, 1.0, 1.0),
            ],
            // tilted above
            [Vec3::new(-1.0, 0.5, 0.5), Vec3::new(1.0, 0.5, 0.5), Vec3::new(1.0, 1.5, 1.5), Vec3::new(-1.0, 1.5, 1.5)],
            // wholly below
            [
                Vec3::new(-1.0, -2.0, 1.0),
                Vec3::new(1.0, -2.0, 1.0),
                Vec3::new(1.0, -1.0, 1.0),
                Vec3::new(-1.0, -1.0, 1.0),
            ],
        ];
        for q in quads {
            let normal = (q[1] - q[0]).cross(q[3] - q[0]).normalize();
            let n = 400_000;
            let mut hits = 0usize;
            for _ in 0..n {
                // cosine-weighted direction about +y: the hit fraction is the form factor
                let (u1, u2): (f32, f32) = (rng.random(), rng.random());
                let r = u1.sqrt();
                let phi = u2 * std::f32::consts::TAU;
                let d = Vec3::new(r * phi.cos(), (1.0 - u1).max(0.0).sqrt(), r * phi.sin());
                let denom = normal.dot(d);
                if denom.abs() < 1e-9 {
                    continue;
                }
                let t = normal.dot(q[0]) / denom;
                if t <= 0.0 {
                    continue;
                }
                let x = d * t;
                // inside the convex quad: same side of every edge
                let inside = (0..4).all(|k| (q[(k + 1) % 4] - q[k]).cross(x - q[k]).dot(normal) >= 0.0);
                hits += usize::from(inside);
            }
            let mc = hits as f32 / n as f32;
            let got = point_to_polygon(Vec3::ZERO, Vec3::Y, &q);
            let sigma = (mc * (1.0 - mc) / n as f32).sqrt();
            assert!((got - mc).abs() < 5.0 * sigma + 1e-4, "{q:?}: {got} vs {mc} ± {sigma}");
        }
    }

    #[test]
    fn degenerate_input_gives_zero_not_nan() {
        let q = [Vec3::X, Vec3::X, Vec3::X, Vec3::X];
        assert_eq!(point_to_polygon(Vec3::ZERO, Vec3::Y, &q), 0.0);
        // a coplanar polygon beside the point: grazing, nothing
        let q =
            [Vec3::new(2.0, 0.0, -1.0), Vec3::new(3.0, 0.0, -1.0), Vec3::new(3.0, 0.0, 1.0), Vec3::new(2.0, 0.0, 1.0)];
        let f = point_to_polygon(Vec3::ZERO, Vec3::Y, &q);
        assert!(f.is_finite() && f <= 1e-6, "{f}");
        // around the point in its own plane: the limit from above, the whole hemisphere
        let q = [
            Vec3::new(-1.0, 0.0, 1.0),
            Vec3::new(1.0, 0.0, 1.0),
            Vec3::new(1.0, 0.0, -1.0),
            Vec3::new(-1.0, 0.0, -1.0),
        ];
        assert!((point_to_polygon(Vec3::ZERO, Vec3::Y, &q) - 1.0).abs() < 1e-5);
        // a point at a polygon's vertex, facing it
        let f = point_to_polygon(Vec3::new(-1.0, 1.0, -1.0), Vec3::NEG_Y, &q);
        assert!(f.is_finite() && (0.0..=1.0).contains(&f));
        assert!(point_to_polygon(Vec3::ZERO, Vec3::Y, &[]) == 0.0);
    }
}
