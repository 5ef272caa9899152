//! The view a G-buffer was rendered from, as a renderer has it: view and projection matrices
//! (perspective or orthographic, off-centre and jittered included) and the image size. What
//! techniques know of the camera; `scene::Camera` is one way to make one.

use crate::context::GpuError;
use glam::{DVec3, DVec4, Mat4, Vec3, Vec4};

/// A view: world to view space (`view`), view to wgpu's clip space (`projection`: x, y in
/// [-w, w], depth z in [0, w], y up; near and far, reversed or not, finite or infinite, as the
/// caller's renderer has them) and the image's size in pixels.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct View {
    view: Mat4,
    projection: Mat4,
    size: (u32, u32),
    eye: Vec3,
    orthographic: bool,
    // derived from the matrices once (`axis`): the wedges read it for every light
    forward: Vec3,
    rays: scene::CameraRays,
    // the pinhole it was made from, if any: its own ray generation (`scene::Camera::rays`),
    // which the reference tracer shares, is kept bit for bit through `resized`
    pinhole: Option<scene::Camera>,
}

impl View {
    /// The view of a renderer's matrices for a `width` x `height` image.
    ///
    /// # Errors
    /// [`GpuError::Failed`] for an empty image, non-finite matrices or a projection × view
    /// that maps no volume (not invertible).
    pub fn new(view: Mat4, projection: Mat4, (width, height): (u32, u32)) -> Result<Self, GpuError> {
        if width == 0 || height == 0 {
            return Err(GpuError::Failed(format!("view of {width}x{height} pixels: the image is empty")));
        }
        if !(view.is_finite() && projection.is_finite()) {
            return Err(GpuError::Failed("view: the matrices are not finite".to_string()));
        }
        let m = (projection * view).as_dmat4();
        let det = m.determinant();
        if !det.is_finite() || det == 0.0 || !m.inverse().is_finite() {
            return Err(GpuError::Failed("view: projection x view is not invertible".to_string()));
        }
        let w = row(&m, 3);
        let orthographic = w.truncate() == DVec3::ZERO;
        let eye = if orthographic {
            // a point on the view plane through the view's origin
            view.inverse().w_axis.truncate()
        } else {
            // the centre of projection: where x, y and w all vanish
            let (x, y) = (row(&m, 0), row(&m, 1));
            let a = glam::DMat3::from_cols(x.truncate(), y.truncate(), w.truncate()).transpose();
            let p = a.inverse() * -DVec3::new(x.w, y.w, w.w);
            if !p.is_finite() {
                return Err(GpuError::Failed("view: the projection has no centre".to_string()));
            }
            p.as_vec3()
        };
        let mut v = Self {
            view,
            projection,
            size: (width, height),
            eye,
            orthographic,
            forward: Vec3::ZERO,
            rays: zero_rays(),
            pinhole: None,
        };
        v.forward = v.axis();
        v.rays = v.rays_from_matrices();
        Ok(v)
    }

    /// The view of `camera`, projected with an infinite reversed-depth perspective whose near
    /// plane is at `near` (what [`crate::GBufferPass::record`] renders with).
    #[must_use]
    pub fn from_camera(camera: &scene::Camera, near: f32) -> Self {
        let (fov_y, aspect, view) = crate::gbuffer::view_and_fov(camera);
        let projection = glam::camera::rh::proj::directx::perspective_infinite_reverse(fov_y, aspect, near);
        let mut v = Self {
            view,
            projection,
            size: (camera.width.max(1), camera.height.max(1)),
            eye: camera.eye,
            orthographic: false,
            forward: Vec3::ZERO,
            rays: camera.rays(),
            pinhole: Some(*camera),
        };
        v.forward = v.axis();
        v
    }

    /// This view with its projection moved by (`dx`, `dy`) pixels (right, down): the jitter of a
    /// temporal anti-aliasing sequence.
    #[must_use]
    pub fn jittered(&self, dx: f32, dy: f32) -> Self {
        let (w, h) = (self.size.0 as f32, self.size.1 as f32);
        let shift = Mat4::from_translation(Vec3::new(2.0 * dx / w, -2.0 * dy / h, 0.0));
        let mut v = Self { projection: shift * self.projection, pinhole: None, ..*self };
        v.forward = v.axis();
        v.rays = v.rays_from_matrices();
        v
    }

