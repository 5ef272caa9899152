//! `envshadow view`: a window on the real-time frame. A scene (built in or a glTF model) lit by
//! a map's decomposition, its shadows drawn by the technique chosen, through the libraries'
//! public recorded-frame API only ([`stage::Stage`]: `gpu::LitFrame` with the techniques of
//! `penumbra-wedge` and `shadowmap-paraboloid`), then tone mapped into the window
//! ([`display::Display`]). `--frames N` renders N frames and exits (scripts, tests, timings);
//! `--offscreen` draws the same frames into a texture, for machines without a display. While
//! the view stays still, the reference tracer refines a reference of it in the background and
//! the frame is measured against it ([`reference`]); `--reference SPP` does the same at the end
//! of a scripted run.

mod display;
mod orbit;
mod panel;
mod reference;
mod stage;
mod window;

use display::Shown;
use envmap_sphere::EnvMap;
use glam::Vec3;
use gpu::Gpu;
use std::path::{Path, PathBuf};
use std::sync::Arc;
use std::time::{Duration, Instant};

pub(crate) use stage::ViewTechnique;

/// What `view` was asked for (parsed by clap).
#[derive(clap::Args)]
pub(crate) struct ViewArgs {
    /// Environment map (.exr or .hdr); the embedded default when absent.
    #[arg(long)]
    pub envmap: Option<PathBuf>,
    /// Built-in scene, or a glTF 2.0 model (`.gltf`, `.glb`).
    #[arg(long, default_value = "spheres_box")]
    pub scene: String,
    /// For a model: a Lambertian ground plane under it (albedo 0.5, or the value given).
    #[arg(long, num_args = 0..=1, default_missing_value = "0.5", value_parser = trade::args::parse_albedo)]
    pub ground: Option<f32>,
    /// Shadow technique: paper001 (wedges for the strongest lights, maps for the rest at half
    /// resolution), wedges, maps (3 x 3 PCF), pcss, none. `T` cycles through them.
    #[arg(long, default_value = "paper001")]
    pub technique: String,
    /// Lights extracted from the map.
    #[arg(long, default_value_t = 32)]
    pub lights: usize,
    /// GPU adapter: a case-insensitive part of its name, or `cpu` for a software one.
    #[arg(long)]
    pub adapter: Option<String>,
    /// Window (and frame) size WIDTHxHEIGHT.
    #[arg(long, value_parser = trade::args::parse_size, default_value = "1280x720")]
    pub size: (u32, u32),
    /// Render this many frames, then exit (with --screenshot, --json).
    #[arg(long)]
    pub frames: Option<usize>,
    /// Save the last frame as this PNG (with --frames).
    #[arg(long, requires = "frames")]
    pub screenshot: Option<PathBuf>,
    /// Turn the map about the vertical by this many degrees (its lights, ambient and
    /// background together; `Q` / `E` turn it by 15 degrees in the window).
    #[arg(long, default_value_t = 0.0, allow_hyphen_values = true)]
    pub turn: f32,
    /// Turn the camera this many degrees about the target each frame.
    #[arg(long, default_value_t = 0.0, allow_hyphen_values = true)]
    pub orbit: f32,
    /// Print one JSON object (frame times, technique, adapter) when done (with --frames).
    #[arg(long, requires = "frames")]
    pub json: bool,
    /// No window: draw the same frames into a texture (a machine without a display).
    #[arg(long, requires = "frames")]
    pub offscreen: bool,
    /// Load this file after the first frame as if it were dropped on the window (scripts,
    /// tests): a map (.hdr, .exr) or a model (.gltf, .glb).
    #[arg(long)]
    pub drop: Option<PathBuf>,
    /// After the frames, refine the reference of the last one's view to this many samples per
    /// pixel and measure the frame against it (with --frames; the JSON's `reference`).
    #[arg(long, requires = "frames")]
    pub reference: Option<u32>,
    /// What the window shows: frame, reference or difference (`R` cycles; the reference once
    /// the view has stayed still, or with --reference).
    #[arg(long, default_value = "frame")]
    pub show: String,
    /// With --reference: save the difference view (frame against reference) as this PNG.
    #[arg(long, requires = "reference")]
    pub difference: Option<PathBuf>,
    /// After the frames, keep the window's view still this many seconds (its background
    /// reference refining, the frame measured against it) before the screenshot; the JSON's
    /// `live_reference` is what it reached.
    #[arg(long, requires = "frames")]
    pub hold: Option<f32>,
    /// No panel over the window's view (`H` toggles it).
    #[arg(long)]
    pub no_panel: bool,
}

