//! One `[[tree]]` of a scene as it runs: grown, animated by its method on the CPU or the GPU,
//! meshed on the GPU every frame and drawn at every one of its instances.
//!
//! * A method that poses every instance on its own (Zioma) with copies: one simulation
//!   posing them all, and one rest mesh skinned per instance (Zioma §6.5).
//! * Otherwise the instances are dealt among the tree's phase groups: each an independent
//!   simulation started at its own point of the wind, whose mesh is drawn at its instances.
//! * A method that bends curves (Skjermo) has its bark built by the deformer (§3).

use crate::RuntimeError;
use crate::registry::MethodRegistry;
use crate::wind::{ClockWind, WorldWind};
use glam::{Mat4, Quat, Vec3};
use std::sync::Arc;
use sylva_core::Tree;
use sylva_core::mesh::{DeformLayout, DeformerParams, MeshLayout, MeshParams, RawVertex, SkinLayout};
use sylva_core::methods::{Animator, MethodOptions};
use sylva_core::model::LeafShape;
use sylva_core::pose::{Placement, Pose, SeamPose};
use sylva_core::scene::{BackendChoice, Scene, SceneTree};
use sylva_core::species::SpeciesSource;
use sylva_gpu::mesh::GpuMesh;
use sylva_gpu::mesh::deform::GpuDeform;
use sylva_gpu::mesh::skin::GpuSkin;
use sylva_gpu::methods::GpuAnimator;
use sylva_gpu::render::{DrawItem, Instance, Renderer};
use sylva_gpu::{GpuContext, GpuError};

/// Most GPU memory a tree's skinned instances may take: beyond this a scene asks for more
/// vertex memory than most GPUs have to spare.
pub const MAX_SKINNED_BYTES: u64 = 2 << 30;

/// A simulation on the CPU or the GPU.
#[derive(Debug)]
pub enum Simulation {
    /// The CPU reference.
    Cpu(Box<dyn Animator>),
    /// The GPU twin.
    Gpu(Box<dyn GpuAnimator>),
}

impl Simulation {
    fn set_wind(&mut self, wind: &ClockWind) {
        match self {
            Self::Cpu(a) => a.set_wind(wind.packed.clone()),
            Self::Gpu(g) => g.set_wind(&wind.gpu),
        }
    }

    fn advance(&mut self, ctx: &GpuContext, dt: f32, steps: usize) {
        match self {
            Self::Cpu(a) => a.advance(dt, steps),
            Self::Gpu(g) => g.advance(ctx, dt, steps),
        }
    }

    fn reset(&mut self, ctx: &GpuContext, time: f32) {
        match self {
            Self::Cpu(a) => a.reset(time),
            Self::Gpu(g) => g.reset(ctx, time),
        }
    }

    /// The method's name.
    pub fn name(&self) -> &'static str {
        match self {
            Self::Cpu(a) => a.name(),
            Self::Gpu(g) => g.name(),
        }
    }

    /// Simulated time, s (the scene's plus the simulation's lead).
    pub fn time(&self) -> f32 {
        match self {
            Self::Cpu(a) => a.time(),
            Self::Gpu(g) => g.time(),
        }
    }

    /// The current pose (the first instance; read back for GPU methods).
    pub fn pose(&self, ctx: &GpuContext) -> Result<Pose, GpuError> {
        match self {
            Self::Cpu(a) => Ok(a.pose()),
            Self::Gpu(g) => g.read_pose(ctx),
        }
    }

    /// Debug data: cluster centres in the tree's frame, for methods that have clusters.
    pub fn cluster_centres(&self, ctx: &GpuContext) -> Result<Option<Vec<Vec3>>, GpuError> {
        match self {
            Self::Cpu(a) => Ok(a.cluster_centres()),
            Self::Gpu(g) => g.cluster_centres(ctx),
        }
    }

    /// Particles simulated, for particle methods.
    pub fn particles(&self) -> Option<usize> {
        match self {
            Self::Cpu(a) => a.particles(),
            Self::Gpu(g) => g.particles(),
        }
    }

    fn has_curves(&self) -> bool {
        match self {
            Self::Cpu(a) => a.curves().is_some(),
            Self::Gpu(g) => g.curves().is_some(),
        }
    }
}

