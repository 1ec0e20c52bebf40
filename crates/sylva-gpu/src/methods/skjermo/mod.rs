//! Skjermo's method on the GPU: the steps (ping-pong state buffers; up to
//! [`STEPS_PER_PASS`] steps in one compute pass, each reading its parameters from its own
//! slot, [`StepSlots`]), then the seam rotations and forward kinematics, all in one
//! submission however many steps a frame advances; the curves stay on the device for the
//! deformer.

use super::{BuildError, GpuAnimator, GpuCurves};
use crate::kernel::{Kernel, Plan, compute_pass, output, read_back, upload};
use crate::leaves::GpuLeafFlutter;
use crate::pose::GpuPose;
use crate::step_slots::StepSlots;
use crate::wind::GpuWind;
use crate::{GpuContext, GpuError};
use bytemuck::Zeroable;
use glam::Vec3;
use std::sync::Arc;
use sylva_core::Tree;
use sylva_core::methods::MethodOptions;
use sylva_core::methods::skjermo::{RawSkjermoState, RawSkjermoStep, RawSkjermoSway, Skjermo, SkjermoParams};
use sylva_core::pose::{Placement, Pose};

/// Skjermo's method on the GPU for one tree.
#[derive(Debug)]
pub struct GpuSkjermo {
    tree: Arc<Tree>,
    step_kernel: Arc<Kernel>,
    rotations: Arc<Kernel>,
    pose: GpuPose,
    wind: GpuWind,
    stems: wgpu::Buffer,
    params: wgpu::Buffer,
    /// [`STEPS_PER_PASS`] slots of step parameters: step k of a pass reads slot k.
    steps: StepSlots<RawSkjermoStep>,
    /// Per slot, the step from state 0 to 1 and from 1 to 0, bound on first use after the
    /// wind is set.
    plans: Option<Vec<[Plan; 2]>>,
    /// The seam's rotations from state 0 and from state 1.
    rotation_plans: [Plan; 2],
    state: [wgpu::Buffer; 2],
    current: usize,
    modes: wgpu::Buffer,
    sway: wgpu::Buffer,
    /// The rest state (every displacement zero).
    rest: Vec<RawSkjermoState>,
    /// Each stem's rest control points.
    rest_curves: Vec<[Vec3; 4]>,
    method_step: RawSkjermoStep,
    leaves: GpuLeafFlutter,
    /// Simulated time, s.
    pub time: f32,
}

impl GpuSkjermo {
    /// Uploads the tree and Skjermo's constants and binds the scene's wind; the state starts
    /// at rest.
    pub fn new(ctx: &GpuContext, tree: Arc<Tree>, method: &Skjermo, wind: &GpuWind) -> Result<Self, GpuError> {
        // The rest orientations as this device rounds them (a GPU that fuses multiply-adds
        // rounds the attachment frames differently from the CPU): with the CPU's, a step in
        // still air would move the stems by rounding errors instead of keeping the rest.
        let stems_buffer = upload(ctx, "skjermo stems", &method.stems)?;
        let orient = Self::rest_orientations(ctx, &stems_buffer, method)?;
        let mut stems = method.stems.clone();
        for st in &mut stems {
            if st.parent != sylva_core::model::NONE {
                st.parent_orient = orient[st.parent as usize];
            }
        }
        ctx.queue.write_buffer(&stems_buffer, 0, bytemuck::cast_slice(&stems));
        let rest = vec![RawSkjermoState { delta: [[0.0; 4]; 4] }; method.stems.len()];
        let mut this = Self {
            leaves: GpuLeafFlutter::new(ctx, &method.leaves)?,
            step_kernel: Kernel::get(ctx, "skjermo_step"),
            rotations: Kernel::get(ctx, "skjermo_rotations"),
            pose: GpuPose::new(ctx, &tree)?,
            wind: wind.clone(),
            stems: stems_buffer,
            params: upload(ctx, "segment params", &method.segment_param)?,
            steps: StepSlots::new(ctx, "skjermo steps", STEPS_PER_PASS, method.step_params(0.0))?,
            plans: None,
            state: [upload(ctx, "skjermo state a", &rest)?, upload(ctx, "skjermo state b", &rest)?],
            current: 0,
            modes: upload(ctx, "skjermo modes", &method.modes)?,
            sway: upload(ctx, "skjermo sway", &vec![RawSkjermoSway::zeroed(); method.stems.len()])?,
            rest,
            rest_curves: method.stems.iter().map(|s| s.rest.map(|p| Vec3::from_slice(&p[..3]))).collect(),
            method_step: method.step_params(0.0),
            time: 0.0,
            tree,
            rotation_plans: Default::default(),
        };
        // The seam's rotations from either state buffer (their buffers never change).
        this.rotation_plans = [0, 1].map(|current| {
            let pose = &this.pose;
            let buffers = [&this.params, &this.stems, &this.state[current], pose.parents_buffer(), pose.delta_buffer()];
            let mut plan = Plan::default();
            plan.push(ctx, &this.rotations, &buffers, pose.segment_count() as u32);
            plan
        });
        Ok(this)
    }

