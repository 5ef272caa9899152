//! A user's HDR environment map as the real scene: the backdrop. As three.js's ground-projected
//! skybox and Unreal's HDRI backdrop do, the map's lower hemisphere is projected from the
//! map's centre of projection (the probe, `camera_height` above the ground) onto a ground disc
//! of radius `ground_radius` at y = 0; everything else is the map at infinity. A camera at the
//! probe sees the map unchanged; one elsewhere sees the ground in perspective.
//!
//! What the compositor knows of that scene is the ground ([`Backdrop::real_scene`]): patches
//! whose radiance is what the camera sees of the map there and whose reflectance is estimated
//! from it as a capture estimates it, radiance over the irradiance the map gives, ρ = π L / E.
//! The truth's ground ([`Backdrop::ground`]) is the same estimate per texel.

use envmap_sphere::EnvMap;
use glam::{Vec2, Vec3};
use rayon::prelude::*;

use crate::{Patch, RealScene, RealSceneError};

/// The largest reflectance an estimate takes (radiance over irradiance can exceed 1 where the
/// map's ground is brighter than a white surface under its sky could be).
pub const MAX_REFLECTANCE: f32 = 0.98;

/// The ground-projected backdrop of a map.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Backdrop {
    /// Height of the map's centre of projection above the ground, metres: where the map was
    /// taken (a tripod's 1.6 m by default).
    pub camera_height: f32,
    /// Radius of the ground disc the lower hemisphere is projected onto, metres.
    pub ground_radius: f32,
    /// Angular segments of the ground's patches (the compositor's receivers).
    pub segments: u32,
}

impl Backdrop {
    /// The default probe height, metres.
    pub const DEFAULT_CAMERA_HEIGHT: f32 = 1.6;
    /// The default ground radius, metres.
    pub const DEFAULT_GROUND_RADIUS: f32 = 20.0;
    /// The default angular segments: patches about 13 % as wide as they are far from the
    /// probe's foot.
    pub const DEFAULT_SEGMENTS: u32 = 48;

    /// A backdrop with the probe `camera_height` above a ground disc of `ground_radius`.
    ///
    /// # Errors
    /// [`RealSceneError::Parameter`] unless the height is in (0, 10 km], the radius is in
    /// [the height / 100, 100 km] and not below it by more than that ratio.
    pub fn new(camera_height: f32, ground_radius: f32) -> Result<Self, RealSceneError> {
        if !(camera_height.is_finite() && camera_height > 0.0 && camera_height <= 1e4) {
            return Err(RealSceneError::Parameter(format!(
                "camera height {camera_height} m: it must be above the ground, at most 10 km"
            )));
        }
        if !(ground_radius.is_finite() && ground_radius >= camera_height * 0.01 && ground_radius <= 1e5) {
            return Err(RealSceneError::Parameter(format!(
                "ground radius {ground_radius} m: from a hundredth of the camera height ({camera_height} m) to 100 km"
            )));
        }
        Ok(Self { camera_height, ground_radius, segments: Self::DEFAULT_SEGMENTS })
    }

    /// The map's centre of projection.
    #[must_use]
    pub fn probe(&self) -> Vec3 {
        Vec3::new(0.0, self.camera_height, 0.0)
    }

    /// Refuses a camera the backdrop cannot be seen from: not finite, or not above the ground.
    ///
    /// # Errors
    /// [`RealSceneError::Parameter`].
    pub fn check_camera(camera: &scene::Camera) -> Result<(), RealSceneError> {
        if !(camera.eye.is_finite() && camera.target.is_finite()) || camera.eye == camera.target {
            return Err(RealSceneError::Parameter(format!(
                "camera at {} looking at {}: not a view",
                camera.eye, camera.target
            )));
        }
        if camera.eye.y <= 0.0 {
            return Err(RealSceneError::Parameter(format!(
                "camera at {}: it is not above the ground (y = 0)",
                camera.eye
            )));
        }
        Ok(())
    }

