//! The viewer's window: winit events, the egui panel beside the 3D view (the renderer's
//! image shown as an egui texture), scripted input, screenshots and reports.

use crate::ViewOptions;
use crate::camera::Orbit;
use crate::overlay::{self, Overlays};
use crate::panel::{Action, panel};
use crate::script::{Command, Tool};
use crate::session::{SCRIPT_FRAME_S, Session, Stages, ms};
use anyhow::{Context, Result};
use glam::Vec3;
use std::path::Path;
use std::sync::Arc;
use std::time::Instant;
use sylva_core::scene::Scene;
use sylva_gpu::GpuContext;
use sylva_gpu::render::{Lighting, RenderSettings, Renderer};
use winit::application::ApplicationHandler;
use winit::event::WindowEvent;
use winit::event_loop::{ActiveEventLoop, ControlFlow, EventLoop};
use winit::window::{Window, WindowId};

/// The 3D view: the renderer at the view's size and its image registered with egui.
struct View {
    renderer: Renderer,
    texture: egui::TextureId,
    size: (u32, u32),
}

/// Everything that needs the window.
struct Gfx {
    window: Arc<Window>,
    surface: wgpu::Surface<'static>,
    config: wgpu::SurfaceConfiguration,
    egui: egui::Context,
    state: egui_winit::State,
    painter: egui_wgpu::Renderer,
    view: Option<View>,
}

struct App {
    args_size: (u32, u32),
    sim: Session,
    orbit: Orbit,
    gfx: Option<Gfx>,
    script: std::collections::VecDeque<Command>,
    wait_frames: u32,
    error: Option<anyhow::Error>,
    stages: Stages,
    last_frame: Instant,
    overlays: Overlays,
    status: String,
    /// Stage times summed since the last report, and the frames they cover.
    sums: Stages,
    summed: u32,
    push_from: Option<egui::Pos2>,
    /// GPU timers: simulation and meshing, drawing (with timestamp queries).
    timers: Option<(sylva_gpu::timer::GpuTimer, sylva_gpu::timer::GpuTimer)>,
}

/// Runs the viewer until the window closes or the script quits.
pub(crate) fn run(args: &ViewOptions, script: Vec<Command>) -> Result<()> {
    let (scene, path) = match &args.scene {
        Some(p) => (Scene::load(p)?, Some(p.clone())),
        None => (Scene::default_scene(), None),
    };
    let event_loop = EventLoop::new().map_err(|e| {
        anyhow::anyhow!("cannot open a window ({e}); `sylva render` renders the scene to files instead")
    })?;
    event_loop.set_control_flow(ControlFlow::Poll);
    let ctx = Arc::new(GpuContext::new(&Default::default())?);
    println!("GPU: {}", ctx.summary);
    let orbit = Orbit::from_scene(&scene);
    let timers = sylva_gpu::timer::GpuTimer::new(&ctx).zip(sylva_gpu::timer::GpuTimer::new(&ctx));
    let sim = Session::new(ctx, scene, path)?;
    let mut app = App {
        args_size: (args.width, args.height),
        sim,
        orbit,
        gfx: None,
        script: script.into(),
        wait_frames: 0,
        error: None,
        stages: Stages::default(),
        last_frame: Instant::now(),
        overlays: Overlays { wind: true, skeleton: false, clusters: false },
        status: String::new(),
        sums: Stages::default(),
        summed: 0,
        push_from: None,
        timers,
    };
    event_loop.run_app(&mut app).context("running the window")?;
    match app.error {
        Some(e) => Err(e),
        None => Ok(()),
    }
}

