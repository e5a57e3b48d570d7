//! The winit window: surface set-up, the frame loop (simulate → panel → 3D
//! render → egui on top → present), camera input, resize/minimise/close,
//! surface loss, and the `--screenshot` capture of the whole window.

use std::collections::HashSet;
use std::path::PathBuf;
use std::sync::Arc;
use std::time::Instant;

use winit::application::ApplicationHandler;
use winit::dpi::{LogicalSize, PhysicalPosition};
use winit::event::{ElementState, MouseButton, MouseScrollDelta, WindowEvent};
use winit::event_loop::{ActiveEventLoop, ControlFlow, EventLoop};
use winit::keyboard::{KeyCode, PhysicalKey};
use winit::window::{Window, WindowId};

use super::draw::{draw_frame, read_back, view3d_rect};
use super::ellipsoid_mouse;
use super::panel::{self, PanelState};
use super::state::{FIXED_FRAME_DT_S, Model};
use crate::error::{Error, Result};
use crate::render::renderer::texture_2d;
use crate::render::{FrameInput, GpuContext, Renderer};

/// What `cumulus watch` was asked to do.
#[derive(Debug, Clone)]
pub struct WatchOptions {
    /// Scene profile; None = the embedded default.
    pub scene: Option<PathBuf>,
    /// Capture the whole window at the last frame, write this PNG and exit.
    pub screenshot: Option<PathBuf>,
    /// Frames to run before exiting; None = until closed (10 with a
    /// screenshot). Counted frames use a fixed time step.
    pub frames: Option<u32>,
    /// Simulated time of the first frame (pre-simulated); None = the
    /// scene's `[simulation] start_s`. Reset returns to it. units: s
    pub warmup_s: Option<f64>,
    /// Inner window size. units: logical pixels
    pub size: (u32, u32),
    /// Render method overriding the scene's `[render] method`.
    pub method: Option<crate::config::RenderMethod>,
    /// `--set TABLE.KEY=VALUE` scene overrides (see `crate::scene::set`).
    pub set: Vec<String>,
    /// Destroy the GPU device (`wgpu::Device::destroy`) after this frame,
    /// so the device-loss recovery runs (a test hook: real losses come from
    /// drivers, which a CPU adapter never resets).
    pub lose_device_after: Option<u32>,
}

impl Default for WatchOptions {
    fn default() -> Self {
        Self {
            scene: None,
            screenshot: None,
            frames: None,
            warmup_s: None,
            size: (1280, 760),
            method: None,
            set: Vec::new(),
            lose_device_after: None,
        }
    }
}

/// Opens the window and runs until it is closed (or the screenshot is written).
pub fn run(mut opts: WatchOptions) -> Result<()> {
    if opts.screenshot.is_some() && opts.frames.is_none() {
        opts.frames = Some(10);
    }
    let (profile, source) = crate::scene::load_scene_with(opts.scene.as_deref(), &opts.set)?;
    let mut model = Model::new(profile, source)?;
    if let Some(m) = opts.method {
        model.render_cfg.method = m;
    }
    if let Some(s) = opts.warmup_s {
        model.start_s = s;
    }
    if opts.frames.is_some() {
        // Counted frames (captures): the whole pre-simulation first, with a
        // progress bar on the terminal, so the frames do not depend on speed.
        super::progress::warm_up_with_bar(&mut model);
    } else {
        // Live: the window opens at once and shows the pre-simulation's progress.
        model.begin_warm_up();
    }
    let event_loop = EventLoop::new()
        .map_err(|e| Error::Gpu(format!("cannot open a window (is DISPLAY set?): {e}")))?;
    event_loop.set_control_flow(ControlFlow::Poll);
    let mut app = App {
        opts,
        model,
        panel: PanelState::default(),
        egui_ctx: panel::egui_context(),
        gfx: None,
        input: Input::default(),
        frame: 0,
        last_frame: Instant::now(),
        error: None,
    };
    event_loop
        .run_app(&mut app)
        .map_err(|e| Error::Gpu(format!("window event loop: {e}")))?;
    match app.error {
        Some(e) => Err(e),
        None => Ok(()),
    }
}

