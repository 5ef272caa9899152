//! The window's panel (egui): the frame's GPU and CPU times, the lights shadowed and skipped and
//! why, the reference refined in the background and the frame's error against it, and the
//! controls the keys also reach. Drawn over the view after the display pass, into the same
//! encoder.

use super::display::{DIFFERENCE_SCALE, Shown};
use super::reference::Progress;
use super::stage::ViewTechnique;
use gpu::Gpu;
use winit::window::Window;

/// egui's state beside the window: its context, its input and its renderer.
pub(crate) struct Panel {
    state: egui_winit::State,
    renderer: egui_wgpu::Renderer,
    /// Shown (`H` hides it).
    pub visible: bool,
}

/// What the panel shows of a frame.
pub(crate) struct Facts<'a> {
    pub adapter: &'a str,
    pub size: (u32, u32),
    pub gpu_ms: Option<f64>,
    pub cpu_ms: Option<f64>,
    pub frame_ms: Option<f64>,
    pub technique: ViewTechnique,
    pub lights: usize,
    pub shadowed: usize,
    pub skipped: &'a [(String, usize)],
    pub turn_degrees: f32,
    pub scene: &'a str,
    pub triangles: usize,
    /// The reference of the view shown (`None`: the view is moving, or none yet).
    pub reference: Option<&'a Progress>,
    /// The frame shown (its id: view, technique and lights).
    pub frame: u64,
    /// The view is still (a reference is being made, or will be).
    pub still: bool,
    pub message: Option<&'a str>,
    /// What the display shows.
    pub shown: Shown,
}

/// What the panel's controls asked for.
#[derive(Default)]
pub(crate) struct Asked {
    pub technique: Option<ViewTechnique>,
    pub lights: Option<usize>,
    pub shown: Option<Shown>,
}

impl Panel {
    pub(crate) fn new(gpu: &Gpu, window: &Window, format: wgpu::TextureFormat) -> Self {
        let ctx = egui::Context::default();
        let max_side = gpu.device.limits().max_texture_dimension_2d as usize;
        let state = egui_winit::State::new(
            ctx,
            egui::ViewportId::ROOT,
            window,
            Some(window.scale_factor() as f32),
            None,
            Some(max_side),
        );
        let renderer = egui_wgpu::Renderer::new(&gpu.device, format, egui_wgpu::RendererOptions::default());
        Self { state, renderer, visible: true }
    }

    /// Hands a window event to egui; true when egui used it (a click on the panel, say), so the
    /// view should not.
    pub(crate) fn on_event(&mut self, window: &Window, event: &winit::event::WindowEvent) -> bool {
        self.visible && self.state.on_window_event(window, event).consumed
    }

    /// Records the panel over `target` (the window's image, already drawn) and returns what its
    /// controls asked for.
    pub(crate) fn record(
        &mut self,
        gpu: &Gpu,
        encoder: &mut wgpu::CommandEncoder,
        window: &Window,
        target: &wgpu::TextureView,
        size: (u32, u32),
        facts: &Facts<'_>,
    ) -> Asked {
        let mut asked = Asked::default();
        if !self.visible {
            return asked;
        }
        let input = self.state.take_egui_input(window);
        let ctx = self.state.egui_ctx().clone();
        let output = ctx.run_ui(input, |ui| {
            egui::Window::new("envshadow")
                .default_pos([8.0, 8.0])
                .default_width(340.0)
                .resizable(false)
                .show(ui.ctx(), |ui| contents(ui, facts, &mut asked));
        });
        self.state.handle_platform_output(window, output.platform_output);
        let pixels_per_point = output.pixels_per_point;
        let primitives = ctx.tessellate(output.shapes, pixels_per_point);
        // egui checks that every delta was taken
        let mut textures = output.textures_delta;
        for (id, deltas) in textures.set.drain() {
            for delta in &deltas {
                self.renderer.update_texture(&gpu.device, &gpu.queue, id, delta);
            }
        }
        let screen = egui_wgpu::ScreenDescriptor { size_in_pixels: [size.0, size.1], pixels_per_point };
        let extra = self.renderer.update_buffers(&gpu.device, &gpu.queue, encoder, &primitives, &screen);
        if !extra.is_empty() {
            gpu.queue.submit(extra);
        }
        {
            let pass = encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
                label: Some("panel"),
                color_attachments: &[Some(wgpu::RenderPassColorAttachment {
                    view: target,
                    depth_slice: None,
                    resolve_target: None,
                    ops: wgpu::Operations { load: wgpu::LoadOp::Load, store: wgpu::StoreOp::Store },
                })],
                ..Default::default()
            });
            self.renderer.render(&mut pass.forget_lifetime(), &primitives, &screen);
        }
        for id in textures.free.drain() {
            self.renderer.free_texture(&id);
        }
        asked
    }
}

