//! Zioma's method on the GPU: every instance's frame values from `zioma_frames.wgsl`, the
//! rotations from `zioma_rotations.wgsl`, the pose from [`GpuPose`], every instance in one
//! submission per frame (§6.5 instancing). The CPU writes 64 bytes a frame (the tree's
//! [`sylva_core::methods::zioma::RawZiomaTrunk`] with the time), whatever the number of instances; each instance's
//! ring, taken at its own crown, is computed and uploaded when the wind changes.

pub mod frames;
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
use sylva_core::methods::zioma::{RawZiomaFrame, RawZiomaInstance, RawZiomaRing, Ring, Zioma, ZiomaParams};
use sylva_core::pose::{Placement, Pose};

/// Zioma's method on the GPU for one tree and its placed instances.
#[derive(Debug)]
pub struct GpuZioma {
    tree: Arc<Tree>,
    method: Zioma,
    frames_kernel: Arc<Kernel>,
    kernel: Arc<Kernel>,
    pose: GpuPose,
    wind: GpuWind,
    segments: wgpu::Buffer,
    stems: wgpu::Buffer,
    /// The tree's values for the frame ([`sylva_core::methods::zioma::RawZiomaTrunk`]), written each frame.
    trunk: wgpu::Buffer,
    /// The instances (one unturned at the origin for a single tree).
    instances: Vec<Placement>,
    /// As the kernel reads them ([`RawZiomaInstance`]).
    placements: wgpu::Buffer,
    /// Each instance's ring ([`RawZiomaRing`]), written when the wind changes.
    ring_buffer: wgpu::Buffer,
    /// One [`RawZiomaFrame`] per instance, written by the frame kernel.
    frame: wgpu::Buffer,
    leaves: GpuLeafFlutter,
    /// The frame and rotation kernels, bound on first use after the wind is set.
    rotations: Option<Plan>,
    /// Each instance's ring-down since the wind last changed, taken at its crown (as the
    /// CPU's state).
    rings: Vec<Ring>,
    /// The rings changed since they were last uploaded.
    rings_changed: bool,
    /// Time of the pose, s.
    pub time: f32,
}

impl GpuZioma {
    /// Uploads the tree and Zioma's per-stem constants; binds the scene's wind.
    pub fn new(ctx: &GpuContext, tree: Arc<Tree>, method: Zioma, wind: &GpuWind) -> Result<Self, GpuError> {
        Self::with_instances(ctx, tree, method, wind, &[])
    }

    /// Many placed instances of the tree (§6.5 instancing): one dispatch for every
    /// instance's frame values, one for every (instance, segment) and one forward-kinematics
    /// pass over them all per frame. An empty list is the single tree at the origin.
    pub fn with_instances(
        ctx: &GpuContext,
        tree: Arc<Tree>,
        method: Zioma,
        wind: &GpuWind,
        instances: &[Placement],
    ) -> Result<Self, GpuError> {
        let instances = if instances.is_empty() { vec![Placement::default()] } else { instances.to_vec() };
        let count = instances.len();
        let zeroed: RawZiomaFrame = bytemuck::Zeroable::zeroed();
        let placements: Vec<RawZiomaInstance> = instances.iter().map(RawZiomaInstance::from).collect();
        let rings = method.start_rings(&wind.packed.fields, &wind.packed.waves, &instances, 0.0);
        let raw_rings: Vec<RawZiomaRing> = rings.iter().map(RawZiomaRing::from).collect();
        Ok(Self {
            rings,
            rings_changed: false,
            frames_kernel: Kernel::get(ctx, "zioma_frames"),
            kernel: Kernel::get(ctx, "zioma_rotations"),
            pose: GpuPose::with_instances(ctx, &tree, count)?,
            wind: wind.clone(),
            segments: upload(ctx, "segments", &tree.raw_segments())?,
            stems: upload(ctx, "zioma stems", &method.stems)?,
            trunk: upload(ctx, "zioma trunk", &[method.raw_trunk(0.0)])?,
            placements: upload(ctx, "zioma instances", &placements)?,
            ring_buffer: upload(ctx, "zioma rings", &raw_rings)?,
            instances,
            frame: upload(ctx, "zioma frames", &vec![zeroed; count])?,
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

    /// Records and submits every instance's pose at time `t` without reading it back.
    pub fn submit(&mut self, ctx: &GpuContext, t: f32) {
        let mut encoder = ctx.device.create_command_encoder(&Default::default());
        self.record(ctx, &mut encoder, t);
        ctx.submit([encoder.finish()]);
    }

    /// Records every instance's pose at time `t` into `encoder`, for work that reads it in
    /// the same submission (skinning, meshing); the tree's values for the frame are written to
    /// the queue now, so record one pose per submission.
    pub fn record(&mut self, ctx: &GpuContext, encoder: &mut wgpu::CommandEncoder, t: f32) {
        self.time = t;
        if self.rings_changed {
            let raw: Vec<RawZiomaRing> = self.rings.iter().map(RawZiomaRing::from).collect();
            ctx.queue.write_buffer(&self.ring_buffer, 0, bytemuck::cast_slice(&raw));
            self.rings_changed = false;
        }
        let trunk = self.method.raw_trunk(t);
        ctx.queue.write_buffer(&self.trunk, 0, bytemuck::bytes_of(&trunk));
        let plan = self.rotations.get_or_insert_with(|| {
            let mut plan = Plan::default();
            let buffers =
                [&self.wind.fields, &self.wind.waves, &self.trunk, &self.placements, &self.ring_buffer, &self.frame];
            plan.push(ctx, &self.frames_kernel, &buffers, self.pose.instance_count() as u32);
            let buffers = [
                &self.wind.fields,
                &self.wind.waves,
                &self.segments,
                &self.stems,
                &self.frame,
                self.pose.delta_buffer(),
            ];
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

    /// The pose at time `t`.
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
            let (m, old) = (&self.method, &self.wind.packed);
            self.rings = m.instance_rings_after(old, &wind.packed, &self.rings, &self.instances, self.time);
            self.rings_changed = true;
        }
        self.wind = wind.clone();
        self.rotations = None;
    }
    /// Back to rest at `time`, as the CPU's `reset`: the wind starts blowing then, so every
    /// instance's ring is the one of a change from still air at `time`.
    fn reset(&mut self, _ctx: &GpuContext, time: f32) {
        self.rings = self.method.start_rings(&self.wind.packed.fields, &self.wind.packed.waves, &self.instances, time);
        self.rings_changed = true;
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
