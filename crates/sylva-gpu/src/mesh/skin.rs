//! Skinning on the GPU (Zioma §6.5): one rest mesh, every instance's pose applied by
//! `skin_vertices.wgsl` into instance-major vertex buffers the renderer draws as they are.

use crate::kernel::{Kernel, Plan, PlanCache, read_back, upload};
use crate::mesh::{index_buffer, uv_buffer, vertex_buffer};
use crate::render::{DrawItem, MeshBuffers};
use crate::{GpuContext, GpuError};
use std::sync::Arc;
use sylva_core::mesh::{MeshFrame, MeshLayout, RawSkinInfo, RawVertex, SkinLayout, Uv};

struct Part {
    rest: wgpu::Buffer,
    /// Texture coordinates of one instance's vertices (every instance's).
    uv: wgpu::Buffer,
    skin: wgpu::Buffer,
    indices: wgpu::Buffer,
    index_count: u32,
    vertices: usize,
}

impl std::fmt::Debug for Part {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Part").field("vertices", &self.vertices).field("index_count", &self.index_count).finish()
    }
}

/// A run of instances whose skinned vertices fit one storage binding.
struct Batch {
    first: u32,
    count: u32,
    /// Bark then leaves: the dispatch's sizes and its output.
    out: [(wgpu::Buffer, wgpu::Buffer); 2],
}

impl std::fmt::Debug for Batch {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Batch").field("first", &self.first).field("count", &self.count).finish()
    }
}

/// A skinned mesh for `instances` poses of one tree. The output is split into batches of
/// instances so no buffer exceeds the device's largest storage binding (128 MiB on
/// lavapipe: about 980 instances of a 4,275-vertex tree); each batch is one dispatch per
/// part and one draw item.
#[derive(Debug)]
pub struct GpuSkin {
    kernel: Arc<Kernel>,
    rest_joint: wgpu::Buffer,
    leaf_attach: wgpu::Buffer,
    /// The identity for every leaf: leaves at rest.
    leaf_rest: wgpu::Buffer,
    tubes: Part,
    leaves: Part,
    batches: Vec<Batch>,
    instances: u32,
    /// The batches bound to the last pose buffers skinned.
    plan: PlanCache,
}

impl GpuSkin {
    /// Uploads the rest mesh and weights for `instances` instances, in as few batches as
    /// the device's binding limit allows.
    pub fn new(ctx: &GpuContext, layout: &MeshLayout, skin: &SkinLayout, instances: u32) -> Result<Self, GpuError> {
        Self::with_max_batch(ctx, layout, skin, instances, u32::MAX)
    }

    /// As [`Self::new`] with at most `max_batch` instances per batch (tests use it to
    /// exercise batching without buffers of the limit's size).
    pub fn with_max_batch(
        ctx: &GpuContext,
        layout: &MeshLayout,
        skin: &SkinLayout,
        instances: u32,
        max_batch: u32,
    ) -> Result<Self, GpuError> {
        let instances = instances.max(1);
        let part = |rest: &[RawVertex], uv: &[Uv], weights, indices: &[u32]| -> Result<Part, GpuError> {
            Ok(Part {
                rest: upload(ctx, "skin rest", rest)?,
                uv: uv_buffer(ctx, "skin uv", uv),
                skin: upload(ctx, "skin weights", weights)?,
                indices: index_buffer(ctx, "skin indices", indices),
                index_count: indices.len() as u32,
                vertices: rest.len(),
            })
        };
        let tubes = part(&skin.tube_rest, &layout.tube_uv(), &skin.tube_skin, &layout.tube_indices)?;
        let leaves = part(&skin.leaf_rest, &layout.leaf_uv(), &skin.leaf_skin, &layout.leaf_indices)?;
        let limits = ctx.device.limits();
        let limit = limits.max_storage_buffer_binding_size.min(limits.max_buffer_size);
        let per_instance = (tubes.vertices.max(leaves.vertices).max(1) * std::mem::size_of::<RawVertex>()) as u64;
        // One instance too large for a binding fails in `vertex_buffer` below.
        let per_batch = (limit / per_instance).clamp(1, u32::MAX as u64) as u32;
        let per_batch = per_batch.min(max_batch.max(1));
        let mut batches = Vec::new();
        let mut first = 0;
        while first < instances {
            let count = per_batch.min(instances - first);
            let out = |p: &Part, label| -> Result<(wgpu::Buffer, wgpu::Buffer), GpuError> {
                let info = RawSkinInfo {
                    vertices: p.vertices as u32,
                    segments: skin.segments,
                    instances: count,
                    first_instance: first,
                };
                Ok((upload(ctx, "skin info", &[info])?, vertex_buffer(ctx, label, p.vertices * count as usize)?))
            };
            batches.push(Batch { first, count, out: [out(&tubes, "skinned bark")?, out(&leaves, "skinned leaves")?] });
            first += count;
        }
        Ok(Self {
            kernel: Kernel::get(ctx, "skin_vertices"),
            rest_joint: upload(ctx, "skin rest joints", &skin.rest_joint)?,
            leaf_attach: upload(ctx, "skin leaf attachments", &skin.leaf_attach)?,
            leaf_rest: upload(
                ctx,
                "skin leaf rotations",
                &vec![[0.0f32, 0.0, 0.0, 1.0]; skin.leaf_attach.len().max(1)],
            )?,
            tubes,
            leaves,
            batches,
            instances,
            plan: Default::default(),
        })
    }