impl App {
    fn init(&mut self, event_loop: &ActiveEventLoop) -> Result<()> {
        let attrs = Window::default_attributes()
            .with_title("Sylva")
            .with_inner_size(winit::dpi::PhysicalSize::new(self.args_size.0, self.args_size.1));
        let window = Arc::new(event_loop.create_window(attrs).context("creating the window")?);
        let ctx = self.sim.ctx.clone();
        let instance = ctx.instance.as_ref().context("the GPU context has no instance to make a window surface")?;
        let surface = instance.create_surface(window.clone()).context("creating the window's surface")?;
        let caps = surface.get_capabilities(&ctx.adapter);
        if caps.formats.is_empty() {
            anyhow::bail!("the GPU adapter `{}` cannot present to this window", ctx.summary.name);
        }
        let format = egui_wgpu::preferred_framebuffer_format(&caps.formats).unwrap_or(caps.formats[0]);
        let size = window.inner_size();
        let config = wgpu::SurfaceConfiguration {
            usage: wgpu::TextureUsages::RENDER_ATTACHMENT,
            format,
            width: size.width.max(1),
            height: size.height.max(1),
            present_mode: wgpu::PresentMode::AutoVsync,
            desired_maximum_frame_latency: 2,
            alpha_mode: caps.alpha_modes[0],
            view_formats: vec![],
            color_space: wgpu::SurfaceColorSpace::Auto,
        };
        surface.configure(&ctx.device, &config);
        let egui = egui::Context::default();
        let state = egui_winit::State::new(
            egui.clone(),
            egui::ViewportId::ROOT,
            &window,
            Some(window.scale_factor() as f32),
            None,
            Some(ctx.device.limits().max_texture_dimension_2d as usize),
        );
        let painter = egui_wgpu::Renderer::new(&ctx.device, format, Default::default());
        self.gfx = Some(Gfx { window, surface, config, egui, state, painter, view: None });
        Ok(())
    }

    /// Runs the next scripted commands, up to a `frames` wait.
    fn run_script(&mut self, event_loop: &ActiveEventLoop) -> Result<()> {
        if self.wait_frames > 0 {
            self.wait_frames -= 1;
            return Ok(());
        }
        while let Some(cmd) = self.script.pop_front() {
            match cmd {
                Command::Frames(n) => {
                    self.wait_frames = n.saturating_sub(1);
                    if n > 0 {
                        return Ok(());
                    }
                }
                Command::Click(u, v) => {
                    let aspect = self.view_aspect();
                    if let Some(p) = self.orbit.ground_point(u, v, aspect) {
                        self.sim.place(p.x, p.z, self.sim.tool);
                    }
                }
                Command::Tool(t) => self.sim.tool = t,
                Command::Blast(x, z) => self.sim.place(x, z, Tool::Blast),
                Command::Wind(deg, speed) => self.sim.set_extra_wind(Some((deg, speed))),
                Command::Method(i, m) => {
                    let trees = self.sim.world.trees().len();
                    if i >= trees {
                        anyhow::bail!("script: `method {i}`: the scene has {trees} trees");
                    }
                    self.sim.world.registry().entry(&m).map_err(|e| anyhow::anyhow!("script: {e}"))?;
                    self.sim.rebuild(i, |st| st.method = sylva_core::scene::MethodName::new(m));
                }
                Command::OverwriteScene(src) => {
                    let dst = self.sim.path.clone().context("script: overwrite-scene needs a scene file")?;
                    let text = std::fs::read(&src).with_context(|| format!("reading {}", src.display()))?;
                    std::fs::write(&dst, text).with_context(|| format!("writing {}", dst.display()))?;
                    self.sim.poll_reload(true);
                }
                Command::Screenshot(p) => self.screenshot(&p)?,
                Command::Forest(i, n) => {
                    let trees = self.sim.world.trees().len();
                    if i >= trees {
                        anyhow::bail!("script: `forest {i}`: the scene has {trees} trees");
                    }
                    self.sim.set_forest(i, n);
                }
                Command::Report(p) => {
                    let mean = self.sums.scaled(1.0 / self.summed.max(1) as f64);
                    let json = serde_json::to_string_pretty(&self.sim.report(&mean, self.summed)?)?;
                    sylva_core::io::write_atomic(&p, |w| w.write_all(json.as_bytes()))
                        .with_context(|| format!("writing {}", p.display()))?;
                    (self.sums, self.summed) = (Stages::default(), 0);
                }
                Command::Quit => {
                    event_loop.exit();
                    return Ok(());
                }
            }
        }
        Ok(())
    }

    fn view_aspect(&self) -> f32 {
        match self.gfx.as_ref().and_then(|g| g.view.as_ref()) {
            Some(v) => v.size.0 as f32 / v.size.1.max(1) as f32,
            None => self.args_size.0 as f32 / self.args_size.1.max(1) as f32,
        }
    }

