//! The paraboloid mapping of Brabec, Annen and Seidel (paper 004) in a light's frame, on the
//! CPU: a direction d in the frame of one map (its hemisphere z >= 0) maps to the point where the
//! paraboloid f(x, y) = 1/2 - (x^2 + y^2)/2 reflects d into +z, whose normal is the halfway
//! vector (d + z) — so (u, v) = (d.x, d.y) / (1 + d.z), the unit disk for the hemisphere. Depth
//! is the distance to the light between a near and a far sphere, mapped to [0, 1].
//!
//! The mapping itself, and the back map's frame (the front's turned 180° about its y axis,
//! (x, y, z) -> (-x, y, -z)), are `envmap_sphere::paraboloid`'s: the project has one paraboloid
//! mapping, and this module places it in a light's frame. The GPU shaders
//! (`crates/shadowmap-paraboloid/shaders/paraboloid.wgsl`) do the same arithmetic; tests compare
//! both.

use envmap_sphere::paraboloid::{paraboloid_dir_to_point, paraboloid_point_to_dir};
use glam::{Mat4, Vec2, Vec3};

/// Which map of a dual paraboloid: the environment maps' [`envmap_sphere::paraboloid::Hemisphere`]
/// (front around the light's forward axis, +z of its frame; back around the opposite axis).
pub use envmap_sphere::paraboloid::Hemisphere;

/// Each map covers its hemisphere plus a band of this height below the rim (z >= -margin):
/// clipping at exactly z = 0 leaves the polygonal outline of the clipped triangles (chords)
/// inside the rim circle, and receivers between chord and circle would find no occluder. The
/// (u, v) disk is scaled by [`uv_scale`] so the band still fits the map.
pub const RIM_MARGIN: f32 = 0.05;

/// The (u, v) radius of the band's edge, sqrt(1 - m²) / (1 - m) for m = [`RIM_MARGIN`]: map
/// coordinates are (u, v) divided by it.
#[must_use]
pub fn uv_scale() -> f32 {
    (1.0 - RIM_MARGIN * RIM_MARGIN).sqrt() / (1.0 - RIM_MARGIN)
}

/// A light's paraboloid frame: position, axes, and the depth range.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ParaboloidFrame {
    /// Light position, metres.
    pub position: Vec3,
    /// Unit forward axis: the centre of the front map.
    pub forward: Vec3,
    /// Unit axis perpendicular to `forward`: +x of the maps' (u, v).
    pub right: Vec3,
    /// Distance mapped to depth 0.
    pub near: f32,
    /// Distance mapped to depth 1.
    pub far: f32,
}

/// Where a point lands in a paraboloid map.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ParaboloidCoords {
    /// The map.
    pub hemisphere: Hemisphere,
    /// Map position in [-1, 1]²: the paraboloid (u, v) divided by [`uv_scale`] (the rim z = 0
    /// at radius 1 / `uv_scale()`).
    pub uv: Vec2,
    /// Normalised depth (distance - near) / (far - near).
    pub depth: f32,
}

impl ParaboloidFrame {
    /// A frame at `position` whose front map is centred on `forward`, with the depth range
    /// `[near, far]`. `forward` need not be unit; a perpendicular axis is chosen.
    #[must_use]
    pub fn new(position: Vec3, forward: Vec3, near: f32, far: f32) -> Self {
        let forward = forward.normalize_or(Vec3::NEG_Y);
        let helper = if forward.y.abs() < 0.9 { Vec3::Y } else { Vec3::X };
        let right = helper.cross(forward).normalize();
        Self { position, forward, right, near, far }
    }

    /// The up axis (+v): forward × right completes a right-handed frame (right, up, forward).
    #[must_use]
    pub fn up(&self) -> Vec3 {
        self.forward.cross(self.right)
    }

    /// World -> light space of one map: the light at the origin, the map's centre on +z.
    #[must_use]
    pub fn world_to_light(&self, hemisphere: Hemisphere) -> Mat4 {
        let (r, u, f) = match hemisphere {
            Hemisphere::Front => (self.right, self.up(), self.forward),
            Hemisphere::Back => (-self.right, self.up(), -self.forward),
        };
        let rot = Mat4::from_cols(r.extend(0.0), u.extend(0.0), f.extend(0.0), glam::Vec4::W).transpose();
        rot * Mat4::from_translation(-self.position)
    }

    /// The map a world point belongs to (front when on the rim z = 0) and its coordinates.
    #[must_use]
    pub fn project(&self, p: Vec3) -> ParaboloidCoords {
        let d = p - self.position;
        let hemisphere = if d.dot(self.forward) >= 0.0 { Hemisphere::Front } else { Hemisphere::Back };
        self.project_into(p, hemisphere).0
    }

    /// Coordinates of `p` in the given map, and its clip distance z / |d| + [`RIM_MARGIN`]
    /// (negative: outside this map's band, rejected).
    #[must_use]
    pub fn project_into(&self, p: Vec3, hemisphere: Hemisphere) -> (ParaboloidCoords, f32) {
        let l = self.world_to_light(hemisphere).transform_point3(p);
        let dist = l.length();
        if dist == 0.0 {
            // The light's own position: the centre of the map, at distance zero.
            let c = ParaboloidCoords { hemisphere, uv: Vec2::ZERO, depth: self.depth(0.0) };
            return (c, 1.0);
        }
        // `l` is in this map's frame already: the front mapping applies
        let n = l / dist;
        let uv = paraboloid_dir_to_point(n, Hemisphere::Front) / uv_scale();
        (ParaboloidCoords { hemisphere, uv, depth: self.depth(dist) }, n.z + RIM_MARGIN)
    }

