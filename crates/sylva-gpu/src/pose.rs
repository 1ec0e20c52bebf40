//! GPU twin of the pose seam ([`sylva_core::animate`]): forward kinematics from per-segment
//! rotations, and Zioma's method producing those rotations on the GPU.

use crate::kernel::{Kernel, output, read_back, upload};
use crate::shader::{NOISE, POSE_ACCUMULATE, POSE_LEVEL, POSE_POSITIONS, QUAT, TREE, WIND, ZIOMA_ROTATIONS};
use crate::{GpuContext, GpuError};
use glam::{Quat, Vec3};
use std::sync::Arc;
use sylva_core::Tree;
use sylva_core::animate::Pose;
use sylva_core::animate::zioma::{RawZiomaFrame, Zioma, ZiomaInstance};
use sylva_core::wind::WindScene;
use sylva_core::wind::raw::{RawField, RawWave};

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
fn upload_buckets(
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
                upload_buckets(ctx, "fk level", &sylva_core::cpu::pose_fk::depth_buckets(&tree.segments.parent))?
            }
        };
        let rest: Vec<[f32; 4]> = tree.segments.start.iter().map(|p| p.extend(0.0).to_array()).collect();
        Ok(Self {
            accumulate: Kernel::cached(ctx, "pose_accumulate", &[QUAT, TREE, POSE_ACCUMULATE]),
            positions: Kernel::cached(ctx, "pose_positions", &[QUAT, TREE, POSE_POSITIONS]),
            level: Kernel::cached(ctx, "pose_level", &[QUAT, TREE, POSE_LEVEL]),
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

/// Zioma's method on the GPU: rotations from `zioma_rotations.wgsl`, pose from [`GpuPose`],
/// all in one submission per frame.
#[derive(Debug)]
pub struct GpuZioma {
    kernel: Arc<Kernel>,
    pose: GpuPose,
    fields: wgpu::Buffer,
    waves: wgpu::Buffer,
    segments: wgpu::Buffer,
    stems: wgpu::Buffer,
    frame: wgpu::Buffer,
    packed: (Vec<RawField>, Vec<RawWave>),
    instances: Vec<ZiomaInstance>,
}

impl GpuZioma {
    /// Replaces the wind (a viewer's edits, a blast placed live).
    pub fn set_wind(&mut self, ctx: &GpuContext, wind: &WindScene) -> Result<(), GpuError> {
        let (fields, waves) = wind.pack();
        (self.fields, self.waves) = crate::wind_sample::upload_wind(ctx, &fields, &waves)?;
        self.packed = (fields, waves);
        Ok(())
    }

    /// The pose seam's buffers on the GPU (for meshing without a round trip).
    pub fn gpu_pose(&self) -> &GpuPose {
        &self.pose
    }

    /// Uploads the tree, Zioma's per-stem constants and the wind scene.
    pub fn new(ctx: &GpuContext, tree: &Tree, method: &Zioma, wind: &WindScene) -> Result<Self, GpuError> {
        Self::with_instances(ctx, tree, method, wind, &[])
    }

    /// Many placed instances of the tree (§6.5 instancing): one dispatch for every
    /// (instance, segment) and one forward-kinematics pass over them all per frame. An empty
    /// list is the single tree at the origin.
    pub fn with_instances(
        ctx: &GpuContext,
        tree: &Tree,
        method: &Zioma,
        wind: &WindScene,
        instances: &[ZiomaInstance],
    ) -> Result<Self, GpuError> {
        let (fields, waves) = wind.pack();
        let count = instances.len().max(1);
        let (wind_fields, wind_waves) = crate::wind_sample::upload_wind(ctx, &fields, &waves)?;
        Ok(Self {
            kernel: Kernel::cached(ctx, "zioma_rotations", &[QUAT, TREE, NOISE, WIND, ZIOMA_ROTATIONS]),
            pose: GpuPose::with_instances(ctx, tree, count)?,
            fields: wind_fields,
            waves: wind_waves,
            segments: upload(ctx, "segments", &tree.raw_segments())?,
            stems: upload(ctx, "zioma stems", &method.stems)?,
            frame: upload(ctx, "zioma frames", &vec![RawZiomaFrame::default_zeroed(); count])?,
            packed: (fields, waves),
            instances: instances.to_vec(),
        })
    }

    /// Records and submits every instance's pose at time `t` without reading it back (the
    /// per-instance frame values are computed on the CPU: one wind sample and the trunk
    /// bands each).
    pub fn submit(&self, ctx: &GpuContext, tree: &Tree, method: &Zioma, t: f32) {
        let frames: Vec<RawZiomaFrame> = if self.instances.is_empty() {
            vec![method.frame(tree, &self.packed.0, &self.packed.1, t)]
        } else {
            self.instances.iter().map(|i| method.frame_for(tree, &self.packed.0, &self.packed.1, t, Some(i))).collect()
        };
        ctx.queue.write_buffer(&self.frame, 0, bytemuck::cast_slice(&frames));
        let mut encoder = ctx.device.create_command_encoder(&Default::default());
        self.kernel.record(
            ctx,
            &mut encoder,
            &[&self.fields, &self.waves, &self.segments, &self.stems, &self.frame, self.pose.delta_buffer()],
            (self.pose.n * self.pose.instances) as u32,
        );
        self.pose.record(ctx, &mut encoder);
        ctx.queue.submit([encoder.finish()]);
    }

    /// Every instance's pose at time `t`.
    pub fn poses(&self, ctx: &GpuContext, tree: &Tree, method: &Zioma, t: f32) -> Result<Vec<Pose>, GpuError> {
        self.submit(ctx, tree, method, t);
        self.pose.read_all(ctx)
    }

    /// The pose at time `t`: the per-tree frame values are computed on the CPU (one wind
    /// sample and the trunk bands), everything per segment on the GPU.
    pub fn pose(&self, ctx: &GpuContext, tree: &Tree, method: &Zioma, t: f32) -> Result<Pose, GpuError> {
        self.submit(ctx, tree, method, t);
        self.pose.read(ctx)
    }
}

trait Zeroed {
    fn default_zeroed() -> Self;
}

impl Zeroed for RawZiomaFrame {
    fn default_zeroed() -> Self {
        bytemuck::Zeroable::zeroed()
    }
}

/// Akagi's method on the GPU: forces, one propagation dispatch per depth (deepest first),
/// springs and the pose seam, all in one submission per step; the state stays on the GPU.
#[derive(Debug)]
pub struct GpuAkagi {
    forces: Arc<Kernel>,
    subtree: Arc<Kernel>,
    integrate: Arc<Kernel>,
    pose: GpuPose,
    fields: wgpu::Buffer,
    waves: wgpu::Buffer,
    segments: wgpu::Buffer,
    akagi: wgpu::Buffer,
    step: wgpu::Buffer,
    method_step: sylva_core::animate::akagi::RawAkagiStep,
    buckets: Vec<(wgpu::Buffer, u32)>,
    child_offset: wgpu::Buffer,
    child_count: wgpu::Buffer,
    child_index: wgpu::Buffer,
    f_own: wgpu::Buffer,
    f_sub: wgpu::Buffer,
    theta: wgpu::Buffer,
    omega: wgpu::Buffer,
    /// Simulated time, s.
    pub time: f32,
}

impl GpuAkagi {
    /// Replaces the wind (a viewer's edits, a blast placed live); the state is kept.
    pub fn set_wind(&mut self, ctx: &GpuContext, wind: &WindScene) -> Result<(), GpuError> {
        let (fields, waves) = wind.pack();
        (self.fields, self.waves) = crate::wind_sample::upload_wind(ctx, &fields, &waves)?;
        Ok(())
    }

    /// The pose seam's buffers on the GPU (for meshing without a round trip).
    pub fn gpu_pose(&self) -> &GpuPose {
        &self.pose
    }

    /// Uploads the tree, Akagi's constants and the wind; the state starts at rest.
    pub fn new(
        ctx: &GpuContext,
        tree: &Tree,
        method: &sylva_core::animate::akagi::Akagi,
        wind: &WindScene,
    ) -> Result<Self, GpuError> {
        use crate::shader::{AKAGI, AKAGI_FORCES, AKAGI_INTEGRATE, AKAGI_SUBTREE};
        let (fields, waves) = wind.pack();
        let (wind_fields, wind_waves) = crate::wind_sample::upload_wind(ctx, &fields, &waves)?;
        let n = tree.segments.len();
        let pose = GpuPose::new(ctx, tree)?;
        // The pose seam's accumulated rotations start at the identity.
        ctx.queue.write_buffer(&pose.acc, 0, bytemuck::cast_slice(&vec![[0.0f32, 0.0, 0.0, 1.0]; n]));
        let rest: Vec<[f32; 4]> = tree.segments.start.iter().map(|p| p.extend(0.0).to_array()).collect();
        ctx.queue.write_buffer(&pose.joints, 0, bytemuck::cast_slice(&rest));
        let c = &tree.children;
        let index = if c.index.is_empty() { vec![0u32] } else { c.index.clone() };
        Ok(Self {
            forces: Kernel::cached(ctx, "akagi_forces", &[QUAT, TREE, NOISE, WIND, AKAGI, AKAGI_FORCES]),
            subtree: Kernel::cached(ctx, "akagi_subtree", &[AKAGI_SUBTREE]),
            integrate: Kernel::cached(ctx, "akagi_integrate", &[QUAT, TREE, AKAGI, AKAGI_INTEGRATE]),
            pose,
            fields: wind_fields,
            waves: wind_waves,
            segments: upload(ctx, "segments", &tree.raw_segments())?,
            akagi: upload(ctx, "akagi segments", &method.segments)?,
            step: upload(ctx, "akagi step", &[method.step_params(0.0, 0.0)])?,
            method_step: method.step_params(0.0, 0.0),
            buckets: upload_buckets(ctx, "akagi bucket", &method.buckets)?,
            child_offset: upload(ctx, "child offsets", &c.offset)?,
            child_count: upload(ctx, "child counts", &c.count)?,
            child_index: upload(ctx, "child indices", &index)?,
            f_own: output::<[f32; 4]>(ctx, "own forces", n)?,
            f_sub: output::<[f32; 4]>(ctx, "subtree forces", n)?,
            theta: output::<[f32; 4]>(ctx, "theta", n)?,
            omega: output::<[f32; 4]>(ctx, "omega", n)?,
            time: 0.0,
        })
    }

    /// Advances by `dt` seconds (one step; submitted, not waited for).
    pub fn step(&mut self, ctx: &GpuContext, dt: f32) {
        self.time += dt;
        let step = sylva_core::animate::akagi::RawAkagiStep { time: self.time, dt, ..self.method_step };
        ctx.queue.write_buffer(&self.step, 0, bytemuck::bytes_of(&step));
        let n = self.pose.n as u32;
        let mut e = ctx.device.create_command_encoder(&Default::default());
        self.forces.record(
            ctx,
            &mut e,
            &[
                &self.fields,
                &self.waves,
                &self.segments,
                &self.akagi,
                &self.pose.joints,
                &self.pose.acc,
                &self.step,
                &self.f_own,
            ],
            n,
        );
        for (bucket, len) in &self.buckets {
            self.subtree.record(
                ctx,
                &mut e,
                &[bucket, &self.child_offset, &self.child_count, &self.child_index, &self.f_own, &self.f_sub],
                *len,
            );
        }
        self.integrate.record(
            ctx,
            &mut e,
            &[
                &self.segments,
                &self.akagi,
                &self.f_sub,
                &self.pose.acc,
                &self.step,
                &self.theta,
                &self.omega,
                &self.pose.delta,
            ],
            n,
        );
        self.pose.record(ctx, &mut e);
        ctx.queue.submit([e.finish()]);
    }

    /// Reads the current pose back (waits for the GPU).
    pub fn read(&self, ctx: &GpuContext) -> Result<Pose, GpuError> {
        self.pose.read(ctx)
    }
}

/// Skjermo's method on the GPU: the step (ping-pong state buffers), the seam rotations and
/// forward kinematics in one submission per step.
#[derive(Debug)]
pub struct GpuSkjermo {
    step_kernel: Arc<Kernel>,
    rotations: Arc<Kernel>,
    pose: GpuPose,
    fields: wgpu::Buffer,
    waves: wgpu::Buffer,
    stems: wgpu::Buffer,
    params: wgpu::Buffer,
    step: wgpu::Buffer,
    state: [wgpu::Buffer; 2],
    current: usize,
    n_stems: usize,
    method_step: sylva_core::animate::skjermo::RawSkjermoStep,
    /// Simulated time, s.
    pub time: f32,
}

impl GpuSkjermo {
    /// Replaces the wind (a viewer's edits, a blast placed live); the state is kept.
    pub fn set_wind(&mut self, ctx: &GpuContext, wind: &WindScene) -> Result<(), GpuError> {
        let (fields, waves) = wind.pack();
        (self.fields, self.waves) = crate::wind_sample::upload_wind(ctx, &fields, &waves)?;
        Ok(())
    }

    /// Skjermo's per-stem constants on the GPU (`RawSkjermoStem`).
    pub fn stems_buffer(&self) -> &wgpu::Buffer {
        &self.stems
    }

    /// The current per-stem state (`RawSkjermoState`: control-point displacements).
    pub fn state_buffer(&self) -> &wgpu::Buffer {
        &self.state[self.current]
    }

    /// The pose seam's buffers on the GPU (for meshing without a round trip).
    pub fn gpu_pose(&self) -> &GpuPose {
        &self.pose
    }

    /// Uploads the tree, Skjermo's constants and the wind; the state starts at rest.
    pub fn new(
        ctx: &GpuContext,
        tree: &Tree,
        method: &sylva_core::animate::skjermo::Skjermo,
        wind: &WindScene,
    ) -> Result<Self, GpuError> {
        use crate::shader::{SKJERMO, SKJERMO_ROTATIONS, SKJERMO_STEP};
        use sylva_core::animate::skjermo::RawSkjermoState;
        let (fields, waves) = wind.pack();
        let (wind_fields, wind_waves) = crate::wind_sample::upload_wind(ctx, &fields, &waves)?;
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
        let rest: Vec<RawSkjermoState> =
            orient.iter().map(|o| RawSkjermoState { delta: [[0.0; 4]; 4], orient: *o }).collect();
        Ok(Self {
            step_kernel: Kernel::cached(ctx, "skjermo_step", &[QUAT, TREE, NOISE, WIND, SKJERMO, SKJERMO_STEP]),
            rotations: Kernel::cached(ctx, "skjermo_rotations", &[QUAT, TREE, SKJERMO, SKJERMO_ROTATIONS]),
            pose: GpuPose::new(ctx, tree)?,
            fields: wind_fields,
            waves: wind_waves,
            stems: stems_buffer,
            params: upload(ctx, "segment params", &method.segment_param)?,
            step: upload(ctx, "skjermo step", &[method.step_params(0.0)])?,
            state: [upload(ctx, "skjermo state a", &rest)?, upload(ctx, "skjermo state b", &rest)?],
            current: 0,
            n_stems: method.stems.len(),
            method_step: method.step_params(0.0),
            time: 0.0,
        })
    }

    /// The rest orientation vectors computed on the device: `skjermo_rest_orient` once per
    /// stem depth, ping-pong, over the uploaded `stems` (whose parent orientations it does
    /// not read; waits for the GPU).
    fn rest_orientations(
        ctx: &GpuContext,
        stems: &wgpu::Buffer,
        method: &sylva_core::animate::skjermo::Skjermo,
    ) -> Result<Vec<[f32; 4]>, GpuError> {
        use crate::shader::{SKJERMO, SKJERMO_REST_ORIENT};
        let kernel = Kernel::cached(ctx, "skjermo_rest_orient", &[QUAT, TREE, SKJERMO, SKJERMO_REST_ORIENT]);
        let orient = [
            upload(ctx, "skjermo rest orientations a", &method.rest_orient)?,
            output::<[f32; 4]>(ctx, "skjermo rest orientations b", method.stems.len())?,
        ];
        let levels = sylva_core::cpu::skjermo::stem_depth(&method.stems) + 1;
        let mut e = ctx.device.create_command_encoder(&Default::default());
        for level in 0..levels {
            let (from, to) = (&orient[level % 2], &orient[1 - level % 2]);
            kernel.record(ctx, &mut e, &[stems, from, to], method.stems.len() as u32);
        }
        ctx.queue.submit([e.finish()]);
        read_back(ctx, &orient[levels % 2], method.stems.len())
    }

    /// Advances by one step of `dt` seconds (submitted, not waited for).
    pub fn step(&mut self, ctx: &GpuContext, dt: f32) {
        self.advance(ctx, dt, true);
    }

    /// Advances the curves only (no pose): Skjermo's branch update as the paper measures it.
    pub fn step_only(&mut self, ctx: &GpuContext, dt: f32) {
        self.advance(ctx, dt, false);
    }

    fn advance(&mut self, ctx: &GpuContext, dt: f32, with_pose: bool) {
        self.time += dt;
        let step = sylva_core::animate::skjermo::RawSkjermoStep { time: self.time, ..self.method_step };
        ctx.queue.write_buffer(&self.step, 0, bytemuck::bytes_of(&step));
        let (prev, next) = (&self.state[self.current], &self.state[1 - self.current]);
        let mut e = ctx.device.create_command_encoder(&Default::default());
        self.step_kernel.record(
            ctx,
            &mut e,
            &[&self.fields, &self.waves, &self.stems, prev, &self.step, next],
            self.n_stems as u32,
        );
        if with_pose {
            self.rotations.record(
                ctx,
                &mut e,
                &[&self.params, &self.stems, next, &self.pose.parents, &self.pose.delta],
                self.pose.n as u32,
            );
            self.pose.record(ctx, &mut e);
        }
        ctx.queue.submit([e.finish()]);
        self.current = 1 - self.current;
    }

    /// Reads the current pose back, with the animated Béziers (waits for the GPU).
    pub fn read(&self, ctx: &GpuContext, method: &sylva_core::animate::skjermo::Skjermo) -> Result<Pose, GpuError> {
        let mut pose = self.pose.read(ctx)?;
        let state: Vec<sylva_core::animate::skjermo::RawSkjermoState> =
            read_back(ctx, &self.state[self.current], self.n_stems)?;
        pose.bezier = Some(
            method
                .stems
                .iter()
                .zip(&state)
                .map(|(r, s)| {
                    [0, 1, 2, 3].map(|j| Vec3::from_slice(&r.rest[j][..3]) + Vec3::from_slice(&s.delta[j][..3]))
                })
                .collect(),
        );
        Ok(pose)
    }
}
