//! The reference beside the frame: while the view stays still (camera, object, map and its turn),
//! a thread refines a progressive reference of it with the reference tracer (the map's direct
//! light ray traced with MIS, the truth `trade` measures every technique against) and measures
//! the frame shown against it. The frame's technique and light count are not part of the view:
//! switching them keeps the reference and measures the new frame against it.
//!
//! The reference is two halves refined in step (seeds 1 and 2): their mean is the reference, half
//! their difference's RMSE its own noise (each half's mean has twice the full mean's variance,
//! their difference four times). The frame's RMSE against a noisy reference is, in expectation,
//! the root of its RMSE against the truth squared plus that noise squared, so the noise is taken
//! out. A scripted run ([`converge`]) keeps the first half's image after each pass: against the
//! second half's final image (whose noise adds to both sides alike) they give the time a
//! progressive reference takes to reach the frame's error.

use envmap_sphere::{EnvMap, Tonemap};
use glam::{Affine3A, Quat, Vec3};
use ref_tracer::metrics::{FlipTonemap, flip, rmse};
use ref_tracer::{EnvLight, Integrator, Progressive, RenderSettings, SceneBvh, Strategy};
use std::collections::HashMap;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::{Arc, Condvar, Mutex, MutexGuard, PoisonError};
use std::thread::JoinHandle;
use std::time::Instant;

/// What a reference is of: equal keys, the same image.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct ViewKey {
    eye: Vec3,
    target: Vec3,
    hfov: f32,
    size: (u32, u32),
    offset: Vec3,
    turn: f32,
    /// Counts loaded maps and scenes.
    content: u64,
}

impl ViewKey {
    pub(crate) fn new(camera: &scene::Camera, offset: Vec3, turn: f32, content: u64) -> Self {
        Self {
            eye: camera.eye,
            target: camera.target,
            hfov: camera.hfov_degrees,
            size: (camera.width, camera.height),
            offset,
            turn,
            content,
        }
    }
}

/// A view to refine.
pub(crate) struct Job {
    pub key: ViewKey,
    /// The scene as the frame shows it: the moving object where it is, and the world (camera
    /// included) turned against the map's turn, which is the map turned (exactly: no map is
    /// resampled).
    pub scene: scene::Scene,
    pub map: Arc<EnvMap>,
    /// The display's exposure: FLIP is of what the window shows.
    pub exposure: f32,
    /// Stop at this many samples per pixel (both halves together).
    pub max_spp: u32,
}

impl Job {
    /// The view of `scene` (objects at rest) from `camera`, object `moving` moved by `offset`
    /// and the map turned by `turn` radians about +Y.
    #[allow(clippy::too_many_arguments)]
    pub(crate) fn new(
        key: ViewKey,
        scene: &scene::Scene,
        camera: &scene::Camera,
        moving: Option<usize>,
        offset: Vec3,
        turn: f32,
        map: Arc<EnvMap>,
        exposure: f32,
        max_spp: u32,
    ) -> Self {
        let mut scene = scene.clone();
        if let Some(object) = moving.and_then(|k| scene.objects.get_mut(k)) {
            object.mesh.transform(&Affine3A::from_translation(offset));
        }
        let back = Quat::from_rotation_y(-turn);
        if turn != 0.0 {
            for o in &mut scene.objects {
                o.mesh.transform(&Affine3A::from_quat(back));
            }
        }
        scene.camera = scene::Camera { eye: back * camera.eye, target: back * camera.target, ..*camera };
        Self { key, scene, map, exposure, max_spp }
    }
}

/// The frame measured against the reference.
#[derive(Clone, Copy, Debug)]
pub(crate) struct FrameError {
    /// The frame's id (its view, technique and lights).
    pub frame: u64,
    /// RMSE against the reference as it is.
    pub rmse: f64,
    /// Against the truth: the reference's own noise taken out.
    pub rmse_truth: f64,
    /// LDR-FLIP against the reference, tone mapped as shown (the reference's noise included).
    pub flip: f64,
    /// When the reference's own noise first fell below the frame's error: (seconds, spp).
    pub passed: Option<(f64, u32)>,
}

