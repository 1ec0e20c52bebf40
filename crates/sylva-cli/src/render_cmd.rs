//! `sylva render`: the main job. Grows every tree of a scene, animates each with its method
//! (CPU or GPU), meshes every frame on the GPU, renders it (sun, shadows, sky, ground,
//! instancing) and writes a GIF, PNG frames and, when `ffmpeg` is installed, an MP4 — each
//! file complete or not at all.

use anyhow::{Context, Result, bail};
use glam::{Mat4, Quat, Vec3};
use indicatif::{ProgressBar, ProgressStyle};
use std::borrow::Cow;
use std::io::Write;
use std::path::{Path, PathBuf};
use std::sync::Arc;
use std::sync::atomic::{AtomicBool, Ordering};
use std::time::Instant;
use sylva_core::animate::akagi::{Akagi, AkagiParams, AkagiState};
use sylva_core::animate::hsm::{Hsm, HsmParams, HsmState};
use sylva_core::animate::skjermo::{Skjermo, SkjermoParams, SkjermoState};
use sylva_core::animate::zioma::{Zioma, ZiomaInstance, ZiomaParams};
use sylva_core::animate::{Pose, seam_buffers};
use sylva_core::mesh::{DeformLayout, DeformerParams, MeshLayout, MeshParams, SkinLayout};
use sylva_core::scene::{BackendChoice, MethodName, Scene};
use sylva_core::species::SpeciesSource;
use sylva_core::wind::WindScene;
use sylva_core::wind::raw::{RawField, RawWave};
use sylva_core::{Limits, Tree};
use sylva_gpu::GpuContext;
use sylva_gpu::deform::GpuDeform;
use sylva_gpu::mesh::GpuMesh;
use sylva_gpu::render::{Camera, DrawItem, Instance, Lighting, RenderSettings, Renderer};
use sylva_gpu::skin::GpuSkin;

/// Arguments of `sylva render`.
#[derive(clap::Args, Debug, Default)]
pub struct RenderArgs {
    /// Scene file (TOML); the built-in default scene when absent.
    pub scene: Option<PathBuf>,
    /// Output directory (overrides the scene's).
    #[arg(long)]
    pub out_dir: Option<PathBuf>,
    /// Image width (overrides the scene's).
    #[arg(long)]
    pub width: Option<u32>,
    /// Image height (overrides the scene's).
    #[arg(long)]
    pub height: Option<u32>,
    /// Duration, s (overrides the scene's).
    #[arg(long)]
    pub seconds: Option<f32>,
    /// Frames per second (overrides the scene's).
    #[arg(long)]
    pub fps: Option<f32>,
    /// Where every tree's simulation runs (overrides each tree's `backend`).
    #[arg(long, value_enum)]
    pub backend: Option<BackendArg>,
    /// Write no MP4 even when ffmpeg is installed.
    #[arg(long)]
    pub no_mp4: bool,
    /// Write no PNG frames.
    #[arg(long)]
    pub no_png: bool,
}

/// Backend override.
#[derive(clap::ValueEnum, Clone, Copy, Debug, PartialEq, Eq)]
pub enum BackendArg {
    /// GPU on hardware adapters, CPU on software rasterisers.
    Auto,
    /// CPU reference.
    Cpu,
    /// GPU kernels.
    Gpu,
}

/// One tree's animation, on the CPU or the GPU.
enum Anim {
    ZiomaCpu(Zioma),
    ZiomaGpu(Zioma, sylva_gpu::pose::GpuZioma),
    AkagiCpu(Akagi, Box<AkagiState>),
    AkagiGpu(sylva_gpu::pose::GpuAkagi),
    SkjermoCpu(Skjermo, Box<SkjermoState>),
    SkjermoGpu(sylva_gpu::pose::GpuSkjermo),
    HsmCpu(Box<Hsm>, Box<HsmState>),
    HsmGpu(Box<Hsm>, sylva_gpu::hsm::GpuHsm),
}

