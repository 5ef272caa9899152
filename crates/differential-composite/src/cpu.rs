//! The compositor on the CPU: each representative's hard shadow of the object tested by a ray
//! from the pixel's surface point to the representative's origin (what the GPU's shadow map
//! approximates), then the subtraction. The reference the GPU compositor is checked against,
//! and the compositor where there is no GPU.

use glam::Vec3;
use rayon::prelude::*;
use real_scene::Visibility;
use shaft_hierarchy::preprocess::Origin;

use crate::compositor::{Compositor, FrameTransfers};
use crate::{Mode, SyntheticObject};

/// An object's ray queries: against the shaded mesh (what the camera sees) and the
/// shadow-casting one.
pub struct ObjectBvh {
    seen: Box<dyn Visibility>,
    caster: Box<dyn Visibility>,
}

/// Builds the ray queries of a scene (the caller's tracer, e.g. `ref_tracer::SceneBvh`).
pub type BuildRays<'a> = dyn Fn(&scene::Scene) -> Box<dyn Visibility> + 'a;

impl ObjectBvh {
    /// For `object`, its shadows cast from `shadow_mesh`; `camera` is the scene's; `build`
    /// makes each mesh's ray queries (a scene of that one object).
    #[must_use]
    pub fn new(object: &SyntheticObject, shadow_mesh: &scene::Mesh, camera: scene::Camera, build: &BuildRays) -> Self {
        let one = |mesh: &scene::Mesh| {
            let o = scene::Object { mesh: mesh.clone(), ..object.to_object() };
            build(&scene::Scene {
                name: object.name.clone(),
                objects: vec![o],
                camera,
                point_lights: Vec::new(),
                textures: Vec::new(),
            })
        };
        Self { seen: one(&object.mesh), caster: one(shadow_mesh) }
    }

    /// True when the object blocks the way from `p` to `origin`.
    #[must_use]
    pub fn blocks(&self, p: Vec3, origin: &Origin) -> bool {
        match *origin {
            Origin::Point(q) => {
                let d = q - p;
                let len = d.length();
                len > 0.0 && self.caster.occluded(p, d / len, len)
            }
            Origin::Direction(d) => self.caster.occluded(p, d, f32::INFINITY),
        }
    }
}

/// Per pixel, whether its centre ray sees the object before the model.
#[must_use]
pub fn object_pixels(c: &Compositor, bvh: &ObjectBvh) -> Vec<bool> {
    let (w, h) = c.size;
    let rays = c.model.camera.rays();
    (0..w * h)
        .map(|k| {
            let (o, d) = rays.ray((k % w) as f32 + 0.5, (k / w) as f32 + 0.5);
            let px = c.pixels[k as usize];
            let behind = if px.position.is_finite() { (px.position - o).length() } else { f32::INFINITY };
            bvh.seen.first_hit(o, d).is_some_and(|(_, t)| t < behind)
        })
        .collect()
}

/// Sub-pixel offsets of the object's coverage: a 2 x 2 rotated grid (its edges antialiased as
/// the truth's jittered samples are).
const COVERAGE: [(f32, f32); 4] = [(0.375, 0.125), (0.875, 0.375), (0.625, 0.875), (0.125, 0.625)];

/// The composite as 8-bit pixels (row-major): the object shaded by the frame's irradiance and
/// blended by its coverage, the rest the photograph less each representative's transfer where
/// the object blocks the representative's origin.
#[must_use]
pub fn composite(
    c: &Compositor,
    frame: &FrameTransfers,
    object: &SyntheticObject,
    bvh: &ObjectBvh,
    mode: Mode,
) -> Vec<[u8; 3]> {
    let (w, h) = c.size;
    let rays = c.model.camera.rays();
    let eps = c.model_bvh().epsilon();
    let shade = |n: Vec3| (object.albedo / std::f32::consts::PI * frame.object_irradiance_at(n)).max(Vec3::ZERO);
    (0..h)
        .into_par_iter()
        .flat_map_iter(|y| {
            let rays = &rays;
            (0..w).map(move |x| {
                let k = (y * w + x) as usize;
                let px = c.pixels[k];
                // the object's coverage and mean radiance over the sub-pixel rays
                let (mut covered, mut object_radiance) = (0u32, Vec3::ZERO);
                for (dx, dy) in COVERAGE {
                    let (o, d) = rays.ray(x as f32 + dx, y as f32 + dy);
                    // the object's few hundred triangles first: the model is traced only where
                    // a ray finds the object, to see whether something stands in front of it
                    let Some((t, normal)) = bvh.seen.first_hit_normal(o, d) else { continue };
                    if c.model_bvh().first_hit(o, d).is_none_or(|m| m.1 > t) {
                        let n = if normal.dot(d) > 0.0 { -normal } else { normal };
                        covered += 1;
                        object_radiance += shade(n);
                    }
                }
                let alpha = covered as f32 / COVERAGE.len() as f32;
                let object_radiance = if covered > 0 { object_radiance / covered as f32 } else { Vec3::ZERO };
                if covered as usize == COVERAGE.len() {
                    return c.response.apply(object_radiance);
                }
                let mut sum = Vec3::ZERO;
                if px.slot != u32::MAX {
                    let p = px.position + px.normal * eps;
                    let slot = px.slot as usize;
                    for r in frame.reps.iter().filter(|r| bvh.blocks(p, &r.origin)) {
                        let (per_vertex, keep) = match mode {
                            Mode::Hdr => (&r.radiance, r.keep),
                            Mode::Ldr => (&r.intensity, Vec3::ONE),
                        };
                        sum += keep * (0..4).map(|v| px.weights[v] * per_vertex[slot + v]).sum::<Vec3>();
                    }
                    sum *= c.pixel_scale[k];
                }
                if sum == Vec3::ZERO && covered == 0 {
                    return c.photo_ldr[k];
                }
                match mode {
                    Mode::Hdr => {
                        let background = (c.photo_hdr[k] - sum).max(Vec3::ZERO);
                        c.response.apply(background.lerp(object_radiance, alpha))
                    }
                    Mode::Ldr => {
                        let photo = Vec3::from_array(c.photo_ldr[k].map(f32::from));
                        let background = (photo - sum).clamp(Vec3::ZERO, Vec3::splat(255.0));
                        let object = crate::ldr::codes(&c.response, object_radiance);
                        background
                            .lerp(object, alpha)
                            .round()
                            .clamp(Vec3::ZERO, Vec3::splat(255.0))
                            .to_array()
                            .map(|v| v as u8)
                    }
                }
            })
        })
        .collect()
}
