//! The pose seam on the GPU ([`sylva_core::pose`]): the seam's buffers (joints and
//! accumulated rotations) and forward kinematics from per-segment rotations.

pub mod segment_ends;

use crate::kernel::{Kernel, Plan, compute_pass, output, read_back, upload};
use crate::{GpuContext, GpuError};
use glam::{Quat, Vec3};
use std::sync::Arc;
use sylva_core::Tree;
use sylva_core::pose::Pose;

/// How forward kinematics walks the hierarchy on the GPU.
///
/// Measured (`cargo bench -p sylva-gpu --bench animate`, figures in `docs/PERFORMANCE.md`):
/// the ancestor walk is one pair of dispatches whatever the depth, and each invocation reads
/// its chain (≤ depth quaternions, cached: siblings share them), so its work grows as
/// segments × depth. Level by level needs one dispatch per depth. Pointer jumping does
/// segments × ⌈log₂(depth + 1)⌉ work in 2⌈log₂(depth + 1)⌉ + 2 dispatches.
/// [`FkStrategy::for_tree`] walks ancestors up to [`FkStrategy::WALK_MAX_DEPTH`] levels (every
/// shipped species) and jumps pointers beyond.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum FkStrategy {
    /// Every segment walks its own ancestor chain (`pose_accumulate`, `pose_positions`).
    AncestorWalk,
    /// One dispatch per depth, root first (`pose_level`).
    LevelByLevel,
    /// Pointer jumping: each round doubles how far up every segment has gathered
    /// (`pose_jump_rotations`, `pose_jump_terms`, `pose_jump_sums`, `pose_jump_joints`).
    PointerJump,
}

impl FkStrategy {
    /// The deepest hierarchy [`FkStrategy::for_tree`] gives to ancestor walks. On lavapipe
    /// pointer jumping already wins from depth ≈ 30 (`docs/PERFORMANCE.md`); on a discrete
    /// GPU each of its dispatches costs microseconds while a walk's extra reads are cached,
    /// so every shipped species (≤ 37 levels) stays on the walk and deep grammars jump.
    pub const WALK_MAX_DEPTH: usize = 64;

    /// The strategy for a hierarchy, by its depth: ancestor walks up to
    /// [`Self::WALK_MAX_DEPTH`] levels, pointer jumping beyond.
    pub fn for_tree(parent: &[u32]) -> Self {
        if max_depth(parent) <= Self::WALK_MAX_DEPTH { Self::AncestorWalk } else { Self::PointerJump }
    }
}

/// The number of levels below the deepest root (0 for roots alone); parents come first.
pub fn max_depth(parent: &[u32]) -> usize {
    let mut depth = vec![0usize; parent.len()];
    for i in 0..parent.len() {
        if let Some(&d) = depth.get(parent[i] as usize) {
            depth[i] = d + 1;
        }
    }
    depth.into_iter().max().unwrap_or(0)
}

/// Uploads depth buckets of segment indices, each padded with `u32::MAX` to a multiple of
/// four entries (storage bindings are at least 16 bytes), with its unpadded length.
pub fn upload_buckets(
    ctx: &GpuContext,
    label: &'static str,
    buckets: &[Vec<u32>],
) -> Result<Vec<(wgpu::Buffer, u32)>, GpuError> {
    buckets
        .iter()
        .map(|b| {
            let mut padded = b.clone();
            padded.resize(b.len().div_ceil(4) * 4, u32::MAX);
            Ok((upload(ctx, label, &padded)?, b.len() as u32))
        })
        .collect()
}

/// A tree uploaded once; poses computed on the GPU from rotations made there.
#[derive(Debug)]
pub struct GpuPose {
    accumulate: Arc<Kernel>,
    positions: Arc<Kernel>,
    level: Arc<Kernel>,
    jump: [Arc<Kernel>; 4],
    strategy: FkStrategy,
    levels: Vec<(wgpu::Buffer, u32)>,
    /// Pointer jumping: the ancestors each round reads, and a scratch buffer (instance-major).
    jumps: Vec<wgpu::Buffer>,
    scratch: wgpu::Buffer,
    disp: wgpu::Buffer,
    parents: wgpu::Buffer,
    rest: wgpu::Buffer,
    delta: wgpu::Buffer,
    acc: wgpu::Buffer,
    joints: wgpu::Buffer,
    leaf: wgpu::Buffer,
    leaves: usize,
    n: usize,
    instances: usize,
    rest_orientation: Vec<Quat>,
    /// The dispatches from δ to the accumulated rotations, then from those to the joints,
    /// bound once.
    rotations_plan: Plan,
    positions_plan: Plan,
}

