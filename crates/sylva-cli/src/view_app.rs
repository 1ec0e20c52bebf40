//! The viewer's window: winit events, the egui panel, the 3D view (the renderer's image shown
//! as an egui texture) and the simulation it drives ([`Sim`]). See [`crate::view_cmd`].

use crate::bench_cmd::write_atomic;
use crate::scene_runtime::Entry;
use crate::view_cmd::{Command, Tool, ViewArgs};
use anyhow::{Context, Result};
use glam::{Mat4, Vec3, Vec4};
use std::path::{Path, PathBuf};
use std::sync::Arc;
use std::time::{Instant, SystemTime};
use sylva_core::scene::{BackendChoice, MethodName, Scene};
use sylva_core::species::PRESETS;
use sylva_core::wind::raw::{RawField, RawWave};
use sylva_core::wind::{Blast, Constant, GustFront, Vortex, WindField, WindScene};
use sylva_gpu::GpuContext;
use sylva_gpu::render::{Camera, Lighting, RenderSettings, Renderer};
use winit::application::ApplicationHandler;
use winit::event::WindowEvent;
use winit::event_loop::{ActiveEventLoop, ControlFlow, EventLoop};
use winit::window::{Window, WindowId};

/// Seconds of simulation per scripted frame (times the time scale).
const SCRIPT_FRAME_S: f32 = 1.0 / 60.0;
/// Most simulation steps per frame: a slow frame slows the clock rather than spiral.
const MAX_STEPS_PER_FRAME: usize = 8;
/// How often the scene's files are checked for changes, s.
const WATCH_INTERVAL_S: f64 = 0.5;
/// Largest forest the panel's slider makes, instances per tree.
const MAX_FOREST: usize = 5_000;

/// Per-frame costs, ms.
#[derive(Debug, Clone, Copy, Default)]
struct Stages {
    /// Composing and uploading the wind (CPU).
    wind: f64,
    /// CPU methods' steps and recording every simulation and mesh (CPU).
    simulate: f64,
    /// The GPU's share of simulation and meshing (timestamp queries; 0 without them).
    gpu_mesh: f64,
    /// The GPU's shadow and main passes (timestamp queries; 0 without them).
    gpu_draw: f64,
    /// From recording the draw to presenting, waits included (CPU wall clock).
    draw: f64,
    /// The panel (CPU).
    ui: f64,
    /// The whole frame.
    frame: f64,
}

impl Stages {
    fn add(&mut self, o: &Stages) {
        self.wind += o.wind;
        self.simulate += o.simulate;
        self.gpu_mesh += o.gpu_mesh;
        self.gpu_draw += o.gpu_draw;
        self.draw += o.draw;
        self.ui += o.ui;
        self.frame += o.frame;
    }

    fn scaled(&self, k: f64) -> Stages {
        Stages {
            wind: self.wind * k,
            simulate: self.simulate * k,
            gpu_mesh: self.gpu_mesh * k,
            gpu_draw: self.gpu_draw * k,
            draw: self.draw * k,
            ui: self.ui * k,
            frame: self.frame * k,
        }
    }
}

/// The scene as the viewer runs it: what the panel edits and the script drives.
struct Sim {
    ctx: &'static GpuContext,
    scene: Scene,
    path: Option<PathBuf>,
    watched: Vec<(PathBuf, Option<SystemTime>)>,
    last_watch: Instant,
    reload_error: Option<String>,
    build_error: Option<String>,
    /// The scene's own wind (preset or file), as edited in the panel.
    base_wind: WindScene,
    /// Whether the panel changed `base_wind` (saved beside the scene on save).
    wind_edited: bool,
    scene_wind: bool,
    /// A constant wind on top: (direction, degrees from +X toward +Z; speed, m/s).
    extra_wind: Option<(f32, f32)>,
    /// Blasts and vortices placed live.
    effects: Vec<WindField>,
    /// The scene's and the extra wind, without the effects.
    steady: WindScene,
    /// Everything: what the scene's clock sees.
    wind: WindScene,
    packed: (Vec<RawField>, Vec<RawWave>),
    entries: Vec<Entry>,
    /// Forest size per tree (copies on a grid around it), when the panel set one.
    forest: Vec<usize>,
    t: f32,
    dt: f32,
    carry: f32,
    paused: bool,
    step_once: bool,
    time_scale: f32,
    frames: u64,
    tool: Tool,
    effect_strength: f32,
}

impl Sim {
    fn new(ctx: &'static GpuContext, scene: Scene, path: Option<PathBuf>) -> Result<Self> {
        let base_wind = load_wind(&scene)?;
        let dt = 1.0 / scene.output.sim_rate;
        let n = scene.trees.len();
        let mut sim = Self {
            ctx,
            scene,
            path,
            watched: Vec::new(),
            last_watch: Instant::now(),
            reload_error: None,
            build_error: None,
            base_wind,
            wind_edited: false,
            scene_wind: true,
            extra_wind: None,
            effects: Vec::new(),
            steady: WindScene::default(),
            wind: WindScene::default(),
            packed: (Vec::new(), Vec::new()),
            entries: Vec::new(),
            forest: vec![0; n],
            t: 0.0,
            dt,
            carry: 0.0,
            paused: false,
            step_once: false,
            time_scale: 1.0,
            frames: 0,
            tool: Tool::Blast,
            effect_strength: 25.0,
        };
        sim.compose_wind();
        sim.rebuild_all()?;
        sim.watch_files();
        Ok(sim)
    }