    /// Skjermo's per-stem constants on the GPU (`RawSkjermoStem`).
    pub fn stems_buffer(&self) -> &wgpu::Buffer {
        &self.stems
    }

    /// The current per-stem state (`RawSkjermoState`: control-point displacements).
    pub fn state_buffer(&self) -> &wgpu::Buffer {
        &self.state[self.current]
    }

    /// The rest orientation vectors computed on the device: `skjermo_rest_orient` once per
    /// stem depth, ping-pong, over the uploaded `stems` (whose parent orientations it does
    /// not read; waits for the GPU).
    fn rest_orientations(ctx: &GpuContext, stems: &wgpu::Buffer, method: &Skjermo) -> Result<Vec<[f32; 4]>, GpuError> {
        let kernel = Kernel::get(ctx, "skjermo_rest_orient");
        let orient = [
            upload(ctx, "skjermo rest orientations a", &method.rest_orient)?,
            output::<[f32; 4]>(ctx, "skjermo rest orientations b", method.stems.len())?,
        ];
        let levels = sylva_core::methods::skjermo::kernels::stem_depth(&method.stems) + 1;
        let mut e = ctx.device.create_command_encoder(&Default::default());
        for level in 0..levels {
            let (from, to) = (&orient[level % 2], &orient[1 - level % 2]);
            kernel.record(ctx, &mut e, &[stems, from, to], method.stems.len() as u32);
        }
        ctx.submit([e.finish()]);
        read_back(ctx, &orient[levels % 2], method.stems.len())
    }

    /// Advances by one step of `dt` seconds (submitted, not waited for).
    pub fn step(&mut self, ctx: &GpuContext, dt: f32) {
        self.advance_steps(ctx, dt, 1, true);
    }

    /// Advances the curves only (no pose): Skjermo's branch update as the paper measures it.
    pub fn step_only(&mut self, ctx: &GpuContext, dt: f32) {
        self.advance_steps(ctx, dt, 1, false);
    }

    /// Advances by `steps` steps of `dt` seconds in one submission (not waited for): the
    /// steps' parameters are written once and copied, [`STEPS_PER_PASS`] at a time, into the
    /// slots that the steps of a pass read; the state buffers ping-pong; and with `with_pose`
    /// the seam's rotations, forward kinematics and leaves are written once, for the last
    /// step (the same pose as stepping one by one).
    pub fn advance_steps(&mut self, ctx: &GpuContext, dt: f32, steps: usize, with_pose: bool) {
        if steps == 0 {
            return;
        }
        // Times accumulate step by step, as on the CPU.
        let params: Vec<RawSkjermoStep> = (0..steps)
            .map(|_| {
                self.time += dt;
                RawSkjermoStep { time: self.time, dt, ..self.method_step }
            })
            .collect();
        self.steps.write(ctx, &params);
        let plans = match self.plans.take() {
            Some(p) => p,
            None => (0..STEPS_PER_PASS).map(|slot| [0, 1].map(|from| self.plan_step(ctx, slot, from))).collect(),
        };
        let mut e = ctx.device.create_command_encoder(&wgpu::CommandEncoderDescriptor { label: Some("skjermo") });
        for first in (0..steps).step_by(STEPS_PER_PASS) {
            let count = (steps - first).min(STEPS_PER_PASS);
            self.steps.copy(&mut e, first, count);
            let mut pass = compute_pass(ctx, &mut e, "skjermo steps");
            for slot in &plans[..count] {
                slot[self.current].dispatch(ctx, &mut pass);
                self.current = 1 - self.current;
            }
        }
        self.plans = Some(plans);
        if with_pose {
            let pose = &self.pose;
            self.rotation_plans[self.current].record(ctx, &mut e, "skjermo rotations");
            pose.record(ctx, &mut e);
            self.leaves.record_pose(ctx, &mut e, &self.wind, pose, self.time);
        }
        ctx.submit([e.finish()]);
    }