/// The reference as it is now.
#[derive(Clone)]
pub(crate) struct Progress {
    pub key: ViewKey,
    pub image: Arc<Vec<Vec3>>,
    pub spp: u32,
    /// Since the view became still: the scene's hierarchy and every pass.
    pub seconds: f64,
    /// Its RMSE against the truth, estimated from its halves.
    pub noise: f64,
    pub error: Option<FrameError>,
    /// Counts what was published, so a viewer redraws only for something new.
    pub generation: u64,
}

/// The two halves being refined, and what they need.
struct Running<'a> {
    job: &'a Job,
    bvh: SceneBvh,
    env: EnvLight<'a>,
    halves: [Progressive; 2],
    tonemap: FlipTonemap,
}

impl<'a> Running<'a> {
    fn new(job: &'a Job) -> Self {
        let settings = |seed| RenderSettings { seed, aovs: false, ..RenderSettings::default() };
        Self {
            bvh: SceneBvh::new(&job.scene),
            env: EnvLight::new(&job.map),
            halves: [Progressive::new(&job.scene, &settings(1)), Progressive::new(&job.scene, &settings(2))],
            tonemap: FlipTonemap { tonemap: Tonemap { exposure: job.exposure } },
            job,
        }
    }

    fn spp(&self) -> u32 {
        self.halves[0].spp() + self.halves[1].spp()
    }

    /// One pass of each half, a quarter of what each has (one at first): the reference updates
    /// often early on and every 25 % or so later. False when cancelled.
    fn pass(&mut self, cancel: &AtomicBool) -> bool {
        let left = self.job.max_spp.saturating_sub(self.spp()).div_ceil(2).max(1);
        let count = (self.halves[0].spp() / 4).clamp(1, left);
        let integrator = Integrator::EnvDirect(Strategy::Mis);
        let (scene, bvh, env) = (&self.job.scene, &self.bvh, &self.env);
        self.halves.iter_mut().all(|h| h.pass(scene, bvh, Some(env), &integrator, count, cancel))
    }

    /// The reference (the halves' mean) and its noise, from one look at each half.
    fn reference(&self) -> (Vec<Vec3>, f64) {
        let (a, b) = (self.halves[0].image(), self.halves[1].image());
        (a.iter().zip(&b).map(|(a, b)| 0.5 * (*a + *b)).collect(), 0.5 * rmse(&a, &b))
    }

    /// (RMSE, RMSE with the noise taken out, FLIP) of `frame` against `reference`.
    fn measure(&self, reference: &[Vec3], noise: f64, frame: &[Vec3]) -> (f64, f64, f64) {
        let (w, h) = self.halves[0].size();
        let e = rmse(reference, frame);
        (e, (e * e - noise * noise).max(0.0).sqrt(), flip(reference, frame, w, h, &self.tonemap))
    }
}

#[derive(Default)]
struct State {
    /// The view to refine (`None`: none), and whether the thread has seen it.
    job: Option<Arc<Job>>,
    job_fresh: bool,
    /// The frame to measure: its id and image.
    frame: Option<(u64, Arc<Vec<Vec3>>)>,
    frame_fresh: bool,
    progress: Option<Progress>,
    generation: u64,
    quit: bool,
}

struct Shared {
    state: Mutex<State>,
    wake: Condvar,
    /// Set with a new job: the pass under way stops between tiles.
    cancel: AtomicBool,
}

impl Shared {
    fn lock(&self) -> MutexGuard<'_, State> {
        self.state.lock().unwrap_or_else(PoisonError::into_inner)
    }
}

/// The thread refining references, and what it has published.
pub(crate) struct Reference {
    shared: Arc<Shared>,
    thread: Option<JoinHandle<()>>,
}

impl Reference {
    pub(crate) fn new() -> Self {
        let shared = Arc::new(Shared { state: Mutex::default(), wake: Condvar::new(), cancel: AtomicBool::new(false) });
        let worker = Arc::clone(&shared);
        let thread = std::thread::Builder::new().name("reference".into()).spawn(move || work(&worker)).ok();
        Self { shared, thread }
    }

