//! Hierarchical shape matching on the GPU (Song §5.2): the four stages as compute kernels
//! over the same linearised buffers as the CPU ([`sylva_core::methods::hsm::HsmLayout`]),
//! every substep of a step (and the pose) recorded into one command submission. The state
//! stays on the GPU; read it back with [`GpuHsm::read_state`] or [`GpuHsm::read_pose`].
//!
//! Stage 1 `hsm_clusters` runs one 64-invocation workgroup per cluster with a shared-memory
//! reduction; stage 2, the synchronisation, is the boundary between dispatches; stage 3
//! `hsm_goals` and stage 4 `hsm_integrate` run one invocation per particle, or fused as
//! `hsm_particles` ([`sylva_core::methods::hsm::HsmParams::fused`]). Each substep's
//! parameters (its time) are written once per submission and copied, up to
//! [`SUBSTEPS_PER_PASS`] at a time, into as many slots ([`StepSlots`]): one submission
//! carries every substep, up to 64 substeps share a compute pass, and their bind groups are
//! made once.

use super::{BuildError, GpuAnimator};
use crate::kernel::{Kernel, Plan, compute_pass, output, upload};
use crate::pose::GpuPose;
use crate::step_slots::StepSlots;
use crate::wind::GpuWind;
use crate::{GpuContext, GpuError};
use glam::Vec3;
use std::sync::Arc;
use sylva_core::Tree;
use sylva_core::methods::MethodOptions;
use sylva_core::methods::hsm::{Hsm, HsmParams, HsmState, RawHsmClusterState, RawHsmStep};
use sylva_core::pose::{Placement, Pose};

/// Song's four stages on the GPU for one [`Hsm`] (a tree or a forest of copies).
#[derive(Debug)]
pub struct GpuHsm {
    method: Arc<Hsm>,
    tree: Option<Arc<Tree>>,
    clusters_kernel: Arc<Kernel>,
    goals_kernel: Arc<Kernel>,
    integrate_kernel: Arc<Kernel>,
    particles_kernel: Arc<Kernel>,
    fused: bool,
    pose_kernel: Arc<Kernel>,
    pose: Option<GpuPose>,
    wind: GpuWind,
    info: wgpu::Buffer,
    clusters: wgpu::Buffer,
    slots: wgpu::Buffer,
    owner: wgpu::Buffer,
    member_offset: wgpu::Buffer,
    member: wgpu::Buffer,
    segment_cluster: wgpu::Buffer,
    leaf_pose_kernel: Arc<Kernel>,
    leaves: wgpu::Buffer,
    /// [`SUBSTEPS_PER_PASS`] slots of substep parameters: substep k of a pass reads slot k.
    steps: StepSlots<RawHsmStep>,
    displacement: wgpu::Buffer,
    velocity: wgpu::Buffer,
    state: wgpu::Buffer,
    goal: wgpu::Buffer,
    n_clusters: usize,
    n_particles: usize,
    /// The pose's dispatches, bound once: segment rotations, then leaf rotations.
    pose_plan: Plan,
    leaf_plan: Plan,
    /// A substep's dispatches (stage 1, then the fused particle pass or stages 3 and 4), one
    /// plan per slot of `steps`, all bound on first use after the wind is set.
    substep: Option<Vec<Plan>>,
    /// Simulated time, s.
    pub time: f32,
}

/// Most substeps recorded into one submission by [`GpuHsm::advance_steps`]; longer runs are split.
pub const MAX_SUBSTEPS_PER_SUBMISSION: usize = 4096;

/// Substeps recorded into one compute pass: their parameters are copied into that many slots
/// once before the pass, rather than one copy and one pass per substep.
pub const SUBSTEPS_PER_PASS: usize = 64;

impl GpuHsm {
    /// The pose seam's buffers on the GPU, when built with the tree.
    pub fn gpu_pose(&self) -> Option<&GpuPose> {
        self.pose.as_ref()
    }