    /// Normalised depth of a distance.
    #[must_use]
    pub fn depth(&self, distance: f32) -> f32 {
        (distance - self.near) / (self.far - self.near)
    }

    /// The unit world direction at `uv` of a map (the inverse of the mapping on the disk).
    #[must_use]
    pub fn direction(&self, uv: Vec2, hemisphere: Hemisphere) -> Vec3 {
        // in the front map's frame (right, up, forward); the back map's turn is the mapping's
        let local = paraboloid_point_to_dir(uv * uv_scale(), hemisphere);
        (self.right * local.x + self.up() * local.y + self.forward * local.z).normalize()
    }
}

/// Texel (column, row) from the top-left of a `resolution`² map holding [-1, 1]²,
/// as the rasterizer lays out clip space (+v up). Clamped to the map.
#[must_use]
pub fn texel_of(uv: Vec2, resolution: u32) -> (u32, u32) {
    let r = resolution as f32;
    let x = ((uv.x * 0.5 + 0.5) * r).floor().clamp(0.0, r - 1.0);
    let y = ((0.5 - uv.y * 0.5) * r).floor().clamp(0.0, r - 1.0);
    (x as u32, y as u32)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn frame() -> ParaboloidFrame {
        ParaboloidFrame::new(Vec3::new(0.3, 2.0, -0.4), Vec3::new(0.2, -1.0, 0.1), 0.01, 20.0)
    }

    #[test]
    fn project_then_direction_round_trips() {
        let f = frame();
        for k in 0..500 {
            let a = k as f32 * 2.399_963;
            let z = 1.0 - 2.0 * (k as f32 + 0.5) / 500.0;
            let s = (1.0 - z * z).sqrt();
            let d = Vec3::new(s * a.cos(), z, s * a.sin());
            let c = f.project(f.position + d * 3.0);
            assert!(c.uv.length() <= 1.0 / uv_scale() + 1e-5, "{d}: radius {}", c.uv.length());
            let back = f.direction(c.uv, c.hemisphere);
            assert!(back.dot(d) > 1.0 - 1e-5, "{d} -> {back}");
            assert!((c.depth - f.depth(3.0)).abs() < 1e-6);
        }
    }

    #[test]
    fn maps_directions_as_the_environment_maps_paraboloid_does() {
        // A frame on the world axes (forward +Z gives right +X, up +Y): each map's (u, v) is
        // envmap_sphere's paraboloid point of the direction, back map included.
        let f = ParaboloidFrame::new(Vec3::ZERO, Vec3::Z, 0.01, 10.0);
        assert!(f.right.abs_diff_eq(Vec3::X, 1e-6) && f.up().abs_diff_eq(Vec3::Y, 1e-6));
        for k in 0..400 {
            let a = k as f32 * 2.399_963;
            let z = 1.0 - 2.0 * (k as f32 + 0.5) / 400.0;
            let s = (1.0 - z * z).sqrt();
            let d = Vec3::new(s * a.cos(), s * a.sin(), z);
            let c = f.project(d * 2.0);
            assert_eq!(c.hemisphere, Hemisphere::of(d));
            let want = paraboloid_dir_to_point(d, c.hemisphere);
            assert!((c.uv * uv_scale() - want).length() < 1e-5, "{d}: {:?} vs {want}", c.uv * uv_scale());
        }
    }

    #[test]
    fn rim_lands_on_the_unit_circle_of_either_map() {
        let f = frame();
        for k in 0..64 {
            let a = k as f32 * std::f32::consts::TAU / 64.0;
            let d = f.right * a.cos() + f.up() * a.sin();
            for h in [Hemisphere::Front, Hemisphere::Back] {
                let (c, z) = f.project_into(f.position + d * 2.0, h);
                assert!(
                    (z - RIM_MARGIN).abs() < 1e-5 && (c.uv.length() * uv_scale() - 1.0).abs() < 1e-4,
                    "{h:?} {a}: {c:?}"
                );
                let (x, y) = texel_of(c.uv, 512);
                assert!(x < 512 && y < 512);
            }
        }
    }

    #[test]
    fn no_nan_at_extremes() {
        let f = frame();
        // the singular direction of each map, the light's own position, huge and tiny distances
        for (p, h) in [
            (f.position - f.forward, Hemisphere::Front),
            (f.position + f.forward, Hemisphere::Back),
            (f.position - f.forward * 1e-30, Hemisphere::Front),
            (f.position, Hemisphere::Front),
            (f.position + Vec3::splat(1e15), Hemisphere::Front),
        ] {
            let (c, z) = f.project_into(p, h);
            assert!(c.uv.is_finite() && c.depth.is_finite() && z.is_finite(), "{p}: {c:?} {z}");
            assert!(c.uv.length() <= envmap_sphere::paraboloid::PARABOLOID_MAX_RADIUS);
        }
    }
}
