//! Akagi's method on the GPU: forces, one propagation dispatch per depth (deepest first),
//! springs and the pose seam, all in one submission per step; the state stays on the GPU.

use super::{BuildError, GpuAnimator};
use crate::kernel::{Kernel, output, upload};
use crate::leaves::GpuLeafFlutter;
use crate::pose::{GpuPose, upload_buckets};
use crate::wind::GpuWind;
use crate::{GpuContext, GpuError};
use std::sync::Arc;
use sylva_core::Tree;
use sylva_core::methods::MethodOptions;
use sylva_core::methods::akagi::{Akagi, AkagiParams, RawAkagiStep};
use sylva_core::pose::Placement;

/// Akagi's method on the GPU for one tree.
#[derive(Debug)]
pub struct GpuAkagi {
    tree: Arc<Tree>,
    forces: Arc<Kernel>,
    subtree: Arc<Kernel>,
    integrate: Arc<Kernel>,
    pose: GpuPose,
    wind: GpuWind,
    segments: wgpu::Buffer,
    akagi: wgpu::Buffer,
    step: wgpu::Buffer,
    method_step: RawAkagiStep,
    buckets: Vec<(wgpu::Buffer, u32)>,
    child_offset: wgpu::Buffer,
    child_count: wgpu::Buffer,
    child_index: wgpu::Buffer,
    /// Own drag and centre per segment (two entries each).
    f_own: wgpu::Buffer,
    /// Force, moment and damping beyond each joint (three entries each).
    sub: wgpu::Buffer,
    theta: wgpu::Buffer,
    omega: wgpu::Buffer,
    leaves: GpuLeafFlutter,
    /// Simulated time, s.
    pub time: f32,
}

impl GpuAkagi {
    /// Uploads the tree and Akagi's constants and binds the scene's wind; the state starts at
    /// rest.
    pub fn new(ctx: &GpuContext, tree: Arc<Tree>, method: &Akagi, wind: &GpuWind) -> Result<Self, GpuError> {
        let n = tree.segments.len();
        let pose = GpuPose::new(ctx, &tree)?;
        let c = &tree.children;
        let index = if c.index.is_empty() { vec![0u32] } else { c.index.clone() };
        let this = Self {
            forces: Kernel::get(ctx, "akagi_forces"),
            subtree: Kernel::get(ctx, "akagi_subtree"),
            integrate: Kernel::get(ctx, "akagi_integrate"),
            pose,
            wind: wind.clone(),
            segments: upload(ctx, "segments", &tree.raw_segments())?,
            akagi: upload(ctx, "akagi segments", &method.segments)?,
            step: upload(ctx, "akagi step", &[method.step_params(0.0, 0.0)])?,
            method_step: method.step_params(0.0, 0.0),
            buckets: upload_buckets(ctx, "akagi bucket", &method.buckets)?,
            child_offset: upload(ctx, "child offsets", &c.offset)?,
            child_count: upload(ctx, "child counts", &c.count)?,
            child_index: upload(ctx, "child indices", &index)?,
            f_own: output::<[f32; 4]>(ctx, "own forces", 2 * n)?,
            sub: output::<[f32; 4]>(ctx, "subtree sums", 3 * n)?,
            theta: output::<[f32; 4]>(ctx, "theta", n)?,
            omega: output::<[f32; 4]>(ctx, "omega", n)?,
            leaves: GpuLeafFlutter::new(ctx, &method.leaves)?,
            time: 0.0,
            tree,
        };
        this.pose.write_rest(ctx, &this.tree);
        Ok(this)
    }

    /// Advances by `dt` seconds (one step; submitted, not waited for).
    pub fn step(&mut self, ctx: &GpuContext, dt: f32) {
        self.time += dt;
        let step = RawAkagiStep { time: self.time, dt, ..self.method_step };
        ctx.queue.write_buffer(&self.step, 0, bytemuck::bytes_of(&step));
        let n = self.pose.segment_count() as u32;
        let (joints, acc, delta) = (self.pose.joints_buffer(), self.pose.acc_buffer(), self.pose.delta_buffer());
        let mut e = ctx.device.create_command_encoder(&Default::default());
        self.forces.record(
            ctx,
            &mut e,
            &[&self.wind.fields, &self.wind.waves, &self.segments, &self.akagi, joints, acc, &self.step, &self.f_own],
            n,
        );
        for (bucket, len) in &self.buckets {
            self.subtree.record(
                ctx,
                &mut e,
                &[bucket, &self.child_offset, &self.child_count, &self.child_index, &self.f_own, joints, &self.sub],
                *len,
            );
        }
        self.integrate.record(
            ctx,
            &mut e,
            &[&self.segments, &self.akagi, &self.sub, acc, &self.step, &self.theta, &self.omega, delta],
            n,
        );
        self.pose.record(ctx, &mut e);
        self.leaves.record_pose(ctx, &mut e, &self.wind, &self.pose, self.time);
        ctx.submit([e.finish()]);
    }
}

/// The registry's GPU constructor: Akagi's method on `tree` (its copies share it).
pub fn animator(
    ctx: &GpuContext,
    tree: Arc<Tree>,
    options: &MethodOptions,
    wind: &GpuWind,
    _instances: &[Placement],
) -> Result<Box<dyn GpuAnimator>, BuildError> {
    let params = options.parse::<AkagiParams>("akagi")?;
    params.check()?;
    let method = Akagi::new(&tree, params);
    Ok(Box::new(GpuAkagi::new(ctx, tree, &method, wind)?))
}

impl GpuAnimator for GpuAkagi {
    fn name(&self) -> &'static str {
        "akagi"
    }
    fn tree(&self) -> &Arc<Tree> {
        &self.tree
    }
    fn set_wind(&mut self, wind: &GpuWind) {
        self.wind = wind.clone();
    }
    fn reset(&mut self, ctx: &GpuContext, time: f32) {
        let zero = vec![[0.0f32; 4]; self.tree.segments.len()];
        ctx.queue.write_buffer(&self.theta, 0, bytemuck::cast_slice(&zero));
        ctx.queue.write_buffer(&self.omega, 0, bytemuck::cast_slice(&zero));
        self.pose.write_rest(ctx, &self.tree);
        self.time = time;
    }
    fn advance(&mut self, ctx: &GpuContext, dt: f32, steps: usize) {
        for _ in 0..steps {
            self.step(ctx, dt);
        }
    }
    fn time(&self) -> f32 {
        self.time
    }
    fn pose_buffers(&self) -> &GpuPose {
        &self.pose
    }
}