    /// The step from state `from` to the other, reading its parameters from slot `slot`.
    fn plan_step(&self, ctx: &GpuContext, slot: usize, from: usize) -> Plan {
        fn all(b: &wgpu::Buffer) -> wgpu::BindingResource<'_> {
            b.as_entire_binding()
        }
        let resources = [
            all(&self.wind.fields),
            all(&self.wind.waves),
            all(&self.stems),
            all(&self.state[from]),
            self.steps.binding(slot),
            all(&self.state[1 - from]),
            all(&self.modes),
            all(&self.sway),
        ];
        let mut plan = Plan::default();
        plan.push_resources(ctx, &self.step_kernel, &resources, self.rest.len() as u32);
        plan
    }

    /// Reads the current pose back, with the animated Béziers (waits for the GPU).
    pub fn read(&self, ctx: &GpuContext) -> Result<Pose, GpuError> {
        let mut pose = self.pose.read(ctx)?;
        let state: Vec<RawSkjermoState> = read_back(ctx, &self.state[self.current], self.rest.len())?;
        pose.bezier = Some(
            self.rest_curves
                .iter()
                .zip(&state)
                .map(|(r, s)| [0, 1, 2, 3].map(|j| r[j] + Vec3::from_slice(&s.delta[j][..3])))
                .collect(),
        );
        Ok(pose)
    }
}

/// Steps recorded into one compute pass: their parameters are copied into that many slots
/// once before the pass, rather than one copy and one pass per step.
pub const STEPS_PER_PASS: usize = 64;

/// The registry's GPU constructor: Skjermo's method on `tree` (its copies share it).
pub fn animator(
    ctx: &GpuContext,
    tree: Arc<Tree>,
    options: &MethodOptions,
    wind: &GpuWind,
    _instances: &[Placement],
) -> Result<Box<dyn GpuAnimator>, BuildError> {
    let params = options.parse::<SkjermoParams>("skjermo")?;
    params.check()?;
    let method = Skjermo::new(&tree, params);
    Ok(Box::new(GpuSkjermo::new(ctx, tree, &method, wind)?))
}

impl GpuAnimator for GpuSkjermo {
    fn name(&self) -> &'static str {
        "skjermo"
    }
    fn tree(&self) -> &Arc<Tree> {
        &self.tree
    }
    fn set_wind(&mut self, wind: &GpuWind) {
        self.wind = wind.clone();
        self.plans = None;
    }
    fn reset(&mut self, ctx: &GpuContext, time: f32) {
        for s in &self.state {
            ctx.queue.write_buffer(s, 0, bytemuck::cast_slice(&self.rest));
        }
        ctx.queue.write_buffer(&self.sway, 0, bytemuck::cast_slice(&vec![RawSkjermoSway::zeroed(); self.rest.len()]));
        self.current = 0;
        self.pose.write_rest(ctx, &self.tree);
        self.time = time;
    }
    fn advance(&mut self, ctx: &GpuContext, dt: f32, steps: usize) {
        self.advance_steps(ctx, dt, steps, true);
    }
    fn time(&self) -> f32 {
        self.time
    }
    fn pose_buffers(&self) -> &GpuPose {
        &self.pose
    }
    fn read_pose(&self, ctx: &GpuContext) -> Result<Pose, GpuError> {
        self.read(ctx)
    }
    fn curves(&self) -> Option<GpuCurves<'_>> {
        Some(GpuCurves { stems: &self.stems, state: &self.state[self.current] })
    }
}
