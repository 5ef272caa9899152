//! Cube-map parameterization with the Vulkan / OpenGL face convention, so a strip uploads
//! directly as a GPU cube texture.
//!
//! Faces in layer order +X, -X, +Y, -Y, +Z, -Z. Face coordinates (s, t) in [0, 1]^2 with
//! a = 2s - 1, b = 2t - 1: +X (1, -b, -a); -X (-1, -b, a); +Y (a, 1, b); -Y (a, -1, -b);
//! +Z (a, -b, 1); -Z (-a, -b, -1) (then normalized).

use glam::{Vec2, Vec3};

/// One face of a cube map, in GPU layer order.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
#[repr(u8)]
pub enum CubeFace {
    /// +X
    PosX = 0,
    /// -X
    NegX = 1,
    /// +Y
    PosY = 2,
    /// -Y
    NegY = 3,
    /// +Z
    PosZ = 4,
    /// -Z
    NegZ = 5,
}

impl CubeFace {
    /// All faces in layer order.
    pub const ALL: [CubeFace; 6] =
        [CubeFace::PosX, CubeFace::NegX, CubeFace::PosY, CubeFace::NegY, CubeFace::PosZ, CubeFace::NegZ];

    /// The face for layer index 0..6.
    #[must_use]
    pub fn from_index(k: usize) -> Option<Self> {
        Self::ALL.get(k).copied()
    }
}

/// Face and face coordinates (s, t) in [0, 1]^2 of a non-zero direction.
///
/// Ties between faces (edges, corners) go to X before Y before Z, deterministically.
#[must_use]
pub fn cube_dir_to_uv(dir: Vec3) -> (CubeFace, Vec2) {
    let a = dir.abs();
    let (face, sc, tc, ma) = if a.x >= a.y && a.x >= a.z {
        if dir.x >= 0.0 { (CubeFace::PosX, -dir.z, -dir.y, a.x) } else { (CubeFace::NegX, dir.z, -dir.y, a.x) }
    } else if a.y >= a.z {
        if dir.y >= 0.0 { (CubeFace::PosY, dir.x, dir.z, a.y) } else { (CubeFace::NegY, dir.x, -dir.z, a.y) }
    } else if dir.z >= 0.0 {
        (CubeFace::PosZ, dir.x, -dir.y, a.z)
    } else {
        (CubeFace::NegZ, -dir.x, -dir.y, a.z)
    };
    let st = (Vec2::new(sc, tc) / ma + 1.0) * 0.5;
    (face, st.clamp(Vec2::ZERO, Vec2::ONE))
}

/// Unit direction of face coordinates (s, t) on `face`.
#[must_use]
pub fn cube_uv_to_dir(face: CubeFace, st: Vec2) -> Vec3 {
    let (a, b) = (2.0 * st.x - 1.0, 2.0 * st.y - 1.0);
    let d = match face {
        CubeFace::PosX => Vec3::new(1.0, -b, -a),
        CubeFace::NegX => Vec3::new(-1.0, -b, a),
        CubeFace::PosY => Vec3::new(a, 1.0, b),
        CubeFace::NegY => Vec3::new(a, -1.0, -b),
        CubeFace::PosZ => Vec3::new(a, -b, 1.0),
        CubeFace::NegZ => Vec3::new(-a, -b, -1.0),
    };
    d.normalize()
}

/// Solid angle per unit area of face coordinates: d omega = 4 / (1 + a^2 + b^2)^(3/2) ds dt.
#[must_use]
pub fn cube_jacobian(st: Vec2) -> f32 {
    let (a, b) = (2.0 * st.x - 1.0, 2.0 * st.y - 1.0);
    4.0 / (1.0 + a * a + b * b).powf(1.5)
}

/// Exact solid angle of the face rectangle [s0, s1] x [t0, t1].
#[must_use]
pub fn cube_rect_solid_angle(s0: f64, t0: f64, s1: f64, t1: f64) -> f64 {
    // The solid angle of [0,a] x [0,b] on the plane at distance 1 is atan(ab / sqrt(a^2+b^2+1)).
    let f = |a: f64, b: f64| (a * b).atan2((a * a + b * b + 1.0).sqrt());
    let (a0, a1, b0, b1) = (2.0 * s0 - 1.0, 2.0 * s1 - 1.0, 2.0 * t0 - 1.0, 2.0 * t1 - 1.0);
    f(a1, b1) - f(a0, b1) - f(a1, b0) + f(a0, b0)
}
