//! Per-frame meshing on the GPU: `mesh_tubes.wgsl` (then `mesh_detail.wgsl` for the
//! midpoints of subdivided bands) and `mesh_leaves.wgsl` write vertex
//! buffers the renderer draws directly (no CPU round trip per frame), from the pose seam's
//! buffers — a GPU method's [`crate::pose::GpuPose`], or a CPU pose uploaded each frame.
//! [`skin`] poses a static rest mesh (Zioma §6.5), [`deform`] bends Skjermo's grid (§3).
//! The topology ([`MeshLayout`]: rings, index buffers) is uploaded once.

pub mod deform;
pub mod skin;

use crate::kernel::{Kernel, Plan, PlanCache, output, read_back, upload};
use crate::{GpuContext, GpuError};
use std::sync::Arc;
use sylva_core::Tree;
use sylva_core::mesh::{MeshFrame, MeshLayout, RawVertex, Uv};
use sylva_core::pose::Pose;
use sylva_core::pose::{SeamPose, pose_buffers};
use wgpu::util::DeviceExt;

/// One tree's mesh on the GPU: static topology, per-frame vertex buffers.
#[derive(Debug)]
pub struct GpuMesh {
    tubes: Arc<Kernel>,
    detail_kernel: Arc<Kernel>,
    leaves_kernel: Arc<Kernel>,
    info: wgpu::Buffer,
    rings: wgpu::Buffer,
    details: wgpu::Buffer,
    segments: wgpu::Buffer,
    leaves: wgpu::Buffer,
    /// Pose buffers used when the pose comes from the CPU.
    joint: wgpu::Buffer,
    acc: wgpu::Buffer,
    /// Leaf rotations used when the pose comes from the CPU (the identity: leaves at rest).
    leaf_rotation: wgpu::Buffer,
    /// Every leaf shape's rim ([`MeshLayout::leaf_rim_table`]), made once.
    leaf_rim: wgpu::Buffer,
    /// Bark vertices (storage + vertex buffer).
    pub tube_vertices: wgpu::Buffer,
    /// Bark triangle indices.
    pub tube_indices: wgpu::Buffer,
    /// Leaf vertices (storage + vertex buffer).
    pub leaf_vertices: wgpu::Buffer,
    /// Bark texture coordinates (static vertex buffer, [`MeshLayout::tube_uv`]).
    pub tube_uv: wgpu::Buffer,
    /// Leaf texture coordinates (static vertex buffer, [`MeshLayout::leaf_uv`]).
    pub leaf_uv: wgpu::Buffer,
    /// Leaf triangle indices.
    pub leaf_indices: wgpu::Buffer,
    /// Number of bark indices.
    pub tube_index_count: u32,
    /// Number of leaf indices.
    pub leaf_index_count: u32,
    tube_vertex_count: usize,
    leaf_vertex_count: usize,
    ring_count: usize,
    detail_count: usize,
    leaf_count: usize,
    segment_count: usize,
    leaf_slots: usize,
    staged: bool,
    /// The kernels bound to the last pose buffers meshed (a method's are the same every
    /// frame).
    plan: PlanCache,
    parts: MeshParts,
}

/// Which of the mesh kernels [`GpuMesh::record`] runs (all by default); a benchmark times
/// them one at a time ([`GpuMesh::set_parts`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct MeshParts {
    /// `mesh_tubes`: the rings' vertices.
    pub tubes: bool,
    /// `mesh_detail`: the subdivided bands' midpoints (reads the rings' vertices).
    pub detail: bool,
    /// `mesh_leaves`: the leaves' vertices.
    pub leaves: bool,
}

impl Default for MeshParts {
    fn default() -> Self {
        Self { tubes: true, detail: true, leaves: true }
    }
}

pub(crate) fn vertex_buffer(ctx: &GpuContext, label: &'static str, len: usize) -> Result<wgpu::Buffer, GpuError> {
    let bytes = (len * std::mem::size_of::<RawVertex>()).max(32) as u64;
    let limit = ctx.device.limits().max_storage_buffer_binding_size;
    if bytes > limit {
        return Err(GpuError::TooLarge { what: label, bytes, limit });
    }
    Ok(ctx.device.create_buffer(&wgpu::BufferDescriptor {
        label: Some(label),
        size: bytes,
        usage: wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::VERTEX | wgpu::BufferUsages::COPY_SRC,
        mapped_at_creation: false,
    }))
}

/// A buffer made once from `data` (one zero element when empty: a binding can't be).
fn static_buffer<T: bytemuck::Pod>(
    ctx: &GpuContext,
    label: &'static str,
    data: &[T],
    usage: wgpu::BufferUsages,
) -> wgpu::Buffer {
    let zero = [T::zeroed()];
    let contents = if data.is_empty() { &zero[..] } else { data };
    ctx.device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
        label: Some(label),
        contents: bytemuck::cast_slice(contents),
        usage,
    })
}

