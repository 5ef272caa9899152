//! Rotated-grid supersampling: a frame rendered with the camera rolled by atan(1/k) at k × k
//! samples per pixel, then box-filtered back onto the unrolled pixel grid.
//!
//! Why: an ordered k × k grid sees a horizontal or vertical edge at only k sub-pixel offsets,
//! so such an edge's coverage is quantized to 1/k along the whole edge, the same error in every
//! pixel of a row. A box-filtered ray tracer's pixels have no such bias. Rolled by atan(1/k),
//! the same lattice projects onto k² distinct offsets on each axis (Akeley's rotated grid,
//! generalized), so axis-aligned edges, the common ones, resolve to about 1/k². The roll is a
//! rotation about the view axis, so every pass that draws from the camera (G-buffer, shadow
//! volumes, wedges, background) stays consistent without knowing about it.

use glam::Vec3;
use scene::Camera;

/// A camera rolled for rotated-grid supersampling, and the resolve back to the original pixels.
///
/// The samples form the square lattice spanned by (k, ±1)/n and (∓1, k)/n in pixel units,
/// n = k² + 1: turned by atan(1/k), pitch 1/√n. It contains (1, 0) and (0, 1), so every pixel
/// holds the same n samples, at n distinct offsets along each axis (a perfectly stratified
/// n-rooks pattern; k = 2 is Akeley's 5-sample rotated grid). Sample positions are kept as
/// exact integers in units of 1/(2n) pixel, so no sample changes pixel through rounding.
#[derive(Clone, Debug)]
pub struct RotatedGrid {
    original: Camera,
    rolled: Camera,
    factor: u32,
    /// samples per pixel, k² + 1 (1 at factor 1)
    n: i64,
    /// the lattice's basis, one sample step along u and along v, in units of 1/n pixel
    du: (i64, i64),
    dv: (i64, i64),
}

impl RotatedGrid {
    /// Rolled sample grids are rounded up to a multiple of this, so that passes at 1/2 to 1/16
    /// of their resolution divide them.
    pub const ALIGN: u32 = 16;

    /// The grid for `camera` with k = `factor` (0 reads as 1): k² + 1 samples per pixel. Even
    /// factors put every sample at the centre of its stratum; odd ones on stratum edges. Factor
    /// 1 is the camera itself, unrolled: one sample at each pixel centre.
    #[must_use]
    pub fn new(camera: &Camera, factor: u32) -> Self {
        let k = factor.max(1);
        if k == 1 {
            return Self { original: *camera, rolled: *camera, factor: 1, n: 1, du: (1, 0), dv: (0, 1) };
        }
        let n = f64::from(k * k + 1);
        let theta = (1.0 / f64::from(k)).atan();
        let (s, c) = theta.sin_cos();
        let (half_w, half_h) = (f64::from(camera.width) * 0.5, f64::from(camera.height) * 0.5);
        // the rolled frame's half extents in original pixels: it must contain the original frame
        let (rw, rh) = (half_w * c + half_h * s, half_w * s + half_h * c);
        let align = |x: f64| {
            let samples = (2.0 * x * n.sqrt()).ceil() as u32 + 2;
            samples.div_ceil(Self::ALIGN) * Self::ALIGN
        };
        let (w, h) = (align(rw), align(rh));
        let (right, up, forward) = camera.basis();
        // roll: the rolled image's axes are the original's turned by theta in the image plane
        let rolled_up = (up * c as f32 + right * s as f32).normalize();
        let tan_half = f64::from((camera.hfov_degrees.to_radians() * 0.5).tan());
        // the same angular pitch per sample: 1/sqrt(n) of an original pixel
        let tan_half_rolled = tan_half * f64::from(w) / (n.sqrt() * f64::from(camera.width));
        let rolled = Camera {
            up: rolled_up,
            target: camera.eye + forward,
            hfov_degrees: (2.0 * tan_half_rolled.atan()).to_degrees() as f32,
            width: w,
            height: h,
            ..*camera
        };
        // the lattice's orientation as the rays define it (the roll's sign is the basis's)
        let project = |x: f32, y: f32| project(&rolled, camera, x, y);
        let p00 = project(0.5, 0.5);
        let step = |p: glam::Vec2| {
            let q = (p - p00) * n as f32;
            (q.x.round() as i64, q.y.round() as i64)
        };
        Self {
            original: *camera,
            rolled,
            factor: k,
            n: n as i64,
            du: step(project(1.5, 0.5)),
            dv: step(project(0.5, 1.5)),
        }
    }

    /// The camera to render with: rolled, `ALIGN`-aligned, at `factor` samples per pixel pitch.
    #[must_use]
    pub fn camera(&self) -> &Camera {
        &self.rolled
    }