/// One simulation and its mesh, drawn at every instance dealt to it.
#[derive(Debug)]
struct Group {
    sim: Simulation,
    mesh: GpuMesh,
    /// The bark from the deformer (methods that bend curves).
    deform: Option<GpuDeform>,
    instances: wgpu::Buffer,
    count: u32,
    /// Extra pre-roll steps: the group's phase offset in the wind.
    lead_steps: usize,
    /// The offset in seconds: this group's clock runs this far ahead of the scene's.
    lead_s: f32,
    seam: SeamPose,
}

impl Group {
    fn record(&mut self, ctx: &GpuContext, encoder: &mut wgpu::CommandEncoder) {
        match &self.sim {
            Simulation::Cpu(a) => {
                a.seam(&mut self.seam);
                self.mesh.record_seam(ctx, encoder, &self.seam);
                if let (Some(d), Some(c)) = (&self.deform, a.curves()) {
                    d.record_curves(ctx, encoder, c);
                }
            }
            Simulation::Gpu(g) => {
                let p = g.pose_buffers();
                self.mesh.record_with_leaves(ctx, encoder, p.joints_buffer(), p.acc_buffer(), p.leaf_buffer());
                if let (Some(d), Some(c)) = (&self.deform, g.curves()) {
                    d.record(ctx, encoder, c.stems, c.state);
                }
            }
        }
    }
}

/// The copies of a method that poses every instance: one simulation, skinned instances.
#[derive(Debug)]
struct Forest {
    sim: Simulation,
    placements: Vec<Placement>,
    transforms: wgpu::Buffer,
    skin: GpuSkin,
    joint: wgpu::Buffer,
    acc: wgpu::Buffer,
    /// The first instance's leaf rotations when the pose comes from the CPU (every copy's).
    leaf: wgpu::Buffer,
    seam: SeamPose,
    one: SeamPose,
}

impl Forest {
    fn record(&mut self, ctx: &GpuContext, tree: &Tree, encoder: &mut wgpu::CommandEncoder) {
        match &self.sim {
            Simulation::Gpu(g) => {
                let p = g.pose_buffers();
                self.skin.record_with_leaves(ctx, encoder, p.joints_buffer(), p.acc_buffer(), p.leaf_buffer());
            }
            Simulation::Cpu(a) => {
                if !a.seam_instances(&self.placements, &mut self.seam) {
                    // A method without per-instance poses: every copy takes the one pose.
                    a.seam(&mut self.one);
                    let n = self.placements.len();
                    let total = n * tree.segments.len();
                    self.seam.joints.clear();
                    self.seam.joints.extend(self.one.joints.iter().cycle().take(total));
                    self.seam.acc.clear();
                    self.seam.acc.extend(self.one.acc.iter().cycle().take(total));
                    self.seam.leaf.clone_from(&self.one.leaf);
                }
                ctx.queue.write_buffer(&self.joint, 0, bytemuck::cast_slice(&self.seam.joints));
                ctx.queue.write_buffer(&self.acc, 0, bytemuck::cast_slice(&self.seam.acc));
                // The first instance's leaf rotations; fewer than the leaves (none: at rest)
                // leave the rest at the identity.
                let leaves = tree.leaves.len();
                if leaves > 0 {
                    if let Some(all) = self.seam.leaf.get(..leaves) {
                        ctx.queue.write_buffer(&self.leaf, 0, bytemuck::cast_slice(all));
                    } else {
                        let identity = [0.0f32, 0.0, 0.0, 1.0];
                        self.seam.leaf.resize(leaves, identity);
                        ctx.queue.write_buffer(&self.leaf, 0, bytemuck::cast_slice(&self.seam.leaf));
                    }
                }
                self.skin.record_with_leaves(ctx, encoder, &self.joint, &self.acc, &self.leaf);
            }
        }
    }