/// The most samples per pixel of a scripted run's reference.
const MAX_REFERENCE_SPP: u32 = 1 << 16;

/// Samples per pixel the background reference stops at.
const LIVE_REFERENCE_SPP: u32 = 4096;

/// The most frames a scripted run renders: a typo should not hold a machine for hours.
const MAX_FRAMES: usize = 100_000;

/// The most lights: the decomposition's, and the frame's layers.
const MAX_LIGHTS: usize = 256;

/// Runs the viewer.
///
/// # Errors
/// Bad arguments, a map or model that cannot be read, no display (without `--offscreen`), GPU
/// failures: one line.
pub(crate) fn run(args: &ViewArgs) -> Result<(), String> {
    let technique = ViewTechnique::parse(&args.technique)?;
    if let Some(n) = args.frames
        && !(1..=MAX_FRAMES).contains(&n)
    {
        return Err(format!("--frames {n}: give 1 to {MAX_FRAMES}"));
    }
    if !(1..=MAX_LIGHTS).contains(&args.lights) {
        return Err(format!("--lights {}: give 1 to {MAX_LIGHTS}", args.lights));
    }
    for (name, degrees) in [("--orbit", args.orbit), ("--turn", args.turn)] {
        if !degrees.is_finite() {
            return Err(format!("{name} {degrees}: give a finite number of degrees"));
        }
    }
    if let Some(spp) = args.reference
        && !(2..=MAX_REFERENCE_SPP).contains(&spp)
    {
        return Err(format!("--reference {spp}: give 2 to {MAX_REFERENCE_SPP} samples per pixel"));
    }
    Shown::parse(&args.show)?;
    if let Some(h) = args.hold
        && !(h.is_finite() && (0.0..=3600.0).contains(&h))
    {
        return Err(format!("--hold {h}: give 0 to 3600 seconds"));
    }
    if args.hold.is_some() && args.offscreen {
        return Err("--hold is the window's: it has no background reference offscreen".into());
    }
    if args.size.0 == 0 || args.size.1 == 0 || args.size.0 > 16384 || args.size.1 > 16384 {
        return Err(format!("--size {}x{}: give 1 to 16384 a side", args.size.0, args.size.1));
    }
    let start = Instant::now();
    let map = trade::args::load_map(args.envmap.as_deref()).map_err(|e| e.to_string())?;
    let (scene, warnings) = open_scene(&args.scene, args.size, args.ground)?;
    for w in warnings {
        eprintln!("warning: {}: {w}", args.scene);
    }
    let content = Content { map, scene, loaded: start.elapsed() };
    if args.offscreen {
        let gpu = crate::composite::open_gpu(args.adapter.as_deref())?;
        let mut session = Session::new(&gpu, content, technique, args)?;
        offscreen(&gpu, &mut session, args)
    } else {
        window::run(content, technique, args)
    }
}

/// What was loaded before the GPU: the map, the scene and how long they took.
pub(crate) struct Content {
    map: EnvMap,
    scene: scene::Scene,
    loaded: Duration,
}

fn open_scene(spec: &str, size: (u32, u32), ground: Option<f32>) -> Result<(scene::Scene, Vec<String>), String> {
    trade::args::open_scene(spec, size, ground).map_err(|e| e.to_string())
}

/// The viewer's state beside the window: the stage, the camera, the map (for a new light
/// count), the frames' times and what went wrong with dropped files.
pub(crate) struct Session {
    stage: stage::Stage,
    camera: scene::Camera,
    orbit: orbit::Orbit,
    map: Arc<EnvMap>,
    /// Counts the maps and scenes loaded: a reference is of one of each.
    content: u64,
    scene_name: String,
    ground: Option<f32>,
    /// Per frame, from its start to the next one's (the first frame's alone apart).
    times: Vec<Duration>,
    /// Per frame, the CPU's recording of it.
    cpu: Vec<Duration>,
    /// Per frame, its GPU time (from timestamps, where the adapter has them inside encoders).
    gpu_times: Vec<Duration>,
    /// The last finished frame's image (the frame's target, until the next frame).
    last_texture: Option<wgpu::Texture>,
    /// What the display shows.
    shown: Shown,
    /// A scripted run's reference (`--reference`).
    converged: Option<reference::Converged>,
    /// The window's background reference at the end of `--hold`.
    live_reference: Option<reference::Progress>,
    /// Scene, map and GPU set-up.
    setup: Duration,
    /// Dropped files that could not be loaded, one line each.
    messages: Vec<String>,
    /// The last frame's lights shadowed and skipped (why, how many).
    shadowed: usize,
    skipped: Vec<(String, usize)>,
    adapter: String,
}