    /// The same view for an image of `width` x `height` pixels (the same matrices: each pixel
    /// covers more or less of the view).
    #[must_use]
    pub fn resized(&self, width: u32, height: u32) -> Self {
        let size = (width.max(1), height.max(1));
        let pinhole = self.pinhole.map(|c| scene::Camera { width: size.0, height: size.1, ..c });
        let mut v = Self { size, pinhole, ..*self };
        v.rays = pinhole.map_or_else(|| v.rays_from_matrices(), |c| c.rays());
        v
    }

    /// World to view space.
    #[must_use]
    pub fn view(&self) -> Mat4 {
        self.view
    }

    /// View to clip space.
    #[must_use]
    pub fn projection(&self) -> Mat4 {
        self.projection
    }

    /// World to clip space.
    #[must_use]
    pub fn view_projection(&self) -> Mat4 {
        self.projection * self.view
    }

    /// Image size in pixels.
    #[must_use]
    pub fn size(&self) -> (u32, u32) {
        self.size
    }

    /// Whether the projection is orthographic (its w does not depend on the point).
    #[must_use]
    pub fn is_orthographic(&self) -> bool {
        self.orthographic
    }

    /// The centre of projection; for an orthographic view, a point of its view plane.
    #[must_use]
    pub fn eye(&self) -> Vec3 {
        self.eye
    }

    /// Unit direction the view looks along: for a perspective, from the eye through the
    /// screen's centre; for an orthographic view, away from the side whose surfaces wind
    /// counter-clockwise in NDC (y up), wgpu's default front faces: an orthographic view is
    /// taken not to mirror ([`View::is_mirrored`]), whatever its depth convention.
    #[must_use]
    pub fn forward(&self) -> Vec3 {
        self.forward
    }

    /// [`View::forward`] from the matrices.
    fn axis(&self) -> Vec3 {
        let m = self.view_projection().as_dmat4();
        let toward = row(&m, 0).truncate().cross(row(&m, 1).truncate());
        if self.orthographic {
            return (-toward).normalize_or_zero().as_vec3();
        }
        // a perspective looks from the eye through the screen's centre
        self.toward(0.0, 0.0).normalize_or_zero().as_vec3()
    }

    /// The direction from `p` toward the viewer, as a shader computes it from
    /// [`View::toward_viewer`]: `xyz - p * w`.
    #[must_use]
    pub fn toward_viewer(&self) -> Vec4 {
        if self.orthographic { (-self.forward()).extend(0.0) } else { self.eye.extend(1.0) }
    }

    /// Camera rays through the image, as `scene::CameraRays` generates them (pixel (x, y) from
    /// the top-left corner); for an orthographic view the direction is the same for every pixel
    /// and `eye` a point of the view plane.
    #[must_use]
    pub fn rays(&self) -> scene::CameraRays {
        self.rays
    }

    /// Projection × view with the depth row replaced so that clip-space depth is in [0, w] for
    /// every point whose w is at least `near` and no point is clipped by a far plane: what a
    /// pass needs that rasterizes geometry reaching to infinity over the view's pixels (the
    /// same x, y and w as the view's own). For a perspective of `scene::Camera` it is
    /// [`crate::view_projection_infinite`].
    #[must_use]
    pub fn unclipped_projection(&self, near: f32) -> Mat4 {
        let mut p = self.projection;
        // row 2 := row 3 - near e_w, column by column (glam's matrices are column-major)
        p.x_axis.z = p.x_axis.w;
        p.y_axis.z = p.y_axis.w;
        p.z_axis.z = p.z_axis.w;
        p.w_axis.z = p.w_axis.w - near;
        p * self.view
    }

    /// The depth of the view's far end, what its depth buffer is cleared to: 0 where nearer
    /// points have larger depths (reversed depth), else 1.
    #[must_use]
    pub fn far_depth(&self) -> f32 {
        let inv = self.view_projection().as_dmat4().inverse();
        let along = |z: f64| {
            let p = inv * DVec4::new(0.0, 0.0, z, 1.0);
            let p = p.truncate() / p.w;
            if self.orthographic {
                p.dot(self.forward().as_dvec3())
            } else {
                (p - self.eye.as_dvec3()).dot(self.forward().as_dvec3())
            }
        };
        if along(0.75) < along(0.25) { 0.0 } else { 1.0 }
    }