    fn screenshot(&self, path: &Path) -> Result<()> {
        let view = self.gfx.as_ref().and_then(|g| g.view.as_ref()).context("screenshot: no frame drawn yet")?;
        let ctx = &self.sim.ctx;
        let rgba = view.renderer.read_image(ctx, ctx.device.create_command_encoder(&Default::default()))?;
        let img = image::RgbaImage::from_raw(view.size.0, view.size.1, rgba).context("image size")?;
        let mut png = Vec::new();
        img.write_to(&mut std::io::Cursor::new(&mut png), image::ImageFormat::Png)?;
        sylva_core::io::write_atomic(path, |w| w.write_all(&png)).with_context(|| format!("writing {}", path.display()))
    }

    /// One frame: script, reload check, simulation, 3D view, panel, present.
    fn frame(&mut self, event_loop: &ActiveEventLoop) -> Result<()> {
        let frame_start = Instant::now();
        let wall = frame_start.duration_since(self.last_frame).as_secs_f32().min(0.1);
        self.last_frame = frame_start;
        self.run_script(event_loop)?;
        self.sim.poll_reload(false);
        let scripted = !self.script.is_empty() || self.wait_frames > 0;
        let seconds = if self.sim.paused && !self.sim.step_once {
            0.0
        } else if self.sim.step_once {
            self.sim.step_once = false;
            self.sim.world.dt()
        } else if scripted {
            SCRIPT_FRAME_S * self.sim.time_scale
        } else {
            wall * self.sim.time_scale
        };
        let ctx = self.sim.ctx.clone();
        let ctx = &*ctx;
        // Simulation and meshing go in a submission of their own between the timer's stamps:
        // submissions complete in order, while passes inside one encoder may overlap a
        // stamp (lavapipe runs compute asynchronously up to the next barrier).
        let mut encoder = ctx.device.create_command_encoder(&Default::default());
        let sim_ms = self.sim.advance(seconds, &mut encoder)?;
        if let Some((t, _)) = &self.timers {
            t.start(ctx);
        }
        ctx.submit([encoder.finish()]);
        if let Some((t, _)) = &self.timers {
            t.stop(ctx);
        }
        let mut encoder = ctx.device.create_command_encoder(&Default::default());
        self.sim.frames += 1;

        let Some(gfx) = &mut self.gfx else { return Ok(()) };
        // The panel first: it decides the 3D view's size.
        let raw = gfx.state.take_egui_input(&gfx.window);
        let ui_start = Instant::now();
        let mut actions = Vec::new();
        let mut view_rect = egui::Rect::NOTHING;
        let texture = gfx.view.as_ref().map(|v| (v.texture, v.size));
        let stages = self.stages;
        let mut overlays = self.overlays;
        let tool = self.sim.tool;
        let output = gfx.egui.run_ui(raw, |ui| {
            egui::Panel::left("panel").resizable(true).default_size(300.0).show(ui, |ui| {
                egui::ScrollArea::vertical().show(ui, |ui| {
                    panel(ui, &mut self.sim, &mut self.orbit, &stages, &mut overlays, &self.status, &mut actions);
                });
            });
            egui::CentralPanel::default().frame(egui::Frame::NONE).show(ui, |ui| {
                view_rect = ui.max_rect();
                let response = ui.allocate_rect(view_rect, egui::Sense::click_and_drag());
                if let Some((id, _)) = texture {
                    let uv = egui::Rect::from_min_max(egui::pos2(0.0, 0.0), egui::pos2(1.0, 1.0));
                    ui.painter().image(id, view_rect, uv, egui::Color32::WHITE);
                }
                interact(ui, &response, view_rect, tool, &mut self.push_from, &mut self.orbit, &mut actions);
                overlay::draw(ui, view_rect, &self.sim, &self.orbit, &stages, overlays);
            });
        });
        let ui_ms = ms(ui_start.elapsed());
        self.overlays = overlays;
        for a in actions {
            match a {
                Action::Place(u, v) => {
                    let aspect = view_rect.width() / view_rect.height().max(1.0);
                    if let Some(p) = self.orbit.ground_point(u, v, aspect) {
                        self.sim.place(p.x, p.z, self.sim.tool);
                    }
                }
                Action::Push(a, b) => {
                    let aspect = view_rect.width() / view_rect.height().max(1.0);
                    let ground = |(u, v): (f32, f32)| self.orbit.ground_point(u, v, aspect);
                    if let (Some(a), Some(b)) = (ground(a), ground(b)) {
                        self.sim.push(a, b);
                    }
                }
                Action::Save => {
                    self.status = match self.sim.save() {
                        Ok(p) => format!("saved {}", p.display()),
                        Err(e) => format!("save failed: {e:#}"),
                    };
                }
            }
        }
        // The 3D view at the panel's size in pixels.
        let ppp = output.pixels_per_point;
        let want =
            ((view_rect.width() * ppp).round().max(16.0) as u32, (view_rect.height() * ppp).round().max(16.0) as u32);
        if gfx.view.as_ref().is_none_or(|v| v.size != want) {
            let renderer = Renderer::new(
                ctx,
                RenderSettings {
                    width: want.0,
                    height: want.1,
                    msaa: self.sim.world.scene().output.msaa,
                    ..Default::default()
                },
            )?;
            if let Some(old) = gfx.view.take() {
                gfx.painter.free_texture(&old.texture);
            }
            let texture =
                gfx.painter.register_native_texture(&ctx.device, &renderer.image_view(), wgpu::FilterMode::Linear);
            gfx.view = Some(View { renderer, texture, size: want });
        }
        let draw_start = Instant::now();
        let view = gfx.view.as_ref().expect("made above");
        let light = Lighting {
            sun_direction: Vec3::from_array(self.sim.world.scene().sun.direction).normalize(),
            sun_intensity: self.sim.world.scene().sun.intensity,
            ..Default::default()
        };
        let globals = view.renderer.globals(&self.orbit.camera(), &light, self.sim.world.bounds());
        let items = self.sim.world.draw_items();
        if let Some((_, t)) = &self.timers {
            t.begin(&mut encoder);
        }
        view.renderer.record(ctx, &mut encoder, &globals, &items);
        if let Some((_, t)) = &self.timers {
            t.end(&mut encoder);
        }
        drop(items);
        gfx.state.handle_platform_output(&gfx.window, output.platform_output);
        // Texture changes are applied every frame, presented or not (egui insists); frees
        // come after the frame's paint.
        let mut textures = output.textures_delta;
        for (id, deltas) in &textures.set {
            for delta in deltas {
                gfx.painter.update_texture(&ctx.device, &ctx.queue, *id, delta);
            }
        }
        let frame = match gfx.surface.get_current_texture() {
            wgpu::CurrentSurfaceTexture::Success(f) | wgpu::CurrentSurfaceTexture::Suboptimal(f) => Some(f),
            // Lost or outdated (a resize): reconfigure and present the next frame.
            _ => {
                gfx.surface.configure(&ctx.device, &gfx.config);
                None
            }
        };
        match frame {
            Some(frame) => {
                let target = frame.texture.create_view(&Default::default());
                let screen = egui_wgpu::ScreenDescriptor {
                    size_in_pixels: [gfx.config.width, gfx.config.height],
                    pixels_per_point: ppp,
                };
                let prims = gfx.egui.tessellate(output.shapes, ppp);
                let extra = gfx.painter.update_buffers(&ctx.device, &ctx.queue, &mut encoder, &prims, &screen);
                {
                    let pass = encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
                        label: Some("egui"),
                        color_attachments: &[Some(wgpu::RenderPassColorAttachment {
                            view: &target,
                            depth_slice: None,
                            resolve_target: None,
                            ops: wgpu::Operations {
                                load: wgpu::LoadOp::Clear(wgpu::Color::BLACK),
                                store: wgpu::StoreOp::Store,
                            },
                        })],
                        depth_stencil_attachment: None,
                        timestamp_writes: None,
                        occlusion_query_set: None,
                        multiview_mask: None,
                    });
                    gfx.painter.render(&mut pass.forget_lifetime(), &prims, &screen);
                }
                ctx.submit(extra.into_iter().chain([encoder.finish()]));
                ctx.queue.present(frame);
            }
            None => {
                ctx.submit([encoder.finish()]);
            }
        }
        for id in &textures.free {
            gfx.painter.free_texture(id);
        }
        textures.clear();
        let (gpu_mesh, gpu_draw) = match &self.timers {
            Some((m, d)) => (m.read(ctx)?.map_or(0.0, ms), d.read(ctx)?.map_or(0.0, ms)),
            None => (0.0, 0.0),
        };
        self.stages = Stages {
            simulate: sim_ms,
            gpu_mesh,
            gpu_draw,
            draw: ms(draw_start.elapsed()),
            ui: ui_ms,
            frame: ms(frame_start.elapsed()),
        };
        self.sums.add(&self.stages);
        self.summed += 1;
        Ok(())
    }
}