impl Session {
    fn new(gpu: &Gpu, content: Content, technique: ViewTechnique, args: &ViewArgs) -> Result<Self, String> {
        let t = Instant::now();
        let camera = content.scene.camera;
        let mut stage = stage::Stage::new(gpu, content.scene, &content.map, args.lights, technique)?;
        stage.set_turn(args.turn.to_radians());
        Ok(Self {
            orbit: orbit::Orbit::from_camera(&camera),
            camera,
            stage,
            map: Arc::new(content.map),
            content: 0,
            scene_name: args.scene.clone(),
            ground: args.ground,
            times: Vec::new(),
            cpu: Vec::new(),
            gpu_times: Vec::new(),
            last_texture: None,
            shown: Shown::parse(&args.show)?,
            converged: None,
            live_reference: None,
            setup: content.loaded + t.elapsed(),
            messages: Vec::new(),
            shadowed: 0,
            skipped: Vec::new(),
            adapter: gpu.describe(),
        })
    }

    /// The camera of the next frame.
    fn camera(&self) -> scene::Camera {
        let (w, h) = self.stage.size();
        scene::Camera { width: w, height: h, ..self.orbit.apply(&self.camera) }
    }

    /// Loads a dropped file: a map replaces the lighting, a model the scene. What fails is kept
    /// as a message and returned; the viewer goes on with what it had.
    fn load(&mut self, gpu: &Gpu, path: &Path) -> Result<(), String> {
        let r = self.try_load(gpu, path);
        if let Err(e) = &r {
            self.messages.push(e.clone());
        }
        r
    }

    fn try_load(&mut self, gpu: &Gpu, path: &Path) -> Result<(), String> {
        let name = path.to_string_lossy();
        let ext = path.extension().map(|e| e.to_string_lossy().to_ascii_lowercase()).unwrap_or_default();
        match ext.as_str() {
            "hdr" | "exr" => {
                let map = EnvMap::load(path).map_err(|e| e.to_string())?;
                self.stage.set_map(gpu, &map)?;
                self.map = Arc::new(map);
                self.content += 1;
            }
            "gltf" | "glb" => {
                let ground = self.ground.or(Some(0.5));
                let (scene, warnings) = open_scene(&name, self.stage.size(), ground)?;
                for w in warnings {
                    eprintln!("warning: {name}: {w}");
                }
                let camera = scene.camera;
                self.stage.set_scene(gpu, scene)?;
                self.camera = camera;
                self.orbit = orbit::Orbit::from_camera(&camera);
                self.scene_name = name.into_owned();
                self.content += 1;
            }
            _ => return Err(format!("{name}: not a map (.hdr, .exr) or a model (.gltf, .glb)")),
        }
        Ok(())
    }

    /// Moves the scene's moving object by `delta` on the ground.
    fn nudge(&mut self, gpu: &Gpu, delta: Vec3) {
        let offset = self.stage.offset() + delta;
        if let Err(e) = self.stage.move_object(gpu, offset) {
            self.messages.push(e);
        }
    }

    /// What a reference of the view from `camera` is of.
    fn view_key(&self, camera: &scene::Camera) -> reference::ViewKey {
        reference::ViewKey::new(camera, self.stage.offset(), self.stage.turn(), self.content)
    }

    /// An id of the frame from `camera`: its view, technique and lights.
    fn frame_id(&self, camera: &scene::Camera) -> u64 {
        use std::hash::{Hash, Hasher};
        let mut h = std::collections::hash_map::DefaultHasher::new();
        format!("{:?}", self.view_key(camera)).hash(&mut h);
        (self.stage.technique.name(), self.stage.lights).hash(&mut h);
        h.finish()
    }