    /// The files whose changes reload the scene: the scene itself, its wind file and its
    /// species or grammar files (presets by name are not files).
    fn watch_files(&mut self) {
        let mut files: Vec<PathBuf> = self.path.iter().cloned().collect();
        let named = std::iter::once(&self.scene.wind).chain(self.scene.trees.iter().map(|t| &t.species));
        for name in named {
            let p = PathBuf::from(self.scene.resolve_path(name));
            if p.is_file() {
                files.push(p);
            }
        }
        self.watched = files.into_iter().map(|p| (p.clone(), mtime(&p))).collect();
    }

    fn compose_wind(&mut self) {
        let mut fields = if self.scene_wind { self.base_wind.fields.clone() } else { Vec::new() };
        if let Some((deg, speed)) = self.extra_wind {
            let a = deg.to_radians();
            fields.push(WindField::Constant(Constant { direction: [a.cos(), 0.0, a.sin()], speed }));
        }
        self.steady = WindScene { fields: fields.clone() };
        fields.extend(self.effects.iter().cloned());
        self.wind = WindScene { fields };
        self.packed = self.wind.pack();
    }

    /// Drops the effects that are over (they would still cost a term per sample); true
    /// when any was.
    fn expire_effects(&mut self) -> bool {
        let (t, before) = (self.t, self.effects.len());
        self.effects.retain(|f| match f {
            WindField::Blast(b) => t < b.start + 8.0 * b.decay + b.radius / b.speed.max(1.0),
            WindField::Vortex(v) => t < v.start + v.duration + v.fade,
            WindField::GustFront(g) => t < g.start + 4.0,
            _ => true,
        });
        self.effects.len() != before
    }

    /// After a wind edit: the CPU methods read `packed` every step; the GPU ones get it now.
    fn wind_changed(&mut self) {
        self.compose_wind();
        for e in &mut self.entries {
            if let Err(err) = e.set_wind(self.ctx, &self.steady, &self.effects) {
                self.build_error = Some(format!("{err:#}"));
            }
        }
    }

    fn rebuild_all(&mut self) -> Result<()> {
        self.forest.resize(self.scene.trees.len(), 0);
        let mut entries = Vec::new();
        for i in 0..self.scene.trees.len() {
            entries.push(self.build(i)?);
        }
        self.entries = entries;
        Ok(())
    }

    /// Builds tree `i` at the current time: its phase groups pre-rolled by their leads.
    fn build(&self, i: usize) -> Result<Entry> {
        let st = &self.scene.trees[i];
        let mut e = Entry::build(self.ctx, &self.scene, i, st, &self.wind, self.dt)?;
        if !self.effects.is_empty() {
            e.set_wind(self.ctx, &self.steady, &self.effects)?;
        }
        let mut encoder = self.ctx.device.create_command_encoder(&Default::default());
        e.advance(self.ctx, (&self.packed.0, &self.packed.1), self.t, self.dt, 0, true, &mut encoder)?;
        self.ctx.queue.submit([encoder.finish()]);
        Ok(e)
    }

    fn rebuild(&mut self, i: usize) {
        match self.build(i) {
            Ok(e) => {
                self.entries[i] = e;
                self.build_error = None;
            }
            Err(e) => self.build_error = Some(format!("tree {i}: {e:#}")),
        }
    }

    /// Sets tree `i`'s forest: `n` instances in all, the tree and copies on a jittered grid.
    fn set_forest(&mut self, i: usize, n: usize) {
        let st = &mut self.scene.trees[i];
        let spacing = 8.0 * st.scale.max(0.1);
        let side = (n as f32).sqrt().ceil().max(1.0) as usize;
        st.copies = (1..n.max(1))
            .map(|k| {
                let h = sylva_core::rng::mix64(st.seed ^ (k as u64).wrapping_mul(0x9E37_79B9_7F4A_7C15));
                let u = |s: u32| ((h >> s) & 0xFFFF) as f32 / 65_536.0 - 0.5;
                sylva_core::scene::Copy {
                    position: [
                        st.position[0] + ((k % side) as f32 + 0.6 * u(0)) * spacing,
                        st.position[1],
                        st.position[2] - ((k / side) as f32 + 0.6 * u(16)) * spacing,
                    ],
                    yaw_deg: 360.0 * (u(32) + 0.5),
                    scale: st.scale * (0.85 + 0.3 * (u(48) + 0.5)),
                }
            })
            .collect();
        self.forest[i] = n;
        self.rebuild(i);
    }