/// Orbit (left drag), pan (right or middle drag), zoom (scroll), place (left click).
fn interact(
    ui: &egui::Ui,
    r: &egui::Response,
    rect: egui::Rect,
    tool: Tool,
    push_from: &mut Option<egui::Pos2>,
    orbit: &mut Orbit,
    actions: &mut Vec<Action>,
) {
    let d = r.drag_delta();
    let uv = |p: egui::Pos2| ((p.x - rect.left()) / rect.width(), (p.y - rect.top()) / rect.height());
    if tool == Tool::Push && r.dragged_by(egui::PointerButton::Primary) {
        if r.drag_started() {
            *push_from = r.interact_pointer_pos();
        }
    } else if r.dragged_by(egui::PointerButton::Primary) {
        orbit.yaw -= d.x * 0.008;
        orbit.pitch = (orbit.pitch + d.y * 0.008).clamp(-0.1, 1.5);
    } else if r.dragged_by(egui::PointerButton::Secondary) || r.dragged_by(egui::PointerButton::Middle) {
        let cam = orbit.camera();
        let forward = (cam.target - cam.eye).normalize_or_zero();
        let right = forward.cross(Vec3::Y).normalize_or_zero();
        let up = right.cross(forward);
        let scale = orbit.distance * 0.0015;
        orbit.target += (-right * d.x + up * d.y) * scale;
    }
    if r.hovered() {
        let scroll = ui.input(|i| i.smooth_scroll_delta.y);
        if scroll != 0.0 {
            orbit.distance = (orbit.distance * (-scroll * 0.002).exp()).clamp(0.5, 2_000.0);
        }
    }
    if r.drag_stopped()
        && let (Some(a), Some(b)) = (push_from.take(), r.interact_pointer_pos())
    {
        actions.push(Action::Push(uv(a), uv(b)));
    }
    if r.clicked()
        && let Some(p) = r.interact_pointer_pos()
    {
        let (u, v) = uv(p);
        actions.push(Action::Place(u, v));
    }
}

impl ApplicationHandler for App {
    fn resumed(&mut self, event_loop: &ActiveEventLoop) {
        if self.gfx.is_none()
            && let Err(e) = self.init(event_loop)
        {
            self.error = Some(e);
            event_loop.exit();
        }
    }

    fn window_event(&mut self, event_loop: &ActiveEventLoop, _: WindowId, event: WindowEvent) {
        let Some(gfx) = &mut self.gfx else { return };
        // Every input goes to egui; the 3D view reads its drags and clicks from there.
        let _ = gfx.state.on_window_event(&gfx.window, &event);
        match event {
            WindowEvent::CloseRequested => event_loop.exit(),
            WindowEvent::Resized(size) => {
                gfx.config.width = size.width.max(1);
                gfx.config.height = size.height.max(1);
                gfx.surface.configure(&self.sim.ctx.device, &gfx.config);
            }
            WindowEvent::RedrawRequested => {
                if let Err(e) = self.frame(event_loop) {
                    self.error = Some(e);
                    event_loop.exit();
                }
            }
            _ => {}
        }
    }

    fn about_to_wait(&mut self, _: &ActiveEventLoop) {
        if let Some(gfx) = &self.gfx {
            gfx.window.request_redraw();
        }
    }
}