impl GpuPose {
    /// Uploads the tree's hierarchy and rest joints, walking it as
    /// [`FkStrategy::for_tree`] chooses by depth.
    pub fn new(ctx: &GpuContext, tree: &Tree) -> Result<Self, GpuError> {
        Self::with_strategy(ctx, tree, FkStrategy::for_tree(&tree.segments.parent))
    }

    /// Uploads the tree's hierarchy and rest joints, walking the hierarchy as `strategy` says.
    pub fn with_strategy(ctx: &GpuContext, tree: &Tree, strategy: FkStrategy) -> Result<Self, GpuError> {
        Self::build(ctx, tree, strategy, 1)
    }

    /// `count` instances of the tree over instance-major buffers (a method writes
    /// `instance × segments + segment`), walked as [`FkStrategy::for_tree`] chooses.
    pub fn with_instances(ctx: &GpuContext, tree: &Tree, count: usize) -> Result<Self, GpuError> {
        Self::build(ctx, tree, FkStrategy::for_tree(&tree.segments.parent), count.max(1))
    }

    fn build(ctx: &GpuContext, tree: &Tree, strategy: FkStrategy, instances: usize) -> Result<Self, GpuError> {
        let n = tree.segments.len();
        // Level by level writes one instance. Pointer jumping takes a hierarchy's length from
        // its ancestor lists, which storage bindings pad to 4 entries: under 4 segments (at
        // most 3 levels) the walk is the same work.
        let strategy = match strategy {
            FkStrategy::LevelByLevel if instances > 1 => FkStrategy::AncestorWalk,
            FkStrategy::PointerJump if n < 4 => FkStrategy::AncestorWalk,
            s => s,
        };
        let total = n * instances;
        let levels = match strategy {
            FkStrategy::AncestorWalk => Vec::new(),
            FkStrategy::LevelByLevel => {
                upload_buckets(ctx, "fk level", &sylva_core::pose::fk::depth_buckets(&tree.segments.parent))?
            }
            FkStrategy::PointerJump => Vec::new(),
        };
        let jumps = match strategy {
            FkStrategy::PointerJump => sylva_core::pose::fk::jump_ancestors(&tree.segments.parent)
                .iter()
                .map(|anc| upload(ctx, "fk jump ancestors", anc))
                .collect::<Result<_, _>>()?,
            _ => Vec::new(),
        };
        let rest: Vec<[f32; 4]> = tree.segments.start.iter().map(|p| p.extend(0.0).to_array()).collect();
        let mut this = Self {
            accumulate: Kernel::get(ctx, "pose_accumulate"),
            positions: Kernel::get(ctx, "pose_positions"),
            level: Kernel::get(ctx, "pose_level"),
            jump: ["pose_jump_rotations", "pose_jump_terms", "pose_jump_sums", "pose_jump_joints"]
                .map(|k| Kernel::get(ctx, k)),
            strategy,
            levels,
            scratch: output::<[f32; 4]>(
                ctx,
                "fk scratch",
                if strategy == FkStrategy::PointerJump { total } else { 1 },
            )?,
            jumps,
            disp: output::<[f32; 4]>(
                ctx,
                "fk displacements",
                if strategy == FkStrategy::LevelByLevel { n } else { 1 },
            )?,
            parents: upload(ctx, "parents", &tree.segments.parent)?,
            rest: upload(ctx, "rest joints", &rest)?,
            delta: output::<[f32; 4]>(ctx, "delta", total)?,
            acc: output::<[f32; 4]>(ctx, "acc", total)?,
            joints: output::<[f32; 4]>(ctx, "joints", total)?,
            leaf: upload(ctx, "leaf rotations", &vec![[0.0f32, 0.0, 0.0, 1.0]; tree.leaves.len().max(1)])?,
            leaves: tree.leaves.len(),
            n,
            instances,
            rest_orientation: tree.segments.orientation.clone(),
            rotations_plan: Plan::default(),
            positions_plan: Plan::default(),
        };
        this.plan(ctx);
        Ok(this)
    }