    /// k, as given to [`RotatedGrid::new`].
    #[must_use]
    pub fn factor(&self) -> u32 {
        self.factor
    }

    /// Samples per pixel: k² + 1, or 1 at factor 1.
    #[must_use]
    pub fn samples_per_pixel(&self) -> u32 {
        self.n as u32
    }

    /// The output image size (the original camera's).
    #[must_use]
    pub fn output_size(&self) -> (u32, u32) {
        (self.original.width, self.original.height)
    }

    /// Original pixel coordinates of sample (u, v)'s centre, ×2n: exact integers. The two
    /// image centres are the same ray.
    fn position_2n(&self, u: u32, v: u32) -> (i64, i64) {
        let (a, b) =
            (2 * i64::from(u) + 1 - i64::from(self.rolled.width), 2 * i64::from(v) + 1 - i64::from(self.rolled.height));
        (
            self.n * i64::from(self.original.width) + a * self.du.0 + b * self.dv.0,
            self.n * i64::from(self.original.height) + a * self.du.1 + b * self.dv.1,
        )
    }

    /// Original pixel coordinates of the centre of sample (u, v) of the rolled image.
    #[must_use]
    pub fn sample_position(&self, u: u32, v: u32) -> glam::Vec2 {
        let (x, y) = self.position_2n(u, v);
        glam::Vec2::new(x as f32, y as f32) / (2 * self.n) as f32
    }

    /// The output pixel (row-major index) that sample (u, v) falls in, if any.
    fn pixel_of(&self, u: u32, v: u32) -> Option<usize> {
        let (x, y) = self.position_2n(u, v);
        let (x, y) = (x.div_euclid(2 * self.n), y.div_euclid(2 * self.n));
        let (w, h) = (i64::from(self.original.width), i64::from(self.original.height));
        ((0..w).contains(&x) && (0..h).contains(&y)).then(|| (y * w + x) as usize)
    }

    /// Box-filters a rolled image (the rolled camera's size, row-major) onto the original
    /// pixels: each pixel is the mean of its n samples.
    ///
    /// # Panics
    /// When `image` does not hold the rolled camera's `width × height` values.
    #[must_use]
    pub fn resolve(&self, image: &[Vec3]) -> Vec<Vec3> {
        let (rw, rh) = (self.rolled.width, self.rolled.height);
        assert_eq!(image.len(), rw as usize * rh as usize, "a {rw}x{rh} rolled image");
        let size = self.original.width as usize * self.original.height as usize;
        let (mut sum, mut count) = (vec![Vec3::ZERO; size], vec![0u32; size]);
        for v in 0..rh {
            for u in 0..rw {
                if let Some(i) = self.pixel_of(u, v) {
                    sum[i] += image[(v * rw + u) as usize];
                    count[i] += 1;
                }
            }
        }
        sum.iter().zip(&count).map(|(s, &c)| *s / c.max(1) as f32).collect()
    }

    /// Samples each output pixel receives in [`RotatedGrid::resolve`]: n everywhere, as the
    /// rolled frame covers the original.
    #[must_use]
    pub fn coverage(&self) -> Vec<u32> {
        let mut count = vec![0u32; self.original.width as usize * self.original.height as usize];
        for v in 0..self.rolled.height {
            for u in 0..self.rolled.width {
                if let Some(i) = self.pixel_of(u, v) {
                    count[i] += 1;
                }
            }
        }
        count
    }
}

/// Where `rolled`'s ray through sample position (x, y) (pixel centres at half-integers) crosses
/// `original`'s image, in original pixel coordinates.
fn project(rolled: &Camera, original: &Camera, x: f32, y: f32) -> glam::Vec2 {
    let (_, d) = rolled.ray(x, y);
    let o = original.rays();
    let forward = o.right.cross(o.down).normalize();
    let q = d * (o.corner.dot(forward) / d.dot(forward));
    let rel = q - o.corner;
    glam::Vec2::new(rel.dot(o.right) / o.right.length_squared(), rel.dot(o.down) / o.down.length_squared())
}

#[cfg(test)]
mod tests {
    use super::*;

    fn camera(width: u32, height: u32) -> Camera {
        Camera {
            eye: Vec3::new(0.3, 1.2, 4.0),
            target: Vec3::new(0.0, 0.4, 0.0),
            up: Vec3::Y,
            hfov_degrees: 50.0,
            width,
            height,
        }
    }

    #[test]
    fn factor_one_is_the_camera_itself() {
        let cam = camera(40, 30);
        let g = RotatedGrid::new(&cam, 1);
        assert_eq!(*g.camera(), cam);
        let image: Vec<Vec3> = (0..1200).map(|i| Vec3::splat(i as f32)).collect();
        assert_eq!(g.resolve(&image), image);
    }