/// Camera input state.
#[derive(Default)]
struct Input {
    /// Button held for a camera drag that started outside the panel.
    dragging: Option<MouseButton>,
    cursor: Option<PhysicalPosition<f64>>,
    keys: HashSet<KeyCode>,
    /// An ellipsoid being dragged (slices method; see `ellipsoid_mouse`).
    ellipsoid: Option<ellipsoid_mouse::Drag>,
}

pub(super) struct Gfx {
    pub(super) window: Arc<Window>,
    pub(super) surface: wgpu::Surface<'static>,
    pub(super) ctx: GpuContext,
    pub(super) renderer: Renderer,
    pub(super) config: wgpu::SurfaceConfiguration,
    /// The surface takes copies (COPY_DST): the 3D view is rendered beside
    /// the panel and copied in. Otherwise it fills the window under the panel.
    pub(super) split: bool,
    /// Offscreen target of the 3D view when split, sized to it.
    pub(super) view3d: Option<(wgpu::Texture, wgpu::TextureView)>,
    pub(super) egui_state: egui_winit::State,
    pub(super) egui_renderer: egui_wgpu::Renderer,
    /// Set by the device-lost callback: why the device was lost.
    pub(super) lost: Arc<std::sync::Mutex<Option<String>>>,
}

struct App {
    opts: WatchOptions,
    model: Model,
    panel: PanelState,
    egui_ctx: egui::Context,
    gfx: Option<Gfx>,
    input: Input,
    frame: u32,
    last_frame: Instant,
    error: Option<Error>,
}

impl App {
    fn fail(&mut self, event_loop: &ActiveEventLoop, e: Error) {
        self.error = Some(e);
        event_loop.exit();
    }

    fn init(&mut self, event_loop: &ActiveEventLoop) -> Result<()> {
        let (w, h) = self.opts.size;
        let attrs = Window::default_attributes()
            .with_title(self.model.title())
            .with_inner_size(LogicalSize::new(w, h));
        let window = Arc::new(
            event_loop
                .create_window(attrs)
                .map_err(|e| Error::Gpu(format!("cannot create the window: {e}")))?,
        );
        self.gfx = Some(self.make_gfx(window)?);
        Ok(())
    }