    /// The reference tracer's job for the view from `camera`, to `max_spp` samples.
    fn job(&self, camera: &scene::Camera, max_spp: u32) -> reference::Job {
        reference::Job::new(
            self.view_key(camera),
            self.stage.scene(),
            camera,
            self.stage.moving_index(),
            self.stage.offset(),
            self.stage.turn(),
            Arc::clone(&self.map),
            self.stage.exposure(),
            max_spp,
        )
    }

    /// A scripted run's reference: the last frame's view refined to `spp`, the frame measured
    /// against it (the frame has finished). The reference's image is returned for the display.
    fn converge(&mut self, gpu: &Gpu, spp: u32) -> Result<Option<reference::Progress>, String> {
        let Some(texture) = &self.last_texture else { return Ok(None) };
        let frame = gpu::read_hdr(gpu, texture).map_err(|e| e.to_string())?;
        let camera = self.camera();
        let job = self.job(&camera, spp);
        let Some(c) = reference::converge(&job, &frame) else { return Ok(None) };
        let progress = reference::Progress {
            key: job.key,
            image: Arc::new(c.image.clone()),
            spp: c.spp,
            seconds: c.seconds,
            noise: c.noise,
            error: Some(reference::FrameError {
                frame: self.frame_id(&camera),
                rmse: c.rmse,
                rmse_truth: c.rmse_truth,
                flip: c.flip,
                passed: c.reached_rmse.map(|(spp, s)| (s, spp)),
            }),
            generation: 0,
        };
        self.converged = Some(c);
        Ok(Some(progress))
    }

    /// A step on the ground: 2 % of the scene's size.
    fn step(&self) -> f32 {
        let (lo, hi) = self.stage.bounds();
        let d = (hi - lo).length();
        if d.is_finite() && d > 0.0 { 0.02 * d } else { 0.1 }
    }

    /// The frame-time summary (`--json`).
    fn json(&self, screenshot: Option<(&Path, &str)>) -> serde_json::Value {
        let ms = |d: &Duration| d.as_secs_f64() * 1e3;
        // the first frame compiles pipelines and grows buffers: the median is of the rest
        let steady: Vec<f64> =
            if self.times.len() > 1 { &self.times[1..] } else { &self.times[..] }.iter().map(ms).collect();
        let cpu: Vec<f64> = if self.cpu.len() > 1 { &self.cpu[1..] } else { &self.cpu[..] }.iter().map(ms).collect();
        let gpu: Vec<f64> =
            if self.gpu_times.len() > 1 { &self.gpu_times[1..] } else { &self.gpu_times[..] }.iter().map(ms).collect();
        let reach = |r: Option<(u32, f64)>| r.map(|(spp, s)| serde_json::json!({"spp": spp, "seconds": s}));
        let reference = self.converged.as_ref().map(|c| {
            serde_json::json!({
                "of": "the map's direct light ray traced (MIS), two halves of seeds 1 and 2",
                "spp": c.spp,
                "seconds": c.seconds,
                "noise_rmse": c.noise,
                "rmse": c.rmse,
                "rmse_without_noise": c.rmse_truth,
                "flip": c.flip,
                "flip_tonemap": c.tonemap,
                "reached_rmse": reach(c.reached_rmse),
                "reached_flip": reach(c.reached_flip),
            })
        });
        let (w, h) = self.stage.size();
        serde_json::json!({
            "frames": self.times.len(),
            "median_ms": median(&steady),
            "max_ms": steady.iter().copied().fold(0.0, f64::max),
            "first_frame_ms": self.times.first().map(ms),
            "cpu_median_ms": median(&cpu),
            "gpu_median_ms": median(&gpu),
            "technique": self.stage.technique.name(),
            "adapter": self.adapter,
            "size": [w, h],
            "scene": self.scene_name,
            "triangles": self.stage.scene().triangle_count(),
            "moving_object": self.stage.moving_object(),
            "lights": self.stage.lights,
            "map_turn_degrees": self.stage.turn().to_degrees(),
            "lights_shadowed": self.shadowed,
            "lights_skipped": self.skipped.iter().map(|(why, n)| serde_json::json!({"why": why, "lights": n})).collect::<Vec<_>>(),
            "setup_ms": ms(&self.setup),
            "screenshot": screenshot.map(|(p, _)| p.display().to_string()),
            "screenshot_from": screenshot.map(|(_, from)| from),
            "messages": self.messages,
            "reference": reference,
            "live_reference": self.live_reference.as_ref().map(|p| {
                let e = p.error.as_ref();
                serde_json::json!({
                    "spp": p.spp,
                    "seconds": p.seconds,
                    "noise_rmse": p.noise,
                    "rmse": e.map(|e| e.rmse),
                    "rmse_without_noise": e.map(|e| e.rmse_truth),
                    "flip": e.map(|e| e.flip),
                    "passed": e.and_then(|e| e.passed).map(|(s, spp)| serde_json::json!({"seconds": s, "spp": spp})),
                })
            }),
        })
    }

