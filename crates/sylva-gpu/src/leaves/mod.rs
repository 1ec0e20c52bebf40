//! Leaves that move on the GPU ([`sylva_core::leaves`]): `leaf_wind.wgsl` samples the wind at
//! every twig, `leaf_flutter.wgsl` turns every leaf about its attachment from it, reading
//! the seam's rotations and writing the seam's leaf rotations ([`crate::pose::GpuPose`]).

use crate::kernel::{Kernel, Plan, PlanCache, output, upload};
use crate::pose::GpuPose;
use crate::wind::GpuWind;
use crate::{GpuContext, GpuError};
use std::sync::Arc;
use sylva_core::leaves::{LeafFlutter, RawLeafFrame};

/// A tree's leaf motion on the device: per-leaf constants, twigs and their wind.
#[derive(Debug)]
pub struct GpuLeafFlutter {
    wind_kernel: Arc<Kernel>,
    flutter_kernel: Arc<Kernel>,
    leaves: LeafFlutter,
    frame: wgpu::Buffer,
    motion: wgpu::Buffer,
    twigs: wgpu::Buffer,
    twig_wind: wgpu::Buffer,
    /// Both kernels bound to the last wind and seam buffers.
    plan: PlanCache,
}

impl GpuLeafFlutter {
    /// Uploads `leaves`' constants.
    pub fn new(ctx: &GpuContext, leaves: &LeafFlutter) -> Result<Self, GpuError> {
        Ok(Self {
            wind_kernel: Kernel::get(ctx, "leaf_wind"),
            flutter_kernel: Kernel::get(ctx, "leaf_flutter"),
            frame: upload(ctx, "leaf frame", &[leaves.frame(0.0)])?,
            motion: upload(ctx, "leaf motion", &leaves.leaves)?,
            twigs: upload(ctx, "leaf twigs", &leaves.twigs)?,
            twig_wind: output::<[f32; 4]>(ctx, "twig wind", 2 * leaves.twigs.len())?,
            leaves: leaves.clone(),
            plan: Default::default(),
        })
    }

    /// Records both kernels at time `t` on `pose`'s first instance: its leaf rotations
    /// from its joints and rotations.
    pub fn record_pose(
        &self,
        ctx: &GpuContext,
        encoder: &mut wgpu::CommandEncoder,
        wind: &GpuWind,
        pose: &GpuPose,
        t: f32,
    ) {
        self.record(ctx, encoder, wind, [pose.joints_buffer(), pose.acc_buffer(), pose.leaf_buffer()], t);
    }

    /// Records both kernels at time `t` on seam buffers `[joints, acc, leaf rotations]`: the
    /// wind at the twigs from the joints, then every leaf's rotation from it and `acc`.
    pub fn record(
        &self,
        ctx: &GpuContext,
        encoder: &mut wgpu::CommandEncoder,
        wind: &GpuWind,
        [joints, acc, out]: [&wgpu::Buffer; 3],
        t: f32,
    ) {
        if self.leaves.leaves.is_empty() || self.leaves.params.strength == 0.0 {
            return;
        }
        let frame: RawLeafFrame = self.leaves.frame(t);
        ctx.queue.write_buffer(&self.frame, 0, bytemuck::bytes_of(&frame));
        let plan = self.plan.get(&[&wind.fields, &wind.waves, joints, acc, out], || {
            let mut plan = Plan::default();
            let buffers = [&wind.fields, &wind.waves, &self.frame, &self.twigs, joints, &self.twig_wind];
            plan.push(ctx, &self.wind_kernel, &buffers, self.leaves.twigs.len() as u32);
            let buffers = [&self.frame, &self.motion, &self.twig_wind, acc, out];
            plan.push(ctx, &self.flutter_kernel, &buffers, self.leaves.leaves.len() as u32);
            plan
        });
        plan.record(ctx, encoder, "leaves");
    }
}