    /// Opens a device for `window` and everything drawn with it (also after
    /// the device was lost).
    fn make_gfx(&mut self, window: Arc<Window>) -> Result<Gfx> {
        let instance = GpuContext::new_instance(Box::new(window.clone()));
        let surface = instance
            .create_surface(window.clone())
            .map_err(|e| Error::Gpu(format!("cannot create a surface for the window: {e}")))?;
        let ctx = GpuContext::new_for_surface(instance, &surface)?;
        let adapter = &ctx.adapter;
        let device = &ctx.device;
        eprintln!("GPU: {}", ctx.describe());
        self.model.stats.adapter = ctx.describe();
        let size = window.inner_size();
        let caps = surface.get_capabilities(adapter);
        // egui paints in gamma space and expects a non-sRGB target.
        let format = caps
            .formats
            .iter()
            .copied()
            .find(|f| !f.is_srgb())
            .or(caps.formats.first().copied())
            .ok_or_else(|| Error::Gpu("the surface supports no format".into()))?;
        let split = caps.usages.contains(wgpu::TextureUsages::COPY_DST);
        let usage = if split {
            wgpu::TextureUsages::RENDER_ATTACHMENT | wgpu::TextureUsages::COPY_DST
        } else {
            wgpu::TextureUsages::RENDER_ATTACHMENT
        };
        let config = wgpu::SurfaceConfiguration {
            usage,
            format,
            color_space: wgpu::SurfaceColorSpace::Auto,
            width: size.width.max(1),
            height: size.height.max(1),
            present_mode: wgpu::PresentMode::AutoVsync,
            desired_maximum_frame_latency: 2,
            alpha_mode: caps.alpha_modes[0],
            view_formats: vec![],
        };
        if size.width > 0 && size.height > 0 {
            surface.configure(device, &config);
        }
        let (_, w3d, h3d) = view3d_rect(split, &window, config.width, config.height);
        // The scene's method when this adapter can draw it; else, unless the
        // user asked for it, the first that can, said in the panel.
        let (method, note) = crate::render::renderer::method_for(
            &ctx,
            &self.model.resolved_render_config(),
            self.opts.method.is_some(),
        );
        if let Some(note) = note {
            eprintln!("{note}");
            self.model.status = note;
            self.model.render_cfg.method = method;
        }
        let mut renderer =
            Renderer::new(&ctx, &self.model.resolved_render_config(), format, w3d, h3d)?;
        // Never wait for the GPU to read the timings back: the panel shows
        // the latest finished frame's.
        renderer.set_timing_mode(crate::render::TimingMode::GpuLagged);
        // The scene's own sprite clouds, drawn under every method.
        renderer.set_sprite_clouds(&ctx, self.model.profile.build_sprite_clouds())?;
        // Live, the pipelines of every setting one click away are built in
        // the background, so a toggle in the panel does not stop a frame for
        // a compile; counted captures (`--frames`) change no setting.
        renderer.set_prebuild(&ctx, self.opts.frames.is_none())?;
        let egui_state = egui_winit::State::new(
            self.egui_ctx.clone(),
            egui::ViewportId::ROOT,
            &window,
            Some(window.scale_factor() as f32),
            None,
            Some(device.limits().max_texture_dimension_2d as usize),
        );
        let egui_renderer =
            egui_wgpu::Renderer::new(device, format, egui_wgpu::RendererOptions::default());
        // Device loss (driver reset, GPU removed) is reported here and
        // handled in `frame`: a message in the panel and a new device.
        let lost = Arc::new(std::sync::Mutex::new(None));
        let flag = lost.clone();
        device.set_device_lost_callback(move |reason, msg| {
            *flag.lock().unwrap_or_else(|e| e.into_inner()) = Some(format!("{reason:?}: {msg}"));
        });
        Ok(Gfx {
            window,
            surface,
            ctx,
            renderer,
            config,
            split,
            view3d: None,
            egui_state,
            egui_renderer,
            lost,
        })
    }

    /// After a device loss: says so in the panel and rebuilds the device,
    /// renderer and panel painter for the same window.
    fn recover_lost_device(&mut self) -> Result<()> {
        let Some(g) = &self.gfx else { return Ok(()) };
        let Some(reason) = g.lost.lock().unwrap_or_else(|e| e.into_inner()).take() else {
            return Ok(());
        };
        let window = g.window.clone();
        self.gfx = None;
        // A fresh egui context re-sends its font atlas to the new painter.
        self.egui_ctx = panel::egui_context();
        self.gfx = Some(self.make_gfx(window)?);
        self.model.status = format!("GPU device lost ({reason}); recreated it");
        eprintln!("{}", self.model.status);
        Ok(())
    }

    fn resize(&mut self, w: u32, h: u32) -> Result<()> {
        let Some(g) = &mut self.gfx else {
            return Ok(());
        };
        g.config.width = w;
        g.config.height = h;
        // Minimised windows report zero size: keep the old configuration
        // and skip frames until the window comes back.
        if w > 0 && h > 0 {
            g.surface.configure(&g.ctx.device, &g.config);
            let (_, w3d, h3d) = view3d_rect(g.split, &g.window, w, h);
            g.renderer.resize(&g.ctx, w3d, h3d)?;
            g.view3d = None;
        }
        Ok(())
    }

    /// Moves the camera by the keys held this frame.
    fn fly(&mut self, dt_s: f32) {
        let k = &self.input.keys;
        let axis = |pos: KeyCode, neg: KeyCode| k.contains(&pos) as i32 - k.contains(&neg) as i32;
        let (f, r, u) = (
            axis(KeyCode::KeyW, KeyCode::KeyS),
            axis(KeyCode::KeyD, KeyCode::KeyA),
            axis(KeyCode::KeyE, KeyCode::KeyQ),
        );
        if (f, r, u) != (0, 0, 0) {
            // Speed scales with the view distance so both close-ups and the
            // whole landscape are quick to cross.
            let speed = 0.5 * self.model.camera.distance_m * dt_s;
            self.model
                .camera
                .fly(f as f32 * speed, r as f32 * speed, u as f32 * speed);
        }
    }

