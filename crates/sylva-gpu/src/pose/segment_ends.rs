//! GPU twin of [`sylva_core::pose::segment_ends::segment_ends`]: the end joint of every segment.

use crate::kernel::{Kernel, output, read_back, upload};
use crate::{GpuContext, GpuError};
use sylva_core::model::RawSegment;

/// Computes `ends[i] = start[i] + orientation[i] · (0, length[i], 0)` on the GPU.
/// Bindings: 0 = segments (read), 1 = ends (write, `vec4<f32>`, w = 1).
pub fn segment_ends(ctx: &GpuContext, segments: &[RawSegment]) -> Result<Vec<[f32; 4]>, GpuError> {
    segment_ends_with(ctx, kernel(ctx), segments)
}

/// The kernel itself, compiled once by the caller.
pub fn kernel(ctx: &GpuContext) -> Kernel {
    let def = crate::shaders::kernel("segment_ends").expect("registered");
    Kernel::new(ctx, def.name, def.sources)
}

/// [`segment_ends`] with a kernel compiled by the caller.
pub fn segment_ends_with(ctx: &GpuContext, kernel: Kernel, segments: &[RawSegment]) -> Result<Vec<[f32; 4]>, GpuError> {
    let input = upload(ctx, "segments", segments)?;
    let ends = output::<[f32; 4]>(ctx, "ends", segments.len())?;
    kernel.run(ctx, &[&input, &ends], segments.len() as u32);
    read_back(ctx, &ends, segments.len())
}