    /// Where the ray from `o` (above the ground) along unit `d` meets the ground disc.
    #[must_use]
    pub fn ground_hit(&self, o: Vec3, d: Vec3) -> Option<Vec3> {
        if o.y <= 0.0 || d.y >= 0.0 {
            return None;
        }
        let mut p = o + d * (-o.y / d.y);
        p.y = 0.0;
        (Vec2::new(p.x, p.z).length() <= self.ground_radius && p.is_finite()).then_some(p)
    }

    /// The map's radiance projected onto ground point `p`.
    #[must_use]
    pub fn ground_radiance(&self, map: &EnvMap, p: Vec3) -> Vec3 {
        let d = p - self.probe();
        if d.length_squared() > 0.0 { map.lookup(d.normalize()) } else { map.lookup(Vec3::NEG_Y) }
    }

    /// What a ray from `o` along unit `d` sees: the ground where it meets the disc, the map
    /// beyond.
    #[must_use]
    pub fn seen(&self, map: &EnvMap, o: Vec3, d: Vec3) -> Vec3 {
        match self.ground_hit(o, d) {
            Some(p) => self.ground_radiance(map, p),
            None => map.lookup(d),
        }
    }

    /// The backplate `camera` sees (HDR, row-major): each pixel the mean over `n` x `n`
    /// stratified positions in it (the box filter, so the disc's edge is antialiased).
    #[must_use]
    pub fn plate(&self, map: &EnvMap, camera: &scene::Camera, n: u32) -> Vec<Vec3> {
        let n = n.clamp(1, 16);
        let rays = camera.rays();
        let w = camera.width as usize;
        (0..w * camera.height as usize)
            .into_par_iter()
            .map(|k| {
                let (x, y) = ((k % w) as f32, (k / w) as f32);
                let mut sum = Vec3::ZERO;
                for j in 0..n {
                    for i in 0..n {
                        let (o, d) = rays.ray(x + (i as f32 + 0.5) / n as f32, y + (j as f32 + 0.5) / n as f32);
                        sum += self.seen(map, o, d);
                    }
                }
                sum / (n * n) as f32
            })
            .collect()
    }

    /// The irradiance the map gives the open ground: its upper hemisphere, cosine-weighted.
    #[must_use]
    pub fn ground_irradiance(map: &EnvMap) -> Vec3 {
        map.irradiance(Vec3::Y)
    }

    /// A capture's estimate of a Lambertian reflectance: π `radiance` over `irradiance`, per
    /// channel, within [0, [`MAX_REFLECTANCE`]] (0 where no light arrives).
    #[must_use]
    pub fn reflectance(radiance: Vec3, irradiance: Vec3) -> Vec3 {
        Vec3::from_array(std::array::from_fn(|c| {
            let (l, e) = (radiance[c], irradiance[c]);
            if e > 0.0 && l.is_finite() && e.is_finite() {
                (std::f32::consts::PI * l / e).clamp(0.0, MAX_REFLECTANCE)
            } else {
                0.0
            }
        }))
    }

    /// The ring radii of the ground's patches: a cap of a quarter of the camera height (at most
    /// the radius), then rings about as wide as a segment is long, to the disc's edge.
    fn rings(&self) -> Vec<f32> {
        let r = self.ground_radius;
        let growth = 1.0 + std::f32::consts::TAU / self.segments.max(3) as f32;
        let mut rings = vec![(0.25 * self.camera_height).min(r)];
        while let Some(&last) = rings.last().filter(|&&last| last < r) {
            // the last ring is at least half as wide as the one before it
            let next = last * growth;
            rings.push(if r < last + 1.5 * (next - last) { r } else { next });
        }
        rings
    }

