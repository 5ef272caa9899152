//! The built-in real scenes, procedural (no capture files), and perturbed reconstructions.

use glam::Vec3;

use crate::{Patch, RealScene, RealSceneError};

/// Names accepted by [`RealScene::builtin`].
pub const BUILTIN_REAL_SCENES: &[&str] = &["ar_room", "ar_ground"];

/// How the reconstruction differs from the real scene: what a capture gets wrong.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Perturbation {
    /// Every reflectance times this (clamped below 0.98).
    pub reflectance_scale: f32,
    /// Patches this many times coarser along each side (1: as built).
    pub coarsen: u32,
}

impl Perturbation {
    /// The reconstruction as built.
    pub const NONE: Self = Self { reflectance_scale: 1.0, coarsen: 1 };
}

impl Default for Perturbation {
    fn default() -> Self {
        Self::NONE
    }
}

/// Patches being built: cell size and reflectance scale applied to every surface.
struct Builder {
    patches: Vec<Patch>,
    cell: f32,
    scale: f32,
}

impl Builder {
    /// The parallelogram from `corner` spanned by `u`, `v` (normal u x v) in cells of about
    /// `cell` (times the coarsening).
    fn grid(&mut self, corner: Vec3, u: Vec3, v: Vec3, reflectance: Vec3, emission: Vec3) {
        let nu = (u.length() / self.cell - 1e-3).ceil().max(1.0) as u32;
        let nv = (v.length() / self.cell - 1e-3).ceil().max(1.0) as u32;
        let reflectance = (reflectance * self.scale).min(Vec3::splat(0.98));
        for j in 0..nv {
            for i in 0..nu {
                let at = |a: u32, b: u32| corner + u * (a as f32 / nu as f32) + v * (b as f32 / nv as f32);
                self.patches.push(Patch {
                    corners: [at(i, j), at(i + 1, j), at(i + 1, j + 1), at(i, j + 1)],
                    reflectance,
                    emission,
                    radiance: emission,
                });
            }
        }
    }

    /// A box's faces, normals out; `faces` masks them in the order +x, -x, +y, -y, +z, -z.
    fn cuboid(&mut self, min: Vec3, max: Vec3, reflectance: Vec3, faces: [bool; 6]) {
        let d = max - min;
        let (x, y, z) = (Vec3::X * d.x, Vec3::Y * d.y, Vec3::Z * d.z);
        let sides = [
            (Vec3::new(max.x, min.y, min.z), y, z),
            (min, z, y),
            (Vec3::new(min.x, max.y, min.z), z, x),
            (min, x, z),
            (Vec3::new(min.x, min.y, max.z), x, y),
            (min, y, x),
        ];
        for ((corner, u, v), keep) in sides.into_iter().zip(faces) {
            if keep {
                self.grid(corner, u, v, reflectance, Vec3::ZERO);
            }
        }
    }
}

impl RealScene {
    /// A built-in real scene as built.
    ///
    /// # Errors
    /// [`RealSceneError::Unknown`] for a name not in [`BUILTIN_REAL_SCENES`].
    pub fn builtin(name: &str) -> Result<Self, RealSceneError> {
        Self::builtin_with(name, &Perturbation::NONE)
    }

    /// A built-in real scene, reconstructed with `perturbation`. Radiances are the emission
    /// only until [`crate::solve`] runs.
    ///
    /// # Errors
    /// [`RealSceneError::Unknown`] for a name not in [`BUILTIN_REAL_SCENES`].
    pub fn builtin_with(name: &str, perturbation: &Perturbation) -> Result<Self, RealSceneError> {
        let coarsen = perturbation.coarsen.max(1) as f32;
        let scale = perturbation.reflectance_scale.max(0.0);
        match name {
            "ar_room" => Ok(ar_room(Builder { patches: Vec::new(), cell: 0.25 * coarsen, scale })),
            "ar_ground" => Ok(ar_ground(Builder { patches: Vec::new(), cell: 0.25 * coarsen, scale })),
            _ => Err(RealSceneError::Unknown(name.to_string())),
        }
    }
}