/// A static vertex buffer of texture coordinates (the second stream beside the vertices).
pub(crate) fn uv_buffer(ctx: &GpuContext, label: &'static str, uv: &[Uv]) -> wgpu::Buffer {
    static_buffer(ctx, label, uv, wgpu::BufferUsages::VERTEX)
}

pub(crate) fn index_buffer(ctx: &GpuContext, label: &'static str, indices: &[u32]) -> wgpu::Buffer {
    static_buffer(ctx, label, indices, wgpu::BufferUsages::INDEX)
}

/// The bark or leaf kernel, its runs of vertices staged in workgroup memory or written
/// directly (`STAGE_RUNS` in `vertex_stage.wgsl`).
fn run_kernel(ctx: &GpuContext, name: &str, staged: bool) -> Arc<Kernel> {
    if staged { Kernel::get(ctx, name) } else { Kernel::get_with(ctx, name, &[("STAGE_RUNS", 0.0)]) }
}

impl GpuMesh {
    /// Whether the bark and leaf kernels write their runs through workgroup memory (the
    /// default) or each invocation its own directly; the vertices are the same bit for bit.
    pub fn set_staged(&mut self, ctx: &GpuContext, on: bool) {
        self.tubes = run_kernel(ctx, "mesh_tubes", on);
        self.leaves_kernel = run_kernel(ctx, "mesh_leaves", on);
        self.staged = on;
        self.plan = Default::default();
    }

    /// Runs only the kernels in `parts` from the next [`Self::record`] on (all by default);
    /// a kernel left out leaves its vertices as they were.
    pub fn set_parts(&mut self, parts: MeshParts) {
        self.parts = parts;
        self.plan = Default::default();
    }

    /// Whether runs are staged ([`Self::set_staged`]).
    pub fn staged(&self) -> bool {
        self.staged
    }

    /// Uploads the topology of `layout`.
    pub fn new(ctx: &GpuContext, layout: &MeshLayout) -> Result<Self, GpuError> {
        let n = layout.segments.len();
        Ok(Self {
            tubes: Kernel::get(ctx, "mesh_tubes"),
            detail_kernel: Kernel::get(ctx, "mesh_detail"),
            leaves_kernel: Kernel::get(ctx, "mesh_leaves"),
            info: upload(ctx, "mesh info", &[layout.info()])?,
            rings: upload(ctx, "rings", &layout.rings)?,
            details: upload(ctx, "mesh details", &layout.details)?,
            segments: upload(ctx, "mesh segments", &layout.segments)?,
            leaves: upload(ctx, "mesh leaves", &layout.leaves)?,
            joint: output::<[f32; 4]>(ctx, "mesh joints", n)?,
            acc: output::<[f32; 4]>(ctx, "mesh rotations", n)?,
            leaf_rotation: upload(
                ctx,
                "mesh leaf rotations",
                &vec![[0.0f32, 0.0, 0.0, 1.0]; layout.leaf_slots.max(1) as usize],
            )?,
            tube_vertices: vertex_buffer(ctx, "tube vertices", layout.tube_vertex_count())?,
            tube_indices: index_buffer(ctx, "tube indices", &layout.tube_indices),
            leaf_vertices: vertex_buffer(ctx, "leaf vertices", layout.leaf_vertex_count())?,
            leaf_indices: index_buffer(ctx, "leaf indices", &layout.leaf_indices),
            tube_uv: uv_buffer(ctx, "tube uv", &layout.tube_uv()),
            leaf_uv: uv_buffer(ctx, "leaf uv", &layout.leaf_uv()),
            leaf_rim: static_buffer(ctx, "leaf rims", &layout.leaf_rim_table(), wgpu::BufferUsages::STORAGE),
            tube_index_count: layout.tube_indices.len() as u32,
            leaf_index_count: layout.leaf_indices.len() as u32,
            tube_vertex_count: layout.tube_vertex_count(),
            leaf_vertex_count: layout.leaf_vertex_count(),
            ring_count: layout.rings.len(),
            detail_count: layout.details.len(),
            leaf_count: layout.leaves.len(),
            segment_count: n,
            leaf_slots: layout.leaf_slots as usize,
            staged: true,
            plan: Default::default(),
            parts: MeshParts::default(),
        })
    }

    /// Records the vertex kernels reading the pose from `joint` and `acc` (a GPU method's
    /// [`crate::pose::GpuPose::joints_buffer`] and [`crate::pose::GpuPose::acc_buffer`]),
    /// leaves at rest on their segments.
    pub fn record(
        &self,
        ctx: &GpuContext,
        encoder: &mut wgpu::CommandEncoder,
        joint: &wgpu::Buffer,
        acc: &wgpu::Buffer,
    ) {
        self.record_with_leaves(ctx, encoder, joint, acc, &self.leaf_rotation);
    }

