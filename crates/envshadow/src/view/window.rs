//! The window: winit's event loop, a wgpu surface on the adapter that can present to it, the
//! device the toolkit is handed (`gpu::Gpu::from_device`, as a renderer hands it its own), and
//! the input.
//!
//! Keys: `T` the next technique, `+` / `-` twice or half the lights, `Q` / `E` turn the map,
//! arrows (or W A S D) move the scene's object on the ground, `R` shows the frame, the reference
//! or their difference, `H` hides the panel, `P` saves a screenshot, `Esc` quits. Mouse: left
//! drag orbits, right drag (or shift + left) pans, the wheel zooms, ctrl + left drag moves the
//! object. Files dropped on the window load: a map or a model.
//!
//! A frame is drawn when something changed. While nothing does, the view is still: the reference
//! tracer refines its reference in the background ([`super::reference`]), the frame shown is
//! measured against it, and the window redraws (the display pass and the panel, not the frame)
//! when the reference has something new. Scripted runs (`--frames`) draw every frame.

use super::display::{Display, PendingShot, Shown};
use super::panel::{Facts, Panel};
use super::reference::{Progress, Reference};
use super::{Content, FrameStamps, LIVE_REFERENCE_SPP, Session, ViewArgs, ViewTechnique, finish_run};
use gpu::Gpu;
use std::sync::Arc;
use std::time::{Duration, Instant};
use winit::application::ApplicationHandler;
use winit::dpi::PhysicalSize;
use winit::event::{ElementState, MouseButton, MouseScrollDelta, WindowEvent};
use winit::event_loop::{ActiveEventLoop, ControlFlow, EventLoop};
use winit::keyboard::{Key, ModifiersState, NamedKey};
use winit::window::{Window, WindowId};

/// Opens the window and runs until it closes (or `--frames` are done).
///
/// # Errors
/// No display; no adapter that can present to the window; GPU failures; the run's own.
pub(crate) fn run(content: Content, technique: ViewTechnique, args: &ViewArgs) -> Result<(), String> {
    let event_loop = EventLoop::new()
        .map_err(|e| format!("cannot open a window: {e} (no display? run under xvfb-run, or add --offscreen)"))?;
    // scripted runs draw frame after frame; the window waits for input, and looks at the
    // background reference a few times a second
    event_loop.set_control_flow(if args.frames.is_some() { ControlFlow::Poll } else { ControlFlow::Wait });
    let mut app = App {
        args,
        technique,
        content: Some(content),
        live: None,
        error: None,
        in_flight: None,
        started: None,
        shown_id: None,
        hold_until: None,
        measured: None,
        progress: None,
        uploaded: None,
        drag: Drag::default(),
        modifiers: ModifiersState::empty(),
        shot_asked: false,
        shots_saved: 0,
        dropped: false,
    };
    event_loop.run_app(&mut app).map_err(|e| e.to_string())?;
    app.error.map_or(Ok(()), Err)
}

/// What the window holds once it exists.
struct Live {
    window: Arc<Window>,
    instance: wgpu::Instance,
    surface: wgpu::Surface<'static>,
    config: wgpu::SurfaceConfiguration,
    gpu: Gpu,
    session: Session,
    display: Display,
    /// The display pass into a texture that can be copied, for screenshots where the
    /// surface's images cannot be (`None` where they can: the screenshot is what was shown).
    fallback: Option<Display>,
    panel: Panel,
    reference: Reference,
    /// The reference uploaded for the display, and its generation.
    reference_texture: Option<wgpu::Texture>,
}

#[derive(Default)]
struct Drag {
    left: bool,
    right: bool,
    last: Option<(f64, f64)>,
}

struct App<'a> {
    args: &'a ViewArgs,
    technique: ViewTechnique,
    content: Option<Content>,
    live: Option<Live>,
    error: Option<String>,
    /// The frame submitted last, read once the next one starts (one frame in flight).
    in_flight: Option<(gpu::RenderedFrame, FrameStamps)>,
    /// When the last frame started.
    started: Option<Instant>,
    /// The frame drawn last (its view, technique and lights), and the one measured last.
    shown_id: Option<u64>,
    /// `--hold`: the scripted frames are done, the view is held still until then.
    hold_until: Option<Instant>,
    measured: Option<u64>,
    /// The reference of the view shown, as the panel and display show it.
    progress: Option<Progress>,
    /// The generation of the reference uploaded for the display.
    uploaded: Option<u64>,
    drag: Drag,
    modifiers: ModifiersState,
    /// The `P` key was pressed: the next frame is saved.
    shot_asked: bool,
    shots_saved: usize,
    /// `--drop`'s file was loaded (once, after the first frame).
    dropped: bool,
}