    /// Uploads the layout and the wind; the state starts at `method.rest_state()`. With a
    /// `tree`, each step also writes the pose (the layout's segment clusters must be the
    /// tree's); without one (a forest for benchmarks) only the particles are simulated.
    pub fn new(ctx: &GpuContext, tree: Option<Arc<Tree>>, method: Arc<Hsm>, wind: &GpuWind) -> Result<Self, GpuError> {
        let l = &method.layout;
        let rest_state = method.state_at_rest();
        let pose = match &tree {
            Some(t) => Some(GpuPose::new(ctx, t)?),
            None => None,
        };
        let step = method.step_params(0.0, 0.0);
        let mut this = Self {
            clusters_kernel: clusters_kernel(ctx, true),
            goals_kernel: Kernel::get(ctx, "hsm_goals"),
            integrate_kernel: Kernel::get(ctx, "hsm_integrate"),
            particles_kernel: Kernel::get(ctx, "hsm_particles"),
            fused: method.params.fused,
            pose_kernel: Kernel::get(ctx, "hsm_pose"),
            pose,
            wind: wind.clone(),
            info: upload(ctx, "hsm cluster info", &l.info)?,
            clusters: upload(ctx, "hsm clusters", &l.clusters)?,
            slots: upload(ctx, "hsm slots", &l.slots)?,
            owner: upload(ctx, "hsm owners", &l.owner)?,
            member_offset: upload(ctx, "hsm member offsets", &l.member_offset)?,
            member: upload(ctx, "hsm members", &l.member)?,
            segment_cluster: upload(ctx, "hsm segment clusters", &l.segment_cluster)?,
            leaf_pose_kernel: Kernel::get(ctx, "hsm_leaf_pose"),
            leaves: upload(ctx, "hsm leaves", &method.leaves)?,
            steps: StepSlots::new(ctx, "hsm substeps", SUBSTEPS_PER_PASS, step)?,
            displacement: upload(ctx, "hsm displacements", &rest_state.displacement)?,
            velocity: upload(ctx, "hsm velocities", &rest_state.velocity)?,
            state: upload(ctx, "hsm cluster state", &rest_state.clusters)?,
            goal: output::<[f32; 4]>(ctx, "hsm goals", l.rest.len())?,
            n_clusters: l.info.len(),
            n_particles: l.rest.len(),
            substep: None,
            pose_plan: Plan::default(),
            leaf_plan: Plan::default(),
            time: 0.0,
            method: method.clone(),
            tree,
        };
        ctx.queue.write_buffer(&this.goal, 0, bytemuck::cast_slice(&rest_state.goal));
        this.plan_pose(ctx);
        // The rest pose, until the first step writes one.
        let mut e = ctx.device.create_command_encoder(&Default::default());
        this.record_pose(ctx, &mut e);
        ctx.submit([e.finish()]);
        Ok(this)
    }

    /// Replaces the GPU state by `state` (for example a settled CPU state).
    pub fn write_state(&mut self, ctx: &GpuContext, state: &HsmState) {
        ctx.queue.write_buffer(&self.displacement, 0, bytemuck::cast_slice(&state.displacement));
        ctx.queue.write_buffer(&self.velocity, 0, bytemuck::cast_slice(&state.velocity));
        ctx.queue.write_buffer(&self.state, 0, bytemuck::cast_slice(&state.clusters));
        ctx.queue.write_buffer(&self.goal, 0, bytemuck::cast_slice(&state.goal));
        self.time = state.time;
    }

    /// The method's layout and parameters.
    pub fn method(&self) -> &Arc<Hsm> {
        &self.method
    }

    /// Stage 1's reduction: by subgroup shuffles below the subgroup size (the default where
    /// [`GpuContext::subgroup_size`] is known), or in shared memory throughout. Both add the
    /// same terms in the same order, so they give the same bits.
    pub fn set_subgroups(&mut self, ctx: &GpuContext, on: bool) {
        self.clusters_kernel = clusters_kernel(ctx, on);
        self.substep = None;
    }

    /// Whether stage 1 reduces by subgroup shuffles ([`Self::set_subgroups`]).
    pub fn subgroups(&self) -> bool {
        self.clusters_kernel.name == "hsm_clusters_subgroup"
    }

    /// Advances by one step of `dt` seconds in the method's substeps, all in one submission
    /// (not waited for).
    pub fn step(&mut self, ctx: &GpuContext, dt: f32) {
        self.advance_steps(ctx, dt, 1);
    }