    /// The real scene the compositor knows: the ground disc as patches (a cap of triangular
    /// patches around the probe's foot, then rings), each with the mean of the projected map
    /// over 4 x 4 of its points as its radiance and [`Backdrop::reflectance`] of that under
    /// [`Backdrop::ground_irradiance`]; `camera` is the view composited.
    #[must_use]
    pub fn real_scene(&self, map: &EnvMap, camera: &scene::Camera) -> RealScene {
        self.real_scene_from(&|p| self.ground_radiance(map, p), Self::ground_irradiance(map), camera)
    }

    /// [`Backdrop::real_scene`] with the ground's radiance at each point from `radiance` (a
    /// photograph's, [`crate::PhotoGround`]) under irradiance `e`.
    #[must_use]
    pub fn real_scene_from(
        &self,
        radiance: &(dyn Fn(Vec3) -> Vec3 + Sync),
        e: Vec3,
        camera: &scene::Camera,
    ) -> RealScene {
        let s = self.segments.max(3);
        let at = |r: f32, k: u32| {
            let (sin, cos) = (std::f32::consts::TAU * k as f32 / s as f32).sin_cos();
            Vec3::new(r * cos, 0.0, r * sin)
        };
        let mut corners = Vec::new();
        let rings = self.rings();
        for k in 0..s {
            // corners counter-clockwise seen from above (normal +y); the cap's two last corners
            // are the centre
            corners.push([at(rings[0], k + 1), at(rings[0], k), Vec3::ZERO, Vec3::ZERO]);
        }
        for pair in rings.windows(2) {
            for k in 0..s {
                corners.push([at(pair[0], k), at(pair[0], k + 1), at(pair[1], k + 1), at(pair[1], k)]);
            }
        }
        let patches = corners
            .into_par_iter()
            .map(|mut c| {
                // corners as [inner k, inner k+1, outer k+1, outer k] wind clockwise from above
                if (c[1] - c[0]).cross(c[3] - c[0]).y < 0.0 {
                    c.swap(1, 3);
                }
                let mut p = Patch { corners: c, reflectance: Vec3::ZERO, emission: Vec3::ZERO, radiance: Vec3::ZERO };
                let n = 4;
                let mut sum = Vec3::ZERO;
                for j in 0..n {
                    for i in 0..n {
                        let q = p.point((i as f32 + 0.5) / n as f32, (j as f32 + 0.5) / n as f32);
                        sum += radiance(q);
                    }
                }
                p.radiance = sum / (n * n) as f32;
                p.reflectance = Self::reflectance(p.radiance, e);
                p
            })
            .collect();
        RealScene { name: "backdrop".into(), patches, camera: *camera, environment_lit: true }
    }

    /// The truth's ground: a disc of `segments` x 4 triangles (texture coordinates across its
    /// square, y up) and a Lambertian texture of `texels` x `texels` holding
    /// [`Backdrop::reflectance`] of the projected map at each texel's centre (sRGB, 8 bits), so
    /// that the ground lit by the map without the object shows the backplate.
    #[must_use]
    pub fn ground(&self, map: &EnvMap, texels: u32) -> (scene::Object, scene::Texture) {
        self.ground_from(&|p| self.ground_radiance(map, p), Self::ground_irradiance(map), texels)
    }

