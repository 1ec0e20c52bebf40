//! Zioma's method on the GPU: rotations from `zioma_rotations.wgsl`, the pose from
//! [`GpuPose`], every instance in one submission per frame (§6.5 instancing).

pub mod trunk_noise;

use super::{BuildError, GpuAnimator};
use crate::kernel::{Kernel, Plan, upload};
use crate::leaves::GpuLeafFlutter;
use crate::pose::GpuPose;
use crate::wind::GpuWind;
use crate::{GpuContext, GpuError};
use std::sync::Arc;
use sylva_core::Tree;
use sylva_core::methods::MethodOptions;
use sylva_core::methods::zioma::{RawZiomaFrame, Ring, Zioma, ZiomaParams};
use sylva_core::pose::{Placement, Pose};

/// Zioma's method on the GPU for one tree and its placed instances.
#[derive(Debug)]
pub struct GpuZioma {
    tree: Arc<Tree>,
    method: Zioma,
    kernel: Arc<Kernel>,
    pose: GpuPose,
    wind: GpuWind,
    segments: wgpu::Buffer,
    stems: wgpu::Buffer,
    frame: wgpu::Buffer,
    instances: Vec<Placement>,
    leaves: GpuLeafFlutter,
    /// The rotation kernel, bound on first use after the wind is set.
    rotations: Option<Plan>,
    /// The trunk's ring-down since the wind last changed (as the CPU's state).
    ring: Ring,
    /// Time of the pose, s.
    pub time: f32,
}

impl GpuZioma {
    /// Uploads the tree and Zioma's per-stem constants; binds the scene's wind.
    pub fn new(ctx: &GpuContext, tree: Arc<Tree>, method: Zioma, wind: &GpuWind) -> Result<Self, GpuError> {
        Self::with_instances(ctx, tree, method, wind, &[])
    }

    /// Many placed instances of the tree (§6.5 instancing): one dispatch for every
    /// (instance, segment) and one forward-kinematics pass over them all per frame. An empty
    /// list is the single tree at the origin.
    pub fn with_instances(
        ctx: &GpuContext,
        tree: Arc<Tree>,
        method: Zioma,
        wind: &GpuWind,
        instances: &[Placement],
    ) -> Result<Self, GpuError> {
        let count = instances.len().max(1);
        let zeroed: RawZiomaFrame = bytemuck::Zeroable::zeroed();
        let ring = method.start_ring(&wind.packed.fields, &wind.packed.waves);
        Ok(Self {
            ring,
            kernel: Kernel::get(ctx, "zioma_rotations"),
            pose: GpuPose::with_instances(ctx, &tree, count)?,
            wind: wind.clone(),
            segments: upload(ctx, "segments", &tree.raw_segments())?,
            stems: upload(ctx, "zioma stems", &method.stems)?,
            frame: upload(ctx, "zioma frames", &vec![zeroed; count])?,
            instances: instances.to_vec(),
            leaves: GpuLeafFlutter::new(ctx, &method.leaves)?,
            rotations: None,
            tree,
            method,
            time: 0.0,
        })
    }

    /// The method's constants.
    pub fn method(&self) -> &Zioma {
        &self.method
    }

    /// Records and submits every instance's pose at time `t` without reading it back (the
    /// per-instance frame values are computed on the CPU: the trunk's filtered wind and its
    /// bands each).
    pub fn submit(&mut self, ctx: &GpuContext, t: f32) {
        let mut encoder = ctx.device.create_command_encoder(&Default::default());
        self.record(ctx, &mut encoder, t);
        ctx.submit([encoder.finish()]);
    }

    /// Records every instance's pose at time `t` into `encoder`, for work that reads it in
    /// the same submission (skinning, meshing); the frame values are written to the queue now,
    /// so record one pose per submission.
    pub fn record(&mut self, ctx: &GpuContext, encoder: &mut wgpu::CommandEncoder, t: f32) {
        self.time = t;
        let (m, w) = (&self.method, &*self.wind.packed);
        let frames: Vec<RawZiomaFrame> = if self.instances.is_empty() {
            vec![m.frame(&w.fields, &w.waves, t, &self.ring)]
        } else {
            m.frames_for(&w.fields, &w.waves, t, &self.instances, &self.ring)
        };
        ctx.queue.write_buffer(&self.frame, 0, bytemuck::cast_slice(&frames));
        let plan = self.rotations.get_or_insert_with(|| {
            let buffers = [
                &self.wind.fields,
                &self.wind.waves,
                &self.segments,
                &self.stems,
                &self.frame,
                self.pose.delta_buffer(),
            ];
            let mut plan = Plan::default();
            plan.push(ctx, &self.kernel, &buffers, (self.pose.segment_count() * self.pose.instance_count()) as u32);
            plan
        });
        plan.record(ctx, encoder, "zioma rotations");
        self.pose.record(ctx, encoder);
        self.leaves.record_pose(ctx, encoder, &self.wind, &self.pose, t);
    }

    /// Every instance's pose at time `t`.
    pub fn poses(&mut self, ctx: &GpuContext, t: f32) -> Result<Vec<Pose>, GpuError> {
        self.submit(ctx, t);
        self.pose.read_all(ctx)
    }

    /// The pose at time `t`: the per-tree frame values are computed on the CPU (one wind
    /// sample and the trunk bands), everything per segment on the GPU.
    pub fn pose(&mut self, ctx: &GpuContext, t: f32) -> Result<Pose, GpuError> {
        self.submit(ctx, t);
        self.pose.read(ctx)
    }
}

/// The registry's GPU constructor: Zioma's method on `tree`, posing every placed instance.
pub fn animator(
    ctx: &GpuContext,
    tree: Arc<Tree>,
    options: &MethodOptions,
    wind: &GpuWind,
    instances: &[Placement],
) -> Result<Box<dyn GpuAnimator>, BuildError> {
    let params = ZiomaParams { seed: options.seed, ..options.parse::<ZiomaParams>("zioma")? };
    params.check()?;
    let method = Zioma::new(&tree, params);
    Ok(Box::new(GpuZioma::with_instances(ctx, tree, method, wind, instances)?))
}

impl GpuAnimator for GpuZioma {
    fn name(&self) -> &'static str {
        "zioma"
    }
    fn tree(&self) -> &Arc<Tree> {
        &self.tree
    }
    /// A wind unlike the last starts a ring at the current time, as on the CPU.
    fn set_wind(&mut self, wind: &GpuWind) {
        if *wind.packed != *self.wind.packed {
            self.ring = self.method.ring_after(&self.wind.packed, &wind.packed, &self.ring, self.time);
        }
        self.wind = wind.clone();
        self.rotations = None;
    }
    fn reset(&mut self, _ctx: &GpuContext, time: f32) {
        self.time = time;
    }
    fn advance(&mut self, ctx: &GpuContext, dt: f32, steps: usize) {
        // Time accumulates step by step, as on the CPU.
        let mut t = self.time;
        for _ in 0..steps {
            t += dt;
        }
        self.submit(ctx, t);
    }
    fn time(&self) -> f32 {
        self.time
    }
    fn pose_buffers(&self) -> &GpuPose {
        &self.pose
    }
}