impl Anim {
    fn new(ctx: &GpuContext, tree: &Tree, method: MethodName, gpu: bool, seed: u64, wind: &WindScene) -> Result<Self> {
        Ok(match (method, gpu) {
            (MethodName::Zioma, false) => Self::ZiomaCpu(Zioma::new(tree, ZiomaParams { seed, ..Default::default() })),
            (MethodName::Zioma, true) => {
                let m = Zioma::new(tree, ZiomaParams { seed, ..Default::default() });
                let g = sylva_gpu::pose::GpuZioma::new(ctx, tree, &m, wind)?;
                Self::ZiomaGpu(m, g)
            }
            (MethodName::Akagi, false) => {
                let m = Akagi::new(tree, AkagiParams::default());
                let s = m.rest_state(tree);
                Self::AkagiCpu(m, Box::new(s))
            }
            (MethodName::Akagi, true) => {
                let m = Akagi::new(tree, AkagiParams::default());
                Self::AkagiGpu(sylva_gpu::pose::GpuAkagi::new(ctx, tree, &m, wind)?)
            }
            (MethodName::Skjermo, false) => {
                let m = Skjermo::new(tree, SkjermoParams::default());
                let s = m.rest_state(tree);
                Self::SkjermoCpu(m, Box::new(s))
            }
            (MethodName::Skjermo, true) => {
                let m = Skjermo::new(tree, SkjermoParams::default());
                Self::SkjermoGpu(sylva_gpu::pose::GpuSkjermo::new(ctx, tree, &m, wind)?)
            }
            (MethodName::Hsm, false) => {
                let m = Hsm::new(tree, HsmParams::default())?;
                let s = m.rest_state();
                Self::HsmCpu(Box::new(m), Box::new(s))
            }
            (MethodName::Hsm, true) => {
                let m = Hsm::new(tree, HsmParams::default())?;
                let g = sylva_gpu::hsm::GpuHsm::new(ctx, Some(tree), &m, wind)?;
                Self::HsmGpu(Box::new(m), g)
            }
        })
    }

    /// Advances `steps` steps of `dt` (stateful methods) to time `t` (Zioma), then records
    /// the mesh of the new pose: from the GPU pose buffers, or from a CPU pose uploaded.
    #[allow(clippy::too_many_arguments)]
    fn advance_and_mesh(
        &mut self,
        ctx: &GpuContext,
        tree: &Tree,
        wind: (&[RawField], &[RawWave]),
        t: f32,
        dt: f32,
        steps: usize,
        mesh: &GpuMesh,
        encoder: &mut wgpu::CommandEncoder,
    ) -> Result<()> {
        let (fields, waves) = wind;
        let cpu_pose: Option<Cow<'_, Pose>> = match self {
            Self::ZiomaCpu(m) => Some(Cow::Owned(m.pose_packed(tree, fields, waves, t))),
            Self::ZiomaGpu(m, g) => {
                g.submit(ctx, tree, m, t);
                None
            }
            Self::AkagiCpu(m, s) => {
                for _ in 0..steps {
                    m.step(tree, fields, waves, s, dt);
                }
                Some(Cow::Borrowed(&s.pose))
            }
            Self::AkagiGpu(g) => {
                for _ in 0..steps {
                    g.step(ctx, dt);
                }
                None
            }
            Self::SkjermoCpu(m, s) => {
                for _ in 0..steps {
                    m.step(tree, fields, waves, s, dt);
                }
                Some(Cow::Borrowed(&s.pose))
            }
            Self::SkjermoGpu(g) => {
                for _ in 0..steps {
                    g.step(ctx, dt);
                }
                None
            }
            Self::HsmCpu(m, s) => {
                for _ in 0..steps {
                    m.step(fields, waves, s, dt);
                }
                Some(Cow::Owned(m.pose(tree, s)))
            }
            Self::HsmGpu(m, g) => {
                g.advance(ctx, m, dt, steps);
                None
            }
        };
        match cpu_pose {
            Some(pose) => mesh.record_pose(ctx, encoder, tree, &pose),
            None => {
                let pose = match self {
                    Self::ZiomaGpu(_, g) => g.gpu_pose(),
                    Self::AkagiGpu(g) => g.gpu_pose(),
                    Self::SkjermoGpu(g) => g.gpu_pose(),
                    Self::HsmGpu(_, g) => g.gpu_pose().context("HSM on the GPU was built without its tree")?,
                    _ => unreachable!("CPU methods return a pose"),
                };
                mesh.record(ctx, encoder, pose.joints_buffer(), pose.acc_buffer());
            }
        }
        Ok(())
    }
}