    /// [`Backdrop::ground`] with the ground's radiance at each point from `radiance` under
    /// irradiance `e`.
    #[must_use]
    pub fn ground_from(
        &self,
        radiance: &(dyn Fn(Vec3) -> Vec3 + Sync),
        e: Vec3,
        texels: u32,
    ) -> (scene::Object, scene::Texture) {
        let r = self.ground_radius;
        let t = texels.clamp(1, 8192);
        let texel_point = |k: usize| {
            let (i, j) = ((k % t as usize) as f32, (k / t as usize) as f32);
            Vec3::new(((i + 0.5) / t as f32 - 0.5) * 2.0 * r, 0.0, ((j + 0.5) / t as f32 - 0.5) * 2.0 * r)
        };
        let texels_rgba: Vec<[u8; 4]> = (0..(t * t) as usize)
            .into_par_iter()
            .map(|k| {
                let rho = Self::reflectance(radiance(texel_point(k)), e);
                let c = rho.to_array().map(scene::texture::linear_to_srgb8);
                [c[0], c[1], c[2], 255]
            })
            .collect();
        let texture = scene::Texture {
            width: t,
            height: t,
            texels: texels_rgba,
            wrap: [scene::Wrap::Clamp; 2],
            filter: scene::Filter::Linear,
        };
        let n = self.segments.max(3) * 4;
        let mut positions = vec![Vec3::ZERO];
        positions.extend((0..n).map(|k| {
            let (sin, cos) = (std::f32::consts::TAU * k as f32 / n as f32).sin_cos();
            Vec3::new(r * cos, 0.0, r * sin)
        }));
        let uvs = positions.iter().map(|p| Vec2::new(p.x / (2.0 * r) + 0.5, p.z / (2.0 * r) + 0.5)).collect();
        // (centre, k + 1, k) winds counter-clockwise seen from above
        let indices = (0..n).map(|k| [0, 1 + (k + 1) % n, 1 + k]).collect();
        let maps = scene::Maps {
            base_color: Vec3::ONE,
            metallic: 0.0,
            roughness: 1.0,
            emissive: Vec3::ZERO,
            base_color_texture: Some(0),
            metallic_roughness_texture: None,
            emissive_texture: None,
            specular: false,
        };
        let object = scene::Object {
            name: "ground".into(),
            mesh: scene::Mesh { positions, normals: Some(vec![Vec3::Y; n as usize + 1]), indices, uvs: Some(uvs) },
            material: scene::Material { maps: Some(maps), ..scene::Material::lambert(1.0) },
        };
        (object, texture)
    }
}

/// A user's photograph as the backplate of a backdrop: the ground the camera sees in it takes
/// the photograph's radiance, the ground it does not see the probe's projection
/// ([`Backdrop::ground_radiance`], the probe at the backdrop's centre of projection). Where the
/// photograph clipped, a ground pixel's channel is the probe's projection of the same point
/// where that is brighter (the clip is a lower bound; the probe, an HDR capture of the same
/// place, saw past it).
#[derive(Clone, Debug)]
pub struct PhotoGround {
    /// The ground projection (the probe's height, the disc).
    pub backdrop: Backdrop,
    /// The camera that took the photograph (its size the photograph's).
    pub camera: scene::Camera,
    /// The photograph in the probe's units, clipped channels raised as above (row-major).
    pub plate: Vec<Vec3>,
    /// The radiance a channel of the photograph saturates at (the probe's units), if it clips.
    pub clip: Option<f32>,
    /// Pixels whose clipped channels the probe raised.
    pub raised: usize,
}

impl PhotoGround {
    /// The ground of `photo` (at `camera`'s size; times `exposure`, in `probe`'s units) seen
    /// by `camera`, above `backdrop`'s ground.
    ///
    /// # Errors
    /// [`RealSceneError::Parameter`] when the photograph's size is not the camera's.
    pub fn new(
        backdrop: Backdrop,
        probe: &EnvMap,
        (photo, exposure): (&crate::Photograph, f32),
        camera: scene::Camera,
    ) -> Result<Self, RealSceneError> {
        if (photo.width, photo.height) != (camera.width, camera.height) {
            return Err(RealSceneError::Parameter(format!(
                "a photograph of {} x {} for a camera of {} x {}",
                photo.width, photo.height, camera.width, camera.height
            )));
        }
        let rays = camera.rays();
        let w = camera.width as usize;
        let (plate, raised): (Vec<Vec3>, Vec<bool>) =
            (0..photo.radiance.len())
                .into_par_iter()
                .map(|k| {
                    let (l, mask) = (photo.radiance[k] * exposure, photo.clipped[k]);
                    if mask == 0 {
                        return (l, false);
                    }
                    let (o, d) = rays.ray((k % w) as f32 + 0.5, (k / w) as f32 + 0.5);
                    let Some(p) = backdrop.ground_hit(o, d) else { return (l, false) };
                    let seen = backdrop.ground_radiance(probe, p);
                    let up = Vec3::from_array(std::array::from_fn(|c| {
                        if mask & (1 << c) != 0 { l[c].max(seen[c]) } else { l[c] }
                    }));
                    (up, up != l)
                })
                .unzip();
        let raised = raised.iter().filter(|&&r| r).count();
        Ok(Self { backdrop, camera, plate, clip: photo.clip.map(|c| c * exposure), raised })
    }