    /// The view being refined.
    pub(crate) fn key(&self) -> Option<ViewKey> {
        self.shared.lock().job.as_ref().map(|j| j.key)
    }

    /// Refines `job` from now on, dropping what was being refined (`None`: nothing, the view is
    /// moving).
    pub(crate) fn want(&self, job: Option<Job>) {
        let mut s = self.shared.lock();
        if s.job.is_none() && job.is_none() {
            return;
        }
        self.shared.cancel.store(true, Ordering::Relaxed);
        s.job = job.map(Arc::new);
        s.job_fresh = true;
        s.progress = None;
        drop(s);
        self.shared.wake.notify_all();
    }

    /// Measures the frame `id` (the image shown) against the reference from now on.
    pub(crate) fn measure(&self, id: u64, image: Vec<Vec3>) {
        let mut s = self.shared.lock();
        s.frame = Some((id, Arc::new(image)));
        s.frame_fresh = true;
        drop(s);
        self.shared.wake.notify_all();
    }

    /// What was published last for the view being refined.
    pub(crate) fn progress(&self) -> Option<Progress> {
        self.shared.lock().progress.clone()
    }
}

impl Drop for Reference {
    fn drop(&mut self) {
        self.shared.lock().quit = true;
        self.shared.cancel.store(true, Ordering::Relaxed);
        self.shared.wake.notify_all();
        if let Some(t) = self.thread.take() {
            let _ = t.join();
        }
    }
}

/// The thread: waits for a job, refines it until another comes.
fn work(shared: &Shared) {
    let mut next = None;
    loop {
        let job = match next.take() {
            Some(job) => job,
            None => {
                let mut s = shared.lock();
                loop {
                    if s.quit {
                        return;
                    }
                    if s.job_fresh {
                        s.job_fresh = false;
                        shared.cancel.store(false, Ordering::Relaxed);
                        if let Some(job) = s.job.clone() {
                            break job;
                        }
                    }
                    s = shared.wake.wait(s).unwrap_or_else(PoisonError::into_inner);
                }
            }
        };
        match refine(shared, &job) {
            Some(j) => next = j,
            None => return,
        }
    }
}

/// Refines `job` until it is replaced (returns the next job, `None` within for none) or the
/// viewer quits (returns `None`).
fn refine(shared: &Shared, job: &Arc<Job>) -> Option<Option<Arc<Job>>> {
    let start = Instant::now();
    let mut run = Running::new(job);
    let mut reference: Option<(Arc<Vec<Vec3>>, f64)> = None;
    let mut passed: HashMap<u64, (f64, u32)> = HashMap::new();
    loop {
        let (frame, refine_more) = {
            let mut s = shared.lock();
            loop {
                if s.quit {
                    return None;
                }
                if s.job_fresh {
                    s.job_fresh = false;
                    shared.cancel.store(false, Ordering::Relaxed);
                    return Some(s.job.clone());
                }
                let more = run.spp() < job.max_spp;
                if s.frame_fresh || more {
                    s.frame_fresh = false;
                    break (s.frame.clone(), more);
                }
                s = shared.wake.wait(s).unwrap_or_else(PoisonError::into_inner);
            }
        };
        if refine_more {
            if !run.pass(&shared.cancel) {
                continue;
            }
            let (image, noise) = run.reference();
            reference = Some((Arc::new(image), noise));
        }
        let Some((image, noise)) = reference.clone() else { continue };
        let seconds = start.elapsed().as_secs_f64();
        let error = frame.filter(|(_, f)| f.len() == image.len()).map(|(id, f)| {
            let (rmse, rmse_truth, flip) = run.measure(&image, noise, &f);
            if noise <= rmse_truth {
                passed.entry(id).or_insert((seconds, run.spp()));
            }
            FrameError { frame: id, rmse, rmse_truth, flip, passed: passed.get(&id).copied() }
        });
        let mut s = shared.lock();
        if s.job_fresh {
            continue;
        }
        s.generation += 1;
        s.progress =
            Some(Progress { key: job.key, image, spp: run.spp(), seconds, noise, error, generation: s.generation });
    }
}

