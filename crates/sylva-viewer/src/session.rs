//! The viewer's session: the runtime's [`World`] and what the panel and the script edit
//! around it (the clock's speed, the tool a click uses, forest sizes, errors to show).

use crate::reload::Watch;
use crate::script::Tool;
use anyhow::Result;
use glam::Vec3;
use std::path::PathBuf;
use std::sync::Arc;
use std::time::Instant;
use sylva_core::scene::Scene;
use sylva_gpu::GpuContext;
use sylva_runtime::{Effect, World};

/// Seconds of simulation per scripted frame (times the time scale).
pub(crate) const SCRIPT_FRAME_S: f32 = 1.0 / 60.0;
/// Most simulation steps per frame: a slow frame slows the clock rather than spiral.
const MAX_STEPS_PER_FRAME: usize = 8;

/// Per-frame costs, ms.
#[derive(Debug, Clone, Copy, Default)]
pub(crate) struct Stages {
    /// Stepping every simulation (CPU methods' steps, GPU methods' submissions, live effects
    /// expired) and recording every mesh (CPU).
    pub simulate: f64,
    /// The GPU's share of simulation and meshing (timestamp queries; 0 without them).
    pub gpu_mesh: f64,
    /// The GPU's shadow and main passes (timestamp queries; 0 without them).
    pub gpu_draw: f64,
    /// From recording the draw to presenting, waits included (CPU wall clock).
    pub draw: f64,
    /// The panel (CPU).
    pub ui: f64,
    /// The whole frame.
    pub frame: f64,
}

impl Stages {
    pub(crate) fn add(&mut self, o: &Stages) {
        self.simulate += o.simulate;
        self.gpu_mesh += o.gpu_mesh;
        self.gpu_draw += o.gpu_draw;
        self.draw += o.draw;
        self.ui += o.ui;
        self.frame += o.frame;
    }

    pub(crate) fn scaled(&self, k: f64) -> Stages {
        Stages {
            simulate: self.simulate * k,
            gpu_mesh: self.gpu_mesh * k,
            gpu_draw: self.gpu_draw * k,
            draw: self.draw * k,
            ui: self.ui * k,
            frame: self.frame * k,
        }
    }
}

pub(crate) fn ms(d: std::time::Duration) -> f64 {
    d.as_secs_f64() * 1e3
}

/// The scene as the viewer runs it.
pub(crate) struct Session {
    pub ctx: Arc<GpuContext>,
    pub world: World,
    /// The scene file (none for the built-in scene).
    pub path: Option<PathBuf>,
    pub watch: Watch,
    pub reload_error: Option<String>,
    pub build_error: Option<String>,
    /// Whether the panel changed the scene's wind fields (saved beside the scene on save).
    pub wind_edited: bool,
    /// Forest size per tree (copies on a grid around it), when the panel set one.
    pub forest: Vec<usize>,
    pub paused: bool,
    pub step_once: bool,
    pub time_scale: f32,
    pub frames: u64,
    pub tool: Tool,
    pub effect_strength: f32,
}

impl Session {
    pub(crate) fn new(ctx: Arc<GpuContext>, scene: Scene, path: Option<PathBuf>) -> Result<Self> {
        let n = scene.trees.len();
        let mut world = World::new(ctx.clone(), scene)?;
        world.preroll(0);
        let watch = Watch::of(world.scene(), path.as_deref());
        Ok(Self {
            ctx,
            world,
            path,
            watch,
            reload_error: None,
            build_error: None,
            wind_edited: false,
            forest: vec![0; n],
            paused: false,
            step_once: false,
            time_scale: 1.0,
            frames: 0,
            tool: Tool::Blast,
            effect_strength: 25.0,
        })
    }

    /// Shows a failed edit in the panel instead of stopping.
    pub(crate) fn note(&mut self, r: Result<(), sylva_runtime::RuntimeError>) {
        if let Err(e) = r {
            self.build_error = Some(e.to_string());
        }
    }

    /// Places the tool's effect at ground point (x, z).
    pub(crate) fn place(&mut self, x: f32, z: f32, tool: Tool) {
        let s = self.effect_strength;
        let effect = match tool {
            Tool::Blast => Effect::Blast { at: [x, z], strength: s },
            Tool::Vortex => Effect::Vortex { at: [x, z], strength: s },
            Tool::Push | Tool::None => return,
        };
        let r = self.world.place(effect);
        self.note(r);
    }

    /// A gust along a drag on the ground from `a` to `b`.
    pub(crate) fn push(&mut self, a: Vec3, b: Vec3) {
        let r = self.world.place(Effect::Push { from: [a.x, a.z], to: [b.x, b.z], strength: self.effect_strength });
        self.note(r);
    }

    /// Sets an extra constant wind (direction in degrees from +X toward +Z, m/s) or none.
    pub(crate) fn set_extra_wind(&mut self, extra: Option<(f32, f32)>) {
        let r = self.world.edit_wind(|w| {
            let changed = w.extra != extra;
            w.extra = extra;
            changed
        });
        self.note(r);
    }

    /// Rebuilds tree `i` as `edit` changes its scene entry.
    pub(crate) fn rebuild(&mut self, i: usize, edit: impl FnOnce(&mut sylva_core::scene::SceneTree)) {
        let Some(mut st) = self.world.scene().trees.get(i).cloned() else {
            self.build_error = Some(format!("tree {i}: the scene has {} trees", self.world.scene().trees.len()));
            return;
        };
        edit(&mut st);
        match self.world.rebuild_tree(i, st) {
            Ok(()) => self.build_error = None,
            Err(e) => self.build_error = Some(format!("tree {i}: {e}")),
        }
    }

    /// Sets tree `i`'s forest: `n` instances in all, the tree and copies on a jittered grid.
    pub(crate) fn set_forest(&mut self, i: usize, n: usize) {
        self.rebuild(i, |st| {
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
        });
        if i < self.forest.len() {
            self.forest[i] = n;
        }
    }

    /// Advances by `seconds` of simulation and records every mesh; returns the time taken,
    /// ms.
    pub(crate) fn advance(&mut self, seconds: f32, encoder: &mut wgpu::CommandEncoder) -> Result<f64> {
        let t0 = Instant::now();
        self.world.advance(seconds, MAX_STEPS_PER_FRAME)?;
        self.world.record(encoder);
        Ok(ms(t0.elapsed()))
    }

    /// The report a script asks for.
    pub(crate) fn report(&self, stages: &Stages, frames: u32) -> Result<serde_json::Value> {
        let mut trees = Vec::new();
        for t in self.world.trees() {
            let each = t.displacements(&self.ctx)?;
            trees.push(serde_json::json!({
                "label": t.label,
                "method": t.method,
                "segments": t.tree.segments.len(),
                "instances": t.instances,
                "simulations": t.simulations,
                "displacement_m": each[0],
                "simulation_displacements_m": each,
            }));
        }
        Ok(serde_json::json!({
            "frames": self.frames,
            "time_s": self.world.time(),
            "scene_file": self.world.scene().file,
            "reload_error": self.reload_error,
            "build_error": self.build_error,
            "wind_fields": self.world.wind().composed().fields.len(),
            "effects": self.world.wind().effects().len(),
            "triangles": self.world.triangles(),
            "instances": self.world.instances(),
            "stages_ms": {
                "frames": frames,
                "frame": stages.frame, "simulate": stages.simulate,
                "gpu_simulate_mesh": stages.gpu_mesh, "gpu_draw": stages.gpu_draw,
                "draw": stages.draw, "ui": stages.ui,
            },
            "trees": trees,
        }))
    }
}