    /// The direction (f64) of a perspective's ray through NDC (`x`, `y`), scaled alike for
    /// every pixel: between two depths of the view (0.25 and 0.5 lie in front of the eye for
    /// every projection in wgpu's clip space), not from the eye, whose f32 rounding would
    /// swamp the nearness of the points.
    fn toward(&self, x: f64, y: f64) -> DVec3 {
        let m = self.view_projection().as_dmat4();
        let inv = m.inverse();
        let at = |z: f64| {
            let p = inv * DVec4::new(x, y, z, 1.0);
            p.truncate() / p.w
        };
        let d = at(0.25) - at(0.5);
        // away from the eye: where w grows
        if d.dot(row(&m, 3).truncate()) < 0.0 { -d } else { d }
    }

    fn rays_from_matrices(&self) -> scene::CameraRays {
        if self.orthographic {
            let d = self.forward();
            return scene::CameraRays { eye: self.eye, right: Vec3::ZERO, down: Vec3::ZERO, corner: d };
        }
        let (w, h) = (f64::from(self.size.0), f64::from(self.size.1));
        // NDC of pixel coordinate (px, py): x = 2 px / w - 1, y = 1 - 2 py / h; all three on
        // one plane of constant view depth
        let at = |px: f64, py: f64| self.toward(2.0 * px / w - 1.0, 1.0 - 2.0 * py / h);
        let (c, r, d) = (at(0.0, 0.0), at(1.0, 0.0), at(0.0, 1.0));
        // scale to the unit distance along the view's axis, as `scene::Camera::rays` does
        let s = 1.0 / c.dot(self.forward().as_dvec3());
        let f = |v: DVec3| (v * s).as_vec3();
        scene::CameraRays { eye: self.eye, right: f(r - c), down: f(d - c), corner: f(c) }
    }

    /// Whether the view mirrors: a surface facing the eye winds clockwise in NDC (a
    /// left-handed view), so the rasterizer's front faces (counter-clockwise, wgpu's default)
    /// face away from the viewer. An orthographic view is taken not to mirror.
    #[must_use]
    pub fn is_mirrored(&self) -> bool {
        if self.orthographic {
            return false;
        }
        let m = self.view_projection().as_dmat4();
        row(&m, 0).truncate().cross(row(&m, 1).truncate()).dot(self.forward().as_dvec3()) > 0.0
    }
}

fn row(m: &glam::DMat4, r: usize) -> DVec4 {
    DVec4::new(m.x_axis[r], m.y_axis[r], m.z_axis[r], m.w_axis[r])
}

fn zero_rays() -> scene::CameraRays {
    scene::CameraRays { eye: Vec3::ZERO, right: Vec3::ZERO, down: Vec3::ZERO, corner: Vec3::ZERO }
}

/// A box that holds every point of `scene` (a box) that `view` can see, or `None` when none:
/// the bounds of the box clipped to the view's frustum (its four sides, its near and, where the
/// projection has one, its far plane; in f64), widened by a millionth of the box's diagonal
/// against the rounding of interpolated positions. What the CPU knows of the receivers
/// without the G-buffer.
#[must_use]
pub fn conservative_bounds(scene: (Vec3, Vec3), view: &View) -> Option<(Vec3, Vec3)> {
    let (lo, hi) = scene;
    if !(lo.is_finite() && hi.is_finite() && lo.cmple(hi).all()) {
        return None;
    }
    let m = view.view_projection().as_dmat4();
    let (x, y, z, w) = (row(&m, 0), row(&m, 1), row(&m, 2), row(&m, 3));
    // inside where plane · (p, 1) >= 0
    let mut planes = vec![w + x, w - x, w + y, w - y, z, w - z];
    let (dlo, dhi) = (lo.as_dvec3(), hi.as_dvec3());
    for a in 0..3 {
        let mut e = DVec3::ZERO;
        e[a] = 1.0;
        planes.push(e.extend(-dlo[a]));
        planes.push((-e).extend(dhi[a]));
    }
    planes.retain(|p| p.truncate() != DVec3::ZERO || p.w < 0.0);
    if planes.iter().any(|p| p.truncate() == DVec3::ZERO) {
        return None; // a constant plane with nothing inside
    }
    // the intersection's boundary lies on its planes: each plane's polygon (a square holding
    // the box's projection on it) clipped by all the others
    let centre = 0.5 * (dlo + dhi);
    let half = (dhi - dlo).length().max(f64::MIN_POSITIVE) * 2.0;
    let (mut blo, mut bhi) = (DVec3::splat(f64::INFINITY), DVec3::splat(f64::NEG_INFINITY));
    for (k, plane) in planes.iter().enumerate() {
        let n = plane.truncate();
        let nn = n.length_squared();
        let origin = centre - n * ((n.dot(centre) + plane.w) / nn);
        let u = n.normalize().any_orthonormal_vector() * half;
        let v = n.normalize().cross(u);
        let mut poly = vec![origin - u - v, origin + u - v, origin + u + v, origin - u + v];
        for (j, other) in planes.iter().enumerate() {
            if j != k {
                poly = clip(&poly, *other);
            }
        }
        for p in poly {
            blo = blo.min(p);
            bhi = bhi.max(p);
        }
    }
    if !(blo.is_finite() && bhi.is_finite()) {
        return None;
    }
    let margin = DVec3::splat((dhi - dlo).length() * 1e-6);
    let (a, b) = ((blo - margin).max(dlo - margin).as_vec3(), (bhi + margin).min(dhi + margin).as_vec3());
    (a.is_finite() && b.is_finite() && a.cmple(b).all()).then_some((a, b))
}

