//! A scene as it runs: every `[[tree]]` grown, animated by its method (CPU or GPU), meshed
//! on the GPU every frame and handed to the renderer as draw items. Shared by `sylva
//! render` (frames to files) and `sylva view` (the interactive window).

// Wind edits, poses and placement serve the viewer only.
#![cfg_attr(not(feature = "viewer"), allow(dead_code))]

use anyhow::{Context, Result};
use glam::{Mat4, Quat, Vec3};
use std::borrow::Cow;
use sylva_core::mesh::{DeformLayout, DeformerParams, MeshLayout, MeshParams, SkinLayout};
use sylva_core::methods::akagi::{Akagi, AkagiParams, AkagiState};
use sylva_core::methods::hsm::{Hsm, HsmParams, HsmState};
use sylva_core::methods::skjermo::{Skjermo, SkjermoParams, SkjermoState};
use sylva_core::methods::zioma::{Zioma, ZiomaInstance, ZiomaParams};
use sylva_core::pose::{Pose, seam_buffers};
use sylva_core::scene::{BackendChoice, MethodName, Scene, SceneTree};
use sylva_core::species::SpeciesSource;
use sylva_core::wind::raw::{RawField, RawWave};
use sylva_core::wind::{WindField, WindScene};
use sylva_core::{Limits, Tree};
use sylva_gpu::GpuContext;
use sylva_gpu::deform::GpuDeform;
use sylva_gpu::mesh::GpuMesh;
use sylva_gpu::render::{DrawItem, Instance, Renderer};
use sylva_gpu::skin::GpuSkin;

/// Most GPU memory a tree's skinned instances (Zioma copies) may take: beyond this a scene
/// asks for more vertex memory than most GPUs have to spare.
pub(crate) const MAX_SKINNED_BYTES: u64 = 2 << 30;

