//! GPU twin of [`sylva_core::methods::zioma::trunk::trunk_noise`]: trunk noise bands at many (t, tree).

use crate::kernel::{Kernel, output, read_back, upload};
use crate::{GpuContext, GpuError};
use sylva_core::methods::zioma::trunk::RawBand;

/// Angles (parallel, perpendicular, twist, 0) at samples (t, tree seed bits, –, –).
pub fn trunk_noise(ctx: &GpuContext, bands: &[RawBand], samples: &[[f32; 4]]) -> Result<Vec<[f32; 4]>, GpuError> {
    let kernel = Kernel::get(ctx, "trunk_noise");
    let zero = [RawBand { axis: 0, seed: 0, frequency: 0.0, amplitude: 0.0, bias: 0.0, _pad: [0; 3] }];
    let b = upload(ctx, "bands", if bands.is_empty() { &zero } else { bands })?;
    let s = upload(ctx, "samples", samples)?;
    let out = output::<[f32; 4]>(ctx, "angles", samples.len())?;
    kernel.run(ctx, &[&b, &s, &out], samples.len() as u32);
    read_back(ctx, &out, samples.len())
}
