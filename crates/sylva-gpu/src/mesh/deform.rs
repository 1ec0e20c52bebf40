//! Skjermo's deformer on the GPU (`skjermo_deform.wgsl`): every stem's grid bent along its
//! current Bézier, written into a vertex buffer the renderer draws as it is. The control
//! points come from a curve-bending method on the GPU ([`crate::methods::GpuCurves`]) or
//! are uploaded from the CPU ([`sylva_core::pose::Curves`]).

use crate::kernel::{Kernel, output, read_back, upload};
use crate::mesh::{index_buffer, uv_buffer, vertex_buffer};
use crate::render::MeshBuffers;
use crate::{GpuContext, GpuError};
use std::sync::Arc;
use sylva_core::mesh::{DeformLayout, RawVertex};
use sylva_core::methods::skjermo::{RawSkjermoState, RawSkjermoStem};
use sylva_core::pose::Curves;

/// A tree's deformer grid on the GPU.
#[derive(Debug)]
pub struct GpuDeform {
    kernel: Arc<Kernel>,
    info: wgpu::Buffer,
    rings: wgpu::Buffer,
    shapes: wgpu::Buffer,
    stems: wgpu::Buffer,
    state: wgpu::Buffer,
    vertices: wgpu::Buffer,
    uv: wgpu::Buffer,
    indices: wgpu::Buffer,
    index_count: u32,
    vertex_count: usize,
    ring_count: usize,
}

impl GpuDeform {
    /// Uploads the grid and Skjermo's per-stem constants (used when the state comes from
    /// the CPU).
    pub fn new(ctx: &GpuContext, layout: &DeformLayout, stems: &[RawSkjermoStem]) -> Result<Self, GpuError> {
        Ok(Self {
            kernel: Kernel::get(ctx, "skjermo_deform"),
            info: upload(ctx, "deform info", &[layout.info()])?,
            rings: upload(ctx, "deform rings", &layout.rings)?,
            shapes: upload(ctx, "deform shapes", &layout.shapes)?,
            stems: upload(ctx, "deform stems", stems)?,
            state: output::<RawSkjermoState>(ctx, "deform state", stems.len())?,
            vertices: vertex_buffer(ctx, "deformed bark", layout.vertex_count())?,
            uv: uv_buffer(ctx, "deformed bark uv", &layout.uv()),
            indices: index_buffer(ctx, "deformed bark indices", &layout.indices),
            index_count: layout.indices.len() as u32,
            vertex_count: layout.vertex_count(),
            ring_count: layout.rings.len(),
        })
    }

    /// The grid alone, for curves that stay on the device ([`Self::record`]).
    pub fn for_device_curves(ctx: &GpuContext, layout: &DeformLayout) -> Result<Self, GpuError> {
        Self::new(ctx, layout, &[])
    }

    /// Records the deformer reading a method's curves on the GPU.
    pub fn record(
        &self,
        ctx: &GpuContext,
        encoder: &mut wgpu::CommandEncoder,
        stems: &wgpu::Buffer,
        state: &wgpu::Buffer,
    ) {
        if self.ring_count > 0 {
            self.kernel.record(
                ctx,
                encoder,
                &[&self.info, &self.rings, &self.shapes, stems, state, &self.vertices],
                self.ring_count as u32,
            );
        }
    }

    /// Uploads a CPU state and records the deformer on it.
    pub fn record_state(&self, ctx: &GpuContext, encoder: &mut wgpu::CommandEncoder, state: &[RawSkjermoState]) {
        ctx.queue.write_buffer(&self.state, 0, bytemuck::cast_slice(state));
        self.record(ctx, encoder, &self.stems, &self.state);
    }

    /// Uploads a CPU method's current curves and records the deformer on them (the stems
    /// must be those this deformer was built with).
    pub fn record_curves(&self, ctx: &GpuContext, encoder: &mut wgpu::CommandEncoder, curves: Curves<'_>) {
        self.record_state(ctx, encoder, curves.state);
    }

    /// Deforms a CPU state and reads the vertices back.
    pub fn deform(&self, ctx: &GpuContext, state: &[RawSkjermoState]) -> Result<Vec<RawVertex>, GpuError> {
        let mut e = ctx.device.create_command_encoder(&Default::default());
        self.record_state(ctx, &mut e, state);
        ctx.submit([e.finish()]);
        read_back(ctx, &self.vertices, self.vertex_count)
    }

    /// The bark for the renderer.
    pub fn bark(&self) -> MeshBuffers<'_> {
        MeshBuffers {
            vertices: &self.vertices,
            uv: &self.uv,
            indices: &self.indices,
            index_count: self.index_count,
            per_instance_vertices: 0,
        }
    }
}
