//! The wind on the device: a scene's packed fields and waves uploaded once per change and
//! shared by every GPU method that samples it ([`GpuWind`]), and the `wind_sample` kernel
//! (twin of [`sylva_core::wind::sample::wind_sample`]): the wind at many (x, t).

use crate::kernel::{Kernel, KernelTiming, output, read_back, upload};
use crate::{GpuContext, GpuError};
use std::sync::Arc;
use sylva_core::wind::raw::{RawField, RawWave};
use sylva_core::wind::{PackedWind, WindScene};

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

/// A wind scene on the device: the buffers `wind.wgsl` binds at 0 and 1, and the packed
/// scene they hold (the CPU side of a GPU method reads it too). Cloning shares the buffers:
/// one upload serves every method of a scene.
#[derive(Debug, Clone)]
pub struct GpuWind {
    /// Field records (binding 0).
    pub fields: wgpu::Buffer,
    /// Wave table (binding 1).
    pub waves: wgpu::Buffer,
    /// The packed scene the buffers hold.
    pub packed: Arc<PackedWind>,
}

impl GpuWind {
    /// Uploads a packed scene.
    pub fn new(ctx: &GpuContext, packed: Arc<PackedWind>) -> Result<Self, GpuError> {
        let (fields, waves) = upload_wind(ctx, &packed.fields, &packed.waves)?;
        Ok(Self { fields, waves, packed })
    }

    /// Packs and uploads a scene.
    pub fn from_scene(ctx: &GpuContext, scene: &WindScene) -> Result<Self, GpuError> {
        Self::new(ctx, Arc::new(scene.packed()))
    }

    /// Still air.
    pub fn calm(ctx: &GpuContext) -> Result<Self, GpuError> {
        Self::new(ctx, Arc::new(PackedWind::calm()))
    }

    /// Replaces the scene: written into the same buffers when the sizes match (edits of a
    /// value), new buffers otherwise (hand the new handles to every method that binds them).
    pub fn update(&mut self, ctx: &GpuContext, packed: Arc<PackedWind>) -> Result<(), GpuError> {
        let same = packed.fields.len() == self.packed.fields.len()
            && packed.waves.len() == self.packed.waves.len()
            && !packed.fields.is_empty()
            && !packed.waves.is_empty();
        if same {
            ctx.queue.write_buffer(&self.fields, 0, bytemuck::cast_slice(&packed.fields));
            ctx.queue.write_buffer(&self.waves, 0, bytemuck::cast_slice(&packed.waves));
            self.packed = packed;
        } else {
            *self = Self::new(ctx, packed)?;
        }
        Ok(())
    }
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
        Ok(Self { kernel: Kernel::get(ctx, "wind_sample"), fields, waves })
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