    /// One frame. Returns Ok(true) when the app should exit.
    fn frame(&mut self) -> Result<bool> {
        self.recover_lost_device()?;
        let now = Instant::now();
        let real_dt = now - self.last_frame;
        self.last_frame = now;
        // Counted frames advance by a fixed step, so a capture is reproducible.
        let dt_s = if self.opts.frames.is_some() {
            FIXED_FRAME_DT_S
        } else {
            real_dt.as_secs_f64()
        };
        self.fly(dt_s as f32);
        self.model.advance(dt_s);

        let Some(g) = &mut self.gfx else {
            return Ok(false);
        };
        if g.config.width == 0 || g.config.height == 0 {
            return Ok(false);
        }
        let raw = g.egui_state.take_egui_input(&g.window);
        let model = &mut self.model;
        let panel_state = &mut self.panel;
        let mut actions = panel::PanelActions::default();
        let rect = view3d_rect(g.split, &g.window, g.config.width, g.config.height);
        let out = self.egui_ctx.run_ui(raw, |ui| {
            actions = panel::show(ui, model, panel_state);
            ellipsoid_mouse::paint_outlines(ui.ctx(), model, rect, panel_state.selected_ellipsoid);
            super::progress::warm_up_overlay(ui.ctx(), model, rect);
        });
        if actions.render_changed {
            // Only what the changed settings need is rebuilt (Renderer::set_config).
            // Settings this adapter cannot draw (a method it lacks a
            // feature for) are refused in the panel; the frame goes on with
            // the renderer's current settings.
            if let Err(e) = g
                .renderer
                .set_config(&g.ctx, &self.model.resolved_render_config())
            {
                self.model.status = format!("settings not applied: {e}");
            }
        }
        // The authored ellipsoids as the panel left them (slices method).
        g.renderer.set_authored(
            &self.model.profile.ellipsoids,
            &self.model.profile.particles,
        );
        let mut input = FrameInput {
            camera: self.model.render_camera(),
            parcels: &self.model.parcels,
            sun: self.model.sun(),
            time_s: self.model.world.time_s() as f32,
        };
        // GPU errors outside every error scope since the last frame: shown
        // in the panel (and printed), the window keeps drawing.
        if let Some(e) = g.ctx.take_errors().pop() {
            self.model.status = format!("GPU error: {e}");
        }
        if let Err(e) = g.renderer.prepare(&g.ctx, &input) {
            // More cloud than the renderer's buffers hold: say so in the
            // panel and draw the frame without clouds rather than quit.
            self.model.status = format!("clouds not drawn: {e}");
            input.parcels = &[];
            g.renderer.prepare(&g.ctx, &input)?;
        }
        g.egui_state
            .handle_platform_output(&g.window, out.platform_output);
        let jobs = self.egui_ctx.tessellate(out.shapes, out.pixels_per_point);
        let screen = egui_wgpu::ScreenDescriptor {
            size_in_pixels: [g.config.width, g.config.height],
            pixels_per_point: out.pixels_per_point,
        };
        for (id, deltas) in &out.textures_delta.set {
            for delta in deltas {
                g.egui_renderer
                    .update_texture(&g.ctx.device, &g.ctx.queue, *id, delta);
            }
        }

        self.frame += 1;
        let last = self.opts.frames.is_some_and(|n| self.frame >= n);
        let capture_now = last && self.opts.screenshot.is_some();
        let mut encoder = g
            .ctx
            .device
            .create_command_encoder(&wgpu::CommandEncoderDescriptor {
                label: Some("frame"),
            });
        let user_cmds = g.egui_renderer.update_buffers(
            &g.ctx.device,
            &g.ctx.queue,
            &mut encoder,
            &jobs,
            &screen,
        );

        let result = if capture_now {
            let path = self.opts.screenshot.clone().expect("capture set");
            let tex = texture_2d(
                &g.ctx.device,
                "screenshot",
                g.config.width,
                g.config.height,
                g.config.format,
                wgpu::TextureUsages::RENDER_ATTACHMENT
                    | wgpu::TextureUsages::COPY_SRC
                    | wgpu::TextureUsages::COPY_DST,
            );
            let view = tex.create_view(&Default::default());
            let timings = draw_frame(g, &mut encoder, &tex, &view, &jobs, &screen);
            record(&mut self.model, timings, &g.renderer);
            let rgba = read_back(g, encoder, user_cmds, &tex)?;
            crate::output::write_png_atomic(&path, g.config.width, g.config.height, &rgba)?;
            // Where the 3D view is in the capture: tests compare it with
            // a headless frame of the same camera.
            let (x0, w3d, h3d) = view3d_rect(g.split, &g.window, g.config.width, g.config.height);
            eprintln!(
                "wrote {} ({}×{}; 3D view at x = {x0}, {w3d}×{h3d}; t = {:.6} s)",
                path.display(),
                g.config.width,
                g.config.height,
                self.model.world.time_s()
            );
            Ok(true)
        } else {
            let frame = match g.surface.get_current_texture() {
                wgpu::CurrentSurfaceTexture::Success(t)
                | wgpu::CurrentSurfaceTexture::Suboptimal(t) => t,
                wgpu::CurrentSurfaceTexture::Outdated => {
                    // The window changed under us: reconfigure and retry next frame.
                    g.surface.configure(&g.ctx.device, &g.config);
                    return Ok(false);
                }
                wgpu::CurrentSurfaceTexture::Lost => {
                    // The surface itself is gone (the device is not): make a
                    // new one for the same window and go on next frame.
                    g.surface = g
                        .ctx
                        .instance
                        .create_surface(g.window.clone())
                        .map_err(|e| {
                            Error::Gpu(format!("cannot recreate the lost surface: {e}"))
                        })?;
                    g.surface.configure(&g.ctx.device, &g.config);
                    return Ok(false);
                }
                wgpu::CurrentSurfaceTexture::Timeout | wgpu::CurrentSurfaceTexture::Occluded => {
                    return Ok(false);
                }
                other => {
                    return Err(Error::Gpu(format!(
                        "cannot get the window's next frame: {other:?}"
                    )));
                }
            };
            let view = frame.texture.create_view(&Default::default());
            let timings = draw_frame(g, &mut encoder, &frame.texture, &view, &jobs, &screen);
            record(&mut self.model, timings, &g.renderer);
            g.ctx
                .queue
                .submit(user_cmds.into_iter().chain([encoder.finish()]));
            g.window.pre_present_notify();
            g.ctx.queue.present(frame);
            Ok(last)
        };
        for id in &out.textures_delta.free {
            g.egui_renderer.free_texture(id);
        }
        self.model.stats.frame_ms = real_dt.as_secs_f64() * 1000.0;
        if self.opts.lose_device_after == Some(self.frame) {
            // Destroying the device reports it lost (reason Destroyed) once
            // its queue is idle: wait for that, so the next frame recovers.
            g.ctx.device.destroy();
            g.ctx.wait_idle();
        }
        result
    }
}