    /// The first instance's pose.
    fn pose(&self, ctx: &GpuContext, tree: &Tree) -> Result<Pose, GpuError> {
        match &self.sim {
            Simulation::Gpu(g) => g.read_pose(ctx),
            Simulation::Cpu(a) => {
                let mut seam = SeamPose::default();
                Ok(if a.seam_instances(&self.placements[..1], &mut seam) { seam.pose(tree, 0) } else { a.pose() })
            }
        }
    }
}

#[derive(Debug)]
enum Drawn {
    Groups(Vec<Group>),
    Forest(Box<Forest>),
}

/// One `[[tree]]` of a scene as it runs (see the module docs).
#[derive(Debug)]
pub struct WorldTree {
    /// The grown tree.
    pub tree: Arc<Tree>,
    drawn: Drawn,
    /// The method's name.
    pub method: &'static str,
    /// Whether it simulates on the GPU.
    pub on_gpu: bool,
    /// Its label.
    pub label: String,
    /// Its position (the label's anchor), m.
    pub base: Vec3,
    /// The first instance's transform (the tree itself).
    pub transform: Mat4,
    /// Every instance's transform.
    pub instance_transforms: Vec<Mat4>,
    /// Scene-space bounds of all its instances.
    pub bounds: (Vec3, Vec3),
    /// Triangles drawn per frame, all instances.
    pub triangles: usize,
    /// Instances drawn.
    pub instances: usize,
    /// Independent simulations.
    pub simulations: usize,
}

fn instance(position: [f32; 3], yaw_deg: f32, scale: f32, tint: Vec3, leaf_shape: LeafShape) -> Instance {
    Instance {
        transform: Mat4::from_scale_rotation_translation(
            Vec3::splat(scale),
            Quat::from_rotation_y(yaw_deg.to_radians()),
            Vec3::from_array(position),
        ),
        tint,
        leaf_shape,
    }
}

impl WorldTree {
    /// Grows tree `i` of `scene` and checks it, with `others` segments and leaves of the
    /// scene's other trees and instances, against the scene's `max_scene_elements`: before
    /// any simulation or mesh of the scene is set up.
    pub(crate) fn grow(scene: &Scene, i: usize, st: &SceneTree, others: usize) -> Result<Arc<Tree>, RuntimeError> {
        let species = scene.resolve_path(&st.species);
        let species_error =
            |source| RuntimeError::Species { file: scene.file.clone(), index: i, source: Box::new(source) };
        let source = SpeciesSource::resolve_with(&species, &scene.limits).map_err(species_error)?;
        let mut grown = source.generate(st.seed, &scene.limits, None).map_err(species_error)?;
        if let Some(table) = &st.leaf_motion {
            grown.leaf_motion = grown.leaf_motion.with_table(table).map_err(|value| {
                let field = format!("tree[{i}].leaf_motion");
                RuntimeError::Scene(Box::new(sylva_core::scene::SceneError::Value {
                    file: scene.file.clone(),
                    line: scene.line_of(&field),
                    field,
                    value,
                    expected: "leaf motion fields in range (see `sylva_core::leaves::LeafMotion`)".into(),
                }))
            })?;
        }
        let tree = Arc::new(grown);
        let total = others.saturating_add(Self::elements(&tree, 1 + st.copies.len()));
        if total > scene.limits.max_scene_elements {
            return Err(RuntimeError::Limit(format!(
                "{}: tree[{i}]: the scene would hold {total} segments and leaves over all its trees and their instances, \
                 more than the limit `max_scene_elements` = {} (raise it with --max-scene-elements)",
                scene.file, scene.limits.max_scene_elements
            )));
        }
        Ok(tree)
    }

    pub(crate) fn elements(tree: &Tree, instances: usize) -> usize {
        (tree.segments.len() + tree.leaves.len()).saturating_mul(instances.max(1))
    }

    /// Segments and leaves over all its instances: what it counts against the scene's
    /// `max_scene_elements`.
    pub fn scene_elements(&self) -> usize {
        Self::elements(&self.tree, self.instances)
    }

