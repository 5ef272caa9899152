//! Rendering an image: rayon over 16 x 16 tiles, passes of samples until the sample count or
//! the time budget is reached, and the AOVs of each pixel's centre ray.

use crate::bvh::SceneBvh;
use crate::integrator::{EnvLight, Integrator, Strategy};
use crate::sampler::{PixelSampler, SamplerKind};
use glam::Vec3;
use rayon::prelude::*;
use scene::Scene;
use std::sync::atomic::{AtomicBool, Ordering};
use std::time::{Duration, Instant};

const TILE: u32 = 16;

/// Render settings.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RenderSettings {
    /// Samples per pixel (the most, with a time budget).
    pub spp: u32,
    /// Seed: the same seed gives the same image bits for any thread count.
    pub seed: u64,
    /// Stop after the first pass that ends past this budget (the image then has fewer spp).
    pub time_budget: Option<Duration>,
    /// Compute the AOVs (one extra ray per pixel); without, they are left empty.
    pub aovs: bool,
    /// Camera rays through a fixed set of this many sub-pixel positions: sample k goes through
    /// position k mod n, which depends on (pixel, k mod n) only, not on the seed. Two renders
    /// with the same n then average over the same points of each pixel, and their difference
    /// holds no antialiasing noise (for comparing light approximations against a truth). `None`:
    /// a fresh jittered position per sample (the box filter's unbiased estimate).
    pub pixel_positions: Option<u32>,
    /// How sample points are drawn: stratified Sobol (the default) or independent.
    pub sampler: SamplerKind,
}

impl Default for RenderSettings {
    fn default() -> Self {
        Self { spp: 16, seed: 0, time_budget: None, aovs: true, pixel_positions: None, sampler: SamplerKind::Sobol }
    }
}

/// Seed of the shared sub-pixel positions of [`RenderSettings::pixel_positions`].
const POSITIONS_SEED: u64 = 0x5eed_0f90_5171_05aa;

/// A rendered image with its AOVs.
#[derive(Clone, Debug)]
pub struct Render {
    /// Width in pixels.
    pub width: u32,
    /// Height in pixels.
    pub height: u32,
    /// Linear RGB radiance, the plain mean of each pixel's samples (box filter).
    pub color: Vec<Vec3>,
    /// AOV: diffuse albedo of the first hit (zero for the background). The AOVs are empty when
    /// [`RenderSettings::aovs`] is off.
    pub albedo: Vec<Vec3>,
    /// AOV: unit shading normal of the first hit, facing the camera (zero for the background).
    pub normal: Vec<Vec3>,
    /// AOV: distance from the eye to the first hit along the centre ray (infinity for the background).
    pub depth: Vec<f32>,
    /// AOV: index of the first hit's object (`u32::MAX` for the background).
    pub object_id: Vec<u32>,
    /// Samples per pixel actually taken.
    pub spp: u32,
    /// Wall time of the sampling passes.
    pub seconds: f64,
}

/// A render refined pass by pass: each pass adds samples to every pixel's sum, continuing one
/// seed's sample sequence, so after n samples the image is the one [`render`] makes with n
/// samples in the same passes (bit for bit). A pass can be cancelled between tiles (a viewer
/// whose camera moved): the pass is then dropped whole and the image stays as it was.
#[derive(Clone, Debug)]
pub struct Progressive {
    width: u32,
    height: u32,
    settings: RenderSettings,
    sum: Vec<Vec3>,
    done: u32,
    seconds: f64,
}

impl Progressive {
    /// No samples yet, for frames of `scene`'s camera size; `settings.spp` and `time_budget`
    /// are not used (the caller decides how many passes).
    #[must_use]
    pub fn new(scene: &Scene, settings: &RenderSettings) -> Self {
        let (width, height) = (scene.camera.width, scene.camera.height);
        let n = width as usize * height as usize;
        Self { width, height, settings: *settings, sum: vec![Vec3::ZERO; n], done: 0, seconds: 0.0 }
    }

