//! Paraboloid parameterization (Heidrich and Seidel; Brabec et al., paper 004): one hemisphere
//! maps onto the unit disk, two make a dual-paraboloid map.
//!
//! Front (+Z) hemisphere: p = (x, y) / (1 + z); back (-Z): p = (-x, y) / (1 - z), i.e. the
//! front formula after turning the frame 180 degrees about +Y, (x, y, z) -> (-x, y, -z). A turn,
//! not a mirror, because a rasterizer draws into these maps: a mirror would reverse triangles'
//! winding. This is the project's one paraboloid mapping: environment maps stored as dual
//! paraboloids and `shadowmap_paraboloid`'s shadow maps (in their light's frame) both use it.
//! The inverse is z = (1 - r^2)/(1 + r^2), (x, y) = 2p / (1 + r^2), with r = |p|, and
//! d omega = 4 / (1 + r^2)^2 dp: 4 at the centre, 1 on the rim z = 0.

use glam::{Vec2, Vec3};

/// Which hemisphere a paraboloid map covers.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Hemisphere {
    /// z >= 0
    Front,
    /// z <= 0
    Back,
}

impl Hemisphere {
    /// The hemisphere that contains `dir` (z = 0 goes to the front).
    #[must_use]
    pub fn of(dir: Vec3) -> Self {
        if dir.z >= 0.0 { Self::Front } else { Self::Back }
    }

    /// `dir` in the frame of this hemisphere's map, whose centre is +Z (the back map's frame is
    /// the front's turned 180 degrees about +Y). Its own inverse.
    #[must_use]
    pub fn to_map_frame(self, dir: Vec3) -> Vec3 {
        match self {
            Self::Front => dir,
            Self::Back => Vec3::new(-dir.x, dir.y, -dir.z),
        }
    }
}

/// Largest radius [`paraboloid_dir_to_point`] returns. Directions of the other hemisphere lie
/// outside the unit disk at radius (1 - z')/sqrt(1 - z'^2) for z' = their z in the map's frame; the
/// singular direction itself (z' = -1 exactly) has no image and is sent to this radius on the
/// +x axis, a finite point far outside any map.
pub const PARABOLOID_MAX_RADIUS: f32 = 1.0e4;

/// Disk point of a unit direction on `hemisphere`'s map. Directions of the other hemisphere
/// map outside the unit disk (radius > 1); none gives NaN or infinity.
///
/// For z' < 0 it computes 1 + z' as (x^2 + y^2)/(1 - z'), which has no cancellation, so points
/// near the singular direction z' -> -1 stay accurate until they reach the radius limit.
#[must_use]
pub fn paraboloid_dir_to_point(dir: Vec3, hemisphere: Hemisphere) -> Vec2 {
    let d = hemisphere.to_map_frame(dir);
    let xy = Vec2::new(d.x, d.y);
    let p = if d.z >= 0.0 {
        xy / (1.0 + d.z)
    } else {
        let r2 = xy.length_squared();
        if r2 == 0.0 {
            return Vec2::new(PARABOLOID_MAX_RADIUS, 0.0);
        }
        xy * ((1.0 - d.z) / r2)
    };
    let r = p.length();
    if r > PARABOLOID_MAX_RADIUS { p * (PARABOLOID_MAX_RADIUS / r) } else { p }
}

/// Unit direction of disk point `p` on `hemisphere`'s map (any `p`; |p| > 1 gives the other
/// hemisphere).
#[must_use]
pub fn paraboloid_point_to_dir(p: Vec2, hemisphere: Hemisphere) -> Vec3 {
    let r2 = p.length_squared();
    let k = 1.0 / (1.0 + r2);
    let d = Vec3::new(2.0 * p.x * k, 2.0 * p.y * k, (1.0 - r2) * k);
    hemisphere.to_map_frame(d.normalize())
}

/// Solid angle per unit disk area at `p`: 4 / (1 + r^2)^2.
#[must_use]
pub fn paraboloid_jacobian(p: Vec2) -> f32 {
    let s = 1.0 + p.length_squared();
    4.0 / (s * s)
}
