//! The pose seam on the GPU ([`sylva_core::pose`]): the seam's buffers (joints and
//! accumulated rotations) and forward kinematics from per-segment rotations.

pub mod segment_ends;

use crate::kernel::{Kernel, output, read_back, upload};
use crate::{GpuContext, GpuError};
use glam::{Quat, Vec3};
use std::sync::Arc;
use sylva_core::Tree;
use sylva_core::pose::Pose;

/// How forward kinematics walks the hierarchy on the GPU.
///
/// Measured on every preset (`cargo bench -p sylva-gpu --bench animate`, figures in
/// `docs/PERFORMANCE.md`): the ancestor walk is one pair of dispatches whatever the depth,
/// and each invocation reads its chain (≤ depth quaternions, cached: siblings share them);
/// level by level needs one dispatch per depth (37 for the weeping willow) with little work
/// in each. The walk is the default.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum FkStrategy {
    /// Every segment walks its own ancestor chain (`pose_accumulate`, `pose_positions`).
    #[default]
    AncestorWalk,
    /// One dispatch per depth, root first (`pose_level`).
    LevelByLevel,
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
    strategy: FkStrategy,
    levels: Vec<(wgpu::Buffer, u32)>,
    disp: wgpu::Buffer,
    parents: wgpu::Buffer,
    rest: wgpu::Buffer,
    delta: wgpu::Buffer,
    acc: wgpu::Buffer,
    joints: wgpu::Buffer,
    n: usize,
    instances: usize,
    rest_orientation: Vec<Quat>,
}

impl GpuPose {
    /// Uploads the tree's hierarchy and rest joints (ancestor walks).
    pub fn new(ctx: &GpuContext, tree: &Tree) -> Result<Self, GpuError> {
        Self::with_strategy(ctx, tree, FkStrategy::default())
    }

    /// Uploads the tree's hierarchy and rest joints, walking the hierarchy as `strategy` says.
    pub fn with_strategy(ctx: &GpuContext, tree: &Tree, strategy: FkStrategy) -> Result<Self, GpuError> {
        Self::build(ctx, tree, strategy, 1)
    }

    /// `count` instances of the tree (ancestor walks over instance-major buffers: a
    /// method writes `instance × segments + segment`).
    pub fn with_instances(ctx: &GpuContext, tree: &Tree, count: usize) -> Result<Self, GpuError> {
        Self::build(ctx, tree, FkStrategy::AncestorWalk, count.max(1))
    }

    fn build(ctx: &GpuContext, tree: &Tree, strategy: FkStrategy, instances: usize) -> Result<Self, GpuError> {
        let n = tree.segments.len();
        let total = n * instances;
        let levels = match strategy {
            FkStrategy::AncestorWalk => Vec::new(),
            FkStrategy::LevelByLevel => {
                upload_buckets(ctx, "fk level", &sylva_core::pose::fk::depth_buckets(&tree.segments.parent))?
            }
        };
        let rest: Vec<[f32; 4]> = tree.segments.start.iter().map(|p| p.extend(0.0).to_array()).collect();
        Ok(Self {
            accumulate: Kernel::get(ctx, "pose_accumulate"),
            positions: Kernel::get(ctx, "pose_positions"),
            level: Kernel::get(ctx, "pose_level"),
            strategy,
            levels,
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
            n,
            instances,
            rest_orientation: tree.segments.orientation.clone(),
        })
    }

    /// The buffer a method writes its rotations δ into.
    pub fn delta_buffer(&self) -> &wgpu::Buffer {
        &self.delta
    }

    /// Runs forward kinematics on the rotations in [`Self::delta_buffer`] (recorded into
    /// `encoder`).
    pub fn record(&self, ctx: &GpuContext, encoder: &mut wgpu::CommandEncoder) {
        match self.strategy {
            FkStrategy::AncestorWalk => {
                let total = (self.n * self.instances) as u32;
                self.accumulate.record(ctx, encoder, &[&self.parents, &self.delta, &self.acc], total);
                self.positions.record(ctx, encoder, &[&self.parents, &self.rest, &self.acc, &self.joints], total);
            }
            FkStrategy::LevelByLevel => {
                for (bucket, len) in &self.levels {
                    self.level.record(
                        ctx,
                        encoder,
                        &[bucket, &self.parents, &self.rest, &self.delta, &self.acc, &self.disp, &self.joints],
                        *len,
                    );
                }
            }
        }
    }

    /// Runs only the joint positions, from rotations a method wrote straight into
    /// [`Self::acc_buffer`] (methods whose rotations are already world rotations, as HSM's
    /// cluster R).
    pub fn record_positions(&self, ctx: &GpuContext, encoder: &mut wgpu::CommandEncoder) {
        let total = (self.n * self.instances) as u32;
        self.positions.record(ctx, encoder, &[&self.parents, &self.rest, &self.acc, &self.joints], total);
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
        ctx.queue.submit([encoder.finish()]);
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