impl App<'_> {
    fn fail(&mut self, event_loop: &ActiveEventLoop, e: String) {
        self.error.get_or_insert(e);
        event_loop.exit();
    }

    fn open(&mut self, event_loop: &ActiveEventLoop) -> Result<Live, String> {
        let content = self.content.take().ok_or("the window was opened twice")?;
        let (w, h) = self.args.size;
        let attributes = Window::default_attributes()
            .with_title("envshadow")
            .with_inner_size(PhysicalSize::new(w, h))
            .with_resizable(self.args.frames.is_none());
        let window = Arc::new(event_loop.create_window(attributes).map_err(|e| format!("cannot open a window: {e}"))?);
        let mut descriptor = wgpu::InstanceDescriptor::new_without_display_handle_from_env();
        descriptor.backends = wgpu::Backends::from_env().unwrap_or(wgpu::Backends::PRIMARY);
        let backends = descriptor.backends;
        let instance = wgpu::Instance::new(descriptor);
        let surface =
            instance.create_surface(Arc::clone(&window)).map_err(|e| format!("cannot draw into the window: {e}"))?;
        let adapters: Vec<wgpu::Adapter> = pollster::block_on(instance.enumerate_adapters(backends))
            .into_iter()
            .filter(|a| a.is_surface_supported(&surface))
            .collect();
        let infos: Vec<wgpu::AdapterInfo> = adapters.iter().map(wgpu::Adapter::get_info).collect();
        let wanted =
            self.args.adapter.clone().or_else(|| std::env::var(gpu::ADAPTER_ENV).ok().filter(|n| !n.is_empty()));
        let k = gpu::pick_adapter(&infos, wanted.as_deref()).ok_or_else(|| {
            let found: Vec<String> = infos.iter().map(gpu::describe_adapter).collect();
            format!(
                "no adapter that can present to the window{}; found: {}",
                wanted.map_or(String::new(), |w| format!(" matches {w:?}")),
                if found.is_empty() { "none".to_string() } else { found.join("; ") }
            )
        })?;
        let adapter = &adapters[k];
        // what the toolkit uses when the device has it (as `gpu::Gpu` asks for itself)
        let wanted = wgpu::Features::CLIP_DISTANCES
            | wgpu::Features::FLOAT32_BLENDABLE
            | wgpu::Features::TIMESTAMP_QUERY
            | wgpu::Features::TIMESTAMP_QUERY_INSIDE_ENCODERS;
        let (device, queue) = pollster::block_on(adapter.request_device(&wgpu::DeviceDescriptor {
            label: Some("envshadow view"),
            required_features: adapter.features() & wanted,
            required_limits: adapter.limits(),
            ..Default::default()
        }))
        .map_err(|e| format!("{}: cannot open a device: {e}", adapter.get_info().name))?;
        let gpu = Gpu::from_device(device, queue, adapter.get_info());
        let caps = surface.get_capabilities(adapter);
        use wgpu::TextureFormat as F;
        let format = [F::Rgba8UnormSrgb, F::Bgra8UnormSrgb, F::Rgba8Unorm, F::Bgra8Unorm]
            .into_iter()
            .find(|f| caps.formats.contains(f))
            .ok_or_else(|| format!("the window offers no 8-bit format (it offers {:?})", caps.formats))?;
        let copyable = caps.usages.contains(wgpu::TextureUsages::COPY_SRC);
        let size = window.inner_size();
        let config = wgpu::SurfaceConfiguration {
            usage: wgpu::TextureUsages::RENDER_ATTACHMENT
                | if copyable { wgpu::TextureUsages::COPY_SRC } else { wgpu::TextureUsages::empty() },
            format,
            width: size.width.max(1),
            height: size.height.max(1),
            // a scripted run measures frames, not the display's refresh
            present_mode: if self.args.frames.is_some() {
                wgpu::PresentMode::AutoNoVsync
            } else {
                wgpu::PresentMode::AutoVsync
            },
            desired_maximum_frame_latency: 2,
            alpha_mode: caps.alpha_modes.first().copied().unwrap_or(wgpu::CompositeAlphaMode::Auto),
            view_formats: Vec::new(),
            color_space: wgpu::SurfaceColorSpace::Auto,
        };
        surface.configure(&gpu.device, &config);
        let mut content = content;
        (content.scene.camera.width, content.scene.camera.height) = (config.width, config.height);
        let session = Session::new(&gpu, content, self.technique, self.args)?;
        let display = Display::new(&gpu, format);
        let fallback = (!copyable).then(|| Display::new(&gpu, super::OFFSCREEN_FORMAT));
        let mut panel = Panel::new(&gpu, &window, format);
        panel.visible = !self.args.no_panel;
        let reference = Reference::new();
        Ok(Live {
            window,
            instance,
            surface,
            config,
            gpu,
            session,
            display,
            fallback,
            panel,
            reference,
            reference_texture: None,
        })
    }

    /// One frame: the previous one read; this one recorded where something changed (every
    /// frame of a scripted run), else the reference refined and the frame measured; shown with
    /// the panel; on the last scripted frame the reference asked for, the screenshot and the
    /// JSON.
    fn frame(&mut self, event_loop: &ActiveEventLoop) -> Result<(), String> {
        let Some(live) = self.live.as_mut() else { return Ok(()) };
        let start = Instant::now();
        let holding = self.hold_until;
        let scripted = self.args.frames.is_some() && holding.is_none();
        // one frame in flight: the previous one's work waited for, its reports read
        if let Some((previous, stamps)) = self.in_flight.take() {
            live.gpu.wait(None).map_err(|e| e.to_string())?;
            live.session.finish(&live.gpu, previous)?;
            live.session.gpu_times.extend(stamps.read(&live.gpu));
            // the last scripted frame before --hold: from its start to here
            if self.hold_until.is_some()
                && let Some(t) = self.started
            {
                live.session.times.push(t.elapsed());
            }
        }
        // frames drawn so far
        let k = live.session.cpu.len();
        if k >= 1
            && !self.dropped
            && let Some(p) = &self.args.drop
        {
            self.dropped = true;
            let _ = live.session.load(&live.gpu, p);
        }
        if k > 0 && scripted {
            live.session.orbit.rotate(self.args.orbit.to_radians(), 0.0);
        }
        let surface = match live.surface.get_current_texture() {
            wgpu::CurrentSurfaceTexture::Success(t) | wgpu::CurrentSurfaceTexture::Suboptimal(t) => t,
            // no image this time: try again on the next redraw (the loop only draws when asked)
            wgpu::CurrentSurfaceTexture::Timeout | wgpu::CurrentSurfaceTexture::Occluded => {
                self.started = None;
                live.window.request_redraw();
                return Ok(());
            }
            wgpu::CurrentSurfaceTexture::Outdated => {
                live.surface.configure(&live.gpu.device, &live.config);
                self.started = None;
                live.window.request_redraw();
                return Ok(());
            }
            wgpu::CurrentSurfaceTexture::Lost => {
                live.surface = live
                    .instance
                    .create_surface(Arc::clone(&live.window))
                    .map_err(|e| format!("the window's surface was lost: {e}"))?;
                live.surface.configure(&live.gpu.device, &live.config);
                self.started = None;
                live.window.request_redraw();
                return Ok(());
            }
            other => return Err(format!("cannot draw into the window: {other:?}")),
        };
        let size = (surface.texture.width(), surface.texture.height());
        live.session.stage.resize(&live.gpu, size)?;
        let camera = live.session.camera();
        let key = live.session.view_key(&camera);
        let id = live.session.frame_id(&camera);
        let changed = scripted || self.shown_id != Some(id) || live.session.last_texture.is_none();
        let frame_texture = if changed {
            // the view moved: the reference of the old one is of no use
            if live.reference.key().is_some_and(|r| r != key) {
                live.reference.want(None);
                self.progress = None;
            }
            if let Some(t) = self.started.replace(start) {
                live.session.times.push(start - t);
            }
            let stamps = FrameStamps::begin(&live.gpu);
            let frame = live.session.stage.render(&live.gpu, &camera).map_err(|e| e.to_string())?;
            let texture = frame.texture.clone();
            self.in_flight = Some((frame, stamps));
            self.shown_id = Some(id);
            texture
        } else {
            // still: refine the view's reference, and measure the frame shown (it has finished)
            if live.reference.key() != Some(key) {
                live.reference.want(Some(live.session.job(&camera, LIVE_REFERENCE_SPP)));
            }
            let texture = live.session.last_texture.clone().ok_or("no frame to show")?;
            if self.measured != Some(id) {
                self.measured = Some(id);
                live.reference.measure(id, gpu::read_hdr(&live.gpu, &texture).map_err(|e| e.to_string())?);
            }
            self.progress = live.reference.progress().filter(|p| p.key == key);
            texture
        };
        let mut last = self.args.frames.is_some_and(|n| k + 1 >= n);
        if let Some(t) = holding {
            last = start >= t;
        } else if last && let Some(h) = self.args.hold {
            // the frames are done: the view is held still from the next redraw on
            self.hold_until = Some(start + Duration::from_secs_f32(h));
            last = false;
        }
        if last {
            // the last scripted frame: finished here, then its reference if asked
            live.gpu.wait(None).map_err(|e| e.to_string())?;
            // (its GPU time is not read: its end stamp would be in the display's encoder; its
            // times end here, the reference's apart)
            if changed {
                live.session.cpu.push(start.elapsed());
            }
            if let Some((frame, _)) = self.in_flight.take() {
                live.session.finish(&live.gpu, frame)?;
                live.session.times.push(start.elapsed());
            }
            if holding.is_some() {
                live.session.live_reference.clone_from(&self.progress);
            }
            if let Some(spp) = self.args.reference {
                self.progress = live.session.converge(&live.gpu, spp)?;
            }
        }
        // the reference for the display, uploaded when it has something new
        let reference_shown = live.session.shown != Shown::Frame;
        match &self.progress {
            Some(p) if reference_shown && self.uploaded != Some(p.generation) => {
                live.reference_texture =
                    Some(super::display::upload_hdr(&live.gpu, size, &p.image).map_err(|e| e.to_string())?);
                self.uploaded = Some(p.generation);
            }
            None => {
                live.reference_texture = None;
                self.uploaded = None;
            }
            _ => {}
        }
        let shown = (live.session.shown, live.reference_texture.as_ref().filter(|_| self.progress.is_some()));
        let target = surface.texture.create_view(&wgpu::TextureViewDescriptor::default());
        let mut encoder = live.gpu.encoder("display");
        let exposure = live.session.stage.exposure();
        live.display.record(&live.gpu, &mut encoder, &frame_texture, exposure, &target, shown);
        let asked = {
            let s = &live.session;
            let ms = |d: Option<&Duration>| d.map(|d| d.as_secs_f64() * 1e3);
            let message = s.messages.last().map(String::as_str);
            let facts = Facts {
                adapter: &s.adapter,
                size,
                gpu_ms: ms(s.gpu_times.last()),
                cpu_ms: ms(s.cpu.last()),
                frame_ms: ms(s.times.last()),
                technique: s.stage.technique,
                lights: s.stage.lights,
                shadowed: s.shadowed,
                skipped: &s.skipped,
                turn_degrees: s.stage.turn().to_degrees(),
                scene: &s.scene_name,
                triangles: s.stage.scene().triangle_count(),
                reference: self.progress.as_ref(),
                frame: id,
                still: !changed,
                message,
                shown: s.shown,
            };
            live.panel.record(&live.gpu, &mut encoder, &live.window, &target, size, &facts)
        };
        let mut shot = None;
        if (last && self.args.screenshot.is_some()) || std::mem::take(&mut self.shot_asked) {
            shot = Some(match &live.fallback {
                None => (
                    PendingShot::record(&live.gpu, &mut encoder, &surface.texture).map_err(|e| e.to_string())?,
                    "window",
                ),
                Some(offscreen) => {
                    // the same pass into a texture that can be copied (without the panel)
                    let t = super::display::offscreen_target(&live.gpu, size, super::OFFSCREEN_FORMAT);
                    let view = t.create_view(&wgpu::TextureViewDescriptor::default());
                    offscreen.record(&live.gpu, &mut encoder, &frame_texture, exposure, &view, shown);
                    (PendingShot::record(&live.gpu, &mut encoder, &t).map_err(|e| e.to_string())?, "offscreen")
                }
            });
        }
        if let Some((_, stamps)) = &self.in_flight {
            stamps.end(&mut encoder);
        }
        if changed && !last {
            live.session.cpu.push(start.elapsed());
        }
        live.gpu.submit(encoder);
        live.window.pre_present_notify();
        live.gpu.queue.present(surface);
        if last {
            live.gpu.wait(None).map_err(|e| e.to_string())?;
            let from = shot.as_ref().map_or("", |s| s.1);
            let reference = live.reference_texture.clone().filter(|_| self.args.reference.is_some());
            let reference = match (&reference, &self.progress) {
                (None, Some(p)) if self.args.difference.is_some() => {
                    Some(super::display::upload_hdr(&live.gpu, size, &p.image).map_err(|e| e.to_string())?)
                }
                _ => reference,
            };
            finish_run(&live.gpu, &live.session, self.args, shot.map(|s| s.0), from, reference.as_ref())?;
            event_loop.exit();
            return Ok(());
        }
        if let Some((shot, _)) = shot {
            // the `P` key's screenshot, numbered in the working folder
            let ((w, h), rgb) = shot.finish(&live.gpu).map_err(|e| e.to_string())?;
            self.shots_saved += 1;
            let path = std::path::PathBuf::from(format!("envshadow-{}.png", self.shots_saved));
            match envmap_sphere::io::save_png_srgb8(&path, w, h, &rgb) {
                Ok(()) => eprintln!("saved {}", path.display()),
                Err(e) => eprintln!("screenshot not saved: {e}"),
            }
        }
        self.apply(&asked);
        let Some(live) = self.live.as_mut() else { return Ok(()) };
        let s = &live.session;
        live.window.set_title(&format!(
            "envshadow: {} ({} lights, {} shadowed){}",
            s.stage.technique.name(),
            s.stage.lights,
            s.shadowed,
            s.messages.last().map_or(String::new(), |m| format!(" | {m}"))
        ));
        // a drawn frame asks for the next (a still view is noticed there); a still one waits
        if changed || scripted {
            live.window.request_redraw();
        }
        Ok(())
    }

    /// What the panel's controls asked for.
    fn apply(&mut self, asked: &super::panel::Asked) {
        let Some(live) = self.live.as_mut() else { return };
        let s = &mut live.session;
        if let Some(t) = asked.technique {
            s.stage.technique = t;
        }
        if let Some(n) = asked.lights {
            set_lights(s, &live.gpu, n);
        }
        if let Some(shown) = asked.shown {
            s.shown = shown;
        }
        if asked.technique.is_some() || asked.lights.is_some() || asked.shown.is_some() {
            live.window.request_redraw();
        }
    }

    fn key(&mut self, key: &Key) -> Result<(), String> {
        let Some(live) = self.live.as_mut() else { return Ok(()) };
        let s = &mut live.session;
        let (right, forward) = s.orbit.ground_axes();
        let step = s.step();
        let gpu = &live.gpu;
        match key {
            Key::Named(NamedKey::ArrowLeft) => s.nudge(gpu, -step * right),
            Key::Named(NamedKey::ArrowRight) => s.nudge(gpu, step * right),
            Key::Named(NamedKey::ArrowUp) => s.nudge(gpu, step * forward),
            Key::Named(NamedKey::ArrowDown) => s.nudge(gpu, -step * forward),
            Key::Character(c) => match c.as_str() {
                "a" | "A" => s.nudge(gpu, -step * right),
                "d" | "D" => s.nudge(gpu, step * right),
                "w" | "W" => s.nudge(gpu, step * forward),
                "s" | "S" => s.nudge(gpu, -step * forward),
                "t" | "T" => s.stage.technique = s.stage.technique.next(),
                "q" | "Q" => s.stage.set_turn(s.stage.turn() - 15f32.to_radians()),
                "e" | "E" => s.stage.set_turn(s.stage.turn() + 15f32.to_radians()),
                "+" | "=" => set_lights(s, gpu, (s.stage.lights * 2).min(super::MAX_LIGHTS)),
                "-" => set_lights(s, gpu, (s.stage.lights / 2).max(1)),
                "p" | "P" => self.shot_asked = true,
                "r" | "R" => s.shown = s.shown.next(),
                "h" | "H" => live.panel.visible = !live.panel.visible,
                _ => {}
            },
            _ => {}
        }
        Ok(())
    }

    fn cursor(&mut self, x: f64, y: f64) {
        let Some(live) = self.live.as_mut() else { return };
        let Some((lx, ly)) = self.drag.last.replace((x, y)) else { return };
        let (dx, dy) = ((x - lx) as f32, (y - ly) as f32);
        let s = &mut live.session;
        let h = live.config.height.max(1) as f32;
        if self.drag.left && self.modifiers.control_key() {
            let (right, forward) = s.orbit.ground_axes();
            let scale = 2.0 * s.orbit.distance / h;
            s.nudge(&live.gpu, scale * (dx * right - dy * forward));
        } else if self.drag.right || (self.drag.left && self.modifiers.shift_key()) {
            s.orbit.pan(-dx / h, dy / h);
        } else if self.drag.left {
            s.orbit.rotate(-dx * 0.008, dy * 0.008);
        }
    }
}

