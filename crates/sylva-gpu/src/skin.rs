//! Skinning on the GPU (Zioma §6.5): one rest mesh, every instance's pose applied by
//! `skin_vertices.wgsl` into instance-major vertex buffers the renderer draws as they are.

use crate::kernel::{Kernel, read_back, upload};
use crate::mesh::{index_buffer, vertex_buffer};
use crate::render::{DrawItem, MeshBuffers};
use crate::shader::{MESH, NOISE, QUAT, SKIN_VERTICES};
use crate::{GpuContext, GpuError};
use std::sync::Arc;
use sylva_core::mesh::{MeshFrame, MeshLayout, RawSkinInfo, RawVertex, SkinLayout};

struct Part {
    info: wgpu::Buffer,
    rest: wgpu::Buffer,
    skin: wgpu::Buffer,
    out: wgpu::Buffer,
    indices: wgpu::Buffer,
    index_count: u32,
    vertices: usize,
}

impl std::fmt::Debug for Part {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Part").field("vertices", &self.vertices).field("index_count", &self.index_count).finish()
    }
}

/// A skinned mesh for `instances` poses of one tree.
#[derive(Debug)]
pub struct GpuSkin {
    kernel: Arc<Kernel>,
    rest_joint: wgpu::Buffer,
    tubes: Part,
    leaves: Part,
    instances: u32,
}

impl GpuSkin {
    /// Uploads the rest mesh and weights for `instances` instances.
    pub fn new(ctx: &GpuContext, layout: &MeshLayout, skin: &SkinLayout, instances: u32) -> Result<Self, GpuError> {
        let instances = instances.max(1);
        let part = |rest: &[RawVertex], weights, indices: &[u32], label| -> Result<Part, GpuError> {
            let info = RawSkinInfo { vertices: rest.len() as u32, segments: skin.segments, instances, _pad: 0 };
            Ok(Part {
                info: upload(ctx, "skin info", &[info])?,
                rest: upload(ctx, "skin rest", rest)?,
                skin: upload(ctx, "skin weights", weights)?,
                out: vertex_buffer(ctx, label, rest.len() * instances as usize)?,
                indices: index_buffer(ctx, "skin indices", indices),
                index_count: indices.len() as u32,
                vertices: rest.len(),
            })
        };
        Ok(Self {
            kernel: Kernel::cached(ctx, "skin_vertices", &[QUAT, NOISE, MESH, SKIN_VERTICES]),
            rest_joint: upload(ctx, "skin rest joints", &skin.rest_joint)?,
            tubes: part(&skin.tube_rest, &skin.tube_skin, &layout.tube_indices, "skinned bark")?,
            leaves: part(&skin.leaf_rest, &skin.leaf_skin, &layout.leaf_indices, "skinned leaves")?,
            instances,
        })
    }

    /// Records skinning of every instance from instance-major pose buffers.
    pub fn record(
        &self,
        ctx: &GpuContext,
        encoder: &mut wgpu::CommandEncoder,
        joint: &wgpu::Buffer,
        acc: &wgpu::Buffer,
    ) {
        for p in [&self.tubes, &self.leaves] {
            if p.vertices > 0 {
                self.kernel.record(
                    ctx,
                    encoder,
                    &[&p.info, &p.rest, &p.skin, &self.rest_joint, joint, acc, &p.out],
                    (p.vertices * self.instances as usize) as u32,
                );
            }
        }
    }

    /// Reads every instance's vertices back (instance-major).
    pub fn read(&self, ctx: &GpuContext) -> Result<MeshFrame, GpuError> {
        let n = self.instances as usize;
        Ok(MeshFrame {
            tubes: read_back(ctx, &self.tubes.out, self.tubes.vertices * n)?,
            leaves: read_back(ctx, &self.leaves.out, self.leaves.vertices * n)?,
        })
    }

    /// What the renderer draws: instance k uses vertices `k × vertices ..` and instance
    /// transform k.
    pub fn draw_item<'a>(&'a self, instances: &'a wgpu::Buffer) -> DrawItem<'a> {
        let part = |p: &'a Part| MeshBuffers {
            vertices: &p.out,
            indices: &p.indices,
            index_count: p.index_count,
            per_instance_vertices: p.vertices as u32,
        };
        DrawItem { bark: part(&self.tubes), leaves: part(&self.leaves), instances, instance_count: self.instances }
    }
}