    #[test]
    fn rolled_rays_are_the_original_rays_at_the_sample_positions() {
        for cam in [camera(64, 48), camera(33, 71)] {
            for k in [2, 3, 4, 8] {
                let g = RotatedGrid::new(&cam, k);
                let (w, h) = (g.camera().width, g.camera().height);
                assert_eq!((w % RotatedGrid::ALIGN, h % RotatedGrid::ALIGN), (0, 0));
                // a square lattice of n points per unit cell
                let n = i64::from(k * k + 1);
                assert_eq!(g.du.0 * g.du.0 + g.du.1 * g.du.1, n, "k {k}: {:?}", g.du);
                assert_eq!((g.du.0 * g.dv.0 + g.du.1 * g.dv.1, g.dv.0 * g.dv.0 + g.dv.1 * g.dv.1), (0, n));
                for (u, v) in [(0, 0), (w - 1, 0), (0, h - 1), (w / 2, h / 3), (w - 1, h - 1)] {
                    let (_, rolled) = g.camera().ray(u as f32 + 0.5, v as f32 + 0.5);
                    let p = g.sample_position(u, v);
                    let (_, original) = cam.ray(p.x, p.y);
                    assert!((rolled - original).length() < 1e-4, "k {k} ({u}, {v}): {rolled} vs {original}");
                }
            }
        }
    }

    #[test]
    fn every_pixel_holds_the_same_n_rooks_pattern() {
        for cam in [camera(64, 48), camera(33, 71)] {
            for k in [2u32, 3, 4] {
                let g = RotatedGrid::new(&cam, k);
                let n = k * k + 1;
                assert_eq!(g.samples_per_pixel(), n);
                assert!(g.coverage().iter().all(|&c| c == n), "k {k}");
                // one pixel's offsets: n distinct strata on each axis
                let (mut xs, mut ys) = (Vec::new(), Vec::new());
                for v in 0..g.camera().height {
                    for u in 0..g.camera().width {
                        if g.pixel_of(u, v) == Some(cam.width as usize * 7 + 5) {
                            let (x, y) = g.position_2n(u, v);
                            xs.push(x.rem_euclid(2 * i64::from(n)) / 2);
                            ys.push(y.rem_euclid(2 * i64::from(n)) / 2);
                        }
                    }
                }
                xs.sort_unstable();
                ys.sort_unstable();
                let strata: Vec<i64> = (0..i64::from(n)).collect();
                assert_eq!((xs, ys), (strata.clone(), strata), "k {k}");
            }
        }
    }

    /// Coverage of a horizontal and a vertical edge swept across a pixel: an ordered k x k
    /// grid's error reaches 1/(2k); the rotated grid's 1/(2n) (even k) or 1/n (odd k).
    #[test]
    fn axis_aligned_edges_resolve_to_one_nth_of_a_pixel() {
        let cam = camera(32, 24);
        for k in [2u32, 3, 4] {
            let g = RotatedGrid::new(&cam, k);
            let (rw, rh) = (g.camera().width, g.camera().height);
            let mut worst = 0.0f32;
            for step in 0..=50 {
                let edge = 10.0 + step as f32 / 50.0;
                for horizontal in [true, false] {
                    let image: Vec<Vec3> = (0..rh)
                        .flat_map(|v| (0..rw).map(move |u| (u, v)))
                        .map(|(u, v)| {
                            let p = g.sample_position(u, v);
                            Vec3::splat(if (if horizontal { p.y } else { p.x }) < edge { 1.0 } else { 0.0 })
                        })
                        .collect();
                    let out = g.resolve(&image);
                    let (x, y) = if horizontal { (16, 10) } else { (10, 12) };
                    worst = worst.max((out[y * 32 + x].x - (edge - 10.0)).abs());
                }
            }
            let n = (k * k + 1) as f32;
            let bound = if k % 2 == 0 { 0.5 / n } else { 1.0 / n } + 1e-4;
            assert!(worst <= bound, "k {k}: worst coverage error {worst}, bound {bound}");
            assert!(worst < 0.5 / k as f32, "k {k}: no better than an ordered grid");
        }
    }

    #[test]
    fn constant_images_stay_constant() {
        let g = RotatedGrid::new(&camera(50, 37), 4);
        let c = Vec3::new(0.25, 2.0, 1e30);
        let image = vec![c; (g.camera().width * g.camera().height) as usize];
        assert!(g.resolve(&image).iter().all(|p| ((*p - c) / c).abs().max_element() < 1e-6));
    }
}