    /// The radiance of ground point `p`: the plate's (bilinear) where the camera sees it, the
    /// probe's projection elsewhere.
    #[must_use]
    pub fn radiance(&self, probe: &EnvMap, p: Vec3) -> Vec3 {
        let (w, h) = (self.camera.width as f32, self.camera.height as f32);
        match self.camera.project(p) {
            Some(xy) if xy.x >= 0.0 && xy.y >= 0.0 && xy.x < w && xy.y < h => {
                let (x, y) = ((xy.x - 0.5).clamp(0.0, w - 1.0), (xy.y - 0.5).clamp(0.0, h - 1.0));
                let (x0, y0) = (x.floor() as usize, y.floor() as usize);
                let (x1, y1) = ((x0 + 1).min(w as usize - 1), (y0 + 1).min(h as usize - 1));
                let (fx, fy) = (x - x0 as f32, y - y0 as f32);
                let at = |i: usize, j: usize| self.plate[j * w as usize + i];
                at(x0, y0).lerp(at(x1, y0), fx).lerp(at(x0, y1).lerp(at(x1, y1), fx), fy)
            }
            _ => self.backdrop.ground_radiance(probe, p),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn gradient_map() -> EnvMap {
        // a sky of 1 over a ground whose radiance varies with direction
        EnvMap::from_texels(64, 32, |i, j| {
            if j < 16 { Vec3::ONE } else { Vec3::new(0.1 + 0.2 * i as f32 / 64.0, 0.15, 0.1 + 0.01 * j as f32) }
        })
    }

    fn camera() -> scene::Camera {
        scene::Camera {
            eye: Vec3::new(0.0, 1.6, 0.0),
            target: Vec3::new(0.0, 0.3, 3.0),
            up: Vec3::Y,
            hfov_degrees: 60.0,
            width: 64,
            height: 48,
        }
    }

    #[test]
    fn a_camera_at_the_probe_sees_the_map_unchanged() {
        let map = gradient_map();
        let b = Backdrop::new(1.6, 20.0).unwrap();
        let rays = camera().rays();
        for k in 0..64 * 48 {
            let (o, d) = rays.ray((k % 64) as f32 + 0.5, (k / 64) as f32 + 0.5);
            let (seen, direct) = (b.seen(&map, o, d), map.lookup(d));
            assert!((seen - direct).abs().max_element() < 1e-4, "pixel {k}: {seen} against {direct}");
        }
    }

    #[test]
    fn ground_points_project_from_the_probe() {
        let b = Backdrop::new(2.0, 10.0).unwrap();
        // from a camera elsewhere, the ground point straight ahead 2 m out, seen from the probe
        let p = b.ground_hit(Vec3::new(1.0, 3.0, 0.0), Vec3::new(1.0, -3.0, 2.0).normalize()).unwrap();
        assert!((p - Vec3::new(2.0, 0.0, 2.0)).length() < 1e-5, "{p}");
        assert!(
            b.ground_hit(Vec3::new(0.0, 1.0, 0.0), Vec3::new(1.0, -0.01, 0.0).normalize()).is_none(),
            "past the edge"
        );
        assert!(b.ground_hit(Vec3::new(0.0, 1.0, 0.0), Vec3::Y).is_none());
        assert!(b.ground_hit(Vec3::new(0.0, -1.0, 0.0), Vec3::NEG_Y).is_none(), "from below");
    }

    #[test]
    fn reflectance_is_radiance_over_irradiance_within_its_range() {
        // a white sky of radiance 1 gives E = pi: a ground of radiance 0.3 has reflectance 0.3
        let sky = EnvMap::from_texels(256, 128, |_, j| if j < 64 { Vec3::ONE } else { Vec3::ZERO });
        let e = Backdrop::ground_irradiance(&sky);
        assert!((e - Vec3::splat(std::f32::consts::PI)).abs().max_element() < 1e-3, "{e}");
        let rho = Backdrop::reflectance(Vec3::new(0.3, 0.0, 5.0), e);
        assert!((rho - Vec3::new(0.3, 0.0, MAX_REFLECTANCE)).abs().max_element() < 1e-3, "{rho}");
        // no light, or not a number: nothing to estimate
        assert_eq!(Backdrop::reflectance(Vec3::ONE, Vec3::ZERO), Vec3::ZERO);
        assert_eq!(Backdrop::reflectance(Vec3::NAN, Vec3::ONE), Vec3::ZERO);
    }

    #[test]
    fn the_ground_patches_tile_the_disc_facing_up() {
        let map = gradient_map();
        for (h, r) in [(1.6, 20.0), (1.6, 0.3), (0.01, 1000.0), (50.0, 60.0)] {
            let b = Backdrop::new(h, r).unwrap();
            let s = b.real_scene(&map, &camera());
            let area: f32 = s.patches.iter().map(Patch::area).sum();
            let disc = std::f32::consts::PI * r * r;
            // chords: a polygon of 48 sides holds 99.7 % of its circle
            assert!((area / disc - 0.997).abs() < 0.003, "{h}, {r}: {area} of {disc}");
            for p in &s.patches {
                assert!(p.normal().y > 0.999, "{h}, {r}: {p:?}");
                assert!(p.reflectance.max_element() <= MAX_REFLECTANCE && p.radiance.is_finite());
            }
            assert!(s.patches.len() < 10_000, "{h}, {r}: {} patches", s.patches.len());
        }
    }

    #[test]
    fn the_truths_ground_shows_the_backplate() {
        // a ground whose radiance is what the sky over it gives a reflectance of 0.1 .. 0.3
        let map = gradient_map();
        let b = Backdrop::new(1.6, 20.0).unwrap();
        let (ground, texture) = b.ground(&map, 256);
        let e = Backdrop::ground_irradiance(&map);
        for (k, &p) in ground.mesh.positions.iter().enumerate().step_by(7) {
            let uv = ground.mesh.uvs.as_ref().unwrap()[k];
            let m = ground.material.at(std::slice::from_ref(&texture), uv * 0.999 + Vec2::splat(0.0005));
            assert!(m.specular.is_none());
            let shown = m.albedo * e / std::f32::consts::PI;
            let want = b.ground_radiance(&map, p * 0.999);
            assert!(
                (shown - want).abs().max_element() < 0.02 * want.max_element() + 2e-3,
                "{p}: {shown} against {want}"
            );
        }
    }

    #[test]
    fn bad_heights_radii_and_cameras_are_refused() {
        for (h, r) in [(0.0, 10.0), (-1.0, 10.0), (f32::NAN, 10.0), (1.6, 0.0), (1.6, f32::INFINITY), (1e6, 1e6)] {
            assert!(matches!(Backdrop::new(h, r), Err(RealSceneError::Parameter(_))), "{h}, {r}");
        }
        let below = scene::Camera { eye: Vec3::new(0.0, -0.5, 0.0), ..camera() };
        assert!(Backdrop::check_camera(&below).unwrap_err().to_string().contains("not above the ground"));
        assert!(Backdrop::check_camera(&camera()).is_ok());
    }
}