fn set_lights(s: &mut Session, gpu: &Gpu, lights: usize) {
    if lights != s.stage.lights {
        let map = s.map.clone();
        if let Err(e) = s.stage.set_lights(gpu, &map, lights) {
            s.messages.push(e);
        }
    }
}

impl ApplicationHandler for App<'_> {
    fn resumed(&mut self, event_loop: &ActiveEventLoop) {
        if self.live.is_some() {
            return;
        }
        match self.open(event_loop) {
            Ok(live) => {
                live.window.request_redraw();
                self.live = Some(live);
            }
            Err(e) => self.fail(event_loop, e),
        }
    }

    fn about_to_wait(&mut self, event_loop: &ActiveEventLoop) {
        let Some(live) = self.live.as_ref() else { return };
        if self.args.frames.is_some() && self.hold_until.is_none() {
            return;
        }
        // a still view's reference has something new: show it
        if let Some(p) = live.reference.progress()
            && self.progress.as_ref().is_none_or(|q| q.generation != p.generation)
            && self.measured.is_some()
        {
            live.window.request_redraw();
        }
        let now = Instant::now();
        let wake = if live.reference.key().is_some() { Duration::from_millis(250) } else { Duration::from_secs(1) };
        let mut until = now + wake;
        if let Some(t) = self.hold_until {
            // --hold's end: the last redraw
            if now >= t {
                live.window.request_redraw();
            }
            until = until.min(t);
        }
        event_loop.set_control_flow(ControlFlow::WaitUntil(until));
    }

    fn window_event(&mut self, event_loop: &ActiveEventLoop, _: WindowId, event: WindowEvent) {
        let input = matches!(
            event,
            WindowEvent::KeyboardInput { .. }
                | WindowEvent::MouseInput { .. }
                | WindowEvent::CursorMoved { .. }
                | WindowEvent::MouseWheel { .. }
                | WindowEvent::ModifiersChanged(_)
        );
        if let Some(live) = self.live.as_mut() {
            if input || matches!(event, WindowEvent::Resized(_) | WindowEvent::DroppedFile(_)) {
                live.window.request_redraw();
            }
            // what the panel takes (a click on a button) is not the view's; a release always is
            let release = matches!(event, WindowEvent::MouseInput { state: ElementState::Released, .. });
            if input && live.panel.on_event(&live.window, &event) && !release {
                return;
            }
        }
        let r = match event {
            WindowEvent::CloseRequested => {
                event_loop.exit();
                Ok(())
            }
            WindowEvent::RedrawRequested => self.frame(event_loop),
            WindowEvent::Resized(size) => {
                if let Some(live) = self.live.as_mut()
                    && size.width > 0
                    && size.height > 0
                {
                    (live.config.width, live.config.height) = (size.width, size.height);
                    live.surface.configure(&live.gpu.device, &live.config);
                }
                Ok(())
            }
            WindowEvent::DroppedFile(path) => {
                if let Some(live) = self.live.as_mut()
                    && let Err(e) = live.session.load(&live.gpu, &path)
                {
                    eprintln!("not loaded: {e}");
                }
                Ok(())
            }
            WindowEvent::ModifiersChanged(m) => {
                self.modifiers = m.state();
                Ok(())
            }
            WindowEvent::KeyboardInput { event, .. } if event.state == ElementState::Pressed => {
                if event.logical_key == Key::Named(NamedKey::Escape) {
                    event_loop.exit();
                    Ok(())
                } else {
                    self.key(&event.logical_key)
                }
            }
            WindowEvent::MouseInput { state, button, .. } => {
                let down = state == ElementState::Pressed;
                match button {
                    MouseButton::Left => self.drag.left = down,
                    MouseButton::Right | MouseButton::Middle => self.drag.right = down,
                    _ => {}
                }
                Ok(())
            }
            WindowEvent::CursorMoved { position, .. } => {
                self.cursor(position.x, position.y);
                Ok(())
            }
            WindowEvent::MouseWheel { delta, .. } => {
                let lines = match delta {
                    MouseScrollDelta::LineDelta(_, y) => y,
                    MouseScrollDelta::PixelDelta(p) => (p.y / 40.0) as f32,
                };
                if let Some(live) = self.live.as_mut() {
                    live.session.orbit.zoom(0.9f32.powf(lines));
                }
                Ok(())
            }
            _ => Ok(()),
        };
        if let Err(e) = r {
            self.fail(event_loop, e);
        }
    }
}
