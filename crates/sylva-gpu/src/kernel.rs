//! A small, uniform way to run a compute kernel: build the pipeline from composed WGSL
//! ([`crate::shaders::compose`]), upload structure-of-arrays buffers, dispatch over any
//! number of invocations, and read back.
//!
//! Kernels index their work item as `gid.x + gid.y * num_workgroups.x * WORKGROUP`, so a
//! dispatch larger than the 65,535-workgroup limit of one dimension spills into `y`.

use crate::context::Counters;
use crate::{GpuContext, GpuError};
use bytemuck::Pod;
use wgpu::util::DeviceExt;

/// How long a kernel took.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct KernelTiming {
    /// GPU time of the compute pass from timestamp queries, where the adapter supports them.
    pub gpu: Option<std::time::Duration>,
    /// Wall-clock time from submission to completion.
    pub wall: std::time::Duration,
}

impl KernelTiming {
    /// The best available figure: GPU time if measured, else wall clock.
    pub fn best(&self) -> std::time::Duration {
        self.gpu.unwrap_or(self.wall)
    }
}

/// Threads per workgroup used by Sylva's one-dimensional kernels.
pub const WORKGROUP: u32 = 64;

/// A compiled compute kernel.
#[derive(Debug)]
pub struct Kernel {
    /// Kernel name (for labels and timing).
    pub name: &'static str,
    pipeline: wgpu::ComputePipeline,
    layout: wgpu::BindGroupLayout,
    max_groups_x: Option<u32>,
}

impl Kernel {
    /// Compiles `sources` (composed in order) with entry point `main`.
    pub fn new(ctx: &GpuContext, name: &'static str, sources: &[&str]) -> Self {
        Self::with_constants(ctx, name, sources, &[])
    }

    /// [`Self::new`] with values for the module's pipeline-overridable constants.
    pub fn with_constants(ctx: &GpuContext, name: &'static str, sources: &[&str], constants: &[(&str, f64)]) -> Self {
        let module = ctx.device.create_shader_module(wgpu::ShaderModuleDescriptor {
            label: Some(name),
            source: wgpu::ShaderSource::Wgsl(crate::shaders::compose(sources).into()),
        });
        let pipeline = ctx.device.create_compute_pipeline(&wgpu::ComputePipelineDescriptor {
            label: Some(name),
            layout: None,
            module: &module,
            entry_point: Some("main"),
            compilation_options: wgpu::PipelineCompilationOptions { constants, ..Default::default() },
            cache: None,
        });
        let layout = pipeline.get_bind_group_layout(0);
        Self { name, pipeline, layout, max_groups_x: None }
    }

    /// The kernel `name` composed from `sources`, compiled on first use and shared after
    /// (shader compilation is the slow part of setting a kernel up, seconds on a software
    /// rasteriser). Sylva's own kernels come by [`Self::get`]; this is for kernels of
    /// methods defined outside the crate, under names of their own.
    pub fn cached(ctx: &GpuContext, name: &'static str, sources: &[&str]) -> std::sync::Arc<Self> {
        Self::cached_with(ctx, name, sources, &[])
    }

    /// [`Self::cached`] with values for the module's pipeline-overridable constants, used on
    /// first compilation.
    fn cached_with(
        ctx: &GpuContext,
        name: &'static str,
        sources: &[&str],
        constants: &[(&str, f64)],
    ) -> std::sync::Arc<Self> {
        let key = (name, constants.iter().map(|(k, v)| (k.to_string(), v.to_bits())).collect());
        let mut map = ctx.kernels.lock().unwrap_or_else(|e| e.into_inner());
        map.entry(key)
            .or_insert_with(|| std::sync::Arc::new(Self::with_constants(ctx, name, sources, constants)))
            .clone()
    }

    /// The registered kernel `name` ([`crate::shaders::KERNELS`]), compiled on first use and
    /// shared after. Panics when no kernel has that name (names are constants of the crate).
    pub fn get(ctx: &GpuContext, name: &str) -> std::sync::Arc<Self> {
        Self::get_with(ctx, name, &[])
    }

