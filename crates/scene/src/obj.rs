//! Wavefront OBJ export: one `o` per object, vertex normals where the object shades with them,
//! each object's material in a comment, so another renderer can render the same geometry.

use crate::{Scene, SceneError};
use std::fmt::Write as _;
use std::path::Path;

impl Scene {
    /// The scene's geometry as OBJ text (1-based indices, counter-clockwise faces).
    #[must_use]
    pub fn to_obj(&self) -> String {
        let mut out = String::new();
        let c = &self.camera;
        let _ = writeln!(out, "# envshadow scene {} ({} triangles), +Y up, metres", self.name, self.triangle_count());
        let _ = writeln!(
            out,
            "# camera eye {} {} {} target {} {} {} up {} {} {} hfov {} deg {} x {}",
            c.eye.x,
            c.eye.y,
            c.eye.z,
            c.target.x,
            c.target.y,
            c.target.z,
            c.up.x,
            c.up.y,
            c.up.z,
            c.hfov_degrees,
            c.width,
            c.height
        );
        for l in &self.point_lights {
            let (p, i) = (l.position, l.intensity);
            let _ = writeln!(out, "# point light at {} {} {} intensity {} {} {} W/sr", p.x, p.y, p.z, i.x, i.y, i.z);
        }
        let (mut v_base, mut n_base) = (1usize, 1usize);
        for o in &self.objects {
            let _ = writeln!(out, "o {}", o.name);
            let _ = writeln!(out, "# material {}", o.material.describe());
            for p in &o.mesh.positions {
                let _ = writeln!(out, "v {} {} {}", p.x, p.y, p.z);
            }
            if let Some(normals) = &o.mesh.normals {
                for n in normals {
                    let _ = writeln!(out, "vn {} {} {}", n.x, n.y, n.z);
                }
            }
            for t in &o.mesh.indices {
                let v = t.map(|i| i as usize + v_base);
                if o.mesh.normals.is_some() {
                    let n = t.map(|i| i as usize + n_base);
                    let _ = writeln!(out, "f {}//{} {}//{} {}//{}", v[0], n[0], v[1], n[1], v[2], n[2]);
                } else {
                    let _ = writeln!(out, "f {} {} {}", v[0], v[1], v[2]);
                }
            }
            v_base += o.mesh.positions.len();
            n_base += o.mesh.normals.as_ref().map_or(0, Vec::len);
        }
        out
    }

    /// Writes [`Scene::to_obj`] to `path`.
    ///
    /// # Errors
    /// [`SceneError::Io`] naming the file.
    pub fn write_obj(&self, path: &Path) -> Result<(), SceneError> {
        std::fs::write(path, self.to_obj()).map_err(|source| SceneError::Io { path: path.to_path_buf(), source })
    }
}