    /// The last frame's reports, read once it has finished.
    fn finish(&mut self, gpu: &Gpu, frame: gpu::RenderedFrame) -> Result<(), String> {
        let (texture, reports) = frame.finish_reports(gpu).map_err(|e| e.to_string())?;
        self.last_texture = Some(texture);
        self.skipped = gpu::skip_reasons(&reports);
        self.shadowed = reports.len() - self.skipped.iter().map(|(_, n)| n).sum::<usize>();
        Ok(())
    }
}

/// The one of `all` called `name` (a `what`), or an error listing the names.
fn named<T: Copy>(all: &[T], name_of: fn(T) -> &'static str, what: &str, name: &str) -> Result<T, String> {
    all.iter().copied().find(|t| name_of(*t) == name).ok_or_else(|| {
        let known: Vec<&str> = all.iter().map(|t| name_of(*t)).collect();
        format!("unknown {what} {name:?}; known: {}", known.join(", "))
    })
}

/// The one after `t` in `all`, the first after the last.
fn after<T: Copy + PartialEq>(all: &[T], t: T) -> T {
    let k = all.iter().position(|&x| x == t).unwrap_or(0);
    all[(k + 1) % all.len()]
}

fn median(v: &[f64]) -> Option<f64> {
    if v.is_empty() {
        return None;
    }
    let mut s = v.to_vec();
    s.sort_by(f64::total_cmp);
    let n = s.len();
    Some(if n % 2 == 1 { s[n / 2] } else { 0.5 * (s[n / 2 - 1] + s[n / 2]) })
}

/// The 8-bit format frames are shown in offscreen (and screenshots taken from where a window's
/// surface cannot be copied).
const OFFSCREEN_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Rgba8UnormSrgb;

/// GPU timestamps around one frame: before the stage's first submission and after the
/// display pass (`None` without timestamps inside encoders).
struct FrameStamps(Option<gpu::StageStamps>);

impl FrameStamps {
    fn begin(gpu: &Gpu) -> Self {
        let stamps = gpu::StageStamps::new(gpu, 1).ok().flatten();
        if let Some(s) = &stamps {
            let mut encoder = gpu.encoder("frame start stamp");
            s.write(&mut encoder, 0);
            gpu.submit(encoder);
        }
        Self(stamps)
    }

    /// Records the end stamp and the resolve into the frame's last encoder.
    fn end(&self, encoder: &mut wgpu::CommandEncoder) {
        if let Some(s) = &self.0 {
            s.write(encoder, 1);
            s.record_resolve(encoder);
        }
    }

    /// The frame's GPU time, once it has finished.
    fn read(self, gpu: &Gpu) -> Option<Duration> {
        self.0?.read(gpu).ok()?.first().copied()
    }
}

