//! GPU twin of [`sylva_core::cpu::wind_sample`]: the wind of a scene at many (x, t).

use crate::kernel::{Kernel, KernelTiming, output, read_back, upload};
use crate::shader::{NOISE, WIND, WIND_SAMPLE};
use crate::{GpuContext, GpuError};
use sylva_core::wind::WindScene;
use sylva_core::wind::raw::{RawField, RawWave};

/// Uploads a packed wind scene as the (fields, waves) storage buffers that `wind.wgsl` binds
/// at 0 and 1. An empty scene is bound as one zero constant field (bindings cannot be empty).
pub fn upload_wind(
    ctx: &GpuContext,
    fields: &[RawField],
    waves: &[RawWave],
) -> Result<(wgpu::Buffer, wgpu::Buffer), GpuError> {
    let zero_field =
        [RawField { kind: 0, wave_offset: 0, wave_count: 0, _pad: 0, a: [0.0; 4], b: [0.0; 4], c: [0.0; 4] }];
    let zero_wave = [RawWave { dir: [0.0; 4], k: [0.0; 4], phase: [0.0; 4] }];
    Ok((
        upload(ctx, "wind fields", if fields.is_empty() { &zero_field } else { fields })?,
        upload(ctx, "wind waves", if waves.is_empty() { &zero_wave } else { waves })?,
    ))
}

/// A scene uploaded once, sampled many times.
#[derive(Debug)]
pub struct WindSampler {
    kernel: std::sync::Arc<Kernel>,
    fields: wgpu::Buffer,
    waves: wgpu::Buffer,
}

impl WindSampler {
    /// Compiles the kernel and uploads the packed scene.
    pub fn new(ctx: &GpuContext, scene: &WindScene) -> Result<Self, GpuError> {
        let (fields, waves) = scene.pack();
        Self::from_raw(ctx, &fields, &waves)
    }

    /// From packed fields and waves. An empty scene is bound as one zero constant field.
    pub fn from_raw(ctx: &GpuContext, fields: &[RawField], waves: &[RawWave]) -> Result<Self, GpuError> {
        let (fields, waves) = upload_wind(ctx, fields, waves)?;
        Ok(Self { kernel: Kernel::cached(ctx, "wind_sample", &[NOISE, WIND, WIND_SAMPLE]), fields, waves })
    }

    /// Velocities (x, y, z, 0) at samples (x, y, z, t).
    pub fn sample(&self, ctx: &GpuContext, samples: &[[f32; 4]]) -> Result<Vec<[f32; 4]>, GpuError> {
        Ok(self.sample_timed(ctx, samples)?.0)
    }

    /// Samples `count` points already on the GPU into a new buffer, submitted, not waited
    /// for.
    pub fn sample_into(&self, ctx: &GpuContext, input: &wgpu::Buffer, count: usize) -> wgpu::Buffer {
        let out = output::<[f32; 4]>(ctx, "wind velocities", count).expect("the output is no larger than the input");
        self.kernel.run(ctx, &[&self.fields, &self.waves, input, &out], count as u32);
        out
    }

    /// [`Self::sample`], with the kernel's timing (upload and readback excluded).
    pub fn sample_timed(
        &self,
        ctx: &GpuContext,
        samples: &[[f32; 4]],
    ) -> Result<(Vec<[f32; 4]>, KernelTiming), GpuError> {
        let input = upload(ctx, "wind samples", samples)?;
        let out = output::<[f32; 4]>(ctx, "wind velocities", samples.len())?;
        let timing = self.kernel.run_timed(ctx, &[&self.fields, &self.waves, &input, &out], samples.len() as u32)?;
        Ok((read_back(ctx, &out, samples.len())?, timing))
    }
}