    /// Binds the strategy's dispatches once: δ to accumulated rotations, then to joints.
    fn plan(&mut self, ctx: &GpuContext) {
        let total = (self.n * self.instances) as u32;
        let (mut rotations, mut positions) = (Plan::default(), Plan::default());
        match self.strategy {
            FkStrategy::AncestorWalk => {
                rotations.push(ctx, &self.accumulate, &[&self.parents, &self.delta, &self.acc], total);
                positions.push(ctx, &self.positions, &[&self.parents, &self.rest, &self.acc, &self.joints], total);
            }
            FkStrategy::LevelByLevel => {
                // Each level writes rotations and joints together.
                for (bucket, len) in &self.levels {
                    rotations.push(
                        ctx,
                        &self.level,
                        &[bucket, &self.parents, &self.rest, &self.delta, &self.acc, &self.disp, &self.joints],
                        *len,
                    );
                }
                positions.push(ctx, &self.positions, &[&self.parents, &self.rest, &self.acc, &self.joints], total);
            }
            FkStrategy::PointerJump => {
                // Rounds alternate between acc and scratch so that the last one writes acc
                // (with no rounds, `record` copies δ into acc).
                let rounds = self.jumps.len();
                let mut input = &self.delta;
                for (k, anc) in self.jumps.iter().enumerate() {
                    let out = if (rounds - 1 - k) % 2 == 0 { &self.acc } else { &self.scratch };
                    rotations.push(ctx, &self.jump[0], &[anc, input, out], total);
                    input = out;
                }
                // The joints from acc: the terms, the rounds of sums alternating between
                // joints and scratch so that the last one writes scratch, then rest + sum.
                let ping = |k: usize| if (rounds - k) % 2 == 0 { &self.scratch } else { &self.joints };
                positions.push(ctx, &self.jump[1], &[&self.parents, &self.rest, &self.acc, ping(0)], total);
                for (k, anc) in self.jumps.iter().enumerate() {
                    positions.push(ctx, &self.jump[2], &[anc, ping(k), ping(k + 1)], total);
                }
                positions.push(ctx, &self.jump[3], &[&self.rest, &self.scratch, &self.joints], total);
            }
        }
        self.rotations_plan = rotations;
        self.positions_plan = positions;
    }

    /// The first instance's leaf rotations (`λ` of [`sylva_core::pose::SeamPose::leaf`]; the
    /// identity until a method writes them), one per leaf of the tree.
    pub fn leaf_buffer(&self) -> &wgpu::Buffer {
        &self.leaf
    }

    /// The first instance's leaf rotations read back (waits for the GPU).
    pub fn read_leaves(&self, ctx: &GpuContext) -> Result<Vec<[f32; 4]>, GpuError> {
        read_back(ctx, &self.leaf, self.leaves)
    }

    /// The buffer a method writes its rotations δ into.
    pub fn delta_buffer(&self) -> &wgpu::Buffer {
        &self.delta
    }

    /// The strategy this pose walks its hierarchy with.
    pub fn strategy(&self) -> FkStrategy {
        self.strategy
    }

    /// Runs forward kinematics on the rotations in [`Self::delta_buffer`] (recorded into
    /// `encoder`, one compute pass).
    pub fn record(&self, ctx: &GpuContext, encoder: &mut wgpu::CommandEncoder) {
        match self.strategy {
            FkStrategy::LevelByLevel => self.rotations_plan.record(ctx, encoder, "forward kinematics"),
            _ => {
                if self.strategy == FkStrategy::PointerJump && self.jumps.is_empty() {
                    encoder.copy_buffer_to_buffer(&self.delta, 0, &self.acc, 0, self.acc.size());
                }
                let mut pass = compute_pass(ctx, encoder, "forward kinematics");
                self.rotations_plan.dispatch(ctx, &mut pass);
                self.positions_plan.dispatch(ctx, &mut pass);
            }
        }
    }