/// Zioma trees with copies (§6.5): every instance its own wind sample, phase and trunk
/// seed, all skinned from one rest mesh on the GPU.
struct ZiomaForest {
    method: Zioma,
    instances: Vec<ZiomaInstance>,
    /// The instances' transforms for the renderer.
    transforms: wgpu::Buffer,
    gpu: Option<sylva_gpu::pose::GpuZioma>,
    skin: GpuSkin,
    joint: wgpu::Buffer,
    acc: wgpu::Buffer,
}

impl ZiomaForest {
    fn new(
        ctx: &GpuContext,
        tree: &Tree,
        layout: &MeshLayout,
        placements: &[Instance],
        gpu: bool,
        seed: u64,
        wind: &WindScene,
    ) -> Result<Self> {
        let method = Zioma::new(tree, ZiomaParams { seed, ..Default::default() });
        let instances: Vec<ZiomaInstance> = placements
            .iter()
            .enumerate()
            .map(|(k, p)| {
                let (_, rotation, position) = p.transform.to_scale_rotation_translation();
                let key = sylva_core::rng::mix64(seed ^ (k as u64).wrapping_mul(0x9e37_79b9_7f4a_7c15));
                ZiomaInstance {
                    position,
                    yaw: rotation.to_euler(glam::EulerRot::YXZ).0,
                    phase: (key & 0xFFFF) as f32 / 65_536.0,
                    seed: (key >> 32) as u32,
                }
            })
            .collect();
        let n = instances.len() * tree.segments.len();
        let g = if gpu {
            Some(sylva_gpu::pose::GpuZioma::with_instances(ctx, tree, &method, wind, &instances)?)
        } else {
            None
        };
        Ok(Self {
            transforms: Renderer::instances(ctx, placements),
            skin: GpuSkin::new(ctx, layout, &SkinLayout::new(layout), instances.len() as u32)?,
            joint: sylva_gpu::kernel::output::<[f32; 4]>(ctx, "forest joints", n)?,
            acc: sylva_gpu::kernel::output::<[f32; 4]>(ctx, "forest rotations", n)?,
            method,
            instances,
            gpu: g,
        })
    }

    fn frame(
        &self,
        ctx: &GpuContext,
        tree: &Tree,
        wind: (&[RawField], &[RawWave]),
        t: f32,
        encoder: &mut wgpu::CommandEncoder,
    ) {
        match &self.gpu {
            Some(g) => {
                g.submit(ctx, tree, &self.method, t);
                self.skin.record(ctx, encoder, g.gpu_pose().joints_buffer(), g.gpu_pose().acc_buffer());
            }
            None => {
                let delta = self.method.rotations_instances(tree, wind.0, wind.1, t, &self.instances);
                let (joint, acc) = seam_buffers(tree, &delta);
                ctx.queue.write_buffer(&self.joint, 0, bytemuck::cast_slice(&joint));
                ctx.queue.write_buffer(&self.acc, 0, bytemuck::cast_slice(&acc));
                self.skin.record(ctx, encoder, &self.joint, &self.acc);
            }
        }
    }
}

/// One simulation and its mesh, drawn at every instance dealt to it.
struct Group {
    anim: Anim,
    mesh: GpuMesh,
    /// Skjermo's bark from the deformer.
    deform: Option<GpuDeform>,
    instances: wgpu::Buffer,
    count: u32,
    /// Extra pre-roll steps: the group's phase offset in the wind.
    lead_steps: usize,
}