    /// Batches of instances (one dispatch per part and one draw item each).
    pub fn batch_count(&self) -> usize {
        self.batches.len()
    }

    /// Records skinning of every instance from instance-major pose buffers, leaves at rest.
    pub fn record(
        &self,
        ctx: &GpuContext,
        encoder: &mut wgpu::CommandEncoder,
        joint: &wgpu::Buffer,
        acc: &wgpu::Buffer,
    ) {
        self.record_with_leaves(ctx, encoder, joint, acc, &self.leaf_rest);
    }

    /// Records skinning of every instance, every instance's leaves turned by
    /// `leaf_rotation` (one per leaf, shared: a GPU method's
    /// [`crate::pose::GpuPose::leaf_buffer`]).
    pub fn record_with_leaves(
        &self,
        ctx: &GpuContext,
        encoder: &mut wgpu::CommandEncoder,
        joint: &wgpu::Buffer,
        acc: &wgpu::Buffer,
        leaf_rotation: &wgpu::Buffer,
    ) {
        let plan = self.plan.get(&[joint, acc, leaf_rotation], || {
            let mut plan = Plan::default();
            for b in &self.batches {
                for (p, (info, out)) in [&self.tubes, &self.leaves].into_iter().zip(&b.out) {
                    if p.vertices > 0 {
                        let buffers = [
                            info,
                            &p.rest,
                            &p.skin,
                            &self.rest_joint,
                            joint,
                            acc,
                            out,
                            &self.leaf_attach,
                            leaf_rotation,
                        ];
                        plan.push(ctx, &self.kernel, &buffers, (p.vertices * b.count as usize) as u32);
                    }
                }
            }
            plan
        });
        plan.record(ctx, encoder, "skin");
    }

    /// Reads every instance's vertices back (instance-major).
    pub fn read(&self, ctx: &GpuContext) -> Result<MeshFrame, GpuError> {
        let mut frame = MeshFrame { tubes: Vec::new(), leaves: Vec::new() };
        for b in &self.batches {
            let n = b.count as usize;
            frame.tubes.extend(read_back::<RawVertex>(ctx, &b.out[0].1, self.tubes.vertices * n)?);
            frame.leaves.extend(read_back::<RawVertex>(ctx, &b.out[1].1, self.leaves.vertices * n)?);
        }
        Ok(frame)
    }

    /// What the renderer draws, one item per batch: instance `first + k` of `instances` uses
    /// the batch's vertices `k × vertices ..`.
    pub fn draw_items<'a>(&'a self, instances: &'a wgpu::Buffer) -> Vec<DrawItem<'a>> {
        self.batches
            .iter()
            .map(|b| {
                let part = |p: &'a Part, out: &'a wgpu::Buffer| MeshBuffers {
                    vertices: out,
                    uv: &p.uv,
                    indices: &p.indices,
                    index_count: p.index_count,
                    per_instance_vertices: p.vertices as u32,
                };
                DrawItem {
                    bark: part(&self.tubes, &b.out[0].1),
                    leaves: part(&self.leaves, &b.out[1].1),
                    instances,
                    first_instance: b.first,
                    instance_count: b.count,
                }
            })
            .collect()
    }

    /// Instances skinned.
    pub fn instance_count(&self) -> u32 {
        self.instances
    }
}