/// One tree's animation, on the CPU or the GPU.
enum Anim {
    ZiomaCpu(Zioma),
    ZiomaGpu(Zioma, sylva_gpu::pose::GpuZioma),
    AkagiCpu(Akagi, Box<AkagiState>),
    AkagiGpu(sylva_gpu::pose::GpuAkagi),
    SkjermoCpu(Skjermo, Box<SkjermoState>),
    SkjermoGpu(Box<Skjermo>, sylva_gpu::pose::GpuSkjermo),
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
                let g = sylva_gpu::pose::GpuSkjermo::new(ctx, tree, &m, wind)?;
                Self::SkjermoGpu(Box::new(m), g)
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
            Self::SkjermoGpu(_, g) => {
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
                    Self::SkjermoGpu(_, g) => g.gpu_pose(),
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
    /// The offset in seconds: this group's clock runs this far ahead of the scene's.
    lead_s: f32,
    /// The group's own wind when live effects must reach it on its clock (see
    /// [`Entry::set_wind`]); the shared wind otherwise.
    own_wind: Option<(Vec<RawField>, Vec<RawWave>)>,
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
    /// Hands a new wind to a GPU method (CPU methods read it every step).
    fn set_wind(&mut self, ctx: &GpuContext, wind: &WindScene) -> Result<()> {
        match self {
            Self::ZiomaGpu(_, g) => g.set_wind(ctx, wind)?,
            Self::AkagiGpu(g) => g.set_wind(ctx, wind)?,
            Self::SkjermoGpu(_, g) => g.set_wind(ctx, wind)?,
            Self::HsmGpu(_, g) => g.set_wind(ctx, wind)?,
            _ => {}
        }
        Ok(())
    }

    /// The current pose (read back from the GPU for GPU methods; Zioma's at time `t`).
    fn pose(&self, ctx: &GpuContext, tree: &Tree, wind: (&[RawField], &[RawWave]), t: f32) -> Result<Pose> {
        Ok(match self {
            Self::ZiomaCpu(m) => m.pose_packed(tree, wind.0, wind.1, t),
            Self::ZiomaGpu(m, g) => g.pose(ctx, tree, m, t)?,
            Self::AkagiCpu(_, s) => s.pose.clone(),
            Self::AkagiGpu(g) => g.read(ctx)?,
            Self::SkjermoCpu(_, s) => s.pose.clone(),
            Self::SkjermoGpu(m, g) => g.read(ctx, m)?,
            Self::HsmCpu(m, s) => m.pose(tree, s),
            Self::HsmGpu(_, g) => g.read_pose(ctx)?.context("HSM on the GPU was built without its tree")?,
        })
    }
}

impl Anim {
    /// Records Skjermo's deformer on the method's current curves (§3: the bark follows the
    /// animated Béziers); nothing for other methods.
    fn record_deform(&self, ctx: &GpuContext, encoder: &mut wgpu::CommandEncoder, deform: &GpuDeform) {
        match self {
            Self::SkjermoCpu(_, s) => deform.record_state(ctx, encoder, &s.stems),
            Self::SkjermoGpu(_, g) => deform.record(ctx, encoder, g.stems_buffer(), g.state_buffer()),
            _ => {}
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

/// One `[[tree]]` of a scene as it is animated and drawn.
pub(crate) struct Entry {
    /// The grown tree.
    pub tree: Tree,
    drawn: Drawn,
    /// Its label.
    pub label: String,
    /// Its position (the labels' anchor).
    pub base: Vec3,
    /// The first instance's transform (the tree itself).
    pub transform: Mat4,
    /// Scene-space bounds of all its instances.
    pub bounds: (Vec3, Vec3),
    /// Triangles drawn per frame, all instances.
    pub triangles: usize,
    /// Instances drawn.
    pub instances: usize,
    /// Independent simulations.
    pub simulations: usize,
}
impl Entry {
    /// Advances every simulation `steps` steps (plus its phase lead when `preroll`).
    #[allow(clippy::too_many_arguments)]
    pub(crate) fn advance(
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
                    let own = g.own_wind.take();
                    let w = own.as_ref().map_or(wind, |(f, w)| (&f[..], &w[..]));
                    let done = g.advance(ctx, &self.tree, w, t, dt, steps + lead, encoder);
                    g.own_wind = own;
                    done?;
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

impl Entry {
    /// Grows, lays out and sets up tree `i` of `scene` (`st`, which may differ from
    /// `scene.trees[i]` when a viewer edits it): its method on the CPU or the GPU (`auto`:
    /// GPU unless the adapter is a software rasteriser), its meshes, and the phase groups
    /// of its copies (`dt` converts their offsets to steps).
    pub(crate) fn build(
        ctx: &GpuContext,
        scene: &Scene,
        i: usize,
        st: &SceneTree,
        wind: &WindScene,
        dt: f32,
    ) -> Result<Self> {
        let software = ctx.summary.device_type == "Cpu";
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
        let (mut lo, mut hi) = (Vec3::splat(f32::INFINITY), Vec3::splat(f32::NEG_INFINITY));
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
            let vertices = layout.tube_vertex_count() + layout.leaf_vertex_count();
            let bytes = (vertices * std::mem::size_of::<sylva_core::mesh::RawVertex>() * inst.len()) as u64;
            if bytes > MAX_SKINNED_BYTES {
                anyhow::bail!(
                    "{}: tree[{i}]: {} skinned instances of {vertices} vertices need {:.1} GiB of vertex buffers; \
                     at most {} GiB: use fewer copies, fewer `sides`/`leaf_sides`, or a stateful method \
                     (whose copies share their simulations' meshes)",
                    scene.file,
                    inst.len(),
                    bytes as f64 / (1u64 << 30) as f64,
                    MAX_SKINNED_BYTES >> 30
                );
            }
            Drawn::Forest(Box::new(ZiomaForest::new(ctx, &tree, &layout, &inst, gpu, st.seed, wind)?))
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
                    anim: Anim::new(ctx, &tree, st.method, gpu, st.seed, wind)?,
                    mesh: GpuMesh::new(ctx, &layout)?,
                    deform: match &grid {
                        Some((grid, m)) => Some(GpuDeform::new(ctx, grid, &m.stems)?),
                        None => None,
                    },
                    instances: Renderer::instances(ctx, &members),
                    count: members.len() as u32,
                    lead_steps: (group.offset_s / dt).round() as usize,
                    lead_s: (group.offset_s / dt).round() * dt,
                    own_wind: None,
                });
            }
            Drawn::Groups(built)
        };
        let tree_triangles = bark_triangles + layout.leaf_indices.len() / 3;
        let simulations = match &drawn {
            Drawn::Groups(g) => g.len(),
            Drawn::Forest(_) => 1,
        };
        // Poses are in the tree's own frame (skinned instances sample the wind at their
        // placement and turn it by their yaw); the instance transforms place them.
        Ok(Entry {
            base: Vec3::from_array(st.position),
            transform: inst[0].transform,
            bounds: (lo, hi),
            triangles: tree_triangles * inst.len(),
            instances: inst.len(),
            simulations,
            tree,
            drawn,
            label,
        })
    }

    /// One line for a console: counts, instances, simulations, label.
    pub(crate) fn summary(&self) -> String {
        let simulations =
            if self.simulations > 1 { format!(" in {} simulations", self.simulations) } else { String::new() };
        format!(
            "  {:<18} {:>6} segments {:>7} leaves  {:>8} triangles × {} instance(s){simulations}  {}",
            self.tree.name,
            self.tree.segments.len(),
            self.tree.leaves.len(),
            self.triangles / self.instances.max(1),
            self.instances,
            self.label
        )
    }

    /// What the renderer draws for this tree.
    pub(crate) fn draw_items(&self) -> Vec<DrawItem<'_>> {
        match &self.drawn {
            Drawn::Groups(groups) => groups
                .iter()
                .map(|g| {
                    let mut item = g.mesh.draw_item(&g.instances, g.count);
                    if let Some(d) = &g.deform {
                        item.bark = d.bark();
                    }
                    item
                })
                .collect(),
            Drawn::Forest(f) => f.skin.draw_items(&f.transforms),
        }
    }