    /// [`Self::get`] for a kernel with pipeline-overridable constants: compiled with
    /// `constants` on first use on this context, shared after (one pipeline per kernel and
    /// set of values).
    pub fn get_with(ctx: &GpuContext, name: &str, constants: &[(&str, f64)]) -> std::sync::Arc<Self> {
        let def = crate::shaders::kernel(name).unwrap_or_else(|| panic!("no kernel `{name}` in shaders::KERNELS"));
        Self::cached_with(ctx, def.name, def.sources, constants)
    }

    /// Caps the workgroups in `x` below the device limit, so tests can exercise the spill
    /// into `y` without buffers of 4 million elements.
    pub fn with_max_groups_x(mut self, max: u32) -> Self {
        self.max_groups_x = Some(max.max(1));
        self
    }

    /// Binds `buffers` at 0, 1, 2, … for this kernel, once, for dispatches recorded many
    /// times ([`Self::dispatch`], [`Plan`]): creating a bind group is most of
    /// what recording a small dispatch costs the CPU.
    pub fn bind(&self, ctx: &GpuContext, buffers: &[&wgpu::Buffer]) -> wgpu::BindGroup {
        self.bind_resources(ctx, &buffers.iter().map(|b| b.as_entire_binding()).collect::<Vec<_>>())
    }

    /// A bind group of `resources` at bindings 0, 1, 2, … (a buffer's range, where a kernel
    /// reads one element of a larger buffer).
    pub fn bind_resources(&self, ctx: &GpuContext, resources: &[wgpu::BindingResource<'_>]) -> wgpu::BindGroup {
        let entries: Vec<wgpu::BindGroupEntry<'_>> = resources
            .iter()
            .enumerate()
            .map(|(i, r)| wgpu::BindGroupEntry { binding: i as u32, resource: r.clone() })
            .collect();
        Counters::add(&ctx.counters.bind_groups);
        ctx.device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some(self.name),
            layout: &self.layout,
            entries: &entries,
        })
    }

    /// Records a dispatch of `invocations` work items with `buffers` bound at 0, 1, 2, …, in
    /// a pass of its own.
    pub fn record(
        &self,
        ctx: &GpuContext,
        encoder: &mut wgpu::CommandEncoder,
        buffers: &[&wgpu::Buffer],
        invocations: u32,
    ) {
        let bind = self.bind(ctx, buffers);
        let mut pass = compute_pass(ctx, encoder, self.name);
        self.dispatch(ctx, &mut pass, &bind, invocations);
    }

    /// Records a dispatch of `invocations` work items on a bind group from [`Self::bind`]
    /// into an open pass ([`compute_pass`]): dependent dispatches of one pass are ordered
    /// by the barriers wgpu inserts between them.
    pub fn dispatch(
        &self,
        ctx: &GpuContext,
        pass: &mut wgpu::ComputePass<'_>,
        bind: &wgpu::BindGroup,
        invocations: u32,
    ) {
        let groups = invocations.div_ceil(WORKGROUP).max(1);
        let device_max = ctx.device.limits().max_compute_workgroups_per_dimension.max(1);
        let max = self.max_groups_x.map_or(device_max, |m| m.min(device_max));
        let (x, y) = if groups <= max { (groups, 1) } else { (max, groups.div_ceil(max)) };
        Counters::add(&ctx.counters.dispatches);
        pass.set_pipeline(&self.pipeline);
        pass.set_bind_group(0, bind, &[]);
        pass.dispatch_workgroups(x, y, 1);
    }

    /// Dispatches once, submits and waits, timing the kernel: with timestamp queries when
    /// the device has them (GPU time of the pass), and always by wall clock from submit to
    /// completion.
    pub fn run_timed(
        &self,
        ctx: &GpuContext,
        buffers: &[&wgpu::Buffer],
        invocations: u32,
    ) -> Result<KernelTiming, GpuError> {
        let mut encoder = ctx.device.create_command_encoder(&wgpu::CommandEncoderDescriptor { label: Some(self.name) });
        let timer = crate::timer::GpuTimer::new(ctx);
        if let Some(t) = &timer {
            t.begin(&mut encoder);
        }
        self.record(ctx, &mut encoder, buffers, invocations);
        if let Some(t) = &timer {
            t.end(&mut encoder);
        }
        ctx.wait()?;
        let start = std::time::Instant::now();
        ctx.submit([encoder.finish()]);
        ctx.wait()?;
        let wall = start.elapsed();
        let gpu = match &timer {
            Some(t) => t.read(ctx)?,
            None => None,
        };
        Ok(KernelTiming { gpu, wall })
    }

    /// Dispatches once and submits.
    pub fn run(&self, ctx: &GpuContext, buffers: &[&wgpu::Buffer], invocations: u32) {
        let mut encoder = ctx.device.create_command_encoder(&wgpu::CommandEncoderDescriptor { label: Some(self.name) });
        self.record(ctx, &mut encoder, buffers, invocations);
        ctx.submit([encoder.finish()]);
    }
}

