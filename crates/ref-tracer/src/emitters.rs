//! Emitting surfaces for `PathEmissive`: the emitting triangles of a scene, chosen by power
//! (luminance of the emitted radiance x area) and sampled uniformly by area, for next-event
//! estimation combined by MIS with the BRDF samples that hit them.

use envmap_sphere::luminance;
use glam::{Vec2, Vec3};
use scene::Scene;

/// One emitting triangle.
#[derive(Clone, Copy, Debug)]
struct Triangle {
    v0: Vec3,
    e1: Vec3,
    e2: Vec3,
    /// Unit front normal (e1 x e2).
    n: Vec3,
    object: u32,
}

/// The emitting triangles of a scene and their sampling distribution.
#[derive(Clone, Debug, Default)]
pub struct Emitters {
    /// Radiance each object emits from its front faces.
    emission: Vec<Vec3>,
    triangles: Vec<Triangle>,
    /// Cumulative power, normalized to end at 1.
    cdf: Vec<f32>,
    /// Σ luminance(Le) x area over the emitting triangles.
    total: f32,
}

impl Emitters {
    /// The emitters of `scene`: object k emits `emission[k]` from its front faces (objects past
    /// the end, non-finite or non-positive emission emit nothing).
    #[must_use]
    pub fn new(scene: &Scene, emission: &[Vec3]) -> Self {
        let emission: Vec<Vec3> = (0..scene.objects.len())
            .map(|k| emission.get(k).copied().filter(|e| e.is_finite()).unwrap_or(Vec3::ZERO).max(Vec3::ZERO))
            .collect();
        let mut triangles = Vec::new();
        let mut cdf = Vec::new();
        let mut total = 0.0f64;
        for (k, o) in scene.objects.iter().enumerate() {
            let l = luminance(emission[k]);
            if l <= 0.0 {
                continue;
            }
            for t in 0..o.mesh.indices.len() {
                let [a, b, c] = o.mesh.triangle(t);
                let (e1, e2) = (b - a, c - a);
                let cross = e1.cross(e2);
                let area = 0.5 * cross.length();
                if area <= 0.0 || !area.is_finite() {
                    continue;
                }
                total += f64::from(l * area);
                triangles.push(Triangle { v0: a, e1, e2, n: cross.normalize(), object: k as u32 });
                cdf.push(total as f32);
            }
        }
        let total = total as f32;
        for c in &mut cdf {
            *c /= total;
        }
        Self { emission, triangles, cdf, total }
    }

    /// True when nothing emits.
    #[must_use]
    pub fn is_empty(&self) -> bool {
        self.emission.iter().all(|e| *e == Vec3::ZERO)
    }

    /// What object `object` emits from its front faces.
    #[must_use]
    pub fn emission(&self, object: u32) -> Vec3 {
        self.emission.get(object as usize).copied().unwrap_or(Vec3::ZERO)
    }

    /// Density per unit area of sampling a point of `object` (0 for objects never sampled).
    #[must_use]
    pub fn pdf_area(&self, object: u32) -> f32 {
        if self.triangles.is_empty() { 0.0 } else { luminance(self.emission(object)) / self.total }
    }

    /// A point on an emitter: (position, unit front normal, emitted radiance, pdf per area).
    #[must_use]
    pub fn sample(&self, u: f32, uv: Vec2) -> Option<(Vec3, Vec3, Vec3, f32)> {
        let k = self.cdf.partition_point(|&c| c <= u).min(self.triangles.len().checked_sub(1)?);
        let t = &self.triangles[k];
        // uniform on the triangle
        let s = uv.x.sqrt();
        let (b1, b2) = (s * (1.0 - uv.y), s * uv.y);
        let p = t.v0 + t.e1 * b1 + t.e2 * b2;
        Some((p, t.n, self.emission(t.object), self.pdf_area(t.object)))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use scene::{Camera, Material, Mesh, Object};

    fn scene(quads: &[(f32, f32)]) -> Scene {
        Scene {
            name: "quads".into(),
            objects: quads
                .iter()
                .map(|&(x, size)| Object {
                    name: format!("q{x}"),
                    mesh: Mesh::quad(Vec3::new(x, 0.0, 0.0), Vec3::X * size, Vec3::Z * size, 2, 2),
                    material: Material::lambert(0.5),
                })
                .collect(),
            camera: Camera { eye: Vec3::Y, target: Vec3::ZERO, up: Vec3::Z, hfov_degrees: 60.0, width: 4, height: 4 },
            point_lights: Vec::new(),
            textures: Vec::new(),
        }
    }

    /// Points land on each emitter in proportion to its power, uniformly over its area, and
    /// the density integrates to 1 over the emitting area.
    #[test]
    fn samples_follow_power_and_the_pdf_integrates_to_one() {
        let s = scene(&[(0.0, 1.0), (5.0, 2.0), (9.0, 1.0)]);
        let e = Emitters::new(&s, &[Vec3::splat(2.0), Vec3::splat(1.0), Vec3::ZERO]);
        // powers: 2 x 1 and 1 x 4: 1/3 and 2/3; the third emits nothing
        let n = 60_000;
        let mut counts = [0usize; 3];
        let mut left_half = 0usize;
        for k in 0..n {
            let u = (k as f32 + 0.5) / n as f32;
            let uv = Vec2::new(
                ((k as u64 * 7919) % n as u64) as f32 / n as f32,
                ((k as u64 * 104_729) % n as u64) as f32 / n as f32,
            );
            let (p, normal, _, _) = e.sample(u, uv).unwrap();
            assert!((normal.y.abs() - 1.0).abs() < 1e-6);
            let which = if p.x < 2.0 {
                0
            } else if p.x < 8.0 {
                1
            } else {
                2
            };
            counts[which] += 1;
            if which == 1 && p.x < 6.0 {
                left_half += 1;
            }
        }
        assert!((counts[0] as f32 / n as f32 - 1.0 / 3.0).abs() < 0.01, "{counts:?}");
        assert_eq!(counts[2], 0);
        assert!((left_half as f32 / counts[1] as f32 - 0.5).abs() < 0.02);
        let integral = e.pdf_area(0) * 1.0 + e.pdf_area(1) * 4.0 + e.pdf_area(2) * 1.0;
        assert!((integral - 1.0).abs() < 1e-5, "{integral}");
        assert!(Emitters::new(&s, &[]).is_empty() && Emitters::new(&s, &[]).sample(0.5, Vec2::splat(0.5)).is_none());
    }
}