/// Keeps a frame's render timings for the panel.
fn record(m: &mut Model, t: crate::render::FrameTimings, renderer: &Renderer) {
    m.stats.upload_ms = t.upload_ms;
    m.stats.gpu_timestamps = t.gpu_timestamps;
    m.stats.passes = t.passes;
    m.stats.bake_note = (renderer.config().method == crate::config::RenderMethod::Baked)
        .then(|| renderer.bake_info().coarsening_note())
        .flatten();
}

impl ApplicationHandler for App {
    fn resumed(&mut self, event_loop: &ActiveEventLoop) {
        if self.gfx.is_none()
            && let Err(e) = self.init(event_loop)
        {
            self.fail(event_loop, e);
        }
    }

    fn window_event(&mut self, event_loop: &ActiveEventLoop, _id: WindowId, event: WindowEvent) {
        let Some(g) = &mut self.gfx else { return };
        let consumed = g.egui_state.on_window_event(&g.window, &event).consumed;
        let over_panel = self.egui_ctx.is_pointer_over_egui();
        match event {
            WindowEvent::CloseRequested => event_loop.exit(),
            WindowEvent::Resized(size) => {
                if let Err(e) = self.resize(size.width, size.height) {
                    self.fail(event_loop, e);
                }
            }
            WindowEvent::RedrawRequested => match self.frame() {
                Ok(true) => event_loop.exit(),
                Ok(false) => {}
                Err(e) => self.fail(event_loop, e),
            },
            WindowEvent::MouseInput { state, button, .. } => match state {
                ElementState::Pressed if !consumed && !over_panel => {
                    let rect = view3d_rect(g.split, &g.window, g.config.width, g.config.height);
                    let ray = self.input.cursor.and_then(|c| {
                        ellipsoid_mouse::cursor_ray(&self.model.render_camera(), rect, (c.x, c.y))
                    });
                    self.input.ellipsoid =
                        ray.filter(|_| button == MouseButton::Left).and_then(|ray| {
                            let selected = &mut self.panel.selected_ellipsoid;
                            ellipsoid_mouse::press(&self.model, ray, selected)
                        });
                    if self.input.ellipsoid.is_none() {
                        self.input.dragging = Some(button)
                    }
                }
                ElementState::Released if button == MouseButton::Left => {
                    self.input.ellipsoid = None;
                    if self.input.dragging == Some(button) {
                        self.input.dragging = None
                    }
                }
                ElementState::Released if self.input.dragging == Some(button) => {
                    self.input.dragging = None
                }
                _ => {}
            },
            WindowEvent::CursorMoved { position, .. } if self.input.ellipsoid.is_some() => {
                let rect = view3d_rect(g.split, &g.window, g.config.width, g.config.height);
                let camera = self.model.render_camera();
                if let (Some(d), Some(ray)) = (
                    self.input.ellipsoid.as_mut(),
                    ellipsoid_mouse::cursor_ray(&camera, rect, (position.x, position.y)),
                ) {
                    ellipsoid_mouse::drag(&mut self.model, d, &camera, ray);
                }
                self.input.cursor = Some(position);
            }
            WindowEvent::CursorMoved { position, .. } => {
                if let (Some(b), Some(last)) = (self.input.dragging, self.input.cursor) {
                    let (dx, dy) = ((position.x - last.x) as f32, (position.y - last.y) as f32);
                    match b {
                        MouseButton::Left => self.model.camera.orbit(dx, dy),
                        MouseButton::Right => self.model.camera.look(dx, dy),
                        _ => {}
                    }
                }
                self.input.cursor = Some(position);
            }
            WindowEvent::MouseWheel { delta, .. } if !consumed && !over_panel => {
                let steps = match delta {
                    MouseScrollDelta::LineDelta(_, y) => y,
                    MouseScrollDelta::PixelDelta(p) => p.y as f32 / 40.0,
                };
                let shift = [KeyCode::ShiftLeft, KeyCode::ShiftRight]
                    .iter()
                    .any(|k| self.input.keys.contains(k));
                let selected = self.panel.selected_ellipsoid;
                if !(shift && ellipsoid_mouse::resize(&mut self.model, selected, steps)) {
                    self.model.camera.zoom(steps);
                }
            }
            WindowEvent::KeyboardInput { event, .. } => {
                if let PhysicalKey::Code(code) = event.physical_key {
                    if event.state == ElementState::Released {
                        self.input.keys.remove(&code);
                    } else if !self.egui_ctx.egui_wants_keyboard_input() {
                        self.input.keys.insert(code);
                        match code {
                            KeyCode::KeyR => self.model.camera = self.model.default_camera,
                            KeyCode::Space if !event.repeat => {
                                self.model.playback.playing = !self.model.playback.playing
                            }
                            _ => {}
                        }
                    }
                }
            }
            WindowEvent::Focused(false) => self.input.keys.clear(),
            _ => {}
        }
    }

    fn about_to_wait(&mut self, _event_loop: &ActiveEventLoop) {
        if let Some(g) = &self.gfx {
            g.window.request_redraw();
        }
    }
}