    /// Hands a new wind to every GPU simulation of this tree.
    /// `wind` is the scene's wind; `effects` (blasts, vortices, pushes placed live, times on
    /// the scene's clock) are added to it. A phase group whose clock runs ahead gets the
    /// effects shifted onto its clock, so a blast reaches every copy at the same moment.
    pub(crate) fn set_wind(&mut self, ctx: &GpuContext, wind: &WindScene, effects: &[WindField]) -> Result<()> {
        let on_clock = |lead: f32| {
            let mut w = wind.clone();
            w.fields.extend(effects.iter().cloned().map(|mut f| {
                match &mut f {
                    WindField::Blast(b) => b.start += lead,
                    WindField::Vortex(v) => v.start += lead,
                    WindField::GustFront(g) => g.start += lead,
                    _ => {}
                }
                f
            }));
            w
        };
        match &mut self.drawn {
            Drawn::Groups(groups) => {
                for g in groups {
                    let w = on_clock(g.lead_s);
                    g.anim.set_wind(ctx, &w)?;
                    g.own_wind = (g.lead_s != 0.0 && !effects.is_empty()).then(|| w.pack());
                }
            }
            Drawn::Forest(f) => {
                if let Some(g) = &mut f.gpu {
                    g.set_wind(ctx, &on_clock(0.0))?;
                }
            }
        }
        Ok(())
    }

    /// The pose of the first instance (the tree itself), in the tree's frame; read back from
    /// the GPU for GPU methods.
    pub(crate) fn pose(&self, ctx: &GpuContext, wind: (&[RawField], &[RawWave]), t: f32) -> Result<Pose> {
        Ok(match &self.drawn {
            Drawn::Groups(groups) => groups[0].anim.pose(ctx, &self.tree, wind, t)?,
            Drawn::Forest(f) => {
                let delta = f.method.rotations_instances(&self.tree, wind.0, wind.1, t, &f.instances[..1]);
                Pose::from_rotations_instances(&self.tree, &delta).swap_remove(0)
            }
        })
    }

    /// HSM's particles per simulation (`None` for the other methods).
    pub(crate) fn particles(&self) -> Option<usize> {
        let Drawn::Groups(groups) = &self.drawn else { return None };
        match &groups[0].anim {
            Anim::HsmCpu(m, _) | Anim::HsmGpu(m, _) => Some(m.layout.particle_count()),
            _ => None,
        }
    }

    /// HSM's cluster centres of mass in the first simulation, in the tree's frame; `None`
    /// for the other methods.
    pub(crate) fn clusters(&self, ctx: &GpuContext) -> Result<Option<Vec<Vec3>>> {
        let Drawn::Groups(groups) = &self.drawn else { return Ok(None) };
        let state = match &groups[0].anim {
            Anim::HsmCpu(_, s) => Cow::Borrowed(&**s),
            Anim::HsmGpu(_, g) => Cow::Owned(g.read_state(ctx)?),
            _ => return Ok(None),
        };
        Ok(Some(state.clusters.iter().map(|c| Vec3::new(c.cm[0], c.cm[1], c.cm[2])).collect()))
    }

    /// [`Entry::displacement`] of every simulation (phase group), each on its own clock.
    pub(crate) fn group_displacements(
        &self,
        ctx: &GpuContext,
        wind: (&[RawField], &[RawWave]),
        t: f32,
    ) -> Result<Vec<f32>> {
        let Drawn::Groups(groups) = &self.drawn else { return Ok(vec![self.displacement(ctx, wind, t)?]) };
        groups.iter().map(|g| Ok(self.distance_from_rest(&g.anim.pose(ctx, &self.tree, wind, t + g.lead_s)?))).collect()
    }

    /// Mean distance of the segments' joints from rest, m, in the tree's first simulation
    /// (the instance itself): how far the wind has moved it.
    pub(crate) fn displacement(&self, ctx: &GpuContext, wind: (&[RawField], &[RawWave]), t: f32) -> Result<f32> {
        Ok(self.distance_from_rest(&self.pose(ctx, wind, t)?))
    }

    /// Mean distance of `pose`'s joints from the tree's rest joints, m.
    fn distance_from_rest(&self, pose: &Pose) -> f32 {
        let rest = &self.tree.segments.start;
        pose.start.iter().zip(rest).map(|(p, r)| p.distance(*r)).sum::<f32>() / rest.len().max(1) as f32
    }

    /// Whether any phase group pre-rolls further than the scene.
    pub(crate) fn has_leads(&self) -> bool {
        matches!(&self.drawn, Drawn::Groups(g) if g.iter().any(|g| g.lead_steps > 0))
    }
}