/// A 5 x 3 x 4 m room: a window of sky in the right wall and a ceiling lamp as primary
/// sources, walls, floor and ceiling as secondary ones, a table and a cabinet. 1,712 patches.
fn ar_room(mut b: Builder) -> RealScene {
    let (wall, floor, ceiling) = (Vec3::new(0.75, 0.72, 0.65), Vec3::new(0.45, 0.32, 0.22), Vec3::splat(0.8));
    let none = Vec3::ZERO;
    b.grid(Vec3::ZERO, Vec3::Z * 4.0, Vec3::X * 5.0, floor, none);
    b.grid(Vec3::Y * 3.0, Vec3::X * 5.0, Vec3::Z * 4.0, ceiling, none);
    b.grid(Vec3::ZERO, Vec3::X * 5.0, Vec3::Y * 3.0, wall, none);
    b.grid(Vec3::Z * 4.0, Vec3::Y * 3.0, Vec3::X * 5.0, wall, none);
    b.grid(Vec3::ZERO, Vec3::Y * 3.0, Vec3::Z * 4.0, wall, none);
    // the right wall (x = 5, facing -x) around a window at z 1.5..3, y 1..2.2
    let right = |z0: f32, z1: f32, y0: f32, y1: f32| (Vec3::new(5.0, y0, z0), Vec3::Z * (z1 - z0), Vec3::Y * (y1 - y0));
    for (corner, u, v) in
        [right(0.0, 4.0, 0.0, 1.0), right(0.0, 4.0, 2.2, 3.0), right(0.0, 1.5, 1.0, 2.2), right(3.0, 4.0, 1.0, 2.2)]
    {
        b.grid(corner, u, v, wall, none);
    }
    let (corner, u, v) = right(1.5, 3.0, 1.0, 2.2);
    b.grid(corner, u, v, Vec3::ZERO, Vec3::new(4.0, 4.6, 5.6));
    // the lamp: 0.5 m square just under the ceiling, facing down
    b.grid(Vec3::new(2.25, 2.98, 1.75), Vec3::X * 0.5, Vec3::Z * 0.5, Vec3::ZERO, Vec3::new(34.0, 30.0, 24.0));
    // a table and a cabinet
    let wood = Vec3::new(0.55, 0.4, 0.28);
    b.cuboid(Vec3::new(1.9, 0.71, 1.6), Vec3::new(3.1, 0.75, 2.4), wood, [true; 6]);
    for (x, z) in [(1.95, 1.65), (3.0, 1.65), (1.95, 2.3), (3.0, 2.3)] {
        b.cuboid(
            Vec3::new(x, 0.0, z),
            Vec3::new(x + 0.05, 0.71, z + 0.05),
            wood,
            [true, true, false, false, true, true],
        );
    }
    b.cuboid(
        Vec3::new(0.3, 0.0, 0.5),
        Vec3::new(0.9, 1.2, 1.3),
        Vec3::new(0.3, 0.35, 0.5),
        [true, true, true, false, true, true],
    );
    RealScene {
        name: "ar_room".into(),
        patches: b.patches,
        camera: scene::Camera {
            eye: Vec3::new(2.5, 1.7, 3.9),
            target: Vec3::new(2.3, 0.6, 0.8),
            up: Vec3::Y,
            hfov_degrees: 75.0,
            width: 640,
            height: 480,
        },
        environment_lit: false,
    }
}

/// A 12 x 12 m ground (0.5 m patches, aligned with the objects' feet so that no patch lies half
/// under an object) with two boxes and a low wall, lit by an environment map. 1,108 patches.
fn ar_ground(mut b: Builder) -> RealScene {
    let ground = b.cell;
    b.cell = ground * 2.0;
    b.grid(Vec3::new(-6.0, 0.0, -6.0), Vec3::Z * 12.0, Vec3::X * 12.0, Vec3::new(0.35, 0.33, 0.3), Vec3::ZERO);
    b.cell = ground;
    let no_bottom = [true, true, true, false, true, true];
    b.cuboid(Vec3::new(-1.5, 0.0, -1.0), Vec3::new(-0.5, 1.0, 0.0), Vec3::new(0.7, 0.3, 0.25), no_bottom);
    b.cuboid(Vec3::new(0.5, 0.0, -2.0), Vec3::new(1.5, 1.8, -1.0), Vec3::new(0.3, 0.5, 0.7), no_bottom);
    b.cuboid(Vec3::new(-3.0, 0.0, -3.5), Vec3::new(3.0, 1.2, -3.0), Vec3::splat(0.6), no_bottom);
    RealScene {
        name: "ar_ground".into(),
        patches: b.patches,
        camera: scene::Camera {
            eye: Vec3::new(0.0, 1.6, 5.5),
            target: Vec3::new(0.0, 0.5, -1.0),
            up: Vec3::Y,
            hfov_degrees: 60.0,
            width: 640,
            height: 480,
        },
        environment_lit: true,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn builtins_have_the_papers_scale_and_sane_patches() {
        for (name, count) in BUILTIN_REAL_SCENES.iter().zip([1_712, 1_108]) {
            let s = RealScene::builtin(name).unwrap();
            assert_eq!(s.patches.len(), count, "{name}: the doc comment's count");
            for p in &s.patches {
                assert!(p.area() > 1e-4 && (p.normal().length() - 1.0).abs() < 1e-4, "{name}: {p:?}");
                assert!(p.reflectance.max_element() < 1.0 && p.reflectance.min_element() >= 0.0);
            }
            // coarser reconstructions have fewer patches, covering the same area
            let coarse = RealScene::builtin_with(name, &Perturbation { coarsen: 2, ..Perturbation::NONE }).unwrap();
            assert!(coarse.patches.len() * 2 < s.patches.len(), "{name}");
            let area = |s: &RealScene| s.patches.iter().map(Patch::area).sum::<f32>();
            assert!((area(&coarse) / area(&s) - 1.0).abs() < 1e-4, "{name}");
            // darker ones scale every reflectance, emission untouched
            let dark =
                RealScene::builtin_with(name, &Perturbation { reflectance_scale: 0.8, ..Perturbation::NONE }).unwrap();
            for (d, p) in dark.patches.iter().zip(&s.patches) {
                assert!((d.reflectance - p.reflectance * 0.8).abs().max_element() < 1e-6 && d.emission == p.emission);
            }
        }
        assert!(matches!(RealScene::builtin("nope"), Err(RealSceneError::Unknown(_))));
    }

    /// The room's surfaces face into it: every patch's normal points towards the room's centre
    /// side of its plane (except the objects' outward faces, which point away from their own).
    #[test]
    fn room_faces_inwards() {
        let s = RealScene::builtin("ar_room").unwrap();
        let inside = Vec3::new(2.5, 1.5, 2.0);
        let walls = s.patches.iter().filter(|p| {
            let c = p.center();
            c.x <= 0.0 || c.x >= 5.0 || c.y <= 0.0 || c.y >= 3.0 || c.z <= 0.0 || c.z >= 4.0
        });
        let mut n = 0;
        for p in walls {
            assert!(p.normal().dot(inside - p.center()) > 0.0, "{p:?}");
            n += 1;
        }
        assert!(n > 1_000);
    }
}