    /// Records the vertex kernels reading the pose from `joint`, `acc` and the leaves'
    /// rotations `leaf_rotation` (a GPU method's [`crate::pose::GpuPose::leaf_buffer`]).
    pub fn record_with_leaves(
        &self,
        ctx: &GpuContext,
        encoder: &mut wgpu::CommandEncoder,
        joint: &wgpu::Buffer,
        acc: &wgpu::Buffer,
        leaf_rotation: &wgpu::Buffer,
    ) {
        let plan = self.plan.get(&[joint, acc, leaf_rotation], || {
            // One pass: the detail kernel reads the rings' vertices the tube kernel wrote,
            // which the barrier between dispatches orders.
            let mut plan = Plan::default();
            if self.ring_count > 0 && self.parts.tubes {
                let buffers = [&self.info, &self.rings, &self.segments, joint, acc, &self.tube_vertices];
                plan.push(ctx, &self.tubes, &buffers, self.ring_count as u32);
            }
            if self.detail_count > 0 && self.parts.detail {
                let buffers = [&self.info, &self.details, &self.tube_vertices, &self.rings];
                plan.push(ctx, &self.detail_kernel, &buffers, self.detail_count as u32);
            }
            if self.leaf_count > 0 && self.parts.leaves {
                let buffers = [
                    &self.info,
                    &self.leaves,
                    &self.segments,
                    joint,
                    acc,
                    &self.leaf_vertices,
                    leaf_rotation,
                    &self.leaf_rim,
                ];
                plan.push(ctx, &self.leaves_kernel, &buffers, self.leaf_count as u32);
            }
            plan
        });
        plan.record(ctx, encoder, "mesh");
    }

    /// Uploads a CPU pose and records the vertex kernels on it.
    pub fn record_pose(&self, ctx: &GpuContext, encoder: &mut wgpu::CommandEncoder, tree: &Tree, pose: &Pose) {
        let (joint, acc) = pose_buffers(tree, pose);
        debug_assert_eq!(joint.len(), self.segment_count);
        self.record_seam(ctx, encoder, &SeamPose { joints: joint, acc, leaf: Vec::new() });
    }

    /// Uploads the seam's buffers of a pose made on the CPU (one instance) and records the
    /// meshing kernels on them.
    pub fn record_seam(&self, ctx: &GpuContext, encoder: &mut wgpu::CommandEncoder, seam: &SeamPose) {
        debug_assert_eq!(seam.joints.len(), self.segment_count);
        ctx.queue.write_buffer(&self.joint, 0, bytemuck::cast_slice(&seam.joints));
        ctx.queue.write_buffer(&self.acc, 0, bytemuck::cast_slice(&seam.acc));
        if self.leaf_slots > 0 {
            if let Some(all) = seam.leaf.get(..self.leaf_slots) {
                ctx.queue.write_buffer(&self.leaf_rotation, 0, bytemuck::cast_slice(all));
            } else {
                // Fewer rotations than leaves (none: at rest): the rest take the identity.
                let identity = [0.0f32, 0.0, 0.0, 1.0];
                let leaves: Vec<[f32; 4]> =
                    (0..self.leaf_slots).map(|l| seam.leaf.get(l).copied().unwrap_or(identity)).collect();
                ctx.queue.write_buffer(&self.leaf_rotation, 0, bytemuck::cast_slice(&leaves));
            }
        }
        self.record(ctx, encoder, &self.joint, &self.acc);
    }

    /// Meshes a CPU pose and reads the vertices back (tests, exporters).
    pub fn mesh(&self, ctx: &GpuContext, tree: &Tree, pose: &Pose) -> Result<MeshFrame, GpuError> {
        let mut encoder = ctx.device.create_command_encoder(&Default::default());
        self.record_pose(ctx, &mut encoder, tree, pose);
        ctx.submit([encoder.finish()]);
        self.read(ctx)
    }

    /// What the renderer draws: this mesh once per instance of `instances`.
    pub fn draw_item<'a>(&'a self, instances: &'a wgpu::Buffer, instance_count: u32) -> crate::render::DrawItem<'a> {
        let buffers = |vertices, uv, indices, index_count| crate::render::MeshBuffers {
            vertices,
            uv,
            indices,
            index_count,
            per_instance_vertices: 0,
        };
        crate::render::DrawItem {
            bark: buffers(&self.tube_vertices, &self.tube_uv, &self.tube_indices, self.tube_index_count),
            leaves: buffers(&self.leaf_vertices, &self.leaf_uv, &self.leaf_indices, self.leaf_index_count),
            instances,
            first_instance: 0,
            instance_count,
        }
    }

    /// Reads the current vertices back.
    pub fn read(&self, ctx: &GpuContext) -> Result<MeshFrame, GpuError> {
        Ok(MeshFrame {
            tubes: read_back(ctx, &self.tube_vertices, self.tube_vertex_count)?,
            leaves: read_back(ctx, &self.leaf_vertices, self.leaf_vertex_count)?,
        })
    }
}