/// `--offscreen`: the window's frames drawn into a texture, one frame in flight.
fn offscreen(gpu: &Gpu, session: &mut Session, args: &ViewArgs) -> Result<(), String> {
    let frames = args.frames.unwrap_or(1);
    let display = display::Display::new(gpu, OFFSCREEN_FORMAT);
    let target = display::offscreen_target(gpu, session.stage.size(), OFFSCREEN_FORMAT);
    let view = target.create_view(&wgpu::TextureViewDescriptor::default());
    for k in 0..frames {
        let start = Instant::now();
        if k == 1
            && let Some(p) = &args.drop
        {
            let _ = session.load(gpu, p);
        }
        session.orbit.rotate(args.orbit.to_radians() * f32::from(k > 0), 0.0);
        let camera = session.camera();
        let stamps = FrameStamps::begin(gpu);
        let frame = session.stage.render(gpu, &camera).map_err(|e| e.to_string())?;
        let mut encoder = gpu.encoder("display");
        display.record(gpu, &mut encoder, &frame.texture, session.stage.exposure(), &view, (Shown::Frame, None));
        stamps.end(&mut encoder);
        session.cpu.push(start.elapsed());
        gpu.submit(encoder);
        // one frame in flight: this one, waited for before the next is recorded
        gpu.wait(None).map_err(|e| e.to_string())?;
        session.finish(gpu, frame)?;
        session.gpu_times.extend(stamps.read(gpu));
        session.times.push(start.elapsed());
    }
    let reference = scripted_reference(gpu, session, args)?;
    let mut shot = None;
    if args.screenshot.is_some()
        && let Some(frame) = &session.last_texture
    {
        // the last frame shown again, as the window would show it (with the reference, if asked)
        let mut encoder = gpu.encoder("screenshot");
        let shown = (session.shown, reference.as_ref().map(|r| &r.1));
        display.record(gpu, &mut encoder, frame, session.stage.exposure(), &view, shown);
        shot = Some(display::PendingShot::record(gpu, &mut encoder, &target).map_err(|e| e.to_string())?);
        gpu.submit(encoder);
    }
    finish_run(gpu, session, args, shot, "offscreen", reference.as_ref().map(|r| &r.1))
}

/// `--reference`: the last frame's view refined and the frame measured (it has finished), with
/// the reference uploaded for the display.
fn scripted_reference(
    gpu: &Gpu,
    session: &mut Session,
    args: &ViewArgs,
) -> Result<Option<(reference::Progress, wgpu::Texture)>, String> {
    let Some(spp) = args.reference else { return Ok(None) };
    let Some(progress) = session.converge(gpu, spp)? else { return Ok(None) };
    let texture = display::upload_hdr(gpu, session.stage.size(), &progress.image).map_err(|e| e.to_string())?;
    Ok(Some((progress, texture)))
}

/// Saves the screenshot (and `--difference`) and prints the JSON of a `--frames` run.
fn finish_run(
    gpu: &Gpu,
    session: &Session,
    args: &ViewArgs,
    shot: Option<display::PendingShot>,
    from: &str,
    reference: Option<&wgpu::Texture>,
) -> Result<(), String> {
    let mut saved = None;
    if let (Some(path), Some(shot)) = (&args.screenshot, shot) {
        let ((w, h), rgb) = shot.finish(gpu).map_err(|e| e.to_string())?;
        envmap_sphere::io::save_png_srgb8(path, w, h, &rgb).map_err(|e| e.to_string())?;
        saved = Some((path.as_path(), from));
    }
    if let (Some(path), Some(reference), Some(frame)) = (&args.difference, reference, &session.last_texture) {
        let display = display::Display::new(gpu, OFFSCREEN_FORMAT);
        let target = display::offscreen_target(gpu, session.stage.size(), OFFSCREEN_FORMAT);
        let view = target.create_view(&wgpu::TextureViewDescriptor::default());
        let mut encoder = gpu.encoder("difference");
        let shown = (Shown::Difference, Some(reference));
        display.record(gpu, &mut encoder, frame, session.stage.exposure(), &view, shown);
        let shot = display::PendingShot::record(gpu, &mut encoder, &target).map_err(|e| e.to_string())?;
        gpu.submit(encoder);
        let ((w, h), rgb) = shot.finish(gpu).map_err(|e| e.to_string())?;
        envmap_sphere::io::save_png_srgb8(path, w, h, &rgb).map_err(|e| e.to_string())?;
    }
    if args.json {
        outln!("{}", session.json(saved));
    } else {
        let j = session.json(saved);
        outln!(
            "{} frames of {} at {}x{} ({}): median {:.1} ms",
            j["frames"],
            j["technique"].as_str().unwrap_or_default(),
            session.stage.size().0,
            session.stage.size().1,
            session.adapter,
            j["median_ms"].as_f64().unwrap_or(f64::NAN)
        );
        if let Some(r) = session.converged.as_ref() {
            outln!(
                "against a reference of {} spp: RMSE {:.5} ({:.5} without its noise), FLIP {:.4}",
                r.spp,
                r.rmse,
                r.rmse_truth,
                r.flip
            );
        }
        for m in &session.messages {
            outln!("not loaded: {m}");
        }
    }
    Ok(())
}