    fn place_effect(&mut self, x: f32, z: f32, tool: Tool) {
        let s = self.effect_strength;
        let field = match tool {
            Tool::Blast => WindField::Blast(Blast {
                centre: [x, 1.0, z],
                strength: s,
                start: self.t,
                speed: 25.0,
                width: 6.0,
                decay: 1.2,
                radius: 40.0,
            }),
            Tool::Vortex => WindField::Vortex(Vortex {
                centre: [x, z],
                drift: [0.0, 0.0],
                strength: 0.6 * s,
                radius: 6.0,
                updraft: 0.1 * s,
                start: self.t,
                duration: 6.0,
                fade: 1.0,
            }),
            Tool::Push | Tool::None => return,
        };
        self.effects.push(field);
        self.wind_changed();
    }

    /// A gust along a drag on the ground from `a` to `b` (x, z): a narrow front that starts
    /// behind `a` and runs toward `b`, stronger for a longer drag.
    fn push(&mut self, a: Vec3, b: Vec3) {
        let d = glam::Vec2::new(b.x - a.x, b.z - a.z);
        let len = d.length();
        if len < 0.1 {
            return;
        }
        let dir = d / len;
        self.effects.push(WindField::GustFront(GustFront {
            origin: [a.x - 4.0 * dir.x, a.z - 4.0 * dir.y],
            direction_deg: dir.y.atan2(dir.x).to_degrees(),
            strength: (2.0 * len).clamp(4.0, self.effect_strength.max(4.0)),
            speed: 12.0,
            width: 3.0,
            length: 6.0 + len,
            radius: 5.0,
            start: self.t,
        }));
        self.wind_changed();
    }

    /// Checks the watched files; a changed scene that parses replaces the running one, one
    /// that does not leaves it running and shows the error.
    fn poll_reload(&mut self, force: bool) {
        if !force && self.last_watch.elapsed().as_secs_f64() < WATCH_INTERVAL_S {
            return;
        }
        self.last_watch = Instant::now();
        let changed = self.watched.iter().any(|(p, m)| mtime(p) != *m);
        if !changed && !force {
            return;
        }
        for (p, m) in &mut self.watched {
            *m = mtime(p);
        }
        let Some(path) = self.path.clone() else { return };
        let loaded = Scene::load(&path).map_err(anyhow::Error::from).and_then(|scene| {
            let wind = load_wind(&scene)?;
            Ok((scene, wind))
        });
        match loaded {
            Ok((scene, wind)) => {
                let old = std::mem::replace(&mut self.scene, scene);
                self.base_wind = wind;
                self.wind_edited = false;
                self.dt = 1.0 / self.scene.output.sim_rate;
                self.compose_wind();
                match self.rebuild_all() {
                    Ok(()) => {
                        self.reload_error = None;
                        self.watch_files();
                    }
                    Err(e) => {
                        self.reload_error = Some(format!("{e:#}"));
                        self.scene = old;
                        if let Ok(w) = load_wind(&self.scene) {
                            self.base_wind = w;
                        }
                        self.compose_wind();
                    }
                }
            }
            Err(e) => self.reload_error = Some(format!("{e:#}")),
        }
    }

    /// Advances by `seconds` of simulation (in whole steps, at most
    /// [`MAX_STEPS_PER_FRAME`]) and records every mesh; returns (wind ms, simulate ms).
    fn advance(&mut self, seconds: f32, encoder: &mut wgpu::CommandEncoder) -> Result<(f64, f64)> {
        let t0 = Instant::now();
        self.carry += seconds;
        let steps = ((self.carry / self.dt).floor() as usize).min(MAX_STEPS_PER_FRAME);
        self.carry = (self.carry - steps as f32 * self.dt).clamp(0.0, self.dt);
        self.t += steps as f32 * self.dt;
        if self.expire_effects() {
            self.compose_wind();
            for e in &mut self.entries {
                e.set_wind(self.ctx, &self.steady, &self.effects)?;
            }
        }
        let t1 = Instant::now();
        for e in &mut self.entries {
            e.advance(self.ctx, (&self.packed.0, &self.packed.1), self.t, self.dt, steps, false, encoder)?;
        }
        Ok((ms(t1 - t0), ms(t1.elapsed())))
    }

    fn bounds(&self) -> (Vec3, Vec3) {
        self.entries.iter().fold((Vec3::splat(f32::INFINITY), Vec3::splat(f32::NEG_INFINITY)), |(lo, hi), e| {
            (lo.min(e.bounds.0), hi.max(e.bounds.1))
        })
    }

    fn report(&self, stages: &Stages, frames: u32) -> Result<serde_json::Value> {
        let wind = (&self.packed.0[..], &self.packed.1[..]);
        let mut trees = Vec::new();
        for e in &self.entries {
            trees.push(serde_json::json!({
                "label": e.label,
                "segments": e.tree.segments.len(),
                "instances": e.instances,
                "simulations": e.simulations,
                "displacement_m": e.displacement(self.ctx, wind, self.t)?,
                "simulation_displacements_m": e.group_displacements(self.ctx, wind, self.t)?,
            }));
        }
        Ok(serde_json::json!({
            "frames": self.frames,
            "time_s": self.t,
            "scene_file": self.scene.file,
            "reload_error": self.reload_error,
            "build_error": self.build_error,
            "wind_fields": self.wind.fields.len(),
            "effects": self.effects.len(),
            "triangles": self.entries.iter().map(|e| e.triangles).sum::<usize>(),
            "instances": self.entries.iter().map(|e| e.instances).sum::<usize>(),
            "stages_ms": {
                "frames": frames,
                "frame": stages.frame, "wind": stages.wind, "simulate": stages.simulate,
                "gpu_simulate_mesh": stages.gpu_mesh, "gpu_draw": stages.gpu_draw,
                "draw": stages.draw, "ui": stages.ui,
            },
            "trees": trees,
        }))
    }
}