/// A scripted run's reference of `job` refined to its `max_spp` in this thread, and `frame`
/// measured against it.
pub(crate) struct Converged {
    /// The reference: the halves' mean.
    pub image: Vec<Vec3>,
    pub spp: u32,
    pub seconds: f64,
    pub noise: f64,
    pub rmse: f64,
    pub rmse_truth: f64,
    pub flip: f64,
    /// The first half's first image within the frame's RMSE (FLIP) of the second half's final
    /// one: its samples per pixel and their time.
    pub reached_rmse: Option<(u32, f64)>,
    pub reached_flip: Option<(u32, f64)>,
    pub tonemap: String,
}

/// Refines `job` to its samples, keeping the first half's image after each pass, and measures
/// `frame` against the result. Returns `None` for an image of another size than the job's.
pub(crate) fn converge(job: &Job, frame: &[Vec3]) -> Option<Converged> {
    let start = Instant::now();
    let mut run = Running::new(job);
    if frame.len() != (job.scene.camera.width * job.scene.camera.height) as usize {
        return None;
    }
    let never = AtomicBool::new(false);
    let mut snapshots = Vec::new();
    while run.spp() < job.max_spp {
        run.pass(&never);
        snapshots.push((run.halves[0].spp(), run.halves[0].seconds(), run.halves[0].image()));
    }
    let seconds = start.elapsed().as_secs_f64();
    let (image, noise) = run.reference();
    let (rmse_all, rmse_truth, flip_all) = run.measure(&image, noise, frame);
    let other = run.halves[1].image();
    let (w, h) = run.halves[1].size();
    let (frame_rmse, frame_flip) = (rmse(&other, frame), flip(&other, frame, w, h, &run.tonemap));
    let mut reached_rmse = None;
    let mut reached_flip = None;
    for (spp, secs, snap) in &snapshots {
        if reached_rmse.is_none() && rmse(&other, snap) <= frame_rmse {
            reached_rmse = Some((*spp, *secs));
        }
        if reached_flip.is_none() && flip(&other, snap, w, h, &run.tonemap) <= frame_flip {
            reached_flip = Some((*spp, *secs));
        }
        if reached_rmse.is_some() && reached_flip.is_some() {
            break;
        }
    }
    Some(Converged {
        image,
        spp: run.spp(),
        seconds,
        noise,
        rmse: rmse_all,
        rmse_truth,
        flip: flip_all,
        reached_rmse,
        reached_flip,
        tonemap: format!(
            "LDR-FLIP after exposure {:.4} (the viewer's: a white ground under the map at middle grey), ACES (Narkowicz), sRGB 8-bit; {} pixels per degree",
            job.exposure,
            ref_tracer::metrics::FLIP_PIXELS_PER_DEGREE
        ),
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn job(max_spp: u32, turn: f32) -> Job {
        let mut scene = scene::Scene::builtin("spheres_box").unwrap_or_else(|e| panic!("{e}"));
        (scene.camera.width, scene.camera.height) = (24, 18);
        let camera = scene.camera;
        let map = Arc::new(envmap_sphere::default_map().resize(128, 64));
        let key = ViewKey::new(&camera, Vec3::ZERO, turn, 0);
        Job::new(key, &scene, &camera, Some(1), Vec3::ZERO, turn, map, 1.0, max_spp)
    }

    #[test]
    fn the_background_reference_converges_and_measures_a_frame_against_it() {
        let reference = Reference::new();
        let j = job(64, 0.0);
        let key = j.key;
        // a frame far from the truth: black
        let black = vec![Vec3::ZERO; 24 * 18];
        reference.want(Some(j));
        reference.measure(7, black);
        let start = Instant::now();
        let done = loop {
            if let Some(p) = reference.progress().filter(|p| p.spp >= 64 && p.error.is_some()) {
                break p;
            }
            assert!(start.elapsed().as_secs() < 120, "no reference after 2 minutes");
            std::thread::sleep(std::time::Duration::from_millis(20));
        };
        assert_eq!(done.key, key);
        let e = done.error.unwrap_or_else(|| panic!("no error"));
        assert_eq!(e.frame, 7);
        // black against the reference: its RMSE is the reference's root mean square
        let rms = rmse(&done.image, &vec![Vec3::ZERO; done.image.len()]);
        assert!((e.rmse - rms).abs() <= 1e-9 * rms.max(1.0), "{} against {rms}", e.rmse);
        assert!(done.noise > 0.0 && done.noise < 0.2 * e.rmse, "noise {} against {}", done.noise, e.rmse);
        assert!(e.flip > 0.3, "black against a lit scene: FLIP {}", e.flip);
        // the reference's noise fell below black's error early on
        assert!(e.passed.is_some_and(|(_, spp)| spp <= 64));
        // a new job drops the old one's progress; none stops it
        reference.want(None);
        assert!(reference.progress().is_none() && reference.key().is_none());
    }

    #[test]
    fn a_black_frame_is_reached_at_one_sample_and_a_converged_one_not_within_a_few() {
        let j = job(32, 0.7);
        let zeros = vec![Vec3::ZERO; 24 * 18];
        let black = converge(&j, &zeros).unwrap_or_else(|| panic!("sizes"));
        assert_eq!(black.spp, 32);
        assert_eq!(black.reached_rmse.map(|r| r.0), Some(1));
        assert_eq!(black.reached_flip.map(|r| r.0), Some(1));
        assert!(black.rmse_truth <= black.rmse && black.noise > 0.0);
        // a frame of 512 samples of another seed: closer to the truth than 16 samples get
        let settings = RenderSettings { spp: 512, seed: 9, aovs: false, ..RenderSettings::default() };
        let (bvh, env) = (SceneBvh::new(&j.scene), EnvLight::new(&j.map));
        let integrator = Integrator::EnvDirect(Strategy::Mis);
        let good = ref_tracer::render(&j.scene, &bvh, Some(&env), &integrator, &settings, &|_, _| {}).color;
        let near = converge(&j, &good).unwrap_or_else(|| panic!("sizes"));
        assert_eq!(near.reached_rmse, None, "16 samples reached a 512-sample frame's error");
        assert!(near.rmse_truth < 0.1 * black.rmse_truth, "{} against black's {}", near.rmse_truth, black.rmse_truth);
        assert!(converge(&j, &[Vec3::ZERO; 3]).is_none());
    }

    #[test]
    fn the_reference_is_of_the_view_drawn_with_the_map_turned_and_the_object_moved() {
        use super::super::stage::{Stage, ViewTechnique};
        let gpu = gpu::Gpu::new().unwrap_or_else(|e| panic!("{e}"));
        let map = Arc::new(envmap_sphere::default_map().resize(256, 128));
        let mut scene = scene::Scene::builtin("spheres_box").unwrap_or_else(|e| panic!("{e}"));
        (scene.camera.width, scene.camera.height) = (48, 36);
        let mut stage = Stage::new(&gpu, scene, &map, 16, ViewTechnique::Paper001).unwrap_or_else(|e| panic!("{e}"));
        stage.set_turn(1.0);
        stage.move_object(&gpu, Vec3::new(0.4, 0.0, -0.3)).unwrap_or_else(|e| panic!("{e}"));
        let camera = stage.scene().camera;
        let f = stage.render(&gpu, &camera).unwrap_or_else(|e| panic!("{e}"));
        gpu.wait(None).unwrap_or_else(|e| panic!("{e}"));
        let frame = gpu::read_hdr(&gpu, &f.texture).unwrap_or_else(|e| panic!("{e}"));
        let error = |offset: Vec3, turn: f32| {
            let key = ViewKey::new(&camera, offset, turn, 0);
            let job =
                Job::new(key, stage.scene(), &camera, stage.moving_index(), offset, turn, Arc::clone(&map), 1.0, 64);
            converge(&job, &frame).unwrap_or_else(|| panic!("sizes")).rmse_truth
        };
        let right = error(stage.offset(), stage.turn());
        let unturned = error(stage.offset(), 0.0);
        let unmoved = error(Vec3::ZERO, stage.turn());
        // measured: 0.059 against 0.181 unturned and 0.195 at rest
        assert!(right < 0.5 * unturned, "{right} against the unturned map's {unturned}");
        assert!(right < 0.5 * unmoved, "{right} against the object at rest's {unmoved}");
    }
}