/// `poly` clipped to the half-space `plane · (p, 1) >= 0` (Sutherland-Hodgman).
fn clip(poly: &[DVec3], plane: DVec4) -> Vec<DVec3> {
    let d = |p: DVec3| plane.truncate().dot(p) + plane.w;
    let mut out = Vec::with_capacity(poly.len() + 1);
    for k in 0..poly.len() {
        let (a, b) = (poly[k], poly[(k + 1) % poly.len()]);
        let (da, db) = (d(a), d(b));
        if da >= 0.0 {
            out.push(a);
        }
        if (da >= 0.0) != (db >= 0.0) {
            out.push(a + (b - a) * (da / (da - db)));
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::camera::{lh, rh};

    fn camera(eye: Vec3, target: Vec3) -> scene::Camera {
        scene::Camera { eye, target, up: Vec3::Y, hfov_degrees: 50.0, width: 64, height: 48 }
    }

    #[test]
    fn a_camera_view_is_the_renderers_projection_bit_for_bit() {
        let c = camera(Vec3::new(0.3, 1.2, 4.0), Vec3::new(0.0, 0.4, 0.0));
        let v = View::from_camera(&c, 1e-4);
        assert_eq!(v.view_projection(), crate::view_projection_reverse(&c, 1e-4));
        assert_eq!(v.unclipped_projection(3e-6), crate::view_projection_infinite(&c, 3e-6));
        // the matrices alone give the same view: its eye, axis and rays
        let m = View::new(v.view(), v.projection(), v.size()).unwrap();
        assert!(m.eye().distance(c.eye) < 1e-5, "{} vs {}", m.eye(), c.eye);
        let (_, _, forward) = c.basis();
        assert!(m.forward().distance(forward) < 1e-6);
        assert!(!m.is_orthographic());
        let (a, b) = (m.rays(), c.rays());
        for (x, y) in [(0.0, 0.0), (63.5, 0.5), (17.25, 47.0)] {
            let (_, da) = a.ray(x, y);
            let (_, db) = b.ray(x, y);
            assert!(da.distance(db) < 1e-5, "ray ({x}, {y}): {da} vs {db}");
        }
    }

    #[test]
    fn a_jittered_view_moves_each_pixels_ray_by_the_jitter() {
        let c = camera(Vec3::new(0.0, 1.0, 3.0), Vec3::ZERO);
        let v = View::from_camera(&c, 1e-3);
        let j = v.jittered(0.25, -0.5);
        assert_eq!(j.eye(), v.eye());
        let (_, moved) = j.rays().ray(10.0, 20.0);
        let (_, expected) = c.rays().ray(10.0 - 0.25, 20.0 + 0.5);
        assert!(moved.distance(expected) < 1e-5, "{moved} vs {expected}");
    }

    #[test]
    fn views_look_along_their_axis_and_left_handed_perspectives_mirror() {
        let view = rh::view::look_at_mat4(Vec3::new(0.0, 5.0, 0.0), Vec3::ZERO, Vec3::Z);
        let rh = rh::proj::directx::orthographic(-2.0, 2.0, -1.5, 1.5, 0.1, 20.0);
        let v = View::new(view, rh, (40, 30)).unwrap();
        assert!(v.is_orthographic());
        assert!(v.forward().distance(Vec3::NEG_Y) < 1e-6, "{}", v.forward());
        assert_eq!(v.toward_viewer(), Vec4::new(0.0, 1.0, 0.0, 0.0));
        assert!(!v.is_mirrored());
        // a left-handed perspective looks the same way, and mirrors
        let view = lh::view::look_at_mat4(Vec3::new(0.0, 5.0, 0.0), Vec3::ZERO, Vec3::Z);
        let lh = lh::proj::directx::perspective_infinite_reverse(1.0, 4.0 / 3.0, 0.1);
        let l = View::new(view, lh, (40, 30)).unwrap();
        assert!(l.forward().distance(Vec3::NEG_Y) < 1e-6 && l.is_mirrored(), "{}", l.forward());
        let r = View::new(
            rh::view::look_at_mat4(Vec3::new(0.0, 5.0, 0.0), Vec3::ZERO, Vec3::Z),
            rh::proj::directx::perspective_infinite_reverse(1.0, 4.0 / 3.0, 0.1),
            (40, 30),
        )
        .unwrap();
        assert!(r.forward().distance(Vec3::NEG_Y) < 1e-6 && !r.is_mirrored());
    }

    #[test]
    fn the_far_depth_is_zero_for_reversed_depth_and_one_otherwise() {
        let c = camera(Vec3::new(0.3, 1.2, 4.0), Vec3::ZERO);
        assert_eq!(View::from_camera(&c, 1e-4).far_depth(), 0.0);
        let look = rh::view::look_at_mat4(c.eye, c.target, Vec3::Y);
        let frustum = rh::proj::directx::frustum(-0.1, 0.1, -0.1, 0.1, 0.1, 50.0);
        assert_eq!(View::new(look, frustum, (8, 8)).unwrap().far_depth(), 1.0);
        let ortho = rh::proj::directx::orthographic(-1.0, 1.0, -1.0, 1.0, 0.0, 10.0);
        assert_eq!(View::new(look, ortho, (8, 8)).unwrap().far_depth(), 1.0);
        let reversed = rh::proj::directx::orthographic(-1.0, 1.0, -1.0, 1.0, 10.0, 0.0);
        assert_eq!(View::new(look, reversed, (8, 8)).unwrap().far_depth(), 0.0);
    }

    #[test]
    fn degenerate_views_are_refused() {
        let p = rh::proj::directx::perspective_infinite_reverse(1.0, 1.0, 0.1);
        assert!(View::new(Mat4::IDENTITY, p, (0, 4)).is_err());
        assert!(View::new(Mat4::ZERO, p, (4, 4)).is_err());
        assert!(View::new(Mat4::from_scale(Vec3::splat(f32::NAN)), p, (4, 4)).is_err());
    }

    /// Points of the box the view sees, brute force: clip-space tests on a grid.
    fn seen(scene: (Vec3, Vec3), view: &View) -> Vec<Vec3> {
        let m = view.view_projection();
        let n = 24;
        let mut out = Vec::new();
        for i in 0..=n {
            for j in 0..=n {
                for k in 0..=n {
                    let t = Vec3::new(i as f32, j as f32, k as f32) / n as f32;
                    let p = scene.0 + (scene.1 - scene.0) * t;
                    let c = m * p.extend(1.0);
                    if c.w.abs() > 0.0 && c.x.abs() <= c.w && c.y.abs() <= c.w && c.z >= 0.0 && c.z <= c.w {
                        out.push(p);
                    }
                }
            }
        }
        out
    }

    #[test]
    fn conservative_bounds_hold_every_point_any_view_sees_of_the_box() {
        for scale in [1e-3f32, 1.0, 1e4] {
            let scene = (Vec3::new(-2.0, 0.0, -2.0) * scale, Vec3::new(2.0, 1.5, 2.0) * scale);
            let c = camera(Vec3::new(0.5, 0.8, 1.0) * scale, Vec3::new(-3.0, 0.2, -1.0) * scale);
            let perspective = View::from_camera(&c, 1e-3 * scale);
            let look = rh::view::look_at_mat4(Vec3::new(1.0, 6.0, 1.0) * scale, Vec3::ZERO, Vec3::Z);
            let ortho = View::new(
                look,
                rh::proj::directx::orthographic(
                    -0.8 * scale,
                    1.1 * scale,
                    -0.5 * scale,
                    0.4 * scale,
                    0.0,
                    20.0 * scale,
                ),
                (40, 30),
            )
            .unwrap();
            let off_centre = View::new(
                look,
                rh::proj::directx::frustum(
                    -0.1 * scale,
                    0.3 * scale,
                    -0.05 * scale,
                    0.2 * scale,
                    0.5 * scale,
                    9.0 * scale,
                ),
                (40, 30),
            )
            .unwrap();
            for view in [perspective, perspective.jittered(0.4, -0.3), ortho, off_centre] {
                let points = seen(scene, &view);
                assert!(!points.is_empty());
                let (lo, hi) = conservative_bounds(scene, &view).unwrap();
                let (mut slo, mut shi) = (Vec3::INFINITY, Vec3::NEG_INFINITY);
                for p in points {
                    assert!(p.cmpge(lo).all() && p.cmple(hi).all(), "{p} outside {lo}..{hi} at {scale}");
                    (slo, shi) = (slo.min(p), shi.max(p));
                }
                // and tight: within three grid steps of the seen points' own bounds
                let step = (scene.1 - scene.0) / 24.0 * 3.0;
                assert!((slo - lo).cmple(step).all() && (hi - shi).cmple(step).all(), "{lo}..{hi} vs {slo}..{shi}");
            }
        }
    }

    /// A wide scene seen from outside it: random points of the box in the view's pyramid lie
    /// in the bounds, which are smaller than the box.
    #[test]
    fn conservative_bounds_cut_a_wide_box_to_the_view() {
        for scale in [1e-3f32, 1.0, 1e4] {
            let camera = scene::Camera {
                eye: Vec3::new(0.0, 2.0, 6.0) * scale,
                target: Vec3::ZERO,
                up: Vec3::Y,
                hfov_degrees: 50.0,
                width: 160,
                height: 90,
            };
            let scene = (Vec3::new(-20.0, -1.0, -30.0) * scale, Vec3::new(20.0, 3.0, 2.0) * scale);
            let (lo, hi) = conservative_bounds(scene, &View::from_camera(&camera, 1e-4 * scale)).unwrap();
            assert!(lo.cmpge(scene.0 - scale * 1e-3).all() && hi.cmple(scene.1 + scale * 1e-3).all());
            assert!((hi - lo).length() < 0.9 * (scene.1 - scene.0).length());
            let (right, up, forward) = camera.basis();
            let tx = (camera.hfov_degrees.to_radians() * 0.5).tan();
            let ty = tx * 90.0 / 160.0;
            let mut seen = 0;
            let mut state = 12345u32;
            let mut next = || {
                state = state.wrapping_mul(1_664_525).wrapping_add(1_013_904_223);
                (state >> 8) as f32 / (1u32 << 24) as f32
            };
            for _ in 0..20_000 {
                let p = scene.0 + (scene.1 - scene.0) * Vec3::new(next(), next(), next());
                let v = p - camera.eye;
                let z = v.dot(forward);
                if z > 1e-4 * scale && v.dot(right).abs() <= tx * z && v.dot(up).abs() <= ty * z {
                    seen += 1;
                    assert!(p.cmpge(lo).all() && p.cmple(hi).all(), "{p} outside {lo} .. {hi}");
                }
            }
            assert!(seen > 100, "{seen} points seen");
        }
    }

    #[test]
    fn conservative_bounds_are_none_where_nothing_is_seen() {
        let c =
            scene::Camera { eye: Vec3::ZERO, target: Vec3::Z, up: Vec3::Y, hfov_degrees: 60.0, width: 4, height: 4 };
        let v = View::from_camera(&c, 1e-3);
        assert_eq!(conservative_bounds((Vec3::splat(-3.0), Vec3::new(3.0, 3.0, -1.0)), &v), None);
        assert_eq!(conservative_bounds((Vec3::splat(f32::NAN), Vec3::ONE), &v), None);
        assert_eq!(conservative_bounds((Vec3::ONE, Vec3::ZERO), &v), None);
        // a box beside the view, off every side
        assert_eq!(conservative_bounds((Vec3::new(50.0, -1.0, 1.0), Vec3::new(51.0, 1.0, 2.0)), &v), None);
    }
}