    /// Grows, lays out and sets up tree `i` of `scene` (`st`, which may differ from
    /// `scene.trees[i]` when an editor changes it): its method on the CPU or the GPU (`auto`:
    /// GPU unless the adapter is a software rasteriser), its meshes, and the phase groups of
    /// its copies (`dt` converts their offsets to steps). The tree is `grown` ([`Self::grow`])
    /// or grown here, checked with `others` against the scene's `max_scene_elements`.
    #[allow(clippy::too_many_arguments)]
    pub(crate) fn build(
        ctx: &GpuContext,
        registry: &MethodRegistry,
        scene: &Scene,
        i: usize,
        st: &SceneTree,
        wind: &mut WorldWind,
        dt: f32,
        grown: Option<Arc<Tree>>,
        others: usize,
    ) -> Result<Self, RuntimeError> {
        let method_error = |source: sylva_core::methods::MethodError| {
            let field = match &source {
                sylva_core::methods::MethodError::Param { field, .. } if st.params.is_some() => {
                    format!("tree[{i}].params.{field}")
                }
                _ => format!("tree[{i}].method"),
            };
            RuntimeError::Method {
                file: scene.file.clone(),
                line: scene.line_of(&field),
                index: i,
                source: Box::new(source),
            }
        };
        let entry = *registry.entry(st.method.as_str()).map_err(method_error)?;
        let tree = match grown {
            Some(t) => t,
            None => Self::grow(scene, i, st, others)?,
        };
        let software = ctx.summary.device_type == "Cpu";
        let gpu = match st.backend {
            BackendChoice::Auto => !software && entry.gpu.is_some(),
            BackendChoice::Cpu => false,
            BackendChoice::Gpu if entry.gpu.is_none() => {
                return Err(RuntimeError::NoGpuTwin { index: i, method: entry.name.to_string() });
            }
            BackendChoice::Gpu => true,
        };
        let options = MethodOptions { seed: st.seed, params: st.params.clone().unwrap_or_default() };
        let defaults = MeshParams::default();
        let params = MeshParams {
            sides: st.sides.unwrap_or(defaults.sides),
            leaf_sides: st.leaf_sides.unwrap_or(defaults.leaf_sides),
            ..defaults
        };
        let layout = MeshLayout::new(&tree, params)?;
        let tint = Vec3::from_array(st.tint.unwrap_or([0.28, 0.50, 0.12]));
        let shape = tree.leaf_shape;
        let mut inst = vec![instance(st.position, st.yaw_deg, st.scale, tint, shape)];
        inst.extend(st.copies.iter().map(|c| instance(c.position, c.yaw_deg, c.scale, tint * 1.05, shape)));
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
            format!("{} · {} ({})", tree.name.replace('_', " "), entry.name, if gpu { "GPU" } else { "CPU" })
        });
        let build_sim = |wind: &ClockWind, placements: &[Placement]| -> Result<Simulation, RuntimeError> {
            let mut sim = match (gpu, entry.gpu) {
                (true, Some(build)) => {
                    Simulation::Gpu(build(ctx, tree.clone(), &options, &wind.gpu, placements).map_err(|e| match e {
                        sylva_gpu::methods::BuildError::Method(m) => method_error(m),
                        sylva_gpu::methods::BuildError::Gpu(g) => RuntimeError::Gpu(g),
                    })?)
                }
                _ => Simulation::Cpu((entry.cpu)(tree.clone(), &options).map_err(method_error)?),
            };
            sim.set_wind(wind);
            Ok(sim)
        };
        let mut bark_triangles = layout.tube_indices.len() / 3;
        let drawn = if entry.per_instance && inst.len() > 1 {
            let vertices = layout.tube_vertex_count() + layout.leaf_vertex_count();
            let bytes = (vertices * std::mem::size_of::<RawVertex>() * inst.len()) as u64;
            if bytes > MAX_SKINNED_BYTES {
                return Err(RuntimeError::Limit(format!(
                    "{}: tree[{i}]: {} skinned instances of {vertices} vertices need {:.1} GiB of vertex buffers; \
                     at most {} GiB: use fewer copies, fewer `sides`/`leaf_sides`, or a stateful method \
                     (whose copies share their simulations' meshes)",
                    scene.file,
                    inst.len(),
                    bytes as f64 / (1u64 << 30) as f64,
                    MAX_SKINNED_BYTES >> 30
                )));
            }
            let placements: Vec<Placement> = inst
                .iter()
                .enumerate()
                .map(|(k, p)| {
                    let (_, rotation, position) = p.transform.to_scale_rotation_translation();
                    let key = sylva_core::rng::mix64(st.seed ^ (k as u64).wrapping_mul(0x9e37_79b9_7f4a_7c15));
                    Placement {
                        position,
                        yaw: rotation.to_euler(glam::EulerRot::YXZ).0,
                        phase: (key & 0xFFFF) as f32 / 65_536.0,
                        seed: (key >> 32) as u32,
                    }
                })
                .collect();
            let n = placements.len() * tree.segments.len();
            let mut sim = build_sim(&wind.clock(ctx, 0.0)?, &placements)?;
            if let Simulation::Cpu(a) = &mut sim {
                // Methods with per-instance state (Zioma's rings) keep one for each copy.
                a.set_instances(&placements);
            }
            Drawn::Forest(Box::new(Forest {
                sim,
                transforms: Renderer::instances(ctx, &inst),
                skin: GpuSkin::new(ctx, &layout, &SkinLayout::new(&layout), placements.len() as u32)?,
                joint: sylva_gpu::kernel::output::<[f32; 4]>(ctx, "forest joints", n)?,
                acc: sylva_gpu::kernel::output::<[f32; 4]>(ctx, "forest rotations", n)?,
                leaf: sylva_gpu::kernel::upload(
                    ctx,
                    "forest leaf rotations",
                    &vec![[0.0f32, 0.0, 0.0, 1.0]; tree.leaves.len().max(1)],
                )?,
                placements,
                seam: SeamPose::default(),
                one: SeamPose::default(),
            }))
        } else {
            let mut groups = Vec::new();
            for group in st.phase_groups(entry.per_instance) {
                let lead_steps = (group.offset_s / dt).round() as usize;
                let lead_s = lead_steps as f32 * dt;
                let sim = build_sim(&wind.clock(ctx, lead_s)?, &[])?;
                let deform = if sim.has_curves() {
                    let grid = DeformLayout::new(
                        &tree,
                        DeformerParams { sides: params.sides, ..DeformerParams::for_tree(&tree) },
                    )?;
                    bark_triangles = grid.triangle_count();
                    Some(match &sim {
                        Simulation::Cpu(a) => GpuDeform::new(ctx, &grid, a.curves().expect("has curves").stems)?,
                        Simulation::Gpu(_) => GpuDeform::for_device_curves(ctx, &grid)?,
                    })
                } else {
                    None
                };
                let members: Vec<Instance> = group.members.iter().map(|&k| inst[k]).collect();
                groups.push(Group {
                    sim,
                    mesh: GpuMesh::new(ctx, &layout)?,
                    deform,
                    instances: Renderer::instances(ctx, &members),
                    count: members.len() as u32,
                    lead_steps,
                    lead_s,
                    seam: SeamPose::default(),
                });
            }
            Drawn::Groups(groups)
        };
        let tree_triangles = bark_triangles + layout.leaf_indices.len() / 3;
        let simulations = match &drawn {
            Drawn::Groups(g) => g.len(),
            Drawn::Forest(_) => 1,
        };
        // Poses are in the tree's own frame (instances posed on their own sample the wind at
        // their placement and turn it by their yaw); the instance transforms place them.
        Ok(Self {
            method: entry.name,
            on_gpu: gpu,
            base: Vec3::from_array(st.position),
            transform: inst[0].transform,
            instance_transforms: inst.iter().map(|i| i.transform).collect(),
            bounds: (lo, hi),
            triangles: tree_triangles * inst.len(),
            instances: inst.len(),
            simulations,
            tree,
            drawn,
            label,
        })
    }

    /// Advances every simulation `steps` steps of `dt` (plus its phase lead when `preroll`).
    pub(crate) fn advance(&mut self, ctx: &GpuContext, dt: f32, steps: usize, preroll: bool) {
        match &mut self.drawn {
            Drawn::Groups(groups) => {
                for g in groups {
                    let lead = if preroll { g.lead_steps } else { 0 };
                    g.sim.advance(ctx, dt, steps + lead);
                }
            }
            Drawn::Forest(f) => f.sim.advance(ctx, dt, steps),
        }
    }

    /// Puts every simulation at rest at scene time `time` (a tree built while the world
    /// runs), then pre-rolls each phase group by its lead.
    pub(crate) fn start_at(&mut self, ctx: &GpuContext, dt: f32, time: f32) {
        match &mut self.drawn {
            Drawn::Groups(groups) => groups.iter_mut().for_each(|g| g.sim.reset(ctx, time)),
            Drawn::Forest(f) => f.sim.reset(ctx, time),
        }
        self.advance(ctx, dt, 0, true);
    }

    /// Records the meshes of the current poses.
    pub(crate) fn record(&mut self, ctx: &GpuContext, encoder: &mut wgpu::CommandEncoder) {
        match &mut self.drawn {
            Drawn::Groups(groups) => groups.iter_mut().for_each(|g| g.record(ctx, encoder)),
            Drawn::Forest(f) => f.record(ctx, &self.tree, encoder),
        }
    }

    /// Binds the wind of each simulation's clock.
    pub(crate) fn set_wind(&mut self, ctx: &GpuContext, wind: &mut WorldWind) -> Result<(), GpuError> {
        match &mut self.drawn {
            Drawn::Groups(groups) => {
                for g in groups {
                    g.sim.set_wind(&wind.clock(ctx, g.lead_s)?);
                }
            }
            Drawn::Forest(f) => f.sim.set_wind(&wind.clock(ctx, 0.0)?),
        }
        Ok(())
    }

    /// One line for a console: counts, instances, simulations, label.
    pub fn summary(&self) -> String {
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
    pub fn draw_items(&self) -> Vec<DrawItem<'_>> {
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

    /// The simulations (one per phase group, or the one posing every instance).
    pub fn simulations(&self) -> Vec<&Simulation> {
        match &self.drawn {
            Drawn::Groups(g) => g.iter().map(|g| &g.sim).collect(),
            Drawn::Forest(f) => vec![&f.sim],
        }
    }

    /// Whether any phase group pre-rolls further than the scene.
    pub fn has_leads(&self) -> bool {
        matches!(&self.drawn, Drawn::Groups(g) if g.iter().any(|g| g.lead_steps > 0))
    }

    /// The pose of the first instance (the tree itself), in the tree's frame; read back from
    /// the GPU for GPU methods.
    pub fn pose(&self, ctx: &GpuContext) -> Result<Pose, GpuError> {
        match &self.drawn {
            Drawn::Groups(groups) => groups[0].sim.pose(ctx),
            Drawn::Forest(f) => f.pose(ctx, &self.tree),
        }
    }

    /// Mean distance of the segments' joints from rest in every simulation, m: how far the
    /// wind has moved each.
    pub fn displacements(&self, ctx: &GpuContext) -> Result<Vec<f32>, GpuError> {
        let rest = &self.tree.segments.start;
        let distance = |pose: &Pose| {
            pose.start.iter().zip(rest).map(|(p, r)| p.distance(*r)).sum::<f32>() / rest.len().max(1) as f32
        };
        match &self.drawn {
            Drawn::Groups(groups) => groups.iter().map(|g| Ok(distance(&g.sim.pose(ctx)?))).collect(),
            Drawn::Forest(f) => Ok(vec![distance(&f.pose(ctx, &self.tree)?)]),
        }
    }

    /// Particles per simulation (particle methods).
    pub fn particles(&self) -> Option<usize> {
        self.simulations()[0].particles()
    }
}