impl Group {
    #[allow(clippy::too_many_arguments)]
    fn advance(
        &mut self,
        ctx: &GpuContext,
        tree: &Tree,
        wind: (&[RawField], &[RawWave]),
        t: f32,
        dt: f32,
        steps: usize,
        encoder: &mut wgpu::CommandEncoder,
    ) -> Result<()> {
        self.anim.advance_and_mesh(ctx, tree, wind, t, dt, steps, &self.mesh, encoder)?;
        if let Some(d) = &self.deform {
            self.anim.record_deform(ctx, encoder, d);
        }
        Ok(())
    }
}

/// A tree of the scene as it is animated and drawn.
enum Drawn {
    /// Independent simulations (phase groups), each with its own mesh drawn at its
    /// instances.
    Groups(Vec<Group>),
    /// Zioma's copies: skinned instances, each with its own pose.
    Forest(Box<ZiomaForest>),
}

impl Anim {
    /// Records Skjermo's deformer on the method's current curves (§3: the bark follows the
    /// animated Béziers); nothing for other methods.
    fn record_deform(&self, ctx: &GpuContext, encoder: &mut wgpu::CommandEncoder, deform: &GpuDeform) {
        match self {
            Self::SkjermoCpu(_, s) => deform.record_state(ctx, encoder, &s.stems),
            Self::SkjermoGpu(g) => deform.record(ctx, encoder, g.stems_buffer(), g.state_buffer()),
            _ => {}
        }
    }
}

/// A temporary file renamed into place on success and removed otherwise.
struct Pending {
    tmp: PathBuf,
    path: PathBuf,
    done: bool,
}

impl Pending {
    fn new(path: &Path) -> Self {
        let name = path.file_name().map(|n| n.to_string_lossy().into_owned()).unwrap_or_default();
        // The extension is kept last: encoders pick the format from it.
        let ext = path.extension().map(|e| e.to_string_lossy().into_owned()).unwrap_or_default();
        let tmp = path.with_file_name(format!(".{name}.tmp-{}.{ext}", std::process::id()));
        Self { tmp, path: path.to_path_buf(), done: false }
    }

    fn commit(mut self) -> Result<()> {
        std::fs::rename(&self.tmp, &self.path).with_context(|| format!("writing {}", self.path.display()))?;
        self.done = true;
        Ok(())
    }
}

impl Drop for Pending {
    fn drop(&mut self) {
        if !self.done {
            let _ = std::fs::remove_file(&self.tmp);
        }
    }
}

fn instance(position: [f32; 3], yaw_deg: f32, scale: f32, tint: Vec3) -> Instance {
    Instance {
        transform: Mat4::from_scale_rotation_translation(
            Vec3::splat(scale),
            Quat::from_rotation_y(yaw_deg.to_radians()),
            Vec3::from_array(position),
        ),
        tint,
    }
}

fn ffmpeg_available() -> bool {
    std::process::Command::new("ffmpeg")
        .arg("-version")
        .stdout(std::process::Stdio::null())
        .stderr(std::process::Stdio::null())
        .status()
        .is_ok_and(|s| s.success())
}

/// Draws labels (white on a dark shadow) onto an RGBA image.
fn draw_labels(rgba: &mut [u8], w: u32, h: u32, labels: &[(String, f32, f32)]) -> Result<()> {
    use plotters::prelude::*;
    use plotters::style::text_anchor::{HPos, Pos, VPos};
    let mut rgb: Vec<u8> = rgba.chunks(4).flat_map(|p| [p[0], p[1], p[2]]).collect();
    {
        let root = BitMapBackend::with_buffer(&mut rgb, (w, h)).into_drawing_area();
        let size = (h as f64 / 30.0).clamp(10.0, 40.0);
        for (text, x, y) in labels {
            let (x, y) = (*x as i32, *y as i32);
            let pos = Pos::new(HPos::Center, VPos::Top);
            for (dx, c) in [(1, RGBColor(20, 20, 20)), (0, RGBColor(250, 250, 245))] {
                let style = TextStyle::from(("sans-serif", size).into_font()).color(&c).pos(pos);
                root.draw(&Text::new(text.as_str(), (x + dx, y + dx), style))
                    .map_err(|e| anyhow::anyhow!("drawing a label: {e}"))?;
            }
        }
        root.present().map_err(|e| anyhow::anyhow!("drawing labels: {e}"))?;
    }
    for (d, s) in rgba.chunks_mut(4).zip(rgb.chunks(3)) {
        d[..3].copy_from_slice(s);
    }
    Ok(())
}