    /// Runs only the joint positions, from rotations a method wrote straight into
    /// [`Self::acc_buffer`] (methods whose rotations are already world rotations, as HSM's
    /// cluster R).
    pub fn record_positions(&self, ctx: &GpuContext, encoder: &mut wgpu::CommandEncoder) {
        self.positions_plan.record(ctx, encoder, "joint positions");
    }

    /// [`Self::record_positions`] into an open pass, after the dispatches that write acc.
    pub fn dispatch_positions(&self, ctx: &GpuContext, pass: &mut wgpu::ComputePass<'_>) {
        self.positions_plan.dispatch(ctx, pass);
    }

    /// The buffer of posed joint positions (w = 0), instance-major.
    pub fn joints_buffer(&self) -> &wgpu::Buffer {
        &self.joints
    }

    /// The buffer of accumulated (world) rotations D.
    pub fn acc_buffer(&self) -> &wgpu::Buffer {
        &self.acc
    }

    /// Number of segments of one instance.
    pub fn segment_count(&self) -> usize {
        self.n
    }

    /// Number of instances held.
    pub fn instance_count(&self) -> usize {
        self.instances
    }

    /// The parent index of every segment.
    pub fn parents_buffer(&self) -> &wgpu::Buffer {
        &self.parents
    }

    /// Writes the rest pose (identity rotations, rest joints) into the seam's buffers, every
    /// instance.
    pub fn write_rest(&self, ctx: &GpuContext, tree: &Tree) {
        let total = self.n * self.instances;
        let rest: Vec<[f32; 4]> = tree.segments.start.iter().map(|p| p.extend(0.0).to_array()).collect();
        let joints: Vec<[f32; 4]> = rest.iter().cycle().take(total).copied().collect();
        ctx.queue.write_buffer(&self.acc, 0, bytemuck::cast_slice(&vec![[0.0f32, 0.0, 0.0, 1.0]; total]));
        ctx.queue.write_buffer(&self.joints, 0, bytemuck::cast_slice(&joints));
    }

    /// Forward kinematics of given rotations, read back as a [`Pose`].
    pub fn pose_from_rotations(&self, ctx: &GpuContext, delta: &[[f32; 4]]) -> Result<Pose, GpuError> {
        ctx.queue.write_buffer(&self.delta, 0, bytemuck::cast_slice(delta));
        let mut encoder = ctx.device.create_command_encoder(&Default::default());
        self.record(ctx, &mut encoder);
        ctx.submit([encoder.finish()]);
        self.read(ctx)
    }

    /// Reads the current pose back (the first instance).
    pub fn read(&self, ctx: &GpuContext) -> Result<Pose, GpuError> {
        let joints: Vec<[f32; 4]> = read_back(ctx, &self.joints, self.n)?;
        let acc: Vec<[f32; 4]> = read_back(ctx, &self.acc, self.n)?;
        Ok(Pose {
            start: joints.iter().map(|p| Vec3::new(p[0], p[1], p[2])).collect(),
            orientation: acc.iter().zip(&self.rest_orientation).map(|(d, q)| Quat::from_array(*d) * *q).collect(),
            bezier: None,
        })
    }

    /// Reads every instance's pose back.
    pub fn read_all(&self, ctx: &GpuContext) -> Result<Vec<Pose>, GpuError> {
        let total = self.n * self.instances;
        let joints: Vec<[f32; 4]> = read_back(ctx, &self.joints, total)?;
        let acc: Vec<[f32; 4]> = read_back(ctx, &self.acc, total)?;
        Ok(joints
            .chunks(self.n.max(1))
            .zip(acc.chunks(self.n.max(1)))
            .map(|(j, a)| Pose {
                start: j.iter().map(|p| Vec3::new(p[0], p[1], p[2])).collect(),
                orientation: a.iter().zip(&self.rest_orientation).map(|(d, q)| Quat::from_array(*d) * *q).collect(),
                bezier: None,
            })
            .collect())
    }
}
