//! GPU twin of [`sylva_core::methods::zioma::frames::zioma_frames`]: every instance's frame
//! values in one dispatch. [`super::GpuZioma`] records the kernel in its plan; this runs it
//! once and reads the result back (tests, tools).

use crate::kernel::{Kernel, output, read_back, upload};
use crate::wind::GpuWind;
use crate::{GpuContext, GpuError};
use sylva_core::methods::zioma::{RawZiomaFrame, RawZiomaInstance, RawZiomaRing, RawZiomaTrunk};

/// The frame values of every instance in `instances`, ringing by its ring in `rings`, for the
/// tree's values `trunk`, in the wind `wind`.
pub fn zioma_frames(
    ctx: &GpuContext,
    wind: &GpuWind,
    trunk: &RawZiomaTrunk,
    instances: &[RawZiomaInstance],
    rings: &[RawZiomaRing],
) -> Result<Vec<RawZiomaFrame>, GpuError> {
    if instances.is_empty() {
        return Ok(Vec::new());
    }
    let kernel = Kernel::get(ctx, "zioma_frames");
    let k = upload(ctx, "zioma trunk", std::slice::from_ref(trunk))?;
    assert_eq!(instances.len(), rings.len(), "one ring per instance");
    let i = upload(ctx, "zioma instances", instances)?;
    let r = upload(ctx, "zioma rings", rings)?;
    let out = output::<RawZiomaFrame>(ctx, "zioma frames", instances.len())?;
    kernel.run(ctx, &[&wind.fields, &wind.waves, &k, &i, &r, &out], instances.len() as u32);
    read_back(ctx, &out, instances.len())
}