/// Runs the command.
pub fn run(a: &RenderArgs) -> Result<()> {
    let mut scene = match &a.scene {
        Some(p) => Scene::load(p)?,
        None => Scene::default_scene(),
    };
    if let Some(d) = &a.out_dir {
        scene.output.dir = d.clone();
    }
    if let Some(v) = a.width {
        scene.output.width = v;
    }
    if let Some(v) = a.height {
        scene.output.height = v;
    }
    if let Some(v) = a.seconds {
        scene.output.seconds = v;
    }
    if let Some(v) = a.fps {
        scene.output.fps = v;
    }
    if a.no_mp4 {
        scene.output.mp4 = false;
    }
    if a.no_png {
        scene.output.png = false;
    }
    if let Some(b) = a.backend {
        for t in &mut scene.trees {
            t.backend = match b {
                BackendArg::Auto => BackendChoice::Auto,
                BackendArg::Cpu => BackendChoice::Cpu,
                BackendArg::Gpu => BackendChoice::Gpu,
            };
        }
    }
    scene.check().map_err(|(field, value, expected)| {
        anyhow::anyhow!("{}: field `{field}` = {value}: expected {expected}", scene.file)
    })?;
    let interrupted = Arc::new(AtomicBool::new(false));
    {
        let flag = interrupted.clone();
        // A second handler cannot be installed (tests call `run` once per process).
        let _ = ctrlc::set_handler(move || flag.store(true, Ordering::SeqCst));
    }
    render(&scene, &interrupted)
}