fn mtime(p: &Path) -> Option<SystemTime> {
    std::fs::metadata(p).and_then(|m| m.modified()).ok()
}

fn ms(d: std::time::Duration) -> f64 {
    d.as_secs_f64() * 1e3
}

fn load_wind(scene: &Scene) -> Result<WindScene> {
    WindScene::resolve(&scene.resolve_path(&scene.wind)).with_context(|| format!("{}: field `wind`", scene.file))
}

/// An orbit camera: yaw and pitch about a target, at a distance.
#[derive(Debug, Clone, Copy)]
struct Orbit {
    target: Vec3,
    yaw: f32,
    pitch: f32,
    distance: f32,
    fov_deg: f32,
}

impl Orbit {
    fn from_scene(s: &Scene) -> Self {
        let (eye, target) = (Vec3::from_array(s.camera.eye), Vec3::from_array(s.camera.target));
        let d = eye - target;
        let distance = d.length().max(0.5);
        Self {
            target,
            yaw: d.x.atan2(d.z),
            pitch: (d.y / distance).clamp(-1.0, 1.0).asin(),
            distance,
            fov_deg: s.camera.fov_deg,
        }
    }

    fn eye(&self) -> Vec3 {
        self.target
            + self.distance
                * Vec3::new(self.pitch.cos() * self.yaw.sin(), self.pitch.sin(), self.pitch.cos() * self.yaw.cos())
    }

    fn camera(&self) -> Camera {
        Camera { eye: self.eye(), target: self.target, fov_y_deg: self.fov_deg }
    }

    /// Where the ray through view point (u, v) (0…1 from the top left) meets the ground.
    fn ground_point(&self, u: f32, v: f32, aspect: f32) -> Option<Vec3> {
        let inv = self.camera().view_proj(aspect).inverse();
        let ndc = |z: f32| {
            let p = inv * Vec4::new(2.0 * u - 1.0, 1.0 - 2.0 * v, z, 1.0);
            p.truncate() / p.w
        };
        let (near, far) = (ndc(0.0), ndc(1.0));
        let dir = far - near;
        (dir.y.abs() > 1e-6).then(|| near + dir * (-near.y / dir.y)).filter(|p| (p - near).dot(dir) > 0.0)
    }
}

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
    sim: Sim,
    orbit: Orbit,
    gfx: Option<Gfx>,
    script: std::collections::VecDeque<Command>,
    wait_frames: u32,
    error: Option<anyhow::Error>,
    stages: Stages,
    last_frame: Instant,
    show_wind: bool,
    show_skeleton: bool,
    show_clusters: bool,
    status: String,
    /// Stage times summed since the last report, and the frames they cover.
    sums: Stages,
    summed: u32,
    push_from: Option<egui::Pos2>,
    /// GPU timers: simulation and meshing, drawing (with timestamp queries).
    timers: Option<(sylva_gpu::timer::GpuTimer, sylva_gpu::timer::GpuTimer)>,
}