/// Dispatches bound once and recorded together: each entry a kernel, its bind group and its
/// invocations, recorded in order into one compute pass (the barriers between dispatches
/// order those that depend on each other). For work whose buffers do not change from frame
/// to frame, such as a pose's forward kinematics.
#[derive(Debug, Default)]
pub struct Plan(Vec<(std::sync::Arc<Kernel>, wgpu::BindGroup, u32)>);

impl Plan {
    /// Appends a dispatch of `kernel` over `invocations` with `buffers` bound at 0, 1, 2, …
    pub fn push(
        &mut self,
        ctx: &GpuContext,
        kernel: &std::sync::Arc<Kernel>,
        buffers: &[&wgpu::Buffer],
        invocations: u32,
    ) {
        self.0.push((kernel.clone(), kernel.bind(ctx, buffers), invocations));
    }

    /// Appends a dispatch of `kernel` over `invocations` with `resources` bound at 0, 1, 2, …
    pub fn push_resources(
        &mut self,
        ctx: &GpuContext,
        kernel: &std::sync::Arc<Kernel>,
        resources: &[wgpu::BindingResource<'_>],
        invocations: u32,
    ) {
        self.0.push((kernel.clone(), kernel.bind_resources(ctx, resources), invocations));
    }

    /// Records every dispatch, in order, in one pass labelled `label` (none when empty).
    pub fn record(&self, ctx: &GpuContext, encoder: &mut wgpu::CommandEncoder, label: &'static str) {
        if self.0.is_empty() {
            return;
        }
        let mut pass = compute_pass(ctx, encoder, label);
        self.dispatch(ctx, &mut pass);
    }

    /// Records every dispatch, in order, into an open pass.
    pub fn dispatch(&self, ctx: &GpuContext, pass: &mut wgpu::ComputePass<'_>) {
        for (kernel, bind, invocations) in &self.0 {
            kernel.dispatch(ctx, pass, bind, *invocations);
        }
    }
}

/// A [`Plan`] for the buffers it was last asked for, made again when they change: for
/// kernels that read a method's or an application's buffers, the same ones frame after
/// frame. It keeps those buffers alive until it is dropped or asked for others.
#[derive(Debug, Default)]
pub struct PlanCache(std::sync::Mutex<Option<(Vec<wgpu::Buffer>, std::sync::Arc<Plan>)>>);

impl PlanCache {
    /// The plan for `buffers`, made by `make` unless the last call passed the same ones.
    pub fn get(&self, buffers: &[&wgpu::Buffer], make: impl FnOnce() -> Plan) -> std::sync::Arc<Plan> {
        let mut cache = self.0.lock().unwrap_or_else(|e| e.into_inner());
        match &*cache {
            Some((key, plan)) if key.len() == buffers.len() && key.iter().zip(buffers).all(|(a, b)| a == *b) => {
                plan.clone()
            }
            _ => {
                let plan = std::sync::Arc::new(make());
                *cache = Some((buffers.iter().map(|b| (*b).clone()).collect(), plan.clone()));
                plan
            }
        }
    }
}

/// Begins a compute pass (counted in [`GpuContext::counts`]) for dispatches recorded with
/// [`Kernel::dispatch`].
pub fn compute_pass<'e>(
    ctx: &GpuContext,
    encoder: &'e mut wgpu::CommandEncoder,
    label: &'static str,
) -> wgpu::ComputePass<'e> {
    Counters::add(&ctx.counters.passes);
    encoder.begin_compute_pass(&wgpu::ComputePassDescriptor { label: Some(label), timestamp_writes: None })
}