    /// Advances by `steps` steps of `dt` seconds; every substep of up to
    /// [`MAX_SUBSTEPS_PER_SUBMISSION`] goes into one submission, the pose is written once at
    /// the end (not waited for).
    pub fn advance_steps(&mut self, ctx: &GpuContext, dt: f32, steps: usize) {
        let method = self.method.clone();
        let n = method.substeps(dt) as usize;
        let h = dt / n as f32;
        let total = steps * n;
        let mut done = 0;
        while done < total {
            let batch = (total - done).min(MAX_SUBSTEPS_PER_SUBMISSION);
            // Times accumulate substep by substep as on the CPU (`state.time + h`).
            // The wind sampled on each step's first substep only, as `Hsm::step_packed`.
            let params: Vec<RawHsmStep> = (done..done + batch)
                .map(|k| {
                    self.time += h;
                    RawHsmStep { sample_wind: (k % n == 0) as u32, ..method.step_params(self.time, h) }
                })
                .collect();
            self.steps.write(ctx, &params);
            let mut e = ctx.device.create_command_encoder(&wgpu::CommandEncoderDescriptor { label: Some("hsm") });
            let plans = match self.substep.take() {
                Some(p) => p,
                None => (0..SUBSTEPS_PER_PASS).map(|k| self.plan_substep(ctx, k)).collect(),
            };
            for first in (0..batch).step_by(SUBSTEPS_PER_PASS) {
                let count = (batch - first).min(SUBSTEPS_PER_PASS);
                self.steps.copy(&mut e, first, count);
                let mut pass = compute_pass(ctx, &mut e, "hsm substeps");
                for plan in &plans[..count] {
                    plan.dispatch(ctx, &mut pass);
                }
            }
            self.substep = Some(plans);
            done += batch;
            if done == total {
                self.record_pose(ctx, &mut e);
            }
            ctx.submit([e.finish()]);
        }
    }

    /// The dispatches of the substep that reads slot `slot` of `steps`.
    fn plan_substep(&self, ctx: &GpuContext, slot: usize) -> Plan {
        let lanes = sylva_core::methods::hsm::kernels::LANES as u32;
        let step = self.steps.binding(slot);
        fn all(b: &wgpu::Buffer) -> wgpu::BindingResource<'_> {
            b.as_entire_binding()
        }
        let mut plan = Plan::default();
        let resources = [
            all(&self.wind.fields),
            all(&self.wind.waves),
            all(&self.info),
            all(&self.clusters),
            all(&self.slots),
            all(&self.displacement),
            step.clone(),
            all(&self.state),
        ];
        plan.push_resources(ctx, &self.clusters_kernel, &resources, self.n_clusters as u32 * lanes);
        let n = self.n_particles as u32;
        if self.fused {
            let resources = [
                all(&self.member_offset),
                all(&self.member),
                all(&self.state),
                all(&self.owner),
                step,
                all(&self.displacement),
                all(&self.velocity),
            ];
            plan.push_resources(ctx, &self.particles_kernel, &resources, n);
        } else {
            plan.push(ctx, &self.goals_kernel, &[&self.member_offset, &self.member, &self.state, &self.goal], n);
            let resources = [
                all(&self.owner),
                all(&self.state),
                all(&self.goal),
                step,
                all(&self.displacement),
                all(&self.velocity),
            ];
            plan.push_resources(ctx, &self.integrate_kernel, &resources, n);
        }
        plan
    }

    fn record_pose(&self, ctx: &GpuContext, e: &mut wgpu::CommandEncoder) {
        if let Some(pose) = &self.pose {
            // One pass: segment rotations, the joints from them, the leaves from both.
            let mut pass = compute_pass(ctx, e, "hsm pose");
            self.pose_plan.dispatch(ctx, &mut pass);
            pose.dispatch_positions(ctx, &mut pass);
            self.leaf_plan.dispatch(ctx, &mut pass);
        }
    }

    /// Binds the pose's kernels once (their buffers never change): the segments' rotations
    /// from their clusters, and the leaves' from theirs.
    fn plan_pose(&mut self, ctx: &GpuContext) {
        let Some(pose) = &self.pose else { return };
        let mut plan = Plan::default();
        let buffers = [&self.segment_cluster, &self.state, pose.acc_buffer()];
        plan.push(ctx, &self.pose_kernel, &buffers, pose.segment_count() as u32);
        self.pose_plan = plan;
        let mut plan = Plan::default();
        if !self.method.leaves.is_empty() {
            let buffers =
                [&self.leaves, &self.slots, &self.displacement, &self.state, pose.acc_buffer(), pose.leaf_buffer()];
            plan.push(ctx, &self.leaf_pose_kernel, &buffers, self.method.leaves.len() as u32);
        }
        self.leaf_plan = plan;
    }

    /// Reads the particle and cluster state back (waits for the GPU).
    pub fn read_state(&self, ctx: &GpuContext) -> Result<HsmState, GpuError> {
        use crate::kernel::read_back;
        Ok(HsmState {
            displacement: read_back(ctx, &self.displacement, self.n_particles)?,
            velocity: read_back(ctx, &self.velocity, self.n_particles)?,
            clusters: read_back::<RawHsmClusterState>(ctx, &self.state, self.n_clusters)?,
            goal: read_back(ctx, &self.goal, self.n_particles)?,
            time: self.time,
        })
    }

    /// Reads the pose written by the last step back (waits for the GPU); `None` without a
    /// tree.
    pub fn read_pose(&self, ctx: &GpuContext) -> Result<Option<Pose>, GpuError> {
        self.pose.as_ref().map(|p| p.read(ctx)).transpose()
    }
}