/// Runs the viewer until the window closes or the script quits.
pub fn run(args: &ViewArgs, script: Vec<Command>) -> Result<()> {
    let (scene, path) = match &args.scene {
        Some(p) => (Scene::load(p)?, Some(p.clone())),
        None => (Scene::default_scene(), None),
    };
    let event_loop = EventLoop::new().map_err(|e| {
        anyhow::anyhow!("cannot open a window ({e}); `sylva render` renders the scene to files instead")
    })?;
    event_loop.set_control_flow(ControlFlow::Poll);
    let ctx: &'static GpuContext = Box::leak(Box::new(GpuContext::new(&Default::default())?));
    println!("GPU: {}", ctx.summary);
    let orbit = Orbit::from_scene(&scene);
    let sim = Sim::new(ctx, scene, path)?;
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
        show_wind: true,
        show_skeleton: false,
        show_clusters: false,
        status: String::new(),
        sums: Stages::default(),
        summed: 0,
        push_from: None,
        timers: sylva_gpu::timer::GpuTimer::new(ctx).zip(sylva_gpu::timer::GpuTimer::new(ctx)),
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
        let ctx = self.sim.ctx;
        let surface = ctx.instance.create_surface(window.clone()).context("creating the window's surface")?;
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
                        self.sim.place_effect(p.x, p.z, self.sim.tool);
                    }
                }
                Command::Tool(t) => self.sim.tool = t,
                Command::Blast(x, z) => self.sim.place_effect(x, z, Tool::Blast),
                Command::Wind(deg, speed) => {
                    self.sim.extra_wind = Some((deg, speed));
                    self.sim.wind_changed();
                }
                Command::Method(i, m) => {
                    if i >= self.sim.scene.trees.len() {
                        anyhow::bail!("script: `method {i}`: the scene has {} trees", self.sim.scene.trees.len());
                    }
                    self.sim.scene.trees[i].method = m;
                    self.sim.rebuild(i);
                }
                Command::OverwriteScene(src) => {
                    let dst = self.sim.path.clone().context("script: overwrite-scene needs a scene file")?;
                    let text = std::fs::read(&src).with_context(|| format!("reading {}", src.display()))?;
                    std::fs::write(&dst, text).with_context(|| format!("writing {}", dst.display()))?;
                    self.sim.poll_reload(true);
                }
                Command::Screenshot(p) => self.screenshot(&p)?,
                Command::Forest(i, n) => {
                    if i >= self.sim.scene.trees.len() {
                        anyhow::bail!("script: `forest {i}`: the scene has {} trees", self.sim.scene.trees.len());
                    }
                    self.sim.set_forest(i, n);
                }
                Command::Report(p) => {
                    let mean = self.sums.scaled(1.0 / self.summed.max(1) as f64);
                    let json = serde_json::to_string_pretty(&self.sim.report(&mean, self.summed)?)?;
                    write_atomic(&p, json.as_bytes())?;
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
        let ctx = self.sim.ctx;
        let rgba = view.renderer.read_image(ctx, ctx.device.create_command_encoder(&Default::default()))?;
        let img = image::RgbaImage::from_raw(view.size.0, view.size.1, rgba).context("image size")?;
        let tmp = path.with_extension("tmp.png");
        img.save(&tmp).with_context(|| format!("writing {}", tmp.display()))?;
        std::fs::rename(&tmp, path).with_context(|| format!("writing {}", path.display()))
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
            self.sim.dt
        } else if scripted {
            SCRIPT_FRAME_S * self.sim.time_scale
        } else {
            wall * self.sim.time_scale
        };
        let ctx = self.sim.ctx;
        // Simulation and meshing go in a submission of their own between the timer's stamps:
        // submissions complete in order, while passes inside one encoder may overlap a
        // stamp (lavapipe runs compute asynchronously up to the next barrier).
        let mut encoder = ctx.device.create_command_encoder(&Default::default());
        let (wind_ms, sim_ms) = self.sim.advance(seconds, &mut encoder)?;
        if let Some((t, _)) = &self.timers {
            t.start(ctx);
        }
        ctx.queue.submit([encoder.finish()]);
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
        let mut overlays = [self.show_wind, self.show_skeleton, self.show_clusters];
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
                overlay(ui, view_rect, &self.sim, &self.orbit, &stages, overlays);
            });
        });
        let ui_ms = ms(ui_start.elapsed());
        [self.show_wind, self.show_skeleton, self.show_clusters] = overlays;
        for a in actions {
            match a {
                Action::Place(u, v) => {
                    let aspect = view_rect.width() / view_rect.height().max(1.0);
                    if let Some(p) = self.orbit.ground_point(u, v, aspect) {
                        self.sim.place_effect(p.x, p.z, self.sim.tool);
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
                    self.status = match save_scene(&mut self.sim) {
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
                    msaa: self.sim.scene.output.msaa,
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
            sun_direction: Vec3::from_array(self.sim.scene.sun.direction).normalize(),
            sun_intensity: self.sim.scene.sun.intensity,
            ..Default::default()
        };
        let globals = view.renderer.globals(&self.orbit.camera(), &light, self.sim.bounds());
        let items: Vec<_> = self.sim.entries.iter().flat_map(Entry::draw_items).collect();
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
                ctx.queue.submit(extra.into_iter().chain([encoder.finish()]));
                ctx.queue.present(frame);
            }
            None => {
                ctx.queue.submit([encoder.finish()]);
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
            wind: wind_ms,
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

/// What the panel and the view ask for after the UI pass.
enum Action {
    /// A click at view point (u, v) with the current tool.
    Place(f32, f32),
    /// A push dragged from one view point to another.
    Push((f32, f32), (f32, f32)),
    Save,
}

fn save_scene(sim: &mut Sim) -> Result<PathBuf> {
    let path = sim.path.clone().unwrap_or_else(|| PathBuf::from("scene.toml"));
    // Wind edited in the panel (and the extra constant wind) go to a wind file beside the
    // scene, which the scene then names.
    if sim.wind_edited || sim.extra_wind.is_some() || !sim.scene_wind {
        let mut wind = if sim.scene_wind { sim.base_wind.clone() } else { WindScene::default() };
        if let Some((deg, speed)) = sim.extra_wind {
            let a = deg.to_radians();
            wind.fields.push(WindField::Constant(Constant { direction: [a.cos(), 0.0, a.sin()], speed }));
        }
        let stem = path.file_stem().map_or("scene".into(), |s| s.to_string_lossy().into_owned());
        let name = format!("{stem}.wind.toml");
        let file = path.with_file_name(&name);
        let text = toml::to_string_pretty(&wind).context("writing the wind as TOML")?;
        write_atomic(&file, text.as_bytes())?;
        sim.scene.wind = name;
        sim.base_wind = wind;
        (sim.wind_edited, sim.extra_wind, sim.scene_wind) = (false, None, true);
    }
    write_atomic(&path, sim.scene.to_toml().as_bytes())?;
    if sim.path.is_none() {
        sim.path = Some(path.clone());
    }
    // Our own write is not an edit to reload.
    sim.watch_files();
    Ok(path)
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

#[allow(clippy::too_many_arguments)]
fn panel(
    ui: &mut egui::Ui,
    sim: &mut Sim,
    orbit: &mut Orbit,
    stages: &Stages,
    overlays: &mut [bool; 3],
    status: &str,
    actions: &mut Vec<Action>,
) {
    ui.heading("Sylva");
    ui.label(sim.path.as_ref().map_or("built-in default scene".to_string(), |p| p.display().to_string()));
    if let Some(e) = &sim.reload_error {
        ui.colored_label(
            egui::Color32::from_rgb(230, 80, 70),
            format!("reload failed, still running the last good scene:\n{e}"),
        );
    }
    if let Some(e) = &sim.build_error {
        ui.colored_label(egui::Color32::from_rgb(230, 80, 70), e);
    }
    ui.horizontal(|ui| {
        if ui.button("Save scene").clicked() {
            actions.push(Action::Save);
        }
        if ui.button("Reset camera").clicked() {
            *orbit = Orbit::from_scene(&sim.scene);
        }
    });
    if !status.is_empty() {
        ui.label(status);
    }
    ui.separator();
    ui.label(format!("t = {:.2} s", sim.t));
    ui.horizontal(|ui| {
        ui.checkbox(&mut sim.paused, "pause");
        if ui.button("step").clicked() {
            sim.step_once = true;
        }
    });
    ui.add(egui::Slider::new(&mut sim.time_scale, 0.0..=4.0).text("time scale"));

    ui.separator();
    ui.strong("Wind");
    let mut changed = ui.checkbox(&mut sim.scene_wind, format!("scene wind `{}`", sim.scene.wind)).changed();
    let mut extra = sim.extra_wind.is_some();
    changed |= ui.checkbox(&mut extra, "extra constant wind").changed();
    let (mut deg, mut speed) = sim.extra_wind.unwrap_or((0.0, 8.0));
    if extra {
        changed |= ui.add(egui::Slider::new(&mut deg, -180.0..=180.0).text("direction °")).changed();
        changed |= ui.add(egui::Slider::new(&mut speed, 0.0..=40.0).text("speed m/s")).changed();
    }
    if changed {
        sim.extra_wind = extra.then_some((deg, speed));
        sim.wind_changed();
    }
    egui::CollapsingHeader::new("scene wind fields").show(ui, |ui| {
        if wind_fields(ui, &mut sim.base_wind) {
            sim.wind_edited = true;
            sim.wind_changed();
        }
    });
    ui.horizontal(|ui| {
        ui.label("click places:");
        ui.radio_value(&mut sim.tool, Tool::Blast, "blast");
        ui.radio_value(&mut sim.tool, Tool::Vortex, "vortex");
        ui.radio_value(&mut sim.tool, Tool::Push, "push (drag)");
        ui.radio_value(&mut sim.tool, Tool::None, "nothing");
    });
    ui.add(egui::Slider::new(&mut sim.effect_strength, 2.0..=60.0).text("strength m/s"));
    if !sim.effects.is_empty() && ui.button(format!("clear {} effect(s)", sim.effects.len())).clicked() {
        sim.effects.clear();
        sim.wind_changed();
    }

    ui.separator();
    ui.strong("Trees");
    for i in 0..sim.scene.trees.len() {
        let label = sim.entries.get(i).map_or(String::new(), |e| e.label.clone());
        egui::CollapsingHeader::new(format!("{i}: {label}")).id_salt(("tree", i)).show(ui, |ui| {
            let st = &mut sim.scene.trees[i];
            let mut rebuild = false;
            egui::ComboBox::from_id_salt(("species", i)).selected_text(st.species.clone()).show_ui(ui, |ui| {
                for p in PRESETS {
                    rebuild |= ui.selectable_value(&mut st.species, p.name.to_string(), p.name).changed();
                }
            });
            ui.horizontal(|ui| {
                ui.label("or file:");
                let edit = ui.add(egui::TextEdit::singleline(&mut st.species).desired_width(150.0));
                rebuild |= edit.lost_focus() && ui.input(|i| i.key_pressed(egui::Key::Enter));
            });
            ui.horizontal(|ui| {
                rebuild |= ui.add(egui::DragValue::new(&mut st.seed).prefix("seed ")).changed();
                if ui.button("new seed").clicked() {
                    st.seed = st.seed.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407) >> 33;
                    rebuild = true;
                }
            });
            ui.horizontal(|ui| {
                for m in [MethodName::Zioma, MethodName::Akagi, MethodName::Skjermo, MethodName::Hsm] {
                    rebuild |= ui.radio_value(&mut st.method, m, m.as_str()).changed();
                }
            });
            ui.horizontal(|ui| {
                for (b, name) in
                    [(BackendChoice::Auto, "auto"), (BackendChoice::Cpu, "CPU"), (BackendChoice::Gpu, "GPU")]
                {
                    rebuild |= ui.radio_value(&mut st.backend, b, name).changed();
                }
            });
            let mut n = if sim.forest[i] > 0 { sim.forest[i] } else { 1 + st.copies.len() };
            let forest =
                ui.add(egui::Slider::new(&mut n, 1..=MAX_FOREST).logarithmic(true).text("instances")).drag_stopped();
            if rebuild {
                sim.rebuild(i);
            } else if forest {
                sim.set_forest(i, n);
            }
            if let Some(e) = sim.entries.get(i) {
                ui.label(format!(
                    "{} segments, {} leaves, {} triangles, {} instance(s), {} simulation(s)",
                    e.tree.segments.len(),
                    e.tree.leaves.len(),
                    e.triangles,
                    e.instances,
                    e.simulations
                ));
            }
        });
    }

    ui.separator();
    ui.strong("Overlays");
    ui.checkbox(&mut overlays[0], "wind arrows");
    ui.checkbox(&mut overlays[1], "skeleton (first instance of each tree)");
    ui.checkbox(&mut overlays[2], "HSM clusters (centres of mass)");
    ui.separator();
    ui.strong("Frame");
    ui.monospace(format!(
        "frame         {:6.1} ms\nwind          {:6.1} ms\nsimulate      {:6.1} ms\n GPU sim+mesh {:6.1} ms\n GPU draw     {:6.1} ms\ndraw+present  {:6.1} ms\nui            {:6.1} ms",
        stages.frame, stages.wind, stages.simulate, stages.gpu_mesh, stages.gpu_draw, stages.draw, stages.ui
    ));
    let segments: usize = sim.entries.iter().map(|e| e.tree.segments.len() * e.simulations).sum();
    let triangles: usize = sim.entries.iter().map(|e| e.triangles).sum();
    let instances: usize = sim.entries.iter().map(|e| e.instances).sum();
    let particles: usize = sim.entries.iter().filter_map(|e| e.particles().map(|n| n * e.simulations)).sum();
    ui.monospace(format!(
        "{segments} segments simulated\n{particles} particles (HSM)\n{triangles} triangles\n{instances} instances"
    ));
    ui.label(format!("GPU: {}", sim.ctx.summary.name));
}

/// Sliders for the fields of the scene's wind; true when one moved.
fn wind_fields(ui: &mut egui::Ui, wind: &mut WindScene) -> bool {
    let mut changed = false;
    for (k, f) in wind.fields.iter_mut().enumerate() {
        ui.push_id(("field", k), |ui| match f {
            WindField::Constant(c) => {
                ui.label("constant");
                let mut deg = c.direction[2].atan2(c.direction[0]).to_degrees();
                if ui.add(egui::Slider::new(&mut deg, -180.0..=180.0).text("direction °")).changed() {
                    let a = deg.to_radians();
                    c.direction = [a.cos(), c.direction[1], a.sin()];
                    changed = true;
                }
                changed |= ui.add(egui::Slider::new(&mut c.speed, 0.0..=40.0).text("speed m/s")).changed();
            }
            WindField::SumOfSines(s) => {
                ui.label("sum of sines (Skjermo eqs. 11–14)");
                for (i, w) in s.waves.iter_mut().enumerate() {
                    ui.push_id(i, |ui| {
                        changed |=
                            ui.add(egui::Slider::new(&mut w.amplitude, 0.0..=10.0).text("amplitude m/s")).changed();
                        changed |= ui
                            .add(egui::Slider::new(&mut w.direction_deg, -180.0..=180.0).text("direction °"))
                            .changed();
                        changed |=
                            ui.add(egui::Slider::new(&mut w.wavelength, 1.0..=200.0).text("wavelength m")).changed();
                        changed |= ui.add(egui::Slider::new(&mut w.speed, 0.0..=20.0).text("speed m/s")).changed();
                    });
                }
            }
            WindField::Turbulence(t) => {
                ui.label("turbulence (1/f^β)");
                changed |= ui.add(egui::Slider::new(&mut t.intensity, 0.0..=8.0).text("gustiness (rms m/s)")).changed();
                changed |= ui.add(egui::Slider::new(&mut t.beta, 0.5..=3.0).text("β")).changed();
            }
            WindField::GustFront(g) => {
                ui.label("gust front");
                changed |= ui.add(egui::Slider::new(&mut g.strength, 0.0..=30.0).text("strength m/s")).changed();
                changed |=
                    ui.add(egui::Slider::new(&mut g.direction_deg, -180.0..=180.0).text("direction °")).changed();
            }
            WindField::Vortex(v) => {
                ui.label("vortex");
                changed |= ui.add(egui::Slider::new(&mut v.strength, -40.0..=40.0).text("strength m/s")).changed();
                changed |= ui.add(egui::Slider::new(&mut v.radius, 0.5..=40.0).text("radius m")).changed();
            }
            WindField::Blast(b) => {
                ui.label("blast");
                changed |= ui.add(egui::Slider::new(&mut b.strength, 0.0..=100.0).text("strength m/s")).changed();
            }
        });
        ui.separator();
    }
    changed
}

/// Frame time and counts over the view, wind arrows on the ground.
fn overlay(
    ui: &egui::Ui,
    rect: egui::Rect,
    sim: &Sim,
    orbit: &Orbit,
    stages: &Stages,
    [show_wind, show_skeleton, show_clusters]: [bool; 3],
) {
    let painter = ui.painter_at(rect);
    painter.text(
        rect.left_top() + egui::vec2(8.0, 6.0),
        egui::Align2::LEFT_TOP,
        format!(
            "{:.1} ms  ({:.0} fps)   t = {:.2} s{}",
            stages.frame,
            1e3 / stages.frame.max(1e-3),
            sim.t,
            if sim.paused { "  paused" } else { "" }
        ),
        egui::FontId::monospace(13.0),
        egui::Color32::WHITE,
    );
    let aspect = rect.width() / rect.height().max(1.0);
    let vp = orbit.camera().view_proj(aspect);
    let project = |p: Vec3| -> Option<egui::Pos2> {
        let c = vp * p.extend(1.0);
        (c.w > 0.0).then(|| {
            let n = c.truncate() / c.w;
            egui::pos2(rect.left() + (n.x * 0.5 + 0.5) * rect.width(), rect.top() + (0.5 - n.y * 0.5) * rect.height())
        })
    };
    if show_wind {
        let (lo, hi) = sim.bounds();
        if lo.is_finite() && hi.is_finite() {
            let (fields, waves) = (&sim.packed.0, &sim.packed.1);
            for i in 0..5 {
                for k in 0..5 {
                    let p = Vec3::new(
                        lo.x + (hi.x - lo.x) * (i as f32 + 0.5) / 5.0,
                        1.5,
                        lo.z + (hi.z - lo.z) * (k as f32 + 0.5) / 5.0,
                    );
                    let v = sylva_core::wind::sample::wind_at(fields, waves, p, sim.t);
                    let (Some(a), Some(b)) = (project(p), project(p + v * 0.25)) else { continue };
                    painter.arrow(
                        a,
                        b - a,
                        egui::Stroke::new(1.5, egui::Color32::from_rgba_unmultiplied(255, 240, 120, 200)),
                    );
                }
            }
        }
    }
    if show_clusters {
        for e in &sim.entries {
            let Ok(Some(centres)) = e.clusters(sim.ctx) else { continue };
            for c in centres {
                if let Some(p) = project(e.transform.transform_point3(c)) {
                    painter.circle_filled(p, 2.0, egui::Color32::from_rgb(90, 200, 255));
                }
            }
        }
    }
    if show_skeleton {
        let wind = (&sim.packed.0[..], &sim.packed.1[..]);
        let stroke = egui::Stroke::new(1.0, egui::Color32::from_rgb(255, 120, 60));
        for e in &sim.entries {
            let Ok(pose) = e.pose(sim.ctx, wind, sim.t) else { continue };
            let m: Mat4 = e.transform;
            for s in 0..e.tree.segments.len() {
                let (a, b) = (m.transform_point3(pose.start[s]), m.transform_point3(pose.end(&e.tree, s)));
                if let (Some(a), Some(b)) = (project(a), project(b)) {
                    painter.line_segment([a, b], stroke);
                }
            }
        }
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

#[cfg(test)]
mod tests {
    use super::*;

    /// Picking: the view's centre lands on the target when it lies on the ground; a point
    /// lower in the view lands nearer the camera; the sky hits nothing.
    #[test]
    fn clicks_pick_the_ground_under_the_cursor() {
        let orbit = Orbit { target: Vec3::new(3.0, 0.0, -2.0), yaw: 0.7, pitch: 0.2, distance: 20.0, fov_deg: 45.0 };
        let centre = orbit.ground_point(0.5, 0.5, 16.0 / 9.0).unwrap();
        assert!(centre.distance(orbit.target) < 1e-3, "{centre}");
        let near = orbit.ground_point(0.5, 0.9, 16.0 / 9.0).unwrap();
        assert!(near.distance(orbit.eye()) < centre.distance(orbit.eye()));
        assert!(near.y.abs() < 1e-4);
        assert!(orbit.ground_point(0.5, 0.02, 16.0 / 9.0).is_none(), "the sky is not ground");
        // The scene's camera round-trips through the orbit.
        let mut scene = Scene::default_scene();
        scene.camera.eye = [4.0, 6.0, 30.0];
        scene.camera.target = [1.0, 2.0, 0.0];
        let o = Orbit::from_scene(&scene);
        assert!(o.eye().distance(Vec3::from_array(scene.camera.eye)) < 1e-4, "{}", o.eye());
    }
}