fn render(scene: &Scene, interrupted: &AtomicBool) -> Result<()> {
    let o = &scene.output;
    let ctx = GpuContext::shared()?;
    let software = ctx.summary.device_type == "Cpu";
    println!("GPU: {}", ctx.summary);
    let wind = WindScene::resolve(&scene.resolve_path(&scene.wind))
        .with_context(|| format!("{}: field `wind`", scene.file))?;
    let (fields, waves) = wind.pack();

    struct Entry {
        tree: Tree,
        drawn: Drawn,
        label: String,
        base: Vec3,
    }
    impl Entry {
        /// Advances every simulation `steps` steps (plus its phase lead when `preroll`).
        #[allow(clippy::too_many_arguments)]
        fn advance(
            &mut self,
            ctx: &GpuContext,
            wind: (&[RawField], &[RawWave]),
            t: f32,
            dt: f32,
            steps: usize,
            preroll: bool,
            encoder: &mut wgpu::CommandEncoder,
        ) -> Result<()> {
            match &mut self.drawn {
                Drawn::Groups(groups) => {
                    for g in groups {
                        let lead = if preroll { g.lead_steps } else { 0 };
                        g.advance(ctx, &self.tree, wind, t, dt, steps + lead, encoder)?;
                    }
                    Ok(())
                }
                Drawn::Forest(f) => {
                    f.frame(ctx, &self.tree, wind, t, encoder);
                    Ok(())
                }
            }
        }
    }
    let steps = (o.sim_rate / o.fps).round().max(1.0) as usize;
    let dt = 1.0 / (o.fps * steps as f32);
    let setup = Instant::now();
    let mut entries = Vec::new();
    let (mut lo, mut hi) = (Vec3::splat(f32::INFINITY), Vec3::splat(f32::NEG_INFINITY));
    let mut triangles = 0usize;
    for (i, st) in scene.trees.iter().enumerate() {
        let species = scene.resolve_path(&st.species);
        let source =
            SpeciesSource::resolve(&species).with_context(|| format!("{}: field `tree[{i}].species`", scene.file))?;
        let tree = source.generate(st.seed, &Limits::default(), None)?;
        let gpu = match st.backend {
            BackendChoice::Auto => !software,
            BackendChoice::Cpu => false,
            BackendChoice::Gpu => true,
        };
        let defaults = MeshParams::default();
        let params = MeshParams {
            sides: st.sides.unwrap_or(defaults.sides),
            leaf_sides: st.leaf_sides.unwrap_or(defaults.leaf_sides),
            ..defaults
        };
        let layout = MeshLayout::new(&tree, params)?;
        let tint = Vec3::from_array(st.tint.unwrap_or([0.28, 0.50, 0.12]));
        let mut inst = vec![instance(st.position, st.yaw_deg, st.scale, tint)];
        inst.extend(st.copies.iter().map(|c| instance(c.position, c.yaw_deg, c.scale, tint * 1.05)));
        let (tlo, thi) = tree.bounds();
        for i in &inst {
            for k in 0..8 {
                let corner = Vec3::new(
                    if k & 1 == 0 { tlo.x } else { thi.x },
                    if k & 2 == 0 { tlo.y } else { thi.y },
                    if k & 4 == 0 { tlo.z } else { thi.z },
                );
                let p = i.transform.transform_point3(corner);
                lo = lo.min(p);
                hi = hi.max(p);
            }
        }
        let label = st.label.clone().unwrap_or_else(|| {
            format!("{} · {} ({})", tree.name.replace('_', " "), st.method.as_str(), if gpu { "GPU" } else { "CPU" })
        });
        let mut bark_triangles = layout.tube_indices.len() / 3;
        let groups = st.phase_groups();
        let drawn = if st.method == MethodName::Zioma && inst.len() > 1 {
            Drawn::Forest(Box::new(ZiomaForest::new(ctx, &tree, &layout, &inst, gpu, st.seed, &wind)?))
        } else {
            let grid = if st.method == MethodName::Skjermo {
                let grid = DeformLayout::new(&tree, DeformerParams { sides: params.sides, ..Default::default() })?;
                bark_triangles = grid.triangle_count();
                Some((grid, Skjermo::new(&tree, SkjermoParams::default())))
            } else {
                None
            };
            let mut built = Vec::new();
            for group in &groups {
                let members: Vec<Instance> = group.members.iter().map(|&k| inst[k]).collect();
                built.push(Group {
                    anim: Anim::new(ctx, &tree, st.method, gpu, st.seed, &wind)?,
                    mesh: GpuMesh::new(ctx, &layout)?,
                    deform: match &grid {
                        Some((grid, m)) => Some(GpuDeform::new(ctx, grid, &m.stems)?),
                        None => None,
                    },
                    instances: Renderer::instances(ctx, &members),
                    count: members.len() as u32,
                    lead_steps: (group.offset_s / dt).round() as usize,
                });
            }
            Drawn::Groups(built)
        };
        let tree_triangles = bark_triangles + layout.leaf_indices.len() / 3;
        triangles += tree_triangles * inst.len();
        let simulations = match &drawn {
            Drawn::Groups(g) if g.len() > 1 => format!(" in {} simulations", g.len()),
            _ => String::new(),
        };
        println!(
            "  {:<18} {:>6} segments {:>7} leaves  {:>8} triangles × {} instance(s){simulations}  {}",
            tree.name,
            tree.segments.len(),
            tree.leaves.len(),
            tree_triangles,
            inst.len(),
            label
        );
        // Poses are in the tree's own frame (skinned instances sample the wind at their
        // placement and turn it by their yaw); the instance transforms place them.
        entries.push(Entry { tree, drawn, label, base: Vec3::from_array(st.position) });
    }
    let renderer =
        Renderer::new(ctx, RenderSettings { width: o.width, height: o.height, msaa: o.msaa, ..Default::default() })?;
    let camera = Camera {
        eye: Vec3::from_array(scene.camera.eye),
        target: Vec3::from_array(scene.camera.target),
        fov_y_deg: scene.camera.fov_deg,
    };
    let light = Lighting {
        sun_direction: Vec3::from_array(scene.sun.direction).normalize(),
        sun_intensity: scene.sun.intensity,
        ..Default::default()
    };
    let globals = renderer.globals(&camera, &light, (lo, hi));
    let view_proj = camera.view_proj(o.width as f32 / o.height as f32);
    let labels: Vec<(String, f32, f32)> = if o.labels {
        entries
            .iter()
            .enumerate()
            .filter_map(|(k, e)| {
                let c = view_proj * e.base.extend(1.0);
                // Alternate rows so neighbours' labels do not overlap.
                let row = (k % 2) as f32 * (o.height as f32 / 26.0).clamp(12.0, 44.0);
                (c.w > 0.0).then(|| {
                    let n = c.truncate() / c.w;
                    let (x, y) = ((n.x * 0.5 + 0.5) * o.width as f32, (0.5 - n.y * 0.5) * o.height as f32);
                    (e.label.clone(), x, y + 6.0 + row)
                })
            })
            .collect()
    } else {
        Vec::new()
    };
    if o.labels {
        let _ = plotters::style::register_font("sans-serif", plotters::style::FontStyle::Normal, crate::wind_cmd::FONT);
    }

    std::fs::create_dir_all(&o.dir).with_context(|| format!("creating {}", o.dir.display()))?;
    let frames_dir = o.dir.join("frames");
    if o.png {
        std::fs::create_dir_all(&frames_dir).with_context(|| format!("creating {}", frames_dir.display()))?;
    }
    let frames = scene.frames();
    let gif_path = o.dir.join(format!("{}.gif", o.name));
    let gif_pending = o.gif.then(|| Pending::new(&gif_path));
    let mut gif = match &gif_pending {
        Some(p) => {
            let f = std::fs::File::create(&p.tmp).with_context(|| format!("creating {}", p.tmp.display()))?;
            let mut enc = image::codecs::gif::GifEncoder::new_with_speed(std::io::BufWriter::new(f), 10);
            enc.set_repeat(image::codecs::gif::Repeat::Infinite)?;
            Some(enc)
        }
        None => None,
    };
    let mp4_path = o.dir.join(format!("{}.mp4", o.name));
    let mp4_pending = (o.mp4 && ffmpeg_available()).then(|| Pending::new(&mp4_path));
    let mut ffmpeg = match &mp4_pending {
        Some(p) => Some(
            std::process::Command::new("ffmpeg")
                .args(["-loglevel", "error", "-y", "-f", "rawvideo", "-pix_fmt", "rgba", "-s"])
                .arg(format!("{}x{}", o.width, o.height))
                .args(["-r", &o.fps.to_string(), "-i", "-", "-c:v", "libx264", "-pix_fmt", "yuv420p"])
                .args(["-vf", "pad=ceil(iw/2)*2:ceil(ih/2)*2", "-movflags", "+faststart", "-f", "mp4"])
                .arg(&p.tmp)
                .stdin(std::process::Stdio::piped())
                .spawn()
                .context("starting ffmpeg")?,
        ),
        None => None,
    };

    // Pre-roll: stateful methods start at rest; let the wind move them first.
    // Phase groups pre-roll further, each by its own lead.
    let preroll_steps = (o.preroll * o.fps * steps as f32).round() as usize;
    let leads = entries.iter().any(|e| matches!(&e.drawn, Drawn::Groups(g) if g.iter().any(|g| g.lead_steps > 0)));
    let prerolled = preroll_steps > 0 || leads;
    let mut t = 0.0f32;
    if prerolled {
        let mut encoder = ctx.device.create_command_encoder(&Default::default());
        t = preroll_steps as f32 * dt;
        for e in &mut entries {
            e.advance(ctx, (&fields, &waves), t, dt, preroll_steps, true, &mut encoder)?;
        }
        ctx.queue.submit([encoder.finish()]);
    }
    println!("set up in {:.2} s; {} triangles per frame", setup.elapsed().as_secs_f64(), triangles);

    let bar = ProgressBar::new(frames as u64);
    bar.set_style(
        ProgressStyle::with_template("{bar:40} {pos}/{len} frames {elapsed} (eta {eta})").expect("valid template"),
    );
    let start = Instant::now();
    let (mut sim_s, mut draw_s, mut encode_s) = (0.0f64, 0.0f64, 0.0f64);
    for f in 0..frames {
        if interrupted.load(Ordering::SeqCst) {
            bar.abandon();
            bail!("interrupted after {f} of {frames} frames; no partial animation was written");
        }
        let t0 = Instant::now();
        let mut encoder = ctx.device.create_command_encoder(&Default::default());
        let advance = if f == 0 && prerolled { 0 } else { steps };
        t += advance as f32 * dt;
        for e in &mut entries {
            e.advance(ctx, (&fields, &waves), t, dt, advance, false, &mut encoder)?;
        }
        let t1 = Instant::now();
        let items: Vec<DrawItem<'_>> = entries
            .iter()
            .flat_map(|e| match &e.drawn {
                Drawn::Groups(groups) => groups
                    .iter()
                    .map(|g| {
                        let mut item = g.mesh.draw_item(&g.instances, g.count);
                        if let Some(d) = &g.deform {
                            item.bark = d.bark();
                        }
                        item
                    })
                    .collect::<Vec<_>>(),
                Drawn::Forest(f) => f.skin.draw_items(&f.transforms),
            })
            .collect();
        renderer.record(ctx, &mut encoder, &globals, &items);
        let mut rgba = renderer.read_image(ctx, encoder)?;
        let t2 = Instant::now();
        draw_labels(&mut rgba, o.width, o.height, &labels)?;
        let img = image::RgbaImage::from_raw(o.width, o.height, rgba).context("image size")?;
        if o.png {
            let path = frames_dir.join(format!("{}_{f:04}.png", o.name));
            let p = Pending::new(&path);
            img.save(&p.tmp).with_context(|| format!("writing {}", p.tmp.display()))?;
            p.commit()?;
        }
        if let Some(enc) = &mut gif {
            let delay = image::Delay::from_numer_denom_ms(1000, o.fps.round().max(1.0) as u32);
            enc.encode_frame(image::Frame::from_parts(img.clone(), 0, 0, delay))?;
        }
        if let Some(child) = &mut ffmpeg {
            child.stdin.as_mut().context("ffmpeg stdin")?.write_all(img.as_raw()).context("feeding ffmpeg")?;
        }
        sim_s += (t1 - t0).as_secs_f64();
        draw_s += (t2 - t1).as_secs_f64();
        encode_s += t2.elapsed().as_secs_f64();
        bar.inc(1);
    }
    bar.finish_and_clear();
    if let Some(enc) = gif {
        drop(enc);
    }
    if let Some(p) = gif_pending {
        p.commit()?;
        println!("wrote {}", gif_path.display());
    }
    if let (Some(mut child), Some(p)) = (ffmpeg, mp4_pending) {
        drop(child.stdin.take());
        let status = child.wait().context("waiting for ffmpeg")?;
        if !status.success() {
            bail!("ffmpeg failed ({status}); no MP4 written");
        }
        p.commit()?;
        println!("wrote {}", mp4_path.display());
    }
    if o.png {
        println!("wrote {} frames to {}", frames, frames_dir.display());
    }
    let n = frames as f64;
    println!(
        "{frames} frames of {}×{} in {:.2} s: {:.1} ms per frame (simulate + mesh recording {:.1}, GPU mesh + draw + readback {:.1}, labels + encoding {:.1})",
        o.width,
        o.height,
        start.elapsed().as_secs_f64(),
        1e3 * start.elapsed().as_secs_f64() / n,
        1e3 * sim_s / n,
        1e3 * draw_s / n,
        1e3 * encode_s / n
    );
    Ok(())
}