/// Stage 1's kernel: with `subgroups` and a device of one subgroup size, the reduction by
/// shuffles below it; else in shared memory.
fn clusters_kernel(ctx: &GpuContext, subgroups: bool) -> Arc<Kernel> {
    match ctx.subgroup_size {
        Some(size) if subgroups => Kernel::get_with(ctx, "hsm_clusters_subgroup", &[("SUBGROUP_SIZE", size as f64)]),
        _ => Kernel::get(ctx, "hsm_clusters"),
    }
}

/// The registry's GPU constructor: hierarchical shape matching on `tree` (its copies share
/// it).
pub fn animator(
    ctx: &GpuContext,
    tree: Arc<Tree>,
    options: &MethodOptions,
    wind: &GpuWind,
    _instances: &[Placement],
) -> Result<Box<dyn GpuAnimator>, BuildError> {
    let params = options.parse::<HsmParams>("hsm")?;
    let method = Hsm::new(&tree, params).map_err(sylva_core::methods::MethodError::from)?;
    Ok(Box::new(GpuHsm::new(ctx, Some(tree), Arc::new(method), wind)?))
}

impl GpuAnimator for GpuHsm {
    fn name(&self) -> &'static str {
        "hsm"
    }
    fn tree(&self) -> &Arc<Tree> {
        self.tree.as_ref().expect("the registry builds HSM with its tree")
    }
    fn set_wind(&mut self, wind: &GpuWind) {
        self.wind = wind.clone();
        self.substep = None;
    }
    fn reset(&mut self, ctx: &GpuContext, time: f32) {
        self.write_state(ctx, &self.method.state_at_rest());
        self.time = time;
        let mut e = ctx.device.create_command_encoder(&Default::default());
        self.record_pose(ctx, &mut e);
        ctx.submit([e.finish()]);
    }
    fn advance(&mut self, ctx: &GpuContext, dt: f32, steps: usize) {
        self.advance_steps(ctx, dt, steps);
    }
    fn time(&self) -> f32 {
        self.time
    }
    fn pose_buffers(&self) -> &GpuPose {
        self.pose.as_ref().expect("the registry builds HSM with its tree")
    }
    fn cluster_centres(&self, ctx: &GpuContext) -> Result<Option<Vec<Vec3>>, GpuError> {
        let state = self.read_state(ctx)?;
        Ok(Some(state.clusters.iter().map(|c| Vec3::new(c.cm[0], c.cm[1], c.cm[2])).collect()))
    }
    fn particles(&self) -> Option<usize> {
        Some(self.n_particles)
    }
}