fn check_size(ctx: &GpuContext, what: &'static str, bytes: u64) -> Result<(), GpuError> {
    let limit = ctx.device.limits().max_storage_buffer_binding_size;
    if bytes > limit {
        return Err(GpuError::TooLarge { what, bytes, limit });
    }
    Ok(())
}

/// Uploads a slice as a storage buffer (at least 16 bytes, as empty bindings are invalid).
pub fn upload<T: Pod>(ctx: &GpuContext, label: &'static str, data: &[T]) -> Result<wgpu::Buffer, GpuError> {
    let bytes: &[u8] = bytemuck::cast_slice(data);
    check_size(ctx, label, bytes.len() as u64)?;
    let mut padded;
    let contents = if bytes.len() < 16 {
        padded = bytes.to_vec();
        padded.resize(16, 0);
        &padded[..]
    } else {
        bytes
    };
    Ok(ctx.device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
        label: Some(label),
        contents,
        usage: wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_SRC | wgpu::BufferUsages::COPY_DST,
    }))
}

/// A storage buffer for `len` elements of `T` to be written by a kernel.
pub fn output<T: Pod>(ctx: &GpuContext, label: &'static str, len: usize) -> Result<wgpu::Buffer, GpuError> {
    let bytes = (len * std::mem::size_of::<T>()).max(16) as u64;
    check_size(ctx, label, bytes)?;
    Ok(ctx.device.create_buffer(&wgpu::BufferDescriptor {
        label: Some(label),
        size: bytes,
        usage: wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_SRC | wgpu::BufferUsages::COPY_DST,
        mapped_at_creation: false,
    }))
}

/// Copies `len` elements of `T` from a storage buffer back to the CPU (waits for the GPU).
pub fn read_back<T: Pod>(ctx: &GpuContext, buffer: &wgpu::Buffer, len: usize) -> Result<Vec<T>, GpuError> {
    let bytes = (len * std::mem::size_of::<T>()) as u64;
    if bytes == 0 {
        return Ok(Vec::new());
    }
    let staging = ctx.device.create_buffer(&wgpu::BufferDescriptor {
        label: Some("readback"),
        size: bytes,
        usage: wgpu::BufferUsages::MAP_READ | wgpu::BufferUsages::COPY_DST,
        mapped_at_creation: false,
    });
    let mut encoder = ctx.device.create_command_encoder(&wgpu::CommandEncoderDescriptor { label: Some("readback") });
    encoder.copy_buffer_to_buffer(buffer, 0, &staging, 0, bytes);
    ctx.submit([encoder.finish()]);
    map_read(ctx, &staging, |bytes| bytemuck::cast_slice::<u8, T>(bytes).to_vec())
}

/// Maps a `MAP_READ` buffer (waiting for the GPU), passes its bytes to `read`, unmaps it.
pub fn map_read<R>(ctx: &GpuContext, buffer: &wgpu::Buffer, read: impl FnOnce(&[u8]) -> R) -> Result<R, GpuError> {
    let slice = buffer.slice(..);
    let (tx, rx) = std::sync::mpsc::channel();
    slice.map_async(wgpu::MapMode::Read, move |r| {
        let _ = tx.send(r);
    });
    ctx.wait()?;
    rx.recv().map_err(|e| GpuError::Map(e.to_string()))?.map_err(|e| GpuError::Map(e.to_string()))?;
    let view = slice.get_mapped_range().map_err(|e| GpuError::Map(e.to_string()))?;
    let out = read(&view);
    drop(view);
    buffer.unmap();
    Ok(out)
}