fn ms(v: Option<f64>) -> String {
    v.map_or("-".into(), |v| format!("{v:.1} ms"))
}

fn contents(ui: &mut egui::Ui, f: &Facts<'_>, asked: &mut Asked) {
    let shown = f.shown;
    ui.label(format!("{} ({} triangles)", f.scene, f.triangles));
    ui.label(format!("{}x{} on {}", f.size.0, f.size.1, f.adapter));
    ui.label(format!("frame: GPU {}, CPU {}, every {}", ms(f.gpu_ms), ms(f.cpu_ms), ms(f.frame_ms)));
    ui.separator();
    ui.horizontal(|ui| {
        ui.label("shadows");
        for t in ViewTechnique::ALL {
            if ui.selectable_label(t == f.technique, t.name()).clicked() && t != f.technique {
                asked.technique = Some(t);
            }
        }
    });
    ui.horizontal(|ui| {
        ui.label(format!("lights {}", f.lights));
        if ui.button("-").clicked() {
            asked.lights = Some((f.lights / 2).max(1));
        }
        if ui.button("+").clicked() {
            asked.lights = Some((f.lights * 2).min(super::MAX_LIGHTS));
        }
        ui.label(format!("map turned {:.0} deg", f.turn_degrees));
    });
    ui.label(format!("shadowed: {} of {}", f.shadowed, f.lights));
    for (why, n) in f.skipped {
        ui.label(format!("skipped {n}: {why}"));
    }
    ui.separator();
    match f.reference {
        Some(p) => {
            ui.label(format!("reference: {} spp in {:.1} s, its noise RMSE {:.4}", p.spp, p.seconds, p.noise));
            match p.error.filter(|e| e.frame == f.frame) {
                Some(e) => {
                    ui.label(format!(
                        "frame against it: RMSE {:.4} ({:.4} without its noise), FLIP {:.4}",
                        e.rmse, e.rmse_truth, e.flip
                    ));
                    ui.label(match e.passed {
                        Some((s, spp)) => format!("the reference passed the frame's error after {s:.1} s ({spp} spp)"),
                        None => "the reference is still noisier than the frame's error".into(),
                    });
                }
                None => {
                    ui.label("measuring the frame...");
                }
            }
        }
        None if f.still => {
            ui.label("reference: starting (the view is still)");
        }
        None => {
            ui.label("reference: waits for the view to stay still");
        }
    }
    ui.horizontal(|ui| {
        ui.label("show");
        for s in Shown::ALL {
            if ui.selectable_label(s == shown, s.name()).clicked() && s != shown {
                asked.shown = Some(s);
            }
        }
    });
    if shown == Shown::Difference {
        ui.label(format!("red: the frame brighter, blue: darker; full at {DIFFERENCE_SCALE} of the display's range"));
    }
    if let Some(m) = f.message {
        ui.separator();
        ui.colored_label(egui::Color32::from_rgb(255, 160, 80), m);
    }
    ui.separator();
    ui.weak("drag: orbit; right drag: pan; wheel: zoom; ctrl drag or arrows: move the object");
    ui.weak("T technique, +/- lights, Q/E turn the map, R frame/reference/difference, H panel, P screenshot");
}