    /// Adds `count` samples to every pixel of `scene` (the scene this was made for). Returns
    /// false, adding nothing, when `cancel` was set during the pass.
    pub fn pass(
        &mut self,
        scene: &Scene,
        bvh: &SceneBvh,
        env: Option<&EnvLight>,
        integrator: &Integrator,
        count: u32,
        cancel: &AtomicBool,
    ) -> bool {
        let start = Instant::now();
        let (w, h) = (self.width, self.height);
        let cam = scene.camera.rays();
        let settings = &self.settings;
        let done = self.done;
        let count = count.min(u32::MAX - done);
        let tiles: Vec<(u32, u32)> =
            (0..h.div_ceil(TILE)).flat_map(|ty| (0..w.div_ceil(TILE)).map(move |tx| (tx * TILE, ty * TILE))).collect();
        let results: Vec<Vec<(usize, Vec3)>> = tiles
            .par_iter()
            .map(|&(x0, y0)| {
                if cancel.load(Ordering::Relaxed) {
                    return Vec::new();
                }
                let mut out = Vec::with_capacity((TILE * TILE) as usize);
                for y in y0..(y0 + TILE).min(h) {
                    for x in x0..(x0 + TILE).min(w) {
                        let pixel = (y * w + x) as usize;
                        let mut acc = Vec3::ZERO;
                        for k in done..done + count {
                            let sampler = |seed, k| PixelSampler::with_kind(settings.sampler, seed, pixel as u64, k);
                            let mut s = sampler(settings.seed, u64::from(k));
                            let j = match settings.pixel_positions {
                                Some(n) => sampler(POSITIONS_SEED, u64::from(k % n.max(1))).next_2d(),
                                None => s.next_2d(),
                            };
                            let (o, d) = cam.ray(x as f32 + j.x, y as f32 + j.y);
                            acc += integrator.radiance(bvh, env, o, d, &mut s);
                        }
                        out.push((pixel, acc));
                    }
                }
                out
            })
            .collect();
        if cancel.load(Ordering::Relaxed) {
            return false;
        }
        for (pixel, acc) in results.into_iter().flatten() {
            self.sum[pixel] += acc;
        }
        self.done += count;
        self.seconds += start.elapsed().as_secs_f64();
        true
    }

    /// Samples per pixel so far.
    #[must_use]
    pub fn spp(&self) -> u32 {
        self.done
    }

    /// Wall time of the passes that were kept.
    #[must_use]
    pub fn seconds(&self) -> f64 {
        self.seconds
    }

    /// The image so far: each pixel's mean (black before the first pass).
    #[must_use]
    pub fn image(&self) -> Vec<Vec3> {
        let n = self.done.max(1) as f32;
        self.sum.iter().map(|s| *s / n).collect()
    }

    /// (width, height).
    #[must_use]
    pub fn size(&self) -> (u32, u32) {
        (self.width, self.height)
    }
}

/// Renders `scene` with `integrator`. `progress` is called after each pass with
/// (samples done, samples planned) per pixel.
#[must_use]
pub fn render(
    scene: &Scene,
    bvh: &SceneBvh,
    env: Option<&EnvLight>,
    integrator: &Integrator,
    settings: &RenderSettings,
    progress: &(dyn Fn(u32, u32) + Sync),
) -> Render {
    debug_assert!(
        !(matches!(integrator, Integrator::EnvDirect(Strategy::EnvOnly)) && env.is_some_and(|e| !e.dist.is_complete())),
        "map-only sampling needs the complete distribution (EnvLight::for_strategy)"
    );
    let (w, h) = (scene.camera.width, scene.camera.height);
    let cam = scene.camera.rays();
    let n = (w * h) as usize;
    let start = Instant::now();
    let mut image = Progressive::new(scene, settings);
    let never = AtomicBool::new(false);
    // with a time budget a pass is one sample, so the budget is overshot by one pass at most
    let pass_size = if settings.time_budget.is_some() { 1 } else { (settings.spp / 16).max(1) };
    while image.spp() < settings.spp {
        let count = pass_size.min(settings.spp - image.spp());
        image.pass(scene, bvh, env, integrator, count, &never);
        progress(image.spp(), settings.spp);
        if settings.time_budget.is_some_and(|b| start.elapsed() >= b) {
            break;
        }
    }
    let (color, done) = (image.image(), image.spp());
    let seconds = start.elapsed().as_secs_f64();
    let mut r = Render {
        width: w,
        height: h,
        color,
        albedo: vec![],
        normal: vec![],
        depth: vec![],
        object_id: vec![],
        spp: done,
        seconds,
    };
    if !settings.aovs {
        return r;
    }
    r.albedo = vec![Vec3::ZERO; n];
    r.normal = vec![Vec3::ZERO; n];
    r.depth = vec![f32::INFINITY; n];
    r.object_id = vec![u32::MAX; n];
    let aovs: Vec<_> = (0..n)
        .into_par_iter()
        .map(|pixel| {
            let (x, y) = ((pixel as u32 % w) as f32 + 0.5, (pixel as u32 / w) as f32 + 0.5);
            let (o, d) = cam.ray(x, y);
            bvh.intersect_camera(o, d).map(|sp| (sp, bvh.material_at(&sp).albedo))
        })
        .collect();
    for (pixel, aov) in aovs.into_iter().enumerate() {
        if let Some((sp, albedo)) = aov {
            r.albedo[pixel] = albedo;
            r.normal[pixel] = sp.shading_normal;
            r.depth[pixel] = sp.t;
            r.object_id[pixel] = sp.object;
        }
    }
    r
}
